"""``run_map``: check a map, run its points (serially or on Dask), and write the dataset, tables and figures.

Order of work
    1. Check: the map's size at once from its first point, then every grid point's scene loaded, validated and
       within the limits (:func:`rotorred.maps.store.check_map_size`; refused unless ``force``), the
       folder is locked (a second map into it is refused), and points already in
       ``folder/points`` of another map are refused. Nothing runs before this passes.
    2. Run the points not on disk (:func:`rotorred.maps.execute.run_points`), each written as
       it finishes, with a progress bar (points done, failures, ETA).
    3. Build the dataset from every point on disk and write ``map.nc``, ``map.csv``,
       ``map_lines.csv``, the figures and ``map.txt`` through a staged
       :class:`rotorred.writers.OutputFolder`.

Interrupts and lost clusters
    An interrupt in step 2 (``interrupts``: SIGINT's ``KeyboardInterrupt`` and whatever the caller names, the
    command line's SIGTERM), or a Dask cluster lost under it (a worker killed more often than Dask retries, a
    scheduler that died or cannot be reached: :func:`rotorred.maps.execute.is_lost`), ends the run there: step 3
    runs on the points finished so far with SIGINT and SIGTERM held back (:func:`rotorred.writers.signals_held`, a
    second signal does not cut it), the folder is marked INCOMPLETE with the reason, :attr:`MapRun.interrupt` names
    the signal, and the same command later completes the map. Step 3 of a complete map holds the signals back too (a
    signal then is named in :attr:`MapRun.interrupt` once the map is written whole), so that no signal leaves points
    without their dataset. A signal before step 2 (the checks, the model) leaves the folder's earlier result.
"""

from __future__ import annotations

import textwrap
import time
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from rotorred.maps.execute import connect, is_lost, local_cluster, run_points
from rotorred.maps.spec import MapSpec
from rotorred.scenes.keys import key_unit
from rotorred.maps.store import PointStore, check_map_size, to_dataset, write_tables
from rotorred.progress import bar as progress_bar
from rotorred.progress import interrupt_in, stage
from rotorred.provenance import Provenance
from rotorred.results import Result
from rotorred.scenes.run import table_dof
from rotorred.progress import INTERRUPTS, interrupt_name
from rotorred.writers import OutputFolder, render_table, signals_held, write_netcdf, write_text

__all__ = ["MapRun", "run_map", "format_map"]


@dataclass(frozen=True, repr=False)
class MapRun(Result):
    """What :func:`run_map` did: the map, its dataset, the files written, the counts, why it stopped early.

    Attributes
    ----------
    spec : MapSpec
        The map: its scene, varied keys and sweeps.
    dataset : xarray.Dataset
        Every point on disk, labelled (:func:`rotorred.maps.store.to_dataset`; ``map.nc``).
    files : tuple of Path
        The files of the map's folder.
    n_run, n_resumed, n_failed : int
        Points run now, read back from an earlier run, and without results (diverged or failed).
    incomplete : str or None
        Why the map stopped early (the folder is marked INCOMPLETE), or None.
    wall_time : float
        Time the run took (s).
    interrupt : str
        The signal that ended the map ("SIGINT", "SIGTERM": the caller's ``interrupts``; one that came as a complete
        map was written is named too, the map complete), or "" (none; a lost cluster, if :attr:`incomplete`).
    """

    spec: MapSpec
    dataset: object
    files: tuple
    n_run: int
    n_resumed: int
    n_failed: int
    incomplete: str | None
    wall_time: float
    interrupt: str = ""

    def summary(self) -> list[str]:
        """The map's scene, keys and sweeps, the points run, resumed and failed, the classes found, and whether it
        stopped early."""
        spec, done = self.spec, int(np.count_nonzero(self.dataset["status"].values != ""))
        counts = Counter(str(k) for k in self.dataset["kind"].values.ravel() if k)
        lines = [f"map of {spec.scene} over " + " x ".join(f"{a.key} ({len(a.values)} values)" for a in spec.axes)
                 + f", sweeps {'/'.join(spec.directions)} ({'cold starts' if spec.cold else 'continued'})",
                 f"{done} of {spec.n_points} points: {self.n_run} run, {self.n_resumed} "
                 f"resumed, {self.n_failed} without results; wall time {self.wall_time:.3g} s",
                 "classes: " + (", ".join(f"{k} {n}" for k, n in counts.most_common()) or "none")]
        if self.incomplete:
            lines += textwrap.wrap(f"INCOMPLETE: {self.incomplete}", 110)
        if self.files:
            lines.append(f"{len(self.files)} files in {Path(self.files[0]).parent}")
        return lines

    def plot(self, ax=None, *, kind: str = "bifurcation", direction: str | None = None, quantity: str = "class"):
        """One figure of the map (:func:`rotorred.maps.figures.draw`): ``kind`` "bifurcation" (the default: the
        Poincare samples of every sweep along the first key), "lines" (line amplitudes and contact of one sweep; ``ax``
        a pair of axes), "waterfall" (the labelled lines of one sweep) or "heatmap" (``quantity`` "class", "contact",
        "explained" or "amplitude" of one sweep over the first two keys).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into (a pair of axes for "lines"); default a new figure.
        kind : {"bifurcation", "lines", "waterfall", "heatmap"}
            The figure; "heatmap" needs two varied keys.
        direction : str, optional
            The sweep of "lines", "waterfall" and "heatmap" (:attr:`MapSpec.directions`); default the first.
        quantity : {"class", "contact", "explained", "amplitude"}
            The heat map's quantity.

        Returns
        -------
        matplotlib.figure.Figure

        Raises
        ------
        InputError
            If ``kind`` is unknown or ``direction`` is not a sweep of the map.
        """
        from rotorred.maps.figures import draw

        return draw(self.dataset, self.spec, kind, ax, direction=direction, quantity=quantity)

    def to_xarray(self):
        """The map's dataset (:attr:`dataset`, module :mod:`rotorred.maps.store`), as ``map.nc`` holds it."""
        return self.dataset


class _Progress:
    """The progress bar over the map's points (:func:`rotorred.progress.bar`), with the failures in its postfix."""

    def __init__(self, total: int, done: int, progress: bool | None):
        self.failed = 0
        self.bar = progress_bar(total, "map", "point", progress=progress, initial=done)

    def __call__(self, direction: str, index: tuple, point) -> None:
        self.failed += point.status != "ok"
        self.bar.set_postfix(failed=self.failed, refresh=False)
        self.bar.update(1)

    def close(self) -> None:
        self.bar.close()


def _client(workers: int | None, scheduler: str | None):
    """None for a serial map (``workers == 0``), else a client of ``scheduler`` or of a new LocalCluster."""
    if scheduler:
        return connect(scheduler)
    if workers == 0:
        return None
    return local_cluster(workers)


def run_map(spec: MapSpec, out: str | Path, *, workers: int | None = None, scheduler: str | None = None,
            progress: bool | None = None, figures: bool = True, provenance: Provenance | None = None,
            force: bool = False, interrupts=INTERRUPTS) -> MapRun:
    """Run a map into ``out`` (module docstring); resumable.

    Parameters
    ----------
    spec : MapSpec
        The map: base scene, varied keys and their values, sweeps.
    out : str or Path
        Output folder; its ``points/`` are kept between runs.
    workers : int, optional
        Local Dask workers (default: one per core); 0 runs serially in this process.
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:port``), in place of a local cluster.
    progress : bool, optional
        The progress bar: True always, False never, None (default) on a terminal when the ``"rotorred"`` logger
        passes INFO (:func:`rotorred.progress.bar`).
    figures : bool
        Write the figures.
    provenance : rotorred.provenance.Provenance, optional
        What made the map (the command line's, with the base scene): written as ``scene.toml``, at the top of
        ``map.txt`` and as attributes of ``map.nc``.
    force : bool
        Go on with a map beyond the size limits (:mod:`rotorred.scenes.budget`).
    interrupts : mapping of exception type to str
        The exceptions that end the map where it is, its points kept (module docstring), and the signal each stands
        for (default: SIGINT's ``KeyboardInterrupt``).

    Returns
    -------
    MapRun

    Raises
    ------
    InputError
        If a point's scene is invalid, the map is beyond the size limits (without ``force``), or the folder holds
        points of another map, before any point runs.
    """
    import os

    t0 = time.perf_counter()
    at_once = 1 if scheduler or workers == 0 else (workers or os.cpu_count() or 1)
    check_map_size(spec, at_once, force)  # 1. the whole map at once, then every point, before anything runs
    scenes = spec.scenes()
    out = Path(out)
    with OutputFolder(out) as folder:
        store = PointStore(out, spec)
        n_resumed = len(store.read())
        client = _client(workers, scheduler) if n_resumed < spec.n_points else None
        stage("running %d of %d points (%d kept from an earlier run) %s", spec.n_points - n_resumed, spec.n_points,
              n_resumed, "in this process" if client is None else "on Dask")
        bar = _Progress(spec.n_points, n_resumed, progress)

        def close():
            bar.close()
            if client is not None:
                _close(client, scheduler)
        try:
            run_points(spec, store, client, on_point=bar)
            stopped = None
        except tuple(interrupts) as exc:
            stopped = exc
        except Exception as exc:  # noqa: BLE001 -- an interrupt's error or a lost cluster; anything else is raised
            stopped = interrupt_in(exc, tuple(interrupts))
            if stopped is None and (client is None or not is_lost(exc)):
                close()
                raise
            stopped = stopped or exc
        run = _committed(spec, scenes[0], store, folder, (figures, provenance, n_resumed), stopped, interrupts, close)
    return replace(run, wall_time=time.perf_counter() - t0)


def _committed(spec, scene, store, folder, outputs: tuple, stopped, interrupts, close) -> MapRun:
    """Close the progress bar and the cluster (``close``), build the map of every point on disk, write and commit it,
    all with SIGINT and SIGTERM held back (a signal cannot leave the points without their dataset); INCOMPLETE when
    ``stopped`` (an interrupt or a lost cluster) ended the run. A signal that came meanwhile is dropped once the
    map is committed and named in :attr:`MapRun.interrupt` (the exit status is the first signal's)."""
    figures, provenance, n_resumed = outputs
    interrupt = interrupt_name(stopped, interrupts) if isinstance(stopped, tuple(interrupts)) else ""
    run = None
    try:
        with signals_held():
            close()
            points = store.read()
            incomplete = None if stopped is None else _stopped(stopped, interrupt, len(points), spec.n_points)
            run = MapRun(spec, _dataset(spec, scene, points), (), len(points) - n_resumed, n_resumed,
                         sum(p.status != "ok" for p in points.values()), incomplete, 0.0, interrupt)
            _write(run, folder, figures, provenance)
            run = replace(run, files=tuple(folder.commit(incomplete)))
    except tuple(interrupts) as exc:
        if run is None or not folder.committed:
            raise
        run = replace(run, interrupt=interrupt or interrupt_name(exc, interrupts))
    return run


def _stopped(exc: BaseException, interrupt: str, done: int, total: int) -> str:
    """Why a map stopped early: the signal, or the lost cluster (the first line of its error), and the points done."""
    if interrupt:
        cause = f"interrupted ({interrupt})"
    else:
        why = (str(exc).strip().splitlines() or [""])[0].rstrip(":")[:200]
        cause = f"the Dask cluster was lost ({type(exc).__name__}: {why})"
    return f"{cause} after {done} of {total} points; run the same command again to complete the map"


def _close(client, scheduler: str | None) -> None:
    """Close the client, and the local cluster it started (not a cluster given by ``--scheduler``); a cluster
    already lost is let go (its errors are not the map's)."""
    cluster = None if scheduler else client.cluster
    try:
        client.close(timeout=10)
        if cluster is not None:
            cluster.close(timeout=10)
    except Exception as exc:  # noqa: BLE001 -- closing what is left of a lost cluster
        if not is_lost(exc):
            raise


def _dataset(spec: MapSpec, scene, points: dict):
    d = table_dof(scene)
    attrs = {"scene": spec.scene, "settings": repr(dict(spec.settings)), "ratios": repr(dict(spec.ratios)),
             "table_dof": f"{d[0]}:{d[1]}", "continuation": "cold" if spec.cold else "warm",
             "directions": ",".join(spec.directions)}
    return to_dataset(spec, points, tuple(scene.output.nodes), attrs)


def _write(run: MapRun, folder: OutputFolder, figures: bool, provenance: Provenance | None) -> list[Path]:
    staging, ds = folder.staging, run.to_xarray()
    attributes = provenance.netcdf_attributes() if provenance is not None else None
    files = [write_netcdf(staging / "map.nc", ds, attributes), *write_tables(ds, staging)]
    if figures:
        from rotorred.maps.figures import map_figures

        files += map_figures(run, staging)
    text = format_map(ds, run.spec)
    files.append(write_text(staging / "map.txt", (text if provenance is None else provenance.on_top(text)) + "\n"))
    if provenance is not None:
        files.append(write_text(staging / provenance.file_name, provenance.file_text()))
    return files


def format_map(ds, spec: MapSpec) -> str:
    """Text table of a map: per point, the class, settling time (s), explained share, contact fraction and
    number of impacts.

    Parameters
    ----------
    ds : xarray.Dataset
        The map's dataset (:func:`rotorred.maps.store.to_dataset`, :attr:`MapRun.dataset`).
    spec : MapSpec
        The map; its keys are printed in their display units (:func:`rotorred.scenes.keys.key_unit`).

    Returns
    -------
    str
        A heading line and the table, a row per point on disk.
    """
    status = ds["status"].values
    rows = []
    for at in zip(*np.nonzero(status != "")):
        point = {name: ds[name].values[at] for name in ("status", "kind", "settling_time", "explained_share",
                                                         "contact_fraction", "n_impacts", "reason")}
        keys = [f"{key_unit(a.key)[0] * a.values[i]:.6g}" for a, i in zip(spec.axes, at[1:])]
        rows.append([str(ds["direction"].values[at[0]]), *keys,
                     point["kind"] if point["status"] == "ok" else f"{point['status']}: {point['reason'][:60]}",
                     "-" if np.isnan(point["settling_time"]) else f"{point['settling_time']:.3g}",
                     f"{point['explained_share']:.4f}", f"{point['contact_fraction']:.3f}", str(point["n_impacts"])])
    header = ["sweep", *[a.label for a in spec.axes], "class", "settled (s)", "explained", "contact", "impacts"]
    counts = Counter(str(k) for k in ds["kind"].values.ravel() if k)
    done = int(np.sum(status != ""))
    return (f"map of {spec.scene}: {done} of {spec.n_points} points; classes: "
            + ", ".join(f"{k} {n}" for k, n in counts.most_common()) + "\n" + render_table(header, rows))
