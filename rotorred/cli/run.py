"""``rotorred run [SCENE] --out DIR``: run a scene and write its figures, data and summary.

With no scene it runs the built-in ``paper-rub`` (Xu et al. 2016: rub at node 18, 70/90 Hz).
Writes ``waveforms.png``, ``spectra_node<N>.png``, ``orbits.png``, ``result.npz``,
``result.mat``, ``timeseries.csv``, ``spectra.csv``, ``lines.csv`` and ``summary.txt``
(as the scene's ``[output]`` asks), and prints the summary.
"""

from __future__ import annotations

import time

from rotorred import checks

DEFAULT_SCENE = "paper-rub"


def add_parser(subparsers):
    from rotorred.scenes.schema import builtin_scenes
    p = subparsers.add_parser(
        "run", help="run a scene (default paper-rub): figures, data (NPZ, CSV, .mat) and a summary",
        description="Run a scene file or built-in scene and write the paper's figures (time waveforms, spectra, "
                    "orbits; rub against normal), the data as NPZ, CSV and MATLAB .mat, and a summary (peak "
                    "amplitudes, contact fraction, impacts, labelled spectral lines in the form of the paper's "
                    "Table 1). Scene keys: docs/scenes.md.")
    p.add_argument("scene", nargs="?", default=DEFAULT_SCENE, metavar="SCENE",
                   help=f"built-in scene ({', '.join(builtin_scenes())}) or scene TOML file (default {DEFAULT_SCENE})")
    p.add_argument("--out", default=None, help="output directory (default ./rotorred-<scene name>)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene key before validation, e.g. rub.clearance=20e-6 or solver.model=full "
                        "(repeatable)")
    p.add_argument("--no-normal", action="store_true", help="do not compute the scene without rub for comparison")
    return p


def run(args) -> int:
    from pathlib import Path

    from rotorred.scenes.outputs import write_outputs
    from rotorred.scenes.run import run_scene
    from rotorred.scenes.summary import format_summary
    from rotorred.scenes.schema import load_scene, parse_setting

    t0 = time.perf_counter()
    settings = {}
    for item in args.set:
        key, values = parse_setting(item)
        if len(values) != 1:
            checks.fail("--set", item, "takes one value in `rotorred run` (use `rotorred sweep` for several)")
        settings[key] = values[0]
    scene = load_scene(args.scene, settings)
    result = run_scene(scene, compare_normal=False if args.no_normal else None, progress=None)
    out = Path(args.out) if args.out else Path(f"rotorred-{scene.name}")
    files = write_outputs(result, out)
    print(format_summary(result, files))
    print(f"wall time {time.perf_counter() - t0:.2f} s")
    return 0
