"""Rotor files saved by ROSS 3 (``ross.Rotor.save``, TOML), read without ROSS installed.

ROSS (https://github.com/petrobras/ross) saves a rotor as a ``ross_version`` line, a
``[parameters]`` table and one table per element named ``"<Class>_<tag>"``: shaft elements by their
geometry and material, disks, point masses, bearings and seals by their coefficients (tables
against speed for fluid-film bearings and seals). :func:`ross_document` turns such a file into the
equivalent rotorred rotor-file document (the dictionary of a rotorred TOML file, module
:mod:`rotorred.model.rotor_file`), so that a ROSS file is validated, loaded and written out
(``rotorred convert``) along the one path of rotorred's own files.

What maps to what (docs/model.md §14):

- ``ShaftElement`` n -> the element between nodes n and n + 1 of one spool named ``"rotor"``; several
  elements at one n (ROSS's layered elements, a sleeve on the shaft) -> the first in the chain, the
  others as ``sleeves`` on it. ``shear_effects``, ``shear_method_calc``, ``rotary_inertia`` map to
  ``shear`` and ``rotary_inertia``; the material to a ``[[material]]`` with E, rho and G.
- ``DiskElement`` -> a ``[[disk]]`` with m, I_d, I_p. ``PointMass`` -> a disk without inertia on a
  shaft node, a ``[[pedestal]]`` off the shaft.
- ``BearingElement``, ``SealElement``, ``BallBearingElement``, ``RollerBearingElement`` -> a
  ``[[bearing]]`` (``n_link``: ``link``); tables against ``speed`` (rad/s) -> ``speed_rpm`` lists with
  ROSS's interpolation (``"pchip"`` or ``"linear"``) and its extrapolation along the end tangents
  (``extrapolate = "linear"``); tables against whirl ``frequency`` -> ``frequency_rpm`` lists, evaluated as ROSS's
  modal and unbalance analyses evaluate them, at frequency = the spool's speed (said once at load, as a warning of
  the logger ``rotorred.model.ross_file``; docs/model.md §20).

ROSS models have 6 DOFs a node; rotorred's are lateral (x, y, theta_x, theta_y). The axial and
torsional coefficients (``kzz``, ``czz``, ``mzz``) do not couple to lateral motion in ROSS's linear
model and are not read. Anything else rotorred cannot represent (another element kind, bearing
mass coefficients, axial force or torque on a shaft, a table against both speed and whirl frequency, Rayleigh
or modal damping) is refused by name, never dropped.
"""

from __future__ import annotations

import logging
import math
from collections import defaultdict
from typing import Any

from rotorred import checks

__all__ = ["READ_KINDS", "is_ross_document", "ross_document"]

#: where the reader says what it read differently from ROSS's saved form (a warning each, once a file)
LOG = logging.getLogger(__name__)

#: the ROSS element classes rotorred reads, and what it makes of them
READ_KINDS = {"ShaftElement": "shaft element", "DiskElement": "disk", "PointMass": "point mass",
              "BearingElement": "bearing", "SealElement": "bearing", "BallBearingElement": "bearing",
              "RollerBearingElement": "bearing"}
#: why some ROSS element classes cannot be read (any other class: it is not a lateral element rotorred knows)
_WHY_NOT = {
    "MagneticBearingElement": "an active magnetic bearing, whose force follows its controller's states",
    "CouplingElement": "a flexible coupling with its own torsional and misalignment stiffness",
    "GearElement": "a gear mesh, which couples lateral and torsional motion",
    "MotorElement": "a motor's electromagnetic stiffness",
}
_DISPLAY_KEYS = {"tag", "color", "scale_factor"}  # how ROSS draws an element: no physics
_SHAFT_KEYS = {"L", "idl", "odl", "idr", "odr", "n", "axial_force", "torque", "shear_effects", "rotary_inertia",
               "gyroscopic", "shear_method_calc", "alpha", "beta", "material"} | _DISPLAY_KEYS
_DISK_KEYS = {"n", "m", "Id", "Ip"} | _DISPLAY_KEYS
_POINT_MASS_KEYS = {"n", "m", "mx", "my", "mz"} | _DISPLAY_KEYS
_LATERAL = ("kxx", "kyy", "kxy", "kyx", "cxx", "cyy", "cxy", "cyx")
_AXIAL = ("kzz", "czz", "mzz")  # not coupled to lateral motion: not read
_BEARING_MASS = ("mxx", "mxy", "myx", "myy")
_BEARING_KEYS = {"n", "n_link", "speed", "frequency", "interpolation", *_LATERAL, *_AXIAL, *_BEARING_MASS} \
    | _DISPLAY_KEYS
#: the rating data ROSS keeps beside a rolling bearing's computed coefficients (which are what it reads back)
_ROLLING_KEYS = {"BallBearingElement": {"n_balls", "d_balls", "fs", "alpha"},
                 "RollerBearingElement": {"n_rollers", "l_rollers", "fs", "alpha"}}


def is_ross_document(data: dict[str, Any]) -> bool:
    """Whether a parsed TOML document is a rotor saved by ROSS (its ``ross_version`` key or ``<Class>_<tag>`` tables)."""
    return "ross_version" in data or any(isinstance(v, dict) and k.split("_", 1)[0] in READ_KINDS | _WHY_NOT.keys()
                                         and "_" in k for k, v in data.items())


def ross_document(data: dict[str, Any], name: str = "ross-rotor") -> dict[str, Any]:
    """The rotorred rotor-file document of a rotor saved by ROSS 3.

    Parameters
    ----------
    data : dict
        The parsed TOML of ``ross.Rotor.save``.
    name : str
        The rotor's name (ROSS files have none; the file's stem, say).

    Returns
    -------
    dict
        A rotor-file document (``rotor_from_dict`` builds the rotor; ``rotorred convert`` writes it). Node numbers
        are ROSS's.

    Raises
    ------
    rotorred.checks.InputError
        Naming the ROSS table and key of anything rotorred cannot represent.
    """
    _check_version(data.get("ross_version", checks.MISSING))
    _check_parameters(data.get("parameters", {}))
    sections = _sections(data)
    materials: dict[str, dict] = {}
    spool = _spool(sections["ShaftElement"], materials)
    shaft_nodes = set(range(spool["first_node"], spool["first_node"] + len(spool["elements"]) + 1))
    disks, pedestals = _masses(sections["DiskElement"], sections["PointMass"], shaft_nodes)
    bearings = [_bearing(table, kind, values) for kind in ("BearingElement", "SealElement", "BallBearingElement",
                                                           "RollerBearingElement")
                for table, values in sections[kind]]
    _note_frequency_tables(bearings)
    document = {"name": name, "description": f"read from a rotor saved by ROSS {data.get('ross_version')}",
                "material": list(materials.values()), "spool": [spool], "disk": disks, "bearing": bearings}
    if pedestals:
        document["pedestal"] = pedestals
    return document


# --- the file, one step each ------------------------------------------------------------------------
def _check_version(version) -> None:
    if version is checks.MISSING:
        raise checks.InputError("ross_version", checks.MISSING, "required: the line ROSS writes first in a saved rotor")
    text = checks.string("ross_version", version)
    if not text.split(".", 1)[0] == "3":
        checks.fail("ross_version", version, "must be 3.x: rotorred reads rotors saved by ROSS 3 (ROSS 2's bearing "
                    "tables name the speed axis 'frequency'); load the rotor in ROSS 3 and save it again")


def _check_parameters(parameters) -> None:
    table = checks.table("parameters", parameters)
    for key, value in table.items():
        if key in ("alpha", "beta", "default_damping_ratio"):
            if checks.number(f"parameters.{key}", value) != 0.0:
                checks.fail(f"parameters.{key}", value, "must be 0: ROSS's proportional and modal damping of the "
                            "whole rotor has no equivalent in rotorred (whose Rayleigh damping is the shafts')")
        else:
            checks.fail(f"parameters.{key}", value, "unknown ROSS rotor parameter; rotorred reads alpha, beta and "
                        "default_damping_ratio (all 0)")


def _sections(data: dict[str, Any]) -> dict[str, list[tuple[str, dict]]]:
    """The element tables by ROSS class, in the file's order; a class rotorred cannot represent is refused."""
    out: dict[str, list[tuple[str, dict]]] = defaultdict(list)
    for key, value in data.items():
        if key in ("ross_version", "parameters") or key.startswith("_"):
            continue
        kind = key.split("_", 1)[0]
        where = f"[{key!r}]" if "_" in key else key
        if kind not in READ_KINDS:
            _refuse(where, kind)
        table = checks.table(where, value)
        if kind == "BearingElement" and "kp_pid" in table:  # ROSS 3.1 saves a magnetic bearing as a BearingElement
            _refuse(where, "MagneticBearingElement")
        out[kind].append((where, table))
    if not out["ShaftElement"]:
        raise checks.InputError("ShaftElement", checks.MISSING, "required: a ROSS rotor holds at least one "
                                "ShaftElement table")
    return out


def _refuse(where: str, kind: str) -> None:
    why = _WHY_NOT.get(kind, "not a lateral element rotorred knows")
    checks.fail(where, kind, f"is a ROSS {kind} ({why}), which rotorred cannot represent; it reads "
                f"{', '.join(READ_KINDS)}. Replace it in ROSS (a bearing by a BearingElement with its coefficients) "
                "and save again")


def _spool(shafts: list[tuple[str, dict]], materials: dict[str, dict]) -> dict[str, Any]:
    """One spool: the first element at each n in the chain, the others (layers) as sleeves on it."""
    by_n: dict[int, list[dict]] = defaultdict(list)
    for where, table in shafts:
        checks.keys(where, table, _SHAFT_KEYS, required={"L", "idl", "odl", "idr", "odr", "n", "material"})
        by_n[checks.integer(f"{where}.n", table["n"], ge=0)].append(_shaft_entry(where, table, materials))
    first, last = min(by_n), max(by_n)
    gaps = sorted(set(range(first, last + 1)) - set(by_n))
    if gaps:
        checks.fail("ShaftElement.n", checks.ranges_text(by_n), f"must run without a gap from {first} to {last}; no "
                    f"element has n = {checks.ranges_text(gaps)}. A ROSS file holds one shaft: a coaxial rotor's file "
                    "(which ROSS cannot load either) must be written as a rotorred rotor file with two [[spool]] "
                    "tables (preset ross-coaxial is ROSS's coaxial example)")
    chain = [by_n[n][0] for n in range(first, last + 1)]
    sleeves = [dict(layer, left=n) for n in range(first, last + 1) for layer in by_n[n][1:]]
    for sleeve in sleeves:
        del sleeve["L"]  # a sleeve has the length of the element it lies on (checked by Spool)
    spool = {"name": "rotor", "first_node": first, "speed_rpm": 0.0, "elements": chain}
    if sleeves:
        spool["sleeves"] = sleeves
    return spool


def _shaft_entry(where: str, t: dict, materials: dict[str, dict]) -> dict[str, Any]:
    """A rotorred element entry of one ROSS ShaftElement table."""
    for key in ("axial_force", "torque", "alpha", "beta"):
        if checks.number(f"{where}.{key}", t.get(key, 0.0)) != 0.0:
            checks.fail(f"{where}.{key}", t[key], "must be 0: rotorred's shaft element has no "
                        + ("Rayleigh damping of its own" if key in ("alpha", "beta") else "axial load stiffening"))
    rotary = checks.boolean(f"{where}.rotary_inertia", t.get("rotary_inertia", True))
    if checks.boolean(f"{where}.gyroscopic", t.get("gyroscopic", True)) != rotary:
        checks.fail(f"{where}.gyroscopic", t["gyroscopic"], f"must equal rotary_inertia = {rotary}: rotorred's shaft "
                    "element spins its rotary inertia (the gyroscopic matrix is rho I, with it or without it)")
    shear = "none"
    if checks.boolean(f"{where}.shear_effects", t.get("shear_effects", True)):
        shear = checks.choice(f"{where}.shear_method_calc", t.get("shear_method_calc", "cowper"),
                              ("cowper", "hutchinson"))
    entry = {"L": t["L"], "D_o": t["odl"], "D_i": t["idl"], "material": _material(f"{where}.material", t["material"],
                                                                                   materials)}
    if (t["odr"], t["idr"]) != (t["odl"], t["idl"]):
        entry.update(D_o_right=t["odr"], D_i_right=t["idr"])
    if shear != "cowper":
        entry["shear"] = shear
    if not rotary:
        entry["rotary_inertia"] = False
    return entry


def _material(where: str, m, materials: dict[str, dict]) -> str:
    """The name of the ``[[material]]`` of a ROSS material table (E, rho, G_s), added on first use."""
    table = checks.table(where, m)
    checks.keys(where, table, {"name", "rho", "E", "G_s", "Poisson", "color"}, required={"name", "rho", "E", "G_s"})
    values = {"E": table["E"], "rho": table["rho"], "G": table["G_s"]}
    name = checks.string(f"{where}.name", table["name"], empty=False)
    for existing in materials.values():
        if {k: existing[k] for k in values} == values:
            return existing["name"]
    taken = {m["name"] for m in materials.values()}
    unique = name if name not in taken else next(f"{name}-{i}" for i in range(2, len(taken) + 2)
                                                 if f"{name}-{i}" not in taken)
    materials[unique] = {"name": unique, **values}
    return unique


def _masses(disks: list[tuple[str, dict]], points: list[tuple[str, dict]], shaft_nodes: set[int]):
    """Disks, and point masses: without inertia on a shaft node, a pedestal off the shaft."""
    out_disks, pedestals = [], []
    for where, t in disks:
        checks.keys(where, t, _DISK_KEYS, required={"n", "m", "Id", "Ip"})
        out_disks.append({"node": t["n"], "m": t["m"], "I_d": t["Id"], "I_p": t["Ip"], "name": str(t.get("tag", ""))})
    for where, t in points:
        checks.keys(where, t, _POINT_MASS_KEYS, required={"n"})
        mx, my = (checks.positive(f"{where}.{k}", t.get(k, t.get("m", checks.MISSING)), "kg") for k in ("mx", "my"))
        if mx != my:
            checks.fail(f"{where}.my", t.get("my"), f"must equal mx = {mx!r}: rotorred's point masses and pedestals "
                        "have one mass in x and y", "kg")
        node = checks.integer(f"{where}.n", t["n"], ge=0)
        name = str(t.get("tag", ""))
        if node in shaft_nodes:
            out_disks.append({"node": node, "m": mx, "I_d": 0.0, "I_p": 0.0, "name": name})
        else:
            pedestals.append({"node": node, "m": mx, "name": name})
    return out_disks, pedestals


def _bearing(where: str, kind: str, t: dict) -> dict[str, Any]:
    """A rotorred ``[[bearing]]`` of a ROSS bearing or seal table: constant, or a table against speed."""
    checks.keys(where, t, _BEARING_KEYS | _ROLLING_KEYS.get(kind, set()), required={"n", "kxx", "kyy"})
    axis = "frequency" if t.get("frequency") is not None else "speed"
    if axis == "frequency" and t.get("speed") is not None:
        checks.fail(f"{where}.frequency", t["frequency"], "must not be given with speed: a table against both speed "
                    "and whirl frequency (ROSS's 2-D table) has no rotorred equivalent; rotorred's tables follow one "
                    "axis, evaluated at the spool speed (give the synchronous coefficients against speed)")
    columns = {c: _column(f"{where}.{c}", t.get(c, [0.0])) for c in _LATERAL + _BEARING_MASS}
    for c in _BEARING_MASS:
        if any(v != 0.0 for v in columns[c]):
            checks.fail(f"{where}.{c}", t[c], "must be 0: rotorred's bearings have no added-mass coefficients")
    out: dict[str, Any] = {"node": t["n"], "name": str(t.get("tag", ""))}
    if t.get("n_link") is not None:
        out["link"] = t["n_link"]
    lengths = {len(v) for v in columns.values()}
    if t.get(axis) is None:
        if lengths != {1}:
            checks.fail(f"{where}.kxx", t["kxx"], "must hold one value a coefficient without a speed table")
        out.update({f"{c[0]}_{c[1:]}": v[0] for c, v in ((c, columns[c]) for c in _LATERAL)})
        return out
    speeds = _column(f"{where}.{axis}", t[axis])
    if lengths != {len(speeds)}:
        checks.fail(f"{where}.kxx", t["kxx"], f"must hold one value per entry of {where}.{axis} ({len(speeds)})")
    out[f"{axis}_rpm"] = [w * 30.0 / math.pi for w in speeds]
    out.update({f"{c[0]}_{c[1:]}": columns[c] for c in _LATERAL})
    out["interpolation"] = checks.choice(f"{where}.interpolation", t.get("interpolation", "pchip"), ("pchip", "linear"))
    out["extrapolate"] = "linear"  # ROSS continues a table along its end tangents
    return out


def _note_frequency_tables(bearings: list[dict[str, Any]]) -> None:
    """Say once which bearings are tabulated against whirl frequency, and how they are read."""
    named = [f"{b['name']!r} (node {b['node']})" if b["name"] else f"node {b['node']}" for b in bearings
             if "frequency_rpm" in b]
    if named:
        LOG.warning("%s tabulated against whirl frequency in the ROSS file: read as ROSS's modal and unbalance "
                    "analyses evaluate such tables, at frequency = the speed of the bearing's spool (synchronous); "
                    "a mode whirling at another frequency sees the coefficients of the spool speed, not of its own "
                    "frequency (docs/model.md §20)",
                    ("bearing " if len(named) == 1 else "bearings ") + ", ".join(named)
                    + (" is" if len(named) == 1 else " are"))


def _column(where: str, value) -> list[float]:
    """A ROSS coefficient: a list of numbers (one, or one per speed); a single number is a list of one."""
    values = value if isinstance(value, list) else [value]
    return [checks.number(f"{where}[{i}]", v) for i, v in enumerate(values)]
