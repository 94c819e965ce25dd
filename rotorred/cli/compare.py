"""``rotorred compare SCENE --modes 8,16,24 [--dt DT,...] [--refine N] [--set KEY=VALUE ...] --out DIR``: reduced
against full.

Runs the scene on its full model and on each reduced model (Craig–Bampton with each count of fixed-interface modes),
at each time step, and measures every run against the full model at the finest step
(:func:`rotorred.scenes.compare.compare_models`): the spectral error of the recorded DOFs, the orbit error at the rub
node, the contact fraction's error, the DOFs and the run time (wall and CPU, the model's build included). Writes
``compare.csv`` (a row a run), ``compare.png`` (wall time against spectral error, the front), ``compare.txt`` (the
printed table) and ``scene.toml`` (the scene as set, the comparison's options in the command line on top of
``compare.txt``).

SIGINT or SIGTERM after the reference run keeps the runs done: they are written, the folder marked INCOMPLETE, exit
130 or 143; before it, the folder keeps its earlier result, as in every command. A run that diverges ends the
comparison with exit 3 and one line saying when, where and why; nothing is written.
"""

from __future__ import annotations

import contextlib
import time

from rotorred import checks
from rotorred.cli.feedback import error, report
from rotorred.cli.options import add_settings, number_list, out_dir, provenance


def add_parser(subparsers):
    p = subparsers.add_parser(
        "compare", help="a scene on its full model and on reduced models: error against run time",
        description="Run a scene on its full model and on Craig-Bampton reduced models (each --modes count), at each "
                    "time step (--dt), and measure every run against the full model at the finest step: the "
                    "spectral error of every recorded DOF (worst of its largest lines), the orbit error at the rub "
                    "node, the DOFs and the run time (wall and CPU, reduction included); write compare.csv, "
                    "compare.png (time against error, the front) and compare.txt.")
    p.add_argument("scene", metavar="SCENE", help="built-in scene or scene TOML file (constant speeds, stepped in time)")
    p.add_argument("--modes", default="8,16,24",
                   help="fixed-interface mode counts of the reduced models, a comma list (default 8,16,24)")
    p.add_argument("--dt", default=None, metavar="DT,...",
                   help="time steps in s, a comma list, each a whole fraction of the largest (default the scene's "
                        "solver.dt); the finest is the reference's")
    p.add_argument("--refine", type=int, default=1, metavar="N",
                   help="split every shaft element of the scene's rotor into N (node numbers kept; default 1)")
    add_settings(p, "fix")
    p.add_argument("--force", action="store_true",
                   help="go on with a run beyond the size limits (steps, memory, model size; see the message)")
    p.add_argument("--out", required=True, help="output directory")
    return p


def _modes(text: str) -> tuple:
    """``"8,16,24"`` -> (8, 16, 24); their upper bound (the interior DOFs) is the scene's, checked with it."""
    requirement = "must be a comma list of whole numbers >= 1 (fixed-interface mode counts)"
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        checks.fail("--modes", text, requirement)
    if not all(v.is_integer() and v >= 1 for v in values):
        checks.fail("--modes", text, requirement)
    return tuple(int(v) for v in values)


def _options(args):
    """The :class:`rotorred.scenes.compare.CompareOptions` of the command line (values checked against the scene
    by ``check_comparison``)."""
    from rotorred import CompareOptions

    dts = () if args.dt is None else tuple(checks.bounded("--dt", args.dt, number_list("--dt", args.dt, "s", gt=0),
                                                          "step"))
    refine = checks.integer("--refine", args.refine, ge=1)
    checks.bounded("--refine", args.refine, refine, "refine")
    return CompareOptions(modes=_modes(args.modes), dts=dts, refine=refine, progress=None)


def run(args) -> int:
    """Check everything, then compare into ``--out`` (exit 130 or 143 when interrupted, the runs done kept)."""
    import dataclasses

    from rotorred.cli import EXIT_DIVERGED, interrupted_status, interrupts
    from rotorred.cli.run import _settings
    from rotorred import (InputError, SceneDiverged, check_comparison, compare_models, format_comparison, load_scene,
                          scene_estimate, scene_toml)

    t0 = time.perf_counter()
    out = out_dir("--out", args.out)
    options = _options(args)
    scene = load_scene(args.scene, _settings(args.set))
    try:
        checked = check_comparison(scene, options)
    except InputError as exc:  # the options' names on the command line
        field = {"modes": "--modes", "dts": "--dt", "refine": "--refine"}.get(exc.field, exc.field)
        raise InputError(field, exc.value, exc.requirement, exc.unit, exc.source) from None
    finest = min(options.dts or (scene.solver.dt,))
    scene_estimate(dataclasses.replace(checked, solver=dataclasses.replace(checked.solver, dt=finest,
                                                                           model="full"))).check(force=args.force)
    record = provenance(args, "scene", scene_toml(scene))
    try:
        comparison = compare_models(scene, options, interrupts=interrupts())
    except SceneDiverged as exc:  # the scene's message, less its promise of a record kept: a comparison writes none
        error(f"{str(exc).split('; the record up to')[0]}; nothing is written (a comparison needs every run)")
        return EXIT_DIVERGED
    report(format_comparison(comparison))
    for f in _write(comparison, out, tuple(interrupts()), record):
        report(f"wrote {f}")
    report(f"wall time {time.perf_counter() - t0:.2f} s")
    if comparison.interrupted:
        error(f"interrupted ({comparison.interrupted}) after {len(comparison.runs)} runs; the runs done are written, "
              f"the folder marked INCOMPLETE")
        return interrupted_status(comparison.interrupted)
    return 0


def _write(comparison, out, interrupts: tuple, record) -> list:
    """Stage and commit the files into ``out``; those of an interrupted comparison with SIGINT and SIGTERM held back
    (a second signal does not cut the runs the first one kept)."""
    from rotorred import write_comparison, writers

    folder, files = writers.OutputFolder(out), []
    stopped = f"interrupted ({comparison.interrupted})" if comparison.interrupted else None
    try:
        with writers.signals_held() if stopped else contextlib.nullcontext(), folder:
            write_comparison(comparison, folder, record)
            files = folder.commit(incomplete=stopped)
    except interrupts:
        if not (stopped and folder.committed):
            raise
    return files
