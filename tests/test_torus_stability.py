"""Stability of a torus by the Lyapunov exponents of the variational equation along it
(rotorred.nonlinear.torus_stability, docs/model.md §27), against independent references: the closed-form exponents of
linear damped systems, Hill's Floquet exponents of the periodic orbit the torus becomes when one tone is switched off,
and solve_ivp runs started on each torus with a small perturbation (a torus called stable keeps them, the one called
unstable loses them at the rate its exponent says)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rotorred as rr
from rotorred.checks import InputError
from rotorred.nonlinear.forces import CubicSpring
from rotorred.nonlinear.fourier import Harmonics, alias_free_samples
from rotorred.nonlinear.hb import PeriodicProblem, solve_periodic
from rotorred.nonlinear.stability import floquet
from rotorred.nonlinear.torus import TorusHarmonics, TorusProblem, alias_free_grid, solve_torus
from rotorred.nonlinear.torus_stability import LyapunovOptions, torus_lyapunov, torus_trajectory
from results_checks import assert_shows_itself
from test_nonlinear_torus import LinearSpring

# the hardening Duffing oscillator x'' + C x' + x + K3 x^3 = F1 cos(w1 t) + F2 cos(w2 t): at w1 = 1.3 the tone F1 alone
# has three periodic responses (single-term amplitudes 0.49, 1.09, 1.50); the weak second tone at the golden ratio
# of w1 turns each into a torus
C, K3, F1, F2 = 0.1, 0.5, 0.3, 0.02
W1 = 1.3
W = (W1, W1 * (math.sqrt(5.0) - 1.0) / 2.0)


def duffing(H: int, F2: float = F2) -> TorusProblem:
    h = TorusHarmonics(H, H, *alias_free_grid(H, H, 3))
    Q = np.zeros((h.n_orders, 1), complex)
    Q[h.index(1, 0)], Q[h.index(0, 1)] = F1, F2
    return TorusProblem(np.eye(1), C * np.eye(1), np.eye(1), h, W, (0,), h.from_phasors(Q), (CubicSpring(0, K3),))


def single_term_starts(problem: TorusProblem) -> list[np.ndarray]:
    """The three single-term balances of the tone F1 (amplitudes A from the cubic in A^2, each line from the 2 x 2
    balance of its cos and sin), as starts on the torus's orders: low, middle, high."""
    a, b = 0.75 * K3, 1.0 - W1**2
    roots = np.roots([a * a, 2 * a * b, b * b + (C * W1) ** 2, -F1**2])
    amplitudes = np.sqrt(np.sort(roots[np.abs(roots.imag) < 1e-12].real))
    h, starts = problem.harmonics, []
    for A in amplitudes:
        kappa = b + a * A**2
        cos, sin = np.linalg.solve([[kappa, C * W1], [-C * W1, kappa]], [F1, 0.0])
        Q = np.zeros((h.n_orders, 1), complex)
        Q[h.index(1, 0)] = cos - 1j * sin
        starts.append(h.from_phasors(Q))
    return starts


def three_tori(H: int, F2: float = F2) -> tuple[TorusProblem, list[np.ndarray]]:
    problem = duffing(H, F2)
    return problem, [solve_torus(problem, z0).z for z0 in single_term_starts(problem)]


def perturbed_distance(problem: TorusProblem, z: np.ndarray, relative: float, T: float, t: np.ndarray):
    """solve_ivp (DOP853, rtol 1e-11) from the torus's state at t = 0 with x moved by ``relative`` of the state's norm;
    its distance from the torus in (x, x') at the times t, relative to the state's norm at t = 0."""
    q0, v0 = torus_trajectory(problem, z, [0.0])
    scale = math.hypot(q0[0, 0], v0[0, 0])
    F2_ = problem.harmonics.phasors(problem.forcing, 1)[problem.harmonics.index(0, 1), 0].real

    def rhs(_, y):
        return [y[1], F1 * math.cos(W[0] * _) + F2_ * math.cos(W[1] * _) - C * y[1] - y[0] - K3 * y[0] ** 3]
    ode = solve_ivp(rhs, (0.0, T), [q0[0, 0] + relative * scale, v0[0, 0]], method="DOP853", rtol=1e-11,
                    atol=1e-13, dense_output=True)
    q, v = torus_trajectory(problem, z, t)
    x = ode.sol(t)
    return np.hypot(x[0] - q[:, 0], x[1] - v[:, 0]) / scale


# ------------------------------------------------------------------------------------------------- closed forms
def test_linear_damped_systems_have_the_exponents_minus_zeta_omega():
    """x'' + c x' + x forced at two incommensurate tones: the torus is the closed-form steady state (torus_trajectory
    equals sum_k Re(F_k / (1 - w_k^2 + i c w_k) e^{i w_k t}) to 1e-15), and its two exponents are -zeta omega = -c / 2
    (measured 1.1e-7 off over 100 periods, inside the error 5.5e-7 the function states) with their sum the trace -c
    (1e-15). A 2-DOF system whose spring S passes through the force-derivative path (every step its own exponential):
    its four exponents are the real parts of the state matrix's eigenvalues, -0.0502 twice and -0.2998 twice
    (measured 4.0e-7 and 6.5e-7 off; their sum the trace to 1e-15)."""
    c = 0.1
    h = TorusHarmonics(2, 2, 6, 6)
    Q = np.zeros((h.n_orders, 1), complex)
    Q[h.index(1, 0)], Q[h.index(0, 1)] = 1.0, 0.5
    problem = TorusProblem(np.eye(1), c * np.eye(1), np.eye(1), h, W, (0,), h.from_phasors(Q), ())
    z = solve_torus(problem, np.zeros(problem.size)).z
    t = np.linspace(0.0, 50.0, 101)
    x = sum(np.real(F / (1 - w**2 + 1j * c * w) * np.exp(1j * w * t)) for F, w in zip((1.0, 0.5), W))
    assert np.max(np.abs(torus_trajectory(problem, z, t)[0][:, 0] - x)) < 1e-14
    result = torus_lyapunov(problem, z, LyapunovOptions(periods=100))
    assert result.contact_steps == 0 and result.verdict == "stable"
    assert np.all(np.abs(result.exponents + c / 2) < 2e-6)
    assert np.all(np.abs(result.exponents + c / 2) < result.errors)
    assert abs(result.exponents.sum() + c) < 1e-13

    S = np.array([[0.4, -0.1], [-0.1, 0.7]])
    M, D, K = np.eye(2), np.diag([0.1, 0.6]), np.diag([1.0, 4.0])
    h2 = TorusHarmonics(2, 3, 6, 8)
    Q2 = np.zeros((h2.n_orders, 2), complex)
    Q2[h2.index(1, 0), 0], Q2[h2.index(0, 1), 1] = 0.3, 0.2j
    two = TorusProblem(M, D, K, h2, W, (0, 1), h2.from_phasors(Q2), (LinearSpring(S),))
    state = np.block([[np.zeros((2, 2)), np.eye(2)], [-(K + S), -D]])
    exact = np.sort(np.linalg.eigvals(state).real)[::-1]
    result2 = torus_lyapunov(two, solve_torus(two, np.zeros(two.size)).z, LyapunovOptions(count=4, periods=100))
    assert result2.contact_steps == result2.steps
    assert np.all(np.abs(result2.exponents - exact) < 5e-6)
    assert abs(result2.exponents.sum() - np.trace(state)) < 1e-12


# ------------------------------------------------------------------------------------------------- the Duffing tori
def test_bistable_duffing_tori_stable_stays_unstable_leaves_at_its_exponent():
    """Three tori at one forcing (from the three single-term balances of the tone F1): the low and the high one are
    called stable (largest exponents -0.04995 ± 0.00018 and -0.04999 ± 0.00024), the middle one unstable (0.09927 ±
    0.00043), with exponents summing to -C (the trace, 1e-15). Perturbed by 1e-6 of the state on the torus at t = 0,
    solve_ivp stays on the stable ones (distance after 40 periods of w2, 313 s: measured 1.1e-5 and 1.7e-3 of the
    start's, the floor of the torus's truncation at H = 11, not a growth; at most 1.02 and 2.7 times the start's on
    the way) and leaves the unstable one (0.64 of the state at 313 s): its distance grows from 1e-5 to 1e-2 of the
    state at the rate 0.09916 against the exponent 0.09927 (measured 1.2e-3 relative)."""
    problem, tori = three_tori(11)
    results = [torus_lyapunov(problem, z, LyapunovOptions(periods=60)) for z in tori]
    assert [r.verdict for r in results] == ["stable", "unstable", "stable"]
    for r in results:
        assert abs(r.exponents.sum() + C) < 1e-12
    T = 40 * 2 * math.pi / W[1]
    t = np.linspace(0.0, T, 1601)
    for r, z in zip(results, tori):
        d = perturbed_distance(problem, z, 1e-6, T, t)
        if r.verdict == "stable":
            assert d[-1] < 1e-2 * d[0] and d.max() < 10 * d[0]
        else:
            assert d[-1] > 1e4 * d[0]
            window = (d > 1e-5) & (d < 1e-2)
            rate = np.polyfit(t[window], np.log(d[window]), 1)[0]
            assert rate == pytest.approx(r.largest, rel=1e-2)


def test_with_one_tone_the_exponents_are_hills_floquet_exponents():
    """With F2 = 0 each torus is the periodic orbit of the tone F1 (constant along theta_2): its Lyapunov exponents
    equal the real parts of the orbit's Floquet exponents by Hill's method (rotorred.nonlinear.stability.floquet, 15
    harmonics), an independent computation, within the error the function states: the middle orbit's 0.099518
    (measured 3.3e-4 off, stated error 1.0e-3: mostly the step's, second order: 1.3e-3, 3.3e-4, 7.9e-5, 1.7e-5 at 1, 2,
    4, 8 steps an AFT interval), the others' -0.05 (measured 2.7e-6 and 4.5e-6 off; errors 4.0e-6 and 3.0e-4)."""
    problem, tori = three_tori(7, F2=0.0)
    hp = Harmonics(15, alias_free_samples(15, 3))

    def forcing(omega):
        f = np.zeros(hp.size)
        f[1] = F1
        return f, np.zeros(hp.size)
    periodic = PeriodicProblem(np.eye(1), C * np.eye(1), np.eye(1), hp, forcing, (CubicSpring(0, K3),))
    h = problem.harmonics
    for z in tori:
        Q = problem.recover(z)[:, 0]
        zp = np.zeros(hp.size)
        zp[0] = Q[0].real
        for k in range(1, h.H1 + 1):
            zp[2 * k - 1], zp[2 * k] = Q[h.index(k, 0)].real, -Q[h.index(k, 0)].imag
        zp = solve_periodic(periodic, zp, W1).z
        hill = np.sort(floquet(periodic, zp, W1).exponents.real)[::-1]
        result = torus_lyapunov(problem, z, LyapunovOptions(periods=60))
        assert np.all(np.abs(result.exponents - hill) < result.errors)


# ------------------------------------------------------------------------------------------------- input and result
def test_torus_lyapunov_refuses_bad_input_and_shows_itself(tmp_path):
    problem, tori = three_tori(5)
    with pytest.raises(InputError, match="options.count = 3: must be at most the state's size 2 n = 2"):
        torus_lyapunov(problem, tori[0], LyapunovOptions(count=3))
    with pytest.raises(InputError, match="z"):
        torus_lyapunov(problem, tori[0][:-1])
    with pytest.raises(InputError, match="options.blocks = 2"):
        LyapunovOptions(blocks=2)
    with pytest.raises(InputError, match="dofs = 'some'"):
        torus_trajectory(problem, tori[0], [0.0], dofs="some")
    result = torus_lyapunov(problem, tori[1], LyapunovOptions(periods=20))
    assert_shows_itself(result, tmp_path, of=rr.TorusStability)
    assert result.stable is False and result.largest > 0
