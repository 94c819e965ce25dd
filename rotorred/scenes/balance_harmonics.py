"""The truncations of a rub scene's harmonic balance: harmonics chosen by the convergence of its response
(``[solver] tolerance`` with ``method = "harmonic-balance"``), and a cold start up through coarser truncations.

The harmonics double along :data:`LADDER`, each with :data:`SAMPLES_PER_HARMONIC` AFT samples a period (the
default's 2048 for 100), and each solution starts Newton from the one before it (its coefficients, the new harmonics
zero; the first from a short transient's record, or a cold start, :func:`cold_solution`). The error estimate of a
truncation is the change of the response to the next one, the largest over the scene's output DOFs of

    ||c_H - c_2H|| / ||c_2H||,

with ``c`` the DOF's Fourier coefficients (its RMS and spectrum, by Parseval). The first truncation whose change is
within the tolerance is met, and the finer solution of the pair is the one returned. With an error ``e(H) ~ H^-p``
the change is ``e(H) (1 - 2^-p)`` and the finer error ``e(H) 2^-p``: below the change for any order p >= 1. The
rig's changes fall with observed orders of 2.2 to 3.9 (:mod:`validation.hb_harmonics`, docs/model.md §15), so
what is returned is about 4-8 times more accurate than its estimate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotorred.nonlinear.hb import NotConverged, solve_periodic
from rotorred.scenes.branch import cold_start
from rotorred.scenes.harmonic_balance import RubProblem, rub_problem

__all__ = ["LADDER", "SAMPLES_PER_HARMONIC", "HarmonicsChoice", "HarmonicsNotConverged", "balance_to_tolerance",
           "cold_solution", "response_change"]

#: the harmonics tried, in order (each doubles the one before)
LADDER = (25, 50, 100, 200, 400)
#: AFT samples a period per harmonic: the default (2048 samples for 100 harmonics, ``BALANCE_DEFAULTS``)
SAMPLES_PER_HARMONIC = 20.48
#: the relative residual every solution here is solved to (that of :func:`rotorred.scenes.branch.cold_start`)
TOL = 1e-9
#: how :func:`cold_solution` started its solution (for the summary)
FROM_RECORD = "Newton from a short transient's last period"
COLD = ("a cold start (Newton from the linear response, else a continuation in the clearance) at the coarsest "
        "truncation, then Newton up to the harmonics asked")
#: how :func:`balance_to_tolerance` starts each truncation (for the summary)
LADDER_START = "each truncation's Newton from the record of a short transient or the truncation before"


@dataclass(frozen=True)
class HarmonicsChoice:
    """What ``solver.tolerance`` chose for a harmonic balance.

    Attributes
    ----------
    tolerance : float
    harmonics, samples : int
        The solution returned: harmonics of f_0 and AFT samples a period.
    estimate : float
        The change of the response from the truncation before it (the error estimate, <= ``tolerance``).
    steps : tuple of (int, float)
        Each truncation tried after the first, and its change from the one before.
    """

    tolerance: float
    harmonics: int
    samples: int
    estimate: float
    steps: tuple[tuple[int, float], ...]

    def describe(self) -> str:
        tried = ", ".join(f"{H}: {change:.2g}" for H, change in self.steps)
        return (f"solver.tolerance = {self.tolerance:g}: {self.harmonics} harmonics and {self.samples} AFT samples a "
                f"period, the response's change from {self.harmonics // 2} harmonics {self.estimate:.2g} <= "
                f"{self.tolerance:g} (largest over the output DOFs of ||c_H - c_2H|| / ||c_2H||; harmonics: change "
                f"{tried})")


class HarmonicsNotConverged(NotConverged):
    """The response still changes by more than the tolerance at the last truncation of :data:`LADDER`."""

    def __init__(self, omega: float, change: float, tol: float, harmonics: int):
        self.omega, self.residual, self.tol, self.iterations = omega, change, tol, len(LADDER)
        RuntimeError.__init__(self, f"harmonic balance did not meet solver.tolerance = {tol:g}: the response still "
                              f"changes by {change:.3g} from {harmonics // 2} to {harmonics} harmonics (at most "
                              f"{LADDER[-1]}); give solver.harmonics and solver.samples instead, or a larger "
                              f"tolerance")


def samples_for(H: int) -> int:
    """AFT samples a period for ``H`` harmonics: :data:`SAMPLES_PER_HARMONIC` H, rounded up to an even number."""
    N = int(np.ceil(SAMPLES_PER_HARMONIC * H))
    return N + N % 2


def response_change(coarse: RubProblem, z_coarse: np.ndarray, fine: RubProblem, z_fine: np.ndarray,
                    dofs) -> float:
    """The largest over ``dofs`` (model DOFs (node, direction)) of ``||c_coarse - c_fine|| / ||c_fine||``, the coarse
    coefficients padded with zeros to the fine harmonics."""
    worst = 0.0
    for dof in dofs:
        c_fine = fine.coefficients(z_fine, dof)
        c_coarse = np.zeros_like(c_fine)
        c = coarse.coefficients(z_coarse, dof)
        c_coarse[:len(c)] = c
        worst = max(worst, float(np.linalg.norm(c_coarse - c_fine) / (np.linalg.norm(c_fine) or 1.0)))
    return worst


def padded(z: np.ndarray, fine: RubProblem) -> np.ndarray:
    """A coarser truncation's coefficients ``z`` on the unknowns of ``fine`` (harmonic-major; new harmonics zero)."""
    out = np.zeros(fine.problem.size)
    out[:z.size] = z  # harmonic-major: [a_0 (m), a_1 (m), b_1 (m), ...], the first 2 H + 1 rows are the coarse ones
    return out


def balance_to_tolerance(scene, model, tol: float, dofs, progress=None, record=None) -> tuple[
        RubProblem, np.ndarray, HarmonicsChoice]:
    """The periodic rub response of ``scene`` on ``model`` with the harmonics chosen for ``tol`` (module docstring).

    Parameters
    ----------
    scene : rotorred.scenes.schema.Scene
        A rub scene at commensurate speeds.
    model : SystemMatrices or ReducedSystem
    tol : float
        Relative error target of the response at ``dofs``.
    dofs : sequence of (int, str)
        The output DOFs whose response is compared.
    progress : callable, optional
        ``progress(H, change)`` after each truncation (change None for the first).
    record : (ndarray, dict), optional
        A short transient's last period (:func:`cold_solution`): each truncation's Newton starts from its fit first,
        then from the truncation before.

    Returns
    -------
    (RubProblem, ndarray, HarmonicsChoice)
        The finer problem of the pair that met ``tol``, its solution's coefficients, and the choice.

    Raises
    ------
    NotConverged
        If a truncation's Newton does not converge from the one before nor from a cold start, or
        :class:`HarmonicsNotConverged` when the last truncation still changes by more than ``tol``.
    """
    rp, z, _ = cold_solution(scene, model, LADDER[0], samples_for(LADDER[0]), record)
    if progress is not None:
        progress(LADDER[0], None)
    steps = []
    for H in LADDER[1:]:
        fine = rub_problem(scene, model, H, samples_for(H))
        z_fine = _solve_from(fine, *([fine.start_from_record(*record)] if record is not None else []),
                             padded(z, fine))
        change = response_change(rp, z, fine, z_fine, dofs)
        steps.append((H, change))
        if progress is not None:
            progress(H, change)
        if change <= tol:
            return fine, z_fine, HarmonicsChoice(tol, H, samples_for(H), change, tuple(steps))
        rp, z = fine, z_fine
    raise HarmonicsNotConverged(rp.omega, steps[-1][1], tol, LADDER[-1])


def cold_solution(scene, model, H: int, N: int, record=None) -> tuple[RubProblem, np.ndarray, str]:
    """The periodic rub response of ``scene`` on ``model`` with ``H`` harmonics and ``N`` AFT samples, from nothing.

    With ``record``, a short transient's last period ``(t, {position: samples})``
    (:func:`rotorred.scenes.run.start_record`), Newton from its fit: on paper-rub, 5 periods of f_0 from the
    settled linear state put Newton 4 iterations from the orbit the settled transient reaches (docs/model.md §15).
    Without one, or if Newton does not converge from it: a cold start (:func:`rotorred.scenes.branch.cold_start`) at
    the first truncation of :data:`LADDER` below ``H``, then Newton up the ladder, each truncation from the one before,
    to ``H`` itself. The cold start's continuation in the clearance costs per point what a truncation costs per Newton
    iteration, so it is cheapest at the coarsest: on paper-rub at 100 harmonics 1.3 s, against 3.2 s for the cold
    start at 100 harmonics itself, and the same solution (7.6e-11 apart; validation/hb_rig.py).

    Returns
    -------
    (RubProblem, ndarray, str)
        The problem, the solution's coefficients, and how it was started: :data:`FROM_RECORD` or :data:`COLD`.
    """
    if record is not None:
        rp = rub_problem(scene, model, H, N)
        z = _newton(rp, rp.start_from_record(*record))
        if z is not None:
            return rp, z, FROM_RECORD
    coarser = [h for h in LADDER if h < H]
    if not coarser:
        rp = rub_problem(scene, model, H, N)
        return rp, cold_start(rp.problem, rp.omega), COLD
    rp = rub_problem(scene, model, coarser[0], samples_for(coarser[0]))
    z = cold_start(rp.problem, rp.omega)
    for h, n in [(h, samples_for(h)) for h in coarser[1:]] + [(H, N)]:
        fine = rub_problem(scene, model, h, n)
        z, rp = _solve_from(fine, padded(z, fine)), fine
    return rp, z, COLD


def _newton(rp: RubProblem, z0: np.ndarray) -> np.ndarray | None:
    """Newton from ``z0`` (to the cold start's tolerance), or None if it does not converge."""
    try:
        return solve_periodic(rp.problem, z0, rp.omega, tol=TOL).z
    except NotConverged:
        return None


def _solve_from(rp: RubProblem, *starts: np.ndarray) -> np.ndarray:
    """Newton from each of ``starts`` in turn, or a cold start if it converges from none."""
    for z0 in starts:
        z = _newton(rp, z0)
        if z is not None:
            return z
    return cold_start(rp.problem, rp.omega)
