"""Cost as the model grows: full model against Craig–Bampton, seed rig refined(1, 2, 4, 8, 16).

Each configuration runs the paper-rub transient (``bench_pareto.paper_rub``: the one definition of
the scene, started from the linear steady state, dt = 1e-5 s, recorded every 10th step) in its
own subprocess, so that the peak resident memory belongs to that configuration alone:

* ``µs/step``: the compiled step loop's wall time per step (``TransientResult.us_per_step``),
  median of ``--repeats`` runs after a warm-up run; threads pinned to one core's worth
  (NUMBA/OMP/OPENBLAS/MKL_NUM_THREADS=1, set before numpy is imported). ``cpu µs/step``: the
  process CPU time of the same runs, set-up excluded (two run lengths subtracted), which a busy
  machine disturbs less than wall time.
* the reduced models run the paper's full length, 3 s = 3x10^5 steps (``run (s)``: that run's
  step loop); the full models run fewer steps (about 1 s of work each).
* memory: ``traced MB`` is the peak of Python/numpy allocations (``tracemalloc``) during assembly,
  reduction and one ``simulate`` call; ``RSS MB`` is the subprocess's peak resident set
  (``resource.getrusage(RUSAGE_SELF).ru_maxrss``), which includes the interpreter, numpy,
  scipy and numba (see the baseline row: a process that imports everything and runs the
  smallest case).
* compile time: the step kernel compiled into an empty numba cache (a fresh ``NUMBA_CACHE_DIR``)
  and then loaded from that cache by a new process; reported separately from every run time.

Run: ``python validation/bench_scaling.py [--quick] [--repeats N] [--plot PATH]``.
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import importlib.util  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).resolve().parent
REFINES = (1, 2, 4, 8, 16)
MODES = (10, 24)                 # fixed-interface modes: 10 (the automatic count), 24 (the scene's, < 0.2 % error)
DT = 1e-5                        # s
PAPER_STEPS = 300_000            # the paper's run: 3 s at 1e-5 s
DECIMATE = 10                    # record every 1e-4 s
QUICK = dict(refines=(1, 4, 16), modes=(10,), repeats=1, paper_steps=100_000)


def _bench_pareto():
    """The sibling script ``bench_pareto.py`` (home of the paper-rub configuration), imported by path."""
    name = "rotorred_bench_pareto"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, HERE / "bench_pareto.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def full_steps(n_dof: int, paper_steps: int = PAPER_STEPS) -> int:
    """Steps for a full-model timing run: about 3e9 / n² (about 1 s of work), 2000 .. ``paper_steps``."""
    return int(min(paper_steps, max(2000, round(3e9 / n_dof**2, -3))))


def worker(refine: int, n_modes: int | None, steps: int, repeats: int) -> dict:
    """Measure one configuration in this process (called in a subprocess by :func:`measure`)."""
    import resource
    import tracemalloc

    from rotorred.model.assembly import assemble

    bp = _bench_pareto()
    t_end = steps * DT
    case = dataclasses.replace(bp.paper_rub(refine, t_end=t_end, n_periods=0), record_start=0.0)
    # warm-up: load the compiled kernel (not traced, not timed)
    bp.run(assemble(bp.paper_rub(1, t_end=0.01, n_periods=0).rotor), bp.paper_rub(1, t_end=0.01, n_periods=0), DT)

    tracemalloc.start()
    t0 = time.perf_counter()
    system = assemble(case.rotor)
    model = system if n_modes is None else bp.reduced_model(case, n_modes, system)
    t_model = time.perf_counter() - t0
    short = bp.paper_rub(refine, t_end=min(t_end, 0.01), n_periods=0)
    first = _run(bp, model, short)
    traced = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()

    walls, cpus, us, runs = [], [], [], []
    for _ in range(repeats):
        c0, w0 = time.process_time(), time.perf_counter()
        res = _run(bp, model, case)
        cpus.append(time.process_time() - c0)
        walls.append(time.perf_counter() - w0)
        us.append(res.us_per_step)
        runs.append(res.run_time)
    # CPU time of the set-up (and recording overhead outside the loop): a run of 1/10 the length
    c0 = time.process_time()
    short_case = dataclasses.replace(bp.paper_rub(refine, t_end=t_end / 10, n_periods=0), record_start=0.0)
    short_res = _run(bp, model, short_case)
    c_short = time.process_time() - c0
    # meaningful only when the run is long against the clock's resolution and the set-up
    cpu_us = (1e6 * (statistics.median(cpus) - c_short) / (res.n_steps - short_res.n_steps)
              if statistics.median(cpus) > 0.05 else float("nan"))
    return dict(refine=refine, n_modes=n_modes, n_dof=int(model.M.shape[0]), n_full=int(system.M.shape[0]),
                steps=int(res.n_steps), us_per_step=statistics.median(us), us_spread=(min(us), max(us)),
                cpu_us_per_step=cpu_us, run_time=statistics.median(runs), wall=statistics.median(walls),
                setup_time=float(first.setup_time), model_time=t_model, traced_mb=traced / 2**20,
                rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                contact_steps=int(res.n_contact_steps))


def _run(bp, model, case):
    q0, v0 = bp.steady_state(model, case)
    from rotorred.model.operating import Operating
    from rotorred.transient.newmark import Initial, Loads, Recording, StepControl, simulate
    return simulate(model, Operating.point(case.speeds), case.t_end, DT, loads=Loads(case.unbalances),
                    contacts=case.plates, recording=Recording(case.outputs, decimate=DECIMATE),
                    start=Initial(q0=q0, v0=v0), control=StepControl(progress=False))


def _subprocess(args: list[str], env: dict | None = None) -> dict:
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), *args], capture_output=True, text=True,
                         env={**os.environ, **(env or {})}, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"worker {args} failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure(refine: int, n_modes: int | None, steps: int, repeats: int) -> dict:
    """One configuration in a fresh subprocess; returns the worker's dict."""
    spec = {"refine": refine, "n_modes": n_modes, "steps": steps, "repeats": repeats}
    return _subprocess(["--worker", json.dumps(spec)])


def compile_times() -> dict:
    """Kernel compile time into an empty numba cache, then load time from that cache (new processes)."""
    with tempfile.TemporaryDirectory(prefix="rotorred-numba-") as cache:
        cold = _subprocess(["--first-call"], env={"NUMBA_CACHE_DIR": cache})
        warm = _subprocess(["--first-call"], env={"NUMBA_CACHE_DIR": cache})
    return {"compile": cold["first"] - cold["second"], "cache_load": warm["first"] - warm["second"],
            "first_cold": cold["first"], "first_cached": warm["first"], "run": warm["second"]}


def first_call() -> dict:
    """Time of the first and of the second tiny rub run in this process (s)."""
    from rotorred.model.assembly import assemble
    bp = _bench_pareto()
    case = bp.paper_rub(1, t_end=0.01, n_periods=0)
    system = assemble(case.rotor)
    times = []
    for _ in range(2):
        t0 = time.perf_counter()
        bp.run(system, case, DT)
        times.append(time.perf_counter() - t0)
    return {"first": times[0], "second": times[1]}


@dataclass(frozen=True)
class Scaling:
    rows: list
    compile: dict


def scaling(refines=REFINES, modes=MODES, repeats: int = 3, paper_steps: int = PAPER_STEPS,
            progress: bool = True) -> Scaling:
    """Measure every (refine, model) configuration and the compile time."""
    rows = []
    for refine in refines:
        n_full = 4 * (1 + 18 * refine + 1)  # 18 elements on two spools: 18 refine + 2 nodes
        for k in (None, *modes):
            steps = full_steps(n_full, paper_steps) if k is None else paper_steps
            row = measure(refine, k, steps, repeats)
            rows.append(row)
            if progress:
                print(f"  measured refined({refine}) {'full' if k is None else f'CB {k}'}: "
                      f"{row['us_per_step']:.2f} µs/step", file=sys.stderr, flush=True)
    return Scaling(rows=rows, compile=compile_times())


def format_table(s: Scaling) -> str:
    head = (f"{'mesh':<12} {'model':<6} {'DOF':>5} {'steps':>7} {'µs/step':>9} {'spread':>13} {'cpu µs/step':>11} "
            f"{'run (s)':>8} {'setup (s)':>9} {'model (s)':>9} {'traced MB':>9} {'RSS MB':>7} {'contact':>7}")
    lines = ["threads pinned: NUMBA/OMP/OPENBLAS/MKL_NUM_THREADS=1; paper-rub transient, dt = 1e-5 s, record every "
             "10th step", head, "-" * len(head)]
    for r in s.rows:
        name = "full" if r["n_modes"] is None else f"CB {r['n_modes']}"
        mesh = f"refined({r['refine']})"
        lines.append(f"{mesh:<12} {name:<6} {r['n_dof']:>5} {r['steps']:>7} "
                     f"{r['us_per_step']:>9.3f} {r['us_spread'][0]:>6.2f}-{r['us_spread'][1]:<6.2f} "
                     f"{r['cpu_us_per_step']:>11.3f} {r['run_time']:>8.3f} {r['setup_time']:>9.3f} "
                     f"{r['model_time']:>9.3f} {r['traced_mb']:>9.1f} {r['rss_mb']:>7.0f} {r['contact_steps']:>7}")
    c = s.compile
    lines.append(f"step kernel: compile into an empty numba cache {c['compile']:.2f} s "
                 f"(first run {c['first_cold']:.2f} s); a new process loading it from the cache "
                 f"{c['cache_load']:.2f} s (first run {c['first_cached']:.2f} s, "
                 f"second {c['run']:.3f} s)")
    for k in sorted({r["n_modes"] for r in s.rows if r["n_modes"] is not None}):
        sel = [r for r in s.rows if r["n_modes"] == k]
        us = [r["us_per_step"] for r in sel]
        lines.append(f"CB {k}: µs/step from {min(us):.3f} to {max(us):.3f} across "
                     f"refined({', '.join(str(r['refine']) for r in sel)}); "
                     f"{sel[0]['steps']} steps take {min(r['run_time'] for r in sel):.3f}-"
                     f"{max(r['run_time'] for r in sel):.3f} s")
    return "\n".join(lines)


def plot(s: Scaling, path: str) -> str:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 4.2))
    ax1, ax2 = fig.subplots(1, 2)
    for k, style in zip([None, *sorted({r["n_modes"] for r in s.rows if r["n_modes"] is not None})],
                        ["ko-", "C0s-", "C1^-", "C2v-"]):
        sel = sorted([r for r in s.rows if r["n_modes"] == k], key=lambda r: r["refine"])
        label = "full" if k is None else f"CB {k} modes"
        ax1.loglog([r["n_full"] for r in sel], [r["us_per_step"] for r in sel], style, label=f"{label}, wall")
        cpu = [(r["n_full"], r["cpu_us_per_step"]) for r in sel if r["cpu_us_per_step"] == r["cpu_us_per_step"]]
        if cpu:
            ax1.loglog(*zip(*cpu), style[:2] + ":", mfc="none", label=f"{label}, CPU time")
        ax2.loglog([r["n_full"] for r in sel], [r["traced_mb"] for r in sel], style, label=label)
    ax1.axhline(1.0, color="0.5", ls=":", lw=0.8)
    ax1.set_xlabel("full-model DOF (refined 1, 2, 4, 8, 16)")
    ax1.set_ylabel("time per step (µs), one thread")
    ax1.set_title("Cost per step, rub transient", fontsize=10)
    ax2.set_xlabel("full-model DOF (refined 1, 2, 4, 8, 16)")
    ax2.set_ylabel("peak traced allocations (MB)")
    ax2.set_title("Memory: assembly + reduction + simulate", fontsize=10)
    for ax in (ax1, ax2):
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="refined(1, 4, 16), CB 10 only, one repeat, 1e5 steps")
    parser.add_argument("--repeats", type=int, default=None)
    parser.add_argument("--plot", metavar="PATH")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--first-call", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        spec = json.loads(args.worker)
        print(json.dumps(worker(spec["refine"], spec["n_modes"], spec["steps"], spec["repeats"])))
        return 0
    if args.first_call:
        print(json.dumps(first_call()))
        return 0
    opts = dict(refines=REFINES, modes=MODES, repeats=3, paper_steps=PAPER_STEPS)
    if args.quick:
        opts.update(QUICK)
    if args.repeats is not None:
        opts["repeats"] = args.repeats
    s = scaling(**opts)
    print(format_table(s))
    if args.plot:
        print(f"plot: {plot(s, args.plot)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
