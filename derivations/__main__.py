"""Regenerate (or, with ``--check``, verify) the generated modules of rotorred.

Usage::

    python -m derivations           # write every generated module
    python -m derivations --check   # exit 1 if a checked-in module differs from a fresh one
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from derivations import TARGETS

# Derivations are deterministic: within one process each module's text is computed once.
_TEXT: dict[str, str] = {}


def module_text(relative: str, text_fn) -> str:
    """Text of the generated module ``relative`` (cached per process)."""
    if relative not in _TEXT:
        _TEXT[relative] = text_fn()
    return _TEXT[relative]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m derivations", description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare instead of writing; exit 1 on drift")
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent,
                        help="project root to write into (default: this checkout)")
    args = parser.parse_args(argv)
    stale = []
    for relative, text_fn in TARGETS:
        path = args.root / relative
        text = module_text(relative, text_fn)
        if args.check:
            if not path.exists() or path.read_text() != text:
                stale.append(relative)
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            print(f"wrote {relative}")
    if stale:
        print("stale: run `python -m derivations`: " + ", ".join(stale), file=sys.stderr)
        return 1
    if args.check:
        print("generated modules are current")
    return 0


if __name__ == "__main__":
    sys.exit(main())
