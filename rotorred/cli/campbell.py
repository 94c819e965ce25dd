"""``rotorred campbell ROTOR --speeds START:STOP:COUNT --out DIR``: Campbell diagram and critical speeds."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np


def parse_speeds(text: str) -> np.ndarray:
    """``"0:12000:61"`` (rpm, count >= 2 points, 0 <= start < stop) -> speeds (rad/s), shape (count,)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise ValueError(f"--speeds must be START:STOP:COUNT in rpm (e.g. 0:12000:61), got {text!r}")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        raise ValueError(f"--speeds START and STOP must be numbers (rpm), got {text!r}") from None
    try:
        count = int(parts[2])
    except ValueError:
        raise ValueError(f"--speeds COUNT must be an integer >= 2, got {parts[2]!r} in {text!r}") from None
    if not (math.isfinite(start) and math.isfinite(stop)) or start < 0:
        raise ValueError(f"--speeds START must be a finite speed >= 0 rpm, got {text!r}")
    if not stop > start:
        raise ValueError(f"--speeds STOP must be greater than START, got {text!r}")
    if count < 2:
        raise ValueError(f"--speeds COUNT must be an integer >= 2, got {count} in {text!r}")
    return np.linspace(start, stop, count) * math.pi / 30.0


def parse_harmonics(text: str) -> tuple[float, ...]:
    """``"1,2"`` -> (1.0, 2.0); each > 0."""
    try:
        h = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise ValueError(f"--harmonics must be a comma-separated list of positive numbers (e.g. 1,2), "
                         f"got {text!r}") from None
    if not all(math.isfinite(v) and v > 0 for v in h):
        raise ValueError(f"--harmonics must be positive numbers, got {text!r}")
    return h


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "campbell", help="Campbell diagram and critical speeds",
        description="Whirl frequencies against the speed of a reference spool (other spools at a fixed speed "
                    "ratio), forward/backward whirl, modes tracked by MAC, and the critical speeds where a "
                    "whirl curve crosses an excitation line h x (spool speed). Writes campbell.csv and "
                    "campbell.png to --out and prints the critical speeds.")
    p.add_argument("rotor", metavar="ROTOR", help="preset name (e.g. seed-rig) or rotor TOML file")
    p.add_argument("--speeds", required=True, metavar="START:STOP:COUNT",
                   help="reference-spool speeds in rpm, e.g. 0:12000:61")
    p.add_argument("--ratio", type=float, default=None,
                   help="two spools: speed of the second spool / speed of the first (Omega_H/Omega_L for "
                        "the seed rig); default: ratio of the nominal speeds")
    p.add_argument("--reference", default=None, metavar="SPOOL", help="spool on the x-axis (default: the first)")
    p.add_argument("--modes", type=int, default=6, metavar="N", help="number of tracked modes (default 6)")
    p.add_argument("--harmonics", default="1", metavar="H1,H2",
                   help="multiples of each spool's speed used as excitation lines (default 1)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if missing)")
    return p


def run(args) -> int:
    from rotorred.linear.campbell import campbell
    from rotorred.model.rotor_file import load_rotor

    speeds = parse_speeds(args.speeds)
    harmonics = parse_harmonics(args.harmonics)
    rotor = load_rotor(args.rotor)
    result = campbell(rotor, speeds, ratio=args.ratio, reference=args.reference, n_modes=args.modes,
                      harmonics=harmonics)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    csv_path = result.to_csv(out / "campbell.csv")
    ref_nominal = rotor.speeds[result.reference]
    png_path = result.plot(out / "campbell.png", operating_speed=ref_nominal if ref_nominal > 0 else None)
    print(format_critical_speeds(result))
    print(f"wrote {csv_path} and {png_path}")
    return 0


def format_critical_speeds(result) -> str:
    """The critical speeds as a text table."""
    ratios = ", ".join(f"{s}: {r:.4g}" for s, r in result.speed_ratios.items())
    lines = [f"critical speeds of {result.rotor_name or 'rotor'} (speed ratios to {result.reference}: {ratios})",
             f"{result.reference + ' rpm':>14} {'line':>12} {'mode':>5} {'freq Hz':>10} {'whirl':>9} {'log dec':>9}"]
    if not result.critical_speeds:
        lines.append("  (none in the speed range)")
    for c in result.critical_speeds:
        lines.append(f"{c.speed_rpm:14.1f} {c.line:>12} {c.mode:5d} {c.frequency_hz:10.2f} {c.whirl:>9} "
                     f"{c.log_dec:9.4f}")
    return "\n".join(lines)
