"""Stability of the rig's torus: the Lyapunov exponents of the variational equation along it against perturbed
transients started on it (docs/model.md §27).

``paper-rub`` with the outer spool at 91.37 Hz (inner 70 Hz): the rub locks to f_H/3 and the response is the torus
(f_L, f_H/3) (``validation/hb_torus.py``). The torus is solved by :func:`rotorred.torus_balance` (its own 3 s
transient for the start and the bases, then Newton on the box ``ORDERS``), and its stability by
:func:`rotorred.torus_lyapunov` over ``PERIODS`` periods of f_H/3 (the plate law's own contact Jacobian along the
torus; each step's error checked by a second integration at twice the step). Then the rig's transient
(:func:`rotorred.simulate`, the scene's Newmark step) runs twice from the torus's state at t = 0: as it is, and with
the state scaled by ``1 + RELATIVE``; the distance between the two runs (the largest over node 14 and node 18, x and
y, in each period of f_H/3, relative to the torus's largest displacement there) at the start and after
``TRANSIENT_PERIODS`` periods says whether the perturbation dies, and its rate of decay is fitted against the largest
exponent. The distance of the unperturbed run from the torus's Fourier series is printed too: the torus's own error
(its truncation, the transient's step), which the perturbation is measured apart from.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/torus_stability.py

Prints the torus, the exponents with their errors and the verdict, and the table: torus, exponents, verdict, the
perturbed transient's distance at the start and after N periods, its fitted rate against the largest exponent.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

import rotorred as rr
from rotorred.scenes.run import build_model
from rotorred.scenes.schema import load_scene

OUTER_HZ = 91.37  #: outer spool (Hz); inner 70 Hz as paper-rub
ORDERS = (16, 70)  #: the torus's box |k1| <= H1, |k2| <= H2 (grid 64 x 1024, default_grid)
PERIODS = 300  #: periods of f_H/3 the variational equation is integrated over (9.9 s)
COUNT = 4  #: leading exponents
RELATIVE = 1e-3  #: the perturbation: the torus's state at t = 0 scaled by 1 + RELATIVE
TRANSIENT_PERIODS = 300  #: periods of f_H/3 the two transients run (9.85 s), as the exponents' integration
OUTPUTS = ((14, "x"), (14, "y"), (18, "x"), (18, "y"))
NOISE = 1e-6  #: the decay rate is fitted over the periods whose distance is above NOISE of the first's


@dataclass(frozen=True)
class Outcome:
    """The rig's torus: its stability and the perturbed transient's distances (relative to the torus's largest
    displacement at the outputs) in each period of f_H/3, and the rate fitted to them (1/s)."""

    stability: object
    period: float
    distances: np.ndarray
    from_torus: np.ndarray
    rate: float


def rig_torus(scene, sm):
    """The torus at the scene's speeds by :func:`rotorred.torus_balance`: its own start transient, then Newton."""
    options = rr.TorusOptions(orders=ORDERS, outputs=list(OUTPUTS))
    return rr.torus_balance(sm.model, rr.Operating.point(dict(scene.speeds)), rr.Loads(scene.unbalances),
                            scene.plates, options)


def transients(scene, sm, rt, t_end: float):
    """The scene's transient from the torus's state at t = 0, and from that state scaled by 1 + RELATIVE."""
    problem, n = rt.problem.problem, rt.problem.n_model
    q, v = rr.torus_trajectory(problem, rt.solution.z, [0.0], dofs="all")
    runs = []
    for scale in (1.0, 1.0 + RELATIVE):
        runs.append(rr.simulate(sm.model, rr.Operating.point(dict(scene.speeds)), t_end, scene.solver.dt,
                                loads=rr.Loads(scene.unbalances), contacts=scene.plates,
                                recording=rr.Recording(list(OUTPUTS)),
                                start=rr.Initial(scale * q[0, :n], scale * v[0, :n]),
                                control=rr.StepControl(progress=False)))
    return runs


def per_period(t: np.ndarray, difference: np.ndarray, period: float) -> np.ndarray:
    """The largest |difference| in each whole period."""
    k = (t // period).astype(int)
    whole = k < int(t[-1] // period)
    return np.array([np.max(np.abs(difference[:, whole & (k == j)])) for j in range(k[whole].max() + 1)])


def main() -> Outcome:
    scene = load_scene("paper-rub", {"speeds.outer": OUTER_HZ})
    sm = build_model(scene)
    t0 = time.perf_counter()
    rt = rig_torus(scene, sm)
    print(f"torus (torus_balance, {time.perf_counter() - t0:.1f} s):")
    for line in rt.summary()[:4]:
        print(f"  {line}")
    problem = rt.problem.problem
    stability = rr.torus_lyapunov(problem, rt.solution.z, rr.LyapunovOptions(count=COUNT, periods=PERIODS))
    for line in stability.summary():
        print(f"  {line}")
    print("  block exponents (1/s): " + ", ".join(f"{b:.3g}" for b in stability.blocks[:, 0]))
    state = np.block([[np.zeros_like(problem.M), np.eye(len(problem.M))],
                      [-np.linalg.solve(problem.M, problem.K), -np.linalg.solve(problem.M, problem.D)]])
    print(f"  the linear system's least damped motion (no contact): {np.linalg.eigvals(state).real.max():.3g} 1/s")
    period = 1.0 / rt.bases_hz[1]
    t_end = TRANSIENT_PERIODS * period
    on, off = transients(scene, sm, rt, t_end)
    A = np.array([on.outputs[o] for o in OUTPUTS])
    B = np.array([off.outputs[o] for o in OUTPUTS])
    rows = sm.model.output_rows(list(OUTPUTS))
    q, _ = rr.torus_trajectory(problem, rt.solution.z, on.t, dofs="all")
    series = rows @ q[:, :rt.problem.n_model].T
    size = np.max(np.abs(series))
    distances = per_period(on.t, B - A, period) / size
    from_torus = per_period(on.t, A - series, period) / size
    kept = distances > NOISE * distances[0]
    centres = (np.arange(len(distances)) + 0.5) * period
    rate = float(np.polyfit(centres[kept], np.log(distances[kept]), 1)[0])
    N = len(distances) - 1
    verdict_kept = "stays" if distances[-1] < distances[0] else "LEAVES"
    print(f"perturbed transients (rotorred.simulate, dt = {scene.solver.dt:g} s, {t_end:.3g} s = {TRANSIENT_PERIODS} "
          f"periods of f_H/3): the state at t = 0 scaled by 1 + {RELATIVE:g}")
    print("  distance every 30 periods: " + ", ".join(f"{d:.3g}" for d in distances[::30]))
    print(f"  the unperturbed run's distance from the torus's series: {from_torus[0]:.3g} in the first period, "
          f"{from_torus[-1]:.3g} in the last (of the torus's largest displacement {1e6 * size:.4g} um)")
    print("  | torus | exponents (1/s) | verdict | time (s) | distance, period 0 | distance, period "
          f"{N} | fitted rate (1/s) | largest exponent (1/s) |")
    exponents = ", ".join(f"{e:.3g} ± {s:.2g}" for e, s in zip(stability.exponents[:2], stability.errors[:2]))
    print(f"  | paper-rub {OUTER_HZ:g} Hz, (f_L, f_H/3), {ORDERS[0]} x {ORDERS[1]} | {exponents} | "
          f"{stability.verdict} | {stability.elapsed:.1f} | {distances[0]:.3g} | {distances[-1]:.3g} "
          f"({verdict_kept}) | {rate:.2f} | {stability.largest:.3g} ± {stability.errors[0]:.2g} |")
    print(f"  (distance: the largest |perturbed - unperturbed| at nodes 14 and 18, x and y, in the period, over the "
          f"torus's largest displacement there; fitted rate: log of the distance against time over the periods above "
          f"{NOISE:g} of the first)")
    return Outcome(stability, period, distances, from_torus, rate)


if __name__ == "__main__":
    main()
