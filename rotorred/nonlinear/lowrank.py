"""Linear solves with harmonic-balance Jacobians: a dense LU, or the identity plus a low-rank product (Woodbury).

A contact acts on a small part of the period, so the Jacobian of its force coefficients is a sum of few outer
products ``U V^T``, one term a contact sample (:mod:`rotorred.nonlinear.sampled`). The condensed Jacobian
``I + G U V^T`` (:mod:`rotorred.nonlinear.condensed`) is then solved through the Woodbury identity, with an LU of the
small ``I + V^T G U`` (r x r, r the contact samples) in place of the size^3 one: at the rig's H = 100, N = 2048, r is
90-200 against a size of 804. Both forms solve the bordered systems of the continuation ``[[A, r], [t^T, tau]]`` (a
rank-two update more). Singular matrices raise ``LinAlgError``."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.linalg as sla

__all__ = ["Dense", "Factor", "IdentityPlusLowRank", "factored", "bordered"]


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


@dataclass(frozen=True)
class Factor:
    """A factor F (n, r) of a low-rank product, by its action on matrices (2-D only; :class:`IdentityPlusLowRank`
    takes vectors): ``times(Y) = F Y`` for Y (r, k) and ``t_times(X) = F^T X`` for X (n, k). An array is one
    (:meth:`of`); so are factors never formed (:class:`rotorred.nonlinear.sampled.SampledFactors`). Not scipy's
    ``LinearOperator``: its checks on every product cost half of a Woodbury solve here (0.11 of 0.23 ms at the rig's
    H = 100)."""

    shape: tuple
    times: Callable[[np.ndarray], np.ndarray]
    t_times: Callable[[np.ndarray], np.ndarray]

    @staticmethod
    def of(A) -> Factor:
        """``A`` as a factor (an array, or a factor as it is)."""
        return A if isinstance(A, Factor) else Factor(A.shape, A.__matmul__, A.T.__matmul__)

    def after(self, apply: Callable, apply_t: Callable) -> Factor:
        """The factor ``G F`` for G given by its action ``apply(X) = G X`` and ``apply_t(X) = G^T X``."""
        return Factor(self.shape, lambda Y: apply(self.times(Y)), lambda X: self.t_times(apply_t(X)))

    def dense(self) -> np.ndarray:
        """F as an array, shape (n, r)."""
        return self.times(np.eye(self.shape[1]))


class IdentityPlusLowRank:
    """``A = I + P Q^T``, P and Q of shape (n, r), solved by the Woodbury identity
    ``A^-1 = I - P (I + Q^T P)^-1 Q^T`` (and its transpose) with the small matrix factored once.

    P and Q are arrays or :class:`Factor` s (never formed); ``QtP``, the small ``Q^T P``, is then given. Acts as the
    matrix where one is needed: ``A @ x``, ``np.asarray(A)``.
    """

    def __init__(self, P, Q, QtP: np.ndarray | None = None):
        self.P, self.Q = Factor.of(P), Factor.of(Q)
        n = P.shape[0]
        self.shape = (n, n)
        self.QtP = self.Q.dense().T @ self.P.dense() if QtP is None else QtP  # (r, r)
        self._small = None  # the LU factors of I + Q^T P, at the first solve

    @property
    def rank(self) -> int:
        return self.P.shape[1]

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        return x + self.P.times(self.Q.t_times(_matrix(x))).reshape(x.shape)

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return (np.eye(self.shape[0]) + self.P.dense() @ self.Q.dense().T).astype(dtype or float)

    def solve(self, b: np.ndarray, trans: bool = False) -> np.ndarray:
        if self.rank == 0:
            return np.array(b, float)
        if self._small is None:
            self._small = _lu(np.eye(self.rank) + self.QtP)
        left, right = (self.Q, self.P) if trans else (self.P, self.Q)
        y = sla.lu_solve(self._small, right.t_times(_matrix(b)), trans=1 if trans else 0, check_finite=False)
        return b - left.times(y).reshape(b.shape)

    def bordered(self, column: np.ndarray, row: np.ndarray) -> IdentityPlusLowRank:
        """The (n + 1) matrix ``[[A, c], [row[:-1]^T, row[-1]]]`` for ``column`` c (n,) and ``row`` (n + 1,): the
        identity plus ``[[P, c, 0], [0, 0, 1]] [[Q, 0, row[:-1]], [0, 1, row[-1] - 1]]^T`` (rank r + 2), its small
        matrix by blocks from this one's (:func:`_augmented`)."""
        n = self.shape[0]
        W_P, w_P = np.column_stack([column, np.zeros(n)]), np.array([0.0, 1.0])
        W_Q, w_Q = np.column_stack([np.zeros(n), row[:-1]]), np.array([1.0, row[-1] - 1.0])
        QtP = np.block([[self.QtP, self.Q.t_times(W_P)], [self.P.t_times(W_Q).T, W_Q.T @ W_P + np.outer(w_Q, w_P)]])
        return IdentityPlusLowRank(_augmented(self.P, W_P, w_P), _augmented(self.Q, W_Q, w_Q), QtP)


def _augmented(X: Factor, W: np.ndarray, w: np.ndarray) -> Factor:
    """The factor ``[[X, W], [0, w]]``, shape (n + 1, r + 2), of X (n, r), two columns W (n, 2) and a last row w (2,):
    a factor of a bordered matrix."""
    n, r = X.shape

    def times(Y):
        return np.vstack([X.times(Y[:r]) + W @ Y[r:], w @ Y[r:]])

    def t_times(Z):
        return np.vstack([X.t_times(Z[:n]), W.T @ Z[:n] + np.outer(w, Z[n])])
    return Factor((n + 1, r + 2), times, t_times)


def _matrix(x: np.ndarray) -> np.ndarray:
    """A vector as a one-column matrix (a matrix as it is)."""
    return x[:, None] if x.ndim == 1 else x


def factored(A) -> Dense | IdentityPlusLowRank:
    """``A`` ready to solve with: an :class:`IdentityPlusLowRank` as it is, a dense matrix LU-factored."""
    return A if isinstance(A, IdentityPlusLowRank) else Dense(np.asarray(A))


def bordered(A, column: np.ndarray, row: np.ndarray) -> Dense | IdentityPlusLowRank:
    """The bordered matrix ``[[A, column], [row]]`` (``row`` of length n + 1), ready to solve with."""
    if isinstance(A, IdentityPlusLowRank):
        return A.bordered(column, row)
    return Dense(np.vstack([np.column_stack([A, column]), row]))
