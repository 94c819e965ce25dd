"""Newton's step on a torus without its Jacobian: GMRES on the contact's rank, preconditioned on the orders of largest
compliance (docs/model.md §25).

The condensed torus Jacobian (:class:`rotorred.nonlinear.torus.TorusProblem`) is ``J = I + G sum_t T_t (x) A_t``: G the
dynamic compliance of the unknown DOFs, block diagonal over the orders, and ``T_t`` the multiplication by a sampled
force derivative ``d_t(theta)`` (times the derivative ``w . nabla`` for a velocity derivative), acting on the DOF
pattern ``A_t``. The patterns span few directions: ``A_t = U B_t V^T`` with U (c, r) and V (c, s) orthonormal (a rub:
r = s = 1, the force along one direction, driven by the penetration along one). With ``X = G (I (x) U)`` and
``Y = C (I (x) V^T)``, ``C = sum_t T_t (x) B_t``, Woodbury's identity gives Newton's step

    -J^-1 R = -R + X y,   (I + C G_VU) y = C (R V),   G_VU = (I (x) V^T) G (I (x) U),

an equation in the coefficients of r signals on the torus. ``C`` is never formed: its product with p, the
coefficients of s signals, is their samples and rates on the grid by one inverse real 2-D FFT, multiplied there by
the fields ``Mq(theta) = sum d_t B_t`` (position terms) and ``Mv(theta)`` (velocity terms), r x s at each sample, and
returned by one forward FFT: O(N_1 N_2 log(N_1 N_2) (r + 2 s)) a product, memory O(N_1 N_2 r s + K (r + s)^2).
GMRES preconditioned on the right (:func:`right_gmres`) solves it; the preconditioner is the inverse of its block
between the orders of largest compliance (:data:`COARSE_ORDERS`: the orders where ``C G_VU`` is large, whose
eigenvalues would otherwise be GMRES's outliers) and the identity elsewhere; the block is the fields' Toeplitz
matrices between those orders only (built from their 2-D spectrum), factorised once (LU, single precision) and
reused by the following Newton steps until GMRES needs more than :data:`REFRESH_ITERATIONS`. *Choice*
(docs/model.md §25): the block diagonal over the orders (each order's 2 x 2 block with the contact's mean stiffness)
stalls on the rig: its impacts couple the orders far from the diagonal
(at |k1| <= 6, |k2| <= 30, GMRES stalled at 4.5e-2 after 2000 iterations, against 4.5e-5 after 43 without a
preconditioner).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numba import njit

from rotorred.nonlinear.torus_toeplitz import pair_block, pair_positions
from rotorred.transient import numba_cache

numba_cache.register()

__all__ = ["RankJacobian", "pattern_bases"]

#: singular values of the stacked DOF patterns below this share of the largest count as zero (their rank)
RANK_RTOL = 1e-12
#: the orders of largest compliance whose block of the reduced equation the preconditioner inverts exactly
COARSE_ORDERS = 1000
#: the largest coarse block factorised in double precision (a larger one in single)
DOUBLE_BLOCK = 1024
#: GMRES iterations past which a reused preconditioner is built afresh from the current fields
REFRESH_ITERATIONS = 60


def pattern_bases(patterns: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal bases U (c, r) of the patterns' column spaces and V (c, s) of their row spaces."""
    def basis(stack):
        u, sv, _ = np.linalg.svd(stack, full_matrices=False)
        return u[:, sv > RANK_RTOL * sv[0]]
    return basis(np.hstack(patterns)), basis(np.hstack([A.T for A in patterns]))


def projected_blocks(G0: np.ndarray, Gk: np.ndarray, V: np.ndarray, U: np.ndarray):
    """``V^T G0 U`` and ``(I_2 (x) V^T) Gk[k] (I_2 (x) U)`` of every order: shapes (s, r) and (K - 1, 2s, 2r)."""
    V2, U2 = np.kron(np.eye(2), V), np.kron(np.eye(2), U)
    return V.T @ G0 @ U, V2.T @ Gk @ U2


@dataclass
class KrylovStats:
    """What a Krylov solve took: GMRES iterations and the true relative residual of the reduced equation."""

    iterations: int
    residual: float


class RankJacobian:
    """The torus Jacobian at a point, held by its sampled fields on the contact's rank (module docstring).

    Parameters
    ----------
    harmonics : TorusHarmonics
        The orders and grid.
    w : (float, float)
        The base frequencies (rad/s).
    G : (ndarray (c, c), ndarray (K - 1, 2c, 2c))
        The compliance blocks of the unknowns (m/N): order 0 and each other order's real form.
    columns : ndarray, shape (N_1 N_2, b)
        The distinct sampled derivative shapes d_b(theta) (N/m or N s/m).
    terms : sequence of (int, int, ndarray (c, c))
        ``(b, kind, A)``: shape b times the DOF pattern A, of a position (kind 0) or a velocity (kind 1) derivative.
    reuse : RankJacobian, optional
        An earlier Jacobian of the same problem whose preconditioner (built from its own fields) serves this one, if
        its patterns span the same directions (:meth:`solve` builds a fresh one where it serves badly).
    """

    def __init__(self, harmonics, w, G, columns: np.ndarray, terms, reuse: RankJacobian | None = None):
        self.h, self.w = harmonics, tuple(w)
        self.G0, self.Gk = G
        self.c = self.G0.shape[0]
        self.U, self.V = pattern_bases([A for _, _, A in terms])
        self.r, self.s = self.U.shape[1], self.V.shape[1]
        self.Mq, self.Mv = self._fields(columns, terms)
        self.has_velocity = bool(np.any(self.Mv))
        self.P0, self.Pk = projected_blocks(self.G0, self.Gk, self.V, self.U)
        same = reuse is not None and reuse.U.shape == self.U.shape and reuse.V.shape == self.V.shape and \
            np.allclose(np.abs(reuse.U.T @ self.U), np.eye(self.r)) and \
            np.allclose(np.abs(reuse.V.T @ self.V), np.eye(self.s))
        self._preconditioner = reuse._preconditioner if same else None
        if same:  # the bases' signs may differ: the reused factors act in the earlier bases
            self.U, self.V = reuse.U, reuse.V
            self.Mq, self.Mv = self._fields(columns, terms)
            self.P0, self.Pk = reuse.P0, reuse.Pk
        self.reused = same

    def _fields(self, columns: np.ndarray, terms) -> tuple[np.ndarray, np.ndarray]:
        """The fields ``Mq = sum d_t B_t`` (position terms) and ``Mv`` (velocity terms), ``B_t = U^T A_t V``, on the
        grid: shape (r, s, N_1 N_2) each, the samples contiguous (the layout of the FFT's signals)."""
        N = self.h.n_samples
        Mq, Mv = np.zeros((self.r, self.s, N)), np.zeros((self.r, self.s, N))
        for b, kind, A in terms:
            B = self.U.T @ A @ self.V
            (Mq if kind == 0 else Mv)[...] += B[:, :, None] * columns[None, None, :, b]
        return Mq, Mv

    @property
    def inner_size(self) -> int:
        """Unknowns of the reduced equation: (2K - 1) r."""
        return self.h.size * self.r

    # ------------------------------------------------------------------------------------------ products
    def core(self, p: np.ndarray) -> np.ndarray:
        """``C p``: the coefficients (m, r) of ``Mq p(theta) + Mv (w . nabla) p(theta)`` for the coefficients
        ``p`` (m, s) of s signals, through the grid."""
        h, s = self.h, self.s
        Q = _phasors(p)
        if not self.has_velocity:
            return h.grid_product(Q, lambda x, out: _field_product(self.Mq, x, out), self.r)
        both = np.empty((len(Q), 2 * s), complex)
        both[:, :s] = Q
        np.multiply(Q, 1j * h.frequencies(self.w)[:, None], out=both[:, s:])  # (w . nabla): the phasor times i k . w

        def product(x, out):
            _field_product(self.Mq, x[:s], out)
            out += _field_product(self.Mv, x[s:])
        return h.grid_product(both, product, self.r)

    def compliance(self, y: np.ndarray) -> np.ndarray:
        """``G_VU y`` for y (m, r): (m, s)."""
        return block_product(self.P0, self.Pk, y.reshape(-1, 1), self.r).reshape(-1, self.s)

    def inner(self, y: np.ndarray) -> np.ndarray:
        """``(I + C G_VU) y`` for y of shape ((2K - 1) r,)."""
        y = y.reshape(-1, self.r)
        return (y + self.core(self.compliance(y))).reshape(-1)

    def times(self, v: np.ndarray) -> np.ndarray:
        """``J v`` for v of shape ((2K - 1) c,): ``v + G (I (x) U) C (I (x) V^T) v``."""
        Cv = self.core(v.reshape(-1, self.c) @ self.V)
        return v + block_product(self.G0, self.Gk, (Cv @ self.U.T).reshape(-1, 1), self.c).reshape(-1)

    # ------------------------------------------------------------------------------------------ preconditioner
    def _coarse_block(self):
        """The orders where the compliance is largest (:data:`COARSE_ORDERS` of them, the mean among them): their
        positions in the reduced vector and the LU factors of the reduced equation's dense block between them,
        ``I + C_LL G_VU,L`` (C_LL the fields' Toeplitz matrices between those orders, from their 2-D spectra), written
        by one compiled pass (:func:`_compliant_block`) in the factors' precision."""
        h, r, s = self.h, self.r, self.s
        weight = np.concatenate([[np.linalg.norm(self.P0)], np.linalg.norm(self.Pk, axis=(1, 2))])
        among = np.union1d([0], np.argsort(-weight)[:COARSE_ORDERS])
        n = (2 * len(among) - 1) * r
        spectra = [np.fft.fft2(M.reshape(r * s, h.N1, h.N2), axes=(1, 2)).reshape(r * s, -1) / h.n_samples
                   for M in ((self.Mq, self.Mv) if self.has_velocity else (self.Mq,))]
        velocity = spectra[1] if self.has_velocity else np.zeros((0, 1), complex)
        orders = h.orders[among]
        # factorised once, in single precision (a preconditioner only shapes GMRES's spectrum: on the rig's 1999 x 1999
        # block the LU takes 1/7 of the double inverse's time and its solve 1/4 of that inverse's product, GMRES's
        # iterations unchanged, docs/model.md §25); in double for a small block (cheap either way, and where it is
        # the whole equation the step is then exact to round-off)
        transposed = np.empty((n, n), np.float64 if n <= DOUBLE_BLOCK else np.float32)
        _compliant_block(spectra[0], velocity, orders[:, 0].astype(np.int64), orders[:, 1].astype(np.int64), h.N1,
                         h.N2, h.frequencies(self.w)[among[1:]], self.P0, np.ascontiguousarray(self.Pk[among[1:] - 1]),
                         transposed)
        rows = np.concatenate([[0], np.column_stack([2 * among[1:] - 1, 2 * among[1:]]).ravel()])
        rows = (rows[:, None] * r + np.arange(r)[None]).ravel()
        return rows, sla.lu_factor(transposed.T, check_finite=False, overwrite_a=True)  # Fortran order: no copy

    def precondition(self, y: np.ndarray) -> np.ndarray:
        """An approximate inverse of ``I + C G_VU`` applied to y ((2K - 1) r,): exact on the block between the orders
        of largest compliance (:meth:`_coarse_block`), the identity elsewhere (where ``C G_VU`` is small)."""
        if self._preconditioner is None:
            self._preconditioner = self._coarse_block()
        rows, factors = self._preconditioner
        out = y.copy()
        out[rows] = sla.lu_solve(factors, y[rows].astype(factors[0].dtype), check_finite=False)
        return out

    # ------------------------------------------------------------------------------------------ the step
    def solve(self, b: np.ndarray, rtol: float, maxiter: int = 300, restart: int = 100,
              start: np.ndarray | None = None):
        """``J^-1 b`` by Woodbury's identity and GMRES on the reduced equation to the relative residual ``rtol``
        (:func:`right_gmres`), from the reduced solution ``start`` if given (a nearby system's :attr:`reduced`, in
        this Jacobian's bases); returns the solution and :class:`KrylovStats` (GMRES's iterations, the reduced
        residual reached), and keeps the reduced solution as :attr:`reduced`."""
        rhs = self.core(b.reshape(-1, self.c) @ self.V).reshape(-1)
        y, iterations, achieved = right_gmres(self.inner, self.precondition, rhs, start, rtol, restart, maxiter)
        if self.reused and (achieved > rtol or iterations > REFRESH_ITERATIONS):  # the earlier factors serve badly:
            self._preconditioner, self.reused = None, False  # fresh ones from the current fields
            y, more, achieved = right_gmres(self.inner, self.precondition, rhs, y, rtol, restart, maxiter)
            iterations += more
        if not np.all(np.isfinite(y)):
            raise sla.LinAlgError("GMRES gave a non-finite solution")
        self.reduced = y
        X_y = block_product(self.G0, self.Gk, (y.reshape(-1, self.r) @ self.U.T).reshape(-1, 1), self.c).reshape(-1)
        return b - X_y, KrylovStats(iterations, achieved)


def right_gmres(A, M, b: np.ndarray, x0: np.ndarray | None, rtol: float, restart: int, maxiter: int):
    """``A x = b`` by GMRES on ``A M u = b``, ``x = M u``: preconditioned on the right, so its residual is the true
    one's and it stops when ``||b - A x|| <= rtol ||b||`` (scipy's GMRES, preconditioned on the left, stops on the
    preconditioned residual: on the rig 5 to 20 times below the tolerance asked). Restarted every ``restart``
    iterations; Gram-Schmidt classical and done twice (two products with the basis an iteration).

    Parameters
    ----------
    A, M : callable
        ``v -> A v`` and ``v -> M v`` (M an approximate inverse of A) for v of shape (n,).
    b : ndarray, shape (n,)
        The right-hand side.
    x0 : ndarray, shape (n,), optional
        The start (default 0).
    rtol : float
        The relative residual to reach.
    restart, maxiter : int
        Iterations between restarts, and in all.

    Returns
    -------
    x : ndarray, shape (n,)
        In the units of ``b`` over those of A.
    iterations : int
        Products with A (besides the residuals at the restarts).
    residual : float
        ``||b - A x|| / ||b||`` reached.
    """
    norm = float(np.linalg.norm(b)) or 1.0
    n, target = b.size, rtol * norm
    x = np.zeros(n) if x0 is None else x0.copy()
    r = b - A(x) if x0 is not None else b.copy()
    beta, total = float(np.linalg.norm(r)), 0
    while beta > target and total < maxiter:
        m = min(restart, maxiter - total)
        V, Z, H = np.empty((m + 1, n)), np.empty((m, n)), np.zeros((m + 1, m))
        cs, sn, g = np.zeros(m), np.zeros(m), np.zeros(m + 1)
        V[0], g[0] = r / beta, beta
        for j in range(m):
            Z[j] = M(V[j])
            w = A(Z[j])
            h = V[:j + 1] @ w
            w -= h @ V[:j + 1]
            again = V[:j + 1] @ w
            w -= again @ V[:j + 1]
            H[:j + 1, j], H[j + 1, j] = h + again, np.linalg.norm(w)
            if H[j + 1, j] > 0.0:
                V[j + 1] = w / H[j + 1, j]
            for i in range(j):  # the earlier rotations on the new column
                H[i, j], H[i + 1, j] = cs[i] * H[i, j] + sn[i] * H[i + 1, j], -sn[i] * H[i, j] + cs[i] * H[i + 1, j]
            radius = math.hypot(H[j, j], H[j + 1, j])
            cs[j], sn[j] = (1.0, 0.0) if radius == 0.0 else (H[j, j] / radius, H[j + 1, j] / radius)
            H[j, j], H[j + 1, j] = radius, 0.0
            g[j], g[j + 1] = cs[j] * g[j], -sn[j] * g[j]
            total += 1
            if abs(g[j + 1]) <= target or H[j, j] == 0.0:
                break
        k = j + 1
        u = sla.solve_triangular(H[:k, :k], g[:k], check_finite=False)
        x += u @ Z[:k]
        r = b - A(x)
        beta = float(np.linalg.norm(r))
        if H[k - 1, k - 1] == 0.0:
            break
    return x, total, beta / norm


def _field_product(M: np.ndarray, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``M(theta) x(theta)`` at each sample: fields (r, s, N) times signals (s, N), shape (r, N) (into ``out``)."""
    if M.shape[:2] == (1, 1):
        return np.multiply(M[0], x, out=out)
    return np.einsum("rsn,sn->rn", M, x, out=out)


def _phasors(p: np.ndarray) -> np.ndarray:
    """Complex amplitudes (K, p) of harmonic-major coefficient rows (m, p)."""
    out = np.empty(((p.shape[0] + 1) // 2, p.shape[1]), complex)
    out[0] = p[0]
    out[1:] = p[1::2] - 1j * p[2::2]
    return out


def block_product(B0: np.ndarray, Bk: np.ndarray, X: np.ndarray, c: int) -> np.ndarray:
    """``B X`` for block-diagonal B: B0 (a, c) on the first c rows of X (m c, p), Bk[k] (2a, 2c) on each next 2c:
    shape (m a, p)."""
    a = B0.shape[0]
    out = np.empty((a + 2 * a * len(Bk), X.shape[1]))
    out[:a] = B0 @ X[:c]
    if Bk.shape[1:] == (2, 2):  # one signal (a rub's rank): the 2 x 2 products written out (matmul's are slow)
        x, y = X[1::2], X[2::2]
        out[1::2] = Bk[:, 0, 0, None] * x + Bk[:, 0, 1, None] * y
        out[2::2] = Bk[:, 1, 0, None] * x + Bk[:, 1, 1, None] * y
    else:
        out[a:] = np.matmul(Bk, X[c:].reshape(len(Bk), 2 * c, -1)).reshape(-1, X.shape[1])
    return out


@njit(cache=True)
def _compliant_block(Sq, Sv, k1, k2, N1, N2, wk, P0, Pk, out):  # pragma: no cover (compiled)
    """``out`` (n, n), n = (2L - 1) r, receives ``(I + C G)^T``: C the Toeplitz matrix (harmonic-major, real form)
    between the L orders ``(k1, k2)`` (the first (0, 0)) of the position field, spectrum ``Sq`` (r s, N_1 N_2) (the
    2-D DFT over N_1 N_2 samples, component rho s + sigma), plus the velocity field's (``Sv``, or no rows) times the
    derivative ``w . nabla`` on the right (``wk`` (L - 1,): each order's ``k . w``, rad/s); G the compliance blocks of
    those orders, ``P0`` (s, r) and ``Pk`` (L - 1, 2s, 2r). Row by row of ``out`` (a column order b at a time), so
    that ``out.T`` is the block in Fortran order. The Toeplitz entries of the orders a, b are
    :func:`rotorred.nonlinear.torus_toeplitz.pair_block`'s, the rule of the dense Jacobian's too."""
    rs, L = Sq.shape[0], k1.shape[0]
    r, s = P0.shape[1], P0.shape[0]
    n = (2 * L - 1) * r
    velocity = Sv.shape[0] > 0
    C = np.empty((n, 2 * s))  # the column order b's columns of C: (cos, sin) x s (the mean: s)
    for b in range(L):
        width = s if b == 0 else 2 * s
        C[:, :width] = 0.0
        for a in range(L):
            minus, plus = pair_positions(k1, k2, a, b, N1, N2)
            for c in range(rs):
                rho, sigma = c // s, c % s
                for field in range(2 if velocity else 1):
                    S = Sq if field == 0 else Sv
                    block = pair_block(S[c, minus], S[c, plus], a, b)
                    for i in range(1 if a == 0 else 2):  # the row order's cos (or mean), sin
                        row = (0 if a == 0 else 2 * a - 1 + i) * r + rho
                        if field == 0:
                            C[row, sigma] += block[i][0]
                            if b > 0:
                                C[row, s + sigma] += block[i][1]
                        elif b > 0:  # (w . nabla) on the right: cos_b <- -(k.w) sin_b's, sin_b <- (k.w) cos_b's
                            C[row, sigma] -= wk[b - 1] * block[i][1]
                            C[row, s + sigma] += wk[b - 1] * block[i][0]
        if b == 0:
            for j in range(r):
                for row in range(n):
                    acc = 0.0
                    for k in range(s):
                        acc += C[row, k] * P0[k, j]
                    out[j, row] = acc
                out[j, j] += 1.0
        else:
            for j in range(2 * r):
                col = (2 * b - 1) * r + j  # the block's cos_b comps, then sin_b's
                for row in range(n):
                    acc = 0.0
                    for k in range(2 * s):
                        acc += C[row, k] * Pk[b - 1, k, j]
                    out[col, row] = acc
                out[col, col] += 1.0
