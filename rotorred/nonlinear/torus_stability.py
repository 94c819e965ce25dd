"""Stability of a torus by the Lyapunov exponents of the variational equation along it (docs/model.md §27).

A torus of a forced system is read along ``theta = w t``: both angles are forced, so the response on it is one
trajectory, q(t) = sum_k Re(Q_k exp(i k . w t)), with no free phase. A small perturbation x of that trajectory obeys
the linearised equation

    M x'' + (D + J_v(t)) x' + (K + J_q(t)) x = 0,

J_q and J_v the nonlinear forces' derivatives by q and dq/dt at the torus's state at time t, on their few DOFs: a
linear equation whose coefficients are quasi-periodic. Its Lyapunov exponents (the growth rates
``lim (1/T) log |x(T)|`` of independent perturbations) say what a transient started near the torus does: it returns
when the largest is negative and leaves at that rate when it is positive. They are the real parts of the Floquet
exponents when the torus is a periodic orbit (w_2 unforced), and -zeta omega of each mode for a linear system.

**How they are computed** (:func:`torus_lyapunov`). The state matrix ``A(t) = [[0, I], [-M^-1 (K + J_q),
-M^-1 (D + J_v)]]`` is held at its value midway through each step of length ``dt`` and the step is its matrix
exponential (second order in ``dt``, as :func:`rotorred.nonlinear.stability.floquet_by_monodromy` integrates a
period); a stretch of steps where every derivative vanishes (out of contact) is one exponential of the linear state
matrix. ``p`` perturbations (the columns of an orthonormal ``Y``, started at random with a fixed seed) are carried
step by step and re-orthonormalised by a QR factorisation after every product (Benettin et al. 1980): the logarithms
of R's diagonal, summed over a block of time and divided by it, are the block's exponents (a stretch without force
derivatives is at most 1/32 of the faster base's period, so that S below is sampled finely). The first block, where
the columns turn into the leading directions, is discarded. The summed logarithms S(t) grow as the exponents times t
plus a bounded quasi-periodic wobble; S averaged over each block (the wobble mostly averaged out) is fitted by a
line against the blocks' centres, and the slope is the exponent. Its error is the range of the fit's residuals over
the centres' span (the steepest slope what the line leaves could fake) plus the change of the exponent when the
whole integration is repeated at ``2 dt`` (the step's error, for any order >= 1: second order where the derivatives
are smooth, first at a contact's crossings). The torus is called stable when the largest exponent is below
``-margin`` times its error, unstable when above ``+margin`` times it, and undecided between.

**A piecewise-smooth force** (the rig's plate law, docs/model.md §4): the derivatives are the solver's own
(``force.evaluate``, the law's analytic tangent, zero out of contact). The plate's force is continuous across the
touch-down and the lift-off (Hertz ``delta^1.5`` and the Hunt-Crossley clamp both reach 0 there) and friction slides
one way (the rim's speed against the whirl's), so the vector field is continuous and its derivative jumps only on the
crossings, a set of times of measure zero: the flow is differentiable through a transversal crossing with the
identity as saltation matrix (Leine & Nijmeijer 2004, §7.2), and the variational equation is the one above with the
derivative taken on either side. The midpoint step of a step holding a crossing is first order there.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from rotorred import checks, progress as feedback
from rotorred.nonlinear.hb import local_forces, sampled_forces
from rotorred.nonlinear.torus import TorusSeries
from rotorred.results import Result

__all__ = ["LyapunovOptions", "TorusStability", "torus_lyapunov", "torus_trajectory"]

#: time steps whose state matrices are built and exponentiated at once
CHUNK = 256
#: samples of the summed logarithms a period of the faster base at least: a stretch of steps without a force
#: derivative is one exponential, at most 1 / SAMPLES of that period long (the block averages need the samples)
SAMPLES = 32
#: the verdicts
STABLE, UNSTABLE, UNDECIDED = "stable", "unstable", "undecided"


@dataclass(frozen=True)
class LyapunovOptions:
    """How long and how finely :func:`torus_lyapunov` integrates.

    Parameters
    ----------
    count : int
        Leading exponents computed, >= 1 (at most the state's 2 n).
    periods : float
        Duration in periods of the slower base, 2 pi / min(w), > 0.
    substeps : int
        Steps per AFT grid interval along the faster-sampled angle: ``dt = min_i 2 pi / (N_i w_i) / substeps``
        (the resolution the torus was solved at), >= 1. Ignored when ``dt`` is given.
    dt : float, optional
        The step (s), > 0.
    blocks : int
        Blocks of time the duration is split into, >= 3 (the first discarded).
    margin : float
        Errors by which the largest exponent must clear zero for a verdict, > 0.
    seed : int
        Seed of the random start of the perturbations.
    progress : bool, optional
        A progress bar of the steps (:func:`rotorred.progress.bar`: None, on a terminal when shown).
    """

    count: int = 2
    periods: float = 100.0
    substeps: int = 2
    dt: float | None = None
    blocks: int = 8
    margin: float = 3.0
    seed: int = 0
    progress: bool | None = None

    def __post_init__(self):
        checks.integer("options.count", self.count, ge=1)
        checks.positive("options.periods", self.periods)
        checks.integer("options.substeps", self.substeps, ge=1)
        if self.dt is not None:
            checks.positive("options.dt", self.dt, "s")
        checks.integer("options.blocks", self.blocks, ge=3)
        checks.positive("options.margin", self.margin)
        checks.integer("options.seed", self.seed, ge=0)


@dataclass(frozen=True, repr=False)
class TorusStability(Result):
    """The leading Lyapunov exponents of a torus and the verdict they give.

    Attributes
    ----------
    exponents : ndarray, shape (p,)
        The exponents (1/s), largest first.
    errors : ndarray, shape (p,)
        Their errors (1/s): the range of the block averages' residuals from the fitted line over the span of the
        blocks' centres, plus the change of the exponent at twice the step.
    blocks : ndarray, shape (b, p)
        Each block's exponents, its growth over the block's length (1/s); the first block (the alignment) is not in
        the fit.
    block_times : ndarray, shape (b,)
        The end of each block (s).
    verdict : str
        ``"stable"``, ``"unstable"`` or ``"undecided"``.
    margin : float
        Errors by which the largest exponent cleared zero for the verdict.
    dt : float
        The step (s).
    steps, contact_steps : int
        Steps in all, and those where a force's derivative was not zero (each its own exponential).
    elapsed : float
        Wall time (s).
    """

    exponents: np.ndarray
    errors: np.ndarray
    blocks: np.ndarray
    block_times: np.ndarray
    verdict: str
    margin: float
    dt: float
    steps: int
    contact_steps: int
    elapsed: float

    @property
    def largest(self) -> float:
        """The largest exponent (1/s): > 0 unstable."""
        return float(self.exponents[0])

    @property
    def stable(self) -> bool | None:
        """True, False, or None where undecided."""
        return {STABLE: True, UNSTABLE: False}.get(self.verdict)

    @property
    def duration(self) -> float:
        """The integrated time (s)."""
        return float(self.block_times[-1])

    def summary(self) -> list[str]:
        """The verdict, the leading exponents with their errors, and the integration."""
        shown = ", ".join(f"{e:.5g} ± {s:.2g}" for e, s in zip(self.exponents[:4], self.errors[:4]))
        return [f"{self.verdict}: largest Lyapunov exponent {self.largest:.5g} ± {self.errors[0]:.2g} 1/s "
                f"(verdict at {self.margin:g} errors)",
                f"leading exponents (1/s): {shown}",
                f"{self.steps} steps of {self.dt:.3g} s over {self.duration:.4g} s ({self.contact_steps} with the "
                f"forces' derivatives), {len(self.block_times)} blocks; {self.elapsed:.3g} s"]

    def plot(self, ax=None, *, title: str | None = None):
        """Each block's exponents against the block's end time (1/s), the fitted exponents dashed, zero solid.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        title : str, optional

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.axes import axes

        fig, ax = axes(ax)
        for j in range(self.blocks.shape[1]):
            line, = ax.plot(self.block_times, self.blocks[:, j], "o-", label=f"λ{j + 1} = {self.exponents[j]:.4g}")
            ax.axhline(self.exponents[j], color=line.get_color(), ls="--", lw=0.8)
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xlabel("end of block (s)")
        ax.set_ylabel("block's Lyapunov exponent (1/s)")
        ax.set_title(title or f"torus {self.verdict}")
        ax.legend(fontsize="small")
        return fig

    def to_xarray(self):
        """Dims exponent, block: ``exponent`` and ``error`` (1/s), ``block_exponent`` (1/s) and ``block_time`` (s);
        the verdict, step and counts as attributes."""
        import xarray as xr

        return xr.Dataset(
            {"exponent": ("exponent", self.exponents, {"units": "1/s", "long_name": "Lyapunov exponent"}),
             "error": ("exponent", self.errors, {"units": "1/s", "long_name": "error bound"}),
             "block_exponent": (("block", "exponent"), self.blocks, {"units": "1/s",
                                                                     "long_name": "exponent over each block"}),
             "block_time": ("block", self.block_times, {"units": "s", "long_name": "end of each block"})},
            attrs={"verdict": self.verdict, "margin": self.margin, "dt": self.dt, "steps": self.steps,
                   "contact_steps": self.contact_steps})


def torus_trajectory(problem, z: np.ndarray, t: np.ndarray, dofs: str = "unknowns") -> tuple[np.ndarray, np.ndarray]:
    """The torus's displacements and velocities at times ``t``, read along ``theta = w t``.

    The phase origin is t = 0, the forcing's: ``q(t) = sum_k Re(Q_k exp(i k·w t))``.

    Parameters
    ----------
    problem : TorusProblem
    z : ndarray, shape (problem.size,)
        The torus's harmonic-major coefficients of the problem's ``dofs`` (m; rad for a rotation DOF).
    t : ndarray, shape (m,)
        Times (s).
    dofs : {"unknowns", "all"}
        The problem's ``dofs`` (the unknowns), or every DOF of ``M`` (recovered through the compliance).

    Returns
    -------
    q, v : ndarray, shape (m, len(dofs)) or (m, n_all)
        (m) and (m/s).
    """
    if dofs not in ("unknowns", "all"):
        checks.fail("dofs", dofs, "must be 'unknowns' or 'all'")
    h = problem.harmonics
    Q = h.phasors(z, problem.n) if dofs == "unknowns" else problem.recover(z)
    return _series(h, Q, problem.w)(t)


def _series(harmonics, Q: np.ndarray, w):
    """``t -> (q, dq/dt)`` along the torus of amplitudes Q (K, p): one :class:`rotorred.nonlinear.torus.TorusSeries`
    of Q and of its rates ``i (k . w) Q``, shape (len(t), p) each."""
    p = Q.shape[1]
    series = TorusSeries(harmonics.orders, np.hstack([Q, 1j * harmonics.frequencies(w)[:, None] * Q]), w)

    def along(t):
        x = series(t)
        return x[:, :p], x[:, p:]
    return along


def _step(problem, options: LyapunovOptions) -> float:
    """The step: ``options.dt``, or the AFT grid's interval along the faster-sampled angle over ``substeps``."""
    if options.dt is not None:
        return options.dt
    h, w = problem.harmonics, problem.w
    return min(2 * math.pi / (h.N1 * w[0]), 2 * math.pi / (h.N2 * w[1])) / options.substeps


def _state_matrix(problem) -> tuple[np.ndarray, np.ndarray]:
    """The linear state matrix [[0, I], [-M^-1 K, -M^-1 D]] and M^-1's columns of the unknowns."""
    n = problem.M.shape[0]
    Minv = sla.inv(problem.M)
    A0 = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ problem.K, -Minv @ problem.D]])
    return A0, Minv[:, list(problem.dofs)]


def torus_lyapunov(problem, z: np.ndarray, options: LyapunovOptions = LyapunovOptions()) -> TorusStability:
    """The leading Lyapunov exponents of the torus ``z`` of ``problem`` and its stability (module docstring,
    docs/model.md §27): the variational equation along the torus integrated by midpoint matrix exponentials with QR
    re-orthonormalisation, from ``t = 0``.

    Parameters
    ----------
    problem : TorusProblem
        The torus's problem (its matrices, bases, forces and unknowns).
    z : ndarray, shape (problem.size,)
        The torus's harmonic-major coefficients (a :class:`TorusSolution`'s ``z``) (m; rad for a rotation DOF).
    options : LyapunovOptions
        How many exponents, the duration, the step, the blocks and the verdict's margin.

    Returns
    -------
    TorusStability

    Raises
    ------
    rotorred.checks.InputError
        If ``z`` is not of the problem's size, or ``options.count`` exceeds the state's size.
    """
    z = checks.array("z", z, (problem.size,))
    if not isinstance(options, LyapunovOptions):
        checks.fail("options", type(options).__name__, "must be a LyapunovOptions")
    A0, lower = _state_matrix(problem)
    m = A0.shape[0]
    if options.count > m:
        checks.fail("options.count", options.count, f"must be at most the state's size 2 n = {m}")
    started = time.perf_counter()
    dt = _step(problem, options)
    per_block = 2 * max(1, math.ceil(options.periods * math.pi / min(problem.w) / dt / options.blocks))  # even
    Y0 = np.linalg.qr(np.random.default_rng(options.seed).standard_normal((m, options.count)))[0]
    torus = (A0, lower, _series(problem.harmonics, problem.harmonics.phasors(z, problem.n), problem.w),
             local_forces(problem.forces, problem.dofs))
    T_block = per_block * dt
    with feedback.bar(1.5 * per_block * options.blocks, "torus stability", "step", progress=options.progress,
                      delay=1.0) as bar:
        means, logs, contact_steps = _integrate(problem, torus, Y0, dt, (per_block, options.blocks), bar)
        exponents, bound = _slope(means, T_block)
        coarse = _slope(_integrate(problem, torus, Y0, 2 * dt, (per_block // 2, options.blocks), bar)[0], T_block)[0]
    errors = bound + np.abs(exponents - coarse)
    return TorusStability(exponents, errors, logs / T_block, T_block * np.arange(1, options.blocks + 1),
                          _verdict(exponents[0], errors[0], options.margin), options.margin, dt,
                          per_block * options.blocks, contact_steps, time.perf_counter() - started)


def _integrate(problem, torus, Y, dt, layout: tuple[int, int], bar):
    """Carry the perturbations ``Y`` through ``blocks`` blocks of ``per_block`` steps (``layout``) of ``dt`` (s), a
    QR after each product (a step, or a stretch of steps without a force derivative: :func:`_products`), the steps
    counted on ``bar``. Returns the time average over each block of the summed logarithms of R's diagonal, their
    growth in each block, shape (blocks, p) each, and the count of steps with a force derivative."""
    per_block, blocks = layout
    A0, lower, series, forces = torus
    p = Y.shape[1]
    S, means, logs, contact_steps = np.zeros(p), np.zeros((blocks, p)), np.zeros((blocks, p)), 0
    free, n_steps = {}, per_block * blocks
    longest = max(1, int(2 * math.pi / (SAMPLES * max(problem.w) * dt)))
    for lo in range(0, n_steps, CHUNK):
        products, active = _products(problem, A0, lower, (series, forces), dt,
                                     (lo, min(n_steps, lo + CHUNK), per_block), longest, free)
        contact_steps += active
        for block, Phi, steps in products:
            Y, R = np.linalg.qr(Phi @ Y)
            growth = np.log(np.abs(np.diag(R)))
            means[block] += (S + 0.5 * growth) * (steps / per_block)
            S += growth
            logs[block] += growth
        bar.update(min(n_steps, lo + CHUNK) - lo)
    return means, logs, contact_steps


def _products(problem, A0, lower, torus, dt, steps, longest: int, free):
    """The transition matrices of the steps ``lo <= j < hi`` in order, each with the block of its last step and its
    count of steps: the exponential of the state matrix at the step's midpoint where a force's derivative is not zero
    (batched), and one exponential of the linear state matrix for each stretch of steps without (cached by its length
    in ``free``), a stretch cut at the blocks' ends and after ``longest`` steps. Returns the list of
    ``(block, Phi, steps)`` and the count of steps with a derivative."""
    (series, forces), (lo, hi, per_block) = torus, steps
    n, c = problem.M.shape[0], list(problem.dofs)
    q, v = series((np.arange(lo, hi) + 0.5) * dt)
    _, dq, dv = sampled_forces(forces, q, v)
    k = hi - lo
    active = np.any(dq.reshape(k, -1) != 0.0, axis=1) | np.any(dv.reshape(k, -1) != 0.0, axis=1)
    where = np.flatnonzero(active)
    A = np.repeat(A0[None], where.size, axis=0)
    A[:, n:, c] -= lower @ dq[where]
    A[:, n:, [n + i for i in c]] -= lower @ dv[where]
    E = iter(sla.expm(A * dt)) if where.size else iter(())
    out, run = [], 0
    for j in range(lo, hi):
        block = j // per_block
        if active[j - lo]:
            out.append((block, next(E), 1))
        else:
            run += 1
        if run and (run == longest or (j + 1) % per_block == 0 or j + 1 == hi or active[min(j + 1, hi - 1) - lo]):
            if run not in free:
                free[run] = sla.expm(A0 * (run * dt))
            out.append((block, free[run], run))
            run = 0
    return out, int(where.size)


def _slope(means: np.ndarray, T_block: float) -> tuple[np.ndarray, np.ndarray]:
    """The growth rate of the summed logarithms: the least-squares slope of their block averages against the blocks'
    centres, the first block (the alignment) left out, and its error bound: the residuals' range over the centres'
    span (the steepest slope the wobble the line leaves could fake), per exponent. Averaging over a block removes most
    of the bounded quasi-periodic wobble of log |y| that a difference of end values keeps."""
    centres = T_block * (np.arange(1, means.shape[0]) + 0.5)
    slope, intercept = np.polyfit(centres, means[1:], 1)
    residuals = means[1:] - (np.outer(centres, slope) + intercept)
    return slope, np.ptp(residuals, axis=0) / (centres[-1] - centres[0])


def _verdict(largest: float, error: float, margin: float) -> str:
    """Stable below ``-margin`` errors, unstable above ``+margin``, else undecided."""
    if largest < -margin * error:
        return STABLE
    if largest > margin * error:
        return UNSTABLE
    return UNDECIDED
