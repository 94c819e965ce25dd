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

Against another revision (``--against REV``, e.g. ``--against 0e26dbb``): REV is extracted with
``git archive`` into a temporary folder, and the reduced model's rub transient is timed for that
tree and for this one in the same run, in alternating subprocesses (A B A B ..., ``--rounds``
pairs; each subprocess builds the model, warms up, then times ``--repeats`` runs). Reported: CPU
µs per step, min and median over all timed runs of each tree, and their ratios. The subprocess
imports the layout of either tree (``rotorred.transient.newmark``, or ``rotorred.newmark`` before
the layered subpackages).

``--step dense`` (or ``eigen``) times that form of the constant-speed step in a tree that has it (from
issue 15: ``auto`` takes the eigenbasis step), e.g. to compare this tree's dense step against REV's.

Run: ``python validation/transient_speed.py [--repeats N] [--t-end S] [--step FORM] [--against REV [--rounds N]]``.
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tarfile  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402
from types import SimpleNamespace  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
DT = 1e-5
T_END = 3.0
UNBALANCES = ((18, 2e-3, 0.0), (3, 1e-3, 0.0))  # (node, m_e (kg m), phase (rad))
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
    cpu_us: tuple = ()       # CPU µs per step of each timed run


def api() -> SimpleNamespace:
    """What the measurement needs from rotorred, in the layered layout or in the flat one before 0e26dbb."""
    try:
        from rotorred.linear.reduction import reduce_rotor
        from rotorred.model.assembly import assemble
        from rotorred.model.loads import Unbalance
        from rotorred.model.rotor_file import load_rotor
        from rotorred.transient.contact import RubPlate
        from rotorred.transient.newmark import simulate
    except ImportError:  # the flat layout
        from rotorred.assembly import assemble
        from rotorred.contact import RubPlate
        from rotorred.io import load_rotor
        from rotorred.loads import Unbalance
        from rotorred.newmark import simulate
        from rotorred.reduction import reduce_rotor
    return SimpleNamespace(reduce_rotor=reduce_rotor, assemble=assemble, Unbalance=Unbalance, load_rotor=load_rotor,
                           RubPlate=RubPlate, simulate=simulate)


def scene(rr: SimpleNamespace):
    """(rig, plate, unbalances) of the measurement."""
    rig = rr.load_rotor("seed-rig")
    return rig, rr.RubPlate.for_rotor(rig, 18), tuple(rr.Unbalance(*u) for u in UNBALANCES)


def measure(rr, model, name: str, rig, plate, unbalances, repeats: int = 3, t_end: float = T_END,
            step: str | None = None) -> SpeedRow:
    """Warm up, then time ``repeats`` runs of the scene on ``model`` (with ``step``, the constant-speed step's form,
    where the tree's ``simulate`` has that option)."""
    import inspect

    if "operating" in inspect.signature(rr.simulate).parameters:  # the option types (issue 35)
        from rotorred.model.operating import Operating
        from rotorred.transient.newmark import Loads, Recording, Scheme, StepControl

        def run(t):
            return rr.simulate(model, Operating.point(rig.speeds), t, DT, loads=Loads(unbalances), contacts=[plate],
                               scheme=Scheme(step=step or "auto"), recording=Recording(OUTPUTS, decimate=10),
                               control=StepControl(progress=False))
    else:  # a revision before them
        kw = dict(rotor=rig, unbalances=unbalances, plates=[plate], outputs=OUTPUTS, decimate=10, progress=False)
        if step is not None and "step" in inspect.signature(rr.simulate).parameters:
            kw["step"] = step

        def run(t):
            return rr.simulate(model, None, t, DT, **kw)
    warm = run(min(t_end, 0.01))
    runs = [run(t_end) for _ in range(repeats)]
    r = runs[0]
    cpu = [x.cpu_us_per_step for x in runs]
    return SpeedRow(model=name, n_dof=model.n_dof, n_steps=r.n_steps, cpu_us_min=min(cpu),
                    cpu_us_median=statistics.median(cpu),
                    wall_us_median=statistics.median(x.us_per_step for x in runs),
                    first_call_s=warm.run_time, setup_s=r.setup_time,
                    contact_fraction=r.n_contact_steps / r.n_steps,
                    newton_per_contact=r.n_newton / max(r.n_contact_steps, 1), max_newton=r.max_newton_per_solve,
                    n_substeps=r.n_substeps, cpu_us=tuple(cpu))


def worker(repeats: int, t_end: float, step: str | None = None) -> dict:
    """One subprocess of ``--against``: the reduced model's timed runs (CPU µs per step) with this process's rotorred."""
    import rotorred

    rr = api()
    rig, plate, unbalances = scene(rr)
    row = measure(rr, rr.reduce_rotor(rig, extra_nodes=(18,)), "reduced", rig, plate, unbalances, repeats, t_end,
                  step)
    return {"package": str(Path(rotorred.__file__).parent), "n_dof": row.n_dof, "n_steps": row.n_steps,
            "contact_fraction": row.contact_fraction, "cpu_us": list(row.cpu_us)}


def extract(rev: str, into: Path) -> Path:
    """``git archive REV`` of this repository, unpacked into ``into``; returns the tree's root."""
    data = subprocess.run(["git", "-C", str(ROOT), "archive", "--format=tar", rev], capture_output=True,
                          check=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(into, filter="data")
    return into


def run_worker(tree: Path, repeats: int, t_end: float, step: str | None = None) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree))
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker", "--repeats", str(repeats),
                          "--t-end", str(t_end)] + (["--step", step] if step else []), cwd=tree, env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def against(rev: str, rounds: int, repeats: int, t_end: float, step: str | None = None) -> int:
    """Time REV's tree and this one in alternating subprocesses; print min and median CPU µs/step and the ratios."""
    with tempfile.TemporaryDirectory(prefix="rotorred-against-") as tmp:
        trees = {rev: extract(rev, Path(tmp)), "this tree": ROOT}
        samples = {name: [] for name in trees}
        for k in range(rounds):
            for name, tree in trees.items():
                res = run_worker(tree, repeats, t_end, step)
                samples[name] += res["cpu_us"]
                print(f"round {k + 1}/{rounds} {name:>10}: " + " ".join(f"{u:.3f}" for u in res["cpu_us"])
                      + f" µs/step ({res['package']}, {res['n_dof']} DOFs, contact {res['contact_fraction']:.3f})",
                      flush=True)
    print(f"\nreduced seed-rig rub transient, {t_end} s at dt = {DT:g} s; CPU µs per step over "
          f"{rounds} x {repeats} timed runs per tree, alternating subprocesses")
    print(f"{'tree':>12} {'min':>8} {'median':>8}")
    stats = {name: (min(v), statistics.median(v)) for name, v in samples.items()}
    for name, (lo, med) in stats.items():
        print(f"{name:>12} {lo:8.3f} {med:8.3f}")
    (old_min, old_med), (new_min, new_med) = stats[rev], stats["this tree"]
    print(f"this tree / {rev}: min {new_min / old_min:.3f}, median {new_med / old_med:.3f}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--t-end", type=float, default=T_END)
    parser.add_argument("--against", metavar="REV", help="also time this git revision, alternating subprocesses")
    parser.add_argument("--rounds", type=int, default=5, help="subprocess pairs with --against (default 5)")
    parser.add_argument("--step", choices=("auto", "eigen", "dense"), default=None,
                        help="the constant-speed step's form in a tree that has the option (default: the tree's own)")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(args.repeats, args.t_end, args.step)))
        return 0
    if args.against:
        return against(args.against, args.rounds, args.repeats, args.t_end, args.step)
    rr = api()
    rig, plate, unbalances = scene(rr)
    t0 = time.perf_counter()
    red = rr.reduce_rotor(rig, extra_nodes=(18,))
    t_red = time.perf_counter() - t0
    full = rr.assemble(rig)
    rows = [measure(rr, red, "reduced", rig, plate, unbalances, args.repeats, args.t_end),
            measure(rr, full, "full", rig, plate, unbalances, args.repeats, args.t_end)]
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
