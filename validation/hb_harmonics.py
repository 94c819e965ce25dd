"""``[solver] tolerance`` with ``method = "harmonic-balance"`` on paper-rub: the harmonics chosen for 1e-2 and 1e-3,
the estimate behind each choice, and the error actually reached against a converged reference (800 harmonics,
16384 AFT samples a period, Newton from the 400-harmonic solution). As in ``rotorred run``, each truncation starts
from a short transient's last period (the settled transient's orbit); the solve time includes that transient.

Run::

    python validation/hb_harmonics.py      # about 2 minutes, one thread

The error is the estimate's own measure (:func:`rotorred.scenes.balance_harmonics.response_change`): the largest
over the scene's output DOFs of ||c - c_ref|| / ||c_ref|| on their Fourier coefficients. The table also gives each
truncation's change from the one before, and the observed order log2 of the ratio of successive changes.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import math  # noqa: E402
import time  # noqa: E402

from rotorred.nonlinear.hb import solve_periodic  # noqa: E402
from rotorred.scenes.balance_harmonics import (balance_to_tolerance, padded, response_change,  # noqa: E402
                                               samples_for)
from rotorred.scenes.harmonic_balance import rub_problem  # noqa: E402
from rotorred.scenes.run import build_model, start_record  # noqa: E402
from rotorred.scenes.schema import load_scene  # noqa: E402

TOLERANCES = (1e-2, 1e-3)
H_REFERENCE = 800


def main() -> None:
    scene = load_scene("paper-rub")
    model = build_model(scene).model
    dofs = scene.output.dofs
    chosen = {}
    for tol in TOLERANCES:
        t0 = time.perf_counter()
        record = start_record(scene, model)  # as a scene's run: each truncation from a short transient's last period
        chosen[tol] = balance_to_tolerance(scene, model, tol, dofs, record=record) + (time.perf_counter() - t0,)
    rp, z = chosen[TOLERANCES[-1]][:2]
    ref = rub_problem(scene, model, H_REFERENCE, samples_for(H_REFERENCE))
    t0 = time.perf_counter()
    z_ref = solve_periodic(ref.problem, padded(z, ref), ref.omega, tol=1e-9).z
    t_ref = time.perf_counter() - t0
    print(f"paper-rub (13 um, 70/90 Hz, f0 = {ref.f0:g} Hz), output DOFs {', '.join(f'{n}{d.upper()}' for n, d in dofs)}; "
          f"reference {H_REFERENCE} harmonics, {samples_for(H_REFERENCE)} samples ({t_ref:.1f} s)\n")
    print("tolerance | harmonics | samples | estimate | error vs reference | met | solve time (s)")
    print("----------|-----------|---------|----------|--------------------|-----|---------------")
    for tol, (rp, z, choice, seconds) in chosen.items():
        error = response_change(rp, z, ref, z_ref, dofs)
        print(f"{tol:<9g} | {choice.harmonics:<9d} | {choice.samples:<7d} | {choice.estimate:<8.2g} | "
              f"{error:<18.2g} | {'yes' if error <= tol else 'NO':<3} | {seconds:.2f}")
    steps = chosen[TOLERANCES[-1]][2].steps
    print("\nchanges along the ladder: " + ", ".join(f"{H}: {c:.3g}" for H, c in steps))
    print("observed orders (log2 of successive changes): "
          + ", ".join(f"{b[0]}: {math.log2(a[1] / b[1]):.2f}" for a, b in zip(steps, steps[1:])))


if __name__ == "__main__":
    main()
