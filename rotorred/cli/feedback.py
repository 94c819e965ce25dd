"""What a command says, and how much: ``-q``, ``-v`` and the logging set-up of the command line.

Two streams, both through :mod:`logging`:

* **progress and diagnostics** (the ``"rotorred"`` logger, :mod:`rotorred.progress`): stage lines and warnings on
  stderr, as ``rotorred <command>: <text>``; a warning says ``warning:`` first. Written through ``tqdm.write``, so
  a line never cuts a progress bar in half.
* **the report** (:data:`REPORT`): the command's result on stdout: summaries, tables, the files written.

Both streams write what their encoding cannot show in ASCII (µm -> um, × -> x:
:func:`rotorred.progress.ascii_fallback`), so that a terminal with ``PYTHONIOENCODING=ascii`` or an ASCII locale
never fails a command after it computed.

The level: INFO by default (stage lines, bars on a terminal, the report); ``-v`` adds DEBUG (timings and choices,
each line with the seconds since the start); ``-q`` leaves errors only (nothing on stdout). Errors themselves are
printed by :func:`rotorred.cli.main`'s one error path, whatever the level.
"""

from __future__ import annotations

import logging
import sys

from rotorred import progress

LOG = progress.LOG

__all__ = ["REPORT", "report", "error", "configure", "add_options", "level"]

#: the command's result, on stdout
REPORT = logging.getLogger("rotorred.report")


def report(text: str = "") -> None:
    """One piece of the command's result, on stdout (silent with ``-q``)."""
    REPORT.info(text)


def error(text: str) -> None:
    """An error the command ends with after its work (a diverged run, failed points, an interrupt), on stderr as
    ``rotorred <command>: error: <text>``, whatever ``-q`` says."""
    LOG.error(text)


def add_options(parser) -> None:
    """``-v``/``--verbose`` and ``-q``/``--quiet`` on a command's parser."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("-v", "--verbose", action="count", default=0,
                       help="say more: timings and choices, each line with the seconds since the start")
    group.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")


def level(args) -> int:
    """The logging level asked by ``args`` (:func:`add_options`)."""
    if getattr(args, "quiet", False):
        return logging.ERROR
    return logging.DEBUG if getattr(args, "verbose", 0) else logging.INFO


class _LineHandler(logging.StreamHandler):
    """A stream handler that writes through ``tqdm.write`` (a bar in progress is redrawn below the line)."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            from tqdm import tqdm

            tqdm.write(self.format(record), file=self.stream)
            self.flush()
        except Exception:  # noqa: BLE001 -- logging's own rule: a failed message never stops the work
            self.handleError(record)


class _ReportHandler(logging.StreamHandler):
    """The report's handler: a failed write (a closed pipe: ``rotorred run | head``) is raised, so that the command's
    one error path says so (exit 4), where logging would print its own traceback and go on."""

    def handleError(self, record: logging.LogRecord) -> None:
        exc = sys.exc_info()[1]
        if isinstance(exc, OSError):
            raise exc
        super().handleError(record)


class _Format(logging.Formatter):
    """``rotorred <command>: [warning: ]<message>``, with ``[12.34 s]`` since the start at DEBUG."""

    def __init__(self, command: str, timed: bool):
        super().__init__()
        self.prefix, self.timed = f"rotorred {command}".strip(), timed

    def format(self, record: logging.LogRecord) -> str:
        kind = {logging.WARNING: "warning: ", logging.ERROR: "error: "}.get(record.levelno, "")
        when = f" [{record.relativeCreated / 1000:6.2f} s]" if self.timed else ""
        return f"{self.prefix}{when}: {kind}{record.getMessage()}"


def configure(command: str | None, lvl: int) -> None:
    """Set the loggers for one command: stage lines and warnings on the current stderr, the report on the current
    stdout, both at ``lvl`` (replacing the handlers of an earlier call in this process). What the streams' encoding
    cannot show is written in ASCII (:func:`rotorred.progress.ascii_fallback`: µm -> um, × -> x)."""
    for stream in (sys.stdout, sys.stderr):
        progress.ascii_fallback(stream)
    for logger, stream, fmt in ((LOG, sys.stderr, _Format(command or "", lvl <= logging.DEBUG)),
                                (REPORT, sys.stdout, logging.Formatter("%(message)s"))):
        for old in list(logger.handlers):
            if getattr(old, "_rotorred_cli", False):
                logger.removeHandler(old)
        handler = (_LineHandler if logger is LOG else _ReportHandler)(stream)
        handler._rotorred_cli = True
        handler.setFormatter(fmt)
        logger.addHandler(handler)
        logger.setLevel(lvl)
        logger.propagate = False
