"""What a torus branch's point costs, and the settings tried to make it cheaper (issue 40; docs/model.md §26, "Not
met").

paper-rub at outer 91.37 Hz, its clearance branch from 20 µm on the default box (|k1| <= 32, |k2| <= 80, band 900 Hz,
grid 128 x 256), the first ``POINTS`` points, traced once with each setting of ``VARIANTS`` (the module constant of
:mod:`rotorred.nonlinear.torus_krylov`, :mod:`rotorred.nonlinear.torus_continuation` or
:mod:`rotorred.scenes.torus_branch` it changes, or the branch's tolerance), in one run, ``ROUNDS`` times in turn.
GMRES's solves and iterations are counted by wrapping :func:`rotorred.nonlinear.torus_krylov.right_gmres`, the coarse
blocks built by wrapping ``RankJacobian._coarse_block`` (the start's included), the passes through the grid that
evaluate the forces (a residual each; a point's lines one more) by wrapping the torus module's ``sampled_forces``.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/hb_torus_branch_tuning.py

Prints a row per variant and round: the value reached, the median and mean point time (s), the corrections, the
force evaluations, GMRES solves and iterations a point, and the coarse blocks built. The machine may be loaded by
other work: compare rows of one run (on a loaded machine a row's times move by a quarter from one round to the next;
the counts do not).
"""

from __future__ import annotations

import numpy as np

import rotorred.nonlinear.torus as torus
import rotorred.nonlinear.torus_continuation as continuation
import rotorred.nonlinear.torus_krylov as krylov
import rotorred.scenes.torus_branch as torus_branch
from hb_torus_branch import DIVISORS, scene_for
from rotorred.scenes.run import build_model
from rotorred.scenes.torus_branch import TorusBranchOptions, continue_torus

POINTS = 40  #: the branch's first points
ROUNDS = 2
#: (name, module, constant, value, tolerance): the settings tried; the first is the code's own
VARIANTS = (("as is", None, None, None, 1e-6),
            ("J^-1 c from zero", continuation, "WARM_COLUMN", False, 1e-6),
            ("coarse block 500 orders", krylov, "COARSE_ORDERS", 500, 1e-6),
            ("coarse block 1400 orders", krylov, "COARSE_ORDERS", 1400, 1e-6),
            ("fresh block after 12", continuation, "FRESH_AFTER", 12, 1e-6),
            ("fresh block after 35", continuation, "FRESH_AFTER", 35, 1e-6),
            ("tolerance 1e-5", None, None, None, 1e-5),
            ("dR/ds by a difference", torus_branch, "DERIVATIVES", {}, 1e-6))

COUNT = {"solves": 0, "iterations": 0, "blocks": 0, "forces": 0}


def _counted(gmres, block, forces):
    def right_gmres(*args, **kwargs):
        x, iterations, achieved = gmres(*args, **kwargs)
        COUNT["solves"] += 1
        COUNT["iterations"] += iterations
        return x, iterations, achieved

    def coarse_block(self):
        COUNT["blocks"] += 1
        return block(self)

    def sampled_forces(*args):
        COUNT["forces"] += 1
        return forces(*args)
    return right_gmres, coarse_block, sampled_forces


def main():
    krylov.right_gmres, krylov.RankJacobian._coarse_block, torus.sampled_forces = _counted(
        krylov.right_gmres, krylov.RankJacobian._coarse_block, torus.sampled_forces)
    scene = scene_for("rub.clearance", 20e-6, record=False)
    model = build_model(scene).model
    print(f"paper-rub at {91.37} Hz, clearance from 20 µm, the first {POINTS} points of the branch, default box:")
    print("| variant | reached (µm) | median point (s) | mean (s) | corrections | force evaluations a point | "
          "GMRES solves a point | iterations a point | blocks built |")
    for _ in range(ROUNDS):
        for name, module, constant, value, tol in VARIANTS:
            kept = getattr(module, constant) if module is not None else None
            if module is not None:
                setattr(module, constant, value)
            COUNT.update(solves=0, iterations=0, blocks=0, forces=0)
            try:
                branch = continue_torus(scene, model, "rub.clearance", 20e-6, 5e-6,
                                        TorusBranchOptions(divisors=DIVISORS, tol=tol, max_points=POINTS))
            finally:
                if module is not None:
                    setattr(module, constant, kept)
            steps = branch.point_time[1:]
            print(f"| {name:24s} | {branch.values[-1] * 1e6:12.3f} | {np.median(steps):16.3f} | {steps.mean():8.3f} | "
                  f"{branch.iterations[1:].mean():11.2f} | {COUNT['forces'] / len(steps):25.1f} | "
                  f"{COUNT['solves'] / len(steps):20.1f} | "
                  f"{COUNT['iterations'] / len(steps):18.0f} | {COUNT['blocks']:12d} |", flush=True)


if __name__ == "__main__":
    main()
