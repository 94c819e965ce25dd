"""Quasi-periodic harmonic balance on a two-dimensional torus (docs/model.md §15).

A response with two incommensurate base frequencies ``w = (w_1, w_2)`` (rad/s) is a function on the torus of the
angles ``theta = (theta_1, theta_2)``, read along the flow ``theta = w t``:

    q(t) = a_0 + sum_{k in K} (a_k cos(k . theta) + b_k sin(k . theta)),   k = (k_1, k_2),

with the truncated index set ``K`` of the half-plane (``k_1 > 0``, or ``k_1 = 0`` and ``k_2 > 0``), ``|k_1| <= H_1``,
``|k_2| <= H_2`` (a box), optionally only the orders whose frequency ``|k . w| <= w_max`` (a band). Each order is a
line at ``k_1 w_1 + k_2 w_2`` (of either sign). The coefficients are stored harmonic-major as in
:mod:`rotorred.nonlinear.fourier`: ``z = [a_0, a_1, b_1, ..., a_F, b_F]``, each block the ``n`` DOFs.

The AFT samples ``q`` and ``dq/dt = (w . nabla_theta) q`` on an ``N_1 x N_2`` grid of angles
``theta_ij = (2 pi i / N_1, 2 pi j / N_2)`` by the inverse 2-D FFT, evaluates the nonlinear forces there and
returns their coefficients by the 2-D FFT. A polynomial force of degree ``p`` is alias-free for
``N_i >= (p + 1) H_i + 1`` in each direction (:func:`alias_free_grid`); a contact force is not a polynomial and
``N_1, N_2`` are convergence parameters. The Jacobian is analytic: the coefficients of ``d(theta) p(theta)`` for a
sampled derivative ``d`` are ``T(d) z_p``, ``T(d) = forward diag(d) E`` (:meth:`TorusHarmonics.toeplitz_by_samples`,
the sums over samples), computed from ``d``'s 2-D spectrum: with ``D_m`` the complex coefficient of order ``m``
(indices taken modulo the grid, which makes the two equal to round-off),

    T[a_k, a_j] = Re(D_{k-j} + D_{k+j}),   T[a_k, b_j] = Im(D_{k-j} - D_{k+j}),
    T[b_k, a_j] = -Im(D_{k-j} + D_{k+j}),  T[b_k, b_j] = Re(D_{k-j} - D_{k+j}),   row a_0 halved.

The linear rest is condensed per order through the dynamic compliance, as in
:class:`rotorred.nonlinear.condensed.CondensedProblem`: ``Z_k = K - (k.w)^2 M + i (k.w) D`` and

    R(z_c) = z_c - z_lin + G F_nl(z_c),   dR/dz = I + G sum_t (T_t (x) A_t),

the sum over the distinct shapes of the sampled force derivatives (``T_t`` their Toeplitz matrices, times the
derivative operator for a velocity derivative; ``A_t`` the DOF pattern). When the patterns span few directions (a
rub's force is one direction times the normal force: rank 1), Newton's step is an equation on the orders times that
rank (Woodbury's identity), solved by preconditioned GMRES with the Jacobian's products through the grid, never
formed (:meth:`TorusProblem.newton_step`, :mod:`rotorred.nonlinear.torus_krylov`, docs/model.md §25); the dense
Jacobian (:meth:`TorusProblem.evaluate`) is the tests' reference for small sets.

Both base frequencies must be forced or the solution has a continuous phase in each angle; with every base forced
(the rig: unbalances at ``f_L`` and ``f_H = 3 w_2 / (2 pi)``) the solution is isolated and no phase condition is
needed. A sub-harmonic base (``f_H / 3``) leaves a discrete choice of three phases, which the start picks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.fft as sfft
import scipy.linalg as sla

from rotorred import checks
from rotorred.linear.modal import state_matrix
from rotorred.nonlinear.condensed import dynamic_compliance, real_form
from rotorred.nonlinear.fourier import alias_free_samples, from_phasors, proportional_columns, to_phasors
from rotorred.nonlinear.hb import Evaluation, NotConverged, checked_unknowns, harmonic_dataset, sampled_forces
from rotorred.nonlinear.torus_krylov import RankJacobian, block_product
from rotorred.nonlinear.torus_toeplitz import toeplitz_real_form
from rotorred.results import Result
from rotorred.signals.spectra import pyfftw

__all__ = ["TorusHarmonics", "TorusProblem", "TorusSolution", "TorusSeries", "solve_torus", "alias_free_grid"]

#: the loosest and the tightest relative tolerance of GMRES on a Newton step (the inexact Newton's forcing term,
#: :func:`solve_torus`)
FORCING_MAX, KRYLOV_FLOOR = 1e-2, 1e-12
#: the forcing term's power of the relative residual: min(1e-2, rho^1.5), the inexact Newton's order 1.5
FORCING_ORDER = 1.5
#: orders whose dynamic stiffnesses are built and solved at once (:meth:`TorusProblem._compliance`)
COMPLIANCE_CHUNK = 256
#: times a torus series is summed at at once (:class:`TorusSeries`: its table of phases, 29 MB at 1799 orders)
SERIES_BLOCK = 1024
#: the compliance by the modes (:func:`modal_compliance`) is taken where it matches the direct solve at a few orders to
#: this relative difference, else the direct solve serves
MODAL_MATCH = 1e-8

def alias_free_grid(H1: int, H2: int, degree: int) -> tuple[int, int]:
    """The least even grid ``(N_1, N_2)`` that transforms a degree-``degree`` polynomial of a box ``H_1 x H_2``
    without aliasing: ``N_i >= (degree + 1) H_i + 1`` in each direction (as :func:`alias_free_samples`)."""
    return alias_free_samples(H1, degree), alias_free_samples(H2, degree)


def _half_plane_orders(H1: int, H2: int, w, w_max) -> np.ndarray:
    """(0, 0) and the orders of the half-plane in the box, in the band if ``w_max``; shape (K, 2), int."""
    k1, k2 = np.meshgrid(np.arange(H1 + 1), np.arange(-H2, H2 + 1), indexing="ij")
    k1, k2 = k1.ravel(), k2.ravel()
    keep = (k1 > 0) | (k2 > 0)
    if w_max is not None:
        keep &= np.abs(k1 * w[0] + k2 * w[1]) <= w_max
    return np.vstack([[0, 0], np.column_stack([k1[keep], k2[keep]])]).astype(int)


def _order_codes(orders: np.ndarray) -> np.ndarray:
    """One integer an order ``(k_1, k_2)``, distinct for |k_2| < 2**31."""
    return orders[:, 0].astype(np.int64) * (1 << 32) + orders[:, 1].astype(np.int64)


@dataclass(frozen=True)
class TorusHarmonics:
    """The 2-D harmonic basis: the orders of a box (and band) and an ``N_1 x N_2`` AFT grid.

    Parameters
    ----------
    H1, H2 : int
        Largest ``|k_1|`` and ``|k_2|``, >= 1.
    N1, N2 : int
        Grid points in each angle, even and >= 2 H_i + 2 (the basis itself is then not aliased).
    w_max : float, optional
        Keep only the orders with ``|k_1 w_1 + k_2 w_2| <= w_max`` (rad/s); needs ``w``.
    w : (float, float), optional
        The base frequencies (rad/s) of the band.
    """

    H1: int
    H2: int
    N1: int
    N2: int
    w_max: float | None = None
    w: tuple[float, float] | None = None

    def __post_init__(self):
        for i, (H, N) in enumerate(((self.H1, self.N1), (self.H2, self.N2)), start=1):
            checks.integer(f"H{i}", H, ge=1)
            checks.integer(f"N{i}", N, ge=2 * H + 2)
            if N % 2:
                checks.fail(f"N{i}", N, "must be even")
        if self.w is not None:
            object.__setattr__(self, "w", checks.sequence("w", tuple(np.ravel(self.w)),
                                                          lambda f, v: checks.positive(f, v, "rad/s"), min_len=2,
                                                          max_len=2))
        if self.w_max is not None:
            object.__setattr__(self, "w_max", checks.positive("w_max", self.w_max, "rad/s"))
            if self.w is None:
                checks.fail("w", self.w, "must be given with w_max (the band |k . w| <= w_max)", "rad/s")
        orders = _half_plane_orders(self.H1, self.H2, self.w, self.w_max)
        object.__setattr__(self, "orders", orders)
        self._index_maps()

    def _index_maps(self) -> None:
        """Where each order sits on the half spectrum of the real 2-D FFT, the real transform along theta_2 (the
        contiguous axis): ``_half`` the flat position (row k_1 mod N_1, column |k_2|) of each order, its conjugate's
        for k_2 < 0 (``_imaginary_sign``, ``_sine_sign``: the conjugate's signs), and ``_mirror``/``_mirrored``: the
        orders (k_1 > 0, 0), whose negative the column k_2 = 0 holds too."""
        k1, k2 = self.orders[:, 0], self.orders[:, 1]
        width = self.N2 // 2 + 1
        negative = k2 < 0
        row = np.where(negative, -k1, k1) % self.N1
        object.__setattr__(self, "_half", (row * width + np.abs(k2)).astype(np.intp))
        object.__setattr__(self, "_imaginary_sign", np.where(negative, -0.5, 0.5))
        object.__setattr__(self, "_sine_sign", np.where(negative[1:], 2.0, -2.0)[:, None] / self.n_samples)
        mirrored = np.flatnonzero((k2 == 0) & (k1 > 0))
        object.__setattr__(self, "_mirrored", mirrored)
        object.__setattr__(self, "_mirror", (((-k1[mirrored]) % self.N1) * width).astype(np.intp))
        object.__setattr__(self, "_lazy", {})

    def _plan(self, kind: str, p: int) -> _GridTransform:
        """The real 2-D FFT of p signals on this grid (:class:`_GridTransform`), kept per kind and p."""
        key = (kind, p)
        if key not in self._lazy:
            self._lazy[key] = _GridTransform(kind, p, self.N1, self.N2)
        return self._lazy[key]

    # ----------------------------------------------------------------------------------------------- sizes
    @property
    def n_orders(self) -> int:
        """K: the orders, (0, 0) included."""
        return len(self.orders)

    @property
    def size(self) -> int:
        """Coefficients a DOF: 2 K - 1."""
        return 2 * self.n_orders - 1

    @property
    def n_samples(self) -> int:
        """N_1 N_2."""
        return self.N1 * self.N2

    def frequencies(self, w) -> np.ndarray:
        """``k . w`` of each order, signed.

        Parameters
        ----------
        w : (float, float)
            The base frequencies (rad/s).

        Returns
        -------
        ndarray, shape (K,)
            (rad/s).
        """
        return self.orders @ np.asarray(w, float)

    def index(self, k1: int, k2: int) -> int:
        """The position of the order ``(k1, k2)`` or of its negative in :attr:`orders` (the line is the same).

        Parameters
        ----------
        k1, k2 : int
            The order's multiples of ``w_1`` and ``w_2``.

        Returns
        -------
        int

        Raises
        ------
        InputError
            If neither the order nor its negative is in the truncated set.
        """
        if k1 < 0 or (k1 == 0 and k2 < 0):
            k1, k2 = -k1, -k2
        hit = np.flatnonzero((self.orders[:, 0] == k1) & (self.orders[:, 1] == k2))
        if hit.size == 0:
            checks.fail("order", (k1, k2), f"must be in the truncated set (|k1| <= {self.H1}, |k2| <= {self.H2}"
                        + (", in the band" if self.w_max is not None else "") + ")")
        return int(hit[0])

    def angles(self) -> np.ndarray:
        """The grid of angles, shape (N_1 N_2, 2) (rad), theta_1 major."""
        t1, t2 = np.meshgrid(2 * np.pi * np.arange(self.N1) / self.N1, 2 * np.pi * np.arange(self.N2) / self.N2,
                             indexing="ij")
        return np.column_stack([t1.ravel(), t2.ravel()])

    # ----------------------------------------------------------------------------------------------- AFT
    def phasors(self, z: np.ndarray, n: int) -> np.ndarray:
        """Complex amplitudes ``Q_k = a_k - i b_k`` (``Q_0 = a_0``) of the coefficients of ``n`` DOFs: the line of
        order k is ``Re(Q_k exp(i k . theta))``.

        Parameters
        ----------
        z : ndarray, shape ((2K - 1) n,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        n : int
            DOFs.

        Returns
        -------
        ndarray, shape (K, n), complex
            In the units of ``z``.
        """
        return to_phasors(z.reshape(self.size, n))

    def from_phasors(self, Q: np.ndarray) -> np.ndarray:
        """Harmonic-major coefficients of complex amplitudes (the inverse of :meth:`phasors`).

        Parameters
        ----------
        Q : array_like, shape (K, n), complex
            ``Q_k = a_k - i b_k`` of each order (row) and DOF (column), any units (m for a response, N for a
            forcing).

        Returns
        -------
        ndarray, shape ((2K - 1) n,)
            In the units of ``Q``.
        """
        return from_phasors(np.asarray(Q)).reshape(-1)

    def transfer(self, z: np.ndarray, n: int, target: TorusHarmonics) -> np.ndarray:
        """The coefficients ``z`` of ``n`` DOFs on the orders of ``target`` (orders ``target`` has and this set lacks
        start at 0; the others are dropped): a solution as the start of a larger truncation.

        Parameters
        ----------
        z : ndarray, shape ((2K - 1) n,)
            Harmonic-major coefficients on this set's orders (m; rad for a rotation DOF).
        n : int
            DOFs.
        target : TorusHarmonics
            The other truncation.

        Returns
        -------
        ndarray, shape ((2 target.n_orders - 1) n,)
        """
        Q = self.phasors(z, n)
        out = np.zeros((target.n_orders, n), complex)
        j = self.positions(target.orders)
        held = j >= 0
        out[held] = Q[j[held]]
        return target.from_phasors(out)

    def positions(self, orders: np.ndarray) -> np.ndarray:
        """The position of each of ``orders`` in this set's :attr:`orders`, -1 where it lacks one (a vectorised
        lookup on the orders' sorted codes, built once: a branch moves coefficients between sets at every point).

        Parameters
        ----------
        orders : ndarray, shape (L, 2), int
            Orders ``(k_1, k_2)`` of the half-plane (as :attr:`orders`).

        Returns
        -------
        ndarray, shape (L,), int
        """
        if "codes" not in self._lazy:
            codes = _order_codes(self.orders)
            at = np.argsort(codes)
            self._lazy["codes"] = (codes[at], at)
        sorted_codes, at = self._lazy["codes"]
        codes = _order_codes(np.asarray(orders, int).reshape(-1, 2))
        i = np.minimum(np.searchsorted(sorted_codes, codes), len(sorted_codes) - 1)
        return np.where(sorted_codes[i] == codes, at[i], -1)

    def samples(self, z: np.ndarray, n: int) -> np.ndarray:
        """``q`` on the grid of the harmonic-major coefficients ``z`` of ``n`` DOFs (inverse 2-D FFT).

        Parameters
        ----------
        z : ndarray, shape ((2K - 1) n,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        n : int
            DOFs.

        Returns
        -------
        ndarray, shape (N_1 N_2, n)
            In the units of ``z``, theta_1 major (:meth:`angles`).
        """
        return self.synthesised(self.phasors(z, n))

    def synthesised(self, Q: np.ndarray) -> np.ndarray:
        """The real signals of complex amplitudes ``Q`` (K, p) on the grid: ``Re sum_k Q_k exp(i k . theta)``, by one
        inverse real 2-D FFT of the half spectrum.

        Parameters
        ----------
        Q : ndarray, shape (K, p), complex
            Amplitudes of each order, any units.

        Returns
        -------
        ndarray, shape (N_1 N_2, p)
            In the units of ``Q``, theta_1 major.
        """
        return self._synthesis(Q).T.copy()

    def _synthesis(self, Q: np.ndarray) -> np.ndarray:
        """:meth:`synthesised` with the signals leading (p, N_1 N_2), in the inverse plan's own output: valid until
        that plan's next use. The half spectrum of the real transform along theta_2 (:meth:`_index_maps`)."""
        p = Q.shape[1]
        plan = self._plan("inverse", p)
        C = plan.input.reshape(p, -1)
        C.fill(0.0)
        half = np.empty((p, self.n_orders), complex)
        half.real, half.imag = 0.5 * Q.real.T, self._imaginary_sign * Q.imag.T  # k_2 < 0: the conjugate
        C[:, self._half[1:]] = half[:, 1:]
        C[:, self._mirror] = half[:, self._mirrored].conj()
        C[:, 0] = Q[0]
        return plan.execute().reshape(p, self.n_samples)

    def grid_product(self, Q: np.ndarray, product, r: int) -> np.ndarray:
        """The coefficients of ``product(x, out)`` for the signals ``x`` of complex amplitudes Q: one inverse and one
        forward real 2-D FFT, ``product`` writing its r signals on the grid into ``out`` (no other copy).

        Parameters
        ----------
        Q : ndarray, shape (K, p), complex
            Amplitudes of each order of p signals, any units.
        product : callable
            ``product(x, out)``: x (p, N_1 N_2) the signals (read only), out (r, N_1 N_2) to fill.
        r : int
            Signals ``product`` returns.

        Returns
        -------
        ndarray, shape (2K - 1, r)
            Harmonic-major coefficients of the product's signals.
        """
        plan = self._plan("forward", r)
        product(self._synthesis(Q), plan.input.reshape(r, self.n_samples))
        return self._gathered(plan.execute().reshape(r, -1))

    def derivative(self, z: np.ndarray, n: int, w) -> np.ndarray:
        """Coefficients of ``dq/dt = (w . nabla) q``: ``(a_k, b_k) -> (k.w) (b_k, -a_k)``.

        Parameters
        ----------
        z : ndarray, shape ((2K - 1) n,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        n : int
            DOFs.
        w : (float, float)
            The base frequencies (rad/s).

        Returns
        -------
        ndarray, shape ((2K - 1) n,)
            In the units of ``z`` per second (m/s).
        """
        c = z.reshape(self.size, n)
        wk = self.frequencies(w)[1:, None]
        out = np.zeros_like(c)
        out[1::2], out[2::2] = wk * c[2::2], -wk * c[1::2]
        return out.reshape(-1)

    def rates(self, z: np.ndarray, n: int, w) -> np.ndarray:
        """``dq/dt`` on the grid.

        Parameters
        ----------
        z : ndarray, shape ((2K - 1) n,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        n : int
            DOFs.
        w : (float, float)
            The base frequencies (rad/s).

        Returns
        -------
        ndarray, shape (N_1 N_2, n)
            In the units of ``z`` per second (m/s).
        """
        return self.samples(self.derivative(z, n, w), n)

    def times_derivative(self, X: np.ndarray, n: int, w) -> np.ndarray:
        """``X (Omega (x) I_n)``, Omega the derivative operator of :meth:`derivative`: columns
        (a_k, b_k) <- (-(k.w) b_k, (k.w) a_k), a scaling and permutation, not a product.

        Parameters
        ----------
        X : ndarray, shape (p, (2K - 1) n)
            A matrix acting on harmonic-major coefficients (e.g. a Toeplitz matrix, :meth:`toeplitz`).
        n : int
            DOFs.
        w : (float, float)
            The base frequencies (rad/s).

        Returns
        -------
        ndarray, shape (p, (2K - 1) n)
            In the units of ``X`` times (rad/s).
        """
        X3 = X.reshape(X.shape[0], self.size, n)
        wk = self.frequencies(w)[None, 1:, None]
        out = np.zeros_like(X3)
        out[:, 1::2], out[:, 2::2] = -wk * X3[:, 2::2], wk * X3[:, 1::2]
        return out.reshape(X.shape)

    def coefficients(self, f: np.ndarray) -> np.ndarray:
        """The harmonic-major coefficients of samples ``f`` on the orders (2-D FFT).

        Parameters
        ----------
        f : ndarray, shape (N_1 N_2, n)
            Values on the grid (theta_1 major) of n signals (e.g. forces, N).

        Returns
        -------
        ndarray, shape ((2K - 1) n,)
            In the units of ``f``.
        """
        p = f.shape[1]
        plan = self._plan("forward", p)
        plan.input[...] = f.T.reshape(p, self.N1, self.N2)
        return self._gathered(plan.execute().reshape(p, -1)).reshape(-1)

    def _gathered(self, S: np.ndarray) -> np.ndarray:
        """Harmonic-major coefficients (2K - 1, p) of the unnormalised half spectra S (p, N_1 (N_2 / 2 + 1))."""
        c = S[:, self._half].T
        z = np.empty((self.size, S.shape[0]))
        z[0] = c[0].real / self.n_samples
        z[1::2] = c[1:].real * (2.0 / self.n_samples)
        z[2::2] = c[1:].imag * self._sine_sign
        return z

    # ----------------------------------------------------------------------------------------------- Jacobians
    def basis_matrix(self) -> np.ndarray:
        """E: coefficients of one DOF -> samples, shape (N_1 N_2, 2K - 1) (for small problems and tests)."""
        phase = self.angles() @ self.orders[1:].T
        E = np.empty((self.n_samples, self.size))
        E[:, 0] = 1.0
        E[:, 1::2], E[:, 2::2] = np.cos(phase), np.sin(phase)
        return E

    def toeplitz_blocks(self, columns: np.ndarray) -> np.ndarray:
        """``T(d)`` of each sampled column ``d`` of ``columns``, from its 2-D spectrum (module docstring), by the
        compiled rule of :mod:`rotorred.nonlinear.torus_toeplitz` (the one the preconditioner's block is built by).

        Parameters
        ----------
        columns : ndarray, shape (N_1 N_2, p)
            p sampled Jacobian entries on the grid (e.g. df/dq (N/m)).

        Returns
        -------
        ndarray, shape (p, 2K - 1, 2K - 1)
            In the units of ``columns``.
        """
        p = columns.shape[1]
        S = np.fft.fft2(columns.reshape(self.N1, self.N2, p), axes=(0, 1)).reshape(self.n_samples, p) / self.n_samples
        out = np.empty((p, self.size, self.size))
        toeplitz_real_form(np.ascontiguousarray(S.T), self.orders[:, 0].astype(np.int64),
                           self.orders[:, 1].astype(np.int64), self.N1, self.N2, out)
        return out

    def toeplitz(self, d: np.ndarray) -> np.ndarray:
        """``T(d)``, harmonic-major: the coefficients of ``d(theta) p(theta)`` as a matrix acting on those of ``p``.

        Parameters
        ----------
        d : ndarray, shape (N_1 N_2, n, n)
            A Jacobian sampled on the grid (e.g. df/dq (N/m) or df/dv (N s/m)).

        Returns
        -------
        ndarray, shape ((2K - 1) n, (2K - 1) n)
            In the units of ``d``.
        """
        n = d.shape[1]
        return _assembled(self.toeplitz_blocks(d.reshape(self.n_samples, n * n)), n)

    def toeplitz_by_samples(self, d: np.ndarray) -> np.ndarray:
        """:meth:`toeplitz` as its definition, ``forward diag(d) E`` per DOF pair: sums over the samples.

        Parameters
        ----------
        d : ndarray, shape (N_1 N_2, n, n)
            A Jacobian sampled on the grid.

        Returns
        -------
        ndarray, shape ((2K - 1) n, (2K - 1) n)
        """
        n = d.shape[1]
        E = self.basis_matrix()
        forward = E.T * (2.0 / self.n_samples)
        forward[0] *= 0.5
        flat = d.reshape(self.n_samples, n * n)
        return _assembled(np.matmul(forward, flat.T[:, :, None] * E), n)

    def fit(self, t: np.ndarray, x: np.ndarray, w, within: tuple[int, int] | None = None) -> np.ndarray:
        """Coefficients of one DOF fitted by least squares to a record ``x(t)`` on the orders' lines at ``theta = w t``
        (phase origin t = 0) (:func:`rotorred.signals.linefit.fit_frequencies`: the lines must be at least 2 / T apart
        and from 0).

        Parameters
        ----------
        t : ndarray, shape (m,)
            Times of the record (s), span T.
        x : ndarray, shape (m,)
            The record (m; rad for a rotation DOF).
        w : (float, float)
            The base frequencies (rad/s).
        within : (int, int), optional
            ``(h1, h2)``: fit only the orders with ``|k_1| <= h1`` and ``|k_2| <= h2`` (the others are 0), a cheaper
            start for a large set; default all.

        Returns
        -------
        ndarray, shape (2K - 1,)
            Harmonic-major coefficients, in the units of ``x``.

        Raises
        ------
        InputError
            If the fitted lines are closer than :func:`rotorred.signals.linefit.fit_frequencies` resolves in T.
        """
        from rotorred.signals.linefit import fit_frequencies

        f = self.frequencies(w) / (2 * math.pi)
        used = np.ones(self.n_orders, bool) if within is None else \
            (np.abs(self.orders[:, 0]) <= within[0]) & (np.abs(self.orders[:, 1]) <= within[1])
        used[0] = False
        fit = fit_frequencies(t, x, np.abs(f[used]))
        Q = np.zeros(self.n_orders, complex)
        Q[0] = fit.mean
        Q[used] = np.where(f[used] > 0, fit.coefficients, fit.coefficients.conj())
        return self.from_phasors(Q[:, None])


class TorusSeries:
    """A torus's series along ``theta = w t``: ``Re sum_k Q_k exp(i (k . w) t)`` at any times, the one rule for a
    torus's trajectory (a scene's record, :func:`rotorred.scenes.torus_response.torus_record`; the state the stability
    integrates along, :func:`rotorred.nonlinear.torus_stability.torus_lyapunov`).

    By blocks of :data:`SERIES_BLOCK` times, ``exp(i (k . w) t) = exp(i (k . w) t_b) exp(i (k . w) (t - t_b))``, t_b
    the block's first time: for times at a constant step (a record's, an integration's) the second factor's table is
    the same for every block, computed once and kept for the next calls at that step, and a block costs one
    (times x orders) by (orders x p) product.

    Parameters
    ----------
    orders : ndarray, shape (K, 2), int
        The orders ``(k_1, k_2)`` (:attr:`TorusHarmonics.orders`).
    Q : ndarray, shape (K, p), complex
        Each order's complex amplitudes of p signals (any units).
    w : (float, float)
        The base frequencies (rad/s).
    """

    def __init__(self, orders: np.ndarray, Q: np.ndarray, w):
        self.wk = np.asarray(orders, float) @ np.asarray(w, float)
        self.Q = np.asarray(Q, complex)
        self._kept_step, self._table = None, np.zeros((0, len(self.wk)), complex)  # the table, and its step

    def __call__(self, t) -> np.ndarray:
        """The signals at the times ``t`` (s): shape (len(t), p)."""
        t = np.atleast_1d(np.asarray(t, float))
        step = np.diff(t)
        uniform = len(t) > 1 and np.ptp(step) <= 1e-9 * abs(step[0])
        out = np.empty((len(t), self.Q.shape[1]))
        for start in range(0, len(t), SERIES_BLOCK):
            tb = t[start:start + SERIES_BLOCK]
            table = self._phases(tb, float(step[0])) if uniform else np.exp(1j * np.outer(tb - tb[0], self.wk))
            out[start:start + len(tb)] = (table[:len(tb)] @ (self.Q * np.exp(1j * self.wk * tb[0])[:, None])).real
        return out

    def _phases(self, tb: np.ndarray, step: float) -> np.ndarray:
        """``exp(i (k . w) j step)`` for ``j < len(tb)``: the kept table where it has that step (to 1e-9 of it) and
        rows enough, else computed and kept."""
        same = self._kept_step is not None and abs(self._kept_step - step) <= 1e-9 * abs(step)
        if not same or len(self._table) < len(tb):
            self._kept_step, self._table = step, np.exp(1j * np.outer(tb - tb[0], self.wk))
        return self._table


class _GridTransform:
    """The unnormalised real 2-D FFT of p signals on an N_1 x N_2 grid, signals leading, the real transform along
    theta_2 (the contiguous axis: three times faster than along theta_1): ``forward`` samples (p, N_1, N_2) -> half
    spectra (p, N_1, N_2 / 2 + 1), ``inverse`` back (``sum_k C_k exp(i k . theta)``, no 1 / (N_1 N_2)). Callers
    write :attr:`input` and read what :meth:`execute` returns, the plan's own output (valid until its next call). A
    pyFFTW plan (one thread) or scipy's FFT without pyFFTW."""

    def __init__(self, kind: str, p: int, N1: int, N2: int):
        half, full = (p, N1, N2 // 2 + 1), (p, N1, N2)
        self.forward = kind == "forward"
        if pyfftw is None:
            self.input = np.zeros(full if self.forward else half, float if self.forward else complex)
            self._fft = (lambda x: sfft.rfftn(x, axes=(1, 2))) if self.forward else \
                (lambda x: sfft.irfftn(x, s=(N1, N2), axes=(1, 2), norm="forward"))
            return
        source = pyfftw.empty_aligned(full, float) if self.forward else pyfftw.empty_aligned(half, complex)
        target = pyfftw.empty_aligned(half, complex) if self.forward else pyfftw.empty_aligned(full, float)
        self._plan = pyfftw.FFTW(source, target, axes=(1, 2), direction="FFTW_FORWARD" if self.forward else
                                 "FFTW_BACKWARD", flags=("FFTW_ESTIMATE", "FFTW_DESTROY_INPUT"), threads=1)
        self.input = source

    def execute(self) -> np.ndarray:
        """The transform of :attr:`input` (which an inverse transform may overwrite)."""
        if pyfftw is None:
            return self._fft(self.input)
        self._plan.execute()
        return self._plan.output_array


def _assembled(blocks: np.ndarray, n: int) -> np.ndarray:
    """The DOF pairs' blocks (n n, m, m) as one harmonic-major matrix ((m n,) * 2)."""
    m = blocks.shape[1]
    return blocks.reshape(n, n, m, m).transpose(2, 0, 3, 1).reshape(m * n, m * n)


def _stiffness(M, D, K, w: np.ndarray) -> np.ndarray:
    """The dynamic stiffnesses ``K - w^2 M + i w D`` at the frequencies ``w`` (k,) (rad/s): (k, n, n)."""
    w = w[:, None, None]
    return K[None] - w**2 * M[None] + 1j * w * D[None]


def _projected(Q_full: np.ndarray, X: np.ndarray, outputs: np.ndarray | None):
    """``(O Q_full, O X)`` of every DOF's linear responses Q_full (k, n) and compliance columns X (k, n, c) (None: O = I,
    them as they are)."""
    if outputs is None:
        return Q_full, X
    return Q_full @ outputs.T, np.einsum("pn,knc->kpc", outputs, X)


def state_modes(M, D, K):
    """The first-order system's modes: ``(lam, V_q, W)``, its eigenvalues (2n,), their eigenvectors' displacement rows
    (n, 2n) and ``W = V^-1 [0; M^-1]`` (2n, n), so that ``Z(iw)^-1 = V_q (iw - Lambda)^-1 W``; None where M or the
    eigenvectors are singular. One eigen-solution of the 2n state matrix (:func:`modal_compliance` takes its products)."""
    n = M.shape[0]
    try:
        lam, V = sla.eig(state_matrix(M, D, K))
        W = sla.solve(V, np.vstack([np.zeros((n, n)), sla.inv(M)]))
    except (sla.LinAlgError, ValueError):
        return None
    return lam, V[:n], W


def modal_compliance(modes, M, D, K, dofs, w: np.ndarray, forcing: np.ndarray, outputs: np.ndarray):
    """``O (Z_k^-1)[:, dofs]`` and ``O Z_k^-1 f_k`` at the frequencies ``w`` (k,) (rad/s) by the first-order system's
    ``modes`` (:func:`state_modes`): ``Z(iw)^-1 = V_q (iw - Lambda)^-1 V^-1 [0; M^-1]``, O(k n p) products against k
    solves of n x n, for the outputs ``O`` (p, n) (rows of the identity: those DOFs; an output row: a combination), as
    ``(X, Q)`` of shapes (k, p, len(dofs)) and (k, p); None where the modes are too ill-conditioned: the direct solve
    at sixteen of the orders differs by more than :data:`MODAL_MATCH`. Where the speed moves along a branch, every
    value's problem has its own matrices (the gyroscopic term): the modes cost one eigen-solution a value (docs/model.md
    §26); its iterates need only the rows of the ``dofs`` (:meth:`TorusProblem._compliance`), a point's lines only its
    output's."""
    lam, V_q, W = modes
    c = list(dofs)
    r = 1.0 / (1j * w[:, None] - lam[None, :])  # (k, 2n)
    Vq = outputs @ V_q
    X = np.einsum("ij,kj,jc->kic", Vq, r, W[:, c], optimize=True)
    Q = np.zeros((len(w), len(outputs)), complex)
    forced = np.flatnonzero(np.any(forcing != 0.0, axis=1))  # a few orders (each spool's unbalance)
    Q[forced] = (r[forced] * (forcing[forced] @ W.T)) @ Vq.T
    probe = np.unique(np.linspace(0, len(w) - 1, 16).astype(int))
    X_d, Q_d = dynamic_compliance(_stiffness(M, D, K, w[probe]), c, forcing[probe])
    X_d, Q_d = np.einsum("pn,knc->kpc", outputs, X_d), Q_d @ outputs.T
    scale_x, scale_q = np.max(np.abs(X_d)), np.max(np.abs(Q_d)) or 1.0
    if not (np.max(np.abs(X[probe] - X_d)) <= MODAL_MATCH * scale_x
            and np.max(np.abs(Q[probe] - Q_d)) <= MODAL_MATCH * scale_q):
        return None
    return X, Q


@dataclass(frozen=True)
class _Compliance:
    """The condensation at the problem's base frequencies: G as blocks (G0, the (2c, 2c) block of each order), the
    linear response of the ``c`` DOFs, and per order the linear response and the compliance columns of outputs,
    ``recovery(O)`` -> ``(O Q_full, O X)``, ``Q_full`` (K, n_all) the full linear response and ``X = (Z_k^-1)[:, c]``
    (K, n_all, c) (complex; O (p, n_all), None: every DOF, kept by :meth:`full`), computed on use where they were not at
    hand (only a solution's recovery asks them)."""

    G0: np.ndarray
    Gk: np.ndarray
    z_lin: np.ndarray
    recovery: Callable[[np.ndarray | None], tuple[np.ndarray, np.ndarray]]
    _kept: dict = field(default_factory=dict, repr=False, compare=False)

    def full(self) -> tuple[np.ndarray, np.ndarray]:
        """``(Q_full, X)`` of every DOF."""
        if "full" not in self._kept:
            self._kept["full"] = self.recovery(None)
        return self._kept["full"]

    def rows(self, outputs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(O Q_full, O X)`` of the outputs O (p, n_all): from every DOF's where they are kept, else
        ``recovery``'s."""
        return _projected(*self._kept["full"], outputs) if "full" in self._kept else self.recovery(outputs)


@dataclass(frozen=True)
class TorusProblem:
    """A system forced at two incommensurate base frequencies with nonlinear forces on a few DOFs: its quasi-periodic
    response by harmonic balance on the torus, condensed onto those DOFs.

    Parameters
    ----------
    M, D, K : ndarray, shape (n, n)
        Mass, velocity (damping plus gyroscopic at the fixed spin speeds) and stiffness matrices (SI).
    harmonics : TorusHarmonics
    w : (float, float)
        Base frequencies ``(w_1, w_2)`` (rad/s), > 0.
    dofs : tuple of int
        The DOFs ``c`` the nonlinear forces act on: the unknowns.
    forcing : ndarray, shape ((2K - 1) n,)
        Harmonic-major coefficients of the external force on all ``n`` DOFs (N); build them from complex amplitudes
        with :meth:`TorusHarmonics.from_phasors`.
    forces : tuple
        Nonlinear forces (:mod:`rotorred.nonlinear.forces`), their ``dofs`` numbered in the whole system, among
        ``dofs``.
    """

    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    harmonics: TorusHarmonics
    w: tuple[float, float]
    dofs: tuple[int, ...]
    forcing: np.ndarray
    forces: tuple = ()
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        n = np.shape(self.M)[0] if np.ndim(self.M) == 2 else 0
        for name in ("M", "D", "K"):
            object.__setattr__(self, name, checks.array(name, getattr(self, name), (n, n)))
        if not isinstance(self.harmonics, TorusHarmonics):
            checks.fail("harmonics", self.harmonics, "must be a TorusHarmonics")
        w = checks.sequence("w", tuple(np.ravel(self.w)), lambda f, v: checks.positive(f, v, "rad/s"), min_len=2,
                            max_len=2)
        object.__setattr__(self, "w", w)
        checked_unknowns(self, n)
        object.__setattr__(self, "forcing", checks.array("forcing", np.ravel(self.forcing), (self.harmonics.size * n,),
                                                         "N"))

    @property
    def n(self) -> int:
        """The unknown DOFs an order: len(dofs)."""
        return len(self.dofs)

    @property
    def size(self) -> int:
        """Unknowns: (2K - 1) len(dofs)."""
        return self.harmonics.size * self.n

    @property
    def frequencies(self) -> np.ndarray:
        """``k . w`` of each order (rad/s), shape (K,)."""
        return self.harmonics.frequencies(self.w)

    def samples(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Displacements and velocities of the ``dofs`` on the grid.

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients of the ``dofs`` (m; rad for a rotation DOF).

        Returns
        -------
        q, v : ndarray, shape (N_1 N_2, len(dofs))
            (m) and (m/s).
        """
        h = self.harmonics
        return h.samples(z, self.n), h.rates(z, self.n, self.w)

    # ----------------------------------------------------------------------------------------------- condensation
    def _compliance(self) -> _Compliance:
        """Z_k^-1 at every order's frequency, by batched solves of :data:`COMPLIANCE_CHUNK` orders at a time (the
        dynamic stiffnesses of all the orders at once would be the largest array of the solve), computed once: w is
        fixed."""
        if "compliance" in self._cache:
            return self._cache["compliance"]
        n_all, c, wk = self.M.shape[0], list(self.dofs), self.frequencies
        forcing = self.harmonics.phasors(self.forcing, n_all)
        modes = state_modes(self.M, self.D, self.K) if self._cache.get("modes") else None
        found = None if modes is None else modal_compliance(modes, self.M, self.D, self.K, c, wk, forcing,
                                                            np.eye(n_all)[c])
        if found is not None:  # the rows of the dofs: every DOF's, or an output's, only for a solution's recovery
            H, Q_c = found

            def recovery(outputs):
                O = np.eye(n_all) if outputs is None else outputs
                got = modal_compliance(modes, self.M, self.D, self.K, c, wk, forcing, O)
                if got is None:
                    return _projected(*self._solved(wk, forcing), outputs)
                return got[1], got[0]
        else:
            Q_full, X = self._solved(wk, forcing)
            H, Q_c = X[:, c, :], Q_full[:, c]

            def recovery(outputs):
                return _projected(Q_full, X, outputs)
        out = _Compliance(H[0].real, real_form(H[1:]), self.harmonics.from_phasors(Q_c), recovery)
        self._cache["compliance"] = out
        return out

    def _solved(self, wk: np.ndarray, forcing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(Q_full, X)`` at the frequencies ``wk`` by batched solves of :data:`COMPLIANCE_CHUNK` orders at a time."""
        n_all, c = self.M.shape[0], list(self.dofs)
        X, Q_full = np.empty((len(wk), n_all, len(c)), complex), np.empty((len(wk), n_all), complex)
        for lo in range(0, len(wk), COMPLIANCE_CHUNK):
            part = slice(lo, lo + COMPLIANCE_CHUNK)
            X[part], Q_full[part] = dynamic_compliance(_stiffness(self.M, self.D, self.K, wk[part]), c, forcing[part])
        return Q_full, X

    def with_forces(self, forces) -> TorusProblem:
        """This problem with other nonlinear forces on the same DOFs (a contact's clearance, its law's numbers): the
        matrices, orders, bases and forcing kept, and with them the compliance and linear response, computed once.

        Parameters
        ----------
        forces : tuple
            Nonlinear forces (:mod:`rotorred.nonlinear.forces`) on ``dofs``, as the constructor's.

        Returns
        -------
        TorusProblem
        """
        other = TorusProblem(self.M, self.D, self.K, self.harmonics, self.w, self.dofs, self.forcing, tuple(forces))
        other._cache["compliance"] = self._compliance()
        return other

    def by_modes(self) -> TorusProblem:
        """This problem with its compliance computed by the modes (:func:`modal_compliance`, the direct solve where
        they do not match it): one eigen-solution in place of an order's solve each, to about 1e-8 of the direct one
        (for a family that builds a problem a value, a speed branch: docs/model.md §26).

        Returns
        -------
        TorusProblem
            ``self``, its compliance not yet computed.
        """
        if "compliance" not in self._cache:
            self._cache["modes"] = True
        return self

    def linear_response(self) -> np.ndarray:
        """The coefficients of the ``dofs`` without the nonlinear forces, shape (size,)."""
        return self._compliance().z_lin

    def apply(self, X: np.ndarray) -> np.ndarray:
        """``G X`` on the harmonic-major rows of X, G (the dynamic compliance ``Z_k^-1`` of the ``dofs``, m/N) applied
        an order at a time.

        Parameters
        ----------
        X : ndarray, shape (size,) or (size, p)
            Harmonic-major force coefficients (N).

        Returns
        -------
        ndarray, shape of ``X``
            (m).
        """
        g = self._compliance()
        return block_product(g.G0, g.Gk, X.reshape(self.size, -1), self.n).reshape(X.shape)

    @property
    def scale(self) -> float:
        """||z_lin||: what the residual is relative to."""
        return float(np.linalg.norm(self.linear_response())) or 1.0

    def residual(self, z: np.ndarray) -> np.ndarray:
        """``R(z) = z - z_lin + G F_nl(z)`` (no Jacobian: for line searches).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients of the ``dofs`` (m; rad for a rotation DOF).

        Returns
        -------
        ndarray, shape (size,)
            (m).
        """
        return self._evaluated(z)[0].copy()

    def _evaluated(self, z: np.ndarray):
        """R at z and the sampled force derivatives dq, dv (N_1 N_2, c, c), the last point's kept: Newton's step at
        the point its line search has just evaluated needs no second pass through the grid."""
        last = self._cache.get("evaluated")
        if last is not None and np.array_equal(last[0], z):
            return last[1:]
        q, v = self.samples(z)
        f, dq, dv = sampled_forces(self._local_forces, q, v)
        R = z - self.linear_response() + self.apply(self.harmonics.coefficients(f))
        self._cache["evaluated"] = (np.array(z, copy=True), R, dq, dv)
        return R, dq, dv

    def dR_dclearance(self, z: np.ndarray, rub: int = 0) -> np.ndarray:
        """``dR/dclearance = G dF_nl/dclearance`` at z for the clearance of the rub ``forces[rub]``: the forces'
        derivative by the DOF the clearance enters the gap with (``PlateRub.clearance_dof``), a column of the sampled
        Jacobian the residual at z has computed (no residual more; docs/model.md §26).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients of the ``dofs`` (m; rad for a rotation DOF).
        rub : int
            Index in ``forces`` of the rub (a force with ``clearance_dof``).

        Returns
        -------
        ndarray, shape (size,)
            (m/m: dimensionless).
        """
        force, idx = self._local_forces[rub]
        dq = self._evaluated(z)[1]
        return self.apply(self.harmonics.coefficients(dq[:, :, idx[force.clearance_dof]]))

    def _sampled_terms(self, z: np.ndarray):
        """R and the Jacobian's terms at z: the distinct shapes of the sampled force derivatives (N_1 N_2, b) (a shape
        shared by several DOF pairs, e.g. a rub's rank-1 Jacobian, counts once) and the terms ``(b, kind, A)``: shape
        b on the DOF pattern A, of a derivative by q (kind 0) or by dq/dt (kind 1)."""
        h, c = self.harmonics, self.n
        R, dq, dv = self._evaluated(z)
        dq, dv = dq.reshape(h.n_samples, c * c), dv.reshape(h.n_samples, c * c)
        active = np.flatnonzero(np.any(dq != 0.0, axis=1) | np.any(dv != 0.0, axis=1))  # a contact's samples (zero
        flat = np.hstack([dq[active], dv[active]])  # rows are proportional to any: the shapes found on the others)
        base, factor = proportional_columns(flat) if active.size else ([], np.full((2 * c * c, 2), -1.0))
        terms = []
        for b in range(len(base)):
            for kind in (0, 1):
                pairs = factor[kind * c * c:(kind + 1) * c * c]
                A = np.where(pairs[:, 1] == b, pairs[:, 0], 0.0).reshape(c, c)
                if A.any():
                    terms.append((b, kind, A))
        columns = np.zeros((h.n_samples, len(base)))
        columns[active] = flat[:, base]
        return R.copy(), columns, tuple(terms)

    def evaluate(self, z: np.ndarray, omega: float | None = None) -> Evaluation:
        """The residual, and on first use its dense analytic Jacobian ``I + G sum_t kron(T_t, A_t)``
        (:class:`Evaluation`, so :func:`rotorred.nonlinear.hb.solve_periodic` takes the problem). A reference for
        small sets (tests): its memory is size^2; :func:`solve_torus` never builds it (:meth:`jacobian`).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients of the ``dofs`` (m; rad for a rotation DOF).
        omega : float, optional
            Ignored: the base frequencies are fixed, and ``dR_domega`` is NaN, not defined.

        Returns
        -------
        Evaluation
        """
        def jacobian():
            _, columns, terms = self._sampled_terms(z)
            blocks = self.harmonics.toeplitz_blocks(columns) if terms else np.zeros((0, 1, 1))
            T = np.zeros((self.size, self.size))
            for b, kind, A in terms:
                Tb = blocks[b] if kind == 0 else self.harmonics.times_derivative(blocks[b], 1, self.w)
                T += np.kron(Tb, A)
            return np.eye(self.size) + self.apply(T)
        return Evaluation(self.residual(z), self.scale, jacobian, lambda: np.full(self.size, np.nan))

    def jacobian(self, z: np.ndarray, reuse: RankJacobian | None = None) -> tuple[np.ndarray, RankJacobian]:
        """The residual at ``z`` and the Jacobian there, held by its sampled fields on the contact's rank (never a
        matrix: :class:`rotorred.nonlinear.torus_krylov.RankJacobian`).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients of the ``dofs`` (m; rad for a rotation DOF).
        reuse : RankJacobian, optional
            An earlier Jacobian whose preconditioner this one may keep.

        Returns
        -------
        R : ndarray, shape (size,)
            The residual (m).
        J : RankJacobian or None
            None where no force has a derivative (out of contact: J = I).
        """
        R, columns, terms = self._sampled_terms(z)
        if not terms:
            return R, None
        g = self._compliance()
        return R, RankJacobian(self.harmonics, self.w, (g.G0, g.Gk), columns, terms, reuse)

    def newton_step(self, z: np.ndarray, rtol: float = 1e-12, reuse: RankJacobian | None = None):
        """The residual at ``z`` and Newton's step ``-J^-1 R``, by Woodbury's identity on the contact's rank and
        preconditioned GMRES to ``rtol`` (:class:`rotorred.nonlinear.torus_krylov.RankJacobian`).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients of the ``dofs`` (m; rad for a rotation DOF).
        rtol : float
            Relative residual of GMRES on the reduced equation.
        reuse : RankJacobian, optional
            An earlier Jacobian whose preconditioner this step may keep (:meth:`jacobian`).

        Returns
        -------
        R, step : ndarray, shape (size,)
            The residual and the step (m).
        stats : KrylovStats or None
            GMRES's iterations and the residual it reached (None out of contact: the step is -R).
        J : RankJacobian or None
            The Jacobian at ``z`` (its preconditioner for the next step).
        """
        R, J = self.jacobian(z, reuse)
        if J is None:
            return R, -R, None, None
        step, stats = J.solve(-R, rtol)
        return R, step, stats, J

    # ----------------------------------------------------------------------------------------------- recovery
    def recover(self, z: np.ndarray, outputs: np.ndarray | None = None) -> np.ndarray:
        """Complex amplitudes ``Q_k`` of every DOF of the system (the line ``Re(Q_k exp(i k . theta))``), or of
        ``outputs``, from the solution on the ``dofs``.

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients of the ``dofs`` (m; rad for a rotation DOF).
        outputs : ndarray, shape (p, n_all), optional
            Rows that combine the DOFs of ``M`` into p outputs (-); default every DOF (the identity). A few rows
            cost a few DOFs' compliance (by the modes, no eigen-solution more).

        Returns
        -------
        ndarray, shape (K, n_all) or (K, p), complex
            (m; rad for a rotation DOF), n_all the DOFs of ``M``.
        """
        Q_full, X = self._compliance().full() if outputs is None else \
            self._compliance().rows(np.atleast_2d(np.asarray(outputs, float)))
        q, v = self.samples(z)
        f = self.harmonics.coefficients(sampled_forces(self._local_forces, q, v)[0])
        F = self.harmonics.phasors(f, self.n)
        return Q_full - np.einsum("kac,kc->ka", X, F)


@dataclass(frozen=True, repr=False)
class TorusSolution(Result):
    """A converged torus: its coefficients and how Newton got there.

    Attributes
    ----------
    z : ndarray, shape (size,)
        Harmonic-major coefficients of the problem's ``dofs`` (their units: m for the rig).
    iterations : int
        Newton iterations.
    residual : float
        Relative residual ``||R|| / ||z_lin||`` at ``z``.
    history : tuple of float
        The relative residual before each iteration and at the end.
    harmonics : TorusHarmonics
        The orders of ``z``.
    w : (float, float)
        The base frequencies (rad/s).
    dofs : tuple of int
        The DOFs of the unknowns (the problem's ``dofs``).
    krylov : tuple of int
        GMRES iterations of each Newton step (0 for a step out of contact).
    """

    z: np.ndarray
    iterations: int
    residual: float
    history: tuple[float, ...]
    harmonics: TorusHarmonics
    w: tuple[float, float]
    dofs: tuple[int, ...]
    krylov: tuple[int, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "z", checks.array("z", self.z, (self.harmonics.size * len(self.dofs),)))
        checks.integer("iterations", self.iterations, ge=0)
        checks.number("residual", self.residual, ge=0.0)

    @property
    def phasors(self) -> np.ndarray:
        """Complex amplitudes ``Q_k`` of each order and DOF, shape (K, len(dofs)) (m): the line of order k is
        ``Re(Q_k exp(i k . theta))``."""
        return self.harmonics.phasors(self.z, len(self.dofs))

    @property
    def amplitudes(self) -> np.ndarray:
        """Amplitude of each order's line and DOF, shape (K, len(dofs)) (m)."""
        return np.abs(self.phasors)

    @property
    def frequencies(self) -> np.ndarray:
        """The line of each order, ``|k . w| / (2 pi)``, shape (K,) (Hz)."""
        return np.abs(self.harmonics.frequencies(self.w)) / (2.0 * math.pi)

    def summary(self) -> list[str]:
        """The base frequencies, the orders and grid, how Newton converged, and the three strongest lines."""
        h, f = self.harmonics, np.array(self.w) / (2.0 * math.pi)
        amplitudes = self.amplitudes
        strongest = np.argsort(-amplitudes.max(axis=1))[:3]
        top = ", ".join(f"({h.orders[k][0]}, {h.orders[k][1]}) {self.frequencies[k]:.4g} Hz: "
                        f"{amplitudes[k].max():.3g} m" for k in strongest)
        return [f"quasi-periodic harmonic balance on the torus w = ({self.w[0]:.6g}, {self.w[1]:.6g}) rad/s "
                f"({f[0]:.6g}, {f[1]:.6g} Hz): {len(self.dofs)} DOFs",
                f"{h.n_orders} orders (|k1| <= {h.H1}, |k2| <= {h.H2}"
                + (f", |k . w| <= {h.w_max:.6g} rad/s" if h.w_max is not None else "") + f"), grid {h.N1} x {h.N2}",
                f"converged in {self.iterations} Newton iterations ({sum(self.krylov)} GMRES iterations), relative "
                f"residual {self.residual:.3g}",
                f"strongest lines (k1, k2): {top}"]

    def plot(self, ax=None, *, dofs=None, title: str | None = None):
        """The amplitude of each order's line at its frequency ``|k . w| / (2 pi)`` (Hz), a stem a DOF (µm, log scale)
        (:func:`rotorred.plots.branch.plot_harmonics`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        dofs : sequence of int, optional
            Positions among :attr:`dofs` to draw; default all, at most the 6 largest.
        title : str, optional
            The figure's title.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.branch import plot_harmonics

        return plot_harmonics(self.frequencies, self.amplitudes, [f"DOF {d}" for d in self.dofs], ax, columns=dofs,
                              title=title)

    def to_xarray(self):
        """Dims order, dof, base, iteration: ``cos`` a_k, ``sin`` b_k, ``amplitude`` (m) of each order and DOF; the
        orders' ``k1``, ``k2`` and signed ``frequency`` ``k . w / (2 pi)`` (Hz); ``w`` (rad/s); ``history`` of the
        relative residual; the iterations and residual as attributes."""
        h = self.harmonics
        variables = {"k1": ("order", h.orders[:, 0], {"units": "1", "long_name": "order of w_1"}),
                     "k2": ("order", h.orders[:, 1], {"units": "1", "long_name": "order of w_2"}),
                     "w": ("base", np.array(self.w), {"units": "rad/s", "long_name": "base frequencies"}),
                     "history": ("iteration", np.array(self.history),
                                 {"units": "1", "long_name": "relative residual before each Newton iteration"})}
        return harmonic_dataset(self.phasors, np.arange(h.n_orders), h.frequencies(self.w) / (2.0 * math.pi),
                                self.dofs, variables, {"iterations": self.iterations, "residual": self.residual},
                                "order")


def solve_torus(problem: TorusProblem, z0: np.ndarray, *, tol: float = 1e-10, max_iter: int = 40,
                max_halvings: int = 30) -> TorusSolution:
    """The torus near ``z0`` by Newton's method with matrix-free steps (:meth:`TorusProblem.newton_step`: GMRES on
    the contact's rank, never a dense Jacobian) and a backtracking line search on ``||R||`` (trial points by their
    residual alone).

    Each step is solved only as far as it serves (an inexact Newton method): GMRES's relative tolerance is
    ``min(1e-2, rho^1.5)`` with ``rho`` the relative residual of the iterate, so the steps tighten as Newton converges
    and the last ones are nearly exact (docs/model.md §25), never tighter than 1e-3 of what is left to reach ``tol``.

    Parameters
    ----------
    problem : TorusProblem
    z0 : ndarray, shape (problem.size,)
        The start: e.g. the linear response, a transient's record fitted on the orders, or a smaller truncation's
        solution (:meth:`TorusHarmonics.transfer`).
    tol : float
        Relative residual ``||R|| / ||z_lin||`` to reach.
    max_iter, max_halvings : int
        Newton iterations, and halvings of a step in the line search.

    Returns
    -------
    TorusSolution

    Raises
    ------
    NotConverged
        (with omega = w_1) if the relative residual is not below ``tol`` after ``max_iter`` iterations, or no step
        lowers it.
    """
    z = checks.array("z0", z0, (problem.size,)).copy()
    scale, history, krylov, J = problem.scale, [], [], None
    R = problem.residual(z)
    for it in range(max_iter + 1):
        norm = float(np.linalg.norm(R))
        history.append(norm / scale)
        if history[-1] <= tol:
            return TorusSolution(z, it, history[-1], tuple(history), problem.harmonics, problem.w, problem.dofs,
                                 tuple(krylov))
        if it == max_iter:
            break
        rtol = max(min(FORCING_MAX, history[-1] ** FORCING_ORDER), 1e-3 * tol / history[-1], KRYLOV_FLOOR)
        try:
            _, step, stats, J = problem.newton_step(z, rtol, J)
        except (sla.LinAlgError, ValueError):
            raise NotConverged(problem.w[0], history[-1], tol, it, "singular Jacobian") from None
        krylov.append(0 if stats is None else stats.iterations)
        a = 1.0
        for _ in range(max_halvings):  # the residual alone (no Jacobian) for each trial
            trial = z + a * step
            R_trial = problem.residual(trial)
            if np.linalg.norm(R_trial) <= (1.0 - 1e-4 * a) * norm:
                z, R = trial, R_trial
                break
            a *= 0.5
        else:
            raise NotConverged(problem.w[0], history[-1], tol, it, "no step reduces the residual")
    raise NotConverged(problem.w[0], history[-1], tol, max_iter, "iteration limit")
