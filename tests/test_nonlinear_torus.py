"""Quasi-periodic harmonic balance on a two-dimensional torus (rotorred.nonlinear.torus, rotorred.scenes.torus_balance)
against independent references: direct sums and central differences for the AFT and its Jacobian, the closed-form
linear response, scipy's solve_ivp, the periodic harmonic balance at commensurate frequencies, and on the rig the
linear steady state and the transient.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotorred.checks import InputError
from rotorred.nonlinear.forces import CubicSpring
from rotorred.nonlinear.fourier import Harmonics, alias_free_samples
from rotorred.nonlinear.hb import NotConverged, PeriodicProblem, solve_periodic
from rotorred.nonlinear.torus import TorusHarmonics, TorusProblem, TorusSeries, alias_free_grid, solve_torus

# the cubic oscillator x'' + C x' + x + K3 x^3 = F1 cos(w1 t) + F2 cos(w2 t), both tones near its resonance
C, K3, F1, F2 = 0.2, 0.5, 0.15, 0.1
W_INCOMMENSURATE = (0.8, 0.8 * math.sqrt(2.0))


class LinearSpring:
    """A 'nonlinear' force that is linear, f = S q (through the AFT all the same)."""

    def __init__(self, S):
        self.S, self.dofs = np.asarray(S, float), tuple(range(len(S)))

    def evaluate(self, q, v):
        N = q.shape[0]
        return q @ self.S.T, np.broadcast_to(self.S, (N,) + self.S.shape).copy(), np.zeros((N,) + self.S.shape)


class VelocityCubic:
    """f = c3 v^3 on one DOF: a velocity-dependent force."""

    def __init__(self, dof, c3):
        self.dofs, self.c3 = (dof,), c3

    def evaluate(self, q, v):
        return self.c3 * v**3, np.zeros(q.shape + (1,)), (3.0 * self.c3 * v**2)[:, :, None]


class RankOneCubic:
    """f = u k3 (g . q)^3: every DOF pair's derivative a multiple of one shape (a rub's structure, rank 1)."""

    def __init__(self, u, g, k3):
        self.u, self.g, self.k3, self.dofs = np.asarray(u, float), np.asarray(g, float), k3, tuple(range(len(u)))

    def evaluate(self, q, v):
        p = q @ self.g
        d = 3.0 * self.k3 * p**2
        return np.outer(self.k3 * p**3, self.u), d[:, None, None] * np.outer(self.u, self.g)[None], \
            np.zeros((q.shape[0], len(self.u), len(self.u)))


def two_dof(h: TorusHarmonics, w, forces, amplitudes=(0.3, 0.2j)) -> TorusProblem:
    M = np.array([[1.0, 0.1], [0.1, 2.0]])
    D = np.array([[0.05, 0.01], [0.0, 0.08]])  # not symmetric: as a gyroscopic part would make it
    K = np.array([[2.0, -0.5], [-0.5, 1.5]])
    Q = np.zeros((h.n_orders, 2), complex)
    Q[h.index(1, 0), 0], Q[h.index(0, 1), 1] = amplitudes
    return TorusProblem(M, D, K, h, w, (0, 1), h.from_phasors(Q), tuple(forces))


def cubic_oscillator(H: int, w) -> TorusProblem:
    h = TorusHarmonics(H, H, *alias_free_grid(H, H, 3))
    Q = np.zeros((h.n_orders, 1), complex)
    Q[h.index(1, 0)], Q[h.index(0, 1)] = F1, F2
    return TorusProblem(np.eye(1), C * np.eye(1), np.eye(1), h, w, (0,), h.from_phasors(Q), (CubicSpring(0, K3),))


# ------------------------------------------------------------------------------------------------- the basis and AFT
def test_torus_aft_equals_the_direct_sums_and_inverts_exactly():
    """Samples and rates by the inverse 2-D FFT equal the Fourier sums written out (measured 2.9e-15 and 2.6e-15 of
    their largest value); the forward FFT returns the coefficients (3.1e-15); the Toeplitz matrices from the spectrum
    equal forward diag(d) E, the sums over samples (6.7e-16); a transfer to a larger set and back is exact."""
    h = TorusHarmonics(3, 4, 12, 14)
    rng = np.random.default_rng(0)
    n, w = 2, (1.0, math.sqrt(2.0))
    z = rng.standard_normal(h.size * n)
    c = z.reshape(h.size, n)
    theta, wk = h.angles(), h.frequencies(w)
    q_ref, v_ref = np.tile(c[0], (h.n_samples, 1)), np.zeros((h.n_samples, n))
    for i, k in enumerate(h.orders[1:], start=1):
        phase = (theta @ k)[:, None]
        q_ref += np.cos(phase) * c[2 * i - 1] + np.sin(phase) * c[2 * i]
        v_ref += wk[i] * (-np.sin(phase) * c[2 * i - 1] + np.cos(phase) * c[2 * i])
    assert np.max(np.abs(h.samples(z, n) - q_ref)) < 3e-14 * np.max(np.abs(q_ref))
    assert np.max(np.abs(h.rates(z, n, w) - v_ref)) < 3e-14 * np.max(np.abs(v_ref))
    assert np.max(np.abs(h.coefficients(q_ref) - z)) < 3e-14
    d = rng.standard_normal((h.n_samples, n, n))
    assert np.max(np.abs(h.toeplitz(d) - h.toeplitz_by_samples(d))) < 1e-14
    larger = TorusHarmonics(4, 6, 10, 14)
    assert np.array_equal(larger.transfer(h.transfer(z, n, larger), n, h), z)
    assert h.size == 2 * h.n_orders - 1 and h.n_orders == 1 + 3 * 9 + 4  # (0,0), k1 = 1..3 x 9, k1 = 0 x 4


def test_torus_aft_on_a_band_with_and_without_pyfftw_and_the_grid_product(monkeypatch):
    """On a band (orders with k2 < 0 and on the k1 = 0 axis, the real transform along theta_2 holding the conjugates
    of some) the samples equal the Fourier sums (measured 1.2e-15 of the largest) and the forward FFT returns the
    coefficients (2.0e-15), with pyFFTW's plans and with scipy's FFT in their place (1.2e-15, 8.9e-16); the grid
    product's coefficients equal those of the product's samples (1.1e-15)."""
    import rotorred.nonlinear.torus as torus_module

    w = (1.0, math.sqrt(2.0))
    rng = np.random.default_rng(2)
    n = 3
    for fftw in (torus_module.pyfftw, None):
        monkeypatch.setattr(torus_module, "pyfftw", fftw)
        h = TorusHarmonics(4, 6, 12, 16, 6.0, w)
        assert np.any(h.orders[:, 1] < 0) and np.any((h.orders[:, 0] == 0) & (h.orders[:, 1] > 0))
        z = rng.standard_normal(h.size * n)
        q_ref = h.basis_matrix() @ z.reshape(h.size, n)
        assert np.max(np.abs(h.samples(z, n) - q_ref)) < 1e-14 * np.max(np.abs(q_ref))
        assert np.max(np.abs(h.coefficients(q_ref) - z)) < 2e-14
        f = rng.standard_normal(h.n_samples)
        product = h.grid_product(h.phasors(z, n), lambda x, out: np.multiply(f, x, out=out), n)
        reference = h.coefficients(f[:, None] * q_ref).reshape(h.size, n)
        assert np.max(np.abs(product - reference)) < 1e-14 * np.max(np.abs(reference))


def test_right_preconditioned_gmres_stops_on_the_true_residual():
    """``right_gmres`` on a dense nonsymmetric system: the residual it reports is the true ``||b - A x|| / ||b||``
    and within the tolerance, with a near inverse as preconditioner (9 iterations over restarts of 5) and without
    (32); its solution is numpy's to 2.5e-11 and 2.2e-10."""
    from rotorred.nonlinear.torus_krylov import right_gmres

    rng = np.random.default_rng(2)
    A = np.eye(200) + 0.5 * rng.standard_normal((200, 200)) / np.sqrt(200)
    b = rng.standard_normal(200)
    near = np.linalg.inv(A + 0.05 * rng.standard_normal((200, 200)) / np.sqrt(200))
    for M, restart, most, error in ((lambda v: near @ v, 5, 12, 2.5e-10), (lambda v: v, 30, 40, 2.2e-9)):
        x, iterations, residual = right_gmres(lambda v: A @ v, M, b, None, 1e-10, restart, 3000)
        assert iterations <= most and residual <= 1e-10
        assert residual == pytest.approx(np.linalg.norm(b - A @ x) / np.linalg.norm(b), rel=1e-6)
        assert np.max(np.abs(x - np.linalg.solve(A, b))) < error


def test_torus_harmonics_refuses_an_aliased_grid_and_a_band_without_frequencies():
    with pytest.raises(InputError, match="N1 = 7: must be an integer >= 8"):
        TorusHarmonics(3, 4, 7, 14)
    with pytest.raises(InputError, match="N2 = 15: must be even"):
        TorusHarmonics(3, 4, 8, 15)
    with pytest.raises(InputError, match="w = None: must be given with w_max"):
        TorusHarmonics(3, 4, 8, 14, w_max=5.0)
    band = TorusHarmonics(3, 4, 8, 14, w_max=2.0, w=(1.0, math.sqrt(2.0)))
    assert np.all(np.abs(band.frequencies((1.0, math.sqrt(2.0)))) <= 2.0) and band.n_orders < 32


def test_torus_jacobian_is_the_analytic_chain_rule_and_the_matrix_free_step_is_newtons():
    """dR/dz (a cubic spring, a velocity-cubic damper and a rank-1 cubic on a 2-DOF system) equals central differences
    (measured 1.5e-10 of its largest entry); the matrix-free product J v (the sampled fields on the patterns' rank,
    through the grid) equals the dense J @ v (measured 6.6e-16 relative), and Newton's step by Woodbury and GMRES at
    rtol 1e-14 equals the dense solve (full rank, r = s = 2: measured 9.3e-15 in 22 GMRES iterations on the 126
    unknowns of the reduced equation; rank 1: 8.5e-16 in 10 iterations on 63)."""
    h = TorusHarmonics(3, 4, *alias_free_grid(3, 4, 3))
    w = (1.0, math.sqrt(2.0))
    problem = two_dof(h, w, (CubicSpring(0, 0.5), VelocityCubic(1, 0.3), RankOneCubic((1.0, -0.5), (0.3, 1.0), 2.0)))
    z = problem.linear_response() * 3.0
    J = problem.evaluate(z).dR_dz
    eps = 1e-6
    J_fd = np.column_stack([(problem.residual(z + eps * e) - problem.residual(z - eps * e)) / (2 * eps)
                            for e in np.eye(problem.size)])
    assert np.max(np.abs(J - J_fd)) < 2e-9 * np.max(np.abs(J))
    v = np.random.default_rng(1).standard_normal(problem.size)
    R, free = problem.jacobian(z)
    assert (free.r, free.s) == (2, 2)
    assert np.max(np.abs(free.times(v) - J @ v)) < 1e-14 * np.max(np.abs(J @ v))
    R, step, stats, _ = problem.newton_step(z, rtol=1e-14)
    assert np.max(np.abs(step - np.linalg.solve(J, -R))) < 3e-14 * np.max(np.abs(step))
    assert stats.iterations <= 30
    rank_one = two_dof(h, w, (RankOneCubic((1.0, -0.5), (0.3, 1.0), 2.0),))
    ev, (_, step1, stats1, _) = rank_one.evaluate(z), rank_one.newton_step(z, rtol=1e-14)
    assert rank_one.jacobian(z)[1].inner_size == h.size
    assert np.max(np.abs(step1 - np.linalg.solve(ev.dR_dz, -ev.R))) < 3e-14 * np.max(np.abs(step1))
    assert stats1.iterations <= 30


@pytest.mark.parametrize("coarse", [10, 1000])
def test_the_preconditioners_block_is_the_reduced_matrix_between_its_orders(monkeypatch, coarse):
    """The coarse block (written by one compiled pass from the fields' spectra) is the reduced equation's matrix
    ``I + C G_VU`` between the orders it keeps, that matrix built column by column through the grid (the matrix-free
    product, itself the dense J's above): with velocity terms and r = s = 2, on 10 of the 25 orders and on all
    (measured 4.1e-16 of its largest entry on both, in double precision)."""
    from rotorred.nonlinear import torus_krylov
    monkeypatch.setattr(torus_krylov, "COARSE_ORDERS", coarse)
    h = TorusHarmonics(3, 4, *alias_free_grid(3, 4, 3))
    problem = two_dof(h, (1.0, math.sqrt(2.0)), (CubicSpring(0, 0.5), VelocityCubic(1, 0.3),
                                                 RankOneCubic((1.0, -0.5), (0.3, 1.0), 2.0)))
    _, J = problem.jacobian(problem.linear_response() * 3.0)
    assert J.has_velocity and (J.r, J.s) == (2, 2)
    reduced = np.column_stack([J.inner(e) for e in np.eye(J.inner_size)])
    rows, (lu, pivots) = J._coarse_block()
    assert lu.dtype == np.float64 and len(rows) == (2 * min(coarse, h.n_orders) - 1) * J.r
    block = (np.tril(lu, -1) + np.eye(len(lu))) @ np.triu(lu)
    for i, p in reversed(list(enumerate(pivots))):  # undo LAPACK's row interchanges
        block[[i, p]] = block[[p, i]]
    expected = reduced[np.ix_(rows, rows)]
    assert np.max(np.abs(block - expected)) < 1e-14 * np.max(np.abs(expected))


def test_the_compliance_by_the_modes_is_the_direct_solves_and_recovers_every_dof():
    """A problem's compliance by the modes (its iterates ask only the rows of the unknown DOFs, two of three here; every
    DOF's is computed when a solution is recovered) equals the direct solve of each order's dynamic stiffness: G
    applied, the linear response and every DOF's recovered amplitudes (measured 4.7e-15, 4.1e-15, 8.6e-15 of their
    largest)."""
    h = TorusHarmonics(3, 4, *alias_free_grid(3, 4, 3))
    M = np.array([[1.0, 0.1, 0.0], [0.1, 2.0, 0.2], [0.0, 0.2, 1.5]])
    D = np.array([[0.05, 0.01, 0.0], [0.0, 0.08, 0.02], [0.0, -0.02, 0.06]])  # not symmetric (a gyroscopic part)
    K = np.array([[2.0, -0.5, 0.0], [-0.5, 1.5, -0.4], [0.0, -0.4, 3.0]])
    Q = np.zeros((h.n_orders, 3), complex)
    Q[h.index(1, 0), 0], Q[h.index(0, 1), 2] = 0.3, 0.2j

    def problem():
        return TorusProblem(M, D, K, h, (1.0, math.sqrt(2.0)), (0, 1), h.from_phasors(Q),
                            (RankOneCubic((1.0, -0.5), (0.3, 1.0), 2.0),))
    direct, modal = problem(), problem().by_modes()
    z = direct.linear_response() * 3.0
    x = np.random.default_rng(2).standard_normal(direct.size)
    assert direct.recover(z).shape == (h.n_orders, 3)
    for a, b in ((direct.apply(x), modal.apply(x)), (direct.linear_response(), modal.linear_response()),
                 (direct.recover(z), modal.recover(z))):
        assert np.max(np.abs(a - b)) < 5e-14 * np.max(np.abs(a))
        assert np.any(a != b)  # two paths (not the direct solve's fallback where the modes do not match)


def test_an_outputs_recovery_is_those_rows_of_every_dofs():
    """``recover(z, outputs)``: a few rows combining the DOFs (a DOF's own row, a mix of two) are those rows applied to
    every DOF's recovered amplitudes, by the modes (their products for the rows alone, the eigen-solution the
    compliance's) and by the direct solves, asked before every DOF's and after them (then projected from them; measured
    1.9e-17 and 7.0e-18 by the modes, 1.5e-16 both by the direct solves, of the largest)."""
    h = TorusHarmonics(3, 4, *alias_free_grid(3, 4, 3))
    M = np.array([[1.0, 0.1, 0.0], [0.1, 2.0, 0.2], [0.0, 0.2, 1.5]])
    D = np.array([[0.05, 0.01, 0.0], [0.0, 0.08, 0.02], [0.0, -0.02, 0.06]])
    K = np.array([[2.0, -0.5, 0.0], [-0.5, 1.5, -0.4], [0.0, -0.4, 3.0]])
    Q = np.zeros((h.n_orders, 3), complex)
    Q[h.index(1, 0), 0], Q[h.index(0, 1), 2] = 0.3, 0.2j
    O = np.array([[0.0, 0.0, 1.0], [0.5, 0.0, -2.0]])

    def problem():
        return TorusProblem(M, D, K, h, (1.0, math.sqrt(2.0)), (0, 1), h.from_phasors(Q),
                            (RankOneCubic((1.0, -0.5), (0.3, 1.0), 2.0),))
    direct, modal = problem(), problem().by_modes()
    for p in (direct, modal):
        z = p.linear_response() * 3.0
        rows = p.recover(z, O)  # before every DOF's: the outputs' own (the modes' products for the rows alone)
        every, kept = p.recover(z), p.recover(z, O)  # after: every DOF's kept, projected
        assert rows.shape == kept.shape == (h.n_orders, 2)
        for r in (rows, kept):
            assert np.max(np.abs(r - every @ O.T)) < 2e-15 * np.max(np.abs(rows))


# ------------------------------------------------------------------------------------------------- solutions
def test_linear_system_at_two_incommensurate_frequencies_is_the_closed_form():
    """A 2-DOF system with a linear spring S passed through the AFT as a force, forced at w1 and w2 = sqrt(2) w1: each
    forced line is (K + S - w^2 M + i w D)^-1 F (measured 3.4e-15 relative), every other line 0 (8.8e-17); the dense
    Newton of hb.solve and the matrix-free Newton give the same coefficients (measured 2.5e-15)."""
    h = TorusHarmonics(2, 3, 6, 8)
    w = (1.0, math.sqrt(2.0))
    S = np.array([[0.4, -0.1], [-0.1, 0.7]])
    problem = two_dof(h, w, (LinearSpring(S),))
    sol = solve_torus(problem, np.zeros(problem.size))
    Q = problem.recover(sol.z)
    for (k1, k2), F in (((1, 0), np.array([0.3, 0.0])), ((0, 1), np.array([0.0, 0.2j]))):
        om = k1 * w[0] + k2 * w[1]
        ref = np.linalg.solve(problem.K + S - om**2 * problem.M + 1j * om * problem.D, F)
        assert np.max(np.abs(Q[h.index(k1, k2)] - ref)) < 3e-14 * np.max(np.abs(ref))
    others = [i for i in range(h.n_orders) if i not in (h.index(1, 0), h.index(0, 1))]
    assert np.max(np.abs(Q[others])) < 1e-15
    z_dense = solve_periodic(problem, np.zeros(problem.size), w[0]).z
    assert np.max(np.abs(z_dense - sol.z)) < 2e-14 * np.max(np.abs(sol.z))
    assert sol.iterations == 1 and sol.history[0] == pytest.approx(1.0)  # linear: one Newton step from 0


def test_solve_torus_refuses_a_point_that_does_not_converge():
    problem = cubic_oscillator(3, W_INCOMMENSURATE)
    with pytest.raises(NotConverged, match="after 1 Newton iterations"):
        solve_torus(problem, np.zeros(problem.size), max_iter=1)


def test_cubic_oscillator_on_the_torus_equals_a_long_transient():
    """The cubic oscillator forced at w1 = 0.8 and w2 = 0.8 sqrt(2): the torus (H1 = H2 = 9, alias-free grid 38 x 38)
    against solve_ivp (DOP853, rtol 1e-10) from the linear settled state, its record over 200-700 s projected by least
    squares on the torus's lines. Measured: the two forced lines 1.1e-11 and 1.8e-11 relative, the cubic's combinations
    2w1 - w2 and w1 - 2w2 (3.7 % and 3.6 % of the larger forced line) 9.5e-11 and 9.9e-11, the fifth-order 2w1 + w2
    (0.49 %) 4.0e-10 and 3w1 - 2w2 (0.16 %) 5.9e-9; the torus converges with H (the forced line's change H = 5 -> 7:
    4.0e-10, 7 -> 9: 2.2e-13), in 4 Newton iterations from the linear response."""
    problem = cubic_oscillator(9, W_INCOMMENSURATE)
    sol = solve_torus(problem, problem.linear_response())
    assert sol.iterations <= 6
    h, w = problem.harmonics, W_INCOMMENSURATE
    Q = problem.recover(sol.z)[:, 0]
    Q5 = cubic_oscillator(5, w)
    Q7 = cubic_oscillator(7, w)
    a5, a7 = (abs(p.recover(solve_torus(p, p.linear_response()).z)[p.harmonics.index(1, 0), 0]) for p in (Q5, Q7))
    assert abs(a7 - a5) < 4e-9 * a7

    lin = problem.linear_response()  # the linear settled state at t = 0 (no nonlinear part): an independent start
    x0 = h.samples(lin, 1)[0, 0]
    v0 = h.rates(lin, 1, w)[0, 0]

    def rhs(t, y):
        return [y[1], F1 * math.cos(w[0] * t) + F2 * math.cos(w[1] * t) - C * y[1] - y[0] - K3 * y[0] ** 3]
    ode = solve_ivp(rhs, (0.0, 700.0), [x0, v0], method="DOP853", rtol=1e-10, atol=1e-12, dense_output=True)
    t = np.linspace(200.0, 700.0, 20001)
    phase = np.outer(t, h.frequencies(w)[1:])
    coef = np.linalg.lstsq(np.hstack([np.ones((t.size, 1)), np.cos(phase), np.sin(phase)]), ode.sol(t)[0],
                           rcond=None)[0]
    K = h.n_orders
    Q_ode = np.concatenate([[coef[0]], coef[1:K] - 1j * coef[K:]])
    for order, tol in (((1, 0), 2e-10), ((0, 1), 2e-10), ((2, -1), 1e-9), ((1, -2), 1e-9), ((2, 1), 4e-9),
                       ((3, -2), 6e-8)):
        i = h.index(*order)
        assert abs(Q_ode[i] - Q[i]) < tol * abs(Q[i]), order
    assert abs(Q[h.index(1, 1)]) < 1e-15  # an odd force has no even combinations


def test_torus_at_commensurate_frequencies_is_the_periodic_balance():
    """At w2 = 2 w1 the torus u(theta1, theta2) read along theta = w t is the periodic response: the torus's lines
    summed per harmonic k1 + 2 k2 equal rotorred.nonlinear.hb's periodic solution (30 harmonics) forced at harmonics 1
    and 2. Two paths to one answer: measured 1.5e-8 (H = 7) and 9e-11 (H = 9) of the largest line."""
    w1, Hp = 0.6, 30
    hp = Harmonics(Hp, alias_free_samples(Hp, 3))

    def forcing(omega):
        f = np.zeros(hp.size)
        f[1], f[3] = F1, F2
        return f, np.zeros(hp.size)
    periodic = PeriodicProblem(np.eye(1), C * np.eye(1), np.eye(1), hp, forcing, (CubicSpring(0, K3),))
    zp = solve_periodic(periodic, periodic.linear_response(w1), w1).z
    Qp = np.concatenate([[zp[0]], zp[1::2] - 1j * zp[2::2]])
    for H, tol in ((7, 2e-7), (9, 1e-9)):
        problem = cubic_oscillator(H, (w1, 2 * w1))
        Q = problem.recover(solve_torus(problem, problem.linear_response()).z)[:, 0]
        harmonic = problem.harmonics.orders @ np.array([1, 2])
        collapsed = np.zeros(Hp + 1, complex)
        for i, m in enumerate(harmonic):
            if m == 0:
                collapsed[0] += Q[i].real
            else:
                collapsed[abs(m)] += Q[i] if m > 0 else Q[i].conj()
        assert np.max(np.abs(collapsed - Qp)) < tol * np.max(np.abs(Qp))


# ------------------------------------------------------------------------------------------------- the rig
def test_rub_scene_out_of_contact_is_the_linear_unbalance_response_on_the_torus():
    """paper-rub at outer 91.37 Hz on the signal layer's torus (f_L, f_H/3), the clearance opened to 1 mm: each spool's
    unbalance forces its order ((1, 0) and (0, 3)); the solution, read along theta = w t, is the scene's linear steady
    state (rotorred.scenes.run.settled_response; measured 1.2e-13 of the peak at nodes 14 and 18 over 1 s), and the
    start fitted to that record by least squares is the solution (1.1e-13)."""
    from rotorred.scenes.run import build_model, settled_response
    from rotorred.scenes.schema import load_scene
    from rotorred.scenes.torus_balance import torus_rub_problem
    from rotorred.signals.linefit import Torus

    scene = load_scene("paper-rub", {"speeds.outer": 91.37, "rub.clearance": 1e-3})
    model = build_model(scene).model
    rp = torus_rub_problem(scene, model, Torus(70.0, 91.37, k=3, j=1), 2, 4, 8, 16)
    assert rp.bases_hz == pytest.approx((70.0, 91.37 / 3), rel=1e-15)
    assert rp.spool_orders == {"inner": (1, 0), "outer": (0, 3)}
    sol = solve_torus(rp.problem, rp.problem.linear_response())
    assert sol.iterations == 0
    t = np.arange(0.0, 1.0, 1e-4)
    dofs = [(14, "y"), (18, "x"), (18, "y")]
    reference = settled_response(scene, model, model.output_rows(dofs), t)
    Q = rp.problem.recover(sol.z)[:, :rp.n_model] @ model.output_rows(dofs).T
    y = np.real(np.exp(1j * np.outer(t, rp.problem.frequencies)) @ Q).T
    assert np.max(np.abs(y - reference)) < 1e-12 * np.max(np.abs(reference))
    records = {0: reference[1], 1: reference[2], 2: np.zeros_like(t), 3: np.zeros_like(t)}
    z0 = rp.start_from_record(t, records)
    assert np.max(np.abs(z0 - sol.z)) < 1e-12 * np.max(np.abs(sol.z))
    with pytest.raises(InputError, match="commensurate"):
        torus_rub_problem(scene, model, (10.0, 20.0), 2, 4, 8, 16)


def test_rub_torus_from_a_second_of_the_transient_converges_and_holds_the_forced_lines():
    """paper-rub at outer 91.37 Hz, rubbing: a 3 s transient (its line fit on 2-3 s finds the torus (f_H/3, f_L)
    itself) starts the torus on a coarse set (|k1| <= 6, |k2| <= 30, grid 32 x 256; least squares on |k1| <= 4,
    |k2| <= 30). Newton converges (measured 8 iterations, 152 GMRES iterations in all; the rub's Jacobian pattern is
    rank 1, so each step is GMRES on 2K - 1 = 793 unknowns, matrix-free), and the three largest lines at node 14 Y
    equal the transient's (measured f_H
    -0.15 %, 4f_H/3 -0.35 %, f_L -0.017 %); the impacts' combination lines need the larger sets of
    validation/hb_torus.py (here 2f_H/3 + f_L is 3.7 % off)."""
    from rotorred.scenes.harmonic_balance import unknown_records
    from rotorred.scenes.run import build_model, run_scene
    from rotorred.scenes.schema import load_scene
    from rotorred.scenes.torus_balance import torus_rub_problem
    from rotorred.signals.linefit import fit_lines

    scene = load_scene("paper-rub", {"speeds.outer": 91.37, "solver.duration": 3.0, "solver.record_start": 2.0,
                                     "output.nodes": [14, 18], "output.directions": ["x", "y"], "output.table": "14:y",
                                     "output.plots": [], "output.formats": [], "output.compare_normal": False,
                                     "output.plot_window": [2.0, 3.0]})
    sm = build_model(scene)
    result = run_scene(scene, sm, compare_normal=False, analyse=False)
    fit = fit_lines(result.t, result.outputs[(14, "y")], 70.0, 91.37)
    assert (fit.torus.k, fit.torus.j) == (3, 1)
    rp = torus_rub_problem(scene, sm.model, fit.torus, 6, 30, 32, 256)
    records = unknown_records(scene.plates, result)
    sol = solve_torus(rp.problem, rp.start_from_record(result.t, records, within=(4, 30)))
    assert sol.iterations <= 10 and sol.residual < 1e-10 and len(sol.krylov) == sol.iterations
    largest = {ln.label: ln for ln in fit.lines}
    for label, tol in (("f_H", 1.5e-2), ("4f_H/3", 3.5e-2), ("f_L", 2e-3)):
        ln = largest[label]
        assert rp.amplitudes_at(sol.z, (14, "y"), [ln.frequency_hz])[0] == pytest.approx(ln.amplitude, rel=tol)


def test_positions_and_transfer_match_a_lookup_by_hand():
    """``TorusHarmonics.positions`` (sorted codes) is the dictionary lookup it replaced, -1 where an order is absent,
    and ``transfer`` to a larger set and back is the identity on the orders (exactly: a copy of coefficients)."""
    w = (2 * math.pi * 70.0, 2 * math.pi * 91.37 / 3)
    small, large = TorusHarmonics(3, 9, 16, 32, 2 * math.pi * 400.0, w), TorusHarmonics(5, 14, 16, 32)
    by_hand = {(int(a), int(b)): i for i, (a, b) in enumerate(small.orders)}
    expected = np.array([by_hand.get((int(a), int(b)), -1) for a, b in large.orders])
    assert np.array_equal(small.positions(large.orders), expected)
    assert np.sum(expected >= 0) == small.n_orders and np.sum(expected < 0) > 0
    z = np.random.default_rng(1).standard_normal(small.size * 2)
    assert np.array_equal(large.transfer(small.transfer(z, 2, large), 2, small), z)


def test_a_problem_with_other_forces_shares_the_compliance_and_is_a_fresh_build():
    """``TorusProblem.with_forces`` (a clearance along a branch): its residual at the rig's 14 µm torus start equals
    the residual of the problem built afresh at that clearance to round-off (measured 0), and its compliance is the
    original's object (computed once)."""
    from rotorred.scenes.harmonic_balance import plate_rubs
    from rotorred.scenes.run import build_model
    from rotorred.scenes.schema import load_scene
    from rotorred.scenes.torus_balance import torus_rub_problem

    scene = load_scene("paper-rub", {"speeds.outer": 91.37, "rub.clearance": 13e-6})
    model = build_model(scene).model
    there = load_scene("paper-rub", {"speeds.outer": 91.37, "rub.clearance": 9e-6})
    first = torus_rub_problem(scene, model, (70.0, 91.37 / 3), 2, 8, 16, 64).problem
    fresh = torus_rub_problem(there, model, (70.0, 91.37 / 3), 2, 8, 16, 64).problem
    moved = first.with_forces(plate_rubs(model, there)[1])
    z = 3.0 * first.linear_response()  # in contact at both clearances
    assert np.linalg.norm(first.residual(z) - moved.residual(z)) > 1e-3 * np.linalg.norm(moved.residual(z))
    assert np.linalg.norm(moved.residual(z) - fresh.residual(z)) <= 1e-14 * np.linalg.norm(fresh.residual(z))
    assert moved._compliance() is first._compliance()


def test_the_torus_series_is_the_direct_sum_at_any_times_its_phase_table_kept_only_for_its_step():
    """``TorusSeries`` against the direct sum ``Re sum_k Q_k exp(i (k . w) t)`` (one exponential per order and time):
    at uniform times (its kept phase table: 1500 times, two blocks), again at other uniform times of the same step
    (the table reused) and of another step (made afresh), at uneven times and at one time: the same to 1e-13 of the
    largest value (measured 1.3e-14 at most; a table kept for the wrong step is off by 1.3 of it)."""
    rng = np.random.default_rng(3)
    h = TorusHarmonics(3, 5, 16, 32)
    w = (2.0, 2.0 * math.sqrt(2.0))
    Q = rng.standard_normal((h.n_orders, 2)) + 1j * rng.standard_normal((h.n_orders, 2))
    series = TorusSeries(h.orders, Q, w)

    def direct(t):
        return (np.exp(1j * np.outer(t, h.frequencies(w))) @ Q).real
    for t in (np.arange(1500) * 0.01, 3.7 + np.arange(700) * 0.01, np.arange(900) * 0.013,
              np.sort(rng.uniform(0.0, 20.0, 300)), np.array([1.234])):
        x = direct(t)
        assert np.max(np.abs(series(t) - x)) <= 1e-13 * np.max(np.abs(x))


def test_the_clearance_derivative_is_the_central_difference_of_the_residual():
    """``TorusProblem.dR_dclearance`` (a column of the sampled Jacobian, what a clearance branch's corrector borders
    its Jacobian with) against central differences of the residuals of the problems at 13 µm +- h (residuals only, no
    Jacobian). Their difference falls as h^2, the difference's own error (measured: 2.8e-7 at h = 1e-3 of the
    clearance, 2.8e-9 at 1e-4, a ratio of 100.0; 1.0e-10 at 1e-5, round-off then): the observed order is 2 within 0.1,
    which a wrong derivative (an O(1) difference) could not give. No sample of the grid is within 1.3e-7 m of the
    gap's edge (the law's kink; h <= 1.3e-8 m), so the differences are smooth."""
    from rotorred.scenes.run import build_model
    from rotorred.scenes.schema import load_scene
    from rotorred.scenes.torus_balance import torus_rub_problem

    c = 13e-6
    scene = load_scene("paper-rub", {"speeds.outer": 91.37, "rub.clearance": c})
    model = build_model(scene).model
    problem = torus_rub_problem(scene, model, (70.0, 91.37 / 3), 2, 8, 16, 64).problem
    z = 3.0 * problem.linear_response()  # in contact on part of the grid
    rub, (force, idx) = problem.forces[0], problem._local_forces[0]
    penetration = problem.samples(z)[0][:, idx] @ force.gradient - c
    assert np.min(np.abs(penetration - rub.plate.offset)) > 1e-3 * c  # farther than the largest h
    exact = problem.dR_dclearance(z)
    assert np.linalg.norm(exact) > 1.0  # in contact: the clearance moves the residual

    def error(relative):
        h = relative * c
        up, down = (problem.with_forces((rub.with_clearance(c + d),) + problem.forces[1:]) for d in (h, -h))
        return np.linalg.norm(exact - (up.residual(z) - down.residual(z)) / (2 * h)) / np.linalg.norm(exact)
    coarse, fine = error(1e-3), error(1e-4)
    assert math.log10(coarse / fine) == pytest.approx(2.0, abs=0.1)
    assert error(1e-5) <= 1e-9


def test_a_spool_frequency_held_by_several_far_apart_orders_is_its_lowest():
    """At outer 91 Hz the bases (70, 91/3) Hz are 13:10: in the box |k1| <= 32, |k2| <= 80 (band 900 Hz) 70 Hz is the
    order (1, 0) and (12, -30) (and more), 91 Hz (0, 3) and (13, -27). The spool's order is the lowest, the others 42
    and more times higher (|k1| + |k2|); bases commensurate at low orders stay refused (tests/test_scene_analyses.py: (70, 35)
    Hz, 70 Hz the orders (1, 0) and (0, 2))."""
    from rotorred.scenes.run import build_model
    from rotorred.scenes.schema import load_scene
    from rotorred.scenes.torus_balance import torus_rub_problem

    scene = load_scene("paper-rub", {"speeds.outer": 91.0})
    model = build_model(scene).model
    rp = torus_rub_problem(scene, model, (70.0, 91.0 / 3), 32, 80, 128, 256, 900.0)
    h, f = rp.problem.harmonics, np.abs(rp.problem.harmonics.frequencies(rp.bases_hz))
    held = {(int(a), int(b)) for a, b in h.orders[np.abs(f - 70.0) < 1e-9 * 70.0]}
    assert {(1, 0), (12, -30)} <= held and min(abs(a) + abs(b) for a, b in held - {(1, 0)}) == 42
    assert rp.spool_orders == {"inner": (1, 0), "outer": (0, 3)}
