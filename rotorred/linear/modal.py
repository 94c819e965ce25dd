"""Complex eigen-analysis of M q'' + D q' + K q = 0 in first-order (state-space) form.

Shared by the Campbell analysis and the reduced-vs-full checks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla


@dataclass(frozen=True)
class EigenSolution:
    """Eigenvalues with positive imaginary part (one of each conjugate pair), sorted by frequency.

    Attributes
    ----------
    eigenvalues : ndarray, shape (k,), complex
        lambda = -zeta w_n + i w_d (1/s).
    modes : ndarray, shape (n, k), complex
        Displacement part of each eigenvector, unit 2-norm.
    """

    eigenvalues: np.ndarray
    modes: np.ndarray

    @property
    def frequencies(self) -> np.ndarray:
        """Damped natural frequencies Im(lambda) (rad/s), shape (k,)."""
        return self.eigenvalues.imag

    @property
    def log_dec(self) -> np.ndarray:
        """Logarithmic decrement -2 pi Re(lambda) / Im(lambda) (-), shape (k,)."""
        return -2.0 * np.pi * self.eigenvalues.real / self.eigenvalues.imag


def state_matrix(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> np.ndarray:
    """First-order system matrix [[0, I], [-M^-1 K, -M^-1 D]], shape (2n, 2n)."""
    n = M.shape[0]
    lu = sla.lu_factor(M)
    return np.block([[np.zeros((n, n)), np.eye(n)], [-sla.lu_solve(lu, K), -sla.lu_solve(lu, D)]])


#: eigenvalues with a damping ratio -Re(lambda)/|lambda| at or above this are not whirl modes: an
#: overdamped pair (mass-proportional Rayleigh damping makes the rig's lowest shaft modes so) splits by
#: round-off into a complex pair of tiny imaginary part that would read as a mode at ~0 Hz
WHIRL_MAX_DAMPING_RATIO = 0.99


def eigen(M: np.ndarray, D: np.ndarray, K: np.ndarray, n_modes: int | None = None,
          min_frequency: float = 1e-6, max_damping_ratio: float | None = None) -> EigenSolution:
    """Eigenvalues and mode shapes of M q'' + D q' + K q = 0.

    Parameters
    ----------
    M, D, K : ndarray, shape (n, n)
        Mass, total velocity (damping plus gyroscopic) and stiffness matrices.
    n_modes : int, optional
        Keep the lowest ``n_modes`` frequencies (default all).
    min_frequency : float
        Eigenvalues with Im(lambda) below this (rad/s) are dropped (real, overdamped or rigid-body).
    max_damping_ratio : float, optional
        Also drop eigenvalues with a damping ratio at or above this (e.g. :data:`WHIRL_MAX_DAMPING_RATIO`).

    Returns
    -------
    EigenSolution
    """
    n = M.shape[0]
    lam, vec = sla.eig(state_matrix(M, D, K))
    keep = lam.imag > min_frequency
    if max_damping_ratio is not None:
        keep &= -lam.real < max_damping_ratio * np.abs(lam)
    lam, vec = lam[keep], vec[:n, keep]
    order = np.argsort(lam.imag, kind="stable")
    if n_modes is not None:
        order = order[:n_modes]
    lam, vec = lam[order], vec[:, order]
    vec = vec / np.linalg.norm(vec, axis=0)
    return EigenSolution(eigenvalues=lam, modes=vec)


def mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion between the columns of ``a`` (n, p) and ``b`` (n, q), shape (p, q)."""
    num = np.abs(a.conj().T @ b) ** 2
    den = np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0))
    return num / den
