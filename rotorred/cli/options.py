"""Parsers of command-line option values, each refusing bad text with the one message form of
:mod:`rotorred.checks` (``--speeds = '0:12000': must be START:STOP:COUNT or a comma list (rpm)``)."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from rotorred import checks
from rotorred import Operating, parse_dof

__all__ = ["grid", "number_list", "dof_list", "node_list", "ratio_number", "spool_ratios", "speed_line", "out_dir",
           "provenance", "stage_summary", "MAX_COUNT", "SCENE_UNITS", "add_settings", "options_named"]

#: most values a START:STOP:COUNT grid may hold (each value is a solve)
MAX_COUNT = 100_000

#: the units of a scene key's value on the command line: the scene file's (docs/scenes.md)
SCENE_UNITS = "scene units: Hz for speeds.*, m for rub.clearance, N/m for rub.k_n, s for solver.dt"


def add_settings(parser, verb: str = "fix") -> None:
    """The ``--set KEY=VALUE`` option of the scene commands (``verb``: what it does to the key)."""
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help=f"{verb} a scene key, e.g. rub.clearance=20e-6 ({SCENE_UNITS}; repeatable)")


def grid(option: str, text: str, unit: str, *, min_count: int = 1, ge: float | None = None,
         increasing: bool = False) -> np.ndarray:
    """``"START:STOP:COUNT"`` (evenly spaced, both ends included) or ``"v1,v2,..."``, in ``unit``.

    Parameters
    ----------
    option : str
        The option's name, e.g. ``"--speeds"``.
    text : str
        The option's value as typed.
    unit : str
        Unit of the values as typed (``"rpm"``, ``"Hz"``).
    min_count : int
        Fewest values allowed.
    ge : float, optional
        Smallest value allowed.
    increasing : bool
        Values must increase strictly.

    Returns
    -------
    ndarray, shape (count,)
        The values, in ``unit``.
    """
    form = f"must be START:STOP:COUNT (COUNT >= {min_count}) or a comma list of numbers"
    try:
        if ":" in text:
            a, b, n = text.split(":")
            count = int(n)
            if not (math.isfinite(float(a)) and math.isfinite(float(b))):
                raise ValueError
            if count > MAX_COUNT:
                checks.fail(option, text, f"must have COUNT <= {MAX_COUNT} (each value is a solve)", unit)
            values = np.linspace(float(a), float(b), count) if count >= 1 else np.zeros(0)
            if count < min_count:
                raise ValueError
        else:
            values = np.array([float(v) for v in text.split(",") if v.strip()])
    except ValueError:
        checks.fail(option, text, form, unit)
    if len(values) < min_count or not np.all(np.isfinite(values)):
        checks.fail(option, text, form + (f", at least {min_count}" if len(values) < min_count else ", finite"),
                    unit)
    if ge is not None and np.any(values < ge):
        checks.fail(option, text, f"must hold values >= {ge:g}", unit)
    if increasing and np.any(np.diff(values) <= 0):
        checks.fail(option, text, "must hold strictly increasing values", unit)
    return values


def number_list(option: str, text: str, unit: str = "", *, gt: float | None = None) -> tuple[float, ...]:
    """``"1,2"`` -> (1.0, 2.0): finite numbers, each > ``gt`` if given."""
    requirement = "must be a comma list of numbers" + (f" > {gt:g}" if gt is not None else "")
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        checks.fail(option, text, requirement, unit)
    if not all(math.isfinite(v) and (gt is None or v > gt) for v in values):
        checks.fail(option, text, requirement, unit)
    return values


def ratio_number(option: str, text: str) -> float:
    """A bare speed ratio ``"1.2857"`` (a two-spool rotor's): a number; its bounds are the caller's."""
    try:
        return float(text)
    except ValueError:
        checks.fail(option, text, "must be a number or SPOOL=R,...")


def spool_ratios(option: str, items: Sequence[str], *, bound: str = ">= 0",
                 example: str = "outer=1.2857") -> dict[str, float]:
    """``["outer=1.2857", "mid=0.9,low=0.5"]`` -> {spool: ratio}: an option's ``SPOOL=R`` items, repeated or
    comma-separated, each spool once. ``bound`` only words the message; the caller checks R's bounds and the
    spool names against its rotor."""
    out = {}
    for item in (part for text in items for part in text.split(",")):
        spool, eq, r = item.partition("=")
        try:
            value = float(r)
        except ValueError:
            value = None
        if not eq or not spool.strip() or value is None:
            checks.fail(option, item, f"must be SPOOL=R with a number R {bound}, e.g. {example}")
        if spool.strip() in out:
            checks.fail(option, item, f"must give spool {spool.strip()!r} once")
        out[spool.strip()] = value
    return out


def speed_line(rotor, speeds, reference: str | None, ratios: Mapping[str, float] | None, unit: str,
               options: tuple[str, str] = ("--reference", "--ratio")) -> Operating:
    """The speed line of a command's options: the ``reference`` spool (default the rotor's first) at ``speeds``,
    the spools named in ``ratios`` at those ratios to it, and every other spool by the one rule of
    :meth:`rotorred.model.operating.Operating.lines` (the ratio of the nominal speeds).

    Parameters
    ----------
    rotor : Rotor
    speeds : array_like, shape (n,)
        The reference spool's speeds, in ``unit``.
    reference : str or None
        The reference spool's name as typed.
    ratios : dict of str to float or None
        ``Omega_s / Omega_reference`` (-) of the spools named by the ratio option.
    unit : {"rad/s", "rpm", "Hz"}
    options : (str, str)
        The names of the reference and the ratio options, which every error names.

    Returns
    -------
    Operating

    Raises
    ------
    InputError
        A spool beyond :data:`rotorred.checks.BOUNDS` ``["speed"]`` on the line, or a ratio the rotor does not give.
    """
    reference_option, ratio_option = options
    names = [s.name for s in rotor.spools]
    reference = checks.choice(reference_option, names[0] if reference is None else reference, names)
    for spool in ratios or {}:
        checks.choice(ratio_option, spool, [n for n in names if n != reference])
    operating = Operating.line(speeds, reference, ratios=dict(ratios or {}), unit=unit)
    try:
        operating.lines(rotor)
    except checks.InputError as exc:  # a spool whose ratio the rotor does not give
        raise checks.InputError(ratio_option, dict(ratios) if ratios else None, exc.requirement) from None
    _bounded_spools(operating, rotor, ratio_option)
    return operating


def _bounded_spools(operating: Operating, rotor, ratio_option: str) -> None:
    """Refuse a line on which a spool turns beyond :data:`rotorred.checks.BOUNDS` ``["speed"]`` (a speed and a ratio
    each within its bound can still give one), naming the spool and its top speed."""
    limit = checks.BOUNDS["speed"].limit
    for spool, speeds in operating.speeds(rotor).items():
        top = float(np.max(np.abs(speeds), initial=0.0)) * 30.0 / math.pi
        if not top <= limit:
            checks.fail(f"the speed of spool {spool!r} (rpm)", top, f"must be at most {checks.bound_text('speed')}; "
                        f"it is the speed given times the spool's {ratio_option}")


@contextmanager
def options_named(names: Mapping[str, str]):
    """Within the block, an :class:`rotorred.checks.InputError` of a function's parameter named in ``names``
    (``{"n_modes": "--modes"}``) names the option the user typed instead, with the same value and requirement."""
    try:
        yield
    except checks.InputError as exc:
        if exc.field not in names:
            raise
        raise checks.InputError(names[exc.field], exc.value, exc.requirement, exc.unit, exc.source) from None


def dof_list(option: str, text: str, nodes=None) -> list[tuple[int, str]]:
    """``"13:x,14:ty"`` -> [(13, "x"), (14, "theta_y")] (:func:`rotorred.model.dofs.parse_dof`)."""
    items = [item for item in text.split(",") if item.strip()]
    if not items:
        checks.fail(option, text, "must be NODE:DIR,... with DIR x, y, tx, ty")
    return [parse_dof(option, item, nodes) for item in items]


def node_list(option: str, text: str, nodes=None) -> list[int]:
    """``"11,16"`` -> [11, 16]: node numbers, each a node of the rotor if ``nodes`` is given."""
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        checks.fail(option, text, "must be a comma list of node numbers")
    if nodes is not None:
        for v in values:
            checks.node(option, v, nodes)
    return values


def out_dir(option: str, text: str | None) -> Path:
    """The output folder ``text``, refused before anything is computed if it cannot be one.

    Refused: an empty string, an existing file, a path below a file, a folder (or its nearest
    existing parent) that is not writable.

    Returns
    -------
    Path
    """
    if text is None or not str(text).strip():
        checks.fail(option, text, "must be a folder path, not empty (an unset shell variable?)")
    path = Path(text).expanduser()
    if path.exists() and not path.is_dir():
        checks.fail(option, text, "must be a folder; this is an existing file")
    existing = path
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        checks.fail(option, text, f"must be a folder path; {str(existing)!r} on it is a file, not a folder")
    if not _writable(existing):
        checks.fail(option, text, f"must be writable; {str(existing)!r} is not writable")
    return path


def _writable(folder: Path) -> bool:
    """A file can be created in ``folder`` (permissions, and a read-only file system)."""
    if not os.access(folder, os.W_OK | os.X_OK):
        return False
    try:
        st = os.statvfs(folder)
    except (OSError, AttributeError):  # no statvfs on Windows: a read-only file system there fails when written
        return True
    return not st.f_flag & os.ST_RDONLY


def provenance(args, kind: str, toml: str):
    """The :class:`rotorred.provenance.Provenance` of this command: its command line (``args.argv``, set by
    :func:`rotorred.cli.main`; else ``sys.argv``), now, and the resolved ``kind`` ("scene" or "rotor") as ``toml``."""
    import sys

    from rotorred import provenance as records

    argv = getattr(args, "argv", None)
    return records.Provenance.of_command(sys.argv[1:] if argv is None else argv, kind, toml)


def stage_summary(folder, name: str, text: str, record) -> list[Path]:
    """Stage the text summary ``name`` (``record``'s header lines on top of ``text``) and ``record``'s resolved input
    (``rotor.toml`` or ``scene.toml``) in ``folder`` (:class:`rotorred.writers.OutputFolder`); returns their paths."""
    from rotorred import writers

    return [writers.write_text(folder.staged(name), record.on_top(text) + "\n"),
            writers.write_text(folder.staged(record.file_name), record.file_text())]
