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


def eigen_form(levels: kernel.Levels, plates: kernel.Plates, scheme, M: np.ndarray,
               K: np.ndarray) -> tuple[Eigen | None, str]:
    """The eigenbasis step's operators for level 0, or None with the reason the dense step is kept.

    The eigenvectors are those of ``T^-1 A T`` (:func:`modal_scaling`): ``P = T P~``; the condition number
    tested is that of ``P~``.

    Returns
    -------
    eig : Eigen or None
    note : str
        ``"eigenbasis, cond(P) = ..."`` or ``"dense: <why>"``.
    """
    if scheme.method != "newmark" or scheme.gamma != 0.5 or scheme.beta != 0.25:
        return None, "dense: the eigenbasis step is for average acceleration (gamma = 1/2, beta = 1/4) only"
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

    eig = Eigen(a=a, b=b, lam=lam, gF=mapped(levels.UF[0]), gS=mapped(levels.ST[0]),
                Cr=np.ascontiguousarray(plates.BT @ P[:n]), P=np.ascontiguousarray(P),
                Pinv=np.ascontiguousarray(Pinv))
    return eig, f"eigenbasis, cond(P) = {cond:.3g}"


def rows_on_y(rows: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Record rows on x = (q[, v]) mapped to rows on y: ``rows @ P[:k]`` with k the rows' width."""
    return np.ascontiguousarray(rows @ P[:rows.shape[1]])
