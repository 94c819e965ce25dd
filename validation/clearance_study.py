"""The clearance study promised by Xu et al. (2016, abstract): rub clearance against spectral lines.

A one-key map (``rotorred sweep`` is ``rotorred map``) of ``rub.clearance`` on the built-in
``paper-rub`` scene, every point from the scene's start (``cold``: each clearance as the paper
would run it), checks the expected trend:

* above the free (no-rub) orbit's reach towards the plate at the rub node 18 there is no
  contact and the line fit finds f_L and f_H only (the response is the linear one);
* below it the plate is touched at every clearance and combination lines appear.

The line fit's combination lines (the strongest 58 besides f_L and f_H) sum to 10-14 µm at
every touching clearance, 1 to 42 µm, with no trend as the clearance closes. (The study once
reported growth, from the spectrum's peaks above the scene's line threshold; the fitted
lines, which count the whole rub response, show none. Near the reach and at 16-25 µm the
response is still unsettled at the scene's 2.6 s.)

The same map from the command line: ``rotorred sweep paper-rub --vary
rub.clearance=1e-6,4e-6,...,60e-6 --cold --out clearance`` (its ``lines.png`` is the figure).
Run ``python validation/clearance_study.py [--out DIR]``; :func:`study` returns the map's dataset.
"""

from __future__ import annotations

import argparse
import functools
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from rotorred.maps.run import format_map, run_map
from rotorred.maps.spec import Axis, MapSpec

#: clearances (m): from contact at rest to beyond the free orbit's reach (43 um)
CLEARANCES = (1e-6, 4e-6, 7e-6, 10e-6, 13e-6, 16e-6, 20e-6, 25e-6, 30e-6, 35e-6, 40e-6, 42e-6, 45e-6, 50e-6, 60e-6)


def spec(clearances: tuple = CLEARANCES) -> MapSpec:
    return MapSpec("paper-rub", (Axis("rub.clearance", clearances),), cold=True)


@functools.lru_cache(maxsize=None)
def study(clearances: tuple = CLEARANCES, out: str | None = None):
    """The map of ``rub.clearance`` over ``clearances`` (its MapRun), into ``out`` or a temporary folder."""
    if out is not None:
        return run_map(spec(clearances), out, progress=False)
    with tempfile.TemporaryDirectory() as tmp:
        return run_map(spec(clearances), Path(tmp) / "clearance", progress=False, figures=False)


def combination_lines(ds) -> tuple[np.ndarray, np.ndarray]:
    """Per point: the number of lines other than f_L and f_H, and the sum of their amplitudes (m)."""
    labels, amps = ds["line_label"].values, np.nan_to_num(ds["line_amplitude"].values)
    other = (labels != "") & (labels != "f_L") & (labels != "f_H")
    return other.sum(axis=-1), np.where(other, amps, 0.0).sum(axis=-1)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default=None, help="folder of the map's files and figures (default: none kept)")
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    run = study(out=args.out)
    ds = run.dataset.sel(direction="up")
    print(format_map(run.dataset, spec()))
    values, reach = np.array(CLEARANCES), float(ds["free_reach"].values[0])
    far = values > reach
    n_other, total = combination_lines(ds)
    contact = ds["contact_fraction"].values
    no_lines_far = bool(np.all(n_other[far] == 0) and np.all(contact[far] == 0))
    near = ~far
    lines_near = bool(np.all(n_other[near] > 0) and np.all(contact[near] > 0))
    print(f"\nbeyond the free reach ({1e6 * reach:.2f} um): no contact and no combination line: "
          f"{'yes' if no_lines_far else 'NO'}")
    print(f"below it: contact and combination lines at every clearance: {'yes' if lines_near else 'NO'}")
    print(f"sum of the combination lines at the touching clearances: {1e6 * total[near].min():.3g} to "
          f"{1e6 * total[near].max():.3g} um (clearance {1e6 * values[near].min():.3g} to "
          f"{1e6 * values[near].max():.3g} um)")
    print(f"{len(values)} points in {time.perf_counter() - t0:.1f} s (mean "
          f"{np.nanmean(ds['wall_time'].values):.2f} s per point)")
    return 0 if (no_lines_far and lines_near) else 1


if __name__ == "__main__":
    sys.exit(main())
