"""Bending compliance of the rubbing plate at the contact point (Xu et al. 2016, Eqs. 10-11).

The rub-impact law (:mod:`rotorred.transient.contact`) needs the deflection ``W`` of the plate at the
contact point under the normal contact load ``F``. Two plate models of the paper are offered,
both reduced to an affine law ``W = lam F + w0`` valid in contact (``F >= 0``):

* :class:`NavierPlate` -- a simply supported a x b plate (Eq. 10), point load at (xi, eta):

      W = F * 4 / (pi^4 a b D) * sum_m sum_n sin^2(m pi xi / a) sin^2(n pi eta / b)
                                           / (m^2 / a^2 + n^2 / b^2)^2,
      D = E h^3 / (12 (1 - nu^2)),

  so ``lam`` is the double sum times the prefactor and ``w0 = 0``.
* :class:`ClampedFreePlate` -- one edge clamped, the others free (Eq. 11), the paper's fit
  ``F = a0 W - b0``. Inverted, ``W = F / a0 + b0 / a0``: ``lam = 1 / a0`` and ``w0 = b0 / a0``.

Both are precomputed once (the series is summed at construction); the integrator only sees
``compliance`` (m/N) and ``offset`` (m).

Convergence of the Navier series (Eq. 10)
-----------------------------------------
The sum over ``n`` is done exactly (closed form of ``sum_n cos(n x) / (n^2 + beta^2)^2``, see
:func:`_inner_sums`); the remaining sum over ``m`` has terms ``O(m^-3)``, so its tail after ``N``
terms is ``O(N^-2)``: the error at ``2N`` is about one third of the change between ``N`` and
``2N``. The sum is evaluated for ``N = 16, 32, 64, ...`` until that estimate is at most ``tol``
(default 1e-10), then the extrapolated value ``S_2N + (S_2N - S_N) / 3`` is used
(Richardson). ``N`` is capped at 2^22; a plate that does not converge by then raises
:class:`rotorred.checks.InputError` naming ``tol``. (Summing the double series directly converges too
slowly: 4096 x 4096 terms leave a relative error of 5e-8 at the plate centre.)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from rotorred import checks

_N_START = 16
_N_MAX = 1 << 22


def _inner_sums(beta: np.ndarray, x: float) -> np.ndarray:
    """sum_{n>=1} sin^2(n x / 2) / (n^2 + beta^2)^2 in closed form, for each beta > 0.

    With f(x, beta) = sum_n cos(n x) / (n^2 + beta^2) = pi cosh(beta (pi - x)) / (2 beta sinh(pi beta))
    - 1 / (2 beta^2) (0 <= x <= 2 pi), sum_n cos(n x) / (n^2 + beta^2)^2 = -(1 / (2 beta)) df/dbeta, and
    sin^2(n x / 2) = (1 - cos(n x)) / 2. Written with decaying exponentials (no overflow).
    """
    def g(xx):
        e1 = np.exp(-beta * xx)
        e2 = np.exp(-beta * (2 * math.pi - xx))
        e3 = np.exp(-2 * math.pi * beta)
        den = 1.0 - e3
        h = (e1 + e2) / den
        dh = ((-xx * e1 - (2 * math.pi - xx) * e2) * den - (e1 + e2) * 2 * math.pi * e3) / den**2
        df = math.pi * dh / (2 * beta) - math.pi * h / (2 * beta**2) + 1.0 / beta**3
        return -df / (2 * beta)

    return 0.5 * (g(0.0) - g(x))


def _partial_sum(a: float, b: float, xi: float, eta: float, N: int) -> float:
    """sum_{m<=N} sum_{n>=1} sin^2(m pi xi/a) sin^2(n pi eta/b) / (m^2/a^2 + n^2/b^2)^2 (n summed exactly)."""
    m = np.arange(1, N + 1, dtype=float)
    beta = m * b / a
    inner = b**4 * _inner_sums(beta, 2 * math.pi * eta / b)
    return float(np.sum(np.sin(m * math.pi * xi / a) ** 2 * inner))


@functools.lru_cache(maxsize=64)
def navier_series(a: float, b: float, xi: float, eta: float, tol: float = 1e-10) -> tuple[float, int, float]:
    """Double sum of Eq. 10, the inner (n) sum in closed form, with the convergence check of the
    module docstring on the outer (m) sum.

    Returns
    -------
    value : float
        Extrapolated sum (m^4).
    N : int
        Number of outer terms of the last partial sum.
    error : float
        Estimated relative error of the un-extrapolated last partial sum, |S_2N - S_N| / (3 S_2N).
    """
    N = _N_START
    s_prev = _partial_sum(a, b, xi, eta, N)
    while True:
        N2 = 2 * N
        s = _partial_sum(a, b, xi, eta, N2)
        err = abs(s - s_prev) / (3.0 * abs(s))
        if err <= tol:
            return s + (s - s_prev) / 3.0, N2, err
        if N2 >= _N_MAX:
            checks.fail("tol", tol, f"not reached by the Navier series (Eq. 10) with {N2} terms "
                        f"(estimated error {err:.3g}); must be larger")
        N, s_prev = N2, s


@dataclass(frozen=True)
class NavierPlate:
    """Simply supported rectangular plate loaded at (xi, eta) (Xu et al. 2016, Eq. 10).

    Parameters
    ----------
    a, b : float
        Plate side lengths (m).
    h : float
        Thickness (m).
    E : float
        Young's modulus (Pa).
    nu : float
        Poisson's ratio (-).
    xi, eta : float, optional
        Contact point (m), 0 < xi < a, 0 < eta < b; default the plate centre.
    tol : float
        Relative truncation tolerance of the double series (see the module docstring).

    Attributes
    ----------
    compliance : float
        Deflection per unit load at the contact point, ``W / F`` (m/N).
    offset : float
        Always 0 (m).
    n_terms : int
        Outer (m) terms used.
    D : float
        Flexural rigidity E h^3 / (12 (1 - nu^2)) (N m).
    """

    a: float = 0.10
    b: float = 0.06
    h: float = 0.003
    E: float = 2.1e11
    nu: float = 0.3
    xi: float | None = None
    eta: float | None = None
    tol: float = 1e-10
    compliance: float = field(init=False)
    offset: float = field(init=False, default=0.0)
    n_terms: int = field(init=False)
    D: float = field(init=False)

    def __post_init__(self):
        for name, unit in (("a", "m"), ("b", "m"), ("h", "m"), ("E", "Pa"), ("tol", "-")):
            checks.positive(name, getattr(self, name), unit)
        checks.number("nu", self.nu, gt=-1.0, lt=0.5)
        xi = self.a / 2 if self.xi is None else checks.number("xi", self.xi, "m", gt=0.0, lt=self.a)
        eta = self.b / 2 if self.eta is None else checks.number("eta", self.eta, "m", gt=0.0, lt=self.b)
        object.__setattr__(self, "xi", float(xi))
        object.__setattr__(self, "eta", float(eta))
        D = self.E * self.h**3 / (12.0 * (1.0 - self.nu**2))
        s, N, _ = navier_series(self.a, self.b, xi, eta, self.tol)
        object.__setattr__(self, "D", D)
        object.__setattr__(self, "n_terms", N)
        object.__setattr__(self, "compliance", 4.0 / (math.pi**4 * self.a * self.b * D) * s)

    def deflection(self, F: float) -> float:
        """Deflection ``W = lam F`` at the contact point (Eq. 10).

        Parameters
        ----------
        F : float
            Load at the contact point (N).

        Returns
        -------
        float
            W (m).
        """
        return self.compliance * F


@dataclass(frozen=True)
class ClampedFreePlate:
    """Plate with one edge clamped and the others free: the paper's fit F = a0 W - b0 (Eq. 11).

    In contact the deflection is ``W = (F + b0) / a0``: a compliance ``1 / a0`` and an
    offset ``b0 / a0``. The offset is a deflection already present when the contact force
    is zero, which for the contact law is the same as a clearance larger by ``b0 / a0``:
    the force starts from zero when the penetration reaches ``b0 / a0``, so the force stays
    continuous at the onset of contact. ``b0 < 0`` would make the plate push the disk
    before touching it, so ``b0 >= 0`` is required.

    Parameters
    ----------
    a0 : float
        Slope of the fit (N/m), > 0.
    b0 : float
        Intercept of the fit (N), >= 0.

    Attributes
    ----------
    compliance : float
        1 / a0 (m/N).
    offset : float
        b0 / a0 (m).
    """

    a0: float = 5.0e6
    b0: float = 0.0
    compliance: float = field(init=False)
    offset: float = field(init=False)

    def __post_init__(self):
        checks.positive("a0", self.a0, "N/m")
        if checks.number("b0", self.b0, "N") < 0.0:
            checks.fail("b0", self.b0, "must be >= 0 (a negative intercept of F = a0 W - b0 would push the disk "
                        "before contact)", "N")
        object.__setattr__(self, "compliance", 1.0 / self.a0)
        object.__setattr__(self, "offset", self.b0 / self.a0)

    def deflection(self, F: float) -> float:
        """Deflection ``W = (F + b0) / a0`` at the contact point (Eq. 11).

        Parameters
        ----------
        F : float
            Load at the contact point (N), >= 0.

        Returns
        -------
        float
            W (m).
        """
        return (F + self.b0) / self.a0


@dataclass(frozen=True)
class RigidPlate:
    """A plate that does not bend (compliance 0): the whole penetration is Hertz deformation."""

    compliance: float = field(init=False, default=0.0)
    offset: float = field(init=False, default=0.0)

    def deflection(self, F: float) -> float:
        """Deflection at the contact point: always 0.

        Parameters
        ----------
        F : float
            Load at the contact point (N).

        Returns
        -------
        float
            0 (m).
        """
        return 0.0
