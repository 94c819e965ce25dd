"""Figures drawn in worker processes while the caller goes on: :class:`FigurePool`.

Drawing the six figures of ``paper-rub`` takes about as long as everything else of a warm
``rotorred run`` (the solve, the line fit, the data files), and matplotlib's import another 0.4 s.
The pool starts its workers when it is created, so they import matplotlib and build the empty frames of the figures
while the caller computes (``rotorred run`` creates it once the scene is read and checked, naming the scene's frames,
:func:`rotorred.plots.scene.scene_frames`); the caller then submits figure jobs
(:func:`rotorred.plots.scene.scene_figures`: a plot function and plain arrays), which returns at once, and writes its
data files while they are drawn.

Workers are forked from a fork server (a fresh interpreter, not the caller: no fork of a process that holds
numba's threads) that imports matplotlib once (:mod:`rotorred.plots._preload`, through
:mod:`rotorred.plots._fork_server`, which also ends the server without a teardown), so two workers cost one
import of it, not two: a warm ``rotorred run`` of paper-rub took 3.51 s against 3.87 s with spawned workers
(medians of 10, alternated). Where there is no fork server (Windows) they are spawned. The server (from its first preloaded line,
:mod:`rotorred.plots._fork_server`) and the workers ignore SIGINT: Ctrl-C is the caller's to handle, and leaving the pool stops them before the caller cleans up
(:class:`rotorred.writers.OutputFolder` removes its staging folder after a worker can no longer write into
it). ``workers=0`` draws in the calling process.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
from concurrent.futures.process import BrokenProcessPool
import os
import signal

__all__ = ["FigurePool", "Drawing", "default_workers"]

#: the environment variable that names the frames the fork server prepares (:mod:`rotorred.plots._fork_server`):
#: ``repr`` of a list of frame keys (:func:`rotorred.plots.scene.scene_frames`)
FRAMES = "ROTORRED_FIGURE_FRAMES"


def default_workers() -> int:
    """Workers of a pool: one per core the process may use, at most 2 (six figures; 0 on one core)."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cores = os.cpu_count() or 1
    return 0 if cores < 2 else 2


def _start_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    import gc

    import rotorred.plots._preload  # noqa: F401 - already there when forked from the fork server; now, if spawned

    gc.freeze()  # the imported modules are never garbage: drawing then collects only its own objects


def _context(frames=()):
    """The fork server's context with matplotlib preloaded and ``frames`` prepared (started now: it is started with
    the frames named in its environment), or spawn where there is none."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    from multiprocessing import forkserver

    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["rotorred.plots._fork_server"])
    previous = os.environ.get(FRAMES)
    os.environ[FRAMES] = repr([tuple(key) for key in frames])
    try:
        forkserver.ensure_running()
    except OSError:  # no server now: the pool starts one when it starts a worker (without the frames), or breaks and
        pass  # its figures are drawn in the calling process (Drawing)
    finally:
        if previous is None:
            del os.environ[FRAMES]
        else:
            os.environ[FRAMES] = previous
    return context


def _ready() -> int:
    return os.getpid()


class Drawing:
    """A submitted figure: ``result()`` is its path, drawn in this process when its worker died (killed, out of
    memory, a script without a ``__main__`` guard that cannot be spawned) or when there is no worker."""

    def __init__(self, job, future: concurrent.futures.Future | None):
        self._job, self._future = job, future  # future: of the worker's future (the pool's submitting thread's)
        if future is None:
            self._value = job()

    def result(self):
        if self._future is None:
            return self._value
        try:
            future = self._future.result()
        except (BrokenProcessPool, RuntimeError):  # refused: a worker died earlier, or the workers could not start
            return self._job()
        try:
            return future.result()
        except BrokenProcessPool:  # its worker died
            return self._job()


class FigurePool:
    """A context manager of figure-drawing processes; ``submit(job)`` returns its :class:`Drawing`.

    Parameters
    ----------
    workers : int, optional
        Worker processes (default :func:`default_workers`); 0 draws each job when it is submitted.
    frames : sequence of tuple, optional
        Frames the figures will be drawn into (:func:`rotorred.plots.scene.scene_frames`): the fork server prepares
        them before it forks the workers (:mod:`rotorred.plots._fork_server`).
    """

    def __init__(self, workers: int | None = None, frames=()):
        self.workers = default_workers() if workers is None else int(workers)
        self._executor, self._submitting = None, None
        if self.workers > 0:
            self._executor = concurrent.futures.ProcessPoolExecutor(
                self.workers, mp_context=_context(frames), initializer=_start_worker)
            # jobs reach the workers through one thread, in order: the first submission waits for the fork server
            # to import matplotlib (0.5 s), which the caller spends computing; one job each starts every worker
            self._submitting = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="figure-pool")
            for _ in range(self.workers):
                self._submitting.submit(self._executor.submit, _ready)

    def submit(self, job) -> Drawing:
        """Draw ``job`` in a worker, or here with no workers. Returns at once: the job is handed to the workers by the
        pool's thread, once they have started.

        Parameters
        ----------
        job : callable
            Takes no argument, picklable (e.g. one of the jobs of :func:`rotorred.plots.scene.scene_figures`); returns
            what :meth:`Drawing.result` gives (the figure's path).

        Returns
        -------
        Drawing
        """
        if self._executor is None:
            return Drawing(job, None)
        return Drawing(job, self._submitting.submit(self._executor.submit, job))

    def _submitted(self, cancel: bool = False) -> None:
        """Wait until every job has been handed to the workers (or refused: the pool broke); ``cancel``: those not
        handed yet are dropped."""
        if self._submitting is not None:
            self._submitting.shutdown(wait=True, cancel_futures=cancel)
            self._submitting = None

    def __enter__(self) -> FigurePool:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self._close(now=exc_type is not None)  # on an error, stop drawing now: the caller removes what they write into

    def _close(self, now: bool) -> None:
        """Hand over the jobs submitted (``now``: drop those not handed yet and end the workers), wait for the workers
        to end, and stop the fork server."""
        self._submitted(cancel=now)
        if self._executor is None:
            return
        if now:
            for process in list(getattr(self._executor, "_processes", {}).values()):
                process.terminate()
        self._executor.shutdown(wait=True, cancel_futures=now)
        self._executor = None
        _stop_fork_server()


def _stop_fork_server() -> None:
    """Stop the fork server and wait for it (it has reaped its workers): their CPU time then counts as the caller's
    children's, as spawned workers' did (``getrusage``, ``time``). multiprocessing starts it again when asked; its
    stop is not public API, so where it is missing the server simply ends with the caller."""
    from multiprocessing import forkserver

    stop = getattr(getattr(forkserver, "_forkserver", None), "_stop", None)
    if stop is not None:
        stop()
