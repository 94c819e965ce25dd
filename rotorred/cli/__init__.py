"""Command line: ``rotorred <command> ...``.

Each command lives in its own module ``rotorred/cli/<command>.py`` exposing
``add_parser(subparsers)`` (registering the sub-parser) and ``run(args) -> int``.

:func:`main` is the one error path: every error reaches the user as one message on stderr
(``rotorred <command>: error: ...``), without a traceback, and the exit status says which kind
it was (:data:`EXIT_STATUSES`, also printed by ``rotorred --help``). An unexpected error
("internal error") has its traceback written to a log file in the output folder (or the
temporary folder when ``--out`` is unusable), and the message says where. It is the one interrupt path too: SIGINT
and SIGTERM end any command, from its first import on, with one line and exit 130 or 143 (:func:`main`); the long
commands keep what they have through :func:`interrupts`.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import os
import signal
import sys
import tempfile
import traceback
from pathlib import Path

#: command modules, in the order ``rotorred --help`` lists them
COMMANDS = [
    "branch",  # rotorred continue
    "campbell",
    "compare",
    "convert",
    "harmonic",
    "map",
    "modes",
    "run",
]

EXIT_OK, EXIT_INTERNAL, EXIT_INPUT, EXIT_DIVERGED, EXIT_ENVIRONMENT = 0, 1, 2, 3, 4
EXIT_SIGINT, EXIT_SIGTERM = 130, 143

#: exit status -> what it means (the table of ``rotorred --help`` and the README)
EXIT_STATUSES = {
    EXIT_OK: "success: every result written",
    EXIT_INTERNAL: "internal error (a bug): the traceback is in rotorred-error.log in --out (or the temp folder)",
    EXIT_INPUT: "bad input (a file, a key, an option, --out, a size beyond the limits): nothing computed, "
                "nothing written",
    EXIT_DIVERGED: "a run diverged: `run` writes the partial record marked INCOMPLETE; `map` (and `sweep`) keeps "
                   "the other points and names the failed ones in map.csv and map.txt; `compare` writes nothing",
    EXIT_ENVIRONMENT: "the environment: --out is used by another run (lock), an output could not be written (a "
                      "full disk, a quota, the file-size limit, a folder removed, a non-regular file at its path: one "
                      "line naming the file, the earlier result intact), memory that cannot be allocated (the size), "
                      "or an optional library is missing (the message gives its install command)",
    EXIT_SIGINT: "interrupted (Ctrl-C, SIGINT), in any command, from its first imports on: --out keeps its "
                 "earlier result (`continue`: the points traced, marked INCOMPLETE; `compare`: the runs done, marked "
                 "INCOMPLETE; `map`: the points done, resumed by the same command; a run-up: its record up to the "
                 "signal, analysed, marked INCOMPLETE)",
    EXIT_SIGTERM: "terminated (SIGTERM): as 130",
}

#: optional libraries a command may need -> their install command
INSTALL = {
    "pyfftw": "pip install pyFFTW",
    "matplotlib": "pip install matplotlib",
    "numba": "pip install numba",
    "scipy": "pip install scipy",
    "sympy": "pip install sympy",
}

LOG_NAME = "rotorred-error.log"


class Terminated(BaseException):
    """SIGTERM arrived (raised in the main thread like ``KeyboardInterrupt`` for SIGINT)."""


#: examples of each command, shown by ``rotorred <command> --help`` (tests/test_cli_feedback.py parses each and
#: checks its scene keys)
EXAMPLES = {
    "run": ["rotorred run --out out                                  # the paper's rub scene (paper-rub)",
            "rotorred run paper-normal --out normal --set speeds.outer=95",
            "rotorred run out/scene.toml --out again                 # rerun a folder's resolved scene",
            "rotorred run runup-rub --out runup -q                   # a run-up, printing errors only",
            "rotorred run paper-rub --set solver.method=harmonic-balance --set speeds.outer=91.37 --out torus"
            "  # a quasi-periodic torus"],
    "campbell": ["rotorred campbell seed-rig --speeds 0:12000:61 --out campbell",
                 "rotorred campbell seed-rig --speeds 3000 --out whirl     # whirl frequencies at one speed",
                 "rotorred campbell my_rotor.toml --speeds 0:20000:81 --ratio 1.4 --harmonics 1,2 --out cd"],
    "modes": ["rotorred modes seed-rig --speed 3000 --out modes",
              "rotorred modes my_rotor.toml --speed 9000 --ratio outer=1.3 --modes 8 --out modes"],
    "compare": ["rotorred compare paper-rub --modes 8,16,24 --out compare",
                "rotorred compare paper-rub --modes 16,24 --dt 5e-5,2e-5,1e-5 --out front",
                "rotorred compare paper-rub --refine 4 --dt 2e-5,5e-6,2.5e-6 --set output.nodes=[13,14] --out refined"],
    "convert": ["rotorred convert rotor_saved_by_ross.toml rotor.toml"],
    "harmonic": ["rotorred harmonic seed-rig --speeds 0:12000:241 --out bode"],
    "map": ["rotorred map paper-rub --vary rub.clearance=10e-6:60e-6:11 --out clearance",
            "rotorred map paper-rub --vary speeds.outer=60:110:51 --direction both --out envelope",
            "rotorred map paper-rub --vary speeds.outer=60:120:13 --vary rub.clearance=20e-6:50e-6:4 --workers 2 "
            "--out envelope"],
    "continue": ["rotorred continue paper-rub --param rub.clearance=45e-6:5e-6 --out branch",
                 "rotorred continue paper-rub --param speeds.outer=90:110 --no-stability --out speed-branch"],
}


def _epilog(command: str | None = None) -> str:
    examples = ""
    if command in EXAMPLES:
        examples = "examples:\n" + "\n".join(f"  {e}" for e in EXAMPLES[command]) + "\n\n"
    return examples + "exit status:\n" + "\n".join(f"  {code:>3}  {text}" for code, text in EXIT_STATUSES.items())


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """Help wrapped to the terminal: the description's paragraphs filled to the width, the epilog's indented lines
    (examples, exit statuses) kept as written, each exit status's text filled under its number."""

    def _fill_text(self, text, width, indent):
        import textwrap

        out = []
        for paragraph in text.split("\n\n"):
            lines = paragraph.splitlines()
            if lines and all(line.startswith("  ") for line in lines[1:]) and lines[0].endswith(":"):
                out.append("\n".join([indent + lines[0]] + [self._hang(line, width, indent) for line in lines[1:]]))
            else:
                out.append(textwrap.fill(" ".join(paragraph.split()), width, initial_indent=indent,
                                         subsequent_indent=indent))
        return "\n\n".join(out)

    @staticmethod
    def _hang(line: str, width: int, indent: str) -> str:
        import re
        import textwrap

        if line.lstrip().startswith("rotorred "):  # an example: as written
            return indent + line
        head = re.match(r"\s*\S+\s+", line)
        pad = " " * (len(head.group(0)) if head else 2)
        return textwrap.fill(line, width, initial_indent=indent, subsequent_indent=indent + pad)


def build_parser() -> argparse.ArgumentParser:
    from rotorred.cli import feedback
    from rotorred import provenance

    parser = argparse.ArgumentParser(
        prog="rotorred", description="Rotordynamics of dual-rotor machines with rub-impact faults. "
                                     "`rotorred COMMAND --help` describes a command, with examples.",
        epilog=_epilog(), formatter_class=_Formatter)
    parser.add_argument("--version", action="version", version=f"rotorred {provenance.package_version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        module = importlib.import_module(f"rotorred.cli.{name}")
        p = module.add_parser(sub)
        feedback.add_options(p)
        p.epilog = _epilog(p.prog.split()[-1])
        p.formatter_class = _Formatter
        p.set_defaults(_run=module.run)
    return parser


#: BLAS and OpenMP threads of a command unless the environment sets them: one. rotorred's matrices are small (tens to a
#: few hundred DOFs), where BLAS's threads spin against the figure workers for the 2 cores: a warm ``rotorred run``
#: of paper-rub took 3.83 s (CPU 4.5 s) so against 4.30 s (CPU 6.2 s) with OpenBLAS's default (medians of 5,
#: alternated). Set before numpy is imported (the command imports it lazily); maps' workers set the same.
ONE_THREAD = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")


#: the cyclic garbage collector's thresholds in the console script: a young collection every 10 000 new objects, not
#: 700. A command's objects are mostly modules and arrays, with few cycles; numba compiling the step kernel made nine
#: full collections with the defaults (0.76 s; 1.03 s in the collector in all), none with these (0.31 s in all),
#: its peak memory 338 MB against 323 MB (the first run of paper-rub); a warm run spends 0.09 s there, not 0.15 s.
GC_THRESHOLDS = (10_000, 10, 10)


def entry() -> int:
    """The ``rotorred`` console script: :func:`main` with the collector's :data:`GC_THRESHOLDS`, then every object it
    leaves frozen for the garbage collector, so that the interpreter's exit does not walk them (numba's and scipy's
    hundreds of thousands: a warm ``rotorred run`` of paper-rub ended 0.23 s sooner, 2.47 against 2.70 s, medians of
    5). Files are closed and exit handlers run as before; only the collection at exit is skipped.

    :func:`main` sets the handlers of SIGINT and SIGTERM first, before it imports anything, so that a signal at any
    moment of a command, its imports included, ends it with 130 or 143 and one line. Outside them (the instant
    before, and once main has returned, its result complete, as the interpreter ends) each signal has the operating
    system's own action: the process ends by it (exit -2 or -15, a shell's 130 or 143), without Python's
    KeyboardInterrupt traceback."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(signum) is not signal.SIG_IGN:
            signal.signal(signum, signal.SIG_DFL)
    gc.set_threshold(*GC_THRESHOLDS)
    status = main()
    gc.freeze()
    return status


def main(argv: list[str] | None = None) -> int:
    """Run one command; returns its exit status (:data:`EXIT_STATUSES`).

    The one place where every command is interruptible: SIGINT and SIGTERM raise their exceptions (:func:`interrupts`)
    from the first line on, imports and parsing included, and end the command with one line and 130 or 143, never a
    traceback (:func:`_noting`). An error raised from an interrupt (:func:`rotorred.progress.interrupt_in`: a signal
    that came as a module was imported or a class made) is reported as that interrupt, and so is any error after a
    signal came: an extension that swallows the signal's exception fails otherwise (a SIGINT as matplotlib draws
    markers: ``ValueError: Invalid bounding box``, seen at a random moment of ``modes``). A signal that a library
    swallowed (raised in a ctypes callback of llvmlite as numba loads the step kernel, where Python prints "Exception
    ignored" and goes on) leaves the command to run to its end, which then exits 130 or 143 saying so, its result
    written whole: a command never exits 0 when a signal came."""
    noted: list[str] = []
    args = None
    with _noting(noted):
        try:
            for name in ONE_THREAD:
                os.environ.setdefault(name, "1")
            parser = build_parser()
            args = parser.parse_args(argv)
            args.argv = list(sys.argv[1:] if argv is None else argv)  # the command line, for the outputs' provenance
            if not getattr(args, "_run", None):
                parser.print_help()
                return EXIT_INPUT
            from rotorred.cli import feedback

            feedback.configure(args.command, feedback.level(args))
            status = int(args._run(args) or 0)
        except BaseException as exc:  # noqa: BLE001 -- the one place every error is turned into a message
            from rotorred import progress

            found = progress.interrupt_in(exc, tuple(interrupts()))
            if found is None and noted:  # the signal's exception swallowed in an extension, which failed otherwise
                found = interrupt_of(noted[0])  # (matplotlib's markers)
            status = _report(args, found or exc)
    if noted and status not in (interrupted_status(n) for n in noted):
        if status == EXIT_OK:  # an error's status: its message is said
            _error(args, f"interrupted ({noted[0]}), but the signal was lost in a library and the command went on to "
                         "its end: its result is written whole")
        return interrupted_status(noted[0])
    return status


def interrupts() -> dict:
    """The exceptions of SIGINT and SIGTERM in a command (``KeyboardInterrupt``; :class:`Terminated`, raised by
    :func:`main`'s handler) and the signal each stands for: the one mapping every command ends its work on (``map``,
    ``continue``, ``compare`` and the run-ups keeping what they have: ``interrupts`` of :func:`rotorred.run_map`,
    :func:`rotorred.continue_scene`, :func:`rotorred.compare_models`, :func:`rotorred.run_runup`)."""
    return {KeyboardInterrupt: "SIGINT", Terminated: "SIGTERM"}


def interrupt_of(signal_name: str) -> BaseException:
    """The exception a signal raises in a command (:func:`interrupts`): ``KeyboardInterrupt()`` for "SIGINT",
    ``Terminated()`` for "SIGTERM"."""
    return {name: kind for kind, name in interrupts().items()}[signal_name]()


def interrupted_status(signal_name: str) -> int:
    """The exit status of a command its signal ended: 130 (SIGINT) or 143 (SIGTERM)."""
    return {"SIGINT": EXIT_SIGINT, "SIGTERM": EXIT_SIGTERM}[signal_name]


@contextlib.contextmanager
def _noting(noted: list):
    """SIGINT and SIGTERM raise their exceptions (:func:`interrupts`) and are noted in ``noted``; unraisable
    interrupts (raised where Python can only ignore them), and any unraisable error once a signal came, are not
    printed (the command's message says what happened). Restored on exit; in the main thread only, and SIGINT only
    where it is not ignored."""
    def handler(signum, frame):
        name = signal.Signals(signum).name
        noted.append(name)
        raise interrupt_of(name)

    previous, hook = {}, sys.unraisablehook
    try:
        for signum in (signal.SIGINT, signal.SIGTERM):
            if signal.getsignal(signum) is not signal.SIG_IGN:
                previous[signum] = signal.signal(signum, handler)
    except ValueError:  # not the main thread
        pass
    sys.unraisablehook = lambda u: None if noted or isinstance(u.exc_value, tuple(interrupts())) else hook(u)
    try:
        yield
    finally:
        sys.unraisablehook = hook
        for signum, old in previous.items():
            signal.signal(signum, old)


def _error(args, text: str) -> None:
    command = f"rotorred {args.command}" if getattr(args, "command", None) else "rotorred"
    print(f"{command}: error: {text}", file=sys.stderr)


def _report(args, exc: BaseException) -> int:
    """One message for ``exc`` on stderr; returns the exit status."""
    if isinstance(exc, KeyboardInterrupt):
        _error(args, "interrupted (SIGINT); the output folder keeps its earlier result")
        return EXIT_SIGINT
    if isinstance(exc, Terminated):
        _error(args, "terminated (SIGTERM); the output folder keeps its earlier result")
        return EXIT_SIGTERM
    if isinstance(exc, SystemExit):
        raise exc
    from rotorred import InputError, writers

    if isinstance(exc, ModuleNotFoundError) and (exc.name or "").split(".")[0] in INSTALL:
        name = exc.name.split(".")[0]
        _error(args, f"the optional library {name!r} is needed here and is not installed: {INSTALL[name]}")
        return EXIT_ENVIRONMENT
    if isinstance(exc, (InputError, ValueError, FileNotFoundError)) and not _is_internal(exc):
        _error(args, str(exc))
        return EXIT_INPUT
    if _is_diverged(exc):
        _error(args, str(exc))
        return EXIT_DIVERGED
    if isinstance(exc := writers.as_fault(exc), (writers.FolderBusy, writers.ResourceFault)):  # exit 4, one line
        _error(args, str(exc))
        return EXIT_ENVIRONMENT
    if isinstance(exc, OSError):
        where = f" {exc.filename!r}" if exc.filename else ""
        _error(args, f"could not write or read{where}: {exc.strerror or exc}")
        return EXIT_ENVIRONMENT
    return _internal(args, exc)


def _is_internal(exc: BaseException) -> bool:
    """A ValueError from a library deep in a computation, not from an input check (e.g. numpy's)."""
    from rotorred import InputError

    if isinstance(exc, (InputError, FileNotFoundError)):
        return False
    tb = exc.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    return tb is not None and not str(tb.tb_frame.f_globals.get("__name__", "")).startswith("rotorred")


def _is_diverged(exc: BaseException) -> bool:
    """A transient that diverged (a scene's, in its key names), or a harmonic balance that did not converge (each
    says where and why)."""
    kinds = [getattr(sys.modules.get(name), kind, None) for name, kind in
             (("rotorred.transient.results", "SimulationDiverged"), ("rotorred.scenes.run", "SceneDiverged"),
              ("rotorred.nonlinear.hb", "NotConverged"))]
    return any(k is not None and isinstance(exc, k) for k in kinds)


def _internal(args, exc: BaseException) -> int:
    """Say "internal error", write the traceback to a log file and say where."""
    text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    log = None
    for folder in (_usable_out(args), Path(tempfile.gettempdir())):
        if folder is None:
            continue
        try:
            folder.mkdir(parents=True, exist_ok=True)
            log = folder / LOG_NAME
            log.write_text(f"rotorred {' '.join(sys.argv[1:])}\n\n{text}", encoding="utf-8")
            break
        except OSError:
            log = None
    where = f"the traceback is in {log}" if log else "the traceback could not be written:\n" + text
    _error(args, f"internal error ({type(exc).__name__}: {exc}); {where}; please report it")
    return EXIT_INTERNAL


def _usable_out(args) -> Path | None:
    from rotorred import InputError
    from rotorred.cli.options import out_dir

    if getattr(args, "out", None) is None:
        return None
    try:
        return out_dir("--out", getattr(args, "out", None))
    except InputError:
        return None


if __name__ == "__main__":
    sys.exit(entry())
