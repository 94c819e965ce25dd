"""``rotorred convert ROSS_FILE OUT``: a rotor saved by ROSS 3 written as a rotorred rotor file."""

from __future__ import annotations

import argparse
from pathlib import Path

from rotorred import checks, writers
from rotorred.cli.feedback import report


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "convert", help="write a rotor saved by ROSS as a rotorred rotor file",
        description="Read a rotor saved by ROSS 3 (Rotor.save, TOML), check it as rotorred reads it, and write the "
                    "equivalent rotorred rotor file (README, 'Rotor files'): the same nodes, elements, disks and "
                    "bearings, the tables against speed in rpm. rotorred reads the ROSS file directly too "
                    "(rotorred campbell my_ross_rotor.toml ...); the rotorred file is for going on in its format.")
    p.add_argument("source", metavar="ROSS_FILE", help="rotor TOML file saved by ROSS 3 (ross.Rotor.save)")
    p.add_argument("target", metavar="OUT", help="rotorred rotor file to write (.toml)")
    return p


def run(args) -> int:
    from rotorred import BearingTable, convert_ross

    source, target = Path(args.source), _target(args.target, args.source)
    if not source.is_file():
        checks.fail("ROSS_FILE", args.source, "must be an existing file (a rotor saved by ROSS 3)")
    try:
        rotor = convert_ross(source, target)
    except checks.InputError as exc:
        if exc.field != "source":
            raise
        checks.fail("ROSS_FILE", args.source, exc.requirement)
    spool = rotor.spools[0]
    tables = [b.axis for b in rotor.bearings if isinstance(b, BearingTable)]
    against = f"{tables.count('speed')} tabulated against speed" + (
        f", {tables.count('frequency')} against whirl frequency" if "frequency" in tables else "")
    report(f"read {source}: {len(spool.elements)} shaft elements, nodes {spool.nodes[0]}-{spool.nodes[-1]}"
           + (f", {len(spool.sleeves)} sleeves (ROSS layered elements)" if spool.sleeves else "")
           + f", {len(rotor.disks)} disks, {len(rotor.bearings)} bearings and seals ({against})"
           + (f", {len(rotor.pedestals)} pedestals" if rotor.pedestals else ""))
    report(f"wrote {target}")
    return 0


def _target(text: str, source: str) -> Path:
    """The output file ``text``: not empty, not a folder, not the source."""
    if not str(text).strip():
        checks.fail("OUT", text, "must be a file path, not empty")
    path = Path(text).expanduser()
    if path.is_dir():
        checks.fail("OUT", text, "must be a file path; this is a folder")
    kind = writers.non_regular(path)
    if kind is not None:  # replaced by a regular file, a FIFO, a device or a link's target would be lost
        checks.fail("OUT", text, f"must be a new path or a regular file; this is {kind}, which rotorred does not "
                                 "replace")
    if path.exists() and path.resolve() == Path(source).expanduser().resolve():
        checks.fail("OUT", text, "must differ from ROSS_FILE: the ROSS file is kept")
    if not path.parent.exists():
        checks.fail("OUT", text, f"must be in an existing folder; {str(path.parent)!r} does not exist")
    return path

