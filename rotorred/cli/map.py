"""``rotorred map SCENE --vary KEY=START:STOP:N [--vary ...] --out DIR``: a map of the operating envelope.

``rotorred sweep`` is the same command (one code path): a one-key sweep is a map with one
``--vary``, e.g. ``rotorred sweep paper-rub --vary rub.clearance=0:45e-6:10 --cold --out c``.

Runs the scene at every point of the grid of the varied keys on a Dask cluster (a
LocalCluster, one single-threaded worker per core, unless ``--scheduler`` names one; ``--workers
0`` runs serially), each point from its neighbour's final state along the first key (``--cold``:
from the scene's start), up, down or both ways, each until settled or ``--limit`` seconds. Writes
``map.nc`` (xarray/NetCDF), ``map.csv``, ``map_lines.csv``, ``map.txt``, the figures and ``scene.toml`` (the
resolved base scene; the command line, with the varied keys, is at the top of ``map.txt`` and in ``map.nc``),
``report.html`` (class map and bifurcation diagram, a point's orbit and spectrum on a click; ``--no-html``: none); the
points are kept in ``DIR/points`` as they finish, and the same command resumes an interrupted map.
"""

from __future__ import annotations

from rotorred import checks
from rotorred.cli.feedback import error, report
from rotorred.cli.options import SCENE_UNITS, add_settings, out_dir, provenance, spool_ratios
from rotorred.cli.report import add_html_option, write_report_to


def add_parser(subparsers):
    p = subparsers.add_parser(
        "map", aliases=["sweep"], help="run a scene over a grid of keys (speeds, clearance) on Dask: classes, bifurcation diagram",
        description="Run a scene at every point of a grid of one or more keys, each point continued from its "
                    "neighbour's final state along the first key, and write the classes, labelled lines, "
                    "Poincare samples, orbits and contact as NetCDF and CSV with a bifurcation diagram, a waterfall "
                    "and heat maps.")
    p.add_argument("scene", metavar="SCENE", help="built-in scene or scene TOML file")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=VALUES",
                   help=f"KEY=START:STOP:N or KEY=v1,v2,... ({SCENE_UNITS}); repeat for a 2-D map; the first is the "
                        "continuation axis")
    add_settings(p, "fix")
    p.add_argument("--ratio", action="append", default=[], metavar="SPOOL=R",
                   help="that spool turns at R times the varied speed, e.g. inner=0.7778 with --vary speeds.outer=...")
    p.add_argument("--direction", default="up", help="up, down or both (hysteresis, coexisting responses)")
    p.add_argument("--cold", action="store_true", help="start every point from the scene's start (no continuation)")
    p.add_argument("--limit", type=float, default=None, metavar="SECONDS",
                   help="simulate a point that has not settled up to this time (s; default: the scene's duration)")
    p.add_argument("--workers", type=int, default=None, help="local Dask workers (default one per core; 0: serial)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", help="an existing Dask scheduler, tcp://host:port")
    p.add_argument("--out", required=True, help="output directory (its points/ are kept: the same command resumes)")
    p.add_argument("--force", action="store_true",
                   help="go on with maps beyond the size limits (steps, memory, model size; see the message)")
    add_html_option(p)
    return p


def spec_of(args):
    """The :class:`rotorred.maps.spec.MapSpec` of the options (its size and points checked by
    :func:`rotorred.maps.run.run_map`)."""
    from rotorred import Axis, MapSpec, parse_setting

    fixed = []
    for item in args.set:
        key, values = parse_setting(item)
        if len(values) != 1:
            checks.fail("--set", item, "must fix one value; use --vary to vary a key (rotorred sweep is rotorred "
                                       "map: --vary KEY=v1,v2,...)")
        fixed.append((key, values[0]))
    axes = tuple(Axis(*_values(parse_setting(item, option="--vary"), item)) for item in args.vary)
    ratios = tuple(spool_ratios("--ratio", args.ratio, bound="> 0", example="inner=0.7778").items())
    return MapSpec(args.scene, axes, tuple(fixed), ratios, args.direction, args.cold, args.limit)


def workers(args) -> int | None:
    """The local workers of ``--workers`` (None: one per core; 0: serial): more than the machine's cores is warned
    about and capped at them unless ``--force`` (each worker holds a point's model and record, and they would share
    the cores); with ``--scheduler`` the scheduler's workers, None."""
    import logging
    import os

    if args.workers is not None:
        checks.integer("--workers", args.workers, ge=0)
    if args.scheduler:
        return None
    cores = os.cpu_count() or 1
    if args.workers is None:
        return cores
    if args.workers > cores and not args.force:
        logging.getLogger(__name__).warning("--workers = %d is more than the %d cores of this machine: "
                                            "capped at %d (--force to start %d)", args.workers, cores, cores, args.workers)
        return cores
    return args.workers


def base_scene_toml(spec) -> str:
    """The resolved base scene of a map: its scene with the fixed settings (``--set``), the varied keys as the scene
    has them (the command line in the provenance names their values). A base scene that is not valid on its own
    (a varied key makes it so) gives the scene of the map's first grid point."""
    from rotorred import InputError, load_scene, scene_toml

    try:
        scene = load_scene(spec.scene, dict(spec.settings))
    except InputError:
        scene = spec.scene_at((0,) * len(spec.axes))
    return scene_toml(scene)


def _values(parsed, item: str) -> tuple[str, tuple]:
    key, values = parsed
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        checks.fail(f"--vary {key}", item.partition("=")[2], "must be numbers: START:STOP:N or v1,v2,...")
    return key, tuple(float(v) for v in values)


def run(args) -> int:
    """Check everything, then run the map into ``--out`` (exit 3 when points failed or the Dask cluster was lost, 130
    or 143 when SIGINT or SIGTERM ended it: the points done written, the folder marked INCOMPLETE)."""
    from rotorred.cli import EXIT_DIVERGED, interrupted_status, interrupts
    from rotorred import format_map, run_map

    out = out_dir("--out", args.out)
    n_workers = workers(args)
    spec = spec_of(args)
    report(f"map of {spec.scene}: {' x '.join(f'{a.key} ({len(a.values)})' for a in spec.axes)}, "
           f"{'/'.join(spec.directions)}, {spec.n_points} points, "
           f"{'cold starts' if spec.cold else 'continuation along ' + spec.axes[0].key}")
    record = provenance(args, "scene", base_scene_toml(spec))
    result = run_map(spec, out, workers=n_workers, scheduler=args.scheduler, provenance=record,
                     force=args.force, interrupts=interrupts())
    report(format_map(result.dataset, spec))
    for f in list(result.files) + write_report_to(args, out, result):
        report(f"wrote {f}")
    report(f"{result.n_run} points run, {result.n_resumed} resumed from {out / 'points'}; "
           f"wall time {result.wall_time:.2f} s")
    if result.incomplete:
        error(f"{result.incomplete}; the points done are written, the folder marked INCOMPLETE")
        return interrupted_status(result.interrupt) if result.interrupt else EXIT_DIVERGED
    if result.interrupt:  # the signal came as the complete map was written: it was written whole first
        error(f"interrupted ({result.interrupt}) as the complete map was written; it is written whole")
        return interrupted_status(result.interrupt)
    if result.n_failed:
        error(f"{result.n_failed} of {spec.n_points} points failed (named in map.csv and map.txt); the other "
              "points are kept")
        return EXIT_DIVERGED
    return 0
