"""Linear solves with harmonic-balance Jacobians: a dense LU, or the identity plus a low-rank product (Woodbury).

A contact acts on a small part of the period. At the AFT samples out of contact its force's derivatives are zero,
and in contact a rub's derivative is rank one (the force is ``P(delta, delta')`` along a fixed direction), so the
Jacobian of the force coefficients is a sum of few outer products, ``U V^T`` with one column a contact sample. The
condensed Jacobian ``I + G U V^T`` (:mod:`rotorred.nonlinear.condensed`) is then solved through the Woodbury
identity, with an LU of the small ``I + V^T G U`` (r x r, r the contact samples) in place of the size^3 one: at the
rig's H = 100, N = 2048, r is 90-160 against a size of 804. Both forms solve the bordered systems of the
continuation ``[[A, r], [t^T, tau]]`` (a rank-two update more). Singular matrices raise ``LinAlgError``.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla

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

    Acts as the matrix where one is needed: ``A @ x``, ``np.asarray(A)``.
    """

    def __init__(self, P: np.ndarray, Q: np.ndarray, QtP: np.ndarray | None = None):
        self.P, self.Q = P, Q
        n = P.shape[0]
        self.shape = (n, n)
        self.QtP = Q.T @ P if QtP is None else QtP  # (r, r)
        self._small = None  # the LU factors of I + Q^T P, at the first solve

    @property
    def rank(self) -> int:
        return self.P.shape[1]

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        return x + self.P @ (self.Q.T @ x)

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return (np.eye(self.shape[0]) + self.P @ self.Q.T).astype(dtype or float)

    def solve(self, b: np.ndarray, trans: bool = False) -> np.ndarray:
        if self.rank == 0:
            return np.array(b, float)
        if self._small is None:
            self._small = _lu(np.eye(self.rank) + self.QtP)
        left, right = (self.Q, self.P) if trans else (self.P, self.Q)
        return b - left @ sla.lu_solve(self._small, right.T @ b, trans=1 if trans else 0, check_finite=False)

    def bordered(self, column: np.ndarray, row: np.ndarray) -> IdentityPlusLowRank:
        """The (n + 1) matrix ``[[A, c], [row[:-1]^T, row[-1]]]`` for ``column`` c (n,) and ``row`` (n + 1,): the
        identity plus ``[[P, c, 0], [0, 0, 1]] [[Q, 0, row[:-1]], [0, 1, row[-1] - 1]]^T`` (rank r + 2)."""
        n, r = self.P.shape
        P = np.zeros((n + 1, r + 2))
        Q = np.zeros((n + 1, r + 2))
        P[:n, :r], P[:n, r], P[n, r + 1] = self.P, column, 1.0
        Q[:n, :r], Q[n, r], Q[:n, r + 1], Q[n, r + 1] = self.Q, 1.0, row[:-1], row[-1] - 1.0
        QtP = np.zeros((r + 2, r + 2))  # Q^T P by blocks, from this one's (O(n r), not O(n r^2))
        QtP[:r, :r], QtP[:r, r] = self.QtP, self.Q.T @ column
        QtP[r, r + 1] = 1.0
        QtP[r + 1, :r], QtP[r + 1, r], QtP[r + 1, r + 1] = row[:-1] @ self.P, row[:-1] @ column, row[-1] - 1.0
        return IdentityPlusLowRank(P, Q, QtP)


def factored(A) -> Dense | IdentityPlusLowRank:
    """``A`` ready to solve with: an :class:`IdentityPlusLowRank` as it is, a dense matrix LU-factored."""
    return A if isinstance(A, IdentityPlusLowRank) else Dense(np.asarray(A))


def bordered(A, column: np.ndarray, row: np.ndarray) -> Dense | IdentityPlusLowRank:
    """The bordered matrix ``[[A, column], [row]]`` (``row`` of length n + 1), ready to solve with."""
    if isinstance(A, IdentityPlusLowRank):
        return A.bordered(column, row)
    return Dense(np.vstack([np.column_stack([A, column]), row]))
