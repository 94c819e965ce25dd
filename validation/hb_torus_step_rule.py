"""The continuation's step rule on the rig's torus branches (issue 40; docs/model.md §26, "Not met"): how the growth of
the arclength step after a converged correction sets the failed steps, the points and each point's cost.

The rule (:mod:`rotorred.nonlinear.continuation`): after a correction of at most ``GROW_ITERATIONS`` Newton iterations
the step grows by ``GROWTH`` (up to ds_max), after a longer one it is kept, after a failed one halved and retried.
With growth g and no other signal the step climbs to where corrections fail, and one attempt in about
``1 + ln 2 / ln g`` fails (g = 1.5: 37 %). Each variant of ``VARIANTS`` sets the two constants and traces, in one run:

- paper-rub's clearance branch at outer 91.37 Hz from 20 to 5 µm;
- its outer-speed piece from 94.5 to 97 Hz (``validation/hb_torus_branch.py``'s last piece);

on the default box (|k1| <= 32, |k2| <= 80, band 900 Hz, grid 128 x 256), torus (f_L, f_H/3), tolerance 1e-6. The
reference is the 2-22 s transient (``validation/hb_torus.py``'s) at 14 µm and at 94 Hz, each run twice (the first
also compiles and warms), the second's solve time. Attempts are counted by wrapping the continuation's
``_arclength``.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/hb_torus_step_rule.py

Prints a row per branch and variant: points, why it ended, folds (for the speed piece each with the box's order
nearest 0 Hz there, and the speed where that order is at 0 Hz: a resonance tongue of the truncated torus), the
branch's wall time, the points' median, 90th percentile and worst time (s and over the transient), the share of
points within a tenth of the transient, corrections a point, attempts and failed attempts.
"""

from __future__ import annotations

import time

import numpy as np

import rotorred.nonlinear.continuation as continuation
from hb_torus import transient
from hb_torus_branch import DIVISORS, scene_for
from rotorred.scenes.run import build_model
from rotorred.scenes.torus_branch import TorusBranchOptions, continue_torus

#: (GROWTH, GROW_ITERATIONS): the code's own first
VARIANTS = ((1.5, 4), (1.2, 3), (1.5, 2), (1.2, 2))
#: key, start, end, the transient's value, how the value is shown (scale, unit)
BRANCHES = (("rub.clearance", 20e-6, 5e-6, 14e-6, 1e6, "µm"),
            ("speeds.outer", 94.5, 97.0, 94.0, 1.0, "Hz"))
MAX_POINTS = 800  #: a branch's most points (a gentle growth through a tongue takes hundreds)
SPEEDUP = 10.0  #: the issue's: each point at least 10x cheaper than a settled transient there

COUNT = {"attempts": 0, "failed": 0}


def _counted(arclength):
    def counted(*args, **kwargs):
        out = arclength(*args, **kwargs)
        COUNT["attempts"] += 1
        COUNT["failed"] += out is None
        return out
    return counted


def tongue(branch, value: float) -> str:
    """The box's order nearest 0 Hz at the branch's point nearest ``value`` (a speed of the spool of the second
    base), and the speed where its line is at 0 Hz."""
    i = int(np.argmin(np.abs(branch.values - value)))
    f1, f2 = branch.bases_hz[i]
    k = branch.orders[1:]  # (0, 0) excluded
    f = k[:, 0] * f1 + k[:, 1] * f2
    j = int(np.argmin(np.abs(f)))
    k1, k2 = k[j]
    zero = branch.values[i] * (-k1 * f1 / (k2 * f2))
    return f"({k1}, {k2}) at 0 Hz at {zero:.4f}"


def main():
    continuation._arclength = _counted(continuation._arclength)
    kept = continuation.GROWTH, continuation.GROW_ITERATIONS
    print("| branch | growth, grow at most (iterations) | points | end | wall (s) | point median / p90 / worst (s) | "
          "over the transient | within 1/10 | corrections | attempts | failed |")
    for key, start, end, at, xs, xu in BRANCHES:
        scene = scene_for(key, start, record=False)
        model = build_model(scene).model
        checked = scene_for(key, at, record=True)
        reference = [transient(checked, build_model(checked))[0].solve_time for _ in range(2)][-1]
        print(f"{key}: the 2-22 s transient at {xs * at:g} {xu}: {reference:.3f} s", flush=True)
        for growth, grow_at_most in VARIANTS:
            continuation.GROWTH, continuation.GROW_ITERATIONS = growth, grow_at_most
            COUNT.update(attempts=0, failed=0)
            t0 = time.perf_counter()
            try:
                branch = continue_torus(scene, model, key, start, end,
                                        TorusBranchOptions(divisors=DIVISORS, max_points=MAX_POINTS))
            finally:
                continuation.GROWTH, continuation.GROW_ITERATIONS = kept
            wall = time.perf_counter() - t0
            p = branch.point_time[1:]
            q = np.array([np.median(p), np.quantile(p, 0.9), p.max()])
            print(f"| {key} | {growth:g}, {grow_at_most} | {len(branch.values)} | {branch.end} at "
                  f"{xs * branch.values[-1]:.5g} {xu} | {wall:.1f} | {' / '.join(f'{x:.3f}' for x in q)} | "
                  f"{' / '.join(f'{x / reference:.3f}' for x in q)} | {np.mean(p <= reference / SPEEDUP):.0%} | "
                  f"{branch.iterations[1:].mean():.2f} | {COUNT['attempts']} | {COUNT['failed']} |", flush=True)
            for value, smooth in branch.folds:
                where = f"; the box's order {tongue(branch, value)} {xu}" if key.startswith("speeds.") else ""
                print(f"    fold at {xs * value:.5f} {xu} ({'smooth' if smooth else 'corner'}){where}")


if __name__ == "__main__":
    main()
