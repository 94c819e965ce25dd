"""Harmonic balance of the rig's rub response (paper-rub, 70/90 Hz) against the settled transient, and the two
periodic responses it has there.

Run::

    python validation/hb_rig.py            # about 2 minutes

Prints:

1. the settled transient's 10 largest lines at node 14 Y and, for 60, 100 and 150 harmonics of f_0 = 10 Hz, the
   harmonic-balance solution started from the transient's last period: Newton iterations, solve time and each line's
   relative difference;
2. a continuation in the clearance from 50 um (no contact) to 13 um with 30 harmonics (points, folds, time), the
   orbit it ends on refined to 100 harmonics, its distance from the transient's orbit and its lines;
3. the stability of both orbits from the monodromy matrix of the whole linearised system (largest Floquet
   multiplier modulus; < 1 stable);
4. transients started on each orbit (its state at t = 0, ``RubProblem.final_state``) and run for 2 s: the distance of
   their last period from each orbit (relative, in the Fourier coefficients of the unknowns).
"""

from __future__ import annotations

import time

import numpy as np

from rotorred.nonlinear.condensed import ClearanceFamily
from rotorred.nonlinear.continuation import continue_branch
from rotorred.nonlinear.hb import solve
from rotorred.nonlinear.stability import floquet_by_monodromy
from rotorred.scenes.harmonic_balance import rub_problem
from rotorred.scenes.run import build_model, run_scene
from rotorred.scenes.schema import load_scene
from rotorred.transient.newmark import simulate

OUTPUT = (14, "y")


def transient_orbit(scene, sm):
    """The settled transient, its 10 largest lines at node 14 Y and its last period's records of the unknowns."""
    result = run_scene(scene, sm, compare_normal=False)
    largest = sorted(result.analyses[OUTPUT].fit.lines, key=lambda ln: -ln.amplitude)[:10]
    contact = result.contacts[0]
    records = {0: result.outputs[(18, "x")], 1: result.outputs[(18, "y")], 2: contact.u_n, 3: contact.u_t}
    return result, largest, records


def from_transient(scene, sm, result, largest, records, H: int, N: int):
    rp = rub_problem(scene, sm.model, H, N)
    window = result.t >= result.t[-1] - 1.0 / rp.f0 + 1e-9
    z0 = rp.start_from_record(result.t[window], {j: x[window] for j, x in records.items()})
    t0 = time.perf_counter()
    z, _, iterations = solve(rp.problem, z0, rp.omega)
    elapsed = time.perf_counter() - t0
    lines = rp.lines(z, OUTPUT)
    diffs = [lines[round(ln.frequency_hz, 6)] / ln.amplitude - 1 for ln in largest]
    print(f"  H = {H:3d}, N = {N:4d}: {iterations} Newton iterations, {elapsed:.2f} s; worst {max(map(abs, diffs)):.2%}: "
          + " ".join(f"{ln.frequency_hz:.0f}:{d:+.2%}" for ln, d in zip(largest, diffs)))
    return rp, z


def by_clearance(scene, sm, rp100, largest, zA):
    rp = rub_problem(scene, sm.model, 30, 256)
    family = ClearanceFamily(rp.problem, rp.omega)
    t0 = time.perf_counter()
    branch = continue_branch(family, rp.problem.linear_response(rp.omega), 50e-6, 13e-6, ds=2e-6, ds_min=1e-12,
                             ds_max=5e-6, stability=False, tol=1e-9)
    elapsed = time.perf_counter() - t0
    print(f"  30 harmonics: {len(branch.omega)} points in {elapsed:.1f} s ({1e3 * elapsed / len(branch.omega):.0f} ms "
          f"a point); folds at {', '.join(f'{1e6 * f.omega:.2f} um' for f in branch.folds)}; {branch.stopped}")
    i = int(np.argmin(np.abs(branch.omega - 13e-6)))
    z30, _, _ = solve(family.at(13e-6), branch.z[i], rp.omega)
    z0 = np.zeros(rp100.problem.size)
    z0[:len(z30)] = z30
    zB, _, iterations = solve(rp100.problem, z0, rp100.omega, max_iter=60)
    lines = rp100.lines(zB, OUTPUT)
    print(f"  refined to 100 harmonics in {iterations} iterations; distance from the transient's orbit "
          f"{np.linalg.norm(zB - zA) / np.linalg.norm(zA):.2f} (relative); its lines against the transient's:")
    print("   " + " ".join(f"{ln.frequency_hz:.0f}:{lines[round(ln.frequency_hz, 6)] / ln.amplitude - 1:+.1%}"
                         for ln in largest))
    return zB


def main() -> None:
    scene = load_scene("paper-rub")
    sm = build_model(scene)
    result, largest, records = transient_orbit(scene, sm)
    print(f"settled transient (solve {result.solve_time:.2f} s), 10 largest lines at node 14 Y:")
    print("  " + ", ".join(f"{ln.frequency_hz:.0f} Hz {1e6 * ln.amplitude:.3f} um" for ln in largest))
    print("harmonic balance started from the transient's last period:")
    for H, N in ((60, 512), (150, 4096)):
        from_transient(scene, sm, result, largest, records, H, N)
    rp100, zA = from_transient(scene, sm, result, largest, records, 100, 2048)
    print("continuation in the clearance from 50 um (no contact) to 13 um:")
    zB = by_clearance(scene, sm, rp100, largest, zA)
    print("stability (monodromy of the whole linearised system, 2048 intervals):")
    for name, z in (("the transient's orbit", zA), ("the continuation's orbit", zB)):
        t0 = time.perf_counter()
        fl = floquet_by_monodromy(rp100.problem, z, rp100.omega, substeps=1)
        print(f"  {name}: largest |multiplier| {np.abs(fl.multipliers).max():.4f} "
              f"({'stable' if fl.stable else 'unstable'}), {time.perf_counter() - t0:.1f} s")
    print("transients started on each orbit, 2 s later (last period):")
    for name, z in (("from the transient's orbit", zA), ("from the continuation's orbit", zB)):
        zt = settled_from(scene, sm, rp100, z)
        print(f"  {name}: distance {np.linalg.norm(zt - zA) / np.linalg.norm(zA):.4f} from the transient's orbit, "
              f"{np.linalg.norm(zt - zB) / np.linalg.norm(zB):.4f} from the continuation's")


def settled_from(scene, sm, rp, z):
    """The coefficients of the last period of a 2 s transient started on the orbit ``z``."""
    res = simulate(sm.model, scene.speeds, 2.0, scene.solver.dt, unbalances=scene.unbalances, plates=scene.plates,
                   rotor=scene.rotor, outputs=[(18, "x"), (18, "y")], record_start=1.9, start=rp.final_state(z))
    window = res.t >= res.t[-1] - 1.0 / rp.f0 + 1e-9
    contact = res.contacts[0]
    records = {0: res.outputs[(18, "x")], 1: res.outputs[(18, "y")], 2: contact.u_n, 3: contact.u_t}
    return rp.start_from_record(res.t[window], {j: x[window] for j, x in records.items()})


if __name__ == "__main__":
    main()
