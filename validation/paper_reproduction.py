"""Reproduce Xu et al. (2016), Sec. 3.1: normal and rub-impact response of the dual rotor at 70/90 Hz.

Runs the built-in scenes ``paper-normal`` and ``paper-rub`` and checks the paper's signatures:

1. normal state: the node 13 and 14 spectra hold only f_L and f_H above 1 % of the largest line;
2. rub: the node 14 Y spectrum holds the components of the paper's Table 1 above 0.5 % of
   the largest line, each labelled as the paper labels it (printed as a comparison table);
3. rub: the outer orbit contracts on the plate side (its reach towards the plate at the rub
   node 18 is below the normal orbit's);
4. rub: the inner rotor's response at node 13 changes less than the outer rotor's at node 14;
5. the settled response is periodic with the common period 0.1 s (two consecutive periods
   agree), so the spectrum is a line spectrum on the 10 Hz grid;
6. independent references for the rub run: the same scene with half the time step, and with
   the full FE model instead of the reduced one, give the same Table 1 lines.

Run ``python validation/paper_reproduction.py [--plot DIR]``. The numbers are exposed as
module-level functions (:func:`reproduce`, :func:`table1_matches`, ...) for the tests.
"""

from __future__ import annotations

import argparse
import functools
import math
import sys
import time

import numpy as np

from rotorred.scenes.outputs import write_outputs
from rotorred.scenes.run import run_scene
from rotorred.scenes.schema import load_scene
from rotorred.signals.linefit import fit_peaks
from rotorred.signals.lines import XU2016_TABLE1, compare_with_expected, format_comparison, parse_label

#: threshold of the normal-state check (fraction of the largest line), from the issue
NORMAL_THRESHOLD = 0.01
#: threshold of the Table 1 check (fraction of the largest line), from the issue
TABLE1_THRESHOLD = 0.005
#: the paper's Table 1 frequencies were read from a response at 69.58/90.33 Hz with 0.49 Hz
#: bins, so they lie up to 0.8 Hz from the 70/90 Hz grid; 1 Hz pairs them with ours
#: (rotorred.signals.lines.compare_with_expected)
PAIR_TOL_HZ = 1.0


@functools.lru_cache(maxsize=None)
def reproduce(settings: tuple = ()):
    """(normal, rub) SceneResults of the built-in scenes; ``settings`` are (key, value) overrides of the rub scene."""
    normal = run_scene(load_scene("paper-normal"))
    rub = run_scene(load_scene("paper-rub", dict(settings)))
    return normal, rub


def peak_lines(result, dof: tuple, threshold: float):
    """The lines at the peaks of ``result``'s spectrum at ``dof`` above ``threshold`` of the largest (a LineFit)."""
    return fit_peaks(result.t, result.outputs[dof], result.f_L, result.f_H, spectrum=result.spectra[dof],
                     threshold=threshold)


def normal_lines(node: int, direction: str):
    """Lines of the normal-state spectrum at (node, direction) above 1 % of the largest (tuple of FittedLine)."""
    normal, _ = reproduce()
    return peak_lines(normal, (node, direction), NORMAL_THRESHOLD).lines


def table1_matches(settings: tuple = ()):
    """The paper's Table 1 paired with our node 14 Y lines above 0.5 % (list of LineMatch)."""
    _, rub = reproduce(settings)
    lines = peak_lines(rub, (14, "y"), TABLE1_THRESHOLD).lines
    return compare_with_expected(lines, XU2016_TABLE1, tol_hz=PAIR_TOL_HZ)


def n_table1_found(settings: tuple = ()) -> int:
    """How many of the 24 Table 1 components we find with the paper's label."""
    return sum(1 for m in table1_matches(settings) if m.label_agrees)


def plate_side_reach(node: int) -> tuple[float, float]:
    """Largest displacement towards the plate, n . (x, y) (m), at ``node``: (rub, normal)."""
    normal, rub = reproduce()
    n = rub.scene.plates[0].normal

    def reach(r):
        return float(np.max(n[0] * r.outputs[(node, "x")] + n[1] * r.outputs[(node, "y")]))
    return reach(rub), reach(normal)


def relative_change(node: int) -> float:
    """RMS over x and y of (rub - normal) divided by the RMS of normal, at ``node``."""
    normal, rub = reproduce()
    num = sum(np.sum((rub.outputs[(node, d)] - normal.outputs[(node, d)]) ** 2) for d in ("x", "y"))
    den = sum(np.sum(normal.outputs[(node, d)] ** 2) for d in ("x", "y"))
    return float(math.sqrt(num / den))


def period_mismatch(node: int = 18, direction: str = "y") -> float:
    """max |x(t) - x(t - 0.1 s)| over the last period, relative to max |x| (rub run)."""
    _, rub = reproduce()
    x = rub.outputs[(node, direction)]
    n = int(round(0.1 / rub.scene.solver.dt))
    return float(np.max(np.abs(x[-n:] - x[-2 * n:-n])) / np.max(np.abs(x[-n:])))


def reference_line_error(settings: tuple) -> tuple[float, int]:
    """Worst difference of the Table 1 line amplitudes against a reference run, and its Table 1 count.

    Returns (max |A_ref - A| over the 24 Table 1 frequencies / largest line amplitude, Table 1 count
    of the reference run). ``settings`` selects the reference (e.g. (("solver.dt", 1e-5),)).
    """
    _, rub = reproduce()
    _, ref = reproduce(settings)
    a, b = rub.spectra[(14, "y")], ref.spectra[(14, "y")]
    grid = [70 * n + 90 * m for m, n in (_mn(label) for _, label in XU2016_TABLE1)]
    err = max(abs(a.amplitude_at(f) - b.amplitude_at(f)) for f in grid)
    return err / float(np.max(a.amplitudes[1:])), n_table1_found(settings)


def _mn(label: str):
    m, n = parse_label(label)
    return int(m), int(n)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plot", default=None, help="directory for the figures and data of both scenes")
    p.add_argument("--skip-references", action="store_true", help="skip the half-step and full-model runs")
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    normal, rub = reproduce()
    t_runs = time.perf_counter() - t0
    print(f"paper-normal and paper-rub computed in {t_runs:.2f} s ({rub.model_label})\n")

    print("1. Normal state: lines above 1 % of the largest (must be f_L and f_H only)")
    ok1 = True
    for node in (13, 14):
        for d in ("x", "y"):
            labels = [ln.label for ln in normal_lines(node, d)]
            ok = set(labels) <= {"f_L", "f_H"} and "f_H" in labels
            ok1 &= ok
            spec = normal.spectra[(node, d)]
            ratio = spec.amplitude_at(normal.f_L) / spec.amplitude_at(normal.f_H)
            verdict = "ok" if ok else "FAIL"
            print(f"   node {node} {d.upper()}: {', '.join(labels):12s} (f_L/f_H = {ratio:.4f}) {verdict}")

    matches = table1_matches()
    found = n_table1_found()
    print(f"\n2. Rub: node 14 Y lines above 0.5 % of the largest against the paper's Table 1 "
          f"({found} of 24 found with the paper's label; needed 18)")
    print(format_comparison(matches))

    r18, n18 = plate_side_reach(18)
    r14, n14 = plate_side_reach(14)
    print(f"\n3. Reach towards the plate (n . (x, y)): node 18 rub {1e6 * r18:.2f} um, normal {1e6 * n18:.2f} um "
          f"({'contracted' if r18 < n18 else 'NOT contracted'}); node 14 rub {1e6 * r14:.2f} um, normal "
          f"{1e6 * n14:.2f} um")
    c13, c14 = relative_change(13), relative_change(14)
    print(f"4. Relative RMS change rub vs normal: inner node 13 {c13:.3f}, outer node 14 {c14:.3f} "
          f"({'inner changes less' if c13 < c14 else 'inner does NOT change less'}); "
          f"peaks node 13 Y {1e6 * rub.peak((13, 'y')):.2f} um (normal {1e6 * normal.peak((13, 'y')):.2f}), "
          f"node 14 Y {1e6 * rub.peak((14, 'y')):.2f} um (normal {1e6 * normal.peak((14, 'y')):.2f}), "
          f"node 18 Y {1e6 * rub.peak((18, 'y')):.1f} um (normal {1e6 * normal.peak((18, 'y')):.1f})")
    print(f"5. Periodicity: last two 0.1 s periods at node 18 Y differ by {period_mismatch():.2e} of the peak, "
          f"node 14 Y by {period_mismatch(14, 'y'):.2e}; contact {100 * rub.contact_fraction():.2f} % of the "
          f"window, {rub.n_impacts()} impacts in {rub.t[-1] - rub.t[0]:.2f} s")
    if not args.skip_references:
        print("6. Independent references for the rub run (Table 1 line amplitudes, relative to the largest line):")
        rows = [("half time step (dt = 1e-5 s)", (("solver.dt", 1e-5),)),
                ("full FE model (80 DOFs)", (("solver.model", "full"),)),
                ("HHT-alpha (alpha = -0.05)", (("solver.method", "hht"), ("solver.alpha", -0.05))),
                ("start-up from rest", (("solver.start", "rest"),))]
        for name, settings in rows:
            t1 = time.perf_counter()
            err, n = reference_line_error(settings)
            _, ref = reproduce(settings)
            print(f"   {name:32s}: worst difference {err:.2e}, Table 1 found {n}/24, node 18 Y peak "
                  f"{1e6 * ref.peak((18, 'y')):.1f} um ({time.perf_counter() - t1:.1f} s)")
        print("   (the start-up from rest settles on a second periodic orbit of the same spectrum family: the rub "
              "response is not unique)")
    if args.plot:
        for r in (normal, rub):
            files = write_outputs(r, f"{args.plot}/{r.scene.name}")
            print(f"wrote {len(files)} files to {args.plot}/{r.scene.name}")
    ok = ok1 and found >= 18 and r18 < n18 and c13 < c14
    print(f"\n{'all signatures reproduced' if ok else 'SOME SIGNATURES MISSING'} "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
