"""Cost of a run-up against a constant-speed run, reduced against full model, with and without rub (issue 13).

Every run steps the seed rig for 12 s at dt = 2e-5 s (600 000 steps) with paper-rub's unbalances and
damping: at constant speed at the operating point (70/90 Hz) from rest, or along the `runup` scene's
profile (from rest to 84/108 Hz); with paper-rub's plate at node 18 or without. Measured in one run:
µs per step (wall and CPU of the step loop only; the kernel is compiled or loaded before), the ratio
run-up / constant speed, fixed-point passes per step, step matrices built and their setup time.

Run ``python validation/bench_runup.py [--duration S] [--plot PATH]``.
"""

from __future__ import annotations

import argparse
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from rotorred.scenes.run import build_model
from rotorred.scenes.schema import load_scene
from rotorred.transient.newmark import Loads, Recording, StepControl, simulate


def run(model_kind: str, rub: bool, ramp: bool, duration: float):
    scene = load_scene("runup-rub" if rub else "runup", {"solver.model": model_kind, "runup.duration": duration,
                                                         "runup.orbits_hz": []})
    model = build_model(scene).model
    operating = scene.runup.operating if ramp else scene.operating
    res = simulate(model, operating, duration, scene.solver.dt, loads=Loads(scene.unbalances),
                   contacts=scene.plates, recording=Recording(scene.output.dofs, decimate=5),
                   control=StepControl(progress=False))
    return model.M.shape[0], res


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=12.0, help="simulated time of every run (s)")
    parser.add_argument("--plot", default=None, help="bar chart of the µs per step (PNG)")
    args = parser.parse_args()
    rows = []
    print(f"seed rig, {args.duration:g} s at dt = 2e-5 s per run; step loop only (kernel loaded before)")
    header = (f"{'model':>8} {'DOFs':>5} {'rub':>4} {'speeds':>9} {'us/step':>8} {'cpu us':>7} {'x const':>8} "
              f"{'passes':>7} {'matrices':>9} {'setup s':>8} {'contact steps':>14}")
    print(header)
    for kind in ("reduced", "full"):
        for rub in (False, True):
            base = None
            for ramp in (False, True):
                n, res = run(kind, rub, ramp, args.duration)
                us = res.us_per_step
                base = us if not ramp else base
                rows.append((kind, rub, ramp, us))
                print(f"{kind:>8} {n:5d} {'yes' if rub else 'no':>4} {'run-up' if ramp else 'constant':>9} {us:8.2f} "
                      f"{res.cpu_us_per_step:7.2f} {us / base:8.2f} {res.n_passes / res.n_steps:7.2f} "
                      f"{res.n_factorizations:9d} {res.setup_time:8.2f} {res.n_contact_steps:14d}")
    if args.plot:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(7, 3.5))
        ax = fig.subplots()
        labels = [f"{k}\n{'rub' if r else 'no rub'}\n{'run-up' if u else 'const'}" for k, r, u, _ in rows]
        ax.bar(range(len(rows)), [r[3] for r in rows], color=["tab:blue" if not r[2] else "tab:orange" for r in rows])
        ax.set_xticks(range(len(rows)), labels, fontsize=7)
        ax.set_ylabel("µs per step")
        fig.subplots_adjust(bottom=0.3)
        fig.savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
