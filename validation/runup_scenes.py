"""The built-in run-up scenes and the numbers docs/analyses.md quotes from them (issue 13).

Runs `runup`, `runup-rub` and `coastdown-rub` (12 s each on the 48-DOF reduced rig) and prints, per
scene: the largest orbit radius at nodes 14 and 18 with the inner speed where it occurs, the 1x outer
peak at node 18 against the outer line's 42.9 Hz critical speed (inner), the rub intervals, and the
cost. ``--images DIR`` also writes each scene's figures there, as ``<scene>_<figure>.png`` (figures are never
committed under docs/: the site's are drawn by its gallery when it is built).

Run ``python validation/runup_scenes.py [--images DIR]`` (about 30 s).
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import tempfile
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np

from rotorred.scenes.runup import run_runup
from rotorred.scenes.runup_outputs import write_runup_outputs
from rotorred.scenes.schema import load_scene

HZ = 1 / (2 * math.pi)
#: figures of each scene copied to --images, as <scene>_<figure>.png
FIGURES = {"runup": ("runup_amplitude",), "runup-rub": ("runup_amplitude", "waterfall", "runup_orbits"),
           "coastdown-rub": ("runup_amplitude",)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--images", default=None, help="copy each scene's figures into this folder")
    args = parser.parse_args()
    for name in ("runup", "runup-rub", "coastdown-rub"):
        r = run_runup(load_scene(name), progress=False)
        c = r.counters
        print(f"{name}: {r.n_steps} steps, {c['us_per_step']:.2f} us/step, {c['n_passes'] / r.n_steps:.2f} passes/step, "
              f"solve {r.solve_time:.2f} s, analysis {r.analysis_time:.2f} s")
        for node in (14, 18):
            speed, radius = r.overall[node]
            k = int(np.argmax(radius))
            print(f"  node {node}: largest orbit radius {1e6 * radius[k]:.1f} um at inner {speed[k] * HZ:.1f} Hz")
        crit = next(cs for cs in r.critical_speeds if cs.spool == "outer" and cs.whirl == "forward" and cs.speed * HZ > 30)
        track = next(t for t, d in zip(r.tracks, r.track_dofs) if d == (18, "y") and t.spool == "outer" and t.order == 1)
        inner = np.interp(track.t, r.t, r.speeds["inner"]) * HZ
        window = np.abs(inner - crit.speed * HZ) < 10.0
        k = int(np.argmax(np.where(window, track.amplitude, 0.0)))
        print(f"  1x outer at node 18 y: peak {1e6 * track.amplitude[k]:.1f} um at inner {inner[k]:.1f} Hz, "
              f"the critical speed (Campbell, 1x outer forward) at inner {crit.speed * HZ:.1f} Hz")
        for rub in r.rubs:
            print(f"  rub at node {rub.node}: t = {rub.t_start:.2f}-{rub.t_end:.2f} s, inner "
                  f"{rub.speed_start['inner']:.1f} -> {rub.speed_end['inner']:.1f} Hz, {rub.impacts} impacts")
        if args.images:
            with tempfile.TemporaryDirectory() as tmp:
                write_runup_outputs(r, tmp)
                for fig in FIGURES[name]:
                    dest = Path(args.images) / f"{name}_{fig}.png"
                    shutil.copyfile(Path(tmp) / f"{fig}.png", dest)
                    print(f"  wrote {dest}")


if __name__ == "__main__":
    main()
