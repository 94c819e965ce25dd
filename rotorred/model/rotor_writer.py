"""Writing a rotor file: the rotor-file document of a :class:`rotorred.model.rotor.Rotor` (``Rotor.to_toml``).

:func:`rotor_table` is the one writer of rotor files (``rotorred convert`` writes a ROSS rotor through it); the
reader, :mod:`rotorred.model.rotor_file`, makes the same rotor of it again, every number to the bit
(docs/model.md §18). This module does not import :mod:`rotorred.model.rotor` (which calls it), so it takes the rotor
as it is given.
"""

from __future__ import annotations

import math
from typing import Any

from rotorred.model.elements import (Bearing, BearingTable, Disk, IntershaftBearing, IntershaftBearingTable, Material,
                                     Pedestal, ShaftElement, Support)
from rotorred.model.loads import Unbalance
from rotorred.writers import exact_in_unit

__all__ = ["rotor_table", "rpm_to_rad_s"]

#: the internal-damping keys of a spool (its elements' default) and of an element (None: the spool's)
_INTERNAL = ("internal_damping_beta", "internal_loss_factor")


def rpm_to_rad_s(rpm):
    """A speed in rpm in rad/s, ``rpm * pi / 30`` (a float or an array): the one conversion of a rotor file's speeds
    (:mod:`rotorred.model.rotor_file`), which :func:`rotor_table` inverts exactly."""
    return rpm * math.pi / 30.0


def rotor_table(rotor) -> dict[str, Any]:
    """The rotor-file document of ``rotor``, which :func:`rotorred.model.rotor_file.rotor_from_dict` makes the
    same rotor again, to the bit.

    Every float is the stored one (``rotorred.writers.toml_text`` writes ``repr``), except speeds and phases, which
    are written in rpm and degrees when such a number reads back to the stored rad/s and rad exactly
    (:func:`rotorred.writers.exact_in_unit`), else in SI (``speed_rad_s``, ``phase_rad``). A spool on consecutive
    node numbers has a ``first_node``, any other the list ``nodes``; equal consecutive elements are one entry with
    ``repeat``. A material keeps the modulus it was given by (``G`` or ``nu``).

    Parameters
    ----------
    rotor : Rotor

    Returns
    -------
    dict
        The rotor file's tables (``rotorred.writers.toml_text`` writes it).

    Notes
    -----
    Materials are named by their names, made unique (``steel-2``) and non-empty (``material``) where the rotor's
    are not: only then does the rotor read back differ (in those names). A sleeve is read back with the length of
    the element it lies on (which :class:`rotorred.model.rotor.Spool` allows to differ by 1e-9 relative).
    """
    names = _material_names(rotor)
    document: dict[str, Any] = {"name": rotor.name,
                                "material": [_material_table(m, name) for m, name in names.items()],
                                "spool": [_spool_table(s, names) for s in rotor.spools]}
    for key, items, table in (("disk", rotor.disks, _disk_table), ("bearing", rotor.bearings, _bearing_table),
                              ("intershaft_bearing", rotor.intershaft_bearings, _intershaft_table),
                              ("support", rotor.supports, _support_table),
                              ("pedestal", rotor.pedestals, _pedestal_table)):
        if items:
            document[key] = [table(item) for item in items]
    if rotor.rayleigh != (0.0, 0.0):
        document["damping"] = {"rayleigh_alpha": rotor.rayleigh[0], "rayleigh_beta": rotor.rayleigh[1]}
    defaults = _defaults_table(rotor.defaults)
    if defaults:
        document["defaults"] = defaults
    return document


def _material_names(rotor) -> dict[Material, str]:
    """Each material of the shaft elements, in order of first use, and its name in the file (unique, non-empty)."""
    names: dict[Material, str] = {}
    for e in (e for s in rotor.spools for e in s.all_elements):
        if e.material not in names:
            base, taken = e.material.name or "material", set(names.values())
            names[e.material] = base if base not in taken else next(f"{base}-{i}" for i in range(2, len(taken) + 2)
                                                                     if f"{base}-{i}" not in taken)
    return names


def _material_table(m: Material, name: str) -> dict[str, Any]:
    return {"name": name, "E": m.E, "rho": m.rho, **({"G": m.G} if m.G is not None else {"nu": m.nu})}


def _spool_table(s, names: dict[Material, str]) -> dict[str, Any]:
    nodes = s.nodes
    consecutive = nodes == tuple(range(nodes[0], nodes[0] + len(nodes)))
    table: dict[str, Any] = {"name": s.name, **({"first_node": nodes[0]} if consecutive else {"nodes": list(nodes)}),
                             "z0": s.z0}
    if s.speed != 0.0:
        table.update(_speeds_in_rpm("speed", [s.speed], single=True))
    table.update({k: getattr(s, k) for k in _INTERNAL if getattr(s, k) != 0.0})
    materials = {names[e.material] for e in s.all_elements}
    common = materials.pop() if len(materials) == 1 else None
    if common is not None:
        table["material"] = common
    entries = [{"L": e.L, **_section(e, names, common)} for e in s.elements]
    table["elements"] = [dict(entry, **({"repeat": n} if n > 1 else {})) for entry, n in _runs(entries, dict.__eq__)]
    if s.sleeves:
        sleeves = [{"left": e.left, **_section(e, names, common), "_right": e.right} for e in s.sleeves]
        runs = _runs(sleeves, lambda a, b: b["left"] == a["_right"] and _without(a) == _without(b))
        table["sleeves"] = [dict(_without(entry), **({"repeat": n} if n > 1 else {})) for entry, n in runs]
    return table


def _section(e: ShaftElement, names: dict[Material, str], common: str | None) -> dict[str, Any]:
    """The keys of an element or sleeve entry but its length and nodes: the diameters, and what differs from the
    defaults (the spool's material, shear "cowper", element "nelson", rotary inertia)."""
    out: dict[str, Any] = {"D_o": e.D_o, "D_i": e.D_i}
    if e.tapered:
        out.update(D_o_right=e.D_o_right, D_i_right=e.D_i_right)
    if names[e.material] != common:
        out["material"] = names[e.material]
    for key, default in (("shear", "cowper"), ("element", "nelson"), ("rotary_inertia", True)):
        if getattr(e, key) != default:
            out[key] = getattr(e, key)
    out.update({k: getattr(e, k) for k in _INTERNAL if getattr(e, k) is not None})
    return out


def _without(sleeve: dict[str, Any]) -> dict[str, Any]:
    """A sleeve entry without the right node it was grouped by."""
    return {k: v for k, v in sleeve.items() if k != "_right"}


def _runs(entries: list[dict], continues) -> list[tuple[dict, int]]:
    """The entries grouped into runs, each its first entry and its length: ``continues(previous, next)`` says whether
    the next entry repeats the run (a ``repeat`` in the file)."""
    runs: list[list] = []
    for entry in entries:
        if runs and continues(runs[-1][2], entry):
            runs[-1][1] += 1
            runs[-1][2] = entry
        else:
            runs.append([entry, 1, entry])
    return [(first, n) for first, n, _ in runs]


def _speeds_in_rpm(key: str, speeds, single: bool = False) -> dict[str, Any]:
    """``{key_rpm: ...}`` when each speed (rad/s) is exactly an rpm number read back, else ``{key_rad_s: ...}``."""
    rpm = [exact_in_unit(w, rpm_to_rad_s, w * 30.0 / math.pi) for w in speeds]
    if None in rpm:
        return {f"{key}_rad_s": speeds[0] if single else list(speeds)}
    return {f"{key}_rpm": rpm[0] if single else rpm}


def _disk_table(d: Disk) -> dict[str, Any]:
    return {"node": d.node, **_named(d), "m": d.m, "I_d": d.I_d, "I_p": d.I_p,
            **({"radius": d.radius} if d.radius != 0.0 else {})}


def _named(item) -> dict[str, str]:
    return {"name": item.name} if item.name else {}


def _bearing_table(b: Bearing | BearingTable) -> dict[str, Any]:
    table: dict[str, Any] = {"node": b.node, **_named(b), **({"link": b.link} if b.link is not None else {})}
    if isinstance(b, BearingTable):
        table.update(_table_rules(b, b.axis))
    return table | _coefficient_entries(b)


def _table_rules(b: BearingTable | IntershaftBearingTable, axis: str = "speed") -> dict[str, Any]:
    """A table's axis (``speed_rpm``, or ``frequency_rpm`` for a table against whirl frequency) and its rules where
    they differ from the defaults."""
    return {**_speeds_in_rpm(axis, b.speeds),
            **{k: getattr(b, k) for k, default in (("interpolation", "linear"), ("extrapolate", "hold"))
               if getattr(b, k) != default}}


def _intershaft_table(b: IntershaftBearing | IntershaftBearingTable) -> dict[str, Any]:
    table: dict[str, Any] = {"node_a": b.node_a, "node_b": b.node_b, **_named(b)}
    if isinstance(b, IntershaftBearingTable):
        table.update({**({"speed_of": b.speed_of} if b.speed_of is not None else {}), **_table_rules(b)})
    return table | _coefficient_entries(b)


def _coefficient_entries(b) -> dict[str, Any]:
    """The non-zero coefficients: ``k`` / ``c`` (``k_tt`` / ``c_tt``) for equal direct (tilt) terms; a column of a
    table equal at every speed as one number."""
    out: dict[str, Any] = {}
    for short, (x, y) in (("k", ("x", "y")), ("c", ("x", "y")), ("k_tt", ("tx", "ty")), ("c_tt", ("tx", "ty"))):
        kind = short[0]
        xx, yy = getattr(b, f"{kind}_{x}{x}"), getattr(b, f"{kind}_{y}{y}")
        pairs = [(short, xx)] if xx == yy else [(f"{kind}_{x}{x}", xx), (f"{kind}_{y}{y}", yy)]
        pairs += [(f"{kind}_{d}", getattr(b, f"{kind}_{d}")) for d in (x + y, y + x)]
        out.update({key: _column(value) for key, value in pairs if any(v != 0.0 for v in _values(value))})
    return out


def _values(value) -> tuple[float, ...]:
    return tuple(value) if isinstance(value, tuple) else (value,)


def _column(value):
    """A coefficient as written: a number, or a table's column (one number when equal at every speed)."""
    if isinstance(value, tuple):
        return value[0] if len(set(value)) == 1 else list(value)
    return value


def _support_table(sp: Support) -> dict[str, Any]:
    return {"node": sp.node, "kind": sp.kind, **_named(sp)}


def _pedestal_table(p: Pedestal) -> dict[str, Any]:
    return {"node": p.node, **_named(p), "m": p.m}


def _defaults_table(d) -> dict[str, Any]:
    out: dict[str, Any] = {}
    if d.unbalances:
        out["unbalance"] = [_unbalance_table(u) for u in d.unbalances]
    if d.outputs:
        out["outputs"] = [f"{node}:{direction}" for node, direction in d.outputs]
    if d.boundary_nodes:
        out["boundary_nodes"] = list(d.boundary_nodes)
    for spool, lo, hi in d.operating_ranges:  # in rpm where both read back exactly, else in rad/s
        rpm = [exact_in_unit(w, rpm_to_rad_s, w * 30.0 / math.pi) for w in (lo, hi)]
        key, pair = ("operating_range_rpm", rpm) if None not in rpm else ("operating_range_rad_s", [lo, hi])
        out.setdefault(key, {})[spool] = pair
    return out


def _unbalance_table(u: Unbalance) -> dict[str, Any]:
    """An unbalance entry, its phase in degrees when such a number reads back to the phase (rad) exactly."""
    out: dict[str, Any] = {"node": u.node, "m_e": u.m_e}
    if u.phase != 0.0:
        deg = exact_in_unit(u.phase, math.radians, math.degrees(u.phase))
        out.update({"phase_deg": deg} if deg is not None else {"phase_rad": u.phase})
    return out
