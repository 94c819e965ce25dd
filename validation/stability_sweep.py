"""Stability sweep of the rub transient: every run ends bounded or with a clear divergence error.

Scene: the seed rig (dual rotor, reduced by Craig–Bampton with the bearing, inter-shaft and rub
nodes as boundary), both spools unbalanced, one rubbing plate at node 18, both spools run at a
common factor of their nominal speeds chosen so that the outer (rubbing) spool's speed equals
the nearest forward whirl frequency: the rig runs at a critical speed.

Grid (all combinations):
* dt from 1e-6 to 2e-4 s,
* Hertz stiffness K_nr from 1e7 to 1e11 N/m^1.5,
* clearance from touching (0) to far open (1 mm),
* friction mu_s = mu_d from 0 to 0.8.

Each run lasts ``T_END``. A run passes when it either finishes with finite records, or raises
:class:`rotorred.transient.newmark.SimulationDiverged` whose message names a time and a DOF and whose
partial records are finite. No NaN may be returned in either case.

ROSS 3.1.0 lags its rub force one step and diverges on a dual rotor at dt = 1e-4 s; here the
contact force is implicit in every step, so the dt = 1e-4 rows must be bounded.

Run: ``python validation/stability_sweep.py [--quick]``.
"""

from __future__ import annotations

import argparse
import itertools
import math
import time
from dataclasses import dataclass

import numpy as np

from rotorred.model.assembly import assemble
from rotorred.transient.contact import RubPlate
from rotorred.model.rotor_file import load_rotor
from rotorred.model.loads import Unbalance
from rotorred.linear.modal import eigen
from rotorred.model.operating import Operating
from rotorred.transient.newmark import Loads, Recording, SimulationDiverged, StepControl, simulate
from rotorred.linear.reduction import default_boundary_nodes, reduce

DTS = (1e-6, 1e-5, 1e-4, 2e-4)
STIFFNESSES = (1e7, 1e9, 1e11)
CLEARANCES = (0.0, 20e-6, 1e-3)
FRICTIONS = (0.0, 0.3, 0.8)
T_END = 0.1
UNBALANCES = (Unbalance(18, 2e-4, 0.0), Unbalance(3, 1e-4, 0.5))  # ~100 µm at node 18 at the critical


@dataclass(frozen=True)
class SweepRow:
    """One run of the sweep."""

    dt: float
    K_nr: float
    clearance: float
    mu: float
    outcome: str          # "bounded" or "diverged"
    peak_um: float        # peak |(x, y)| at node 18 over the (partial) record (µm)
    contact_fraction: float
    n_substeps: int
    message: str
    finite: bool          # every returned record is finite
    seconds: float

    @property
    def ok(self) -> bool:
        if not self.finite:
            return False
        if self.outcome == "bounded":
            return True
        return "diverged at t =" in self.message and "(" in self.message


def critical_speeds(rig, system) -> dict[str, float]:
    """Spool speeds (rad/s), the nominal ones times a common factor, at which the outer spool's speed
    equals the nearest forward whirl frequency (fixed point of 5 iterations)."""
    nominal = rig.speeds
    factor = 1.0
    for _ in range(5):
        speeds = {s: factor * w for s, w in nominal.items()}
        sol = eigen(system.M, system.damping(speeds), system.K, n_modes=12)
        w_outer = speeds["outer"]
        target = sol.frequencies[np.argmin(np.abs(sol.frequencies - w_outer))]
        factor = target / nominal["outer"]
    return {s: factor * w for s, w in nominal.items()}


def scene():
    """(rig, reduced model, speeds at the critical)."""
    rig = load_rotor("seed-rig")
    system = assemble(rig)
    model = reduce(system, default_boundary_nodes(rig, (18,)), n_modes=10)
    return rig, model, critical_speeds(rig, system)


def run_one(rig, model, speeds, dt, K_nr, clearance, mu, t_end: float = T_END) -> SweepRow:
    plate = RubPlate.for_rotor(rig, 18, K_nr=K_nr, clearance=clearance, mu_s=mu, mu_d=mu)
    outputs = [(18, "x"), (18, "y")]
    t0 = time.perf_counter()
    try:
        res = simulate(model, Operating.point(speeds), t_end, dt, loads=Loads(UNBALANCES), contacts=[plate],
                       recording=Recording(outputs, decimate=max(1, round(1e-5 / dt))),
                       control=StepControl(progress=False))
        outcome, message = "bounded", res.message
    except SimulationDiverged as exc:
        res, outcome, message = exc.result, "diverged", str(exc)
    seconds = time.perf_counter() - t0
    x, y = res.outputs[(18, "x")], res.outputs[(18, "y")]
    finite = bool(np.all(np.isfinite(x)) and np.all(np.isfinite(y)) and np.all(np.isfinite(res.t))
                  and all(np.all(np.isfinite(c.normal_force)) for c in res.contacts))
    peak = float(np.max(np.hypot(x, y))) * 1e6 if len(x) else float("nan")
    return SweepRow(dt, K_nr, clearance, mu, outcome, peak, 1.0 - res.contacts[0].fraction("open"), res.n_substeps,
                    message, finite, seconds)


def sweep(quick: bool = False) -> list[SweepRow]:
    """Run the whole grid (``quick``: the extreme values only)."""
    rig, model, speeds = scene()
    pick = (lambda v: (v[0], v[-1])) if quick else (lambda v: v)
    dts = (1e-6, 1e-4, 2e-4) if quick else DTS
    rows = []
    for dt, K, c, mu in itertools.product(dts, pick(STIFFNESSES), pick(CLEARANCES), pick(FRICTIONS)):
        rows.append(run_one(rig, model, speeds, dt, K, c, mu))
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="extreme values of each parameter (and dt = 1e-4) only")
    args = parser.parse_args(argv)
    rig, model, speeds = scene()
    print(f"seed rig, reduced to {model.n_dof} DOFs; speeds at the critical: "
          + ", ".join(f"{s} {w / (2 * math.pi):.2f} Hz" for s, w in speeds.items()) + f"; {T_END} s per run")
    rows = sweep(args.quick)
    head = (f"{'dt (s)':>8} {'K_nr (N/m^1.5)':>14} {'clear (µm)':>10} {'mu':>4} {'outcome':>9} "
            f"{'peak (µm)':>10} {'contact':>8} {'halved':>6} {'time (s)':>8}")
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r.dt:8.0e} {r.K_nr:14.0e} {r.clearance * 1e6:10.0f} {r.mu:4.1f} {r.outcome:>9} "
              f"{r.peak_um:10.2f} {r.contact_fraction:8.3f} {r.n_substeps:6d} {r.seconds:8.2f}"
              + ("" if r.outcome == "bounded" else f"   {r.message}"))
    n_bad = sum(not r.ok for r in rows)
    n_div = sum(r.outcome == "diverged" for r in rows)
    print(f"\n{len(rows)} runs: {len(rows) - n_div} bounded, {n_div} stopped with a divergence error, "
          f"{n_bad} failing the criteria (NaN returned or unclear error)")
    ross = [r for r in rows if r.dt == 1e-4]
    print(f"dt = 1e-4 s (where ROSS 3.1.0 diverges on a dual rotor): "
          f"{sum(r.outcome == 'bounded' for r in ross)} of {len(ross)} runs bounded")
    return 0 if n_bad == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
