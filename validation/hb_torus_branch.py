"""Torus continuation on the rig (issue 40, build 4): paper-rub's quasi-periodic response followed in the clearance
from 20 to 5 µm at outer 91.37 Hz, and in the outer speed from 91 to 97 Hz at the scene's clearance (inner 70 Hz held),
against settled transients at three points of each branch, in one run.

Each branch is :func:`rotorred.scenes.torus_branch.continue_torus` (the start by a short transient and the line fit's
torus (f_L, f_H/3); pseudo-arclength with matrix-free bordered Newton-Krylov corrections, docs/model.md §26), traced
twice (``TOLERANCES``): on the orders ``ORDERS`` throughout (band 1500 Hz, default grid), and with the box chosen along
the branch by the lines' tolerance of 1 % (``TorusBranchOptions.lines_tol``: from ``ORDERS`` up the ladder where the 10
largest lines change by more against the next box). At three points of each branch (``CHECKS``: the branch's points
nearest to them), the scene there runs a settled transient 2-22 s (``validation/hb_torus.py``'s ``transient``: node 14 Y
line fit, its 10 largest lines), whose solve time is the point's reference. A point's time is all the work between two
accepted points: the corrections, rejected steps, a fold's location, a box's check and the new box's start.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/hb_torus_branch.py [--orders H1,H2] [--branch rub.clearance]

Prints, per branch: a row a point (the key, the bases, the corrections, the point's wall time and the transients'
median time over it: the speed-up), the folds (or, where none, the evidence: the tangent's parameter component keeps
its sign over every point), and at the three points the 10 largest transient lines against the torus's at the same
frequencies (relative differences, the worst); then one table of the issue's measures. The machine may be loaded by
other work: the ratios are of times measured in the same run.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from hb_torus import DURATION, RECORD_START, transient
from rotorred.scenes.run import build_model
from rotorred.scenes.schema import load_scene
from rotorred.scenes.torus_branch import TorusBranchOptions, continue_torus

OUTER_HZ = 91.37  #: Hz, the clearance branch's outer speed (inner 70 Hz)
ORDERS = (8, 40)  #: the box of orders |k1| <= 8, |k2| <= 40 (band 1500 Hz); ``--orders H1,H2`` another
DIVISORS = (1, 3)  #: the torus (f_L, f_H / 3) (at 91 Hz the speeds are 13:10, where the line fit sees no torus)
TOL = 1e-6  #: the relative residual of every point
#: the branches: key, start, end, the values checked against a transient (the branch's points nearest to them), and
#: how each is shown (scale, unit)
BRANCHES = (("rub.clearance", 20e-6, 5e-6, (19e-6, 14e-6, 6e-6), 1e6, "µm"),
            ("speeds.outer", 91.0, 97.0, (91.5, 94.0, 96.5), 1.0, "Hz"))
SPEEDUP = 10.0  #: the issue's: each point at least 10x cheaper than a settled transient there
LINES = 0.01  #: the issue's: the lines within 1 % of the transient's
#: each branch is traced twice: on the box ``ORDERS`` throughout, and with the box chosen along the branch by the
#: lines' tolerance ``LINES`` (TorusBranchOptions.lines_tol, from ``ORDERS`` up the ladder)
TOLERANCES = (None, LINES)


def scene_for(key: str, value: float, record: bool):
    """paper-rub at outer 91.37 Hz with ``key`` at ``value``; ``record``: the transient's settings of
    ``validation/hb_torus.py`` (22 s, recorded from 2 s, node 14 Y the table)."""
    settings = {"speeds.outer": OUTER_HZ, key: value}
    if record:
        settings.update({"solver.duration": DURATION, "solver.record_start": RECORD_START, "output.nodes": [14, 18],
                         "output.directions": ["x", "y"], "output.table": "14:y", "output.plots": [],
                         "output.formats": [], "output.compare_normal": False,
                         "output.plot_window": [RECORD_START, DURATION]})
    return load_scene("paper-rub", settings)


def against_transient(branch, i: int, key: str):
    """The transient at point ``i``'s value: its solve time, and the 10 largest lines at node 14 Y against the
    torus's at the same frequencies (relative differences)."""
    scene = scene_for(key, float(branch.values[i]), record=True)
    result, _, largest, _ = transient(scene, build_model(scene))
    f, a = branch.frequencies[i], branch.amplitudes[i]
    relative = []
    for line in largest:
        k = np.argmin(np.abs(f - line.frequency_hz))
        assert abs(f[k] - line.frequency_hz) < 1e-6 * line.frequency_hz, (f[k], line.frequency_hz)
        relative.append(a[k] / line.amplitude - 1.0)
    return result.solve_time, np.array([ln.frequency_hz for ln in largest]), np.array(relative)


def follow(key, start, end, checked, xs, xu, lines_tol):
    """One branch, its three transients and its rows; returns (points, worst point time over the transients' median,
    folds, worst line)."""
    scene = scene_for(key, start, record=False)
    sm = build_model(scene)
    t0 = time.perf_counter()
    branch = continue_torus(scene, sm.model, key, start, end, TorusBranchOptions(orders=ORDERS, divisors=DIVISORS,
                                                                               tol=TOL, lines_tol=lines_tol))
    wall = time.perf_counter() - t0
    print("\n".join(branch.summary()))
    at = sorted({int(np.argmin(np.abs(branch.values - v))) for v in checked})
    checks = {i: against_transient(branch, i, key) for i in at}
    reference = float(np.median([c[0] for c in checks.values()]))
    print(f"  transients at {', '.join(f'{xs * branch.values[i]:.4g}' for i in at)} {xu}: "
          f"{', '.join(f'{checks[i][0]:.2f}' for i in at)} s (median {reference:.2f} s, the reference of every point)")
    print(f"  | {key} ({xu}) | f_1, f_2 (Hz) | corrections | point (s) | transient / point |")
    for i, v in enumerate(branch.values):
        t = branch.point_time[i]
        print(f"  | {xs * v:10.5g} | {branch.bases_hz[i, 0]:.5g}, {branch.bases_hz[i, 1]:.5g} | "
              f"{branch.iterations[i]:11d} | {t:9.3f} | {reference / t:17.1f} |" + (" (the start)" if i == 0 else ""))
    steps = branch.point_time[1:]
    if branch.folds:
        print("  folds: " + ", ".join(f"{xs * v:.6g} {xu} ({'smooth' if s else 'corner'})" for v, s in branch.folds))
    else:
        signs = np.sign(branch.slope)
        print(f"  no fold: the tangent's {key} component keeps its sign ({'+' if signs[0] > 0 else '-'}) at all "
              f"{len(signs)} points (smallest |d value / ds| {np.min(np.abs(branch.slope)):.3g})"
              if np.all(signs == signs[0]) else "  the tangent's sign changed without a fold located")
    worst = 0.0
    for i in at:
        _, f, d = checks[i]
        worst = max(worst, float(np.max(np.abs(d))))
        print(f"  lines at {xs * branch.values[i]:.5g} {xu} against the transient: worst {np.max(np.abs(d)):.2%}: "
              + " ".join(f"{fi:.0f}:{di:+.2%}" for fi, di in zip(f, d)))
    print(f"  branch wall time {wall:.1f} s (the start {branch.point_time[0]:.2f} s, {len(steps)} points "
          f"{steps.sum():.1f} s)")
    print(f"  a point's time: all the work between two accepted points (rejected steps, a fold's location, a box's "
          f"check); over a transient's: median {np.median(steps) / reference:.3f}, worst {np.max(steps) / reference:.3f}"
          f" (points within 1/{SPEEDUP:g} of a transient: {np.mean(steps <= reference / SPEEDUP):.0%})")
    return len(branch.values), float(np.max(steps)) / reference, float(np.median(steps)) / reference, \
        len(branch.folds), worst, reference


def main():
    global ORDERS
    if "--orders" in sys.argv:
        ORDERS = tuple(int(v) for v in sys.argv[sys.argv.index("--orders") + 1].split(","))
    keys = sys.argv[sys.argv.index("--branch") + 1].split(",") if "--branch" in sys.argv else [b[0] for b in BRANCHES]
    rows = []
    for key, start, end, checked, xs, xu in (b for b in BRANCHES if b[0] in keys):
        for lines_tol in TOLERANCES:
            box = (f"orders |k1| <= {ORDERS[0]}, |k2| <= {ORDERS[1]}" if lines_tol is None else
                   f"orders from |k1| <= {ORDERS[0]}, |k2| <= {ORDERS[1]} by the lines' tolerance {lines_tol:g}")
            print(f"branch in {key} from {xs * start:g} to {xs * end:g} {xu}, {box}, tol {TOL:g}:")
            rows.append((key, "fixed" if lines_tol is None else f"lines {lines_tol:g}",
                         *follow(key, start, end, checked, xs, xu, lines_tol)))
    print("result (the issue asks each point at least 10x cheaper than a settled transient, lines within 1 %):")
    print("  | branch | box | points | transient (s) | point / transient, median | worst | folds | worst line |")
    for key, how, p, worst_ratio, median_ratio, folds, line, reference in rows:
        print(f"  | {key:13s} | {how:10s} | {p:6d} | {reference:13.2f} | {median_ratio:25.3f} | {worst_ratio:5.3f} | "
              f"{folds:5d} | {line:10.2%} |")


if __name__ == "__main__":
    main()
