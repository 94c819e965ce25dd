"""How soon ``rotorred run`` says what it is doing: the seconds from the command's start to its first line on stderr,
and to its end, over warm runs (the kernel in numba's cache), as a table.

    python validation/first_line.py [--repeats 5] [SCENE]

The first run is a warm-up (it may compile the kernel) and is not counted.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def timed_run(scene: str, out: Path) -> tuple[float, float, str]:
    """(seconds to the first stderr line, seconds to the end, the first line) of one ``rotorred run``."""
    cmd = [sys.executable, "-c", "import sys; from rotorred.cli import entry; sys.exit(entry())", "run", scene,
           "--out", str(out)]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    first = proc.stderr.readline()
    t_first = time.perf_counter() - t0
    proc.stderr.read()
    if proc.wait() != 0:
        raise SystemExit(f"rotorred run {scene} failed (exit {proc.returncode})")
    return t_first, time.perf_counter() - t0, first.strip()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="paper-rub")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        timed_run(args.scene, Path(tmp) / "warm-up")
        runs = [timed_run(args.scene, Path(tmp) / f"o{k}") for k in range(args.repeats)]
    firsts, totals = [r[0] for r in runs], [r[1] for r in runs]
    print(f"rotorred run {args.scene}, warm, {args.repeats} runs; first line: {runs[0][2]!r}")
    print("| | median (s) | min (s) | max (s) |\n|---|---|---|---|")
    for name, values in (("first line on stderr", firsts), ("whole run", totals)):
        print(f"| {name} | {statistics.median(values):.2f} | {min(values):.2f} | {max(values):.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
