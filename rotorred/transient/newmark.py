"""Newmark-β / HHT-α transient of a (reduced) rotor with rub-impact plates.

Solves (Xu et al. 2016, Eq. 13, with two spools)

    M q'' + (C + Omega_L G_L + Omega_H G_H) q' + K q = F_unbalance(t) + F_gravity + F_contact(q, q')

together with the rigid-body motion of every rubbing plate (Eq. 7), at constant spool speeds.
``simulate`` is the entry point (in the style of ``scipy.integrate.solve_ivp``): it builds the
constant step matrices once and runs the compiled step loop of :mod:`rotorred.transient.kernel`.

Each step is the exact implicit Newmark (or HHT-α) step of the nonlinear system: the
linear step is condensed onto the contact DOFs (the disk centre x, y of each plate's node)
and the plates' rigid DOFs, and the small nonlinear contact system is solved by Newton with
the law's analytic tangent and a Coulomb active set (see :mod:`rotorred.transient.kernel`). No
contact force is lagged. A step that fails (Newton not converging, a non-finite value) is
redone as two half steps, recursively up to ``max_halvings`` times; if that cannot cure it,
:class:`SimulationDiverged` is raised, carrying every result computed until then.

Contact in each step (details in :mod:`rotorred.transient.kernel`)
--------------------------------------------------------
* Condensation: ``q_new = q_lin + (1 + alpha) A^-1 B f`` with ``f`` the contact forces on the
  disk centres; the plates' rigid DOFs (scalar Newmark oscillators) are condensed likewise, so
  penetration, its rate and the sliding velocity are affine in the unknown forces
  ``z = (P_k, T_k)`` of the plates, coupled through ``B^T A^-1 B``.
* Newton on ``z`` with the analytic tangent of the law (``derivations/contact.py``), backtracking
  on the residual norm; start: the extrapolation of the last two steps' forces.
* Coulomb friction by an active set, without regularisation: a slipping plate has
  ``T = -mu_d P sign(v_rel)``; if the converged ``v_rel`` has reversed within the step, the
  plate sticks (``v_rel = 0`` is its equation); a sticking plate whose required force exceeds
  ``mu_s P`` slips against it. Repeated until consistent (at most 8 passes).
* With the average-acceleration rule a velocity constraint makes the constraint force
  alternate from step to step (``a_rel(n+1) = -a_rel(n)``); after every Newmark step the stick
  forces are corrected, at fixed q and v, to zero relative acceleration (equilibrium kept).

Methods
-------
``"newmark"``: the Newmark-β family, average acceleration (gamma = 1/2, beta = 1/4) by default
(unconditionally stable, no numerical damping, second order).
``"hht"``: Hilber–Hughes–Taylor α (-1/3 <= alpha <= 0; gamma = 1/2 - alpha, beta = (1 - alpha)^2 / 4),
second order, damping the highest modes; the contact force enters like every force,
``(1 + alpha) f_{n+1} - alpha f_n``, with the contact law holding at ``t_{n+1}``.

References
----------
N. M. Newmark, J. Eng. Mech. Div. ASCE 85 (1959) 67-94.
H. M. Hilber, T. J. R. Hughes, R. L. Taylor, Earthquake Eng. Struct. Dyn. 5 (1977) 283-292.
K. H. Hunt, F. R. E. Crossley, J. Appl. Mech. 42 (1975) 440-445.
"""

from __future__ import annotations

import time
from typing import Mapping, Sequence

import numpy as np

from rotorred import checks
from rotorred.model.loads import Unbalance
from rotorred.model.speeds import SpeedProfile
from rotorred.transient import eigen_kernel, kernel
from rotorred.transient.eigenstep import eigen_form, rows_on_y, scheme_excluded, with_record_rows
from rotorred.transient.contact import OPEN, SLIP, STICK, RubPlate
from rotorred.transient.matrices import (contact_rows, force_columns, kernel_plates, newmark_coefficients,
                                         plate_parameters, step_levels, step_matrices)
from rotorred.transient.ramp import run_profile
from rotorred.transient.results import ContactHistory, FinalState, SimulationDiverged, TransientResult
from rotorred.transient.status import NEED_DENSE, NEED_LEVELS, RUNNING
from rotorred.transient.stepping import (  # noqa: F401 - the pipeline's pieces, also read as newmark.<name>
    COMPILING_NOTE, METHODS, Loads, RecordPlan, RunOptions, Scheme, check_loads, check_run_options, check_scheme,
    check_start, initial_state, initial_vector, load_kernel, package_result, record_buffers, record_plan,
    record_rows, step_bar, whole_steps)


def run_kernel(levels: kernel.Levels, forcing: kernel.Forcing, plates: kernel.Plates, state: kernel.State,
               record: kernel.Record, settings: kernel.Settings, diag: kernel.Diagnostics, n_steps: int,
               chunk: int, progress: bool | None, eig=None, every_level=None,
               dense_record: kernel.Record | None = None) -> tuple[int, float, float, float, bool]:
    """Run the compiled loop over ``n_steps`` main steps in chunks of ``chunk``, with an optional progress bar:
    the eigenbasis loop (:mod:`rotorred.transient.eigen_kernel`) when ``eig`` is given (``record.rows`` then act
    on its state y; ``dense_record`` is the same record with the rows on x), else the dense one.

    ``levels`` may hold level 0 only, with ``every_level()`` building every level: a loop then stops at the
    first step that needs halving (``NEED_LEVELS``), and goes on from that step with all of them. A
    step the eigenbasis loop cannot take (``NEED_DENSE``) is taken by the dense loop (compiled or loaded
    when first needed), and the eigenbasis loop goes on from the next step.

    Returns
    -------
    status : int
        The kernel's status (``RUNNING`` when every step completed).
    run_time, run_cpu_time : float
        Wall and CPU time of the loop (s).
    load_time : float
        Time to compile or load the kernels (s, :func:`load_kernel`).
    compiled : bool
        Whether a kernel was compiled (not loaded from numba's cache).
    """
    loops = _Loops(levels, forcing, plates, state, record, dense_record or record, settings, diag, eig, every_level)
    t_run, cpu_run = time.perf_counter(), time.process_time()
    status, i = RUNNING, 0
    with step_bar(n_steps, settings.dt, progress) as shown:
        while i < n_steps:
            i_next = min(n_steps, i + chunk)
            status = loops.run(i, i_next)
            if status != RUNNING:
                break
            shown.update((i_next - i) * settings.dt)
            i = i_next
    run_time = time.perf_counter() - t_run - loops.dense_load_time
    return (status, run_time, time.process_time() - cpu_run - loops.dense_load_time, loops.load_time,
            loops.compiled)


class _Loops:
    """The compiled loops of one run and what they share; :meth:`run` advances main steps ``i .. i_next - 1``,
    answering the loops' requests (every halving level, a dense step)."""

    def __init__(self, levels, forcing, plates, state, record, dense_record, settings, diag, eig, every_level):
        self.levels, self.every_level, self.eig, self.diag = levels, every_level, eig, diag
        spare = kernel.spare_state(state)
        work = kernel.work_arrays(len(state.x) // 3, len(plates.par), len(forcing.kind))
        self.shared = (forcing, plates, state, spare, work)
        self.records, self.settings = (record, dense_record), settings
        self.ework = None if eig is None else eigen_kernel.eigen_work(len(state.x) // 3, len(eig.omega))
        self.dense_loaded, self.dense_load_time = eig is None, 0.0
        self.load_time, self.compiled = load_kernel((0, 0, *self._args()), self._loop())

    def _loop(self):
        return kernel.run_steps if self.eig is None else eigen_kernel.run_eigen_steps

    def _args(self, dense: bool = False) -> tuple:
        forcing, plates, state, spare, work = self.shared
        if dense or self.eig is None:
            return (self.levels, forcing, plates, state, spare, work, self.records[1 if dense else 0], self.settings,
                    self.diag)
        return (self.levels, self.eig, forcing, plates, state, spare, work, self.ework, self.records[0], self.settings,
                self.diag)

    def _steps_done(self) -> int:
        return int(self.diag.counters[kernel.C_STEPS])

    def run(self, i: int, i_next: int) -> int:
        while i < i_next:
            status = self._loop()(i, i_next, *self._args())
            if status == NEED_LEVELS and self.every_level is not None:
                self._build_levels()
            elif status == NEED_DENSE:
                status = self._dense_step(self._steps_done())
                if status != RUNNING:
                    return status
            else:
                return status
            i = self._steps_done()
        return RUNNING

    def _build_levels(self) -> None:
        self.levels, self.every_level = self.every_level(), None

    def _dense_step(self, i: int) -> int:
        """Main step ``i`` by the dense loop (its halvings), recorded on x."""
        if not self.dense_loaded:
            self.dense_load_time, compiled = load_kernel((0, 0, *self._args(dense=True)), kernel.run_steps)
            self.load_time += self.dense_load_time
            self.compiled |= compiled
            self.dense_loaded = True
        while True:
            status = kernel.run_steps(i, i + 1, *self._args(dense=True))
            if status != NEED_LEVELS or self.every_level is None:
                return status
            self._build_levels()



# ----------------------------------------------------------------------------------- the pipeline
def simulate(model, speeds: Mapping[str, float] | SpeedProfile | None, t_end: float, dt: float = 1e-5, *,
             unbalances: Sequence[Unbalance] = (), plates: Sequence[RubPlate] = (), rotor=None,
             spool_of: Mapping[int, str] | None = None, outputs: Sequence[tuple[int, str]] = (),
             record_start: float = 0.0, decimate: int = 1, method: str = "newmark",
             gamma: float | None = None, beta: float | None = None, alpha: float | None = None,
             gravity: float | None = None, q0=None, v0=None, start: FinalState | None = None,
             progress: bool | None = None,
             newton_tol: float = 1e-10, max_newton: int = 50, max_halvings: int = 4,
             displacement_limit: float = 1.0, chunk_steps: int | None = None, record_state: bool = False,
             step: str = "auto", **unknown) -> TransientResult:
    """Transient response with unbalance, optional gravity and rub-impact plates.

    Parameters
    ----------
    model : SystemMatrices or ReducedSystem
        Anything with ``M, K, damping(speeds), output_rows(outputs)``.
    speeds : dict of str to float, SpeedProfile or None
        Constant spool speeds (rad/s); None takes ``rotor.speeds``. A
        :class:`~rotorred.model.speeds.SpeedProfile` runs the speeds it gives in time (a run-up or
        coast-down, :mod:`rotorred.transient.ramp`): gyroscopic terms at ``Omega_s(t)``, the spin
        acceleration terms ``Omega_s' K_G,s``, unbalance forces with their tangential part at the
        spin angle ``int Omega_s dt`` (docs/model.md, Eqs. R1-R4); average-acceleration Newmark only.
    t_end : float
        End time (s); the run starts at t = 0.
    dt : float
        Time step (s); default 1e-5.
    unbalances : sequence of Unbalance
        Each rotates at the speed of its node's spool, with its phase (rotorred.model.loads).
    plates : sequence of RubPlate
        Rubbing plates; several may face the same or different disks.
    rotor : Rotor, optional
        Supplies ``spool_of``, the default ``speeds`` and the disk radius of plates without
        ``disk_radius``.
    spool_of : dict of int to str, optional
        Spool of each node (needed with unbalances or plates when ``rotor`` is not given).
    outputs : sequence of (int, str)
        (node, direction) pairs to record.
    record_start : float
        Record from this time on (s).
    decimate : int
        Record every ``decimate``-th step.
    method : {"newmark", "hht"}
    gamma, beta : float, optional
        Newmark parameters (default 1/2, 1/4); gamma >= 1/2, beta > 0. Not with "hht".
    alpha : float, optional
        HHT-α parameter, -1/3 <= alpha <= 0 (default -0.05); only with "hht".
    gravity : float, optional
        Gravity acceleration along -y (m/s^2), e.g. 9.81.
    q0, v0 : array_like, shape (n,), optional
        Initial displacement and velocity in model coordinates (default 0).
    start : FinalState, optional
        Continue another run from its ``final`` state, in place of ``q0, v0``: its displacement,
        velocity, the plates' own states, the contact forces and slip modes are carried over
        (the plates must be the same); the time restarts at 0, so give each unbalance the angle
        it had reached. The speeds may differ (a map's next point).
    progress : bool, optional
        Progress bar on stderr; default: shown once a run has taken more than 2 s.
    newton_tol : float
        Relative step tolerance of the contact Newton iteration.
    max_newton : int
        Newton iterations per solve before the step is halved.
    max_halvings : int
        How many times a failing step may be halved.
    displacement_limit : float
        A contact-node displacement beyond this (m) is reported as divergence.
    chunk_steps : int, optional
        Steps per compiled call (progress granularity).
    record_state : bool
        Also record the whole state (q, v) in model coordinates (``result.states``), e.g. for
        :func:`rotorred.transient.energy.energy_balance`.
    step : {"auto", "eigen", "dense"}
        Constant speeds: ``"eigen"`` steps the linear part in the eigenbasis of the average-acceleration
        amplification matrix, O(n) per step (:mod:`rotorred.transient.eigen_kernel`), the same recurrence as
        ``"dense"`` (O(n^2)) to rounding; ``"auto"`` (default) takes it wherever it applies and falls back to
        the dense step where the scheme is not average acceleration or the matrix is (nearly) defective.
        ``result.step_form`` says which ran and why.

    Returns
    -------
    TransientResult

    Raises
    ------
    TypeError
        For an unknown option.
    rotorred.checks.InputError
        (a ValueError) For a bad value, before any computation, naming the parameter:
        ``dt = -0.0001: must be > 0 (s)``.
    SimulationDiverged
        When a step cannot be completed; ``.result`` holds the partial result.
    """
    if unknown:
        raise TypeError(f"simulate() got unknown option(s) {sorted(unknown)}")
    t_setup = time.perf_counter()
    # 1. validate the options
    scheme = check_scheme(method, gamma, beta, alpha)
    run = check_run_options(t_end, dt, record_start, decimate, newton_tol, max_newton, max_halvings,
                            displacement_limit, gravity, chunk_steps)
    profile = speeds if isinstance(speeds, SpeedProfile) else None
    loads = check_loads(model, profile.speeds_at(0.0) if profile else speeds, rotor, spool_of, plates, unbalances,
                        outputs)
    n = model.M.shape[0]
    check_start(start, len(loads.plates))
    x0 = initial_vector(n, q0, v0, start)
    record_state = checks.boolean("record_state", record_state)
    step = checks.choice("step", step, STEPS)
    if profile is not None:
        return run_profile(model, profile, scheme, run, loads, rotor, x0, start, progress, record_state=record_state)
    # 2. prepare the matrices: forces, plates, step matrices (with the condensed contact operator) per level
    M, K, D = (np.asarray(model.M, float), np.asarray(model.stiffness(loads.speeds), float),
               np.asarray(model.damping(loads.speeds), float))
    forces = force_columns(model, loads.speeds, loads.spool_of, loads.unbalances, run.gravity)
    par, atol = plate_parameters(loads.plates, loads.speeds, loads.spool_of, rotor, run.newton_tol)
    B = contact_rows(model, loads.plates)
    contact = kernel_plates(M, B, par, atol)

    def step_levels_up_to(n_levels: int) -> kernel.Levels:
        return step_levels(M, D, K, B, forces, loads.plates, run.dt, scheme.gamma, scheme.beta, scheme.alpha, n_levels)

    levels = step_levels_up_to(1)  # the halving levels (dense n x 2n each) are built when a step first needs them
    state = initial_state(M, D, K, B, par, loads.plates, forces, x0, start)
    forcing = kernel.Forcing(forces.kind, forces.omega)
    plan = record_plan(run.t_end, run.dt, run.record_start, run.decimate)
    eig, step_form = choose_step(step, levels, contact, scheme, M, K, forcing, plan.n_steps)
    # 3. plan the record (on the eigenbasis state y when the step runs there)
    rows = record_rows(model, loads.outputs, record_state)
    record = dense_record = record_buffers(plan, rows, len(loads.plates))
    if eig is not None:
        rows = rows_on_y(rows, eig.P)
        eig = with_record_rows(eig, rows)
        record = dense_record._replace(rows=np.ascontiguousarray(rows))  # the same buffers, rows on y
    setup_time = time.perf_counter() - t_setup
    # 4. run the kernel
    settings = kernel.Settings(t0=0.0, dt=run.dt, n_halvings=run.max_halvings, newton_tol=run.newton_tol,
                               max_newton=run.max_newton, limit=run.displacement_limit)
    diag = kernel.Diagnostics(counters=np.zeros(kernel.N_COUNTERS, dtype=np.int64), err=np.zeros(4))
    status, run_time, run_cpu_time, load_time, compiled = run_kernel(
        levels, forcing, contact, state, record, settings, diag, plan.n_steps,
        run.chunk_steps or max(2000, min(plan.n_steps, 100_000)), progress, eig,
        every_level=(lambda: step_levels_up_to(run.max_halvings + 1)) if run.max_halvings > 0 else None,
        dense_record=dense_record)
    # 5. recover and package the results
    return package_result(model, scheme, run, loads, plan, record, state, diag, status,
                          (setup_time, run_time, run_cpu_time, load_time, compiled), record_state=record_state,
                          step_form=step_form)


#: the constant-speed step's forms: "auto" (the eigenbasis where it applies, else dense), "eigen", "dense"
STEPS = ("auto", "eigen", "dense")


#: "auto" takes the eigenbasis step for runs of at least EIGEN_MIN_STEPS + EIGEN_STEPS_PER_DOF * n steps: below that its
#: set-up (an eigen-decomposition of the 2n x 2n amplification matrix) costs more than it saves. Measured
#: (paper-rub on the full refined(k) rig, one thread): break-even at 11 100, 12 300, 23 000 and 23 400 steps for
#: n = 80, 296, 584 and 1160 (set-up 0.018 / 0.35 / 2.1 / 16.8 s against 0.003 / 0.04 / 0.19 / 1.4 s dense)
EIGEN_MIN_STEPS, EIGEN_STEPS_PER_DOF = 10_000, 25


def choose_step(step: str, levels: kernel.Levels, plates: kernel.Plates, scheme, M, K, forcing: kernel.Forcing,
                n_steps: int):
    """(Eigen or None, what was chosen and why) for ``step`` (:data:`STEPS`) and a run of ``n_steps`` steps."""
    if step == "dense":
        return None, "dense (asked)"
    n = len(M)
    if step == "auto" and not scheme_excluded(scheme) and n_steps < EIGEN_MIN_STEPS + EIGEN_STEPS_PER_DOF * n:
        return None, (f"dense: {n_steps} steps are too few to repay the eigenbasis' set-up (it pays from about "
                      f"{EIGEN_MIN_STEPS + EIGEN_STEPS_PER_DOF * n} steps at {n} DOFs)")
    eig, note = eigen_form(levels, plates, scheme, M, K, forcing)
    if eig is None and step == "eigen":
        checks.fail("step", step, f"cannot be used here: {note.removeprefix('dense: ')}")
    return eig, note


__all__ = ["simulate", "TransientResult", "ContactHistory", "FinalState", "SimulationDiverged", "METHODS",
           "newmark_coefficients", "step_matrices", "OPEN", "SLIP", "STICK"]
