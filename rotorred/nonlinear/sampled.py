"""The chain rule through the AFT of forces that act at a few samples, as outer products kept by their samples.

A contact acts on a small part of the period: at the AFT samples out of contact its force's derivatives are zero,
and in contact a rub's are rank one (the force is ``P(p, p')`` along a fixed direction). The Jacobian of the force
coefficients, ``T(df/dq) + omega T(df/dv) (nabla (x) I)`` (:meth:`rotorred.nonlinear.fourier.Harmonics.toeplitz`),
is then a sum of few outer products ``U V^T``, one term a rank of a contact sample ``theta_j``:

    [df/dq, omega df/dv](theta_j) = sum L [Rq, Rv],
    U[:, term] = forward[:, j] (x) L,     V[:, term] = E[j]^T (x) Rq + rate_rows[j]^T (x) Rv,

(harmonic-major, ``forward`` the AFT's DFT rows, ``E`` and ``rate_rows`` the synthesis of values and of
d/dtheta; :class:`rotorred.nonlinear.fourier.Harmonics`). :class:`SampledFactors` keeps U and V by their samples
``(j, L, Rq, Rv)``: their products cost O(size r), never forming the (size, r) arrays. And the small matrix of the
Woodbury solve, ``V^T G U`` for ``G`` the real block form of a complex compliance ``H_k`` (one block a harmonic,
:mod:`rotorred.nonlinear.condensed`), depends on two samples only through ``theta_i - theta_j``:

    (V^T G U)_ij = Rq_i^T K(theta_i - theta_j) L_j + Rv_i^T K'(theta_i - theta_j) L_j,
    K(Delta) = (1/N) (H_0 + 2 sum_k Re(H_k e^{i k Delta})),

on the sample grid, so one inverse FFT of ``H_k`` and a gather of ``K`` at the r^2 differences give it
(:meth:`SampledFactors.coupling`): O(r^2 + N log N) in place of the O(size r^2) product. ``L``, ``Rq`` and ``Rv``
are first written on bases of the few directions they span (one for a rub's gradient, two for its force with
friction of either sign), so K is the compliance between those directions only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.sparse.linalg import LinearOperator

from rotorred.nonlinear.fourier import Harmonics
from rotorred.transient import numba_cache

numba_cache.register()

__all__ = ["SampledFactors", "low_rank"]


@dataclass(frozen=True)
class SampledFactors:
    """``U V^T = T(dq) + omega T(dv) (nabla (x) I)`` kept by its samples (the module's docstring).

    Parameters
    ----------
    harmonics : Harmonics
    at : ndarray of int, shape (r,)
        The sample (0..N-1) of each term.
    L : ndarray, shape (r, m)
        Each term's left factor (on the forces' DOFs).
    R : ndarray, shape (r, 2m)
        Each term's right factor ``[Rq, Rv]``: on the displacements and on ``omega`` times the velocities' DOFs.
    """

    harmonics: Harmonics
    at: np.ndarray
    L: np.ndarray
    R: np.ndarray

    def __post_init__(self):
        h = self.harmonics
        object.__setattr__(self, "_forward", np.ascontiguousarray(h.forward[:, self.at]))  # (2H + 1, r)
        object.__setattr__(self, "_E", h.E[self.at])  # (r, 2H + 1)
        object.__setattr__(self, "_rate", h.rate_rows[self.at])  # (r, 2H + 1)

    @property
    def rank(self) -> int:
        return len(self.at)

    @property
    def m(self) -> int:
        """The forces' DOFs."""
        return self.L.shape[1]

    @property
    def size(self) -> int:
        return self.harmonics.size * self.m

    @property
    def U(self) -> LinearOperator:
        """U, shape (size, r), as a linear operator (``U @ y``, ``U.T @ x``)."""
        return LinearOperator((self.size, self.rank), matvec=self._u, matmat=self._u, rmatvec=self._ut,
                              rmatmat=self._ut, dtype=float)

    @property
    def V(self) -> LinearOperator:
        """V, shape (size, r), as a linear operator."""
        return LinearOperator((self.size, self.rank), matvec=self._v, matmat=self._v, rmatvec=self._vt,
                              rmatmat=self._vt, dtype=float)

    def dense(self) -> tuple[np.ndarray, np.ndarray]:
        """U and V as arrays, each shape (size, r): the definition, written out (for tests and small problems)."""
        m, r = self.m, self.rank
        U = (self._forward[:, None, :] * self.L.T[None, :, :]).reshape(self.size, r)
        V = self._E[:, :, None] * self.R[:, None, :m] + self._rate[:, :, None] * self.R[:, None, m:]
        return U, V.reshape(r, self.size).T

    def coupling(self, Hc: np.ndarray) -> np.ndarray:
        """``V^T G U``, shape (r, r), for ``G`` the real block form of the complex ``Hc`` (H + 1, m, m): the m x m block
        ``Re Hc_0`` on the constant terms and ``[[Re Hc_k, Im Hc_k], [-Im Hc_k, Re Hc_k]]`` on harmonic k's (cos, sin)
        terms. From the kernel of G on the sample grid (the module's docstring)."""
        r, m, h = self.rank, self.m, self.harmonics
        if r == 0:
            return np.zeros((0, 0))
        C, Lam = _directions(self.L)  # L = Lam C^T
        B, A = _directions(np.vstack([self.R[:, :m], self.R[:, m:]]))  # [Rq; Rv] = A B^T
        spectrum = np.zeros((2, h.N // 2 + 1, B.shape[1], C.shape[1]), complex)
        spectrum[0, :h.H + 1] = np.einsum("as,kab,bt->kst", B, Hc, C)  # the compliance between the directions
        spectrum[1, :h.H + 1] = spectrum[0, :h.H + 1] * 1j * np.arange(h.H + 1)[:, None, None]  # d/dDelta
        K = np.fft.irfft(spectrum, n=h.N, axis=1)  # (2, N, p, p'): K and dK/dDelta on the grid
        return _gathered(self.at, np.ascontiguousarray(A), np.ascontiguousarray(Lam), K)

    def _u(self, Y: np.ndarray) -> np.ndarray:
        Y2 = _columns(Y, self.rank)
        S = (self.L[:, :, None] * Y2[:, None, :]).reshape(self.rank, self.m * Y2.shape[1])  # the terms' forces
        return (self._forward @ S).reshape((self.size,) + Y.shape[1:])

    def _ut(self, X: np.ndarray) -> np.ndarray:
        X2 = _columns(X, self.harmonics.size)
        W = (self._forward.T @ X2).reshape(self.rank, self.m, X2.shape[1] // self.m)
        return np.einsum("ja,jak->jk", self.L, W).reshape((self.rank,) + X.shape[1:])

    def _v(self, Y: np.ndarray) -> np.ndarray:
        m, Y2 = self.m, _columns(Y, self.rank)
        Sq = (self.R[:, :m, None] * Y2[:, None, :]).reshape(self.rank, m * Y2.shape[1])
        Sv = (self.R[:, m:, None] * Y2[:, None, :]).reshape(self.rank, m * Y2.shape[1])
        return (self._E.T @ Sq + self._rate.T @ Sv).reshape((self.size,) + Y.shape[1:])

    def _vt(self, X: np.ndarray) -> np.ndarray:
        m, X2 = self.m, _columns(X, self.harmonics.size)
        Wq = (self._E @ X2).reshape(self.rank, m, X2.shape[1] // m)
        Wv = (self._rate @ X2).reshape(self.rank, m, X2.shape[1] // m)
        out = np.einsum("ja,jak->jk", self.R[:, :m], Wq) + np.einsum("ja,jak->jk", self.R[:, m:], Wv)
        return out.reshape((self.rank,) + X.shape[1:])


def _columns(X: np.ndarray, rows: int) -> np.ndarray:
    """A vector or a matrix of ``rows`` blocks of rows, as a matrix of ``rows`` rows (each block's entries side by
    side, the columns within)."""
    return X.reshape(rows, (X.size // rows) if rows else (X.shape[1] if X.ndim > 1 else 1))


@njit(cache=True)
def _gathered(at, A, Lam, K):
    """``(V^T G U)_ij = sum_st (Aq_is K_st(d) + Av_is dK_st(d)) Lam_jt``, d = at_i - at_j on the grid (mod N), for
    the coordinates ``A = [Aq; Av]`` (2r, p) of the right factors and ``Lam`` (r, p') of the left ones, and the kernel
    ``K`` (2, N, p, p'): K and dK/dDelta. Compiled: r^2 entries of a few products each."""
    r, N = at.shape[0], K.shape[1]
    out = np.empty((r, r))
    for i in range(r):
        for j in range(r):
            d = at[i] - at[j]
            if d < 0:
                d += N
            acc = 0.0
            for s in range(A.shape[1]):
                for t in range(Lam.shape[1]):
                    acc += (A[i, s] * K[0, d, s, t] + A[r + i, s] * K[1, d, s, t]) * Lam[j, t]
            out[i, j] = acc
    return out


def _directions(A: np.ndarray, rtol: float = 1e-13):
    """An orthonormal basis ``B`` (m, p) of the directions the rows of ``A`` (a, m) span (singular values above ``rtol``
    of the largest), and the rows' coordinates on it, ``A B`` (a, p): ``A = (A B) B^T``."""
    _, s, vt = np.linalg.svd(A, full_matrices=False)
    B = vt[:max(int(np.count_nonzero(s > rtol * s[0])), 1)].T
    return B, A @ B


def low_rank(h: Harmonics, dq: np.ndarray, dv: np.ndarray, omega: float, max_rank: int,
             rtol: float = 1e-12) -> SampledFactors | None:
    """The chain rule through the AFT as outer products, ``T(dq) + omega T(dv) (nabla (x) I) = U V^T``: one term for
    each rank of each sample's ``[dq, omega dv]`` (m x 2m, its singular values above ``rtol`` of the largest), none out
    of contact, one a contact sample for a rub (its Jacobian is rank one). None if the terms would pass ``max_rank``
    (then the Toeplitz form is the cheaper).

    Parameters
    ----------
    h : Harmonics
    dq, dv : ndarray, shape (N, m, m)
        The sampled derivatives of the forces on the displacements and on the velocities (v = omega dq/dtheta).
    omega : float
    max_rank : int
    rtol : float

    Returns
    -------
    SampledFactors or None
    """
    N = dq.shape[0]
    active = np.flatnonzero((dq != 0.0).reshape(N, -1).any(axis=1) | (dv != 0.0).reshape(N, -1).any(axis=1))
    if len(active) > max_rank:
        return None
    M = np.concatenate([dq[active], omega * dv[active]], axis=2)
    factors = _rank_one(M, rtol)
    if factors is not None:  # every sample rank one (a rub): no SVD
        return SampledFactors(h, active, factors[0], factors[1])
    u, s, vh = np.linalg.svd(M, full_matrices=False)  # (a, m, m), (a, m), (a, m, 2m)
    j, i = np.nonzero(s > rtol * s[:, :1])
    if len(j) > max_rank:
        return None
    return SampledFactors(h, active[j], u[j, :, i] * s[j, i][:, None], vh[j, i, :])


def _rank_one(A: np.ndarray, rtol: float):
    """``(L, R)`` with ``A[j] = outer(L[j], R[j])`` for every sample's matrix ``A[j]`` (a, m, p) when each is rank one
    to ``rtol`` of the largest entry (L the column of largest norm, R its least-squares row), else None. A rub's
    samples are (its force is P along a fixed direction): the SVD then costs more than the Jacobian's use of it."""
    if len(A) == 0:
        return np.zeros((0, A.shape[1])), np.zeros((0, A.shape[2]))
    a = np.arange(len(A))
    L = A[a, :, np.einsum("aij,aij->aj", A, A).argmax(axis=1)]  # (a, m)
    R = np.einsum("ai,aij->aj", L, A) / np.einsum("ai,ai->a", L, L)[:, None]  # (a, p)
    if np.abs(A - L[:, :, None] * R[:, None, :]).max() > rtol * np.abs(A).max():
        return None
    return L, R
