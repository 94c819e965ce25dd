"""Run time against error of the rub transient: full model against Craig–Bampton, dt, Newmark against HHT-α.

Scene: the built-in scene ``paper-rub`` (:mod:`rotorred.scenes.schema`; ``paper_rub`` below is the one
place this benchmark reads it): the seed rig with the scene's damping, inner spool 70 Hz, outer
90 Hz, the scene's unbalances and rub plate at node 18, started from the linear steady state
(the scene's ``start = "settled"``, :func:`rotorred.scenes.run.settled_state`). The rub response settles
onto a period-2 orbit (period 0.2 s; 70 and 90 Hz are multiples of 10 Hz) within about 2 s, so
each run lasts ``T_END`` = 2.5 s and the record is the last ``N_PERIODS`` = 4 common periods.
Simulation time and record are the benchmark's (the scene runs 2.6 s and records from 2.0 s).

Grid: the full model on ``Rotor.refined(REFINE)`` against reduced models (Craig–Bampton with the
bearing, inter-shaft and rub nodes as boundary and k fixed-interface modes) of the same mesh,
for dt from coarse to fine, Newmark (average acceleration) and HHT-α.

Reference: the full model of the same mesh with Newmark at ``DT_REF``; its convergence is shown
by the difference to the grid's run at 2 ``DT_REF`` (and, with ``--mesh-check``, the difference of the
full model on ``refined(2 REFINE)`` to quantify the mesh error, which is common to every row).

Last, the scene as shipped (its own unrefined rig, its mode count, dt and method) and with the
reduction's automatic mode count are measured against the same reference (:func:`scene_checks`).

Error measures (meaningful for a rubbing rotor, where a pointwise time-history error is not), by
:func:`rotorred.signals.compare.response_measures` and :func:`~rotorred.signals.compare.measure_errors`, the ones of
``rotorred compare``:

* ``spectral``: the ten largest spectral amplitudes (0 Hz excluded) of the reference at nodes 13
  and 14 (x and y), relative error of each, worst of the 40 (the largest errors sit on the small
  combination lines, not on the 70/90 Hz lines); spectra by
  :func:`rotorred.signals.spectra.settled_spectrum` (rectangular window on whole common periods, every
  line m f_H + n f_L on a bin) of the records resampled to ``SAMPLE_DT``.
* ``orbit``: relative error of the peak orbit radius sqrt(x² + y²) at node 18 over the record.
* ``contact``: relative error of the contact fraction (fraction of the record's steps in
  slip or stick).

Time: wall time of one run (reduction, when reduced, plus ``simulate``: matrix set-up and the
compiled step loop), median of ``--repeats`` runs, after a warm-up run has loaded the compiled
kernel; µs per step is the step loop alone (``TransientResult.us_per_step``). Threads are pinned
to one (NUMBA/OMP/OPENBLAS/MKL_NUM_THREADS=1, set below before numpy is imported).

Run: ``python validation/bench_pareto.py [--quick] [--repeats N] [--plot PATH] [--mesh-check]``.
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402

import numpy as np  # noqa: E402

from rotorred.model.assembly import assemble  # noqa: E402
from rotorred.model.rotor import Rotor  # noqa: E402
from rotorred.model.operating import Operating  # noqa: E402
from rotorred.transient.newmark import (Initial, Loads, Recording, Scheme, SimulationDiverged,  # noqa: E402
                                        StepControl, simulate)
from rotorred.linear.reduction import default_boundary_nodes, reduce  # noqa: E402
from rotorred.scenes.run import settled_state  # noqa: E402
from rotorred.scenes.schema import Scene, load_scene  # noqa: E402
from rotorred.signals.compare import (N_LINES, MeasureErrors, ResponseMeasures, measure_errors,  # noqa: E402
                                      response_measures)

REFINE = 4                   # mesh of the comparison: Rotor.refined(4) of the 20-node rig
T_END = 2.5                  # s: the rub response settles onto a period-2 (0.2 s) orbit by about 2 s
N_PERIODS = 4                # common periods of 0.1 s in the record (t = 2.1 .. 2.5 s)
SAMPLE_DT = 1e-4             # s, spectra are taken on this grid for every dt (Nyquist 5 kHz)
DT_REF = 2.5e-6              # s, reference step
DTS = (1e-4, 5e-5, 2e-5, 1e-5, 5e-6)
MODES = (8, 10, 16, 24, 48)  # fixed-interface modes (10: the automatic count; 24: the scene's)
HHT_ALPHA = -0.05
SPECTRAL_NODES = (13, 14)
ORBIT_NODE = 18
TARGET = 0.01                # the "1 % spectral error" of the issue
QUICK = dict(dts=(5e-5, 2e-5, 1e-5), modes=(16, 24), dt_ref=5e-6, repeats=1)
LONG_RUN = 3.0               # s: a configuration whose first run takes longer is timed once


@dataclass(frozen=True)
class RubCase:
    """The paper-rub configuration (Xu et al. 2016, section 4, rub at node 18) on a refined mesh.

    Attributes
    ----------
    rotor : Rotor
        The seed rig, refined.
    speeds : dict of str to float
        Spool speeds (rad/s): inner 2 pi 70, outer 2 pi 90 (the scene's).
    unbalances : tuple of Unbalance
    plates : tuple of RubPlate
    outputs : tuple of (int, str)
    t_end, record_start, sample_dt : float
        (s)
    refine : int
        Mesh refinement of ``rotor`` (``Rotor.refined``).
    scene : Scene
        The scene the case comes from.
    """

    rotor: Rotor
    speeds: dict
    unbalances: tuple
    plates: tuple
    outputs: tuple
    t_end: float
    record_start: float
    sample_dt: float
    refine: int = 1
    scene: Scene | None = None


def paper_rub(refine: int = REFINE, t_end: float = T_END, n_periods: int = N_PERIODS) -> RubCase:
    """The built-in scene ``paper-rub`` (:mod:`rotorred.scenes.schema`) on its rotor refined ``refine`` times.

    Rotor (with the scene's Rayleigh damping), spool speeds, unbalances and rub plate are the
    scene's; the run length ``t_end`` and the record (the last ``n_periods`` common periods of
    0.1 s) are this benchmark's, so that the grid stays affordable.
    """
    scene = load_scene("paper-rub")
    rig = scene.rotor.refined(refine)
    outputs = tuple((n, d) for n in (*SPECTRAL_NODES, ORBIT_NODE) for d in ("x", "y"))
    return RubCase(rotor=rig, speeds=dict(scene.speeds), unbalances=tuple(scene.unbalances),
                   plates=tuple(scene.plates), outputs=outputs, t_end=t_end,
                   record_start=t_end - 0.1 * n_periods, sample_dt=SAMPLE_DT, refine=refine, scene=scene)


def steady_state(model, case: RubCase) -> tuple[np.ndarray, np.ndarray]:
    """Linear steady unbalance response (no contact) of ``model`` at t = 0: (q0, v0) in model coordinates.

    The scene's own "settled" start (:func:`rotorred.scenes.run.settled_state`) on the refined rotor.
    """
    return settled_state(dataclasses.replace(case.scene, rotor=case.rotor), model)


def reduced_model(case: RubCase, n_modes: int, system=None):
    """Craig–Bampton model of ``case.rotor``: boundary = bearing, inter-shaft and rub nodes, ``n_modes`` modes."""
    system = assemble(case.rotor) if system is None else system
    boundary = default_boundary_nodes(case.rotor, [p.node for p in case.plates])
    return reduce(system, boundary, n_modes=n_modes)


def run(model, case: RubCase, dt: float, method: str = "newmark", alpha: float | None = None):
    """One rub transient of ``model``; every step recorded (the spectra resample to ``case.sample_dt``)."""
    q0, v0 = steady_state(model, case)
    return simulate(model, Operating.point(case.speeds), case.t_end, dt, loads=Loads(case.unbalances),
                    contacts=case.plates, scheme=Scheme(method, alpha=alpha if method == "hht" else None),
                    recording=Recording(case.outputs, start=case.record_start), start=Initial(q0, v0),
                    control=StepControl(progress=False))


def measures(result, case: RubCase) -> ResponseMeasures:
    """Spectra at nodes 13 and 14, peak orbit radius at node 18 and contact fraction of a run, its records
    resampled to ``case.sample_dt`` (:func:`rotorred.signals.compare.response_measures`, the measure of
    ``rotorred compare``)."""
    f_L, f_H = case.speeds["inner"] / (2 * math.pi), case.speeds["outer"] / (2 * math.pi)
    dofs = [o for o in case.outputs if o[0] in SPECTRAL_NODES]
    return response_measures(result.outputs, result.dt, case.sample_dt, (f_L, f_H), dofs, ORBIT_NODE,
                             1.0 - result.contacts[0].fraction("open"))


@dataclass(frozen=True)
class Row:
    """One configuration of the grid.

    Attributes
    ----------
    model : str
        "full" or "CB k" (Craig–Bampton with k modes).
    n_dof : int
    dt : float
        (s)
    method : str
    wall : float
        Median wall time of a run (s): reduction (for CB) + simulate.
    wall_spread : tuple of float
        (min, max) of the repeats (s).
    cpu : float
        Median process CPU time of a run (s), less disturbed by other load than ``wall``.
    repeats : int
        Number of timed runs.
    reduce_time : float
        Median time of the reduction (s), included in ``wall``; 0 for the full model.
    us_per_step : float
        Median step-loop time per step (µs).
    n_steps : int
    errors : MeasureErrors or None
        None when the run diverged.
    note : str
    """

    model: str
    n_dof: int
    dt: float
    method: str
    wall: float
    wall_spread: tuple
    cpu: float
    repeats: int
    reduce_time: float
    us_per_step: float
    n_steps: int
    errors: MeasureErrors | None
    note: str = ""


@dataclass(frozen=True)
class Reference:
    """The reference run and its convergence check."""

    dt: float
    n_dof: int
    measures: ResponseMeasures
    wall: float
    check_dt: float
    check: MeasureErrors | None = None    # the full Newmark run at check_dt against the reference (from the grid)
    mesh: MeasureErrors | None = None     # the full model on refined(2 REFINE) at check_dt against the reference
    mesh_refine: int = 0
    extra: dict = field(default_factory=dict)


def reference(case: RubCase, dt_ref: float = DT_REF, mesh_check: bool = False, system=None) -> Reference:
    """Full model, Newmark at ``dt_ref``.

    Its convergence is shown by the grid's run at 2 ``dt_ref`` (:func:`with_check`).
    """
    system = assemble(case.rotor) if system is None else system
    t0 = time.perf_counter()
    ref_res = run(system, case, dt_ref)
    wall = time.perf_counter() - t0
    ref = measures(ref_res, case)
    check_dt = 2 * dt_ref
    mesh, mesh_refine = None, 0
    if mesh_check:
        refine = 2 * case.refine
        fine = paper_rub(refine, case.t_end, int(round((case.t_end - case.record_start) / 0.1)))
        mesh = measure_errors(measures(run(assemble(fine.rotor), fine, check_dt), fine), ref)
        mesh_refine = refine
    return Reference(dt=dt_ref, n_dof=system.M.shape[0], measures=ref, wall=wall, check_dt=check_dt,
                     mesh=mesh, mesh_refine=mesh_refine)


def with_check(ref: Reference, rows: list[Row]) -> Reference:
    """``ref`` with ``check``: the errors of the grid's full Newmark run at ``ref.check_dt``, or of a new run."""
    for r in rows:
        if r.model == "full" and r.method == "newmark" and abs(r.dt - ref.check_dt) < 1e-12 * ref.check_dt:
            return dataclasses.replace(ref, check=r.errors)
    return ref


def _timed(fn, repeats: int, long_run: float = math.inf):
    """Wall and CPU times of ``repeats`` calls of ``fn`` (one call only if it takes longer than ``long_run`` s)."""
    walls, cpus, results = [], [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        results.append(fn())
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        if walls[0] > long_run:
            break
    return walls, cpus, results


def grid(case: RubCase, ref: Reference, dts=DTS, modes=MODES, methods=("newmark", "hht"), repeats: int = 3,
         system=None, alpha: float = HHT_ALPHA, long_run: float = LONG_RUN) -> list[Row]:
    """Every (model, dt, method) of the grid against the reference."""
    system = assemble(case.rotor) if system is None else system
    rows = []
    models = [("full", None)] + [(f"CB {k}", k) for k in modes]
    for name, k in models:
        red_walls = [0.0]
        model = system
        if k is not None:
            red_walls, _, reds = _timed(lambda: reduced_model(case, k, system), repeats)
            model = reds[0]
        for method in methods:
            a = alpha if method == "hht" else None
            for dt in dts:
                try:
                    walls, cpus, results = _timed(lambda: run(model, case, dt, method, a), repeats, long_run)
                except SimulationDiverged as exc:
                    rows.append(Row(name, model.M.shape[0], dt, method, math.nan, (math.nan, math.nan), math.nan,
                                    0, statistics.median(red_walls), math.nan, exc.result.n_steps, None,
                                    f"diverged: {exc}"))
                    continue
                res = results[0]
                walls = [w + statistics.median(red_walls) for w in walls]
                cpus = [c + statistics.median(red_walls) for c in cpus]
                rows.append(Row(name, model.M.shape[0], dt, method, statistics.median(walls),
                                (min(walls), max(walls)), statistics.median(cpus), len(walls),
                                statistics.median(red_walls),
                                statistics.median(r.us_per_step for r in results), res.n_steps,
                                measure_errors(measures(res, case), ref.measures),
                                f"{res.n_substeps} half-steps" if res.n_substeps else ""))
    return rows


def fastest_within(rows: list[Row], target: float = TARGET, model_prefix: str = "full") -> Row | None:
    """The fastest row of a model family whose spectral error is at most ``target``."""
    ok = [r for r in rows if r.model.startswith(model_prefix) and r.errors is not None
          and r.errors.spectral <= target]
    return min(ok, key=lambda r: r.wall) if ok else None


def speedup(rows: list[Row], target: float = TARGET) -> tuple[Row | None, Row | None, float]:
    """(fastest full row, fastest reduced row, wall-time ratio) reaching ``target`` spectral error."""
    full = fastest_within(rows, target, "full")
    red = fastest_within(rows, target, "CB")
    ratio = full.wall / red.wall if (full and red) else math.nan
    return full, red, ratio


def observed_order(rows: list[Row], model: str = "full", method: str = "newmark", max_dt: float = 2e-5) -> float:
    """Slope of log(spectral error) against log(dt) of ``model``/``method`` rows with dt <= ``max_dt``."""
    sel = [r for r in rows if r.model == model and r.method == method and r.errors is not None
           and r.dt <= max_dt and r.errors.spectral > 0]
    if len(sel) < 2:
        return math.nan
    return float(np.polyfit(np.log([r.dt for r in sel]), np.log([r.errors.spectral for r in sel]), 1)[0])


@dataclass(frozen=True)
class SceneCheck:
    """The built-in scene as shipped (its own mesh, model, dt and method) against the reference.

    Attributes
    ----------
    label : str
        The scene's model (:func:`rotorred.scenes.run.build_model`), method and dt.
    errors : MeasureErrors or None
        None when the scene's dt does not divide the sample interval.
    wall : float
        Wall time of the model build plus one run of ``T_END`` (s).
    note : str
    """

    label: str
    errors: MeasureErrors | None
    wall: float
    note: str = ""


def scene_checks(ref: Reference, t_end: float = T_END, n_periods: int = N_PERIODS) -> list[SceneCheck]:
    """``paper-rub`` as shipped, and with the reduction's automatic mode count, against the reference.

    The scene runs on its own rotor (the unrefined rig), so the error includes the mesh error of
    ``refined(1)`` against ``refined(REFINE)``. ``t_end`` and ``n_periods`` must be those of the
    reference's case.
    """
    from rotorred.scenes.run import build_model

    scene = load_scene("paper-rub")
    case = paper_rub(1, t_end, n_periods)
    auto = dataclasses.replace(scene, solver=dataclasses.replace(scene.solver, modes=None, cutoff_hz=None))
    out = []
    for name, sc in (("as shipped", scene), ("automatic mode count", auto)):
        s = sc.solver
        t0 = time.perf_counter()
        built = build_model(sc)
        res = run(built.model, case, s.dt, s.method, s.alpha)
        wall = time.perf_counter() - t0
        n_modes = getattr(built.model, "n_modes", None)
        what = built.label.split(" (")[0] + (f" ({n_modes} modes)" if n_modes is not None else "")
        label = f"{name}: {what}, {s.method} dt = {s.dt:g} s"
        try:
            out.append(SceneCheck(label, measure_errors(measures(res, case), ref.measures), wall))
        except ValueError as exc:
            out.append(SceneCheck(label, None, wall, str(exc)))
    return out


def format_scene_checks(checks: list[SceneCheck]) -> str:
    lines = [f"scene paper-rub on its own (unrefined) rig against the refined({REFINE}) reference:"]
    for c in checks:
        if c.errors is None:
            lines.append(f"  {c.label}: not comparable ({c.note})")
        else:
            lines.append(f"  {c.label}: spectral {100 * c.errors.spectral:.3g} % ({c.errors.worst_line}), orbit "
                         f"{100 * c.errors.orbit:.3g} %, contact {100 * c.errors.contact:.3g} %; {c.wall:.3f} s")
    return "\n".join(lines)


def warm_up() -> float:
    """Load (or compile) the step kernel with a tiny run; returns its wall time (s)."""
    tiny = paper_rub(1, t_end=0.01, n_periods=0)
    system = assemble(tiny.rotor)
    t0 = time.perf_counter()
    run(system, tiny, 1e-4)
    return time.perf_counter() - t0


def format_table(rows: list[Row], ref: Reference) -> str:
    ref = with_check(ref, rows)
    line = f"reference: full model, {ref.n_dof} DOF, Newmark dt = {ref.dt:g} s ({ref.wall:.1f} s)"
    if ref.check is not None:
        line += (f"; the run at dt = {ref.check_dt:g} s differs by spectral {100 * ref.check.spectral:.3g} %, orbit "
                 f"{100 * ref.check.orbit:.3g} %, contact {100 * ref.check.contact:.3g} %")
    lines = [line]
    if ref.mesh is not None:
        lines.append(f"mesh: full model on refined({ref.mesh_refine}) at dt = {ref.check_dt:g} s differs from the "
                     f"reference by spectral {100 * ref.mesh.spectral:.3g} %, orbit {100 * ref.mesh.orbit:.3g} %, "
                     f"contact {100 * ref.mesh.contact:.3g} % (mesh error common to every row)")
    m = ref.measures
    lines.append(f"reference values: peak orbit radius at node {ORBIT_NODE} {1e6 * m.peak_radius:.2f} µm, "
                 f"contact fraction {100 * m.contact_fraction:.2f} %")
    head = (f"{'model':<7} {'DOF':>4} {'method':<8} {'dt (s)':>8} {'steps':>7} {'wall (s)':>9} "
            f"{'spread (s)':>17} {'n':>2} {'cpu (s)':>8} {'µs/step':>8} {'spectral %':>10} {'orbit %':>8} "
            f"{'contact %':>9}  worst line / note")
    lines += [head, "-" * len(head)]
    for r in rows:
        if r.errors is None:
            lines.append(f"{r.model:<7} {r.n_dof:>4} {r.method:<8} {r.dt:>8.2g} {r.n_steps:>7} {'-':>9} "
                         f"{'':>17} {'':>2} {'-':>8} {'-':>8} {'-':>10} {'-':>8} {'-':>9}  {r.note}")
            continue
        e = r.errors
        lines.append(f"{r.model:<7} {r.n_dof:>4} {r.method:<8} {r.dt:>8.2g} {r.n_steps:>7} {r.wall:>9.4f} "
                     f"{r.wall_spread[0]:>8.4f}-{r.wall_spread[1]:<8.4f} {r.repeats:>2} {r.cpu:>8.4f} "
                     f"{r.us_per_step:>8.2f} "
                     f"{100 * e.spectral:>10.3g} {100 * e.orbit:>8.3g} {100 * e.contact:>9.3g}  "
                     f"{e.worst_line}{'; ' + r.note if r.note else ''}")
    p = observed_order(rows)
    if math.isfinite(p) and ref.check is not None:
        lines.append(f"observed order of the full model's spectral error in dt (Newmark, dt <= 2e-5 s): {p:.2f}, "
                     f"so the reference's own error is about {100 * ref.check.spectral / (2**p - 1):.2g} % "
                     f"(its difference to the 2 dt run / (2^p - 1))")
    full, red, ratio = speedup(rows)
    if full and red:
        lines.append(f"fastest to <= {100 * TARGET:g} % spectral error: full {full.method} dt={full.dt:g} s "
                     f"{full.wall:.4f} s (cpu {full.cpu:.4f} s); reduced {red.model} {red.method} dt={red.dt:g} s "
                     f"{red.wall:.4f} s (cpu {red.cpu:.4f} s, incl. reduction {red.reduce_time:.4f} s): "
                     f"{ratio:.1f}x faster in wall time, {full.cpu / red.cpu:.1f}x in CPU time")
    else:
        lines.append(f"no configuration of {'the full' if not full else 'a reduced'} model reached "
                     f"{100 * TARGET:g} % spectral error")
    return "\n".join(lines)


def plot(rows: list[Row], path: str, ref: Reference) -> str:
    """Log-log Pareto plot: wall time against spectral error, one marker per (model, method), dt along lines."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 5.5))
    ax = fig.add_subplot()
    names = sorted({r.model for r in rows}, key=lambda s: (s != "full", int(s.split()[1]) if s != "full" else 0))
    colors = dict(zip(names, ["k", "tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]))
    for name in names:
        for method, marker, ls in (("newmark", "o", "-"), ("hht", "s", "--")):
            sel = [r for r in rows if r.model == name and r.method == method and r.errors is not None]
            if not sel:
                continue
            sel.sort(key=lambda r: r.dt)
            err = [max(r.errors.spectral, 1e-7) for r in sel]
            ax.loglog([r.wall for r in sel], err, ls, marker=marker, color=colors[name], ms=5,
                      label=f"{name} ({sel[0].n_dof} DOF), {'Newmark' if method == 'newmark' else 'HHT-α'}")
            for r, e in zip(sel, err):
                if method == "newmark":
                    ax.annotate(f"{r.dt:g}", (r.wall, e), textcoords="offset points", xytext=(4, 3), fontsize=6,
                                color=colors[name])
    ax.axhline(TARGET, color="0.5", lw=0.8, ls=":")
    ax.text(ax.get_xlim()[0], TARGET, f" {100 * TARGET:g} %", va="bottom", fontsize=8, color="0.4")
    ax.set_xlabel("wall time per run (s), median, after compilation (reduction included)")
    ax.set_ylabel(f"spectral error (-): worst of the {N_LINES} largest lines, nodes 13/14")
    ax.set_title(f"Rub transient, seed rig refined({REFINE}), {T_END:g} s simulated: time against error\n"
                 f"reference: full {ref.n_dof} DOF, Newmark dt = {ref.dt:g} s; labels: dt (s)", fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), ncol=1)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer dt, modes and repeats; coarser reference")
    parser.add_argument("--repeats", type=int, default=None, help="timed repeats per configuration (default 3)")
    parser.add_argument("--plot", metavar="PATH", help="write the Pareto plot (PNG)")
    parser.add_argument("--mesh-check", action="store_true",
                        help=f"also run the full model on refined({2 * REFINE}) to quantify the mesh error")
    args = parser.parse_args(argv)
    dts, modes, dt_ref, repeats = DTS, MODES, DT_REF, 3
    if args.quick:
        dts, modes, dt_ref, repeats = QUICK["dts"], QUICK["modes"], QUICK["dt_ref"], QUICK["repeats"]
    if args.repeats is not None:
        repeats = args.repeats
    case = paper_rub()
    print(f"threads pinned: NUMBA_NUM_THREADS={os.environ['NUMBA_NUM_THREADS']}, "
          f"OMP/OPENBLAS/MKL_NUM_THREADS={os.environ['OMP_NUM_THREADS']}")
    print(f"warm-up (kernel load/compile): {warm_up():.2f} s")
    system = assemble(case.rotor)
    ref = reference(case, dt_ref, mesh_check=args.mesh_check, system=system)
    rows = grid(case, ref, dts=dts, modes=modes, repeats=repeats, system=system)
    print(format_table(rows, ref))
    print(format_scene_checks(scene_checks(ref)))
    if args.plot:
        print(f"plot: {plot(rows, args.plot, ref)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
