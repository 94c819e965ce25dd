"""Scenes: a complete simulation described in one TOML file (rotor, speeds, loads, rubs, solver, outputs).

A scene is loaded and validated in full before anything is computed: every key is checked
(unknown keys, types, ranges, node numbers against the rotor), and an error names the key,
the value and what is allowed. The format, with every key's unit and default, is documented
in ``docs/scenes.md``; in short::

    name = "paper-rub"
    [rotor]                 # preset = "seed-rig" or file = "rig.toml"; optional Rayleigh override
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

Built-in scenes live in ``rotorred/scenes/*.toml`` (:func:`builtin_scenes`).
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from rotorred.transient.contact import RubPlate
from rotorred.model.rotor_file import load_rotor, presets
from rotorred.model.loads import Unbalance
from rotorred.model.rotor import Rotor
from rotorred.transient.plate import ClampedFreePlate, NavierPlate, RigidPlate

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib

__all__ = ["Scene", "SolverSpec", "OutputSpec", "SceneError", "load_scene", "scene_from_toml", "scene_from_dict",
           "builtin_scenes", "apply_settings", "parse_setting", "DIRECTIONS", "PLOTS", "FORMATS"]

DIRECTIONS = ("x", "y", "theta_x", "theta_y")
PLOTS = ("waveforms", "spectra", "orbits")
FORMATS = ("npz", "csv", "mat")
MODELS = ("reduced", "full")
STARTS = ("settled", "rest")
METHODS = ("newmark", "hht")
BENDING = ("navier", "clamped-free", "rigid")

_TOP_KEYS = {"name", "description", "rotor", "speeds", "unbalance", "rub", "solver", "output"}
_ROTOR_KEYS = {"preset", "file", "rayleigh_alpha", "rayleigh_beta"}
_UNBALANCE_KEYS = {"node", "m_e", "phase_deg"}
_RUB_NUMBERS = {"clearance": ("m", 0.0, False), "K_nr": ("N/m^1.5", 0.0, True), "c": ("s/m", 0.0, False),
                "mu_s": ("-", 0.0, False), "mu_d": ("-", 0.0, False), "m_p": ("kg", 0.0, True),
                "k_n": ("N/m", 0.0, False), "k_t": ("N/m", 0.0, False), "c_n": ("N s/m", 0.0, False),
                "c_t": ("N s/m", 0.0, False), "disk_radius": ("m", 0.0, True)}
_PLATE_NUMBERS = {"plate_a": ("m", 0.0, True), "plate_b": ("m", 0.0, True), "plate_h": ("m", 0.0, True),
                  "plate_E": ("Pa", 0.0, True), "plate_nu": ("-", None, False), "plate_xi": ("m", 0.0, True),
                  "plate_eta": ("m", 0.0, True), "a0": ("N/m", 0.0, True), "b0": ("N", 0.0, False)}
_RUB_KEYS = {"node", "theta_deg", "bending", "name"} | set(_RUB_NUMBERS) | set(_PLATE_NUMBERS)
_SOLVER_KEYS = {"model", "modes", "cutoff_hz", "boundary_nodes", "dt", "duration", "record_start", "start",
                "method", "alpha", "gravity"}
_OUTPUT_KEYS = {"nodes", "directions", "plots", "formats", "plot_window", "table", "line_threshold", "f_max_hz",
                "compare_normal"}
#: relative tolerance of the record-window tests (whole number of steps, of common periods)
_RTOL = 1e-9
#: tolerance of the Navier series of Eq. 10 (relative); 1e-6 is far below the uncertainty of any plate
#: dimension and converges within the series' term cap for a centrally loaded plate
NAVIER_TOL = 1e-6


class SceneError(ValueError):
    """A scene file that does not describe a valid simulation."""


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
    method : {"newmark", "hht"}
    alpha : float or None
        HHT-alpha parameter (only with method "hht").
    gravity : float
        Gravity along -y (m/s^2); 0 for none.
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
        Figures to draw: "waveforms", "spectra", "orbits".
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
class Scene:
    """A validated scene (see the module docstring and ``docs/scenes.md``).

    Attributes
    ----------
    name, description : str
    rotor : Rotor
        The rotor, with the scene's Rayleigh override applied.
    rotor_source : str
        Preset name or file path.
    speeds : dict of str to float
        Spool speeds (rad/s).
    unbalances : tuple of Unbalance
    plates : tuple of RubPlate
    solver : SolverSpec
    output : OutputSpec
    source : str
        Where the scene came from (file, built-in name or "<string>").
    data : dict
        The parsed TOML tables (for :func:`apply_settings` and re-loading).
    """

    name: str
    description: str
    rotor: Rotor
    rotor_source: str
    speeds: dict
    unbalances: tuple
    plates: tuple
    solver: SolverSpec
    output: OutputSpec
    source: str = "<string>"
    data: dict = field(default_factory=dict, repr=False, compare=False)

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


# --------------------------------------------------------------------------- loading
def builtin_scenes() -> list[str]:
    """Names of the built-in scenes (``rotorred/scenes/*.toml``)."""
    return sorted(p.name[:-5] for p in resources.files("rotorred.scenes.builtin").iterdir() if p.name.endswith(".toml"))


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
        text, source, base = path.read_text(), str(path), path.parent
    try:
        return tomllib.loads(text), source, base
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source}: not valid TOML: {exc}") from None


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
    """
    data, source, base = _read(spec)
    if settings:
        data = apply_settings(data, settings)
    return scene_from_dict(data, source=source, base=base)


def scene_from_toml(text: str, source: str = "<string>", base: Path | None = None) -> Scene:
    """Parse and validate a scene TOML document."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source}: not valid TOML: {exc}") from None
    return scene_from_dict(data, source=source, base=base)


def scene_from_dict(data: dict, source: str = "<string>", base: Path | None = None) -> Scene:
    """Build a :class:`Scene` from parsed TOML tables; raises :class:`SceneError` naming the key."""
    try:
        return _build(copy.deepcopy(data), source, base)
    except SceneError:
        raise
    except FileNotFoundError as exc:
        raise SceneError(f"{source}: {exc}") from None
    except (ValueError, TypeError) as exc:
        raise SceneError(f"{source}: {exc}") from None


# --------------------------------------------------------------------------- settings (--set)
def parse_setting(text: str) -> tuple[str, list]:
    """Parse ``"section.key=v1,v2,..."`` or ``"section.key=start:stop:n"`` into (key, values).

    Values are TOML values (numbers, strings, booleans); a bare word is a string.
    ``start:stop:n`` gives ``n`` evenly spaced numbers (n >= 2).
    """
    if "=" not in text:
        raise ValueError(f"`--set` must be KEY=VALUES (e.g. rub.clearance=10e-6,20e-6), got {text!r}")
    key, _, rhs = text.partition("=")
    key, rhs = key.strip(), rhs.strip()
    if not key or not rhs:
        raise ValueError(f"`--set` must be KEY=VALUES (e.g. rub.clearance=10e-6,20e-6), got {text!r}")
    if rhs.count(":") == 2 and "," not in rhs:
        a, b, n = rhs.split(":")
        try:
            a, b, n = float(a), float(b), int(n)
        except ValueError:
            raise ValueError(f"`--set {key}`: a range must be START:STOP:N with numbers and an integer N, "
                             f"got {rhs!r}") from None
        if n < 2:
            raise ValueError(f"`--set {key}`: a range needs N >= 2 points, got {n}")
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
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        if text and all(ch.isalnum() or ch in "_-:.+" for ch in text):
            return text  # a bare word, e.g. full or 14:y
        raise ValueError(f"`--set {key}`: cannot read the value {text!r}") from None


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
            raise ValueError(f"setting {key!r} must be KEY or SECTION.KEY (e.g. rub.clearance)")
        section, name = parts
        index = None
        if section.endswith("]") and "[" in section:
            section, _, idx = section[:-1].partition("[")
            try:
                index = int(idx)
            except ValueError:
                raise ValueError(f"setting {key!r}: the index in [] must be an integer") from None
        target = data.get(section)
        if isinstance(target, list):
            entries = target if index is None else [target[index]] if 0 <= index < len(target) else None
            if entries is None:
                raise ValueError(f"setting {key!r}: the scene has {len(target)} [[{section}]] entries")
            for entry in entries:
                entry[name] = value
        elif index is not None:
            raise ValueError(f"setting {key!r}: [{section}] is not an array of tables")
        elif target is None:
            if section in ("rub", "unbalance"):
                raise ValueError(f"setting {key!r}: the scene has no [[{section}]] entry to set")
            data[section] = {name: value}
        elif isinstance(target, dict):
            target[name] = value
        else:
            raise ValueError(f"setting {key!r}: {section!r} is not a table")
    return data


# --------------------------------------------------------------------------- checks
def _keys(where: str, table, allowed: set[str], required: set[str] = frozenset()) -> None:
    if not isinstance(table, dict):
        raise SceneError(f"`{where}` must be a table, got {table!r}")
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise SceneError(f"unknown key(s) {', '.join(f'`{where}.{k}`' if where else f'`{k}`' for k in unknown)}; "
                         f"allowed: {', '.join(sorted(allowed))}")
    missing = sorted(required - set(table))
    if missing:
        raise SceneError(f"missing key(s) {', '.join(f'`{where}.{k}`' for k in missing)}")


def _number(where: str, value, unit: str, minimum: float | None = None, strict: bool = False) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if ok and minimum is not None:
        ok = value > minimum if strict else value >= minimum
    if not ok:
        rel = "" if minimum is None else (f" > {minimum:g}" if strict else f" >= {minimum:g}")
        raise SceneError(f"`{where}` must be a finite number{rel} ({unit}), got {value!r}")
    return float(value)


def _integer(where: str, value, minimum: int | None = None) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or (minimum is not None and value < minimum):
        rel = "" if minimum is None else f" >= {minimum}"
        raise SceneError(f"`{where}` must be an integer{rel}, got {value!r}")
    return value


def _choice(where: str, value, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise SceneError(f"`{where}` must be one of {', '.join(repr(a) for a in allowed)}, got {value!r}")
    return value


def _string(where: str, value) -> str:
    if not isinstance(value, str):
        raise SceneError(f"`{where}` must be a string, got {value!r}")
    return value


def _node(where: str, value, rotor: Rotor) -> int:
    _integer(where, value)
    if value not in rotor.spool_of:
        raise SceneError(f"`{where}` = {value} is not a node of the rotor; nodes are "
                         f"{min(rotor.nodes)}-{max(rotor.nodes)} ({sorted(rotor.nodes)})")
    return value


def _list(where: str, value, item_check) -> tuple:
    if not isinstance(value, list):
        raise SceneError(f"`{where}` must be a list, got {value!r}")
    return tuple(item_check(f"{where}[{i}]", v) for i, v in enumerate(value))


# --------------------------------------------------------------------------- build
def _rotor(table, base: Path | None) -> tuple[Rotor, str]:
    _keys("rotor", table, _ROTOR_KEYS)
    if ("preset" in table) == ("file" in table):
        raise SceneError(f"`rotor` must give exactly one of `rotor.preset` ({', '.join(presets())}) or `rotor.file` "
                         f"(a rotor TOML path), got {sorted(k for k in table if k in ('preset', 'file')) or 'neither'}")
    if "preset" in table:
        name = _string("rotor.preset", table["preset"])
        if name not in presets():
            raise SceneError(f"`rotor.preset` must be one of {', '.join(repr(p) for p in presets())}, got {name!r}")
        rotor, source = load_rotor(name), name
    else:
        path = Path(_string("rotor.file", table["file"]))
        if not path.is_absolute() and base is not None:
            path = base / path
        if not path.is_file():
            raise SceneError(f"`rotor.file` {str(path)!r} does not exist")
        rotor, source = load_rotor(path), str(path)
    alpha, beta = rotor.rayleigh
    if "rayleigh_alpha" in table:
        alpha = _number("rotor.rayleigh_alpha", table["rayleigh_alpha"], "1/s", 0.0)
    if "rayleigh_beta" in table:
        beta = _number("rotor.rayleigh_beta", table["rayleigh_beta"], "s", 0.0)
    if (alpha, beta) != tuple(rotor.rayleigh):
        rotor = dataclasses.replace(rotor, rayleigh=(alpha, beta))
    return rotor, source


def _speeds(table, rotor: Rotor) -> dict[str, float]:
    names = [s.name for s in rotor.spools]
    speeds = dict(rotor.speeds)
    if table is None:
        return speeds
    _keys("speeds", table, set(names))
    for s, v in table.items():
        speeds[s] = 2 * math.pi * _number(f"speeds.{s}", v, "Hz", 0.0)
    return speeds


def _check_turning(speeds: dict[str, float], table) -> None:
    if not any(w > 0 for w in speeds.values()):
        raise SceneError(f"every spool speed is 0 (the rotor's nominal speeds{' and `speeds`' if table else ''}); "
                         f"give `speeds.<spool>` in Hz (> 0) for at least one of {sorted(speeds)}")


def _unbalances(entries, rotor: Rotor) -> tuple[Unbalance, ...]:
    if not isinstance(entries, list):
        raise SceneError(f"`unbalance` must be an array of tables ([[unbalance]]), got {entries!r}")
    out = []
    for i, u in enumerate(entries):
        where = f"unbalance[{i}]"
        _keys(where, u, _UNBALANCE_KEYS, required={"node", "m_e"})
        node = _node(f"{where}.node", u["node"], rotor)
        m_e = _number(f"{where}.m_e", u["m_e"], "kg m", 0.0)
        phase = math.radians(_number(f"{where}.phase_deg", u.get("phase_deg", 0.0), "deg"))
        out.append(Unbalance(node, m_e, phase))
    return tuple(out)


def _bending(where: str, r: dict):
    kind = _choice(f"{where}.bending", r.get("bending", "navier"), BENDING)
    allowed = {"navier": {"plate_a", "plate_b", "plate_h", "plate_E", "plate_nu", "plate_xi", "plate_eta"},
               "clamped-free": {"a0", "b0"}, "rigid": set()}[kind]
    stray = sorted(k for k in _PLATE_NUMBERS if k in r and k not in allowed)
    if stray:
        raise SceneError(f"`{where}.{stray[0]}` does not apply to `{where}.bending` = {kind!r}; "
                         f"its keys are {', '.join(sorted(allowed)) or 'none'}")
    vals = {}
    for k in allowed:
        if k in r:
            unit, lo, strict = _PLATE_NUMBERS[k]
            vals[k] = _number(f"{where}.{k}", r[k], unit, lo, strict)
    if kind == "rigid":
        return RigidPlate()
    if kind == "clamped-free":
        return ClampedFreePlate(**vals)
    kw = {k[len("plate_"):]: v for k, v in vals.items()}
    if "nu" in kw and not -1.0 < kw["nu"] < 0.5:
        raise SceneError(f"`{where}.plate_nu` must lie in (-1, 0.5), got {kw['nu']!r}")
    try:
        return NavierPlate(tol=NAVIER_TOL, **kw)
    except ValueError as exc:
        raise SceneError(f"`{where}`: {exc}".replace("`xi`", f"`{where}.plate_xi`")
                         .replace("`eta`", f"`{where}.plate_eta`")) from None


def _plates(entries, rotor: Rotor) -> tuple[RubPlate, ...]:
    if not isinstance(entries, list):
        raise SceneError(f"`rub` must be an array of tables ([[rub]]), got {entries!r}")
    out = []
    for i, r in enumerate(entries):
        where = f"rub[{i}]"
        _keys(where, r, _RUB_KEYS, required={"node", "clearance"})
        node = _node(f"{where}.node", r["node"], rotor)
        kw = {}
        for k, (unit, lo, strict) in _RUB_NUMBERS.items():
            if k in r:
                kw[k] = _number(f"{where}.{k}", r[k], unit, lo, strict)
        if "mu_s" in kw or "mu_d" in kw:
            mu_s = kw.get("mu_s", RubPlate.mu_s)
            mu_d = kw.get("mu_d", RubPlate.mu_d)
            if mu_d > mu_s:
                raise SceneError(f"`{where}.mu_d` = {mu_d:g} must not exceed `{where}.mu_s` = {mu_s:g}")
        theta = math.radians(_number(f"{where}.theta_deg", r.get("theta_deg", 90.0), "deg"))
        if "disk_radius" not in kw:
            disk = next((d for d in rotor.disks if d.node == node), None)
            if disk is None or disk.radius <= 0:
                raise SceneError(f"`{where}.node` = {node} carries no disk with a radius; rub plates face a disk "
                                 f"(disks with a radius at nodes "
                                 f"{[d.node for d in rotor.disks if d.radius > 0]}) or give `{where}.disk_radius`")
            kw["disk_radius"] = disk.radius
        name = _string(f"{where}.name", r.get("name", f"rub plate at node {node}"))
        out.append(RubPlate(node=node, theta=theta, bending=_bending(where, r), name=name, **kw))
    return tuple(out)


def _solver(table, rotor: Rotor, speeds: dict[str, float]) -> SolverSpec:
    table = {} if table is None else table
    _keys("solver", table, _SOLVER_KEYS)
    d = SolverSpec()
    model = _choice("solver.model", table.get("model", d.model), MODELS)
    modes = table.get("modes", None)
    if modes == "auto":
        modes = None
    if modes is not None:
        if not isinstance(modes, int) or isinstance(modes, bool) or modes < 0:
            raise SceneError(f"`solver.modes` must be \"auto\" or an integer >= 0, got {modes!r}")
    cutoff = table.get("cutoff_hz")
    if cutoff is not None:
        cutoff = _number("solver.cutoff_hz", cutoff, "Hz", 0.0, strict=True)
        if modes is not None:
            raise SceneError(f"give `solver.modes` or `solver.cutoff_hz`, not both (got {modes!r} and {cutoff!r})")
    # modes, cutoff_hz and boundary_nodes are validated but unused with model = "full", so that
    # `--set solver.model=full` switches a reduced scene to the full model
    boundary = _list("solver.boundary_nodes", table.get("boundary_nodes", []), lambda w, v: _node(w, v, rotor))
    dt = _number("solver.dt", table.get("dt", d.dt), "s", 0.0, strict=True)
    duration = _number("solver.duration", table.get("duration", d.duration), "s", 0.0, strict=True)
    record_start = _number("solver.record_start", table.get("record_start", d.record_start), "s", 0.0)
    if dt >= duration:
        raise SceneError(f"`solver.dt` = {dt:g} s must be smaller than `solver.duration` = {duration:g} s")
    if record_start >= duration:
        raise SceneError(f"`solver.duration` = {duration:g} s must exceed `solver.record_start` = {record_start:g} s "
                         f"(the recorded window is record_start..duration)")
    for name, value in (("duration", duration), ("record_start", record_start)):
        steps = value / dt
        if abs(steps - round(steps)) > _RTOL * max(steps, 1.0):
            raise SceneError(f"`solver.{name}` = {value:g} s must be a whole number of steps `solver.dt` = {dt:g} s "
                             f"(got {steps:.6g} steps)")
    # The spectrum needs two common periods of the spools (lines 1/T apart must be resolved).
    f = sorted(w / (2 * math.pi) for w in speeds.values() if w > 0)
    if len(f) >= 2:
        from fractions import Fraction
        ratio = Fraction(f[-1] / f[0]).limit_denominator(100)
        if abs(f[-1] / f[0] - float(ratio)) <= _RTOL * f[-1] / f[0]:
            period = ratio.denominator / f[0]
            if duration - record_start < 2 * period * (1 - _RTOL):
                raise SceneError(f"the recorded window `solver.duration` - `solver.record_start` = "
                                 f"{duration - record_start:g} s is shorter than two common periods of the spools "
                                 f"(2 x {period:g} s), too short to resolve their combination lines")
    start = _choice("solver.start", table.get("start", d.start), STARTS)
    method = _choice("solver.method", table.get("method", d.method), METHODS)
    alpha = table.get("alpha")
    if alpha is not None:
        if method != "hht":
            raise SceneError("`solver.alpha` applies to `solver.method` = \"hht\" only")
        alpha = _number("solver.alpha", alpha, "-")
        if not -1 / 3 <= alpha <= 0:
            raise SceneError(f"`solver.alpha` must lie in [-1/3, 0], got {alpha!r}")
    gravity = _number("solver.gravity", table.get("gravity", d.gravity), "m/s^2")
    return SolverSpec(model=model, modes=modes, cutoff_hz=cutoff, boundary_nodes=boundary, dt=dt, duration=duration,
                      record_start=record_start, start=start, method=method, alpha=alpha, gravity=gravity)


def _dof_text(where: str, value, rotor: Rotor) -> tuple[int, str]:
    text = _string(where, value)
    node, _, direction = text.partition(":")
    try:
        node = int(node)
    except ValueError:
        raise SceneError(f"`{where}` must be NODE:DIR (e.g. \"14:y\"), got {value!r}") from None
    _node(where, node, rotor)
    _choice(where + " direction", direction, DIRECTIONS)
    return node, direction


def _output(table, rotor: Rotor, solver: SolverSpec, plates) -> OutputSpec:
    table = {} if table is None else table
    _keys("output", table, _OUTPUT_KEYS)
    d = OutputSpec()
    default_nodes = [min(rotor.nodes)] if not plates else [plates[0].node]
    nodes = _list("output.nodes", table.get("nodes", default_nodes), lambda w, v: _node(w, v, rotor))
    if not nodes:
        raise SceneError("`output.nodes` must name at least one node")
    if len(set(nodes)) != len(nodes):
        raise SceneError(f"`output.nodes` lists a node twice: {list(nodes)}")
    directions = _list("output.directions", table.get("directions", list(d.directions)),
                       lambda w, v: _choice(w, v, DIRECTIONS))
    if not directions or len(set(directions)) != len(directions):
        raise SceneError(f"`output.directions` must list distinct directions of {DIRECTIONS}, got {list(directions)}")
    plots = _list("output.plots", table.get("plots", list(d.plots)), lambda w, v: _choice(w, v, PLOTS))
    formats = _list("output.formats", table.get("formats", list(d.formats)), lambda w, v: _choice(w, v, FORMATS))
    if "orbits" in plots and not {"x", "y"} <= set(directions):
        raise SceneError("`output.plots` asks for \"orbits\", which need both \"x\" and \"y\" in `output.directions`")
    window = table.get("plot_window")
    lo, hi = solver.record_start, solver.duration
    if window is not None:
        window = _list("output.plot_window", window, lambda w, v: _number(w, v, "s"))
        if len(window) != 2 or not lo - 1e-12 <= window[0] < window[1] <= hi + 1e-12:
            raise SceneError(f"`output.plot_window` must be [start, end] inside the recorded window "
                             f"[{lo:g}, {hi:g}] s with start < end, got {list(window)}")
    table_dof = table.get("table")
    if table_dof is not None:
        table_dof = _dof_text("output.table", table_dof, rotor)
        if table_dof not in set((n, dd) for n in nodes for dd in directions):
            raise SceneError(f"`output.table` = {table.get('table')!r} is not a recorded DOF (`output.nodes` x "
                             f"`output.directions`)")
    threshold = _number("output.line_threshold", table.get("line_threshold", d.line_threshold), "-", 0.0, True)
    if threshold > 1:
        raise SceneError(f"`output.line_threshold` must lie in (0, 1], got {threshold!r}")
    f_max = table.get("f_max_hz")
    if f_max is not None:
        f_max = _number("output.f_max_hz", f_max, "Hz", 0.0, strict=True)
    compare = table.get("compare_normal", d.compare_normal)
    if not isinstance(compare, bool):
        raise SceneError(f"`output.compare_normal` must be true or false, got {compare!r}")
    return OutputSpec(nodes=nodes, directions=directions, plots=plots, formats=formats,
                      plot_window=None if window is None else (window[0], window[1]), table=table_dof,
                      line_threshold=threshold, f_max_hz=f_max, compare_normal=compare)


def _build(data: dict, source: str, base: Path | None) -> Scene:
    _keys("", data, _TOP_KEYS, required={"rotor"})
    name = _string("name", data.get("name", Path(source).stem if base is not None else source))
    description = _string("description", data.get("description", ""))
    rotor, rotor_source = _rotor(data["rotor"], base)
    speeds = _speeds(data.get("speeds"), rotor)
    _check_turning(speeds, data.get("speeds"))
    unbalances = _unbalances(data.get("unbalance", []), rotor)
    plates = _plates(data.get("rub", []), rotor)
    solver = _solver(data.get("solver"), rotor, speeds)
    output = _output(data.get("output"), rotor, solver, plates)
    if not unbalances and solver.gravity == 0:
        raise SceneError("the scene has no load: give at least one `[[unbalance]]` (or `solver.gravity`)")
    return Scene(name=name, description=description, rotor=rotor, rotor_source=rotor_source, speeds=speeds,
                 unbalances=unbalances, plates=plates, solver=solver, output=output, source=source, data=data)
