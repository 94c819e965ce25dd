"""Feedback of long work: stage lines and progress bars, one mechanism for every command and script.

Everything goes through the standard :mod:`logging` module, under the logger ``"rotorred"`` (:data:`LOG`; each
module logs to its own child, ``logging.getLogger(__name__)``):

* a **stage** is one line at INFO saying what starts now (``compiling the step kernel``, ``stepping``,
  ``analysing``, ``writing``): :func:`stage`;
* a **bar** is one :mod:`tqdm` bar on stderr for work counted in steps, points or seconds, with tqdm's rate and time
  estimate: :func:`bar`.

Whether they show is the logger's decision: the command line sets its level from ``-q``/``-v``
(:mod:`rotorred.cli.feedback`); a script that configures no logging sees no stage lines and no bars (Python's
default level, WARNING), unless it asks with ``logging.basicConfig(level=logging.INFO)`` or passes
``progress=True`` where a function offers it. A bar is drawn on a terminal only: in a log file or a pipe
(CI, a batch job) its stage line says what runs, without a screenful of carriage returns.

A terminal (or pipe) whose encoding cannot show a character rotorred prints (µ, ×, °, Ω, ... with
``PYTHONIOENCODING=ascii``, or a Latin-1 console that lacks Ω) gets its ASCII form instead (µm -> um, × -> x):
:func:`ascii_fallback` sets that on a stream, and the command line sets it on stdout and stderr, so that a command
never fails, after computing, on printing its report.
"""

from __future__ import annotations

import codecs
import io
import logging
import sys
import unicodedata
from collections.abc import Mapping
from contextlib import contextmanager
from types import MappingProxyType

__all__ = ["LOG", "stage", "bar", "shown", "muted", "INTERRUPTS", "interrupt_name", "interrupt_in", "ascii_text",
           "ascii_fallback", "ASCII_FORMS"]

#: the package's logger: the parent of every module's logger
LOG = logging.getLogger("rotorred")


def shown(progress: bool | None = None) -> bool:
    """Whether feedback is wanted: ``progress`` when given, else whether :data:`LOG` passes INFO."""
    return LOG.isEnabledFor(logging.INFO) if progress is None else bool(progress)


def stage(text: str, *args, logger: logging.Logger = LOG) -> None:
    """Say at INFO what starts now (``logger.info(text, *args)``)."""
    logger.info(text, *args)


def bar(total: float | None, desc: str, unit: str, *, progress: bool | None = None, initial: float = 0,
        delay: float = 0.0, bar_format: str | None = None):
    """A tqdm progress bar on stderr, or a disabled one (same methods, draws nothing).

    Parameters
    ----------
    total : float or None
        The count at the end (steps, points, seconds of simulated time); None: not known (a count and a rate).
    desc : str
        What is counted (``"stepping"``, ``"map"``).
    unit : str
        The count's unit, as tqdm shows it (``"step"``, ``"point"``, ``"s"``).
    progress : bool, optional
        True: draw it even off a terminal; False: never; None (default): on a terminal when :func:`shown`.
    initial : float
        The count already done (a resumed map).
    delay : float
        Seconds before the bar first appears (work that ends sooner draws nothing) (s).
    bar_format : str, optional
        As tqdm's.

    Returns
    -------
    tqdm.tqdm
    """
    from tqdm import tqdm

    if progress is None:
        disable = not shown() or not _terminal()
    else:
        disable = not progress
    return tqdm(total=total, desc=desc, unit=unit, initial=initial, delay=delay, disable=disable, file=sys.stderr,
                dynamic_ncols=True, leave=False, bar_format=bar_format)


@contextmanager
def muted():
    """No stage lines or bars within the block, for work that is one step of a larger one with its own progress (a
    map's point: its segments would say "stepping" again and again); with ``-v`` (DEBUG) they still show."""
    level = LOG.level
    if logging.DEBUG < LOG.getEffectiveLevel() < logging.WARNING:
        LOG.setLevel(logging.WARNING)
    try:
        yield
    finally:
        LOG.setLevel(level)


#: the interrupts of long work outside the command line, and the signal each stands for: SIGINT's ``KeyboardInterrupt``
#: (the command line adds its SIGTERM exception: ``rotorred.cli.interrupts``)
INTERRUPTS = MappingProxyType({KeyboardInterrupt: "SIGINT"})


def interrupt_name(exc: BaseException, interrupts: Mapping[type[BaseException], str] = INTERRUPTS) -> str:
    """The signal ``exc`` stands for in ``interrupts`` ("SIGINT", "SIGTERM").

    Parameters
    ----------
    exc : BaseException
        An exception of one of ``interrupts``' types.
    interrupts : mapping of exception type to str
        The interrupts and their signals (default :data:`INTERRUPTS`).

    Returns
    -------
    str
    """
    return next(name for kind, name in interrupts.items() if isinstance(exc, kind))


def interrupt_in(exc: BaseException, kinds: tuple) -> BaseException | None:
    """The interrupt (an exception of ``kinds``: SIGINT's ``KeyboardInterrupt``, a command's SIGTERM) that ``exc`` is or
    was raised from, or None.

    A signal's exception raised while a module is imported or a class is made comes back as another error, its cause
    the interrupt: ``ImportError: initialization failed`` (an extension module's), ``RuntimeError: Error calling
    __set_name__`` (matplotlib's classes). Long work that ends on an interrupt (a map, a branch, a run-up) ends on
    those too.

    Parameters
    ----------
    exc : BaseException
        The exception raised.
    kinds : tuple of exception types
        The interrupts.

    Returns
    -------
    BaseException or None
        The first interrupt in ``exc``'s chain of causes and contexts.
    """
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, kinds):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def _terminal() -> bool:
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


#: the ASCII form of a character rotorred prints where the stream's encoding cannot show it (:func:`ascii_text`); a
#: character not listed takes the ASCII letters of its compatibility decomposition (é -> e, ₕ -> h), else ``?``
ASCII_FORMS = {"µ": "u", "μ": "u", "×": "x", "°": "deg", "±": "+/-", "−": "-", "–": "-", "—": "--", "≤": "<=",
               "≥": ">=", "≈": "~", "→": "->", "·": "*", "…": "...", "§": "section ", "²": "^2", "³": "^3",
               "Ω": "Omega", "ω": "omega", "φ": "phi", "κ": "kappa", "λ": "lambda", "Δ": "Delta", "δ": "delta",
               "θ": "theta", "ζ": "zeta", "π": "pi", "σ": "sigma", "ν": "nu", "ρ": "rho",
               "‘": "'", "’": "'", "“": '"', "”": '"'}

#: the codec error handler of :func:`ascii_fallback`
ERRORS = "rotorred-ascii"


def ascii_text(text: str) -> str:
    """``text`` with each character outside ASCII in its ASCII form (:data:`ASCII_FORMS`): ``"4.2 µm, 1× outer"``
    -> ``"4.2 um, 1x outer"``."""
    return "".join(c if c.isascii() else _ascii_char(c) for c in text)


def _ascii_char(char: str) -> str:
    if char in ASCII_FORMS:
        return ASCII_FORMS[char]
    decomposed = "".join(c for c in unicodedata.normalize("NFKD", char) if c.isascii())
    return decomposed or "?"


def _fallback(error: UnicodeError):
    """The codec error handler: what the encoding cannot write, in ASCII (a lone surrogate, a byte that was not
    decodable, written back as that byte, as ``surrogateescape`` does)."""
    if not isinstance(error, UnicodeEncodeError):
        raise error
    part = error.object[error.start:error.end]
    if all("\udc80" <= c <= "\udcff" for c in part):
        return bytes(ord(c) - 0xDC00 for c in part), error.end
    return ascii_text(part), error.end


def ascii_fallback(stream) -> None:
    """Let the text ``stream`` write what its encoding cannot as ASCII (:func:`ascii_text`) instead of raising
    :class:`UnicodeEncodeError`. Characters the encoding has are written as they are (UTF-8 writes everything). A
    stream that cannot be reconfigured (not an :class:`io.TextIOWrapper`) is left as it is.

    Parameters
    ----------
    stream : io.TextIOWrapper
        E.g. ``sys.stdout``.
    """
    try:
        codecs.lookup_error(ERRORS)
    except LookupError:
        codecs.register_error(ERRORS, _fallback)
    reconfigure = getattr(stream, "reconfigure", None)
    if reconfigure is None:
        return
    try:
        reconfigure(errors=ERRORS)
    except (ValueError, io.UnsupportedOperation, AttributeError):  # closed, or not a text wrapper after all
        pass
