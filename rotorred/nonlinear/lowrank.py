"""Linear solves with harmonic-balance Jacobians: a dense LU, or the identity plus a low-rank product (Woodbury).

A contact acts on a small part of the period, so the Jacobian of its force coefficients is a sum of few outer
products ``U V^T``, one term a contact sample (:mod:`rotorred.nonlinear.sampled`). The condensed Jacobian
``I + G U V^T`` (:mod:`rotorred.nonlinear.condensed`) is then solved through the Woodbury identity, with an LU of the
small ``I + V^T G U`` (r x r, r the contact samples) in place of the size^3 one: at the rig's H = 100, N = 2048, r is
90-180 against a size of 804. Both forms solve the bordered systems of the continuation ``[[A, r], [t^T, tau]]`` (a
rank-two update more). Singular matrices raise ``LinAlgError``."""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla
from scipy.sparse.linalg import LinearOperator, aslinearoperator

__all__ = ["Dense", "IdentityPlusLowRank", "factored", "bordered"]


def _lu(A: np.ndarray):
    """LU factors of a square matrix, or LinAlgError if it is singular (a zero pivot) or not finite."""
    if not np.all(np.isfinite(A)):
        raise sla.LinAlgError("the matrix is not finite")
    with warnings.catch_warnings():  # a zero pivot is raised below, as LinAlgError
        warnings.simplefilter("ignore", sla.LinAlgWarning)
        lu, piv = sla.lu_factor(A, check_finite=False)
    if np.any(np.diag(lu) == 0.0):
        raise sla.LinAlgError("the matrix is singular")
    return lu, piv


class Dense:
    """A dense matrix, LU-factored once: ``solve(b)``, ``solve(b, trans=True)`` for ``A^T x = b``."""

    def __init__(self, A: np.ndarray):
        self.shape = A.shape
        self._lu = _lu(A)

    def solve(self, b: np.ndarray, trans: bool = False) -> np.ndarray:
        return sla.lu_solve(self._lu, b, trans=1 if trans else 0, check_finite=False)


class IdentityPlusLowRank:
    """``A = I + P Q^T``, P and Q of shape (n, r), solved by the Woodbury identity
    ``A^-1 = I - P (I + Q^T P)^-1 Q^T`` (and its transpose) with the small matrix factored once.

    P and Q are arrays or linear operators (``P @ y``, ``P.T @ x``: :class:`rotorred.nonlinear.sampled.SampledFactors`
    never forms its factors); ``QtP``, the small ``Q^T P``, is then given. Acts as the matrix where one is needed:
    ``A @ x``, ``np.asarray(A)``.
    """

    def __init__(self, P, Q, QtP: np.ndarray | None = None):
        self.P, self.Q = aslinearoperator(P), aslinearoperator(Q)
        n = P.shape[0]
        self.shape = (n, n)
        self.QtP = _dense(Q).T @ _dense(P) if QtP is None else QtP  # (r, r)
        self._small = None  # the LU factors of I + Q^T P, at the first solve

    @property
    def rank(self) -> int:
        return self.P.shape[1]

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        return x + self.P @ (self.Q.T @ x)

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return (np.eye(self.shape[0]) + _dense(self.P) @ _dense(self.Q).T).astype(dtype or float)

    def solve(self, b: np.ndarray, trans: bool = False) -> np.ndarray:
        if self.rank == 0:
            return np.array(b, float)
        if self._small is None:
            self._small = _lu(np.eye(self.rank) + self.QtP)
        left, right = (self.Q, self.P) if trans else (self.P, self.Q)
        return b - left @ sla.lu_solve(self._small, right.T @ b, trans=1 if trans else 0, check_finite=False)

    def bordered(self, column: np.ndarray, row: np.ndarray) -> IdentityPlusLowRank:
        """The (n + 1) matrix ``[[A, c], [row[:-1]^T, row[-1]]]`` for ``column`` c (n,) and ``row`` (n + 1,): the
        identity plus ``[[P, c, 0], [0, 0, 1]] [[Q, 0, row[:-1]], [0, 1, row[-1] - 1]]^T`` (rank r + 2), its small
        matrix by blocks from this one's (:func:`_augmented`)."""
        n = self.shape[0]
        W_P, w_P = np.column_stack([column, np.zeros(n)]), np.array([0.0, 1.0])
        W_Q, w_Q = np.column_stack([np.zeros(n), row[:-1]]), np.array([1.0, row[-1] - 1.0])
        QtP = np.block([[self.QtP, self.Q.T @ W_P], [(self.P.T @ W_Q).T, W_Q.T @ W_P + np.outer(w_Q, w_P)]])
        return IdentityPlusLowRank(_augmented(self.P, W_P, w_P), _augmented(self.Q, W_Q, w_Q), QtP)


def _augmented(X: LinearOperator, W: np.ndarray, w: np.ndarray) -> LinearOperator:
    """The operator ``[[X, W], [0, w]]``, shape (n + 1, r + 2), of X (n, r), two columns W (n, 2) and a last row w (2,):
    a factor of a bordered matrix."""
    n, r = X.shape

    def times(Y):
        Y2 = Y.reshape(r + 2, -1)
        out = np.vstack([X @ Y2[:r] + W @ Y2[r:], w @ Y2[r:]])
        return out.reshape((n + 1,) + Y.shape[1:])

    def transposed(Z):
        Z2 = Z.reshape(n + 1, -1)
        out = np.vstack([X.T @ Z2[:n], W.T @ Z2[:n] + np.outer(w, Z2[n])])
        return out.reshape((r + 2,) + Z.shape[1:])
    return LinearOperator((n + 1, r + 2), matvec=times, matmat=times, rmatvec=transposed, rmatmat=transposed,
                          dtype=float)


def _dense(X) -> np.ndarray:
    """An array or a linear operator (n, r) as an array."""
    return X if isinstance(X, np.ndarray) else X @ np.eye(X.shape[1])


def factored(A) -> Dense | IdentityPlusLowRank:
    """``A`` ready to solve with: an :class:`IdentityPlusLowRank` as it is, a dense matrix LU-factored."""
    return A if isinstance(A, IdentityPlusLowRank) else Dense(np.asarray(A))


def bordered(A, column: np.ndarray, row: np.ndarray) -> Dense | IdentityPlusLowRank:
    """The bordered matrix ``[[A, column], [row]]`` (``row`` of length n + 1), ready to solve with."""
    if isinstance(A, IdentityPlusLowRank):
        return A.bordered(column, row)
    return Dense(np.vstack([np.column_stack([A, column]), row]))
