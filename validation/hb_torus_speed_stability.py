"""Stability along the outer-speed torus branch's piece below 91.37 Hz, between its folds (issue 40; docs/model.md
§26).

paper-rub, inner spool 70 Hz, the rub torus (f_L, f_H/3), the default box of ``continue --torus`` (|k1| <= 32,
|k2| <= 80, band 900 Hz, grid 128 x 256), tolerance 1e-6: the branch down from 91.37 Hz (``validation/
hb_torus_branch.py``'s first piece: six folds between 91.08 and 91.16 Hz and the corner at 91.049 Hz where it ends).
The branch's points are cut into runs where its tangent's speed component keeps its sign (between two folds, or a
fold and an end), and at the middle point of each run :func:`rotorred.torus_lyapunov` (default options, docs/model.md
§27) gives the two leading Lyapunov exponents, their errors and the verdict. Each point's problem is rebuilt at its
speed on the branch's orders (:func:`rotorred.scenes.torus_balance.torus_rub_problem_on`), and the point's relative
residual on it is printed: the point is that problem's torus.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/hb_torus_speed_stability.py

Prints the branch's folds and a row per run: its points, its speeds, the sign of d f_out / ds, the middle point, its
residual, the exponents with their errors (1/s) and the verdict.
"""

from __future__ import annotations

import numpy as np

import rotorred as rr
from hb_torus_branch import DIVISORS, TOL, scene_for
from rotorred.scenes.run import build_model
from rotorred.scenes.torus_balance import torus_rub_problem, torus_rub_problem_on

KEY = "speeds.outer"
START, END = 91.37, 91.0  #: Hz: the piece down from 91.37 Hz
INNER = 70.0  #: Hz
BOX = (32, 80, 128, 256, 900.0)  #: H1, H2, N1, N2, band (Hz): continue --torus's default


def runs_of(slope: np.ndarray) -> list[np.ndarray]:
    """The runs of consecutive points whose slope keeps its sign."""
    sign = np.sign(slope)
    return np.split(np.arange(len(sign)), np.flatnonzero(sign[1:] != sign[:-1]) + 1)


def main():
    scene = scene_for(KEY, START, record=False)
    model = build_model(scene).model
    branch = rr.continue_torus(scene, model, KEY, START, END,
                               rr.TorusBranchOptions(divisors=DIVISORS, tol=TOL, max_points=400))
    print(f"paper-rub, {KEY} from {START} Hz: {len(branch.values)} points, folds "
          + ", ".join(f"{v:.5f} Hz ({'smooth' if s else 'corner'})" for v, s in branch.folds))
    print(f"  {branch.stopped.splitlines()[0] if branch.stopped else ''}")
    start = torus_rub_problem(scene, model, (INNER, START / DIVISORS[1]), *BOX)
    print("| run | points | outer speed (Hz) | d f_out / ds | middle point (Hz) | its residual | exponents (1/s) | "
          "verdict |")
    for k, run in enumerate(runs_of(branch.slope)):
        i = int(run[len(run) // 2])
        value = float(branch.values[i])
        there = scene_for(KEY, value, record=False)
        problem = torus_rub_problem_on(there, model, (INNER, value / DIVISORS[1]), start.problem.harmonics,
                                       start.spool_orders).problem
        residual = np.linalg.norm(problem.residual(branch.z[i])) / problem.scale
        st = rr.torus_lyapunov(problem, branch.z[i])
        exponents = ", ".join(f"{e:+.2f} ± {d:.2f}" for e, d in zip(st.exponents, st.errors))
        print(f"| {k + 1} | {run[0]}-{run[-1]} | {branch.values[run[0]]:.4f}-{branch.values[run[-1]]:.4f} | "
              f"{np.sign(branch.slope[i]):+.0f} | {value:.4f} | {residual:.1e} | {exponents} | {st.verdict} |",
              flush=True)


if __name__ == "__main__":
    main()
