"""``rotorred sweep SCENE --set rub.clearance=v1,v2,... --out DIR``: run a scene over values of one key.

Plots the amplitudes of f_L, f_H and the strongest combination lines, and the contact
fraction, against the swept value (``sweep.png``), and writes ``sweep.csv`` and ``sweep.txt``.
"""

from __future__ import annotations

import time

from rotorred import checks
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
    p.add_argument("--out", required=True, help="output directory")
    return p


def run(args) -> int:
    from rotorred.scenes.schema import parse_setting
    from rotorred.scenes.sweep import format_sweep, sweep, write_sweep

    t0 = time.perf_counter()
    swept, fixed = None, {}
    for item in args.set:
        key, values = parse_setting(item)
        if len(values) > 1:
            if swept is not None:
                checks.fail("--set", item, f"sweeps one key; {swept[0]!r} already has several values")
            swept = (key, values)
        else:
            fixed[key] = values[0]
    if swept is None:
        if len(fixed) == 1:
            swept = next(iter(fixed.items()))
            swept = (swept[0], [swept[1]])
            fixed = {}
        else:
            checks.fail("--set", args.set, "must give one key with several values, e.g. rub.clearance=10e-6,20e-6")
    dof = parse_dof("--dof", args.dof) if args.dof else None
    key, values = swept
    print(f"sweep of {key} over {len(values)} values")
    result = sweep(args.scene, key, values, settings=fixed, dof=dof, progress=True)
    files = write_sweep(result, args.out)
    print(format_sweep(result))
    for f in files:
        print(f"wrote {f}")
    print(f"wall time {time.perf_counter() - t0:.2f} s")
    return 0
