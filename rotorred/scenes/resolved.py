"""The resolved scene: a validated :class:`rotorred.scenes.schema.Scene` written back as a scene file.

:func:`scene_document` gives the tables of a scene file that holds every key the scene resolved: the defaults
filled in, the overrides (``--set``) applied, and the rotor inline (``[rotor]`` holding the rotor file's own
tables, whatever preset or file the scene named), so that the file alone reproduces the run, bit for bit:
:func:`rotorred.scenes.schema.scene_from_toml` of :func:`scene_toml` builds a scene equal to the one it was written
from. A key is left out only where its value is automatic (``solver.cutoff_hz``, ``solver.alpha``,
``solver.tolerance``, ``output.plot_window``, ``output.table``, ``output.f_max_hz`` when not given; TOML has no
"none").

Values are written in the units of a scene file (speeds in Hz, angles in degrees): a value converted by the scene's
validation (``speeds``, ``phase_deg``, ``theta_deg``, a run-up's ``from``, ``to`` and ``table``) is written as the
scene wrote it, or as its default; the others are the validated values themselves. Floats are written with ``repr``
(:func:`rotorred.writers.toml_text`), so they read back to the same bits.
"""

from __future__ import annotations

import math

import numpy as np

from rotorred.model.rotor_writer import rotor_table
from rotorred.scenes.schema import RunupSpec, Scene
from rotorred.transient.plate import ClampedFreePlate, NavierPlate
from rotorred.writers import exact_in_unit, toml_text

__all__ = ["scene_document", "scene_toml"]

#: defaults of the keys the validation converts (their units as written)
THETA_DEG, PHASE_DEG = 90.0, 0.0
RUNUP_RAMP = {"from": 0.0, "to": 1.2, "duration": 10.0, "hold": 0.0}
#: the plate numbers of a rub entry, and where the plate keeps them
_RUB_NUMBERS = ("clearance", "K_nr", "c", "mu_s", "mu_d", "m_p", "k_n", "k_t", "c_n", "c_t", "disk_radius")
_NAVIER = {"plate_a": "a", "plate_b": "b", "plate_h": "h", "plate_E": "E", "plate_nu": "nu", "plate_xi": "xi",
           "plate_eta": "eta"}


def scene_toml(scene: Scene) -> str:
    """The resolved scene as the text of a scene file (:func:`scene_document`).

    Parameters
    ----------
    scene : Scene
        A validated scene; its defaults are written out, in the units of a scene file (speeds in Hz,
        angles in degrees, the rest SI).

    Returns
    -------
    str
        TOML text that :func:`rotorred.scenes.schema.load_scene` reads back to the same scene.
    """
    return toml_text(scene_document(scene))


def scene_document(scene: Scene) -> dict:
    """The tables of a scene file reproducing ``scene`` (module docstring)."""
    written = scene.data  # empty for a scene built in Python (rotorred.scenes.balance, runup): the objects' own values
    doc = {"name": scene.name, "description": scene.description, "rotor": _rotor(scene),
           "speeds": _speeds(scene, written.get("speeds") or {}, built=not written),
           "unbalance": [_unbalance(u, w) for u, w in zip(scene.unbalances,
                                                          written.get("unbalance") or [{}] * len(scene.unbalances))],
           "rub": [_rub(p, w) for p, w in zip(scene.plates, written.get("rub") or [{}] * len(scene.plates))],
           "solver": _solver(scene.solver), "output": _output(scene.output)}
    if scene.runup is not None:
        doc["runup"] = _runup(scene.runup, written.get("runup") or {"table": _profile_table(scene)})
    return {k: v for k, v in doc.items() if v != []}


def _rotor(scene: Scene) -> dict:
    """``[rotor]``: the rayleigh values in effect and the rotor's own tables inline (as read, or, for a scene built in
    Python, written by :func:`rotorred.model.rotor_writer.rotor_table`)."""
    alpha, beta = scene.rotor.rayleigh
    return {"rayleigh_alpha": alpha, "rayleigh_beta": beta, **(scene.rotor_data or rotor_table(scene.rotor))}


def _speeds(scene: Scene, written: dict, built: bool = False) -> dict:
    """Every spool's speed (Hz) the scene's operating point needs: the spools the scene gave, as written and in their
    order (the first is the reference; a spool left out follows it by the same rule on reading back); no ``[speeds]``:
    the rotor's nominal speeds where every one reads back exactly from its Hz value, else none (the same default). A
    scene ``built`` in Python writes every speed, within 1 ulp where no Hz value reads back."""
    if written:
        return dict(written)
    exact = {s: _exact_hz(w) for s, w in scene.speeds.items()}
    if built:
        return {s: hz if hz is not None else scene.speeds[s] / (2 * math.pi) for s, hz in exact.items()}
    return exact if None not in exact.values() else {}


def _exact_hz(w: float) -> float | None:
    """A frequency f (Hz) with 2 pi f == w (rad/s) to the bit, or None (the key is then left to the rotor's own
    nominal speed, the same default)."""
    f = w / (2 * math.pi)
    for candidate in (f, *np.nextafter(f, [np.inf, -np.inf])):
        if 2 * math.pi * float(candidate) == w:
            return float(candidate)
    return None


def _unbalance(u, written: dict) -> dict:
    """An ``[[unbalance]]`` entry: the phase as written, else (a scene built in Python) in degrees where a number
    reads back to it exactly, else in rad."""
    if "phase_rad" in written or "phase_deg" in written:
        phase = {k: written[k] for k in ("phase_rad", "phase_deg") if k in written}
    elif not written and u.phase != math.radians(PHASE_DEG):
        deg = exact_in_unit(u.phase, math.radians, math.degrees(u.phase))
        phase = {"phase_deg": deg} if deg is not None else {"phase_rad": u.phase}
    else:
        phase = {"phase_deg": PHASE_DEG}
    return {"node": u.node, "m_e": u.m_e, **phase}


def _rub(plate, written: dict) -> dict:
    """A ``[[rub]]`` entry: node, angle and name, every number of the plate and of its bending model."""
    if written:
        theta = written.get("theta_deg", THETA_DEG)
    else:  # a scene built in Python: the plate's own angle (the reader converts by math.radians)
        theta = exact_in_unit(plate.theta, math.radians, math.degrees(plate.theta))
        if theta is None:
            raise ValueError(f"rub at node {plate.node}: theta = {plate.theta!r} rad has no number of degrees that "
                             "reads back to it; a scene file gives the angle in degrees")
    out = {"node": plate.node, "theta_deg": theta, "name": plate.name}
    out.update({k: getattr(plate, k) for k in _RUB_NUMBERS})
    bending = plate.bending
    if isinstance(bending, NavierPlate):
        out["bending"] = "navier"
        out.update({k: getattr(bending, attr) for k, attr in _NAVIER.items()})
    elif isinstance(bending, ClampedFreePlate):
        out.update(bending="clamped-free", a0=bending.a0, b0=bending.b0)
    else:
        out["bending"] = "rigid"
    return out


def _solver(s) -> dict:
    out = {"model": s.model}
    if s.cutoff_hz is not None:
        out["cutoff_hz"] = s.cutoff_hz
    else:
        out["modes"] = "auto" if s.modes is None else s.modes
    out.update(boundary_nodes=list(s.boundary_nodes), dt=s.dt, duration=s.duration, record_start=s.record_start,
               start=s.start, method=s.method, gravity=s.gravity)
    optional = {"alpha": s.alpha, "tolerance": s.tolerance, "harmonics": s.harmonics, "samples": s.samples}
    out.update({k: v for k, v in optional.items() if v is not None})
    return out


def _output(o) -> dict:
    out = {"nodes": list(o.nodes), "directions": list(o.directions), "plots": list(o.plots),
           "formats": list(o.formats)}
    if o.plot_window is not None:
        out["plot_window"] = list(o.plot_window)
    if o.table is not None:
        out["table"] = f"{o.table[0]}:{o.table[1]}"
    out["line_threshold"] = o.line_threshold
    if o.f_max_hz is not None:
        out["f_max_hz"] = o.f_max_hz
    out["compare_normal"] = o.compare_normal
    return out


def _profile_table(scene: Scene) -> list[list[float]]:
    """A scene built in Python: its speed profile as ``runup.table`` rows [t (s), each spool's speed (Hz) in the
    rotor's order], each speed the number of Hz that reads back to it exactly where there is one (the reader
    multiplies by 2 pi, which reaches about 1 float in 6: the others read back within 1 ulp, as a scene file's table
    gives speeds in Hz only)."""
    p = scene.runup.profile
    spools = [s.name for s in scene.rotor.spools]

    def hz(w: float) -> float:
        estimate = float(w) / (2 * math.pi)
        exact = exact_in_unit(float(w), lambda f: 2 * math.pi * f, estimate)
        return estimate if exact is None else exact
    return [[float(t)] + [hz(p.speeds[s][k]) for s in spools] for k, t in enumerate(p.t)]


def _runup(r: RunupSpec, written: dict) -> dict:
    """``[runup]``: the speed profile as written (a ramp's fractions with their defaults, or the table), the rest
    validated."""
    out = {"table": written["table"]} if "table" in written else {k: written.get(k, v) for k, v in RUNUP_RAMP.items()}
    out.update(reference=r.reference, orders=list(r.orders), orbits_hz=list(r.orbits_hz), record_dt=r.record_dt,
               revs_per_block=r.revs_per_block)
    return out
