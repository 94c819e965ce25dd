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

import math
import sys
import time
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
import scipy.linalg as sla

from rotorred.transient import kernel as _kernel
from rotorred.transient.contact import OPEN, SLIP, STICK, STATE_NAMES, RubPlate, normal_force
from rotorred.model.loads import Unbalance, gravity_force

METHODS = ("newmark", "hht")
_CAUSES = {
    _kernel.NONFINITE: "a non-finite value",
    _kernel.NEWTON_FAILED: "the contact Newton iteration failed",
    _kernel.LIMIT: "a contact-node displacement beyond `displacement_limit`",
}


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
        n, t = self.plate.normal, self.plate.tangent
        return -np.outer(self.normal_force, n) + np.outer(self.friction_force, t)

    def fraction(self, state: str) -> float:
        """Fraction of the records in ``state`` ("open", "slip" or "stick")."""
        code = {v: k for k, v in STATE_NAMES.items()}[state]
        return float(np.mean(self.state == code)) if len(self.state) else 0.0


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
    """

    t: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    plate: np.ndarray
    forces: np.ndarray


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
        0 finished; 2 non-finite value; 3 Newton failure; 4 displacement limit.
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

    @property
    def us_per_step(self) -> float:
        """Step-loop wall time per main step (µs)."""
        return 1e6 * self.run_time / max(self.n_steps, 1)

    @property
    def cpu_us_per_step(self) -> float:
        """Step-loop CPU time of this process per main step (µs); robust to other load on the machine."""
        return 1e6 * self.run_cpu_time / max(self.n_steps, 1)


def newmark_coefficients(h: float, gamma: float, beta: float) -> np.ndarray:
    """Newmark constants (c0, ..., c5) for the step ``h``.

    ``a1 = c0 (q1 - q0) - c1 v0 - c2 a0`` and ``v1 = c3 (q1 - q0) + c4 v0 + c5 a0``.
    """
    return np.array([1.0 / (beta * h * h), 1.0 / (beta * h), 0.5 / beta - 1.0,
                     gamma / (beta * h), 1.0 - gamma / beta, h * (1.0 - 0.5 * gamma / beta)])


def step_matrices(M: np.ndarray, D: np.ndarray, K: np.ndarray, h: float, gamma: float, beta: float,
                  alpha: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Linear HHT-α/Newmark step ``q1 = Hq q0 + Hv v0 + Ha a0 + A^-1 (forces)``.

    Returns
    -------
    Ainv, Hq, Hv, Ha : ndarray, shape (n, n)
        ``A = c0 M + (1 + alpha)(c3 D + K)`` inverted, and the history maps.
    """
    c0, c1, c2, c3, c4, c5 = newmark_coefficients(h, gamma, beta)
    A = c0 * M + (1.0 + alpha) * (c3 * D + K)
    lu = sla.lu_factor(A, check_finite=False)
    Ainv = sla.lu_solve(lu, np.eye(len(A)), check_finite=False)
    Hq = Ainv @ (c0 * M + (1.0 + alpha) * c3 * D + alpha * K)
    Hv = Ainv @ (c1 * M - (1.0 + alpha) * c4 * D + alpha * D)
    Ha = Ainv @ (c2 * M - (1.0 + alpha) * c5 * D)
    return Ainv, Hq, Hv, Ha


def _scalar_step(m: float, c: float, k: float, h: float, gamma: float, beta: float, alpha: float) -> np.ndarray:
    """(hq, hv, ha, 1/A) of the scalar oscillator m u'' + c u' + k u = f."""
    c0, c1, c2, c3, c4, c5 = newmark_coefficients(h, gamma, beta)
    A = c0 * m + (1.0 + alpha) * (c3 * c + k)
    return np.array([(c0 * m + (1.0 + alpha) * c3 * c + alpha * k) / A,
                     (c1 * m - (1.0 + alpha) * c4 * c + alpha * c) / A,
                     (c2 * m - (1.0 + alpha) * c5 * c) / A, 1.0 / A])


def _fold_forcing(U1: np.ndarray, U0: np.ndarray, kinds: np.ndarray, omegas: np.ndarray, h: float) -> np.ndarray:
    """Fold ``U1 w(tb) + U0 w(ta)`` into ``U w(tb)`` for constant (kind 0) and (cos, sin) pairs (kinds 1, 2).

    With ``ta = tb - h``: cos(W ta) = cos(W tb) cos(W h) + sin(W tb) sin(W h) and
    sin(W ta) = sin(W tb) cos(W h) - cos(W tb) sin(W h).
    """
    U = U1.copy()
    j = 0
    while j < len(kinds):
        if kinds[j] == 0:
            U[:, j] += U0[:, j]
            j += 1
        else:  # a (cos, sin) pair at omegas[j]
            c, s = math.cos(omegas[j] * h), math.sin(omegas[j] * h)
            U[:, j] += c * U0[:, j] - s * U0[:, j + 1]
            U[:, j + 1] += s * U0[:, j] + c * U0[:, j + 1]
            j += 2
    return U


def _dof_label(model, i: int) -> str:
    if hasattr(model, "boundary_dofs") and hasattr(model, "full_dofs"):
        nb = len(model.boundary_dofs)
        if i < nb:
            return model.full_dofs.label(int(model.boundary_dofs[i]))
        return f"modal coordinate {i - nb}"
    return model.dofs.label(i)


def _positive(name, value, unit):
    if not (isinstance(value, (int, float, np.floating)) and math.isfinite(value) and value > 0):
        raise ValueError(f"`{name}` must be a positive finite number ({unit}), got {value!r}")
    return float(value)


def simulate(model, speeds: Mapping[str, float] | None, t_end: float, dt: float = 1e-5, *,
             unbalances: Sequence[Unbalance] = (), plates: Sequence[RubPlate] = (), rotor=None,
             spool_of: Mapping[int, str] | None = None, outputs: Sequence[tuple[int, str]] = (),
             record_start: float = 0.0, decimate: int = 1, method: str = "newmark",
             gamma: float | None = None, beta: float | None = None, alpha: float | None = None,
             gravity: float | None = None, q0=None, v0=None, progress: bool | None = None,
             newton_tol: float = 1e-10, max_newton: int = 50, max_halvings: int = 4,
             displacement_limit: float = 1.0, chunk_steps: int | None = None, **unknown) -> TransientResult:
    """Transient response with unbalance, optional gravity and rub-impact plates.

    Parameters
    ----------
    model : SystemMatrices or ReducedSystem
        Anything with ``M, K, damping(speeds), output_rows(outputs)``.
    speeds : dict of str to float or None
        Constant spool speeds (rad/s); None takes ``rotor.speeds``.
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

    Returns
    -------
    TransientResult

    Raises
    ------
    TypeError
        For an unknown option.
    ValueError
        For a bad value, before any computation.
    SimulationDiverged
        When a step cannot be completed; ``.result`` holds the partial result.
    """
    if unknown:
        raise TypeError(f"simulate() got unknown option(s) {sorted(unknown)}")
    t_setup = time.perf_counter()
    # ---- validation ---------------------------------------------------------------------
    if method not in METHODS:
        raise ValueError(f"`method` must be one of {METHODS}, got {method!r}")
    if method == "newmark":
        if alpha is not None:
            raise ValueError("`alpha` applies to method='hht' only")
        gamma = 0.5 if gamma is None else gamma
        beta = 0.25 if beta is None else beta
        alpha = 0.0
        if not (isinstance(gamma, (int, float)) and math.isfinite(gamma) and gamma >= 0.5):
            raise ValueError(f"`gamma` must be >= 1/2 (less amplifies the response), got {gamma!r}")
        _positive("beta", beta, "-")
    else:
        if gamma is not None or beta is not None:
            raise ValueError("method='hht' derives `gamma` and `beta` from `alpha`; do not give them")
        alpha = -0.05 if alpha is None else alpha
        if not (isinstance(alpha, (int, float)) and -1.0 / 3.0 <= alpha <= 0.0):
            raise ValueError(f"`alpha` must lie in [-1/3, 0], got {alpha!r}")
        gamma = 0.5 - alpha
        beta = 0.25 * (1.0 - alpha) ** 2
    t_end = _positive("t_end", t_end, "s")
    dt = _positive("dt", dt, "s")
    if dt > t_end:
        raise ValueError(f"`dt` = {dt!r} s exceeds `t_end` = {t_end!r} s")
    if not (isinstance(decimate, int) and decimate >= 1):
        raise ValueError(f"`decimate` must be an integer >= 1, got {decimate!r}")
    if not (isinstance(record_start, (int, float)) and 0.0 <= record_start <= t_end):
        raise ValueError(f"`record_start` must lie in [0, t_end] = [0, {t_end}] s, got {record_start!r}")
    for name, v, lo in (("max_newton", max_newton, 1), ("max_halvings", max_halvings, 0)):
        if not (isinstance(v, int) and v >= lo):
            raise ValueError(f"`{name}` must be an integer >= {lo}, got {v!r}")
    _positive("newton_tol", newton_tol, "-")
    _positive("displacement_limit", displacement_limit, "m")
    if gravity is not None and not (isinstance(gravity, (int, float)) and math.isfinite(gravity)):
        raise ValueError(f"`gravity` must be a finite acceleration (m/s^2) or None, got {gravity!r}")
    if speeds is None:
        if rotor is None:
            raise ValueError("`speeds` is required when no `rotor` is given")
        speeds = rotor.speeds
    speeds = {str(k): float(v) for k, v in dict(speeds).items()}
    for s, w in speeds.items():
        if not (math.isfinite(w) and w >= 0):
            raise ValueError(f"`speeds[{s!r}]` must be finite and >= 0 rad/s, got {w!r}")
    spools = tuple(model.G)
    missing = [s for s in spools if s not in speeds]
    if missing:
        raise ValueError(f"`speeds` must give every spool's speed; missing {missing}")
    if spool_of is None and rotor is not None:
        spool_of = rotor.spool_of
    if spool_of is None and len(spools) == 1:
        spool_of = {n: spools[0] for n in model.full_dofs.nodes}
    outputs = model.full_dofs.checked_outputs(outputs)
    plates = tuple(plates)
    for k, p in enumerate(plates):
        if not isinstance(p, RubPlate):
            raise ValueError(f"`plates[{k}]` must be a RubPlate, got {p!r}")
    unbalances = tuple(unbalances)
    for k, u in enumerate(unbalances):
        if not isinstance(u, Unbalance):
            raise ValueError(f"`unbalances[{k}]` must be an Unbalance, got {u!r}")
    if (plates or unbalances) and spool_of is None:
        raise ValueError("`rotor` or `spool_of` is required to know the spool (speed) of unbalance and plate nodes")
    n = model.M.shape[0]
    x0 = np.zeros(3 * n)
    for name, vec, off in (("q0", q0, 0), ("v0", v0, n)):
        if vec is not None:
            arr = np.asarray(vec, dtype=float)
            if arr.shape != (n,) or not np.all(np.isfinite(arr)):
                raise ValueError(f"`{name}` must be a finite array of shape ({n},), got shape {arr.shape}")
            x0[off:off + n] = arr

    # ---- loads ----------------------------------------------------------------------------
    M, K = np.asarray(model.M, float), np.asarray(model.K, float)
    D = np.asarray(model.damping(speeds), float)
    cols, kinds, omegas = [], [], []
    if gravity:
        cols.append(gravity_force(model, float(gravity)))
        kinds.append(0)
        omegas.append(0.0)
    per_spool: dict[str, list[np.ndarray]] = {}
    for k, u in enumerate(unbalances):
        s = spool_of.get(u.node)
        if s not in speeds:
            raise ValueError(f"`unbalances[{k}]`: node {u.node} has no spool in `spool_of`")
        W = speeds[s]
        rx, ry = model.output_rows([(u.node, "x"), (u.node, "y")])
        amp = u.m_e * W * W
        c, sn = math.cos(u.phase), math.sin(u.phase)
        fc, fs = amp * (c * rx + sn * ry), amp * (-sn * rx + c * ry)
        acc = per_spool.setdefault(s, [np.zeros(n), np.zeros(n)])
        acc[0] += fc
        acc[1] += fs
    for s, (fc, fs) in per_spool.items():
        cols += [fc, fs]
        kinds += [1, 2]
        omegas += [speeds[s], speeds[s]]
    Fcols = np.array(cols).T if cols else np.zeros((n, 0))
    f_kind = np.array(kinds, dtype=np.int64)
    f_omega = np.array(omegas, dtype=float)

    # ---- plates ---------------------------------------------------------------------------
    n_p = len(plates)
    pp = np.zeros((n_p, _kernel.N_PLATE_PAR))
    B = np.zeros((n, 2 * n_p))
    atol = np.zeros(n_p)
    for k, p in enumerate(plates):
        rows = model.output_rows([(p.node, "x"), (p.node, "y")])
        B[:, 2 * k], B[:, 2 * k + 1] = rows[0], rows[1]
        radius = p.disk_radius
        if radius is None:
            if rotor is None:
                raise ValueError(f"`plates[{k}]` has no `disk_radius` and no `rotor` was given to take it from")
            radius = rotor.disk_at(p.node).radius
        s = spool_of.get(p.node)
        if s not in speeds:
            raise ValueError(f"`plates[{k}]`: node {p.node} has no spool in `spool_of`")
        pp[k] = (math.cos(p.theta), math.sin(p.theta), p.clearance, p.offset, p.compliance, p.K_nr, p.c,
                 p.mu_s, p.mu_d, speeds[s] * radius, p.m_p)
        atol[k] = newton_tol * p.K_nr * 1e-9  # force at 1 µm of Hertz deformation times the tolerance

    # ---- step matrices per level ------------------------------------------------------------
    L = max_halvings + 1
    n_hist = 2 * n if alpha == 0.0 else 3 * n
    H = np.empty((L, n, n_hist))
    UF = np.empty((L, Fcols.shape[1], n))
    ST = np.empty((L, 2 * n_p, n))
    S0T = np.empty((L, 2 * n_p, n))
    Wm = np.empty((L, 2 * n_p, 2 * n_p))
    Jp = np.zeros((L, n_p, 2 * n_p))
    Jv = np.zeros((L, n_p, 2 * n_p))
    plvl = np.empty((L, n_p, 2, 4))
    coef = np.empty((L, 8))
    lu_M = sla.lu_factor(M, check_finite=False)
    for lvl in range(L):
        h = dt / 2**lvl
        Ainv, Hq, Hv, Ha = step_matrices(M, D, K, h, gamma, beta, alpha)
        S = Ainv @ B
        if alpha == 0.0:
            # a = M^-1 (F + B f - D v - K q) holds at every step: eliminate it
            HaMinv = sla.lu_solve(lu_M, Ha.T, trans=1, check_finite=False).T  # Ha M^-1
            H[lvl] = np.hstack([Hq - HaMinv @ K, Hv - HaMinv @ D])
            U1, U0 = Ainv @ Fcols, HaMinv @ Fcols
            S0T[lvl] = (HaMinv @ B).T
        else:
            H[lvl] = np.hstack([Hq, Hv, Ha])
            U1, U0 = (1.0 + alpha) * Ainv @ Fcols, -alpha * Ainv @ Fcols
            S0T[lvl] = -alpha * S.T
        UF[lvl] = _fold_forcing(U1, U0, f_kind, f_omega, h).T
        ST[lvl] = S.T
        Wm[lvl] = (1.0 + alpha) * (B.T @ S)
        coef[lvl, :6] = newmark_coefficients(h, gamma, beta)
        coef[lvl, 6] = alpha
        coef[lvl, 7] = h
        for k, p in enumerate(plates):
            plvl[lvl, k, 0] = _scalar_step(p.m_p, p.c_n, p.k_n, h, gamma, beta, alpha)
            plvl[lvl, k, 1] = _scalar_step(p.m_p, p.c_t, p.k_t, h, gamma, beta, alpha)
            nk, tk = p.normal, p.tangent
            for j, pj in enumerate(plates):
                Wkj = Wm[lvl, 2 * k:2 * k + 2, 2 * j:2 * j + 2]
                nj, tj = pj.normal, pj.tangent
                Jp[lvl, k, 2 * j] = -nk @ Wkj @ nj
                Jp[lvl, k, 2 * j + 1] = nk @ Wkj @ tj
                Jv[lvl, k, 2 * j] = -tk @ Wkj @ nj
                Jv[lvl, k, 2 * j + 1] = tk @ Wkj @ tj
            Jp[lvl, k, 2 * k] -= (1.0 + alpha) * plvl[lvl, k, 0, 3]
            Jv[lvl, k, 2 * k + 1] += (1.0 + alpha) * plvl[lvl, k, 1, 3]

    Minv_B = sla.solve(M, B) if n_p else np.zeros((n, 0))
    MBT = np.ascontiguousarray(Minv_B.T)
    Gm = B.T @ Minv_B

    # ---- initial state ----------------------------------------------------------------------
    q, v = x0[:n], x0[n:2 * n]
    xc = np.zeros((2 * n_p, 3))
    xc[:, 0] = B.T @ q
    xc[:, 1] = B.T @ v
    z = np.zeros(2 * n_p)
    mode = np.ones(n_p, dtype=np.int64)
    sgn = np.ones(n_p)
    pinfo = np.zeros((n_p, 3))
    ps = np.zeros((n_p, 2, 3))
    for k, p in enumerate(plates):
        x_, y_ = xc[2 * k, 0], xc[2 * k + 1, 0]
        vx, vy = xc[2 * k, 1], xc[2 * k + 1, 1]
        pen = x_ * pp[k, 0] + y_ * pp[k, 1] - p.clearance
        rate = vx * pp[k, 0] + vy * pp[k, 1]
        vrel = pp[k, 9] + (-vx * pp[k, 1] + vy * pp[k, 0])
        P, _ = normal_force(pen, rate, p)
        sgn[k] = 1.0 if vrel >= 0 else -1.0
        T = -p.mu_d * P * np.sign(vrel)
        z[2 * k], z[2 * k + 1] = P, T
        pinfo[k] = (vrel, -pen, 0.0 if P == 0 else SLIP)
        ps[k, 0, 2] = P / p.m_p
        ps[k, 1, 2] = -T / p.m_p
    frot = np.zeros(2 * n_p)
    for k, p in enumerate(plates):
        frot[2 * k:2 * k + 2] = -z[2 * k] * p.normal + z[2 * k + 1] * p.tangent
    F0 = Fcols @ np.array([_kernel._forcing_value(kd, w, 0.0) for kd, w in zip(f_kind, f_omega)]) \
        if Fcols.shape[1] else np.zeros(n)
    a0 = sla.solve(M, F0 + B @ frot - D @ v - K @ q)
    x0[2 * n:] = a0
    xc[:, 2] = B.T @ a0

    # ---- records ----------------------------------------------------------------------------
    N = int(round(t_end / dt))
    if abs(N * dt - t_end) > 1e-9 * t_end:
        N = int(math.ceil(t_end / dt - 1e-9))
    j_start = int(math.ceil(record_start / dt - 1e-9))
    n_rec = (N - j_start) // decimate + 1 if j_start <= N else 0
    out_t = np.zeros(n_rec)
    rows = model.output_rows(outputs) if outputs else np.zeros((0, n))
    rows = np.ascontiguousarray(rows, dtype=float)
    out_y = np.zeros((n_rec, len(outputs)))
    out_plate = np.zeros((n_rec, n_p, _kernel.N_PLATE_REC))
    out_state = np.zeros((n_rec, n_p), dtype=np.int8)
    rec_count = np.zeros(1, dtype=np.int64)
    counters = np.zeros(8, dtype=np.int64)
    err = np.zeros(4)
    setup_time = time.perf_counter() - t_setup

    # ---- run ----------------------------------------------------------------------------
    x = x0
    BT = np.ascontiguousarray(B.T)
    chunk = chunk_steps or max(2000, min(N, 100_000))
    t_run = time.perf_counter()
    cpu_run = time.process_time()
    status = _kernel.RUNNING
    i = 0
    shown = False
    while i < N:
        i_next = min(N, i + chunk)
        status = _kernel.run_steps(i, i_next, 0.0, dt, L - 1, H, UF, f_kind, f_omega, ST, S0T, BT, Wm, Jp, Jv,
                                   pp, plvl, coef, MBT, Gm, x, xc, ps, z, mode, sgn, pinfo, rows, j_start, decimate,
                                   out_t, out_y, out_plate, out_state, rec_count, newton_tol, atol,
                                   max_newton, displacement_limit, counters, err)
        if status != _kernel.RUNNING:
            break
        i = i_next
        elapsed = time.perf_counter() - t_run
        if progress or (progress is None and elapsed > 2.0 and i < N):
            shown = True
            frac = i / N
            bar = "#" * int(30 * frac)
            eta = elapsed / frac * (1 - frac)
            print(f"\rrotorred transient [{bar:<30}] {100 * frac:5.1f} %  t = {i * dt:.4g} s  eta {eta:.0f} s",
                  end="", file=sys.stderr, flush=True)
    if shown:
        print(file=sys.stderr)
    run_time = time.perf_counter() - t_run
    run_cpu_time = time.process_time() - cpu_run

    # ---- result -----------------------------------------------------------------------------
    nr = int(rec_count[0])
    contacts = tuple(
        ContactHistory(plate=p, normal_force=out_plate[:nr, k, _kernel.R_P].copy(),
                       friction_force=out_plate[:nr, k, _kernel.R_T].copy(), state=out_state[:nr, k].copy(),
                       u_n=out_plate[:nr, k, _kernel.R_UN].copy(), u_t=out_plate[:nr, k, _kernel.R_UT].copy(),
                       sliding_velocity=out_plate[:nr, k, _kernel.R_VREL].copy(),
                       gap=out_plate[:nr, k, _kernel.R_GAP].copy())
        for k, p in enumerate(plates))
    success = status == _kernel.RUNNING
    t_done = int(counters[_kernel.C_STEPS]) * dt
    if success:
        message = f"finished: {N} steps of {dt:g} s"
    else:
        t_fail = float(err[0])
        if status == _kernel.NONFINITE:
            dof = _dof_label(model, int(err[1]))
        elif status == _kernel.LIMIT:
            j = -int(err[1]) - 1
            dof = f"plate {j // 2} node {plates[j // 2].node} {'xy'[j % 2]}"
        else:
            kk = int(err[2])
            dof = f"plate {kk} at node {plates[kk].node}" if n_p else "contact"
        cause = _CAUSES.get(status, f"status {status}")
        message = (f"diverged at t = {t_fail:.9g} s ({dof}): {cause}, not cured by halving the step "
                   f"{max_halvings} times; results kept up to t = {t_done:.9g} s")
    final = FinalState(t=t_done, q=x[:n].copy(), v=x[n:2 * n].copy(), a=x[2 * n:].copy(), plate=ps.copy(),
                       forces=z.reshape(n_p, 2).copy())
    result = TransientResult(
        t=out_t[:nr].copy(), outputs={o: out_y[:nr, j].copy() for j, o in enumerate(outputs)}, contacts=contacts,
        success=success, status=0 if success else int(status), message=message, final=final, method=method,
        dt=dt, gamma=float(gamma), beta=float(beta), alpha=float(alpha),
        n_steps=int(counters[_kernel.C_STEPS]), n_substeps=int(counters[_kernel.C_SUBSTEPS]),
        n_newton=int(counters[_kernel.C_NEWTON]), n_contact_steps=int(counters[_kernel.C_CONTACT]),
        max_newton_per_solve=int(counters[_kernel.C_MAXNEWTON]), n_factorizations=L,
        setup_time=setup_time, run_time=run_time, run_cpu_time=run_cpu_time)
    if not success:
        raise SimulationDiverged(message, result, float(err[0]), dof, cause)
    return result


__all__ = ["simulate", "TransientResult", "ContactHistory", "FinalState", "SimulationDiverged", "METHODS",
           "newmark_coefficients", "step_matrices", "OPEN", "SLIP", "STICK"]
