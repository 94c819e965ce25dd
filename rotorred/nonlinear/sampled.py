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

from rotorred.nonlinear.fourier import Harmonics
from rotorred.nonlinear.lowrank import Factor
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
        object.__setattr__(self, "_rows", np.vstack([h.E[self.at], h.rate_rows[self.at]]))  # (2r, 2H + 1): E, rate
        m = self.L.shape[1]
        object.__setattr__(self, "_right", np.stack([self.R[:, :m], self.R[:, m:]]))  # (2, r, m): Rq, Rv

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
    def U(self) -> Factor:
        """U, shape (size, r), by its action (:class:`rotorred.nonlinear.lowrank.Factor`)."""
        return Factor((self.size, self.rank), self._u, self._ut)

    @property
    def V(self) -> Factor:
        """V, shape (size, r), by its action."""
        return Factor((self.size, self.rank), self._v, self._vt)

    def dense(self) -> tuple[np.ndarray, np.ndarray]:
        """U and V as arrays, each shape (size, r): the definition, written out (for tests and small problems)."""
        m, r, E, rate = self.m, self.rank, self._rows[:self.rank], self._rows[self.rank:]
        U = (self._forward[:, None, :] * self.L.T[None, :, :]).reshape(self.size, r)
        V = E[:, :, None] * self.R[:, None, :m] + rate[:, :, None] * self.R[:, None, m:]
        return U, V.reshape(r, self.size).T

    def coupling(self, Hc: np.ndarray) -> np.ndarray:
        """``V^T G U``, shape (r, r), for ``G`` the real block form of the complex ``Hc`` (H + 1, m, m): the m x m block
        ``Re Hc_0`` on the constant terms and ``[[Re Hc_k, Im Hc_k], [-Im Hc_k, Re Hc_k]]`` on harmonic k's (cos, sin)
        terms. From the kernel of G on the sample grid (the module's docstring)."""
        r, m, h = self.rank, self.m, self.harmonics
        if r == 0:
            return np.zeros((0, 0))
        C, Lam = _directions(self.L)  # L = Lam C^T
        B, A = _directions(self._right.reshape(2 * r, m))  # [Rq; Rv] = A B^T
        spectrum = np.zeros((2, h.N // 2 + 1, B.shape[1], C.shape[1]), complex)
        spectrum[0, :h.H + 1] = np.einsum("as,kab,bt->kst", B, Hc, C)  # the compliance between the directions
        spectrum[1, :h.H + 1] = spectrum[0, :h.H + 1] * 1j * np.arange(h.H + 1)[:, None, None]  # d/dDelta
        K = np.fft.irfft(spectrum, n=h.N, axis=1)  # (2, N, p, p'): K and dK/dDelta on the grid
        return _gathered(self.at, np.ascontiguousarray(A), np.ascontiguousarray(Lam), K)

    def _u(self, Y: np.ndarray) -> np.ndarray:
        """U Y, Y (r, k): the coefficients of each column's forces, ``L_j y_j`` at sample j."""
        S = (self.L[:, :, None] * Y[:, None, :]).reshape(self.rank, self.m * Y.shape[1])
        return (self._forward @ S).reshape(self.size, Y.shape[1])

    def _ut(self, X: np.ndarray) -> np.ndarray:
        """U^T X, X (size, k)."""
        W = (self._forward.T @ X.reshape(self.harmonics.size, -1)).reshape(self.rank, self.m, X.shape[1])
        return np.einsum("ja,jak->jk", self.L, W)

    def _v(self, Y: np.ndarray) -> np.ndarray:
        """V Y, Y (r, k)."""
        S = (self._right[:, :, :, None] * Y[None, :, None, :]).reshape(2 * self.rank, self.m * Y.shape[1])  # Rq y; Rv y
        return (self._rows.T @ S).reshape(self.size, Y.shape[1])

    def _vt(self, X: np.ndarray) -> np.ndarray:
        """V^T X, X (size, k): each column's values and rates at the samples, along Rq and Rv."""
        W = (self._rows @ X.reshape(self.harmonics.size, -1)).reshape(2, self.rank, self.m, X.shape[1])
        return (self._right[:, :, :, None] * W).sum(axis=(0, 2))


@njit(cache=True)
def _gathered(at, A, Lam, K):
    """``(V^T G U)_ij = sum_st (Aq_is K_st(d) + Av_is dK_st(d)) Lam_jt``, d = at_i - at_j on the grid (mod N), for
    the coordinates ``A = [Aq; Av]`` (2r, p) of the right factors and ``Lam`` (r, p') of the left ones, and the kernel
    ``K`` (2, N, p, p'): K and dK/dDelta. Compiled: r^2 entries of a few products each, one pair of directions at a
    time (its kernel contiguous: 0.13 -> 0.05 ms at the rig's r = 175)."""
    r, N = at.shape[0], K.shape[1]
    out = np.zeros((r, r))
    for s in range(A.shape[1]):
        for t in range(Lam.shape[1]):
            k0, k1 = K[0, :, s, t].copy(), K[1, :, s, t].copy()
            for i in range(r):
                aq, av, ai = A[i, s], A[r + i, s], at[i]
                for j in range(r):
                    d = ai - at[j]
                    if d < 0:
                        d += N
                    out[i, j] += (aq * k0[d] + av * k1[d]) * Lam[j, t]
    return out


def _directions(A: np.ndarray, rtol: float = 1e-13):
    """An orthonormal basis ``B`` (m, p) of the directions the rows of ``A`` (a, m) span (singular values above ``rtol``
    of the largest), and the rows' coordinates on it, ``A B`` (a, p): ``A = (A B) B^T``. Rows along one direction to
    ``rtol`` of the largest entry (a rub's gradient; its force with friction of one sign) skip the SVD."""
    u = A[np.argmax(np.einsum("ij,ij->i", A, A))]
    u = u / np.linalg.norm(u)
    if np.abs(A - np.outer(A @ u, u)).max() <= rtol * np.abs(A).max():
        return u[:, None], (A @ u)[:, None]
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
    at, L, R, rank_one = _rank_one(np.ascontiguousarray(dq), np.ascontiguousarray(dv), float(omega), rtol)
    if len(at) > max_rank:
        return None
    if rank_one:  # every sample rank one (a rub): no SVD
        return SampledFactors(h, at, L, R)
    M = np.concatenate([dq[at], omega * dv[at]], axis=2)  # (a, m, 2m)
    u, s, vh = np.linalg.svd(M, full_matrices=False)  # (a, m, m), (a, m), (a, m, 2m)
    j, i = np.nonzero(s > rtol * s[:, :1])
    if len(j) > max_rank:
        return None
    return SampledFactors(h, at[j], u[j, :, i] * s[j, i][:, None], vh[j, i, :])


@njit(cache=True)
def _rank_one(dq, dv, omega, rtol):
    """The samples where ``[dq, omega dv]`` (N, m, 2m) is not zero, and there ``(L, R)`` with ``[dq, omega dv] =
    outer(L, R)`` (L the column of largest norm, R its least-squares row): ``(at, L, R, rank_one)``, ``rank_one``
    whether every sample is, to ``rtol`` of the largest entry. A rub's samples are (its force is P along a fixed
    direction): the SVD then costs more than the Jacobian's use of it. Compiled: one pass over the samples."""
    N, m = dq.shape[0], dq.shape[1]
    at, L, R = np.empty(N, np.int64), np.empty((N, m)), np.empty((N, 2 * m))
    A = np.empty((m, 2 * m))
    count, largest, worst = 0, 0.0, 0.0
    for j in range(N):
        big, best, column = 0.0, -1.0, 0
        for a in range(m):
            for b in range(m):
                A[a, b], A[a, m + b] = dq[j, a, b], omega * dv[j, a, b]
        for b in range(2 * m):
            norm = 0.0
            for a in range(m):
                norm += A[a, b] * A[a, b]
                big = max(big, abs(A[a, b]))
            if norm > best:
                best, column = norm, b
        if big == 0.0:
            continue
        largest = max(largest, big)
        for a in range(m):
            L[count, a] = A[a, column]
        for b in range(2 * m):
            dot = 0.0
            for a in range(m):
                dot += L[count, a] * A[a, b]
            R[count, b] = dot / best
            for a in range(m):
                worst = max(worst, abs(A[a, b] - L[count, a] * R[count, b]))
        at[count] = j
        count += 1
    return at[:count].copy(), L[:count].copy(), R[:count].copy(), worst <= rtol * largest
