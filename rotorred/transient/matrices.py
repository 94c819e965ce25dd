"""The constant matrices of the transient: forces, plates, and the step matrices of every step size.

Built once per :func:`rotorred.transient.newmark.simulate` call, in model coordinates (n DOFs,
n_p plates, m = 2 n_p contact DOFs: x, y of each plate's node; nf force columns; L step sizes
``h = dt / 2**level``). The step algebra is described in :mod:`rotorred.transient.kernel`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
import scipy.linalg as sla

from rotorred import checks
from rotorred.model.loads import Unbalance, gravity_force
from rotorred.transient import kernel
from rotorred.transient.contact import RubPlate


def newmark_coefficients(h: float, gamma: float, beta: float) -> np.ndarray:
    """Newmark constants (c0, ..., c5) for the step ``h``.

    ``a1 = c0 (q1 - q0) - c1 v0 - c2 a0`` and ``v1 = c3 (q1 - q0) + c4 v0 + c5 a0``.
    """
    return np.array([1.0 / (beta * h * h), 1.0 / (beta * h), 0.5 / beta - 1.0,
                     gamma / (beta * h), 1.0 - gamma / beta, h * (1.0 - 0.5 * gamma / beta)])


def step_matrices(M: np.ndarray, D: np.ndarray, K: np.ndarray, h: float, gamma: float, beta: float,
                  alpha: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Linear HHT-α/Newmark step ``q1 = Hq q0 + Hv v0 + Ha a0 + A^-1 (forces)``.

    Parameters
    ----------
    M, D, K : ndarray, shape (n, n)
        Mass, damping (with gyroscopic) and stiffness matrices.
    h : float
        Step (s).
    gamma, beta, alpha : float
        Newmark and HHT-α parameters.

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


def scalar_step(m: float, c: float, k: float, h: float, gamma: float, beta: float, alpha: float) -> np.ndarray:
    """(hq, hv, ha, 1/A) of the scalar oscillator m u'' + c u' + k u = f (:func:`step_matrices` for n = 1)."""
    c0, c1, c2, c3, c4, c5 = newmark_coefficients(h, gamma, beta)
    A = c0 * m + (1.0 + alpha) * (c3 * c + k)
    return np.array([(c0 * m + (1.0 + alpha) * c3 * c + alpha * k) / A,
                     (c1 * m - (1.0 + alpha) * c4 * c + alpha * c) / A,
                     (c2 * m - (1.0 + alpha) * c5 * c) / A, 1.0 / A])


# ----------------------------------------------------------------------------------- forces
@dataclass(frozen=True)
class ForceColumns:
    """External forces ``F(t) = sum_j F[:, j] w_j(t)``, each ``w_j`` a constant, a cos or a sin.

    Attributes
    ----------
    F : ndarray, shape (n, nf)
        Force columns (N, model coordinates).
    kind : ndarray of int64, shape (nf,)
        0 constant, 1 cos(omega t), 2 sin(omega t); a cos column is followed by its sin column.
    omega : ndarray, shape (nf,)
        Angular frequency (rad/s).
    spool : tuple of str or None, length nf
        Spool whose unbalances make each column (None for gravity).
    """

    F: np.ndarray
    kind: np.ndarray
    omega: np.ndarray
    spool: tuple = ()

    def at(self, t: float) -> np.ndarray:
        """F(t) (N), shape (n,)."""
        if not self.kind.size:
            return np.zeros(self.F.shape[0])
        w = np.where(self.kind == 0, 1.0, np.where(self.kind == 1, np.cos(self.omega * t), np.sin(self.omega * t)))
        return self.F @ w


def force_columns(model, speeds: Mapping[str, float], spool_of: Mapping[int, str] | None,
                  unbalances: Sequence[Unbalance], gravity: float | None) -> ForceColumns:
    """Gravity (a constant column) and, per spool, the unbalances' (cos, sin) pair at the spool's speed.

    An unbalance ``m_e`` at phase ``phi`` on a spool at ``Omega`` pushes its node with
    ``m_e Omega^2 (cos(Omega t + phi), sin(Omega t + phi))`` (rotorred.model.loads).
    """
    n = model.M.shape[0]
    cols, kinds, omegas, owners = [], [], [], []
    if gravity:
        cols.append(gravity_force(model, float(gravity)))
        kinds.append(0)
        omegas.append(0.0)
        owners.append(None)
    per_spool: dict[str, list[np.ndarray]] = {}
    for k, u in enumerate(unbalances):
        s = spool_of.get(u.node)
        if s not in speeds:
            checks.fail(f"loads.unbalances[{k}].node", u.node, "must be a node of a spool in spool_of")
        W = speeds[s]
        rx, ry = model.output_rows([(u.node, "x"), (u.node, "y")])
        amp = u.m_e * W * W
        c, sn = math.cos(u.phase), math.sin(u.phase)
        acc = per_spool.setdefault(s, [np.zeros(n), np.zeros(n)])
        acc[0] += amp * (c * rx + sn * ry)
        acc[1] += amp * (-sn * rx + c * ry)
    for s, (fc, fs) in per_spool.items():
        cols += [fc, fs]
        kinds += [1, 2]
        omegas += [speeds[s], speeds[s]]
        owners += [s, s]
    return ForceColumns(F=np.array(cols).T if cols else np.zeros((n, 0)), kind=np.array(kinds, dtype=np.int64),
                        omega=np.array(omegas, dtype=float), spool=tuple(owners))


def fold_forcing(U1: np.ndarray, U0: np.ndarray, kinds: np.ndarray, omegas: np.ndarray, h: float) -> np.ndarray:
    """Fold ``U1 w(tb) + U0 w(ta)`` into ``U w(tb)`` for constant (kind 0) and (cos, sin) pairs (kinds 1, 2).

    With ``ta = tb - h``: cos(W ta) = cos(W tb) cos(W h) + sin(W tb) sin(W h) and
    sin(W ta) = sin(W tb) cos(W h) - cos(W tb) sin(W h).

    Parameters
    ----------
    U1, U0 : ndarray, shape (n, nf)
        Response per unit time function at the end and at the start of the step.
    kinds, omegas : ndarray, shape (nf,)
        As :class:`ForceColumns`.
    h : float
        Step (s).

    Returns
    -------
    ndarray, shape (n, nf)
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


# ----------------------------------------------------------------------------------- plates
def contact_rows(model, plates: Sequence[RubPlate]) -> np.ndarray:
    """``B``, shape (n, 2 n_p): columns x, y of each plate's node (model coordinates)."""
    B = np.zeros((model.M.shape[0], 2 * len(plates)))
    for k, p in enumerate(plates):
        B[:, 2 * k], B[:, 2 * k + 1] = model.output_rows([(p.node, "x"), (p.node, "y")])
    return B


def disk_radii(plates: Sequence[RubPlate], rotor) -> list[float]:
    """The disk radius under each plate (m): the plate's ``disk_radius``, else the disk at its node of ``rotor`` (the
    rotor the model was built from, or None)."""
    radii = []
    for k, p in enumerate(plates):
        if p.disk_radius is None and rotor is None:
            checks.fail(f"contacts[{k}].disk_radius", None, "must be given when the model has no rotor to take it "
                        "from", "m")
        if p.disk_radius is None and p.node not in {d.node for d in rotor.disks}:
            checks.fail(f"contacts[{k}].disk_radius", None, f"must be given: the model's rotor has no disk at node "
                        f"{p.node} to take it from", "m")
        radii.append(p.disk_radius if p.disk_radius is not None else rotor.disk_at(p.node).radius)
    return radii


def plate_parameters(plates: Sequence[RubPlate], speeds: Mapping[str, float], spool_of: Mapping[int, str] | None,
                     rotor, newton_tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's plate table and Newton's absolute tolerances.

    Returns
    -------
    par : ndarray, shape (n_p, kernel.N_PLATE_PAR)
        Columns of :class:`rotorred.transient.kernel.Plates` (P_COS ... P_MP).
    atol : ndarray, shape (n_p,)
        ``newton_tol`` times the force at 1 µm of Hertz deformation (N).
    """
    par = np.zeros((len(plates), kernel.N_PLATE_PAR))
    atol = np.zeros(len(plates))
    for k, (p, radius) in enumerate(zip(plates, disk_radii(plates, rotor))):
        s = spool_of.get(p.node)
        if s not in speeds:
            checks.fail(f"contacts[{k}].node", p.node, "must be a node of a spool in spool_of")
        par[k] = (math.cos(p.theta), math.sin(p.theta), p.clearance, p.offset, p.compliance, p.K_nr, p.c,
                  p.mu_s, p.mu_d, speeds[s] * radius, p.m_p)
        atol[k] = newton_tol * p.K_nr * 1e-9
    return par, atol


def kernel_plates(M: np.ndarray, B: np.ndarray, par: np.ndarray, atol: np.ndarray) -> kernel.Plates:
    """The kernel's :class:`~rotorred.transient.kernel.Plates`: ``B^T``, ``(M^-1 B)^T``, ``B^T M^-1 B``."""
    Minv_B = sla.solve(M, B) if B.shape[1] else np.zeros_like(B)
    return kernel.Plates(par=par, atol=atol, BT=np.ascontiguousarray(B.T), MBT=np.ascontiguousarray(Minv_B.T),
                         G=B.T @ Minv_B)


# ----------------------------------------------------------------------------------- step matrices
def contact_operator(W: np.ndarray, normals: np.ndarray, tangents: np.ndarray, plate_inv: np.ndarray,
                     alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """The condensed contact operator of one step size: penetration and sliding velocity per unit force.

    The step's contact-DOF displacement is ``r = r_lin + W f`` with ``f`` the forces on the disks,
    ``f_j = -P_j n_j + T_j t_j`` (Eq. 12); the plates move by ``(1 + alpha) (P_k, -T_k) / A_k``.
    With ``p_k = r_k . n_k - u_n,k`` and ``v_rel,k / c3 = r_k . t_k - u_t,k`` (+ terms free of z):

    Parameters
    ----------
    W : ndarray, shape (m, m)
        ``(1 + alpha) B^T A^-1 B`` (m/N).
    normals, tangents : ndarray, shape (n_p, 2)
        n and t of each plate.
    plate_inv : ndarray, shape (n_p, 2)
        1/A of each plate's normal and tangential scalar step (m/N).
    alpha : float
        HHT-α parameter.

    Returns
    -------
    Jp, Jv : ndarray, shape (n_p, m)
        d(penetration)/dz and d(v_rel)/dz / c3, z = (P_0, T_0, P_1, ...) (m/N).
    """
    n_p = len(normals)
    Jp = np.zeros((n_p, 2 * n_p))
    Jv = np.zeros((n_p, 2 * n_p))
    for k in range(n_p):
        nk, tk = normals[k], tangents[k]
        for j in range(n_p):
            Wkj = W[2 * k:2 * k + 2, 2 * j:2 * j + 2]
            nj, tj = normals[j], tangents[j]
            Jp[k, 2 * j] = -nk @ Wkj @ nj
            Jp[k, 2 * j + 1] = nk @ Wkj @ tj
            Jv[k, 2 * j] = -tk @ Wkj @ nj
            Jv[k, 2 * j + 1] = tk @ Wkj @ tj
        Jp[k, 2 * k] -= (1.0 + alpha) * plate_inv[k, 0]
        Jv[k, 2 * k + 1] += (1.0 + alpha) * plate_inv[k, 1]
    return Jp, Jv


def level_matrices(M, D, K, B, forces: ForceColumns, h: float, gamma: float, beta: float, alpha: float,
                   lu_M) -> dict[str, np.ndarray]:
    """Step matrices of the rotor for one step size ``h`` (the arrays of :class:`~rotorred.transient.kernel.Levels`
    without the plates' ones): ``H``, ``UF``, ``ST``, ``S0T``, ``W`` and ``coef``.

    ``lu_M`` is the LU factorisation of ``M`` (Newmark with ``gamma != 2 beta`` eliminates the acceleration
    with it).

    Newmark (alpha = 0) eliminates the acceleration through the equation of motion,
    ``M a = F + B f - D v - K q``, which holds after every step. When ``c5 = h (1 - gamma / (2 beta))``
    is zero (``gamma = 2 beta``: average acceleration) ``Ha = c2 A^-1 M``, so ``Ha M^-1 = c2 A^-1`` and
    the predictor needs no ``M^-1``:

        A q1 = F1 + B f1 + c2 (F0 + B f0) + (c0 M + c3 D - c2 K) q0 + (c1 M - (c4 + c2) D) v0,

    for gamma = 1/2, beta = 1/4 (c2 = 1, c4 = -1): ``H = [I - 2 A^-1 K, (4/h) A^-1 M]``, evaluated as
    ``[I - 2 A^-1 K, h (I - A^-1 (c3 D + K))]`` (identity minus small terms). Forming
    ``Hq - Ha M^-1 K`` through ``M^-1`` instead cancels digits: with cond(M) ~ 2e6 (a Craig–Bampton
    model) the round-off of that difference dominates the error below dt ~ 2.5e-6 s
    (tests/test_roundoff.py).
    """
    c = newmark_coefficients(h, gamma, beta)
    if alpha == 0.0 and c[5] == 0.0:
        # closed form without M^-1 (gamma = 2 beta): Ha M^-1 = c2 A^-1
        # with c0 M = A - c3 D - K, written as identity minus small terms (a solve of A against a
        # matrix close to A would leave ~cond(A) eps on the identity part). Built in place from solves with A's
        # factors (no A^-1, Hq, Hv, Ha of the general form): the refined(16) rig's set-up peaked at 298 MB with them
        n = len(M)
        lu_A = sla.lu_factor(c[0] * M + c[3] * D + K, check_finite=False)
        H = np.empty((n, 2 * n))
        Hq, Hv = H[:, :n], H[:, n:]
        AiK = sla.lu_solve(lu_A, K, check_finite=False)
        AiD = sla.lu_solve(lu_A, D, check_finite=False)
        diagonal = np.arange(n)
        # Hq = I - (1 + c2) A^-1 K and Hv = (c1/c0) (I - c3 A^-1 D - A^-1 K) - (c4 + c2) A^-1 D, in this order
        np.multiply(AiK, -(1.0 + c[2]), out=Hq)
        Hq[diagonal, diagonal] += 1.0
        np.multiply(AiD, -c[3], out=Hv)
        Hv[diagonal, diagonal] += 1.0
        Hv -= AiK
        Hv *= c[1] / c[0]
        AiD *= c[4] + c[2]
        Hv -= AiD
        del AiK, AiD
        # S and U1 through A^-1 of A = c0 M + (c3 D + K), as the general form has them: the same rounding as
        # before this form was built in place (a chaotic rub response follows the last bit: tests/test_chaos_rig.py)
        Ainv = sla.lu_solve(sla.lu_factor(c[0] * M + (c[3] * D + K), check_finite=False), np.eye(n),
                            check_finite=False)
        S = Ainv @ B
        U1 = Ainv @ forces.F
        U0 = c[2] * U1
        del Ainv
        S0T = c[2] * S.T
        return _level(H, forces, U1, U0, S, S0T, B, alpha, h, gamma, beta)
    Ainv, Hq, Hv, Ha = step_matrices(M, D, K, h, gamma, beta, alpha)
    S = Ainv @ B
    if alpha == 0.0:
        # a = M^-1 (F + B f - D v - K q) holds at every step: eliminate it
        HaMinv = sla.lu_solve(lu_M, Ha.T, trans=1, check_finite=False).T  # Ha M^-1
        H = np.hstack([Hq - HaMinv @ K, Hv - HaMinv @ D])
        U1, U0 = Ainv @ forces.F, HaMinv @ forces.F
        S0T = (HaMinv @ B).T
    else:
        H = np.hstack([Hq, Hv, Ha])
        U1, U0 = (1.0 + alpha) * Ainv @ forces.F, -alpha * Ainv @ forces.F
        S0T = -alpha * S.T
    return _level(H, forces, U1, U0, S, S0T, B, alpha, h, gamma, beta)


def _level(H, forces: ForceColumns, U1, U0, S, S0T, B, alpha: float, h: float, gamma: float, beta: float) -> dict:
    """The arrays of one level (:func:`level_matrices`) from its step matrix, force and contact maps."""
    coef = np.zeros(8)
    coef[:6] = newmark_coefficients(h, gamma, beta)
    coef[6], coef[7] = alpha, h
    return {"H": H, "UF": fold_forcing(U1, U0, forces.kind, forces.omega, h).T, "ST": S.T, "S0T": S0T,
            "W": (1.0 + alpha) * (B.T @ S), "coef": coef}


def step_levels(M, D, K, B, forces: ForceColumns, plates: Sequence[RubPlate], dt: float, gamma: float,
                beta: float, alpha: float, n_levels: int) -> kernel.Levels:
    """The kernel's :class:`~rotorred.transient.kernel.Levels` for ``h = dt / 2**level``, level < ``n_levels``."""
    lu_M = sla.lu_factor(M, check_finite=False)
    normals = np.array([p.normal for p in plates]).reshape(-1, 2)
    tangents = np.array([p.tangent for p in plates]).reshape(-1, 2)
    stacked: dict[str, np.ndarray] = {}
    for level in range(n_levels):
        h = dt / 2**level
        arrays = level_matrices(M, D, K, B, forces, h, gamma, beta, alpha, lu_M)
        arrays["plate"] = np.array([[scalar_step(p.m_p, p.c_n, p.k_n, h, gamma, beta, alpha),
                                     scalar_step(p.m_p, p.c_t, p.k_t, h, gamma, beta, alpha)]
                                    for p in plates]).reshape(-1, 2, 4)
        arrays["Jp"], arrays["Jv"] = contact_operator(arrays["W"], normals, tangents, arrays["plate"][:, :, 3], alpha)
        for name, value in arrays.items():  # each level written into its slot: no second copy of every level
            if name not in stacked:
                stacked[name] = np.empty((n_levels,) + np.shape(value))
            stacked[name][level] = value
        del arrays
    return kernel.Levels(**{name: stacked[name] for name in kernel.Levels._fields})
