"""Reduced against full: a scene run on its full model and on Craig–Bampton models, error against run time.

:func:`compare_models` runs the scene on the full finite-element model and on each reduced model (Craig–Bampton with
the scene's boundary and ``k`` fixed-interface modes, for each ``k`` of :attr:`CompareOptions.modes`), at each time
step of :attr:`CompareOptions.dts`, and measures every run against the **reference**: the full model at the finest
step. The measures are :mod:`rotorred.signals.compare`'s (the same as ``validation/bench_pareto.py``'s, docs/model.md
§22):

* spectral: the worst relative error of the reference's :data:`~rotorred.signals.compare.N_LINES` largest lines of
  every recorded DOF, those above the scene's ``output.line_threshold`` of the DOF's largest (records resampled to the
  coarsest step, rectangular window on whole common periods);
* orbit: the peak orbit radius at the rub node (its x and y are recorded for this), else at the recorded node with
  the largest orbit of the reference;
* contact: the fraction of the record the (first) rub plate touches.

The time of a run is its wall and CPU time from the model's build (assembly, and the reduction for a reduced model)
to the end of the record, after a short warm-up run (imports, the step kernel's loading) and less any later kernel
load (reported apart: paid once per process, not per model).

An interrupt (``KeyboardInterrupt``, or the exceptions the caller names) after the reference is computed ends the
comparison there: the result holds the runs done, :attr:`ModelComparison.interrupted` names the signal.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from rotorred import checks, progress
from rotorred.results import Result, dof_coordinates, label_coordinate
from rotorred.scenes.run import build_model, respond, spool_frequencies
from rotorred.scenes.schema import Scene, is_whole_steps
from rotorred.signals.compare import N_LINES, MeasureErrors, measure_errors, response_measures

__all__ = ["CompareOptions", "ModelRun", "ModelComparison", "compare_models", "check_comparison", "DEFAULT_MODES",
           "format_comparison", "write_comparison"]

LOG = logging.getLogger(__name__)

#: fixed-interface mode counts compared by default (bench_pareto's 8, 16 and 24: docs/benchmarks.md)
DEFAULT_MODES = (8, 16, 24)


@dataclass(frozen=True)
class CompareOptions:
    """What :func:`compare_models` compares.

    Attributes
    ----------
    modes : tuple of int
        Fixed-interface mode counts of the reduced models (each >= 1 and at most the interior DOFs).
    dts : tuple of float
        Time steps (s); empty: the scene's ``solver.dt``. The finest is the reference's; each must be a whole fraction
        of the coarsest (the interval the records are compared at) and of the scene's ``solver.duration`` and
        ``solver.record_start``.
    refine : int
        Split every shaft element of the scene's rotor into this many (:meth:`rotorred.model.rotor.Rotor.refined`;
        node numbers kept), >= 1.
    n_lines : int
        Largest spectral lines compared per DOF.
    progress : bool or None
        Stage lines and a bar of the runs: True, False, or None (when :mod:`rotorred.progress` shows them).
    """

    modes: tuple[int, ...] = DEFAULT_MODES
    dts: tuple[float, ...] = ()
    refine: int = 1
    n_lines: int = N_LINES
    progress: bool | None = None


@dataclass(frozen=True)
class ModelRun:
    """One run of the comparison.

    Attributes
    ----------
    model : str
        ``"full"`` or ``"CB k"`` (Craig–Bampton, ``k`` fixed-interface modes).
    n_modes : int
        Fixed-interface modes (0 for the full model).
    n_dof : int
        DOFs of the model.
    dt : float
        Time step (s).
    n_steps : int
    wall, cpu : float
        Wall and CPU time of the run, the model's build included, the step kernel's loading excluded (s).
    build_time : float
        Wall time of the model's build (assembly, reduction) (s), included in ``wall``.
    errors : MeasureErrors
        Against the reference (all 0 for the reference itself).
    peak_radius : float
        Peak orbit radius at the orbit node (m); NaN without one.
    contact_fraction : float
        (-); NaN without a rub plate.
    """

    model: str
    n_modes: int
    n_dof: int
    dt: float
    n_steps: int
    wall: float
    cpu: float
    build_time: float
    errors: MeasureErrors
    peak_radius: float = math.nan
    contact_fraction: float = math.nan

    @property
    def label(self) -> str:
        """``"CB 16, dt 2e-05 s"``."""
        return f"{self.model}, dt {self.dt:g} s"


@dataclass(frozen=True, repr=False)
class ModelComparison(Result):
    """A scene on its full model and on reduced models, each run measured against the reference (module docstring).

    Attributes
    ----------
    scene : Scene
        The scene as compared (its rotor refined when asked).
    runs : tuple of ModelRun
        The reference first, then the full model at the other steps, then each reduced model at each step.
    dofs : tuple of (int, str)
        The DOFs whose spectra are compared (the scene's recorded DOFs).
    orbit_node : int or None
        Node of the orbit error.
    sample_dt : float
        Interval the records are compared at (s): the coarsest step.
    n_lines : int
        Largest lines compared per DOF.
    kernel_time : float
        Time of the warm-up run (imports, the step kernel's loading or compiling) and of the kernel loads of later
        runs, not in any run's time (s).
    interrupted : str
        The signal that ended the comparison early ("SIGINT", "SIGTERM"), or "".
    """

    scene: Scene
    runs: tuple
    dofs: tuple
    orbit_node: int | None
    sample_dt: float
    n_lines: int
    kernel_time: float = 0.0
    interrupted: str = ""

    @property
    def reference(self) -> ModelRun:
        """The full model at the finest step."""
        return self.runs[0]

    def floors(self) -> dict[str, ModelRun]:
        """Each model's run at the finest step (a reduced model's error there is its reduction floor)."""
        dt = self.reference.dt
        return {r.model: r for r in self.runs if abs(r.dt - dt) <= 1e-9 * dt}

    def front(self) -> list[ModelRun]:
        """The runs no other run beats in both wall time and spectral error, fastest first (the reference last)."""
        runs = sorted(self.runs, key=lambda r: (r.wall, r.errors.spectral))
        front, best = [], math.inf
        for r in runs:
            if r.errors.spectral < best:
                front.append(r)
                best = r.errors.spectral
        return front

    def summary(self) -> list[str]:
        """The scene, the reference, and each model's error at the finest step."""
        ref = self.reference
        lines = [f"scene {self.scene.name}: {len(self.runs)} runs, errors against the full model ({ref.n_dof} DOFs) "
                 f"at dt {ref.dt:g} s",
                 f"spectral: worst of the {self.n_lines} largest lines of {len(self.dofs)} DOFs; orbit at node "
                 f"{self.orbit_node}"]
        for name, r in list(self.floors().items())[1:11]:
            lines.append(f"{name} ({r.n_dof} DOFs): spectral {100 * r.errors.spectral:.3g} %, orbit "
                         f"{100 * r.errors.orbit:.3g} %, {r.wall:.3g} s (full {ref.wall:.3g} s)")
        if self.interrupted:
            lines.append(f"INCOMPLETE: interrupted ({self.interrupted}) after {len(self.runs)} runs")
        return lines

    def table(self) -> str:
        """Every run with units: model, DOFs, dt (s), steps, wall and CPU time (s), errors (%), worst line."""
        from rotorred.writers import render_table

        header = ["model", "DOFs", "dt (s)", "steps", "wall (s)", "CPU (s)", "build (s)", "spectral (%)",
                  "orbit (%)", "contact (%)", "worst line"]
        rows = [[r.model, str(r.n_dof), f"{r.dt:g}", str(r.n_steps), f"{r.wall:.3g}", f"{r.cpu:.3g}",
                 f"{r.build_time:.3g}", _percent(r.errors.spectral), _percent(r.errors.orbit),
                 _percent(r.errors.contact), "reference" if k == 0 else r.errors.worst_line]
                for k, r in enumerate(self.runs)]
        return render_table(header, rows)

    def columns(self) -> tuple[list[str], list]:
        """The CSV's header and columns: one row a run, each DOF's spectral error in its own column (%)."""
        runs = self.runs
        header = ["model", "modes", "DOFs", "dt (s)", "steps", "wall (s)", "CPU (s)", "build (s)", "spectral error (%)",
                  "orbit error (%)", "contact error (%)", "worst line", "peak orbit radius (um)", "contact fraction (-)"]
        columns = [[r.model for r in runs], np.array([r.n_modes for r in runs]), np.array([r.n_dof for r in runs]),
                   [r.dt for r in runs], np.array([r.n_steps for r in runs]), [r.wall for r in runs],
                   [r.cpu for r in runs], [r.build_time for r in runs], [100 * r.errors.spectral for r in runs],
                   [100 * r.errors.orbit for r in runs], [100 * r.errors.contact for r in runs],
                   [r.errors.worst_line for r in runs], [1e6 * r.peak_radius for r in runs],
                   [r.contact_fraction for r in runs]]
        for d in self.dofs:
            header.append(f"spectral error {d[0]}{d[1]} (%)")
            columns.append([100 * r.errors.per_dof.get(d, (0.0, 0.0))[0] for r in runs])
        return header, columns

    def plot(self, ax=None, **options):
        """Wall time against spectral error of every run, each model's steps joined, the front drawn
        (:func:`rotorred.plots.compare.draw_comparison`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            ``title`` (str).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.compare import draw_comparison

        return draw_comparison(self, ax, **options)

    def to_xarray(self):
        """The runs as an :class:`xarray.Dataset` along dimension ``run``: model, DOFs, dt (s), times (s), errors
        (1, relative), worst line, peak orbit radius (m), contact fraction (1), and each DOF's spectral error
        (``run``, ``output``); the scene, reference and orbit node as attributes."""
        import xarray as xr

        runs = self.runs
        coords = {"run": label_coordinate("run", [r.label for r in runs], "model and time step"),
                  **dof_coordinates("output", self.dofs, "recorded DOF compared")}

        def var(values, units, long_name):
            return ("run", np.asarray(values), {"units": units, "long_name": long_name})
        data = {"model": ("run", np.array([r.model for r in runs], dtype=object), {"units": "1", "long_name": (
                    "full, or CB k: Craig-Bampton with k fixed-interface modes")}),
                "n_modes": var([r.n_modes for r in runs], "1", "fixed-interface modes (0: full)"),
                "n_dof": var([r.n_dof for r in runs], "1", "degrees of freedom of the model"),
                "dt": var([r.dt for r in runs], "s", "time step"),
                "n_steps": var([r.n_steps for r in runs], "1", "time steps"),
                "wall_time": var([r.wall for r in runs], "s", "wall time, build included, kernel load excluded"),
                "cpu_time": var([r.cpu for r in runs], "s", "CPU time, build included, kernel load excluded"),
                "build_time": var([r.build_time for r in runs], "s", "wall time of assembly and reduction"),
                "spectral_error": var([r.errors.spectral for r in runs], "1", (
                    f"worst relative error of the {self.n_lines} largest lines of every DOF")),
                "orbit_error": var([r.errors.orbit for r in runs], "1", "relative error of the peak orbit radius"),
                "contact_error": var([r.errors.contact for r in runs], "1", "relative error of the contact fraction"),
                "worst_line": ("run", np.array([r.errors.worst_line for r in runs], dtype=object), {
                    "units": "1", "long_name": "DOF and frequency of the worst line"}),
                "peak_orbit_radius": var([r.peak_radius for r in runs], "m", "peak orbit radius at the orbit node"),
                "contact_fraction": var([r.contact_fraction for r in runs], "1", "fraction of the record in contact"),
                "dof_spectral_error": (("run", "output"), np.array(
                    [[r.errors.per_dof.get(d, (0.0, 0.0))[0] for d in self.dofs] for r in runs]), {
                    "units": "1", "long_name": "worst relative error of the DOF's largest lines"})}
        attrs = {"title": f"reduced against full: scene {self.scene.name}", "scene": self.scene.name,
                 "reference": f"full model, dt {self.reference.dt:g} s", "sample_dt_s": float(self.sample_dt),
                 "orbit_node": -1 if self.orbit_node is None else int(self.orbit_node),
                 "interrupted": self.interrupted or "no"}
        return xr.Dataset(data, coords=coords, attrs=attrs)


def _percent(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{100 * x:.3g}"


# --------------------------------------------------------------------------- checks
def check_comparison(scene: Scene, options: CompareOptions) -> Scene:
    """Refuse what cannot be compared, before any run: the scene as compared (rotor refined).

    Parameters
    ----------
    scene : Scene
    options : CompareOptions

    Returns
    -------
    Scene
        With its rotor refined ``options.refine`` times.

    Raises
    ------
    InputError
        A scene without recorded DOFs, a run-up, harmonic balance or tolerance scene; mode counts that are not
        whole numbers from 1 to the interior DOFs; steps that are not whole fractions of the coarsest, of
        ``solver.duration`` and of ``solver.record_start``.
    """
    refine = checks.integer("refine", options.refine, ge=1)
    checks.integer("n_lines", options.n_lines, ge=1)
    if not scene.output.dofs:
        checks.fail("output.nodes", list(scene.output.nodes), "must name at least one node: the comparison measures "
                    "the recorded DOFs' spectra")
    if scene.runup is not None:
        checks.fail("runup", "[runup]", "must not be given: the comparison runs a scene at constant speeds")
    if scene.solver.method == "harmonic-balance":
        checks.fail("solver.method", scene.solver.method, "must be newmark or hht: the comparison steps in time")
    if scene.solver.tolerance is not None:
        checks.fail("solver.tolerance", scene.solver.tolerance, "must not be given: the comparison sets the model "
                    "and the time step itself")
    spool_frequencies(scene)  # a spectrum needs a turning spool
    if refine > 1:
        scene = replace(scene, rotor=scene.rotor.refined(refine), rotor_source=f"{scene.rotor_source} refined({refine})")
    _check_modes(scene, options.modes)
    _check_dts(scene, _dts(scene, options))
    return scene


def _check_modes(scene: Scene, modes) -> None:
    from rotorred.linear.reduction import default_boundary_nodes
    from rotorred.model.assembly import assemble

    dofs = assemble(scene.rotor).dofs  # its DOF map (milliseconds): the interior DOFs exactly
    n_dof = dofs.n_dof
    n_interior = n_dof - sum(len(dofs.node_dofs(n)) for n in default_boundary_nodes(scene.rotor, _extra_nodes(scene)))
    allowed = f"must be whole numbers from 1 to {n_interior}, the interior DOFs of the {n_dof}-DOF model"
    if not modes:
        checks.fail("modes", list(modes), allowed)
    for k in modes:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= n_interior:
            checks.fail("modes", list(modes), allowed)
    if len(set(modes)) != len(modes):
        checks.fail("modes", list(modes), "must give each count once")


def _extra_nodes(scene: Scene) -> tuple[int, ...]:
    return tuple(sorted(set(scene.solver.boundary_nodes) | {p.node for p in scene.plates}))


def _dts(scene: Scene, options: CompareOptions) -> tuple[float, ...]:
    return tuple(sorted(options.dts or (scene.solver.dt,), reverse=True))


def _check_dts(scene: Scene, dts: tuple[float, ...]) -> None:
    s = scene.solver
    for dt in dts:
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            checks.fail("dts", list(dts), "must be numbers > 0", "s")
        for name, t in (("solver.duration", s.duration), ("solver.record_start", s.record_start),
                        ("the coarsest dt", dts[0])):
            if not is_whole_steps(t, dt):
                checks.fail("dts", dt, f"must be a whole fraction of {name} = {t:g} s (the comparison steps to it "
                            f"and resamples every record to the coarsest dt, {dts[0]:g} s)", "s")
    if len(set(dts)) != len(dts):
        checks.fail("dts", list(dts), "must give each step once", "s")


# --------------------------------------------------------------------------- runs
def compare_models(scene: Scene, options: CompareOptions = CompareOptions(),
                   interrupts: Mapping[type[BaseException], str] = progress.INTERRUPTS) -> ModelComparison:
    """Run ``scene`` on its full model and on each reduced model, at each step, and measure each against the full
    model at the finest step (module docstring).

    Parameters
    ----------
    scene : Scene
        A constant-speed scene stepped in time, with recorded DOFs.
    options : CompareOptions
        Mode counts, time steps (s), refinement, lines compared, progress.
    interrupts : mapping of exception type to str
        Exceptions that end the comparison with the runs done, and the signal each stands for; one before the
        reference is done is raised as it came.

    Returns
    -------
    ModelComparison

    Raises
    ------
    InputError
        Before any run (:func:`check_comparison`).
    SceneDiverged
        If a run diverges.
    """
    scene = check_comparison(scene, options)
    dts = _dts(scene, options)
    plan = [(None, dt) for dt in reversed(dts)] + [(k, dt) for k in options.modes for dt in reversed(dts)]
    recorded = _recording_scene(scene)
    orbit_node = scene.plates[0].node if scene.plates else None
    runs, kernel, interrupted = [], [_warm_up(recorded, dts[0])], ""
    progress.stage("comparing %s: the full model and %d reduced models at %d steps, %d runs", scene.name,
                   len(options.modes), len(dts), len(plan), logger=LOG)
    with progress.bar(len(plan), "compare", "run", progress=options.progress) as bar:
        try:
            for n_modes, dt in plan:
                runs.append(_run(recorded, n_modes, dt, kernel, options.progress))
                bar.update(1)
        except tuple(interrupts) as exc:
            if not runs:
                raise
            interrupted = next(name for kind, name in interrupts.items() if isinstance(exc, kind))
    if orbit_node is None:
        orbit_node = _largest_orbit(runs[0][1], scene.output.dofs)
    return _measured(scene, runs, orbit_node, dts[0], options.n_lines, kernel[0], interrupted)


def _recording_scene(scene: Scene) -> Scene:
    """``scene`` recording the rub node's x and y as well (the orbit error's), without its no-rub comparison."""
    out = scene.output
    nodes, directions = out.nodes, out.directions
    if scene.plates:
        nodes = nodes + tuple(n for n in (scene.plates[0].node,) if n not in nodes)
        directions = directions + tuple(d for d in ("x", "y") if d not in directions)
    return replace(scene, output=replace(out, nodes=nodes, directions=directions, compare_normal=False))


#: steps of the warm-up run (:func:`_warm_up`)
WARM_UP_STEPS = 10


def _warm_up(scene: Scene, dt: float) -> float:
    """A short untimed run of the full model (:data:`WARM_UP_STEPS` steps of ``dt``), which imports the transient's
    modules and loads the step kernel once (0.3 s of imports the first run would otherwise count); its wall time
    (s)."""
    t0 = time.perf_counter()
    short = replace(scene.solver, model="full", dt=dt, duration=WARM_UP_STEPS * dt, record_start=0.0)
    case = replace(scene, solver=short)
    with progress.muted():
        respond(case, build_model(case), progress=False)
    return time.perf_counter() - t0


def _run(scene: Scene, n_modes: int | None, dt: float, kernel: list, shown: bool | None = False) -> tuple:
    """One run: (ModelRun without errors, its Response); ``kernel[0]`` gathers the kernel load time; ``shown``: the
    transient's own stage line and step bar (:func:`rotorred.scenes.run.respond`)."""
    solver = replace(scene.solver, dt=dt, model="full" if n_modes is None else "reduced", modes=n_modes,
                     cutoff_hz=None)
    case = replace(scene, solver=solver)
    name = "full" if n_modes is None else f"CB {n_modes}"
    progress.stage("%s on %s at dt = %g s", scene.name, name, dt, logger=LOG)
    t0, c0 = time.perf_counter(), time.process_time()
    with progress.muted():  # the line above says it
        model = build_model(case)
    c_build = time.process_time() - c0
    response = respond(case, model, progress=shown)  # its steps and time left on a terminal, when long
    load = float(response.counters.get("kernel_load_time", 0.0))
    wall, cpu = time.perf_counter() - t0 - load, time.process_time() - c0 - load
    kernel[0] += load
    LOG.debug("%s dt %g: %.3f s (build %.3f s, CPU %.3f s)", name, dt, wall, model.build_time, c_build)
    run = ModelRun(model=name, n_modes=n_modes or 0, n_dof=int(model.model.n_dof), dt=dt, n_steps=response.n_steps,
                   wall=wall, cpu=max(cpu, 0.0), build_time=model.build_time, errors=MeasureErrors(0.0, 0.0, 0.0))
    return run, response


def _largest_orbit(response, dofs) -> int | None:
    """The recorded node (x and y) with the largest peak orbit radius, None if no node has both."""
    nodes = [n for n in dict.fromkeys(n for n, _ in dofs) if (n, "x") in dofs and (n, "y") in dofs]
    if not nodes:
        return None
    return max(nodes, key=lambda n: float(np.hypot(response.outputs[(n, "x")], response.outputs[(n, "y")]).max()))


def _measured(scene: Scene, runs: list, orbit_node, sample_dt: float, n_lines: int, kernel_time: float,
              interrupted: str) -> ModelComparison:
    """The comparison: each run's measures (:func:`rotorred.signals.compare.response_measures`) against the
    reference's (the first run)."""
    speeds = spool_frequencies(scene)
    dofs = scene.output.dofs
    measures = [response_measures(resp.outputs, run.dt, sample_dt, speeds, dofs, orbit_node,
                                  1.0 - resp.contacts[0].fraction("open") if resp.contacts else None)
                for run, resp in runs]
    threshold = scene.output.line_threshold
    out = [replace(run, errors=measure_errors(m, measures[0], n_lines, threshold), peak_radius=m.peak_radius,
                   contact_fraction=m.contact_fraction) for (run, _), m in zip(runs, measures)]
    return ModelComparison(scene=scene, runs=tuple(out), dofs=tuple(dofs), orbit_node=orbit_node,
                           sample_dt=sample_dt, n_lines=n_lines, kernel_time=kernel_time, interrupted=interrupted)


# --------------------------------------------------------------------------- files
def format_comparison(comparison: ModelComparison) -> str:
    """The printed report: what was compared and against what, the table of every run (units in its header), each
    reduced model's floor, and the time left out.

    Parameters
    ----------
    comparison : ModelComparison

    Returns
    -------
    str
    """
    ref, c = comparison.reference, comparison
    head = [f"INCOMPLETE: interrupted ({c.interrupted}) after {len(c.runs)} runs"] if c.interrupted else []
    dofs = ", ".join(f"{n}{d}" for n, d in c.dofs)
    head += [f"scene {c.scene.name} ({c.scene.rotor_source}): reference the full model, {ref.n_dof} DOFs, "
             f"{c.scene.solver.method} dt = {ref.dt:g} s, record {c.scene.solver.record_start:g}-"
             f"{c.scene.solver.duration:g} s compared at {c.sample_dt:g} s",
             f"spectral: worst relative error of the {c.n_lines} largest lines (0 Hz excluded) of {dofs}; orbit: peak "
             f"orbit radius at node {c.orbit_node} (reference {1e6 * ref.peak_radius:.4g} um); contact: fraction "
             f"in contact (reference {100 * ref.contact_fraction:.3g} %)"]
    floors = [f"{name} {_percent(r.errors.spectral)} %" for name, r in c.floors().items() if name != "full"]
    tail = [f"at dt = {ref.dt:g} s (the reduction's floor), spectral error: {', '.join(floors)}"] if floors else []
    tail.append(f"times: wall and CPU of each run, its model's build included; warm-up and step-kernel loads "
                f"({c.kernel_time:.2f} s) left out")
    return "\n".join(head + [c.table()] + tail)


def write_comparison(comparison: ModelComparison, folder, provenance=None) -> list:
    """Stage ``compare.csv`` (a row a run, :meth:`ModelComparison.columns`), ``compare.png``
    (:meth:`ModelComparison.plot`) and ``compare.txt`` (:func:`format_comparison`) in ``folder``
    (:class:`rotorred.writers.OutputFolder`); a ``provenance`` (:class:`rotorred.provenance.Provenance`, with the
    scene) goes on top of ``compare.txt`` and is written as ``scene.toml``.

    Parameters
    ----------
    comparison : ModelComparison
    folder : rotorred.writers.OutputFolder
        The open output folder; the files are staged, and written when it commits.
    provenance : Provenance, optional

    Returns
    -------
    list of Path
        The staged files.
    """
    from rotorred.plots.axes import save_figure  # matplotlib only when figures are written
    from rotorred.writers import write_csv, write_text

    header, columns = comparison.columns()
    files = [write_csv(folder.staged("compare.csv"), header, columns),
             save_figure(comparison.plot(), folder.staged("compare.png"))]
    text = format_comparison(comparison)
    files.append(write_text(folder.staged("compare.txt"), (text if provenance is None else provenance.on_top(text))
                            + "\n"))
    if provenance is not None:
        files.append(write_text(folder.staged(provenance.file_name), provenance.file_text()))
    return files
