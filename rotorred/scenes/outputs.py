"""The files of a scene's result: figures (PNG), data (NPZ, CSV, MATLAB .mat), ``summary.txt`` and, given a
provenance, ``scene.toml``.

Keys, columns and variables are documented in ``docs/scenes.md``. Every file goes through the
one writer of its format (:mod:`rotorred.writers`); figures come from
:func:`rotorred.plots.scene.plot_scene`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rotorred.progress import stage
from rotorred.provenance import Provenance
from rotorred.scenes.run import SceneResult
from rotorred.scenes.summary import format_summary
from rotorred.signals.lines import UNLABELLED
from rotorred.writers import write_csv, write_mat, write_npz, write_text

__all__ = ["data_arrays", "write_data", "write_outputs", "submit_figures", "LINEFIT_HEADER", "POINCARE_HEADER"]

#: columns of ``linefit.csv`` (docs/scenes.md)
LINEFIT_HEADER = ["frequency (Hz)", "label", "labels", "m", "n", "k", "j", "amplitude (um)", "phase (rad)",
                  "amplitude SE (um)", "share"]
#: columns of ``poincare.csv``
POINCARE_HEADER = ["t (s)", "x (um)", "velocity (um/s)"]


def _key(case: str, d) -> str:
    return f"{case}_{d[0]}_{d[1]}"


def _cases(result: SceneResult) -> list[tuple[SceneResult, str]]:
    """(result, name) of the run and of its no-rub companion: ("rub" or "response", "normal")."""
    case = "rub" if result.scene.plates else "response"
    return [(r, c) for r, c in ((result, case), (result.normal, "normal")) if r is not None]


def _unit(d) -> str:
    return "urad" if d[1].startswith("theta") else "um"


def data_arrays(result: SceneResult) -> dict[str, np.ndarray]:
    """The arrays written to NPZ and .mat (keys documented in ``docs/scenes.md``)."""
    arrays = {"t": result.t, "f_L": np.array(result.f_L), "f_H": np.array(result.f_H)}
    if result.spectra:
        arrays["frequency"] = next(iter(result.spectra.values())).frequencies
    for r, c in _cases(result):
        for d in r.scene.output.dofs:
            arrays[_key(c, d)] = r.outputs[d]
            if d in r.spectra:
                arrays[_key(f"{c}_amp", d)] = r.spectra[d].amplitudes
    a = result.analysis
    if a is not None:
        p = a.classification.poincare
        arrays.update({"poincare_frequency": np.array(p.frequency_hz), "poincare_t": p.times, "poincare_x": p.x,
                       "poincare_velocity": p.velocity,
                       "poincare_dof": np.array(f"{a.dof[0]}:{a.dof[1]}")})
    for k, ch in enumerate(result.contacts):
        arrays[f"plate{k}_normal_force"] = ch.normal_force
        arrays[f"plate{k}_friction_force"] = ch.friction_force
        arrays[f"plate{k}_state"] = ch.state.astype(np.int8)
        arrays[f"plate{k}_gap"] = ch.gap
    return arrays


def _timeseries_csv(result: SceneResult, path: Path) -> Path:
    header, cols = ["t (s)"], [result.t]
    for r, c in _cases(result):
        for d in result.scene.output.dofs:
            header.append(f"{c} node {d[0]} {d[1]} ({_unit(d)})")
            cols.append(1e6 * r.outputs[d])
    for k, ch in enumerate(result.contacts):
        header += [f"plate {k} normal force (N)", f"plate {k} friction force (N)", f"plate {k} state",
                   f"plate {k} gap (um)"]
        cols += [ch.normal_force, ch.friction_force, ch.state.astype(int), 1e6 * ch.gap]
    return write_csv(path, header, cols)


def _spectra_csv(result: SceneResult, path: Path) -> Path:
    dofs = result.scene.output.dofs
    header, cols = ["frequency (Hz)"], [result.spectra[dofs[0]].frequencies]
    for r, c in _cases(result):
        for d in dofs:
            header.append(f"{c} node {d[0]} {d[1]} amplitude ({_unit(d)})")
            cols.append(1e6 * r.spectra[d].amplitudes)
    return write_csv(path, header, cols)


def _lines_csv(result: SceneResult, path: Path) -> Path:
    """The lines at every DOF's spectral peaks, then the peaks at no line (label ``unlabelled``)."""
    rows = []
    for d in result.scene.output.dofs:
        fit = result.lines[d]
        rows += [[d[0], d[1], ln.frequency_hz, 1e6 * ln.amplitude, str(ln.m), str(ln.n), ln.label]
                 for ln in fit.lines]
        rows += [[d[0], d[1], p.frequency_hz, 1e6 * p.amplitude, "", "", UNLABELLED] for p in fit.unlabelled]
    header = ["node", "direction", "frequency (Hz)", "amplitude (um or urad)", "m (multiple of f_H)",
              "n (multiple of f_L)", "label"]
    return write_csv(path, header, list(zip(*rows)) if rows else [[]] * len(header))


def _linefit_csv(result: SceneResult, path: Path) -> Path:
    """Fitted lines of the table DOF, then its residual's strongest peaks (label ``unlabelled``)."""
    a = result.analysis
    fit, k, j = a.fit, a.fit.torus.k, a.fit.torus.j
    rows = [[ln.frequency_hz, ln.label, ";".join(ln.labels), str(ln.m), str(ln.n), k, j, 1e6 * ln.amplitude,
             ln.phase, 1e6 * ln.standard_error, ln.share] for ln in fit.lines]
    rows += [[p.frequency_hz, UNLABELLED, "", "", "", "", "", 1e6 * p.amplitude, "", "", ""] for p in fit.unlabelled]
    cols = list(zip(*rows)) if rows else [[]] * len(LINEFIT_HEADER)
    return write_csv(path, LINEFIT_HEADER, cols, digits=17)


def _torus_csv(result: SceneResult, path: Path) -> Path:
    """Every order's line of a torus (a harmonic balance at incommensurate speeds) at every recorded DOF, by frequency:
    its order, label, and each DOF's amplitude and phase (of ``a cos(2 pi f t + phase)``, t the run's time)."""
    from rotorred.scenes.torus_response import order_label, spool_bases

    torus = result.counters["torus"]
    bases = spool_bases(torus, result.f_L, result.f_H)
    by_frequency = np.argsort(torus.frequencies, kind="stable")
    header = ["frequency (Hz)", "k1", "k2", "label"]
    cols = [torus.frequencies[by_frequency], torus.orders[by_frequency, 0], torus.orders[by_frequency, 1],
            [order_label(torus.orders[k], bases) for k in by_frequency]]
    signed = torus.problem.problem.harmonics.frequencies(torus.bases_hz)[by_frequency, None]
    phasors = np.where(signed < 0, np.conj(torus.phasors[by_frequency]), torus.phasors[by_frequency])  # at +|f|
    for j, d in enumerate(torus.outputs):
        header += [f"node {d[0]} {d[1]} amplitude ({_unit(d)})", f"node {d[0]} {d[1]} phase (rad)"]
        cols += [1e6 * np.abs(phasors[:, j]), np.angle(phasors[:, j])]
    return write_csv(path, header, cols, digits=17)


def _poincare_csv(result: SceneResult, path: Path) -> Path:
    p = result.analysis.classification.poincare
    return write_csv(path, POINCARE_HEADER, [p.times, 1e6 * p.x, 1e6 * p.velocity], digits=17)


def write_data(result: SceneResult, out: str | Path, provenance: Provenance | None = None) -> list[Path]:
    """Write the data files the scene's ``output.formats`` asks for, the NPZ and .mat with the ``provenance``'s
    attributes; returns their paths."""
    out = Path(out)
    formats = result.scene.output.formats
    files = []
    arrays = data_arrays(result) if {"npz", "mat"} & set(formats) else {}
    attributes = provenance.attributes() if provenance is not None else None
    if "npz" in formats:
        files.append(write_npz(out / "result.npz", arrays, attributes))
    if "mat" in formats:
        files.append(write_mat(out / "result.mat", arrays, attributes))
    if "csv" in formats:
        files.append(_timeseries_csv(result, out / "timeseries.csv"))
        if result.spectra:
            files += [_spectra_csv(result, out / "spectra.csv"), _lines_csv(result, out / "lines.csv")]
        if "torus" in result.counters:
            files.append(_torus_csv(result, out / "torus.csv"))
        if result.analysis is not None:
            files += [_linefit_csv(result, out / "linefit.csv"), _poincare_csv(result, out / "poincare.csv")]
    return files


def submit_figures(result: SceneResult, out: str | Path, pool, which: str = "all") -> list:
    """The scene's figures as :class:`rotorred.plots.pool.Drawing` s, none for a scene without plots or an incomplete
    result.

    Parameters
    ----------
    result : SceneResult
        The scene's result.
    out : str or Path
        Folder the figures are written to.
    pool : rotorred.plots.pool.FigurePool or None
        Draws the figures; None: drawn now, here.
    which : {"all", "record", "analysis"}
        "all"; "record", those drawn from the record alone (:func:`rotorred.plots.scene.record_figures`: from
        ``run_scene``'s ``on_record``, while the analysis runs); or "analysis", the others.

    Returns
    -------
    list of Drawing
        Each one's ``result()`` is the path of its PNG.
    """
    from rotorred.plots import scene as figures  # matplotlib only when figures are written
    from rotorred.plots.pool import FigurePool

    if not result.scene.output.plots or result.incomplete:
        return []
    make = {"all": figures.scene_figures, "record": figures.record_figures,
            "analysis": figures.analysis_figures}[which]
    if pool is None:
        pool = FigurePool(workers=0)
    return [pool.submit(job) for job in make(result, Path(out))]


def write_outputs(result: SceneResult, out: str | Path, shown: str | Path | None = None, pool=None,
                  drawing: list | None = None, provenance: Provenance | None = None) -> list[Path]:
    """Write figures, data files and ``summary.txt`` into ``out`` (with ``provenance``, ``scene.toml`` too); returns
    the paths written.

    An incomplete result (a diverged transient, ``result.incomplete``) gets its data files and
    the summary, which says why it stops; no figures or spectra (the record is not settled).

    Parameters
    ----------
    result : SceneResult
    out : str or Path
        Folder the files are written to (created if missing).
    shown : str or Path, optional
        Folder the summary names the files in (the final folder when ``out`` is a staging folder,
        :class:`rotorred.writers.OutputFolder`); default ``out``.
    pool : rotorred.plots.pool.FigurePool, optional
        Draws the figures while the data files are written (default: one after the other, here).
    drawing : list of Drawing, optional
        The record's figures, submitted already (:func:`submit_figures` with "record"): only the others are.
    provenance : rotorred.provenance.Provenance, optional
        What made the result (the command line's): its resolved scene written as ``scene.toml``, its header lines on
        top of ``summary.txt``, its attributes in ``result.npz`` and ``result.mat``.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stage("writing the figures, data and summary into %s", shown if shown is not None else out)
    if drawing is None:
        figures = submit_figures(result, out, pool)
    else:
        figures = list(drawing) + submit_figures(result, out, pool, "analysis")
    data = write_data(result, out, provenance)
    files = [f.result() for f in figures] + data
    if provenance is not None:
        files.append(write_text(out / provenance.file_name, provenance.file_text()))
    summary = out / "summary.txt"
    files.append(summary)
    named = [Path(shown) / f.name for f in files] if shown is not None else files
    text = format_summary(result, named)
    write_text(summary, (text if provenance is None else provenance.on_top(text)) + "\n")
    return named
