"""Pseudo-arclength continuation of periodic solutions in the response frequency omega, with folds located.

The branch is a curve ``y(s) = (z(s), omega(s))`` with ``R(z, omega) = 0`` (:mod:`rotorred.nonlinear.hb`).
From a point and its unit tangent ``t`` (the null vector of ``[dR/dz, dR/domega]``, oriented along the previous one),
the predictor steps ``ds`` along the tangent, or with ``curved`` along the branch to second order,
``y + ds t + ds^2 / 2 kappa`` (``kappa`` the change of ``t`` from the previous point over the chord); the corrector is
Newton's method on ``R = 0`` together with ``t . (y - y_pred) = 0`` (the plane through the prediction, normal to the
tangent), each step shortened until it lowers the residual. Step control: ``ds`` grows by :data:`GROWTH` (1.5) after
a correction of at most :data:`GROW_ITERATIONS` (4) iterations, up to ``ds_max``; a failed correction, or one that
jumps (the point more than 2 ds away), halves it and retries from the same point, down to ``ds_min``, where the branch
stops and says where and why; a branch that comes back onto its own path, or goes back along it, stops there
(:func:`_retraced`).

A *fold* (turning point, saddle-node) is where ``d omega / ds`` changes sign between two points: it is
located by Brent's method on ``d omega / ds`` along the arclength between them, each evaluation a corrected
point, to the larger of ``1e-10`` and the corrector's tolerance of the step (a looser corrector, a torus's inexact
Newton, leaves ``d omega / ds`` that uncertain: Brent would spend its evaluations on noise). Each point's stability is Hill's (:mod:`rotorred.nonlinear.stability`).

An *interrupt* (:data:`INTERRUPTS`, or the exceptions a caller names: the command line's SIGTERM) ends the tracing
where it is: the points so far are returned, ``stopped`` and ``interrupt`` saying so.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
import scipy.linalg as sla
from scipy.optimize import brentq

from rotorred import checks
from rotorred.progress import INTERRUPTS, interrupt_name
from rotorred.nonlinear.fourier import to_phasors
from rotorred.nonlinear.hb import NotConverged, PeriodicProblem, coefficient_variables, solve_periodic
from rotorred.nonlinear.lowrank import bordered
from rotorred.nonlinear.stability import floquet
from rotorred.results import Result

__all__ = ["Fold", "Branch", "ContinuationOptions", "STABILITY_FLAGS", "continue_branch", "parameter_of",
           "stability_variable"]

#: a point's stability as a NetCDF flag (CF flag_values, flag_meanings: the variable ``stable``,
#: :func:`stability_variable`)
STABILITY_FLAGS = MappingProxyType({1: "stable", 0: "unstable", -1: "unknown"})
#: a corrected point farther than this many steps ds from the last has left the branch for another part of the
#: curve: the step is halved instead
MAX_JUMP = 2.0
#: step control: ds grows by this factor after a correction of at most :data:`GROW_ITERATIONS` Newton iterations (up
#: to ds_max), is kept after a longer one and halved after a failed one. *Choice*: on the rig's torus branches
#: (docs/model.md §26, ``validation/hb_torus_step_rule.py``) a gentler growth fails fewer steps but, on the
#: outer-speed branch, resolves the thin resonance tongues of the box's orders in many more points
GROWTH = 1.5
GROW_ITERATIONS = 4
#: the predictor is second order where the tangent turns by at most this (rad) over a step, first order beyond
MAX_TURN = 0.2
#: with ``curved``, a corrector iteration must leave at most this fraction of the last residual, else the step is
#: halved at once: where each correction costs much, a prediction Newton converges from contracts by 1e-2 or more an
#: iteration, and one that does not (a kink of the branch, where a contact starts or ends) is cheaper to retry shorter
#: than to iterate on. Not for the tangent predictor's branches: corrections at grazing that creep (0.99 an iteration)
#: and then converge take the 4-DOF branch of the tests past its corner
CONTRACTION = 0.5
#: Newton iterations, and step halvings in each, that a step in omega alone gets at a corner: one that lands near
#: the branch converges in a few full steps; most candidates do not, and cost the continuation its time
CORNER_ITERATIONS = 12
CORNER_HALVINGS = 4
#: Brent's tolerance on a fold's position, a share of the step (at least the corrector's tolerance)
FOLD_XTOL = 1e-10
#: a fold interpolated without a solve (:func:`_interpolated_fold`) is a corner where the tangents either side of it
#: turn by more than this (rad): at a smooth fold traced in steps that follow its curvature they turn by little
CORNER_TURN = np.pi / 3
#: the points a stall is judged on (:class:`ContinuationOptions`'s ``stall``)
STALL_POINTS = 10
#: why a branch ends (:attr:`Branch.end`), each with its own words in :attr:`Branch.stopped`: the end reached, the
#: most points, a stall, the step below ds_min, a closed loop, back along its own path, back past the start, a signal
ENDS = ("reached", "max_points", "stalled", "ds_min", "closed loop", "went back", "past the start", "interrupted")


@dataclass(frozen=True)
class Fold:
    """Where the branch turns back in omega: a smooth fold (saddle-node, located by Brent on d omega / ds) or, with
    ``smooth`` False, a corner (a kink where a contact starts or ends), at the last point before the turn (the steps
    shrink onto a corner). The solution there, its frequency (rad/s; a family's carried parameter) and ``value``, the
    parameter in its own unit (``omega`` itself but for a family that carries it scaled: :func:`parameter_of`)."""

    omega: float
    z: np.ndarray
    value: float
    smooth: bool = True


@dataclass(frozen=True, repr=False)
class Branch(Result):
    """A branch of periodic solutions.

    Attributes
    ----------
    omega : ndarray, shape (p,)
        Response frequency of each point (rad/s), or the family's carried parameter (``problem.parameter``).
    z : ndarray, shape (p, (2H + 1) n)
        Fourier coefficients of each point (harmonic-major; m, rad for a rotation DOF).
    max_real : ndarray, shape (p,)
        Largest real part of the Floquet exponents (1/s), NaN where stability was not asked.
    folds : tuple of Fold
    stopped : str
        Why the continuation ended: "reached the end, omega = ...", or where and why it stopped early (in the
        problem's parameter: omega, or ``problem.parameter``).
    end : str
        The same as one of :data:`ENDS` (a caller's test: ``stopped``'s words are for people).
    iterations : ndarray, shape (p,)
        Corrector iterations of each point.
    slope : ndarray, shape (p,)
        d omega / ds of the unit tangent at each point: its sign says which way the branch runs in omega (it
        changes at the folds).
    interrupt : str
        The signal that ended the tracing ("SIGINT", ... : :data:`INTERRUPTS`), or "" when nothing interrupted it.
    n : int
        The unknown DOFs a harmonic.
    parameter : (str, str)
        The continuation parameter's name and unit: ("omega", "rad/s"), or the family's (:func:`parameter_of`).
    values : ndarray, shape (p,)
        The parameter at each point, in its unit (``omega`` itself but for a family that carries it scaled).
    """

    omega: np.ndarray
    z: np.ndarray
    max_real: np.ndarray
    folds: tuple[Fold, ...]
    stopped: str
    end: str
    iterations: np.ndarray
    slope: np.ndarray
    interrupt: str
    n: int
    parameter: tuple[str, str]
    values: np.ndarray

    def __post_init__(self):
        checks.choice("end", self.end, ENDS)

    @property
    def stable(self) -> np.ndarray:
        """Whether each point is stable (False where stability was not computed)."""
        return self.max_real < 0.0

    @property
    def known(self) -> np.ndarray:
        """Whether each point's stability was computed."""
        return ~np.isnan(self.max_real)

    @property
    def H(self) -> int:
        """The highest harmonic."""
        return (self.z.shape[1] // self.n - 1) // 2

    @property
    def phasors(self) -> np.ndarray:
        """Complex amplitudes ``Q_k = a_k - i b_k`` (``Q_0 = a_0``) of each point, harmonic k and DOF, shape
        (p, H + 1, n) (:func:`rotorred.nonlinear.fourier.to_phasors`)."""
        return np.array([to_phasors(zi.reshape(-1, self.n)) for zi in self.z])

    def amplitude(self, dof: int, order: int = 1) -> np.ndarray:
        """The amplitude sqrt(a^2 + b^2) of harmonic ``order`` (``|a_0|`` for 0) of the unknown ``dof`` at each point.

        Parameters
        ----------
        dof : int
            Position of the DOF among the unknowns, 0 to n - 1.
        order : int
            The harmonic k, 0 to H.

        Returns
        -------
        ndarray, shape (p,)
            (m; rad for a rotation DOF).
        """
        n = self.n
        if order == 0:
            return np.abs(self.z[:, dof])
        a, b = self.z[:, (2 * order - 1) * n + dof], self.z[:, 2 * order * n + dof]
        return np.hypot(a, b)

    def summary(self) -> list[str]:
        """The parameter's range, the size, the turns, the stability, the largest amplitude and why it stopped."""
        name, unit = self.parameter
        p, k = len(self.values), int(np.count_nonzero(self.known))
        folds = [f"{f.value:.6g}{'' if f.smooth else ' (corner)'}" for f in self.folds]
        shown = ", ".join(folds[:4]) + (f" and {len(folds) - 4} more" if len(folds) > 4 else "")
        stability = (f"{int(np.count_nonzero(self.stable))} of {p} points stable" if k == p else
                     "stability not computed" if k == 0 else f"stability computed for {k} of {p} points")
        return [f"harmonic-balance branch in {name} ({unit}): {p} points from {self.values[0]:.6g} to "
                f"{self.values[-1]:.6g}; {self.n} DOFs, {self.H} harmonics",
                f"turns: {len(folds)}" + (f", at {name} = {shown}" if folds else ""),
                f"{stability}; largest amplitude of harmonic 1: {np.abs(self.phasors[:, 1]).max():.4g} m",
                *textwrap.wrap(f"stopped: {self.stopped}", 110)]

    def plot(self, ax=None, *, dof: int = 0, order: int = 1, title: str | None = None):
        """The amplitude of harmonic ``order`` of the unknown ``dof`` (µm) against the parameter: stable solid, unstable
        dashed, stability not computed grey, folds and corners marked (:func:`rotorred.plots.branch.plot_branch`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        dof : int
            Position of the DOF among the unknowns, 0 to n - 1.
        order : int
            The harmonic k, 0 to H.
        title : str, optional
            The figure's title.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.branch import plot_branch

        name, unit = self.parameter
        stable = None if not self.known.any() else np.where(self.known, self.stable, np.nan)
        return plot_branch(self.values, self.amplitude(dof, order), stable, [(f.value, f.smooth) for f in self.folds],
                           ax, xlabel=f"{name} ({unit})", ylabel=f"amplitude of harmonic {order} of DOF {dof} (µm)",
                           title=title)

    def to_xarray(self):
        """Dims point, harmonic, dof, fold: the ``parameter`` (its own unit) of each point; ``cos`` a_k, ``sin`` b_k
        and ``amplitude`` (m) of each point, harmonic and DOF; ``max_real`` (1/s), ``stable`` (1, 0; -1 not computed),
        ``iterations``, ``slope``; the folds' ``fold_parameter`` and ``fold_smooth``; ``stopped`` and ``interrupt`` as
        attributes."""
        import xarray as xr

        name, unit = self.parameter
        return xr.Dataset(
            {**coefficient_variables(self.phasors, ("point", "harmonic", "dof")),
             "max_real": ("point", self.max_real, {"units": "s-1", "long_name": "largest real part of the Floquet "
                                                   "exponents (NaN: not computed)"}),
             "stable": stability_variable(self.stable, self.known),
             "iterations": ("point", self.iterations, {"units": "1", "long_name": "corrector iterations"}),
             "slope": ("point", self.slope, {"units": "1", "long_name": "d parameter / ds of the unit tangent"}),
             "fold_parameter": ("fold", np.array([f.value for f in self.folds], float),
                                {"units": _cf(unit), "long_name": f"{name} at each turn"}),
             "fold_smooth": ("fold", np.array([f.smooth for f in self.folds], np.int8),
                             {"units": "1", "long_name": "1: a smooth fold, 0: a corner"})},
            coords={"parameter": ("point", self.values, {"units": _cf(unit), "long_name": name}),
                    "harmonic": ("harmonic", np.arange(self.H + 1), {"units": "1", "long_name": "harmonic k"}),
                    "dof": ("dof", np.arange(self.n), {"units": "1", "long_name": "unknown DOF"})},
            attrs={"stopped": self.stopped, "end": self.end, "interrupt": self.interrupt or "no"})


def stability_variable(stable: np.ndarray, known: np.ndarray) -> tuple:
    """The dataset variable ``stable`` of a branch's points (dim point): each point's :data:`STABILITY_FLAGS` value, 1
    stable, 0 unstable, -1 where ``known`` is False (not computed), int8, with its CF flag attributes."""
    flags = np.where(known, np.asarray(stable).astype(np.int8), np.int8(-1)).astype(np.int8)
    return ("point", flags, {"units": "1", "long_name": "stability of the point (-1: not computed)",
                             "flag_values": np.array(list(STABILITY_FLAGS), np.int8),
                             "flag_meanings": " ".join(STABILITY_FLAGS.values())})


def _cf(unit: str) -> str:
    """CF units of a parameter's unit: "1" for a dimensionless one ("-")."""
    return "1" if unit in ("", "-") else unit


@dataclass
class _Point:
    y: np.ndarray  # (z, omega)
    t: np.ndarray  # unit tangent
    iterations: int
    clean: bool = False  # reached by an arclength step at its first try (no halving): the branch is smooth there
    corner: float = 0.0  # reached by a step in omega alone past a corner: that step (signed), else 0


@dataclass(frozen=True)
class ContinuationOptions:
    """The steps, accuracy and extent of a branch (:func:`continue_branch`).

    Parameters
    ----------
    ds, ds_min, ds_max : float
        Initial, least and largest arclength step (in the units of (z, omega)), 0 < ds_min <= ds <= ds_max.
    max_points : int
        Most points traced, >= 2.
    tol : float
        Relative residual of every point (:func:`rotorred.nonlinear.hb.solve_periodic`), > 0 (-).
    stability : bool
        Compute each point's Floquet exponents (Hill's method).
    curved : bool
        Predict to second order where the branch is smooth (:func:`_arclength`): fewer corrector iterations a point
        where each costs much (the rig's condensed problem: 2 in place of 3). Off by default: on a small problem with
        kinks it lets the steps grow past what the kinks allow (the Jeffcott rotor at H = 10, N = 1024 then jumped
        from the free branch above resonance to the one below, at ds_max = 0.5, and traced its loop twice).
    fold_refine : bool
        Locate each fold by Brent on d omega / ds (default: each evaluation a corrected point and a tangent, to
        :data:`FOLD_XTOL` of the step). False: the fold is the turn of the cubic Hermite curve through the two points
        either side of it and their tangents, without a solve (:func:`_interpolated_fold`), for a problem whose
        corrections are costly (a torus); a corner where the tangents turn by more than :data:`CORNER_TURN`.
    stall : float, optional
        A branch whose last :data:`STALL_POINTS` points lie within this share of their omega (> 0) and together moved
        less than the first step ``ds`` along it ends there, saying so: its steps crawl through corners, each point at
        the step control's greatest cost (its halvings, then a step in omega alone). None (default): no such end.
    """

    ds: float = 0.05
    ds_min: float = 1e-6
    ds_max: float = 0.2
    max_points: int = 5000
    tol: float = 1e-10
    stability: bool = True
    curved: bool = False
    fold_refine: bool = True
    stall: float | None = None

    def __post_init__(self):
        checks.positive("ds_min", self.ds_min)
        checks.number("ds", self.ds, ge=self.ds_min)
        checks.number("ds_max", self.ds_max, ge=self.ds)
        checks.integer("max_points", self.max_points, ge=2)
        checks.positive("tol", self.tol)
        checks.boolean("stability", self.stability)
        checks.boolean("curved", self.curved)
        checks.boolean("fold_refine", self.fold_refine)
        if self.stall is not None:
            checks.positive("stall", self.stall)


def continue_branch(problem: PeriodicProblem, z0: np.ndarray, omega_start: float, omega_end: float,
                    options: ContinuationOptions = ContinuationOptions(), *, progress=None,
                    interrupts: Mapping[type[BaseException], str] = INTERRUPTS) -> Branch:
    """Follow the branch through ``z0`` at ``omega_start`` until omega passes ``omega_end`` (either direction).

    Parameters
    ----------
    problem : PeriodicProblem
    z0 : ndarray, shape (problem.size,)
        A start for the first point (e.g. the linear response; m, rad for a rotation DOF).
    omega_start, omega_end : float
        Response frequencies (rad/s), > 0.
    options : ContinuationOptions
        Steps, tolerance, stability, the most points and the predictor.
    progress : callable, optional
        ``progress(points, omega)`` after each point.
    interrupts : mapping of exception type to str
        The exceptions that end the branch where it is, and the signal each stands for (default SIGINT's
        ``KeyboardInterrupt``; empty: none, they propagate): the points so far are returned, ``stopped`` and
        ``interrupt`` saying so.

    Returns
    -------
    Branch

    Raises
    ------
    InputError
        If ``options`` is not a ContinuationOptions, or ``omega_start`` or ``omega_end`` is not > 0.
    NotConverged
        If the first point does not converge (a later point that does not ends the branch instead).
    """
    if not isinstance(options, ContinuationOptions):
        checks.fail("options", type(options).__name__, "must be a ContinuationOptions")
    o = options
    ds, ds_min, ds_max, max_points, tol, stability, curved = (o.ds, o.ds_min, o.ds_max, o.max_points, o.tol,
                                                             o.stability, o.curved)
    checks.positive("omega_start", omega_start, "rad/s")
    checks.positive("omega_end", omega_end, "rad/s")
    direction = 1.0 if omega_end > omega_start else -1.0
    start = _solved(problem, z0, omega_start, tol)
    y = np.append(start.z, omega_start)
    first = _Point(y, _tangent(problem, y, None, direction, start.evaluation), start.iterations)
    points, folds = [first], []
    path = np.empty((max_points, len(first.y)))  # the points' y, for the check that the branch is not retracing itself
    path[0], chords = first.y, np.empty(max_points)  # and the chord from each point to the next
    try:  # the whole loop: an interrupt anywhere in it leaves ``points`` whole
        end, stopped = _trace(problem, points, folds, path, chords, direction, omega_start, omega_end, ds, ds_min,
                              ds_max, max_points, tol, progress, curved, o.fold_refine, o.stall)
        interrupt = ""
    except tuple(interrupts) as exc:
        interrupt, end = interrupt_name(exc, interrupts), "interrupted"
        stopped = f"interrupted ({interrupt}) at {_at(problem, points[-1].y[-1])}, after {len(points)} points"
    return _branch(problem, points, folds, (end, stopped), stability, interrupt)


def _trace(problem, points, folds, path, chords, direction, omega_start, omega_end, ds, ds_min, ds_max, max_points,
           tol, progress, curved, fold_refine: bool = True, stall: float | None = None) -> tuple[str, str]:
    """Step from ``points[-1]`` on, appending to ``points`` and ``folds`` (``path`` and ``chords`` kept with them),
    until omega passes ``omega_end``: why it stopped, ``(end, words)`` (:data:`ENDS`)."""
    first_ds, found = ds, []  # found: the point each of ``folds`` was found before (its index in ``points``)
    while len(points) < max_points:
        if progress is not None:
            progress(len(points), points[-1].y[-1])
        nxt, ds, why = _step(problem, points[-1], points[-2] if len(points) > 1 else None, ds, ds_min, ds_max, tol,
                             curved)
        if nxt is not None and nxt.t[-1] * points[-1].t[-1] < 0.0:
            folds.append(_locate_fold(problem, points[-1], nxt, tol) if fold_refine else
                         _interpolated_fold(problem, points[-1], nxt))
            found.append(len(points))
        if nxt is None:
            return "ds_min", why
        points.append(nxt)
        if direction * (nxt.y[-1] - omega_end) >= 0.0:
            return "reached", f"reached the end, {_at(problem, omega_end)}"
        path[len(points) - 1] = nxt.y
        chords[len(points) - 2] = np.linalg.norm(nxt.y - points[-2].y)
        again = _retraced(path[:len(points)], chords[:len(points) - 1], nxt.t)
        if again is not None:
            j, same_way = again
            if same_way:
                return "closed loop", (f"the branch came back onto its own path at {_at(problem, nxt.y[-1])} "
                                       f"(traced before as points {j} to {j + 1} of {len(points)}): a closed loop, "
                                       f"followed once")
            # the points before the corners passed after segment j: where the path may have reversed onto it
            corners = [i - 1 for i, f in zip(found, folds[len(folds) - len(found):]) if not f.smooth and i - 1 > j + 1]
            traced = len(points)
            turn = _turned_back(path[:traced], chords[:traced - 1], np.array([p.t for p in points]), corners)
            del points[turn + 1:]  # the points after the turn are the traced part's again: not kept
            kept = sum(1 for i in found if i <= turn + 1)  # the turn's own fold (a corner) is the branch's
            del folds[len(folds) - len(found) + kept:]
            return "went back", (f"the branch went back along its own path after {_at(problem, points[-1].y[-1])}: it "
                                 f"turned back there onto the part it had traced, and the {traced - turn - 1} points "
                                 f"after the turn, traced the other way as points {j} to {j + 1} before, are not kept")
        if direction * (nxt.y[-1] - omega_start) < 0.0:
            return "past the start", (f"the branch turned back past the start, {_at(problem, omega_start)} (at "
                                      f"{_at(problem, nxt.y[-1])}, after {len(folds)} fold{'s' * (len(folds) != 1)})")
        if stall is not None and len(points) >= STALL_POINTS:
            why = _stalled(problem, path[len(points) - STALL_POINTS:len(points)],
                           chords[len(points) - STALL_POINTS:len(points) - 1], stall, first_ds)
            if why:
                return "stalled", why
    return "max_points", f"stopped at max_points = {max_points} ({_at(problem, points[-1].y[-1])})"


def _stalled(problem, Y: np.ndarray, chords: np.ndarray, share: float, ds: float) -> str:
    """Why the branch stalled at its last points ``Y`` (their chords ``chords``): within ``share`` of their omega and
    less than ``ds`` along it together; "" where it did not."""
    values = [_value(problem, s) for s in Y[:, -1]]
    span, moved = max(values) - min(values), float(np.sum(chords))
    if span > share * abs(values[-1]) or moved >= ds:
        return ""
    return (f"the branch stalled at {_at(problem, Y[-1, -1])}: its last {len(Y)} points lie within {span:.3g} "
            f"{parameter_of(problem)[1]} and moved {moved:.3g} along it together, less than its first step ds = "
            f"{ds:.3g}; start another branch past it")


def _retraced(Y: np.ndarray, chords: np.ndarray, t: np.ndarray) -> tuple[int, bool] | None:
    """``(j, same_way)``: the index j of an earlier segment [y_j, y_j+1] of the path ``Y`` (p, size + 1) that its last
    point lies on, going the same way or the other way along it (the unit tangent ``t`` there within about 18 degrees
    of the segment, or of its reverse), after a path of more than 20 times that segment or the last step since, or
    None: the branch retracing itself. ``chords`` (p - 1,) are the segments' lengths. On the segment means within a
    quarter of the larger of the segment and the last step (a chord leaves its arc by L^2 kappa / 8); the path since
    keeps the creeping steps at a corner, on one line, apart. A branch that closes on itself (an isola, or a corner
    that led back onto a part traced) would otherwise go round until max_points: the Jeffcott rotor with ds = 0.11
    went round its fold-corner loop 15 times. One that goes back along its path (a step past a corner that lands on
    the part just traced, going back: a solution curve does not cross itself, so it is that part) would trace it
    again: the rig's outer-speed torus branch down from 91.37 Hz turned at a corner near 91.05 Hz and went back up
    through three of its folds until it passed its start (docs/model.md §26).

    Only the segments whose parameter range comes within that distance of the last point's parameter are measured in
    full (a lower bound of the distance, O(p)): the check costs O(p), not O(p size), a point."""
    if len(Y) < 5:
        return None
    last, step, k = Y[-1], chords[-1], len(Y) - 4  # segments 0 .. k - 1: all but the last three
    scale = np.maximum(chords[:k], step)
    travelled = np.sum(chords) - np.cumsum(chords[:k])  # from each segment's end to the last point
    lo, hi = np.minimum(Y[:k, -1], Y[1:k + 1, -1]), np.maximum(Y[:k, -1], Y[1:k + 1, -1])
    j = np.flatnonzero((travelled > 20.0 * scale) & (last[-1] > lo - 0.25 * scale) & (last[-1] < hi + 0.25 * scale))
    on, along = _on_segments(Y, chords, last, step, t, j)
    return (int(j[on][0]), bool(along[on][0] > 0.0)) if np.any(on) else None


def _turned_back(Y: np.ndarray, chords: np.ndarray, T: np.ndarray, corners=()) -> int:
    """The index of the point where a path that went back along itself turned. From the last point back, each point
    that lies on a segment of the path before it going the other way (:func:`_on_segments`, with the points' unit
    tangents ``T`` (p, size + 1)) is the traced part's again; the first that does not ends the walk (a point going on,
    the way the path went, is never on a segment the other way). The turn is then the last of ``corners`` (the
    indices of the points before the corners the path passed after the segment it went back along) at or before that
    point, or that point where there is none: a path reverses onto itself only at a corner (a step that jumped: a
    solution curve neither crosses nor joins itself smoothly), and between the corner and the walk's end its points
    follow the traced part the other way, some farther from its chords than the walk's quarter of a chord (the rig's
    outer-speed branch, docs/model.md §15). ``Y`` (p, size + 1) the path's points, ``chords`` (p - 1,) its segments'
    lengths."""
    i = len(Y) - 1
    while i >= 2 and np.any(_on_segments(Y[:i], chords[:i - 1], Y[i], chords[i - 1], T[i], np.arange(i - 1), -1)[0]):
        i -= 1
    return max([c for c in corners if c <= i], default=i)


def _on_segments(Y: np.ndarray, chords: np.ndarray, last: np.ndarray, step: float, t: np.ndarray, j: np.ndarray,
                 way: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Which of the segments ``j`` of the path ``Y`` (their lengths ``chords[j]``) the point ``last``, reached by a
    step of length ``step`` with the unit tangent ``t``, lies on: within a quarter of the larger of the segment and the
    step (a chord leaves its arc by L^2 kappa / 8), the tangent within about 18 degrees of the segment (``way`` 1: the
    same way, -1: the other way, 0: either). Returns the mask over ``j`` and the segments' components along ``t``."""
    scale = np.maximum(chords[j], step)
    A, AB, length = Y[j], Y[j + 1] - Y[j], chords[j]
    u = np.clip(np.einsum("ij,ij->i", last - A, AB) / np.where(length > 0, length**2, 1.0), 0.0, 1.0)
    distance = np.linalg.norm(last - (A + u[:, None] * AB), axis=1)
    along = AB @ t
    aligned = np.abs(along) if way == 0 else way * along
    return (aligned > 0.95 * length) & (distance < 0.25 * scale), along


def parameter_of(problem) -> tuple[str, str]:
    """The name and unit of the parameter a problem is continued in: ("omega", "rad/s"), or a family's own
    (``problem.parameter``)."""
    return getattr(problem, "parameter", ("omega", "rad/s"))


def _value(problem, s: float) -> float:
    """The parameter's value in its own unit of the carried ``s``: ``s`` itself, or ``problem.parameter_value(s)``
    for a family that carries it scaled."""
    return float(getattr(problem, "parameter_value", lambda v: v)(s))


def _at(problem, value: float) -> str:
    """``omega = 62.8 rad/s``, or the problem's own parameter (:func:`parameter_of`; a scaled parameter is shown in its
    own unit, :func:`_value`)."""
    name, unit = parameter_of(problem)
    return f"{name} = {_value(problem, value):.9g} {unit}"


def _branch(problem, points, folds, ending: tuple[str, str], stability, interrupt="") -> Branch:
    y = np.array([p.y for p in points])
    omega, z = y[:, -1], y[:, :-1]
    max_real = np.array([floquet(problem, zi, wi).max_real for zi, wi in zip(z, omega)]) if stability \
        else np.full(len(points), np.nan)
    end, stopped = ending
    return Branch(omega, z, max_real, tuple(folds), stopped, end, np.array([p.iterations for p in points]),
                  np.array([p.t[-1] for p in points]), interrupt, problem.n, parameter_of(problem),
                  np.array([_value(problem, w) for w in omega]))


def _tangent(problem, y, previous, direction: float = 1.0, ev=None) -> np.ndarray:
    """The unit null vector of ``[dR/dz, dR/domega]`` at ``y`` (``ev``: its evaluation, if at hand), oriented along
    ``previous`` (or with omega growing in ``direction`` at the start)."""
    ev = ev if ev is not None else problem.evaluate(y[:-1], y[-1])
    guide = previous if previous is not None else np.append(np.zeros(len(y) - 1), direction)
    return _unit_along(_bordered(ev.dR_dz, ev.dR_domega, guide), guide)


def _bordered(A, column: np.ndarray, row: np.ndarray):
    """The bordered matrix ``[[A, column], [row]]``, ready to solve with: a Jacobian that borders itself (``A.bordered``:
    the torus's matrix-free one, :class:`rotorred.nonlinear.torus_continuation.TorusJacobian`, and the identity plus a
    low-rank product), else a dense one (:func:`rotorred.nonlinear.lowrank.bordered`)."""
    return A.bordered(column, row) if hasattr(A, "bordered") else bordered(A, column, row)


def _unit_along(matrix, guide: np.ndarray) -> np.ndarray:
    """The unit vector t solving ``matrix t = e_last`` for the factored bordered Jacobian ``[[dR/dz, dR/domega],
    [guide]]``, oriented along ``guide``: the tangent."""
    t = matrix.solve(np.append(np.zeros(len(guide) - 1), 1.0))
    t /= np.linalg.norm(t)
    return t if t @ guide > 0 else -t


def _correct(problem, y_pred, t, tol, max_iter: int = 20, contraction: float | None = None):
    """Newton on ``R(y) = 0`` and ``t . (y - y_pred) = 0``, each step shortened until it lowers the residual (a
    contact's kink at grazing makes full steps cycle): the corrected point, its iterations and its unit tangent, or
    None. An iterate's derivatives are built only if the iteration goes on from it (:class:`Evaluation`): the
    tangent is the one of the last Jacobian (the iterate a Newton step before, solved with its factors)."""
    y = y_pred.copy()
    ev = problem.evaluate(y[:-1], y[-1])
    if not np.isfinite(ev.relative):  # no problem there (a family's value refused): a failed step
        return None
    for it in range(max_iter):
        try:
            matrix = _bordered(ev.dR_dz, ev.dR_domega, t)
            step = matrix.solve(-np.append(ev.R, t @ (y - y_pred)))
        except (sla.LinAlgError, ValueError):
            return None
        before = ev.relative
        y, ev = _shortened(problem, y, step, ev)
        if ev is None or (contraction is not None and ev.relative > contraction * before):
            return None
        if ev.relative <= tol:
            return y, it + 1, _unit_along(matrix, t)
    return None


def _shortened(problem, y, step, ev, tries: int = 8):
    """``y + a step`` for the largest ``a`` in 1, 1/2, ... 1/128 that lowers ``||R||`` (omega kept > 0), and its
    evaluation (its derivatives built on first use); (y, None) if none does.

    Eight tries: a step that must be shortened further rarely converges, and the step control's halving of ds is
    the cheaper way on. On the Jeffcott branch (H = 5, N = 1024) 12 tries took 3719 evaluations, 48 of its 67
    searches past 8 tries failed all the same; 8 took 2550, for the same 334 points (and the rig's clearance branch
    the same 373)."""
    r0, a = np.linalg.norm(ev.R), 1.0
    for _ in range(tries):
        trial = y + a * step
        if trial[-1] > 0.0:
            ev_t = problem.evaluate(trial[:-1], trial[-1])
            if np.linalg.norm(ev_t.R) < r0 or ev_t.relative <= 1e-3 * ev.relative:
                return trial, ev_t
        a *= 0.5
    return y, None


def _step(problem, point: _Point, previous: _Point | None, ds, ds_min, ds_max, tol, curved: bool = False):
    """The next point from ``point`` with step control: (point, next ds, "") or (None, ds, why). After six
    halvings (or at ``ds_min``), a corner is tried once (:func:`_past_a_corner`), then the halving goes on down to
    ``ds_min``. (Trying a corner at the first failure was tried and taken back: in smooth stretches its steps in
    omega land on other parts of the branch.) A point itself reached past a corner tries the corner, its own step in
    omega first, after the first failure: where the branch goes on in corners, each point a step in omega alone (the
    rig's outer-speed torus branch down from 92.4 Hz past 91.503 Hz), the halvings and the search's failing candidates
    took 5 to 8 s a point."""
    first, cornered = ds, False
    while ds >= ds_min:
        smooth = curved and ds == first and point.clean and previous is not None  # a curvature to predict with
        done = _arclength(problem, point, previous if smooth else None, ds, tol, clean=ds == first,
                          contraction=CONTRACTION if curved else None)
        if done is not None:
            return done[0], (min(ds * GROWTH, ds_max) if done[1] <= GROW_ITERATIONS else ds), ""
        if not cornered and (ds <= first / 64 or ds / 2 < ds_min or point.corner):
            cornered = True
            corner = _past_a_corner(problem, point, previous, max(first, 64 * ds_min), tol, point.corner)
            if corner is not None:
                return corner, first, ""
        ds *= 0.5
    return None, ds, (f"the step fell below ds_min = {ds_min:g} at {_at(problem, point.y[-1])}: the corrector did "
                      f"not converge to a relative residual of {tol:g}, nor a step in omega alone")


def _arclength(problem, point: _Point, previous: _Point | None, ds, tol, clean: bool = False,
               contraction: float | None = None):
    """The corrected point ``ds`` along the branch, and its iterations, or None (not converged, or a jump).

    With a ``previous`` point the prediction is second order, ``y + ds t + ds^2 / 2 kappa``, with the curvature
    ``kappa`` the change of the unit tangent from the previous point over the chord between them, where it turns the
    tangent by at most :data:`MAX_TURN` over the step; else first order. Its error is O(ds^3) against the tangent's
    O(ds^2): on the rig's clearance branch most corrections take two Newton iterations in place of three
    (validation/hb_rig.py). :func:`_step` gives a previous point only where the branch is smooth (the last two steps
    taken at their first try): near a kink the curvature between points on either side means nothing, and a second
    order prediction there can land on the other side (the Jeffcott rotor's corner, where it then cycled)."""
    prediction = point.y + ds * point.t
    if previous is not None:
        kappa = (point.t - previous.t) / np.linalg.norm(point.y - previous.y)
        if ds * np.linalg.norm(kappa) <= MAX_TURN:
            prediction += 0.5 * ds**2 * kappa
    done = _correct(problem, prediction, point.t, tol, contraction=contraction)
    if done is None:
        return None
    y, it, t = done
    if np.linalg.norm(y - point.y) > MAX_JUMP * ds:
        return None
    return _Point(y, t, it, clean), it


def _past_a_corner(problem, point: _Point, previous: _Point | None, ds, tol, again: float = 0.0):
    """The next point past a corner of the branch, or None. Where a contact starts (grazing) the branch has a kink:
    it may turn by about a right angle, so the plane normal to the old tangent meets the new part far away, and the
    arclength corrector fails at every step. A step in omega alone (``ds``, ``ds``/4, ... down to ``ds`` 4^-8, the first
    that lands within ``MAX_JUMP ds``), in the direction omega was going, then the other, solved by Newton at that
    omega, gets past it, started from the corner's solution and from the linear response (the side without contact);
    the new tangent is oriented along the secant. A candidate back along the tangent (its
    secant within 26 degrees of the reversed tangent), or nearer to the previous point than the corner is, lies on
    the part just traced, and is passed over; so is one Newton took from the corner's own solution without an
    iteration at a step shorter than the first (the larger steps failed, so the solution moves there: the old one
    within the tolerance at a small step is the same point, no progress; on the rig's outer-speed torus branch such
    points went back and forth at 96.162 Hz until ``max_points``). At the first step it is a point: a flat branch.
    ``again``: the step in omega that reached ``point`` past a corner, tried first (where the branch goes on in
    corners, each step in omega alone, its arclength steps failing: :func:`_step` comes here after the first of
    them instead of six halvings)."""
    heading = np.sign(point.t[-1]) or 1.0
    steps = [(again, True)] if again else []  # (the step, shorter than the search's first)
    steps += [(sign * delta, k > 0) for sign in (heading, -heading)
              for k, delta in enumerate(ds * 0.25 ** np.arange(9))]  # a steep branch moves far for a small change
    for step, shorter in steps:
        omega = point.y[-1] + step
        if omega <= 0.0:
            continue
        for own, start in ((shorter, point.y[:-1]), (False, problem.linear_response(omega))):
            found = _candidate(problem, point, previous, start, omega, ds, tol, own)
            if found is not None:
                return found
    return None


def _solved(problem, z0, omega, tol, max_iter: int = 40, max_halvings: int = 30):
    """The solution at ``omega`` by Newton from ``z0``: the problem's own point solver where it has one
    (``problem.solve_point(z0, omega, tol, max_iter, max_halvings)``: a family of tori,
    :class:`rotorred.nonlinear.torus_continuation.TorusFamily`), else :func:`rotorred.nonlinear.hb.solve_periodic`.
    NotConverged if it does not converge."""
    own = getattr(problem, "solve_point", None)
    if own is not None:
        return own(z0, omega, tol, max_iter, max_halvings)
    return solve_periodic(problem, z0, omega, tol=tol, max_iter=max_iter, max_halvings=max_halvings)


def _candidate(problem, point: _Point, previous: _Point | None, start, omega, ds, tol, own: bool = False):
    """The solution at ``omega`` Newton reaches from ``start``, as the next point, unless it is too far, on the part
    just traced, or (``own``: ``start`` is the corner's solution, at a step shorter than the first) reached without an
    iteration."""
    try:
        found = _solved(problem, start, omega, tol, CORNER_ITERATIONS, CORNER_HALVINGS)
    except NotConverged:
        return None
    if own and found.iterations == 0:
        return None
    y = np.append(found.z, omega)
    secant = y - point.y
    traced = secant @ point.t < -0.9 * np.linalg.norm(secant) or (  # back along the tangent, or nearer to
        previous is not None and np.linalg.norm(y - previous.y) < np.linalg.norm(point.y - previous.y))
    if np.linalg.norm(secant) > MAX_JUMP * ds or traced:
        return None
    return _Point(y, _tangent(problem, y, secant, ev=found.evaluation), found.iterations, corner=omega - point.y[-1])


def _interpolated_fold(problem, a: _Point, b: _Point) -> Fold:
    """The fold between points ``a`` and ``b`` without a solve: where omega turns on the cubic Hermite curve
    ``y(u)``, u in [0, 1], through ``a.y`` and ``b.y`` with derivatives ``L a.t`` and ``L b.t`` (L the chord, the
    tangents oriented alike), its point there; a corner (at ``a``) where the tangents turn by more than
    :data:`CORNER_TURN`. Its error is the curve's, O(L^4) in omega (docs/model.md §26 gives it measured against
    Brent's)."""
    if a.t @ b.t < np.cos(CORNER_TURN):
        return Fold(float(a.y[-1]), a.y[:-1].copy(), _value(problem, a.y[-1]), smooth=False)
    chord = b.y - a.y
    L = np.linalg.norm(chord)
    A, B = L * a.t, L * b.t
    c2, c3 = 3.0 * chord - 2.0 * A - B, A + B - 2.0 * chord
    roots = np.roots([3.0 * c3[-1], 2.0 * c2[-1], A[-1]])  # (a zero leading coefficient: np.roots drops it)
    inside = [r.real for r in roots if abs(r.imag) <= 1e-12 and 0.0 <= r.real <= 1.0]
    u = min(inside, key=lambda r: abs(r - 0.5)) if inside else 0.5  # the sign change of A[-1] and B[-1]: one root
    y = a.y + A * u + c2 * u**2 + c3 * u**3
    return Fold(float(y[-1]), y[:-1].copy(), _value(problem, y[-1]))


def _locate_fold(problem, a: _Point, b: _Point, tol) -> Fold:
    """The fold between points ``a`` and ``b``: d omega/ds = 0, by Brent on the arclength from ``a``."""
    span = float((b.y - a.y) @ a.t)
    corrected = {}  # each arclength's corrected point: Brent's last is the fold, not corrected again

    def domega(s: float) -> float:
        if s == 0.0:
            return a.t[-1]
        done = _correct(problem, a.y + s * a.t, a.t, tol)
        if done is None:
            raise NotConverged(float(a.y[-1]), np.inf, tol, 20, "while locating a fold")
        corrected[s] = done[0]
        return _tangent(problem, done[0], a.t)[-1]  # at the point itself: the fold's position rests on it

    try:
        s = brentq(domega, 0.0, span, xtol=max(FOLD_XTOL, tol) * abs(span), rtol=4 * np.finfo(float).eps)
    except (ValueError, NotConverged):  # omega turned at a corner (a kink of the branch), not at a smooth fold
        return Fold(float(a.y[-1]), a.y[:-1].copy(), _value(problem, a.y[-1]), smooth=False)
    y = a.y if s == 0.0 else corrected[s] if s in corrected else _correct(problem, a.y + s * a.t, a.t, tol)[0]
    return Fold(float(y[-1]), y[:-1].copy(), _value(problem, y[-1]))
