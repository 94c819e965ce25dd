"""The real-form Toeplitz rule on a torus: the coefficients of ``d(theta) p(theta)`` as a matrix acting on those of
``p`` (docs/model.md §15), compiled, one implementation for the dense Jacobian
(:meth:`rotorred.nonlinear.torus.TorusHarmonics.toeplitz_blocks`) and the preconditioner's block
(:func:`rotorred.nonlinear.torus_krylov._compliant_block`).

With ``D_m`` the complex coefficient of order m of the sampled ``d`` (its 2-D DFT over the N_1 N_2 samples, indices
modulo the grid), the block between the row order ``k_a`` and the column order ``k_b`` (cos, sin each) is

    [[Re(D_(a-b) + D_(a+b)),   Im(D_(a-b) - D_(a+b))],
     [-Im(D_(a-b) + D_(a+b)),  Re(D_(a-b) - D_(a+b))]],

the mean's row (a = 0) halved and holding only its first row, the mean's column (b = 0) only the first column.
"""

from __future__ import annotations

from numba import njit

from rotorred.transient import numba_cache

numba_cache.register()

__all__ = ["pair_block", "pair_positions", "toeplitz_real_form"]


@njit(cache=True, inline="always")
def _wrapped(k, N):  # pragma: no cover (compiled)
    """``k mod N``, without a division where ``-N <= k < N`` (the pairs of orders of a grid that resolves them)."""
    if k < 0:
        k += N
    return k if 0 <= k < N else k % N


@njit(cache=True, inline="always")
def pair_positions(k1, k2, a, b, N1, N2):  # pragma: no cover (compiled)
    """The flat positions on the N_1 x N_2 spectrum of the difference and the sum of the orders a and b."""
    return (_wrapped(k1[a] - k1[b], N1) * N2 + _wrapped(k2[a] - k2[b], N2),
            _wrapped(k1[a] + k1[b], N1) * N2 + _wrapped(k2[a] + k2[b], N2))


@njit(cache=True, inline="always")
def pair_block(D_minus, D_plus, a, b):  # pragma: no cover (compiled)
    """The 2 x 2 block ``((cos-cos, cos-sin), (sin-cos, sin-sin))`` between the row order a and the column order b
    from ``D_(a-b)`` and ``D_(a+b)`` (module docstring); the entries a mean lacks are 0."""
    rm, im, rp, ip = D_minus.real, D_minus.imag, D_plus.real, D_plus.imag
    if a == 0 and b == 0:
        return (rm, 0.0), (0.0, 0.0)
    if a == 0:
        return (0.5 * (rm + rp), 0.5 * (im - ip)), (0.0, 0.0)
    if b == 0:
        return (rm + rp, 0.0), (-(im + ip), 0.0)
    return (rm + rp, im - ip), (-(im + ip), rm - rp)


@njit(cache=True)
def toeplitz_real_form(S, k1, k2, N1, N2, out):  # pragma: no cover (compiled)
    """``out`` (p, 2L - 1, 2L - 1) receives the Toeplitz matrix, harmonic-major (mean, then cos and sin of each
    order), between the L orders ``(k1, k2)`` (the first (0, 0)) of each of the p sampled signals whose 2-D DFT over
    the N_1 N_2 samples, divided by N_1 N_2, is ``S`` (p, N_1 N_2)."""
    L = k1.shape[0]
    for c in range(S.shape[0]):
        for a in range(L):
            for b in range(L):
                minus, plus = pair_positions(k1, k2, a, b, N1, N2)
                block = pair_block(S[c, minus], S[c, plus], a, b)
                for i in range(1 if a == 0 else 2):
                    row = 0 if a == 0 else 2 * a - 1 + i
                    for j in range(1 if b == 0 else 2):
                        out[c, row, 0 if b == 0 else 2 * b - 1 + j] = block[i][j]
