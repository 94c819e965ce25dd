"""Command line: ``rotorred <command> ...``.

Each command lives in its own module ``rotorred/cli/<command>.py`` exposing
``add_parser(subparsers)`` (registering the sub-parser) and ``run(args) -> int``.
"""

from __future__ import annotations

import argparse
import importlib
import sys

#: command modules, in the order ``rotorred --help`` lists them
COMMANDS = [
    "campbell",
    "harmonic",
    "run",
    "sweep",
]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rotorred",
        description="Rotordynamics of dual-rotor machines with rub-impact faults.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        module = importlib.import_module(f"rotorred.cli.{name}")
        p = module.add_parser(sub)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    try:
        return int(args._run(args) or 0)
    except (ValueError, FileNotFoundError) as exc:
        print(f"rotorred {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
