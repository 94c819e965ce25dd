"""Cost against model size, sparse beside dense: the seed rig refined(1, 2, 4, ..., 128), 80 to 9224 DOFs.

For each mesh and each form of the full model (``assemble(rotor, as_sparse=...)``, solved on the same path whatever
its size; dense up to ``--dense-up-to``, default refined(16), beyond which a dense eigen-solve takes minutes), one
subprocess measures, one thread
(OPENBLAS/OMP/MKL/NUMBA_NUM_THREADS=1 before numpy loads):

* ``assembly``: :func:`rotorred.model.assembly.assemble`;
* ``Campbell/speed``: one Campbell grid speed, the eigen-solution for the lowest 12 modes with the forward/backward
  basis (:func:`rotorred.linear.campbell.modes_at`: 2 x 12 + 4 candidates), the median of three speeds;
* ``unbalance/freq``: :func:`rotorred.unbalance_response` over 20 speeds (two unbalances, two outputs), per speed;
* ``reduction``: Craig-Bampton with the default boundary and 10 fixed-interface modes (the automatic count);
* ``rub 1 s``: the paper-rub scene (validation/bench_pareto.py) on that mesh's 10-mode reduced model, 1 s at
  dt = 1e-5 s (1e5 steps), its µs per step (the reduced model does not depend on the form: sparse form only).

Memory: ``MB`` is each task's peak of traced Python/numpy allocations (``tracemalloc``, in a second, untimed run of
the task; SuperLU's own work arrays are not traced), ``RSS`` the subprocess's own peak resident set after all its
tasks (``VmHWM``: validation/peak_memory.py; not ``ru_maxrss``, which on Linux a child carries from its parent),
interpreter and libraries included. The growth exponent of each task is the slope of log(cost) against log(DOFs) over
the sparse rows from refined(16) on. The issue's checks on refined(128) (``--checks``) run each in its own subprocess:
the 61-speed Campbell 0-12 000 rpm with critical speeds (default mode count), the unbalance response at 200
speeds, the automatic Craig-Bampton reduction, and the rub transient's µs per step against the unrefined rig's
(median of three alternating runs). The last check (``--scene`` runs it alone) is the user's way: ``rotorred run`` of
the paper-rub scene whose ``[rotor] file`` is the rig refined(128) written by ``Rotor.to_toml``, against
``rotorred run paper-rub`` (the unrefined rig), and the first with ``--set solver.modes=auto``, alternating, three
runs each: the µs per step, the model's build time (both from the run's summary.txt), the command's wall time and its
peak resident set (``ru_maxrss`` from ``wait4``, its own when above the check process's peak, else an error:
validation/peak_memory.py).

The ``cli_campbell`` check is the same Campbell diagram through the command line with its margins:
``rotorred campbell`` of the refined(128) rotor file at 0:12000:61 rpm with an operating range of 4000-9000 rpm (the
critical speeds, their API 684 amplification factors and API 617 margins), its wall time, CPU time and peak resident
set (as ``rotorred run``'s).

``--csv PATH`` writes the table (one row per mesh and form) as CSV, with ``#`` lines first naming the command, the
machine, its load average at the start, the commit and the date, and the checks beside it as
``PATH``'s ``_checks.csv`` (check, quantity, value); docs/data/bench_sparse.csv is this file, read by
examples/plot_sparse_scaling.py (the site's figure) and by tests/test_bench.py against docs/performance.md.

Run ``python validation/bench_sparse.py [--quick] [--checks] [--scene] [--dense-up-to N] [--plot PATH] [--csv PATH]``
(about 4 minutes with ``--checks`` on a quiet 2-core machine, 21 at a load average of 4-7).
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
REFINES = (1, 2, 4, 8, 16, 32, 64, 128)
QUICK = (1, 4, 16, 64)
TASKS = ("assembly", "campbell_speed", "unbalance_freq", "reduction", "rub_us_step")
LABELS = {"assembly": "assembly (s)", "campbell_speed": "Campbell/speed (s)", "unbalance_freq": "unbalance/freq (s)",
          "reduction": "reduction (s)", "rub_us_step": "rub µs/step"}
#: the issue's checks on refined(128) (:func:`check`)
CHECKS = ("campbell61", "cli_campbell", "unbalance200", "reduction", "rub", "cli_scene")
TOP_RPM = 12000.0
RUB_SECONDS = 1.0
DT = 1e-5


def _sibling(name: str):
    """validation/``name``.py (bench_pareto: the paper-rub case; peak_memory), imported by path once."""
    key = f"rotorred_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, HERE / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[key] = module
        spec.loader.exec_module(module)
    return sys.modules[key]


def _timed(f):
    """(result, wall time (s), traced peak (MB)) of ``f()``: timed untraced (tracemalloc slows down code that makes
    many small arrays several-fold), then run again traced for the memory."""
    t0 = time.perf_counter()
    out = f()
    seconds = time.perf_counter() - t0
    tracemalloc.start()
    f()
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return out, seconds, peak


def _rpm(x) -> np.ndarray:
    return np.asarray(x, float) * np.pi / 30.0


def worker(refine: int, as_sparse: bool, rub: bool) -> dict:
    """Every task on one mesh and form, in this process; the dense rows solve dense at every size, and the size at
    which analyses solve sparse is restored after (a test runs this in the test process)."""
    from rotorred.model import sparse

    solve_from = sparse.SOLVE_SPARSE_FROM
    try:
        if not as_sparse:
            sparse.SOLVE_SPARSE_FROM = 10**9  # the dense rows solve dense at every size (docs/model.md §24)
        return _tasks(refine, as_sparse, rub)
    finally:
        sparse.SOLVE_SPARSE_FROM = solve_from


def _tasks(refine: int, as_sparse: bool, rub: bool) -> dict:
    """Every task on one mesh and form (:func:`worker`)."""
    import rotorred as rr
    from rotorred.linear.campbell import modes_at
    from rotorred.linear.reduction import default_boundary_nodes, reduce
    from rotorred.model.assembly import assemble
    from rotorred.model.loads import Unbalance

    rotor = rr.load_rotor("seed-rig").refined(refine)
    warm = assemble(rr.load_rotor("seed-rig"), as_sparse=as_sparse)  # first calls load modules: not timed
    modes_at(warm, rr.Operating.line(_rpm([0.0, TOP_RPM])).lines(warm), 100.0, 12)
    out = {"refine": refine, "sparse": as_sparse}
    system, out["assembly"], out["assembly_mb"] = _timed(lambda: assemble(rotor, as_sparse=as_sparse))
    out["n_dof"] = system.n_dof
    lines = rr.Operating.line(_rpm([0.0, TOP_RPM])).lines(system)
    times = []
    for rpm in (2000.0, 6000.0, 10000.0):
        t0 = time.perf_counter()
        modes_at(system, lines, float(_rpm(rpm)), 12)
        times.append(time.perf_counter() - t0)
    out["campbell_speed"] = statistics.median(times)
    out["campbell_speed_mb"] = _timed(lambda: modes_at(system, lines, float(_rpm(6000.0)), 12))[2]
    sweep = rr.Operating.line(_rpm(np.linspace(300.0, TOP_RPM, 20)))
    unbalances = [Unbalance(11, 1e-5), Unbalance(16, 1e-5, 1.5)]
    _, t, out["unbalance_freq_mb"] = _timed(lambda: rr.unbalance_response(system, sweep, unbalances,
                                                                          [(13, "x"), (18, "y")]))
    out["unbalance_freq"] = t / 20
    boundary = default_boundary_nodes(rotor, (18,))
    model, out["reduction"], out["reduction_mb"] = _timed(lambda: reduce(system, boundary, n_modes=10))
    if rub:
        out["rub_us_step"] = rub_us_per_step(refine, model)
    out["rss_mb"] = _sibling("peak_memory").own_peak_mb()  # not ru_maxrss: the parent's peak on Linux
    return out


def rub_us_per_step(refine: int, model) -> float:
    """µs per step of the paper-rub scene's 1 s transient on ``model`` (a reduced model of the rig refined
    ``refine`` times), after a warm-up run that loads the compiled kernel."""
    import dataclasses

    bp = _sibling("bench_pareto")
    warm = bp.paper_rub(refine, t_end=0.01, n_periods=0)
    bp.run(model, warm, DT)
    case = dataclasses.replace(bp.paper_rub(refine, t_end=RUB_SECONDS, n_periods=0), record_start=0.0)
    return float(bp.run(model, case, DT).us_per_step)


def check(name: str) -> dict:
    """One of the issue's checks on refined(128), in this process: wall time (s), peak RSS (MB) and its result."""
    import resource

    import rotorred as rr
    from rotorred.linear.reduction import reduce_rotor
    from rotorred.model.assembly import assemble
    from rotorred.model.loads import Unbalance

    rotor = rr.load_rotor("seed-rig").refined(128)
    out = {"check": name}
    t0 = time.perf_counter()
    cpu0 = _cpu_seconds(resource.RUSAGE_SELF)
    if name == "campbell61":
        result = rr.campbell(rotor, rr.Operating.line(_rpm(np.linspace(0.0, TOP_RPM, 61))))
        out.update(n_modes=result.n_modes, n_critical=len(result.critical_speeds),
                   critical_rpm=[round(c.speed_rpm, 3) for c in result.critical_speeds[:6]])
    elif name == "unbalance200":
        rr.unbalance_response(rotor, rr.Operating.line(_rpm(np.linspace(0.0, TOP_RPM, 200))),
                              [Unbalance(11, 1e-5), Unbalance(16, 1e-5, 1.5)], [(13, "x"), (18, "y")])
    elif name == "reduction":
        red = reduce_rotor(rotor, (18,), system=assemble(rotor))
        out.update(n_modes=red.n_modes, error=red.selection.error)
    elif name == "rub":
        bp = _sibling("bench_pareto")
        models = {refine: bp.reduced_model(bp.paper_rub(refine), 10) for refine in (1, 128)}
        runs = {refine: [] for refine in models}
        for _ in range(3):  # alternating, the median of three: a busy machine moves one run by up to 60 %
            for refine, model in models.items():
                runs[refine].append(rub_us_per_step(refine, model))
        out.update({f"us_step_{refine}": statistics.median(v) for refine, v in runs.items()})
    elif name == "cli_scene":
        out.update(cli_scene_runs())
    elif name == "cli_campbell":
        out.update(cli_campbell_run(rotor))
    out["seconds"] = round(time.perf_counter() - t0, 2)
    out["cpu_s"] = round(_cpu_seconds(resource.RUSAGE_SELF) - cpu0, 2)
    out["rss_mb"] = round(_sibling("peak_memory").own_peak_mb(), 1)
    return out


def _cpu_seconds(who) -> float:
    import resource

    usage = resource.getrusage(who)
    return usage.ru_utime + usage.ru_stime


def _rotorred_command() -> str:
    import shutil

    return shutil.which("rotorred", path=str(Path(sys.executable).parent)) or shutil.which("rotorred")


def cli_campbell_run(rotor) -> dict:
    """``rotorred campbell`` of ``rotor`` (written by ``Rotor.to_toml``) at 0:12000:61 rpm, operating range
    4000-9000 rpm: its wall time (s), CPU time (s) and peak RSS (MB), its critical speeds and how many of them have
    an amplification factor (a response peak of their own)."""
    import csv
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rotor.to_toml(tmp / "rig128.toml")
        t0 = time.perf_counter()
        child = subprocess.Popen([_rotorred_command(), "campbell", str(tmp / "rig128.toml"), "--speeds",
                                  f"0:{TOP_RPM:.0f}:61", "--operating-range", "4000:9000", "--out", str(tmp / "out"),
                                  "--no-html", "-q"], stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
        wall = time.perf_counter() - t0
        if os.waitstatus_to_exitcode(status) != 0:
            raise RuntimeError(f"rotorred campbell failed: exit {os.waitstatus_to_exitcode(status)}")
        with open(tmp / "out" / "critical_speeds.csv", encoding="utf-8") as f:
            rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))][1:]
    return {"cli_wall_s": round(wall, 2), "cli_cpu_s": round(usage.ru_utime + usage.ru_stime, 2),
            "cli_rss_mb": round(_sibling("peak_memory").child_peak_mb(usage), 1), "cli_n_critical": len(rows)}


def cli_scene_runs(repeats: int = 3) -> dict:
    """``rotorred run`` of the paper-rub scene on the rig refined(128) (a rotor file written by ``Rotor.to_toml``,
    9224 DOFs), of the built-in paper-rub (80 DOFs), and of the first with ``solver.modes = "auto"``, alternating
    ``repeats`` times after one warm-up run: the medians of the µs per step and the build time (summary.txt), of the
    wall time (s) and the peak RSS (MB) of each."""
    import re
    import tempfile
    from importlib import resources

    import rotorred as rr

    command = _rotorred_command()
    runs = {"rig": [], "refined128": [], "refined128_auto": []}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rr.load_rotor("seed-rig").refined(128).to_toml(tmp / "rig128.toml")
        text = resources.files("rotorred.scenes.builtin").joinpath("paper-rub.toml").read_text(encoding="utf-8")
        (tmp / "big.toml").write_text(text.replace('preset = "seed-rig"', 'file = "rig128.toml"'), encoding="utf-8")
        scenes = {"rig": ["paper-rub"], "refined128": [str(tmp / "big.toml")],
                  "refined128_auto": [str(tmp / "big.toml"), "--set", "solver.modes=auto"]}

        def run(key: str, k: int) -> dict:
            out = tmp / f"{key}{k}"
            t0 = time.perf_counter()
            child = subprocess.Popen([command, "run", *scenes[key], "--out", str(out), "-q"])
            _, status, usage = os.wait4(child.pid, 0)
            wall = time.perf_counter() - t0
            if os.waitstatus_to_exitcode(status) != 0:
                raise RuntimeError(f"rotorred run {scenes[key]} failed: exit {os.waitstatus_to_exitcode(status)}")
            summary = (out / "summary.txt").read_text(encoding="utf-8")
            return {"us_step": float(re.search(r"\(([0-9.]+) us/step", summary).group(1)),
                    "build_s": float(re.search(r"built in ([0-9.]+) s", summary).group(1)),
                    "wall_s": wall, "rss_mb": _sibling("peak_memory").child_peak_mb(usage)}

        run("rig", 0)  # the step kernel compiled and cached once: not measured
        for k in range(repeats):
            for key in runs:
                runs[key].append(run(key, k + 1))
    out = {f"{key}_{m}": round(statistics.median(r[m] for r in v), 3) for key, v in runs.items()
           for m in ("us_step", "build_s", "wall_s", "rss_mb")}
    out["us_step_ratio"] = round(out["refined128_us_step"] / out["rig_us_step"], 3)
    return out


def _subprocess(args: list[str]) -> dict:
    done = subprocess.run([sys.executable, str(Path(__file__).resolve()), *args], capture_output=True, text=True,
                          check=False)
    if done.returncode != 0:
        raise RuntimeError(f"worker {args} failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure(refines=REFINES, dense_up_to: int = 16, progress: bool = True) -> list[dict]:
    """Every mesh, sparse and (up to ``dense_up_to``) dense, each in a fresh subprocess."""
    rows = []
    for refine in refines:
        for as_sparse in (True, False) if refine <= dense_up_to else (True,):
            rows.append(_subprocess(["--worker", json.dumps([refine, as_sparse, as_sparse])]))
            if progress:
                r = rows[-1]
                print(f"  refined({refine}) {'sparse' if as_sparse else 'dense'}: Campbell/speed "
                      f"{r['campbell_speed']:.3g} s", file=sys.stderr, flush=True)
    return rows


def exponents(rows: list[dict], from_dofs: int = 1000) -> dict[str, float]:
    """Slope of log(cost) against log(DOFs) of each task over the sparse rows of at least ``from_dofs`` DOFs."""
    sel = [r for r in rows if r["sparse"] and r["n_dof"] >= from_dofs]
    out = {}
    for task in TASKS:
        pts = [(r["n_dof"], r[task]) for r in sel if r.get(task)]
        if len(pts) >= 2:
            x, y = np.log(np.array(pts, float)).T
            out[task] = float(np.polyfit(x, y, 1)[0])
    return out


def format_table(rows: list[dict], checks: list[dict] | None = None) -> str:
    head = (f"{'mesh':<13}{'form':<7}{'DOF':>6}" + "".join(f"{LABELS[t]:>20}" for t in TASKS)
            + f"{'peak MB':>9}{'RSS MB':>8}")
    lines = ["one thread; the seed rig refined; peak MB: the largest traced peak of the tasks", head, "-" * len(head)]
    for r in sorted(rows, key=lambda r: (r["refine"], not r["sparse"])):
        cells = "".join(f"{r[t]:>20.4g}" if r.get(t) is not None else f"{'':>20}" for t in TASKS)
        peak = max(r[f"{t}_mb"] for t in ("assembly", "campbell_speed", "unbalance_freq", "reduction"))
        lines.append(f"refined({r['refine']})".ljust(13) + f"{'sparse' if r['sparse'] else 'dense':<7}{r['n_dof']:>6}"
                     + cells + f"{peak:>9.1f}{r['rss_mb']:>8.0f}")
    for r in rows:
        twin = next((d for d in rows if not d["sparse"] and d["refine"] == r["refine"]), None)
        if r["sparse"] and twin is not None and r["refine"] == max(d["refine"] for d in rows if not d["sparse"]):
            lines.append(f"dense / sparse at refined({r['refine']}), {r['n_dof']} DOFs: " + ", ".join(
                f"{LABELS[t].split(' (')[0]} {twin[t] / r[t]:.3g}x" for t in TASKS[:4]))
    lines.append("growth exponent (sparse, >= 1000 DOFs): " + ", ".join(
        f"{LABELS[t].split(' (')[0]} n^{p:.2f}" for t, p in exponents(rows).items()))
    for c in checks or ():
        if c["check"] == "cli_scene":
            lines.append(format_scene(c))
            continue
        lines.append("refined(128) check: " + ", ".join(f"{k} {v}" for k, v in c.items() if k != "check")
                     + f"  [{c['check']}]")
    return "\n".join(lines)


def markdown_table(rows: list[dict]) -> str:
    """The table of :func:`format_table` in Markdown (docs/performance.md quotes it as printed from the CSV), with
    the growth exponents of the sparse tasks from 1000 DOFs on."""
    lines = ["| mesh | form | DOF | " + " | ".join(LABELS[t] for t in TASKS) + " | peak MB | RSS MB |",
             "|---|---|---:|" + "---:|" * (len(TASKS) + 2)]
    for r in sorted(rows, key=lambda r: (r["refine"], not r["sparse"])):
        peak = max(r[f"{t}_mb"] for t in TASKS[:4])
        lines.append(f"| refined({r['refine']}) | {'sparse' if r['sparse'] else 'dense'} | {r['n_dof']} | "
                     + " | ".join(f"{r[t]:.3g}" if r.get(t) is not None else "" for t in TASKS)
                     + f" | {peak:.1f} | {r['rss_mb']:.0f} |")
    lines += ["", "Growth exponents of the sparse tasks from 1000 DOFs on (slope of log cost against log DOFs): "
              + ", ".join(f"{LABELS[t].split(' (')[0]} **n^{p:.2f}**" for t, p in exponents(rows).items()) + "."]
    return "\n".join(lines)


def markdown_checks(checks: dict[str, dict[str, str]]) -> str:
    """The issue's checks on refined(128) (:func:`read_checks`) as a Markdown table: wall and CPU time, peak RSS and
    what each found."""
    what = {"campbell61": ("61-speed Campbell 0-12 000 rpm, critical speeds (`rr.campbell`)",
                           lambda c: f"{c['n_modes']} modes, {c['n_critical']} critical speeds"),
            "cli_campbell": ("the same through `rotorred campbell`, with the API 684/617 margins",
                             lambda c: f"{c['cli_n_critical']} critical speeds with margins"),
            "unbalance200": ("unbalance response at 200 speeds", lambda c: ""),
            "reduction": ("automatic Craig-Bampton reduction", lambda c: f"{c['n_modes']} modes, whirl error "
                          f"{100 * float(c['error']):.2g} %"),
            "rub": ("paper-rub transient on its 10-mode reduced model", lambda c: f"{float(c['us_step_128']):.2f} "
                    f"µs/step against {float(c['us_step_1']):.2f} for the rig's")}
    lines = ["| check on refined(128), 9224 DOFs | wall (s) | CPU (s) | peak RSS (MB) | result |",
             "|---|---:|---:|---:|---|"]
    for name, (label, result) in what.items():
        if name not in checks:
            continue
        c = checks[name]
        wall, cpu, rss = ((c["cli_wall_s"], c["cli_cpu_s"], c["cli_rss_mb"]) if name == "cli_campbell"
                          else (c["seconds"], c["cpu_s"], c["rss_mb"]))
        lines.append(f"| {label} | {float(wall):.1f} | {float(cpu):.1f} | {float(rss):.0f} | {result(c)} |")
    return "\n".join(lines)


def markdown_ratios(rows: list[dict]) -> str:
    """Dense against sparse at the largest mesh solved both ways, each task's ratio of times in the same run."""
    refine = max((r["refine"] for r in rows if not r["sparse"]), default=None)
    pair = {r["sparse"]: r for r in rows if r["refine"] == refine}
    if refine is None or len(pair) < 2:
        return ""
    return (f"Dense against sparse at refined({refine}), {pair[True]['n_dof']} DOFs, in the same run: "
            + ", ".join(f"{LABELS[t].split(' (')[0]} **{pair[False][t] / pair[True][t]:.3g}×**" for t in TASKS[:4])
            + ".")


def markdown_scene(checks: dict[str, dict[str, str]]) -> str:
    """The ``cli_scene`` check (:func:`read_checks`) as a Markdown table: ``rotorred run`` of paper-rub on the rig
    and on refined(128) (:func:`format_scene`)."""
    c = {k: float(v) for k, v in checks["cli_scene"].items()}
    lines = ["| rotor | DOF | µs/step | build (s) | wall (s) | peak RSS (MB) |", "|---|---:|---:|---:|---:|---:|"]
    for key, label, n in (("rig", "seed-rig (preset)", 80), ("refined128", "refined(128) rotor file", 9224),
                          ("refined128_auto", 'refined(128), `solver.modes = "auto"`', 9224)):
        lines.append(f"| {label} | {n} | {c[key + '_us_step']:.3g} | {c[key + '_build_s']:.3g} | "
                     f"{c[key + '_wall_s']:.3g} | {c[key + '_rss_mb']:.0f} |")
    lines += ["", f"µs/step of refined(128) against the rig's in the same run: **{c['us_step_ratio']:.2f}×**."]
    return "\n".join(lines)


def format_scene(c: dict) -> str:
    """The ``cli_scene`` check as a table: ``rotorred run`` of paper-rub on the rig and on refined(128)."""
    lines = ["rotorred run paper-rub (median of 3 alternating runs, one thread)",
             f"{'rotor':<26}{'DOF':>6}{'µs/step':>9}{'build s':>9}{'wall s':>8}{'peak RSS MB':>13}"]
    for key, label, n in (("rig", "seed-rig (preset)", 80), ("refined128", "refined(128) rotor file", 9224),
                          ("refined128_auto", "refined(128), modes auto", 9224)):
        lines.append(f"{label:<26}{n:>6}{c[key + '_us_step']:>9.3g}{c[key + '_build_s']:>9.3g}"
                     f"{c[key + '_wall_s']:>8.3g}{c[key + '_rss_mb']:>13.0f}")
    lines.append(f"µs/step refined(128) / rig: {c['us_step_ratio']:.2f}x (the same run)")
    return "\n".join(lines)


CSV_COLUMNS = ("mesh", "form", "n_dof", *TASKS, *(f"{t}_mb" for t in TASKS[:4]), "peak_mb", "rss_mb")


def write_csv(rows: list[dict], checks: list[dict], path: str, command: str) -> list[str]:
    """The table as CSV at ``path`` (``#`` lines first: the command, the machine, the commit, the date) and the
    checks as ``<stem>_checks.csv`` beside it (check, quantity, value); the paths written."""
    import csv
    import datetime
    import platform

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    commit = subprocess.run(["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            check=False).stdout.strip() or "unknown"
    header = [f"# python validation/bench_sparse.py {command}",
              f"# machine: {' '.join(filter(None, (platform.machine(), platform.processor())))}, {os.cpu_count()} cores, "
              f"{platform.python_implementation()} {platform.python_version()}, numpy {np.__version__}, one thread; "
              f"load average at the start {os.getloadavg()[0]:.1f}",
              f"# commit {commit}, {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC"]
    with open(path, "w", encoding="utf-8", newline="") as f:
        f.write("\n".join(header) + "\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(CSV_COLUMNS)
        for r in sorted(rows, key=lambda r: (r["refine"], not r["sparse"])):
            peak = max(r[f"{t}_mb"] for t in TASKS[:4])
            w.writerow([f"refined({r['refine']})", "sparse" if r["sparse"] else "dense", r["n_dof"],
                        *(f"{r[t]:.4g}" if r.get(t) is not None else "" for t in TASKS),
                        *(f"{r[f'{t}_mb']:.4g}" for t in TASKS[:4]), f"{peak:.1f}", f"{r['rss_mb']:.0f}"])
    written = [str(path)]
    if checks:
        side = path.with_name(path.stem + "_checks.csv")
        with open(side, "w", encoding="utf-8", newline="") as f:
            f.write("\n".join(header) + "\n")
            w = csv.writer(f, lineterminator="\n")
            w.writerow(("check", "quantity", "value"))
            for c in checks:
                for k, v in c.items():
                    if k != "check":
                        w.writerow((c["check"], k, json.dumps(v) if isinstance(v, (list, dict)) else v))
        written.append(str(side))
    return written


def read_csv(path) -> tuple[list[dict], list[str]]:
    """The rows :func:`write_csv` wrote (the fields of :func:`measure`'s rows: refine, sparse, n_dof, each task and
    its ``_mb``, peak_mb, rss_mb) and its ``#`` header lines."""
    import csv

    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    header = [line[1:].strip() for line in lines if line.startswith("#")]
    rows = []
    for r in csv.DictReader(line for line in lines if not line.startswith("#")):
        row = {"refine": int(r["mesh"][len("refined("):-1]), "sparse": r["form"] == "sparse", "n_dof": int(r["n_dof"])}
        row.update({k: float(v) if v else None for k, v in r.items() if k not in ("mesh", "form", "n_dof")})
        rows.append(row)
    return rows, header


def read_checks(path) -> dict[str, dict[str, str]]:
    """The checks of :func:`write_csv` (``<stem>_checks.csv``): check -> quantity -> value (text)."""
    import csv

    with open(path, encoding="utf-8") as f:
        out: dict[str, dict[str, str]] = {}
        for r in csv.DictReader(line for line in f if not line.startswith("#")):
            out.setdefault(r["check"], {})[r["quantity"]] = r["value"]
    return out


def draw(rows: list[dict], ax1, ax2=None) -> None:
    """Cost (``ax1``) and, if given, memory (``ax2``) against DOFs, log-log, each task sparse (solid) and dense
    (dashed), the sparse growth exponents (:func:`exponents`) in the legend."""
    slopes = exponents(rows)
    for k, task in enumerate(TASKS[:4]):
        for as_sparse, style in ((True, "-o"), (False, "--s")):
            sel = sorted((r for r in rows if r["sparse"] == as_sparse and r.get(task)), key=lambda r: r["n_dof"])
            if not sel:
                continue
            growth = f" ($n^{{{slopes[task]:.2f}}}$ from 1000 DOFs)" if as_sparse and task in slopes else ""
            ax1.loglog([r["n_dof"] for r in sel], [r[task] for r in sel], style, color=f"C{k}",
                       mfc="none" if not as_sparse else None,
                       label=f"{LABELS[task].split(' (')[0]}, {'sparse' if as_sparse else 'dense'}{growth}")
            if ax2 is not None:
                ax2.loglog([r["n_dof"] for r in sel], [r[f"{task}_mb"] for r in sel], style, color=f"C{k}",
                           mfc="none" if not as_sparse else None)
    ax1.set_ylabel("wall time (s), one thread")
    for ax, title in ((ax1, "Cost against model size"), (ax2, "Memory")):
        if ax is None:
            continue
        ax.set_xlabel("full-model DOFs (seed rig refined 1 ... 128)")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", lw=0.3)
    if ax2 is not None:
        ax2.set_ylabel("peak traced allocations (MB)")
    # below the axes: inside, it hid the dense curves' middle
    (ax2 or ax1).figure.legend(*ax1.get_legend_handles_labels(), fontsize=7.5, loc="lower center", ncol=2,
                               frameon=False)


def plot(rows: list[dict], path: str) -> str:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 5.6))
    draw(rows, *fig.subplots(1, 2))
    fig.tight_layout(rect=(0, 0.15, 1, 1))
    fig.savefig(path, dpi=130)
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help=f"refined{QUICK} only")
    parser.add_argument("--checks", action="store_true", help="also the issue's checks on refined(128)")
    parser.add_argument("--scene", action="store_true", help="only `rotorred run` on refined(128) against the rig")
    parser.add_argument("--dense-up-to", type=int, default=16, help="largest refinement solved dense too")
    parser.add_argument("--plot", metavar="PATH")
    parser.add_argument("--csv", metavar="PATH", help="write the table (and the checks beside it) as CSV, e.g. "
                        "docs/data/bench_sparse.csv")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--check", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(*json.loads(args.worker))))
        return 0
    if args.check:
        print(json.dumps(check(args.check)))
        return 0
    if args.scene:
        print(format_scene(_subprocess(["--check", "cli_scene"])))
        return 0
    rows = measure(QUICK if args.quick else REFINES, args.dense_up_to)
    checks = [_subprocess(["--check", c]) for c in CHECKS] if args.checks else []
    print(format_table(rows, checks))
    if args.plot:
        print(f"plot: {plot(rows, args.plot)}")
    if args.csv:
        print("csv: " + ", ".join(write_csv(rows, checks, args.csv, " ".join(sys.argv[1:] if argv is None else argv))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
