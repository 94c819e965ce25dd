"""Cost per step of the rig's rub transient, reduced and full model.

Scene: the seed rig at its nominal speeds (inner 70 Hz, outer 90 Hz), unbalance on both spools
(node 18: 2e-3 kg m, about 65 µm steady response there, above the 40 µm clearance; node 3:
1e-3 kg m), one default :class:`rotorred.transient.contact.RubPlate` facing the disk at node 18
(Navier-plate bending, Hertz with Hunt–Crossley damping, Coulomb friction). 3 s at dt = 1e-5 s
(3e5 steps) from rest, outputs node 14 y and node 18 x, y every 10th step.

Reduced model: :func:`rotorred.linear.reduction.reduce_rotor` with the rub node on the boundary
(automatic mode count). Full model: the 80-DOF assembly.

Timing: one warm-up run per model loads (or compiles) the numba kernel; then ``--repeats`` runs,
reporting the step loop's CPU time per step of this process (``TransientResult.cpu_us_per_step``,
robust to other load on the machine; min and median) and the wall time per step. Threads are
pinned to one.

For comparison (quoted by the project's issue, not measured here): ROSS 3.1.0 spends
270-830 µs per Newmark step with its rub on a 120-DOF rotor.

Run: ``python validation/transient_speed.py [--repeats N] [--t-end S]``.
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402

from rotorred.model.assembly import assemble  # noqa: E402
from rotorred.transient.contact import RubPlate  # noqa: E402
from rotorred.model.rotor_file import load_rotor  # noqa: E402
from rotorred.model.loads import Unbalance  # noqa: E402
from rotorred.transient.newmark import simulate  # noqa: E402
from rotorred.linear.reduction import reduce_rotor  # noqa: E402

DT = 1e-5
T_END = 3.0
UNBALANCES = (Unbalance(18, 2e-3, 0.0), Unbalance(3, 1e-3, 0.0))
OUTPUTS = ((14, "y"), (18, "x"), (18, "y"))


@dataclass(frozen=True)
class SpeedRow:
    """Measured cost of one model."""

    model: str
    n_dof: int
    n_steps: int
    cpu_us_min: float
    cpu_us_median: float
    wall_us_median: float
    first_call_s: float      # wall time of the warm-up run's step loop (kernel load or compile included)
    setup_s: float           # matrix preparation (s)
    contact_fraction: float  # fraction of steps with a plate touching
    newton_per_contact: float
    max_newton: int
    n_substeps: int


def scene():
    rig = load_rotor("seed-rig")
    return rig, RubPlate.for_rotor(rig, 18)


def measure(model, name: str, rig, plate, repeats: int = 3, t_end: float = T_END) -> SpeedRow:
    """Warm up, then time ``repeats`` runs of the scene on ``model``."""
    kw = dict(rotor=rig, unbalances=UNBALANCES, plates=[plate], outputs=OUTPUTS, decimate=10, progress=False)
    warm = simulate(model, None, min(t_end, 0.01), DT, **kw)
    runs = [simulate(model, None, t_end, DT, **kw) for _ in range(repeats)]
    r = runs[0]
    cpu = [x.cpu_us_per_step for x in runs]
    return SpeedRow(model=name, n_dof=model.n_dof, n_steps=r.n_steps, cpu_us_min=min(cpu),
                    cpu_us_median=statistics.median(cpu),
                    wall_us_median=statistics.median(x.us_per_step for x in runs),
                    first_call_s=warm.run_time, setup_s=r.setup_time,
                    contact_fraction=r.n_contact_steps / r.n_steps,
                    newton_per_contact=r.n_newton / max(r.n_contact_steps, 1), max_newton=r.max_newton_per_solve,
                    n_substeps=r.n_substeps)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--t-end", type=float, default=T_END)
    args = parser.parse_args(argv)
    rig, plate = scene()
    t0 = time.perf_counter()
    red = reduce_rotor(rig, extra_nodes=(18,))
    t_red = time.perf_counter() - t0
    full = assemble(rig)
    rows = [measure(red, "reduced", rig, plate, args.repeats, args.t_end),
            measure(full, "full", rig, plate, args.repeats, args.t_end)]
    print(f"seed-rig rub transient: {args.t_end} s at dt = {DT:g} s ({rows[0].n_steps} steps), "
          f"{args.repeats} timed runs per model; reduction ({red.selection.describe()}) took {t_red:.1f} s")
    head = (f"{'model':>8} {'DOFs':>5} {'CPU µs/step min':>15} {'median':>7} {'wall µs/step':>12} "
            f"{'1st call (s)':>12} {'setup (s)':>9} {'contact':>8} {'Newton/contact':>14} {'max':>4} {'halved':>6}")
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r.model:>8} {r.n_dof:5d} {r.cpu_us_min:15.3f} {r.cpu_us_median:7.3f} {r.wall_us_median:12.3f} "
              f"{r.first_call_s:12.2f} {r.setup_s:9.3f} {r.contact_fraction:8.3f} {r.newton_per_contact:14.2f} "
              f"{r.max_newton:4d} {r.n_substeps:6d}")
    print(f"\nfull / reduced cost per step: {rows[1].cpu_us_min / rows[0].cpu_us_min:.2f}x; "
          f"target: <= 1 µs per step on the reduced model; ROSS 3.1.0 (quoted): 270-830 µs per step")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
