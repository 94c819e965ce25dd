"""Craig–Bampton reduced model against the full model: the seed rig (also refined(4), refined(8))
and the Nelson–McVaugh rotor.

For each number of fixed-interface modes the table gives the reduced size, the worst relative
error of the first 8 whirl speeds over 0–1.5x the operating speed (7 speeds), the worst
relative unbalance-response error at nodes 13 and 14 (x and y) over a 151-point speed sweep
(see :func:`rotorred.linear.harmonic.response_error`), and the wall time of the reduction, of the
eigen-analyses and of the sweep. "auto" rows are the automatic choices: whirl target 0.1 %
alone, and whirl target plus 0.5 % response target over the sweep.

Choices: the rig's boundary is its bearing and inter-shaft nodes plus the rub node 18 (the
"+11,16" case also puts the unbalanced disks on the boundary, so the load needs no modes); its
unbalances are 1e-5 kg m on disks 11 (inner) and 16 (outer, phase 90 deg), at the nominal
ratio 5400/4200 rpm. The Nelson–McVaugh preset is at rest; its operating speed is taken as
10 000 rpm (the sweep 0–15 000 rpm stays below the first critical speed, ~16 000 rpm, as its
bearings are undamped); unbalance 1e-5 kg m on the disk (node 4); outputs 13 (interior,
recovered through T) and 14 (bearing).

Run ``python validation/reduced_vs_full.py [--plot PATH] [--quick]``.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from dataclasses import dataclass

# one BLAS thread, as in the test suite: the dense problems here are small, and multi-threaded
# OpenBLAS on a busy 2-core machine is many times slower on them (must be set before numpy loads)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np

from rotorred.model.assembly import assemble
from rotorred.linear.harmonic import response_error, unbalance_response
from rotorred.model.rotor_file import load_rotor
from rotorred.model.loads import Unbalance
from rotorred.model.operating import Operating
from rotorred.linear.reduction import ResponseCheck, default_boundary_nodes, reduce, whirl_error, whirl_frequencies

MODE_COUNTS = (0, 2, 4, 6, 8, 10, 12, 16, 20, 24)
SPEED_FACTORS = np.linspace(0.0, 1.5, 7)
N_SWEEP = 151
WHIRL_TARGET = 1e-3
RESPONSE_TARGET = 5e-3


@dataclass(frozen=True)
class Case:
    """One rotor and its reduced-vs-full settings."""

    label: str
    rotor: object
    extra_nodes: tuple
    operating: dict          # spool -> rad/s
    unbalances: tuple
    outputs: tuple


@dataclass(frozen=True)
class Row:
    """One line of the table."""

    label: str
    modes: str
    size: int
    whirl_error: float
    response_error: float
    t_reduce: float
    t_eigen: float
    t_response: float


def rig_case(refine: int = 1, loaded_boundary: bool = False) -> Case:
    """The seed rig; ``loaded_boundary`` also puts the unbalanced disks 11 and 16 on the boundary."""
    rig = load_rotor("seed-rig")
    rotor = rig.refined(refine)
    label = "seed-rig" if refine == 1 else f"seed-rig refined({refine})"
    extra = (18,)
    if loaded_boundary:
        label, extra = label + " +11,16", (18, 11, 16)
    return Case(label, rotor, extra, rig.speeds, (Unbalance(11, 1e-5), Unbalance(16, 1e-5, math.pi / 2)),
                ((13, "x"), (13, "y"), (14, "x"), (14, "y")))


def nelson_case() -> Case:
    rotor = load_rotor("nelson-mcvaugh")
    return Case("nelson-mcvaugh", rotor, (), {"shaft": 2 * math.pi * 10_000 / 60}, (Unbalance(4, 1e-5),),
                ((13, "x"), (13, "y"), (14, "x"), (14, "y")))


def _sweep(case: Case) -> Operating:
    """The response sweep: the first spool 0 to 1.5x its speed at ``case.operating``, the others at its ratios."""
    ref = case.rotor.spools[0].name
    ratios = {s: w / case.operating[ref] for s, w in case.operating.items() if s != ref}
    return Operating.line(np.linspace(0.0, 1.5 * case.operating[ref], N_SWEEP), ref, ratios=ratios)


def run_case(case: Case, mode_counts=MODE_COUNTS) -> list[Row]:
    """Full model, each mode count and the automatic choices, as table rows."""
    t0 = time.perf_counter()
    system = assemble(case.rotor)
    t_asm = time.perf_counter() - t0
    speeds = [{s: f * w for s, w in case.operating.items()} for f in SPEED_FACTORS]
    t0 = time.perf_counter()
    reference = [whirl_frequencies(system, s) for s in speeds]
    t_eig_full = time.perf_counter() - t0
    sweep = _sweep(case)
    args = (sweep, case.unbalances, case.outputs)
    t0 = time.perf_counter()
    full = unbalance_response(system, *args)
    t_resp_full = time.perf_counter() - t0
    rows = [Row(case.label, "full", system.n_dof, 0.0, 0.0, t_asm, t_eig_full, t_resp_full)]
    boundary = default_boundary_nodes(case.rotor, case.extra_nodes)
    n_interior = system.n_dof - 4 * len(boundary)

    def row(modes_label, **kwargs):
        t0 = time.perf_counter()
        red = reduce(system, boundary, **kwargs)
        t_red = time.perf_counter() - t0
        t0 = time.perf_counter()
        w_err = whirl_error(reference, red, speeds, n_check=8)
        t_eig = time.perf_counter() - t0
        t0 = time.perf_counter()
        got = unbalance_response(red, *args)
        t_resp = time.perf_counter() - t0
        label = modes_label if modes_label != "auto" else f"auto {red.n_modes}"
        return Row(case.label, label, red.n_dof, w_err, response_error(full, got), t_red, t_eig, t_resp)

    for n in mode_counts:
        if n <= n_interior:
            rows.append(row(str(n), n_modes=n))
    sel_speeds = [{s: f * w for s, w in case.operating.items()} for f in (0.0, 0.5, 1.0, 1.5)]
    rows.append(row("auto", check_speeds=sel_speeds, target=WHIRL_TARGET))
    check = ResponseCheck(case.unbalances, sweep, case.outputs, target=RESPONSE_TARGET)
    r = row("auto", check_speeds=sel_speeds, target=WHIRL_TARGET, response=check)
    rows.append(Row(r.label, r.modes + " (+resp)", r.size, r.whirl_error, r.response_error, r.t_reduce,
                    r.t_eigen, r.t_response))
    return rows


def all_interior_modes_error(case: Case, factors=(0.0, 0.7, 1.5)) -> float:
    """Worst relative difference of all eigenvalues, every interior mode kept (round-off)."""
    from rotorred.linear.modal import eigen
    system = assemble(case.rotor)
    boundary = default_boundary_nodes(case.rotor, case.extra_nodes)
    red = reduce(system, boundary, n_modes=system.n_dof - 4 * len(boundary))
    worst = 0.0
    for f in factors:
        s = {k: f * w for k, w in case.operating.items()}
        a = eigen(system.M, system.damping(s), system.K).eigenvalues
        b = eigen(red.M, red.damping(s), red.K).eigenvalues
        worst = max(worst, float(np.max(np.abs(a - b) / np.abs(a))))
    return worst


def print_table(rows: list[Row]) -> None:
    print(f"{'model':<26} {'modes':>14} {'size':>5} {'whirl err 8 modes':>18} {'resp err 13/14':>15} "
          f"{'t reduce':>9} {'t eigen':>8} {'t sweep':>8}")
    for r in rows:
        we = "-" if r.modes == "full" else f"{100 * r.whirl_error:.2e} %"
        re = "-" if r.modes == "full" else f"{100 * r.response_error:.2e} %"
        t_red = f"{r.t_reduce:.3f}s" + ("*" if r.modes == "full" else " ")
        print(f"{r.label:<26} {r.modes:>14} {r.size:>5} {we:>18} {re:>15} {t_red:>9} {r.t_eigen:>7.3f}s "
              f"{r.t_response:>7.3f}s")


def plot(results: dict[str, list[Row]], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.4))
    for label, rows in results.items():
        pts = [r for r in rows if r.modes.isdigit()]
        n = [int(r.modes) for r in pts]
        line, = a1.semilogy(n, [max(100 * r.whirl_error, 1e-12) for r in pts], "o-", ms=3, label=label)
        a2.semilogy(n, [max(100 * r.response_error, 1e-12) for r in pts], "o-", ms=3, color=line.get_color(),
                    label=label)
    a1.axhline(100 * WHIRL_TARGET, color="k", ls="--", lw=0.8, label="target 0.1 %")
    a2.axhline(100 * RESPONSE_TARGET, color="k", ls="--", lw=0.8, label="target 0.5 %")
    a1.set_title("first 8 whirl speeds, 0-1.5x operating speed", fontsize=10)
    a2.set_title("unbalance response at nodes 13, 14 over the sweep", fontsize=10)
    for a in (a1, a2):
        a.set_xlabel("fixed-interface modes kept")
        a.set_ylabel("worst relative error (%)")
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle("Craig-Bampton reduced vs full model")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> dict[str, list[Row]]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", default=None, help="PNG path for error against modes")
    parser.add_argument("--quick", action="store_true", help="skip the refined meshes")
    args = parser.parse_args(argv)
    cases = [rig_case(1), rig_case(1, loaded_boundary=True), nelson_case()]
    if not args.quick:
        cases[2:2] = [rig_case(4), rig_case(8)]
    results = {}
    for case in cases:
        results[case.label] = run_case(case)
    print_table([r for rows in results.values() for r in rows])
    print("(* full rows: assembly time; t eigen = 7 complex eigen-analyses, t sweep = "
          f"{N_SWEEP}-point unbalance sweep)")
    for case in (rig_case(1), nelson_case()):
        print(f"{case.label}: every interior mode kept, worst eigenvalue difference "
              f"{all_interior_modes_error(case):.2e} (relative) at 0, 0.7, 1.5x operating speed")
    if args.plot:
        plot(results, args.plot)
        print(f"wrote {args.plot}")
    return results


if __name__ == "__main__":
    main()
