"""What report.html costs: the Campbell command of seed-rig over 61 speeds with and without ``--no-html``.

``rotorred campbell seed-rig --speeds 0:12000:61`` runs ``ROUNDS`` times each way, alternating (with, without, with,
...), each a fresh subprocess (one BLAS thread); the table gives each way's median wall time, their difference (what
the report adds: the mode shapes at 16 speeds, one eigen-solve each, and the page with plotly.js inlined) and the
report's size. The issue's limits: at most 1 s added, at most 5 MB. Where the machine is shared, say so beside the
numbers (both ways ran in the same minutes, alternating). On a loaded machine wall times swing by seconds, so the
report's own cost is also measured in one process as CPU time (``time.process_time``, one thread): the Campbell
diagram itself, then :func:`rotorred.write_report` of it (median of ``ROUNDS``).

Run ``python validation/bench_reports.py [--rounds N]``.
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROUNDS = 5
COMMAND = ["campbell", "seed-rig", "--speeds", "0:12000:61"]


def timed(out: Path, *extra: str) -> float:
    """Wall time (s) of one run of :data:`COMMAND` into ``out``."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "import sys; from rotorred.cli import main; sys.exit(main())", *COMMAND,
                    "--out", str(out), *extra], check=True, capture_output=True, env=env)
    return time.perf_counter() - t0


def measure(rounds: int = ROUNDS) -> dict:
    """Median wall times with and without the report, their difference (s), and the report's size (bytes)."""
    times = {"report.html": [], "--no-html": []}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(rounds):
            times["report.html"].append(timed(Path(tmp) / f"with{k}"))
            times["--no-html"].append(timed(Path(tmp) / f"without{k}", "--no-html"))
        size = (Path(tmp) / "with0" / "report.html").stat().st_size
    med = {k: statistics.median(v) for k, v in times.items()}
    return {"times": times, "median": med, "added": med["report.html"] - med["--no-html"], "size": size}


def cpu_times(rounds: int = ROUNDS) -> dict:
    """Median CPU time (s) of the diagram (:func:`rotorred.campbell`) and of its report (:func:`rotorred.write_report`
    with the model and operating speed, as the command writes it), in this process."""
    import numpy as np

    import rotorred as rr

    rotor = rr.load_rotor("seed-rig")
    line = rr.Operating.line(np.linspace(0.0, 12000.0, 61), unit="rpm")
    out = {"campbell": [], "report.html": []}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(rounds):
            t0 = time.process_time()
            cd = rr.campbell(rotor, line)
            t1 = time.process_time()
            rr.write_report(cd, Path(tmp) / "report.html", model=rotor, operating_speed=rotor.speeds[cd.reference])
            t2 = time.process_time()
            out["campbell"].append(t1 - t0)
            out["report.html"].append(t2 - t1)
    return {k: statistics.median(v) for k, v in out.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=ROUNDS)
    m = measure(parser.parse_args().rounds)
    print(f"rotorred {' '.join(COMMAND)}: {len(m['times']['--no-html'])} alternating runs each way")
    print(f"{'way':>12} {'median s':>9}  runs (s)")
    for way, ts in m["times"].items():
        print(f"{way:>12} {m['median'][way]:9.2f}  " + " ".join(f"{t:.2f}" for t in ts))
    print(f"report.html adds {m['added']:.2f} s (limit 1 s); its size {m['size'] / 1e6:.2f} MB (limit 5 MB)")
    cpu = cpu_times(len(m["times"]["--no-html"]))
    print(f"CPU time in one process (median): the diagram {cpu['campbell']:.2f} s, its report {cpu['report.html']:.2f} s")


if __name__ == "__main__":
    main()
