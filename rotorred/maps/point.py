"""One point of a map: run its scene (from rest or from a neighbour's final state) and keep what a map records.

Continuation
    A warm point starts from the previous point's final state ``(q, v)`` (model coordinates) and
    with each unbalance at the angle it had reached, ``phase + Omega T`` (T the previous run's
    duration), so the forcing turns on without a jump in angle; only the speed (or the varied
    key) changes at the junction. A cold point starts as its scene says (``solver.start``). A
    point after a diverged one starts cold.

Recorded per point (:class:`PointResult`)
    The class, settling time, explained share and torus of the table DOF
    (:mod:`rotorred.signals.classify`); its labelled lines, strongest first, at most
    ``N_LINES``; its Poincare samples, the last ``N_SAMPLES``; the peak orbit radius
    ``max sqrt(x^2 + y^2)`` at each output node (m); the contact fraction, impact count and
    largest normal force of the first plate; the wall time. A diverged run records the reason
    in place of the results.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from rotorred.scenes.run import SceneDiverged, SceneModel, run_scene
from rotorred.scenes.schema import Scene

__all__ = ["N_LINES", "N_SAMPLES", "StartState", "PointResult", "run_point"]

N_LINES = 60  #: lines kept per point, the strongest (issue 19: 60 lines explain >= 90 % off 70/90 Hz)
N_SAMPLES = 400  #: Poincare samples kept per point, the last ones


@dataclass(frozen=True)
class StartState:
    """Where a continued point starts: model state and the unbalance angles (rad) reached."""

    q: np.ndarray
    v: np.ndarray
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
    start : {"cold", "warm"}
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
    start: str = "cold"
    wall_time: float = math.nan
    final: StartState | None = None


def continued(scene: Scene, start: StartState | None) -> Scene:
    """The scene with its unbalances at the angles a continued start has reached."""
    if start is None:
        return scene
    return replace(scene, unbalances=tuple(replace(u, phase=p) for u, p in zip(scene.unbalances, start.phases)))


def run_point(scene: Scene, model: SceneModel, start: StartState | None = None) -> PointResult:
    """Run one point and keep what a map records (:class:`PointResult`)."""
    t0 = time.perf_counter()
    scene = continued(scene, start)
    initial = None if start is None else (start.q, start.v)
    try:
        res = run_scene(scene, model, compare_normal=False, initial=initial)
    except SceneDiverged as exc:
        return PointResult("diverged", reason=str(exc), start="cold" if start is None else "warm",
                           wall_time=time.perf_counter() - t0)
    if res.analysis is None:
        reason = "; ".join(res.analysis_errors.values()) or "no line analysis of the table DOF"
        return PointResult("failed", reason=reason, wall_time=time.perf_counter() - t0)
    return replace(_recorded(res), start="cold" if start is None else "warm", wall_time=time.perf_counter() - t0,
                   final=_final(scene, res))


def _final(scene: Scene, res) -> StartState | None:
    """The state the next point starts from: the run's last state and the unbalance angles reached."""
    if res.final is None:
        return None
    T = scene.solver.duration
    phases = tuple(math.remainder(u.phase + scene.speeds[scene.rotor.spool_of[u.node]] * T, 2 * math.pi)
                   for u in scene.unbalances)
    return StartState(np.array(res.final.q), np.array(res.final.v), phases)


def _recorded(res) -> PointResult:
    """The class, lines, Poincare samples, orbits and contact of a finished run."""
    a = res.analysis
    c = a.classification
    lines = sorted(a.fit.lines, key=lambda ln: -ln.amplitude)[:N_LINES]
    return PointResult(
        "ok", kind=c.kind, subharmonic=-1 if c.subharmonic is None else int(c.subharmonic),
        period=math.nan if c.period is None else float(c.period),
        settling_time=float(c.settling.time) if c.settling.settled else math.nan,
        explained_share=float(a.fit.explained_share), torus=(a.fit.torus.k, a.fit.torus.j),
        line_frequency=np.array([ln.frequency_hz for ln in lines]),
        line_amplitude=np.array([ln.amplitude for ln in lines]), line_phase=np.array([ln.phase for ln in lines]),
        line_label=tuple(ln.label_ascii for ln in lines),
        poincare_x=c.poincare.x[-N_SAMPLES:], poincare_velocity=c.poincare.velocity[-N_SAMPLES:],
        poincare_frequency=float(c.poincare.frequency_hz), peak_orbit=_peak_orbits(res),
        **_contact(res))


def _peak_orbits(res) -> np.ndarray:
    """Largest orbit radius (m) at each output node with x and y recorded (NaN for a node without both)."""
    out = []
    for n in res.scene.output.nodes:
        x, y = res.outputs.get((n, "x")), res.outputs.get((n, "y"))
        out.append(float(np.max(np.hypot(x, y))) if x is not None and y is not None else math.nan)
    return np.array(out)


def _contact(res) -> dict:
    """Contact fraction, impacts and largest normal force (N) of the first plate."""
    if not res.contacts:
        return {"contact_fraction": 0.0, "n_impacts": 0, "max_contact_force": 0.0}
    force = np.asarray(res.contacts[0].normal_force)
    return {"contact_fraction": float(res.contact_fraction()), "n_impacts": int(res.n_impacts()),
            "max_contact_force": float(np.max(np.abs(force))) if force.size else 0.0}
