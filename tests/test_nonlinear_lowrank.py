"""The low-rank form of the harmonic-balance Jacobian (rotorred.nonlinear.lowrank, rotorred.nonlinear.sampled): two
paths to one answer, the Woodbury solves against dense ones, the outer products against the Toeplitz matrices, their
operators against their arrays and the kernel's coupling against the product it stands for."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from rotorred.nonlinear.examples import GAP, K_C
from rotorred.nonlinear.forces import CircularClearance
from rotorred.nonlinear.fourier import Harmonics
from rotorred.nonlinear.lowrank import Dense, IdentityPlusLowRank, bordered, factored
from rotorred.nonlinear.sampled import low_rank


def test_woodbury_solves_equal_dense_ones():
    """I + P Q^T (n = 60, rank 9) and its bordered form [[A, c], [row]]: products, solves and transposed solves
    equal the dense matrix's (measured 4.6e-14 relative, condition numbers 1.8e3 and 1.1e3); the bordered small matrix
    built by blocks equals Q^T P formed whole (measured 5e-16)."""
    rng = np.random.default_rng(3)
    n, r = 60, 9
    P, Q = rng.normal(size=(n, r)) / 3, rng.normal(size=(n, r)) / 3
    A = IdentityPlusLowRank(P, Q)
    dense = np.eye(n) + P @ Q.T
    b = rng.normal(size=n)
    assert np.allclose(A @ b, dense @ b, rtol=0, atol=1e-13)
    for trans in (False, True):
        exact = np.linalg.solve(dense.T if trans else dense, b)
        assert np.max(np.abs(A.solve(b, trans) - exact)) < 5e-13 * np.max(np.abs(exact))
    column, row, c = rng.normal(size=n), rng.normal(size=n + 1), rng.normal(size=n + 1)
    B = bordered(A, column, row)
    dense_B = np.vstack([np.column_stack([dense, column]), row])
    assert np.max(np.abs(np.asarray(B) - dense_B)) == 0.0
    assert np.max(np.abs(B.QtP - B.Q.dense().T @ B.P.dense())) < 5e-15 * np.max(np.abs(B.QtP))
    for trans in (False, True):
        exact = np.linalg.solve(dense_B.T if trans else dense_B, c)
        assert np.max(np.abs(B.solve(c, trans) - exact)) < 2e-13 * np.max(np.abs(exact))
        assert np.max(np.abs(bordered(dense, column, row).solve(c, trans) - exact)) < 2e-13 * np.max(np.abs(exact))
    assert factored(A) is A and isinstance(factored(dense), Dense)


def test_singular_matrices_are_refused():
    """A singular I + P Q^T (Q^T P = -1 in one direction) and a singular dense matrix raise LinAlgError, not inf."""
    P = np.array([[1.0], [0.0]])
    with pytest.raises(sla.LinAlgError):
        IdentityPlusLowRank(P, -P).solve(np.ones(2))
    with pytest.raises(sla.LinAlgError):
        Dense(np.zeros((2, 2)))


@pytest.mark.parametrize("H, N", [(5, 128), (30, 256)])
def test_outer_products_equal_the_toeplitz_matrices(H, N):
    """For a Jeffcott disk in a circular clearance (rank 2 a contact sample) and for a rank-1 rub-like Jacobian
    (a_i g_j s(theta) on 4 DOFs, contact on a tenth of the period), U V^T from rotorred.nonlinear.sampled.low_rank equals
    T(dq) + omega T(dv) (nabla (x) I) from the Toeplitz matrices (measured 6.5e-15 of the largest entry), with one
    column a rank of a contact sample; above max_rank it declines (None)."""
    h, omega = Harmonics(H, N), 1.7
    theta = 2 * np.pi * np.arange(N) / N
    q = np.column_stack([1.3 * np.cos(theta), 1.1 * np.sin(theta) + 0.2])
    v = omega * np.column_stack([-1.3 * np.sin(theta), 1.1 * np.cos(theta)])
    _, dq, dv = CircularClearance((0, 1), GAP, K_C).evaluate(q, v)
    s = np.where(np.cos(theta) > 0.95, np.cos(theta) - 0.95, 0.0)  # a tenth of the period in contact
    a, g, gv = np.array([1.0, -0.5, 2.0, 0.0]), np.array([0.3, 1.0, -1.0, 0.0]), np.array([0.0, 0.2, 0.1, 0.0])
    rub = (s[:, None, None] * np.outer(a, g), s[:, None, None] * np.outer(a, gv))
    for (dq_, dv_), rank in (((dq, dv), 2), (rub, 1)):
        m = dq_.shape[1]
        active = np.count_nonzero(np.abs(dq_).sum(axis=(1, 2)) + np.abs(dv_).sum(axis=(1, 2)))
        U, V = low_rank(h, dq_, dv_, omega, max_rank=10**6).dense()
        dense = h.toeplitz(dq_) + omega * h.times_derivative(h.toeplitz(dv_), m)
        assert U.shape == V.shape == (h.size * m, rank * active)
        assert np.max(np.abs(U @ V.T - dense)) < 6.5e-14 * np.max(np.abs(dense))
        assert low_rank(h, dq_, dv_, omega, max_rank=rank * active - 1) is None


@pytest.mark.parametrize("H, N", [(5, 128), (30, 256)])
def test_sampled_factors_act_as_their_arrays_and_couple_through_the_kernel(H, N):
    """SampledFactors' factors act as its arrays on matrices and single columns, both ways (U Y, U^T X, V Y, V^T X), and
    its coupling V^T G U from the kernel of G on the sample grid equals the product of the arrays with G's real block
    form, for a random complex compliance on 4 DOFs and a rub-like Jacobian whose left factors take two directions
    (friction of either sign) at a tenth of the samples (measured 1.3e-15 of the largest entry); with no contact
    sample, rank 0, an empty coupling and zero products."""
    rng = np.random.default_rng(7)
    h, omega, m = Harmonics(H, N), 1.7, 4
    theta = 2 * np.pi * np.arange(N) / N
    s = np.where(np.cos(theta) > 0.8, np.cos(theta) - 0.8, 0.0)
    sign = np.where(np.sin(theta) > 0.0, 1.0, -1.0)
    a = np.array([1.0, -0.5, 2.0, 0.0])[None, :] + 0.3 * sign[:, None] * np.array([0.0, 1.0, 0.0, -1.0])
    g, gv = np.array([0.3, 1.0, -1.0, 0.0]), 0.2 * np.array([0.3, 1.0, -1.0, 0.0])
    dq = s[:, None, None] * a[:, :, None] * g[None, None, :]
    dv = (s**2)[:, None, None] * a[:, :, None] * gv[None, None, :]
    fac = low_rank(h, dq, dv, omega, max_rank=10**6)
    U, V = fac.dense()
    Y, X = rng.normal(size=(fac.rank, 3)), rng.normal(size=(h.size * m, 3))
    for op, A in ((fac.U, U), (fac.V, V)):
        for left, right in ((op.times(Y), A @ Y), (op.t_times(X), A.T @ X), (op.times(Y[:, :1]), A @ Y[:, :1])):
            assert left.shape == right.shape and np.max(np.abs(left - right)) < 6e-15 * np.max(np.abs(right))
    Hc = rng.normal(size=(H + 1, m, m)) + 1j * rng.normal(size=(H + 1, m, m))
    G = sla.block_diag(Hc[0].real, *[np.block([[c.real, c.imag], [-c.imag, c.real]]) for c in Hc[1:]])
    exact = V.T @ G @ U
    assert np.max(np.abs(fac.coupling(Hc) - exact)) < 2e-13 * np.max(np.abs(exact))
    none = low_rank(h, 0 * dq, 0 * dv, omega, max_rank=10)
    assert none.rank == 0 and none.coupling(Hc).shape == (0, 0) and not np.any(none.U.times(np.zeros((0, 2))))
