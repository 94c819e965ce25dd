"""Stability of a periodic solution by Hill's method.

A perturbation ``e^{lambda t} p(t)`` with ``p`` of period T in the same harmonic basis turns the linearised
equation into the quadratic eigenproblem ``(lambda^2 A2 + lambda A1 + A0) p = 0``
(:meth:`PeriodicProblem.hill_matrices`), solved as a first-order problem of size 2 (2H + 1) n. Its eigenvalues
are the Floquet exponents, each repeated at ``lambda + i j omega`` for every shift j within the truncation.

**Sorting** (which 2 n eigenvalues are the exponents): each eigenvector's displacement part is split over the
harmonic orders, and the 2 n eigenvalues whose eigenvectors have the lowest mean order (the |p_h|^2-weighted
mean of h) are kept: the exponent's own representative carries its motion on the lowest harmonics, its
shifted copies on harmonics shifted by j (the symmetric sorting of Lazarus & Thomas, C. R. Mecanique 338, 2010).
Tested on systems with known exponents: a linear oscillator (its eigenvalues, exactly) and the Duffing
oscillator's branches against long transients.

The solution is stable when every exponent has ``Re lambda < 0``; the Floquet multipliers are
``exp(lambda T)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

__all__ = ["Floquet", "floquet"]


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
        """Every multiplier inside the unit circle (by a margin of 1e-9 in |mu| over a period)."""
        return self.max_real * self.period < -1e-9


def floquet(problem, z: np.ndarray, omega: float) -> Floquet:
    """Floquet exponents of the periodic solution ``z`` at ``omega`` by Hill's method with symmetric sorting."""
    A2, A1, A0 = problem.hill_matrices(z, omega)
    m = A0.shape[0]
    A2_inv = sla.inv(A2)
    state = np.block([[np.zeros((m, m)), np.eye(m)], [-A2_inv @ A0, -A2_inv @ A1]])
    lam = sla.eigvals(state)
    keep = np.argsort(np.abs(lam.imag), kind="stable")[:2 * problem.n]
    exponents = lam[keep]
    return Floquet(exponents[np.argsort(-exponents.real, kind="stable")], 2.0 * np.pi / omega)
