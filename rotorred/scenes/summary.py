"""The text summary of a scene's result: set-up, peaks, rub contact and the labelled lines (Table 1 form)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from rotorred.model.dofs import direction_name
from rotorred.scenes.run import SceneResult
from rotorred.scenes.run import table_dof as _scene_table_dof
from rotorred.signals.lines import format_table
from rotorred.signals.spectra import WINDOWS
from rotorred.writers import render_table

__all__ = ["format_summary", "table_dof"]

_RPM = 60.0 / (2.0 * math.pi)


def table_dof(result) -> tuple[int, str]:
    """The DOF whose lines are tabulated: ``output.table``, else the last node's y (or first direction).

    ``result`` is a :class:`SceneResult` or a :class:`rotorred.scenes.schema.Scene`.
    """
    return _scene_table_dof(getattr(result, "scene", result))


def format_summary(result: SceneResult, files: list[Path] = ()) -> str:
    """Text summary: set-up, peaks, contact, impacts, the labelled lines (paper's Table 1 form); an incomplete result's
    first line says so (:meth:`rotorred.provenance.Provenance.on_top` keeps it first under the provenance).

    Parameters
    ----------
    result : SceneResult
        The scene's run (:func:`rotorred.scenes.run.run_scene`).
    files : list of Path
        Files written, listed at the end.

    Returns
    -------
    str
        Blocks separated by blank lines; peaks in µm, speeds in rpm and Hz, line frequencies in Hz.
    """
    parts = [_incomplete(result), _setup(result), _peaks(result), range_warnings(result),
             _contacts(result), _torus_lines(result), _lines(result) if result.spectra else "", _line_fit(result)]
    if files:
        parts.append("\n".join(f"wrote {f}" for f in files))
    return "\n\n".join(p for p in parts if p)


#: the small-displacement range of the model: a translation beyond this fraction of the largest disk
#: radius of the rotor (1.25 mm for the seed rig's 0.125 m disks) leaves the linear beam model
SMALL_DISPLACEMENT_FRACTION = 0.01
#: the radius used when the rotor's disks give none (m)
DEFAULT_RADIUS = 0.1


def _incomplete(result: SceneResult) -> str:
    if not result.incomplete:
        return ""
    return (f"INCOMPLETE: {result.incomplete}. The record below ends there: peaks and contact over the partial "
            f"record; no figures, spectra or lines.")


def small_displacement_limit(scene) -> float:
    """Largest translation (m) inside the model's small-displacement range (:data:`SMALL_DISPLACEMENT_FRACTION`)."""
    radii = [d.radius for d in scene.rotor.disks if getattr(d, "radius", 0.0) > 0]
    return SMALL_DISPLACEMENT_FRACTION * (max(radii) if radii else DEFAULT_RADIUS)


def range_warnings(result) -> str:
    """A warning per node whose orbit (or translation) leaves the small-displacement range (a steady run's or a
    run-up's ``result``: its ``scene`` and ``outputs``)."""
    limit = small_displacement_limit(result.scene)
    lines = []
    for node in dict.fromkeys(d[0] for d in result.scene.output.dofs):
        x, y = result.outputs.get((node, "x")), result.outputs.get((node, "y"))
        parts = [v for v in (x, y) if v is not None and len(v)]
        if not parts:
            continue
        reach = float(np.max(np.hypot(x, y))) if x is not None and y is not None and len(x) else max(
            float(np.max(np.abs(v))) for v in parts)
        if reach > limit:
            lines.append(f"WARNING: node {node} orbits {1e3 * reach:.4g} mm from the axis, beyond the model's "
                         f"small-displacement range of {1e3 * limit:.4g} mm ({100 * SMALL_DISPLACEMENT_FRACTION:g} % "
                         f"of the largest disk radius): a linear beam model does not hold there")
    return "\n".join(lines)


def _setup(result: SceneResult) -> str:
    sc, s = result.scene, result.scene.solver
    spools = ", ".join(f"{name} {w / (2 * math.pi):.6g} Hz ({w * _RPM:.0f} rpm)" for name, w in sc.speeds.items())
    lines = [f"scene {sc.name} ({sc.source}){': ' + sc.description if sc.description else ''}",
             f"rotor {sc.rotor_source}; Rayleigh damping alpha = {sc.rotor.rayleigh[0]:g} 1/s, "
             f"beta = {sc.rotor.rayleigh[1]:g} s; speeds {spools}",
             "unbalances: " + (", ".join(f"node {u.node} {u.m_e:g} kg m at {math.degrees(u.phase):g} deg"
                                         for u in sc.unbalances) or "none"),
             f"model: {result.model_label}; built in {result.build_time:.2f} s"]
    if result.settings is not None:
        lines[3:3] = result.settings.describe()
    if result.method == "harmonic":
        lines.append(f"response: harmonic steady state (linear scene, settled start), {len(result.t)} samples "
                     f"of {s.dt:g} s in {s.record_start:g}-{s.duration:g} s; {result.solve_time:.2f} s")
    elif result.method == "harmonic-balance" and "torus" in result.counters:
        lines += torus_setup(result)
    elif result.method == "harmonic-balance":
        c = result.counters
        if c.get("choice") is not None:
            lines.append(c["choice"].describe())
        lines.append(f"response: harmonic balance, {c['harmonics']} harmonics of f0 = {c['f0']:g} Hz and "
                     f"{c['samples']} AFT samples a period ({c['start']}), at "
                     f"{len(result.t)} samples of {s.dt:g} s in {s.record_start:g}-{s.duration:g} s; "
                     f"{result.solve_time:.2f} s")
    else:
        c = result.counters
        origin = "the settled linear state" if s.start == "settled" else "rest"
        lines.append(f"response: {s.method} time stepping from {origin}, {result.n_steps} steps of {s.dt:g} s to "
                     f"{s.duration:g} s ({c.get('us_per_step', 0):.2f} us/step, "
                     f"{c.get('n_contact_steps', 0)} contact steps, {c.get('n_substeps', 0)} half steps), recorded "
                     f"{s.record_start:g}-{s.duration:g} s; {result.solve_time:.2f} s")
        if c.get("kernel_compiled"):  # a compilation, not numba's cache
            lines.append(f"step kernel compiled in {c['kernel_load_time']:.1f} s (once per install; not in the "
                         "us/step; cached on disk)")
    return "\n".join(lines)


def torus_setup(result: SceneResult) -> list[str]:
    """The lines of a torus's response (a harmonic balance at incommensurate speeds): its bases named in the spools'
    frequencies, its truncation (orders, grid, unknowns), Newton's convergence, what a tolerance chose, the record."""
    from rotorred.scenes.torus_response import describe_torus

    s, torus = result.scene.solver, result.counters["torus"]
    sol = torus.solution
    shape, truncation = describe_torus(torus, result.f_L, result.f_H)
    lines = [f"response: harmonic balance on a {shape}: the speeds share no period of at most 10 s",
             f"truncation: {truncation}"]
    if torus.truncation is not None:
        lines.append(torus.truncation.describe())
    lines.append(f"{sol.iterations} Newton iterations ({sum(sol.krylov)} GMRES), relative residual "
                 f"{sol.residual:.3g}; started from {torus.start}; recorded at {len(result.t)} samples of {s.dt:g} s "
                 f"in {s.record_start:g}-{s.duration:g} s; {result.solve_time:.2f} s")
    return lines


#: lines of the table DOF listed from a torus's series
N_TORUS_LINES = 10


def _torus_lines(result: SceneResult) -> str:
    """The table DOF's :data:`N_TORUS_LINES` largest lines of a torus's series (exact: its coefficients, not a fit)."""
    torus = result.counters.get("torus") if result.method == "harmonic-balance" else None
    d = table_dof(result)
    if torus is None or d not in torus.outputs:
        return ""
    from rotorred.scenes.torus_response import base_labels, order_label, spool_bases

    names, bases = base_labels(torus, result.f_L, result.f_H), spool_bases(torus, result.f_L, result.f_H)
    scale, unit = 1e6, ("urad" if d[1].startswith("theta") else "um")
    a = torus.amplitudes[:, torus.outputs.index(d)]
    rows = [[f"{torus.frequencies[k]:.6g}", f"({torus.orders[k, 0]}, {torus.orders[k, 1]})",
             order_label(torus.orders[k], bases), f"{scale * a[k]:.6g}"] for k in np.argsort(-a)[:N_TORUS_LINES]]
    return (f"Torus lines of node {d[0]} {direction_name(d[1])} (the {min(N_TORUS_LINES, len(a))} largest of the "
            f"harmonic balance's {len(a)} orders k1 {names[0]} + k2 {names[1]}):\n"
            + render_table(["frequency (Hz)", "order (k1, k2)", "line", f"amplitude ({unit})"], rows))


def _peaks(result: SceneResult) -> str:
    sc, normal = result.scene, result.normal
    header = ["DOF", "peak (um)"] + (["normal peak (um)", "change (%)"] if normal else [])
    rows = []
    for d in sc.output.dofs:
        row = [f"node {d[0]} {direction_name(d[1])}", f"{1e6 * result.peak(d):.4g}"]
        if normal:
            pn = normal.peak(d)
            row += [f"{1e6 * pn:.4g}", f"{100 * (result.peak(d) - pn) / pn:+.1f}" if pn > 0 else "-"]
        rows.append(row)
    rotations = any(d[1].startswith("theta") for d in sc.output.dofs)
    title = "Peak amplitudes in the recorded window" + (" (rotations in urad)" if rotations else "")
    return title + "\n" + render_table(header, rows)


def _contacts(result: SceneResult) -> str:
    duration = result.t[-1] - result.t[0] if len(result.t) > 1 else 0.0
    lines = []
    for k, (p, ch) in enumerate(zip(result.scene.plates, result.contacts)):
        impacts = result.n_impacts(k)
        lines.append(f"rub plate {k} at node {p.node} (normal at {math.degrees(p.theta):g} deg, clearance "
                     f"{1e6 * p.clearance:.4g} um): contact {100 * result.contact_fraction(k):.2f} % of the window "
                     f"(slip {100 * ch.fraction('slip'):.2f} %, stick {100 * ch.fraction('stick'):.2f} %), "
                     f"{impacts} impacts ({impacts / duration if duration else 0:.1f}/s), "
                     f"max normal force {ch.normal_force.max(initial=0.0):.4g} N")
    return "\n".join(lines)


def _lines(result: SceneResult) -> str:
    sc = result.scene
    d = table_dof(result)
    spec, fit = result.spectra[d], result.lines[d]
    exact = spec.window == "rectangular" and "on bins" in spec.note
    error = "0 on-bin" if exact else f"<= {WINDOWS[spec.window].max_scalloping_db:.3g} dB"
    combos = [ln for ln in fit.lines if ln.m not in (0, 1) or ln.n not in (0, 1) or (ln.m == 1 and ln.n == 1)]
    lines = [f"Spectral lines of node {d[0]} {direction_name(d[1])} above {100 * sc.output.line_threshold:g} % of "
             f"the largest (f_L = {result.f_L:.6g} Hz, f_H = {result.f_H:.6g} Hz; bin {spec.df:.4g} Hz, peaks "
             f"labelled m f_H + n f_L within half a bin and fitted by least squares; {spec.window} window, "
             f"spectrum amplitude error {error}):",
             format_table(fit, amplitude_scale=1e6, amplitude_unit="um"),
             f"{len(fit.lines) + len(fit.unlabelled)} lines, {len(fit.lines)} labelled, {len(combos)} besides f_L "
             f"and f_H; spectrum: {spec.note}"]
    others = [x for x in sc.output.dofs if x != d]
    if others:
        lines.append("other DOFs: " + "; ".join(
            f"node {x[0]} {direction_name(x[1])}: {len(result.lines[x].lines)} lines "
            f"({', '.join(ln.label for ln in result.lines[x].lines[:6])}"
            f"{', ...' if len(result.lines[x].lines) > 6 else ''})"
            for x in others))
    return "\n".join(lines)


#: residual peaks listed in the summary
N_UNLABELLED_SHOWN = 5
#: lines listed in the summary: those with at least 0.1 % of the energy (all are in linefit.csv)
SHARE_SHOWN = 1e-3


def _line_fit(result: SceneResult) -> str:
    """The issue-19 block: torus, explained share, lines kept, class, settling, unlabelled residual peaks."""
    d = table_dof(result)
    name = f"node {d[0]} {direction_name(d[1])}"
    if d in result.analysis_errors:
        return f"Line fit of {name}: not computed: {result.analysis_errors[d]}"
    a = result.analyses.get(d)
    if a is None:
        return ""
    fit, st, cls = a.fit, a.settling, a.classification
    rot = d[1].startswith("theta")
    scale, unit = 1e6, ("urad" if rot else "um")
    tried = ", ".join(f"k={tr.k} j={tr.j}: {tr.n_lines} lines, {tr.explained_share:.6f}" for tr in fit.trials)
    kind = cls.label + (f", period {cls.period:.6g} s" if cls.period is not None else "")
    if cls.kind == "period-k":
        kind += f" (k = {cls.subharmonic})"
    settled = (st.reason if st.settled else
               f"not settled by {result.t[-1]:.4g} s: " + st.reason.removeprefix("not settled: "))
    shown = [ln for ln in fit.lines if ln.share >= SHARE_SHOWN]
    rows = [[f"{ln.frequency_hz:.6g}", "; ".join(ln.labels), f"{scale * ln.amplitude:.4g}", f"{ln.phase:+.4f}",
             f"{scale * ln.standard_error:.2g}", f"{ln.share:.4g}"] for ln in shown]
    peaks = "; ".join(f"{p.frequency_hz:.5g} Hz {scale * p.amplitude:.3g} {unit}"
                      for p in fit.unlabelled[:N_UNLABELLED_SHOWN]) or "none above the floor"
    lines = [f"Line fit of {name} (least squares at (m/k) f_H + (n/j) f_L on the time record, "
             f"{fit.n_samples} samples from {fit.t0:.6g} s, {fit.duration:.4g} s; lines closer than "
             f"{fit.resolution_hz:.4g} Hz merged; {a.time:.2f} s):",
             f"torus found: {fit.torus.label} (tried {tried})",
             f"explained share (1 - residual/signal energy): {fit.explained_share:.6f}; {fit.n_significant} "
             f"significant lines, {len(fit.lines)} kept; residual rms {scale * fit.noise_rms:.3g} {unit}",
             render_table(["frequency (Hz)", "label(s)", f"amplitude ({unit})", "phase (rad)", f"SE ({unit})",
                           "share"], rows) if rows else "(no line with 0.1 % of the energy)",
             f"({len(fit.lines) - len(shown)} lines with less than {SHARE_SHOWN:.1%} of the energy each, "
             f"{sum(ln.share for ln in fit.lines if ln.share < SHARE_SHOWN):.2g} together: see linefit.csv)"
             if len(shown) < len(fit.lines) else "",
             f"class: {kind} ({cls.rules[-1]})",
             f"settling: {settled}" + _record_advice(result, st),
             f"unlabelled residual peaks (strongest first): {peaks}"]
    return "\n".join(line for line in lines if line)


def _record_advice(result: SceneResult, settling) -> str:
    """What recorded window would let the settling be measured, when the record is shorter than two windows."""
    record = result.t[-1] - result.t[0] if result.t.size else 0.0
    if settling.settled or not settling.window < math.inf or record >= 2 * settling.window:
        return ""
    return (f"\n  a recorded window of at least {2 * settling.window:.3g} s (solver.duration - solver.record_start, "
            f"now {record:.3g} s) holds the two {settling.window:.3g} s windows settling compares")
