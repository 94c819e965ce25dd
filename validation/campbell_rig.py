"""Seed rig (Xu et al. 2016): Campbell diagram, critical speeds, margin to the operating point, timing.

The spools turn at the paper's ratio Omega_H / Omega_L = 90 / 70 (outer / inner); the x-axis is the
inner-spool speed, 0-12000 rpm in 61 speeds; excitation lines 1x inner and 1x outer. The operating
point is inner 4200 rpm (70 Hz), outer 5400 rpm (90 Hz).

Separation margin. A critical speed is a reference (inner) speed Omega_c at which a whirl curve meets
a 1x line. On the 1x inner line the inner spool's unbalance resonates when the inner spool turns at
Omega_c; on the 1x outer line the outer spool's unbalance resonates when the outer spool turns at
ratio x Omega_c. Both spools hold the fixed ratio, so in either case the machine runs at the critical
when the inner speed is Omega_c, and the margin of the operating point is

    margin = |Omega_c - Omega_op| / Omega_op,   Omega_op = 4200 rpm (inner),

(the same number as |ratio Omega_c - 5400 rpm| / 5400 rpm for the outer spool). The requirement is
margin >= 10 % for every critical speed (cf. API 684's separation margin, relative to the operating
speed).

Run: ``python validation/campbell_rig.py [--plot PATH]``.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import time

import dataclasses

import numpy as np
import scipy.linalg as sla

from rotorred.model.assembly import assemble
from rotorred.linear.campbell import CampbellResult, campbell
from rotorred.model.operating import Operating
from rotorred.model.rotor_file import load_rotor
from rotorred.model.rotor import Rotor

RATIO = 90.0 / 70.0            # Omega_H / Omega_L = outer / inner
OPERATING_RPM = 4200.0         # inner spool (70 Hz); outer 5400 rpm (90 Hz)
SPEEDS_RPM = np.linspace(0.0, 12000.0, 61)
REQUIRED_MARGIN = 0.10
N_MODES = 10  # enough to hold every curve that meets a 1x line below 12000 rpm (checked by `completeness`)


def rig_campbell(n_modes: int = N_MODES) -> CampbellResult:
    """Campbell diagram of the seed rig at Omega_H/Omega_L = 90/70 over inner 0-12000 rpm (61 speeds)."""
    return campbell(load_rotor("seed-rig"), operating(), n_modes=n_modes, harmonics=(1,))


def operating() -> Operating:
    """The speed line of the rig's diagram: inner 0-12000 rpm (61 speeds), outer at RATIO."""
    return Operating.line(SPEEDS_RPM, "inner", ratios={"outer": RATIO}, unit="rpm")


def margins(result: CampbellResult, operating_rpm: float = OPERATING_RPM) -> list[tuple[object, float]]:
    """(critical speed, |Omega_c - Omega_op| / Omega_op) for every critical speed, Omega on the reference axis."""
    return [(c, abs(c.speed_rpm - operating_rpm) / operating_rpm) for c in result.critical_speeds]


def min_margin(result: CampbellResult | None = None) -> float:
    """Smallest separation margin of the operating point from a critical speed (-)."""
    result = result or rig_campbell()
    return min(m for _, m in margins(result))


def undamped(rotor: Rotor) -> Rotor:
    """``rotor`` without bearing, inter-shaft bearing and Rayleigh damping."""
    def strip(b):
        return dataclasses.replace(b, c_xx=0.0, c_yy=0.0, c_xy=0.0, c_yx=0.0)
    return dataclasses.replace(rotor, bearings=tuple(map(strip, rotor.bearings)),
                               intershaft_bearings=tuple(map(strip, rotor.intershaft_bearings)), rayleigh=(0.0, 0.0))


def undamped_critical_speeds(rotor: Rotor, ratios: dict[str, float], spool: str, harmonic: float,
                             top: float) -> np.ndarray:
    """All critical speeds <= ``top`` (rad/s, reference spool) of an undamped rotor, with no Campbell diagram.

    q = v e^{i w t} with w = c Omega, c = harmonic x Omega_spool / Omega_ref, in M q'' + Omega G q' + K q = 0,
    G = sum_s r_s G_s, gives K v = Omega^2 (c^2 M - i c G) v: the Hermitian-definite problem
    B v = mu K v (K positive definite), mu = 1 / Omega^2. Damping is ignored (C must be 0 for exactness).
    """
    sm = assemble(rotor, as_sparse=False)  # the dense reference, whatever the size
    G = sum(r * sm.G[s] for s, r in ratios.items())
    c = harmonic * ratios[spool]
    mu = sla.eigh(c * c * sm.M - 1j * c * G, sm.K, eigvals_only=True)
    W = 1 / np.sqrt(mu[mu > 0])
    return np.sort(W[W <= top])


def completeness(result: CampbellResult) -> tuple[int, float]:
    """Check that the rig's Campbell ``result`` holds every 1x critical speed in its range.

    The Campbell diagram of the undamped rig (same speeds, ratio 90/70, reference and number of
    tracked modes) must find every critical speed of the Hermitian formulation
    (:func:`undamped_critical_speeds`: all modes, no tracking) to 1e-8; the damped ``result`` must have
    the same crossings (same line, same mode, in the same order).

    Returns
    -------
    n_missing : int
        Undamped critical speeds not found, plus crossings the damped result lacks or adds.
    damping_shift : float
        Largest |Omega_c,damped - Omega_c,undamped| / Omega_c,undamped (-).
    """
    bare_rotor = undamped(load_rotor("seed-rig"))
    bare = campbell(bare_rotor, result.operating, n_modes=result.n_modes, harmonics=(1,))
    missing = 0
    for spool in bare.speed_ratios:
        found = np.array([c.speed for c in bare.critical_speeds if c.spool == spool])
        for W in undamped_critical_speeds(bare_rotor, bare.speed_ratios, spool, 1.0, result.speeds[-1]):
            if not len(found) or np.min(np.abs(found - W)) > 1e-8 * W:
                missing += 1
    damped = sorted((c for c in result.critical_speeds if c.harmonic == 1.0), key=lambda c: (c.spool, c.mode, c.speed))
    plain = sorted(bare.critical_speeds, key=lambda c: (c.spool, c.mode, c.speed))
    if [(c.spool, c.mode) for c in damped] != [(c.spool, c.mode) for c in plain]:
        return missing + max(1, abs(len(damped) - len(plain))), math.inf
    shift = max(abs(a.speed - b.speed) / b.speed for a, b in zip(damped, plain))
    return missing, float(shift)


def timing(repeats: int = 3) -> tuple[float, float, int]:
    """(first call (s), best of ``repeats`` (s), number of speeds) of the 61-speed rig Campbell after import."""
    rotor = load_rotor("seed-rig")
    line = operating()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        campbell(rotor, line, n_modes=N_MODES)
        times.append(time.perf_counter() - t0)
    return times[0], min(times), line.n_points


def eigen_time(repeats: int = 10) -> float:
    """Best time (s) of one :func:`rotorred.linear.modal.eigen` call on the rig (the unit of work per speed)."""
    from rotorred.linear.modal import eigen

    rotor = load_rotor("seed-rig")
    sm = assemble(rotor)
    D = sm.damping(rotor.speeds)
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        eigen(sm.M, D, sm.K)
        best = min(best, time.perf_counter() - t0)
    return best


def timing_single_thread_blas() -> tuple[float, float]:
    """(best-of-3 Campbell time (s), one eigen-solve (s)) in a fresh process with one BLAS thread."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    code = "import runpy, sys; m = runpy.run_path(sys.argv[1]); print(m['timing']()[1], m['eigen_time']())"
    out = subprocess.run([sys.executable, "-c", code, os.path.abspath(__file__)], env=env,
                         capture_output=True, text=True, check=True)
    campbell_s, eigen_s = out.stdout.strip().splitlines()[-1].split()
    return float(campbell_s), float(eigen_s)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plot", metavar="PATH", help="write the Campbell diagram as a PNG")
    args = p.parse_args(argv)
    result = rig_campbell()
    print(f"seed rig, Omega_outer/Omega_inner = 90/70 = {RATIO:.4f}, inner 0-12000 rpm, {len(SPEEDS_RPM)} speeds")
    print(f"{'inner rpm':>10} {'outer rpm':>10} {'line':>9} {'mode':>4} {'freq Hz':>8} {'whirl':>9} "
          f"{'log dec':>8} {'margin':>7}")
    for c, m in margins(result):
        print(f"{c.speed_rpm:10.1f} {c.speed_rpm * RATIO:10.1f} {c.line:>9} {c.mode + 1:4d} {c.frequency_hz:8.2f} "
              f"{c.whirl:>9} {c.log_dec:8.4f} {100 * m:6.1f}%")
    missing, shift = completeness(result)
    print(f"completeness: {missing} of the undamped rig's 1x critical speeds (Hermitian formulation, all modes) "
          f"missed; damping moves them by <= {100 * shift:.2f} %")
    worst = min(margins(result), key=lambda t: t[1])
    ok = worst[1] >= REQUIRED_MARGIN
    print(f"operating point inner {OPERATING_RPM:.0f} rpm / outer {OPERATING_RPM * RATIO:.0f} rpm: smallest margin "
          f"{100 * worst[1]:.1f}% ({worst[0].line} critical at inner {worst[0].speed_rpm:.1f} rpm, "
          f"{worst[0].whirl}) -> {'OK' if ok else 'FAILS'} (required >= {100 * REQUIRED_MARGIN:.0f}%)")
    first, best, n = timing()
    one = eigen_time()
    single, one_single = timing_single_thread_blas()
    load = os.getloadavg()[0]
    print(f"time of the {n}-speed Campbell with {N_MODES} tracked modes and critical speeds, after import "
          f"(requirement < 1000 ms); load average {load:.1f} on {os.cpu_count()} CPUs:")
    print(f"{'BLAS threads':>14} {'first ms':>9} {'best of 3 ms':>13} {'ms/speed':>9} {'one eigen ms':>13} "
          f"{'Campbell / eigen':>17}")
    print(f"{'default':>14} {1e3 * first:9.0f} {1e3 * best:13.0f} {1e3 * best / n:9.1f} {1e3 * one:13.1f} "
          f"{best / one:17.1f}")
    print(f"{'1':>14} {'':>9} {1e3 * single:13.0f} {1e3 * single / n:9.1f} {1e3 * one_single:13.1f} "
          f"{single / one_single:17.1f}")
    print(f"(one eigen = dense eig of the {2 * assemble(load_rotor('seed-rig')).n_dof}x"
          f"{2 * assemble(load_rotor('seed-rig')).n_dof} state matrix with vectors; the Campbell costs about "
          f"{n} of them, so its time scales with the machine's speed for LAPACK)")
    if args.plot:
        from rotorred.plots.axes import save_figure

        print(f"wrote {save_figure(result.plot(operating_speed=OPERATING_RPM * math.pi / 30), args.plot)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
