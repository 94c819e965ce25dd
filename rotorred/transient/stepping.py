"""What every compiled step loop shares (:func:`rotorred.transient.newmark.simulate` at constant speeds,
:mod:`rotorred.transient.ramp` at varying ones): the checked options, the initial state, the record
plan and buffers, loading the kernel, the progress bar and the packaging of the result."""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
import scipy.linalg as sla

from rotorred import checks
from rotorred.progress import bar, stage
from rotorred.transient import kernel
from rotorred.transient.contact import OPEN, SLIP, STICK, RubPlate, disk_force, normal_force
from rotorred.transient.contact_solve import C_PASSES
from rotorred.model.loads import Unbalance
from rotorred.transient.matrices import ForceColumns
from rotorred.transient.results import (FinalState, SimulationDiverged, TransientResult, contact_histories,
                                        failure)

LOG = logging.getLogger(__name__)

METHODS = ("newmark", "hht")


# ----------------------------------------------------------------------------------- 1. options
@dataclass(frozen=True)
class Scheme:
    """The time-integration scheme: ``method`` and its gamma, beta, alpha (-)."""

    method: str
    gamma: float
    beta: float
    alpha: float


def check_scheme(method, gamma, beta, alpha) -> Scheme:
    """Newmark (gamma >= 1/2, beta > 0; default average acceleration) or HHT-α (-1/3 <= alpha <= 0)."""
    checks.choice("method", method, METHODS)
    if method == "newmark":
        if alpha is not None:
            checks.fail("alpha", alpha, "must not be given with method = 'newmark' (it applies to 'hht' only)")
        gamma = checks.number("gamma", 0.5 if gamma is None else gamma, ge=0.5)
        beta = checks.positive("beta", 0.25 if beta is None else beta)
        return Scheme(method, gamma, beta, 0.0)
    for name, value in (("gamma", gamma), ("beta", beta)):
        if value is not None:
            checks.fail(name, value, "must not be given with method = 'hht' (it follows from alpha)")
    alpha = checks.number("alpha", -0.05 if alpha is None else alpha, ge=-1.0 / 3.0, le=0.0)
    return Scheme(method, 0.5 - alpha, 0.25 * (1.0 - alpha) ** 2, alpha)


@dataclass(frozen=True)
class RunOptions:
    """Checked run options of :func:`simulate` (same names and units)."""

    t_end: float
    dt: float
    record_start: float
    decimate: int
    newton_tol: float
    max_newton: int
    max_halvings: int
    displacement_limit: float
    gravity: float | None
    chunk_steps: int | None


def check_run_options(t_end, dt, record_start, decimate, newton_tol, max_newton, max_halvings, displacement_limit,
                      gravity, chunk_steps) -> RunOptions:
    """Every scalar option of :func:`simulate`, checked with :mod:`rotorred.checks`."""
    t_end = checks.positive("t_end", t_end, "s")
    dt = checks.positive("dt", dt, "s")
    if dt > t_end:
        checks.fail("dt", dt, f"must not exceed t_end = {t_end!r}", "s")
    return RunOptions(
        t_end=t_end, dt=dt, record_start=checks.number("record_start", record_start, "s", ge=0.0, le=t_end),
        decimate=checks.integer("decimate", decimate, ge=1),
        newton_tol=checks.positive("newton_tol", newton_tol),
        max_newton=checks.integer("max_newton", max_newton, ge=1),
        max_halvings=checks.integer("max_halvings", max_halvings, ge=0),
        displacement_limit=checks.positive("displacement_limit", displacement_limit, "m"),
        gravity=None if gravity is None else checks.number("gravity", gravity, "m/s^2"),
        chunk_steps=None if chunk_steps is None else checks.integer("chunk_steps", chunk_steps, ge=1))


@dataclass(frozen=True)
class Loads:
    """Checked speeds (rad/s), spool map, plates, unbalances and outputs of :func:`simulate`."""

    speeds: dict
    spool_of: Mapping[int, str] | None
    plates: tuple
    unbalances: tuple
    outputs: tuple


def check_loads(model, speeds, rotor, spool_of, plates, unbalances, outputs) -> Loads:
    """Speeds of every spool, the spool of each loaded node, plates and unbalances of the right types."""
    if speeds is None:
        if rotor is None:
            raise checks.InputError("speeds", checks.MISSING, "required when no rotor is given", "rad/s")
        speeds = rotor.speeds
    speeds = {str(s): checks.non_negative(f"speeds[{s!r}]", w, "rad/s") for s, w in dict(speeds).items()}
    spools = tuple(model.G)
    missing = [s for s in spools if s not in speeds]
    if missing:
        checks.fail("speeds", speeds, f"must give the speed of every spool; missing {missing}", "rad/s")
    if spool_of is None and rotor is not None:
        spool_of = rotor.spool_of
    if spool_of is None and len(spools) == 1:
        spool_of = {n: spools[0] for n in model.full_dofs.nodes}
    outputs = tuple(model.full_dofs.checked_outputs(outputs))
    plates, unbalances = tuple(plates), tuple(unbalances)
    for name, items, cls in (("plates", plates, RubPlate), ("unbalances", unbalances, Unbalance)):
        for k, item in enumerate(items):
            if not isinstance(item, cls):
                checks.fail(f"{name}[{k}]", item, f"must be a {cls.__name__}")
    if (plates or unbalances) and spool_of is None:
        raise checks.InputError("spool_of", checks.MISSING, "required (or rotor) to know the spool of the nodes "
                                "of unbalances and plates")
    return Loads(speeds, spool_of, plates, unbalances, outputs)


def initial_vector(n: int, q0, v0, start: FinalState | None = None) -> np.ndarray:
    """(q0, v0, 0), shape (3 n,), from the optional initial displacement and velocity or the ``start`` state
    (model coordinates)."""
    if start is not None:
        if q0 is not None or v0 is not None:
            checks.fail("start", "a FinalState", "must not be given with q0 or v0 (it holds both)")
        q0, v0 = start.q, start.v
    x0 = np.zeros(3 * n)
    for name, vec, off in (("q0", q0, 0), ("v0", v0, n)):
        if vec is not None:
            x0[off:off + n] = checks.array(name if start is None else f"start.{name[0]}", vec, (n,))
    return x0


def check_start(start: FinalState | None, n_p: int) -> None:
    """A continued run's plates are the run's plates: ``start`` holds the state of ``n_p`` plates."""
    if start is None:
        return
    if not isinstance(start, FinalState):
        checks.fail("start", type(start).__name__, "must be a FinalState (another run's `final`)")
    shapes = {"plate": (n_p, 2, 3), "forces": (n_p, 2), "mode": (n_p,), "sgn": (n_p,)}
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


def record_plan(t_end: float, dt: float, record_start: float, decimate: int) -> RecordPlan:
    """Steps and records of a run to ``t_end`` (s): ``t_end / dt`` steps, records from the first step at or after
    ``record_start`` (s), every ``decimate``-th (each count by :func:`whole_steps`)."""
    N = whole_steps(t_end / dt)
    first = whole_steps(record_start / dt)
    return RecordPlan(n_steps=N, first=first, every=decimate,
                      n_records=(N - first) // decimate + 1 if first <= N else 0)


def record_rows(model, outputs, record_state: bool) -> np.ndarray:
    """Rows of the record on the state (q, v): the outputs' rows on q, then, with ``record_state``, every q and v
    (model coordinates), shape (n_out [+ 2 n], n [or 2 n])."""
    n = model.M.shape[0]
    rows = model.output_rows(outputs) if outputs else np.zeros((0, n))
    if not record_state:
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
    neither the wait nor the µs per step of the first run after an install hide it.

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
    dispatcher.compile(sig)
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
def package_result(model, scheme: Scheme, run: RunOptions, loads: Loads, plan: RecordPlan, record: kernel.Record,
                   state: kernel.State, diag: kernel.Diagnostics, status: int, times: tuple,
                   n_factorizations: int | None = None, record_state: bool = False,
                   step_form: str = "") -> TransientResult:
    """The :class:`TransientResult` of a run (raises :class:`SimulationDiverged` carrying it if the run failed).

    ``times`` is (setup time, loop wall time, loop CPU time, kernel load time (s), whether the kernel was compiled)
    (:func:`load_kernel`); ``n_factorizations``
    defaults to one per step size; with ``record_state`` the records after the outputs are (q, v).
    """
    n, n_p, counters = len(state.x) // 3, len(loads.plates), diag.counters
    nr = int(record.count[0])
    t_done = int(counters[kernel.C_STEPS]) * run.dt
    success = status == kernel.RUNNING
    if success:
        message = f"finished: {plan.n_steps} steps of {run.dt:g} s"
    else:
        message, dof, cause = failure(model, loads.plates, status, diag.err, run.max_halvings, t_done)
    x = state.x
    final = FinalState(t=t_done, q=x[:n].copy(), v=x[n:2 * n].copy(), a=x[2 * n:].copy(), plate=state.ps.copy(),
                       forces=state.z.reshape(n_p, 2).copy(), mode=state.mode.copy(), sgn=state.sgn.copy())
    result = TransientResult(
        t=record.t[:nr].copy(), outputs={o: record.y[:nr, j].copy() for j, o in enumerate(loads.outputs)},
        states=record.y[:nr, len(loads.outputs):].copy() if record_state else None,
        contacts=contact_histories(loads.plates, record), success=success, status=0 if success else int(status),
        message=message, final=final, method=scheme.method, dt=run.dt, gamma=float(scheme.gamma),
        beta=float(scheme.beta), alpha=float(scheme.alpha), n_steps=int(counters[kernel.C_STEPS]),
        n_substeps=int(counters[kernel.C_SUBSTEPS]), n_newton=int(counters[kernel.C_NEWTON]),
        n_contact_steps=int(counters[kernel.C_CONTACT]), max_newton_per_solve=int(counters[kernel.C_MAXNEWTON]),
        n_factorizations=run.max_halvings + 1 if n_factorizations is None else n_factorizations,
        n_passes=int(counters[C_PASSES]), step_form=step_form, setup_time=times[0], run_time=times[1], run_cpu_time=times[2],
        kernel_load_time=times[3], kernel_compiled=bool(times[4]))
    if not success:
        raise SimulationDiverged(message, result, float(diag.err[kernel.E_TIME]), dof, cause)
    return result
