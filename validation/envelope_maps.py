"""The two maps of the operating envelope in docs/analyses.md, and the numbers it quotes from them.

Issue 12, Must show "In the README" (since issue 36 on the site's page docs/analyses.md). Runs, on a LocalCluster
of one worker per core:

1. ``rotorred map paper-rub --vary speeds.outer=60:110:101 --direction both --limit 4`` (inner 70 Hz);
2. ``rotorred map paper-rub --vary rub.clearance=0:45e-6:10 --direction both --limit 4`` (70/90 Hz);

and prints what docs/analyses.md says of them: the speeds without contact, the class of 90 Hz up and
down, the chaotic points (count, and in 74.5-86.5 Hz), the speeds where up and down differ in
class, the peak orbit at node 14 at 63 Hz; for the clearance map, the contact fraction and orbit
radius at node 18 at 45 µm each way, and the Poincaré samples' range per sweep below 30 µm.
``--out DIR`` keeps the two maps' folders (figures included); default a temporary folder.

Run: ``python validation/envelope_maps.py [--out DIR]`` (about 3 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from rotorred.maps.run import run_map
from rotorred.maps.spec import Axis, MapSpec
from rotorred.scenes.keys import netcdf_name

SPEEDS = tuple(60.0 + (110.0 - 60.0) * i / 100 for i in range(101))  #: Hz, as the CLI's 60:110:101
CLEARANCES = tuple(0.0 + (45e-6 - 0.0) * i / 9 for i in range(10))  #: m, as the CLI's 0:45e-6:10
LIMIT = 4.0


def speed_map(out: Path, report=sys.stdout):
    spec = MapSpec("paper-rub", (Axis("speeds.outer", SPEEDS),), direction="both", limit=LIMIT)
    run = run_map(spec, out, progress=False)
    print(f"speed map: {spec.n_points} points in {run.wall_time:.0f} s", file=report)
    return run.dataset


def clearance_map(out: Path, report=sys.stdout):
    spec = MapSpec("paper-rub", (Axis("rub.clearance", CLEARANCES),), direction="both", limit=LIMIT)
    run = run_map(spec, out, progress=False)
    print(f"clearance map: {spec.n_points} points in {run.wall_time:.0f} s", file=report)
    return run.dataset


def report_speed(ds, out=sys.stdout) -> None:
    f = ds[netcdf_name("speeds.outer")].values
    up, down = (ds["kind"].sel(direction=d).values for d in ("up", "down"))
    k_up, k_down = (ds["subharmonic"].sel(direction=d).values for d in ("up", "down"))
    contact = ds["contact_fraction"].values
    chaotic = f[up == "chaotic"].tolist() + f[down == "chaotic"].tolist()
    inside = [x for x in chaotic if 74.5 <= x <= 86.5]
    i63, i90 = int(np.argmin(abs(f - 63.0))), int(np.argmin(abs(f - 90.0)))
    orbit = 1e6 * ds["peak_orbit"].sel(node=14).values[:, i63]
    print(f"speed map: points without contact: {int((contact == 0).sum())} of {contact.size}", file=out)
    print(f"90 Hz: up {up[i90]} (k = {k_up[i90]}), down {down[i90]} (k = {k_down[i90]})", file=out)
    print(f"chaotic points: {len(chaotic)} of {up.size + down.size}, {len(inside)} in 74.5-86.5 Hz", file=out)
    print(f"speeds where up and down differ in class: {int((up != down).sum())} of {f.size}", file=out)
    print(f"peak orbit at node 14, 63 Hz: up {orbit[0]:.1f} um, down {orbit[1]:.1f} um", file=out)


def report_clearance(ds, out=sys.stdout) -> None:
    c = ds[netcdf_name("rub.clearance")].values
    last = int(np.argmax(c))
    for d in ("up", "down"):
        one = ds.sel(direction=d)
        below = 1e6 * one["poincare_x"].values[c < 30e-6 - 1e-12]
        print(f"clearance map, {d}: at 45 um contact fraction {float(one['contact_fraction'].values[last]):.3f}, "
              f"orbit radius at node 18 {1e6 * float(one['peak_orbit'].sel(node=18).values[last]):.0f} um; "
              f"Poincare samples below 30 um in [{np.nanmin(below):.2f}, {np.nanmax(below):.2f}] um", file=out)


def main(argv=None, out=sys.stdout) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=None, help="keep the maps' folders here")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.out or tmp)
        report_speed(speed_map(root / "speed", out), out)
        report_clearance(clearance_map(root / "clearance", out), out)
    print(f"total time {time.perf_counter() - t0:.1f} s", file=out)


if __name__ == "__main__":
    main()
