"""Nonlinear forces for harmonic balance, evaluated at the AFT's time samples.

Each force acts on a few DOFs (``dofs``) of the system and gives, at ``N`` instants, its value and its
derivatives with respect to those DOFs' displacements and velocities:

    f, df_dq, df_dv = force.evaluate(q, v)      # q, v: (N, m); f: (N, m); df_dq, df_dv: (N, m, m)

with ``m = len(dofs)``. The force is the one the structure feels, on the left-hand side of
``M q'' + D q' + K q + f(q, q') = F(t)``.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from rotorred import checks
from rotorred.transient import numba_cache
from rotorred.transient.contact import RubPlate, sliding_velocity
from rotorred.transient.contact_solve import compiled_disk_force, compiled_normal_root

numba_cache.register()

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
        """The force ``k3 q^3`` and its derivatives at the AFT samples.

        Parameters
        ----------
        q, v : ndarray, shape (N, 1)
            Displacement (m) and velocity (m/s) of :attr:`dof` at each sample.

        Returns
        -------
        f : ndarray, shape (N, 1)
            The force (N).
        df_dq, df_dv : ndarray, shape (N, 1, 1)
            ``3 k3 q^2`` (N/m) and zeros (N s/m).
        """
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
        """The contact force ``k_c (r - g) (x, y) / r`` (0 for ``r <= g``) and its derivatives at the AFT samples.

        Parameters
        ----------
        q, v : ndarray, shape (N, 2)
            Displacements (m) and velocities (m/s) of the x and y DOFs at each sample.

        Returns
        -------
        f : ndarray, shape (N, 2)
            The force on (x, y) (N).
        df_dq, df_dv : ndarray, shape (N, 2, 2)
            Its Jacobians (N/m) and zeros (N s/m): no friction, no damping.
        """
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
        """The forces ``P n - T t`` on the disk and ``(-P, T)`` on the plate, and their derivatives, at the AFT samples.

        Parameters
        ----------
        q, v : ndarray, shape (N, 4)
            Displacements (m) and velocities (m/s) of (x, y, u_n, u_t) at each sample.

        Returns
        -------
        f : ndarray, shape (N, 4)
            The forces on (x, y, u_n, u_t) (N), zero out of contact.
        df_dq, df_dv : ndarray, shape (N, 4, 4)
            Their Jacobians (N/m) and (N s/m), rank one at each sample.
        """
        plate, grad, (N, m) = self.plate, self.gradient, q.shape
        f, dq, dv = np.zeros((N, m)), np.zeros((N, m, m)), np.zeros((N, m, m))
        _plate_rub(q @ grad - plate.clearance, v @ grad, self.slip_sign(v), grad, plate.mu_d,
                   (plate.K_nr, plate.c, plate.compliance, plate.offset, ROOT_TOL), f, dq, dv)
        return f, dq, dv

    def slip_sign(self, v: np.ndarray) -> np.ndarray:
        """sign(v_rel) of ``v_rel = Omega r + (x', y') . t - u_t'`` at the samples
        (:func:`rotorred.transient.contact.sliding_velocity`, the rim speed given as Omega r).

        Parameters
        ----------
        v : ndarray, shape (N, 4)
            Velocities of (x, y, u_n, u_t) at each sample (m/s).

        Returns
        -------
        ndarray, shape (N,)
            -1, 0 or 1 (-).
        """
        return np.sign(sliding_velocity(self.plate, self.surface_speed, 1.0, v[:, 0], v[:, 1], v[:, 3]))

    @property
    def gradient(self) -> np.ndarray:
        """d p / d(x, y, u_n, u_t): the disk's approach to the plate ``p = q . gradient - clearance`` (the
        penetration, m, > 0 in contact) is its displacement along the normal less the plate's."""
        return np.array([math.cos(self.plate.theta), math.sin(self.plate.theta), -1.0, 0.0])

    def with_clearance(self, clearance: float) -> PlateRub:
        """The same rub at another clearance: a copy with the clearance checked alone, the rest checked already (a
        branch in the clearance asks one at every evaluation; the whole plate's checks were a quarter of one).

        Parameters
        ----------
        clearance : float
            The plate's clearance (m).

        Returns
        -------
        PlateRub

        Raises
        ------
        InputError
            If ``clearance`` is not a finite number.
        """
        plate, rub = copy.copy(self.plate), copy.copy(self)
        object.__setattr__(plate, "clearance", checks.number("clearance", clearance, "m"))
        object.__setattr__(rub, "plate", plate)
        return rub

    #: the position among ``dofs`` of the DOF the clearance enters the gap with: ``g = clearance + u_n - (x, y) . n``,
    #: so d f / d clearance is the column of d f / dq at u_n (the derivative of the forces by the clearance, for free)
    clearance_dof = 2



@njit(cache=True)
def _plate_rub(penetration, rate, slip, grad, mu_d, law, f, dq, dv):
    """:class:`PlateRub`'s forces and their derivatives at every sample, into ``f`` (N, 4) and ``dq``, ``dv`` (N, 4, 4)
    (zero out of contact): the normal force P of the series law and its tangents at the penetration and its rate
    (:func:`rotorred.transient.contact.normal_root`, compiled), friction ``T = -mu_d sign(v_rel) P``, and per unit P
    the forces ``P n - T t`` on the disk (:func:`rotorred.transient.contact.disk_force` to the left-hand side) and
    ``(-P, T)`` on the plate; the derivatives are rank one, (forces per unit P) (dP/dp, dP/dp') ``grad^T``.

    Parameters
    ----------
    penetration, rate, slip : ndarray, shape (N,)
        p = q . grad - clearance (m), its rate (m/s) and sign(v_rel) at each sample.
    grad : ndarray, shape (4,)
        d p / d(x, y, u_n, u_t) (:attr:`PlateRub.gradient`).
    mu_d : float
    law : tuple
        ``(K_nr, c, lam, w0, tol)`` of the normal law.
    """
    per = np.empty(4)
    for j in range(penetration.shape[0]):
        if penetration[j] <= law[3]:  # no deformation: no force
            continue
        P, dP_dp, dP_drate = compiled_normal_root(penetration[j], rate[j], law[0], law[1], law[2], law[3], law[4])
        T_per_P = -mu_d * slip[j]
        fx, fy = compiled_disk_force(1.0, T_per_P, grad[0], grad[1])
        per[0], per[1], per[2], per[3] = -fx, -fy, -1.0, T_per_P
        for a in range(4):
            f[j, a] = per[a] * P
            for b in range(4):
                dq[j, a, b] = per[a] * dP_dp * grad[b]
                dv[j, a, b] = per[a] * dP_drate * grad[b]
