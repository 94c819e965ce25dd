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
from typing import Sequence

import numpy as np

from rotorred import checks
from rotorred.model.operating import Operating
from rotorred.transient import eigen_kernel, kernel
from rotorred.transient.eigenstep import eigen_form, rows_on_y, scheme_excluded, with_record_rows
from rotorred.transient.contact import OPEN, SLIP, STICK, RubPlate
from rotorred.transient.matrices import (contact_rows, force_columns, kernel_plates, newmark_coefficients,
                                         plate_parameters, step_levels, step_matrices)
from rotorred.transient.ramp import run_profile
from rotorred.transient.results import ContactHistory, FinalState, SimulationDiverged, TransientResult
from rotorred.transient.status import NEED_DENSE, NEED_LEVELS, RUNNING
from rotorred.transient.options import (  # noqa: F401 - the options, also read as newmark.<name>
    METHODS, STEPS, Initial, Loads, Recording, Scheme, StepControl)
from rotorred.transient.stepping import (  # noqa: F401 - the pipeline's pieces, also read as newmark.<name>
    COMPILING_NOTE, RecordPlan, Run, check_run, initial_state, initial_vector, load_kernel, package_result,
    record_buffers, record_plan, record_rows, step_bar, whole_steps)


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
def simulate(model, operating: Operating, t_end: float, dt: float = 1e-5, *, loads: Loads = Loads(),
             contacts: Sequence[RubPlate] = (), scheme: Scheme = Scheme(), recording: Recording = Recording(),
             start: Initial | FinalState | None = None, control: StepControl = StepControl()) -> TransientResult:
    """Transient response with unbalance, optional gravity and rub-impact plates.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        The model (:func:`rotorred.model.assembly.system_of`: a rotor is assembled). The rotor it was built from
        (``model.rotor``) gives the spool of each loaded node and the disk radius under a plate that does not
        give its ``disk_radius``; a single-spool model built by hand has every node on its spool.
    operating : Operating
        The spool speeds (rad/s inside), by the ratio rule of :class:`~rotorred.model.operating.Operating` (a spool
        left out follows the reference at the nominal ratio). A point (:meth:`Operating.point`) runs at constant
        speeds. A profile (:meth:`Operating.profile`, :meth:`Operating.ramp`: a run-up or coast-down,
        :mod:`rotorred.transient.ramp`) runs the speeds in time: gyroscopic terms at ``Omega_s(t)``, the spin
        acceleration terms ``Omega_s' K_G,s``, unbalance forces with their tangential part at the spin angle
        ``int Omega_s dt`` (docs/model.md, Eqs. R1-R4); average-acceleration Newmark only.
    t_end : float
        End time (s); the run starts at t = 0.
    dt : float
        Time step (s); default 1e-5.
    loads : Loads
        Unbalances (each rotating at the speed of its node's spool, with its phase) and gravity (m/s^2).
    contacts : sequence of RubPlate
        Rubbing plates; several may face the same or different disks.
    scheme : Scheme
        Newmark-β (default average acceleration) or HHT-α, and the form of the constant-speed step.
    recording : Recording
        The (node, direction) outputs, from when, every how many steps, and whether the whole state.
    start : Initial or FinalState, optional
        ``Initial(q0, v0)``: displacement and velocity at t = 0 in model coordinates (default rest). A
        :class:`FinalState` (another run's ``final``) continues that run: its displacement, velocity, the plates'
        own states, the contact forces and slip modes are carried over (the plates must be the same); the time
        restarts at 0, so give each unbalance the angle it had reached. The speeds may differ (a map's next point).
    control : StepControl
        The contact Newton iteration, step halving, the divergence limit and the progress bar.

    Returns
    -------
    TransientResult

    Raises
    ------
    rotorred.checks.InputError
        (a ValueError) For a bad value, before any computation, naming the parameter:
        ``dt = -0.0001: must be > 0 (s)``, ``recording.decimate = 0: must be an integer >= 1``.
    SimulationDiverged
        When a step cannot be completed; ``.result`` holds the partial result.
    """
    t_setup = time.perf_counter()
    # 1. validate the inputs
    run = check_run(model, operating, t_end, dt, loads, contacts, scheme, recording, start, control)
    if run.profile is not None:
        return run_profile(run)
    # 2. prepare the matrices: forces, plates, step matrices (with the condensed contact operator) per level
    system, speeds, scheme, control = run.system, run.speeds, run.scheme, run.control
    M, K, D = (np.asarray(system.M, float), np.asarray(system.stiffness(speeds), float),
               np.asarray(system.damping(speeds), float))
    forces = force_columns(system, speeds, run.spool_of, run.loads.unbalances, run.loads.gravity)
    par, atol = plate_parameters(run.plates, speeds, run.spool_of, run.rotor, control.newton_tol)
    B = contact_rows(system, run.plates)
    contact = kernel_plates(M, B, par, atol)

    def step_levels_up_to(n_levels: int) -> kernel.Levels:
        return step_levels(M, D, K, B, forces, run.plates, run.dt, scheme.gamma, scheme.beta, scheme.alpha, n_levels)

    levels = step_levels_up_to(1)  # the halving levels (dense n x 2n each) are built when a step first needs them
    state = initial_state(M, D, K, B, par, run.plates, forces, run.x0, run.start)
    forcing = kernel.Forcing(forces.kind, forces.omega)
    plan = record_plan(run.t_end, run.dt, run.recording.start, run.recording.decimate)
    eig, step_form = choose_step(scheme.step, levels, contact, scheme, M, K, forcing, plan.n_steps)
    # 3. plan the record (on the eigenbasis state y when the step runs there)
    rows = record_rows(system, run.recording.outputs, run.recording.states)
    record = dense_record = record_buffers(plan, rows, len(run.plates))
    if eig is not None:
        rows = rows_on_y(rows, eig.P)
        eig = with_record_rows(eig, rows)
        record = dense_record._replace(rows=np.ascontiguousarray(rows))  # the same buffers, rows on y
    setup_time = time.perf_counter() - t_setup
    # 4. run the kernel
    settings = kernel.Settings(t0=0.0, dt=run.dt, n_halvings=control.max_halvings, newton_tol=control.newton_tol,
                               max_newton=control.max_newton, limit=control.displacement_limit)
    diag = kernel.Diagnostics(counters=np.zeros(kernel.N_COUNTERS, dtype=np.int64), err=np.zeros(4))
    status, run_time, run_cpu_time, load_time, compiled = run_kernel(
        levels, forcing, contact, state, record, settings, diag, plan.n_steps,
        control.chunk_steps or max(2000, min(plan.n_steps, 100_000)), control.progress, eig,
        every_level=(lambda: step_levels_up_to(control.max_halvings + 1)) if control.max_halvings > 0 else None,
        dense_record=dense_record)
    # 5. recover and package the results
    return package_result(run, plan, record, state, diag, status,
                          (setup_time, run_time, run_cpu_time, load_time, compiled), step_form=step_form)


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
        checks.fail("scheme.step", step, f"cannot be used here: {note.removeprefix('dense: ')}")
    return eig, note


__all__ = ["simulate", "Loads", "Scheme", "Recording", "StepControl", "Initial", "TransientResult", "ContactHistory",
           "FinalState", "SimulationDiverged", "METHODS", "newmark_coefficients", "step_matrices", "OPEN", "SLIP", "STICK"]
