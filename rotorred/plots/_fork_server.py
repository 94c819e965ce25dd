"""What the figure pool's fork server imports (:mod:`rotorred.plots.pool`): the workers' modules
(:mod:`rotorred.plots._preload`), and an exit without the interpreter's teardown.

The caller waits for the server to end when its pool stops (so that the workers' CPU time counts as the caller's
children's); tearing down matplotlib's modules took the server about 0.09 s, the last wait of a warm ``rotorred
run``. The server holds nothing to clean up (its workers have ended and been reaped by then), so it leaves with
``os._exit`` as soon as it exits. Workers forked from it end with ``os._exit`` anyway (multiprocessing's own).
"""

import atexit
import os
import sys

import rotorred.plots._preload  # noqa: F401


def _exit_now() -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, OSError, ValueError):  # closed or missing
            pass
    os._exit(0)


atexit.register(_exit_now)  # the last registered runs first: before multiprocessing's and the teardown
