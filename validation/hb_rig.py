"""Harmonic balance of the rig's rub response (paper-rub, 70/90 Hz) against the settled transient, its cold solution,
a continuation in the clearance, and the costs of each, measured in one run.

Run::

    python validation/hb_rig.py            # about 30 s

Prints:

1. the settled transient's 10 largest lines at node 14 Y and, for 60, 150 and 100 harmonics of f_0 = 10 Hz, the
   harmonic-balance solution started from the transient's last period: Newton iterations, solve time and each line's
   relative difference;
2. the cold solutions at 13 um: a scene's (Newton from a 5-period transient's last period: the transient's orbit),
   and without that record (:func:`rotorred.scenes.balance_harmonics.cold_solution` through 25 and 50 harmonics,
   and the cold start at 100 harmonics itself, :func:`rotorred.scenes.branch.cold_start`): their times, their
   distances, and the second periodic response the latter reach, with its lines;
3. the branch from 20 to 5 um (:func:`rotorred.scenes.branch.continue_scene`, 100 harmonics): points, time a point
   (mean, median, largest), and the settled transient at every point's clearance against each point's cost;
4. the stability of both orbits from the monodromy matrix of the whole linearised system (largest Floquet
   multiplier modulus; < 1 stable);
5. transients started on each orbit (its state at t = 0, ``RubProblem.final_state``) and run for 2 s: the distance of
   their last period from each orbit (relative, in the Fourier coefficients of the unknowns);
6. the cost table of docs/benchmarks.md: transient, HB from the transient, HB cold, continuation a
   point (solve times only).
"""

from __future__ import annotations

import time

import numpy as np

from rotorred.nonlinear.hb import solve_periodic
from rotorred.nonlinear.stability import floquet_by_monodromy
from rotorred.scenes.balance_harmonics import cold_solution
from rotorred.scenes.branch import STABILITY_SUBSTEPS, BranchOptions, cold_start, continue_scene
from rotorred.scenes.harmonic_balance import rub_problem, unknown_records
from rotorred.scenes.run import build_model, run_scene, start_record
from rotorred.scenes.schema import load_scene
from rotorred.transient.newmark import Loads, Recording, simulate

OUTPUT = (14, "y")


def transient_orbit(scene, sm):
    """The settled transient, its 10 largest lines at node 14 Y and its last period's records of the unknowns."""
    result = run_scene(scene, sm, compare_normal=False)
    largest = sorted(result.analyses[OUTPUT].fit.lines, key=lambda ln: -ln.amplitude)[:10]
    records = unknown_records(scene.plates, result)
    return result, largest, records


def from_transient(scene, sm, result, largest, records, H: int, N: int):
    rp = rub_problem(scene, sm.model, H, N)
    window = result.t >= result.t[-1] - 1.0 / rp.f0 + 1e-9
    z0 = rp.start_from_record(result.t[window], {j: x[window] for j, x in records.items()})
    t0 = time.perf_counter()
    solution = solve_periodic(rp.problem, z0, rp.omega)
    z, iterations = solution.z, solution.iterations
    elapsed = time.perf_counter() - t0
    lines = rp.lines(z, OUTPUT)
    diffs = [lines[round(ln.frequency_hz, 6)] / ln.amplitude - 1 for ln in largest]
    print(f"  H = {H:3d}, N = {N:4d}: {iterations} Newton iterations, {elapsed:.2f} s; worst {max(map(abs, diffs)):.2%}: "
          + " ".join(f"{ln.frequency_hz:.0f}:{d:+.2%}" for ln, d in zip(largest, diffs)))
    return rp, z, elapsed


def cold(scene, sm, rp100, largest, zA):
    """The cold solutions at 13 um, 100 harmonics, and their times (solve only):

    * a scene's (:func:`rotorred.scenes.run.start_record` and :func:`rotorred.scenes.balance_harmonics.cold_solution`:
      Newton from a 5-period transient's last period), best of 3, and its distance from the settled transient's orbit;
    * without that record: a cold start at 25 harmonics, then Newton through 50 to 100 (a second orbit), its distance
      from the cold start at 100 harmonics itself (:func:`rotorred.scenes.branch.cold_start`) and the lines.
    """
    H, N = rp100.problem.harmonics.H, rp100.problem.harmonics.N
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        _, zC, how = cold_solution(scene, sm.model, H, N, record=start_record(scene, sm.model))
        times.append(time.perf_counter() - t0)
    print(f"  a scene's ({how}): {min(times):.3f} s (best of 3); {np.linalg.norm(zC - zA) / np.linalg.norm(zA):.1e} "
          f"(relative) from the settled transient's orbit")
    t0 = time.perf_counter()
    zB = cold_solution(scene, sm.model, H, N)[1]
    elapsed = time.perf_counter() - t0
    t0 = time.perf_counter()
    zD = cold_start(rp100.problem, rp100.omega)
    direct = time.perf_counter() - t0
    lines = rp100.lines(zB, OUTPUT)
    print(f"  without the transient's record (a cold start at 25 harmonics, Newton at 50 and 100): {elapsed:.2f} s; the "
          f"cold start at 100 harmonics itself {direct:.2f} s, {np.linalg.norm(zB - zD) / np.linalg.norm(zD):.1e} "
          f"(relative) from it")
    print(f"  that solution's distance from the transient's orbit {np.linalg.norm(zB - zA) / np.linalg.norm(zA):.2f} "
          f"(relative): a second orbit; its lines against the transient's:")
    print("   " + " ".join(f"{ln.frequency_hz:.0f}:{lines[round(ln.frequency_hz, 6)] / ln.amplitude - 1:+.1%}"
                         for ln in largest))
    return zB, min(times), elapsed


def by_clearance(scene, sm):
    """The branch from 20 to 5 um at 100 harmonics (no stability: the continuation's own cost), each point's cost (the
    time between the continuation's reports: a point carries the corrections that failed before it), and the settled
    transient at every point's clearance (warm, solve time only)."""
    stamps = []
    branch = continue_scene(scene, sm.model, "rub.clearance", 20e-6, 5e-6, BranchOptions(100, 2048, stability=False),
                            progress=lambda p, v: stamps.append(time.perf_counter()))
    per_point = branch.solve_time / (len(branch.values) - 1)
    costs = np.diff(stamps[:-1])  # points 2 .. p - 1 (the last stamp: continue_scene's report of the whole branch)
    print(f"  {len(branch.values)} points from 20 to 5 um in {branch.solve_time:.3f} s: {1e3 * per_point:.1f} ms a "
          f"point (median {1e3 * np.median(costs):.1f}, largest {1e3 * costs.max():.1f} ms; cold start at 20 um "
          f"{branch.start_time:.2f} s); {branch.stopped}")
    transients = np.array([run_scene(load_scene("paper-rub", {"rub.clearance": c}), sm, compare_normal=False).solve_time
                           for c in branch.values])
    ratios = transients[1:-1] / costs
    print(f"  the settled transient at each point's clearance: {1e3 * transients.min():.1f}-{1e3 * transients.max():.1f} ms "
          f"(mean {1e3 * transients.mean():.1f}); a point's cost against it: mean {transients.mean() / per_point:.1f}x "
          f"faster, {np.count_nonzero(ratios >= 10)} of {len(ratios)} points 10x or more (each point's own ratio: "
          f"median {np.median(ratios):.1f}x, least {ratios.min():.1f}x, after a kink)")
    return per_point, transients


def main() -> None:
    scene = load_scene("paper-rub")
    sm = build_model(scene)
    result, largest, records = transient_orbit(scene, sm)
    print(f"settled transient (solve {result.solve_time:.2f} s), 10 largest lines at node 14 Y:")
    print("  " + ", ".join(f"{ln.frequency_hz:.0f} Hz {1e6 * ln.amplitude:.3f} um" for ln in largest))
    print("harmonic balance started from the transient's last period:")
    for H, N in ((60, 512), (150, 4096)):
        from_transient(scene, sm, result, largest, records, H, N)
    rp100, zA, warm = from_transient(scene, sm, result, largest, records, 100, 2048)
    print("cold harmonic balance at 13 um, 100 harmonics:")
    zB, cold_time, ladder_time = cold(scene, sm, rp100, largest, zA)
    print("continuation in the clearance, 100 harmonics:")
    per_point, transients = by_clearance(scene, sm)
    print(f"stability (monodromy of the whole linearised system, {STABILITY_SUBSTEPS} intervals an AFT sample):")
    for name, z in (("the transient's orbit", zA), ("the second orbit", zB)):
        t0 = time.perf_counter()
        fl = floquet_by_monodromy(rp100.problem, z, rp100.omega, STABILITY_SUBSTEPS)
        print(f"  {name}: largest |multiplier| {np.abs(fl.multipliers).max():.4f} "
              f"({'stable' if fl.stable else 'unstable'}), {time.perf_counter() - t0:.1f} s")
    print("transients started on each orbit, 2 s later (last period):")
    for name, z in (("from the transient's orbit", zA), ("from the second orbit", zB)):
        zt = settled_from(scene, sm, rp100, z)
        print(f"  {name}: distance {np.linalg.norm(zt - zA) / np.linalg.norm(zA):.4f} from the transient's orbit, "
              f"{np.linalg.norm(zt - zB) / np.linalg.norm(zB):.4f} from the second orbit")
    transient = min(run_scene(scene, sm, compare_normal=False).solve_time for _ in range(3))  # warm: no first call
    print("costs (solve time only, this run; 100 harmonics, 2048 samples):")
    print(f"  settled transient at 13 um (warm)   {transient:6.3f} s  (20 um: {transients[0]:.3f} s, 5 um: "
          f"{transients[-1]:.3f} s; the first run {result.solve_time:.2f} s)")
    print(f"  HB from the transient's last period {warm:6.3f} s  ({warm / transient:.2f}x the transient's time)")
    print(f"  HB cold (a scene's)                 {cold_time:6.3f} s  ({cold_time / transient:.2f}x the transient's time)")
    print(f"  HB cold without a transient         {ladder_time:6.2f} s  ({ladder_time / transient:.0f}x the transient's time)")
    print(f"  continuation, per point (20-5 um)   {per_point:6.4f} s  ({transients.mean() / per_point:.1f}x faster than the "
          f"settled transient at the points' clearances, {1e3 * transients.mean():.0f} ms on average)")


def settled_from(scene, sm, rp, z):
    """The coefficients of the last period of a 2 s transient started on the orbit ``z``."""
    res = simulate(sm.model, scene.operating, 2.0, scene.solver.dt, loads=Loads(scene.unbalances),
                   contacts=scene.plates, recording=Recording([(18, "x"), (18, "y")], start=1.9),
                   start=rp.final_state(z))
    window = res.t >= res.t[-1] - 1.0 / rp.f0 + 1e-9
    records = unknown_records(scene.plates, res)
    return rp.start_from_record(res.t[window], {j: x[window] for j, x in records.items()})


if __name__ == "__main__":
    main()
