"""Truncated real Fourier series of a periodic response and the alternating frequency-time (AFT) transforms.

A periodic vector ``q(t)`` of period ``T = 2 pi / omega`` with ``H`` harmonics is

    q(t) = a_0 + sum_{k=1..H} (a_k cos(k omega t) + b_k sin(k omega t)),

stored *harmonic-major*: ``z = [a_0, a_1, b_1, ..., a_H, b_H]``, each block the ``n`` DOFs, shape
``((2H + 1) n,)``. The AFT evaluates ``q`` and ``q'`` at ``N`` equally spaced instants of one period
(``theta_j = 2 pi j / N``), a nonlinear force there, and its Fourier coefficients back by the DFT: a matrix
product at the harmonic counts of harmonic balance, where it is the cheaper, the FFT (pyFFTW,
:func:`rotorred.signals.spectra.rfft`) beyond (:data:`MATRIX_US`). The coefficients are exact (no aliasing)
for a force that is a polynomial of degree ``p`` in ``q`` when ``N >= (p + 1) H + 1``
(:func:`alias_free_samples`); a contact force is not a polynomial, and its sample count is a
convergence parameter (docs/model.md §15).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from rotorred import checks
from rotorred.signals.spectra import rfft

__all__ = ["Harmonics", "basis", "alias_free_samples", "proportional_columns", "to_phasors", "from_phasors"]

#: the cost model that picks the DFT's method, in microseconds for 2 DOFs: the matrix product ``MATRIX_US`` per
#: term and sample, one pyFFTW plan call for all the columns ``FFT_US[0] + FFT_US[1] N``. Measured here (2 DOFs,
#: one thread): at N = 128 the matrix takes 2.5-10 us for H = 5-60 and the FFT 20-21 us; at N = 1024 (23, 42, 80
#: against 30, 25, 31 us at H = 15, 30, 60) they cross near H = 18, at N = 4096 (42, 86 against 45, 46 us at H = 8,
#: 15) near H = 8. (A plan call a column, before: 38 + 0.018 N.)
MATRIX_US = 1.4e-3
FFT_US = (19.5, 0.0063)
#: below this N (2H + 1), the Toeplitz matrices are the product forward diag(d) E itself; above, they are built from
#: d's spectrum (measured per DOF pair set: H = 5, N = 128: 0.05 against 0.19 ms; H = 10, N = 1024: 0.39 against
#: 0.32; H = 30, N = 256: 6.3 against 1.4; H = 100, N = 2048: 149 against 51)
TOEPLITZ_BY_SAMPLES = 8000
#: above this N (2H + 1), samples are synthesised by an inverse FFT of all the DOFs at once rather than the product
#: ``E z`` (measured, 4 DOFs: H = 25, N = 512: 24 against 16 us; H = 50, N = 1024: 31 against 64; H = 100,
#: N = 2048: 47 against 148; H = 200, N = 4096: 79 against 872)
SYNTHESIS_BY_FFT = 40000


def proportional_columns(flat: np.ndarray, rtol: float = 1e-13):
    """Columns of ``flat`` (N, p) as multiples of a few base columns: ``base`` (indices of the distinct shapes) and
    ``factor`` (p, 2): each column's multiplier and the position of its base in ``base`` (-1 for a zero column).
    Two columns share a base when one is the other times a constant, to ``rtol`` of their largest entry."""
    p = flat.shape[1]
    factor = np.full((p, 2), -1.0)
    peaks = np.argmax(np.abs(flat), axis=0)
    scale = flat[peaks, np.arange(p)]
    base: list[int] = []
    shapes: list[np.ndarray] = []
    for j in range(p):
        if scale[j] == 0.0:
            continue
        shape = flat[:, j] / scale[j]
        for b, ref in enumerate(shapes):
            if np.max(np.abs(shape - ref)) <= rtol:
                factor[j] = (scale[j] / scale[base[b]], b)
                break
        else:
            base.append(j)
            shapes.append(shape)
            factor[j] = (1.0, len(base) - 1)
    return base, factor


def alias_free_samples(H: int, degree: int) -> int:
    """The least even sample count that transforms a degree-``degree`` polynomial of an ``H``-harmonic signal
    without aliasing: ``N >= (degree + 1) H + 1``."""
    n = (degree + 1) * H + 1
    return n + n % 2


@dataclass(frozen=True)
class Harmonics:
    """The harmonic basis: ``H`` harmonics sampled at ``N`` instants a period.

    Parameters
    ----------
    H : int
        Highest harmonic, >= 1.
    N : int
        Time samples a period for the AFT, even and > 2 H (so the basis itself is not aliased).
    """

    H: int
    N: int

    def __post_init__(self):
        checks.integer("H", self.H, ge=1)
        checks.integer("N", self.N, ge=2 * self.H + 2)
        if self.N % 2:
            checks.fail("N", self.N, "must be even")
        k = np.arange(1, self.H + 1)
        E = self.rows_at(2.0 * math.pi * np.arange(self.N) / self.N)
        nabla = np.zeros((2 * self.H + 1, 2 * self.H + 1))
        for j in k:  # d/dtheta (a cos j theta + b sin j theta) = j b cos - j a sin
            nabla[2 * j - 1, 2 * j] = j
            nabla[2 * j, 2 * j - 1] = -j
        forward = E.T * (2.0 / self.N)
        forward[0] *= 0.5
        object.__setattr__(self, "E", E)  # (N, 2H + 1): coefficients -> samples
        object.__setattr__(self, "nabla", nabla)  # d/dtheta on the coefficients of one DOF
        object.__setattr__(self, "forward", forward)  # (2H + 1, N): samples -> coefficients (least squares)
        object.__setattr__(self, "rate_rows", E @ nabla)  # (N, 2H + 1): coefficients -> samples of d/dtheta
        self._complex_basis()

    def _complex_basis(self) -> None:
        """Q: real coefficients -> complex ones c_m (m = -H..H, index m + H), with c_0 = a_0, c_{+-k} = (a_k -+ i b_k)/2;
        and where each c_m of a real signal sits in its rfft (index |m| mod N, conjugated for m < 0)."""
        H, m = self.H, 2 * self.H + 1
        Q = np.zeros((m, m), complex)
        Q[H, 0] = 1.0
        for k in range(1, H + 1):
            Q[H + k, 2 * k - 1], Q[H + k, 2 * k] = 0.5, -0.5j
            Q[H - k, 2 * k - 1], Q[H - k, 2 * k] = 0.5, 0.5j
        orders = np.arange(-2 * H, 2 * H + 1) % self.N  # the DFT index of each difference h - j = -2H..2H
        upper = orders > self.N // 2
        object.__setattr__(self, "_rfft_index", np.where(upper, self.N - orders, orders))
        object.__setattr__(self, "_conjugate", upper)
        # R = Q^-1 T_c Q entry by entry: each real row combines at most two complex rows, each real column two
        # complex columns, so R[h', j'] = sum over at most 4 terms w d_{h - j}: the weights and indices of d. Term
        # t = 2 (the row's entry) + (the column's entry), each entry's complex index ascending; the second entry of
        # a_0's row and column is weighted 0. Q^-1: a_0 = c_0, a_k = c_-k + c_k, b_k = -i c_-k + i c_k.
        k = np.arange(1, H + 1)
        entries = np.full((m, 2), H)  # the complex indices of each real coefficient: Q's columns, Q^-1's rows
        entries[1::2, 0], entries[1::2, 1] = H - k, H + k
        entries[2::2, 0], entries[2::2, 1] = H - k, H + k
        col_w = Q[entries, np.arange(m)[:, None]]
        col_w[0, 1] = 0.0
        row_w = np.zeros((m, 2), complex)
        row_w[0, 0], row_w[1::2] = 1.0, 1.0
        row_w[2::2, 0], row_w[2::2, 1] = -1j, 1j
        weights = (row_w[:, :, None, None] * col_w[None, None, :, :]).transpose(1, 3, 0, 2).reshape(4, m, m)
        index = (entries[:, :, None, None] - entries[None, None, :, :] + 2 * H).transpose(1, 3, 0, 2).reshape(4, m, m)
        object.__setattr__(self, "_weights", weights)
        object.__setattr__(self, "_index", index)

    def rows_at(self, theta: np.ndarray) -> np.ndarray:
        """The rows ``[1, cos theta, sin theta, ..., cos H theta, sin H theta]`` at the angles ``theta``: coefficients
        -> values there (``E`` at the AFT instants).

        Parameters
        ----------
        theta : array_like, shape (m,)
            Angles ``omega t`` (rad).

        Returns
        -------
        ndarray, shape (m, 2H + 1)
        """
        theta = np.asarray(theta, float)
        k = np.arange(1, self.H + 1)
        rows = np.empty((len(theta), 2 * self.H + 1))
        rows[:, 0], rows[:, 1::2], rows[:, 2::2] = 1.0, np.cos(np.outer(theta, k)), np.sin(np.outer(theta, k))
        return rows

    @property
    def size(self) -> int:
        """Coefficients a DOF: 2 H + 1."""
        return 2 * self.H + 1

    @property
    def orders(self) -> np.ndarray:
        """The harmonic order of each coefficient: 0, 1, 1, 2, 2, ..., H, H."""
        return np.concatenate([[0], np.repeat(np.arange(1, self.H + 1), 2)])

    def samples(self, z: np.ndarray, n: int) -> np.ndarray:
        """``q(theta_j)`` at the N AFT instants of the harmonic-major coefficients ``z`` of ``n`` DOFs.

        Parameters
        ----------
        z : ndarray, shape ((2H + 1) n,)
            Harmonic-major coefficients ``[a_0, a_1, b_1, ..., a_H, b_H]``, each block the n DOFs (m; rad for a
            rotation DOF).
        n : int
            DOFs.

        Returns
        -------
        ndarray, shape (N, n)
            The values, in the units of ``z``.
        """
        return self.synthesised(z.reshape(self.size, n))

    def rates(self, z: np.ndarray, n: int) -> np.ndarray:
        """``dq/dtheta (theta_j)`` at the N AFT instants: multiply by omega for dq/dt.

        Parameters
        ----------
        z : ndarray, shape ((2H + 1) n,)
            Harmonic-major coefficients of ``n`` DOFs (m; rad for a rotation DOF).
        n : int
            DOFs.

        Returns
        -------
        ndarray, shape (N, n)
            The rates per radian of ``theta``, in the units of ``z``.
        """
        return self.synthesised(self.derivative(z, n).reshape(self.size, n))

    def motion(self, z: np.ndarray, n: int, omega: float) -> tuple[np.ndarray, np.ndarray]:
        """Displacements and velocities ``q(theta_j)``, ``omega dq/dtheta (theta_j)`` of the harmonic-major
        coefficients ``z`` of ``n`` DOFs at frequency ``omega``: one synthesis of both.

        Parameters
        ----------
        z : ndarray, shape ((2H + 1) n,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        n : int
            DOFs.
        omega : float
            The fundamental frequency (rad/s).

        Returns
        -------
        q, v : ndarray, shape (N, n)
            Displacements (m) and velocities (m/s) at the N AFT instants.
        """
        both = self.synthesised(np.hstack([z.reshape(self.size, n), self.derivative(z, n).reshape(self.size, n)]))
        return both[:, :n], omega * both[:, n:]

    def synthesised(self, Z: np.ndarray) -> np.ndarray:
        """``E Z``: the samples of coefficients ``Z``, by the product or, for a large N (2H + 1)
        (:data:`SYNTHESIS_BY_FFT`), by an inverse real FFT of the spectrum ``X_0 = N a_0``, ``X_k = N (a_k - i b_k) / 2``
        (the same sums: equal to 1.2e-12 of unit coefficients at H = 100, test).

        Parameters
        ----------
        Z : ndarray, shape (2H + 1, p)
            Coefficients ``[a_0, a_1, b_1, ..., a_H, b_H]`` (rows) of p signals (columns), any units.

        Returns
        -------
        ndarray, shape (N, p)
            The values at the N AFT instants, in the units of ``Z``.
        """
        if self.N * self.size <= SYNTHESIS_BY_FFT:
            return self.E @ Z
        X = np.zeros((self.N // 2 + 1, Z.shape[1]), complex)
        X[0] = self.N * Z[0]
        X[1:self.H + 1] = (0.5 * self.N) * (Z[1::2] - 1j * Z[2::2])
        return np.fft.irfft(X, n=self.N, axis=0)

    def derivative(self, z: np.ndarray, n: int) -> np.ndarray:
        """The harmonic-major coefficients of dq/dtheta, ``(nabla (x) I_n) z``: (a_k, b_k)' = k (b_k, -a_k), written
        out (not the dense product with ``nabla``).

        Parameters
        ----------
        z : ndarray, shape ((2H + 1) n,)
            Harmonic-major coefficients of ``n`` DOFs (m; rad for a rotation DOF).
        n : int
            DOFs.

        Returns
        -------
        ndarray, shape ((2H + 1) n,)
            In the units of ``z`` per radian of ``theta``.
        """
        Z, out = z.reshape(self.size, n), np.zeros((self.size, n))
        k = np.arange(1, self.H + 1)[:, None]
        out[1::2], out[2::2] = k * Z[2::2], -k * Z[1::2]
        return out.reshape(-1)

    def times_derivative(self, X: np.ndarray, n: int) -> np.ndarray:
        """``X (nabla (x) I_n)``: a permutation and scaling of X's columns, (a_k, b_k) <- (-k b_k, k a_k), not a dense
        product.

        Parameters
        ----------
        X : ndarray, shape (p, (2H + 1) n)
            A matrix acting on harmonic-major coefficients (e.g. a Toeplitz matrix, :meth:`toeplitz`).
        n : int
            DOFs.

        Returns
        -------
        ndarray, shape (p, (2H + 1) n)
        """
        H = self.H
        X3 = X.reshape(X.shape[0], self.size, n)
        out = np.zeros_like(X3)
        k = np.arange(1, H + 1)[None, :, None]
        out[:, 1::2] = -k * X3[:, 2::2]
        out[:, 2::2] = k * X3[:, 1::2]
        return out.reshape(X.shape)

    def coefficients(self, f: np.ndarray) -> np.ndarray:
        """The harmonic-major coefficients of samples ``f``: the first H + 1 terms of the DFT, as the matrix product
        ``forward @ f`` where that is the cheaper (:data:`MATRIX_US`), else by the FFT (pyFFTW). Both are the same DFT
        (test: equal to 1.7e-14 on unit coefficients).

        Parameters
        ----------
        f : ndarray, shape (N, n)
            Values at the N AFT instants of n signals (e.g. forces, N).

        Returns
        -------
        ndarray, shape ((2H + 1) n,)
            Harmonic-major coefficients, in the units of ``f``.
        """
        if MATRIX_US * (self.H + 1) * self.N < FFT_US[0] + FFT_US[1] * self.N:
            return (self.forward @ f).reshape(-1)
        return self.coefficients_fft(f)

    def coefficients_fft(self, f: np.ndarray) -> np.ndarray:
        """:meth:`coefficients` by the FFT (pyFFTW plans of :func:`rotorred.signals.spectra.rfft`).

        Parameters
        ----------
        f : ndarray, shape (N, n)
            Values at the N AFT instants of n signals.

        Returns
        -------
        ndarray, shape ((2H + 1) n,)
            Harmonic-major coefficients, in the units of ``f``.
        """
        X = rfft(f)  # every column at once
        out = np.empty((self.size, f.shape[1]))
        out[0] = X[0].real / self.N
        out[1::2] = 2.0 * X[1:self.H + 1].real / self.N
        out[2::2] = -2.0 * X[1:self.H + 1].imag / self.N
        return out.reshape(-1)

    def toeplitz(self, d: np.ndarray) -> np.ndarray:
        """The coefficients of ``d(theta) p(theta)`` as a matrix acting on those of ``p``: ``forward diag(d) E`` per
        DOF pair, harmonic-major. It is the chain rule through the AFT (and the Hill matrix of ``d``). Written out for
        small N (2H + 1); else from the spectrum, where entries of ``d`` that are multiples of one another (a rub's
        Jacobian is rank 1, each entry a constant times dP/dp) share one block, computed once (the rig's evaluation:
        133 -> 51 ms at H = 100).

        Parameters
        ----------
        d : ndarray, shape (N, n, n)
            A Jacobian sampled at the N AFT instants (e.g. df/dq (N/m) or df/dv (N s/m)).

        Returns
        -------
        ndarray, shape ((2H + 1) n, (2H + 1) n)
            In the units of ``d``.
        """
        n = d.shape[1]
        flat = d.reshape(self.N, n * n)
        if self.N * self.size < TOEPLITZ_BY_SAMPLES:  # cheap: every pair written out
            return self._assembled(self._blocks_by_samples(flat), n)
        if n < 3:  # a few pairs: finding shared shapes costs more than it saves (0.58 against 0.32 ms, n = 2)
            return self._assembled(self._blocks_by_spectrum(flat), n)
        base, factor = proportional_columns(flat)
        distinct = self._blocks_by_spectrum(flat[:, base]) if base else np.zeros((0, self.size, self.size))
        blocks = np.zeros((n * n, self.size, self.size))
        used = factor[:, 1] >= 0
        blocks[used] = distinct[factor[used, 1].astype(int)] * factor[used, 0][:, None, None]
        return self._assembled(blocks, n)

    def toeplitz_by_samples(self, d: np.ndarray) -> np.ndarray:
        """:meth:`toeplitz` as the product ``forward diag(d) E`` written out for every pair (the definition).

        Parameters
        ----------
        d : ndarray, shape (N, n, n)
            A Jacobian sampled at the N AFT instants.

        Returns
        -------
        ndarray, shape ((2H + 1) n, (2H + 1) n)
        """
        n = d.shape[1]
        return self._assembled(self._blocks_by_samples(d.reshape(self.N, n * n)), n)

    def _blocks_by_samples(self, columns: np.ndarray) -> np.ndarray:
        return np.matmul(self.forward, columns.T[:, :, None] * self.E)

    def _blocks_by_spectrum(self, columns: np.ndarray) -> np.ndarray:
        """c_{h - j} in the complex basis, mapped to the real one entry by entry (at most four weighted c's each)."""
        spectrum = np.fft.rfft(columns, axis=0) / self.N  # the columns' complex coefficients, m >= 0
        c = spectrum[self._rfft_index]  # orders -2H..2H, shape (4H + 1, p)
        c[self._conjugate] = c[self._conjugate].conj()
        cr, ci = np.ascontiguousarray(c.real.T), np.ascontiguousarray(c.imag.T)  # (p, 4H + 1)
        blocks = np.zeros((columns.shape[1], self.size, self.size))
        for w, i in zip(self._weights, self._index):  # Re(w c) = Re w Re c - Im w Im c, term by term
            blocks += w.real * cr[:, i] - w.imag * ci[:, i]
        return blocks

    def _assembled(self, blocks: np.ndarray, n: int) -> np.ndarray:
        """The pairs' blocks (n n, 2H + 1, 2H + 1) as one harmonic-major matrix ((2H + 1) n,) * 2."""
        m = self.size
        return blocks.reshape(n, n, m, m).transpose(2, 0, 3, 1).reshape(m * n, m * n)

    def _toeplitz_by_spectrum(self, d: np.ndarray) -> np.ndarray:
        """:meth:`toeplitz` from the spectrum for every pair (for tests)."""
        n = d.shape[1]
        return self._assembled(self._blocks_by_spectrum(d.reshape(self.N, n * n)), n)


def to_phasors(C: np.ndarray) -> np.ndarray:
    """Harmonic-major real coefficients, rows ``[a_0, a_1, b_1, ...]`` (2K - 1, n), as complex amplitudes ``a_0`` and
    ``a_k - i b_k`` (K, n): the line of order k is ``Re(Q_k exp(i k theta))`` (of the periodic and the torus bases)."""
    Q = np.empty(((C.shape[0] + 1) // 2, C.shape[1]), complex)
    Q[0] = C[0]
    Q[1:] = C[1::2] - 1j * C[2::2]
    return Q


def from_phasors(Q: np.ndarray) -> np.ndarray:
    """The harmonic-major real coefficients (2K - 1, n) of complex amplitudes ``Q`` (K, n): :func:`to_phasors`'s
    inverse (a_0 is the real part of Q_0)."""
    C = np.empty((2 * Q.shape[0] - 1, Q.shape[1]))
    C[0], C[1::2], C[2::2] = Q[0].real, Q[1:].real, -Q[1:].imag
    return C


@functools.lru_cache(maxsize=16)
def basis(H: int, N: int) -> Harmonics:
    """``Harmonics(H, N)``, built once for each (H, N) (0.036 s at H = 100, N = 2048; 0.58 s at H = 400, N = 8192): for
    the problems built again and again along a branch."""
    return Harmonics(H, N)
