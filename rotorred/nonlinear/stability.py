"""Stability of a periodic solution by Hill's method.

A perturbation ``e^{lambda t} p(t)`` with ``p`` of period T in the same harmonic basis turns the linearised
equation into the quadratic eigenproblem ``(lambda^2 A2 + lambda A1 + A0) p = 0``
(:meth:`PeriodicProblem.hill_matrices`), solved as a first-order problem of size 2 (2H + 1) n. Its eigenvalues
are the Floquet exponents, each repeated at ``lambda + i j omega`` for every shift j within the truncation.

**Sorting** (which 2 n eigenvalues are the exponents): the 2 n eigenvalues of smallest ``|Im lambda|`` are kept:
an exponent's copies lie ``j omega`` apart along the imaginary axis, and its own representative is the one nearest
the real axis (on sorting Hill's eigenvalues: Lazarus & Thomas, C. R. Mecanique 338, 2010).
Tested on systems with known exponents: a linear oscillator (its eigenvalues, exactly) and the Duffing
oscillator's branches against long transients.

The solution is stable when every exponent has ``Re lambda < 0``; the Floquet multipliers are
``exp(lambda T)``.

**The monodromy matrix** (:func:`floquet_by_monodromy`) needs no sorting and works on condensed problems, whose
Hill matrices would be the whole system's: the linearised equation ``M x'' + (D + J_v(t)) x' + (K + J_q(t)) x = 0``
(the nonlinear forces' derivatives along the solution, on their few DOFs) is integrated over one period in state
space as a product of matrix exponentials, the state matrix held at its value midway through each of
``N substeps`` intervals (second order in the interval). Stretches where the derivatives vanish (out of contact)
are one exponential each. Its multipliers are the Floquet multipliers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from rotorred.nonlinear.fourier import Harmonics, basis
from rotorred.nonlinear.hb import sampled_forces

__all__ = ["Floquet", "floquet", "floquet_by_monodromy"]


@dataclass(frozen=True)
class Floquet:
    """The Floquet exponents of a periodic solution.

    Attributes
    ----------
    exponents : ndarray, shape (2 n,), complex
        lambda (1/s), sorted by real part, largest first.
    period : float
        T = 2 pi / omega (s).
    """

    exponents: np.ndarray
    period: float

    @property
    def multipliers(self) -> np.ndarray:
        """exp(lambda T), shape (2 n,)."""
        return np.exp(self.exponents * self.period)

    @property
    def max_real(self) -> float:
        """The largest Re lambda (1/s): > 0 unstable."""
        return float(self.exponents.real.max())

    @property
    def stable(self) -> bool:
        """Every multiplier inside the unit circle (by a margin of 1e-9 in ``|mu|`` over a period)."""
        return self.max_real * self.period < -1e-9


def floquet(problem, z: np.ndarray, omega: float) -> Floquet:
    """Floquet exponents of the periodic solution ``z`` at ``omega`` by Hill's method: the eigenvalues of the Hill
    quadratic eigenproblem (:meth:`PeriodicProblem.hill_matrices`) in first-order form, the 2 n of smallest
    ``|Im lambda|`` kept.

    Parameters
    ----------
    problem : PeriodicProblem
        Anything with ``hill_matrices(z, omega)`` and ``n`` (:meth:`PeriodicProblem.hill_matrices`).
    z : ndarray, shape ((2H + 1) n,)
        The solution's harmonic-major coefficients (m; rad for a rotation DOF).
    omega : float
        Its response frequency (rad/s).

    Returns
    -------
    Floquet
        The 2 n exponents (1/s).
    """
    A2, A1, A0 = problem.hill_matrices(z, omega)
    m = A0.shape[0]
    A2_inv = sla.inv(A2)
    state = np.block([[np.zeros((m, m)), np.eye(m)], [-A2_inv @ A0, -A2_inv @ A1]])
    lam = sla.eigvals(state)
    keep = np.argsort(np.abs(lam.imag), kind="stable")[:2 * problem.n]
    exponents = lam[keep]
    return Floquet(exponents[np.argsort(-exponents.real, kind="stable")], 2.0 * np.pi / omega)


def floquet_by_monodromy(problem, z: np.ndarray, omega: float, substeps: int = 4) -> Floquet:
    """Floquet exponents ``log(mu) / T`` of the periodic solution ``z`` at ``omega`` from the monodromy matrix of
    the whole linearised system (all 2 n_all multipliers; a :class:`PeriodicProblem` or a condensed one).

    Parameters
    ----------
    problem : PeriodicProblem or CondensedProblem
    z : ndarray, shape ((2H + 1) n,)
        The solution's harmonic-major coefficients on the problem's ``dofs`` (m; rad for a rotation DOF).
    omega : float
        Its base frequency (rad/s).
    substeps : int
        Intervals per AFT sample interval (the derivatives are evaluated from the Fourier series at the refined
        midpoints).

    Returns
    -------
    Floquet
    """
    h = problem.harmonics
    fine = basis(h.H, h.N * substeps)
    T = 2.0 * np.pi / omega
    dt = T / fine.N
    shift = _half_interval_shift(fine)  # the state matrix midway through each interval
    zc = z.reshape(h.size, problem.n)
    q = fine.E @ (shift @ zc)
    v = omega * (fine.E @ (shift @ (h.nabla @ zc)))
    _, dq, dv = sampled_forces(problem.force_columns, q, v)
    A0, lower = _state_matrix(problem, omega)
    c = list(problem.dofs)
    n_all = problem.M.shape[0]
    Phi, run = np.eye(2 * n_all), 0
    free = {}
    for j in range(fine.N):
        if not (dq[j].any() or dv[j].any()):
            run += 1
            continue
        if run:
            Phi = _free(free, A0, run * dt) @ Phi
            run = 0
        A = A0.copy()
        A[n_all:, c] -= lower @ dq[j]
        A[n_all:, [n_all + i for i in c]] -= lower @ dv[j]
        Phi = sla.expm(A * dt) @ Phi
    if run:
        Phi = _free(free, A0, run * dt) @ Phi
    mu = sla.eigvals(Phi)
    exponents = np.log(mu.astype(complex)) / T
    return Floquet(exponents[np.argsort(-exponents.real, kind="stable")], T)


def _half_interval_shift(h: Harmonics) -> np.ndarray:
    """The coefficient map of a shift by half a sample interval, d theta = pi / N: (a, b) of harmonic k rotate."""
    R = np.zeros((h.size, h.size))
    R[0, 0] = 1.0
    phase = np.pi / h.N
    for k in range(1, h.H + 1):
        c, s = np.cos(k * phase), np.sin(k * phase)
        # a cos(k(t + d)) + b sin(k(t + d)) = (a c + b s) cos kt + (b c - a s) sin kt
        R[2 * k - 1, 2 * k - 1], R[2 * k - 1, 2 * k] = c, s
        R[2 * k, 2 * k - 1], R[2 * k, 2 * k] = -s, c
    return R


def _state_matrix(problem, omega: float):
    """The linear state matrix [[0, I], [-M^-1 K, -M^-1 D]] and M^-1's columns of the nonlinear DOFs."""
    M, K, D = problem.M, problem.stiffness_matrix(omega), problem.velocity_matrix(omega)
    n = M.shape[0]
    Minv = sla.inv(M)
    A0 = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ D]])
    return A0, Minv[:, list(problem.dofs)]


def _free(cache: dict, A0: np.ndarray, t: float) -> np.ndarray:
    key = round(t, 15)
    if key not in cache:
        cache[key] = sla.expm(A0 * t)
    return cache[key]
