"""What a map varies: a scene, one or more keys over a grid, the sweep direction and the start.

A map runs a scene at every point of a grid of scene keys (:func:`rotorred.scenes.schema.apply_settings`
names, e.g. ``speeds.outer`` in Hz or ``rub.clearance`` in m). The first key is the
**continuation axis**: along it, each point starts from its neighbour's final state (unless
``cold``), up, down or both ways; every combination of the other keys is one such **chain**.

Every point's scene is loaded and validated when the :class:`MapSpec` is checked
(:meth:`MapSpec.scenes`), before any worker starts, so a bad key or value is refused with the
scene's own message naming the key.
"""

from __future__ import annotations

import itertools
import logging
import math
from dataclasses import dataclass, field
from pathlib import Path

from rotorred import checks
from rotorred.model.operating import SpoolLine
from rotorred.scenes.schema import Scene, load_scene
from rotorred.scenes.keys import key_unit

__all__ = ["Axis", "MapSpec", "Chain", "DIRECTIONS"]

#: sweep directions along the continuation axis
DIRECTIONS = ("up", "down", "both")


@dataclass(frozen=True)
class Axis:
    """One varied key and its values (scene units: Hz for speeds, m for a clearance)."""

    key: str
    values: tuple[float, ...]

    def __post_init__(self):
        checks.string("--vary", self.key)
        values = tuple(checks.vector(f"--vary {self.key}", list(self.values), min_len=1))
        if len(set(values)) != len(values):
            checks.fail(f"--vary {self.key}", list(values), "must not repeat a value")
        object.__setattr__(self, "values", values)

    @property
    def label(self) -> str:
        """The key and its unit, e.g. ``"speeds.outer (Hz)"``."""
        return f"{self.key} ({key_unit(self.key)[1]})"


@dataclass(frozen=True)
class Chain:
    """Points run in order, each from the previous one's final state (continuation).

    ``direction`` is "up" or "down"; ``index`` the grid index of the other axes; ``order`` the
    continuation-axis indices in the order run.
    """

    direction: str
    index: tuple[int, ...]
    order: tuple[int, ...]

    def points(self) -> list[tuple[str, tuple[int, ...]]]:
        """(direction, full grid index) of each point, in the order run."""
        return [(self.direction, (i, *self.index)) for i in self.order]


@dataclass(frozen=True)
class MapSpec:
    """A map: a scene, the varied axes (the first is the continuation axis), fixed settings.

    Attributes
    ----------
    scene : str
        Built-in scene name or scene file.
    axes : tuple of Axis
        Varied keys, at least one; the first is the continuation axis.
    settings : tuple of (str, value)
        Fixed overrides of the scene (``--set``).
    ratios : tuple of (str, float)
        ``(spool, r)``: that spool turns at ``r`` times the varied speed (``--ratio``); only with a
        ``speeds.<spool>`` continuation axis.
    direction : {"up", "down", "both"}
        Sweep direction along the continuation axis; "both" runs up, then down.
    cold : bool
        Every point from the scene's own start (no continuation).
    limit : float, optional
        Simulated time (s) up to which a point that has not settled runs on
        (:func:`rotorred.maps.point.run_point`); default the scene's ``solver.duration`` (no
        extension).
    """

    scene: str
    axes: tuple[Axis, ...]
    settings: tuple = ()
    ratios: tuple = ()
    direction: str = "up"
    cold: bool = False
    limit: float | None = None
    _scenes: dict = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self):
        if isinstance(self.scene, Path):
            object.__setattr__(self, "scene", str(self.scene))
        checks.string("scene", self.scene)
        if not self.axes:
            checks.fail("--vary", [], "must give at least one key to vary, e.g. --vary speeds.outer=60:110:51")
        keys = [a.key for a in self.axes]
        if len(set(keys)) != len(keys):
            checks.fail("--vary", keys, "must name each key once")
        fixed = {k for k, _ in self.settings}
        if fixed & set(keys):
            checks.fail("--set", sorted(fixed & set(keys)), "must not fix a key that --vary varies")
        checks.choice("--direction", self.direction, DIRECTIONS)
        if self.limit is not None:
            object.__setattr__(self, "limit", checks.positive("--limit", self.limit, "s"))
        self._check_ratios()

    def _check_ratios(self) -> None:
        if not self.ratios:
            return
        key = self.axes[0].key
        if not key.startswith("speeds."):
            checks.fail("--ratio", dict(self.ratios), f"must go with a speeds.<spool> continuation axis, not {key!r}")
        fixed = dict(self.settings)
        for spool, r in self.ratios:
            checks.positive(f"--ratio {spool}", r)
            if f"speeds.{spool}" == key or any(a.key == f"speeds.{spool}" for a in self.axes):
                checks.fail("--ratio", spool, "must name a spool that --vary does not vary")
            if f"speeds.{spool}" in fixed:
                checks.fail("--ratio", f"{spool}={r:g}", f"conflicts with --set speeds.{spool}="
                            f"{fixed[f'speeds.{spool}']!r}: both set the {spool} spool's speed; give one of them")

    # ------------------------------------------------------------------ grid
    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values of each axis."""
        return tuple(len(a.values) for a in self.axes)

    @property
    def directions(self) -> tuple[str, ...]:
        """The sweeps run: ``("up",)``, ``("down",)`` or ``("up", "down")``."""
        return ("up", "down") if self.direction == "both" else (self.direction,)

    @property
    def n_points(self) -> int:
        """Number of points run: grid points times sweeps."""
        return math.prod(self.shape) * len(self.directions)

    def settings_at(self, index: tuple[int, ...]) -> dict:
        """The scene overrides of grid point ``index``: fixed settings, varied keys, ratio-bound speeds.

        Parameters
        ----------
        index : tuple of int, length len(axes)
            Grid index: the position in each axis's values.

        Returns
        -------
        dict of str to value
            Scene key to value, in scene units (Hz for speeds, m for a clearance).
        """
        out = dict(self.settings)
        for axis, i in zip(self.axes, index):
            out[axis.key] = axis.values[i]
        for spool, r in self.ratios:  # a spool at ratio r of the varied speed, by the speed line's rule
            out[f"speeds.{spool}"] = float(SpoolLine(r, 0.0, "ratio").at(self.axes[0].values[index[0]]))
        return out

    def scene_at(self, index: tuple[int, ...]) -> Scene:
        """The validated scene of grid point ``index`` (loaded once).

        Parameters
        ----------
        index : tuple of int, length len(axes)
            Grid index: the position in each axis's values.

        Raises
        ------
        InputError
            If the scene with the point's settings is invalid, naming the key, or has a ``[runup]`` (a map runs
            every point at steady speeds).
        """
        index = tuple(index)
        if index not in self._scenes:
            scene = load_scene(self.scene, self.settings_at(index))
            if scene.runup is not None:
                checks.fail("scene", self.scene, "has a [runup], which a map cannot honour (every point runs at steady "
                            "speeds, --vary sets them): run the run-up with `rotorred run`, or map a scene without "
                            "[runup]")
            self._scenes[index] = scene
        return self._scenes[index]

    def scenes(self) -> list[Scene]:
        """Every grid point's scene, validated (raises the scene's error naming the key)."""
        return [self.scene_at(ix) for ix in itertools.product(*(range(n) for n in self.shape))]

    def check_size(self, force: bool = False) -> None:
        """Every point's scene validated and within the size limits of a run (:mod:`rotorred.scenes.budget`), and the
        map's steps in all, each point run to ``limit`` s, at most ``budget.MAX_STEPS`` (a varied ``solver.dt`` or
        duration). :func:`rotorred.maps.store.map_estimate` checks the whole map at once, from its first point.

        Parameters
        ----------
        force : bool
            Let a map beyond the size limits go on.

        Raises
        ------
        InputError
            If a point's scene is invalid or asks for ``solver.tolerance``, or (without ``force``) a point or
            the whole map is beyond the size limits.
        """
        from rotorred.scenes import budget

        total, warned = 0, []
        for scene in self.scenes():
            if scene.solver.tolerance is not None:
                checks.fail("solver.tolerance", scene.solver.tolerance, "is not available in maps yet (each point would "
                            "choose its own model and step): choose the settings with `rotorred run --set "
                            "solver.tolerance=...` at a representative point and give them to the map")
            warned += budget.scene_estimate(scene).check(force=force).warnings
            total += self.steps_at(scene)
        self.check_steps(total, force)
        if warned:  # the first point's, and how many points have one
            logging.getLogger(__name__).warning("%s%s", warned[0], f" (and at {len(warned) - 1} other points of the "
                                                                   "map)" if len(warned) > 1 else "")

    def check_steps(self, total: float, force: bool = False) -> None:
        """Refuse ``total`` steps of the map beyond ``budget.MAX_STEPS`` (unless ``force``).

        Parameters
        ----------
        total : float
            The map's steps in all, every point and sweep.
        force : bool
            Let a map beyond the limit go on.

        Raises
        ------
        InputError
            Naming ``--vary``, the points, the steps and ``--force``.
        """
        from rotorred.scenes import budget

        if total > budget.MAX_STEPS and not force:
            checks.fail("--vary", self.described,
                        f"gives {total:.3g} steps in all (--limit {self.limit or 'the scene duration'}), more than "
                        f"{budget.MAX_STEPS:.3g}; use --force to go on")

    def steps_at(self, scene: Scene) -> float:
        """Steps of one grid point's ``scene`` in every sweep, each run to ``limit`` s.

        Parameters
        ----------
        scene : Scene
            A grid point's validated scene (:meth:`scene_at`).

        Returns
        -------
        float
        """
        return max(self.limit or 0.0, scene.solver.duration) / scene.solver.dt * len(self.directions)

    @property
    def described(self) -> str:
        """The varied keys and the points, as a message names them: ``rub.clearance=<11 values> (11 points)``."""
        return " ".join(f"{a.key}=<{len(a.values)} values>" for a in self.axes) + f" ({self.n_points} points)"

    def chains(self) -> list[Chain]:
        """The chains along the continuation axis: one per direction and combination of the other axes."""
        up = tuple(int(i) for i in sorted(range(self.shape[0]), key=lambda i: self.axes[0].values[i]))
        out = []
        for direction in self.directions:
            order = up if direction == "up" else up[::-1]
            for rest in itertools.product(*(range(n) for n in self.shape[1:])):
                out.append(Chain(direction, tuple(rest), order))
        return out
