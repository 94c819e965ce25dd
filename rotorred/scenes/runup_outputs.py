"""The files of a run-up's result: figures, data (NPZ, .mat, CSV) and ``summary.txt``.

Columns and keys are documented in ``docs/scenes.md`` ("Run-ups"). Every file goes through the
one writer of its format (:mod:`rotorred.writers`); figures come from
:func:`rotorred.plots.runup.plot_runup`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from rotorred.progress import stage
from rotorred.provenance import Provenance
from rotorred.scenes.runup import RUB_GAP_REVS, RunupResult
from rotorred.scenes.summary import range_warnings
from rotorred.writers import render_table, write_csv, write_mat, write_npz, write_text

__all__ = ["write_runup_outputs", "format_runup_summary", "runup_arrays"]

HZ = 1.0 / (2 * math.pi)


def runup_arrays(result: RunupResult) -> dict[str, np.ndarray]:
    """The record written to NPZ and .mat: ``t``, ``speed_<spool>`` (Hz), ``<node>_<dir>`` (m or rad), contacts."""
    arrays = {"t": result.t}
    for s, w in result.speeds.items():
        arrays[f"speed_{s}"] = w * HZ
    for (node, d), y in result.outputs.items():
        arrays[f"node{node}_{d}"] = y
    for k, ch in enumerate(result.contacts):
        arrays[f"plate{k}_normal_force"] = ch.normal_force
        arrays[f"plate{k}_friction_force"] = ch.friction_force
        arrays[f"plate{k}_state"] = ch.state.astype(np.int8)
    return arrays


def _amplitude_csv(result: RunupResult, path: Path) -> Path:
    """Per block of the reference spool: its speed (Hz, rpm) and each node's largest orbit radius (µm)."""
    nodes = sorted(result.overall)
    speed = result.overall[nodes[0]][0]
    header = [f"{result.reference} speed (Hz)", f"{result.reference} speed (rpm)"] + \
             [f"node {n} orbit radius (um)" for n in nodes]
    return write_csv(path, header, [speed * HZ, 60 * speed * HZ] + [1e6 * result.overall[n][1] for n in nodes])


def _tracks_csv(result: RunupResult, path: Path) -> Path:
    """One row per track and block: spool, order, DOF, time, the spool's speed, amplitude and phase."""
    cols = [[], [], [], [], [], [], [], []]
    for track, dof in zip(result.tracks, result.track_dofs):
        n = len(track.t)
        cols[0] += [track.spool] * n
        cols[1] += [track.order] * n
        cols[2] += [f"{dof[0]}:{dof[1]}"] * n
        cols[3] += list(track.t)
        cols[4] += list(track.speed * HZ)
        cols[5] += list(60 * track.speed * HZ)
        cols[6] += list(1e6 * track.amplitude)  # um, or urad for a rotation
        cols[7] += list(np.degrees(track.phase))
    header = ["spool", "order", "dof", "t (s)", "spool speed (Hz)", "spool speed (rpm)", "amplitude (um or urad)",
              "phase (deg)"]
    return write_csv(path, header, cols)


def _rubs_csv(result: RunupResult, path: Path) -> Path:
    spools = list(result.speeds)
    header = ["plate", "node", "t start (s)", "t end (s)"] + [f"{s} at start (Hz)" for s in spools] + \
             [f"{s} at end (Hz)" for s in spools] + ["impacts"]
    rows = [[r.plate, r.node, r.t_start, r.t_end, *[r.speed_start[s] for s in spools],
             *[r.speed_end[s] for s in spools], r.impacts] for r in result.rubs]
    return write_csv(path, header, list(map(list, zip(*rows))) if rows else [[] for _ in header])


def _criticals_csv(result: RunupResult, path: Path) -> Path:
    """The critical speeds in the swept range as ``rotorred campbell`` writes them, through the same writer
    (:meth:`rotorred.linear.campbell.CampbellResult.critical_speeds_to_csv`): with the margin to the rotor's operating
    speed of the reference spool and the API 684 columns of :attr:`RunupResult.margins`."""
    nominal = result.scene.rotor.speeds.get(result.reference, 0.0)
    return result.campbell.critical_speeds_to_csv(path, nominal if nominal > 0 else None, result.margins)


def write_runup_outputs(result: RunupResult, out: str | Path, shown: str | Path | None = None,
                        provenance: Provenance | None = None) -> list[Path]:
    """Write figures, data and ``summary.txt`` into ``out``; returns the paths (named in ``shown``).

    Parameters
    ----------
    result : RunupResult
        The run-up (:func:`rotorred.scenes.runup.run_runup`).
    out : str or Path
        Folder the files are written to (created if missing).
    shown : str or Path, optional
        Folder the summary names the files in (the final folder when ``out`` is a staging folder,
        :class:`rotorred.writers.OutputFolder`); default ``out``.
    provenance : rotorred.provenance.Provenance, optional
        What made the result: written as ``scene.toml``, on top of the summary and as attributes of the NPZ and .mat.

    Returns
    -------
    list of Path
        The files, in ``shown``.
    """
    from rotorred.plots.runup import plot_runup  # matplotlib only when figures are written

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stage("writing the figures, data and summary into %s", shown if shown is not None else out)
    formats = result.scene.output.formats
    files = plot_runup(result, out) if result.scene.output.plots else []
    arrays = runup_arrays(result)
    attributes = provenance.attributes() if provenance is not None else None
    if "npz" in formats:
        files.append(write_npz(out / "result.npz", arrays, attributes))
    if "mat" in formats:
        files.append(write_mat(out / "result.mat", arrays, attributes))
    if "csv" in formats:
        keys = list(arrays)
        files.append(write_csv(out / "timeseries.csv", keys, [arrays[k] for k in keys]))
        if result.overall:
            files.append(_amplitude_csv(result, out / "runup_amplitude.csv"))
        if result.tracks:
            files.append(_tracks_csv(result, out / "order_tracks.csv"))
        files.append(_rubs_csv(result, out / "rub_intervals.csv"))
        files.append(_criticals_csv(result, out / "critical_speeds.csv"))
    if provenance is not None:
        files.append(write_text(out / provenance.file_name, provenance.file_text()))
    summary = out / "summary.txt"
    files.append(summary)
    named = [Path(shown) / f.name for f in files] if shown is not None else files
    text = format_runup_summary(result, named)
    write_text(summary, (text if provenance is None else provenance.on_top(text)) + "\n")
    return named


def format_runup_summary(result: RunupResult, files=()) -> str:
    """What the run-up shows: setup, peaks against speed, critical speeds, rub intervals, cost, files.

    Parameters
    ----------
    result : RunupResult
        The run-up.
    files : sequence of Path
        The files written, listed last; default none.

    Returns
    -------
    str
        Lines of text: speeds in Hz and rpm, amplitudes in µm, times in s.
    """
    ref, sc = result.reference, result.scene
    c = result.counters
    speeds = " / ".join(f"{s} {w[0] * HZ:.1f} -> {w[-1] * HZ:.1f} Hz" for s, w in result.speeds.items())
    lines = [f"scene {sc.name}: {sc.description}",
             f"run-up: {speeds} in {result.t[-1]:.3g} s; {result.model_label}",
             f"steps: {result.n_steps} of {sc.solver.dt:g} s, {c['us_per_step']:.2f} us/step, "
             f"{c['n_passes'] / max(result.n_steps, 1):.2f} passes/step, {c['n_factorizations']} step matrices "
             f"(speed intervals x step sizes); solve {result.solve_time:.2f} s, analysis {result.analysis_time:.2f} s"]
    if result.incomplete:
        lines.append(f"INCOMPLETE: {result.incomplete}")
    if result.overall:
        rows = []
        for node, (speed, radius) in sorted(result.overall.items()):
            if not len(radius):  # a record shorter than two revolutions (an early divergence or interrupt)
                continue
            k = int(np.argmax(radius))
            rows.append([str(node), f"{1e6 * radius[k]:.2f}", f"{speed[k] * HZ:.2f}", f"{60 * speed[k] * HZ:.0f}"])
        lines += ["", f"largest orbit radius against {ref} speed:",
                  render_table(["node", "radius (um)", f"at {ref} (Hz)", "(rpm)"], rows)]
    warned = range_warnings(result)  # as a steady run's summary
    if warned:
        lines += ["", warned]
    if result.tracks:
        rows = []
        for track, dof in zip(result.tracks, result.track_dofs):
            if track.order != 1.0 or dof[1] != "y" or not len(track.amplitude):
                continue
            k = int(np.argmax(track.amplitude))
            rows.append([f"1x {track.spool}", f"{dof[0]}:{dof[1]}", f"{1e6 * track.amplitude[k]:.2f}",
                         f"{track.speed[k] * HZ:.2f}"])
        lines += ["", "1x order peaks (y):", render_table(["order", "dof", "peak (um)", "at its spool (Hz)"], rows)]
    if result.critical_speeds:
        rows = [[f"{cs.speed * HZ:.2f}", f"{60 * cs.speed * HZ:.0f}", f"1x {cs.spool}", cs.whirl, f"{cs.log_dec:.3f}"]
                for cs in result.critical_speeds]
        ratio = ", ".join(f"{s} {r:.4g}" for s, r in result.campbell_ratio.items())
        lines += ["", f"critical speeds in the swept range (Campbell at speed ratios {ratio}):",
                  render_table([f"{ref} (Hz)", "(rpm)", "line", "whirl", "log dec"], rows)]
    if sc.plates:
        if result.rubs:
            rows = [[str(r.plate), str(r.node), f"{r.t_start:.3f}", f"{r.t_end:.3f}", f"{r.speed_start[ref]:.2f}",
                     f"{r.speed_end[ref]:.2f}", str(r.impacts)] for r in result.rubs]
            lines += ["", f"rub intervals (contact at least every {RUB_GAP_REVS} revolutions of {ref}):",
                      render_table(["plate", "node", "from (s)", "to (s)", f"onset {ref} (Hz)", f"end {ref} (Hz)",
                                    "impacts"], rows)]
        else:
            lines += ["", "no contact during the run-up"]
    if files:
        lines += ["", "files: " + ", ".join(str(f) for f in files)]
    return "\n".join(lines)
