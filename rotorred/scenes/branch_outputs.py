"""The files of a harmonic-balance branch (``rotorred continue``): CSV, NetCDF, the figure, a summary and, given a
provenance, the base scene (``scene.toml``).

A point whose stability was not computed (``--no-stability``, or an interrupt in the stability phase) is marked
alike in each: stability "unknown" in the CSV and the summary, the NetCDF flag -1 (:data:`STABILITY_FLAGS`), its
multiplier NaN, and drawn grey in the figure. An interrupted branch's summary starts with "INCOMPLETE: " and why.
"""

from __future__ import annotations

import numpy as np

from rotorred.provenance import Provenance
from rotorred.scenes.keys import cf_units, netcdf_name
from rotorred.writers import render_table, write_csv, write_netcdf, write_text

__all__ = ["STABILITY_FLAGS", "format_branch", "branch_dataset", "write_branch"]

#: the NetCDF variable ``stable``'s values and their meanings (CF flag_values, flag_meanings)
STABILITY_FLAGS = {1: "stable", 0: "unstable", -1: "unknown"}


def _scale(branch) -> tuple[float, str]:
    """The key's shown scale and unit: a clearance in µm, any other key in its own unit (Hz, N/m, ...)."""
    return (1e6, "µm") if branch.key == "rub.clearance" else (1.0, branch.unit)


def _dof_name(dof) -> str:
    return f"{dof[0]}{dof[1]}"


def _stability_flags(branch) -> np.ndarray:
    """Each point's :data:`STABILITY_FLAGS` value: 1 stable, 0 unstable, -1 not computed."""
    return np.where(branch.known, branch.stable.astype(np.int8), np.int8(-1)).astype(np.int8)


def format_branch(branch) -> str:
    """A summary: the points, the folds, where it stopped, the stable share and the times (an interrupted branch's
    first line says so: "INCOMPLETE: interrupted (SIGINT) ...")."""
    xs, xu = _scale(branch)
    dof = _dof_name(branch.dofs[0])
    rows = [[f"{xs * v:.4g}", f"{1e6 * p:.3f}", "-" if np.isnan(m) else f"{m:.3f}", STABILITY_FLAGS[f]]
            for v, p, m, f in zip(branch.values, branch.peaks[:, 0], branch.multipliers, _stability_flags(branch))]
    step = max(1, len(rows) // 25)
    table = render_table([f"{branch.key} ({xu})", f"peak {dof} (µm)", "max |mu|", "stability"], rows[::step])
    folds = ", ".join(f"{xs * v:.6g} {xu} ({'fold' if smooth else 'corner'})" for v, smooth in branch.folds) or "none"
    changes = ", ".join(f"{kind} between {xs * a:.6g} and {xs * b:.6g} {xu}" for a, b, kind in branch.bifurcations)
    n = len(branch.values)
    head, tail = (f"INCOMPLETE: {branch.stopped}\n", "") if branch.interrupted else ("", f"{branch.stopped}\n")
    return (f"{head}{table}\n{n} points{f' (every {step}th shown)' if step > 1 else ''}; turns: {folds}\n"
            f"stability changes: {changes or 'none'}\n{tail}"
            f"times: cold start {branch.start_time:.2f} s, continuation {branch.solve_time:.2f} s "
            f"({1e3 * branch.solve_time / max(n - 1, 1):.0f} ms a point), stability {branch.stability_time:.2f} s")


def branch_dataset(branch, scene_name: str):
    """The branch as an :class:`xarray.Dataset`: dims point, dof, harmonic; the key's coordinate named
    :func:`rotorred.scenes.keys.netcdf_name` (``rub_clearance``), the key itself in its ``long_name`` and
    ``rotorred_key``; CF ``units`` on every variable and coordinate ("1" when dimensionless)."""
    import xarray as xr

    key = netcdf_name(branch.key)
    return xr.Dataset(
        {"peak": (("point", "dof"), branch.peaks, {"units": "m", "long_name": "largest |q(t)| over the period"}),
         "line": (("point", "harmonic"), branch.lines,
                  {"units": "m", "long_name": f"amplitude of harmonic k f0 of {_dof_name(branch.dofs[0])}"}),
         "critical_multiplier_re": ("point", branch.critical.real, {"units": "1", "long_name": "Floquet multiplier of largest modulus, real part"}),
         "critical_multiplier_im": ("point", branch.critical.imag, {"units": "1", "long_name": "Floquet multiplier of largest modulus, imaginary part"}),
         "stable": ("point", _stability_flags(branch),
                    {"units": "1", "long_name": "stability of the point (-1: not computed)", "flag_values": np.array(
                        list(STABILITY_FLAGS), np.int8), "flag_meanings": " ".join(STABILITY_FLAGS.values())}),
         "f0": ("point", branch.f0, {"units": "Hz", "long_name": "base frequency"}),
         "iterations": ("point", branch.iterations, {"units": "1", "long_name": "Newton iterations of the point"})},
        coords={key: ("point", branch.values, {"units": cf_units(branch.key), "long_name": branch.key,
                                               "rotorred_key": branch.key}),
                "dof": ("dof", [_dof_name(d) for d in branch.dofs], {"units": "1", "long_name": "output DOF"}),
                "harmonic": ("harmonic", np.arange(branch.lines.shape[1]),
                             {"units": "1", "long_name": "harmonic k of f0"})},
        attrs={"scene": scene_name, "stopped": branch.stopped, "interrupted": branch.interrupt or "no",
               "folds": "; ".join(f"{v:.9g} {'fold' if s else 'corner'}" for v, s in branch.folds),
               "bifurcations": "; ".join(f"{kind} between {a:.9g} and {b:.9g}" for a, b, kind in branch.bifurcations)})


def write_branch(branch, folder, scene_name: str, provenance: Provenance | None = None) -> None:
    """Stage the branch's files in ``folder`` (:class:`rotorred.writers.OutputFolder`); a ``provenance``
    (:class:`rotorred.provenance.Provenance`, with the base scene) is written as ``scene.toml``, on top of
    ``branch.txt`` and as attributes of ``branch.nc``."""
    from rotorred.plots.branch import plot_branch  # matplotlib only when figures are written

    xs, xu = _scale(branch)
    dof = _dof_name(branch.dofs[0])
    header = [f"{branch.key} ({branch.unit})", "f0 (Hz)"] + [f"peak {_dof_name(d)} (um)" for d in branch.dofs] + \
        ["max |mu|", "stable", "iterations"]
    write_csv(folder.staged("branch.csv"), header,
              [branch.values, branch.f0, *(1e6 * branch.peaks.T), branch.multipliers,
               [STABILITY_FLAGS[f] if f < 0 else int(f) for f in _stability_flags(branch)], branch.iterations])
    write_csv(folder.staged("branch_lines.csv"), [f"{branch.key} ({branch.unit})"] +
              [f"{dof} k={k} (um)" for k in range(branch.lines.shape[1])], [branch.values, *(1e6 * branch.lines.T)])
    write_netcdf(folder.staged("branch.nc"), branch_dataset(branch, scene_name),
                 provenance.netcdf_attributes() if provenance is not None else None)
    stable = None if not branch.known.any() else np.where(branch.known, branch.stable, np.nan)
    plot_branch(branch.values, branch.peaks[:, 0], stable, branch.folds, folder.staged("branch.png"),
                xlabel=f"{branch.key} ({xu})", ylabel=f"peak |{dof}| (µm)", changes=branch.bifurcations, xscale=xs,
                title=f"{scene_name}: harmonic-balance branch"
                      + (f" (INCOMPLETE: interrupted by {branch.interrupt})" if branch.interrupted else ""))
    text = format_branch(branch)
    write_text(folder.staged("branch.txt"), (text if provenance is None else provenance.on_top(text)) + "\n")
    if provenance is not None:
        write_text(folder.staged(provenance.file_name), provenance.file_text())
