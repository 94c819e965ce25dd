"""Response classification: periodic, period-2, quasi-periodic, chaotic (Duffing), unsettled; Poincare; 0-1 test."""

import math
from fractions import Fraction

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotorred.signals.classify import classify, poincare_samples, zero_one_test

DT = 1e-4
T = np.arange(20_000) * DT  # 2 s
BASE = [(1, 0), (0, 1), (1, -1), (2, 0), (1, 1), (2, -1)]  # m f_H + n f_L


def _lines(orders, f_L, f_H, t=T, seed=1):
    rng = np.random.default_rng(seed)
    return sum(rng.uniform(0.2, 1.0) * np.cos(2 * np.pi * (float(m) * f_H + float(n) * f_L) * t + rng.uniform(-3, 3))
               for m, n in orders)


def test_periodic_at_70_90_has_the_common_period():
    c = classify(T, _lines(BASE, 70.0, 90.0), 70.0, 90.0)
    assert c.kind == "periodic" and c.subharmonic == 1
    assert c.period == pytest.approx(0.1, rel=1e-12)  # 1 / gcd(70, 90)
    assert c.settling.settled and c.explained_share > 1 - 1e-12


def test_period_2_at_70_90():
    """Lines at f_H/2 combinations: the response repeats every two common periods."""
    x = _lines(BASE + [(Fraction(1, 2), 0), (Fraction(1, 2), 1), (Fraction(3, 2), -1)], 70.0, 90.0)
    c = classify(T, x, 70.0, 90.0)
    assert (c.kind, c.label, c.subharmonic) == ("period-k", "period-2", 2)
    assert c.period == pytest.approx(0.2, rel=1e-12)
    assert (c.torus.k, c.torus.j) == (2, 1) and c.torus.bases == (5.0,)
    # The Poincare section at the forcing period 0.1 s shows two points, alternating.
    p = c.poincare
    spread = np.ptp(p.x)
    assert np.max(np.abs(p.x[2:] - p.x[:-2])) < 1e-6 * spread  # spline error ~1e-9 of the spread
    assert np.min(np.abs(p.x[1:] - p.x[:-1])) > 0.01 * spread


def test_quasi_periodic_two_torus_lies_on_a_closed_curve():
    f_L, f_H = 70.0, 70.0 * math.sqrt(2.0)
    c = classify(T, _lines(BASE, f_L, f_H), f_L, f_H)
    assert c.kind == "quasi-periodic" and c.period is None
    assert c.torus.bases == (f_H, f_L)
    assert c.curve_share > 1 - 1e-6  # measured 1 - 1e-12: the samples lie on the curve to spline error
    assert c.zero_one_K < 0.2  # measured 0.06; K -> 0 for quasi-periodic motion


def test_a_third_frequency_leaves_the_response_unexplained():
    """A strong tone at 150.3 Hz, on no torus: no sub-harmonic torus is made up for one tone."""
    f_L, f_H = 70.0, 70.0 * math.sqrt(2.0)
    x = _lines(BASE, f_L, f_H) + 1.5 * np.cos(2 * np.pi * 150.3 * T)
    c = classify(T, x, f_L, f_H)
    print(c.rules)
    assert c.kind == "unexplained" and c.settling.settled
    assert (c.torus.k, c.torus.j) == (1, 1) and c.explained_share < 0.9  # measured 0.53
    assert c.residual_peak_share > 0.9  # a missed line, not a broadband residual (measured 1.00)
    assert any(abs(p.frequency_hz - 150.3) < 0.05 for p in c.fit.unlabelled)  # listed as unlabelled


def _duffing():
    """Double-well Duffing x'' + 0.3 x' - x + x^3 = 0.5 cos(1.2 t): chaotic (Guckenheimer and Holmes)."""
    omega = 1.2
    period = 2 * np.pi / omega

    def rhs(t, y):
        return (y[1], -0.3 * y[1] + y[0] - y[0] ** 3 + 0.5 * math.cos(omega * t))

    # 1000 forcing periods, 16 samples each; rtol 1e-4 (1 s of CPU): an attractor's statistics, not
    # one trajectory, are tested, and any error of the integration is one more perturbation of it.
    t = np.arange(1000 * 16) * (period / 16)
    sol = solve_ivp(rhs, (0.0, t[-1]), [0.1, 0.0], method="DOP853", t_eval=t, rtol=1e-4, atol=1e-6)
    keep = t >= 20 * period  # drop the start
    return t[keep], sol.y[0][keep], omega / (2 * np.pi)


def test_chaotic_duffing():
    t, x, f = _duffing()
    c = classify(t, x, f, f)  # one forcing frequency: f_L = f_H
    print(c.rules)
    assert c.kind == "chaotic"
    # Measured: explained 0.08, residual peak share 0.71, K 0.98 on 490 Poincare samples (last half).
    assert c.explained_share < 0.5 and c.residual_peak_share < 0.9 and c.zero_one_K > 0.8


def test_a_decaying_transient_is_unsettled():
    x = _lines(BASE, 70.0, 90.0) + 3.0 * np.exp(-T / 0.8) * np.cos(2 * np.pi * 90.0 * T)
    c = classify(T, x, 70.0, 90.0)
    assert c.kind == "unsettled" and not c.settling.settled


# --------------------------------------------------------------------------- the tools
def test_zero_one_test_separates_chaos_from_regular_motion():
    logistic = np.empty(1100)
    logistic[0] = 0.3
    for i in range(1, logistic.size):
        logistic[i] = 4.0 * logistic[i - 1] * (1.0 - logistic[i - 1])
    n = np.arange(1000)
    K_chaos = zero_one_test(logistic[100:])
    K_periodic = zero_one_test(np.cos(2 * np.pi * n / 7) + 0.3 * np.cos(4 * np.pi * n / 7))
    K_quasi = zero_one_test(np.cos(2 * np.pi * n / math.sqrt(2)) + 0.5 * np.cos(2 * np.pi * n * math.sqrt(3)))
    print(f"K: logistic {K_chaos:.3f}, period-7 {K_periodic:.3f}, quasi-periodic {K_quasi:.3f}")
    assert K_chaos > 0.95 and abs(K_periodic) < 0.1 and abs(K_quasi) < 0.1  # measured 0.998, ~0, ~0


def test_poincare_interpolation_error_is_within_its_stated_bound():
    dt = 2e-4
    t = np.arange(5000) * dt
    f_a, f_b = 37.0, 311.0
    x = np.cos(2 * np.pi * f_a * t) + 0.2 * np.sin(2 * np.pi * f_b * t + 0.5)
    p = poincare_samples(t, x, 13.7)  # sample times fall between grid points
    exact = np.cos(2 * np.pi * f_a * p.times) + 0.2 * np.sin(2 * np.pi * f_b * p.times + 0.5)
    exact_v = (-2 * np.pi * f_a * np.sin(2 * np.pi * f_a * p.times)
               + 0.4 * np.pi * f_b * np.cos(2 * np.pi * f_b * p.times + 0.5))
    err, err_v = np.max(np.abs(p.x - exact)), np.max(np.abs(p.velocity - exact_v))
    print(f"spline error {err:.2e} (bound {p.interpolation_error:.2e}), velocity {err_v:.2e} "
          f"(bound {p.velocity_error:.2e})")
    assert err <= p.interpolation_error and err_v <= p.velocity_error
    assert p.interpolation_error < 20 * err  # the bound is not vacuous (measured ratio ~2-5)
    assert np.allclose(p.times * 13.7, np.round(p.times * 13.7), atol=1e-9)  # whole periods
