"""``rotorred run paper-rub --set solver.method=harmonic-balance --set speeds.outer=91.37``: the command's torus
(:mod:`rotorred.scenes.torus_response`) against the Python ``torus_balance`` on the same scene and against a settled
transient.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/torus_run.py

Prints, in one run:

1. the command (the default truncation: orders |k1| <= 16, |k2| <= 70, grid 64 x 1024) and its wall time, the
   solve time and the torus and truncation its summary names;
2. its 10 largest node 14 Y lines (read from its ``summary.txt``, 6 digits) against ``rr.torus_balance`` with the
   scene's settings (``rr.TorusOptions(dt=solver.dt)``): the largest relative difference;
3. the same lines against the line fit of a transient from the settled linear state, recorded 2-22 s (the scene's
   default 0.6 s record cannot resolve a torus's lines, validation/hb_torus.py; the mean against the record's mean),
   with its solve time.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import rotorred as rr

COMMAND = ["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "speeds.outer=91.37", "--no-html",
           "--no-normal"]
DURATION, RECORD_START = 22.0, 2.0  #: s: the transient's 20 s record (hb_torus.py's)


def printed_lines(summary: str) -> dict:
    """The summary's torus lines of node 14 Y: {(k1, k2): (frequency (Hz), amplitude (m))}."""
    block = summary.split("Torus lines of node 14 Y")[1].split("\n\n")[0]
    rows = re.findall(r"^\s*([0-9.e+-]+)\s*\|\s*\((-?\d+), (-?\d+)\)\s*\|[^|]*\|\s*([0-9.e+-]+)\s*$", block, re.M)
    return {(int(k1), int(k2)): (float(f), 1e-6 * float(a)) for f, k1, k2, a in rows}


def command() -> tuple[float, str]:
    """The command in a fresh process: its wall time (s) and summary."""
    out = Path(tempfile.mkdtemp()) / "o"
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "import sys; from rotorred.cli import entry; sys.exit(entry())", *COMMAND,
                    "--out", str(out), "-q"], check=True)
    return time.perf_counter() - t0, (out / "summary.txt").read_text(encoding="utf-8")


def main():
    wall, summary = command()
    print(f"command: rotorred {' '.join(COMMAND)}: wall time {wall:.1f} s (model, start transient, torus, line fit, "
          "files)")
    for line in summary.splitlines():
        if line.startswith(("response:", "truncation:")) or "Newton iterations" in line:
            print("  " + line)
    lines = printed_lines(summary)

    scene = rr.load_scene("paper-rub", {"speeds.outer": 91.37})
    model = rr.build_model(scene).model
    t0 = time.perf_counter()
    torus = rr.torus_balance(model, scene.operating, rr.Loads(scene.unbalances), scene.plates,
                             rr.TorusOptions(dt=scene.solver.dt, outputs=[(14, "y")]))
    python_time = time.perf_counter() - t0
    amplitude = {tuple(int(v) for v in k): a for k, a in zip(torus.orders, torus.amplitudes[:, 0])}
    worst = max(abs(a / amplitude[k] - 1) for k, (_, a) in lines.items())
    print(f"torus_balance from Python, same scene and settings: {python_time:.1f} s; the 10 printed lines differ by "
          f"at most {worst:.1e} (relative; 6 digits printed)")

    transient = rr.load_scene("paper-rub", {"speeds.outer": 91.37, "solver.duration": DURATION,
                                            "solver.record_start": RECORD_START})
    result = rr.run_scene(transient, compare_normal=False)
    fit = result.analyses[(14, "y")].fit
    print(f"transient {RECORD_START:g}-{DURATION:g} s: {result.solve_time:.1f} s to solve; torus found "
          f"{fit.torus.label}, explained {fit.explained_share:.4f}")
    print(f"{'frequency (Hz)':>15} {'order':>9} {'torus (um)':>11} {'transient (um)':>15} {'difference':>11}")
    differences = []
    for k, (f, a) in sorted(lines.items(), key=lambda item: -item[1][1]):
        if k == (0, 0):  # the mean: the line fit has no 0 Hz line; the record's mean over its 20 s
            ref = abs(np.mean(result.outputs[(14, "y")]))
        else:
            match = [ln for ln in fit.lines if abs(ln.frequency_hz - f) <= 1e-3 * f]
            ref = match[0].amplitude if match else np.nan
        differences.append(a / ref - 1)
        print(f"{f:15.6g} {str(k):>9} {1e6 * a:11.5g} {1e6 * ref:15.5g} {a / ref - 1:+11.2%}")
    print(f"worst of the 10 largest lines against the transient: {np.nanmax(np.abs(differences)):.2%}")


if __name__ == "__main__":
    main()
