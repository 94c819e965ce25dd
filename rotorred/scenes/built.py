"""A scene built from Python objects, in place of one read from a file.

The ``(model, operating, loads, contacts, options)`` forms of the scene analyses (:func:`rotorred.scenes.balance.
harmonic_balance`, :func:`~rotorred.scenes.balance.continue_balance`, :func:`rotorred.scenes.runup.runup`,
:func:`rotorred.maps.envelope.envelope_map`) run the scene's own analysis of a :class:`Scene` built here: the same
checks of their inputs, one way of building it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from rotorred import checks
from rotorred.model.assembly import system_of
from rotorred.model.operating import Operating
from rotorred.scenes.schema import OutputSpec, RunupSpec, Scene, SolverSpec
from rotorred.transient.contact import RubPlate
from rotorred.transient.matrices import disk_radii
from rotorred.transient.options import Loads

__all__ = ["rotor_model", "checked_loads", "balance_loads", "plates_on", "load_nodes", "recorded_nodes", "built_scene"]


def rotor_model(model):
    """``model`` through :func:`rotorred.model.assembly.system_of`, which must carry the rotor it was built from
    (its spools, disks and nominal speeds are the scene's)."""
    system = system_of(model)
    if system.rotor is None:
        checks.fail("model", type(model).__name__, "must be built from a Rotor (assemble, reduce_rotor): the scene's "
                    "spools and disks are the rotor's")
    return system


def checked_loads(loads) -> Loads:
    """``loads``, a :class:`rotorred.transient.options.Loads`."""
    if not isinstance(loads, Loads):
        checks.fail("loads", type(loads).__name__, "must be a Loads")
    return loads


def balance_loads(loads) -> Loads:
    """``loads``, a :class:`rotorred.transient.options.Loads` without gravity: a static load has no harmonic balance
    here (periodic or on a torus)."""
    if checked_loads(loads).gravity:
        checks.fail("loads.gravity", loads.gravity, "must be None: harmonic balance here has no static load", "m/s^2")
    return loads


def plates_on(contacts: Sequence[RubPlate], rotor, min_len: int = 0) -> tuple[RubPlate, ...]:
    """The plates (at least ``min_len``), each with its disk radius: the plate's ``disk_radius``, else the rotor's
    disk at its node (:func:`rotorred.transient.matrices.disk_radii`, the rule of
    :func:`rotorred.transient.newmark.simulate`)."""
    plates = checks.sequence("contacts", list(contacts), min_len=min_len)
    for k, p in enumerate(plates):
        if not isinstance(p, RubPlate):
            checks.fail(f"contacts[{k}]", type(p).__name__, "must be a RubPlate")
    return tuple(p if p.disk_radius is not None else p.with_(disk_radius=r)
                 for p, r in zip(plates, disk_radii(plates, rotor)))


def load_nodes(loads: Loads, plates: Sequence[RubPlate]) -> tuple[int, ...]:
    """The unbalance nodes, then the plate nodes, each once: the nodes a built scene records by default."""
    return tuple(dict.fromkeys([u.node for u in loads.unbalances] + [p.node for p in plates]))


def recorded_nodes(nodes: Sequence[int], defaults: Sequence[int], system, field: str = "options.nodes",
                   what: str = "there is no unbalance or plate to default to") -> tuple[int, ...]:
    """The nodes given (each a node of ``system``), else ``defaults``; at least one."""
    nodes = tuple(nodes) or tuple(defaults)
    if not nodes:
        checks.fail(field, (), f"must name a node to record ({what})")
    return tuple(checks.node(f"{field}[{k}]", n, system.full_dofs.nodes) for k, n in enumerate(nodes))


def built_scene(system, description: str, speeds: Mapping[str, float], loads: Loads, plates: tuple,
                solver: SolverSpec, output: OutputSpec, runup: RunupSpec | None = None) -> Scene:
    """The scene of ``system``'s rotor at ``speeds`` (rad/s) with ``loads``' unbalances and ``plates``; its
    ``rotor_source`` is ``"python"`` (:func:`rotorred.scenes.resolved.scene_toml` writes the rotor inline)."""
    return Scene(name=system.rotor.name or "rotor", description=description, rotor=system.rotor,
                 rotor_source="python", operating=Operating.point(dict(speeds)), unbalances=tuple(loads.unbalances), plates=plates,
                 solver=solver, output=output, runup=runup)
