"""The eigenbasis form of the constant-speed average-acceleration step (:mod:`rotorred.transient.eigen_kernel`).

:func:`eigen_form` diagonalises the amplification matrix ``A`` of level 0 into real blocks,
``A = P D P^-1``, and maps the step's inputs into that basis. It refuses, with the reason, where the
dense step must be kept: another scheme than average acceleration, or a basis whose condition
number would cost more digits than :data:`MAX_COND` allows (a defective or nearly defective ``A``,
e.g. a critically damped mode).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from rotorred.transient import kernel
from rotorred.transient.eigen_kernel import Eigen

#: largest condition number of the eigenbasis P accepted: the histories then agree with the dense
#: step's to about MAX_COND * 1e-16 relative
MAX_COND = 1e6
#: an eigenvalue with |Im| below this times |lambda| counts as real
REAL_TOL = 1e-12


def amplification(levels: kernel.Levels) -> np.ndarray:
    """``A`` of level 0: ``x' = A x`` for x = (q, v) with no force (average acceleration), shape (2 n, 2 n)."""
    H = levels.H[0]
    n = H.shape[0]
    h = levels.coef[0, 7]
    Hq, Hv = H[:, :n], H[:, n:2 * n]
    return np.block([[Hq, Hv], [(2.0 / h) * (Hq - np.eye(n)), (2.0 / h) * Hv - np.eye(n)]])


def real_block_form(A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``A = P D P^-1`` with D real: (a, b, lam, P) as :class:`Eigen` holds them.

    The columns of P are ordered ``[Re v_k (n_c), Im v_k (n_c), real eigenvectors]`` with ``v_k`` the
    eigenvector of ``lam_k = a_k + i b_k`` (b_k > 0): ``A Re v = a Re v - b Im v``, ``A Im v = b Re v + a Im v``.
    """
    lam, V = sla.eig(A)
    is_real = np.abs(lam.imag) <= REAL_TOL * np.abs(lam)
    upper = np.flatnonzero(~is_real & (lam.imag > 0))
    lower = np.flatnonzero(~is_real & (lam.imag < 0))
    if len(upper) != len(lower):
        raise np.linalg.LinAlgError("complex eigenvalues without their conjugates")
    real = np.flatnonzero(is_real)
    Vc = V[:, upper] / np.linalg.norm(V[:, upper], axis=0)
    Vr = V[:, real].real
    Vr = Vr / np.linalg.norm(Vr, axis=0) if len(real) else Vr
    P = np.hstack([Vc.real, Vc.imag, Vr])
    return lam[upper].real, lam[upper].imag, lam[real].real, P


def modal_scaling(M: np.ndarray, K: np.ndarray) -> np.ndarray:
    """``T`` with x = T x~: q = Phi eta, v = Phi Omega eta~, Phi the mass-normalised modes of (K, M) and Omega their
    frequencies (floored at 1e-3 of the largest: rigid-body modes), shape (2 n, 2 n).

    In x~ the undamped, non-spinning step is a rotation per mode; damping and gyroscopic terms perturb it, so
    its eigenbasis stays near orthogonal. In x itself q and v differ in scale by the frequencies (up to 1e5 on
    the rig's reduced model) and the eigenbasis' condition number with them.
    """
    lam, Phi = sla.eigh(0.5 * (K + K.T), 0.5 * (M + M.T))
    omega = np.sqrt(np.clip(lam, 0.0, None))
    omega = np.maximum(omega, 1e-3 * omega.max() if omega.max() > 0 else 1.0)
    n = len(M)
    T = np.zeros((2 * n, 2 * n))
    T[:n, :n] = Phi
    T[n:, n:] = Phi * omega
    return T


def scheme_excluded(scheme) -> str:
    """Why the eigenbasis step cannot run ``scheme`` ("dense: ..."), or "" when it can."""
    if scheme.method != "newmark" or scheme.gamma != 0.5 or scheme.beta != 0.25:
        return "dense: the eigenbasis step is for average acceleration (gamma = 1/2, beta = 1/4) only"
    return ""


def eigen_form(levels: kernel.Levels, plates: kernel.Plates, scheme, M: np.ndarray, K: np.ndarray,
               forcing: kernel.Forcing) -> tuple[Eigen | None, str]:
    """The eigenbasis step's operators for level 0, or None with the reason the dense step is kept.

    The eigenvectors are those of ``T^-1 A T`` (:func:`modal_scaling`): ``P = T P~``; the condition number
    tested is that of ``P~``.

    Returns
    -------
    eig : Eigen or None
    note : str
        ``"eigenbasis, cond(P) = ..."`` or ``"dense: <why>"``.
    """
    why = scheme_excluded(scheme)
    if why:
        return None, why
    T = modal_scaling(M, K)
    Tinv = np.linalg.inv(T)
    try:
        a, b, lam, Pt = real_block_form(Tinv @ amplification(levels) @ T)
    except np.linalg.LinAlgError as exc:
        return None, f"dense: no eigenbasis ({exc})"
    cond = np.linalg.cond(Pt)
    if not np.isfinite(cond) or cond > MAX_COND:
        return None, (f"dense: the amplification matrix is defective or nearly so (cond(P) = {cond:.2g} > "
                      f"{MAX_COND:.0e})")
    P, Pinv = T @ Pt, np.linalg.solve(Pt, Tinv)
    n = P.shape[0] // 2
    h = levels.coef[0, 7]

    def mapped(rows):  # each row u -> P^-1 [u; (2/h) u]
        return np.ascontiguousarray((Pinv @ np.vstack([rows.T, (2.0 / h) * rows.T])).T) if len(rows) else \
            np.zeros((0, 2 * n))

    gF = mapped(levels.UF[0])
    particular = particular_solutions(a, b, lam, gF, forcing, h)
    if isinstance(particular, str):
        return None, particular
    pair_col, omega, Yr, Yi, Y0 = particular
    Cr = np.ascontiguousarray(plates.BT @ P[:n])
    m = Cr.shape[0]
    eig = Eigen(a=a, b=b, lam=lam, pair_col=pair_col, omega=omega, Yr=Yr, Yi=Yi, Y0=Y0,
                CYr=np.ascontiguousarray(Yr @ Cr.T).reshape(len(omega), m),
                CYi=np.ascontiguousarray(Yi @ Cr.T).reshape(len(omega), m), CY0=Cr @ Y0,
                RYr=np.zeros((len(omega), 0)), RYi=np.zeros((len(omega), 0)), RY0=np.zeros(0),
                gS=mapped(levels.ST[0]), Cr=Cr, P=np.ascontiguousarray(P), Pinv=np.ascontiguousarray(Pinv))
    return eig, f"eigenbasis, cond(P) = {cond:.3g}"


def particular_solutions(a, b, lam, gF: np.ndarray, forcing: kernel.Forcing, h: float):
    """The periodic particular solution of ``y' = D y + sum_j w_j(t') gF_j`` for constant columns (kind 0) and
    (cos, sin) pairs (kinds 1, 2), or a "dense: ..." reason when a pair is at a natural frequency of the step.

    Returns
    -------
    pair_col : ndarray of int64, shape (n_f,)
    omega : ndarray, shape (n_f,)
    Yr, Yi : ndarray, shape (n_f, 2 n)
        ``Y = Yr + i Yi`` solves ``(I - e^(-i omega h) D) Y = gF_cos - i gF_sin``.
    Y0 : ndarray, shape (2 n,)
        ``(I - D) Y0 = sum of the constant columns``.
    """
    nc = len(a)
    m = 2 * nc + len(lam)

    def solve(g, z):  # (I - z D) Y = g, block by block
        Y = np.zeros(m, complex)
        p, q = 1.0 - z * a, z * b
        det = p * p + q * q
        gr, gi = g[:nc], g[nc:2 * nc]
        Y[:nc] = (p * gr + q * gi) / det
        Y[nc:2 * nc] = (p * gi - q * gr) / det
        Y[2 * nc:] = g[2 * nc:] / (1.0 - z * lam)
        smallest = min(np.min(np.abs(det), initial=np.inf), np.min(np.abs(1.0 - z * lam), initial=np.inf))
        return Y, smallest

    kinds, omegas = np.asarray(forcing.kind), np.asarray(forcing.omega)
    Y0 = np.zeros(m)
    cols, oms, Yr, Yi = [], [], [], []
    for j, kind in enumerate(kinds):
        if kind == 0:
            Y, smallest = solve(gF[j].astype(complex), 1.0)
            Y0 += Y.real
        elif kind == 1:
            Y, smallest = solve(gF[j] - 1j * gF[j + 1], np.exp(-1j * omegas[j] * h))
            cols.append(j)
            oms.append(omegas[j])
            Yr.append(Y.real)
            Yi.append(Y.imag)
        else:
            continue
        if smallest < 1e-12:
            return (f"dense: a force at {omegas[j]:.6g} rad/s excites an undamped mode of the step at its own "
                    "frequency (no periodic particular solution)")
    return (np.array(cols, dtype=np.int64), np.array(oms, dtype=float),
            np.ascontiguousarray(np.array(Yr).reshape(len(cols), m)),
            np.ascontiguousarray(np.array(Yi).reshape(len(cols), m)), Y0)


def rows_on_y(rows: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Record rows on x = (q[, v]) mapped to rows on y: ``rows @ P[:k]`` with k the rows' width."""
    return np.ascontiguousarray(rows @ P[:rows.shape[1]])


def with_record_rows(eig: Eigen, rows_y: np.ndarray) -> Eigen:
    """``eig`` with the particular solution's contributions to the record rows (on y)."""
    n_out = rows_y.shape[0]
    return eig._replace(RYr=np.ascontiguousarray(eig.Yr @ rows_y.T).reshape(len(eig.omega), n_out),
                        RYi=np.ascontiguousarray(eig.Yi @ rows_y.T).reshape(len(eig.omega), n_out),
                        RY0=rows_y @ eig.Y0)
