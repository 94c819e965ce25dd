"""``[solver] tolerance``: the tool chooses the model, the time step and the recorded window to meet a relative
error target on the scene's outputs, and says what it chose and the error estimate behind each choice.

The error of the outputs is :mod:`rotorred.signals.compare`'s: each recorded DOF's amplitude spectrum up to
the band's top (relative to its largest line) and its peak. The target ``tol`` is shared out
(docs/model.md §9):

1. **Band.** ``output.f_max_hz`` when given, else :data:`BAND_FACTOR` x f_H (the rub lines above 0.5 % of
   the largest reach 6.8 f_H on paper-rub).
2. **Model** (reduced scenes): the smallest number of fixed-interface modes whose receptance error against
   the full model (:mod:`rotorred.linear.accuracy`; inputs: the unbalance and rub DOFs, outputs: the
   recorded DOFs; over the band with a rub plate, whose contact force has every frequency, else at the spool
   speeds, the only frequencies the unbalances force) is at most ``MODEL_SHARE tol``. A forced node inside the reduced model is tried as a
   boundary node too (its four DOFs kept physical, the attachment of its force): the smaller model meeting the
   target wins. When the reduced model would be as large as the full one, the full model is used.
3. **Time step, a priori**: the largest step of the 1-2-5 ladder whose receptance error (the
   average-acceleration step's frequency warping, exact for the linear steady state) is at most
   ``DT_SHARE tol``. A linear scene started settled gets the harmonic solution, exact at any sample: its
   step is the largest with the band below half the Nyquist frequency whose sampled peak misses the true one
   by at most ``DT_SHARE tol / 4`` ((Omega dt)^2 / 8 at the fastest spool).
4. **Window**: the record starts once the slowest mode of the band has decayed to ``WINDOW_SHARE tol``
   (``ln(1 / (WINDOW_SHARE tol)) / sigma_min``, rounded up to whole common periods); its length is the
   scene's.
5. **Time step, measured** (a scene stepped in time: rub plates, or a start from rest): the scene runs at dt
   and dt/2 and 4/3 of the difference of the outputs (Richardson, order 2) is the step's error estimate on
   the actual (nonlinear) response; dt is halved until it is at most what the model and window estimates
   leave of tol (at least ``STEP_SHARE tol``), or, when the a-priori step already meets it, doubled while it
   still does.

The sum of the estimates (model + time step + window) is at most tol.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from rotorred import checks
from rotorred.linear.accuracy import band_frequencies, receptance, receptance_error
from rotorred.linear.modal import eigen
from rotorred.model.assembly import assemble
from rotorred.scenes.modes import BAND_FACTOR, band_hz, choose_modes, input_dofs, running
from rotorred.scenes.schema import Scene, is_whole_steps
from rotorred.signals.compare import outputs_error
from rotorred.signals.spectra import NotCommensurateError, commensurate_record

__all__ = ["Choice", "Settings", "choose", "run_to_tolerance", "BAND_FACTOR", "MODEL_SHARE", "DT_SHARE", "WINDOW_SHARE",
           "STEP_SHARE", "DT_LADDER"]

#: shares of the tolerance: model, window, the time step on a stepped response (measured), and the a-priori
#: time step (the harmonic solution's sampling; the start of the measured step's ladder)
MODEL_SHARE, WINDOW_SHARE, STEP_SHARE, DT_SHARE = 0.25, 0.25, 0.5, 1.0
#: time steps tried (s), largest first: a 1-2-5 ladder, each a whole fraction of 0.1 s
DT_LADDER = tuple(m * 10.0 ** -e for e in range(3, 8) for m in (5, 2, 1))[1:]
#: most halvings of dt the contact check makes
MAX_HALVINGS = 6
#: longest common period the record start is rounded up to (s); a longer one (or none): whole steps
MAX_PERIOD = 1.0


@dataclass(frozen=True)
class Choice:
    """One chosen setting: the scene key, its value, the error estimate behind it and why."""

    key: str
    value: object
    estimate: float | None
    reason: str


@dataclass(frozen=True)
class Settings:
    """What ``[solver] tolerance`` chose for a scene (:func:`choose`).

    Attributes
    ----------
    tolerance : float
    band_hz : float
        Top of the frequency band of the estimates (Hz).
    scene : Scene
        The scene with the chosen ``solver`` settings (tolerance kept).
    choices : tuple of Choice
        model, modes, boundary nodes, dt, record_start and duration, each with its estimate and reason.
    estimate : float
        Sum of the error estimates (<= tolerance).
    time : float
        Wall time of the choice (s), runs of the contact check included.
    """

    tolerance: float
    band_hz: float
    scene: Scene
    choices: tuple
    estimate: float
    time: float

    def describe(self) -> list[str]:
        """One line per choice, then the total."""
        lines = [f"solver.tolerance = {self.tolerance:g} (outputs' spectra to {self.band_hz:.4g} Hz and peaks): "
                 f"chosen in {self.time:.2f} s"]
        for c in self.choices:
            est = "" if c.estimate is None else f" (estimate {c.estimate:.2g})"
            lines.append(f"  {c.key} = {c.value}{est}: {c.reason}")
        lines.append(f"  estimated error {self.estimate:.2g} <= {self.tolerance:g}")
        return lines


def choose(scene: Scene) -> Settings:
    """Choose model, dt and window of ``scene`` for its ``solver.tolerance`` (module docstring).

    Returns
    -------
    Settings
        ``settings.scene`` is what to run.
    """
    tol = scene.solver.tolerance
    if tol is None:
        checks.fail("solver.tolerance", tol, "must be given to choose the settings")
    t0 = time.perf_counter()
    band = band_hz(scene)
    system = assemble(scene.rotor)
    # the full model's eigenvalues, once: for the band and for the window
    eigenvalues = eigen(system.M, system.damping(scene.speeds), system.stiffness(scene.speeds)).eigenvalues
    omega = band_frequencies(system, scene.speeds, band, eigenvalues=eigenvalues)
    inputs = input_dofs(scene)
    model, solver, model_choices, e_model = _choose_model(scene, system, tol, omega)
    dt, e_dt = _choose_dt(scene, model, omega, inputs, tol)
    start, duration, e_window, window_reason = _choose_window(scene, eigenvalues, omega, dt, tol)
    chosen = dataclasses.replace(scene, solver=dataclasses.replace(solver, dt=dt, record_start=start,
                                                                   duration=duration),
                                 output=_inside(scene.output, start, duration))
    choices = list(model_choices)
    dt_reason = (f"a priori: the largest step of the ladder whose receptance error (the step's frequency warping) "
                 f"over 0-{band:.4g} Hz is <= {DT_SHARE:g} tol ({e_dt:.2g})")
    e_step = e_dt
    if scene.plates or scene.solver.start != "settled":  # stepped in time: the step's error is measured
        budget = tol - e_model - e_window  # what the model and the window leave, at least STEP_SHARE tol
        chosen, e_step, dt_reason = _measure_dt(chosen, band, tol, budget, dt_reason)
    choices.append(Choice("solver.dt", f"{chosen.solver.dt:g} s", e_step, dt_reason))
    choices.append(Choice("solver.record_start", f"{start:g} s", e_window, window_reason))
    choices.append(Choice("solver.duration", f"{duration:g} s", None,
                          f"record_start + the scene's window of {scene.solver.duration - scene.solver.record_start:g} s"))
    estimate = e_model + e_step + e_window
    return Settings(tol, band, chosen, tuple(choices), estimate, time.perf_counter() - t0)


def run_to_tolerance(scene: Scene, **options):
    """Choose the settings of ``scene`` (:func:`choose`) and run them (:func:`rotorred.scenes.run.run_scene`); the
    result's ``settings`` says what was chosen. A scene without a tolerance runs as it is, and so does a harmonic
    balance (its tolerance chooses the harmonics: :mod:`rotorred.scenes.balance_harmonics`).

    Parameters
    ----------
    scene : Scene
        The scene; ``solver.tolerance`` (-) is the relative error the settings are chosen for.
    **options
        Options of :func:`rotorred.scenes.run.run_scene`.

    Returns
    -------
    SceneResult
    """
    from rotorred.scenes.run import run_scene

    if scene.solver.tolerance is None or scene.solver.method == "harmonic-balance":  # that chooses its harmonics
        return run_scene(scene, **options)
    settings = choose(scene)
    return run_scene(settings.scene, settings=settings, **options)


# --------------------------------------------------------------------------- model
def _choose_model(scene, system, tol, band):
    """(model, solver settings, choices, estimate): the smallest model meeting MODEL_SHARE tol
    (:func:`rotorred.scenes.modes.choose_modes`; ``band``: the band's frequencies, rad/s)."""
    s = scene.solver
    if s.model == "full":
        return system, s, [Choice("solver.model", "full", 0.0, "the scene asks for the full model")], 0.0
    choice = choose_modes(scene, system, MODEL_SHARE * tol, band)
    if choice.full:
        why = "no reduced model smaller than the full one meets the target"
        return system, dataclasses.replace(s, model="full"), [Choice("solver.model", "full", 0.0, why)], 0.0
    model, err, extra = choice.model, choice.error, choice.extra_nodes
    solver = dataclasses.replace(s, model="reduced", modes=model.n_modes, cutoff_hz=None,
                                 boundary_nodes=tuple(sorted(set(s.boundary_nodes) | set(extra))))
    where = f"worst at {err.output} from a force at {err.input}, {err.frequency_hz:.4g} Hz"
    choices = [Choice("solver.model", f"reduced, {model.n_dof} of {system.dofs.n_dof} DOFs", None,
                      f"the smallest Craig-Bampton model meeting {MODEL_SHARE:g} tol over 0-{choice.band_hz:.4g} Hz")]
    choices.append(Choice("solver.modes", model.n_modes, err.error,
                          f"fewest fixed-interface modes with a receptance error against the full model <= "
                          f"{MODEL_SHARE:g} tol ({where})"))
    if extra:
        choices.append(Choice("solver.boundary_nodes", list(solver.boundary_nodes), None,
                              f"forced interior node(s) {list(extra)} kept physical: fewer DOFs than modes alone"))
    return model, solver, choices, err.error


# --------------------------------------------------------------------------- time step
def _choose_dt(scene, model, omega, inputs, tol) -> tuple[float, float]:
    """(dt, estimate): the largest step of :data:`DT_LADDER` whose warping error is <= DT_SHARE tol."""
    outputs = scene.output.dofs
    if scene.is_linear and scene.solver.start == "settled":  # the harmonic solution: exact at its samples, whose
        # peak misses the true one by at most 1 - cos(Omega dt / 2) ~ (Omega dt)^2 / 8 at the fastest spool
        w = max(running(scene))
        dt = next(dt for dt in DT_LADDER
                  if omega[-1] * dt < 0.5 * math.pi and (w * dt) ** 2 / 8 <= DT_SHARE * tol / 4)
        return dt, (w * dt) ** 2 / 8
    H = receptance(model, scene.speeds, omega, outputs, inputs)
    for dt in DT_LADDER:
        if omega[-1] * dt >= 0.5 * math.pi:
            continue  # the band must sit well below the step's Nyquist frequency
        err = receptance_error(receptance(model, scene.speeds, omega, outputs, inputs, dt=dt), H, omega, outputs,
                               inputs, at=running(scene))
        if err.error <= DT_SHARE * tol:
            return dt, err.error
    checks.fail("solver.tolerance", tol, f"is not reachable with a time step of {DT_LADDER[-1]:g} s or more")


# --------------------------------------------------------------------------- window
def _choose_window(scene, eigenvalues, omega, dt, tol) -> tuple[float, float, float, str]:
    """(record_start, duration, estimate, reason): the record starts when the slowest mode of the band (of the full
    model's ``eigenvalues``) has decayed to WINDOW_SHARE tol; the scene's window length is kept."""
    s = scene.solver
    in_band = eigenvalues[eigenvalues.imag <= omega[-1]]
    sigma = -in_band.real
    if not in_band.size or sigma.min() <= 0:
        checks.fail("solver.tolerance", tol, "cannot be met: a mode of the band is undamped or unstable, so the "
                    "response does not settle")
    k = int(np.argmin(sigma))
    length = s.duration - s.record_start
    period = _common_period(scene, dt)
    t_decay = math.log(1.0 / (WINDOW_SHARE * tol)) / sigma[k]
    start = period * math.ceil(t_decay / period - 1e-9)
    n_steps = round((start + length) / dt)
    reason = (f"the slowest mode of the band ({in_band[k].imag / (2 * math.pi):.4g} Hz, decay rate "
              f"{sigma[k]:.3g} 1/s) decays to {WINDOW_SHARE:g} tol in {t_decay:.3g} s; rounded up to whole "
              f"{'common periods' if period > dt else 'steps'}")
    return start, n_steps * dt, WINDOW_SHARE * tol, reason


def _common_period(scene, dt) -> float:
    """The spools' common period (:func:`rotorred.signals.spectra.commensurate_record`, the spectrum's own rule) when
    it is a whole number of steps of ``dt`` and at most :data:`MAX_PERIOD`, else ``dt``."""
    from rotorred.scenes.run import spool_frequencies

    try:
        period = commensurate_record(*spool_frequencies(scene), dt).period
    except NotCommensurateError:
        return dt
    return period if period <= MAX_PERIOD else dt


def _inside(output, start: float, duration: float):
    """``output`` with a ``plot_window`` outside the new record dropped (the default window is used)."""
    w = output.plot_window
    if w is not None and not (start <= w[0] and w[1] <= duration):
        return dataclasses.replace(output, plot_window=None)
    return output


# --------------------------------------------------------------------------- time step, measured
def _measure_dt(scene: Scene, band: float, tol: float, budget: float, reason: str) -> tuple[Scene, float, str]:
    """The largest dt of a halving ladder from the a-priori step whose Richardson estimate on the stepped response
    is at most ``budget``: ``4/3 |y(dt) - y(dt/2)|`` (order 2), the step coarsened while it holds, refined until it
    holds."""
    from rotorred.scenes.run import build_model, respond, spool_frequencies

    f_L, f_H = spool_frequencies(scene)
    model = build_model(scene)
    target = max(budget, STEP_SHARE * tol)
    runs = {}

    def response(dt):
        if dt not in runs:
            runs[dt] = respond(_with_dt(scene, dt), model).outputs
        return runs[dt]

    def estimate(dt):  # Richardson: 4/3 of the difference to the run at dt/2
        return 4.0 / 3.0 * outputs_error(response(dt), dt, response(dt / 2), dt / 2, f_L, f_H, band).error

    dt = scene.solver.dt
    est = estimate(dt)
    halvings = 0
    while est > target:
        if halvings == MAX_HALVINGS:
            checks.fail("solver.tolerance", tol, f"is not reached after {MAX_HALVINGS} halvings of the time step "
                        f"(estimate {est:.2g} at dt = {dt:g} s)")
        dt, halvings = dt / 2, halvings + 1
        est = estimate(dt)
    while halvings == 0 and _whole(2 * dt, scene) and 2 * dt <= DT_LADDER[0]:
        coarse_est = estimate(2 * dt)
        if coarse_est > target:
            break
        dt, est = 2 * dt, coarse_est
    why = (f"{reason}; measured on the stepped response: 4/3 x the difference to the run at dt/2 (Richardson, "
           f"order 2) is {est:.2g} <= {target:.2g}, the tolerance left by the model and window ({len(runs)} runs)")
    return _with_dt(scene, dt), est, why


def _whole(dt: float, scene: Scene) -> bool:
    """Whether ``record_start`` and ``duration`` are whole numbers of steps of ``dt``."""
    return all(is_whole_steps(t, dt) for t in (scene.solver.record_start, scene.solver.duration))


def _with_dt(scene: Scene, dt: float) -> Scene:
    return dataclasses.replace(scene, solver=dataclasses.replace(scene.solver, dt=dt))
