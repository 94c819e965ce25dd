"""Compile time of rotorred's step loops into an empty numba cache, and their load from that cache (issue 15).

Each loop is compiled in a new Python process with an empty ``NUMBA_CACHE_DIR`` by a few steps of paper-rub's
reduced model (its plate, its unbalances), and the result's ``kernel_load_time`` is read (the compilation, reported
apart from the run by :func:`rotorred.transient.stepping.load_kernel`); a second new process with the same cache
reads the load. Loops:

* **eigenbasis** (:func:`rotorred.transient.eigen_kernel.run_eigen_steps`): constant speeds, what the scenes use;
* **dense** (:func:`rotorred.transient.kernel.run_steps`): ``step="dense"``, as for HHT-α or a step that must be
  halved;
* **varying speed** (:func:`rotorred.transient.ramp_kernel.run_ramp_steps`): a speed profile (run-ups).

Run: ``python validation/bench_compile.py [--repeats N]`` (about 1 minute a repeat); prints the least and the
largest of the repeats (the machine's speed varies: alternate with another tree to compare).
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402

LOOPS = ("eigenbasis", "dense", "varying speed")


def worker(loop: str) -> float:
    """Seconds this process spent compiling (or loading) ``loop``'s kernel for a few steps of paper-rub."""
    import numpy as np

    from rotorred.model.speeds import SpeedProfile
    from rotorred.scenes.run import build_model
    from rotorred.scenes.schema import load_scene
    from rotorred.model.operating import Operating
    from rotorred.transient.newmark import Loads, Scheme, simulate

    scene = load_scene("paper-rub")
    model = build_model(scene).model
    operating = scene.operating
    if loop == "varying speed":
        operating = Operating.profile(SpeedProfile(t=np.array([0.0, 1.0]), speeds={k: np.array([v, 1.01 * v])
                                                                                   for k, v in scene.speeds.items()}))
    step = {"eigenbasis": "eigen", "dense": "dense"}.get(loop, "auto")  # "auto" takes dense for 10 steps
    res = simulate(model, operating, 2e-4, 2e-5, loads=Loads(scene.unbalances), contacts=scene.plates,
                   scheme=Scheme(step=step))
    return res.kernel_load_time


def _run(loop: str, cache: str) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    done = subprocess.run([sys.executable, __file__, "--worker", loop], env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{loop}: {done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--worker", choices=LOOPS, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(args.worker)))
        return 0
    rows = {loop: ([], []) for loop in LOOPS}
    for _ in range(args.repeats):
        for loop in LOOPS:
            with tempfile.TemporaryDirectory(prefix="rotorred-numba-") as cache:
                rows[loop][0].append(_run(loop, cache))
                rows[loop][1].append(_run(loop, cache))
    print(f"step loops of rotorred, compiled into an empty numba cache ({os.cpu_count()} cores; {args.repeats} "
          "repeat(s): least-largest)")
    print("| loop | compile s | load from the cache s |")
    print("|---|---|---|")
    for loop, (compiled, loaded) in rows.items():
        print(f"| {loop} | {min(compiled):.1f}-{max(compiled):.1f} | {min(loaded):.2f}-{max(loaded):.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
