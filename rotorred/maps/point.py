"""One point of a map: run its scene (from rest or from a neighbour's final state) and keep what a map records.

Continuation
    A warm point starts from the previous point's final state (model coordinates, the rub
    plates' own states, contact forces and slip modes: ``simulate(..., start=final)``) and with
    each unbalance at the angle it had reached, ``phase + Omega T`` (T the previous run's
    duration), so the forcing turns on without a jump in angle; only the speed (or the varied
    key) changes at the junction. At 90 Hz two runs of 0.5 s joined so equal one run of 1 s to
    round-off (tests/test_maps.py). A cold point starts as its scene says (``solver.start``). A
    point after a diverged one starts cold.

Run until settled
    A cold point runs the scene as it is (``solver.duration``, recorded from ``record_start``); a
    warm point first runs one recorded window's length, recorded from its start. When the table
    DOF's response has not settled on that record
    (:func:`rotorred.signals.settling.settling_time`), the run goes on from its final state in
    segments as long as the scene's recorded window, and the settling is measured again on the
    joined record, until it has settled or ``limit`` seconds have been simulated. The line fit
    uses the last segment (its last whole common periods where the speeds are commensurate); the
    class (:func:`rotorred.signals.classify.classify`) is found once, on the final record. Only
    the response is computed per segment (:func:`rotorred.scenes.run.respond`): no spectra of the
    other output DOFs, which a map does not keep.

Recorded per point (:class:`PointResult`)
    The class, settling time, explained share and torus of the table DOF
    (:mod:`rotorred.signals.classify`); its labelled lines, strongest first, at most
    ``N_LINES``; its Poincare samples, the last ``N_SAMPLES``; the peak orbit radius
    ``max sqrt(x^2 + y^2)`` at each output node (m); the contact fraction, impact count and
    largest normal force of the first plate, and the free orbit's reach towards it; the wall time. A diverged run records the reason
    in place of the results.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from rotorred.scenes.run import (SceneDiverged, SceneModel, analyse_lines, fit_and_settling, respond,
                                 spool_frequencies, table_dof)
from rotorred.scenes.reach import free_reach
from rotorred.scenes.schema import Scene
from rotorred.signals.spectra import settled_spectrum
from rotorred.transient.results import FinalState

__all__ = ["N_LINES", "N_SAMPLES", "StartState", "PointResult", "run_point"]

N_LINES = 60  #: lines kept per point, the strongest (60 lines explain >= 90 % off 70/90 Hz)
N_SAMPLES = 400  #: Poincare samples kept per point, the last ones


@dataclass(frozen=True)
class StartState:
    """Where a continued point starts: the transient's final state and the unbalance angles (rad) reached."""

    state: FinalState | None
    phases: tuple[float, ...]


@dataclass(frozen=True)
class PointResult:
    """What a map keeps of one point (SI units; NaN / -1 / "" where there is nothing).

    Attributes
    ----------
    status : {"ok", "diverged", "failed"}
    reason : str
        Why a point has no results ("" when ok).
    kind : str
        Class of the table DOF's response (:data:`rotorred.signals.classify.KINDS`).
    subharmonic : int
        k of a period-k response, else -1.
    period, settling_time, explained_share : float
        s, s (NaN when not settled), fraction.
    torus : (int, int)
        Sub-harmonic orders (k, j) of the fit.
    line_frequency, line_amplitude, line_phase : ndarray, shape (L,)
        Hz, m (or rad), rad; strongest first, L <= N_LINES.
    line_label : tuple of str
    poincare_x, poincare_velocity : ndarray, shape (S,)
        m and m/s, S <= N_SAMPLES.
    poincare_frequency : float
        Section frequency (Hz).
    peak_orbit : ndarray, shape (n_nodes,)
        Largest orbit radius at each output node (m).
    contact_fraction, n_impacts, max_contact_force : float, int, float
        First plate (0, 0, 0 without plates); N.
    free_reach : float
        Reach of the settled no-rub orbit towards the first plate (m,
        :func:`rotorred.scenes.reach.free_reach`): contact cannot start from the free orbit at a
        larger clearance. NaN without plates.
    start : {"cold", "warm"}
    simulated : float
        Simulated time (s): the scene's duration, plus the segments run until settled.
    wall_time : float
        s.
    final : StartState or None
        Start of the next point (None when diverged).
    """

    status: str
    reason: str = ""
    kind: str = ""
    subharmonic: int = -1
    period: float = math.nan
    settling_time: float = math.nan
    explained_share: float = math.nan
    torus: tuple = (0, 0)
    line_frequency: np.ndarray = field(default_factory=lambda: np.zeros(0))
    line_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    line_phase: np.ndarray = field(default_factory=lambda: np.zeros(0))
    line_label: tuple = ()
    poincare_x: np.ndarray = field(default_factory=lambda: np.zeros(0))
    poincare_velocity: np.ndarray = field(default_factory=lambda: np.zeros(0))
    poincare_frequency: float = math.nan
    peak_orbit: np.ndarray = field(default_factory=lambda: np.zeros(0))
    contact_fraction: float = math.nan
    n_impacts: int = -1
    max_contact_force: float = math.nan
    free_reach: float = math.nan
    start: str = "cold"
    simulated: float = math.nan
    wall_time: float = math.nan
    final: StartState | None = None


def continued(scene: Scene, start: StartState | None) -> Scene:
    """The scene with its unbalances at the angles a continued start has reached."""
    if start is None:
        return scene
    return replace(scene, unbalances=tuple(replace(u, phase=p) for u, p in zip(scene.unbalances, start.phases)))


def _angles(scene: Scene, T: float) -> tuple[float, ...]:
    """Each unbalance's angle (rad, in (-pi, pi]) after ``T`` seconds of the scene."""
    return tuple(math.remainder(u.phase + scene.speeds[scene.rotor.spool_of[u.node]] * T, 2 * math.pi)
                 for u in scene.unbalances)


def _recorded_from_start(scene: Scene) -> Scene:
    """A warm point's first run: one recorded window, recorded from its start (the neighbour's state is
    already near the settled response, so the settling is measured from t = 0, not after the
    scene's ``record_start``)."""
    s = scene.solver
    return replace(scene, solver=replace(s, duration=s.duration - s.record_start, record_start=0.0))


def _segment(scene: Scene, T: float) -> Scene:
    """The scene continued after ``T`` s for one more recorded window, recorded whole.

    (Segments as long as the record so far were tried: fewer analyses, but each on a longer last
    segment, and on the 9 x 2 benchmark map fewer points settled, 5 against 9, at twice the cost.)
    """
    s = scene.solver
    solver = replace(s, duration=s.duration - s.record_start, record_start=0.0)
    return replace(continued(scene, StartState(None, _angles(scene, T))), solver=solver)


@dataclass
class _Record:
    """The table DOF's record so far, joined over segments, and the last segment's response."""

    t: np.ndarray
    x: np.ndarray
    last: object  # rotorred.scenes.run.Response
    T: float  # simulated time (s)


def _until_settled(scene: Scene, model: SceneModel, record: _Record, limit: float):
    """Run segments from the last state until the settling is measured or ``limit`` s are simulated.

    Returns the last record's (LineFit, Settling) and the record."""
    d = table_dof(scene)
    settled = _fit_and_settling(scene, record)
    while not settled[1].settled and record.T < limit - 1e-9:
        seg = _segment(scene, record.T)
        res = respond(seg, model, record.last.final)
        new = res.t > 0.0  # its first sample is the previous segment's last
        record = _Record(np.concatenate((record.t, res.t[new] + record.T)),
                         np.concatenate((record.x, res.outputs[d][new])), res, record.T + seg.solver.duration)
        settled = _fit_and_settling(scene, record)
    return settled, record


def _fit_and_settling(scene: Scene, record: _Record):
    """Line fit of the last segment's settled part (the spectrum's samples) and the settling of the record."""
    f_L, f_H = spool_frequencies(scene)
    n_fit = settled_spectrum(record.last.outputs[table_dof(scene)], scene.solver.dt, f_L, f_H).n_samples
    return fit_and_settling(record.t, record.x, f_L, f_H, n_fit)


def run_point(scene: Scene, model: SceneModel, start: StartState | None = None,
              limit: float | None = None) -> PointResult:
    """Run one point until settled or ``limit`` s simulated (default: the scene's duration) and keep what
    a map records (:class:`PointResult`)."""
    t0 = time.perf_counter()
    scene = continued(scene, start)
    how = "cold" if start is None else "warm"
    first = scene if start is None else _recorded_from_start(scene)
    d = table_dof(scene)
    try:
        res = respond(first, model, None if start is None else start.state)
        record = _Record(res.t, res.outputs[d], res, first.solver.duration)
        settled, record = _until_settled(scene, model, record, limit or scene.solver.duration)
        analysis = analyse_lines(record.t, record.x, *spool_frequencies(scene), dof=d, settled=settled)
    except SceneDiverged as exc:
        return PointResult("diverged", reason=str(exc), start=how, wall_time=time.perf_counter() - t0)
    except ValueError as exc:  # a record too short to fit (checks' one-line message)
        return PointResult("failed", reason=str(exc), start=how, wall_time=time.perf_counter() - t0)
    reach = free_reach(scene, model)
    return replace(_recorded(analysis, scene, record.last), start=how, simulated=record.T,
                   free_reach=math.nan if reach is None else reach, wall_time=time.perf_counter() - t0,
                   final=_final(scene, record))


def _final(scene: Scene, record: _Record) -> StartState | None:
    """The state the next point starts from: the run's last state and the unbalance angles reached."""
    final = record.last.final
    return None if final is None else StartState(final, _angles(scene, record.T))


def _recorded(a, scene: Scene, res) -> PointResult:
    """The class, lines, Poincare samples (line analysis ``a``), orbits and contact (last segment ``res``)."""
    c = a.classification
    lines = sorted(a.fit.lines, key=lambda ln: -ln.amplitude)[:N_LINES]
    return PointResult(
        "ok", kind=c.kind, subharmonic=-1 if c.subharmonic is None else int(c.subharmonic),
        period=math.nan if c.period is None else float(c.period),
        settling_time=float(c.settling.time) if c.settling.settled else math.nan,
        explained_share=float(c.explained_share), torus=(a.fit.torus.k, a.fit.torus.j),
        line_frequency=np.array([ln.frequency_hz for ln in lines]),
        line_amplitude=np.array([ln.amplitude for ln in lines]), line_phase=np.array([ln.phase for ln in lines]),
        line_label=tuple(ln.label for ln in lines),
        poincare_x=c.poincare.x[-N_SAMPLES:], poincare_velocity=c.poincare.velocity[-N_SAMPLES:],
        poincare_frequency=float(c.poincare.frequency_hz), peak_orbit=_peak_orbits(scene, res),
        **_contact(res))


def _peak_orbits(scene: Scene, res) -> np.ndarray:
    """Largest orbit radius (m) at each output node with x and y recorded (NaN for a node without both)."""
    out = []
    for n in scene.output.nodes:
        x, y = res.outputs.get((n, "x")), res.outputs.get((n, "y"))
        out.append(float(np.max(np.hypot(x, y))) if x is not None and y is not None else math.nan)
    return np.array(out)


def _contact(res) -> dict:
    """Contact fraction, impacts and largest normal force (N) of the first plate."""
    if not res.contacts:
        return {"contact_fraction": 0.0, "n_impacts": 0, "max_contact_force": 0.0}
    first = res.contacts[0]
    force = np.asarray(first.normal_force)
    return {"contact_fraction": 1.0 - first.fraction("open"), "n_impacts": first.n_impacts(),
            "max_contact_force": float(np.max(np.abs(force))) if force.size else 0.0}
