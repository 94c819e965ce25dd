"""``rotorred sweep SCENE --set rub.clearance=v1,v2,... --out DIR``: run a scene over values of one key.

Plots the amplitudes of f_L, f_H and the strongest combination lines, and the contact
fraction, against the swept value (``sweep.png``), and writes ``sweep.csv`` and ``sweep.txt``.
"""

from __future__ import annotations

import sys
import time

from rotorred import checks
from rotorred.cli.options import out_dir
from rotorred.writers import OutputFolder
from rotorred.model.dofs import parse_dof


def add_parser(subparsers):
    p = subparsers.add_parser(
        "sweep", help="run a scene over several values of one key (e.g. the rub clearance)",
        description="Run a scene once per value of one key and plot the spectral line amplitudes (f_L, f_H, the "
                    "strongest combinations m f_H + n f_L) and the contact fraction against it. Example: "
                    "rotorred sweep paper-rub --set rub.clearance=0:80e-6:9 --out clearance")
    p.add_argument("scene", metavar="SCENE", help="built-in scene or scene TOML file")
    p.add_argument("--set", action="append", required=True, metavar="KEY=VALUES",
                   help="KEY=v1,v2,... or KEY=START:STOP:N sweeps KEY (exactly one such --set); KEY=VALUE fixes a "
                        "key (repeatable). Values in the scene's units (SI: clearance in m)")
    p.add_argument("--dof", default=None, help="DOF whose lines are collected, NODE:DIR (default the scene's "
                                               "output.table)")
    p.add_argument("--out", required=True, help="output directory (locked while the sweep runs; its files are "
                                                "replaced as a whole when the sweep ends)")
    p.add_argument("--force", action="store_true",
                   help="go on with runs beyond the size limits (steps, memory, model size; see the message)")
    return p


def run(args) -> int:
    """Check everything, then sweep into a locked, staged ``--out`` (exit 3 when a value's run failed)."""
    from rotorred.cli import EXIT_DIVERGED
    from rotorred.scenes.sweep import format_sweep, sweep, write_sweep

    t0 = time.perf_counter()
    out = out_dir("--out", args.out)
    key, values, fixed = _swept(args.set)
    dof = _check(args, key, values, fixed)
    print(f"sweep of {key} over {len(values)} values")
    with OutputFolder(out) as folder:
        result = sweep(args.scene, key, values, settings=fixed, dof=dof, progress=True)
        files = [out / f.name for f in write_sweep(result, folder.staging)]
        folder.commit()
    print(format_sweep(result))
    for f in files:
        print(f"wrote {f}")
    print(f"wall time {time.perf_counter() - t0:.2f} s")
    if result.failures:
        print(f"rotorred sweep: error: {len(result.failures)} of {len(values)} values failed (named in "
              f"{out / 'sweep.csv'} and sweep.txt); the other values are kept", file=sys.stderr)
        return EXIT_DIVERGED
    return 0


def _swept(items: list[str]) -> tuple[str, list, dict]:
    """(swept key, its values, the fixed settings) of the ``--set`` options."""
    from rotorred.scenes.schema import parse_setting

    swept, fixed = None, {}
    for item in items:
        key, values = parse_setting(item)
        if len(values) > 1:
            if swept is not None:
                checks.fail("--set", item, f"must sweep one key only; {swept[0]!r} already has several values")
            swept = (key, values)
        else:
            fixed[key] = values[0]
    if swept is None:
        if len(fixed) != 1:
            checks.fail("--set", items, "must give one key with several values, e.g. rub.clearance=10e-6,20e-6")
        key, value = next(iter(fixed.items()))
        return key, [value], {}
    return swept[0], swept[1], fixed


def _check(args, key: str, values: list, fixed: dict):
    """Every scene of the sweep, ``--dof`` and the size estimates, before anything is computed."""
    from rotorred.scenes import budget
    from rotorred.scenes.schema import load_scene
    from rotorred.scenes.sweep import check_dof

    scenes = [load_scene(args.scene, {**fixed, key: v}) for v in values]
    dof = parse_dof("--dof", args.dof, scenes[0].rotor.spool_of) if args.dof else None
    if dof is not None:
        check_dof(scenes[0], dof, text=args.dof)
    estimates = [budget.check(budget.scene_estimate(sc), force=args.force) for sc in scenes]
    total = sum(e.steps for e in estimates)
    if total > budget.MAX_STEPS and not args.force:
        checks.fail("--set", f"{key}=<{len(values)} values>", f"gives {total:.3g} steps in all, more than "
                                                               f"{budget.MAX_STEPS:.3g}; use --force to go on")
    return dof
