"""Nonlinear forces for harmonic balance, evaluated at the AFT's time samples.

Each force acts on a few DOFs (``dofs``) of the system and gives, at ``N`` instants, its value and its
derivatives with respect to those DOFs' displacements and velocities:

    f, df_dq, df_dv = force.evaluate(q, v)      # q, v: (N, m); f: (N, m); df_dq, df_dv: (N, m, m)

with ``m = len(dofs)``. The force is the one the structure feels, on the left-hand side of
``M q'' + D q' + K q + f(q, q') = F(t)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotorred import checks
from rotorred.transient.contact import RubPlate, disk_force, sliding_velocity
from rotorred.transient.contact_solve import normal_roots

__all__ = ["CubicSpring", "CircularClearance", "PlateRub"]

#: the normal law's root at each sample to this step, relative (as the transient's contact.normal_force)
ROOT_TOL = 1e-14


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


@dataclass(frozen=True)
class PlateRub:
    """The paper's rub-impact (Xu et al. 2016, section 2.3; :mod:`rotorred.transient.contact`): the disk at DOFs
    (x, y) against a plate whose rigid motion (u_n, u_t) is two more DOFs, the normal law in series with the plate's
    bending (the generated law), and Coulomb friction sliding at the disk's surface speed.

    With the gap ``g = clearance + u_n - (x, y) . n`` and the penetration ``p = -g``, the normal force ``P(p, p')``
    is the law's root at each sample; friction is ``T = -mu_d P sign(v_rel)``,
    ``v_rel = Omega r + (x', y') . t - u_t'``. The forces on the left-hand side are ``P n - T t`` on the disk and
    ``(-P, +T)`` on (u_n, u_t) (Eq. 12 and Eq. 7 moved to the left). Harmonic balance sees sliding only: a sample
    where ``v_rel`` changes sign would stick, which this force does not model (the rig's rim runs at tens of m/s
    against whirl velocities of cm/s).

    Parameters
    ----------
    dofs : (int, int, int, int)
        The disk's x and y DOFs and the plate's normal and tangential DOFs.
    plate : RubPlate
    surface_speed : float
        Omega r of the disk's rim (m/s): its spool's speed times ``plate.disk_radius``.
    """

    dofs: tuple[int, int, int, int]
    plate: RubPlate
    surface_speed: float

    def __post_init__(self):
        dofs = checks.sequence("dofs", tuple(self.dofs), lambda f, v: checks.integer(f, v, ge=0), min_len=4, max_len=4)
        object.__setattr__(self, "dofs", dofs)
        if not isinstance(self.plate, RubPlate):
            checks.fail("plate", self.plate, "must be a RubPlate")
        object.__setattr__(self, "surface_speed", checks.number("surface_speed", self.surface_speed, "m/s"))

    def evaluate(self, q: np.ndarray, v: np.ndarray):
        grad, P, dP_dp, dP_drate, per_P = self._law(q, v)
        d = np.zeros((2,) + q.shape + (4,))  # df/dq, df/dv: rank one, (forces per unit P) (dP/dp, dP/dp') grad^T
        on = np.flatnonzero((dP_dp != 0.0) | (dP_drate != 0.0))  # in contact: zero elsewhere
        d[0, on] = (per_P[on] * dP_dp[on, None])[:, :, None] * grad
        d[1, on] = (per_P[on] * dP_drate[on, None])[:, :, None] * grad
        return per_P * P[:, None], d[0], d[1]

    def slip_sign(self, v: np.ndarray) -> np.ndarray:
        """sign(v_rel) at the samples of the velocities ``v`` (N, 4) (:func:`rotorred.transient.contact.sliding_velocity`,
        the rim speed given as Omega r)."""
        return np.sign(sliding_velocity(self.plate, self.surface_speed, 1.0, v[:, 0], v[:, 1], v[:, 3]))

    @property
    def gradient(self) -> np.ndarray:
        """d p / d(x, y, u_n, u_t): the disk's approach to the plate ``p = q . gradient - clearance`` (the
        penetration, m, > 0 in contact) is its displacement along the normal less the plate's."""
        return np.array([math.cos(self.plate.theta), math.sin(self.plate.theta), -1.0, 0.0])

    def _law(self, q: np.ndarray, v: np.ndarray):
        """d p / d(x, y, u_n, u_t) (also of p' on the velocities), P and its tangents at the samples, and the forces
        per unit P, shape (N, 4): ``P n - T t`` on the disk (:func:`rotorred.transient.contact.disk_force` turned to
        the left-hand side), ``(-P, T)`` on the plate, with ``T = -mu_d sign(v_rel) P``."""
        plate, grad = self.plate, self.gradient
        c, s = grad[0], grad[1]
        P, dP_dp, dP_drate = normal_roots(np.ascontiguousarray(q @ grad) - plate.clearance, np.ascontiguousarray(v @ grad),
                                          plate.K_nr, plate.c, plate.compliance, plate.offset, ROOT_TOL)
        T_per_P = -plate.mu_d * self.slip_sign(v)
        fx, fy = disk_force(1.0, T_per_P, c, s)
        per_P = np.column_stack([-fx, -fy, -np.ones_like(T_per_P), T_per_P])
        return grad, P, dP_dp, dP_drate, per_P

    def with_clearance(self, clearance: float) -> PlateRub:
        """The same rub at another clearance (m)."""
        return PlateRub(self.dofs, self.plate.with_(clearance=clearance), self.surface_speed)

    #: the position among ``dofs`` of the DOF the clearance enters the gap with: ``g = clearance + u_n - (x, y) . n``,
    #: so d f / d clearance is the column of d f / dq at u_n (the derivative of the forces by the clearance, for free)
    clearance_dof = 2
