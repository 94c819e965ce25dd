"""What every compiled step loop shares (:func:`rotorred.transient.newmark.simulate` at constant speeds,
:mod:`rotorred.transient.ramp` at varying ones): the checked options, the initial state, the record
plan and buffers, loading the kernel, the progress bar and the packaging of the result."""

from __future__ import annotations

import contextlib
import logging
import math
import time
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np
import scipy.linalg as sla

from rotorred import checks
from rotorred.progress import bar, stage
from rotorred.transient import kernel
from rotorred.transient.contact import OPEN, SLIP, STICK, RubPlate, disk_force, normal_force
from rotorred.model.assembly import system_of
from rotorred.model.operating import Operating
from rotorred.model.speeds import SpeedProfile
from rotorred.transient.contact_solve import C_PASSES
from rotorred.transient.matrices import ForceColumns, disk_radii
from rotorred.transient.options import Initial, Loads, Recording, Scheme, StepControl, within
from rotorred.writers import signals_held
from rotorred.transient.results import (FinalState, SimulationDiverged, TransientResult, contact_histories,
                                        failure)

LOG = logging.getLogger(__name__)


# ----------------------------------------------------------------------------------- 1. the checked run
@dataclass(frozen=True, eq=False)
class Run:
    """One transient, every input checked (:func:`check_run`): what every step loop and the packaging read.

    Attributes
    ----------
    system : SystemMatrices or ReducedSystem
        The model (:func:`rotorred.model.assembly.system_of`); its ``rotor`` gives the spool of each node and
        the disk radius under a plate that does not give it.
    speeds : dict of str to float
        Every spool's speed at t = 0 (rad/s), in the model's spool order.
    profile : SpeedProfile or None
        Every spool's speed in time (:meth:`rotorred.model.operating.Operating.profile_for`); None at constant
        speeds.
    t_end, dt : float
        End time and time step (s).
    loads : Loads
    plates : tuple of RubPlate
        The contacts.
    scheme : Scheme
    recording : Recording
        Its outputs checked against the model.
    control : StepControl
    x0 : ndarray, shape (3 n,)
        (q0, v0, 0) in model coordinates.
    start : FinalState or None
        Another run's final state to continue from.
    """

    system: object
    speeds: dict
    profile: SpeedProfile | None
    t_end: float
    dt: float
    loads: Loads
    plates: tuple
    scheme: Scheme
    recording: Recording
    control: StepControl
    x0: np.ndarray
    start: FinalState | None

    @property
    def spool_of(self) -> dict[int, str]:
        """Spool of each node of the model (:class:`rotorred.model.assembly.SpoolSpeedMixin`)."""
        return self.system.spool_of

    @property
    def rotor(self):
        """The rotor the model was built from (or None): the disk radius under a plate that does not give it."""
        return self.system.rotor


def check_run(model, operating, t_end, dt, loads, contacts, scheme, recording, start, control) -> Run:
    """Every input of :func:`rotorred.transient.newmark.simulate`, checked before any computation; an error
    names the parameter (``dt``, ``recording.start``, ``contacts[0]``, ``start.q0``)."""
    system = system_of(model)
    t_end = checks.positive("t_end", t_end, "s")
    dt = checks.positive("dt", dt, "s")
    if dt > t_end:
        checks.fail("dt", dt, f"must not exceed t_end = {t_end!r}", "s")
    for name, value, cls in (("loads", loads, Loads), ("scheme", scheme, Scheme), ("recording", recording, Recording),
                             ("control", control, StepControl)):
        if not isinstance(value, cls):
            checks.fail(name, type(value).__name__, f"must be a {cls.__name__}")
    speeds, profile = operating_speeds(system, operating)
    plates = tuple(checks.sequence("contacts", contacts, _rub_plate))
    if recording.start > t_end:
        checks.fail("recording.start", recording.start, f"must not exceed t_end = {t_end!r}", "s")
    with within("recording"):
        recording = replace(recording, outputs=tuple(system.full_dofs.checked_outputs(recording.outputs)))
    _check_spools(system, loads, plates)
    disk_radii(plates, system.rotor)
    if start is not None and not isinstance(start, (Initial, FinalState)):
        checks.fail("start", type(start).__name__, "must be an Initial(q0, v0) or a FinalState (another run's `final`)")
    n = system.M.shape[0]
    if isinstance(start, FinalState):
        _check_final_state(start, n, len(plates))
    return Run(system=system, speeds=speeds, profile=profile, t_end=t_end, dt=dt, loads=loads, plates=plates,
               scheme=scheme, recording=recording, control=control, x0=initial_vector(n, start),
               start=start if isinstance(start, FinalState) else None)


def operating_speeds(system, operating) -> tuple[dict[str, float], SpeedProfile | None]:
    """Every spool's speed at t = 0 (rad/s) and, for a profile, its speeds in time, by the ratio rule of
    :class:`~rotorred.model.operating.Operating`."""
    if not isinstance(operating, Operating):
        checks.fail("operating", type(operating).__name__, "must be an Operating (Operating.point for constant "
                    "speeds, Operating.profile or Operating.ramp for speeds in time)")
    if operating.kind == "profile":
        profile = operating.profile_for(system)
        return profile.speeds_at(0.0), profile
    return operating.single(system), None


def _rub_plate(field: str, value) -> RubPlate:
    if not isinstance(value, RubPlate):
        checks.fail(field, value, "must be a RubPlate")
    return value


def _check_spools(system, loads: Loads, plates: tuple) -> None:
    """The node of every unbalance and plate is on a spool of the model (``system.spool_of``)."""
    spool_of = system.spool_of
    for field, items in (("loads.unbalances", loads.unbalances), ("contacts", plates)):
        for k, item in enumerate(items):
            if item.node not in spool_of:
                why = ("; the model, built by hand with several spools, knows no node's spool: assemble it from a "
                       "Rotor" if not spool_of else "")
                checks.fail(f"{field}[{k}].node", item.node, "must be a node of a spool of the model" + why)


def initial_vector(n: int, start: Initial | FinalState | None = None) -> np.ndarray:
    """(q0, v0, 0), shape (3 n,), from ``start``'s displacement and velocity (model coordinates; default 0)."""
    x0 = np.zeros(3 * n)
    if start is None:
        return x0
    named = (("q", start.q), ("v", start.v)) if isinstance(start, FinalState) else (("q0", start.q0), ("v0", start.v0))
    for k, (name, vec) in enumerate(named):
        if vec is not None:
            x0[k * n:(k + 1) * n] = checks.array(f"start.{name}", vec, (n,))
    return x0


def _check_final_state(start: FinalState, n: int, n_p: int) -> None:
    """A continued run's plates are the run's plates: ``start`` holds the state of ``n`` DOFs and ``n_p`` plates."""
    shapes = {"q": (n,), "v": (n,), "plate": (n_p, 2, 3), "forces": (n_p, 2), "mode": (n_p,), "sgn": (n_p,)}
    for name, shape in shapes.items():
        checks.array(f"start.{name}", getattr(start, name), shape)


# ----------------------------------------------------------------------------------- 2. initial state, records
def initial_state(M, D, K, B, par: np.ndarray, plates: Sequence[RubPlate], forces: ForceColumns,
                  x0: np.ndarray, start: FinalState | None = None) -> kernel.State:
    """The kernel's :class:`~rotorred.transient.kernel.State` at t = 0.

    From rest or (q0, v0), the plates start at rest; a plate already pressed at t = 0 starts
    slipping with the law's force, which the plate's acceleration balances. From another run's
    ``start`` state, the plates' states, contact forces, slip modes and directions are carried
    over. Either way the acceleration follows from the equation of motion at t = 0,
    ``a0 = M^-1 (F(0) + B f(0) - D v0 - K q0)`` (the forcing may differ from the run that ended
    in ``start``: another speed).
    """
    n, n_p = len(M), len(plates)
    q, v = x0[:n], x0[n:2 * n]
    xc = np.zeros((2 * n_p, 3))
    xc[:, 0], xc[:, 1] = B.T @ q, B.T @ v
    if start is None:
        z, ps, mode, sgn = _plates_from_rest(xc, par, plates)
    else:
        z, ps = start.forces.ravel().astype(float), np.array(start.plate, float)
        mode, sgn = np.array(start.mode, dtype=np.int64), np.array(start.sgn, float)
    pinfo = _plate_info(xc, ps, z, mode, par)
    f = np.column_stack(disk_force(z[0::2], z[1::2], par[:, kernel.P_COS], par[:, kernel.P_SIN])).ravel()
    x0 = x0.copy()
    x0[2 * n:] = sla.solve(M, forces.at(0.0) + B @ f - D @ v - K @ q)
    xc[:, 2] = B.T @ x0[2 * n:]
    return kernel.State(x=x0, xc=xc, ps=ps, z=z, mode=mode, sgn=sgn, pinfo=pinfo)


def _plates_from_rest(xc: np.ndarray, par: np.ndarray, plates: Sequence[RubPlate]):
    """(z, ps, mode, sgn) of plates at rest at t = 0: a pressed plate slips with the law's force."""
    n_p = len(plates)
    z, ps, sgn = np.zeros(2 * n_p), np.zeros((n_p, 2, 3)), np.ones(n_p)
    for k, p in enumerate(plates):
        c, s = par[k, kernel.P_COS], par[k, kernel.P_SIN]
        (x, vx), (y, vy) = xc[2 * k, :2], xc[2 * k + 1, :2]
        vrel = par[k, kernel.P_V] + (-vx * s + vy * c)
        P, _ = normal_force(x * c + y * s - p.clearance, vx * c + vy * s, p)
        T = -p.mu_d * P * np.sign(vrel)
        sgn[k] = 1.0 if vrel >= 0 else -1.0
        z[2 * k], z[2 * k + 1] = P, T
        ps[k, 0, 2], ps[k, 1, 2] = P / p.m_p, -T / p.m_p
    return z, ps, np.ones(n_p, dtype=np.int64), sgn


def _plate_info(xc: np.ndarray, ps: np.ndarray, z: np.ndarray, mode: np.ndarray, par: np.ndarray) -> np.ndarray:
    """The kernel's ``pinfo`` at t = 0: v_rel (m/s), gap (m) and contact state (0 open, 1 slip, 2 stick)."""
    pinfo = np.zeros((len(ps), 3))
    for k in range(len(ps)):
        c, s = par[k, kernel.P_COS], par[k, kernel.P_SIN]
        (x, vx), (y, vy) = xc[2 * k, :2], xc[2 * k + 1, :2]
        vrel = par[k, kernel.P_V] + (-vx * s + vy * c) - ps[k, 1, 1]
        gap = par[k, kernel.P_CLEAR] + ps[k, 0, 0] - (x * c + y * s)
        state = OPEN if z[2 * k] == 0 else (STICK if mode[k] == 2 else SLIP)
        pinfo[k] = (vrel, gap, state)
    return pinfo


@dataclass(frozen=True)
class RecordPlan:
    """Which steps are recorded: step indices ``first, first + every, ...`` up to ``n_steps`` (index j = time j dt).

    Attributes
    ----------
    n_steps : int
        Main steps of the run.
    first, every : int
        First recorded step index and decimation.
    n_records : int
        Number of records.
    """

    n_steps: int
    first: int
    every: int
    n_records: int


def whole_steps(x: float) -> int:
    """The steps a time covers, ``x`` = time / dt: the nearest integer when ``x`` is one up to its rounding, else
    ``x`` rounded up.

    The slack is 1e-9 + 1e-12 |x| steps: the quotient of two decimal times carries a rounding error of
    about |x| 2e-16 (59.7 / 1e-6 = 59700000.00000001), more than a fixed 1e-9 steps once a run has
    some 1e7 steps, and any fraction below the slack means nothing at that step count.
    """
    n = round(x)
    return int(n) if abs(x - n) <= 1e-9 + 1e-12 * abs(x) else int(math.ceil(x))


def record_plan(t_end: float, dt: float, record_start: float = 0.0, decimate: int = 1) -> RecordPlan:
    """Steps and records of a run to ``t_end`` (s): ``t_end / dt`` steps, records from the first step at or after
    ``record_start`` (s), every ``decimate``-th (each count by :func:`whole_steps`)."""
    N = whole_steps(t_end / dt)
    first = whole_steps(record_start / dt)
    return RecordPlan(n_steps=N, first=first, every=decimate,
                      n_records=(N - first) // decimate + 1 if first <= N else 0)


def record_rows(model, outputs, states: bool) -> np.ndarray:
    """Rows of the record on the state (q, v): the outputs' rows on q, then, with ``states``, every q and v
    (model coordinates), shape (n_out [+ 2 n], n [or 2 n])."""
    n = model.M.shape[0]
    rows = model.output_rows(outputs) if outputs else np.zeros((0, n))
    if not states:
        return rows
    return np.vstack([np.hstack([rows, np.zeros_like(rows)]), np.eye(2 * n)])


def record_buffers(plan: RecordPlan, rows: np.ndarray, n_p: int) -> kernel.Record:
    """Empty record buffers of the kernel (:class:`~rotorred.transient.kernel.Record`) for ``plan``."""
    n_rec = plan.n_records
    return kernel.Record(rows=np.ascontiguousarray(rows, dtype=float), start=plan.first, every=plan.every,
                         t=np.zeros(n_rec), y=np.zeros((n_rec, len(rows))),
                         plate=np.zeros((n_rec, n_p, kernel.N_PLATE_REC)), state=np.zeros((n_rec, n_p), dtype=np.int8),
                         count=np.zeros(1, dtype=np.int64))



#: the stage line before the step kernel is compiled (not when numba's on-disk cache holds it)
COMPILING_NOTE = "compiling the step kernel, once per install (numba: 10-20 s, then cached on disk)"


def load_kernel(args: tuple, dispatcher=None) -> tuple[float, bool]:
    """Compile the step kernel ``dispatcher`` (default ``kernel.run_steps``) for the types of ``args`` (a call of
    it), or load it from numba's on-disk cache, before the timed loop.

    A compilation is announced by a stage line (:data:`COMPILING_NOTE`, :func:`rotorred.progress.stage`), so
    neither the wait nor the µs per step of the first run after an install hide it. A load from the cache holds
    SIGINT and SIGTERM back (:func:`rotorred.writers.signals_held`, a fraction of a second): a signal inside it came
    back through llvmlite's ctypes callbacks, where Python ignores it, or crashed the interpreter at exit; a
    compilation (tens of seconds, once per install) is left interruptible.

    Returns
    -------
    seconds : float
        The time it took (0 when this process has it) (s).
    compiled : bool
        Whether it was compiled (False: loaded from the cache, or already in this process).
    """
    import numba

    dispatcher = dispatcher or kernel.run_steps
    sig = tuple(numba.typeof(a) for a in args)
    if sig in dispatcher.overloads:
        return 0.0, False
    t0 = time.perf_counter()
    expected = not _cached(dispatcher, sig)  # said before the wait; what happened is read from numba's counters
    if expected:
        stage(COMPILING_NOTE, logger=LOG)
    else:
        LOG.debug("loading the step kernel %s from numba's cache", dispatcher.__name__)
    misses = _misses(dispatcher)
    with contextlib.nullcontext() if expected else signals_held():  # a load cut by a signal leaves llvmlite's
        dispatcher.compile(sig)  # objects half made: Python ignored the interrupt, or crashed at exit (issue 41)
    compiled = expected if misses is None else _misses(dispatcher) > misses
    if compiled and not expected:
        stage("compiled the step kernel: its cache entry could not be loaded", logger=LOG)
    return time.perf_counter() - t0, compiled


def _misses(dispatcher) -> int | None:
    """numba's count of the dispatcher's compilations that its cache could not serve (None if it keeps none)."""
    try:
        return sum(dispatcher.stats.cache_misses.values())
    except AttributeError:
        return None


def _cached(dispatcher, sig) -> bool:
    """Whether numba's on-disk cache holds the kernel for ``sig`` (True when this cannot be told).

    Looks the key up in the cache's index (numba's own key and index, without loading the entry): loading it
    here and again in ``dispatcher.compile`` took 0.4 s a kernel on every warm run.
    """
    try:
        cache = dispatcher._cache
        dispatcher.targetctx.refresh()
        key = cache._index_key(sig, dispatcher.targetctx.codegen())
        return key in cache._cache_file._load_index()
    except Exception:  # noqa: BLE001 - internals of numba: say nothing rather than fail
        return True


def step_bar(n_steps: int, dt: float, progress: bool | None):
    """The progress bar of a transient (:func:`rotorred.progress.bar`): simulated time against its end, with the
    time left; ``progress`` None draws it on a terminal once the run has taken 1 s (a short run draws nothing)."""
    return bar(n_steps * dt, "stepping", "s", progress=progress, delay=0.0 if progress else 1.0,
               bar_format="{desc}: {percentage:3.0f}%|{bar}| t = {n:.4g} of {total:.4g} s [{elapsed}<{remaining}]")


# ----------------------------------------------------------------------------------- 4. result
def package_result(run: Run, plan: RecordPlan, record: kernel.Record, state: kernel.State, diag: kernel.Diagnostics,
                   status: int, times: tuple, n_factorizations: int | None = None,
                   step_form: str = "") -> TransientResult:
    """The :class:`TransientResult` of ``run`` (raises :class:`SimulationDiverged` carrying it if the run failed).

    ``times`` is (setup time, loop wall time, loop CPU time, kernel load time (s), whether the kernel was compiled)
    (:func:`load_kernel`); ``n_factorizations`` defaults to one per step size; with ``run.recording.states`` the
    records after the outputs are (q, v).
    """
    model, scheme, plates, outputs = run.system, run.scheme, run.plates, run.recording.outputs
    n, n_p, counters = len(state.x) // 3, len(plates), diag.counters
    nr = int(record.count[0])
    t_done = int(counters[kernel.C_STEPS]) * run.dt
    success = status == kernel.RUNNING
    if success:
        message = f"finished: {plan.n_steps} steps of {run.dt:g} s"
    else:
        message, dof, cause = failure(model, plates, status, diag.err, run.control.max_halvings, t_done)
    x = state.x
    final = FinalState(t=t_done, q=x[:n].copy(), v=x[n:2 * n].copy(), a=x[2 * n:].copy(), plate=state.ps.copy(),
                       forces=state.z.reshape(n_p, 2).copy(), mode=state.mode.copy(), sgn=state.sgn.copy())
    result = TransientResult(
        t=record.t[:nr].copy(), outputs={o: record.y[:nr, j].copy() for j, o in enumerate(outputs)},
        states=record.y[:nr, len(outputs):].copy() if run.recording.states else None,
        contacts=contact_histories(plates, record), success=success, status=0 if success else int(status),
        message=message, final=final, method=scheme.method, dt=run.dt, gamma=float(scheme.gamma),
        beta=float(scheme.beta), alpha=float(scheme.alpha), n_steps=int(counters[kernel.C_STEPS]),
        n_substeps=int(counters[kernel.C_SUBSTEPS]), n_newton=int(counters[kernel.C_NEWTON]),
        n_contact_steps=int(counters[kernel.C_CONTACT]), max_newton_per_solve=int(counters[kernel.C_MAXNEWTON]),
        n_factorizations=run.control.max_halvings + 1 if n_factorizations is None else n_factorizations,
        n_passes=int(counters[C_PASSES]), step_form=step_form, setup_time=times[0], run_time=times[1], run_cpu_time=times[2],
        kernel_load_time=times[3], kernel_compiled=bool(times[4]))
    if not success:
        raise SimulationDiverged(message, result, float(diag.err[kernel.E_TIME]), dof, cause)
    return result
