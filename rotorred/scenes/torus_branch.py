"""Branches of a rub scene's quasi-periodic response: tori continued by pseudo-arclength in a scene key, their folds
located (docs/model.md §26).

Keys: ``rub.clearance`` (m) and the plate's numbers (:data:`rotorred.scenes.branch.PLATE_KEYS`), and ``speeds.<spool>``
(Hz): that spool's speed alone, every other spool held (the speed ratio is what moves: a torus has no ratio to keep,
unlike a periodic branch, :mod:`rotorred.scenes.branch`). The bases move with the speeds: ``(f_L / j, f_H / k)``,
``f_L`` and ``f_H`` the two turning spools' frequencies (slower first, at the start), the divisors ``(j, k)`` given or
read from the torus the start's line fit finds; each spool's unbalance forces its order, its force growing with its
speed squared.

The first point is :func:`rotorred.scenes.quasi_periodic.torus_balance` at the start (a short transient, the line
fit's torus, least squares, Newton). Every point keeps its orders: the box and band of the start's truncation (the band
``|k . f| <= f_max`` at the start's bases), so that the unknowns do not change along the branch; the problem at a value
is the start's with that value's forces where the matrices and bases stay (a clearance, a law's number), else
:func:`rotorred.scenes.torus_balance.torus_rub_problem_on` on those orders, each spool forcing the order it started on. The
continuation is :func:`rotorred.nonlinear.continuation.continue_branch` on a
:class:`rotorred.nonlinear.torus_continuation.TorusFamily` (matrix-free bordered solves, the preconditioner kept from
point to point, inexact Newton). No stability: that of a torus is another part of issue 40.
"""

from __future__ import annotations

import dataclasses
import textwrap
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from rotorred import checks
from rotorred.model.operating import Operating
from rotorred.nonlinear.continuation import ENDS, ContinuationOptions, continue_branch
from rotorred.nonlinear.hb import NotConverged
from rotorred.nonlinear.torus import TorusProblem, solve_torus
from rotorred.nonlinear.torus_continuation import TorusFamily
from rotorred.progress import INTERRUPTS
from rotorred.results import Result
from rotorred.scenes.branch import KEYS, PLATE_KEYS, dof_name
from rotorred.scenes.keys import cf_units, netcdf_name
from rotorred.scenes.quasi_periodic import TorusOptions, default_grid, torus_balance
from rotorred.scenes.harmonic_balance import augmented_matrices, plate_rubs
from rotorred.scenes.torus_balance import TorusRubProblem, torus_rub_problem, torus_rub_problem_on
from rotorred.transient.options import Loads
from rotorred.writers import signals_held

__all__ = ["TorusBranchOptions", "TorusBranch", "continue_torus", "check_torus_key"]

#: a speed's dR/dvalue is computed afresh where the speed moved by more than this share since it last was
#: (:class:`rotorred.nonlinear.torus_continuation.TorusFamily`): a point's corrections share one
FROZEN = 1e-3
#: the keys whose dR/dvalue the problem gives exactly (:class:`TorusFamily`'s ``derivative``; the others by the
#: difference of two residuals): the clearance (of the first plate, the key's, :func:`_scene_at`), a column of the
#: sampled Jacobian (docs/model.md §26)
DERIVATIVES = {"rub.clearance": lambda problem, z: problem.dR_dclearance(z, 0)}
#: lines of the output DOF a branch's summary and files show: the largest at the start
SHOWN_LINES = 10
#: the ladder of boxes a lines tolerance climbs (:class:`TorusBranchOptions`): each box's bounds times this
GROWTH = 1.5
#: with a lines tolerance, the box is checked at the start and each time the key passes a further this-th of its range
CHECKS = 8
#: the default box of orders and its grid: with the band of 900 Hz, 1799 orders on the rig's torus (f_L, f_H/3); the
#: grid 128 x 256 gives the lines of 128 x 1024 to 0.06 % (docs/model.md §26)
DEFAULT_ORDERS, DEFAULT_GRID = (32, 80), (128, 256)
#: a branch whose last 10 points lie within this share of their value and moved less than its first step together has
#: stalled and ends, saying where and, for a speed, which order of the box is nearest 0 Hz there
#: (:class:`rotorred.nonlinear.continuation.ContinuationOptions`'s ``stall``): its continuation crawls through
#: corners, each point at the step control's greatest cost. Down from 91.37 Hz the rig's outer-speed branch so ended at
#: 91.1423 Hz, its last 10 points within 0.66 mHz (7e-6 of the speed), the order (23, -53) of the box at -0.18 Hz
#: (docs/model.md §26). A physical branch is not that steep: a resonance of 1 % damping near 100 Hz is 2 Hz wide
STALL_SPAN = 1e-5
#: past a stall (:class:`TorusBranchOptions`'s ``past_stalls``): the first jump in the speed goes this share of it past
#: the nearest order's 0 Hz (past the stall, where that 0 Hz is behind it), then doubled, at most this many times
JUMP_MIN, JUMP_TRIES = 1e-4, 5
#: a stall is passed only where that order's 0 Hz is within this share of the speed (the rig's at 91.1423 Hz: 1.1e-4):
#: farther, it does not explain the stall, and the branch ends there
JUMP_NEAR = 1e-3
#: how a speed branch's segment ends where it cannot go on: it stalled (its steps crawling in corners), or its step
#: fell below ds_min (the corrector and the step in the speed alone failed at every step). Near an order's 0 Hz either
#: is passed alike (:class:`TorusBranchOptions`'s ``past_stalls``): the rig's branch up from 91.37 Hz stalled at
#: 91.4566 Hz in one run and failed there at ds_min in another, on another machine (docs/model.md §26)
STUCK = ("stalled", "ds_min")
#: Newton iterations a jump's solve gets: from the stall's solution, a torus past a thin resonance converges in a
#: few; one that does not is the next jump's
JUMP_ITERATIONS = 15


class _Check(Exception):
    """Ends a segment of a branch where its box is to be checked (:func:`continue_torus`)."""


@dataclass(frozen=True)
class TorusBranchOptions:
    """The truncation, start, accuracy and extent of a torus branch (:func:`continue_torus`).

    Parameters
    ----------
    orders : (int, int)
        The box of orders ``|k_1| <= H1``, ``|k_2| <= H2`` (default (32, 80): with the band of 900 Hz, the rig's
        lines within 0.5 % of settled transients from 20 to 5 µm of clearance, docs/model.md §26).
    grid : (int, int), optional
        The AFT grid ``(N_1, N_2)``; default :data:`DEFAULT_GRID` for the default orders, else
        :func:`rotorred.scenes.quasi_periodic.default_grid` of the orders.
    f_max : float, optional
        Keep only the orders whose line is at most ``f_max`` (Hz) at the start (default 900 Hz; None: the box).
    divisors : (int, int), optional
        ``(j, k)``: the bases ``(f_L / j, f_H / k)``; default those of the torus the start's line fit finds.
    start_window : (float, float)
        The start's transient window (s) (:class:`rotorred.scenes.quasi_periodic.TorusOptions`).
    tol : float
        Relative residual of every point, in (0, 1) (default 1e-6, ``rotorred continue --torus``'s: the branches of
        docs/model.md §26 were measured at it).
    max_points : int
        Most points traced, >= 2.
    steps : (float, float)
        The first and the largest arclength step, as shares of ``max(||z_start||, |s_end - s_start|)`` (the
        coefficients' norm and the carried parameter's range, m), 0 < first <= largest.
    lines_tol : float, optional
        The orders chosen by the tolerance along the branch: at the start and each time the key passes a further
        :data:`CHECKS`-th of its range, the box is checked against the next one of the ladder (bounds times
        :data:`GROWTH`, the grid the default's): while the :data:`SHOWN_LINES` largest lines of the output DOF change
        by more than ``lines_tol`` (relative, the largest), the branch goes on on the larger box. None (default): the
        box ``orders`` throughout.
    max_orders : (int, int)
        The largest box the ladder climbs to.
    fold_refine : bool
        Locate each fold by Brent, each evaluation a corrected point (as a periodic branch's); default False: the
        turn of the cubic Hermite curve through the points either side of it, without a solve
        (:class:`rotorred.nonlinear.continuation.ContinuationOptions`; its error on the rig in docs/model.md §26).
    past_stalls : bool
        Where a speed branch cannot go on (:data:`STUCK`: it stalls, or its step falls below ds_min) within
        :data:`JUMP_NEAR` of the speed from where an order of the box comes to 0 Hz, go on past that order by a jump
        (the stretch between a gap of the branch, :attr:`TorusBranch.gaps`); default True. False: the branch ends
        there, naming the order (``rotorred continue --torus --stop-at-stalls``).
    """

    orders: tuple[int, int] = DEFAULT_ORDERS
    grid: tuple[int, int] | None = None
    f_max: float | None = 900.0
    divisors: tuple[int, int] | None = None
    start_window: tuple[float, float] = (2.0, 3.0)
    tol: float = 1e-6
    max_points: int = 200
    steps: tuple[float, float] = (0.05, 0.15)
    lines_tol: float | None = None
    max_orders: tuple[int, int] = (72, 180)
    fold_refine: bool = False
    past_stalls: bool = True

    def __post_init__(self):
        # the orders, grid, band and window by TorusOptions's own checks
        self.torus_options(None, ())
        if self.divisors is not None:
            d = checks.sequence("options.divisors", list(np.ravel(self.divisors)), min_len=2, max_len=2)
            object.__setattr__(self, "divisors", tuple(checks.integer(f"options.divisors[{i}]", v, ge=1)
                                                       for i, v in enumerate(d)))
        checks.number("options.tol", self.tol, gt=0.0, lt=1.0)
        checks.integer("options.max_points", self.max_points, ge=2)
        s = checks.sequence("options.steps", list(np.ravel(self.steps)), min_len=2, max_len=2)
        first = checks.positive("options.steps[0]", s[0])
        object.__setattr__(self, "steps", (first, checks.number("options.steps[1]", s[1], ge=first)))
        if self.lines_tol is not None:
            checks.number("options.lines_tol", self.lines_tol, gt=0.0, lt=1.0)
        checks.boolean("options.fold_refine", self.fold_refine)
        checks.boolean("options.past_stalls", self.past_stalls)
        m = checks.sequence("options.max_orders", list(np.ravel(self.max_orders)), min_len=2, max_len=2)
        object.__setattr__(self, "max_orders", tuple(checks.integer(f"options.max_orders[{i}]", v, ge=1)
                                                     for i, v in enumerate(m)))

    def torus_options(self, bases, outputs) -> TorusOptions:
        """The start's :class:`rotorred.scenes.quasi_periodic.TorusOptions`.

        Parameters
        ----------
        bases : (float, float) or None
            The base frequencies (Hz), or None: found by the start's line fit.
        outputs : sequence of (int, str)
            The model DOFs reported.

        Returns
        -------
        TorusOptions
        """
        return TorusOptions(bases=bases, orders=self.orders, grid=self.n_grid, f_max=self.f_max,
                            start_window=self.start_window, tol=self.tol, outputs=outputs)

    @property
    def n_grid(self) -> tuple[int, int]:
        """``(N_1, N_2)``: the grid given, or the default of the orders (:attr:`grid`)."""
        if self.grid is not None:
            return self.grid
        return DEFAULT_GRID if tuple(self.orders) == DEFAULT_ORDERS else default_grid(*self.orders)


@dataclass(frozen=True, repr=False)
class TorusBranch(Result):
    """A branch of a rub scene's quasi-periodic response (:func:`continue_torus`).

    Attributes
    ----------
    scene : str
    key, unit : str
        The varied key and its unit (m for a clearance, Hz for a speed).
    values : ndarray, shape (p,)
        The key at each point.
    bases_hz : ndarray, shape (p, 2)
        The base frequencies ``(f_L / j, f_H / k)`` at each point (Hz).
    orders : ndarray, shape (K, 2)
        The orders ``(k_1, k_2)`` of every point's lines.
    dof : (int, str)
        The output DOF whose lines are kept (the scene's table DOF).
    amplitudes : ndarray, shape (p, K)
        Amplitude of each order's line at ``dof`` at each point (m; the mean's absolute value for (0, 0)).
    z : ndarray, shape (p, size)
        Each point's coefficients of the unknowns (:class:`rotorred.nonlinear.torus.TorusProblem`).
    folds : tuple of (float, bool)
        Each turn of the branch: the key's value and whether it is smooth (a saddle-node) or a corner.
    stopped : str
        Why the branch ended.
    iterations : ndarray, shape (p,)
        Corrector iterations of each point.
    point_time : ndarray, shape (p,)
        Wall time of each point (s): the first the start (its transient, line fit and Newton), each next its step
        (prediction, corrections, a fold's location).
    slope : ndarray, shape (p,)
        d value / ds of the unit tangent at each point (its sign changes at the folds).
    truncation : str
        The orders, grid and band.
    interrupt : str
        The signal that ended the branch, or "".
    gaps : tuple of (int, str)
        Each stretch of the key not traced (a stall passed, :class:`TorusBranchOptions`'s ``past_stalls``): the
        position of the first point after it, and why.
    end : str
        Why the branch ended as a code, one of :data:`rotorred.nonlinear.continuation.ENDS`: its last segment's, or
        "max_points" where the branch's most points ended it; keyword-only.
    """

    scene: str
    key: str
    unit: str
    values: np.ndarray
    bases_hz: np.ndarray
    orders: np.ndarray
    dof: tuple
    amplitudes: np.ndarray
    z: np.ndarray
    folds: tuple
    stopped: str
    iterations: np.ndarray
    point_time: np.ndarray
    slope: np.ndarray
    truncation: str
    interrupt: str = ""
    gaps: tuple = ()
    end: str = field(kw_only=True)

    def __post_init__(self):
        checks.choice("end", self.end, ENDS)

    @property
    def interrupted(self) -> bool:
        """Whether a signal ended the branch."""
        return bool(self.interrupt)

    @property
    def shown(self) -> tuple[float, str]:
        """The key's shown scale and unit: a clearance in µm, any other key in its own unit."""
        return (1e6, "µm") if self.key == "rub.clearance" else (1.0, self.unit)

    @property
    def frequencies(self) -> np.ndarray:
        """The frequency ``|k_1 f_1 + k_2 f_2|`` of each order's line at each point, shape (p, K) (Hz)."""
        return np.abs(self.bases_hz @ self.orders.T)

    @property
    def largest(self) -> np.ndarray:
        """The positions of the :data:`SHOWN_LINES` largest lines at the first point (the mean left out)."""
        a = self.amplitudes[0].copy()
        a[0] = -np.inf
        return np.argsort(-a)[:SHOWN_LINES]

    @property
    def not_traced(self) -> list[str]:
        """Each gap as a line: ``not traced: A to B (unit) (why)``, the key in its shown unit."""
        xs, xu = self.shown
        return [f"not traced: {xs * self.values[i - 1]:.6g} to {xs * self.values[i]:.6g} {xu} ({why})"
                for i, why in self.gaps]

    def line_label(self, k: int) -> str:
        """The order at position ``k`` as text, ``(k1,k2)``.

        Parameters
        ----------
        k : int
            Position in :attr:`orders`.

        Returns
        -------
        str
        """
        return f"({self.orders[k, 0]},{self.orders[k, 1]})"

    def summary(self) -> list[str]:
        """The key's range, the torus, the largest line's range (µm), the turns, why it stopped and the times."""
        xs, xu = self.shown
        p, top = len(self.values), self.largest[0]
        turns = [f"{xs * v:.6g}{'' if smooth else ' (corner)'}" for v, smooth in self.folds]
        steps = self.point_time[1:]
        return [f"torus branch of {self.scene} in {self.key} ({xu}): {p} points from {xs * self.values[0]:.6g} to "
                f"{xs * self.values[-1]:.6g}", *textwrap.wrap(self.truncation, 110),
                f"bases from ({self.bases_hz[0, 0]:.6g}, {self.bases_hz[0, 1]:.6g}) to ({self.bases_hz[-1, 0]:.6g}, "
                f"{self.bases_hz[-1, 1]:.6g}) Hz; largest line at {dof_name(self.dof)} {self.line_label(top)} from "
                f"{1e6 * self.amplitudes[:, top].min():.4g} to {1e6 * self.amplitudes[:, top].max():.4g} µm",
                f"turns: {len(turns)}" + (f", at {', '.join(turns[:4])}" if turns else "")
                + (f" and {len(turns) - 4} more" if len(turns) > 4 else ""),
                *[line for gap in self.not_traced for line in textwrap.wrap(gap, 110)],
                *textwrap.wrap(f"{'INCOMPLETE: ' if self.interrupted else 'stopped: '}{self.stopped}", 110),
                f"times: start {self.point_time[0]:.3g} s, then {steps.sum():.3g} s for {p - 1} points "
                f"({1e3 * (steps.mean() if p > 1 else 0.0):.0f} ms a point on average, "
                f"{np.mean(self.iterations[1:]) if p > 1 else 0.0:.2g} corrections)"]

    def plot(self, ax=None, *, lines: int = 4, title: str | None = None):
        """The amplitude (µm) of the ``lines`` largest lines of the output DOF against the key, the folds marked
        (:func:`rotorred.plots.branch.plot_branch`, stability not computed: grey).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        lines : int
            How many of the largest lines (at the start), 1 to 10.
        title : str, optional

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.branch import plot_branch

        xs, xu = self.shown
        title = title or f"{self.scene}: torus branch" + (f" (INCOMPLETE: interrupted by {self.interrupt})"
                                                          if self.interrupted else "")
        fig = None
        for k in self.largest[:checks.integer("lines", lines, ge=1, le=SHOWN_LINES)]:
            fig = plot_branch(self.values, self.amplitudes[:, k], None, self.folds, ax if fig is None else fig.axes[0],
                              xlabel=f"{self.key} ({xu})", ylabel=f"lines of {dof_name(self.dof)} (µm)", xscale=xs,
                              title=title if fig is None else None, breaks=[i for i, _ in self.gaps])
            fig.axes[0].annotate(f"{self.line_label(k)}: {self.frequencies[0, k]:.4g} Hz",
                                 (xs * self.values[0], 1e6 * self.amplitudes[0, k]), xytext=(4, 4),
                                 textcoords="offset points", fontsize=8)
        return fig

    def to_xarray(self):
        """Dims point, order, base: ``amplitude`` (m) and ``frequency`` (Hz) of each order's line at each point, the
        orders' ``k1``, ``k2``, ``base_frequency`` (Hz), ``iterations``, ``point_time`` (s), ``slope``; the key's
        coordinate named :func:`rotorred.scenes.keys.netcdf_name`; the folds, why it stopped and the truncation as
        attributes."""
        import xarray as xr

        return xr.Dataset(
            {"amplitude": (("point", "order"), self.amplitudes,
                           {"units": "m", "long_name": f"amplitude of each line of {dof_name(self.dof)}"}),
             "frequency": (("point", "order"), self.frequencies, {"units": "Hz", "long_name": "|k1 f_1 + k2 f_2|"}),
             "base_frequency": (("point", "base"), self.bases_hz, {"units": "Hz", "long_name": "base frequencies"}),
             "iterations": ("point", self.iterations, {"units": "1", "long_name": "corrector iterations"}),
             "point_time": ("point", self.point_time, {"units": "s", "long_name": "wall time of the point"}),
             "slope": ("point", self.slope, {"units": "1", "long_name": "d parameter / ds of the unit tangent"})},
            coords={netcdf_name(self.key): ("point", self.values, {"units": cf_units(self.key), "long_name": self.key,
                                                                   "rotorred_key": self.key}),
                    "k1": ("order", self.orders[:, 0], {"units": "1", "long_name": "order of f_1"}),
                    "k2": ("order", self.orders[:, 1], {"units": "1", "long_name": "order of f_2"})},
            attrs={"scene": self.scene, "stopped": self.stopped, "end": self.end, "interrupted": self.interrupt or "no",
                   "truncation": self.truncation,
                   "folds": "; ".join(f"{v:.9g} {'fold' if s else 'corner'}" for v, s in self.folds),
                   "gaps": "; ".join(f"{self.values[i - 1]:.9g} to {self.values[i]:.9g}: {why}"
                                     for i, why in self.gaps)})


def check_torus_key(scene, key: str, start: float, end: float) -> None:
    """Refuse, before anything is computed, a key a torus branch cannot follow in ``scene``: a scene without one rub
    plate (a plate's key) or without plates, a ``[runup]``, not two turning spools, a key not of :data:`KEYS`, a
    value <= 0 or one the plate refuses.

    Parameters
    ----------
    scene : Scene
    key : str
        ``"rub.clearance"``, ``"speeds.<spool>"`` or a plate's number.
    start, end : float
        The key's first and last value, > 0 (its unit).

    Raises
    ------
    InputError
        Naming ``--param`` (or the scene) and what is allowed.
    """
    if not scene.plates:
        checks.fail("SCENE", scene.name, "must have a rub plate ([[rub]]): the branch is of the rub response")
    if getattr(scene, "runup", None) is not None:
        checks.fail("SCENE", scene.name, "has a [runup], which a torus branch cannot honour (steady speeds)")
    turning = [s for s, f in scene.frequencies_hz.items() if f > 0]
    if len(turning) != 2:
        checks.fail("SCENE", scene.name, f"must have two turning spools for a torus (it has {len(turning)})")
    allowed = ("rub.clearance",) + tuple(f"speeds.{s}" for s in scene.speeds) + tuple(PLATE_KEYS)
    if key not in allowed:
        checks.fail("--param", key, f"must be one of {', '.join(allowed)}")
    if key.startswith("rub.") and len(scene.plates) != 1:
        checks.fail("--param", key, f"needs a scene with one rub plate (this one has {len(scene.plates)})")
    for value in (start, end):
        checks.positive("--param", value, KEYS.get(key, "Hz"))
        if key.startswith("rub."):
            scene.plates[0].with_(**{key.partition(".")[2]: value})


def _scene_at(scene, key: str, value: float):
    """``scene`` with ``key`` at ``value``: a spool's speed (Hz), every other spool held, or a number of the plate."""
    group, _, name = key.partition(".")
    if group == "speeds":
        hz = dict(scene.frequencies_hz)
        hz[name] = value
        return dataclasses.replace(scene, operating=Operating.point(hz, unit="Hz"))
    return dataclasses.replace(scene, plates=(scene.plates[0].with_(**{name: value}),) + tuple(scene.plates[1:]))


class _Family:
    """The rub tori of a scene along a key, all on the start's orders: ``rub_at(value)`` (the problem and its lines)
    and ``problem_at(value)`` (for :class:`TorusFamily`). Where a value leaves the model's matrices and the bases as
    they were (a clearance, the law's numbers), the start's compliance serves."""

    def __init__(self, scene, model, key, first: TorusRubProblem, divisors):
        self.scene, self.model, self.key, self.first, self.divisors = scene, model, key, first, divisors
        self.spools = sorted((s for s, f in scene.frequencies_hz.items() if f > 0),
                             key=lambda s: scene.frequencies_hz[s])  # (L, H) at the start
        self._kept: dict = {}

    def bases(self, scene) -> tuple[float, float]:
        f = scene.frequencies_hz
        return f[self.spools[0]] / self.divisors[0], f[self.spools[1]] / self.divisors[1]

    def rub_at(self, value: float) -> TorusRubProblem:
        value = float(value)
        if value not in self._kept:
            if len(self._kept) >= 6:
                self._kept.pop(next(iter(self._kept)))
            self._kept[value] = self._built(value)
        return self._kept[value]

    def problem_at(self, value: float) -> TorusProblem:
        return self.rub_at(value).problem

    def _built(self, value: float) -> TorusRubProblem:
        scene = _scene_at(self.scene, self.key, value)
        start, bases = self.first.problem, self.bases(scene)
        if bases == self.first.bases_hz and all(np.array_equal(a, getattr(start, m)) for a, m in
                                                zip(augmented_matrices(self.model, scene), "MDK")):
            # a clearance, a law's number: the start's problem with the value's forces, its compliance computed once
            return dataclasses.replace(self.first, problem=start.with_forces(plate_rubs(self.model, scene)[1]))
        rub = torus_rub_problem_on(scene, self.model, bases, start.harmonics, self.first.spool_orders)  # a speed:
        rub.problem.by_modes()  # matrices and bases move, the compliance by the modes (an eigen-solution a value)
        return rub


def continue_torus(scene, model, key: str, start: float, end: float,
                   options: TorusBranchOptions = TorusBranchOptions(), *, progress=None,
                   interrupts: Mapping[type[BaseException], str] = INTERRUPTS) -> TorusBranch:
    """The branch of ``scene``'s quasi-periodic rub response on ``model`` as ``key`` goes from ``start`` to ``end``.

    Parameters
    ----------
    scene : Scene
        With rub plates and two turning spools at incommensurate speeds.
    model : SystemMatrices or ReducedSystem
        The scene's model (:func:`rotorred.scenes.run.build_model`); the rub node's x and y its own coordinates.
    key : str
        ``rub.clearance`` (m), ``speeds.<spool>`` (Hz, the other spool held) or a plate's number.
    start, end : float
        The key's first and last value (its unit).
    options : TorusBranchOptions
        Orders, grid, band, divisors, the start's window, tolerance, the most points and the steps.
    progress : callable, optional
        ``progress(points, value)`` as the branch grows.
    interrupts : mapping of exception type to str
        The exceptions that end the tracing where it is, every point traced kept, and the signal each stands for.

    Returns
    -------
    TorusBranch

    Raises
    ------
    InputError
        If ``options`` is not a :class:`TorusBranchOptions` or the key cannot be followed (:func:`check_torus_key`);
        from the start (:func:`rotorred.scenes.quasi_periodic.torus_balance`), if its line fit finds no torus.
    NotConverged
        If the start's Newton does not converge.
    """
    if not isinstance(options, TorusBranchOptions):
        checks.fail("options", type(options).__name__, "must be a TorusBranchOptions")
    check_torus_key(scene, key, start, end)
    t0 = time.perf_counter()
    first_scene = _scene_at(scene, key, start)
    dof = scene.output.table or (scene.plates[0].node, "y")
    spools = sorted((s for s, f in first_scene.frequencies_hz.items() if f > 0),
                    key=lambda s: first_scene.frequencies_hz[s])
    f = first_scene.frequencies_hz
    bases = None if options.divisors is None else (f[spools[0]] / options.divisors[0],
                                                   f[spools[1]] / options.divisors[1])
    first = torus_balance(model, first_scene.operating, Loads(first_scene.unbalances), first_scene.plates,
                          options.torus_options(bases, (dof,)))
    divisors = options.divisors or tuple(int(round(f[s] / b)) for s, b in zip(spools, first.bases_hz))
    box = (*options.orders, *options.n_grid)
    segments, value, z, rub, notes, direction = [], float(start), first.solution.z, first.problem, [], np.sign(end - start)
    gap, ended = "", None  # why the next segment starts past a gap ("": it goes on from the last point); why the
    # branch ended, where not its last segment's own words
    reach, furthest, began = abs(end - start) / CHECKS, float(start), t0
    while True:
        if options.lines_tol is not None:  # the box against the ladder's next, here
            box, rub, z, note = _checked_box(_scene_at(scene, key, value), model, box, rub, z, dof, options)
            notes.append(f"{notes and 'then ' or ''}{box[0]}x{box[1]} from {value:.6g} ({note})")
        rubs = _Family(scene, model, key, rub, divisors)
        family = TorusFamily(rubs.problem_at, value, (key, KEYS.get(key, "Hz")),
                             FROZEN if key.startswith("speeds.") else 0.0, DERIVATIVES.get(key))
        check_at = furthest + direction * reach if options.lines_tol is not None else None
        before = _points(segments) - (1 if segments and not gap else 0)  # the joined branch's before this one's
        branch, stamps = _segment(family, z, value, end, options, check_at, progress, before, interrupts,
                                  options.max_points - before)
        times = np.diff(np.array(stamps[1:]))[:len(branch.values) - 1]  # each step, from one call to the next
        point_time = np.concatenate([[stamps[1] - began], times, np.zeros(len(branch.values) - 1 - len(times))])
        stalled = key.startswith("speeds.") and branch.end in STUCK
        if stalled:
            branch = dataclasses.replace(branch, stopped=_nearest_order(rubs, scene, key, branch))
        segments.append((rubs, branch, point_time, gap))
        checked, passing = branch.interrupt == "check", stalled and options.past_stalls
        if (checked or passing) and options.max_points - _points(segments) < (1 if checked else 2):
            ended = _most_points(key, float(branch.values[-1]), options.max_points)  # not a segment's own most
            break
        if not checked:
            jumped = time.perf_counter()  # the jump's solves: the next segment's first point's time
            past = _past_stall(rubs, scene, key, branch, end, options) if passing else None
            if past is None:
                break
            value, z, rub, gap = past
            furthest, began = value, jumped
            continue
        value, z, rub, gap = float(branch.values[-1]), branch.z[-1], rubs.rub_at(branch.values[-1]), ""
        furthest, began = value, time.perf_counter()
    last = segments[-1][1]
    if ended is None and len(segments) > 1 and last.end == "max_points":
        ended = _most_points(key, float(last.values[-1]), options.max_points)
    return _joined(scene, key, segments, dof, divisors, options, notes, ended)


def _points(segments) -> int:
    """The joined branch's points of ``segments``: each one's, less the first of a segment that goes on from the last
    one's last point (a box's check; not one past a stall, which starts past a gap)."""
    return sum(len(b.values) - (0 if j == 0 or gap else 1) for j, (_, b, _, gap) in enumerate(segments))


def _most_points(key: str, value: float, max_points: int) -> str:
    """Why a branch of several segments ended at its most points (each segment's own continuation counts its own)."""
    return f"stopped at max_points = {max_points} ({key} = {value:.9g} {KEYS.get(key, 'Hz')})"


def _segment(family, z, value, end, options, check_at, progress, before, interrupts, max_points):
    """The continuation from ``z`` at ``value`` towards ``end`` on ``family`` in at most ``max_points`` points, ended
    (interrupt "check") where the key passes ``check_at`` (None: never): the branch and the stamps of its progress
    calls."""
    s_start, s_end = family.carried(value), family.carried(end)
    scale = max(float(np.linalg.norm(z)), abs(s_end - s_start))
    stamps = [time.perf_counter()]
    ahead = np.sign(end - value)

    def stamped(points: int, s: float) -> None:
        stamps.append(time.perf_counter())
        v = family.parameter_value(s)
        if progress is not None:
            progress(before + points, v)
        if check_at is not None and points > 1 and ahead * (v - check_at) >= 0.0:
            raise _Check()
    ds, ds_max = options.steps
    branch = continue_branch(family, z, s_start, s_end,
                             ContinuationOptions(ds=ds * scale, ds_min=1e-9 * scale, ds_max=ds_max * scale,
                                                 max_points=max_points, tol=options.tol, stability=False,
                                                 curved=True, fold_refine=options.fold_refine, stall=STALL_SPAN),
                             progress=stamped,
                             interrupts={**interrupts, _Check: "check"})
    stamps.append(time.perf_counter())
    return branch, stamps


def _nearest(rubs: _Family, scene, key: str, value: float) -> tuple[int, int, float, float]:
    """The order ``(k1, k2)`` of the box nearest 0 Hz at the speed ``value`` (Hz) of the spool ``key``, its frequency
    ``k . f`` there (Hz) and its rate ``d (k . f) / d value`` (-): the spool's order over its divisor."""
    orders = rubs.first.problem.harmonics.orders[1:]
    f = orders @ np.asarray(rubs.bases(_scene_at(scene, key, value)))
    k = int(np.argmin(np.abs(f)))
    moving = rubs.spools.index(key.partition(".")[2])
    return int(orders[k, 0]), int(orders[k, 1]), float(f[k]), orders[k, moving] / rubs.divisors[moving]


def _nearest_order(rubs: _Family, scene, key: str, branch) -> str:
    """A stalled speed branch's ``stopped``, with the order of the box nearest 0 Hz at its last value (the stalls of
    docs/model.md §26 are near such an order's 0 Hz)."""
    k1, k2, f, _ = _nearest(rubs, scene, key, float(branch.values[-1]))
    stem = branch.stopped.removesuffix("; start another branch past it")
    return f"{stem} (the order ({k1}, {k2}) of the box is at {f:+.3g} Hz there); start another branch past it"


def _past_stall(rubs: _Family, scene, key: str, branch, end: float, options: TorusBranchOptions):
    """Past a speed branch's stall (:class:`TorusBranchOptions`'s ``past_stalls``): the speed :data:`JUMP_MIN` of it
    past the nearest order's 0 Hz (past the stall, where that 0 Hz is behind it), the jump doubled while Newton from the
    stall's solution does not converge there (:data:`JUMP_TRIES` times), not beyond ``end``: that speed, the solution,
    its problem and why the stretch was not traced; None if no jump converged, or if that 0 Hz is farther than
    :data:`JUMP_NEAR` of the speed from the stall."""
    v, z = float(branch.values[-1]), branch.z[-1]
    direction = np.sign(end - v)
    k1, k2, f, rate = _nearest(rubs, scene, key, v)
    if rate == 0.0 or abs(f / rate) > JUMP_NEAR * abs(v):
        return None
    crossing = v - f / rate
    jump = max(direction * (crossing - v), 0.0) + JUMP_MIN * abs(v)  # just past that 0 Hz
    for attempt in range(JUMP_TRIES):
        target = v + direction * jump * 2**attempt
        if direction * (target - end) > 0.0:
            return None
        try:
            rub = rubs.rub_at(target)
            found = solve_torus(rub.problem, z, tol=options.tol, max_iter=JUMP_ITERATIONS)
        except (NotConverged, checks.InputError):
            continue
        return (target, found.z, rub, f"a stall passed: the order ({k1}, {k2}) of the box at 0 Hz at "
                                      f"{crossing:.6g} Hz")
    return None


def _checked_box(scene, model, box, rub: TorusRubProblem, z, dof, options: TorusBranchOptions):
    """The box (H1, H2, N1, N2), problem and solution the lines tolerance keeps at this value: the box while its
    :data:`SHOWN_LINES` largest lines (of the next box's solution) differ from the next box's by at most
    ``options.lines_tol``, else the next, checked in turn, up to ``options.max_orders``; and what was measured."""
    said = []
    while True:
        H = tuple(min(int(round(GROWTH * h)), m) for h, m in zip(box[:2], options.max_orders))
        if H == tuple(box[:2]):
            return box, rub, z, ", ".join(said + ["the ladder's last"])
        nxt = (*H, *default_grid(*H))
        n = rub.problem.n
        try:
            fine = torus_rub_problem(scene, model, rub.bases_hz, *nxt, options.f_max)
            z_fine = solve_torus(fine.problem, rub.problem.harmonics.transfer(z, n, fine.problem.harmonics),
                                 tol=options.tol).z
        except checks.InputError:  # a speed ratio the larger box holds as an order of both bases: none here
            return box, rub, z, ", ".join(said + [f"{H[0]}x{H[1]} commensurate here"])
        except NotConverged:
            return box, rub, z, ", ".join(said + [f"{H[0]}x{H[1]} did not converge"])
        change = _lines_change(rub, z, fine, z_fine, dof)
        said.append(f"{H[0]}x{H[1]} {change:.2g}")
        if change <= options.lines_tol:
            return box, rub, z, ", ".join(said)
        box, rub, z = nxt, fine, z_fine


def _lines_change(coarse: TorusRubProblem, z_c, fine: TorusRubProblem, z_f, dof) -> float:
    """The largest relative difference of the :data:`SHOWN_LINES` largest lines of ``fine``'s solution (the mean left
    out) from the same orders' lines of ``coarse``'s (an order it lacks: 1)."""
    orders_c, _, a_c = coarse.lines(z_c, dof)
    orders_f, _, a_f = fine.lines(z_f, dof)
    index = {(int(k1), int(k2)): i for i, (k1, k2) in enumerate(orders_c)}
    ranked = np.argsort(-np.where(np.any(orders_f != 0, axis=1), a_f, -np.inf))[:SHOWN_LINES]
    return max(abs(a_c[index[key]] / a_f[k] - 1.0) if (key := (int(orders_f[k, 0]), int(orders_f[k, 1]))) in index
               else 1.0 for k in ranked)


def _joined(scene, key, segments, dof, divisors, options: TorusBranchOptions, notes,
            ended: str | None = None) -> TorusBranch:
    """The segments' branches as one: each segment's points after the first (that is the last one's; past a stall,
    its first too: the segment's fourth field says why the gap before it was not traced), their coefficients and
    lines on the last box's orders (the ones a segment lacks at 0), the times of a segment's start (the box's check,
    the solve at the new box, or the jump past a stall) on its first point; ``ended``: why the branch ended, where not
    its last segment's own words (its most points, which that segment counts alone)."""
    last = segments[-1][0].first
    h, n = last.problem.harmonics, last.problem.n
    where = {(int(k1), int(k2)): i for i, (k1, k2) in enumerate(h.orders)}
    values, z, amplitudes, times, folds, iterations, slope, gaps = [], [], [], [], [], [], [], []
    for j, (rubs, branch, point_time, gap) in enumerate(segments):
        keep = slice(0 if j == 0 or gap else 1, None)
        if gap:
            gaps.append((sum(len(v) for v in values), gap))
        own = rubs.first.problem.harmonics
        with signals_held():  # a few ms a point: the branch's lines whole
            lines = np.array([rubs.rub_at(v).lines(zi, dof)[2] for v, zi in zip(branch.values, branch.z)])
        placed = np.zeros((len(branch.values), h.n_orders))
        placed[:, [where[(int(a), int(b))] for a, b in own.orders]] = lines
        t = point_time.copy()
        if j > 0 and len(t) > 1 and not gap:
            t[1] += t[0]  # the check and the new box's start: the first step's
        values.append(branch.values[keep])
        z.append(np.array([own.transfer(zi, n, h) for zi in branch.z[keep]]).reshape(-1, h.size * n))
        amplitudes.append(placed[keep])
        times.append(t[keep])
        folds += [(fd.value, fd.smooth) for fd in branch.folds]
        iterations.append(branch.iterations[keep])
        slope.append(branch.slope[keep])
    final = segments[-1][1]
    truncation = (f"{h.n_orders} orders at the end (|k1| <= {h.H1}, |k2| <= {h.H2}"
                  + (f", |k . f| <= {options.f_max:g} Hz at a box's start" if options.f_max is not None else "")
                  + f"), grid {h.N1} x {h.N2}, bases (f_L/{divisors[0]}, f_H/{divisors[1]})"
                  + (f"; boxes by the lines' tolerance {options.lines_tol:g}: {'; '.join(notes)}" if notes else ""))
    values = np.concatenate(values)
    return TorusBranch(scene.name, key, KEYS.get(key, "Hz"), values,
                       np.array([segments[0][0].bases(_scene_at(scene, key, v)) for v in values]), h.orders, dof,
                       np.concatenate(amplitudes), np.concatenate(z), tuple(folds), ended or final.stopped,
                       np.concatenate(iterations), np.concatenate(times), np.concatenate(slope), truncation,
                       "" if ended else final.interrupt, tuple(gaps), end="max_points" if ended else final.end)
