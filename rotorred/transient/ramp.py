"""Transient at spool speeds that vary in time: the Python side of :mod:`rotorred.transient.ramp_kernel`.

:func:`rotorred.transient.newmark.simulate` comes here when its ``operating`` is a profile
(:meth:`rotorred.model.operating.Operating.profile`). The run is cut into speed intervals, short enough
that every spool's speed stays within a width of the interval's reference speed (and cut at
the profile's breakpoints, where the acceleration jumps). Per interval the step matrices of
the constant-speed step are built at the reference (one factorisation per step size), with
``R = A_r^-1 [G_s, K_G,s]`` and the bound ``rho`` of the step's fixed-point contraction; the
compiled loop then takes the exact implicit step at the profile's speeds (Eqs. R1-R4 of
docs/model.md).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from rotorred import checks
from rotorred.model.speeds import SpeedProfile
from rotorred.transient import kernel, ramp_kernel, stepping
from rotorred.transient.matrices import (ForceColumns, contact_rows, disk_radii, force_columns, kernel_plates,
                                         newmark_coefficients, plate_parameters, step_levels)
from rotorred.transient.status import RUNNING

#: default bound of the fixed-point contraction per step (sets the speed intervals' width)
RHO_TARGET = 1e-3
#: default relative tolerance of the fixed-point passes on the step's dq
PASS_TOL = 1e-9
#: passes before a step is halved
MAX_PASSES = 8


@dataclass(frozen=True)
class SpeedInterval:
    """Main steps ``begin .. end - 1`` run with the step matrices at one reference.

    Attributes
    ----------
    begin, end : int
        Main step indices.
    ref : ndarray, shape (n_s, 2)
        Reference speed (rad/s) and acceleration (rad/s^2) of each spool.
    delta, epsilon : ndarray, shape (n_s,)
        Largest |Omega - Omega_r| (rad/s) and |Omega' - Omega_r'| (rad/s^2) in the interval.
    """

    begin: int
    end: int
    ref: np.ndarray
    delta: np.ndarray
    epsilon: np.ndarray


def check_profile_run(model, profile: SpeedProfile, scheme) -> dict:
    """The spin-acceleration matrices of the spools (zero for a spool at constant speed); clear errors for a
    model without them or a scheme other than average acceleration."""
    if not scheme.average_acceleration:
        checks.fail("scheme.method", scheme.method, "must be 'newmark' with gamma = 1/2, beta = 1/4 (average "
                    "acceleration) when the speeds vary in time")
    acc = profile.accelerations()
    for t in model.tables:
        if np.any(acc[t.spool] != 0.0):
            checks.fail(f"bearing at node {t.table.node}", "speed-dependent", "is not supported when the speed of "
                        f"spool '{t.spool}' varies in time (a run-up steps with constant bearing matrices); give "
                        "the bearing constant coefficients, or run at constant speeds")
    K_G = {}
    for s in model.spools:
        if s in model.K_G:
            K_G[s] = np.asarray(model.K_G[s], float)
        elif np.any(acc[s] != 0.0):
            checks.fail(f"model.K_G[{s!r}]", None, "is needed when the speed of spool '" + s + "' varies: build the "
                        "model with assemble() or reduce_rotor(), which derive it")
        else:
            K_G[s] = np.zeros_like(model.M)
    return K_G


def speed_intervals(profile: SpeedProfile, spools, n_steps: int, dt: float, width: np.ndarray) -> list[SpeedInterval]:
    """Cut main steps ``0 .. n_steps`` into intervals where each spool's speed stays within ``width`` (rad/s,
    shape (n_s,)) of the reference, cut also at the profile's breakpoints."""
    tk, W, _, _ = profile.kernel_table(spools)
    t_end = n_steps * dt
    cuts = {0, n_steps}
    for k in range(len(tk) - 1):
        ta, tb = tk[k], min(tk[k + 1], t_end)
        if ta >= t_end:
            break
        change = np.abs(W[:, k + 1] - W[:, k]) * (tb - ta) / (tk[k + 1] - tk[k])
        m = max(1, int(np.max(np.ceil(change / (2.0 * width)))))
        for j in range(m + 1):
            cuts.add(min(n_steps, int(round((ta + j * (tb - ta) / m) / dt))))
    edges = sorted(cuts)
    out = []
    for i_a, i_b in zip(edges[:-1], edges[1:]):
        if i_b <= i_a:
            continue
        t = np.unique(np.concatenate([[i_a * dt, i_b * dt], tk[(tk > i_a * dt) & (tk < i_b * dt)]]))
        at_t = profile.speed(t)
        at_mid = profile.at(0.5 * (t[1:] + t[:-1]))  # one time inside each piece of constant acceleration
        speed = np.array([at_t[s] for s in spools])
        acc = np.array([at_mid[s][1] for s in spools])
        lo, hi = speed.min(axis=1), speed.max(axis=1)
        a_ref = profile.at(0.5 * (t[0] + t[-1]))
        ref = np.column_stack([0.5 * (lo + hi), [a_ref[s][1] for s in spools]])
        out.append(SpeedInterval(i_a, i_b, ref, 0.5 * (hi - lo), np.max(np.abs(acc - ref[:, 1:]), axis=1)))
    return out


@dataclass(frozen=True)
class Operators:
    """The model's matrices, split by what the speeds multiply (model coordinates, n DOFs, n_s spools)."""

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    G: np.ndarray    # (n_s, n, n) per unit speed
    K_G: np.ndarray  # (n_s, n, n) per unit acceleration
    N: np.ndarray | None = None  # (n_s, n, n) circulatory stiffness of internal damping, -N_s per unit speed

    @property
    def blocks(self) -> int:
        """Blocks a spool in the pass operator: G, K_G (and -N with internal damping)."""
        return 2 if self.N is None else 3

    def D(self, speeds) -> np.ndarray:
        """``C + sum_s Omega_s G_s`` for speeds of shape (n_s,)."""
        return self.C + np.tensordot(speeds, self.G, axes=1)

    def K_of(self, speeds, accelerations) -> np.ndarray:
        """``K + sum_s Omega_s' K_G,s - sum_s Omega_s N_s`` for speeds and accelerations of shape (n_s,)."""
        K = self.K + np.tensordot(accelerations, self.K_G, axes=1)
        return K if self.N is None else K - np.tensordot(speeds, self.N, axes=1)

    def speed_blocks(self) -> np.ndarray:
        """``[G_0, K_G,0, G_1, K_G,1, ..., (-N_0, -N_1, ...)]``, shape (n, blocks n_s n)."""
        blocks = [m for s in range(len(self.G)) for m in (self.G[s], self.K_G[s])]
        return np.hstack(blocks + ([] if self.N is None else [-N_s for N_s in self.N]))


def operators(model, K_G: dict) -> Operators:
    """The :class:`Operators` of ``model`` (spin-acceleration matrices ``K_G`` of :func:`check_profile_run`): its
    internal damping (docs/model.md §19) in ``C`` and, per spool, the circulatory ``N_s`` (a loss factor at the
    model's ``loss_frequency``)."""
    spools = model.spools
    C_r, _ = model.rotating_damping({})
    N = None
    if model.rotating:
        zero = np.zeros_like(model.M)
        N = np.array([model.rotating[s].at(model.loss_frequency)[1] if s in model.rotating else zero for s in spools])
    return Operators(M=np.asarray(model.M, float), C=np.asarray(model.C + C_r, float), K=np.asarray(model.K, float),
                     G=np.array([model.G[s] for s in spools], float), K_G=np.array([K_G[s] for s in spools]), N=N)


def _pass_operators(ops: Operators, ref: np.ndarray, dt: float, n_levels: int) -> tuple[np.ndarray, np.ndarray]:
    """``R`` per level (shape (L, n, b n_s n)) and the infinity norms of its blocks (shape (L, n_s, b)), b =
    ``ops.blocks``: for spool s its G and K_G blocks, then its -N block among the last n_s."""
    D, K, blocks = ops.D(ref[:, 0]), ops.K_of(ref[:, 0], ref[:, 1]), ops.speed_blocks()
    n, n_s, b = len(D), len(ops.G), ops.blocks
    R, norms = [], []
    for level in range(n_levels):
        c = newmark_coefficients(dt / 2**level, 0.5, 0.25)
        Rl = sla.lu_solve(sla.lu_factor(c[0] * ops.M + c[3] * D + K, check_finite=False), blocks, check_finite=False)
        R.append(Rl)
        columns = [[2 * s + j for j in (0, 1)] + ([2 * n_s + s] if b == 3 else []) for s in range(n_s)]
        norms.append([[np.abs(Rl[:, k * n:(k + 1) * n]).sum(axis=1).max() for k in blocks_of] for blocks_of in columns])
    return np.ascontiguousarray(np.array(R)), np.array(norms)


def interval_widths(ops: Operators, ref: np.ndarray, dt: float, rho_target: float) -> np.ndarray:
    """Speed widths (rad/s, shape (n_s,)) that keep the contraction's speed part at ``rho_target``."""
    _, norms = _pass_operators(ops, ref, dt, 1)
    c3 = 2.0 / dt
    n_s = len(ops.G)
    speed_part = c3 * norms[0, :, 0] + (norms[0, :, 2] if ops.blocks == 3 else 0.0)
    return rho_target / (n_s * np.maximum(speed_part, 1e-300))


def interval_state(ops: Operators, B, forces: ForceColumns, plates, interval: SpeedInterval, dt: float,
                   n_levels: int) -> tuple[kernel.Levels, np.ndarray, np.ndarray]:
    """Levels at the interval's reference, ``R`` and the contraction bound ``rho`` per level."""
    D, K = ops.D(interval.ref[:, 0]), ops.K_of(interval.ref[:, 0], interval.ref[:, 1])
    levels = step_levels(ops.M, D, K, B, forces, plates, dt, 0.5, 0.25, 0.0, n_levels)
    R, norms = _pass_operators(ops, interval.ref, dt, n_levels)
    c3 = levels.coef[:, 3]
    rho = (c3 * (norms[:, :, 0] @ interval.delta) + norms[:, :, 1] @ interval.epsilon)
    if ops.blocks == 3:
        rho = rho + norms[:, :, 2] @ interval.delta
    return levels, R, rho


def profile_table(profile: SpeedProfile, spools, forces: ForceColumns) -> ramp_kernel.ProfileTable:
    """The compiled step's :class:`~rotorred.transient.ramp_kernel.ProfileTable` of ``profile`` and ``forces``."""
    tk, W, Wd, Phi = profile.kernel_table(spools)
    index = {s: j for j, s in enumerate(spools)}
    return ramp_kernel.ProfileTable(
        tk=tk, W=W, Wd=Wd, Phi=Phi,
        force_spool=np.array([-1 if s is None else index[s] for s in forces.spool], dtype=np.int64),
        force_kind=np.array(forces.kind, dtype=np.int64))


def forces_at(forces: ForceColumns, table: ramp_kernel.ProfileTable, t) -> np.ndarray:
    """The external forces at times ``t`` (N), shape (len(t), n), with the step's own time functions (Eq. R3)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    weights = np.zeros((len(t), len(forces.kind)))
    ramp_kernel.force_weights(t, table, weights)
    return weights @ forces.F.T


def run_profile(run: stepping.Run, rho_target: float = RHO_TARGET, pass_tol: float = PASS_TOL,
                max_passes: int = MAX_PASSES):
    """The transient of :func:`rotorred.transient.newmark.simulate` at the speeds of ``run.profile``.

    Parameters
    ----------
    run : rotorred.transient.stepping.Run
        The checked run, its ``profile`` giving every spool's speed in time.
    rho_target : float
        Bound of the fixed-point contraction per step (-), which sets the speed intervals' width.
    pass_tol : float
        Relative tolerance of the fixed-point passes on the step's dq (-).
    max_passes : int
        Passes before a step is halved.

    Returns
    -------
    TransientResult
        With ``n_factorizations`` the step matrices built (intervals x step sizes) and
        ``n_passes`` the fixed-point passes of all steps.
    """
    t_setup = time.perf_counter()
    model, profile, control = run.system, run.profile, run.control
    K_G = check_profile_run(model, profile, run.scheme)
    spools = model.spools
    ops = operators(model, K_G)
    # 1. forces per unit Omega^2 (gravity: constant), plates at the speeds of t = 0
    forces = force_columns(model, {s: 1.0 for s in spools}, run.spool_of, run.loads.unbalances, run.loads.gravity)
    constant = ForceColumns(F=forces.F, kind=np.zeros(len(forces.kind), dtype=np.int64),
                            omega=np.zeros(len(forces.kind)), spool=forces.spool)
    par, atol = plate_parameters(run.plates, run.speeds, run.spool_of, run.rotor, control.newton_tol)
    B = contact_rows(model, run.plates)
    contact = kernel_plates(ops.M, B, par, atol)
    index = {s: j for j, s in enumerate(spools)}
    tables = dict(profile=profile_table(profile, spools, forces),
                  plate_spool=np.array([index[run.spool_of[p.node]] for p in run.plates], dtype=np.int64),
                  plate_radius=np.array(disk_radii(run.plates, run.rotor), dtype=float), tol=float(pass_tol),
                  max_passes=int(max_passes))
    # 2. the state at t = 0 (equation of motion at the speeds and accelerations of t = 0)
    s0 = profile.at(0.0)
    W0, A0 = np.array([s0[s][0] for s in spools]), np.array([s0[s][1] for s in spools])
    F0 = ForceColumns(F=forces_at(forces, tables["profile"], 0.0).T, kind=np.zeros(1, dtype=np.int64),
                      omega=np.zeros(1))
    state = stepping.initial_state(ops.M, ops.D(W0), ops.K_of(W0, A0), B, par, run.plates, F0, run.x0, run.start)
    # 3. record plan and speed intervals
    plan = stepping.record_plan(run.t_end, run.dt, run.recording.start, run.recording.decimate)
    rows = stepping.record_rows(model, run.recording.outputs, run.recording.states)
    record = stepping.record_buffers(plan, rows, len(run.plates))
    n_levels = control.max_halvings + 1
    widths = interval_widths(ops, np.column_stack([W0, A0]), run.dt, rho_target)
    intervals = speed_intervals(profile, spools, plan.n_steps, run.dt, widths)
    setup_time = time.perf_counter() - t_setup
    # 4. run interval by interval
    settings = kernel.Settings(t0=0.0, dt=run.dt, n_halvings=control.max_halvings, newton_tol=control.newton_tol,
                               max_newton=control.max_newton, limit=control.displacement_limit)
    diag = kernel.Diagnostics(counters=np.zeros(kernel.N_COUNTERS, dtype=np.int64), err=np.zeros(4))
    status, times, interrupt = _run_intervals(ops, B, constant, run.plates, intervals, tables, contact, state,
                                              record, settings, diag, plan.n_steps, n_levels, control.chunk_steps,
                                              control.progress)
    # 5. package (the state-recording rows after the outputs)
    result = stepping.package_result(run, plan, record, state, diag, status, (setup_time + times[0], *times[1:]),
                                     n_factorizations=len(intervals) * n_levels)
    if interrupt is not None:
        raise _with_record(interrupt, result, plan.n_steps * run.dt)
    return result


#: the attribute of a signal's exception that ended a run at varying speeds: the record up to there
#: (:func:`interrupted_record`)
RECORD_ATTRIBUTE = "record_until_interrupt"


def interrupted_record(exc: BaseException):
    """The record up to the signal whose exception ``exc`` ended a run at varying speeds (raised again by
    :func:`run_profile` with it), or None.

    Parameters
    ----------
    exc : BaseException
        SIGINT's ``KeyboardInterrupt``, or a caller's SIGTERM exception.

    Returns
    -------
    TransientResult or None
        ``success`` False, ``status`` 0, ``message`` saying when it stopped, the record and ``final`` at the last step
        taken (``n_steps`` of them).
    """
    return getattr(exc, RECORD_ATTRIBUTE, None)


def _with_record(interrupt: BaseException, result, t_end: float) -> BaseException:
    """``interrupt`` carrying ``result`` (finished up to its last step) marked as interrupted there."""
    import dataclasses

    message = (f"interrupted ({type(interrupt).__name__}) at t = {result.final.t:.9g} s of {t_end:.9g} s; results "
               f"kept up to there")
    setattr(interrupt, RECORD_ATTRIBUTE, dataclasses.replace(result, success=False, message=message))
    return interrupt


def _interrupt(exc: BaseException) -> bool:
    """Whether ``exc`` is a signal's exception: a ``BaseException`` that is neither an error nor an exit (SIGINT's
    ``KeyboardInterrupt``, the command line's SIGTERM exception)."""
    return not isinstance(exc, (Exception, SystemExit, GeneratorExit))


def _run_intervals(ops, B, forces, plates, intervals, tables, contact, state, record, settings, diag, n_steps,
                   n_levels, chunk_steps, progress):
    """The compiled loop over every interval, in chunks, with a progress bar; (status, (build, wall, cpu, load,
    compiled), interrupt): the intervals' set-up, the loop's wall and CPU time, the kernel's load (s), whether it
    compiled, and the signal's exception (:func:`_interrupt`) that stopped the loop between two compiled calls (the
    record and state then hold every step taken), or None. A signal is answered in Python between chunks: at most one
    chunk after it came."""
    spare = kernel.spare_state(state)
    n, n_s = len(ops.M), len(ops.G)
    work = kernel.work_arrays(n, len(plates), len(forces.kind))
    rwork = ramp_kernel.ramp_work(n, n_s, len(forces.kind), ops.blocks)
    chunk = chunk_steps or max(2000, min(n_steps, 100_000))
    status, build, load, compiled = RUNNING, 0.0, 0.0, False
    wall = cpu = 0.0
    interrupt = None
    with stepping.step_bar(n_steps, settings.dt, progress) as shown:
        for interval in intervals:
            t_build = time.perf_counter()
            try:
                levels, R, rho = interval_state(ops, B, forces, plates, interval, settings.dt, n_levels)
                var = ramp_kernel.Varying(R=R, rho=rho, ref=np.ascontiguousarray(interval.ref), **tables)
                build += time.perf_counter() - t_build
                args = (0, 0, levels, var, contact, state, spare, work, rwork, record, settings, diag)
                seconds, new = stepping.load_kernel(args, ramp_kernel.run_ramp_steps)
            except BaseException as exc:  # noqa: BLE001 -- a signal's exception ends the run here; others are raised
                if not _interrupt(exc):
                    raise
                interrupt = exc
                break
            load, compiled = load + seconds, compiled or new
            t_run, cpu_run = time.perf_counter(), time.process_time()
            i = interval.begin
            try:
                while i < interval.end:
                    i_next = min(interval.end, i + chunk)
                    status = ramp_kernel.run_ramp_steps(i, i_next, levels, var, contact, state, spare, work, rwork,
                                                        record, settings, diag)
                    if status != RUNNING:
                        break
                    shown.update((i_next - i) * settings.dt)
                    i = i_next
            except BaseException as exc:  # noqa: BLE001 -- as above: the steps taken are in record and state
                if not _interrupt(exc):
                    raise
                interrupt = exc
            wall += time.perf_counter() - t_run
            cpu += time.process_time() - cpu_run
            if status != RUNNING or interrupt is not None:
                break
    return status, (build, wall, cpu, load, compiled), interrupt
