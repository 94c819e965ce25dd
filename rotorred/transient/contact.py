"""Rub-impact between a disk and an elastically supported plate (Xu et al. 2016, section 2.3).

Geometry and sign conventions (the paper's Eqs. 5-6 are inconsistent in sign; this is the
project's single definition)
----------------------------------------------------------------------------------------
* ``n = (cos theta, sin theta)`` is the plate normal, pointing from the disk centre towards
  the plate; ``t = (-sin theta, cos theta)`` is the tangent (``n`` turned by +90 deg, the
  direction in which the rim of a disk spinning about +z passes the contact point).
* The plate moves as a rigid body along ``n`` (``u_n``) and ``t`` (``u_t``) on linear
  spring-dampers (Eq. 7): ``m_p u_n'' + c_n u_n' + k_n u_n = +P`` and
  ``m_p u_t'' + c_t u_t' + k_t u_t = -T``.
* Gap (positive = open), with ``(x, y)`` the displacement of the disk centre:
  ``g = clearance + u_n - (x cos theta + y sin theta)``; penetration ``p = max(0, -g)``.
  The disk radius enters only the sliding speed.
* The penetration is shared between plate bending and local contact deformation
  (Eq. 4): ``p = W + delta``, with ``W = lam P + w0`` from the plate model
  (:mod:`rotorred.transient.plate`, Eqs. 10-11) and ``delta`` the Hertz deformation.
* Normal force (Eq. 8, Hunt–Crossley reading of the "nonlinear spring damping model";
  :func:`normal_law`, the one implementation, evaluates the residual generated from
  ``derivations/contact.py``, and the step kernel compiles it):
  ``P = K_nr delta^1.5 max(0, 1 + c p')`` for ``delta > 0``, else 0. The rate is the total
  approach rate ``p' = -g'`` of the disk towards the plate, not the rate ``delta' = p' - lam P'``
  of the Hertz deformation printed in Eq. 8 (which would make the law a differential equation
  for P; this keeps it algebraic in each step). The clamp at 0 stops the law from pulling the
  disk back (no adhesion).
* Energy: the contact force's power is ``P p'``; bending stores ``lam P^2 / 2`` and the Hertz
  contact ``2/5 K_nr delta^2.5`` (:func:`contact_energy`), so the law dissipates
  ``P p' - d/dt(2/5 K_nr delta^2.5 + lam P^2 / 2) = c K_nr delta^1.5 p' delta'`` (not
  ``c K_nr delta^1.5 p'^2``, which overstates it by 42 % on 0-0.3 s of ``paper-rub``; locally
  negative near the turn-round when the plate bends). tests/test_energy.py closes the discrete
  energy balance of a rub run with it.
* Friction (Eq. 8, Coulomb with static and dynamic coefficients). The relative tangential
  velocity of the disk's contact point against the plate is
  ``v_rel = Omega r + (x', y') . t - u_t'``: the disk's surface speed (spin about +z,
  rim point ``r n`` moving with ``Omega z x r n = Omega r t``), plus the whirl velocity, minus
  the plate's tangential velocity. Slip: ``T = -mu_d P sign(v_rel)``. Stick: ``v_rel = 0`` with
  ``|T| <= mu_s P``. The integrator treats stick exactly as a constraint (no regularisation);
  see :mod:`rotorred.transient.newmark`.
* Forces: on the disk ``-P n + T t`` (:func:`disk_force`); on the plate ``+P n - T t``. In the paper's Eq. 12,
  ``F_x = F_n cos theta + F_t sin theta``, ``F_y = F_n sin theta - F_t cos theta`` with
  ``F_n = -P`` and ``F_t = -T`` (the paper's t axis is ``-t`` here).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from rotorred import checks
from rotorred._generated import contact as _gen
from rotorred.transient.plate import ClampedFreePlate, NavierPlate, RigidPlate

PlateBending = NavierPlate | ClampedFreePlate | RigidPlate

#: contact states recorded per plate
OPEN, SLIP, STICK = 0, 1, 2
STATE_NAMES = {OPEN: "open", SLIP: "slip", STICK: "stick"}

#: the generated residual of the normal law (derivations/contact.py); the kernel compiles
#: :func:`normal_law` with this name bound to the njit wrap of the same function
_normal_residual = _gen.normal_residual


@dataclass(frozen=True)
class RubPlate:
    """An elastically supported rubbing plate facing the disk at ``node`` (Xu et al. 2016, Figs. 3-4).

    Defaults are plausible for the seed rig (a 250 mm steel disk at node 18 running at 90 Hz,
    outer-rotor amplitudes of 60-100 µm); the paper gives no values.

    Parameters
    ----------
    node : int
        Disk node the plate faces (default 18, the rub disk of the seed rig).
    theta : float
        Angle of the plate normal from the x axis (rad); default pi/2 (plate above the disk,
        the paper's strongest rub signature is in the outer rotor's y response).
    clearance : float
        Gap between disk rim and plate at rest (m); default 40e-6 (below the outer rotor's
        unbalance amplitude, so it rubs). Negative values mean an interference fit.
    K_nr : float
        Hertz contact stiffness (N/m^1.5); default 5e9 (steel rim edge on a steel plate:
        (4/3) E* sqrt(R) with a local radius of a few mm).
    c : float
        Hunt–Crossley damping coefficient (s/m); default 1.0 (coefficient of restitution
        e ~ 1 - 2 c v / 3 ~ 0.97 at an impact speed of 0.05 m/s).
    mu_s, mu_d : float
        Static and dynamic Coulomb friction coefficients (-), 0 <= mu_d <= mu_s; default
        0.2 and 0.15 (dry steel on steel with some contamination).
    m_p : float
        Plate mass (kg), > 0; default 0.5.
    k_n, k_t : float
        Support stiffness of the plate, normal and tangential (N/m); default 5e6 and 5e6.
    c_n, c_t : float
        Support damping of the plate, normal and tangential (N s/m); default 100 and 100.
    bending : NavierPlate, ClampedFreePlate or RigidPlate
        Plate bending model (Eqs. 10-11); default a simply supported 100 x 60 x 3 mm steel plate
        loaded at its centre (compliance 1.1e-7 m/N).
    disk_radius : float, optional
        Rim radius of the disk (m); default: the ``radius`` of the rotor's disk at ``node``
        (see :meth:`for_rotor`).
    name : str
    """

    node: int = 18
    theta: float = math.pi / 2
    clearance: float = 40e-6
    K_nr: float = 5e9
    c: float = 1.0
    mu_s: float = 0.2
    mu_d: float = 0.15
    m_p: float = 0.5
    k_n: float = 5e6
    k_t: float = 5e6
    c_n: float = 100.0
    c_t: float = 100.0
    bending: PlateBending = field(default_factory=NavierPlate)
    disk_radius: float | None = None
    name: str = ""

    def __post_init__(self):
        checks.integer("node", self.node)
        checks.number("theta", self.theta, "rad")
        checks.number("clearance", self.clearance, "m")
        checks.positive("K_nr", self.K_nr, "N/m^1.5")
        checks.non_negative("c", self.c, "s/m")
        checks.non_negative("mu_s", self.mu_s)
        checks.non_negative("mu_d", self.mu_d)
        if self.mu_d > self.mu_s:
            checks.fail("mu_d", self.mu_d, f"must not exceed mu_s = {self.mu_s!r}")
        checks.positive("m_p", self.m_p, "kg")
        for name, unit in (("k_n", "N/m"), ("k_t", "N/m"), ("c_n", "N s/m"), ("c_t", "N s/m")):
            checks.non_negative(name, getattr(self, name), unit)
        if not isinstance(self.bending, (NavierPlate, ClampedFreePlate, RigidPlate)):
            checks.fail("bending", self.bending, "must be a NavierPlate, ClampedFreePlate or RigidPlate")
        if self.disk_radius is not None:
            checks.non_negative("disk_radius", self.disk_radius, "m")

    @classmethod
    def for_rotor(cls, rotor, node: int = 18, **kwargs) -> RubPlate:
        """A plate at ``node`` of ``rotor`` with ``disk_radius`` taken from the rotor's disk there.

        Parameters
        ----------
        rotor : Rotor
            The rotor the plate rubs.
        node : int
            A node of ``rotor`` that carries a disk of radius > 0.
        **kwargs
            The other fields of :class:`RubPlate` (``clearance`` (m), ``theta`` (rad), ...).

        Returns
        -------
        RubPlate

        Raises
        ------
        InputError
            If no disk is at ``node``, its radius is 0, or a field in ``kwargs`` is invalid.
        """
        disk = rotor.disk_at(node)
        if disk.radius <= 0:
            checks.fail("node", node, "must carry a disk with a radius > 0; else give disk_radius")
        return cls(node=node, disk_radius=disk.radius, **kwargs)

    def with_(self, **changes) -> RubPlate:
        """A copy with ``changes`` (``dataclasses.replace``)."""
        return dataclasses.replace(self, **changes)

    @property
    def normal(self) -> np.ndarray:
        """Unit normal n = (cos theta, sin theta), shape (2,)."""
        return np.array([math.cos(self.theta), math.sin(self.theta)])

    @property
    def tangent(self) -> np.ndarray:
        """Unit tangent t = (-sin theta, cos theta), shape (2,)."""
        return np.array([-math.sin(self.theta), math.cos(self.theta)])

    @property
    def compliance(self) -> float:
        """Bending compliance lam (m/N) of the plate model."""
        return float(self.bending.compliance)

    @property
    def offset(self) -> float:
        """Bending offset w0 (m) of the plate model (b0/a0 for the clamped-free fit)."""
        return float(self.bending.offset)


def gap(plate: RubPlate, x: float, y: float, u_n: float = 0.0) -> float:
    """Gap g = clearance + u_n - (x cos theta + y sin theta) (m); positive = open."""
    return plate.clearance + u_n - (x * math.cos(plate.theta) + y * math.sin(plate.theta))


def normal_law(F, delta, rate, K_nr, c, lam):
    """The normal contact law in residual form and its tangent, clamped (Eqs. 8, 10-11).

    ``R(F) = F - K_nr delta^1.5 max(0, 1 + c rate)`` for ``delta > 0``, else ``R = F``: the
    generated :func:`rotorred._generated.contact.normal_residual` evaluated at
    ``s = sqrt(delta)``, or at ``s = 0`` (no force) when ``delta <= 0`` or ``1 + c rate <= 0``,
    which gives ``R = F``, ``dR/dF = 1`` and zero other derivatives. Plain Python on floats; the
    kernel compiles this same function (:mod:`rotorred.transient.kernel`), and so evaluates the
    same generated code.

    Parameters
    ----------
    F : float
        Normal force (N).
    delta : float
        Local (Hertz) contact deformation ``p - w0 - lam F`` (m).
    rate : float
        Penetration rate (m/s).
    K_nr : float
        Hertz stiffness (N/m^1.5).
    c : float
        Hunt–Crossley coefficient (s/m).
    lam : float
        Plate bending compliance (m/N).

    Returns
    -------
    tuple of 4 floats
        (R (N), dR/dF (-), dR/dp (N/m), dR/d(rate) (N s/m)), ``p`` the penetration: a tuple, so that the
        compiled law allocates nothing at each Newton iteration of the step loops (:data:`kernel.LOOP`).
    """
    s = math.sqrt(delta) if delta > 0.0 and 1.0 + c * rate > 0.0 else 0.0
    return _normal_residual(F, s, rate, K_nr, c, lam)


def hunt_crossley(delta: float, rate: float, K_nr: float, c: float) -> tuple[float, float, float]:
    """Hertz force with Hunt–Crossley damping, clamped at zero, and its tangent.

    The law of :func:`normal_law` for a rigid plate at zero force: ``F = -R(0)`` with ``lam = 0``.

    Parameters
    ----------
    delta : float
        Local contact deformation (m); no force for ``delta <= 0``.
    rate : float
        Penetration rate (m/s).
    K_nr : float
        Hertz stiffness (N/m^1.5).
    c : float
        Hunt–Crossley coefficient (s/m).

    Returns
    -------
    force, stiffness, damping : float
        F (N), dF/d(delta) (N/m), dF/d(rate) (N s/m).
    """
    R, _, dR_dp, dR_drate = normal_law(0.0, delta, rate, K_nr, c, 0.0)
    return 0.0 - float(R), 0.0 - float(dR_dp), 0.0 - float(dR_drate)


def normal_force(penetration: float, rate: float, plate: RubPlate, tol: float = 1e-14) -> tuple[float, float]:
    """Normal contact force P of the plate's series law: P = K_nr (p - w0 - lam P)^1.5 max(0, 1 + c rate).

    :func:`normal_root` for ``plate``.

    Parameters
    ----------
    penetration : float
        Penetration p = -g (m); no force below the bending offset w0.
    rate : float
        Penetration rate p' (m/s).
    plate : RubPlate

    Returns
    -------
    P : float
        Normal force (N), >= 0.
    dP_dp : float
        Tangent dP/dp (N/m) at fixed rate.
    """
    P, dP_dp, _ = normal_root(penetration, rate, plate.K_nr, plate.c, plate.compliance, plate.offset, tol)
    return P, dP_dp


def normal_root(penetration, rate, K_nr, c, lam, w0, tol):
    """The normal force of the series law and its two tangents: the root P of :func:`normal_law`'s residual at the
    deformation ``p - w0 - lam P``, by Newton from P = 0 (the residual is increasing and concave in P for a fixed
    ``rate``, so the iterates increase monotonically to the root; at most 200, to a step of ``tol`` relative).

    Plain Python on floats; harmonic balance compiles this same function and calls it at every AFT sample
    (:class:`rotorred.nonlinear.forces.PlateRub`).

    Parameters
    ----------
    penetration, rate : float
        Penetration p = -g (m) and its rate p' (m/s).
    K_nr, c, lam, w0 : float
        Hertz stiffness (N/m^1.5), Hunt–Crossley coefficient (s/m), bending compliance (m/N) and offset (m).
    tol : float

    Returns
    -------
    P, dP_dp, dP_drate : float
        The force (N, >= 0) and its derivatives by the penetration (N/m) and its rate (N s/m); zero out of contact.
    """
    P = 0.0
    for _ in range(200):
        R, dR_dF, _, _ = normal_law(P, penetration - w0 - lam * P, rate, K_nr, c, lam)
        step = R / dR_dF
        P -= step
        if abs(step) <= tol * max(abs(P), 1e-300):
            break
    _, dR_dF, dR_dp, dR_drate = normal_law(P, penetration - w0 - lam * P, rate, K_nr, c, lam)
    return max(P, 0.0), -dR_dp / dR_dF, -dR_drate / dR_dF


def contact_energy(P: float, plate: RubPlate) -> float:
    """Elastic energy stored in bending and Hertz contact at the normal force ``P`` (J).

    ``lam P^2 / 2`` (plate bending, linear part of Eqs. 10-11; the offset w0 shifts the penetration
    and stores nothing) plus ``2/5 K_nr delta^2.5`` with ``delta = (P / K_nr)^(2/3)`` (the Hertz
    potential at the static deformation; with c > 0 the deformation is ``p - w0 - lam P`` instead, see
    the module docstring for the energy balance).
    """
    if P <= 0.0:
        return 0.0
    delta = (P / plate.K_nr) ** (2.0 / 3.0)
    return 0.5 * plate.compliance * P * P + float(_gen.hertz_energy(math.sqrt(delta), plate.K_nr)[0])


def sliding_velocity(plate: RubPlate, Omega: float, radius: float, vx: float, vy: float, v_t: float) -> float:
    """Relative tangential velocity v_rel = Omega r + (vx, vy) . t - v_t (m/s) of the disk against the plate."""
    return Omega * radius + (-vx * math.sin(plate.theta) + vy * math.cos(plate.theta)) - v_t


def disk_force(P, T, cos_theta, sin_theta):
    """Force (F_x, F_y) on the disk of normal force ``P`` and friction ``T`` (N) (Eq. 12): ``-P n + T t``.

    ``F_x = -P cos(theta) - T sin(theta)``, ``F_y = -P sin(theta) + T cos(theta)``. Plain arithmetic:
    works on floats and on numpy arrays of any (broadcastable) shape; the kernel compiles this
    same function.

    Parameters
    ----------
    P, T : float or ndarray
        Normal and friction force (N).
    cos_theta, sin_theta : float or ndarray
        Components of the plate normal n (-).

    Returns
    -------
    F_x, F_y : float or ndarray
        (N), the broadcast shape of the arguments.
    """
    return -P * cos_theta - T * sin_theta, -P * sin_theta + T * cos_theta


def rotor_force(plate: RubPlate, P: float, T: float) -> tuple[float, float]:
    """Force (F_x, F_y) (N) on the rotor node for normal force ``P`` and friction ``T`` (Eq. 12)."""
    return disk_force(P, T, math.cos(plate.theta), math.sin(plate.theta))
