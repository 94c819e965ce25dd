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
used (amplitude error below 0.0045 dB) and the spectrum's ``note`` says so. The lines of each DOF
are those at the spectrum's peaks above ``output.line_threshold`` of the largest, labelled and
fitted by least squares on the spectrum's samples (:func:`rotorred.signals.linefit.fit_peaks`).

Line fit, settling and class of the table DOF (:func:`table_dof`): the lines
``(m/k) f_H + (n/j) f_L`` are fitted by least squares (:func:`rotorred.signals.linefit.fit_lines`,
torus found by the fit) on the same samples as the spectrum (the last whole common periods when
the speeds are commensurate, where the fitted amplitudes equal the rectangular FFT's on-bin values;
otherwise the whole record); the settling (:func:`rotorred.signals.settling.settling_time`) and the
class (:func:`rotorred.signals.classify.classify`, Poincare samples) use the whole recorded window
and the torus the fit found, so the search runs once (:class:`LineAnalysis`).

The summary is :mod:`rotorred.scenes.summary`; the files (figures, NPZ, CSV, .mat, summary)
are written by :func:`rotorred.scenes.outputs.write_outputs`.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from rotorred.model.assembly import assemble
from rotorred.progress import stage
from rotorred.results import Result
from rotorred.scenes.schema import Scene
from rotorred.scenes.settled import settled_response, settled_state
from rotorred.signals.classify import Classification, classify
from rotorred.signals.linefit import FitOptions, LineFit, fit_lines, fit_peaks
from rotorred.signals.settling import Settling, settling_time
from rotorred.signals.spectra import settled_spectrum

__all__ = ["SceneModel", "SceneResult", "LineAnalysis", "analyse_lines", "fit_and_settling", "Response", "respond",
           "table_dof", "SceneDiverged", "explain_divergence", "build_model", "model_key", "run_scene",
           "harmonic_outputs", "spool_frequencies"]

LOG = logging.getLogger(__name__)


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
class LineAnalysis:
    """Line fit, measured settling and class of one recorded DOF.

    Attributes
    ----------
    dof : (int, str)
    fit : LineFit
        Least-squares line fit on the spectrum's samples (the commensurate record when there is one).
    settling : Settling
        Of the whole recorded window, lines tracked on the fit's torus.
    classification : Classification
        Of the whole recorded window (with ``settling``), Poincare samples included.
    time : float
        Wall time of the three (s).
    """

    dof: tuple
    fit: LineFit
    settling: Settling
    classification: Classification
    time: float


@dataclass(frozen=True, repr=False)
class SceneResult(Result):
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
    lines : dict of (int, str) to LineFit
        The lines at each spectrum's peaks (:func:`rotorred.signals.linefit.fit_peaks`).
    f_L, f_H : float
        Lower and higher spool frequency (Hz).
    method : {"harmonic", "transient", "harmonic-balance"}
    model_label : str
    n_steps : int
        Time steps taken (0 for the harmonic solution).
    build_time, solve_time : float
        Wall time of the model and of the response (s).
    normal : SceneResult or None
        The same scene without rub plates, when ``output.compare_normal``.
    counters : dict
        Integrator counters (Newton iterations, contact steps, µs per step); a harmonic balance's truncation and
        start, or at incommensurate speeds its torus (``"torus"``: :class:`rotorred.scenes.quasi_periodic.RubTorus`).
    incomplete : str or None
        Why the record stops early (a diverged transient, :class:`SceneDiverged`); None when complete.
        An incomplete result has no spectra, lines or normal comparison.
    analyses : dict of (int, str) to LineAnalysis
        Line fit, settling and class of the table DOF (:func:`table_dof`); empty for an incomplete
        result and for the normal comparison.
    analysis_errors : dict of (int, str) to str
        Why a DOF has no analysis (e.g. a record too short to fit), one line each.
    final : rotorred.transient.results.FinalState or None
        State at the end of a transient (model coordinates), the start of a continuation; None
        for the harmonic solution.
    settings : rotorred.scenes.tolerance.Settings or None
        What ``solver.tolerance`` chose and why (``scene`` is then the scene as run); None without a tolerance.
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
    incomplete: str | None = None
    analyses: dict = field(default_factory=dict)
    analysis_errors: dict = field(default_factory=dict)
    final: object = None
    settings: object = None

    @property
    def analysis(self) -> LineAnalysis | None:
        """The :class:`LineAnalysis` of the table DOF, None when there is none."""
        return self.analyses.get(table_dof(self.scene))

    def peak(self, dof) -> float:
        """Largest ``|displacement|`` of ``dof`` in the window; 0 for an empty (diverged) record.

        Parameters
        ----------
        dof : (int, str)
            (node, direction) of a recorded DOF, e.g. ``(18, "y")``.

        Returns
        -------
        float
            (m; rad for a rotation).
        """
        return float(np.max(np.abs(self.outputs[tuple(dof)]), initial=0.0))

    def contact_fraction(self, plate: int = 0) -> float:
        """Fraction of the recorded samples in which plate ``plate`` touches (slip or stick); 0 without plates.

        Parameters
        ----------
        plate : int
            Position of the plate among the scene's rub plates.

        Returns
        -------
        float
            0 to 1 (-).
        """
        return 1.0 - self.contacts[plate].fraction("open") if self.contacts else 0.0

    def n_impacts(self, plate: int = 0) -> int:
        """Number of contact onsets (open -> slip/stick) of plate ``plate`` in the window; 0 without plates.

        Parameters
        ----------
        plate : int
            Position of the plate among the scene's rub plates.

        Returns
        -------
        int
        """
        return self.contacts[plate].n_impacts() if self.contacts else 0

    def line_amplitude(self, dof, m, n) -> float:
        """Amplitude of the line ``m f_H + n f_L`` of ``dof`` (its first label), 0 if it is not at a peak.

        Parameters
        ----------
        dof : (int, str)
            (node, direction) of a recorded DOF of a complete result (:attr:`lines`).
        m, n : int
            The multiples of f_H and f_L.

        Returns
        -------
        float
            (m; rad for a rotation).
        """
        for ln in self.lines[tuple(dof)].lines:
            if ln.m == m and ln.n == n:
                return ln.amplitude
        return 0.0

    def summary(self) -> list[str]:
        """The scene, how it was solved, the table DOF's class and strongest lines, the peaks, the contacts."""
        from rotorred.transient.results import contact_line, peak_lines, shorten

        sc, d = self.scene, table_dof(self.scene)
        span = f"{len(self.t)} records, t = {self.t[0]:.6g}-{self.t[-1]:.6g} s" if len(self.t) else "no record"
        lines = [shorten(f"scene {sc.name}: {sc.description}"),
                 shorten(f"{self.method} response at f_L = {self.f_L:.6g} Hz, f_H = {self.f_H:.6g} Hz; {span}; "
                         f"{self.n_steps} steps"),
                 self.model_label.split(" (")[0]]  # its boundary nodes are a list
        if "torus" in self.counters:
            from rotorred.scenes.torus_response import describe_torus

            shape, truncation = describe_torus(self.counters["torus"], self.f_L, self.f_H)
            lines += [shorten(f"on a {shape}"), shorten(truncation)]
        if self.incomplete:
            lines.append(shorten(f"INCOMPLETE: {self.incomplete}"))
        if d in self.lines:
            strongest = sorted(self.lines[d].lines, key=lambda ln: -ln.amplitude)[:4]
            unit = "µrad" if d[1].startswith("t") else "µm"
            cls = f"{self.analysis.classification.label}; " if self.analysis is not None else ""
            lines.append(shorten(f"node {d[0]} {d[1]}: {cls}lines " + ", ".join(
                f"{ln.label} {1e6 * ln.amplitude:.4g} {unit}" for ln in strongest)))
        lines += peak_lines(self.outputs)
        lines += [contact_line(k, ch) for k, ch in enumerate(self.contacts[:2])]
        if self.normal is not None:
            lines.append(f"without the rub: node {d[0]} {d[1]} peak {1e6 * self.normal.peak(d):.4g} "
                         f"{'µrad' if d[1].startswith('t') else 'µm'}")
        lines.append(f"model built in {self.build_time:.3g} s, solved in {self.solve_time:.3g} s")
        return lines

    def plot(self, ax=None, kind: str = "waveforms", **options):
        """Draw one of the scene's figures as ``rotorred run`` writes it (:func:`rotorred.plots.scene.draw_scene`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw every panel's series into; default a new figure.
        kind : {"waveforms", "spectra", "orbits", "poincare"}
            "waveforms" (default, every recorded DOF against time (µm, µrad), the normal run overlaid), "spectra"
            (of one node, ``node=``, default the first, with the labelled lines; Hz), "orbits" (x and y recorded) or
            "poincare" (the table DOF's Poincare section).
        **options
            ``node`` (int, for "spectra"), and the drawing's options: ``t_window`` ((float, float), s), ``f_max``
            (Hz), ``log_y``, ``title``, ...

        Returns
        -------
        matplotlib.figure.Figure

        Raises
        ------
        InputError
            If ``kind`` is unknown or has no data in this result, or ``node`` is not a recorded node.
        """
        from rotorred.plots.scene import draw_scene

        return draw_scene(self, kind, ax, **options)

    def to_xarray(self):
        """The result as an :class:`xarray.Dataset`.

        The record (:func:`rotorred.transient.results.record_dataset`: dimensions ``time``, ``output`` (labels
        ``"13:x"``), ``plate``; ``displacement`` in m, contact forces and states), the normal run's record
        ``normal_displacement`` (time, output) at the same record times, the spectra ``amplitude`` and
        ``normal_amplitude`` (frequency, output) in m with ``frequency`` in Hz, the lines at each spectrum's
        peaks (dimension ``line``: ``line_output``, ``line_frequency`` (Hz), ``line_amplitude`` (m),
        ``line_label``), and the table DOF's analysis: its fitted lines (dimension ``fit_line``: ``fit_frequency``,
        ``fit_amplitude``, ``fit_phase``, ``fit_standard_error``, ``fit_label``) and Poincare samples (dimension
        ``poincare``: ``poincare_time``, ``poincare_x``, ``poincare_velocity``). Rotations (rad) go into the same
        variables prefixed ``rotation_`` with dimensions ``rotation_output`` and ``rotation_line``. Scalars ``f_L``
        and ``f_H`` in Hz; the scene, method, model and table DOF as attributes.
        """
        from rotorred.transient.results import dof_groups, record_dataset

        d = table_dof(self.scene)
        ds = record_dataset(self.t, self.outputs, self.contacts, {
            "title": f"scene {self.scene.name}", "scene": self.scene.name, "method": self.method,
            "model": self.model_label, "n_steps": int(self.n_steps), "table_dof": f"{d[0]}:{d[1]}",
            "incomplete": self.incomplete or ""})
        data = {"f_L": ((), self.f_L, {"units": "Hz", "long_name": "lower spool frequency"}),
                "f_H": ((), self.f_H, {"units": "Hz", "long_name": "higher spool frequency"})}
        coords = {}
        if self.spectra:
            coords["frequency"] = ("frequency", next(iter(self.spectra.values())).frequencies,
                                   {"units": "Hz", "long_name": "bin frequency"})
        for prefix, units, dofs in dof_groups(list(self.outputs)):
            output = f"{prefix}output"
            if self.normal is not None:
                data[f"normal_{'rotation' if prefix else 'displacement'}"] = (
                    ("time", output), np.array([self.normal.outputs[o] for o in dofs]).T,
                    {"units": units, "long_name": "the same scene without the rub, at the same record times"})
            for case, r in (("", self), ("normal_", self.normal)):
                if r is not None and r.spectra:
                    data[f"{case}{prefix}amplitude"] = (("frequency", output), np.array(
                        [r.spectra[o].amplitudes for o in dofs]).T, {"units": units, "long_name": (
                            f"amplitude spectrum{' without the rub' if case else ''}: peak amplitude of each bin")})
            lines = [(o, ln) for o in dofs if o in self.lines for ln in self.lines[o].lines]
            if lines:
                data.update(self._line_variables(f"{prefix}line", lines, units))
        a = self.analysis
        if a is not None:
            units = "rad" if d[1].startswith("t") else "m"
            fit = a.fit.lines
            if fit:
                data.update({
                    "fit_frequency": ("fit_line", [ln.frequency_hz for ln in fit], {"units": "Hz", "long_name": (
                        f"frequency of the line fitted to {d[0]}:{d[1]}")}),
                    "fit_amplitude": ("fit_line", [ln.amplitude for ln in fit], {"units": units, "long_name": (
                        "amplitude of the fitted line")}),
                    "fit_phase": ("fit_line", [ln.phase for ln in fit], {"units": "rad", "long_name": (
                        "phase of the fitted line")}),
                    "fit_standard_error": ("fit_line", [ln.standard_error for ln in fit], {"units": units, (
                        "long_name"): "standard error of the amplitude"}),
                    "fit_label": ("fit_line", np.array([ln.label for ln in fit], dtype=object), {"units": "1", (
                        "long_name"): "line m f_H + n f_L"})})
            p = a.classification.poincare
            if p.x.size:
                data.update({
                    "poincare_time": ("poincare", p.times, {"units": "s", "long_name": "Poincare sample time"}),
                    "poincare_x": ("poincare", p.x, {"units": units, "long_name": f"{d[0]}:{d[1]} at the samples"}),
                    "poincare_velocity": ("poincare", p.velocity, {"units": f"{units}/s", "long_name": (
                        "velocity at the samples")}),
                    "poincare_frequency": ((), p.frequency_hz, {"units": "Hz", "long_name": "sampling frequency"})})
            ds.attrs["classification"] = a.classification.label
        return ds.assign_coords(coords).assign(data)

    @staticmethod
    def _line_variables(dim: str, lines: list, units: str) -> dict:
        """The variables of the lines at the spectra's peaks, ``[(dof, FittedLine), ...]``, along ``dim``."""
        return {f"{dim}_output": (dim, np.array([f"{o[0]}:{o[1]}" for o, _ in lines], dtype=object),
                                  {"units": "1", "long_name": "recorded DOF of the line"}),
                f"{dim}_frequency": (dim, [ln.frequency_hz for _, ln in lines], {"units": "Hz", "long_name": (
                    "frequency of the line")}),
                f"{dim}_amplitude": (dim, [ln.amplitude for _, ln in lines], {"units": units, "long_name": (
                    "amplitude of the line, fitted on the spectrum's samples")}),
                f"{dim}_label": (dim, np.array([ln.label for _, ln in lines], dtype=object), {"units": "1", (
                    "long_name"): "line m f_H + n f_L"})}


# --------------------------------------------------------------------------- model
def table_dof(scene: Scene) -> tuple[int, str]:
    """The DOF whose lines are tabulated: ``output.table``, else the last non-rub node's y (or first direction)."""
    out = scene.output
    if out.table is not None:
        return out.table
    node = out.nodes[-1] if not scene.plates else next(
        (n for n in reversed(out.nodes) if n != scene.plates[0].node), out.nodes[-1])
    return (node, "y" if "y" in out.directions else out.directions[0])


def spool_frequencies(scene: Scene) -> tuple[float, float]:
    """(f_L, f_H) (Hz): the lower and higher spool frequency (equal for one spool)."""
    f = sorted(w / (2 * math.pi) for w in scene.speeds.values())
    if not f or f[-1] <= 0:
        raise ValueError("the scene's spools do not turn (every speed is 0); a spectrum needs a speed")
    f_pos = [v for v in f if v > 0]
    return f_pos[0], f_pos[-1]


def model_key(scene: Scene) -> tuple:
    """What the structural model of ``scene`` depends on; scenes with equal keys share one model."""
    s = scene.solver
    return (scene.rotor_source, tuple(scene.rotor.rayleigh), s.model, s.modes, s.cutoff_hz,
            tuple(sorted(set(s.boundary_nodes) | {p.node for p in scene.plates})))


def build_model(scene: Scene) -> SceneModel:
    """Assemble (and reduce) the scene's rotor.

    The reduced model's boundary is every bearing node, both nodes of every inter-shaft
    bearing, every rub node and ``solver.boundary_nodes``
    (:func:`rotorred.linear.reduction.reduce_rotor`). With ``solver.modes = "auto"`` (and no cutoff) the
    mode count is the fewest whose receptance from the unbalance and rub DOFs to the recorded DOFs is within
    :data:`rotorred.scenes.modes.AUTO_TARGET` of the full model's (:func:`rotorred.scenes.modes.choose_modes`;
    an unbalance node may join the boundary, or the full model be used).

    Parameters
    ----------
    scene : Scene
        The scene; its ``solver`` says full or reduced, and the modes (``modes``, ``cutoff_hz`` (Hz)).

    Returns
    -------
    SceneModel
        The model, its label and its build time (s).
    """
    from rotorred.linear.reduction import reduce_rotor
    from rotorred.scenes.modes import AUTO_TARGET, choose_modes

    t0 = time.perf_counter()
    stage("building the model of %s (%s)", scene.name, scene.solver.model, logger=LOG)
    system = assemble(scene.rotor)
    s = scene.solver
    if s.model == "full":
        label = f"full FE model, {system.dofs.n_dof} DOFs"
        model = system
    elif s.modes is None and s.cutoff_hz is None:  # "auto": for the scene's outputs and forces
        choice = choose_modes(scene, system, AUTO_TARGET)
        model = choice.model
        if choice.full:
            label = f"full FE model, {system.dofs.n_dof} DOFs ({choice.describe()})"
        else:
            extra = tuple(sorted(set(s.boundary_nodes) | {p.node for p in scene.plates} | set(choice.extra_nodes)))
            label = _reduced_label(scene, model, extra, choice.describe(), system)
    else:
        extra = tuple(sorted(set(s.boundary_nodes) | {p.node for p in scene.plates}))
        cutoff = None if s.cutoff_hz is None else 2 * math.pi * s.cutoff_hz
        model = reduce_rotor(scene.rotor, extra, n_modes=s.modes, cutoff=cutoff, system=system)
        label = _reduced_label(scene, model, extra, model.selection.describe(), system)
    LOG.debug("%s: %s, built in %.2f s", scene.name, label, time.perf_counter() - t0)
    return SceneModel(model, label, time.perf_counter() - t0, model_key(scene))


def _reduced_label(scene: Scene, model, extra: tuple, how: str, system) -> str:
    from rotorred.linear.reduction import default_boundary_nodes

    return (f"Craig-Bampton model, {model.n_dof} DOFs (boundary nodes "
            f"{list(default_boundary_nodes(scene.rotor, extra))} + {model.n_modes} modes; {how}) of the "
            f"{system.dofs.n_dof}-DOF FE model")


# --------------------------------------------------------------------------- harmonic solution
def harmonic_outputs(scene: Scene, model, t: np.ndarray) -> dict:
    """Settled linear response of the recorded DOFs at times ``t`` (s): {(node, dir): ndarray}."""
    dofs = scene.output.dofs
    y = settled_response(scene, model, model.output_rows(dofs), t)
    return {d: y[j] for j, d in enumerate(dofs)}


# --------------------------------------------------------------------------- run
def run_scene(scene: Scene, model: SceneModel | None = None, *, compare_normal: bool | None = None,
              progress: bool | None = False, analyse: bool = True, initial=None, settings=None,
              on_record=None) -> SceneResult:
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
    analyse : bool
        Line fit, settling and class of the table DOF (:func:`analyse_lines`; not counted in
        ``solve_time``).
    initial : rotorred.transient.results.FinalState, optional
        Continue from another run's ``final`` state (model coordinates, the plates' states and
        contact forces) in place of ``solver.start``; the transient is then always stepped.
    settings : rotorred.scenes.tolerance.Settings, optional
        What ``solver.tolerance`` chose for ``scene`` (kept in the result for the summary;
        :func:`rotorred.scenes.tolerance.run_to_tolerance` chooses and runs).
    on_record : callable, optional
        ``on_record(result)`` once the record, its spectra and lines and the normal run are done, before the
        analysis: ``result`` is the SceneResult without ``analyses`` (its figures can be drawn meanwhile).

    Returns
    -------
    SceneResult

    Raises
    ------
    ValueError
        If ``model`` was built for a different rotor, solver model or rub nodes than ``scene``, or no spool turns.
    SceneDiverged
        If the transient diverges; its ``partial`` holds the record up to then.
    """
    if model is None:
        model = build_model(scene)
    elif model.key != model_key(scene):
        raise ValueError("`model` was built for a different rotor, solver model or rub nodes than `scene`")
    f_L, f_H = spool_frequencies(scene)
    t0 = time.perf_counter()
    response = respond(scene, model, initial, progress)
    spectra, lines = _spectra_and_lines(scene, response.t, response.outputs, f_L, f_H)
    solve_time = time.perf_counter() - t0
    if compare_normal is None:
        compare_normal = scene.output.compare_normal
    normal = None
    if scene.plates and compare_normal:
        without = scene.without_rub()
        normal = run_scene(without, SceneModel(model.model, model.label, 0.0, model_key(without)),
                           compare_normal=False, analyse=False)
    result = SceneResult(scene=scene, t=response.t, outputs=response.outputs, contacts=response.contacts,
                         spectra=spectra, lines=lines, f_L=f_L, f_H=f_H, method=response.method,
                         model_label=model.label, n_steps=response.n_steps, build_time=model.build_time,
                         solve_time=solve_time, normal=normal, counters=response.counters, analyses={},
                         analysis_errors={}, final=response.final, settings=settings)
    if on_record is not None:
        on_record(result)
    if not analyse:
        return result
    d = table_dof(scene)
    stage("analysing %s: line fit, settling and class of node %d %s", scene.name, *d, logger=LOG)
    try:
        analyses = {d: analyse_lines(response.t, response.outputs[d], f_L, f_H, spectra[d].n_samples, d)}
    except ValueError as exc:  # a record too short to fit (checks' one-line message)
        return replace(result, analysis_errors={d: str(exc)})
    return replace(result, analyses=analyses)


def analyse_lines(t: np.ndarray, x: np.ndarray, f_L: float, f_H: float, n_fit: int | None = None,
                  dof: tuple = (), settled: tuple | None = None) -> LineAnalysis:
    """Line fit of the last ``n_fit`` samples, then settling and class of the whole record on its torus.

    Parameters
    ----------
    t, x : ndarray, shape (n,)
        Record times (s) and response (m or rad).
    f_L, f_H : float
        Spool frequencies (Hz).
    n_fit : int, optional
        Samples fitted, from the end (the spectrum's ``n_samples``); default all.
    dof : (int, str)
        Recorded with the result.
    settled : (LineFit, Settling), optional
        :func:`fit_and_settling` of this record, when already computed.
    """
    t0 = time.perf_counter()
    fit, settling = settled or fit_and_settling(t, x, f_L, f_H, n_fit)
    cls = classify(t, x, f_L, f_H, settling=settling, options=FitOptions(torus=(fit.torus.k, fit.torus.j)))
    return LineAnalysis(tuple(dof), fit, settling, cls, time.perf_counter() - t0)


def fit_and_settling(t: np.ndarray, x: np.ndarray, f_L: float, f_H: float,
                     n_fit: int | None = None) -> tuple[LineFit, Settling]:
    """The first two steps of :func:`analyse_lines`: the line fit of the last ``n_fit`` samples and the
    settling of the whole record, which tracks that fit's lines (its torus is found once)."""
    n = len(t) if n_fit is None else min(int(n_fit), len(t))
    fit = fit_lines(t[-n:], x[-n:], f_L, f_H)
    return fit, settling_time(t, x, f_L, f_H, reference=fit)


@dataclass(frozen=True)
class Response:
    """A scene's response in its recorded window, before any spectrum (:func:`respond`).

    Attributes
    ----------
    t : ndarray, shape (n,)
        Record times (s).
    outputs : dict of (int, str) to ndarray, shape (n,)
        Recorded DOFs (m or rad).
    contacts : tuple of ContactHistory
    method : {"harmonic", "transient", "harmonic-balance"}
    n_steps : int
    counters : dict
        As :attr:`SceneResult.counters`.
    final : FinalState or None
        End state of a transient (None for the harmonic solution).
    """

    t: np.ndarray
    outputs: dict
    contacts: tuple
    method: str
    n_steps: int
    counters: dict
    final: object = None


def respond(scene: Scene, model: SceneModel, initial=None, progress: bool | None = False) -> Response:
    """The response in the recorded window: harmonic for a linear scene started settled, by harmonic balance (periodic,
    or on a torus at incommensurate speeds) with ``solver.method = "harmonic-balance"``, else stepped in time.

    ``initial`` (a FinalState) continues another run (:func:`run_scene`). Raises
    :class:`SceneDiverged`, carrying the partial result, when the transient diverges.
    """
    balance = scene.solver.method == "harmonic-balance"
    if scene.is_linear and (scene.solver.start == "settled" or balance) and initial is None:
        return _harmonic_response(scene, model.model)
    if balance:
        return _balance_response(scene, model.model) if _periodic(scene) else _torus_response(scene, model.model)
    f_L, f_H = spool_frequencies(scene)
    return _transient_response(scene, model, progress, f_L, f_H, initial)


def _harmonic_response(scene: Scene, model) -> Response:
    """The settled linear response at the record times (no time stepping)."""
    t = _record_times(scene)
    stage("solving %s: the settled harmonic response at %d record times", scene.name, len(t), logger=LOG)
    return Response(t, harmonic_outputs(scene, model, t), (), "harmonic", 0, {})


def _record_times(scene: Scene) -> np.ndarray:
    """The record times ``record_start .. duration`` at the scene's step (s)."""
    s = scene.solver
    n = int(round((s.duration - s.record_start) / s.dt))
    return s.record_start + s.dt * np.arange(n + 1)


def _periodic(scene: Scene) -> bool:
    """Whether the scene's speeds have a periodic response (:func:`rotorred.scenes.harmonic_balance.common_frequency`)."""
    from rotorred.scenes.harmonic_balance import common_frequency

    return common_frequency(tuple(scene.frequencies_hz.values())) is not None


def _balance_response(scene: Scene, model) -> Response:
    """The periodic rub response by harmonic balance (``solver.method = "harmonic-balance"``) at the record times, as a
    transient's record: Newton from a short transient's last period (:func:`start_record`), else a cold start up
    through coarser truncations (:func:`rotorred.scenes.balance_harmonics.cold_solution`), or the harmonics chosen by
    ``solver.tolerance``."""
    from rotorred.scenes.balance_harmonics import LADDER_START, balance_to_tolerance, cold_solution

    s, t = scene.solver, _record_times(scene)
    stage("solving %s by harmonic balance: a short transient to start from, then Newton", scene.name, logger=LOG)
    record = start_record(scene, model)
    if s.tolerance is not None:
        rp, z, choice = balance_to_tolerance(scene, model, s.tolerance, scene.output.dofs, record=record)
        start = LADDER_START
    else:
        (rp, z, start), choice = cold_solution(scene, model, s.harmonics, s.samples, record=record), None
    outputs, contacts = rp.record(z, t, scene.output.dofs)
    counters = {"f0": rp.f0, "harmonics": rp.problem.harmonics.H, "samples": rp.problem.harmonics.N,
                "choice": choice, "start": start}
    return Response(t, outputs, contacts, "harmonic-balance", 0, counters)


def _torus_response(scene: Scene, model) -> Response:
    """The quasi-periodic rub response by harmonic balance on a torus (``solver.method = "harmonic-balance"`` at
    incommensurate speeds, :mod:`rotorred.scenes.torus_response`) at the record times, as a transient's record; the
    torus (:class:`rotorred.scenes.quasi_periodic.RubTorus`) is the counters' ``"torus"``."""
    from rotorred.scenes.torus_response import solve_scene_torus, torus_record

    t = _record_times(scene)
    stage("solving %s by harmonic balance on a torus (the speeds share no period of at most 10 s): a short transient "
          "to find its bases and start from, then Newton-Krylov", scene.name, logger=LOG)
    torus = solve_scene_torus(scene, model)
    outputs, contacts = torus_record(torus, t, scene.output.dofs)
    return Response(t, outputs, contacts, "harmonic-balance", 0, {"torus": torus})


#: periods of the base frequency f0 of the transient a scene's harmonic balance starts from (docs/model.md §15)
START_PERIODS = 5


def start_record(scene: Scene, model) -> tuple[np.ndarray, dict] | None:
    """A harmonic balance's start: the rub scene's transient from the settled linear state over :data:`START_PERIODS`
    periods 1 / f0 (at the scene's time step or the next smaller one that divides the period) and its last period's
    samples of the balance's unknowns, ``(t, {position: samples})`` (each plate's disk x, y, u_n, u_t); None if the
    transient diverges.
    """
    from rotorred.scenes.harmonic_balance import base_frequency, unknown_records
    from rotorred.transient.newmark import Initial, Loads, Recording, StepControl, simulate
    from rotorred.transient.results import SimulationDiverged

    period = 1.0 / base_frequency(tuple(scene.frequencies_hz.values()))
    dt = period / math.ceil(period / scene.solver.dt - 1e-9)
    outputs = [(p.node, d) for p in scene.plates for d in ("x", "y")]
    try:
        res = simulate(model, scene.operating, START_PERIODS * period, dt,
                       loads=Loads(scene.unbalances), contacts=scene.plates,
                       recording=Recording(outputs, start=(START_PERIODS - 1) * period),
                       start=Initial(*settled_state(scene, model)), control=StepControl(progress=False))
    except SimulationDiverged:
        return None
    last = res.t > res.t[-1] - period + 0.5 * dt
    return res.t[last], {j: x[last] for j, x in unknown_records(scene.plates, res).items()}


def _transient_response(scene: Scene, scene_model: SceneModel, progress: bool | None, f_L: float,
                        f_H: float, initial=None) -> Response:
    """Time stepping from the settled linear state or from rest (:func:`rotorred.transient.newmark.simulate`).

    Raises :class:`SceneDiverged`, carrying the partial result, when the transient diverges.
    """
    # imported here: numba is loaded only when a scene needs it
    from rotorred.transient.newmark import Initial, Loads, Recording, Scheme, StepControl, simulate
    from rotorred.transient.results import SimulationDiverged

    s, model = scene.solver, scene_model.model
    if initial is None and s.start == "settled":
        initial = Initial(*settled_state(scene, model))
    stage("stepping %s: %s, %d steps of %g s to %g s (record from %g s)", scene.name, s.method,
          round(s.duration / s.dt), s.dt, s.duration, s.record_start, logger=LOG)
    try:
        res = simulate(model, scene.operating, s.duration, s.dt,
                       loads=Loads(scene.unbalances, s.gravity or None), contacts=scene.plates,
                       scheme=Scheme(s.method, alpha=s.alpha if s.method == "hht" else None),
                       recording=Recording(scene.output.dofs, start=s.record_start), start=initial,
                       control=StepControl(progress=progress))
    except SimulationDiverged as exc:
        raise SceneDiverged.of(scene, scene_model, exc, f_L, f_H) from None
    return Response(res.t, res.outputs, res.contacts, "transient", res.n_steps, _counters(res), res.final)


def _counters(res) -> dict:
    return {"n_newton": res.n_newton, "n_contact_steps": res.n_contact_steps, "n_substeps": res.n_substeps,
            "us_per_step": res.us_per_step, "kernel_load_time": res.kernel_load_time,
            "kernel_compiled": res.kernel_compiled}


# --------------------------------------------------------------------------- divergence
def explain_divergence(scene: Scene, exc) -> str:
    """When, where and why a scene's transient diverged, in the scene's key names.

    Parameters
    ----------
    exc : rotorred.transient.results.SimulationDiverged
    """
    import re

    from rotorred.transient.status import LIMIT, NEWTON_FAILED, NONFINITE

    status, t_done = exc.result.status, exc.result.final.t
    where, why = exc.dof, exc.cause
    m = re.match(r"plate (\d+)(?: at)? node (\d+) ?([xy]?)", exc.dof)
    if m:
        k = int(m.group(1))
        where = f"rub[{k}] (node {m.group(2)}{', ' + m.group(3) if m.group(3) else ''})"
    if status == LIMIT:
        why = ("the disk's displacement exceeded 1 m, the transient's divergence limit: the response left the "
               "model (lower unbalance[].m_e, or move speeds away from a critical speed)")
    elif status == NEWTON_FAILED:
        why = "the contact iteration did not converge (rub[].K_nr, rub[].c, solver.dt)"
    elif status == NONFINITE:
        why = "a displacement became infinite or NaN (solver.dt, rub[].K_nr)"
    return (f"the transient diverged at t = {exc.time:.6g} s at {where}: {why}; halving solver.dt = "
            f"{scene.solver.dt:g} s did not cure it; the record up to t = {t_done:.6g} s is kept")


class SceneDiverged(RuntimeError):
    """A scene's transient diverged; :attr:`partial` holds the record up to then.

    Attributes
    ----------
    partial : SceneResult
        The result up to the failing step (``incomplete`` set; no spectra, lines or normal comparison).
    time : float
        Time of the failing step (s).
    dof : str
        Where the failure was detected (the kernel's label).
    cause : str
        The kernel's cause.
    """

    def __init__(self, message: str, partial: SceneResult, time: float, dof: str, cause: str):
        super().__init__(message)
        self.partial, self.time, self.dof, self.cause = partial, time, dof, cause

    @classmethod
    def of(cls, scene: Scene, scene_model: SceneModel, exc, f_L: float, f_H: float) -> SceneDiverged:
        """The scene-level error of the transient's ``SimulationDiverged`` ``exc``.

        Parameters
        ----------
        scene : Scene
            The scene that diverged.
        scene_model : SceneModel
            Its model (:func:`build_model`).
        exc : rotorred.transient.results.SimulationDiverged
            The transient's error, with its partial result.
        f_L, f_H : float
            Lower and higher spool frequency (Hz).

        Returns
        -------
        SceneDiverged
            Its message says where and why in the scene's terms, its :attr:`partial` the record up to then.
        """
        message = explain_divergence(scene, exc)
        res = exc.result
        partial = SceneResult(scene=scene, t=res.t, outputs=res.outputs, contacts=res.contacts, spectra={},
                              lines={}, f_L=f_L, f_H=f_H, method="transient", model_label=scene_model.label,
                              n_steps=res.n_steps, build_time=scene_model.build_time, solve_time=res.run_time,
                              counters=_counters(res), incomplete=message)
        return cls(message, partial, exc.time, exc.dof, exc.cause)


def _spectra_and_lines(scene: Scene, t: np.ndarray, outputs: dict, f_L: float, f_H: float) -> tuple[dict, dict]:
    """Amplitude spectrum and the lines at its peaks (a :class:`LineFit`) of every recorded DOF."""
    spectra, lines = {}, {}
    for d in scene.output.dofs:
        spectra[d] = settled_spectrum(outputs[d], scene.solver.dt, f_L, f_H)
        lines[d] = fit_peaks(t, outputs[d], f_L, f_H, spectrum=spectra[d], threshold=scene.output.line_threshold)
    return spectra, lines
