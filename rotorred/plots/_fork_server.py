"""What the figure pool's fork server imports (:mod:`rotorred.plots.pool`): the workers' modules
(:mod:`rotorred.plots._preload`), the frames of the scene's figures, and an exit without the interpreter's teardown.

* **Frames.** The pool names the frames (:func:`rotorred.plots.scene.scene_frames`) in the environment variable
  :data:`rotorred.plots.pool.FRAMES` when it starts the server; the server builds them (:func:`rotorred.plots.scene.prepare_frames`)
  before it forks a worker, so every worker inherits them, built once, while the caller solves the scene.
* **Exit.** The caller waits for the server to end when its pool stops (so that the workers' CPU time counts as the
  caller's children's); tearing down matplotlib's modules took the server about 0.09 s, the last wait of a warm
  ``rotorred run``. The server holds nothing to clean up (its workers have ended and been reaped by then), so it
  leaves with ``os._exit`` as soon as it exits. Workers forked from it end with ``os._exit`` anyway
  (multiprocessing's own).
"""

import signal

# first, before matplotlib's import and the frames (about a second): Ctrl-C reaches the whole process group, and the
# server printed a KeyboardInterrupt traceback from its preload before multiprocessing ignores SIGINT there. Ignoring
# it in the caller while it starts the server would have the child inherit that, but a SIGINT meanwhile could be lost
# to the caller (the kernel hands it to a thread that does not block it, where it is ignored).
signal.signal(signal.SIGINT, signal.SIG_IGN)

import ast  # noqa: E402
import atexit  # noqa: E402
import os  # noqa: E402
import sys  # noqa: E402

import rotorred.plots._preload  # noqa: F401, E402
from rotorred.plots.pool import FRAMES  # noqa: E402
from rotorred.plots.scene import prepare_frames  # noqa: E402


def _exit_now() -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, OSError, ValueError):  # closed or missing
            pass
    os._exit(0)


def _prepare() -> None:
    """Build the frames :data:`FRAMES` names; none when it names none or what it names cannot be built (the figures
    then build their own: the same pixels, as the tests check, a little later)."""
    try:
        prepare_frames(ast.literal_eval(os.environ.get(FRAMES, "[]")))
    except Exception:  # noqa: BLE001 - frames save time, never a figure: no traceback from the server
        pass


atexit.register(_exit_now)  # the last registered runs first: before multiprocessing's and the teardown
_prepare()
