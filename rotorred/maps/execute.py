"""Running a map: its chains of points, serially or on a Dask cluster, written as they finish.

Serial (``client=None``)
    Chains one after the other in this process.

Dask (``client`` a :class:`distributed.Client`)
    Each point is one task that depends on the previous point of its chain (it takes that
    point's final state), so a chain runs in order while chains run side by side; Dask keeps a
    chain's tasks on the worker that holds its previous result. The structural model of each
    model key is built once, here, and scattered to every worker (``broadcast=True``), not
    rebuilt per point; each worker process loads the compiled kernels once (numba's on-disk
    cache). A worker that dies has its tasks (and any lost result they need) recomputed by Dask
    on another worker: every point is deterministic, so the dataset is the same.

Both write each point (:class:`rotorred.maps.store.PointStore`) as soon as it has finished and
skip the points already on disk: a map that was interrupted resumes where it stopped, each
resumed chain from its last finished point's final state. ``on_point`` is called after each
point (the progress bar).

A cluster lost under a map (:func:`is_lost`: a worker killed more often than Dask retries, a scheduler gone, or one
without workers for :data:`NO_WORKER_WAIT` s) ends :func:`run_points` with that error; the points finished are on
disk (:func:`rotorred.maps.run.run_map` writes them, marked INCOMPLETE).
"""

from __future__ import annotations

from collections.abc import Callable

from rotorred.maps.point import PointResult, StartState, run_point
from rotorred.progress import muted
from rotorred.maps.spec import Chain, MapSpec
from rotorred.maps.store import PointStore
from rotorred.scenes.run import SceneModel, build_model, model_key

__all__ = ["run_points", "local_cluster", "connect", "is_lost"]


def _models(spec: MapSpec) -> dict:
    """One structural model per model key of the grid (most maps: one)."""
    models = {}
    for scene in spec.scenes():
        key = model_key(scene)
        if key not in models:
            models[key] = build_model(scene)
    return models


def _pending(spec: MapSpec, chain: Chain, done: dict) -> tuple[list, StartState | None]:
    """The chain's points not yet on disk, and the start state of the first of them."""
    points = chain.points()
    start = None
    for k, point in enumerate(points):
        if point not in done:
            return points[k:], None if spec.cold else start
        start = done[point].final
    return [], None


#: models as this process uses them, one per model key (a worker's copy of a scattered model)
_MODELS: dict = {}


def _local(model: SceneModel) -> SceneModel:
    """This process's copy of ``model``, made once per model key.

    Dask delivers a scattered model's arrays in its message buffers, which need not be 8-byte
    aligned; LAPACK (``scipy.linalg.solve``) refuses unaligned arrays. A deep copy is aligned.
    """
    import copy

    if model.key not in _MODELS:
        _MODELS[model.key] = copy.deepcopy(model)
    return _MODELS[model.key]


def _point_task(scene, model: SceneModel, previous, cold: bool, limit: float | None) -> PointResult:
    """Run one point from the previous point's final state (a StartState, a PointResult, or None)."""
    start = previous.final if isinstance(previous, PointResult) else previous
    with muted():  # the map's bar counts the points; a point's segments say nothing
        return run_point(scene, _local(model), None if cold else start, limit)


def run_points(spec: MapSpec, store: PointStore, client=None,
               on_point: Callable[[str, tuple, PointResult], None] | None = None) -> dict:
    """Run every point of ``spec`` not yet in ``store``; return all finished points.

    Returns
    -------
    dict of (direction, index) to PointResult
    """
    done = store.read()
    models = _models(spec)
    report = on_point or (lambda *_: None)
    if client is None:
        return _run_serial(spec, store, models, done, report)
    return _run_dask(spec, store, client, models, done, report)


def _run_serial(spec: MapSpec, store: PointStore, models: dict, done: dict, report) -> dict:
    """The chains one after the other, BLAS on one thread as on a worker (the same arithmetic, so the
    same answer to the last bit: a chaotic point amplifies a rounding difference e^(lambda t))."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        for chain in spec.chains():
            points, start = _pending(spec, chain, done)
            for direction, index in points:
                scene = spec.scene_at(index)
                p = _point_task(scene, models[model_key(scene)], start, spec.cold, spec.limit)
                store.write(direction, index, p)
                done[(direction, index)] = p
                report(direction, index, p)
                start = p.final
    return done


def _run_dask(spec: MapSpec, store: PointStore, client, models: dict, done: dict, report) -> dict:
    scattered = {key: client.scatter(m, broadcast=True) for key, m in models.items()}
    futures = {}
    for chain in spec.chains():
        points, start = _pending(spec, chain, done)
        previous = start
        for direction, index in points:
            scene = spec.scene_at(index)
            previous = client.submit(_point_task, scene, scattered[model_key(scene)], previous, spec.cold, spec.limit,
                                     pure=False)
            futures[previous] = (direction, index)
    for future in _completed(client, futures):
        direction, index = futures[future]
        p = future.result()
        store.write(direction, index, p)
        done[(direction, index)] = p
        report(direction, index, p)
    return done


#: how long a map waits for a worker when its scheduler has none (s): a killed worker without a nanny, or
#: the last one gone, leaves the tasks waiting for ever
NO_WORKER_WAIT = 60.0


class NoWorkers(RuntimeError):
    """The scheduler of a map has had no worker for :data:`NO_WORKER_WAIT` s."""


def _completed(client, futures, poll: float = 2.0):
    """The futures as they finish (any order); :class:`NoWorkers` when the scheduler has had no worker for
    :data:`NO_WORKER_WAIT` s meanwhile."""
    import time

    from distributed import wait

    pending, idle_since = set(futures), None
    while pending:
        try:
            done = wait(pending, timeout=poll, return_when="FIRST_COMPLETED").done
        except TimeoutError:
            done = set()
        pending -= done
        yield from done
        if done or client.scheduler_info()["workers"]:
            idle_since = None
        elif idle_since is None:
            idle_since = time.monotonic()
        elif time.monotonic() - idle_since > NO_WORKER_WAIT:
            raise NoWorkers(f"its scheduler has had no worker for {NO_WORKER_WAIT:g} s")


#: the periodic callbacks of the workers', nannies' and scheduler's event loops, slowed (local_cluster)
QUIET = {"distributed.admin.tick.interval": "5s", "distributed.worker.memory.monitor-interval": "5s",
         "distributed.admin.system-monitor.interval": "10s", "distributed.deploy.cluster-repr-interval": "10s"}


def local_cluster(n_workers: int | None = None):
    """A :class:`distributed.LocalCluster` with one single-threaded worker process per core, BLAS pinned to
    one thread, and its client.

    Two of Dask's worker defaults are changed, each measured on a rig point (0.61 s in a plain
    process): its ``MALLOC_TRIM_THRESHOLD_`` = 65536 (set before the worker starts) fixes glibc's
    thresholds, which turns off glibc's adaptive mmap threshold, so every large temporary array of
    the line fit is mapped and faulted in afresh (0.86 s per point in a worker); and the
    statistical profiler, which samples every thread's stack every 10 ms, is off. A worker runs its
    tasks in a thread, whose own malloc arena made the same point 9 % slower than in the main thread
    (0.75 against 0.69 s; equal with ``MALLOC_ARENA_MAX=1``), so the workers have one arena.

    The event loops' periodic callbacks run less often (:data:`QUIET`): the loop-blocked check
    every 5 s (default 20 ms), the memory monitor every 5 s (100 ms), the system monitor every
    10 s (500 ms), the cluster's repr every 10 s (500 ms). Each callback needs the GIL, which the
    task thread releases in every numpy call; with every core busy the callback thread then waits
    for a core while holding the GIL, and the task waits for it. On a 41 x 4 map on 2 workers a
    point cost 1.086 s with the defaults, 0.886 s so (0.902 s serially), and the map took 77.6
    against 95.1 s.
    """
    import os

    import dask
    from distributed import Client, LocalCluster

    n = n_workers or os.cpu_count() or 1
    one = {v: "1" for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS",
                            "MALLOC_ARENA_MAX")}
    with dask.config.set({"distributed.worker.profile.enabled": False, "distributed.nanny.pre-spawn-environ": one,
                          **QUIET}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0", env=one)
    return Client(cluster)


def connect(address: str, timeout: float = 10.0):
    """A client of the scheduler at ``address``; a clear error after ``timeout`` s when it cannot be reached, and at
    once when what answers there is not a Dask scheduler (a web server's bytes, read as a Dask frame, once asked for
    3 EiB: an "out of memory" error before)."""
    from distributed import Client

    from rotorred import checks

    try:
        return Client(address, timeout=f"{timeout}s")
    except (OSError, TimeoutError) as exc:
        checks.fail("--scheduler", address, f"must be a reachable Dask scheduler address (tcp://host:port); "
                    f"none answered within {timeout:g} s ({type(exc).__name__})")
    except Exception as exc:  # noqa: BLE001 -- whatever a server that is not Dask's makes the protocol raise
        checks.fail("--scheduler", address, "must be a Dask scheduler's address (tcp://host:port); what answered "
                    f"there does not speak Dask's protocol ({type(exc).__name__})")


def is_lost(exc: BaseException) -> bool:
    """Whether ``exc`` says the Dask cluster under a map was lost, not that a point failed: a worker killed more often
    than Dask retries a task (``KilledWorker``), a task cancelled as its scheduler went (``CancelledError``), a
    connection to the scheduler closed or timed out (``CommClosedError``, ``TimeoutError``), a scheduler left without
    workers (:class:`NoWorkers`).

    Parameters
    ----------
    exc : BaseException
        An exception raised while a map's points ran on Dask or its client closed.

    Returns
    -------
    bool
    """
    from concurrent.futures import CancelledError

    try:
        from distributed.comm.core import CommClosedError
        from distributed.scheduler import KilledWorker
    except ImportError:  # no Dask: no cluster to lose
        return False
    return isinstance(exc, (KilledWorker, CancelledError, CommClosedError, TimeoutError, NoWorkers))
