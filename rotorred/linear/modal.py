"""Complex eigen-analysis of M q'' + D q' + K q = 0 in first-order (state-space) form.

Shared by the Campbell analysis and the reduced-vs-full checks. A dense model is solved whole (LAPACK); a sparse
one (:mod:`rotorred.model.sparse`) for its lowest modes only, by shift-invert Arnoldi (ARPACK) on the state-space
pencil with one sparse LU of the n x n quadratic matrix per solve (:func:`_sparse_eigen`, docs/model.md §24).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rotorred.model import sparse


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


#: a sparse eigen-solution finds every mode below the frequency asked for whose damping ratio is below this: it
#: solves until the eigenvalues found fill a disc about the shift of radius (highest frequency asked for) /
#: sqrt(1 - this^2) (docs/model.md §24); a mode more damped than this, below that frequency, may be missed
SPARSE_COMPLETE_DAMPING_RATIO = 0.6
#: the sparse solve's shift is -this x the softest DOF's own frequency (:func:`_softest`): far below the whirl
#: frequencies, whose disc about the shift it barely widens, and far enough from the rigid-body eigenvalues at 0
#: to keep K + sigma D + sigma^2 M regular
_SHIFT = 1e-4
#: a sparse model is solved dense (whole) when it asks for more than this share of its 2n eigenvalues
_SPARSE_MAX_SHARE = 0.25


def eigen(M: np.ndarray, D: np.ndarray, K: np.ndarray, n_modes: int | None = None,
          min_frequency: float = 1e-6, max_damping_ratio: float | None = None,
          below: float | None = None) -> EigenSolution:
    """Eigenvalues and mode shapes of M q'' + D q' + K q = 0.

    Parameters
    ----------
    M, D, K : ndarray or sparse matrix, shape (n, n)
        Mass, total velocity (damping plus gyroscopic) and stiffness matrices; sparse ones (all three) are solved for
        the lowest modes only (``n_modes`` or ``below`` given): shift-invert (docs/model.md §24).
    n_modes : int, optional
        Keep the lowest ``n_modes`` frequencies (default all).
    min_frequency : float
        Eigenvalues with Im(lambda) below this (rad/s) are dropped (real, overdamped or rigid-body).
    max_damping_ratio : float, optional
        Also drop eigenvalues with a damping ratio at or above this (e.g. :data:`WHIRL_MAX_DAMPING_RATIO`).
    below : float, optional
        With sparse matrices: at least every mode with Im(lambda) below this (rad/s), and the lowest ``n_modes``
        (more may come). Ignored for dense ones (all modes).

    Returns
    -------
    EigenSolution
    """
    n = M.shape[0]
    if sparse.is_sparse(M):
        if n_modes is not None or below is not None:
            solution = _sparse_eigen(M, D, K, (n_modes or 0, below or 0.0), min_frequency, max_damping_ratio)
            if solution is not None:
                return solution
        M, D, K = sparse.dense(M), sparse.dense(D), sparse.dense(K)
    lam, vec = sla.eig(state_matrix(M, D, K))
    keep = lam.imag > min_frequency
    if max_damping_ratio is not None:
        keep &= -lam.real < max_damping_ratio * np.abs(lam)
    lam, vec = lam[keep], vec[:n, keep]
    order = np.argsort(lam.imag, kind="stable")
    if n_modes is not None and below is None:
        order = order[:n_modes]
    lam, vec = lam[order], vec[:, order]
    vec = vec / np.linalg.norm(vec, axis=0)
    return EigenSolution(eigenvalues=lam, modes=vec)


def _sparse_eigen(M, D, K, wanted: tuple[int, float], min_frequency: float,
                  max_damping_ratio: float | None) -> EigenSolution | None:
    """The lowest modes of a sparse model by shift-invert Arnoldi, or None where a dense solve is due (too many
    modes asked for).

    The pencil A z = lambda B z, A = [[0, I], [-K, -D]], B = [[I, 0], [0, M]], z = [q; lambda q], is solved for the
    eigenvalues nearest the shift sigma: ARPACK iterates OP = (A - sigma B)^-1 B, whose eigenvalues are
    1 / (lambda - sigma); each product solves (K + sigma D + sigma^2 M) x = -(M y_2 + (D + sigma M) y_1) with one sparse
    LU per call (real: sigma is real, a little below zero, so a free spool's singular K is factorised). The number of
    eigenvalues k is doubled until the modes wanted, ``wanted`` = (the lowest n, every one below a frequency w), are
    certified: every eigenvalue within the radius R = max |lambda - sigma| found is found, so every mode of damping
    ratio below :data:`SPARSE_COMPLETE_DAMPING_RATIO` with Im(lambda) <= (R - |sigma|) sqrt(1 - zeta^2) is.
    """
    n_wanted, w_wanted = wanted
    n = M.shape[0]
    Mc, Dc, Kc = (sp.csc_array(X) for X in (M, D, K))
    sigma = -_SHIFT * _softest(Kc, Mc)  # a little below zero: away from the rigid-body eigenvalues lambda = 0
    lu = spla.splu((Kc + sigma * Dc + sigma * sigma * Mc).tocsc(), permc_spec="MMD_AT_PLUS_A")
    DsM = (Dc + sigma * Mc).tocsr()

    def op(y):
        y1, y2 = y[:n], y[n:]
        x1 = lu.solve(-(Mc @ y2 + DsM @ y1))
        return np.concatenate([x1, y1 + sigma * x1])

    dtype = np.result_type(Mc.dtype, Dc.dtype, Kc.dtype, float)
    operator = spla.LinearOperator((2 * n, 2 * n), matvec=op, dtype=dtype)
    cover = 1.0 / np.sqrt(1.0 - SPARSE_COMPLETE_DAMPING_RATIO ** 2)
    start = np.random.default_rng(0).standard_normal(2 * n)  # ARPACK's own start is random: results would vary
    k = 2 * n_wanted + 12
    while True:
        if k > _SPARSE_MAX_SHARE * 2 * n:
            return None
        try:
            mu, vec = spla.eigs(operator, k=k, which="LM", tol=0.0, v0=start)
        except spla.ArpackNoConvergence:  # at round-off (tol=0) on a small model: solved dense
            return None
        lam = sigma + 1.0 / mu
        radius = float(np.max(np.abs(lam - sigma)))
        keep = lam.imag > min_frequency
        if max_damping_ratio is not None:
            keep &= -lam.real < max_damping_ratio * np.abs(lam)
        order = np.flatnonzero(keep)[np.argsort(lam.imag[keep], kind="stable")]
        # the highest frequency to certify: the n-th lowest found (not yet found: go on), and w
        top = max(w_wanted, 0.0 if n_wanted == 0 else lam.imag[order[n_wanted - 1]] if n_wanted <= len(order)
                  else np.inf)
        if cover * top + abs(sigma) <= radius:
            break
        k *= 2
    if n_wanted:
        order = order[:max(n_wanted, int(np.sum(lam.imag[order] < w_wanted)))]
    vec = vec[:n, order]
    return EigenSolution(eigenvalues=_rayleigh_quotients(lam[order], vec, (Mc, Dc, Kc)),
                         modes=vec / np.linalg.norm(vec, axis=0))


def _softest(K, M) -> float:
    """sqrt of the smallest positive ratio of K's and M's diagonal entries (rad/s): the frequency of the softest
    DOF alone, a scale of the model's low frequencies (the largest ratio is the stiffest bearing's), 1 if none."""
    ratio = np.abs(K.diagonal()) / np.maximum(M.diagonal(), 1e-300)
    ratio = ratio[ratio > 0]
    return float(np.sqrt(ratio.min())) if len(ratio) else 1.0


def _rayleigh_quotients(lam: np.ndarray, vec: np.ndarray, matrices) -> np.ndarray:
    """Each eigenvalue polished as the root nearest it of v^H (lambda^2 M + lambda D + K) v = 0 (the quadratic
    Rayleigh quotient of its vector v): an Arnoldi eigenvalue of the linearised pencil carries the pencil's scaling
    (displacements against velocities), the quotient only v's error, squared for the undamped part (measured on the
    seed rig refined(16): 2e-8 relative error down to 1.4e-9 against a Newton-converged eigenvalue)."""
    M, D, K = matrices
    out = lam.copy()
    for j, v in enumerate(vec.T):
        roots = np.roots([np.vdot(v, M @ v), np.vdot(v, D @ v), np.vdot(v, K @ v)])
        out[j] = roots[np.argmin(np.abs(roots - lam[j]))]
    return out


def mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion between the columns of ``a`` (n, p) and ``b`` (n, q), shape (p, q)."""
    num = np.abs(a.conj().T @ b) ** 2
    den = np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0))
    return num / den
