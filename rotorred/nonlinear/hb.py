"""Harmonic balance of ``M q'' + D q' + K q + f(q, q') = F(t)`` for periodic responses of frequency ``omega``.

The unknowns are the harmonic-major Fourier coefficients ``z`` (:mod:`rotorred.nonlinear.fourier`). The
residual is

    R(z, omega) = L(omega) z + F_nl(z, omega) - F_ex(omega),
    L(omega) = I (x) K(omega) + omega^2 nabla^2 (x) M + omega nabla (x) D(omega),

with ``nabla`` the d/dtheta operator on one DOF's coefficients and ``(x)`` the Kronecker product; ``F_nl`` is
the AFT of the nonlinear forces (:mod:`rotorred.nonlinear.forces`). The Jacobian is analytic: the chain rule
through the AFT, ``dF_nl/dz = T(df/dq) + omega T(df/dv) (nabla (x) I)``, with ``T(d)`` the coefficient matrix
of multiplying by the sampled derivative ``d`` (:meth:`Harmonics.toeplitz`), and ``dR/domega`` likewise.
:func:`solve_periodic` is Newton's method with a backtracking line search; it returns a :class:`PeriodicSolution` (the
coefficients, their amplitudes per harmonic and DOF, and how Newton got there); a point that does not converge raises
:class:`NotConverged` with its residual and is never returned as a solution.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.linalg as sla

from rotorred import checks
from rotorred.model import sparse
from rotorred.nonlinear.fourier import Harmonics, to_phasors
from rotorred.nonlinear.lowrank import factored
from rotorred.results import Result

__all__ = ["PeriodicProblem", "PeriodicSolution", "Evaluation", "NotConverged", "solve_periodic", "coefficient_variables",
           "harmonic_dataset", "checked_matrices", "checked_unknowns",
           "sampled_forces", "force_coefficients", "transformed_forces", "local_forces"]


class NotConverged(RuntimeError):
    """Newton's method did not meet the tolerance: where, how far, after how many iterations."""

    def __init__(self, omega: float, residual: float, tol: float, iterations: int, why: str):
        self.omega, self.residual, self.tol, self.iterations = omega, residual, tol, iterations
        super().__init__(f"harmonic balance did not converge at omega = {omega:.9g} rad/s: relative residual "
                         f"{residual:.3g} > {tol:.3g} after {iterations} Newton iterations ({why})")


class Evaluation:
    """The residual at ``(z, omega)``, what it is relative to, and its derivatives, each computed on first use.

    A Newton iteration evaluates every trial point, and needs the derivatives only at the point it goes on
    from, and the one by the parameter only where a continuation asks: so an evaluator samples the forces once (values
    and derivatives come out of one call of the law) and hands over ``jacobian`` and ``parameter``, which build
    ``dR_dz`` and ``dR_domega`` from those samples when each is first read.

    Parameters
    ----------
    R : ndarray, shape (size,)
    scale : float
        ``||F_ex||`` (or ``||L z||`` without forcing): what the residual is relative to.
    jacobian : callable
        ``jacobian() -> dR_dz``, an ndarray or linear operator (size, size), called at most once.
    parameter : callable
        ``parameter() -> dR_domega``, shape (size,), called at most once.
    sampled : tuple, optional
        The forces and their derivatives at the AFT samples, ``(f, df/dq, df/dv)`` (N, m) and (N, m, m), where the
        evaluator keeps them (a family's parameter derivative reads them).
    """

    __slots__ = ("R", "scale", "sampled", "_jacobian", "_parameter")

    def __init__(self, R: np.ndarray, scale: float, jacobian: Callable, parameter: Callable,
                 sampled: tuple | None = None):
        self.R, self.scale, self.sampled = R, float(scale), sampled
        self._jacobian, self._parameter = [jacobian, None], [parameter, None]

    @staticmethod
    def _read(slot: list):
        if slot[0] is not None:
            slot[1], slot[0] = slot[0](), None
        return slot[1]

    @property
    def dR_dz(self):
        return self._read(self._jacobian)

    @property
    def dR_domega(self) -> np.ndarray:
        return self._read(self._parameter)

    def with_parameter(self, dR_dp: Callable[[], np.ndarray]) -> Evaluation:
        """This evaluation with the derivative by another parameter in place of ``dR_domega`` (``dR_dp()``, computed on
        first use too): a family of problems continued in a parameter other than omega."""
        return Evaluation(self.R, self.scale, lambda: self.dR_dz, dR_dp, self.sampled)

    @property
    def relative(self) -> float:
        return float(np.linalg.norm(self.R) / self.scale)


@dataclass(frozen=True)
class PeriodicProblem:
    """A forced system whose periodic response is sought by harmonic balance.

    Parameters
    ----------
    M, D, K : ndarray, shape (n, n)
        Mass, velocity (damping plus gyroscopic) and stiffness matrices (SI).
    harmonics : Harmonics
    forcing : callable
        ``forcing(omega) -> (F, dF_domega)``: the harmonic-major coefficients of the external force, shape
        ((2H + 1) n,), and their derivative with respect to omega.
    forces : tuple
        Nonlinear forces (:mod:`rotorred.nonlinear.forces`).
    D1 : ndarray, shape (n, n), optional
        A velocity matrix proportional to omega, ``D(omega) = D + omega D1`` (a gyroscopic matrix per unit speed
        when the spin follows omega, as in a synchronous unbalance response).
    K1 : ndarray, shape (n, n), optional
        A stiffness proportional to omega, ``K(omega) = K + omega K1`` (N/m per rad/s): the circulatory stiffness
        of internal damping per unit speed, ``-sum_s a_s N_s``, when the spin follows omega (docs/model.md §19).
    """

    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    harmonics: Harmonics
    forcing: Callable[[float], tuple[np.ndarray, np.ndarray]]
    forces: tuple = ()
    D1: np.ndarray | None = None
    K1: np.ndarray | None = None
    _ops: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        n = checked_matrices(self)
        for i, force in enumerate(self.forces):
            for d in force.dofs:
                if d >= n:
                    checks.fail(f"forces[{i}].dofs", force.dofs, f"must be DOFs of the system (0-{n - 1})")
        h = self.harmonics
        eye_h, nabla = np.eye(h.size), h.nabla
        self._ops.update(IK=np.kron(eye_h, self.K), N2M=np.kron(nabla @ nabla, self.M), NM=np.kron(nabla, self.M), ND=np.kron(nabla, self.D),
                         ND1=None if self.D1 is None else np.kron(nabla, self.D1),
                         IK1=None if self.K1 is None else np.kron(eye_h, self.K1))

    @property
    def n(self) -> int:
        """DOFs of the system."""
        return self.M.shape[0]

    @property
    def size(self) -> int:
        """Unknowns: (2 H + 1) n."""
        return self.harmonics.size * self.n

    def linear(self, omega: float) -> tuple[np.ndarray, np.ndarray]:
        """``L(omega) = I (x) K(omega) + omega^2 nabla^2 (x) M + omega nabla (x) D(omega)`` and ``dL/domega``.

        Parameters
        ----------
        omega : float
            Response frequency (rad/s).

        Returns
        -------
        L, dL_domega : ndarray, shape (size, size)
            (N/m) and (N s/m).
        """
        o = self._ops
        L = o["IK"] + omega**2 * o["N2M"] + omega * o["ND"]
        dL = 2.0 * omega * o["N2M"] + o["ND"]
        if o["ND1"] is not None:
            L = L + omega**2 * o["ND1"]
            dL = dL + 2.0 * omega * o["ND1"]
        if o["IK1"] is not None:
            L = L + omega * o["IK1"]
            dL = dL + o["IK1"]
        return L, dL

    def linear_response(self, omega: float) -> np.ndarray:
        """The coefficients of the response without the nonlinear forces, ``L(omega)^-1 F_ex(omega)``.

        Parameters
        ----------
        omega : float
            Response frequency (rad/s).

        Returns
        -------
        ndarray, shape (size,)
            Harmonic-major coefficients (m; rad for a rotation DOF): a start for :func:`solve_periodic`.
        """
        return sla.solve(self.linear(omega)[0], self.forcing(omega)[0])

    def samples(self, z: np.ndarray, omega: float) -> tuple[np.ndarray, np.ndarray]:
        """Displacements and velocities at the AFT instants (:meth:`Harmonics.motion`).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        omega : float
            Response frequency (rad/s).

        Returns
        -------
        q, v : ndarray, shape (N, n)
            (m) and (m/s).
        """
        h = self.harmonics
        return h.motion(z, self.n, omega)

    def nonlinear(self, z: np.ndarray, omega: float):
        """The nonlinear force's coefficients and the Toeplitz matrices of its derivatives, T(df/dq) and
        T(df/dv) (:meth:`Harmonics.toeplitz`).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        omega : float
            Response frequency (rad/s).

        Returns
        -------
        F_nl : ndarray, shape (size,)
            Coefficients of the nonlinear forces (N).
        Tq, Tv : ndarray, shape (size, size)
            T(df/dq) (N/m) and T(df/dv) (N s/m).
        """
        q, v = self.samples(z, omega)
        return transformed_forces(self.harmonics, self.force_columns, q, v)

    @property
    def dofs(self) -> tuple[int, ...]:
        """The DOFs of the unknowns: all of them."""
        return tuple(range(self.n))

    @property
    def force_columns(self) -> list:
        """Each nonlinear force with the columns of its DOFs among the unknowns."""
        return [(force, list(force.dofs)) for force in self.forces]

    def velocity_matrix(self, omega: float) -> np.ndarray:
        """D(omega) = D + omega D1 (N s/m).

        Parameters
        ----------
        omega : float
            Response frequency (rad/s).

        Returns
        -------
        ndarray, shape (n, n)
        """
        return self.D if self.D1 is None else self.D + omega * self.D1

    def stiffness_matrix(self, omega: float) -> np.ndarray:
        """K(omega) = K + omega K1 (N/m).

        Parameters
        ----------
        omega : float
            Response frequency (rad/s).

        Returns
        -------
        ndarray, shape (n, n)
        """
        return self.K if self.K1 is None else self.K + omega * self.K1

    def evaluate(self, z: np.ndarray, omega: float) -> Evaluation:
        """The residual ``R(z, omega) = L(omega) z + F_nl(z, omega) - F_ex(omega)`` (N), and its analytic derivatives on
        first use.

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        omega : float
            Response frequency (rad/s).

        Returns
        -------
        Evaluation
        """
        L, dL = self.linear(omega)
        F, dF = self.forcing(omega)
        q, v = self.samples(z, omega)
        f, dq, dv = sampled_forces(self.force_columns, q, v)
        Lz = L @ z
        R = Lz + self.harmonics.coefficients(f) - F
        scale = float(np.linalg.norm(F)) or float(np.linalg.norm(Lz)) or 1.0

        built = {}  # T(df/dq), T(df/dv): built once, for whichever derivative is read first

        def toeplitz():
            if not built:
                built["pair"] = toeplitz_pair(self.harmonics, dq, dv)
            return built["pair"]
        return Evaluation(R, scale, lambda: self._jacobian(L, *toeplitz(), omega),
                          lambda: dL @ z + toeplitz()[1] @ self.harmonics.derivative(z, self.n) - dF)

    def _jacobian(self, L: np.ndarray, Tq: np.ndarray, Tv: np.ndarray, omega: float) -> np.ndarray:
        """dR/dz = L + T(df/dq) + omega T(df/dv) (nabla (x) I)."""
        return L + Tq + omega * self.harmonics.times_derivative(Tv, self.n)

    def hill_matrices(self, z: np.ndarray, omega: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A2, A1, A0)`` of the Hill quadratic eigenproblem ``(lambda^2 A2 + lambda A1 + A0) p = 0`` of the
        perturbation ``e^{lambda t} p(t)`` about the solution ``z`` (``A0`` is ``dR/dz``).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients of a periodic solution (m; rad for a rotation DOF).
        omega : float
            Its response frequency (rad/s).

        Returns
        -------
        A2, A1, A0 : ndarray, shape (size, size)
            (kg), (N s/m) and (N/m).
        """
        _, Tq, Tv = self.nonlinear(z, omega)
        eye = np.eye(self.harmonics.size)
        A2 = np.kron(eye, self.M)
        A1 = 2.0 * omega * self._ops["NM"] + np.kron(eye, self.velocity_matrix(omega)) + Tv
        return A2, A1, self._jacobian(self.linear(omega)[0], Tq, Tv, omega)


def local_forces(forces, dofs: tuple[int, ...]) -> tuple:
    """Each force with the positions of its DOFs among ``dofs`` (the unknowns, for the AFT); an error naming the force
    whose DOFs are not all among them."""
    local = {d: i for i, d in enumerate(dofs)}
    for i, force in enumerate(forces):
        if not set(force.dofs) <= set(local):
            checks.fail(f"forces[{i}].dofs", force.dofs, f"must be among dofs = {dofs}")
    return tuple((force, [local[d] for d in force.dofs]) for force in forces)


#: a harmonic-balance problem takes sparse matrices of at most this many DOFs as dense copies (50 MB each; its
#: operators are dense in the (2H + 1) n unknowns) and refuses larger ones: a large model is reduced first
DENSE_UP_TO = 2500


def checked_matrices(problem) -> int:
    """Check a problem's M, D, K (and D1, K1) as square matrices of one size, and its harmonics; the size n. Sparse
    matrices (a full model assembled sparse) are made dense up to :data:`DENSE_UP_TO` DOFs and refused beyond: the
    harmonic-balance operators are dense in the (2H + 1) n unknowns (docs/model.md §24)."""
    n = np.shape(problem.M)[0] if np.ndim(problem.M) == 2 else 0
    for name in ("M", "D", "K") + tuple(k for k in ("D1", "K1") if getattr(problem, k) is not None):
        X = getattr(problem, name)
        if sparse.is_sparse(X) and n > DENSE_UP_TO:
            checks.fail(name, f"a sparse matrix of {n} DOFs", f"must have at most {DENSE_UP_TO} DOFs: harmonic "
                        "balance is dense in its unknowns; reduce the model first (reduce_rotor)")
        object.__setattr__(problem, name, checks.array(name, sparse.dense(X), (n, n)))
    if not isinstance(problem.harmonics, Harmonics):
        checks.fail("harmonics", problem.harmonics, "must be a Harmonics")
    return n


def checked_unknowns(problem, n: int) -> None:
    """Check a condensed problem's ``dofs`` (the unknowns: distinct DOFs of its ``n``) and keep its forces renumbered on
    them (``problem._local_forces``, :func:`local_forces`)."""
    dofs = checks.sequence("dofs", tuple(problem.dofs), lambda f, v: checks.integer(f, v, ge=0, le=n - 1),
                           min_len=1, unique=True)
    object.__setattr__(problem, "dofs", dofs)
    object.__setattr__(problem, "_local_forces", local_forces(problem.forces, dofs))


def sampled_forces(forces, q: np.ndarray, v: np.ndarray):
    """The nonlinear forces and their derivatives at the samples ``q``, ``v`` (N, m): f (N, m), df/dq and df/dv
    (N, m, m). ``forces`` pairs each force with the columns of its DOFs."""
    N, m = q.shape
    if len(forces) == 1 and list(forces[0][1]) == list(range(m)):  # one force on every column, in order: as it is
        return forces[0][0].evaluate(q, v)
    f = np.zeros((N, m))
    dq = np.zeros((N, m, m))
    dv = np.zeros((N, m, m))
    for force, idx in forces:
        fi, dqi, dvi = force.evaluate(q[:, idx], v[:, idx])
        block = _block(idx)
        f[:, idx] += fi
        dq[(slice(None),) + block] += dqi
        dv[(slice(None),) + block] += dvi
    return f, dq, dv


def _block(idx) -> tuple:
    """The index of a force's DOFs ``idx`` (distinct columns) in a square matrix: slices for a run of consecutive
    columns (a view: the sum is written in place), else the mesh of the columns."""
    if list(idx) == list(range(idx[0], idx[0] + len(idx))):
        return slice(idx[0], idx[0] + len(idx)), slice(idx[0], idx[0] + len(idx))
    return np.ix_(idx, idx)


def force_coefficients(h: Harmonics, forces, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The AFT of the nonlinear forces at the samples ``q``, ``v`` (N, m): their coefficients only (no Toeplitz
    matrices: a residual without its Jacobian). ``forces`` pairs each force with the columns of its DOFs."""
    return h.coefficients(sampled_forces(forces, q, v)[0])


def transformed_forces(h: Harmonics, forces, q: np.ndarray, v: np.ndarray):
    """The AFT of the nonlinear forces at the samples ``q``, ``v`` (N, m): their coefficients, and the Toeplitz matrices
    of their derivatives, T(df/dq) and T(df/dv). ``forces`` pairs each force with the columns of its DOFs."""
    f, dq, dv = sampled_forces(forces, q, v)
    return (h.coefficients(f),) + toeplitz_pair(h, dq, dv)


def toeplitz_pair(h: Harmonics, dq: np.ndarray, dv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """T(df/dq) and T(df/dv) of the sampled derivatives ``dq``, ``dv`` (N, m, m) (T(dv) is zeros without a velocity
    dependence)."""
    m = dq.shape[1]
    Tv = h.toeplitz(dv) if dv.any() else np.zeros((h.size * m, h.size * m))
    return h.toeplitz(dq), Tv


@dataclass(frozen=True, repr=False)
class PeriodicSolution(Result):
    """A converged periodic solution of harmonic balance (:func:`solve_periodic`): its coefficients and how Newton got there.

    Attributes
    ----------
    z : ndarray, shape ((2H + 1) n,)
        Harmonic-major Fourier coefficients ``[a_0, a_1, b_1, ..., a_H, b_H]`` of the ``n`` unknown DOFs (m; rad for a
        rotation DOF).
    omega : float
        The response frequency (rad/s): the fundamental of the harmonics (a family's parameter where the problem is one,
        :mod:`rotorred.nonlinear.continuation`).
    iterations : int
        Newton iterations.
    residual : float
        Relative residual ``||R|| / ||F_ex||`` at ``z``.
    dofs : tuple of int
        The DOFs of the unknowns (the problem's ``dofs``: all of them for a :class:`PeriodicProblem`), length n.
    evaluation : Evaluation
        The residual at ``z`` and its derivatives (built on first use): a continuation's tangent there.
    """

    z: np.ndarray
    omega: float
    iterations: int
    residual: float
    dofs: tuple[int, ...]
    evaluation: Evaluation = field(compare=False)

    @property
    def n(self) -> int:
        """The unknown DOFs."""
        return len(self.dofs)

    @property
    def H(self) -> int:
        """The highest harmonic."""
        return (self.z.size // self.n - 1) // 2

    @property
    def phasors(self) -> np.ndarray:
        """Complex amplitudes ``Q_k = a_k - i b_k`` (``Q_0 = a_0``) of each harmonic k and DOF, shape (H + 1, n) (m):
        harmonic k of a DOF is ``Re(Q_k exp(i k omega t))``."""
        return to_phasors(self.z.reshape(-1, self.n))

    @property
    def amplitudes(self) -> np.ndarray:
        """Amplitude ``sqrt(a_k^2 + b_k^2)`` (``|a_0|`` for k = 0) of each harmonic k and DOF, shape (H + 1, n) (m)."""
        return np.abs(self.phasors)

    @property
    def frequencies(self) -> np.ndarray:
        """Frequency ``k omega / (2 pi)`` of each harmonic k, shape (H + 1,) (Hz)."""
        return np.arange(self.H + 1) * self.omega / (2.0 * np.pi)

    def summary(self) -> list[str]:
        """The frequency, the size, how Newton converged, and the three strongest harmonics."""
        largest = self.amplitudes.max(axis=1)
        strongest = [k for k in np.argsort(-largest)[:3] if largest[k] > 1e-9 * largest.max()]  # above round-off
        top = ", ".join(f"{k} ({self.amplitudes[k].max():.4g} m at DOF {self.dofs[int(np.argmax(self.amplitudes[k]))]})"
                        for k in strongest)
        return [f"harmonic balance at omega = {self.omega:.6g} rad/s ({self.omega / (2 * np.pi):.6g} Hz): "
                f"{self.n} DOFs, {self.H} harmonics",
                f"converged in {self.iterations} Newton iterations, relative residual {self.residual:.3g}",
                f"strongest harmonics k: {top}"]

    def plot(self, ax=None, *, dofs=None, title: str | None = None):
        """The amplitude of each harmonic at its frequency (Hz), a stem a DOF (µm, log scale)
        (:func:`rotorred.plots.branch.plot_harmonics`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        dofs : sequence of int, optional
            Positions among :attr:`dofs` to draw; default all, at most the 6 largest.
        title : str, optional
            The figure's title.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.branch import plot_harmonics

        return plot_harmonics(self.frequencies, self.amplitudes, [f"DOF {d}" for d in self.dofs], ax, columns=dofs,
                              title=title)

    def to_xarray(self):
        """Dims harmonic, dof: ``cos`` a_k, ``sin`` b_k and ``amplitude`` (m); ``frequency`` (Hz) of each harmonic,
        ``omega`` (rad/s); the iterations and residual as attributes."""
        return harmonic_dataset(self.phasors, np.arange(self.H + 1), self.frequencies, self.dofs,
                                {"omega": ((), self.omega, {"units": "rad/s", "long_name": "response frequency"})},
                                {"iterations": self.iterations, "residual": self.residual}, "harmonic")


def coefficient_variables(Q: np.ndarray, dims: tuple[str, ...]) -> dict:
    """The dataset variables of complex amplitudes ``Q = a_k - i b_k`` (m) on ``dims``: ``cos`` a_k, ``sin`` b_k and
    ``amplitude`` sqrt(a_k^2 + b_k^2)."""
    return {"cos": (dims, Q.real, {"units": "m", "long_name": "cosine coefficient a_k"}),
            "sin": (dims, -Q.imag, {"units": "m", "long_name": "sine coefficient b_k"}),
            "amplitude": (dims, np.abs(Q), {"units": "m", "long_name": "amplitude sqrt(a_k^2 + b_k^2)"})}


def harmonic_dataset(Q: np.ndarray, orders, frequencies, dofs, variables: dict, attrs: dict, dim: str):
    """The dataset of a harmonic-balance solution's complex amplitudes ``Q`` (K, n) (m): dims ``dim`` (the harmonics or
    the orders), dof; :func:`coefficient_variables`; the ``frequency`` of each (Hz); ``variables`` and ``attrs`` added
    (:meth:`PeriodicSolution.to_xarray`, :meth:`rotorred.nonlinear.torus.TorusSolution.to_xarray`)."""
    import xarray as xr

    return xr.Dataset(
        {**coefficient_variables(Q, (dim, "dof")), **variables},
        coords={dim: (dim, np.asarray(orders), {"units": "1", "long_name": f"{dim} k"}),
                "frequency": (dim, np.asarray(frequencies), {"units": "Hz", "long_name": f"frequency of the {dim}"}),
                "dof": ("dof", np.asarray(dofs, int), {"units": "1", "long_name": "DOF of the unknowns"})},
        attrs=attrs)


def solve_periodic(problem: PeriodicProblem, z0: np.ndarray, omega: float, *, tol: float = 1e-10, max_iter: int = 40,
                   max_halvings: int = 30) -> PeriodicSolution:
    """The periodic solution near ``z0`` at ``omega`` by Newton's method with a backtracking line search.

    Parameters
    ----------
    problem : PeriodicProblem
        Or a condensed problem or a family of them (anything with ``evaluate(z, omega) -> Evaluation``).
    z0 : ndarray, shape ((2H + 1) n,)
        The start (e.g. the linear response).
    omega : float
        Response frequency (rad/s), or the family's parameter.
    tol : float
        Relative residual ``||R|| / ||F_ex||`` to reach.
    max_iter : int
    max_halvings : int
        How often the line search may halve a step before giving up.

    Returns
    -------
    PeriodicSolution

    Raises
    ------
    NotConverged
        If the relative residual ``||R|| / ||F||`` is not below ``tol`` after ``max_iter`` iterations, or a step
        cannot reduce it.
    """
    z = np.array(z0, float)
    ev = problem.evaluate(z, omega)
    dofs = tuple(getattr(problem, "dofs", range(problem.n)))  # a family has none: its unknowns, 0 to n - 1
    for it in range(max_iter):
        if ev.relative <= tol:
            return PeriodicSolution(z, float(omega), it, ev.relative, dofs, ev)
        try:
            step = factored(ev.dR_dz).solve(-ev.R)
        except (sla.LinAlgError, ValueError):
            raise NotConverged(omega, ev.relative, tol, it, "singular Jacobian") from None
        z, ev = _line_search(problem, z, step, omega, ev, tries=max_halvings)
        if ev is None:
            raise NotConverged(omega, problem.evaluate(z, omega).relative, tol, it,
                               "no step reduces the residual")
    if ev.relative <= tol:
        return PeriodicSolution(z, float(omega), max_iter, ev.relative, dofs, ev)
    raise NotConverged(omega, ev.relative, tol, max_iter, "iteration limit")


def _line_search(problem, z, step, omega, ev, shrink: float = 0.5, tries: int = 30):
    """``z + a step`` for the largest ``a`` in 1, 1/2, 1/4, ... that lowers ``||R||`` (Armijo with a small slope), and
    its evaluation (its derivatives are built only if the iteration goes on from it)."""
    r0 = np.linalg.norm(ev.R)
    a = 1.0
    for _ in range(tries):
        trial = z + a * step
        ev_t = problem.evaluate(trial, omega)
        if np.linalg.norm(ev_t.R) <= (1.0 - 1e-4 * a) * r0:
            return trial, ev_t
        a *= shrink
    return z, None
