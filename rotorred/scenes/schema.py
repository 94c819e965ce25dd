"""Scenes: a complete simulation described in one TOML file (rotor, speeds, loads, rubs, solver, outputs).

A scene is loaded and validated in full before anything is computed: every key is checked
(unknown keys, types, ranges, node numbers against the rotor) by :mod:`rotorred.checks`, as
written (speeds in Hz, angles in degrees) before it is converted, and an error (:class:`SceneError`)
names the file, the key, the value and what is allowed. The format, with every key's unit and default, is documented
in ``docs/scenes.md``; in short::

    name = "paper-rub"
    [rotor]                 # preset = "seed-rig", file = "rig.toml" or the rotor inline; optional Rayleigh override
    preset = "seed-rig"
    rayleigh_alpha = 40.0   # 1/s
    rayleigh_beta = 1e-4    # s
    [speeds]                # Hz per spool (default: the rotor's nominal speeds)
    inner = 70.0
    outer = 90.0
    [[unbalance]]           # kg m, deg
    node = 18
    m_e = 1e-3
    [[rub]]                 # rub plate(s), rotorred.transient.contact.RubPlate; SI units, angles in deg
    node = 18
    clearance = 16e-6
    [solver]
    model = "reduced"       # or "full"
    dt = 2e-5               # s
    duration = 2.6          # s
    record_start = 2.1      # s
    [output]
    nodes = [13, 14, 18]
    directions = ["x", "y"]

Built-in scenes live in ``rotorred/scenes/builtin/*.toml`` (:func:`builtin_scenes`).
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from rotorred import checks
from rotorred.checks import InputError, fail
from rotorred.model.dofs import DIRECTIONS, parse_dof
from rotorred.model.loads import Unbalance, unbalance_from_table
from rotorred.model.operating import Operating
from rotorred.model.rotor import Rotor, node_ranges, plural, speed_text
from rotorred.model.rotor_file import ROTOR_FILE_KEYS, presets, read_rotor, read_text_file, read_toml, rotor_from_dict
from rotorred.model.speeds import SpeedProfile
from rotorred.results import Result
from rotorred.scenes.builtin import builtin_scenes
from rotorred.transient.contact import RubPlate
from rotorred.transient.plate import ClampedFreePlate, NavierPlate, RigidPlate

__all__ = ["Scene", "SolverSpec", "OutputSpec", "RunupSpec", "SceneError", "load_scene", "scene_from_toml", "scene_from_dict",
           "builtin_scenes", "apply_settings", "parse_setting", "DIRECTIONS", "PLOTS", "FORMATS"]

PLOTS = ("waveforms", "spectra", "orbits", "poincare")
FORMATS = ("npz", "csv", "mat")
MODELS = ("reduced", "full")
STARTS = ("settled", "rest")
METHODS = ("newmark", "hht", "harmonic-balance")
BENDING = ("navier", "clamped-free", "rigid")

_TOP_KEYS = {"name", "description", "rotor", "speeds", "unbalance", "rub", "solver", "output", "runup"}
_RUNUP_KEYS = {"from", "to", "duration", "hold", "table", "orders", "orbits_hz", "reference", "record_dt",
               "revs_per_block"}
_ROTOR_KEYS = {"preset", "file", "rayleigh_alpha", "rayleigh_beta"}
_UNBALANCE_KEYS = {"node", "m_e", "phase_deg"}  # rotorred.model.loads.UNBALANCE_KEYS
_RUB_NUMBERS = {"clearance": ("m", 0.0, False), "K_nr": ("N/m^1.5", 0.0, True), "c": ("s/m", 0.0, False),
                "mu_s": ("-", 0.0, False), "mu_d": ("-", 0.0, False), "m_p": ("kg", 0.0, True),
                "k_n": ("N/m", 0.0, False), "k_t": ("N/m", 0.0, False), "c_n": ("N s/m", 0.0, False),
                "c_t": ("N s/m", 0.0, False), "disk_radius": ("m", 0.0, True)}
_PLATE_NUMBERS = {"plate_a": ("m", 0.0, True), "plate_b": ("m", 0.0, True), "plate_h": ("m", 0.0, True),
                  "plate_E": ("Pa", 0.0, True), "plate_nu": ("-", None, False), "plate_xi": ("m", 0.0, True),
                  "plate_eta": ("m", 0.0, True), "a0": ("N/m", 0.0, True), "b0": ("N", 0.0, False)}
_RUB_KEYS = {"node", "theta_deg", "bending", "name"} | set(_RUB_NUMBERS) | set(_PLATE_NUMBERS)
_SOLVER_KEYS = {"model", "modes", "cutoff_hz", "boundary_nodes", "dt", "duration", "record_start", "start",
                "method", "alpha", "gravity", "tolerance", "harmonics", "samples"}
#: harmonics of f_0 and AFT samples a period of ``solver.method = "harmonic-balance"`` unless given: the rig's 10
#: largest lines at node 14 Y within 0.29 % of the settled transient (docs/model.md §15)
BALANCE_DEFAULTS = (100, 2048)
#: range of ``solver.tolerance``: below 1e-5 the time step needed leaves double precision little room
TOLERANCE_RANGE = (1e-5, 0.1)
_OUTPUT_KEYS = {"nodes", "directions", "plots", "formats", "plot_window", "table", "line_threshold", "f_max_hz",
                "compare_normal"}
#: relative tolerance of the record-window tests (whole number of steps, of common periods)
_RTOL = 1e-9


def is_whole_steps(t: float, dt: float) -> bool:
    """Whether the time ``t`` (s) is a whole number of steps of ``dt`` (s), up to the relative rounding ``_RTOL``
    (the rule of a scene's ``record_start`` and ``duration``)."""
    steps = t / dt
    return abs(steps - round(steps)) <= _RTOL * max(steps, 1.0)


#: tolerance of the Navier series of Eq. 10 (relative); 1e-6 is far below the uncertainty of any plate
#: dimension and converges within the series' term cap for a centrally loaded plate
NAVIER_TOL = 1e-6


class SceneError(InputError):
    """A scene file that does not describe a valid simulation (an :class:`rotorred.checks.InputError`).

    Its message names the file, the key path, the value as written and what is allowed, e.g.
    ``paper-rub.toml: rub[0].clearance = -5e-06: must be >= 0 (m)``. An error in the scene's rotor
    file names that file.
    """


@dataclass(frozen=True)
class SolverSpec:
    """How a scene is computed.

    Attributes
    ----------
    model : {"reduced", "full"}
        Craig–Bampton reduced model (boundary: bearings, inter-shaft bearings, rub nodes,
        ``boundary_nodes``) or the full FE model.
    modes : int or None
        Fixed-interface modes kept (None: chosen automatically, :func:`rotorred.linear.reduction.reduce`).
    cutoff_hz : float or None
        Keep the fixed-interface modes below this frequency (Hz) instead of a count.
    boundary_nodes : tuple of int
        Extra boundary nodes of the reduced model.
    dt : float
        Time step (s).
    duration : float
        End time of the run (s); the run starts at t = 0.
    record_start : float
        Start of the recorded window (s).
    start : {"settled", "rest"}
        Initial state: the linear steady state (unbalance and gravity) or rest (the start-up).
    method : {"newmark", "hht", "harmonic-balance"}
        The time step, or the steady response by harmonic balance (a rub scene; the record is that solution at the
        record times): periodic at commensurate speeds (:mod:`rotorred.scenes.harmonic_balance`), on a torus at
        incommensurate ones (:mod:`rotorred.scenes.torus_response`).
    alpha : float or None
        HHT-alpha parameter (only with method "hht").
    harmonics, samples : int, (int, int) or None
        Harmonics of the base frequency and AFT samples a period (only with method "harmonic-balance"; default
        :data:`BALANCE_DEFAULTS`; None when ``tolerance`` chooses them). At incommensurate speeds, the torus's box of
        orders ``(H1, H2)`` and AFT grid ``(N1, N2)`` (default None: those of
        :class:`rotorred.scenes.quasi_periodic.TorusOptions`); with ``tolerance``, the box it starts from.
    gravity : float
        Gravity along -y (m/s^2); 0 for none.
    tolerance : float or None
        Relative error target of the outputs (:mod:`rotorred.scenes.tolerance`): the tool then chooses
        ``modes``, ``boundary_nodes``, ``dt``, ``record_start`` and ``duration`` (the window's length kept); with
        method "harmonic-balance", the harmonics and samples (:mod:`rotorred.scenes.balance_harmonics`).
    """

    model: str = "reduced"
    modes: int | None = None
    cutoff_hz: float | None = None
    boundary_nodes: tuple[int, ...] = ()
    dt: float = 2e-5
    duration: float = 2.0
    record_start: float = 1.5
    start: str = "settled"
    method: str = "newmark"
    alpha: float | None = None
    gravity: float = 0.0
    tolerance: float | None = None
    harmonics: int | tuple[int, int] | None = None
    samples: int | tuple[int, int] | None = None


@dataclass(frozen=True)
class OutputSpec:
    """What a scene writes.

    Attributes
    ----------
    nodes : tuple of int
        Nodes whose displacements are recorded.
    directions : tuple of str
        Directions recorded at every node ("x", "y", "theta_x", "theta_y").
    plots : tuple of str
        Figures to draw: "waveforms", "spectra", "orbits", "poincare" (the Poincare section of the
        table DOF, :mod:`rotorred.signals.classify`).
    formats : tuple of str
        Data files: "npz", "csv", "mat".
    plot_window : (float, float) or None
        Time range of the waveform plot (s); default the first 0.14 s of the record.
    table : (int, str) or None
        The DOF whose labelled lines are printed as the paper's Table 1 (default: the last
        node's "y", or its first direction).
    line_threshold : float
        Spectral peaks below this fraction of the largest line are ignored.
    f_max_hz : float or None
        Upper frequency of the spectrum plots (Hz).
    compare_normal : bool
        With rub plates, also compute the scene without them ("normal") and overlay it.
    """

    nodes: tuple[int, ...] = ()
    directions: tuple[str, ...] = ("x", "y")
    plots: tuple[str, ...] = PLOTS
    formats: tuple[str, ...] = FORMATS
    plot_window: tuple[float, float] | None = None
    table: tuple[int, str] | None = None
    line_threshold: float = 0.005
    f_max_hz: float | None = None
    compare_normal: bool = True

    @property
    def dofs(self) -> tuple[tuple[int, str], ...]:
        """Recorded (node, direction) pairs, node by node."""
        return tuple((n, d) for n in self.nodes for d in self.directions)


@dataclass(frozen=True)
class RunupSpec:
    """A run-up or coast-down: the speed profile and what to show of it (``[runup]``, docs/scenes.md).

    Attributes
    ----------
    profile : SpeedProfile
        Spool speeds against time (rad/s).
    reference : str
        Spool whose speed is the abscissa of the amplitude plots.
    orders : tuple of float
        Orders tracked for every spool (cycles per revolution).
    orbits_hz : tuple of float
        Speeds of the reference spool (Hz) where orbit snapshots are taken.
    record_dt : float
        Record interval (s), a whole number of steps.
    revs_per_block : int
        Revolutions per block of the order tracks (rotorred.signals.orders).
    """

    profile: SpeedProfile
    reference: str
    orders: tuple[float, ...] = (1.0,)
    orbits_hz: tuple[float, ...] = ()
    record_dt: float = 1e-4
    revs_per_block: int = 8

    @property
    def operating(self) -> Operating:
        """The run-up's operating condition: its profile, with its reference spool (:meth:`Operating.profile`)."""
        return Operating.profile(self.profile, self.reference)


@dataclass(frozen=True)
class Scene:
    """A validated scene (see the module docstring and ``docs/scenes.md``).

    Attributes
    ----------
    name, description : str
    rotor : Rotor
        The rotor, with the scene's Rayleigh override applied.
    rotor_source : str
        Preset name or file path.
    operating : Operating
        The operating point (``[speeds]``, Hz, by the rule of :meth:`Operating.point`: the spools given at their
        speeds, the first the reference, a spool left out following it at the rotor's nominal ratio; no ``[speeds]``:
        the rotor's nominal speeds). Its spool speeds are :attr:`speeds`.
    unbalances : tuple of Unbalance
    plates : tuple of RubPlate
    solver : SolverSpec
    output : OutputSpec
    runup : RunupSpec or None
        The speed profile of a run-up or coast-down (its operating condition: ``runup.operating``); None for
        constant ``speeds``.
    source : str
        Where the scene came from (file, built-in name or "<string>").
    data : dict
        The parsed TOML tables (for :func:`apply_settings` and re-loading).
    rotor_data : dict
        The rotor's rotor-file document, as its preset, file or inline ``[rotor]`` tables hold it (without the
        scene's Rayleigh override): the rotor of the resolved scene (:mod:`rotorred.scenes.resolved`).
    """

    name: str
    description: str
    rotor: Rotor
    rotor_source: str
    operating: Operating
    unbalances: tuple
    plates: tuple
    solver: SolverSpec
    output: OutputSpec
    runup: RunupSpec | None = None
    source: str = "<string>"
    data: dict = field(default_factory=dict, repr=False, compare=False)
    rotor_data: dict = field(default_factory=dict, repr=False, compare=False)

    @functools.cached_property
    def speeds(self) -> dict[str, float]:
        """Every spool's speed (rad/s) at the operating point, in the rotor's spool order."""
        return self.operating.single(self.rotor, "speeds")

    @property
    def frequencies_hz(self) -> dict[str, float]:
        """Spool frequencies (Hz)."""
        return {s: w / (2 * math.pi) for s, w in self.speeds.items()}

    @property
    def is_linear(self) -> bool:
        """True when the scene has no rub plate."""
        return not self.plates

    def without_rub(self) -> Scene:
        """The same scene without rub plates (the "normal" state)."""
        return dataclasses.replace(self, plates=(), name=f"{self.name} (normal)")

    def summary(self) -> list[str]:
        """Name, rotor, speeds, unbalances, contact and the run's length: at most 14 lines, no arrays (``repr``)."""
        lines = [f"{self.name!r}: rotor {self.rotor.name!r} ({self.rotor_source})"]
        lines += [f"speed {spool!r}: {speed_text(w)}" for spool, w in list(self.speeds.items())[:4]]
        if self.runup is not None:
            p, ref = self.runup.profile, self.runup.reference
            lines.append(f"run-up of {ref!r} from {speed_text(p.speeds[ref][0])} to {speed_text(p.speeds[ref][-1])} "
                         f"in {p.t[-1]:.4g} s")
        lines.append(f"{plural(len(self.unbalances), 'unbalance')} at nodes "
                     f"{node_ranges(u.node for u in self.unbalances)}" if self.unbalances else "no unbalance")
        lines += [f"contact: rub at node {c.node}, clearance {c.clearance * 1e6:.4g} µm, K_nr {c.K_nr:.4g} N/m^1.5"
                  for c in self.plates[:3]] if self.plates else ["no contact (linear)"]
        s = self.solver
        lines.append(f"solver: {s.model} model, {s.method}, dt {s.dt:.4g} s, duration {s.duration:.4g} s "
                     f"(recorded from {s.record_start:.4g} s)")
        return lines

    __repr__ = Result.__repr__


# --------------------------------------------------------------------------- loading
def _read(spec: str | Path) -> tuple[dict, str, Path | None]:
    spec_str = str(spec)
    if spec_str in builtin_scenes():
        text = resources.files("rotorred.scenes.builtin").joinpath(f"{spec_str}.toml").read_text()
        source, base = f"scene {spec_str!r}", None
    else:
        path = Path(spec)
        if not path.is_file():
            raise FileNotFoundError(f"scene {spec_str!r} is neither a built-in scene "
                                    f"({', '.join(builtin_scenes())}) nor an existing file")
        text, source, base = read_text_file(path, SceneError), str(path), path.parent
    try:
        return read_toml(text, SceneError), source, base
    except SceneError as exc:
        raise exc.from_source(source) from None


def load_scene(spec: str | Path, settings: dict[str, Any] | None = None) -> Scene:
    """Load and validate a scene from a built-in name or a TOML file.

    Parameters
    ----------
    spec : str or Path
        Built-in scene name (:func:`builtin_scenes`) or path of a scene file.
    settings : dict of str to value, optional
        Overrides ``"section.key" -> value`` applied before validation (:func:`apply_settings`).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        For a scene (or its rotor file) that is not valid, naming the file and the key.
    FileNotFoundError
        If ``spec`` is neither a built-in scene nor an existing file.
    """
    data, source, base = _read(spec)
    if settings:
        data = apply_settings(data, settings)
    return scene_from_dict(data, source=source, base=base)


def scene_from_toml(text: str, source: str = "<string>", base: Path | None = None) -> Scene:
    """Parse and validate a scene TOML document."""
    try:
        data = read_toml(text, SceneError)
    except SceneError as exc:
        raise exc.from_source(source) from None
    return scene_from_dict(data, source=source, base=base)


def scene_from_dict(data: dict, source: str = "<string>", base: Path | None = None) -> Scene:
    """Build a :class:`Scene` from parsed TOML tables; raises :class:`SceneError` naming the key.

    An error in the scene's rotor file keeps that file as its source.
    """
    try:
        return _build(copy.deepcopy(checks.table("scene", data)), source, base)
    except InputError as exc:
        raise SceneError(exc.field, exc.value, exc.requirement, exc.unit, exc.source or source) from None


# --------------------------------------------------------------------------- settings (--set)
#: most values of one START:STOP:N setting (a map of them is refused by its size estimate long before)
MAX_VALUES = 1_000_000
_SET_FORM = "must be KEY=VALUES (e.g. rub.clearance=10e-6,20e-6) or KEY=START:STOP:N"


def parse_setting(text: str, option: str = "--set") -> tuple[str, list]:
    """Parse ``"section.key=v1,v2,..."`` or ``"section.key=start:stop:n"`` into (key, values).

    Values are TOML values (numbers, strings, booleans); a bare word is a string.
    ``start:stop:n`` gives ``n`` evenly spaced numbers (n >= 2).

    Parameters
    ----------
    text : str
        The setting, e.g. ``"rub.clearance=10e-6,20e-6"`` or ``"speeds.outer=60:110:51"`` (values in
        scene units: Hz for speeds, m for a clearance).
    option : str
        The command-line option the messages name.

    Returns
    -------
    key : str
        The scene key, e.g. ``"rub.clearance"``.
    values : list
        The values, at least one.

    Raises
    ------
    InputError
        If ``text`` is not of either form.
    """
    checks.string(option, text)
    key, _, rhs = text.partition("=")
    key, rhs = key.strip(), rhs.strip()
    if "=" not in text or not key or not rhs:
        fail(option, text, _SET_FORM)
    if rhs.count(":") == 2 and "," not in rhs:
        a, b, n = rhs.split(":")
        try:
            a, b, n = float(a), float(b), int(n)
        except ValueError:
            n = None
        if n is None or n < 2:
            fail(f"{option} {key}", rhs, "must be START:STOP:N with numbers START, STOP and an integer N >= 2")
        if n > MAX_VALUES:  # refused before a list of n numbers is made (1e9 of them: a MemoryError)
            fail(f"{option} {key}", rhs, f"must have N <= {MAX_VALUES:g} values")
        return key, [a + (b - a) * i / (n - 1) for i in range(n)]
    return key, [_toml_value(v.strip(), key) for v in _split_top(rhs) if v.strip()]


def _split_top(text: str) -> list[str]:
    """Split at commas outside brackets and quotes ("[1, 2],3" -> ["[1, 2]", "3"])."""
    parts, depth, quote, start = [], 0, None, 0
    for i, ch in enumerate(text):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return parts


def _toml_value(text: str, key: str):
    try:
        return read_toml(f"v = {text}")["v"]
    except InputError:
        if text and all(ch.isalnum() or ch in "_-:.+" for ch in text):
            return text  # a bare word, e.g. full or 14:y
        fail(f"--set {key}", text, "must be a TOML value (number, string, boolean, array) or a bare word")


def apply_settings(data: dict, settings: dict[str, Any]) -> dict:
    """A copy of the scene tables with ``"section.key" -> value`` overrides.

    ``section.key`` sets a key of a table (``solver.dt``) or, for the arrays of tables
    ``rub`` and ``unbalance``, of every entry (``rub.clearance``); ``rub[1].clearance``
    sets one entry. Unknown keys are caught by the validation that follows.
    """
    data = copy.deepcopy(data)
    for key, value in settings.items():
        parts = key.split(".")
        if len(parts) == 1:
            data[key] = value
            continue
        if len(parts) != 2:
            fail("--set", key, "must be KEY or SECTION.KEY (e.g. rub.clearance)")
        section, name = parts
        index = None
        if section.endswith("]") and "[" in section:
            section, _, idx = section[:-1].partition("[")
            try:
                index = int(idx)
            except ValueError:
                fail("--set", key, "must index an entry with an integer, e.g. rub[1].clearance")
        target = data.get(section)
        if isinstance(target, list):
            if index is not None and not 0 <= index < len(target):
                fail("--set", key, f"must index an existing entry: the scene has {len(target)} [[{section}]] entries")
            for entry in target if index is None else [target[index]]:
                entry[name] = value
        elif index is not None:
            fail("--set", key, f"must index an array of tables; [{section}] is not one")
        elif target is None:
            if section in ("rub", "unbalance"):
                fail("--set", key, f"must set a key of an existing entry: the scene has no [[{section}]] entry")
            data[section] = {name: value}
        elif isinstance(target, dict):
            target[name] = value
        else:
            fail("--set", key, f"must set a key of a table; {section!r} is not a table")
    return data


# --------------------------------------------------------------------------- checks
def _bounded(field: str, value, unit: str, low: float | None, strict: bool) -> float:
    """A finite number, > ``low`` if ``strict`` else >= ``low`` (no bound for ``low`` None)."""
    if low is None:
        return checks.number(field, value, unit)
    return checks.number(field, value, unit, gt=low) if strict else checks.number(field, value, unit, ge=low)


def _node_of(rotor: Rotor):
    """Item check of :func:`rotorred.checks.sequence`: a node of ``rotor``."""
    return lambda field, value: checks.node(field, value, rotor.spool_of)


# --------------------------------------------------------------------------- build
def _rotor(value, base: Path | None, source: str) -> tuple[Rotor, str, dict]:
    """``[rotor]``: a preset, a file or the rotor's own tables inline, with the Rayleigh override; returns the rotor,
    where it came from and its rotor-file document (before the override)."""
    table = checks.table("rotor", value)
    checks.keys("rotor", table, _ROTOR_KEYS | ROTOR_FILE_KEYS)
    inline = {k: v for k, v in table.items() if k in ROTOR_FILE_KEYS}
    if ("preset" in table) + ("file" in table) + bool(inline) != 1:
        fail("rotor", table, f"must hold exactly one of preset ({', '.join(presets())}) or file (a rotor TOML path), "
             "or the rotor itself (the tables of a rotor file: spool, disk, bearing, ...)")
    if "preset" in table:
        name = checks.choice("rotor.preset", table["preset"], presets())
        (rotor, document), rotor_source = read_rotor(name), name
    elif "file" in table:
        path = Path(checks.string("rotor.file", table["file"], empty=False))
        if not path.is_absolute() and base is not None:
            path = base / path
        if not path.is_file():
            fail("rotor.file", table["file"], f"must be an existing rotor TOML file ({str(path)!r} is not)")
        (rotor, document), rotor_source = read_rotor(path), str(path)
    else:
        rotor, document, rotor_source = _inline_rotor(inline), inline, f"{source} [rotor]"
    alpha, beta = rotor.rayleigh
    if "rayleigh_alpha" in table:
        alpha = checks.non_negative("rotor.rayleigh_alpha", table["rayleigh_alpha"], "1/s")
    if "rayleigh_beta" in table:
        beta = checks.non_negative("rotor.rayleigh_beta", table["rayleigh_beta"], "s")
    if (alpha, beta) != tuple(rotor.rayleigh):
        rotor = dataclasses.replace(rotor, rayleigh=(alpha, beta))
    return rotor, rotor_source, copy.deepcopy(document)


def _inline_rotor(tables: dict) -> Rotor:
    """The rotor of ``[rotor]``'s own tables (a rotor file's keys), its errors named under ``rotor``."""
    try:
        return rotor_from_dict(tables)
    except InputError as exc:
        raise exc.within("rotor") from None


def _operating(value, rotor: Rotor) -> tuple[Operating, dict[str, float]]:
    """``[speeds]`` (Hz) as an operating point (:meth:`Operating.point`: the spools given at their speeds, the first
    the reference, a spool left out following it at the rotor's nominal ratio); none given: the rotor's nominal
    speeds. At least one spool must turn. Returns the point and every spool's speed there (rad/s)."""
    spools = [s.name for s in rotor.spools]
    table = {} if value is None else checks.table("speeds", value)
    checks.keys("speeds", table, spools)
    given = {s: checks.non_negative(f"speeds.{s}", v, "Hz") for s, v in table.items()}
    operating = Operating.point(given, unit="Hz") if given else dataclasses.replace(Operating.point(rotor.speeds),
                                                                                    unit="Hz")
    try:
        speeds = operating.single(rotor, "speeds")
    except InputError as exc:  # a spool left out whose ratio to the reference does not follow from the rotor
        fail("speeds", value, f"must give the speed of every spool whose nominal ratio to {next(iter(given))!r} is "
             f"undefined ({exc.requirement})", "Hz")
    if not any(w > 0 for w in speeds.values()):
        shown = {s: w / (2 * math.pi) for s, w in speeds.items()} if value is None else value
        fail("speeds", shown, f"must give at least one spool of {', '.join(speeds)} a speed > 0"
             + ("; the rotor's nominal speeds are all 0" if value is None else ""), "Hz")
    return operating, speeds


def _runup(value, rotor: Rotor, speeds: dict[str, float]) -> RunupSpec | None:
    """``[runup]``: a ramp between fractions of ``[speeds]`` (fixed ratio) or a table of every spool's speeds."""
    if value is None:
        return None
    table = checks.table("runup", value)
    checks.keys("runup", table, _RUNUP_KEYS)
    spools = [s.name for s in rotor.spools]
    if "table" in table:
        for key in ("from", "to", "duration", "hold"):
            if key in table:
                fail(f"runup.{key}", table[key], "must not be given with runup.table (the table gives the speeds)")
        profile = _runup_table(table["table"], spools)
    else:
        start = checks.non_negative("runup.from", table.get("from", 0.0), "x [speeds]")
        end = checks.non_negative("runup.to", table.get("to", 1.2), "x [speeds]")
        if start == end:
            fail("runup.to", table.get("to", 1.2), f"must differ from runup.from = {start:g} (a ramp changes the "
                 "speeds; a constant speed needs no [runup])", "x [speeds]")
        duration = checks.positive("runup.duration", table.get("duration", 10.0), "s")
        hold = checks.non_negative("runup.hold", table.get("hold", 0.0), "s")
        profile = SpeedProfile.ramp({s: start * w for s, w in speeds.items()}, {s: end * w for s, w in speeds.items()},
                                    duration, hold)
    reference = checks.choice("runup.reference", table.get("reference", spools[0]), spools)
    orders = tuple(checks.sequence("runup.orders", table.get("orders", [1.0]),
                                   lambda f, v: checks.positive(f, v, "-"), min_len=1, unique=True))
    top = round(float(max(profile.speeds[reference])) / (2 * math.pi), 9)  # Hz, as written
    orbits = tuple(checks.sequence("runup.orbits_hz", table.get("orbits_hz", []),
                                   lambda f, v: checks.number(f, v, "Hz", gt=0.0, le=top)))
    record_dt = checks.positive("runup.record_dt", table.get("record_dt", RunupSpec.record_dt), "s")
    revs = checks.integer("runup.revs_per_block", table.get("revs_per_block", RunupSpec.revs_per_block), ge=2)
    return RunupSpec(profile=profile, reference=reference, orders=orders, orbits_hz=orbits, record_dt=record_dt,
                     revs_per_block=revs)


def _runup_table(rows, spools: list[str]) -> SpeedProfile:
    """``runup.table``: rows [t (s), speed of each spool in the rotor's order (Hz)]."""
    rows = checks.sequence("runup.table", rows, min_len=2)
    width = 1 + len(spools)
    t, columns = [], {s: [] for s in spools}
    for k, row in enumerate(rows):
        row = checks.sequence(f"runup.table[{k}]", row, lambda f, v: checks.number(f, v), min_len=width,
                              max_len=width)
        t.append(row[0])
        for s, v in zip(spools, row[1:]):
            columns[s].append(2 * math.pi * checks.non_negative(f"runup.table[{k}][{1 + spools.index(s)}]", v, "Hz"))
    try:
        return SpeedProfile(t, columns)
    except InputError as exc:
        raise exc.within("runup.table") from None


def _unbalances(entries, rotor: Rotor) -> tuple[Unbalance, ...]:
    return tuple(unbalance_from_table(f"unbalance[{i}]", u, rotor.spool_of)
                 for i, u in enumerate(checks.tables("unbalance", entries)))


def _bending(where: str, r: dict):
    kind = checks.choice(f"{where}.bending", r.get("bending", "navier"), BENDING)
    allowed = {"navier": {"plate_a", "plate_b", "plate_h", "plate_E", "plate_nu", "plate_xi", "plate_eta"},
               "clamped-free": {"a0", "b0"}, "rigid": set()}[kind]
    stray = sorted(k for k in _PLATE_NUMBERS if k in r and k not in allowed)
    if stray:
        fail(f"{where}.{stray[0]}", r[stray[0]], f"must not be given with {where}.bending = {kind!r}, whose keys "
             f"are {', '.join(sorted(allowed)) or 'none'}")
    vals = {k: _bounded(f"{where}.{k}", r[k], *_PLATE_NUMBERS[k]) for k in sorted(allowed) if k in r}
    if "plate_nu" in vals:
        checks.number(f"{where}.plate_nu", r["plate_nu"], "-", gt=-1.0, lt=0.5)
    if kind == "rigid":
        return RigidPlate()
    cls, prefix = (ClampedFreePlate, "") if kind == "clamped-free" else (NavierPlate, "plate_")
    kw = {k[len(prefix):]: v for k, v in vals.items()}
    if cls is NavierPlate:
        kw["tol"] = NAVIER_TOL
    try:
        return cls(**kw)
    except InputError as exc:  # the plate names its attributes (xi); the scene's keys are rub[0].plate_xi
        raise InputError(f"{where}.{prefix}{exc.field}", exc.value, exc.requirement, exc.unit) from None
    except ValueError as exc:
        fail(f"{where}.bending", kind, f"must describe a valid plate: {exc}")


def _plates(entries, rotor: Rotor) -> tuple[RubPlate, ...]:
    return tuple(_plate(f"rub[{i}]", r, rotor) for i, r in enumerate(checks.tables("rub", entries)))


def _plate(where: str, r: dict, rotor: Rotor) -> RubPlate:
    checks.keys(where, r, _RUB_KEYS, required={"node", "clearance"})
    node = checks.node(f"{where}.node", r["node"], rotor.spool_of)
    kw = {k: _bounded(f"{where}.{k}", r[k], *_RUB_NUMBERS[k]) for k in _RUB_NUMBERS if k in r}
    if "mu_s" in kw or "mu_d" in kw:
        mu_s, mu_d = kw.get("mu_s", RubPlate.mu_s), kw.get("mu_d", RubPlate.mu_d)
        if mu_d > mu_s:
            fail(f"{where}.mu_d", r.get("mu_d", mu_d), f"must not exceed {where}.mu_s = {mu_s:g}")
    theta = math.radians(checks.number(f"{where}.theta_deg", r.get("theta_deg", 90.0), "deg"))
    if "disk_radius" not in kw:
        disk = next((d for d in rotor.disks if d.node == node), None)
        if disk is None or disk.radius <= 0:
            fail(f"{where}.node", r["node"], f"must carry a disk with a radius (rub plates face a disk: disks with "
                 f"a radius are at nodes {[d.node for d in rotor.disks if d.radius > 0]}), or give "
                 f"{where}.disk_radius")
        kw["disk_radius"] = disk.radius
    name = checks.string(f"{where}.name", r.get("name", f"rub plate at node {node}"))
    bending = _bending(where, r)
    try:
        return RubPlate(node=node, theta=theta, bending=bending, name=name, **kw)
    except InputError as exc:
        raise exc.within(where) from None


def _solver(value, rotor: Rotor, speeds: dict[str, float], d: SolverSpec = SolverSpec()) -> SolverSpec:
    """``[solver]``, with the defaults ``d`` (a run-up's: its whole profile from t = 0)."""
    table = checks.table("solver", {} if value is None else value)
    checks.keys("solver", table, _SOLVER_KEYS)
    model = checks.choice("solver.model", table.get("model", d.model), MODELS)
    modes, cutoff, boundary = _solver_reduction(table, rotor)
    dt, duration, record_start = _solver_times(table, d)
    start = checks.choice("solver.start", table.get("start", d.start), STARTS)
    method = checks.choice("solver.method", table.get("method", d.method), METHODS)
    alpha = table.get("alpha")
    if alpha is not None:
        if method != "hht":
            fail("solver.alpha", alpha, 'must not be given unless solver.method = "hht"')
        alpha = checks.number("solver.alpha", alpha, "-", ge=-1 / 3, le=0.0)
    gravity = checks.number("solver.gravity", table.get("gravity", d.gravity), "m/s^2")
    tolerance = table.get("tolerance")
    if tolerance is not None:
        tolerance = checks.number("solver.tolerance", tolerance, "-", ge=TOLERANCE_RANGE[0], le=TOLERANCE_RANGE[1])
        if method not in ("newmark", "harmonic-balance"):
            fail("solver.tolerance", tolerance, f'must go with solver.method = "newmark" (its error estimates are '
                 f'the average-acceleration step\'s) or "harmonic-balance" (it chooses the harmonics), not {method!r}')
    harmonics, samples = _solver_balance(table, method, speeds)
    return SolverSpec(model=model, modes=modes, cutoff_hz=cutoff, boundary_nodes=boundary, dt=dt, duration=duration,
                      record_start=record_start, start=start, method=method, alpha=alpha, gravity=gravity,
                      tolerance=tolerance, harmonics=harmonics, samples=samples)


def _periodic(speeds: dict) -> bool:
    """Whether the spool speeds (rad/s) have a periodic response (:func:`rotorred.scenes.harmonic_balance.common_frequency`);
    else a harmonic balance is on a torus."""
    from rotorred.scenes.harmonic_balance import common_frequency

    return common_frequency(tuple(w / (2 * math.pi) for w in speeds.values())) is not None


def _solver_balance(table: dict, method: str, speeds: dict) -> tuple:
    """``solver.harmonics`` and ``solver.samples``: only with method "harmonic-balance" (then their defaults), a pair
    each (the torus's orders and grid) at incommensurate ``speeds`` (rad/s)."""
    if method != "harmonic-balance":
        for key in ("harmonics", "samples"):
            if key in table:
                fail(f"solver.{key}", table[key], 'must not be given unless solver.method = "harmonic-balance"')
        return None, None
    periodic = _periodic(speeds)
    if table.get("tolerance") is not None:  # the harmonics are chosen (rotorred.scenes.balance_harmonics)
        for key in ("harmonics", "samples") if periodic else ("samples",):
            if key in table:
                fail(f"solver.{key}", table[key], "must not be given with solver.tolerance (the tolerance chooses "
                     "the harmonics and samples); give one or the other" if periodic else "must not be given with "
                     "solver.tolerance (each box of orders it tries takes its default grid)")
        return (None, None) if periodic else _torus_truncation(table)
    if not periodic:
        return _torus_truncation(table)
    H = table.get("harmonics", BALANCE_DEFAULTS[0])
    if isinstance(H, (list, tuple)):
        fail("solver.harmonics", H, "must be one number of harmonics at speeds sharing a period of at most 10 s (a "
             "pair [H1, H2] is a torus's, at incommensurate speeds)")
    H = checks.integer("solver.harmonics", H, ge=1)
    return H, _samples("solver.samples", table.get("samples", BALANCE_DEFAULTS[1]), H)


def _samples(field: str, N, H: int) -> int:
    """AFT samples for ``H`` harmonics: even and at least 2 H + 2."""
    N = checks.integer(field, N, ge=2 * H + 2)
    if N % 2:
        fail(field, N, "must be even")
    return N


def _torus_truncation(table: dict) -> tuple:
    """``solver.harmonics = [H1, H2]`` and ``solver.samples = [N1, N2]`` of a torus (each None unless given)."""
    H = table.get("harmonics")
    if H is not None:
        if not isinstance(H, (list, tuple)):
            fail("solver.harmonics", H, "must be a pair [H1, H2] at incommensurate speeds (the torus's orders |k1| <= "
                 "H1, |k2| <= H2 of its two base frequencies), or left out (the default box)")
        H = checks.sequence("solver.harmonics", H, lambda f, v: checks.integer(f, v, ge=1), min_len=2, max_len=2)
    N = table.get("samples")
    if N is not None:
        if H is None or not isinstance(N, (list, tuple)):
            fail("solver.samples", N, "must be a pair [N1, N2] with solver.harmonics = [H1, H2] at incommensurate "
                 "speeds (the torus's AFT grid), or left out (the default grid of the orders)")
        N = checks.sequence("solver.samples", N, min_len=2, max_len=2)
        N = tuple(_samples(f"solver.samples[{i}]", v, H[i]) for i, v in enumerate(N))
    return H, N


def _solver_reduction(table: dict, rotor: Rotor) -> tuple[int | None, float | None, tuple[int, ...]]:
    """``solver.modes``, ``solver.cutoff_hz`` and ``solver.boundary_nodes``.

    They are validated but unused with model = "full", so that ``--set solver.model=full``
    switches a reduced scene to the full model.
    """
    modes = table.get("modes")
    if modes == "auto":
        modes = None
    if modes is not None:
        try:
            modes = checks.integer("solver.modes", modes, ge=0)
        except InputError:
            fail("solver.modes", modes, 'must be "auto" or an integer >= 0')
    cutoff = table.get("cutoff_hz")
    if cutoff is not None:
        cutoff = checks.positive("solver.cutoff_hz", cutoff, "Hz")
        if modes is not None:
            fail("solver.cutoff_hz", table["cutoff_hz"], f"must not be given together with solver.modes = {modes!r}: "
                 "give one or the other", "Hz")
    boundary = checks.sequence("solver.boundary_nodes", table.get("boundary_nodes", []), _node_of(rotor))
    return modes, cutoff, boundary


def _solver_times(table: dict, d: SolverSpec) -> tuple[float, float, float]:
    """``solver.dt``, ``solver.duration`` and ``solver.record_start`` (s), consistent with each other."""
    dt = checks.positive("solver.dt", table.get("dt", d.dt), "s")
    duration = checks.positive("solver.duration", table.get("duration", d.duration), "s")
    record_start = checks.non_negative("solver.record_start", table.get("record_start", d.record_start), "s")
    if dt >= duration:
        fail("solver.dt", dt, f"must be < solver.duration = {duration:g}", "s")
    if record_start >= duration:
        fail("solver.duration", duration, f"must exceed solver.record_start = {record_start:g}, the start of the "
             "recorded window record_start..duration", "s")
    for name, value in (("duration", duration), ("record_start", record_start)):
        if not is_whole_steps(value, dt):
            fail(f"solver.{name}", value, f"must be a whole number of steps of solver.dt = {dt:g}; it is "
                 f"{value / dt:.6g} steps", "s")
    # Any record length is accepted at any speeds: the line fit needs no whole common
    # period, and the spectrum uses a window when the record holds none (signals.spectra.settled_spectrum).
    return dt, duration, record_start


def _output(value, rotor: Rotor, solver: SolverSpec, plates) -> OutputSpec:
    table = checks.table("output", {} if value is None else value)
    checks.keys("output", table, _OUTPUT_KEYS)
    d = OutputSpec()
    nodes, directions, table_dof = _output_dofs(table, rotor, plates)
    plots = checks.sequence("output.plots", table.get("plots", list(d.plots)), lambda f, v: checks.choice(f, v, PLOTS))
    formats = checks.sequence("output.formats", table.get("formats", list(d.formats)),
                              lambda f, v: checks.choice(f, v, FORMATS))
    if "orbits" in plots and not {"x", "y"} <= set(directions):
        fail("output.plots", table.get("plots", list(d.plots)), 'must not ask for "orbits" unless '
             'output.directions holds both "x" and "y"')
    window = table.get("plot_window")
    if window is not None:
        lo, hi = solver.record_start, solver.duration
        start, end = checks.sequence("output.plot_window", window, lambda f, v: checks.number(f, v, "s"),
                                     min_len=2, max_len=2)
        if not lo - 1e-12 <= start < end <= hi + 1e-12:
            fail("output.plot_window", window, f"must be [start, end] inside the recorded window [{lo:g}, {hi:g}] "
                 "with start < end", "s")
        window = (start, end)
    threshold = checks.number("output.line_threshold", table.get("line_threshold", d.line_threshold), "-",
                              gt=0.0, le=1.0)
    f_max = table.get("f_max_hz")
    if f_max is not None:
        f_max = checks.positive("output.f_max_hz", f_max, "Hz")
    compare = checks.boolean("output.compare_normal", table.get("compare_normal", d.compare_normal))
    return OutputSpec(nodes=nodes, directions=directions, plots=plots, formats=formats, plot_window=window,
                      table=table_dof, line_threshold=threshold, f_max_hz=f_max, compare_normal=compare)


def _output_dofs(table: dict, rotor: Rotor, plates) -> tuple[tuple[int, ...], tuple[str, ...], tuple | None]:
    """``output.nodes``, ``output.directions`` and ``output.table`` (a recorded DOF)."""
    default_nodes = [min(rotor.nodes)] if not plates else [plates[0].node]
    nodes = checks.sequence("output.nodes", table.get("nodes", default_nodes), _node_of(rotor), min_len=1,
                            unique=True)
    directions = checks.sequence("output.directions", table.get("directions", list(OutputSpec.directions)),
                                 lambda f, v: checks.choice(f, v, DIRECTIONS), min_len=1, unique=True)
    table_dof = table.get("table")
    if table_dof is not None:
        table_dof = parse_dof("output.table", table_dof, rotor.spool_of)
        if table_dof not in {(n, dd) for n in nodes for dd in directions}:
            fail("output.table", table["table"], "must be a recorded DOF (one of output.nodes x output.directions)")
    return nodes, directions, table_dof


def _build(data: dict, source: str, base: Path | None) -> Scene:
    checks.keys("", data, _TOP_KEYS, required={"rotor"})
    name = checks.string("name", data.get("name", Path(source).stem if base is not None else source))
    description = checks.string("description", data.get("description", ""))
    rotor, rotor_source, rotor_data = _rotor(data["rotor"], base, source)
    operating, speeds = _operating(data.get("speeds"), rotor)
    unbalances = _unbalances(data.get("unbalance", []), rotor)
    plates = _plates(data.get("rub", []), rotor)
    runup = _runup(data.get("runup"), rotor, speeds)
    defaults = SolverSpec() if runup is None else SolverSpec(duration=runup.profile.duration, record_start=0.0)
    solver = _solver(data.get("solver"), rotor, speeds, defaults)
    if runup is not None:
        _check_runup_solver(runup, solver)
    if solver.method == "harmonic-balance":
        _check_balance(speeds, plates, solver)
    output = _output(data.get("output"), rotor, solver, plates)
    if not unbalances and solver.gravity == 0:
        fail("unbalance", data.get("unbalance", []), "must hold at least one entry unless solver.gravity is given: "
             "the scene has no load")
    return Scene(name=name, description=description, rotor=rotor, rotor_source=rotor_source,
                 operating=operating, unbalances=unbalances, plates=plates, solver=solver, output=output, runup=runup, source=source,
                 data=data, rotor_data=rotor_data)


def _check_balance(speeds: dict, plates, solver: SolverSpec) -> None:
    """Harmonic balance here is of a rub response without gravity (on a torus at incommensurate speeds)."""
    from rotorred.scenes.harmonic_balance import base_frequency

    if not plates:
        fail("solver.method", solver.method, "must have a rub plate ([[rub]]): harmonic balance here is of the rub "
             "response (a linear scene's settled response is harmonic already)")
    if solver.gravity:
        fail("solver.gravity", solver.gravity, 'must be 0 with solver.method = "harmonic-balance" (no static load in '
             "its forcing)", "m/s^2")
    if not _periodic(speeds):
        return  # a torus: its truncation was read in _solver_balance, the spools' orders are checked on its bases
    frequencies = tuple(w / (2 * math.pi) for w in speeds.values())
    f0 = base_frequency(frequencies)
    order = max(round(f / f0) for f in frequencies)
    if solver.harmonics is not None and solver.harmonics < order:
        fail("solver.harmonics", solver.harmonics, f"must reach the spools' harmonics of f0 = {f0:g} Hz (at least "
             f"{order})")


def _check_runup_solver(runup: RunupSpec, solver: SolverSpec) -> None:
    """A run-up steps with average-acceleration Newmark, records from t = 0, at a whole number of steps."""
    if solver.method != "newmark":
        fail("solver.method", solver.method, 'must be "newmark" with [runup] (average acceleration at varying speed)')
    if solver.tolerance is not None:
        fail("solver.tolerance", solver.tolerance, "is not available with [runup] (its estimates are for constant "
             "speeds): give solver.dt and solver.modes")
    if solver.record_start != 0.0:
        fail("solver.record_start", solver.record_start, "must be 0 with [runup]: the whole run-up is recorded", "s")
    ratio = runup.record_dt / solver.dt
    if ratio < 1 - _RTOL or abs(ratio - round(ratio)) > _RTOL * ratio:
        fail("runup.record_dt", runup.record_dt, f"must be a whole number (>= 1) of steps of solver.dt = "
             f"{solver.dt:g}", "s")
