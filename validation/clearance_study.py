"""The clearance study promised by Xu et al. (2016, abstract): rub clearance against spectral lines.

Sweeps ``rub.clearance`` of the built-in ``paper-rub`` scene and checks the expected trend:

* above the free (no-rub) orbit's reach towards the plate at the rub node 18 there is no
  contact and no combination line (the response is the linear one: f_L and f_H only);
* below it the plate is touched and combination lines m f_H + n f_L appear, and they grow as
  the clearance closes (the total combination amplitude at the smallest clearances exceeds
  the one just below the free reach).

Run ``python validation/clearance_study.py [--plot PATH]``; :func:`study` returns the
:class:`rotorred.scenes.sweep.SweepResult` for the tests.
"""

from __future__ import annotations

import argparse
import functools
import sys
import time

import numpy as np

from rotorred.scenes.sweep import format_sweep, sweep

#: clearances (m): from contact at rest to beyond the free orbit's reach (43 um)
CLEARANCES = (1e-6, 4e-6, 7e-6, 10e-6, 13e-6, 16e-6, 20e-6, 25e-6, 30e-6, 35e-6, 40e-6, 42e-6, 45e-6, 50e-6, 60e-6)


@functools.lru_cache(maxsize=None)
def study(clearances: tuple = CLEARANCES):
    """Sweep of ``rub.clearance`` over ``clearances`` (SweepResult)."""
    return sweep("paper-rub", "rub.clearance", list(clearances))


def beyond_reach(result) -> np.ndarray:
    """Mask of the clearances above the free orbit's reach."""
    return result.values > result.free_reach


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plot", default=None, help="PNG path of the sweep figure")
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    r = study()
    print(format_sweep(r))
    far = beyond_reach(r)
    total = r.combination_total()
    no_lines_far = bool(np.all(r.n_combinations[far] == 0) and np.all(r.contact_fraction[far] == 0))
    near = ~far
    lines_near = bool(np.all(r.n_combinations[near] > 0) and np.all(r.contact_fraction[near] > 0))
    # growth as the clearance closes: the smallest clearances carry more combination amplitude than
    # the largest clearance that still touches
    last_touch = int(np.flatnonzero(near)[-1])
    growth = float(np.max(total[:3]) / total[last_touch]) if total[last_touch] > 0 else float("inf")
    print(f"\nbeyond the free reach ({1e6 * r.free_reach:.2f} um): no contact and no combination line: "
          f"{'yes' if no_lines_far else 'NO'}")
    print(f"below it: contact and combination lines at every clearance: {'yes' if lines_near else 'NO'}")
    print(f"sum of combination lines: {1e6 * total[last_touch]:.3g} um at {1e6 * r.values[last_touch]:.3g} um "
          f"clearance, up to {1e6 * np.max(total[:3]):.3g} um at the three smallest clearances "
          f"(x{growth:.1f})")
    if args.plot:
        from rotorred.plots.sweep import plot_sweep

        print(f"wrote {plot_sweep(r, args.plot)}")
    print(f"{len(r.values)} runs in {time.perf_counter() - t0:.1f} s (mean {np.mean(r.wall_times):.2f} s per run)")
    return 0 if (no_lines_far and lines_near and growth > 1) else 1


if __name__ == "__main__":
    sys.exit(main())
