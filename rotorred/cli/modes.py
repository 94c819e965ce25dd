"""``rotorred modes ROTOR --speed RPM --out DIR``: mode shapes at one operating point.

Writes ``modes.csv`` (one row per mode and shaft node: frequency, whirl, log dec, node, spool, z, amplitude and
phase of x and y), ``mode_shapes.png`` (each mode's deflection along every spool, orbits and whirl sense),
``modes.txt`` (what it prints, under the rotorred version, command line and date) and ``rotor.toml``.
"""

from __future__ import annotations

import argparse
import math

from rotorred import checks, writers
from rotorred.cli.campbell import check_model_size, parse_ratio, ratios_to_reference
from rotorred.cli.feedback import report
from rotorred.cli.options import out_dir, provenance, speed_line, stage_summary


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "modes", help="mode shapes at one operating point",
        description="The rotor's modes at one speed of the reference spool (other spools at a ratio): frequency, "
                    "forward/backward whirl, log dec, and each mode's motion at every shaft node. Modes are "
                    "numbered from 1 in frequency order, as `rotorred campbell --speeds` numbers them at the same "
                    "speed. Writes modes.csv and mode_shapes.png to --out and prints the modes.")
    p.add_argument("rotor", metavar="ROTOR", help="preset name (e.g. seed-rig) or rotor TOML file")
    p.add_argument("--speed", required=True, metavar="RPM", help="speed of the reference spool (rpm, >= 0)")
    p.add_argument("--ratio", action="append", default=[], metavar="SPOOL=R",
                   help="SPOOL turns at R times the reference spool (repeat for more spools); or, for two spools, "
                        "one number R: speed of the second spool / speed of the first; default: the ratios of the "
                        "nominal speeds")
    p.add_argument("--reference", default=None, metavar="SPOOL", help="the spool --speed is of (default: the first)")
    p.add_argument("--modes", type=int, default=None, metavar="N",
                   help="number of modes, the lowest (default: as `rotorred campbell`, every mode below 1.25 x the "
                        "fastest spool's speed, at least 6)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if missing)")
    p.add_argument("--force", action="store_true", help="go on with a model beyond the size limits")
    return p


def parse_speed(text: str) -> float:
    """``"3000"`` (rpm, >= 0) -> 3000.0."""
    try:
        value = float(text)
    except ValueError:
        checks.fail("--speed", text, "must be a number", "rpm")
    return checks.number("--speed", value, "rpm", ge=0.0)


def run(args) -> int:
    import matplotlib  # noqa: F401 - a missing matplotlib fails before any work

    from rotorred import mode_shapes, read_rotor, save_figure

    out = out_dir("--out", args.out)
    speed = parse_speed(args.speed)
    if args.modes is not None:
        checks.integer("--modes", args.modes, ge=1)
    ratio = parse_ratio(args.ratio)
    rotor, document = read_rotor(args.rotor)
    record = provenance(args, "rotor", writers.toml_text(document))
    check_model_size(rotor, args.force)
    operating = speed_line(rotor, [speed], args.reference, ratios_to_reference(ratio, rotor, args.reference), "rpm")
    with writers.OutputFolder(out) as folder:
        result = mode_shapes(rotor, operating, n_modes=args.modes)
        files = [result.to_csv(folder.staged("modes.csv")),
                 save_figure(result.plot(), folder.staged("mode_shapes.png"))]
        text = format_modes(result)
        files += stage_summary(folder, "modes.txt", text, record)
        folder.commit()
    report(text)
    report("wrote " + " and ".join(str(out / f.name) for f in files))
    return 0


def format_modes(result) -> str:
    """The modes as a text table: number, frequency, whirl, damping ratio, log dec, and where each mode moves most."""
    speeds = ", ".join(f"{s} at {w * 30 / math.pi:.6g} rpm" for s, w in result.speeds.items())
    lines = [f"modes of {result.rotor_name or 'rotor'} ({speeds})",
             f"{'mode':>5} {'freq Hz':>12} {'whirl':>9} {'damping ratio':>14} {'log dec':>10}  largest orbit"]
    major = result.semi_major
    for k in range(result.n_modes):
        j = int(major[k].argmax())
        rigid = ", rigid body" if k in result.rigid_modes else ""
        lines.append(f"{k + 1:5d} {result.frequencies_hz[k]:12.4f} {result.whirl[k]:>9} "
                     f"{result.damping_ratio[k]:14.6f} {result.log_dec[k]:10.5f}  node {result.nodes[j]} "
                     f"({result.node_spools[j]}){rigid}")
    return "\n".join(lines)
