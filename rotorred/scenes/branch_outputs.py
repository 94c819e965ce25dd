"""The files of a harmonic-balance branch (``rotorred continue``): CSV, NetCDF, the figure, a summary and, given a
provenance, the base scene (``scene.toml``).

A point whose stability was not computed (``--no-stability``, or an interrupt in the stability phase) is marked
alike in each: stability "unknown" in the CSV and the summary, the NetCDF flag -1
(:data:`rotorred.nonlinear.continuation.STABILITY_FLAGS`), its multiplier NaN, and drawn grey in the
figure. An interrupted branch's summary starts with "INCOMPLETE: " and why.

A torus branch (:class:`rotorred.scenes.torus_branch.TorusBranch`) has its own tables: ``branch.csv`` a row a point
(the key, the bases, the 10 largest lines of its DOF at the start, in µm, the corrections and the point's time) and
``branch_lines.csv`` every order's line at each point (µm).
"""

from __future__ import annotations

import numpy as np

from rotorred.provenance import Provenance
from rotorred.nonlinear.continuation import STABILITY_FLAGS
from rotorred.scenes.branch import dof_name
from rotorred.scenes.torus_branch import TorusBranch
from rotorred.writers import render_table, write_csv, write_netcdf, write_text

__all__ = ["format_branch", "write_branch"]


def format_branch(branch) -> str:
    """A summary: the points, the folds, where it stopped, the stable share and the times (an interrupted branch's
    first line says so: "INCOMPLETE: interrupted (SIGINT) ...").

    Parameters
    ----------
    branch : SceneBranch or TorusBranch
        The branch (:func:`rotorred.scenes.branch.continue_scene`, :func:`rotorred.scenes.torus_branch.continue_torus`).

    Returns
    -------
    str
        A table of at most ~25 points (the key in its shown unit, peak in µm, largest multiplier modulus,
        stability; a torus's: its bases, its largest line, the corrections and the point's time), then the turns,
        stability changes, why it stopped and the times (s).
    """
    if isinstance(branch, TorusBranch):
        return _format_torus(branch)
    xs, xu = branch.shown
    dof = dof_name(branch.dofs[0])
    rows = [[f"{xs * v:.4g}", f"{1e6 * p:.3f}", "-" if np.isnan(m) else f"{m:.3f}", STABILITY_FLAGS[f]]
            for v, p, m, f in zip(branch.values, branch.peaks[:, 0], branch.multipliers, branch.flags)]
    step = max(1, len(rows) // 25)
    table = render_table([f"{branch.key} ({xu})", f"peak {dof} (µm)", "max |mu|", "stability"], rows[::step])
    folds = ", ".join(f"{xs * v:.6g} {xu} ({'fold' if smooth else 'corner'})" for v, smooth in branch.folds) or "none"
    changes = ", ".join(f"{kind} between {xs * a:.6g} and {xs * b:.6g} {xu}" for a, b, kind in branch.bifurcations)
    n = len(branch.values)
    head, tail = (f"INCOMPLETE: {branch.stopped}\n", "") if branch.interrupted else ("", f"{branch.stopped}\n")
    return (f"{head}{table}\n{n} points{f' (one in {step} shown)' if step > 1 else ''}; turns: {folds}\n"
            f"stability changes: {changes or 'none'}\n{tail}"
            f"times: cold start {branch.start_time:.2f} s, continuation {branch.solve_time:.2f} s "
            f"({1e3 * branch.solve_time / max(n - 1, 1):.0f} ms a point), stability {branch.stability_time:.2f} s")


def _format_torus(branch: TorusBranch) -> str:
    """:func:`format_branch` of a torus branch."""
    xs, xu = branch.shown
    top = branch.largest[0]
    rows = [[f"{xs * v:.5g}", f"{b[0]:.5g}, {b[1]:.5g}", f"{1e6 * a:.4f}", f"{it:d}", f"{t:.3f}"]
            for v, b, a, it, t in zip(branch.values, branch.bases_hz, branch.amplitudes[:, top], branch.iterations,
                                      branch.point_time)]
    step = max(1, len(rows) // 25)
    table = render_table([f"{branch.key} ({xu})", "f_1, f_2 (Hz)", f"line {branch.line_label(top)} (µm)",
                          "corrections", "time (s)"], rows[::step])
    folds = ", ".join(f"{xs * v:.6g} {xu} ({'fold' if smooth else 'corner'})" for v, smooth in branch.folds) or "none"
    n = len(branch.values)
    head, tail = (f"INCOMPLETE: {branch.stopped}\n", "") if branch.interrupted else ("", f"{branch.stopped}\n")
    steps, gaps = branch.point_time[1:], "".join(f"{gap}\n" for gap in branch.not_traced)
    return (f"{head}{table}\n{n} points{f' (one in {step} shown)' if step > 1 else ''}; {branch.truncation}\n"
            f"turns: {folds}\n{gaps}{tail}"
            f"times: start {branch.point_time[0]:.2f} s, then {steps.sum():.2f} s "
            f"({1e3 * steps.sum() / max(n - 1, 1):.0f} ms a point)")


def write_branch(branch, folder, provenance: Provenance | None = None) -> None:
    """Stage the branch's files in ``folder`` (:class:`rotorred.writers.OutputFolder`): the tables, ``branch.nc``
    (:meth:`SceneBranch.to_xarray <rotorred.scenes.branch.SceneBranch.to_xarray>`), ``branch.png``
    (:meth:`SceneBranch.plot <rotorred.scenes.branch.SceneBranch.plot>`) and ``branch.txt``; a ``provenance``
    (:class:`rotorred.provenance.Provenance`, with the base scene) is written as ``scene.toml``, on top of
    ``branch.txt`` and as attributes of ``branch.nc``.

    Parameters
    ----------
    branch : SceneBranch or TorusBranch
        The branch.
    folder : rotorred.writers.OutputFolder
        The open output folder; the files are staged, and written when it commits.
    provenance : Provenance, optional
        What made the branch (the command line's, with the base scene).
    """
    from rotorred.plots.axes import save_figure  # matplotlib only when figures are written

    if isinstance(branch, TorusBranch):
        _torus_tables(branch, folder)
    else:
        _tables(branch, folder)
    write_netcdf(folder.staged("branch.nc"), branch.to_xarray(),
                 provenance.netcdf_attributes() if provenance is not None else None)
    save_figure(branch.plot(), folder.staged("branch.png"))
    text = format_branch(branch)
    write_text(folder.staged("branch.txt"), (text if provenance is None else provenance.on_top(text)) + "\n")
    if provenance is not None:
        write_text(folder.staged(provenance.file_name), provenance.file_text())


def _torus_tables(branch: TorusBranch, folder) -> None:
    """``branch.csv`` and ``branch_lines.csv`` of a torus branch."""
    dof, key = dof_name(branch.dof), f"{branch.key} ({branch.unit})"
    shown = branch.largest
    write_csv(folder.staged("branch.csv"), [key, "f_1 (Hz)", "f_2 (Hz)"] +
              [f"{dof} {branch.line_label(k)} (um)" for k in shown] + ["corrections", "time (s)"],
              [branch.values, *branch.bases_hz.T, *(1e6 * branch.amplitudes[:, shown].T), branch.iterations,
               branch.point_time])
    write_csv(folder.staged("branch_lines.csv"), [key] + [f"{dof} {branch.line_label(k)} (um)"
                                                          for k in range(len(branch.orders))],
              [branch.values, *(1e6 * branch.amplitudes.T)])


def _tables(branch, folder) -> None:
    """``branch.csv`` and ``branch_lines.csv`` of a periodic branch."""
    dof = dof_name(branch.dofs[0])
    header = [f"{branch.key} ({branch.unit})", "f0 (Hz)"] + [f"peak {dof_name(d)} (um)" for d in branch.dofs] + \
        ["max |mu|", "stable", "iterations"]
    write_csv(folder.staged("branch.csv"), header,
              [branch.values, branch.f0, *(1e6 * branch.peaks.T), branch.multipliers,
               [STABILITY_FLAGS[f] if f < 0 else int(f) for f in branch.flags], branch.iterations])
    write_csv(folder.staged("branch_lines.csv"), [f"{branch.key} ({branch.unit})"] +
              [f"{dof} k={k} (um)" for k in range(branch.lines.shape[1])], [branch.values, *(1e6 * branch.lines.T)])
