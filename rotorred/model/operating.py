"""Where a multi-spool machine runs: its spool speeds at a point, along a speed line, or in time.

Every analysis of rotorred takes the operating condition as one :class:`Operating`, and reads the
speed of each spool from it by one rule, :meth:`Operating.lines` (docs/model.md, "Operating
points"):

- A **speed line** sweeps the speed ``Omega`` of a reference spool; every other spool ``s`` turns
  at ``Omega_s = a_s Omega + b_s``: at a stated ratio (``a_s = ratios[s]``, ``b_s = 0``), at a
  fixed speed (``a_s = 0``, ``b_s = fixed[s]``), or, when neither is stated, at the ratio of the
  spools' nominal speeds (``a_s = Omega_s,nom / Omega_ref,nom``). A spool whose ratio would be
  undefined (the reference's nominal speed is 0, or the model has no nominal speeds) must be
  stated; the error names it.
- A **point** is a speed line of one speed: the speeds given are fixed, the reference is the first
  spool given, and a spool left out follows the reference as on a line.
- A **profile** gives the speeds in time (:class:`rotorred.model.speeds.SpeedProfile`, a run-up or
  a coast-down); a spool it leaves out follows the reference at the nominal ratio, as on a line.

Speeds are rad/s inside; the constructors take ``unit="rad/s"`` (default), ``"rpm"`` or ``"Hz"``
(revolutions per second), and the unit is kept for display only.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from rotorred import checks
from rotorred.model.speeds import SpeedProfile

#: rad/s per unit of each speed unit the constructors accept
UNITS = {"rad/s": 1.0, "rpm": math.pi / 30.0, "Hz": 2.0 * math.pi}


def to_rad_s(value, unit: str = "rad/s"):
    """``value`` (a number or an array) in ``unit`` (:data:`UNITS`) as rad/s."""
    factor = UNITS[checks.choice("unit", unit, UNITS)]
    return np.asarray(value, dtype=float) * factor if np.ndim(value) else float(value) * factor


def from_rad_s(value, unit: str = "rad/s"):
    """``value`` (rad/s; a number or an array) in ``unit`` (:data:`UNITS`)."""
    factor = UNITS[checks.choice("unit", unit, UNITS)]
    return np.asarray(value, dtype=float) / factor if np.ndim(value) else float(value) / factor


@dataclass(frozen=True)
class SpoolLine:
    """The speed of one spool along a speed line: ``Omega_s = slope * Omega + offset`` (rad/s).

    Attributes
    ----------
    slope : float
        ``dOmega_s / dOmega`` (-): the spool's ratio to the reference, 0 for a fixed spool.
    offset : float
        Speed at ``Omega = 0`` (rad/s): a fixed spool's speed, 0 for a spool at a ratio.
    how : str
        ``"reference"``, ``"ratio"`` (stated), ``"fixed"`` (stated) or ``"nominal ratio"``.
    """

    slope: float
    offset: float
    how: str

    def at(self, Omega):
        """The spool's speed (rad/s) at reference speed(s) ``Omega`` (rad/s).

        Parameters
        ----------
        Omega : float or array_like, shape (n,)
            Speed(s) of the reference spool (rad/s).

        Returns
        -------
        ndarray, shape of ``Omega``
            ``slope * Omega + offset`` (rad/s).
        """
        return self.slope * np.asarray(Omega, dtype=float) + self.offset


@dataclass(frozen=True, eq=False)
class Operating:
    """The operating condition of a multi-spool machine: a point, a speed line or a speed profile.

    Build one with :meth:`point`, :meth:`line`, :meth:`profile` or :meth:`ramp`; read the spool
    speeds for a model with :meth:`lines`, :meth:`speeds`, :meth:`at` or :meth:`profile_for`.

    Attributes
    ----------
    Omega : ndarray, shape (n,)
        Speeds of the reference spool (rad/s), >= 0; one for a point; empty for a profile.
    reference : str or None
        The reference spool; None: the model's first spool.
    ratios : dict of str to float
        ``Omega_s / Omega`` of the spools stated to follow the reference (-).
    fixed : dict of str to float
        Speeds of the spools stated to be fixed (rad/s).
    speed_profile : SpeedProfile or None
        The speeds in time, for a profile.
    unit : str
        The unit the speeds were given in (display only; :data:`UNITS`).
    """

    Omega: np.ndarray
    reference: str | None = None
    ratios: Mapping[str, float] = field(default_factory=dict)
    fixed: Mapping[str, float] = field(default_factory=dict)
    speed_profile: SpeedProfile | None = None
    unit: str = "rad/s"

    def __post_init__(self):
        checks.choice("unit", self.unit, UNITS)
        if self.reference is not None:
            checks.string("reference", self.reference, empty=False)
        if self.speed_profile is not None:
            if not isinstance(self.speed_profile, SpeedProfile):
                checks.fail("speed_profile", type(self.speed_profile).__name__, "must be a SpeedProfile")
            Omega = np.zeros(0)
        else:
            Omega = checks.vector("Omega", self.Omega, "rad/s", ge=0.0)
        Omega.setflags(write=False)
        ratios = {str(s): checks.non_negative(f"ratios[{s!r}]", r) for s, r in checks.table("ratios", self.ratios).items()}
        fixed = {str(s): checks.non_negative(f"fixed[{s!r}]", w, "rad/s")
                 for s, w in checks.table("fixed", self.fixed).items()}
        both = sorted(set(ratios) & set(fixed))
        if both:
            checks.fail("fixed", fixed, f"must not name a spool that ratios also names ({', '.join(both)}): a spool "
                        "either follows the reference or turns at a fixed speed")
        if self.reference is not None and self.reference in set(ratios) | set(fixed):
            checks.fail("reference", self.reference, "must not be named in ratios or fixed: its speed is Omega")
        object.__setattr__(self, "Omega", Omega)
        object.__setattr__(self, "ratios", ratios)
        object.__setattr__(self, "fixed", fixed)

    # ------------------------------------------------------------------------------ constructors
    @classmethod
    def point(cls, speeds: Mapping[str, float], unit: str = "rad/s") -> Operating:
        """Every spool given at one speed: ``{"inner": 528.0, "outer": 679.0}`` (``unit``).

        The first spool given is the reference; a spool of the model left out follows it at the
        nominal ratio (:meth:`lines`).

        Parameters
        ----------
        speeds : dict of str to float
            Speed of each spool given (``unit``), >= 0; at least one.
        unit : {"rad/s", "rpm", "Hz"}
            Unit of ``speeds``; kept for display.

        Raises
        ------
        InputError
            If ``speeds`` is empty, a speed is negative or ``unit`` is unknown.
        """
        speeds = checks.table("speeds", speeds)
        if not speeds:
            checks.fail("speeds", speeds, "must give the speed of at least one spool", unit)
        names = [str(s) for s in speeds]
        values = {s: checks.non_negative(f"speeds[{s!r}]", w, unit) for s, w in zip(names, speeds.values())}
        return cls(np.array([to_rad_s(values[names[0]], unit)]), names[0], {},
                   {s: to_rad_s(w, unit) for s, w in values.items() if s != names[0]}, unit=unit)

    @classmethod
    def line(cls, Omega: Sequence[float], reference: str | None = None, *, ratios: Mapping[str, float] | None = None,
             fixed: Mapping[str, float] | None = None, unit: str = "rad/s") -> Operating:
        """A speed line: the ``reference`` spool at each speed of ``Omega`` (``unit``), shape (n,).

        Parameters
        ----------
        Omega : array_like, shape (n,)
            Speeds of the reference spool (``unit``), >= 0.
        reference : str, optional
            The swept spool; default the model's first spool.
        ratios : dict of str to float, optional
            ``Omega_s / Omega`` of spools that follow the reference (-).
        fixed : dict of str to float, optional
            Speeds of spools held fixed along the line (``unit``).
        unit : {"rad/s", "rpm", "Hz"}
            Unit of ``Omega`` and ``fixed``; kept for display.

        Raises
        ------
        InputError
            If a speed is negative, or a spool is both at a ratio and fixed.
        """
        fixed = {s: to_rad_s(checks.non_negative(f"fixed[{s!r}]", w, unit), unit)
                 for s, w in checks.table("fixed", fixed or {}).items()}
        values = checks.vector("Omega", [Omega] if np.ndim(Omega) == 0 else Omega, unit, ge=0.0)
        return cls(to_rad_s(values, unit), reference, dict(ratios or {}), fixed, unit=unit)

    @classmethod
    def profile(cls, speed_profile: SpeedProfile, reference: str | None = None, unit: str = "rad/s") -> Operating:
        """Speeds in time (a run-up, a coast-down, a measured table), :class:`SpeedProfile` in rad/s.

        Parameters
        ----------
        speed_profile : SpeedProfile
            Speeds of the spools it names (rad/s) at its breakpoints (s); a spool of the model it
            leaves out follows the reference (:meth:`profile_for`).
        reference : str, optional
            The reference spool; default the profile's first spool.
        unit : {"rad/s", "rpm", "Hz"}
            Unit to display the speeds in (the profile itself is in rad/s).
        """
        return cls(np.zeros(0), reference, speed_profile=speed_profile, unit=unit)

    @classmethod
    def ramp(cls, start: Mapping[str, float], end: Mapping[str, float], duration: float, hold: float = 0.0,
             unit: str = "rad/s") -> Operating:
        """A linear ramp from ``start`` to ``end`` speeds (``unit``) over ``duration`` (s), after ``hold`` (s).

        Parameters
        ----------
        start, end : dict of str to float
            Speed of each spool at the start and at the end of the ramp (``unit``), >= 0; the same
            spools in both. The first spool of ``start`` is the reference.
        duration : float
            Length of the ramp (s), > 0.
        hold : float
            Time at the ``start`` speeds before the ramp begins (s), >= 0.
        unit : {"rad/s", "rpm", "Hz"}
            Unit of ``start`` and ``end``; kept for display.

        Raises
        ------
        InputError
            If a speed is negative, the spools of ``start`` and ``end`` differ, or ``duration`` is not > 0.
        """
        start = {s: to_rad_s(checks.non_negative(f"start[{s!r}]", w, unit), unit)
                 for s, w in checks.table("start", start).items()}
        end = {s: to_rad_s(checks.non_negative(f"end[{s!r}]", w, unit), unit)
               for s, w in checks.table("end", end).items()}
        return cls.profile(SpeedProfile.ramp(start, end, duration, hold), next(iter(start), None), unit)

    # ------------------------------------------------------------------------------ what it is
    @property
    def kind(self) -> str:
        """``"point"``, ``"line"`` or ``"profile"``."""
        if self.speed_profile is not None:
            return "profile"
        return "point" if len(self.Omega) == 1 else "line"

    @property
    def n_points(self) -> int:
        """Number of speeds along the line (1 for a point, 0 for a profile)."""
        return len(self.Omega)

    # ------------------------------------------------------------------------------ the one rule
    def lines(self, model) -> dict[str, SpoolLine]:
        """The speed of every spool of ``model`` as a function of the reference speed: the ratio rule.

        Parameters
        ----------
        model : Rotor, SystemMatrices or ReducedSystem
            Anything with ``spools`` (names, or objects with ``name``) and ``nominal_speeds`` (rad/s;
            a Rotor's ``speeds``), which may be empty.

        Returns
        -------
        dict of str to SpoolLine
            In the model's spool order; the reference first has slope 1.

        Raises
        ------
        InputError
            If a spool named in ``ratios``, ``fixed`` or the profile is not a spool of ``model``, or a spool's
            speed is not stated where no nominal ratio to the reference follows from the model.
        """
        spools, nominal = _spools_and_nominal(model)
        reference = self.reference_of(model)
        for what, given in (("ratios", self.ratios), ("fixed", self.fixed)):
            for s in given:
                checks.choice(f"{what} spool", s, [n for n in spools if n != reference])
        if self.speed_profile is not None:
            for s in self.speed_profile.spools:
                checks.choice("speed_profile spool", s, spools)
        out = {}
        missing = []
        for s in spools:
            if s == reference:
                out[s] = SpoolLine(1.0, 0.0, "reference")
            elif s in self.fixed:
                out[s] = SpoolLine(0.0, self.fixed[s], "fixed")
            elif s in self.ratios:
                out[s] = SpoolLine(self.ratios[s], 0.0, "ratio")
            elif self.speed_profile is not None and s in self.speed_profile.spools:
                out[s] = SpoolLine(math.nan, math.nan, "profile")
            elif nominal.get(reference, 0.0) > 0.0 and s in nominal:
                out[s] = SpoolLine(nominal[s] / nominal[reference], 0.0, "nominal ratio")
            else:
                missing.append(s)
        if missing:
            why = (f"the nominal speed of the reference spool {reference!r} is 0" if reference in nominal
                   else "the model has no nominal spool speeds")
            checks.fail("operating", self.describe(), f"must state the speed of spool(s) {missing} (ratios= or "
                        f"fixed=): {why}, so no ratio to it follows from the model")
        return out

    def reference_of(self, model) -> str:
        """The reference spool for ``model``: the one given, or the model's first spool.

        Parameters
        ----------
        model : Rotor, SystemMatrices or ReducedSystem
            Anything with ``spools`` and ``nominal_speeds`` (:meth:`lines`).

        Raises
        ------
        InputError
            If the reference given is not a spool of ``model``.
        """
        spools, _ = _spools_and_nominal(model)
        if self.reference is None and self.speed_profile is not None and self.speed_profile.spools:
            return checks.choice("reference", self.speed_profile.spools[0], spools)
        return checks.choice("reference", spools[0] if self.reference is None else self.reference, spools)

    def speeds(self, model) -> dict[str, np.ndarray]:
        """Speed of every spool of ``model`` at each point of the line (rad/s), each shape (n,).

        Parameters
        ----------
        model : Rotor, SystemMatrices or ReducedSystem
            Anything with ``spools`` and ``nominal_speeds`` (:meth:`lines`).

        Raises
        ------
        InputError
            If this is a profile, or a spool's speed does not follow (:meth:`lines`).
        """
        self._not_a_profile("speeds")
        return {s: line.at(self.Omega) for s, line in self.lines(model).items()}

    def at(self, model, k: int = 0) -> dict[str, float]:
        """Speed of every spool of ``model`` at point ``k`` of the line (rad/s).

        Parameters
        ----------
        model : Rotor, SystemMatrices or ReducedSystem
            Anything with ``spools`` and ``nominal_speeds`` (:meth:`lines`).
        k : int
            Index of the point along the line (negative counts from the end).

        Raises
        ------
        InputError
            If this is a profile, or ``k`` is out of range.
        """
        self._not_a_profile("at")
        k = checks.integer("k", k, ge=-self.n_points, le=self.n_points - 1)
        return {s: float(line.at(self.Omega[k])) for s, line in self.lines(model).items()}

    def single(self, model, field_name: str = "operating") -> dict[str, float]:
        """The spool speeds (rad/s) of an analysis that runs at one point: a point, or a line of one speed.

        Parameters
        ----------
        model : Rotor, SystemMatrices or ReducedSystem
            Anything with ``spools`` and ``nominal_speeds`` (:meth:`lines`).
        field_name : str
            The option or key the error names.

        Raises
        ------
        InputError
            If this is a line of several speeds or a profile.
        """
        if self.kind != "point":
            checks.fail(field_name, self.describe(), "must be one operating point (Operating.point), not a "
                        f"{self.kind}")
        return self.at(model, 0)

    def profile_for(self, model) -> SpeedProfile:
        """The profile with every spool of ``model``: a spool it leaves out follows the reference (the rule of
        :meth:`lines`) at each breakpoint; a point gives a constant profile.

        Parameters
        ----------
        model : Rotor, SystemMatrices or ReducedSystem
            Anything with ``spools`` and ``nominal_speeds`` (:meth:`lines`).

        Returns
        -------
        SpeedProfile
            Speeds of every spool of ``model`` (rad/s) at the profile's breakpoints (s).

        Raises
        ------
        InputError
            If the profile leaves out the reference spool, or this is a line of several speeds.
        """
        if self.speed_profile is None:
            return SpeedProfile.constant(self.single(model))
        p = self.speed_profile
        ref = self.reference_of(model)
        if ref not in p.spools:
            checks.fail("operating", self.describe(), f"must give the reference spool {ref!r} in its profile")
        lines = self.lines(model)
        return SpeedProfile(p.t, {s: (p.speeds[s] if s in p.speeds else lines[s].at(p.speeds[ref])) for s in lines})

    def _not_a_profile(self, what: str) -> None:
        if self.speed_profile is not None:
            checks.fail("operating", self.describe(), f"must be a point or a speed line for {what}(); a profile "
                        "gives speeds in time (profile_for)")

    # ------------------------------------------------------------------------------ display
    def describe(self) -> str:
        """One line: what the operating condition is, in its own unit."""
        u = self.unit
        ref = self.reference or "first spool"
        if self.speed_profile is not None:
            p = self.speed_profile
            return (f"profile of {len(p.t)} breakpoint(s) over {p.duration:g} s, spools "
                    + ", ".join(f"{s} {from_rad_s(float(w.min()), u):.4g}-{from_rad_s(float(w.max()), u):.4g} {u}"
                                for s, w in p.speeds.items()))
        W = from_rad_s(self.Omega, u)
        head = (f"point: {ref} at {W[0]:.6g} {u}" if self.kind == "point"
                else f"line of {len(W)} speeds: {ref} {W.min():.6g}-{W.max():.6g} {u}")
        parts = [f"{s} at ratio {r:.6g}" for s, r in self.ratios.items()]
        parts += [f"{s} at {from_rad_s(w, u):.6g} {u}" for s, w in self.fixed.items()]
        return "; ".join([head] + parts)

    def __repr__(self) -> str:
        return f"Operating({self.describe()})"

    def __eq__(self, other) -> bool:
        if not isinstance(other, Operating):
            return NotImplemented
        return (np.array_equal(self.Omega, other.Omega) and self.reference == other.reference
                and self.ratios == other.ratios and self.fixed == other.fixed
                and self.speed_profile is other.speed_profile and self.unit == other.unit)


def _spools_and_nominal(model) -> tuple[tuple[str, ...], dict[str, float]]:
    """Spool names and nominal speeds (rad/s) of a rotor or a system (:meth:`Operating.lines`)."""
    spools = getattr(model, "spools", None)
    if spools is None:
        checks.fail("model", type(model).__name__, "must be a Rotor, SystemMatrices or ReducedSystem (it has no "
                    "spools)")
    names = tuple(getattr(s, "name", s) for s in spools)
    nominal = getattr(model, "nominal_speeds", None)
    if nominal is None:
        nominal = getattr(model, "speeds", None)
    nominal = dict(nominal) if isinstance(nominal, Mapping) else {}
    return names, nominal


def checked(value, field_name: str = "operating") -> Operating:
    """``value`` if it is an :class:`Operating`; the error names ``field_name`` and the constructors otherwise."""
    if not isinstance(value, Operating):
        checks.fail(field_name, value, "must be an Operating (Operating.point, Operating.line, Operating.profile; "
                    "rotorred.model.operating)")
    return value
