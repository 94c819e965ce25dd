"""Side by side with ROSS: Nelson–McVaugh rotor, Campbell diagram and a linear Newmark transient.

Both codes run in the same process on the same rotor: the preset ``nelson-mcvaugh`` (19 nodes,
bores read as diameters, Cowper shear coefficient, disk at node 4, isotropic bearings 4.378e7 N/m
at nodes 10 and 14, no damping) is rebuilt element by element in ROSS
(``ShaftElement(L, idl=D_i, odl=D_o, shear_method_calc="cowper")``, ``DiskElement``,
``BearingElement``).

* Campbell: first six whirl speeds at ``CAMPBELL_RPM``; ours from :func:`rotorred.linear.campbell.campbell`,
  ROSS's from ``Rotor.run_campbell`` (its axial/torsional modes, whirl NaN, removed; ROSS 2.x has
  6 DOF per node). Agreement: largest relative difference.
* Transient: unbalance ``M_E`` at the disk, spin ``SPEED_RPM``, Newmark average acceleration
  (gamma = 1/2, beta = 1/4), the same dt and duration; ours :func:`rotorred.transient.newmark.simulate`,
  ROSS's ``Rotor.run_time_response(..., method="newmark")``. Agreement: largest difference of the
  disk's x and y displacement histories relative to their peak.
  ROSS's Newmark starts every run from zero acceleration (``ross.utils.newmark`` sets
  ``y2dot0 = 0``), ours from the consistent ``a0 = M^-1 (F(0) - D v0 - K q0)``. With a force that is
  not zero at t = 0 this is an O(dt²) different start that stays in an undamped rotor as free
  vibration; the script shows it by also stepping ROSS's own step function
  (``ross.utils._converge_newmark``, on ROSS's matrices) from the consistent acceleration.
* Times: median of ``--repeats`` runs after a warm-up call of each code (numba compilation of both
  excluded); threads pinned to one (set below before numpy is imported).

What is not compared, because ROSS has no counterpart: a dual rotor with two spool speeds
(one speed per ROSS rotor), Craig–Bampton reduction (ROSS offers Guyan and pseudo-modal), and the
rub-impact law (ROSS's ``run_rubbing`` is a penalty contact with Coulomb friction on a rigid
stator, not the Hertz/Hunt–Crossley contact with a flexible, moving plate and stick-slip used here).

ROSS is optional: ``pip install "rotorred[bench]"`` (``ross-rotordynamics``; on Python < 3.13 pip
gives 2.3.0, which needs ``plotly<6`` to import). Install it in a separate virtual environment so
it cannot change the main environment's numpy/scipy. Without ROSS this script says so and exits 0.

Run: ``python validation/bench_ross.py [--repeats N] [--plot PATH]``.
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import contextlib  # noqa: E402
import io  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402

import numpy as np  # noqa: E402

from rotorred.model.assembly import assemble  # noqa: E402
from rotorred.linear.campbell import campbell  # noqa: E402
from rotorred.model.operating import Operating  # noqa: E402
from rotorred.model.rotor_file import load_rotor  # noqa: E402
from rotorred.model.loads import Unbalance  # noqa: E402
from rotorred.transient.newmark import Loads, Recording, StepControl, simulate  # noqa: E402

CAMPBELL_RPM = np.linspace(0.0, 40000.0, 21)
N_MODES = 6
SPEED_RPM = 10000.0          # spin of the transient
M_E = 1e-4                   # kg m, unbalance at the disk
DT = 1e-5                    # s
T_END = 0.05                 # s (5000 steps; first whirl mode ~ 16000 rpm = 267 Hz: 13 periods)
INSTALL_HINT = ('pip install "rotorred[bench]"  (ross-rotordynamics; on Python < 3.13 pip gives 2.3.0, '
                'which also needs "plotly<6")')


def import_ross():
    """The ``ross`` module, or None when it is not installed (or does not import)."""
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            import ross
    except Exception as exc:  # ImportError, or ROSS failing with a too new plotly
        return None, f"{type(exc).__name__}: {str(exc).splitlines()[0][:200] if str(exc) else ''}"
    return ross, ""


def ross_rotor(rs, rotor):
    """The single-spool ``rotor`` rebuilt in ROSS (same elements, disks, bearings; Cowper shear)."""
    if len(rotor.spools) != 1 or rotor.intershaft_bearings:
        raise ValueError("ROSS has one speed per rotor: `rotor` must have one spool and no inter-shaft bearing")
    spool = rotor.spools[0]
    first = min(rotor.nodes)
    if first != 0:
        raise ValueError(f"the ROSS model numbers nodes from 0; the rotor's first node is {first}")
    materials = {}
    shafts = []
    for e in spool.elements:
        m = e.material
        if m.name not in materials:
            materials[m.name] = rs.Material(name=f"rr_{m.name}", rho=m.rho, E=m.E, Poisson=m.nu)
        if e.shear not in ("cowper", "none"):
            raise ValueError(f"element shear {e.shear!r} has no ROSS counterpart (cowper or none)")
        shafts.append(rs.ShaftElement(L=e.L, idl=e.D_i, odl=e.D_o, material=materials[m.name],
                                      shear_effects=e.shear != "none", rotary_inertia=True, gyroscopic=True,
                                      shear_method_calc="cowper"))
    disks = [rs.DiskElement(n=d.node - first, m=d.m, Id=d.I_d, Ip=d.I_p) for d in rotor.disks]
    bearings = [rs.BearingElement(n=b.node - first, kxx=b.k_xx, kyy=b.k_yy, kxy=b.k_xy, kyx=b.k_yx,
                                  cxx=b.c_xx, cyy=b.c_yy, cxy=b.c_xy, cyx=b.c_yx) for b in rotor.bearings]
    with contextlib.redirect_stdout(io.StringIO()):
        return rs.Rotor(shafts, disks, bearings)


def _median_time(fn, repeats, setup=None):
    """Median wall time of ``fn(setup())`` (or ``fn()``) over ``repeats`` calls, ``setup`` not timed."""
    times, out = [], None
    for _ in range(repeats):
        arg = () if setup is None else (setup(),)
        t0 = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()):
            out = fn(*arg)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), (min(times), max(times)), out


@dataclass(frozen=True)
class CampbellComparison:
    """Whirl speeds (rpm), shape (n_speeds, 6), of both codes, their worst relative difference and times (s)."""

    rpm: np.ndarray
    ours: np.ndarray
    ross: np.ndarray
    max_rel_diff: float
    time_ours: float
    time_ross: float
    spread_ours: tuple
    spread_ross: tuple


def compare_campbell(rs, rotor, rpm=CAMPBELL_RPM, repeats: int = 3) -> CampbellComparison:
    """First six whirl speeds of ``rotor`` at ``rpm`` in rotorred and ROSS."""
    Omega = np.asarray(rpm, float) * math.pi / 30
    campbell(rotor, Operating.line(Omega[:2]), n_modes=N_MODES + 2)     # warm-up
    with contextlib.redirect_stdout(io.StringIO()):
        ross_rotor(rs, rotor).run_campbell(Omega[:2], frequencies=N_MODES + 2)  # warm-up (ROSS's numba code)
    t_ours, s_ours, res = _median_time(lambda: campbell(rotor, Operating.line(Omega), n_modes=N_MODES + 2), repeats)
    # ROSS caches run_modal per rotor and speed (lru_cache): a new rotor object for every repeat
    t_ross, s_ross, camp = _median_time(lambda rr: rr.run_campbell(Omega, frequencies=N_MODES + 2), repeats,
                                        setup=lambda: ross_rotor(rs, rotor))
    ours = np.sort(res.frequencies, axis=1)[:, :N_MODES] * 30 / math.pi
    ross_w = []
    for i in range(len(Omega)):
        lateral = camp.wd[i][~np.isnan(camp.whirl_values[i])]     # drop axial/torsional modes (whirl NaN)
        ross_w.append(np.sort(lateral)[:N_MODES])
    ross_w = np.array(ross_w) * 30 / math.pi
    diff = float(np.max(np.abs(ours - ross_w) / ross_w))
    return CampbellComparison(np.asarray(rpm, float), ours, ross_w, diff, t_ours, t_ross, s_ours, s_ross)


@dataclass(frozen=True)
class TransientComparison:
    """Disk displacement histories (m) of both codes, agreement and times.

    Attributes
    ----------
    t : ndarray, shape (n,)
    ours, ross, ross_consistent : ndarray, shape (n, 2)
        (x, y) of the disk node: rotorred; ROSS's ``run_time_response``; ROSS's step function
        started from the consistent acceleration.
    diff_public, diff_consistent : float
        max |ours - other| / max |ours| over x and y.
    time_ours, time_ross : float
        Median wall time (s) of one run (set-up included).
    us_ours, us_ross : float
        Per step (µs): rotorred's compiled step loop (median), ROSS's whole run / steps.
    n_steps : int
    """

    t: np.ndarray
    ours: np.ndarray
    ross: np.ndarray
    ross_consistent: np.ndarray
    diff_public: float
    diff_consistent: float
    time_ours: float
    time_ross: float
    spread_ours: tuple
    spread_ross: tuple
    us_ours: float
    us_ross: float
    n_steps: int


def compare_transient(rs, rotor, speed_rpm: float = SPEED_RPM, m_e: float = M_E, dt: float = DT,
                      t_end: float = T_END, repeats: int = 3) -> TransientComparison:
    """Linear unbalance transient from rest, Newmark average acceleration, in both codes."""
    W = speed_rpm * math.pi / 30
    disk = rotor.disks[0].node
    spool = rotor.spools[0].name
    system = assemble(rotor)
    unb = [Unbalance(disk, m_e)]
    run_ours = lambda: simulate(system, Operating.point({spool: W}), t_end, dt, loads=Loads(unb),
                                recording=Recording([(disk, "x"), (disk, "y")]),
                                control=StepControl(progress=False))
    run_ours()                                                   # warm-up (kernel load)
    t_ours, s_ours, res = _median_time(run_ours, repeats)
    loop_ours = statistics.median(run_ours().run_time for _ in range(max(repeats, 3)))  # step loop alone (s)
    ours = np.column_stack([res.outputs[(disk, "x")], res.outputs[(disk, "y")]])

    rr = ross_rotor(rs, rotor)
    n = res.t.size
    t = np.arange(n) * dt
    F = np.zeros((n, rr.ndof))
    nd = rr.number_dof
    F[:, nd * disk + 0] = m_e * W * W * np.cos(W * t)
    F[:, nd * disk + 1] = m_e * W * W * np.sin(W * t)
    with contextlib.redirect_stdout(io.StringIO()):
        rr.run_time_response(W, F[:20], t[:20], method="newmark")        # warm-up (numba compilation in ROSS)
    t_ross, s_ross, tr = _median_time(lambda r: r.run_time_response(W, F, t, method="newmark"), repeats,
                                      setup=lambda: ross_rotor(rs, rotor))
    ross_xy = tr.yout[:, [nd * disk, nd * disk + 1]]

    # ROSS's own step, started from the consistent acceleration a0 = M^-1 F(0)
    from ross.utils import _converge_newmark
    M, C, K = rr.M(W), rr.C(W) + rr.G() * W, rr.K(W)
    y, v, a = np.zeros(rr.ndof), np.zeros(rr.ndof), np.linalg.solve(M, F[0])
    cons = np.zeros((n, 2))
    for i in range(1, n):
        y, v, a = _converge_newmark(rr.ndof, y, v, a, dt, M, C, K, F[i], 0.5, 0.25, 1e-6)
        cons[i] = y[nd * disk], y[nd * disk + 1]

    peak = np.max(np.abs(ours))
    return TransientComparison(
        t=res.t, ours=ours, ross=ross_xy, ross_consistent=cons,
        diff_public=float(np.max(np.abs(ours - ross_xy)) / peak),
        diff_consistent=float(np.max(np.abs(ours - cons)) / peak),
        time_ours=t_ours, time_ross=t_ross, spread_ours=s_ours, spread_ross=s_ross,
        us_ours=1e6 * loop_ours / res.n_steps, us_ross=1e6 * t_ross / (n - 1), n_steps=res.n_steps)


def versions(rs) -> str:
    import numba
    import scipy
    return (f"ROSS {rs.__version__} (ross-rotordynamics), rotorred, Python {platform.python_version()}, "
            f"numpy {np.__version__}, scipy {scipy.__version__}, numba {numba.__version__}")


def format_report(cc: CampbellComparison, tc: TransientComparison, rs) -> str:
    lines = [versions(rs), "threads pinned to 1 (NUMBA/OMP/OPENBLAS/MKL_NUM_THREADS)", ""]
    head = f"{'task':<44} {'rotorred (s)':>13} {'ROSS (s)':>10} {'ROSS/ours':>10} {'agreement':>12}"
    lines += [head, "-" * len(head)]
    lines.append(f"{f'Campbell, {len(cc.rpm)} speeds x {N_MODES} whirl modes':<44} {cc.time_ours:>13.4f} "
                 f"{cc.time_ross:>10.3f} {cc.time_ross / cc.time_ours:>10.1f} {cc.max_rel_diff:>12.2e}")
    lines.append(f"{f'Newmark transient, {tc.n_steps} steps of {DT:g} s':<44} {tc.time_ours:>13.4f} "
                 f"{tc.time_ross:>10.3f} {tc.time_ross / tc.time_ours:>10.1f} {tc.diff_public:>12.2e}")
    lines.append(f"{'  per step (µs)':<44} {tc.us_ours:>13.2f} {tc.us_ross:>10.1f} "
                 f"{tc.us_ross / tc.us_ours:>10.1f}")
    lines.append(f"{'  ROSS step from consistent a0 (agreement)':<44} {'':>13} {'':>10} {'':>10} "
                 f"{tc.diff_consistent:>12.2e}")
    lines.append(f"{'dual rotor, two spool speeds':<44} {'yes':>13} {'no':>10} {'-':>10} {'not compared':>12}")
    lines.append(f"{'Craig–Bampton reduction':<44} {'yes':>13} {'no':>10} {'-':>10} {'not compared':>12}")
    lines.append(f"{'rub: Hertz/Hunt–Crossley, moving plate':<44} {'yes':>13} {'other law':>10} {'-':>10} "
                 f"{'not compared':>12}")
    lines.append("")
    lines.append(f"spreads (min-max of repeats, s): Campbell ours {cc.spread_ours[0]:.4f}-{cc.spread_ours[1]:.4f}, "
                 f"ROSS {cc.spread_ross[0]:.3f}-{cc.spread_ross[1]:.3f}; transient ours "
                 f"{tc.spread_ours[0]:.4f}-{tc.spread_ours[1]:.4f}, "
                 f"ROSS {tc.spread_ross[0]:.3f}-{tc.spread_ross[1]:.3f}")
    lines.append("Campbell whirl speeds (rpm), rotorred / ROSS, at 0 and 40000 rpm:")
    for i in (0, len(cc.rpm) - 1):
        pairs = "  ".join(f"{a:.1f}/{b:.1f}" for a, b in zip(cc.ours[i], cc.ross[i]))
        lines.append(f"  {cc.rpm[i]:>7.0f} rpm: {pairs}")
    lines.append("transient agreement = max |ours - ROSS| / max |ours| over the disk's x and y; ROSS's public "
                 "Newmark starts from zero acceleration, ours from the consistent one (see the module docstring)")
    return "\n".join(lines)


def plot(tc: TransientComparison, path: str) -> str:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 5.5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(1e3 * tc.t, 1e6 * tc.ours[:, 1], "k-", lw=1.2, label="rotorred")
    ax1.plot(1e3 * tc.t, 1e6 * tc.ross[:, 1], "C1--", lw=1.0, label="ROSS run_time_response (a0 = 0)")
    ax1.set_ylabel("disk y (µm)")
    ax1.legend(fontsize=8, loc="upper left", ncol=2)
    ax1.set_ylim(1.25 * ax1.get_ylim()[0], 1.5 * ax1.get_ylim()[1])
    ax1.set_title(f"Nelson–McVaugh, {SPEED_RPM:.0f} rpm, unbalance {M_E:g} kg m at the disk, Newmark dt = {DT:g} s",
                  fontsize=10)
    ax2.semilogy(1e3 * tc.t[1:], 1e6 * np.abs(tc.ours[1:, 1] - tc.ross[1:, 1]) + 1e-12, "C1-", lw=0.8,
                 label="|rotorred - ROSS public|")
    ax2.semilogy(1e3 * tc.t[1:], 1e6 * np.abs(tc.ours[1:, 1] - tc.ross_consistent[1:, 1]) + 1e-12, "C0-", lw=0.8,
                 label="|rotorred - ROSS step from consistent a0|")
    ax2.set_xlabel("time (ms)")
    ax2.set_ylabel("difference in y (µm)")
    ax2.legend(fontsize=8)
    ax2.grid(True, which="both", lw=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--plot", metavar="PATH", help="write the transient comparison (PNG)")
    args = parser.parse_args(argv)
    rs, why = import_ross()
    if rs is None:
        print(f"ROSS is not available in this environment ({why}); nothing compared.\n"
              f"To run this benchmark: {INSTALL_HINT}, preferably in a separate virtual environment.")
        return 0
    rotor = load_rotor("nelson-mcvaugh")
    cc = compare_campbell(rs, rotor, repeats=args.repeats)
    tc = compare_transient(rs, rotor, repeats=args.repeats)
    print(format_report(cc, tc, rs))
    if args.plot:
        print(f"plot: {plot(tc, args.plot)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
