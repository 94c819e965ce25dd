"""Results of :func:`rotorred.transient.newmark.simulate`, and their packaging from the kernel's buffers."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotorred.transient import kernel
from rotorred.transient.contact import STATE_NAMES, RubPlate, disk_force
from rotorred.transient.status import LIMIT, NONFINITE, Status


class SimulationDiverged(RuntimeError):
    """The transient diverged; ``result`` holds everything computed until then.

    Attributes
    ----------
    result : TransientResult
        Partial result (``success`` False); every recorded value is finite.
    time : float
        Time of the failing step (s).
    dof : str
        The DOF (or plate) where the failure was detected.
    cause : str
    """

    def __init__(self, message: str, result: TransientResult, time: float, dof: str, cause: str):
        super().__init__(message)
        self.result = result
        self.time = time
        self.dof = dof
        self.cause = cause


@dataclass(frozen=True)
class ContactHistory:
    """Recorded contact quantities of one plate, at the record times of the result.

    Attributes
    ----------
    plate : RubPlate
    normal_force : ndarray, shape (n_rec,)
        P (N), >= 0: the plate pushes the disk along -n with P.
    friction_force : ndarray, shape (n_rec,)
        T (N): friction on the disk along the plate tangent t = (-sin theta, cos theta).
    state : ndarray of int8, shape (n_rec,)
        0 open, 1 slip, 2 stick (:data:`rotorred.transient.contact.STATE_NAMES`).
    u_n, u_t : ndarray, shape (n_rec,)
        Plate rigid-body displacement along n and t (m).
    sliding_velocity : ndarray, shape (n_rec,)
        v_rel = Omega r + (x', y') . t - u_t' (m/s).
    gap : ndarray, shape (n_rec,)
        g = clearance + u_n - (x, y) . n (m), negative in contact.
    """

    plate: RubPlate
    normal_force: np.ndarray
    friction_force: np.ndarray
    state: np.ndarray
    u_n: np.ndarray
    u_t: np.ndarray
    sliding_velocity: np.ndarray
    gap: np.ndarray

    @property
    def force_xy(self) -> np.ndarray:
        """Force on the rotor node (F_x, F_y) (N), shape (n_rec, 2) (Eq. 12)."""
        c, s = self.plate.normal
        return np.column_stack(disk_force(self.normal_force, self.friction_force, c, s))

    def fraction(self, state: str) -> float:
        """Fraction of the records in ``state`` ("open", "slip" or "stick")."""
        code = {v: k for k, v in STATE_NAMES.items()}[state]
        return float(np.mean(self.state == code)) if len(self.state) else 0.0

    def n_impacts(self) -> int:
        """Number of contact onsets (open -> slip or stick) in the record."""
        touching = self.state != 0
        return int(np.count_nonzero(touching[1:] & ~touching[:-1]))


@dataclass(frozen=True)
class FinalState:
    """State after the last completed step (model coordinates).

    Attributes
    ----------
    t : float
        Time (s).
    q, v, a : ndarray, shape (n,)
        Displacement, velocity, acceleration.
    plate : ndarray, shape (n_p, 2, 3)
        Per plate, (normal, tangential) x (displacement (m), velocity (m/s), acceleration (m/s^2)).
    forces : ndarray, shape (n_p, 2)
        Per plate (P, T) (N).
    mode : ndarray of int64, shape (n_p,)
        Per plate, the contact law's branch the next step starts from: 1 slip, 2 stick.
    sgn : ndarray, shape (n_p,)
        Per plate, the slip direction sign(v_rel).

    A run continues another exactly from its ``final`` (``simulate(..., start=final)``).
    """

    t: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    plate: np.ndarray
    forces: np.ndarray
    mode: np.ndarray
    sgn: np.ndarray


@dataclass(frozen=True)
class TransientResult:
    """Result of :func:`simulate`.

    Attributes
    ----------
    t : ndarray, shape (n_rec,)
        Record times (s).
    outputs : dict of (int, str) to ndarray, shape (n_rec,)
        Displacement (m) or rotation (rad) of each requested (node, direction).
    contacts : tuple of ContactHistory
        One per plate, in the order given.
    success : bool
    status : int
        A code of :mod:`rotorred.transient.status`: ``RUNNING`` (0) when finished, else the failure
        (``Status(status).message`` says which).
    message : str
    final : FinalState
    method : str
    dt, gamma, beta, alpha : float
    n_steps : int
        Completed main steps.
    n_substeps : int
        Completed half-steps taken to cure failed steps.
    n_newton : int
        Newton iterations (all steps).
    n_contact_steps : int
        (Sub)steps where at least one plate touched.
    max_newton_per_solve : int
    n_factorizations : int
        Step matrices factorised (one per step size level).
    setup_time, run_time : float
        Wall time of the matrix preparation and of the step loop (s).
    run_cpu_time : float
        CPU time of the step loop (s).
    kernel_load_time : float
        Time to compile the step kernel (first run after an install) or load it from numba's cache,
        before the loop (s); not in ``run_time`` nor in µs per step.
    kernel_compiled : bool
        Whether the step kernel was compiled for this run (not loaded from numba's on-disk cache).
    n_passes : int
        Fixed-point passes of the steps at varying speeds (0 at constant speeds).
    states : ndarray, shape (n_rec, 2 n), or None
        With ``Recording(states=True)``: q and v (model coordinates) at the record times.
    step_form : str
        Which constant-speed step ran and why (``"eigenbasis, cond(P) = ..."``, ``"dense: ..."``); empty at
        varying speeds.
    """

    t: np.ndarray
    outputs: dict
    contacts: tuple
    success: bool
    status: int
    message: str
    final: FinalState
    method: str
    dt: float
    gamma: float
    beta: float
    alpha: float
    n_steps: int
    n_substeps: int
    n_newton: int
    n_contact_steps: int
    max_newton_per_solve: int
    n_factorizations: int
    setup_time: float
    run_time: float
    run_cpu_time: float = 0.0
    kernel_load_time: float = 0.0
    kernel_compiled: bool = False
    n_passes: int = 0
    states: np.ndarray | None = None
    step_form: str = ""

    @property
    def us_per_step(self) -> float:
        """Step-loop wall time per main step (µs)."""
        return 1e6 * self.run_time / max(self.n_steps, 1)

    @property
    def cpu_us_per_step(self) -> float:
        """Step-loop CPU time of this process per main step (µs); robust to other load on the machine."""
        return 1e6 * self.run_cpu_time / max(self.n_steps, 1)


def contact_histories(plates, record: kernel.Record) -> tuple[ContactHistory, ...]:
    """One :class:`ContactHistory` per plate from the kernel's record buffers (the rows written)."""
    nr = int(record.count[0])
    columns = {"normal_force": kernel.R_P, "friction_force": kernel.R_T, "u_n": kernel.R_UN, "u_t": kernel.R_UT,
               "sliding_velocity": kernel.R_VREL, "gap": kernel.R_GAP}
    return tuple(ContactHistory(plate=p, state=record.state[:nr, k].copy(),
                                **{name: record.plate[:nr, k, col].copy() for name, col in columns.items()})
                 for k, p in enumerate(plates))


def failure(model, plates, status: int, err: np.ndarray, max_halvings: int, t_done: float) -> tuple[str, str, str]:
    """(message, dof, cause) of a run that stopped with ``status`` (the kernel's ``Diagnostics.err``)."""
    if status == NONFINITE:
        dof = _dof_label(model, int(err[kernel.E_DOF]))
    elif status == LIMIT:
        j = -int(err[kernel.E_DOF]) - 1
        dof = f"plate {j // 2} node {plates[j // 2].node} {'xy'[j % 2]}"
    else:
        k = int(err[kernel.E_PLATE])
        dof = f"plate {k} at node {plates[k].node}" if plates else "contact"
    cause = Status(status).message
    message = (f"diverged at t = {float(err[kernel.E_TIME]):.9g} s ({dof}): {cause}, not cured by halving the step "
               f"{max_halvings} times; results kept up to t = {t_done:.9g} s")
    return message, dof, cause


def _dof_label(model, i: int) -> str:
    if hasattr(model, "boundary_dofs") and hasattr(model, "full_dofs"):
        nb = len(model.boundary_dofs)
        if i < nb:
            return model.full_dofs.label(int(model.boundary_dofs[i]))
        return f"modal coordinate {i - nb}"
    return model.dofs.label(i)
