"""Rotor files (TOML): load and validate, with errors that name the field, the value and what is allowed.

A rotor is given by a preset name (``seed-rig``, ``nelson-mcvaugh``; see :func:`presets`) or a
path to a TOML file. The format is documented in docs/rotor-files.md; in short::

    name = "my-rotor"
    [[material]]                       # E (Pa), rho (kg/m^3), nu (-) or G (Pa, shear modulus)
    name = "steel"; E = 2.1e11; rho = 7850.0; nu = 0.3
    [[spool]]                          # a chain of elements on consecutive node numbers (or nodes = [1, 2, 7, ...])
    name = "inner"; first_node = 1; z0 = 0.0; speed_rpm = 4200.0; shear = "cowper"; element = "nelson"
    internal_damping_beta = 0.0        # rotating damping beta K (s), or internal_loss_factor (-); also per element
    elements = [ { L = 0.08, D_o = 0.02, D_i = 0.0, material = "steel", repeat = 12 } ]
    [[disk]]                           # either m, I_d, I_p (kg, kg m^2) or D_o, D_i, thickness, material
    node = 3; m = 5.7; I_d = 0.023; I_p = 0.045; radius = 0.125
    [[bearing]]                        # k_* (N/m), c_* (N s/m); k / c set both direct terms
    node = 1; k = 2e7; c = 300.0
    [[bearing]]                        # against speed: speed_rpm and, per coefficient, a number or a list
    node = 13; speed_rpm = [0.0, 3000.0, 6000.0]; k = [1e7, 2e7, 3e7]; c_xx = [400.0, 300.0, 250.0]
    [[bearing]]                        # tilt: k_tt / c_tt (N m/rad, N m s/rad) or k_txtx, k_tyty, k_txty, k_tytx, ...
    node = 7; k = 1e8; k_tt = 2e5      # (frequency_rpm in place of speed_rpm: a table against whirl frequency)
    [[intershaft_bearing]]             # a table too, against the speed of the spool speed_of (default node_a's)
    node_a = 20; node_b = 9; k = 1e7; c = 300.0
    [[support]]                        # a rigid support: "pinned" fixes x, y; "clamped" also theta_x, theta_y
    node = 1; kind = "pinned"
    [[pedestal]]                       # an off-shaft node (x, y) with mass (kg); a [[bearing]] at it holds it to
    node = 30; m = 20.0                # ground, a [[bearing]] with link = 30 joins a shaft node to it
    [damping]
    rayleigh_alpha = 0.0; rayleigh_beta = 0.0
    [defaults]                         # what analyses use when nothing else is given (all optional)
    unbalance = [ { node = 11, m_e = 1e-5, phase_deg = 0.0 } ]   # kg m, deg
    outputs = ["13:x", "13:y"]         # NODE:DIRECTION, DIRECTION x, y, theta_x (tx), theta_y (ty)
    boundary_nodes = [18]              # extra boundary nodes of a reduced model
    operating_range_rpm = { inner = [3000.0, 4500.0] }   # a spool's minimum and maximum continuous speed (API 617)

Speeds and phases may also be given in SI (``speed_rad_s``, ``phase_rad``), as :meth:`Rotor.to_toml` writes those
that no rpm or degree number reads back to exactly (docs/model.md §18).

Every value is checked as written, in the file's units (speeds in rpm), before it is converted;
an error is a :class:`RotorFileError` (a :class:`rotorred.checks.InputError`) naming the file, the
key path, the value and what is allowed, e.g.
``rig.toml: spool[0].elements[1].D_i = 0.03: must be < D_o = 0.02 (m)``.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from rotorred import checks
from rotorred.checks import InputError
from rotorred.model.dofs import parse_dof
from rotorred.model.elements import (FORMULATIONS, SHEAR_METHODS, Bearing, BearingTable, Disk, IntershaftBearing,
                                     IntershaftBearingTable, Material, Pedestal, ShaftElement, Support)
from rotorred.model.loads import unbalance_from_table
from rotorred.model import ross_file
from rotorred.model.assembly import assemble
from rotorred.model.rigid import null_space
from rotorred.model.ross_file import is_ross_document, ross_document
from rotorred.model.rotor import AnalysisDefaults, Rotor, Spool
from rotorred.model.rotor_writer import rpm_to_rad_s

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib

__all__ = ["RotorFileError", "presets", "load_rotor", "read_rotor", "ROTOR_FILE_KEYS", "read_rotor_toml",
           "rotor_document", "rotor_from_toml", "rotor_from_dict", "read_toml"]

_TOP_KEYS = {"name", "description", "material", "spool", "disk", "bearing", "intershaft_bearing", "support", "pedestal",
             "damping", "defaults"}
#: the top-level keys of a rotor file (a scene's inline ``[rotor]`` holds them too)
ROTOR_FILE_KEYS = frozenset(_TOP_KEYS)
_MATERIAL_KEYS = {"name", "E", "rho", "nu", "G"}
#: internal (rotating) damping: on a spool (its elements' default) or an element, sleeve or station (docs/model.md §19)
_INTERNAL_KEYS = {"internal_damping_beta", "internal_loss_factor"}
_SPOOL_KEYS = {"name", "first_node", "nodes", "z0", "speed_rpm", "speed_rad_s", "shear", "element", "rotary_inertia",
               "elements", "stations", "material", "sleeves"} | _INTERNAL_KEYS
_SLEEVE_KEYS = {"left", "D_o", "D_i", "D_o_right", "D_i_right", "material", "repeat", "shear", "element",
                "rotary_inertia"} | _INTERNAL_KEYS
_STATION_KEYS = {"z", "D_o", "D_i", "D_o_end", "D_i_end", "material", "n", "shear", "element",
                 "rotary_inertia"} | _INTERNAL_KEYS
_ELEMENT_KEYS = {"L", "D_o", "D_i", "D_o_right", "D_i_right", "material", "repeat", "shear", "element",
                 "rotary_inertia"} | _INTERNAL_KEYS
_DISK_KEYS = {"node", "name", "m", "I_d", "I_p", "radius", "D_o", "D_i", "thickness", "material"}
_SUPPORT_KEYS = {"name", "k", "c", "k_xx", "k_yy", "k_xy", "k_yx", "c_xx", "c_yy", "c_xy", "c_yx", "k_tt", "c_tt",
                 "k_txtx", "k_tyty", "k_txty", "k_tytx", "c_txtx", "c_tyty", "c_txty", "c_tytx"}
#: a support's isotropic shorthands: each sets the two direct coefficients (docs/model.md §20)
_SHORTHANDS = {"k": ("k_xx", "k_yy", "N/m"), "c": ("c_xx", "c_yy", "N s/m"), "k_tt": ("k_txtx", "k_tyty", "N m/rad"),
               "c_tt": ("c_txtx", "c_tyty", "N m s/rad")}
#: the keys of a bearing table's axis, in rpm or rad/s: spool speed, or whirl frequency (evaluated at the spool speed)
_AXIS_KEYS = {"speed": ("speed_rpm", "speed_rad_s"), "frequency": ("frequency_rpm", "frequency_rad_s")}
_DAMPING_KEYS = {"rayleigh_alpha", "rayleigh_beta"}
_SUPPORT_NODE_KEYS = {"node", "kind", "name"}
_TABLE_KEYS = {"extrapolate", "interpolation"}  # a bearing table's rules, with speed_rpm only
_DEFAULTS_KEYS = {"unbalance", "outputs", "boundary_nodes", "operating_range_rpm", "operating_range_rad_s"}
#: Rotor attribute -> rotor-file key, to name the file's key in an error from Rotor's own checks
_FILE_KEYS = {"spools": "spool", "disks": "disk", "bearings": "bearing", "intershaft_bearings": "intershaft_bearing",
              "supports": "support", "pedestals": "pedestal"}


class RotorFileError(InputError):
    """A rotor file that does not describe a valid rotor (an :class:`rotorred.checks.InputError`)."""


def presets() -> list[str]:
    """Names of the built-in rotors."""
    return sorted(p.name[:-5] for p in resources.files("rotorred.model.presets").iterdir() if p.name.endswith(".toml"))


def load_rotor(spec: str | Path) -> Rotor:
    """Load a rotor from a preset name or a TOML file.

    Parameters
    ----------
    spec : str or Path
        A preset name (see :func:`presets`) or the path of a rotor TOML file.

    Returns
    -------
    Rotor

    Raises
    ------
    RotorFileError
        For a file that does not describe a valid rotor, naming the file and the key.
    FileNotFoundError
        If ``spec`` is neither a preset nor an existing file.
    """
    return read_rotor(spec)[0]


def read_rotor(spec: str | Path) -> tuple[Rotor, dict[str, Any]]:
    """The rotor of a preset name or a TOML file (:func:`load_rotor`) and its rotor-file document: the parsed
    tables as written (a ROSS file's converted, :func:`rotor_document`), which :func:`rotor_from_dict` makes the
    same rotor again, and :func:`rotorred.writers.toml_text` writes as a rotor file.

    Parameters
    ----------
    spec : str or Path
        A preset name (:func:`presets`) or the path of a rotor file, or of a rotor saved by ROSS 3 (TOML).

    Returns
    -------
    rotor : Rotor
    document : dict
        The rotor-file tables in the file's units (speeds in rpm or rad/s, phases in degrees or rad, as the
        file gives them; the rest SI).

    Raises
    ------
    RotorFileError
        For a file that does not describe a valid rotor, naming the file and the key.
    FileNotFoundError
        If ``spec`` is neither a preset nor an existing file.
    """
    spec_str = str(spec)
    if spec_str in presets():
        text = resources.files("rotorred.model.presets").joinpath(f"{spec_str}.toml").read_text()
        source, name = f"preset {spec_str!r}", "ross-rotor"
    else:
        path = Path(spec)
        if not path.exists():
            raise FileNotFoundError(f"rotor {spec_str!r} is neither a preset ({', '.join(presets())}) nor an "
                                    "existing file")
        text, source, name = read_text_file(path, RotorFileError), str(path), path.stem
    document = rotor_document(read_rotor_toml(text, source), source, name)
    try:
        return rotor_from_dict(document), document
    except RotorFileError as exc:
        raise exc.from_source(source) from None


def convert_ross(source: str | Path, target: str | Path) -> Rotor:
    """Read a rotor saved by ROSS 3 (``ross.Rotor.save``, TOML) and write it as a rotorred rotor file.

    The rotor is checked as :func:`load_rotor` reads it, then written by :meth:`Rotor.to_toml` with a header naming
    the source and its ROSS version (axial and torsional coefficients of ROSS's 6-DOF model are not read:
    docs/model.md §14).

    Parameters
    ----------
    source : str or Path
        The ROSS file.
    target : str or Path
        The rotorred rotor file to write (.toml).

    Returns
    -------
    Rotor
        The rotor written.

    Raises
    ------
    rotorred.checks.InputError
        For a source that is not a rotor saved by ROSS, or that rotorred cannot read (naming the entry).
    """
    source = Path(source)
    data = read_rotor_toml(read_text_file(source, RotorFileError), str(source))
    if not is_ross_document(data):
        raise InputError("source", str(source), "must be a rotor saved by ROSS (it has no ross_version line); it "
                         "reads as a rotorred rotor file already")
    try:
        rotor = rotor_from_dict(rotor_document(data, str(source), name=source.stem))
    except RotorFileError as exc:
        raise exc.from_source(str(source)) from None
    rotor.to_toml(target, header=f"rotorred rotor file converted from {source.name} (saved by ROSS "
                                 f"{data.get('ross_version')}) by `rotorred convert`\n(axial and torsional "
                                 "coefficients of ROSS's 6-DOF model are not read: docs/model.md §14)")
    return rotor


def read_rotor_toml(text: str, source: str = "<string>") -> dict[str, Any]:
    """The parsed TOML of a rotor file (rotorred's or ROSS's); a syntax error is a :class:`RotorFileError` naming
    ``source``."""
    try:
        return read_toml(text, RotorFileError)
    except RotorFileError as exc:
        raise exc.from_source(source) from None


def rotor_document(data: dict[str, Any], source: str = "<string>", name: str = "ross-rotor") -> dict[str, Any]:
    """The rotor-file document of parsed TOML: a rotorred rotor file as it is, a rotor saved by ROSS 3 converted
    (:func:`rotorred.model.ross_file.ross_document`, named ``name``).

    Raises
    ------
    RotorFileError
        For a ROSS rotor rotorred cannot represent, naming ``source`` and the key.
    """
    if not is_ross_document(data):
        return data
    try:
        document = ross_document(data, name)
    except InputError as exc:
        raise RotorFileError(exc.field, exc.value, exc.requirement, exc.unit).from_source(source) from None
    _note_ross_hutchinson(document)
    return document


def _note_ross_hutchinson(document: dict[str, Any]) -> None:
    """Say at load how much a ROSS rotor read with Hutchinson's published shear coefficient differs from ROSS's own
    (which omits a factor 1 + nu, :func:`rotorred.model.elements.shear_coefficient`): the relative change of kappa and
    of the rotor's first natural frequency at standstill (undamped), as a warning of ``rotorred.model.ross_file``."""
    as_ross = copy.deepcopy(document)
    entries = [e for s in as_ross["spool"] for e in (*s["elements"], *s.get("sleeves", ()))
               if e.get("shear") == "hutchinson"]
    if not entries:
        return
    for e in entries:
        e["shear"] = "ross-hutchinson"
    try:
        published, as_ross = rotor_from_dict(document), rotor_from_dict(as_ross)
    except InputError:
        return  # the load itself says what is wrong
    pairs = [(a, b) for s, t in zip(published.spools, as_ross.spools) for a, b in zip(s.all_elements, t.all_elements)
             if a.shear == "hutchinson"]
    kappa = [b.kappa / a.kappa - 1.0 for a, b in pairs]
    w_published, w_ross = (_first_frequency(r) for r in (published, as_ross))
    ross_file.LOG.warning(
        "%d shaft elements use ROSS's Hutchinson shear coefficient (shear_method_calc = 'hutchinson'), which omits a "
        "factor 1 + nu of the published formula (Hutchinson 2001, Eq. 52) that rotorred uses: ROSS's kappa differs "
        "by %s and the first natural frequency at standstill by %+.3g %% (ROSS %.6g rad/s, rotorred %.6g rad/s). "
        "shear = 'ross-hutchinson' on these elements reproduces ROSS (docs/model.md §20)",
        len(pairs), " to ".join(dict.fromkeys(f"{100 * k:+.3g} %" for k in (min(kappa), max(kappa)))),
        100 * (w_ross / w_published - 1.0), w_ross, w_published)


def _first_frequency(rotor: Rotor) -> float:
    """The lowest undamped natural frequency (rad/s) of ``rotor`` at its nominal speeds, gyroscopic terms left out:
    sqrt of the least positive eigenvalue of (K, M) that is no rigid-body motion (:func:`rotorred.model.rigid.
    null_space`)."""
    w2, _, rigid = null_space(assemble(rotor))
    return float(np.sqrt(w2[~rigid & (w2 > 0.0)][0]))


def read_text_file(path: Path, error: type[InputError] = InputError) -> str:
    """The text of a TOML file; a file that is not UTF-8 text (a binary or Latin-1 file) is an ``error`` naming it."""
    data = Path(path).read_bytes()
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(str(path), data[exc.start:exc.start + 1],
                    f"must be a UTF-8 text (TOML) file; byte {exc.start} is not UTF-8") from None


def read_toml(text: str, error: type[InputError] = InputError) -> dict[str, Any]:
    """Parse a TOML document; a syntax error is an ``error`` naming the line, its text and the reason."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        reason = str(exc)
        at = re.search(r"\s*\(at line (\d+), column (\d+)\)$", reason)
        if at is None:
            raise error("TOML", text, f"must be valid TOML: {reason}") from None
        line, column = int(at.group(1)), int(at.group(2))
        lines = text.splitlines()
        value = lines[line - 1] if 0 < line <= len(lines) else ""
        key = value.split("=", 1)[0].strip() if "=" in value else ""
        if reason.startswith("Cannot overwrite a value") and key:
            raise error(key, value.split("=", 1)[1].strip(), f"must be given once; it is given again on line {line}") \
                from None
        raise error(f"line {line}", value, f"must be valid TOML: {reason[:at.start()]} at column {column}") from None


def rotor_from_toml(text: str, source: str = "<string>", name: str = "ross-rotor") -> Rotor:
    """Parse and validate a rotor TOML document; see the module docstring for the format. A rotor saved by ROSS 3
    is read too (:func:`rotor_document`), and named ``name``.

    Raises
    ------
    RotorFileError
        Naming ``source``, the key path, the value and what is allowed.
    """
    document = rotor_document(read_rotor_toml(text, source), source, name)
    try:
        return rotor_from_dict(document)
    except RotorFileError as exc:
        raise exc.from_source(source) from None


def rotor_from_dict(data: dict[str, Any]) -> Rotor:
    """Build a :class:`Rotor` from the parsed TOML tables; :class:`RotorFileError` naming the key."""
    try:
        return _rotor(checks.table("rotor file", data))
    except InputError as exc:
        raise RotorFileError(exc.field, exc.value, exc.requirement, exc.unit, exc.source) from None


# --- the tables, one step each --------------------------------------------------------------
def _rotor(data: dict) -> Rotor:
    checks.keys("", data, _TOP_KEYS)
    name = checks.string("name", data.get("name", ""))
    checks.string("description", data.get("description", ""))
    materials = _materials(data.get("material", []))
    spools = _spools(data.get("spool", checks.MISSING), materials)
    nodes = {n for s in spools for n in s.nodes}
    disks = tuple(_disk(f"disk[{i}]", d, materials)
                  for i, d in enumerate(checks.tables("disk", data.get("disk", []))))
    bearings = tuple(_bearing(f"bearing[{i}]", b)
                     for i, b in enumerate(checks.tables("bearing", data.get("bearing", []))))
    inter = tuple(_intershaft_bearing(f"intershaft_bearing[{i}]", b)
                  for i, b in enumerate(checks.tables("intershaft_bearing", data.get("intershaft_bearing", []))))
    supports = tuple(_support(f"support[{i}]", sp) for i, sp in enumerate(checks.tables("support", data.get("support", []))))
    pedestals = tuple(_pedestal(f"pedestal[{i}]", p)
                      for i, p in enumerate(checks.tables("pedestal", data.get("pedestal", []))))
    rayleigh = _damping(data.get("damping", {}))
    defaults = _defaults(data.get("defaults", {}), nodes, [s.name for s in spools])
    try:
        return Rotor(spools=spools, disks=disks, bearings=bearings, intershaft_bearings=inter, rayleigh=rayleigh,
                     name=name, defaults=defaults, supports=supports, pedestals=pedestals)
    except InputError as exc:  # Rotor names its attributes (disks[0].node); the file's keys are disk[0].node
        head, _, rest = exc.field.partition("[")
        field = f"{_FILE_KEYS[head]}[{rest}" if head in _FILE_KEYS and rest else exc.field
        raise InputError(field, exc.value, exc.requirement, exc.unit) from None


def _build(where: str, cls, **kwargs):
    """``cls(**kwargs)``, its InputError prefixed with the key path ``where``."""
    try:
        return cls(**kwargs)
    except InputError as exc:
        raise exc.within(where) from None


def _materials(value) -> dict[str, Material]:
    materials: dict[str, Material] = {}
    for i, m in enumerate(checks.tables("material", value)):
        where = f"material[{i}]"
        checks.keys(where, m, _MATERIAL_KEYS, required={"name", "E", "rho"})
        name = checks.string(f"{where}.name", m["name"], empty=False)
        if name in materials:
            checks.fail(f"{where}.name", name, "must differ from the names of the other [[material]] tables")
        materials[name] = _build(where, Material, name=name, E=m["E"], rho=m["rho"], nu=m.get("nu"), G=m.get("G"))
    return materials


def _material(field: str, name, materials: dict[str, Material]) -> Material:
    if not materials:
        checks.fail(field, name, "must name a [[material]] table; there is none")
    return materials[checks.choice(field, name, sorted(materials))]


def _spools(value, materials: dict[str, Material]) -> tuple[Spool, ...]:
    if value is checks.MISSING:
        raise InputError("spool", checks.MISSING, "required: at least one [[spool]] table")
    return tuple(_spool(f"spool[{i}]", s, materials) for i, s in enumerate(checks.tables("spool", value, min_len=1)))


def _spool(where: str, s: dict, materials: dict[str, Material]) -> Spool:
    checks.keys(where, s, _SPOOL_KEYS, required={"name"})
    _one_of(where, s, ("first_node", "nodes"))
    _one_of(where, s, ("speed_rpm", "speed_rad_s"), required=False)
    if ("elements" in s) == ("stations" in s):
        checks.fail(where, sorted(k for k in ("elements", "stations") if k in s) or "neither",
                    "must give the shaft either as elements (a list of L, D_o, D_i, ...) or as stations (a list of z, D_o, "
                    "D_i, ...), one of the two")
    name = checks.string(f"{where}.name", s["name"], empty=False)
    node = checks.integer(f"{where}.first_node", s["first_node"], ge=0) if "first_node" in s else 0
    defaults = dict(shear=checks.choice(f"{where}.shear", s.get("shear", "cowper"), SHEAR_METHODS),
                    element=checks.choice(f"{where}.element", s.get("element", "nelson"), FORMULATIONS),
                    rotary_inertia=s.get("rotary_inertia", True))
    if "stations" in s:
        if "z0" in s:
            checks.fail(f"{where}.z0", s["z0"], "must not be given with stations: the first station's z is the start")
        sections = _sections_of_stations(where, s, materials)
        z0 = sections[0]["z"]
    else:
        sections = _sections_of_elements(where, s, materials)
        z0 = s.get("z0", 0.0)
    elements = []
    for ew, section in ((sec.pop("where"), sec) for sec in sections):
        section.pop("z", None)
        count, n = section.pop("count"), section.pop("split")
        for _ in range(count):  # each repeat one element, split into n along its taper
            whole = _build(ew, ShaftElement, left=node, right=node + n,
                           **{k: section.get(k, v) for k, v in defaults.items()},
                           **{k: v for k, v in section.items() if k not in defaults})
            elements.extend(whole.split(n, list(range(node + 1, node + n))))
            node += n
    if "nodes" in s:
        elements = _numbered(f"{where}.nodes", s["nodes"], elements)
    if "speed_rad_s" in s:
        speed = checks.non_negative(f"{where}.speed_rad_s", s["speed_rad_s"], "rad/s")
    else:
        speed = rpm_to_rad_s(checks.non_negative(f"{where}.speed_rpm", s.get("speed_rpm", 0.0), "rpm"))
    sleeves = _sleeves(where, s, elements, defaults, materials)
    return _build(where, Spool, name=name, elements=tuple(elements), speed=speed, z0=z0, sleeves=sleeves,
                  **{k: s[k] for k in _INTERNAL_KEYS if k in s})


def _one_of(where: str, table: dict, names: tuple[str, str], required: bool = True) -> None:
    """At most one of the two keys ``names`` (the same quantity in two forms), and one if ``required``."""
    given = [k for k in names if k in table]
    if len(given) == 2:
        checks.fail(f"{where}.{given[1]}", table[given[1]], f"must not be given with {given[0]}: give one of the two")
    if required and not given:
        raise InputError(f"{where}.{names[0]}", checks.MISSING, f"required (or {names[1]})")


def _numbered(where: str, value, chain: list[ShaftElement]) -> list[ShaftElement]:
    """The chain on the node numbers ``value``, one a node along the chain (a chain numbered 0, 1, ... on input)."""
    nodes = checks.sequence(where, value, lambda f, v: checks.integer(f, v, ge=0), min_len=len(chain) + 1,
                            max_len=len(chain) + 1, unique=True)
    return [dataclasses.replace(e, left=nodes[e.left], right=nodes[e.right]) for e in chain]


def _sleeves(where: str, s: dict, chain: list[ShaftElement], defaults: dict, materials: dict[str, Material]):
    """The ``sleeves`` list: each entry lies on ``repeat`` consecutive elements of the chain from node ``left``,
    with their lengths."""
    starting = {e.left: k for k, e in enumerate(chain)}
    out = []
    for j, entry in enumerate(checks.tables(f"{where}.sleeves", s.get("sleeves", []))):
        sw = f"{where}.sleeves[{j}]"
        checks.keys(sw, entry, _SLEEVE_KEYS, required={"left", "D_o"})
        first = starting.get(checks.integer(f"{sw}.left", entry["left"], ge=0))
        if first is None:
            checks.fail(f"{sw}.left", entry["left"], f"must be the left node of an element of the spool "
                        f"({checks.ranges_text(starting)})")
        repeat = checks.integer(f"{sw}.repeat", entry.get("repeat", 1), ge=1)
        if first + repeat > len(chain):
            checks.fail(f"{sw}.repeat", repeat, f"must be <= {len(chain) - first}, the elements from node "
                        f"{entry['left']} to the spool's end")
        section = {"D_i": 0.0, **{k: entry[k] for k in ("D_o", "D_i", "D_o_right", "D_i_right") if k in entry}}
        material = _section_material(sw, entry, s, where, materials)
        options = {k: entry.get(k, v) for k, v in defaults.items()} | {k: entry[k] for k in _INTERNAL_KEYS & set(entry)}
        out.extend(_build(sw, ShaftElement, left=e.left, right=e.right, L=e.L, material=material,
                          **section, **options) for e in chain[first:first + repeat])
    return tuple(out)


def _sections_of_elements(where: str, s: dict, materials: dict[str, Material]) -> list[dict]:
    """The ``elements`` list: one section per entry, ``repeat`` elements of length L each."""
    out = []
    for j, e in enumerate(checks.tables(f"{where}.elements", s["elements"], min_len=1)):
        ew = f"{where}.elements[{j}]"
        checks.keys(ew, e, _ELEMENT_KEYS, required={"L", "D_o"})
        section = {k: e[k] for k in ("L", "D_o", "D_o_right", "D_i_right", "shear", "element", "rotary_inertia",
                                     *sorted(_INTERNAL_KEYS)) if k in e}
        out.append(dict(section, where=ew, D_i=e.get("D_i", 0.0), material=_section_material(ew, e, s, where, materials),
                        count=checks.integer(f"{ew}.repeat", e.get("repeat", 1), ge=1), split=1))
    return out


def _sections_of_stations(where: str, s: dict, materials: dict[str, Material]) -> list[dict]:
    """The ``stations`` list (drawings' and ROSS tables' form): station k starts the section to station k + 1 with
    its D_o, D_i, tapering to D_o_end, D_i_end if given; the last station gives only z, the shaft's end. A section is
    split into ``n`` equal elements (default 1)."""
    stations = checks.tables(f"{where}.stations", s["stations"], min_len=2)
    z = []
    for k, st in enumerate(stations):
        if "z" not in st:
            raise InputError(f"{where}.stations[{k}].z", checks.MISSING, "required")
        z.append(checks.number(f"{where}.stations[{k}].z", st["z"], "m"))
    for k in range(1, len(z)):
        if z[k] <= z[k - 1]:
            checks.fail(f"{where}.stations[{k}].z", z[k], f"must be > the previous station's z = {z[k - 1]:g}", "m")
    checks.keys(f"{where}.stations[{len(z) - 1}]", stations[-1], {"z"})  # the shaft's end
    out = []
    for k, st in enumerate(stations[:-1]):
        sw = f"{where}.stations[{k}]"
        checks.keys(sw, st, _STATION_KEYS, required={"z", "D_o"})
        n = checks.integer(f"{sw}.n", st.get("n", 1), ge=1)
        D_o = checks.positive(f"{sw}.D_o", st["D_o"], "m")
        D_i = checks.non_negative(f"{sw}.D_i", st.get("D_i", 0.0), "m")
        D_o_end = checks.positive(f"{sw}.D_o_end", st.get("D_o_end", D_o), "m")
        D_i_end = checks.non_negative(f"{sw}.D_i_end", st.get("D_i_end", D_i), "m")
        section = dict(where=sw, z=z[k], L=z[k + 1] - z[k], D_o=D_o, D_i=D_i, D_o_right=D_o_end, D_i_right=D_i_end,
                       count=1, split=n, material=_section_material(sw, st, s, where, materials))
        out.append(dict(section, **{k2: st[k2] for k2 in ("shear", "element", "rotary_inertia", *sorted(_INTERNAL_KEYS))
                                    if k2 in st}))
    return out


def _section_material(here: str, entry: dict, spool: dict, where: str, materials: dict[str, Material]) -> Material:
    """The entry's ``material``, else the spool's."""
    if "material" in entry:
        return _material(f"{here}.material", entry["material"], materials)
    if "material" in spool:
        return _material(f"{where}.material", spool["material"], materials)
    raise InputError(f"{here}.material", checks.MISSING, f"required (or {where}.material for every section)")


def _disk(where: str, d: dict, materials: dict[str, Material]) -> Disk:
    checks.keys(where, d, _DISK_KEYS, required={"node"})
    explicit = [k for k in ("m", "I_d", "I_p") if k in d]
    geometric = [k for k in ("D_o", "thickness", "material") if k in d]
    if explicit and geometric:
        checks.fail(f"{where}.{explicit[0]}", d[explicit[0]], f"must not be given with {', '.join(geometric)}: "
                    "give either (m, I_d, I_p) or (D_o, D_i, thickness, material)")
    if not geometric:
        checks.keys(where, d, _DISK_KEYS, required={"node", "m", "I_d", "I_p"})
        return _build(where, Disk, node=d["node"], m=d["m"], I_d=d["I_d"], I_p=d["I_p"], name=d.get("name", ""),
                      radius=d.get("radius", 0.0))
    checks.keys(where, d, _DISK_KEYS, required={"node", "D_o", "thickness", "material"})
    mat = _material(f"{where}.material", d["material"], materials)
    D_o = checks.positive(f"{where}.D_o", d["D_o"], "m")
    D_i = checks.non_negative(f"{where}.D_i", d.get("D_i", 0.0), "m")
    if D_i >= D_o:
        checks.fail(f"{where}.D_i", d["D_i"], f"must be < D_o = {D_o:g}", "m")
    h = checks.positive(f"{where}.thickness", d["thickness"], "m")
    ro2, ri2 = (D_o / 2) ** 2, (D_i / 2) ** 2
    m = mat.rho * math.pi * (ro2 - ri2) * h
    # Thin annular disk: I_p = m (ro^2 + ri^2) / 2, I_d = m (3 (ro^2 + ri^2) + h^2) / 12.
    return _build(where, Disk, node=d["node"], m=m, I_d=m * (3 * (ro2 + ri2) + h**2) / 12, I_p=m * (ro2 + ri2) / 2,
                  name=d.get("name", ""), radius=d.get("radius", D_o / 2))


def _bearing(where: str, b: dict) -> Bearing | BearingTable:
    """A bearing; with ``speed_rpm`` (a list of speeds) its coefficients are numbers or lists, one value per speed;
    ``frequency_rpm`` is the same for a table made against whirl frequency (docs/model.md §20)."""
    axis_keys = {k for keys in _AXIS_KEYS.values() for k in keys}
    checks.keys(where, b, _SUPPORT_KEYS | {"node", "link"} | axis_keys | _TABLE_KEYS, required={"node"})
    axis = _table_axis(where, b)
    if axis is None:
        return _build(where, Bearing, node=b["node"], link=b.get("link"), **_coefficients(where, b))
    speeds = _table_speeds(where, b, axis)
    return _build(where, BearingTable, node=b["node"], link=b.get("link"), speeds=speeds, axis=axis,
                  **{k: b[k] for k in _TABLE_KEYS & set(b)}, **_coefficients(where, b, n_speeds=len(speeds)))


def _table_axis(where: str, b: dict, axes=tuple(_AXIS_KEYS)) -> str | None:
    """The axis of a bearing table (``"speed"``, ``"frequency"``), None for constant coefficients; one axis key at
    most, and interpolation keys with an axis only."""
    given = [k for axis in axes for k in _AXIS_KEYS[axis] if k in b]
    if len(given) > 1:
        checks.fail(f"{where}.{given[1]}", b[given[1]], f"must not be given with {given[0]}: a table has one axis")
    if not given:
        for key in sorted(_TABLE_KEYS & set(b)):
            checks.fail(f"{where}.{key}", b[key], "needs speed_rpm: only a table against speed interpolates and "
                        "extrapolates")
        return None
    return next(axis for axis, keys in _AXIS_KEYS.items() if given[0] in keys)


def _table_speeds(where: str, b: dict, axis: str) -> tuple[float, ...]:
    """A table's axis in rad/s, from its key in rpm or rad/s."""
    rpm_key, si_key = _AXIS_KEYS[axis]
    if si_key in b:
        return tuple(checks.vector(f"{where}.{si_key}", b[si_key], "rad/s", min_len=2, ge=0.0, increasing=True))
    return tuple(rpm_to_rad_s(checks.vector(f"{where}.{rpm_key}", b[rpm_key], "rpm", min_len=2, ge=0.0,
                                            increasing=True)))


def _pedestal(where: str, p: dict) -> Pedestal:
    checks.keys(where, p, {"node", "m", "name"}, required={"node", "m"})
    return _build(where, Pedestal, node=p["node"], m=p["m"], name=p.get("name", ""))


def _support(where: str, sp: dict) -> Support:
    checks.keys(where, sp, _SUPPORT_NODE_KEYS, required={"node", "kind"})
    return _build(where, Support, node=sp["node"], kind=sp["kind"], name=sp.get("name", ""))


def _intershaft_bearing(where: str, b: dict) -> IntershaftBearing | IntershaftBearingTable:
    """An inter-shaft bearing; with ``speed_rpm`` a table against the speed of spool ``speed_of`` (default node_a's)."""
    checks.keys(where, b, _SUPPORT_KEYS | {"node_a", "node_b", "speed_of", *_AXIS_KEYS["speed"]} | _TABLE_KEYS,
                required={"node_a", "node_b"})
    if _table_axis(where, b, ("speed",)) is None:
        if "speed_of" in b:
            checks.fail(f"{where}.speed_of", b["speed_of"], "needs speed_rpm: only a table follows a spool's speed")
        return _build(where, IntershaftBearing, node_a=b["node_a"], node_b=b["node_b"], **_coefficients(where, b))
    speeds = _table_speeds(where, b, "speed")
    return _build(where, IntershaftBearingTable, node_a=b["node_a"], node_b=b["node_b"], speeds=speeds,
                  speed_of=b.get("speed_of"), **{k: b[k] for k in _TABLE_KEYS & set(b)},
                  **_coefficients(where, b, n_speeds=len(speeds)))


def _coefficients(where: str, b: dict, n_speeds: int = 0) -> dict[str, Any]:
    """The support coefficients as given; ``k`` / ``c`` (isotropic) set both direct terms, ``k_tt`` / ``c_tt`` both
    direct tilt terms. With ``n_speeds`` (a table against speed) each may be a number or a list of ``n_speeds``
    values."""
    out: dict[str, Any] = {k: v for k, v in b.items() if k in _SUPPORT_KEYS - set(_SHORTHANDS)}
    for kind, (xx, yy, unit) in _SHORTHANDS.items():
        if kind in b:
            for direct in (xx, yy):
                if direct in b:
                    checks.fail(f"{where}.{direct}", b[direct], f"must not be given with {kind}: "
                                f"give {kind} (isotropic) or {xx}, {yy}")
            ge = 0.0 if kind[0] == "c" else None  # direct damping >= 0; direct stiffness any sign (seals)
            if n_speeds and isinstance(b[kind], (list, tuple)):
                value = tuple(checks.vector(f"{where}.{kind}", b[kind], unit, min_len=n_speeds, max_len=n_speeds,
                                            ge=ge))
            else:
                value = checks.number(f"{where}.{kind}", b[kind], unit, ge=ge)
            out[xx] = out[yy] = value
    return out


def _damping(value) -> tuple[float, float]:
    table = checks.table("damping", value)
    checks.keys("damping", table, _DAMPING_KEYS)
    return (checks.non_negative("damping.rayleigh_alpha", table.get("rayleigh_alpha", 0.0), "1/s"),
            checks.non_negative("damping.rayleigh_beta", table.get("rayleigh_beta", 0.0), "s"))


def _defaults(value, nodes: set[int], spools: list[str]) -> AnalysisDefaults:
    table = checks.table("defaults", value)
    checks.keys("defaults", table, _DEFAULTS_KEYS)
    unbalances = tuple(unbalance_from_table(f"defaults.unbalance[{i}]", u, nodes)
                       for i, u in enumerate(checks.tables("defaults.unbalance", table.get("unbalance", []))))
    outputs = checks.sequence("defaults.outputs", table.get("outputs", []), lambda f, v: parse_dof(f, v, nodes),
                              unique=True)
    boundary = checks.sequence("defaults.boundary_nodes", table.get("boundary_nodes", []),
                               lambda f, v: checks.node(f, v, nodes), unique=True)
    return AnalysisDefaults(unbalances=unbalances, outputs=outputs, boundary_nodes=boundary,
                            operating_ranges=_operating_ranges(table, spools))


def _operating_ranges(table: dict, spools: list[str]) -> tuple[tuple[str, float, float], ...]:
    """``operating_range_rpm = { inner = [3000.0, 4500.0] }`` (or ``operating_range_rad_s``, what a written rotor
    holds where no rpm number reads back exactly): each spool's minimum and maximum continuous speed, in rad/s."""
    out = []
    for key, to_rad_s in (("operating_range_rpm", rpm_to_rad_s), ("operating_range_rad_s", float)):
        unit = "rpm" if key.endswith("rpm") else "rad/s"
        for spool, pair in checks.table(f"defaults.{key}", table.get(key, {})).items():
            where = f"defaults.{key}.{spool}"
            checks.choice(f"defaults.{key}", spool, spools)
            lo, hi = checks.sequence(where, pair, lambda f, v: checks.non_negative(f, v, unit), min_len=2, max_len=2)
            if hi < lo:
                checks.fail(where, pair, "must be [minimum, maximum continuous speed] with minimum <= maximum", unit)
            if spool in {s for s, _, _ in out}:
                checks.fail(where, pair, "must be given once: in operating_range_rpm or operating_range_rad_s")
            out.append((spool, to_rad_s(lo), to_rad_s(hi)))
    return tuple(out)
