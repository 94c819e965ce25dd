"""Benchmark of ``rotorred map``: a 41 x 10 map (outer speed x clearance) serially and on 2 Dask workers,
and warm (continuation) against cold starts.

Issue 12, Must show "Benchmark". The map is ``paper-rub`` (inner 70 Hz) with the outer spool at
80-100 Hz in 0.5 Hz steps (continuation axis) and the rub clearance at 0-45 µm in 5 µm steps,
swept up, each point run until settled or ``LIMIT`` = 4 s simulated
(:func:`rotorred.maps.point.run_point`). Three runs, in this order, each into a fresh folder:

1. serial (``workers=0``: this process, BLAS on one thread);
2. a ``LocalCluster`` of 2 single-threaded workers, continuation (the same answer, bit for bit:
   checked here);
3. the same cluster size with cold starts (``--cold``: every point from the scene's start).

It prints, per run: the wall time, the cost per point (wall time / points, and the mean of the
points' own wall times), the speed-up against serial, and for warm and cold: the points
settled, the mean settling time of the points settled in both, and the mean simulated time per
point (the settling time saved is the difference). The cluster's start-up is included in its
wall time. Run on an otherwise idle 2-core machine: ``python validation/bench_map.py``
(``--quick``: a 9 x 2 map).
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

LIMIT = 4.0  #: s simulated at most per point
SPEEDS = tuple(float(f) for f in np.round(np.arange(80.0, 100.0 + 1e-9, 0.5), 1))  #: outer spool (Hz), 41
CLEARANCES = tuple(float(c) for c in np.round(np.arange(0.0, 45e-6 + 1e-12, 5e-6), 12))  #: m, 10
SETTINGS = (("output.plots", []), ("output.formats", []), ("output.compare_normal", False),
            ("output.nodes", [13, 14, 18]))


def _spec(speeds, clearances, cold: bool) -> MapSpec:
    return MapSpec("paper-rub", (Axis("speeds.outer", speeds), Axis("rub.clearance", clearances)),
                   settings=SETTINGS, cold=cold, limit=LIMIT)


def _run(spec: MapSpec, workers: int, root: Path, name: str) -> dict:
    t0 = time.perf_counter()
    result = run_map(spec, root / name, workers=workers, progress=False, figures=False)
    wall = time.perf_counter() - t0
    ds = result.dataset
    return {"name": name, "workers": workers, "wall": wall, "n": spec.n_points, "ds": ds,
            "point_mean": float(np.nanmean(ds["wall_time"].values))}


def _same(a, b) -> bool:
    """Every variable but the wall time equal, NaN == NaN."""
    for name in a.data_vars:
        if name == "wall_time":
            continue
        x, y = a[name].values, b[name].values
        same = np.array_equal(x, y, equal_nan=True) if x.dtype.kind == "f" else bool((x == y).all())
        if not same:
            return False
    return True


def _settling(run: dict, both: np.ndarray) -> tuple[int, float, float]:
    ds = run["ds"]
    ts = ds["settling_time"].values
    return int(np.isfinite(ts).sum()), float(np.mean(ts[both])), float(np.nanmean(ds["simulated"].values))


def _report(serial: dict, warm: dict, cold: dict, out) -> None:
    print(f"{'run':<22} {'workers':>7} {'points':>6} {'wall (s)':>9} {'s/point':>8} {'point mean':>10} "
          f"{'speed-up':>8}", file=out)
    for r in (serial, warm, cold):
        print(f"{r['name']:<22} {r['workers']:>7} {r['n']:>6} {r['wall']:>9.1f} {r['wall'] / r['n']:>8.3f} "
              f"{r['point_mean']:>10.3f} {serial['wall'] / r['wall']:>8.2f}", file=out)
    print(f"cluster = serial, bit for bit: {_same(serial['ds'], warm['ds'])}", file=out)
    both = np.isfinite(warm["ds"]["settling_time"].values) & np.isfinite(cold["ds"]["settling_time"].values)
    print(f"\n{'starts':<6} {'settled':>8} {'mean settling (s), points settled in both':>42} "
          f"{'mean simulated (s)':>19}", file=out)
    for label, r in (("warm", warm), ("cold", cold)):
        n, ts, sim = _settling(r, both)
        print(f"{label:<6} {n:>8} {ts:>42.3f} {sim:>19.3f}", file=out)
    n_w, ts_w, sim_w = _settling(warm, both)
    n_c, ts_c, sim_c = _settling(cold, both)
    print(f"settling time saved per point by continuation: {ts_c - ts_w:.3f} s (on {int(both.sum())} points "
          f"settled both ways); simulated time saved per point: {sim_c - sim_w:.3f} s", file=out)


def main(argv=None, out=sys.stdout) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a 9 x 2 map")
    args = parser.parse_args(argv)
    speeds, clearances = (SPEEDS[::5], CLEARANCES[2::5]) if args.quick else (SPEEDS, CLEARANCES)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        serial = _run(_spec(speeds, clearances, False), 0, root, "serial")
        warm = _run(_spec(speeds, clearances, False), 2, root, "2 workers, warm")
        cold = _run(_spec(speeds, clearances, True), 2, root, "2 workers, cold")
    print(f"map {len(speeds)} x {len(clearances)} (outer speed x clearance), paper-rub, limit {LIMIT:g} s", file=out)
    _report(serial, warm, cold, out)
    print(f"total time {time.perf_counter() - t0:.1f} s", file=out)
    return {"serial": serial, "warm": warm, "cold": cold}


if __name__ == "__main__":
    main()
