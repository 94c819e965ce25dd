"""Sparse or dense matrices of one model: the few rules every analysis shares.

Two sizes (docs/model.md §24; measured: docs/performance.md, validation/bench_sparse.py). A model of at least
:data:`SPARSE_FROM` DOFs is assembled with ``scipy.sparse`` CSR matrices (:func:`rotorred.model.assembly.assemble`),
a smaller one with dense ndarrays, which code can read as arrays. An analysis with a sparse path solves a model of at
least :data:`SOLVE_SPARSE_FROM` DOFs sparse, a dense one through its sparse twin: from that size a beam model's banded
matrices make a sparse factorisation about O(n) per solve where a dense one is O(n^3).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["SPARSE_FROM", "SOLVE_SPARSE_FROM", "is_sparse", "dense", "csr", "zeros_like", "nonzero", "cut", "solve",
           "lowest_w2"]

#: models of at least this many DOFs are assembled sparse: their dense matrices would take 50 MB each, seven of
#: them at least (M, K, C and a G and K_G per spool); a smaller model's can be read as arrays
SPARSE_FROM = 2500
#: analyses with a sparse path (Campbell, responses, Craig-Bampton) solve models of at least this many DOFs sparse
#: (docs/performance.md, "Sparse models": sparse is quicker from about 150 DOFs for a Campbell speed, from 300-600 for
#: a response and a reduction; below 1000 a dense solve costs at most about a second)
SOLVE_SPARSE_FROM = 1000


def is_sparse(X) -> bool:
    """Whether ``X`` is a ``scipy.sparse`` matrix or array."""
    return sp.issparse(X)


def dense(X):
    """``X`` as a dense ndarray (itself if it is one)."""
    return X.toarray() if sp.issparse(X) else X


def csr(X):
    """``X`` as a CSR array (itself if it is one)."""
    return X if sp.issparse(X) else sp.csr_array(X)


def zeros_like(X):
    """A zero matrix of ``X``'s shape and kind (sparse CSR or dense)."""
    return sp.csr_array(X.shape, dtype=X.dtype) if sp.issparse(X) else np.zeros_like(X)


def nonzero(X) -> bool:
    """Whether ``X`` (sparse or dense) has a non-zero entry."""
    return bool(X.count_nonzero()) if sp.issparse(X) else bool(np.any(X))


def cut(X, rows: np.ndarray, cols: np.ndarray):
    """``X[rows][:, cols]`` of a sparse or dense matrix (index arrays)."""
    if sp.issparse(X):
        return sp.csr_array(X)[rows][:, cols]
    return X[np.ix_(rows, cols)]


def solve(A, rhs: np.ndarray) -> np.ndarray:
    """``A^-1 rhs`` of a square matrix ``A``, sparse or dense: a sparse one by SuperLU with the minimum-degree order of
    A + A^T (``permc_spec="MMD_AT_PLUS_A"``: a beam model is banded up to its node numbering, which a fill-reducing
    order undoes; a banded matrix factorises in O(n)), a dense one by LAPACK.

    Parameters
    ----------
    A : ndarray or sparse matrix, shape (n, n)
        Regular matrix (real or complex).
    rhs : ndarray, shape (n,) or (n, k)
        Right-hand side(s).

    Returns
    -------
    ndarray, shape of ``rhs``
    """
    if sp.issparse(A):
        dtype = np.result_type(A.dtype, np.asarray(rhs).dtype)
        return spla.splu(sp.csc_array(A, dtype=dtype), permc_spec="MMD_AT_PLUS_A").solve(np.asarray(rhs, dtype))
    return sla.solve(A, rhs, check_finite=False)


def lowest_w2(K, M, k: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` lowest eigenpairs of ``K phi = w^2 M phi`` (K symmetric positive semi-definite, M positive
    definite): sparse shift-invert Lanczos (ARPACK, about a shift below zero, so a singular K is factorised) for a
    sparse model with ``k`` well below its size, else the dense symmetric solver.

    Parameters
    ----------
    K, M : ndarray or sparse matrix, shape (n, n)
        Stiffness (N/m) and mass (kg).
    k : int
        Number of eigenpairs (>= 1).

    Returns
    -------
    w2 : ndarray, shape (min(k, n),)
        Eigenvalues w^2 (rad^2/s^2), ascending.
    phi : ndarray, shape (n, min(k, n))
        M-orthonormal eigenvectors.
    """
    n = M.shape[0]
    k = min(k, n)
    if not sp.issparse(M) or 3 * k + 20 > n:
        w2, phi = sla.eigh(dense(K), dense(M), subset_by_index=(0, k - 1))
        return w2, phi
    K, M = sp.csc_array(K), sp.csc_array(M)
    scale = float(np.max(np.abs(K.diagonal()) / np.maximum(M.diagonal(), 1e-300)))
    shift = -1e-8 * max(scale, 1.0)  # below every w^2 >= 0: K - shift M is positive definite
    lu = spla.splu((K - shift * M).tocsc())
    w2, phi = spla.eigsh(K, k=k, M=M, sigma=shift, OPinv=spla.LinearOperator((n, n), lu.solve, dtype=float),
                         tol=0.0)
    order = np.argsort(w2)
    w2, phi = w2[order], phi[:, order]
    return w2, phi / np.sqrt(np.einsum("ij,ij->j", phi, M @ phi))
