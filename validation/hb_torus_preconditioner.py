"""What sets a torus branch point's GMRES iterations (issue 40, item 3): the change of the contact's fields between
Jacobians, not the preconditioner's truncation to the orders of largest compliance.

paper-rub at outer 91.37 Hz, the clearance branch from 14 µm down (the default box, |k1| <= 32, |k2| <= 80, band 900 Hz,
grid 128 x 256: 1799 orders, a reduced equation of 3597 unknowns), its first 12 points traced by
:func:`rotorred.scenes.torus_branch.continue_torus`, every corrector iterate's Jacobian kept. The reduced equation
``(I + C G_VU) y = b`` of a later Jacobian (a random right-hand side through its fields) is solved by right-preconditioned
GMRES (:func:`rotorred.nonlinear.torus_krylov.right_gmres`, restarts of 100, at most 300 iterations) to 1e-2 and 1e-6
with the preconditioner built from the first Jacobian:

- the coarse block the branch uses (:meth:`RankJacobian._coarse_block`: the 1000 orders of largest compliance, exact
  between them, the identity elsewhere);
- the exact inverse of the whole reduced equation (its 3597 x 3597 matrix built column by column through the grid,
  factorised by LU in single precision, as the block is);
- none.

A preconditioner from the same Jacobian would be exact (one iteration); the rows show how many iterations each needs
``lag`` Jacobians later (the next corrector iterate is lag 1). Printed first: the first Jacobian's grid samples in
contact, its coarse block's build and factorisation time, and the times of a GMRES iteration's preconditioner and
product.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/hb_torus_preconditioner.py
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla

import rotorred.nonlinear.torus_continuation as torus_continuation
from hb_torus_branch import DIVISORS, TOL, scene_for
from rotorred.nonlinear.torus_krylov import right_gmres
from rotorred.scenes.run import build_model
from rotorred.scenes.torus_branch import TorusBranchOptions, continue_torus

START, END = 14e-6, 5e-6  #: m, the clearance branch's stretch traced
POINTS = 12  #: points traced (their Jacobians kept)
LAGS = (0, 1, 4, 8, 16, 30)  #: Jacobians between the preconditioner's and the solved one's (0: the same)
TOLERANCES = (1e-2, 1e-6)  #: GMRES's relative residuals: a first corrector iterate's, a last one's
MAXITER = 300
REPEATS = 20  #: calls timed for the iteration's parts


def kept_jacobians() -> list:
    """Every corrector iterate's Jacobian (``RankJacobian``) of the branch's first :data:`POINTS` points."""
    kept, build = [], torus_continuation.TorusFamily._jacobian

    def keeping(self, p, z, relative):
        J = build(self, p, z, relative)
        kept.append(J.J)
        return J
    torus_continuation.TorusFamily._jacobian = keeping
    try:
        scene = scene_for("rub.clearance", START, record=False)
        continue_torus(scene, build_model(scene).model, "rub.clearance", START, END,
                       TorusBranchOptions(divisors=DIVISORS, tol=TOL, max_points=POINTS))
    finally:
        torus_continuation.TorusFamily._jacobian = build
    return [J for J in kept if J is not None]


def main() -> None:
    jacobians = kept_jacobians()
    first = jacobians[0]
    t0 = time.perf_counter()
    reduced = np.column_stack([first.inner(e) for e in np.eye(first.inner_size)])
    exact = sla.lu_factor(reduced.astype(np.float32), check_finite=False)
    print(f"{len(jacobians)} Jacobians; the reduced equation {first.inner_size} unknowns, its exact inverse built and "
          f"factorised in {time.perf_counter() - t0:.1f} s")
    t0 = time.perf_counter()
    block = first._coarse_block()
    built = time.perf_counter() - t0
    first._preconditioner = block
    y = np.random.default_rng(1).standard_normal(first.inner_size)
    applied, product = (_median_time(lambda: first.precondition(y)), _median_time(lambda: first.inner(y)))
    contact = np.count_nonzero(np.any(first.Mq != 0, axis=(0, 1)) | np.any(first.Mv != 0, axis=(0, 1)))
    print(f"the first Jacobian: {contact} of its {first.h.n_samples} grid samples in contact; its coarse block built "
          f"and factorised in {1e3 * built:.0f} ms; a GMRES iteration's preconditioner {1e3 * applied:.2f} ms and "
          f"product {1e3 * product:.2f} ms (median of {REPEATS})")

    def coarse(J):  # the first Jacobian's block on J's equation (its own precondition, handed the block)
        J._preconditioner = block
        return J.precondition
    preconditioners = {
        "coarse block": coarse,
        "exact inverse": lambda J: (lambda y: sla.lu_solve(exact, y.astype(np.float32), check_finite=False)
                                    .astype(float)),
        "none": lambda J: (lambda y: y.copy()),
    }
    rng = np.random.default_rng(0)
    header = " | ".join(f"{name}, {tol:g}" for name in preconditioners for tol in TOLERANCES)
    print(f"| lag | {header} |")
    print("|---|" + "---|" * (len(preconditioners) * len(TOLERANCES)))
    for lag in (lag for lag in LAGS if lag < len(jacobians)):
        J = jacobians[lag]
        if not (np.allclose(first.U.T @ J.U, np.eye(first.r)) and np.allclose(first.V.T @ J.V, np.eye(first.s))):
            print(f"| {lag} | other bases of the contact's directions: not compared |")
            continue
        b = J.core(rng.standard_normal((J.h.size, J.c)) @ J.V).reshape(-1)
        cells = []
        for name, make in preconditioners.items():
            for tol in TOLERANCES:
                _, iterations, reached = right_gmres(J.inner, make(J), b, None, tol, 100, MAXITER)
                cells.append(f"{iterations}" if reached <= tol else f"> {MAXITER}")
        print(f"| {lag} | " + " | ".join(cells) + " |")


def _median_time(f) -> float:
    """The median wall time of :data:`REPEATS` calls of ``f`` (s)."""
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


if __name__ == "__main__":
    main()
