"""Run-ups of the seed rig checked three ways (issue 13), every number printed:

1. **Slow ramp = steady state.** The `runup` scene's rotor (paper damping, paper-rub's unbalances, no rub)
   run up slowly from 30 to 84 Hz inner (fixed ratio 90/70) in ``--slow`` seconds (default 200 s,
   dt = 5e-5 s). Each spool's 1x order track (angle-domain resampling, blocks of 14 inner = 18 outer
   revolutions) against ``rotorred.linear.harmonic.unbalance_response`` at the block's speeds: the largest
   error 5 % or more in speed from every critical speed of the machine (both lines, Campbell; after a
   critical the rotor rings at it while the speed moves on), relative to the local amplitude; the largest
   error anywhere relative to the curve's peak; and the error of each peak of the steady curve. The first
   10 % of the run (the start transient) is left out.
2. **Reduced = full.** The `runup` scene (12 s from rest) on its Craig-Bampton model and on the full FE
   model: the overall amplitude (largest orbit radius per two revolutions) and the 1x tracks, largest
   difference relative to the curve's peak.
3. **Energy balance on the rig.** One second of the run-up through the outer spool's 55 Hz critical
   (inner 39 -> 46 Hz) on the reduced model, the whole state recorded: relative residual of Eq. R5.

Run ``python validation/runup_checks.py [--slow SECONDS]`` (about 1 minute).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import time

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np
from scipy.signal import find_peaks

from rotorred.linear.campbell import campbell
from rotorred.linear.harmonic import unbalance_response
from rotorred.model.operating import Operating
from rotorred.model.speeds import SpeedProfile
from rotorred.scenes.run import build_model
from rotorred.scenes.runup import block_revolutions, run_runup
from rotorred.scenes.schema import load_scene
from rotorred.signals.orders import angle_blocks, order_tracks
from rotorred.transient.energy import energy_balance
from rotorred.transient.newmark import Loads, Recording, StepControl, simulate

HZ = 1 / (2 * math.pi)


def slow_ramp(T: float) -> None:
    scene = load_scene("runup")
    model = build_model(scene).model
    op = scene.speeds
    ratio = op["outer"] / op["inner"]
    profile = SpeedProfile.ramp({s: 30 / 70 * w for s, w in op.items()}, {s: 1.2 * w for s, w in op.items()}, T)
    outputs = [(13, "y"), (14, "y"), (18, "y")]
    t0 = time.perf_counter()
    dt = 5e-5  # Newmark's period error (omega dt)^2/12 moves the 121 Hz mode: 1.1 % near 108 Hz at 1e-4 s
    res = simulate(model, Operating.profile(profile), T, dt, loads=Loads(scene.unbalances),
                   recording=Recording(outputs, decimate=2), control=StepControl(progress=False))
    print(f"1. slow ramp: inner 30 -> 84 Hz in {T:g} s (lambda = Omega'/omega^2 = {0.9 * 2 * math.pi * 54 / T / (2 * math.pi * 55.7) ** 2:.1e} "
          f"at the inner 55.7 Hz critical), {res.n_steps} steps of {dt:g} s in {time.perf_counter() - t0:.1f} s "
          f"({res.us_per_step:.2f} us/step)")
    cd = campbell(scene.rotor, Operating.line(np.linspace(0, 2 * math.pi * 84, 61), "inner", ratios={"outer": ratio}))
    at = profile.at(res.t)
    X = np.array([res.outputs[o] for o in outputs])
    ratios = {"inner": 1.0, "outer": ratio}
    print(f"   {'line':9} {'dof':5} {'away: max err':>13} {'median':>8} {'all: / peak':>11}   peaks of the steady curve "
          "(spool Hz: steady um, track err)")
    for s in ("inner", "outer"):
        revs = block_revolutions(ratio if s == "inner" else 1 / ratio, 8)
        blocks = angle_blocks(res.t, X, at[s][2], revs)
        tracks = order_tracks(blocks, s, [1.0])
        keep = blocks.t.mean(axis=1) > 0.1 * T
        W = blocks.speed[keep]
        steady = unbalance_response(model, Operating.line(W / ratios[s], "inner", ratios={"outer": ratio}),
                                    scene.unbalances, outputs)
        crit = [c.speed * ratios[s] for c in cd.critical_speeds]  # every resonance of the machine, in this spool's speed
        for j, o in enumerate(outputs):
            a, Q = tracks[j][0].amplitude[keep], np.abs(steady.phasors[s][o])
            away = np.all([np.abs(W - c) > 0.05 * c for c in crit], axis=0)
            rel = np.abs(a - Q) / Q
            peaks, _ = find_peaks(Q, prominence=0.05 * Q.max())
            text = ", ".join(f"{W[k] * HZ:.1f}: {1e6 * Q[k]:.2f} um {a[max(k - 3, 0):k + 4].max() / Q[k] - 1:+.2%}"
                             for k in peaks)
            print(f"   1x {s:6} {o[0]}:{o[1]}  {rel[away].max():13.2e} {np.median(rel[away]):8.1e} "
                  f"{np.max(np.abs(a - Q)) / Q.max():11.2e}   {text}")


def reduced_vs_full() -> None:
    curves = {}
    for model in ("reduced", "full"):
        scene = load_scene("runup", {"solver.model": model, "runup.orbits_hz": []})
        t0 = time.perf_counter()
        r = run_runup(scene, progress=False)
        curves[model] = r
        print(f"2. {model:8}: {r.model_label.split(' (')[0]}, {r.n_steps} steps, {r.counters['us_per_step']:.2f} us/step, "
              f"{time.perf_counter() - t0:.1f} s")
    red, full = curves["reduced"], curves["full"]
    print(f"   {'curve':26} {'peak (um)':>10} {'max |reduced - full| / peak':>28}")
    for node in sorted(full.overall):
        a, b = red.overall[node][1], full.overall[node][1]
        print(f"   orbit radius, node {node:3}   {1e6 * b.max():10.2f} {np.max(np.abs(a - b)) / b.max():28.2e}")
    for ta, dof in zip(full.tracks, full.track_dofs):
        if ta.order != 1.0 or dof[1] != "y":
            continue
        tb = next(t for t, d in zip(red.tracks, red.track_dofs) if d == dof and t.spool == ta.spool and t.order == 1.0)
        print(f"   1x {ta.spool:6} {dof[0]}:{dof[1]:14} {1e6 * ta.amplitude.max():10.2f} "
              f"{np.max(np.abs(tb.amplitude - ta.amplitude)) / ta.amplitude.max():28.2e}")


def energy_on_the_rig() -> None:
    scene = load_scene("runup")
    model = build_model(scene).model
    op = scene.speeds
    profile = SpeedProfile.ramp({s: 39 / 70 * w for s, w in op.items()}, {s: 46 / 70 * w for s, w in op.items()}, 1.0)
    loads, run_up = Loads(scene.unbalances), Operating.profile(profile)
    t0 = time.perf_counter()
    res = simulate(model, run_up, 1.0, 2e-5, loads=loads, recording=Recording(states=True),
                   control=StepControl(progress=False))
    balance = energy_balance(model, res, run_up, loads)
    without = energy_balance(dataclasses.replace(model, K_G={s: 0 * k for s, k in model.K_G.items()}), res, run_up,
                             loads)
    print(f"3. energy balance, inner 39 -> 46 Hz in 1 s ({res.n_steps} steps, {time.perf_counter() - t0:.1f} s): "
          f"drive work {balance.drive[-1]:.4g} J, dissipated {balance.damping[-1]:.4g} J, "
          f"energy change {balance.energy[-1]:.4g} J; relative residual {balance.relative_residual:.2e} "
          f"(without the K_G terms {without.relative_residual:.2e})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--slow", type=float, default=200.0, help="length of the slow ramp (s)")
    args = parser.parse_args()
    slow_ramp(args.slow)
    reduced_vs_full()
    energy_on_the_rig()


if __name__ == "__main__":
    main()
