"""Which box of orders a torus branch needs on the rig (issue 40; docs/model.md §26, the default box's choice).

paper-rub at outer 91.37 Hz (inner 70 Hz) on the torus (f_L, f_H/3), at the clearances 19, 14 and 6 µm: the settled
2-22 s transient's 10 largest node-14 Y lines (``validation/hb_torus.py``'s ``transient``) against the torus on each
box, band and grid of ``BOXES``, each solved from the same start (the 10 x 40 torus on a 32 x 256 grid, itself solved
from the transient's record by least squares, as ``hb_torus.py`` does). Then, at 6 µm on the reference box, where the
large lines sit: the largest |k1| and frequency of the orders above 1e-3 and 1e-4 of the largest amplitude (of any
unknown), and how many orders they are.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/hb_torus_box.py

Prints a row per box: its orders and its worst line's relative difference from the transient's at each clearance, and
the reference box's amplitudes. No times: the point's costs are ``validation/hb_torus_branch.py``'s.
"""

from __future__ import annotations

import math

import numpy as np

from hb_torus import OUTPUT, START_ORDERS, START_SPAN, START_STRIDE, transient
from hb_torus_branch import scene_for
from rotorred.nonlinear.torus import TorusHarmonics, solve_torus
from rotorred.scenes.run import build_model
from rotorred.scenes.torus_balance import torus_rub_problem

OUTER_HZ = 91.37
BASES = (70.0, OUTER_HZ / 3)  #: Hz: (f_L, f_H / 3)
CLEARANCES = (19e-6, 14e-6, 6e-6)  #: m
#: (H1, H2, band Hz, N1, N2): the boxes compared; the third is the reference, the fourth the branch's default
BOXES = ((8, 40, 1500.0, 32, 512), (16, 80, 1500.0, 64, 1024), (32, 160, 1500.0, 128, 1024),
         (32, 80, 900.0, 128, 256), (32, 80, 900.0, 128, 1024), (24, 64, 800.0, 128, 256),
         (32, 64, 700.0, 128, 256), (24, 60, 600.0, 128, 256))
REFERENCE = 2  #: the box whose amplitudes are shown
START = (10, 40, 32, 256)  #: the start's torus (band 1500 Hz), solved from the record


def at_clearance(clearance: float):
    """The worst line of each box against the transient at ``clearance``, and the reference box's problem and
    solution."""
    scene = scene_for("rub.clearance", clearance, record=True)
    sm = build_model(scene)
    run, _, largest, records = transient(scene, sm)
    frequencies = [ln.frequency_hz for ln in largest]
    reference = np.array([ln.amplitude for ln in largest])
    start = torus_rub_problem(scene, sm.model, BASES, START[0], START[1], START[2], START[3], 1500.0)
    window = run.t >= run.t[-1] - START_SPAN
    z0 = start.start_from_record(run.t[window][::START_STRIDE],
                                 {j: x[window][::START_STRIDE] for j, x in records.items()}, within=START_ORDERS)
    z_start = solve_torus(start.problem, z0).z
    worst, kept = [], None
    for i, (H1, H2, f_max, N1, N2) in enumerate(BOXES):
        rp = torus_rub_problem(scene, sm.model, BASES, H1, H2, N1, N2, f_max)
        z = solve_torus(rp.problem, start.problem.harmonics.transfer(z_start, start.problem.n,
                                                                     rp.problem.harmonics)).z
        worst.append(float(np.max(np.abs(rp.amplitudes_at(z, OUTPUT, frequencies) / reference - 1))))
        if i == REFERENCE:
            kept = (rp, z)
    return worst, kept


def main():
    rows, kept = [], None
    for clearance in CLEARANCES:
        worst, ref = at_clearance(clearance)
        rows.append(worst)
        kept = ref
    print("the 10 largest node-14 Y lines against the settled 2-22 s transient's, worst relative difference:")
    print("| box, band, grid | orders | " + " | ".join(f"{c * 1e6:g} µm" for c in CLEARANCES) + " |")
    w = tuple(2 * math.pi * f for f in BASES)
    for i, (H1, H2, f_max, N1, N2) in enumerate(BOXES):
        n = TorusHarmonics(H1, H2, N1, N2, 2 * math.pi * f_max, w).n_orders
        print(f"| {H1} x {H2}, {f_max:g} Hz, {N1} x {N2} | {n} | "
              + " | ".join(f"{rows[j][i]:.2%}" for j in range(len(CLEARANCES))) + " |")
    rp, z = kept
    h = rp.problem.harmonics
    a = np.abs(h.phasors(z, rp.problem.n)).max(axis=1)
    a /= a.max()
    f = np.abs(h.frequencies(rp.bases_hz))
    H1, H2, f_max = BOXES[REFERENCE][:3]
    print(f"at {CLEARANCES[-1] * 1e6:g} µm on {H1} x {H2} ({f_max:g} Hz), the orders above a share of the largest "
          f"amplitude:")
    for share in (1e-3, 1e-4):
        big = a > share
        print(f"  {share:g}: {big.sum()} orders, |k1| up to {np.abs(h.orders[big, 0]).max()}, |k2| up to "
              f"{np.abs(h.orders[big, 1]).max()}, frequencies up to {f[big].max():.0f} Hz")


if __name__ == "__main__":
    main()
