"""The scene pipeline: scene -> model -> response -> spectra and lines -> files and summary.

:func:`run_scene` computes only what the scene's outputs need:

* the model is the Craig–Bampton reduced one by default (boundary: bearings, inter-shaft
  bearings, the rub nodes), or the full one;
* only the requested (node, direction) DOFs are recovered, and only inside the recorded
  window ``record_start .. duration``;
* with no rub plate there is no contact work in the loop, and a linear scene that asks for
  the settled response (``solver.start = "settled"``) gets the harmonic (steady-state)
  solution at the record times instead of time stepping; ``start = "rest"`` (the start-up)
  always steps in time;
* a transient with rub plates starts from the linear settled state (unbalance, and gravity's
  static deflection), so only the transient caused by the rub has to decay, not the
  start-up of every lightly damped mode.

Spectra (:func:`rotorred.signals.spectra.settled_spectrum`, pyFFTW with reused plans): single-sided
amplitude in metres, rectangular window over the last whole number of common periods of the
two spools (70/90 Hz: 0.1 s), where every combination ``m f_H + n f_L`` is on a bin and is
read without amplitude error; when the speeds are not commensurate the flat-top window is
used (amplitude error below 0.0045 dB) and the spectrum's ``note`` says so. Lines are the
peaks above ``output.line_threshold`` of the largest, labelled by
:func:`rotorred.signals.lines.label_lines` within half a bin.

:func:`write_outputs` writes the figures (PNG), the data (NPZ, CSV, MATLAB .mat) and
``summary.txt``; the keys and columns are listed in ``docs/scenes.md``.
"""

from __future__ import annotations

import csv
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rotorred.model.assembly import assemble
from rotorred.linear.harmonic import SteadyState, steady_state
from rotorred.signals.lines import format_table, label_lines
from rotorred.model.loads import gravity_force
from rotorred.scenes.schema import Scene
from rotorred.signals.spectra import WINDOWS, settled_spectrum

__all__ = ["SceneModel", "SceneResult", "build_model", "run_scene", "settled_state", "harmonic_outputs",
           "write_outputs", "format_summary", "spool_frequencies"]

_RPM = 60.0 / (2.0 * math.pi)


@dataclass(frozen=True)
class SceneModel:
    """The structural model of a scene.

    Attributes
    ----------
    model : SystemMatrices or ReducedSystem
    label : str
        Human description (size, boundary, modes).
    build_time : float
        Wall time of assembly and reduction (s).
    key : tuple
        What the model depends on (rotor, Rayleigh damping, solver model settings, rub nodes);
        scenes with the same key can share the model (clearance sweeps).
    """

    model: object
    label: str
    build_time: float
    key: tuple


@dataclass(frozen=True)
class SceneResult:
    """Response of a scene in its recorded window.

    Attributes
    ----------
    scene : Scene
    t : ndarray, shape (n,)
        Record times (s), ``record_start .. duration``.
    outputs : dict of (int, str) to ndarray, shape (n,)
        Displacements (m) or rotations (rad) of the recorded DOFs.
    contacts : tuple of rotorred.transient.newmark.ContactHistory
        One per rub plate (empty without plates).
    spectra : dict of (int, str) to Spectrum
        Amplitude spectrum of each recorded DOF (m).
    lines : dict of (int, str) to list of SpectralLine
        Labelled peaks of each spectrum.
    f_L, f_H : float
        Lower and higher spool frequency (Hz).
    method : {"harmonic", "transient"}
    model_label : str
    n_steps : int
        Time steps taken (0 for the harmonic solution).
    build_time, solve_time : float
        Wall time of the model and of the response (s).
    normal : SceneResult or None
        The same scene without rub plates, when ``output.compare_normal``.
    counters : dict
        Integrator counters (Newton iterations, contact steps, µs per step).
    """

    scene: Scene
    t: np.ndarray
    outputs: dict
    contacts: tuple
    spectra: dict
    lines: dict
    f_L: float
    f_H: float
    method: str
    model_label: str
    n_steps: int
    build_time: float
    solve_time: float
    normal: SceneResult | None = None
    counters: dict = field(default_factory=dict)

    def peak(self, dof) -> float:
        """Largest |displacement| of ``dof`` in the window (m)."""
        return float(np.max(np.abs(self.outputs[tuple(dof)])))

    def contact_fraction(self, plate: int = 0) -> float:
        """Fraction of the recorded samples in which plate ``plate`` touches (slip or stick)."""
        return 1.0 - self.contacts[plate].fraction("open") if self.contacts else 0.0

    def n_impacts(self, plate: int = 0) -> int:
        """Number of contact onsets (open -> slip/stick) of plate ``plate`` in the window."""
        if not self.contacts:
            return 0
        touching = self.contacts[plate].state != 0
        return int(np.count_nonzero(touching[1:] & ~touching[:-1]))

    def line_amplitude(self, dof, m: int, n) -> float:
        """Amplitude (m) of the labelled line m f_H + n f_L of ``dof``, 0 if it is not a peak."""
        for ln in self.lines[tuple(dof)]:
            if ln.known and ln.m == m and ln.n == n:
                return ln.amplitude
        return 0.0


# --------------------------------------------------------------------------- model
def spool_frequencies(scene: Scene) -> tuple[float, float]:
    """(f_L, f_H) (Hz): the lower and higher spool frequency (equal for one spool)."""
    f = sorted(w / (2 * math.pi) for w in scene.speeds.values())
    if not f or f[-1] <= 0:
        raise ValueError("the scene's spools do not turn (every speed is 0); a spectrum needs a speed")
    f_pos = [v for v in f if v > 0]
    return f_pos[0], f_pos[-1]


def _model_key(scene: Scene) -> tuple:
    s = scene.solver
    return (scene.rotor_source, tuple(scene.rotor.rayleigh), s.model, s.modes, s.cutoff_hz,
            tuple(sorted(set(s.boundary_nodes) | {p.node for p in scene.plates})))


def build_model(scene: Scene) -> SceneModel:
    """Assemble (and reduce) the scene's rotor.

    The reduced model's boundary is every bearing node, both nodes of every inter-shaft
    bearing, every rub node and ``solver.boundary_nodes``
    (:func:`rotorred.linear.reduction.reduce_rotor`).
    """
    from rotorred.linear.reduction import default_boundary_nodes, reduce_rotor

    t0 = time.perf_counter()
    system = assemble(scene.rotor)
    s = scene.solver
    if s.model == "full":
        label = f"full FE model, {system.dofs.n_dof} DOFs"
        model = system
    else:
        extra = tuple(sorted(set(s.boundary_nodes) | {p.node for p in scene.plates}))
        cutoff = None if s.cutoff_hz is None else 2 * math.pi * s.cutoff_hz
        model = reduce_rotor(scene.rotor, extra, n_modes=s.modes, cutoff=cutoff, system=system)
        label = (f"Craig-Bampton model, {model.n_dof} DOFs (boundary nodes "
                 f"{list(default_boundary_nodes(scene.rotor, extra))} + {model.n_modes} modes; "
                 f"{model.selection.describe()}) of the {system.dofs.n_dof}-DOF FE model")
    return SceneModel(model, label, time.perf_counter() - t0, _model_key(scene))


# --------------------------------------------------------------------------- harmonic solution
def _steady(scene: Scene, model) -> SteadyState | None:
    """Linear steady state of the scene's unbalances (None without unbalances)."""
    if not scene.unbalances:
        return None
    return steady_state(model, scene.unbalances, scene.speeds, scene.rotor.spool_of)


def settled_state(scene: Scene, model) -> tuple[np.ndarray, np.ndarray]:
    """Linear steady state at t = 0: (q0, v0) in model coordinates.

    Sum of the per-spool unbalance phasors (``K - Omega^2 M + i Omega (C + sum Omega_s G_s)``
    solved per spool) and gravity's static deflection.
    """
    q0 = np.zeros(model.M.shape[0])
    v0 = np.zeros_like(q0)
    steady = _steady(scene, model)
    if steady is not None:
        q0 += steady.displacement(0.0)
        v0 += steady.velocity(0.0)
    if scene.solver.gravity:
        q0 += np.linalg.solve(model.K, gravity_force(model, scene.solver.gravity))
    return q0, v0


def harmonic_outputs(scene: Scene, model, t: np.ndarray) -> dict:
    """Settled linear response of the recorded DOFs at times ``t`` (s): {(node, dir): ndarray}."""
    dofs = scene.output.dofs
    R = model.output_rows(dofs)
    y = np.zeros((len(dofs), len(t)))
    steady = _steady(scene, model)
    for s, P in (steady.phasors.items() if steady is not None else ()):
        y += np.real((R @ P)[:, None] * np.exp(1j * steady.speeds[s] * t)[None, :])
    if scene.solver.gravity:
        y += (R @ np.linalg.solve(model.K, gravity_force(model, scene.solver.gravity)))[:, None]
    return {d: y[j] for j, d in enumerate(dofs)}


# --------------------------------------------------------------------------- run
def run_scene(scene: Scene, model: SceneModel | None = None, *, compare_normal: bool | None = None,
              progress: bool | None = False) -> SceneResult:
    """Compute a scene's response, spectra and labelled lines.

    Parameters
    ----------
    scene : Scene
    model : SceneModel, optional
        A model built by :func:`build_model` for a scene with the same key (reused by sweeps).
    compare_normal : bool, optional
        Also compute the scene without rub plates (default ``scene.output.compare_normal``;
        ignored without plates).
    progress : bool or None
        Progress bar of long transients (None: after 2 s).

    Returns
    -------
    SceneResult
    """
    from rotorred.transient.newmark import simulate

    if model is None:
        model = build_model(scene)
    elif model.key != _model_key(scene):
        raise ValueError("`model` was built for a different rotor, solver model or rub nodes than `scene`")
    s = scene.solver
    f_L, f_H = spool_frequencies(scene)
    dofs = scene.output.dofs
    t0 = time.perf_counter()
    counters = {}
    if scene.is_linear and s.start == "settled":
        n = int(round((s.duration - s.record_start) / s.dt))
        t = s.record_start + s.dt * np.arange(n + 1)
        outputs = harmonic_outputs(scene, model.model, t)
        contacts, method, n_steps = (), "harmonic", 0
    else:
        q0, v0 = settled_state(scene, model.model) if s.start == "settled" else (None, None)
        kw = {"alpha": s.alpha} if s.method == "hht" else {}
        res = simulate(model.model, scene.speeds, s.duration, s.dt, unbalances=scene.unbalances,
                       plates=scene.plates, rotor=scene.rotor, outputs=dofs, record_start=s.record_start,
                       method=s.method, gravity=s.gravity or None, q0=q0, v0=v0, progress=progress, **kw)
        t, outputs, contacts, method, n_steps = res.t, res.outputs, res.contacts, "transient", res.n_steps
        counters = {"n_newton": res.n_newton, "n_contact_steps": res.n_contact_steps,
                    "n_substeps": res.n_substeps, "us_per_step": res.us_per_step}
    spectra, lines = {}, {}
    for d in dofs:
        spec = settled_spectrum(outputs[d], s.dt, f_L, f_H)
        spectra[d] = spec
        lines[d] = label_lines(spec, f_L, f_H, threshold=scene.output.line_threshold)
    solve_time = time.perf_counter() - t0
    normal = None
    if compare_normal is None:
        compare_normal = scene.output.compare_normal
    if scene.plates and compare_normal:
        normal = run_scene(scene.without_rub(), SceneModel(model.model, model.label, 0.0,
                                                           _model_key(scene.without_rub())),
                           compare_normal=False)
    return SceneResult(scene=scene, t=t, outputs=outputs, contacts=contacts, spectra=spectra, lines=lines,
                       f_L=f_L, f_H=f_H, method=method, model_label=model.label, n_steps=n_steps,
                       build_time=model.build_time, solve_time=solve_time, normal=normal, counters=counters)


# --------------------------------------------------------------------------- summary
def _dir_name(d: str) -> str:
    return {"x": "X", "y": "Y", "theta_x": "theta_x", "theta_y": "theta_y"}[d]


def table_dof(result: SceneResult) -> tuple[int, str]:
    """The DOF whose lines are tabulated: ``output.table``, else the last node's y (or first direction)."""
    out = result.scene.output
    if out.table is not None:
        return out.table
    node = out.nodes[-1] if not result.scene.plates else next(
        (n for n in reversed(out.nodes) if n != result.scene.plates[0].node), out.nodes[-1])
    return (node, "y" if "y" in out.directions else out.directions[0])


def format_summary(result: SceneResult, files: list[Path] = ()) -> str:
    """Text summary: peaks, contact, impacts, the labelled lines (paper's Table 1 form)."""
    sc, s = result.scene, result.scene.solver
    spools = ", ".join(f"{name} {w / (2 * math.pi):.6g} Hz ({w * _RPM:.0f} rpm)" for name, w in sc.speeds.items())
    lines = [f"scene {sc.name} ({sc.source}){': ' + sc.description if sc.description else ''}",
             f"rotor {sc.rotor_source}; Rayleigh damping alpha = {sc.rotor.rayleigh[0]:g} 1/s, "
             f"beta = {sc.rotor.rayleigh[1]:g} s; speeds {spools}",
             "unbalances: " + (", ".join(f"node {u.node} {u.m_e:g} kg m at {math.degrees(u.phase):g} deg"
                                         for u in sc.unbalances) or "none"),
             f"model: {result.model_label}; built in {result.build_time:.2f} s"]
    if result.method == "harmonic":
        lines.append(f"response: harmonic steady state (linear scene, settled start), {len(result.t)} samples "
                     f"of {s.dt:g} s in {s.record_start:g}-{s.duration:g} s; {result.solve_time:.2f} s")
    else:
        c = result.counters
        origin = "the settled linear state" if s.start == "settled" else "rest"
        lines.append(f"response: {s.method} time stepping from {origin}, {result.n_steps} steps of {s.dt:g} s to "
                     f"{s.duration:g} s ({c.get('us_per_step', 0):.2f} us/step, "
                     f"{c.get('n_contact_steps', 0)} contact steps, {c.get('n_substeps', 0)} half steps), recorded "
                     f"{s.record_start:g}-{s.duration:g} s; {result.solve_time:.2f} s")
    lines.append("")
    normal = result.normal
    hdr = ["DOF", "peak (um)"] + (["normal peak (um)", "change (%)"] if normal else [])
    rows = []
    for d in sc.output.dofs:
        unit_scale = 1e6
        row = [f"node {d[0]} {_dir_name(d[1])}", f"{unit_scale * result.peak(d):.4g}"]
        if normal:
            pn = normal.peak(d)
            row += [f"{unit_scale * pn:.4g}", f"{100 * (result.peak(d) - pn) / pn:+.1f}" if pn > 0 else "-"]
        rows.append(row)
    lines.append("Peak amplitudes in the recorded window" + (" (rotations in urad)" if any(
        d[1].startswith("theta") for d in sc.output.dofs) else ""))
    lines.append(_render(hdr, rows))
    lines.append("")
    duration = result.t[-1] - result.t[0] if len(result.t) > 1 else 0.0
    for k, (p, ch) in enumerate(zip(sc.plates, result.contacts)):
        lines.append(f"rub plate {k} at node {p.node} (normal at {math.degrees(p.theta):g} deg, clearance "
                     f"{1e6 * p.clearance:.4g} um): contact {100 * result.contact_fraction(k):.2f} % of the window "
                     f"(slip {100 * ch.fraction('slip'):.2f} %, stick {100 * ch.fraction('stick'):.2f} %), "
                     f"{result.n_impacts(k)} impacts ({result.n_impacts(k) / duration if duration else 0:.1f}/s), "
                     f"max normal force {ch.normal_force.max(initial=0.0):.4g} N")
    if sc.plates:
        lines.append("")
    d = table_dof(result)
    spec = result.spectra[d]
    found = result.lines[d]
    exact = spec.window == "rectangular" and "on bins" in spec.note
    error = "0 on-bin" if exact else f"<= {WINDOWS[spec.window].max_scalloping_db:.3g} dB"
    lines.append(f"Spectral lines of node {d[0]} {_dir_name(d[1])} above {100 * sc.output.line_threshold:g} % of the "
                 f"largest (f_L = {result.f_L:.6g} Hz, f_H = {result.f_H:.6g} Hz; bin {spec.df:.4g} Hz, labels "
                 f"m f_H + n f_L matched within half a bin; "
                 f"{spec.window} window, amplitude error "
                 f"{error}):")
    lines.append(format_table(found, ascii=True, amplitude_scale=1e6, amplitude_unit="um"))
    known = [ln for ln in found if ln.known]
    combos = [ln for ln in known if ln.m not in (0, 1) or ln.n not in (0, 1) or (ln.m == 1 and ln.n == 1)]
    lines.append(f"{len(found)} lines, {len(known)} labelled, {len(combos)} besides f_L and f_H; spectrum: {spec.note}")
    others = [x for x in sc.output.dofs if x != d]
    if others:
        lines.append("other DOFs: " + "; ".join(
            f"node {x[0]} {_dir_name(x[1])}: {len(result.lines[x])} lines "
            f"({', '.join(ln.label_ascii for ln in result.lines[x][:6])}{', ...' if len(result.lines[x]) > 6 else ''})"
            for x in others))
    if files:
        lines.append("")
        lines += [f"wrote {f}" for f in files]
    return "\n".join(lines)


def _render(header, rows) -> str:
    widths = [max([len(h)] + [len(r[i]) for r in rows]) for i, h in enumerate(header)]
    out = [" | ".join(h.ljust(w) for h, w in zip(header, widths)).rstrip(), "-|-".join("-" * w for w in widths)]
    out += [" | ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    return "\n".join(out)


# --------------------------------------------------------------------------- files
def _key(case: str, d) -> str:
    return f"{case}_{d[0]}_{d[1]}"


def data_arrays(result: SceneResult) -> dict[str, np.ndarray]:
    """The arrays written to NPZ and .mat (keys documented in ``docs/scenes.md``)."""
    case = "rub" if result.scene.plates else "response"
    arrays = {"t": result.t, "f_L": np.array(result.f_L), "f_H": np.array(result.f_H)}
    first = next(iter(result.spectra.values()))
    arrays["frequency"] = first.frequencies
    for r, c in ((result, case), (result.normal, "normal")):
        if r is None:
            continue
        for d in r.scene.output.dofs:
            arrays[_key(c, d)] = r.outputs[d]
            arrays[_key(f"{c}_amp", d)] = r.spectra[d].amplitudes
    for k, ch in enumerate(result.contacts):
        arrays[f"plate{k}_normal_force"] = ch.normal_force
        arrays[f"plate{k}_friction_force"] = ch.friction_force
        arrays[f"plate{k}_state"] = ch.state.astype(np.int8)
        arrays[f"plate{k}_gap"] = ch.gap
    return arrays


def _write_csv(path: Path, header: list[str], columns: list[np.ndarray]) -> Path:
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for row in zip(*columns):
            w.writerow([f"{v:.9g}" if isinstance(v, (float, np.floating)) else v for v in row])
    return path


def _write_csvs(result: SceneResult, out: Path) -> list[Path]:
    case = "rub" if result.scene.plates else "response"
    dofs = result.scene.output.dofs

    def unit(d):
        return "urad" if d[1].startswith("theta") else "um"
    header, cols = ["t (s)"], [result.t]
    for r, c in ((result, case), (result.normal, "normal")):
        if r is not None:
            for d in dofs:
                header.append(f"{c} node {d[0]} {d[1]} ({unit(d)})")
                cols.append(1e6 * r.outputs[d])
    for k, ch in enumerate(result.contacts):
        header += [f"plate {k} normal force (N)", f"plate {k} friction force (N)", f"plate {k} state",
                   f"plate {k} gap (um)"]
        cols += [ch.normal_force, ch.friction_force, ch.state.astype(int), 1e6 * ch.gap]
    files = [_write_csv(out / "timeseries.csv", header, cols)]
    first = result.spectra[dofs[0]]
    header, cols = ["frequency (Hz)"], [first.frequencies]
    for r, c in ((result, case), (result.normal, "normal")):
        if r is not None:
            for d in dofs:
                header.append(f"{c} node {d[0]} {d[1]} amplitude ({unit(d)})")
                cols.append(1e6 * r.spectra[d].amplitudes)
    files.append(_write_csv(out / "spectra.csv", header, cols))
    rows = [[d[0], d[1], ln.frequency_hz, 1e6 * ln.amplitude, "" if ln.m is None else ln.m,
             "" if ln.n is None else str(ln.n), ln.label_ascii] for d in dofs for ln in result.lines[d]]
    files.append(_write_csv(out / "lines.csv", ["node", "direction", "frequency (Hz)", "amplitude (um or urad)",
                                                "m (multiple of f_H)", "n (multiple of f_L)", "label"],
                            list(zip(*rows)) if rows else [[]] * 7))
    return files


def _plots(result: SceneResult, out: Path) -> list[Path]:
    from rotorred.plots.scene import plot_orbits, plot_spectra, plot_waveforms

    sc = result.scene
    plots = sc.output.plots
    case = "rub" if sc.plates else "response"
    pairs = [("normal", result.normal), (case, result)] if result.normal is not None else [(case, result)]
    files = []
    rub_text = "; ".join(f"rub at node {p.node} ({math.degrees(p.theta):g} deg, clearance {1e6 * p.clearance:.3g} um)"
                         for p in sc.plates) or "no rub"
    speeds = ", ".join(f"{w / (2 * math.pi):.4g} Hz" for w in sc.speeds.values())
    translational = [d for d in sc.output.directions if d in ("x", "y")]
    if "waveforms" in plots:
        window = sc.output.plot_window or (result.t[0], min(result.t[-1], result.t[0] + 0.14))
        signals = {f"node {n} {_dir_name(d)}": {label: r.outputs[(n, d)] for label, r in pairs}
                   for n in sc.output.nodes for d in sc.output.directions}
        files.append(plot_waveforms(result.t, signals, out / "waveforms.png", t_window=window,
                                    title=f"{sc.name}: time waveforms ({speeds}; {rub_text})",
                                    unit="µm" if translational else "µrad"))
    if "spectra" in plots:
        f_max = sc.output.f_max_hz
        for n in sc.output.nodes:
            spectra, lines = {}, {}
            for d in sc.output.directions:
                panel = f"node {n} {_dir_name(d)}"
                spectra[panel] = {f"{label} {_dir_name(d)}": r.spectra[(n, d)] for label, r in pairs}
                lines[f"{case} {_dir_name(d)}"] = result.lines[(n, d)]
            if f_max is None:
                known = [ln.frequency_hz for ls in lines.values() for ln in ls if ln.known]
                f_max_n = max(1.1 * max(known, default=0.0), 3.0 * result.f_H)
            else:
                f_max_n = f_max
            files.append(plot_spectra(spectra, out / f"spectra_node{n}.png", lines=lines, f_max=f_max_n,
                                      title=f"{sc.name}: amplitude spectra at node {n} ({rub_text})"))
    if "orbits" in plots and {"x", "y"} <= set(sc.output.directions):
        orbits = {}
        for n in sc.output.nodes:
            title = f"node {n} ({sc.rotor.spool_of[n]})"
            for p in sc.plates:
                if p.node == n:
                    title += f", plate at {math.degrees(p.theta):g} deg"
            orbits[title] = {label: (r.outputs[(n, "x")], r.outputs[(n, "y")]) for label, r in pairs}
        files.append(plot_orbits(orbits, out / "orbits.png",
                                 title=f"{sc.name}: orbits over the recorded window ({rub_text})"))
    return files


def write_outputs(result: SceneResult, out: str | Path) -> list[Path]:
    """Write figures, data files and ``summary.txt`` into ``out``; returns the paths written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    files = _plots(result, out)
    formats = result.scene.output.formats
    arrays = data_arrays(result)
    if "npz" in formats:
        np.savez(out / "result.npz", **arrays)
        files.append(out / "result.npz")
    if "mat" in formats:
        from scipy.io import savemat
        savemat(out / "result.mat", arrays, do_compression=True)
        files.append(out / "result.mat")
    if "csv" in formats:
        files += _write_csvs(result, out)
    summary = out / "summary.txt"
    files.append(summary)
    summary.write_text(format_summary(result, files) + "\n")
    return files
