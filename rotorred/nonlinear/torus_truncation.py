"""The orders of a torus chosen by the convergence of its response (docs/model.md §25), as the periodic solver's
harmonics are (:mod:`rotorred.scenes.balance_harmonics`).

The box of orders ``|k_1| <= H_1``, ``|k_2| <= H_2`` doubles along a ladder (both bounds at once, the grid with them),
each truncation's Newton started from the one before (its coefficients on the new set, the new orders zero). The
estimate of a truncation is its change to the next, the largest over the output signals of

    ||Q_coarse - Q_fine|| / ||Q_fine||,

``Q`` the complex amplitudes of every order (by Parseval the RMS of the signal's change on the torus). The first
change within the tolerance is met and the finer solution of the pair is returned: with an error ``e ~ H^-p`` its
error is ``e 2^-p``, below the change ``e (1 - 2^-p)`` for any order p >= 1.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from rotorred import checks
from rotorred.nonlinear.hb import NotConverged
from rotorred.nonlinear.torus import TorusHarmonics, TorusProblem, TorusSolution, solve_torus

__all__ = ["TorusTruncation", "TorusOrdersNotConverged", "torus_to_tolerance", "torus_change"]


@dataclass(frozen=True)
class TorusTruncation:
    """What a tolerance chose for a torus.

    Attributes
    ----------
    tolerance : float
    orders : (int, int)
        ``(H_1, H_2)`` of the solution returned.
    grid : (int, int)
        Its AFT grid ``(N_1, N_2)``.
    estimate : float
        Its change from the truncation before (<= ``tolerance``).
    steps : tuple of ((int, int), float)
        Each truncation after the first and its change from the one before.
    """

    tolerance: float
    orders: tuple[int, int]
    grid: tuple[int, int]
    estimate: float
    steps: tuple

    def describe(self) -> str:
        """One line (under 120 characters for a ladder of three): the orders chosen and the changes that chose
        them."""
        tried = ", ".join(f"{H[0]}x{H[1]} {change:.2g}" for H, change in self.steps)
        return (f"tolerance {self.tolerance:g}: orders |k1| <= {self.orders[0]}, |k2| <= {self.orders[1]}, "
                f"grid {self.grid[0]}x{self.grid[1]}; change to each box {tried}")


class TorusOrdersNotConverged(NotConverged):
    """The torus's response still changes by more than the tolerance at the ladder's last truncation."""

    def __init__(self, omega: float, change: float, tol: float, orders: tuple[int, int]):
        self.omega, self.residual, self.tol, self.iterations = omega, change, tol, 0
        RuntimeError.__init__(self, f"the torus did not meet the tolerance {tol:g}: its response still changes by "
                              f"{change:.3g} at orders |k1| <= {orders[0]}, |k2| <= {orders[1]}, the ladder's last; give "
                              "the box of orders instead (a scene's solver.harmonics = [H1, H2], or "
                              "TorusOptions(orders=(H1, H2))) or a larger tolerance")


def torus_change(coarse: TorusHarmonics, Q_coarse: np.ndarray, fine: TorusHarmonics, Q_fine: np.ndarray) -> float:
    """The largest over the columns of ``||Q_coarse - Q_fine|| / ||Q_fine||``, the coarse amplitudes (K_c, p) put on
    the fine set's orders (K_f, p) (an order the coarse set lacks counts as 0)."""
    p = Q_fine.shape[1]
    moved = fine.phasors(coarse.transfer(coarse.from_phasors(Q_coarse), p, fine), p)
    norms = np.linalg.norm(Q_fine, axis=0)
    return float(np.max(np.linalg.norm(moved - Q_fine, axis=0) / np.where(norms > 0, norms, 1.0)))


def torus_to_tolerance(build: Callable[[int, int], TorusProblem], ladder, z0: np.ndarray, tolerance: float,
                       outputs: Callable[[TorusProblem, np.ndarray], np.ndarray], *, newton_tol: float = 1e-10):
    """The torus solved up the ``ladder`` of orders until its response changes by less than ``tolerance``.

    Parameters
    ----------
    build : callable
        ``build(H1, H2) -> TorusProblem``: the problem on that box (its grid and band the caller's).
    ladder : sequence of (int, int)
        The boxes ``(H_1, H_2)`` tried in order, at least two.
    z0 : ndarray
        The start of the first truncation's Newton, shape ``(build(*ladder[0]).size,)``.
    tolerance : float
        The change to reach, in (0, 1).
    outputs : callable
        ``outputs(problem, z) -> Q``: complex amplitudes (K, p) of the signals compared (m).
    newton_tol : float
        Each Newton solve's relative residual.

    Returns
    -------
    problem : TorusProblem
    solution : TorusSolution
    choice : TorusTruncation

    Raises
    ------
    TorusOrdersNotConverged
        If no change along the ladder is within the tolerance.
    NotConverged
        If a truncation's Newton does not converge.
    """
    checks.number("tolerance", tolerance, gt=0.0, lt=1.0)
    ladder = [tuple(int(h) for h in H) for H in ladder]
    if len(ladder) < 2:
        checks.fail("ladder", ladder, "must hold at least two truncations")
    previous, steps = None, []
    for H in ladder:
        problem = build(*H)
        if previous is not None:
            z0 = previous[0].harmonics.transfer(previous[1].z, previous[0].n, problem.harmonics)
        solution: TorusSolution = solve_torus(problem, z0, tol=newton_tol)
        Q = outputs(problem, solution.z)
        if previous is not None:
            change = torus_change(previous[0].harmonics, previous[2], problem.harmonics, Q)
            steps.append((H, change))
            if change <= tolerance:
                h = problem.harmonics
                return problem, solution, TorusTruncation(tolerance, H, (h.N1, h.N2), change, tuple(steps))
        previous = (problem, solution, Q)
    raise TorusOrdersNotConverged(previous[0].w[0], steps[-1][1], tolerance, ladder[-1])
