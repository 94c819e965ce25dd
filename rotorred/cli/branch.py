"""``rotorred continue SCENE --param KEY=START:STOP --out DIR``: a branch of the rub response by harmonic balance.

Follows the periodic response of the scene (commensurate speeds, rub plates) by pseudo-arclength continuation in
``rub.clearance`` (m), a spool speed ``speeds.<spool>`` (Hz, the speed ratio kept) or a number of the plate (``rub.k_n``
its supports' stiffness in N/m, ``rub.K_nr``, ``rub.mu_d`` ...: ``scenes.branch.PLATE_KEYS``), through its folds, with
each point's stability (Floquet multipliers of the monodromy matrix). Writes ``branch.csv`` (a row a point: the key, the
peak of each output DOF in µm, the largest multiplier, stable or not), ``branch_lines.csv`` (the amplitude of each
harmonic of f_0 at the first output DOF), ``branch.nc`` (the same, labelled, xarray/NetCDF), ``branch.png`` (peak
against the key: stable solid, unstable dashed, folds and corners marked) and ``branch.txt``. An interrupt keeps the
points so far (written, marked INCOMPLETE; exit 130).
"""

from __future__ import annotations

import sys

from rotorred import checks
from rotorred.cli.options import out_dir, provenance


def add_parser(subparsers):
    p = subparsers.add_parser(
        "continue",
        help="follow the rub response by harmonic balance in a key (clearance, speed, plate): folds, stability",
        description="Follow a rub scene's periodic response by harmonic balance with pseudo-arclength continuation in "
                    "rub.clearance (m), speeds.<spool> (Hz, the speed ratio kept) or a plate number (rub.k_n N/m, "
                    "rub.K_nr, rub.mu_d, ...), through its folds, with each "
                    "point's stability; write the branch as CSV and NetCDF and plot it. Example: rotorred continue "
                    "paper-rub --param rub.clearance=20e-6:5e-6 --out branch")
    p.add_argument("scene", metavar="SCENE", help="built-in scene or scene TOML file (with rub plates)")
    p.add_argument("--param", required=True, metavar="KEY=START:STOP",
                   help="the key and its first and last value (scene units: m for rub.clearance, Hz for speeds, "
                        "N/m for rub.k_n ...)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="fix a scene key (repeatable)")
    p.add_argument("--harmonics", type=int, default=50, help="harmonics of the base frequency f_0 (default 50)")
    p.add_argument("--samples", type=int, default=1024, help="AFT samples a period, even (default 1024)")
    p.add_argument("--tol", type=float, default=1e-9, help="relative residual of every point (default 1e-9)")
    p.add_argument("--no-stability", action="store_true", help="skip the Floquet multipliers (the slow part)")
    p.add_argument("--out", required=True, help="output directory")
    return p


def _param(text: str) -> tuple[str, float, float]:
    """KEY, START, STOP of ``--param KEY=START:STOP``."""
    key, sep, values = text.partition("=")
    parts = values.split(":")
    if not sep or len(parts) != 2:
        checks.fail("--param", text, "must be KEY=START:STOP, e.g. rub.clearance=20e-6:5e-6, speeds.outer=90:95 or "
                    "rub.k_n=1e8:1e9")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        checks.fail("--param", text, "must have numbers START and STOP")
    if not (start > 0 and stop > 0) or start == stop:
        checks.fail("--param", text, "must have START and STOP > 0 and different")
    return key.strip(), start, stop


def run(args) -> int:
    """Check everything, then follow the branch into ``--out`` (exit 130 when interrupted, its points kept)."""
    from rotorred.cli import EXIT_SIGINT
    from rotorred.cli.run import _settings
    from rotorred.scenes.branch import check_key, continue_scene
    from rotorred.scenes.branch_outputs import format_branch, write_branch
    from rotorred.scenes.resolved import scene_toml
    from rotorred.scenes.run import build_model
    from rotorred.scenes.schema import load_scene
    from rotorred.writers import OutputFolder

    out = out_dir("--out", args.out)
    key, start, stop = _param(args.param)
    H = checks.integer("--harmonics", args.harmonics, ge=1)
    N = checks.integer("--samples", args.samples, ge=2 * H + 2)
    if N % 2:
        checks.fail("--samples", N, "must be even")
    tol = checks.positive("--tol", args.tol)
    scene = load_scene(args.scene, _settings(args.set))
    check_key(scene, key, start, stop)
    record = provenance(args, "scene", scene_toml(scene))  # with the base scene; --param in the command line
    model = build_model(scene).model
    print(f"branch of {scene.name} in {key} from {start:g} to {stop:g}: {H} harmonics, {N} samples a period")
    branch = continue_scene(scene, model, key, start, stop, H, N, tol=tol, stability=not args.no_stability,
                            progress=_progress)
    if sys.stdout.isatty():
        print()
    print(format_branch(branch))
    with OutputFolder(out) as folder:
        write_branch(branch, folder, scene.name, record)
        files = folder.commit(incomplete=branch.stopped if branch.interrupted else None)
    for f in files:
        print(f"wrote {f}")
    if branch.interrupted:
        print(f"rotorred continue: {branch.stopped}; the points so far are written", file=sys.stderr)
        return EXIT_SIGINT
    return 0


def _progress(points: int, value) -> None:
    """A line that updates in place on a terminal; every 50th point otherwise (a log)."""
    tty = sys.stdout.isatty()
    if not tty and points % 50:
        return
    text = f"  stability: {points} points" if value is None else f"  {points} points, at {value:.6g}"
    print(f"\r{text}" if tty else text, end="" if tty else "\n", flush=True)
