"""Nonlinear forces for harmonic balance, evaluated at the AFT's time samples.

Each force acts on a few DOFs (``dofs``) of the system and gives, at ``N`` instants, its value and its
derivatives with respect to those DOFs' displacements and velocities:

    f, df_dq, df_dv = force.evaluate(q, v)      # q, v: (N, m); f: (N, m); df_dq, df_dv: (N, m, m)

with ``m = len(dofs)``. The force is the one the structure feels, on the left-hand side of
``M q'' + D q' + K q + f(q, q') = F(t)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotorred import checks

__all__ = ["CubicSpring", "CircularClearance"]


@dataclass(frozen=True)
class CubicSpring:
    """A cubic spring on one DOF: ``f = k3 q^3`` (the Duffing oscillator's).

    Parameters
    ----------
    dof : int
    k3 : float
        Cubic stiffness (N/m^3), any sign (hardening > 0).
    """

    dof: int
    k3: float

    def __post_init__(self):
        object.__setattr__(self, "dof", checks.integer("dof", self.dof, ge=0))
        object.__setattr__(self, "k3", checks.number("k3", self.k3, "N/m^3"))

    @property
    def dofs(self) -> tuple[int, ...]:
        return (self.dof,)

    def evaluate(self, q: np.ndarray, v: np.ndarray):
        f = self.k3 * q**3
        return f, (3.0 * self.k3 * q**2)[:, :, None], np.zeros(q.shape + (1,))


@dataclass(frozen=True)
class CircularClearance:
    """A circular clearance (a rotor in a round stator) with a penalty contact stiffness, no friction: for the
    radial displacement ``r = |(x, y)|`` beyond the gap ``g``, ``f = k_c (r - g) (x, y) / r``, else 0.

    Parameters
    ----------
    dofs : (int, int)
        The x and y DOFs.
    gap : float
        Radial clearance g (m), > 0.
    k_c : float
        Contact stiffness (N/m), > 0.
    """

    dofs: tuple[int, int]
    gap: float
    k_c: float

    def __post_init__(self):
        dofs = checks.sequence("dofs", tuple(self.dofs), lambda f, v: checks.integer(f, v, ge=0), min_len=2, max_len=2)
        object.__setattr__(self, "dofs", dofs)
        object.__setattr__(self, "gap", checks.positive("gap", self.gap, "m"))
        object.__setattr__(self, "k_c", checks.positive("k_c", self.k_c, "N/m"))

    def evaluate(self, q: np.ndarray, v: np.ndarray):
        r = np.hypot(q[:, 0], q[:, 1])
        touching = r > self.gap
        safe = np.where(touching, r, 1.0)
        share = np.where(touching, 1.0 - self.gap / safe, 0.0)  # (r - g) / r, 0 out of contact
        f = self.k_c * share[:, None] * q
        outer = np.einsum("ti,tj->tij", q, q) * np.where(touching, self.gap / safe**3, 0.0)[:, None, None]
        df_dq = self.k_c * (share[:, None, None] * np.eye(2) + outer)
        return f, df_dq, np.zeros_like(df_dq)
