"""Wall time of ``rotorred run`` as a user sees it: the first run after a fresh install, a warm run, and where the
time goes (the solve, the figures).

* **first run**: ``rotorred run --out DIR`` in a subprocess with empty numba and matplotlib caches
  (``NUMBA_CACHE_DIR``, ``MPLCONFIGDIR`` pointed at new folders): what a fresh install meets, numba's
  compilation of the step kernel and matplotlib's font cache included (the compilation's share as the command
  reports it on its summary line); ``--first-runs N``, each into new caches, gives their median;
* **warm run**: the same command again (caches filled), median of ``--repeats``, and its CPU time (user +
  system, the figure workers included): on 2 cores the wall time cannot fall below half of it;
* **solve**: :func:`rotorred.scenes.run.run_scene` in this process (model, both transients, spectra, line
  fit, settling, class), median of ``--repeats`` after a warm-up;
* **figures**: :func:`rotorred.plots.scene.plot_scene` in this process, one after the other, median of
  ``--repeats`` (the command draws them in worker processes while it writes the data files); then the same into
  frames prepared ahead (:func:`rotorred.plots.scene.prepare_frames`, timed apart), as the command's workers draw
  them (their fork server prepares the frames while the scene is solved);
* **data files**: :func:`rotorred.scenes.outputs.write_data`;
* **this machine's speed**: CPU seconds of a fixed Python loop (``sum(range(3e7))``, least of 3), before and after
  the rest: this VM's speed varied by 10-25 % within minutes, every row with it, so the rows are comparable
  only beside it.

Run: ``python validation/bench_run.py [--scene paper-rub] [--repeats 3] [--first-runs 1]``.
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import re  # noqa: E402
import shutil  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402


def cli_run(scene: str, out: Path, env: dict) -> float:
    """Wall time (s) of ``rotorred run SCENE --out OUT`` in a subprocess (its CPU time, with its figure workers',
    is added to :data:`CPU`)."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    command = shutil.which("rotorred", path=str(Path(sys.executable).parent)) or "rotorred"  # the installed script
    done = subprocess.run([command, "run", scene, "--out", str(out)], env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if done.returncode != 0:
        raise SystemExit(f"rotorred run failed:\n{done.stderr}")
    compiled = re.search(r"step kernel compiled in ([0-9.]+) s", done.stdout + done.stderr)
    COMPILE.append(float(compiled.group(1)) if compiled else 0.0)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    CPU.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    return seconds


#: CPU seconds of each command run (user + system, its worker processes included)
CPU: list[float] = []
#: seconds each command run compiled the step kernel, as it reports (0: loaded from numba's cache)
COMPILE: list[float] = []
#: wall seconds of each first run (new numba and matplotlib caches)
FIRST: list[float] = []


def in_process(scene_name: str, repeats: int, folder: Path) -> dict:
    """Median seconds of the solve, the figures and the data files, in this process."""
    import matplotlib

    matplotlib.use("Agg")
    from rotorred.plots.scene import plot_scene, prepare_frames, scene_frames
    from rotorred.scenes.outputs import write_data
    from rotorred.scenes.run import run_scene
    from rotorred.scenes.schema import load_scene

    scene = load_scene(scene_name, {})
    result = run_scene(scene, progress=None)  # warm-up: the kernel from the cache
    plot_scene(result, folder)
    times = {"solve": [], "figures": [], "preparing their frames": [], "figures into the prepared frames": [],
             "data files": []}
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = run_scene(scene, progress=None)
        t1 = time.perf_counter()
        plot_scene(result, folder)
        t2 = time.perf_counter()
        prepare_frames(scene_frames(scene))  # as the figure pool's fork server does
        t3 = time.perf_counter()
        plot_scene(result, folder)
        t4 = time.perf_counter()
        write_data(result, folder)
        for key, seconds in zip(times, (t1 - t0, t2 - t1, t3 - t2, t4 - t3, time.perf_counter() - t4)):
            times[key].append(seconds)
    return {k: statistics.median(v) for k, v in times.items()}


def host_speed() -> float:
    """CPU seconds of ``sum(range(30_000_000))``, least of 3: this machine's speed at the moment."""
    best = float("inf")
    for _ in range(3):
        t0 = time.process_time()
        sum(range(30_000_000))
        best = min(best, time.process_time() - t0)
    return best


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="paper-rub")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--first-runs", type=int, default=1, help="first runs, each into new caches (about 15 s each)")
    args = p.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="rotorred-bench-run-"))
    speed = [host_speed()]
    try:
        for k in range(args.first_runs):
            env = dict(os.environ, NUMBA_CACHE_DIR=str(work / f"numba{k}"), MPLCONFIGDIR=str(work / f"mpl{k}"))
            FIRST.append(cli_run(args.scene, work / "out", env))
        n_first = len(FIRST)
        warm_runs = [cli_run(args.scene, work / "out", env) for _ in range(args.repeats)]
        warm = statistics.median(warm_runs)
        parts = in_process(args.scene, args.repeats, work / "figures")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    speed.append(host_speed())
    print(f"`rotorred run {args.scene}`, {os.cpu_count()} cores, BLAS/numba threads 1")
    print("| what | seconds |")
    print("|---|---|")
    firsts = f"median of {n_first}; spread {min(FIRST):.1f}-{max(FIRST):.1f}" if n_first > 1 else "one run"
    print(f"| first run after a fresh install (empty numba and matplotlib caches; {firsts}) | "
          f"{statistics.median(FIRST):.1f} |")
    print(f"| of it, compiling the step kernel (as the command reports it; median) | "
          f"{statistics.median(COMPILE[:n_first]):.1f} |")
    print(f"| warm run (median of {args.repeats}; spread {min(warm_runs):.2f}-{max(warm_runs):.2f}) | {warm:.2f} |")
    print(f"| warm run's CPU time, its figure workers included (median) | {statistics.median(CPU[n_first:]):.2f} |")
    for k, v in parts.items():
        print(f"| {k} (in one process, median of {args.repeats}) | {v:.2f} |")
    print(f"| this machine's speed: CPU seconds of sum(range(3e7)), before and after | {speed[0]:.2f}, {speed[1]:.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
