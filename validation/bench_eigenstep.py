"""The eigenbasis step against the dense step, in one run (issue 15): µs per step and the histories' difference.

Cases: `paper-rub` as built in (Craig-Bampton, 24 modes, 48 DOFs; rub; 2.6 s at 2e-5 s from the settled
state, record from 2.0 s), the same with 10 modes (34 DOFs), the full FE model (80 DOFs), and
`paper-normal` (no plate). Each case runs the dense and the eigenbasis step alternately ``--repeats``
times; the table gives the least CPU µs per step of the step loop (the kernel is loaded before), the
ratio eigen / dense, cond(P) of the eigenbasis, and the largest difference of the recorded outputs
relative to each output's largest value.

Run ``python validation/bench_eigenstep.py [--repeats N]`` (about 1 minute).
"""

from __future__ import annotations

import argparse
import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

from rotorred.scenes.run import build_model, settled_state  # noqa: E402
from rotorred.scenes.schema import load_scene  # noqa: E402
from rotorred.model.operating import Operating  # noqa: E402
from rotorred.transient.newmark import Initial, Loads, Recording, Scheme, StepControl, simulate  # noqa: E402

CASES = {"paper-rub, 24 modes": ("paper-rub", {}), "paper-rub, 10 modes": ("paper-rub", {"solver.modes": 10}),
         "paper-rub, full model": ("paper-rub", {"solver.model": "full"}), "paper-normal, 24 modes": ("paper-normal", {})}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"{'case':24} {'DOFs':>5} {'dense us':>9} {'eigen us':>9} {'eigen/dense':>11} {'cond(P)':>8} "
          f"{'max |diff|':>10}")
    for name, (scene_name, settings) in CASES.items():
        sc = load_scene(scene_name, settings)
        s = sc.solver
        model = build_model(sc).model
        start = Initial(*settled_state(sc, model)) if s.start == "settled" else None
        kw = dict(loads=Loads(sc.unbalances), contacts=sc.plates,
                  recording=Recording(sc.output.dofs, start=s.record_start), start=start,
                  control=StepControl(progress=False))
        best, last = {}, {}
        for _ in range(args.repeats):
            for step in ("dense", "eigen"):
                r = simulate(model, Operating.point(sc.speeds), s.duration, s.dt, scheme=Scheme(step=step), **kw)
                best[step] = min(best.get(step, np.inf), r.cpu_us_per_step)
                last[step] = r
        a, b = last["dense"], last["eigen"]
        diff = max(np.max(np.abs(a.outputs[o] - b.outputs[o])) / np.max(np.abs(a.outputs[o])) for o in a.outputs)
        cond = b.step_form.split("= ")[-1] if b.step_form.startswith("eigenbasis") else "dense"
        print(f"{name:24} {model.M.shape[0]:5d} {best['dense']:9.3f} {best['eigen']:9.3f} "
              f"{best['eigen'] / best['dense']:11.2f} {cond:>8} {diff:10.2e}")


if __name__ == "__main__":
    main()
