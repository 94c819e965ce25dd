"""The one validation module: every check of an input value, and the one form of its message.

Every bad input a user can give (a rotor file, a scene file, a dataclass argument, a command
option) is refused by a function of this module, before anything is computed, with an
:class:`InputError` whose message has one form::

    <field> = <value as given>: <what is allowed> (<unit>)

for example ``rub[0].clearance = -1e-06: must be >= 0 (m)`` or
``--speeds = '0:12000': must be START:STOP:COUNT in rpm``. The field is the path of the key as
the user wrote it (``spool[1].elements[0].D_i``, ``solver.dt``, ``--out``); a dataclass knows
only its own attribute name, and the loader that built it prefixes the path with
:meth:`InputError.within`. Values are shown as written, in the user's units (the loaders check
raw file values before converting rpm or Hz to rad/s).

The checks return the converted value (``float``, ``int``, ``str``, tuple), so a loader reads as
a list of named fields.

Physical bounds (:data:`BOUNDS`, :func:`bounded`): a value may be a finite number of the right sign and still mean
nothing (a speed of 1e300 rpm, an unbalance of 1e300 kg m): its result overflows to inf or NaN, or is an artefact
of round-off. Such magnitudes are refused before computing, with the bound and why it holds (docs/model.md, "Physical
bounds of command inputs"). After computing, :func:`finite_result` refuses a result that holds NaN or inf before it is
written, naming where it appeared.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, NoReturn

import numpy as np

__all__ = ["InputError", "MISSING", "fail", "join", "number", "positive", "non_negative", "integer", "choice",
           "string", "boolean", "table", "tables", "sequence", "array", "vector", "node", "keys", "ranges_text",
           "fmt_value", "Bound", "BOUNDS", "bounded", "bound_text", "NonFiniteResult", "finite_result"]


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"

    def __reduce__(self) -> str:
        return "MISSING"  # unpickles as the module's one MISSING, so ``value is MISSING`` survives


#: the value of a required key that was not given
MISSING: Any = _Missing()


def fmt_value(value) -> str:
    """The value as the user wrote it: ``repr`` of Python scalars (numpy scalars unwrapped), on one line (a
    result's repr of several lines joined)."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, np.ndarray):
        return f"array of shape {value.shape}"
    text = " ".join(line.strip() for line in repr(value).splitlines())
    return text if len(text) <= 80 else text[:77] + "..."


def join(prefix: str, field: str) -> str:
    """``join("rub[0]", "clearance") == "rub[0].clearance"``; ``join("spool", "[1]") == "spool[1]"``."""
    if not prefix:
        return field
    if not field:
        return prefix
    return prefix + field if field.startswith("[") else f"{prefix}.{field}"


class InputError(ValueError):
    """An input that rotorred refuses: names the field, the value and what is allowed.

    Attributes
    ----------
    field : str
        Path of the key or option (``rub[0].clearance``, ``--out``).
    value : object
        The value as given (:data:`MISSING` for a required key that was not given).
    requirement : str
        What is allowed, e.g. ``"must be >= 0"``.
    unit : str
        Unit of the value as the user gives it (``"m"``, ``"Hz"``, ``"rpm"``); empty if none.
    source : str
        The file or built-in the value came from, if known.
    """

    def __init__(self, field: str, value, requirement: str, unit: str = "", source: str = ""):
        self.field = field
        self.value = value
        self.requirement = requirement
        self.unit = unit
        self.source = source
        super().__init__(field, value, requirement, unit, source)

    def __str__(self) -> str:
        unit = f" ({self.unit})" if self.unit and self.unit != "-" else ""
        where = f"{self.source}: " if self.source else ""
        if self.value is MISSING:
            return f"{where}{self.field}: missing; {self.requirement}{unit}"
        return f"{where}{self.field} = {fmt_value(self.value)}: {self.requirement}{unit}"

    def within(self, prefix: str) -> InputError:
        """The same error with the field path prefixed (``"rub[0]"`` + ``"clearance"``).

        Parameters
        ----------
        prefix : str
            Path of the table or option that holds the field (``"rub[0]"``).

        Returns
        -------
        InputError
            A new error whose ``field`` is ``prefix`` joined with this error's field.
        """
        return type(self)(join(prefix, self.field), self.value, self.requirement, self.unit, self.source)

    def from_source(self, source: str) -> InputError:
        """The same error, naming the file (or built-in) it came from.

        Parameters
        ----------
        source : str
            Path of the file, or name of the built-in, the value was read from.

        Returns
        -------
        InputError
            A new error with ``source`` set.
        """
        return type(self)(self.field, self.value, self.requirement, self.unit, source)


def fail(field: str, value, requirement: str, unit: str = "") -> NoReturn:
    """Raise the :class:`InputError` ``<field> = <value>: <requirement> (<unit>)``."""
    raise InputError(field, value, requirement, unit)


# --------------------------------------------------------------------------- scalars
def _is_real(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def _bounds_text(ge, gt, le, lt) -> str:
    lo = ge if ge is not None else gt
    hi = le if le is not None else lt
    if lo is not None and hi is not None:
        return f"in {'[' if ge is not None else '('}{lo:g}, {hi:g}{']' if le is not None else ')'}"
    if lo is not None:
        return f">= {lo:g}" if ge is not None else f"> {lo:g}"
    if hi is not None:
        return f"<= {hi:g}" if le is not None else f"< {hi:g}"
    return ""


def number(field: str, value, unit: str = "", *, ge: float | None = None, gt: float | None = None,
           le: float | None = None, lt: float | None = None) -> float:
    """A finite real number, optionally bounded: ``ge`` (>=), ``gt`` (>), ``le`` (<=), ``lt`` (<).

    Returns
    -------
    float
    """
    bounds = _bounds_text(ge, gt, le, lt)
    if not _is_real(value) or not math.isfinite(value):
        fail(field, value, "must be a finite number" + (f" {bounds}" if bounds else ""), unit)
    v = float(value)
    if ((ge is not None and not v >= ge) or (gt is not None and not v > gt)
            or (le is not None and not v <= le) or (lt is not None and not v < lt)):
        fail(field, value, f"must be {bounds}" if not bounds.startswith("in") else f"must lie {bounds}", unit)
    return v


def positive(field: str, value, unit: str = "") -> float:
    """A finite number > 0."""
    return number(field, value, unit, gt=0.0)


def non_negative(field: str, value, unit: str = "") -> float:
    """A finite number >= 0."""
    return number(field, value, unit, ge=0.0)


def integer(field: str, value, unit: str = "", *, ge: int | None = None, le: int | None = None) -> int:
    """An integer (not a bool, not a float), optionally bounded (``ge`` <= value <= ``le``)."""
    bounds = _bounds_text(ge, None, le, None)
    if not isinstance(value, (int, np.integer)) or isinstance(value, (bool, np.bool_)):
        fail(field, value, "must be an integer" + (f" {bounds}" if bounds else ""), unit)
    v = int(value)
    if (ge is not None and v < ge) or (le is not None and v > le):
        fail(field, value, "must be an integer " + bounds, unit)
    return v


def choice(field: str, value, allowed: Iterable[str]) -> str:
    """One of ``allowed`` (compared as given)."""
    allowed = tuple(allowed)
    if not isinstance(value, str) or value not in allowed:
        fail(field, value, "must be one of " + ", ".join(repr(a) for a in allowed))
    return value


def string(field: str, value, *, empty: bool = True) -> str:
    """A string (non-empty unless ``empty``)."""
    if not isinstance(value, str) or (not empty and not value):
        fail(field, value, "must be a string" if empty else "must be a non-empty string")
    return value


def boolean(field: str, value) -> bool:
    """``true`` or ``false`` (a bool, not a number)."""
    if not isinstance(value, (bool, np.bool_)):
        fail(field, value, "must be true or false")
    return bool(value)


# --------------------------------------------------------------------------- containers
def table(field: str, value) -> dict:
    """A table (TOML ``[section]``, a dict)."""
    if not isinstance(value, Mapping):
        fail(field, value, "must be a table")
    return dict(value)


def tables(field: str, value, *, min_len: int = 0) -> tuple[dict, ...]:
    """An array of tables (TOML ``[[field]]`` or ``field = [{...}, ...]``): a list of dicts."""
    if not isinstance(value, (list, tuple)):
        fail(field, value, "must be an array of tables")
    if len(value) < min_len:
        fail(field, value, "must be a non-empty array of tables" if min_len == 1
             else f"must be an array of at least {min_len} tables")
    return tuple(table(f"{field}[{i}]", v) for i, v in enumerate(value))


def sequence(field: str, value, item: Callable[[str, Any], Any] | None = None, *, min_len: int = 0,
             max_len: int | None = None, unique: bool = False) -> tuple:
    """A list whose entries each pass ``item(field[i], entry)``; returns the tuple of checked entries."""
    if not isinstance(value, (list, tuple)):
        fail(field, value, "must be a list")
    if len(value) < min_len or (max_len is not None and len(value) > max_len):
        count = f"{min_len}" if max_len == min_len else (
            f"at least {min_len}" if max_len is None else f"{min_len} to {max_len}")
        fail(field, value, f"must hold {count} {'entry' if count.endswith(' 1') or count == '1' else 'entries'}, "
                           f"not {len(value)}")
    out = tuple(item(f"{field}[{i}]", v) if item else v for i, v in enumerate(value))
    if unique and len(set(out)) != len(out):
        fail(field, value, "must not list an entry twice")
    return out


def array(field: str, value, shape: tuple[int, ...] | None = None, unit: str = "") -> np.ndarray:
    """A finite real float array, of ``shape`` if given."""
    if np.iscomplexobj(value):
        fail(field, value, "must be an array of real numbers", unit)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        fail(field, value, "must be an array of numbers", unit)
    if shape is not None and arr.shape != tuple(shape):
        fail(field, value, f"must have shape {tuple(shape)}", unit)
    if not np.all(np.isfinite(arr)):
        fail(field, value, "must hold finite numbers only", unit)
    return arr


def vector(field: str, value, unit: str = "", *, min_len: int = 1, max_len: int | None = None,
           ge: float | None = None, gt: float | None = None, increasing: bool = False) -> np.ndarray:
    """A finite 1-D float array of ``min_len`` to ``max_len`` entries, each ``>= ge`` / ``> gt``,
    strictly increasing if ``increasing``.

    Returns
    -------
    ndarray, shape (n,)
    """
    arr = array(field, value, unit=unit)
    if arr.ndim != 1 or len(arr) < min_len or (max_len is not None and len(arr) > max_len):
        count = (f"{min_len}" if max_len == min_len else f"at least {min_len}" if max_len is None
                 else f"{min_len} to {max_len}")
        fail(field, value, f"must be a 1-D array of {count} value{'' if count.endswith(' 1') or count == '1' else 's'}",
             unit)
    bounds = _bounds_text(ge, gt, None, None)
    if (ge is not None and np.any(arr < ge)) or (gt is not None and np.any(arr <= gt)):
        fail(field, value, f"must hold values {bounds} only", unit)
    if increasing and np.any(np.diff(arr) <= 0):
        i = int(np.argmax(np.diff(arr) <= 0))
        fail(field, value, f"must be strictly increasing; entry {i} = {arr[i]:g} is followed by {arr[i + 1]:g}", unit)
    return arr


def ranges_text(nodes: Iterable[int]) -> str:
    """``'1-13, 14-20'`` for node numbers (sorted, consecutive runs joined)."""
    nodes = sorted(nodes)
    if not nodes:
        return "none"
    out, start, prev = [], nodes[0], nodes[0]
    for n in nodes[1:] + [None]:
        if n is not None and n == prev + 1:
            prev = n
            continue
        out.append(f"{start}" if start == prev else f"{start}-{prev}")
        if n is not None:
            start = prev = n
    return ", ".join(out)


def node(field: str, value, nodes: Collection[int], what: str = "a node of the rotor") -> int:
    """An integer that is one of ``nodes``."""
    integer(field, value)
    if int(value) not in nodes:
        fail(field, value, f"must be {what} ({ranges_text(nodes)})")
    return int(value)


def keys(field: str, data: Mapping, allowed: Iterable[str], required: Iterable[str] = ()) -> None:
    """No key outside ``allowed`` and every key of ``required`` present in the table ``data``."""
    allowed = set(allowed)
    for k in data:
        if k not in allowed:
            fail(join(field, str(k)), data[k], "unknown key; allowed keys are " + ", ".join(sorted(allowed)))
    for k in sorted(set(required)):
        if k not in data:
            raise InputError(join(field, k), MISSING, "required")



# --------------------------------------------------------------------------- physical bounds
@dataclass(frozen=True)
class Bound:
    """The largest magnitude an input may have (and for some the smallest), in the unit the user gives it, and why
    (docs/model.md).

    Attributes
    ----------
    limit : float
        The largest magnitude allowed (in ``unit``).
    unit : str
    why : str
        What the bound stands for, for the message.
    least : float
        The smallest magnitude allowed (in ``unit``; 0: none), for an input whose small values mean nothing too (a
        tolerance below round-off, a step of a femtosecond).
    """

    limit: float
    unit: str
    why: str
    least: float = 0.0


#: the physical bounds of command inputs, each in the unit the user types (docs/model.md, "Physical bounds of command
#: inputs", where each is argued); a spool speed in rad/s or Hz is bounded by the same speed as in rpm
BOUNDS = {
    "speed": Bound(1e6, "rpm", "twice the fastest machine rotors: micro gas turbines and dental air turbines stay "
                               "below 500 000 rpm"),
    "ratio": Bound(100.0, "", "the spools of one machine turn within a factor 100 of each other: dual-rotor "
                              "engines 1-3, geared fans about 3"),
    "unbalance": Bound(1e3, "kg m", "26 x the 38 kg m the coarsest ISO 21940-11 grade, G 4000, allows a 100 t "
                                    "rotor at 100 rpm"),
    "harmonic": Bound(1e3, "", "excitation orders stay below 1000: the highest, blade-passing orders, are blade "
                               "counts"),
    "frequency": Bound(1e6, "Hz", "far beyond the bending modes a beam model describes"),
    "clearance": Bound(0.1, "m", "rub clearances are micrometres to millimetres: a gap of 10 cm never closes on a "
                                 "rotor's orbit"),
    "tolerance": Bound(1e-2, "", "a relative residual of 1 % already is no solution; below 1e-14 it is round-off, "
                                 "never reached", least=1e-14),
    "step": Bound(1e-2, "s", "a 10 ms step samples a 50 Hz whirl twice a period; a step below 1 ns gives a billion "
                             "steps a simulated second", least=1e-9),
    "refine": Bound(100.0, "", "a shaft element split 100 times is far finer than a beam model needs: more only "
                               "multiplies the model's size"),
}

_PER_RPM = {"rpm": 1.0, "Hz": 60.0, "rad/s": 30.0 / math.pi}


def bounded(field: str, value, values, kind: str, unit: str = "") -> np.ndarray:
    """``values`` (a number or an array), refused when not finite or when a magnitude exceeds :data:`BOUNDS` ``[kind]``.

    Parameters
    ----------
    field : str
        The option or key that gave them (``"--speeds"``).
    value : object
        The value as the user gave it (its text), shown in the message.
    values : float or array_like
        The values, in ``unit``.
    kind : str
        A key of :data:`BOUNDS`: ``"speed"``, ``"ratio"``, ``"unbalance"``, ``"harmonic"``, ``"frequency"``,
        ``"clearance"``, ``"tolerance"``, ``"step"``, ``"refine"``.
    unit : str
        The unit of ``values`` (default the bound's; a speed may be in ``"rpm"``, ``"Hz"`` or ``"rad/s"``).

    Returns
    -------
    ndarray
        ``values`` as floats.
    """
    bound = BOUNDS[kind]
    unit = unit or bound.unit
    arr = np.asarray(values, dtype=float)
    if not np.all(np.isfinite(arr)):
        fail(field, value, "must be finite", unit)
    limit = bound.limit / _PER_RPM[unit] if kind == "speed" else bound.limit
    if arr.size and float(np.max(np.abs(arr))) > limit:
        fail(field, value, f"must be at most {bound_text(kind, unit)}")
    if arr.size and float(np.min(np.abs(arr))) < bound.least:
        fail(field, value, f"must be at least {bound_text(kind, unit, least=True)}")
    return arr


def bound_text(kind: str, unit: str = "", least: bool = False) -> str:
    """``"1e+06 rpm (twice the fastest machine rotors: ...)"``: the bound of :data:`BOUNDS` ``[kind]`` in ``unit``
    (default the bound's) and why; with ``least``, its smallest magnitude instead of its largest."""
    bound = BOUNDS[kind]
    unit = unit or bound.unit
    value = bound.least if least else bound.limit
    limit = value / _PER_RPM[unit] if kind == "speed" else value
    shown = f"{limit:.6g}" + (f" {unit}" if unit else "") + (f" = {value:g} {bound.unit}" if unit != bound.unit
                                                             else "")
    return f"{shown} ({bound.why})"


class NonFiniteResult(ValueError):
    """A computed result that holds NaN or inf, refused before it is written: the message names the quantity and
    where (the speed, the frequency) it first appeared."""


def finite_result(what: str, values, where) -> None:
    """Refuse (:class:`NonFiniteResult`) ``values`` holding NaN or inf.

    Parameters
    ----------
    what : str
        The quantity, as the message names it (``"the response at node 13 x"``).
    values : array_like
        The values, of any shape.
    where : callable
        ``where(index)`` -> text naming the place of a value (``"at 1500 rpm"``), from its index tuple.
    """
    arr = np.asarray(values)
    bad = ~np.isfinite(arr)
    if np.any(bad):
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        shown = "nan" if np.isnan(arr[index]) else "inf"
        raise NonFiniteResult(f"{what} is {shown} {where(index)} ({int(bad.sum())} of {arr.size} values not "
                              "finite): nothing written; check the inputs' magnitudes and the model's damping")
