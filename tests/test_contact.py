"""Rub-impact law: plate bending compliance (Eqs. 10-11), Hertz/Hunt–Crossley force and its
derived tangent, series solution, Eq. 12 force mapping, the condensed step residual's Jacobian,
and parameter validation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from rotorred.transient import kernel as _kernel
from rotorred.transient.contact import (RubPlate, contact_energy, gap, hunt_crossley, normal_force, rotor_force,
                              sliding_velocity)
from rotorred.transient.plate import ClampedFreePlate, NavierPlate, RigidPlate, navier_series


def brute_navier(a, b, xi, eta, N):
    """Square partial sums of the double series of Eq. 10, Richardson-extrapolated in N (tail O(N^-2))."""
    def S(N):
        m = np.arange(1, N + 1, dtype=float)
        sm = np.sin(m * math.pi * xi / a) ** 2
        sn = np.sin(m * math.pi * eta / b) ** 2
        return np.sum(sm[:, None] * sn[None, :] / (m[:, None] ** 2 / a**2 + m[None, :] ** 2 / b**2) ** 2)

    s1, s2 = S(N), S(2 * N)
    return s2 + (s2 - s1) / 3.0


@pytest.mark.parametrize("a,b,xi,eta", [(0.10, 0.06, 0.05, 0.03), (0.2, 0.1, 0.03, 0.07), (1.0, 1.0, 0.5, 0.5)])
def test_navier_series_matches_direct_double_sum(a, b, xi, eta):
    """The closed-form inner sum reproduces the plain double sum of Eq. 10 (2048^2 terms,
    extrapolated: its own error is ~1e-7)."""
    s, N, err = navier_series(a, b, xi, eta)
    assert err <= 1e-10
    ref = brute_navier(a, b, xi, eta, 1024)
    assert abs(s - ref) / ref < 1e-6


def test_navier_plate_centre_deflection_of_square_plate():
    """Centre of a simply supported square plate under a central point load: w = alpha P a^2 / D with
    alpha = 0.01160 (Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, Table 23, 4 digits)."""
    p = NavierPlate(a=1.0, b=1.0, h=0.01, E=2.1e11, nu=0.3)
    alpha = p.compliance * p.D / p.a**2
    assert abs(alpha - 0.01160) < 5e-6
    assert p.deflection(2.0) == pytest.approx(2.0 * p.compliance)


def test_clamped_free_fit_and_rigid_plate():
    """Eq. 11 inverted: W = (F + b0) / a0, i.e. compliance 1/a0 and offset b0/a0."""
    p = ClampedFreePlate(a0=4e6, b0=2.0)
    assert p.compliance == 1 / 4e6 and p.offset == 2.0 / 4e6
    F = 10.0
    assert p.a0 * p.deflection(F) - p.b0 == pytest.approx(F)
    with pytest.raises(ValueError, match=r"^b0 = -1\.0: must be >= 0 .*\(N\)$"):
        ClampedFreePlate(a0=4e6, b0=-1.0)
    with pytest.raises(ValueError, match=r"^a0 = 0\.0: must be > 0 \(N/m\)$"):
        ClampedFreePlate(a0=0.0)
    assert RigidPlate().compliance == 0.0


def test_hunt_crossley_tangent_and_clamp():
    """The generated tangent equals central differences; no force when open or when 1 + c rate <= 0."""
    K, c = 5e9, 1.5
    for delta, rate in ((3e-6, 0.02), (1e-7, -0.3), (2e-5, 0.0)):
        F, kd, kr = hunt_crossley(delta, rate, K, c)
        assert F == pytest.approx(K * delta**1.5 * (1 + c * rate), rel=1e-14)
        hd, hr = 1e-6 * delta, 1e-6
        fd = (hunt_crossley(delta + hd, rate, K, c)[0] - hunt_crossley(delta - hd, rate, K, c)[0]) / (2 * hd)
        fr = (hunt_crossley(delta, rate + hr, K, c)[0] - hunt_crossley(delta, rate - hr, K, c)[0]) / (2 * hr)
        assert kd == pytest.approx(fd, rel=1e-8) and kr == pytest.approx(fr, rel=1e-8)
    assert hunt_crossley(-1e-6, 0.0, K, c) == (0.0, 0.0, 0.0)
    assert hunt_crossley(1e-6, -1.0, K, c) == (0.0, 0.0, 0.0)  # 1 + c rate < 0: no pull


@pytest.mark.parametrize("bending", [NavierPlate(), ClampedFreePlate(a0=3e6, b0=1.5), RigidPlate()])
def test_normal_force_solves_series_law(bending):
    """P from Newton equals the brentq root of p = w0 + lam P + (P / (K (1 + c rate)))^(2/3)."""
    plate = RubPlate(bending=bending, K_nr=2e9, c=0.8)
    for pen, rate in ((5e-6, 0.01), (3e-5, -0.2), (1e-4, 0.0)):
        P, dP = normal_force(pen, rate, plate)
        h = 1 + plate.c * rate
        eff = pen - plate.offset
        if eff <= 0:
            assert P == 0.0
            continue
        f = lambda F: plate.offset + plate.compliance * F + (F / (plate.K_nr * h)) ** (2 / 3) - pen
        ref = brentq(f, 0.0, plate.K_nr * h * eff**1.5, xtol=1e-300, rtol=1e-15)
        assert P == pytest.approx(ref, rel=1e-12)
        dd = 1e-7 * pen
        fd = (normal_force(pen + dd, rate, plate)[0] - normal_force(pen - dd, rate, plate)[0]) / (2 * dd)
        assert dP == pytest.approx(fd, rel=1e-6)
    assert normal_force(-1e-6, 0.0, plate)[0] == 0.0


def test_contact_energy_is_the_potential_of_the_series_law():
    """d(energy)/dp = P along the series law (c = 0): the bending + Hertz energy is its potential."""
    plate = RubPlate(K_nr=2e9, c=0.0)
    pens = np.linspace(1e-6, 4e-5, 2001)
    P = np.array([normal_force(p, 0.0, plate)[0] for p in pens])
    E = np.array([contact_energy(f, plate) for f in P])
    work = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(pens))])
    # trapezoidal work with 2000 intervals: relative error ~1e-7
    np.testing.assert_allclose(E - E[0], work, rtol=1e-6, atol=1e-6 * E[-1])


def test_hunt_crossley_dissipates_on_impact():
    """A mass hitting a Hertz/Hunt–Crossley contact rebounds slower; c = 0 conserves energy
    (solve_ivp on the law as written)."""
    m, v0, K = 1.0, 0.1, 1e9

    def rebound(c):
        plate = RubPlate(K_nr=K, c=c, bending=RigidPlate())

        def rhs(t, s):
            return [s[1], -hunt_crossley(s[0], s[1], plate.K_nr, plate.c)[0] / m]

        leave = lambda t, s: s[0] + 1e-15 if t > 0 else 1.0
        leave.terminal, leave.direction = True, -1
        sol = solve_ivp(rhs, (0, 0.1), [1e-15, v0], events=leave, rtol=1e-10, atol=1e-16, method="LSODA")
        return -sol.y_events[0][0][1]

    assert rebound(0.0) == pytest.approx(v0, rel=1e-8)  # elastic: energy kept to the solver's rtol (measured 1.7e-9)
    c = 1.0
    e = rebound(c) / v0
    # exact restitution of F = K d^1.5 (1 + c d'): m v dv / (1 + c v) = -K d^1.5 dd integrates to zero over the
    # impact, so f(-e v0) = f(v0) with f(v) = c v - ln(1 + c v) (~1 - (2/3) c v0 = 0.933 to first order)
    e_exact = brentq(lambda e_: (-c * e_ * v0 - math.log(1 - c * e_ * v0)) - (c * v0 - math.log(1 + c * v0)),
                     0.5, 1.0 - 1e-12, xtol=1e-15)
    # measured |e - e_exact| = 1.7e-9 (solve_ivp at rtol 1e-10, event location); was 0.8 < e < 1 and 1e-2
    assert e == pytest.approx(e_exact, abs=2e-8)


def test_geometry_and_eq12_forces():
    plate = RubPlate(theta=0.4, clearance=5e-5)
    n, t = plate.normal, plate.tangent
    assert np.dot(n, t) == pytest.approx(0.0) and n[0] * t[1] - n[1] * t[0] == pytest.approx(1.0)
    assert gap(plate, *(5e-5 * n)) == pytest.approx(0.0, abs=1e-18)
    assert gap(plate, 0.0, 0.0, u_n=1e-5) == pytest.approx(6e-5)
    # Eq. 12 with F_n = -P, F_t = -T (the paper's t axis is -t here)
    P, T = 100.0, 15.0
    Fx, Fy = rotor_force(plate, P, T)
    Fn, Ft = -P, -T
    c, s = math.cos(plate.theta), math.sin(plate.theta)
    assert Fx == pytest.approx(Fn * c + Ft * s) and Fy == pytest.approx(Fn * s - Ft * c)
    # a disk spinning about +z passes the contact point along +t at Omega r
    assert sliding_velocity(plate, 10.0, 0.1, 0.0, 0.0, 0.0) == pytest.approx(1.0)
    assert sliding_velocity(plate, 0.0, 0.1, *(2.0 * t), 0.5) == pytest.approx(1.5)


def test_plate_parameters_validated():
    # the one message form of rotorred.checks: <field> = <value>: <what is allowed> (<unit>)
    with pytest.raises(ValueError, match=r"^K_nr = 0\.0: must be > 0 \(N/m\^1\.5\)$"):
        RubPlate(K_nr=0.0)
    with pytest.raises(ValueError, match=r"^mu_d = 0\.2: must not exceed mu_s = 0\.1$"):
        RubPlate(mu_s=0.1, mu_d=0.2)
    with pytest.raises(ValueError, match=r"^m_p = -1\.0: must be > 0 \(kg\)$"):
        RubPlate(m_p=-1.0)
    with pytest.raises(ValueError, match=r"^clearance = nan: must be a finite number \(m\)$"):
        RubPlate(clearance=float("nan"))
    with pytest.raises(ValueError, match=r"^node = 1\.5: must be an integer$"):
        RubPlate(node=1.5)
    with pytest.raises(ValueError, match=r"^bending = 'rigid': must be a NavierPlate, ClampedFreePlate or RigidPlate$"):
        RubPlate(bending="rigid")
    with pytest.raises(ValueError, match=r"^xi = 0\.2: must lie in \(0, 0\.1\) \(m\)$"):
        NavierPlate(a=0.1, xi=0.2)


def _residual(z, args, mode, sgn):
    m = len(z)
    R, J = np.empty(m), np.empty((m, m))
    *kinematics, pp = args
    _kernel.contact_residual(z, _kernel.Condensed(*kinematics), pp, mode, sgn, R, J)
    return R, J


@pytest.mark.parametrize("modes", [(1, 1), (2, 1), (2, 2)])
def test_condensed_residual_jacobian(modes):
    """The analytic Jacobian of the condensed contact residual (two coupled plates, bending,
    Hunt–Crossley, slip or stick rows) equals central differences."""
    rng = np.random.default_rng(3)
    plates = [RubPlate(theta=0.2, K_nr=3e9, c=0.7, mu_d=0.15, mu_s=0.2),
              RubPlate(theta=2.5, K_nr=1e9, c=0.3, mu_d=0.1, mu_s=0.3, bending=ClampedFreePlate(a0=2e6, b0=1.0))]
    pp = np.array([[math.cos(p.theta), math.sin(p.theta), p.clearance, p.offset, p.compliance, p.K_nr, p.c,
                    p.mu_s, p.mu_d, 10.0, p.m_p] for p in plates])
    Jp = -1e-8 * np.abs(rng.random((2, 4))) - np.array([[2e-7, 0, 0, 0], [0, 0, 2e-7, 0]])
    Jv = 1e-8 * rng.random((2, 4)) + np.array([[0, 3e-7, 0, 0], [0, 0, 0, 3e-7]])
    p_lin, pd_lin, v_lin = np.array([4e-5, 3e-5]), np.array([0.01, -0.02]), np.array([2.0, -1.0])
    args = (p_lin, pd_lin, v_lin, Jp, Jv, 2e5, pp)
    mode, sgn = np.array(modes, dtype=np.int64), np.array([1.0, -1.0])
    z = np.array([30.0, -4.0, 20.0, 2.0])
    R, J = _residual(z, args, mode, sgn)
    for j in range(4):
        h = 1e-6 * max(abs(z[j]), 1.0)
        zp, zm = z.copy(), z.copy()
        zp[j] += h
        zm[j] -= h
        fd = (_residual(zp, args, mode, sgn)[0] - _residual(zm, args, mode, sgn)[0]) / (2 * h)
        np.testing.assert_allclose(J[:, j], fd, rtol=1e-6, atol=1e-9 * np.max(np.abs(J)))
