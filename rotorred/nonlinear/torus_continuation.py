"""Pseudo-arclength continuation of tori (docs/model.md §26): the periodic continuation's machinery
(:func:`rotorred.nonlinear.continuation.continue_branch`: predictor, corrector, step control, folds, interrupts) on a
one-parameter family of torus problems, with the bordered Newton systems solved matrix-free.

A :class:`TorusFamily` is a map ``value -> TorusProblem`` (a clearance, a speed, a forcing amplitude ...) on one fixed
set of orders. The continuation carries the parameter scaled, ``s = scale value`` with ``scale = ||z_lin|| / value``
at the reference value, so that the arclength weighs it like the coefficients (metres for the rig). The family
evaluates the residual of :class:`rotorred.nonlinear.torus.TorusProblem` at ``(z, s)``; its Jacobian is held by the
contact's rank and never formed (:class:`rotorred.nonlinear.torus_krylov.RankJacobian`), and ``dR/ds`` is a forward
difference of the residual (a relative step :data:`STEP` of the value: one problem more an iteration where the value
changes the compliance, a speed; with ``frozen``, the pair of problems of a nearby value).

The bordered system of the corrector and the tangent, ``[[J, c], [t^T, tau]] [x; mu] = [b; beta]``, is solved by block
elimination with two solves of J (:meth:`RankJacobian.solve`: Woodbury on the rank, preconditioned GMRES):

    x_c = J^-1 c,   x_b = J^-1 b,   mu = (beta - t . x_b) / (tau - t . x_c),   x = x_b - mu x_c,

``x_c`` shared by the step and the tangent of an iterate (the tangent is ``[-x_c; 1]`` normalised). Near a fold J is
nearly singular and ``x_c`` large, but the tangent's direction and the step stay well defined (Keller's block
elimination; its loss of accuracy is that of J^-1 c, about cond(J) eps, 1e-6 at 1e-10 from the fold). Each solve is
inexact (the forcing term of :func:`rotorred.nonlinear.torus.solve_torus`: GMRES to ``min(1e-2, rho)``, rho the
iterate's relative residual), and the preconditioner of one Jacobian serves the next ones (the next iterate's, the next
point's) until a solve needs more than :data:`FRESH_AFTER` GMRES iterations: the next Jacobian then builds its own.
*Choice*: on the rig's clearance branch (|k1| <= 8, |k2| <= 40) a point took 412 ms at 20 against 780 ms with the
Krylov module's own rule alone (a fresh one past 60 iterations), the same load, one after the other.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.linalg as sla

from rotorred import checks
from rotorred.nonlinear.hb import Evaluation, NotConverged
from rotorred.nonlinear.torus import FORCING_MAX, TorusProblem, solve_torus
from rotorred.nonlinear.torus_krylov import projected_blocks

__all__ = ["TorusFamily", "TorusJacobian"]

#: the relative step of the forward difference in dR/dvalue
STEP = 1e-6
#: GMRES iterations of a solve past which the next Jacobian builds its own preconditioner
FRESH_AFTER = 20
#: the tightest GMRES tolerance of a continuation's solves: at a corrected point (rho below the branch's tolerance,
#: down to 1e-14 in a fold's Brent) the solve is the tangent's ``J^-1 c``, whose relative error moves the tangent's
#: parameter component by as much relatively and its sign (the fold's test) not at all; at the rig's folds the
#: solves to 1e-12 took half the location's time
SOLVE_FLOOR = 1e-8
#: problems a family keeps (the corrector's iterates and their differences revisit a few values)
KEPT = 6
#: J^-1 c of an iterate starts from the last one's (where the bases are the same)
WARM_COLUMN = True


class TorusJacobian:
    """The torus Jacobian at an iterate, matrix-free: ``times``, ``solve`` and ``bordered`` (what
    :func:`rotorred.nonlinear.continuation.continue_branch` asks of a Jacobian).

    Parameters
    ----------
    J : RankJacobian or None
        The Jacobian on the contact's rank (:meth:`TorusProblem.jacobian`); None out of contact (J = I).
    rtol : float
        GMRES's relative tolerance on each solve (the inexact Newton's forcing term).
    """

    def __init__(self, J, rtol: float):
        self.J, self.rtol, self.krylov = J, float(rtol), 0

    def times(self, v: np.ndarray) -> np.ndarray:
        """``J v`` (v of shape (size,))."""
        return v.copy() if self.J is None else self.J.times(v)

    def solve(self, b: np.ndarray, start: np.ndarray | None = None) -> np.ndarray:
        """``J^-1 b`` to the relative tolerance ``rtol`` (GMRES on the reduced equation, from the reduced ``start``
        if given); LinAlgError if GMRES gives a non-finite solution."""
        if self.J is None:
            return b.copy()
        x, stats = self.J.solve(b, self.rtol, start=start)
        self.krylov += stats.iterations
        return x

    def solve_column(self, c: np.ndarray) -> np.ndarray:
        """``J^-1 c`` for the border's column (:meth:`solve`; a family's Jacobian starts it from the last one's)."""
        return self.solve(c)

    def bordered(self, column: np.ndarray, row: np.ndarray) -> _Bordered:
        """The bordered matrix ``[[J, column], [row]]`` (``row`` of length size + 1), ready to solve with."""
        return _Bordered(self, column, row)


class _Bordered:
    """``[[J, c], [r^T, d]]`` solved by block elimination (module docstring), ``J^-1 c`` computed once."""

    def __init__(self, jacobian: TorusJacobian, column: np.ndarray, row: np.ndarray):
        self.jacobian, self.column, self.row = jacobian, column, row
        self._x_c = None

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._x_c is None:
            self._x_c = self.jacobian.solve_column(self.column)
        b, beta, r, d = rhs[:-1], rhs[-1], self.row[:-1], self.row[-1]
        x_b = self.jacobian.solve(b) if np.any(b) else np.zeros_like(b)
        schur = d - r @ self._x_c
        if not np.isfinite(schur) or schur == 0.0:
            raise sla.LinAlgError("the bordered torus Jacobian is singular")
        mu = (beta - r @ x_b) / schur
        return np.append(x_b - mu * self._x_c, mu)


@dataclass(frozen=True)
class _Point:
    """A solution at one value, as :func:`rotorred.nonlinear.continuation.continue_branch` reads a point solver's."""

    z: np.ndarray
    iterations: int
    evaluation: Evaluation | None = None


@dataclass(frozen=True)
class TorusFamily:
    """Torus problems along one parameter, for :func:`rotorred.nonlinear.continuation.continue_branch`.

    Parameters
    ----------
    build : callable
        ``build(value) -> TorusProblem`` at the parameter's ``value`` (its unit); every problem on the same orders
        (one :class:`TorusHarmonics`: their number fixes the unknowns), their frequencies free to move with the value.
        It may raise :class:`rotorred.checks.InputError` where the value is refused (then no point there).
    reference : float
        The value that sets the scale of the carried parameter (its unit), != 0.
    parameter : (str, str)
        The parameter's name and unit, for the branch and its messages.
    frozen : float
        ``dR/dvalue`` at ``(z, value)`` is the difference of the residuals at z of the problems at ``v_c`` and
        ``v_c (1 + STEP)``, ``v_c`` the value itself (default, 0) or, with ``frozen`` > 0, the last value they were
        built at while it is within ``frozen |value|`` (>= 0): exact in z, first order in ``value - v_c``. Where a
        value's problem costs its compliance (a speed: every order's dynamic stiffness solved) this halves the
        problems built, and the next steps' derivatives cost two residuals.
    derivative : callable, optional
        ``derivative(problem, z) -> dR/dvalue`` (size,), exact, in place of the difference of two residuals (a
        clearance: :meth:`TorusProblem.dR_dclearance`, a column of the sampled Jacobian at z, no residual more).
    """

    build: Callable[[float], TorusProblem]
    reference: float
    parameter: tuple = ("value", "-")
    frozen: float = 0.0
    derivative: Callable[[TorusProblem, np.ndarray], np.ndarray] | None = None
    _problems: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    _state: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        reference = checks.number("reference", self.reference, self.parameter[1])
        if reference == 0.0:
            checks.fail("reference", reference, "must not be 0 (it scales the carried parameter)", self.parameter[1])
        p = self.at(reference)
        object.__setattr__(self, "scale", float(np.linalg.norm(p.linear_response()) or 1.0) / abs(reference))
        checks.non_negative("frozen", self.frozen)
        self._state.update(last=None, krylov=0, jacobians=0, column=None)

    # ------------------------------------------------------------------------------------------ the problems
    def at(self, value: float) -> TorusProblem:
        """The problem at ``value`` (the last :data:`KEPT` kept).

        Parameters
        ----------
        value : float
            The parameter (its unit).

        Returns
        -------
        TorusProblem
        """
        value = float(value)
        if value not in self._problems:
            if len(self._problems) >= KEPT:
                self._problems.pop(next(iter(self._problems)))
            self._problems[value] = self.build(value)
        return self._problems[value]

    def _valid(self, value: float) -> TorusProblem | None:
        try:
            return self.at(value)
        except checks.InputError:
            return None

    def parameter_value(self, s: float) -> float:
        """The parameter's value of the carried ``s``.

        Parameters
        ----------
        s : float
            The carried parameter (m).

        Returns
        -------
        float
            Its unit.
        """
        return s / self.scale

    def carried(self, value: float) -> float:
        """The carried ``s`` of the parameter's ``value``.

        Parameters
        ----------
        value : float
            Its unit.

        Returns
        -------
        float
            (m).
        """
        return value * self.scale

    @property
    def n(self) -> int:
        """Unknown DOFs an order."""
        return self.at(self.reference).n

    @property
    def size(self) -> int:
        """Unknowns."""
        return self.at(self.reference).size

    @property
    def harmonics(self):
        """The orders (:class:`rotorred.nonlinear.torus.TorusHarmonics`)."""
        return self.at(self.reference).harmonics

    @property
    def krylov(self) -> int:
        """GMRES iterations of every solve so far."""
        return self._state["krylov"]

    # ------------------------------------------------------------------------------------------ the continuation's
    def linear_response(self, s: float) -> np.ndarray:
        """The linear response at the carried ``s`` (NaN where the value is refused).

        Parameters
        ----------
        s : float
            The carried parameter (m).

        Returns
        -------
        ndarray, shape (size,)
            (m; rad for a rotation DOF).
        """
        p = self._valid(self.parameter_value(s))
        return np.full(self.size, np.nan) if p is None else p.linear_response()

    def evaluate(self, z: np.ndarray, s: float) -> Evaluation:
        """The residual at ``(z, s)``; its Jacobian (:class:`TorusJacobian`) and ``dR/ds`` built on first use. Where
        the value is refused, an infinite residual (the corrector takes it for a failed step).

        Parameters
        ----------
        z : ndarray, shape (size,)
            Harmonic-major coefficients (m; rad for a rotation DOF).
        s : float
            The carried parameter (m).

        Returns
        -------
        Evaluation
        """
        value = self.parameter_value(s)
        p = self._valid(value)
        if p is None:
            return Evaluation(np.full(len(z), np.inf), 1.0, _refused, _refused)
        R = p.residual(z)
        relative = float(np.linalg.norm(R)) / p.scale

        def dR_ds():  # the problem's own derivative, or the difference of two problems' residuals at z
            if self.derivative is not None:
                return self.derivative(p, z) / self.scale
            kept = self._state["column"]
            if kept is None or abs(kept[0] - value) > self.frozen * abs(value):
                kept = (value, *self._pair(value, p))
                self._state["column"] = kept
            _, low, high, dv = kept
            R_low = R if low is p else low.residual(z)
            return (high.residual(z) - R_low) / (dv * self.scale)
        return Evaluation(R, p.scale, lambda: self._jacobian(p, z, relative), dR_ds)

    def _pair(self, value: float, p: TorusProblem):
        """The problems at ``value`` and ``value (1 + STEP)`` (or ``value (1 - STEP)`` and ``value`` where the larger
        is refused) and the difference of their values."""
        h = STEP * abs(value)
        up = self._valid(value + h)
        if up is not None:
            return p, up, h
        down = self._valid(value - h)
        if down is None:
            raise sla.LinAlgError("no problem on either side of the value")
        return down, p, h

    def _jacobian(self, p: TorusProblem, z: np.ndarray, relative: float) -> TorusJacobian:
        """The Jacobian at ``z``, keeping the last one's preconditioner (its compliance projected afresh where the
        problem's differs: another speed)."""
        last = self._state["last"] if self._state.get("slow", 0) <= FRESH_AFTER else None
        _, J = p.jacobian(z, last)
        self._state["slow"] = 0
        if J is not None and J.reused and J.G0 is not last.G0:
            J.P0, J.Pk = projected_blocks(J.G0, J.Gk, J.V, J.U)
        if J is not None:
            self._state["last"] = J
        self._state["jacobians"] += 1
        return _Counted(TorusJacobian(J, forcing_term(relative)), self._state)

    def solve_point(self, z0: np.ndarray, s: float, tol: float, max_iter: int, max_halvings: int) -> _Point:
        """The torus at the carried ``s`` by :func:`rotorred.nonlinear.torus.solve_torus` from ``z0`` (the
        continuation's start, and its step in the parameter alone past a corner).

        Parameters
        ----------
        z0 : ndarray, shape (size,)
            The start (m; rad for a rotation DOF).
        s : float
            The carried parameter (m).
        tol : float
            Relative residual to reach.
        max_iter, max_halvings : int
            Newton iterations, and halvings of a step in its line search.

        Returns
        -------
        object
            With ``z`` (size,) and ``iterations``.

        Raises
        ------
        NotConverged
            If Newton does not converge, or the value is refused.
        """
        p = self._valid(self.parameter_value(s))
        if p is None or not np.all(np.isfinite(z0)):
            raise NotConverged(s, np.inf, tol, 0, "no problem at this value")
        found = solve_torus(p, z0, tol=tol, max_iter=max_iter, max_halvings=max_halvings)
        return _Point(found.z, found.iterations)


class _Counted(TorusJacobian):
    """A :class:`TorusJacobian` adding its GMRES iterations to the family's count; its ``J^-1 c`` starts from the
    last Jacobian's reduced solution where the two share their bases (:data:`WARM_COLUMN`), and keeps its own."""

    def __init__(self, jacobian: TorusJacobian, state: dict):
        super().__init__(jacobian.J, jacobian.rtol)
        self._family_state = state

    def solve_column(self, c: np.ndarray) -> np.ndarray:
        kept = self._family_state.get("column_reduced")
        start = kept[1] if WARM_COLUMN and self.J is not None and kept is not None and kept[0] is self.J.U else None
        x = self.solve(c, start)
        if self.J is not None:
            self._family_state["column_reduced"] = (self.J.U, self.J.reduced)
        return x

    def solve(self, b: np.ndarray, start: np.ndarray | None = None) -> np.ndarray:
        before = self.krylov
        x = super().solve(b, start)
        self._family_state["krylov"] += self.krylov - before
        self._family_state["slow"] = max(self._family_state.get("slow", 0), self.krylov - before)
        return x


def forcing_term(relative: float) -> float:
    """GMRES's relative tolerance on a solve at an iterate of relative residual ``relative``: ``min(1e-2, rho)``,
    floored at :data:`SOLVE_FLOOR`."""
    return max(min(FORCING_MAX, relative), SOLVE_FLOOR)


def _refused():
    raise sla.LinAlgError("no problem at this value: it is refused")
