"""Any speed ratio: the rub scene with the inner spool at 70 Hz and the outer swept from 80 to 100 Hz.

Issue 19, item 6. Each operating point of ``paper-rub`` (rub at node 18; node 14 Y read) is run
from the scene's start (the linear settled state, then the rub) until it has settled or up to a
stated limit: first to ``DURATIONS[0]`` = 4 s; when :func:`rotorred.signals.settling.settling_time`
finds the response not settled there, again to ``LIMIT`` = 8 s (a fresh run: the transient
driver starts a scene from its start state, and 4 s of simulation cost about 1.2 s). The
response from the settling time on (from the middle of the record when it has not settled) is
fitted by :func:`rotorred.signals.linefit.fit_lines`, the torus found by the tool, and
classified by :func:`rotorred.signals.classify.classify`.

For each speed it prints the share of the energy the labelled lines explain, the torus, the
class, the settling time ("-" when not settled by the limit), the number of lines and the
largest unlabelled line (the residual's strongest peak), then the total time. ``--plot PATH``
draws the explained share and the class against speed; ``--quick`` runs a few speeds.

Run: ``python validation/any_ratio.py [--quick] [--plot any_ratio.png]``. Runs are serial; set
``OPENBLAS_NUM_THREADS=1`` on a shared machine.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass

import numpy as np

from rotorred.scenes.run import build_model, run_scene
from rotorred.scenes.schema import load_scene
from rotorred.signals.classify import Classification, classify
from rotorred.signals.settling import settling_time

F_INNER = 70.0  #: inner spool (Hz), as paper-rub
SPEEDS = tuple(float(f) for f in np.round(np.arange(80.0, 100.0 + 1e-9, 0.5), 1))  #: outer spool (Hz), 41 points
QUICK = (88.0, 90.0)  #: --quick: a period-3 lock (f_H/3) and the paper's periodic point
DURATIONS = (4.0, 8.0)  #: s: run to 4 s, and when not settled there, to the stated limit
LIMIT = DURATIONS[-1]
CHANNEL = (14, "y")  #: the paper's outer-rotor Y response
KIND_ORDER = ("periodic", "period-k", "quasi-periodic", "unexplained", "chaotic", "unsettled")


@dataclass(frozen=True)
class Point:
    """One operating point: outer speed (Hz), run length (s) and its classification."""

    f_outer: float
    duration: float
    classification: Classification
    sim_time: float
    analysis_time: float

    @property
    def settling_text(self) -> str:
        s = self.classification.settling
        return f"{s.time:.2f}" if s.settled else f"> {self.duration:g}"

    @property
    def largest_unlabelled(self) -> str:
        peaks = self.classification.fit.unlabelled
        if not peaks:
            return "-"
        p = peaks[0]
        return f"{p.frequency_hz:.2f} Hz {1e6 * p.amplitude:.3f} um"


def _scene(f_outer: float, duration: float):
    return load_scene("paper-rub", {
        "speeds.outer": f_outer, "solver.duration": duration, "solver.record_start": 0.0,
        "output.nodes": [CHANNEL[0]], "output.directions": [CHANNEL[1]], "output.table": f"{CHANNEL[0]}:{CHANNEL[1]}",
        "output.plots": [], "output.formats": [], "output.compare_normal": False, "output.plot_window": [0.0, duration],
    })


def run_point(f_outer: float, model=None, durations=DURATIONS) -> Point:
    """Run one outer speed until settled or to the last of ``durations`` (s), and classify it."""
    sim = analysis = 0.0
    for duration in durations:
        scene = _scene(f_outer, duration)
        t0 = time.perf_counter()
        res = run_scene(scene, model if model is not None else build_model(scene))
        t1 = time.perf_counter()
        t, x = res.t, res.outputs[CHANNEL]
        settling = settling_time(t, x, F_INNER, f_outer)
        analysis += time.perf_counter() - t1
        sim += t1 - t0
        if settling.settled:
            break
    t1 = time.perf_counter()
    c = classify(t, x, F_INNER, f_outer, settling=settling)
    return Point(f_outer, duration, c, sim, analysis + time.perf_counter() - t1)


def sweep(speeds=SPEEDS, durations=DURATIONS, out=sys.stdout) -> list[Point]:
    """Every speed in turn (serial), one model for all (the speeds do not change the matrices)."""
    model = build_model(_scene(speeds[0], durations[0]))
    header = (f"{'f_H (Hz)':>8}  {'explained':>9}  {'torus':<32} {'class':<15} {'settled (s)':>11}  "
              f"{'lines':>5}  largest unlabelled")
    print(header, file=out, flush=True)
    points = []
    for f in speeds:
        p = run_point(f, model, durations)
        c = p.classification
        print(f"{f:8.1f}  {c.explained_share:9.4f}  {c.torus.label:<32} {c.label:<15} {p.settling_text:>11}  "
              f"{len(c.fit.lines):5d}  {p.largest_unlabelled}", file=out, flush=True)
        points.append(p)
    return points


def plot(points: list[Point], path: str) -> None:
    """Explained share and class against the outer speed, written to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f = [p.f_outer for p in points]
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    ax1.plot(f, [100 * p.classification.explained_share for p in points], "o-")
    ax1.axhline(90.0, color="0.5", ls="--", lw=0.8)
    ax1.set_ylabel("explained share (%)")
    ax1.set_title(f"paper-rub, inner {F_INNER:g} Hz, node {CHANNEL[0]} {CHANNEL[1].upper()}")
    kinds = [p.classification.kind for p in points]
    ax2.plot(f, [KIND_ORDER.index(k) for k in kinds], "s")
    for p in points:
        if p.classification.kind == "period-k":
            ax2.annotate(str(p.classification.subharmonic), (p.f_outer, KIND_ORDER.index("period-k")),
                         textcoords="offset points", xytext=(0, 6), ha="center", fontsize=7)
    ax2.set_yticks(range(len(KIND_ORDER)), KIND_ORDER)
    ax2.set_xlabel("outer spool f_H (Hz)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> list[Point]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help=f"only {', '.join(map(str, QUICK))} Hz")
    parser.add_argument("--plot", metavar="PATH", help="draw explained share and class against speed")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    speeds = QUICK if args.quick else SPEEDS
    print(f"paper-rub, inner {F_INNER:g} Hz, outer {speeds[0]:g}-{speeds[-1]:g} Hz ({len(speeds)} points); "
          f"each run to {DURATIONS[0]:g} s, and to {LIMIT:g} s when not settled there")
    points = sweep(speeds)
    if args.plot:
        plot(points, args.plot)
        print(f"plot: {args.plot}")
    print(f"total time {time.perf_counter() - t0:.1f} s (simulation {sum(p.sim_time for p in points):.1f} s, "
          f"analysis {sum(p.analysis_time for p in points):.1f} s)")
    return points


if __name__ == "__main__":
    main()
