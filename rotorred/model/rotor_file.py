"""Rotor files (TOML): load and validate, with errors that name the field, the value and what is allowed.

A rotor is given by a preset name (``seed-rig``, ``nelson-mcvaugh``; see :func:`presets`) or a
path to a TOML file. The format is documented in the README ("Rotor files"); in short::

    name = "my-rotor"
    [[material]]                       # E (Pa), rho (kg/m^3), nu (-)
    name = "steel"; E = 2.1e11; rho = 7850.0; nu = 0.3
    [[spool]]                          # a chain of elements on consecutive node numbers
    name = "inner"; first_node = 1; z0 = 0.0; speed_rpm = 4200.0; shear = "cowper"; element = "nelson"
    elements = [ { L = 0.08, D_o = 0.02, D_i = 0.0, material = "steel", repeat = 12 } ]
    [[disk]]                           # either m, I_d, I_p (kg, kg m^2) or D_o, D_i, thickness, material
    node = 3; m = 5.7; I_d = 0.023; I_p = 0.045; radius = 0.125
    [[bearing]]                        # k_* (N/m), c_* (N s/m); k / c set both direct terms
    node = 1; k = 2e7; c = 300.0
    [[intershaft_bearing]]
    node_a = 20; node_b = 9; k = 1e7; c = 300.0
    [damping]
    rayleigh_alpha = 0.0; rayleigh_beta = 0.0
"""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path
from typing import Any

from rotorred.model.elements import Bearing, Disk, IntershaftBearing, Material, ShaftElement
from rotorred.model.rotor import Rotor, Spool

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib

_TOP_KEYS = {"name", "description", "material", "spool", "disk", "bearing", "intershaft_bearing", "damping"}
_MATERIAL_KEYS = {"name", "E", "rho", "nu"}
_SPOOL_KEYS = {"name", "first_node", "z0", "speed_rpm", "shear", "element", "elements"}
_ELEMENT_KEYS = {"L", "D_o", "D_i", "material", "repeat", "shear", "element"}
_DISK_KEYS = {"node", "name", "m", "I_d", "I_p", "radius", "D_o", "D_i", "thickness", "material"}
_SUPPORT_KEYS = {"name", "k", "c", "k_xx", "k_yy", "k_xy", "k_yx", "c_xx", "c_yy", "c_xy", "c_yx"}
_DAMPING_KEYS = {"rayleigh_alpha", "rayleigh_beta"}


class RotorFileError(ValueError):
    """A rotor file that does not describe a valid rotor."""


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
    """
    spec_str = str(spec)
    if spec_str in presets():
        text = resources.files("rotorred.model.presets").joinpath(f"{spec_str}.toml").read_text()
        return rotor_from_toml(text, source=f"preset {spec_str!r}")
    path = Path(spec)
    if not path.exists():
        raise FileNotFoundError(f"rotor {spec_str!r} is neither a preset ({', '.join(presets())}) nor an existing file")
    return rotor_from_toml(path.read_text(), source=str(path))


def rotor_from_toml(text: str, source: str = "<string>") -> Rotor:
    """Parse and validate a rotor TOML document; see the module docstring for the format."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise RotorFileError(f"{source}: not valid TOML: {exc}") from None
    try:
        return rotor_from_dict(data)
    except (ValueError, TypeError) as exc:
        raise RotorFileError(f"{source}: {exc}") from None


def rotor_from_dict(data: dict[str, Any]) -> Rotor:
    """Build a :class:`Rotor` from the parsed TOML tables."""
    _check_keys("rotor file", data, _TOP_KEYS)
    materials: dict[str, Material] = {}
    for i, m in enumerate(_list_of_tables(data, "material")):
        where = f"material[{i}]"
        _check_keys(where, m, _MATERIAL_KEYS, required={"name", "E", "rho"})
        name = _string(where, m, "name")
        if name in materials:
            raise ValueError(f"{where}: material `name` {name!r} is defined twice")
        materials[name] = _build(where, Material, name=name, E=_number(where, m, "E"), rho=_number(where, m, "rho"),
                                 nu=_number(where, m, "nu", 0.3))
    spools = []
    tables = _list_of_tables(data, "spool")
    if not tables:
        raise ValueError("at least one [[spool]] table is required, got none")
    for i, s in enumerate(tables):
        where = f"spool[{i}]"
        _check_keys(where, s, _SPOOL_KEYS, required={"name", "first_node", "elements"})
        name = _string(where, s, "name")
        where = f"spool[{i}] ({name!r})"
        node = _integer(where, s, "first_node")
        if node < 0:
            raise ValueError(f"{where}: `first_node` must be >= 0, got {node}")
        default_shear = s.get("shear", "cowper")
        default_element = s.get("element", "nelson")
        elements = []
        rows = s["elements"]
        if not isinstance(rows, list) or not rows:
            raise ValueError(f"{where}: `elements` must be a non-empty list of tables, got {rows!r}")
        for j, e in enumerate(rows):
            ew = f"{where}.elements[{j}]"
            if not isinstance(e, dict):
                raise ValueError(f"{ew}: must be a table {{L = ..., D_o = ..., ...}}, got {e!r}")
            _check_keys(ew, e, _ELEMENT_KEYS, required={"L", "D_o", "material"})
            mat = _material(ew, e, materials)
            repeat = _integer(ew, e, "repeat", 1)
            if repeat < 1:
                raise ValueError(f"{ew}: `repeat` must be >= 1, got {repeat}")
            for _ in range(repeat):
                elements.append(_build(ew, ShaftElement, left=node, right=node + 1, L=_number(ew, e, "L"),
                                       D_o=_number(ew, e, "D_o"), D_i=_number(ew, e, "D_i", 0.0), material=mat,
                                       shear=e.get("shear", default_shear),
                                       element=e.get("element", default_element)))
                node += 1
        speed_rpm = _number(where, s, "speed_rpm", 0.0)
        if speed_rpm < 0:
            raise ValueError(f"{where}: `speed_rpm` must be >= 0, got {speed_rpm}")
        spools.append(_build(where, Spool, name=name, elements=tuple(elements), speed=speed_rpm * math.pi / 30.0,
                             z0=_number(where, s, "z0", 0.0)))
    disks = []
    for i, d in enumerate(_list_of_tables(data, "disk")):
        where = f"disk[{i}]"
        _check_keys(where, d, _DISK_KEYS, required={"node"})
        disks.append(_disk(where, d, materials))
    bearings = []
    for i, b in enumerate(_list_of_tables(data, "bearing")):
        where = f"bearing[{i}]"
        _check_keys(where, b, _SUPPORT_KEYS | {"node"}, required={"node"})
        bearings.append(_build(where, Bearing, node=_integer(where, b, "node"), **_coefficients(where, b)))
    inter = []
    for i, b in enumerate(_list_of_tables(data, "intershaft_bearing")):
        where = f"intershaft_bearing[{i}]"
        _check_keys(where, b, _SUPPORT_KEYS | {"node_a", "node_b"}, required={"node_a", "node_b"})
        inter.append(_build(where, IntershaftBearing, node_a=_integer(where, b, "node_a"),
                            node_b=_integer(where, b, "node_b"), **_coefficients(where, b)))
    damping = data.get("damping", {})
    if not isinstance(damping, dict):
        raise ValueError(f"`damping` must be a table, got {damping!r}")
    _check_keys("damping", damping, _DAMPING_KEYS)
    rayleigh = (_number("damping", damping, "rayleigh_alpha", 0.0), _number("damping", damping, "rayleigh_beta", 0.0))
    name = data.get("name", "")
    if not isinstance(name, str):
        raise ValueError(f"`name` must be a string, got {name!r}")
    return Rotor(spools=tuple(spools), disks=tuple(disks), bearings=tuple(bearings),
                 intershaft_bearings=tuple(inter), rayleigh=rayleigh, name=name)


# --- helpers ------------------------------------------------------------------------
def _build(where: str, cls, **kwargs):
    try:
        return cls(**kwargs)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def _check_keys(where: str, table: dict, allowed: set[str], required: set[str] = frozenset()) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {unknown}; allowed keys are {sorted(allowed)}")
    missing = sorted(required - set(table))
    if missing:
        raise ValueError(f"{where}: missing required key(s) {missing}")


def _list_of_tables(data: dict, key: str) -> list[dict]:
    value = data.get(key, [])
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise ValueError(f"`{key}` must be an array of tables ([[{key}]]), got {value!r}")
    return value


def _number(where: str, table: dict, key: str, default: float | None = None) -> float:
    if key not in table:
        if default is None:
            raise ValueError(f"{where}: missing required key `{key}`")
        return default
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where}: `{key}` must be a finite number, got {value!r}")
    return float(value)


def _integer(where: str, table: dict, key: str, default: int | None = None) -> int:
    if key not in table:
        if default is None:
            raise ValueError(f"{where}: missing required key `{key}`")
        return default
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{where}: `{key}` must be an integer, got {value!r}")
    return value


def _string(where: str, table: dict, key: str) -> str:
    value = table.get(key)
    if not isinstance(value, str) or not value:
        raise ValueError(f"{where}: `{key}` must be a non-empty string, got {value!r}")
    return value


def _material(where: str, table: dict, materials: dict[str, Material]) -> Material:
    name = table["material"]
    if name not in materials:
        raise ValueError(f"{where}: `material` {name!r} is not defined; defined materials are {sorted(materials)}")
    return materials[name]


def _disk(where: str, d: dict, materials: dict[str, Material]) -> Disk:
    node = _integer(where, d, "node")
    name = d.get("name", "")
    explicit = {"m", "I_d", "I_p"} & set(d)
    geometric = {"D_o", "thickness", "material"} & set(d)
    if explicit and geometric:
        raise ValueError(f"{where}: give either (m, I_d, I_p) or (D_o, D_i, thickness, material), not both")
    if geometric:
        _check_keys(where, d, _DISK_KEYS, required={"node", "D_o", "thickness", "material"})
        mat = _material(where, d, materials)
        D_o, D_i, h = _number(where, d, "D_o"), _number(where, d, "D_i", 0.0), _number(where, d, "thickness")
        if not (D_o > 0 and h > 0 and 0 <= D_i < D_o):
            raise ValueError(f"{where}: need D_o > 0, thickness > 0 and 0 <= D_i < D_o, got D_o={D_o}, D_i={D_i}, "
                             f"thickness={h} (m)")
        ro2, ri2 = (D_o / 2) ** 2, (D_i / 2) ** 2
        m = mat.rho * math.pi * (ro2 - ri2) * h
        # Thin annular disk: I_p = m (ro^2 + ri^2) / 2, I_d = m (3 (ro^2 + ri^2) + h^2) / 12.
        return _build(where, Disk, node=node, m=m, I_d=m * (3 * (ro2 + ri2) + h**2) / 12, I_p=m * (ro2 + ri2) / 2,
                      name=name, radius=_number(where, d, "radius", D_o / 2))
    _check_keys(where, d, _DISK_KEYS, required={"node", "m", "I_d", "I_p"})
    return _build(where, Disk, node=node, m=_number(where, d, "m"), I_d=_number(where, d, "I_d"),
                  I_p=_number(where, d, "I_p"), name=name, radius=_number(where, d, "radius", 0.0))


def _coefficients(where: str, b: dict) -> dict[str, Any]:
    out: dict[str, Any] = {"name": b.get("name", "")}
    for kind in ("k", "c"):
        if kind in b:
            for direct in (f"{kind}_xx", f"{kind}_yy"):
                if direct in b:
                    raise ValueError(f"{where}: give `{kind}` (isotropic) or `{direct}`, not both")
            out[f"{kind}_xx"] = out[f"{kind}_yy"] = _number(where, b, kind)
        for suffix in ("xx", "yy", "xy", "yx"):
            key = f"{kind}_{suffix}"
            if key in b:
                out[key] = _number(where, b, key)
    return out
