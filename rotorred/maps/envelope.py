"""A map along a speed line from Python: ``envelope_map(model, operating, loads, contacts, options, out)``.

The map of ``rotorred map SCENE --vary speeds.<reference>=...`` (:mod:`rotorred.maps.run`), for a model and an
:class:`rotorred.model.operating.Operating` line: the reference spool at each speed of the line, every other spool
by the line's rule (a spool at a ratio turns at that ratio of the varied speed, ``--ratio``; a fixed spool keeps its
speed), each point continued from its neighbour's final state. The map's points run in Dask workers, which read
their scene from a file: the scene built from the inputs is written into ``out/points`` by
:func:`rotorred.scenes.resolved.scene_toml`, under a name holding its digest, so that the same call resumes and a
different one is refused. The model reaches the workers as the scene's ``[solver]`` model: a reduced model as its
kept nodes and mode count (:func:`rotorred.linear.reduction.reduce_rotor` builds the same model again), an assembled
model as the full one, a rotor as the scene default (modes chosen for the outputs).
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from rotorred import checks
from rotorred.maps.run import MapRun, run_map
from rotorred.maps.spec import DIRECTIONS, Axis, MapSpec
from rotorred.model.assembly import SystemMatrices
from rotorred.model.operating import Operating, checked as checked_operating
from rotorred.scenes.built import built_scene, checked_loads, load_nodes, plates_on, recorded_nodes, rotor_model
from rotorred.scenes.resolved import scene_toml
from rotorred.scenes.schema import OutputSpec, Scene, SolverSpec
from rotorred.transient.contact import RubPlate
from rotorred.transient.options import Loads
from rotorred.writers import write_text

__all__ = ["MapOptions", "envelope_map"]


@dataclass(frozen=True)
class MapOptions:
    """How each point of a map runs and what the map records (:func:`envelope_map`).

    Parameters
    ----------
    dt : float
        Time step (s), > 0.
    duration : float
        Simulated time of a point (s), > 0.
    record_start : float
        Start of the recorded window (s), in [0, duration).
    direction : {"up", "down", "both"}
        Sweep direction along the line; "both" runs up, then down.
    cold : bool
        Every point from the scene's start (no continuation).
    limit : float, optional
        Simulated time (s) up to which a point that has not settled runs on; default ``duration``.
    nodes : sequence of int
        Nodes whose x and y are recorded; default the unbalance and rub nodes.
    table : (int, str), optional
        The DOF each point is classified and its lines fitted by (a recorded one); default the first node's y.
    workers : int, optional
        Local Dask workers (default one per core; 0: serially in this process).
    figures : bool
        Write the map's figures.
    """

    dt: float = 2e-5
    duration: float = 2.0
    record_start: float = 1.5
    direction: str = "up"
    cold: bool = False
    limit: float | None = None
    nodes: Sequence[int] = ()
    table: tuple[int, str] | None = None
    workers: int | None = None
    figures: bool = True

    def __post_init__(self):
        checks.positive("options.dt", self.dt, "s")
        checks.positive("options.duration", self.duration, "s")
        checks.number("options.record_start", self.record_start, "s", ge=0.0, lt=self.duration)
        checks.choice("options.direction", self.direction, DIRECTIONS)
        checks.boolean("options.cold", self.cold)
        checks.boolean("options.figures", self.figures)
        if self.workers is not None:
            checks.integer("options.workers", self.workers, ge=0)
        object.__setattr__(self, "nodes", tuple(checks.integer(f"options.nodes[{k}]", n)
                                                for k, n in enumerate(self.nodes)))
        if self.table is not None:
            node, direction = self.table
            if node not in self.nodes or direction not in ("x", "y"):
                checks.fail("options.table", self.table, "must be the x or y of a node of options.nodes")
            object.__setattr__(self, "table", (int(node), str(direction)))


def envelope_map(model, operating: Operating, loads: Loads, contacts: Sequence[RubPlate], options: MapOptions,
                 out: str | Path) -> MapRun:
    """The map of the rub response along the ``operating`` speed line (module docstring), written into ``out``.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        Built from a rotor; a reduced model is rebuilt in the workers from its kept nodes and mode count.
    operating : Operating
        A speed line of the reference spool; the map's points are its speeds.
    loads : Loads
        Unbalances and gravity.
    contacts : sequence of RubPlate
        Rub plates (may be empty); a plate without ``disk_radius`` takes its disk's from the rotor.
    options : MapOptions
        Time step, durations, direction, continuation, recorded nodes, workers, figures.
    out : str or Path
        Output folder (as ``rotorred map --out``); its ``points/`` are kept, and the same call resumes.

    Returns
    -------
    MapRun

    Raises
    ------
    rotorred.checks.InputError
        For a bad input, before any point runs.
    """
    system = rotor_model(model)
    operating = checked_operating(operating)
    if operating.kind == "profile":
        checks.fail("operating", operating.describe(), "must be a speed line (a point is a map of one speed)")
    if not isinstance(options, MapOptions):
        checks.fail("options", type(options).__name__, "must be a MapOptions")
    lines, reference = operating.lines(system), operating.reference_of(system)
    scene = _scene(model, system, operating, loads, contacts, options)
    ratios = tuple((s, line.slope) for s, line in lines.items() if s != reference and line.how != "fixed")
    text = scene_toml(scene)
    out = Path(out)
    path = out / "points" / f"scene-{hashlib.sha256(text.encode()).hexdigest()[:12]}.toml"
    if not path.exists():
        write_text(path, text)
    spec = MapSpec(str(path), (Axis(f"speeds.{reference}", tuple(float(w) / (2 * math.pi) for w in operating.Omega)),),
                   ratios=tuple((s, r) for s, r in ratios if r > 0), direction=options.direction,
                   cold=options.cold, limit=options.limit)
    return run_map(spec, out, workers=options.workers, figures=options.figures)


def _scene(model, system, operating: Operating, loads: Loads, contacts, options: MapOptions) -> Scene:
    """The scene of the map's first point: the model as a ``[solver]`` model, the loads, plates and outputs."""
    loads = checked_loads(loads)
    plates = plates_on(contacts, system.rotor)
    nodes = recorded_nodes(options.nodes, load_nodes(loads, plates), system)
    if model is system.rotor:
        settings = {}  # the scene default: a reduced model, its modes chosen for the outputs
    elif isinstance(system, SystemMatrices):
        settings = dict(model="full")
    else:
        settings = dict(model="reduced", modes=system.n_modes, boundary_nodes=tuple(system.boundary_nodes))
    solver = SolverSpec(dt=options.dt, duration=options.duration, record_start=options.record_start,
                        gravity=loads.gravity or 0.0, **settings)
    return built_scene(system, f"map along {operating.describe()}", operating.at(system, 0), loads, plates, solver,
                       OutputSpec(nodes=nodes, table=options.table or (nodes[0], "y"), plots=(), formats=(),
                                  compare_normal=False))
