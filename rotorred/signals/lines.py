"""Spectral lines of a dual-rotor response, labelled as combinations m f_H + n f_L.

A rub on one spool of a twin-spool rotor makes the response contain combinations
``m f_H + n f_L`` of the two spool frequencies (Xu et al. 2016, Sec. 3, Table 1; the
experiment, Table 2, adds half-integer ``n`` such as ``f_H + 3 f_L / 2``).

Peaks
    A peak is a local maximum of the amplitude spectrum (``A[k] > A[k-1]`` and
    ``A[k] >= A[k+1]``), other than the DC bin, whose amplitude is at least ``threshold``
    times the largest non-DC amplitude (default 0.5 %).

Matching tolerance
    A peak at bin frequency ``f`` matches every combination with
    ``|m f_H + n f_L - f| <= tol_hz``. The default ``tol_hz = df / 2`` (half a bin, plus
    1e-9 df for rounding) is the largest distance between a tone and the bin where it
    peaks, for any window whose kernel falls off monotonically from its centre (all of
    :data:`rotorred.signals.spectra.WINDOWS`). With the exact spool frequencies and a commensurate
    record (:func:`rotorred.signals.spectra.settled_spectrum`) every combination is exactly on a
    bin. Pass a larger ``tol_hz`` when ``f_L`` and ``f_H`` are only estimates: an error
    ``e`` in each moves ``m f_H + n f_L`` by up to ``(|m| + |n|) e``.

Choice among several matches
    With f_L = 70 and f_H = 90 Hz every combination lies on a 10 Hz grid, so many
    ``(m, n)`` give the same frequency (140 Hz = 2 f_L = 9 f_H - 9 f_L ...). The label is
    the combination with the smallest key

        (|m| + |n|,  |n|,  -m)

    i.e. (1) the smallest order ``|m| + |n|``; (2) on a tie, the fewest multiples of f_L:
    the rubbing disk (node 18) is on the high-pressure spool, so harmonics of f_H are the
    carrier and f_L the modulation (the paper's "fundamental modulated by the other rotor");
    (3) then positive ``m``. Rule (1) alone reproduces all 24 lines of the paper's Table 1
    (each has a unique lowest-order combination within ``|m|, |n| <= 8``); rule (2) decides
    lines the paper does not list, e.g. 80 Hz = 4f_H-4f_L (not 5f_L-3f_H) and
    560 Hz = 7f_H-f_L (not 8f_L).

Labels
    Written as in the paper's Table 1: positive terms first, f_H before f_L, coefficient 1
    omitted, half-integer ``n`` as ``3f_L/2``. :attr:`SpectralLine.label` uses the Unicode
    minus sign U+2212 ("f_H−f_L"), :attr:`SpectralLine.label_ascii` the ASCII hyphen
    ("f_H-f_L"), :attr:`SpectralLine.label_math` matplotlib mathtext ("$f_H-f_L$").
    A peak that matches no combination has ``m = n = None`` and label ``"unknown"``.

References
----------
.. [1] Xu et al., "Dynamic Characteristics and Experimental Research of Dual-Rotor System with
   Rub-Impact Fault", Shock and Vibration 2016, 6239281, Tables 1 and 2.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction
from typing import Iterable, Sequence

import numpy as np

from rotorred import checks
from rotorred.writers import render_table
from rotorred.signals.spectra import Spectrum

__all__ = [
    "MINUS",
    "UNKNOWN",
    "XU2016_TABLE1",
    "SpectralLine",
    "LineMatch",
    "combination_label",
    "parse_label",
    "combinations_near",
    "label_frequency",
    "find_peaks",
    "label_lines",
    "format_table",
    "print_table",
    "compare_with_expected",
    "format_comparison",
]

MINUS = "\u2212"  #: the Unicode minus sign used in labels
UNKNOWN = "unknown"  #: label of a peak that matches no combination

#: Table 1 of Xu et al. 2016 (simulated outer-rotor Y spectrum): (frequency as printed (Hz),
#: component). The 520 Hz row is printed "5f_H+2f_L", which is 590 Hz; 5*90 + 70 = 520, so it
#: is given here as "5f_H+f_L" (an erratum of the paper). Every other label is as printed.
XU2016_TABLE1: tuple[tuple[float, str], ...] = (
    (19.53, "f_H-f_L"),
    (109.9, "2f_H-f_L"),
    (130.6, "3f_H-2f_L"),
    (140.4, "2f_L"),
    (150.1, "4f_H-3f_L"),
    (159.9, "f_H+f_L"),
    (179.4, "2f_H"),
    (200.2, "3f_H-f_L"),
    (219.7, "4f_H-2f_L"),
    (230.7, "f_H+2f_L"),
    (250.2, "2f_H+f_L"),
    (269.2, "3f_H"),
    (290.5, "4f_H-f_L"),
    (319.5, "2f_H+2f_L"),
    (339.4, "3f_H+f_L"),
    (360.1, "4f_H"),
    (379.6, "5f_H-f_L"),
    (410.2, "3f_H+2f_L"),
    (429.2, "4f_H+f_L"),
    (450.1, "5f_H"),
    (470.0, "6f_H-f_L"),
    (500.0, "4f_H+2f_L"),
    (520.0, "5f_H+f_L"),  # printed "5f_H+2f_L" (erratum, see above)
    (590.8, "5f_H+2f_L"),
)


# --------------------------------------------------------------------------- labels
def _as_m(m) -> Fraction:
    """m as a Fraction: any ``fractions.Fraction`` (an exact sub-harmonic order, f_H/3), else an integer."""
    if isinstance(m, Fraction):
        return m
    return Fraction(checks.integer("m", m))


def _as_n(n) -> Fraction:
    if isinstance(n, Fraction):  # an exact order: any denominator (f_L/3)
        return n
    if not isinstance(n, Fraction):
        checks.number("n", n)  # a finite real number (not a bool) ...
    f = Fraction(n) if not isinstance(n, np.generic) else Fraction(n.item())
    if f.denominator not in (1, 2):  # ... that is a multiple of 1/2
        checks.fail("n", n, "must be an integer or half-integer")
    return f


def _term(coefficient: Fraction, symbol: str) -> str:
    """``|coefficient|`` times ``symbol`` without sign: f_H, 2f_H, f_L/2, 3f_L/2."""
    a = abs(coefficient)
    num = "" if a.numerator == 1 else str(a.numerator)
    den = "" if a.denominator == 1 else f"/{a.denominator}"
    return f"{num}{symbol}{den}"


def combination_label(m, n, minus: str = MINUS, math_text: bool = False) -> str:
    """Label of ``m f_H + n f_L`` in the paper's Table 1 style.

    Parameters
    ----------
    m : int or Fraction
        Multiple of f_H: an integer, or a ``fractions.Fraction`` of any denominator
        (``Fraction(2, 3)``: ``2f_H/3``, a sub-harmonic order, :mod:`rotorred.signals.linefit`).
    n : int or Fraction or float
        Multiple of f_L: a ``Fraction`` of any denominator, or an integer or half-integer number.
    minus : str
        Minus sign: ``MINUS`` (U+2212, default) or ``"-"``.
    math_text : bool
        Return matplotlib mathtext (``"$2f_H-f_L$"``), which renders subscripts and a minus.

    Returns
    -------
    str
        Positive terms first, f_H before f_L: ``"f_H−f_L"``, ``"2f_L−f_H"``,
        ``"f_H+3f_L/2"``; ``"0"`` for m = n = 0.

    Examples
    --------
    >>> combination_label(3, -2, minus="-")
    '3f_H-2f_L'
    >>> combination_label(1, 1.5, minus="-")
    'f_H+3f_L/2'
    >>> combination_label(Fraction(2, 3), Fraction(-1, 3), minus="-")
    '2f_H/3-f_L/3'
    """
    mf = _as_m(m)
    nf = _as_n(n)
    terms = [(c, s) for c, s in ((mf, "f_H"), (nf, "f_L")) if c != 0]
    if not terms:
        return "$0$" if math_text else "0"
    terms.sort(key=lambda cs: cs[0] < 0)  # stable: positive first, f_H before f_L
    if math_text:
        minus = "-"
    text = ""
    for i, (c, s) in enumerate(terms):
        sign = (minus if c < 0 else "") if i == 0 else (minus if c < 0 else "+")
        text += sign + _term(c, s)
    return f"${text}$" if math_text else text


_TERM_RE = re.compile(r"([+-]?)(\d*)f_?([HL])(?:/(\d+))?")


def parse_label(label: str) -> tuple[int, Fraction]:
    """Inverse of :func:`combination_label`: ``"3f_H−2f_L"`` -> ``(3, Fraction(-2))``.

    Accepts the Unicode or ASCII minus, spaces, ``f_H``/``fH``, and ``3f_L/2``.

    Returns
    -------
    m : int
    n : Fraction
    """
    checks.string("label", label)
    text = label.replace(MINUS, "-").replace(" ", "").strip("$")
    m, n = Fraction(0), Fraction(0)
    pos = 0
    seen = set()
    for match in _TERM_RE.finditer(text):
        if match.start() != pos or (pos > 0 and not match.group(1)):
            break
        sign = -1 if match.group(1) == "-" else 1
        coef = Fraction(int(match.group(2) or 1), int(match.group(4) or 1))
        which = match.group(3)
        if which in seen:
            break
        seen.add(which)
        if which == "H":
            m = sign * coef
        else:
            n = sign * coef
        pos = match.end()
    if pos != len(text) or pos == 0 or m.denominator != 1 or n.denominator not in (1, 2):
        checks.fail("label", label, "must look like 'f_H-f_L', '2f_H+f_L', 'f_H+3f_L/2' (integer m, integer or "
                    "half-integer n)")
    return int(m), n


# --------------------------------------------------------------------------- matching
def _rule_key(mn: tuple[int, Fraction]) -> tuple:
    m, n = mn
    return (abs(m) + abs(n), abs(n), -m)


def combinations_near(
    frequency_hz: float,
    f_L: float,
    f_H: float,
    tol_hz: float,
    *,
    max_m: int = 8,
    max_n: int = 8,
    half_integer: bool = False,
) -> list[tuple[int, Fraction]]:
    """All ``(m, n)`` with ``|m f_H + n f_L - frequency_hz| <= tol_hz``, best first.

    Parameters
    ----------
    frequency_hz : float
        Frequency to explain (Hz), > 0.
    f_L, f_H : float
        Spool frequencies (Hz), > 0.
    tol_hz : float
        Matching tolerance (Hz), > 0.
    max_m, max_n : int
        Bounds ``|m| <= max_m``, ``|n| <= max_n``.
    half_integer : bool
        Also allow half-integer ``n`` (f_L/2, 3f_L/2, ...).

    Returns
    -------
    list of (int, Fraction)
        Sorted by the labelling rule (``(|m| + |n|, |n|, -m)``, see the module docstring);
        only combinations with positive frequency.
    """
    f = checks.positive("frequency_hz", frequency_hz, "Hz")
    f_L = checks.positive("f_L", f_L, "Hz")
    f_H = checks.positive("f_H", f_H, "Hz")
    tol = checks.positive("tol_hz", tol_hz, "Hz")
    max_m = checks.integer("max_m", max_m, ge=0)
    max_n = checks.integer("max_n", max_n, ge=0)
    step = 2 if half_integer else 1
    out = []
    for k in range(-max_n * step, max_n * step + 1):
        n = Fraction(k, step)
        # m f_H within [f - n f_L - tol, f - n f_L + tol]
        lo = math.ceil((f - float(n) * f_L - tol) / f_H - 1e-12)
        hi = math.floor((f - float(n) * f_L + tol) / f_H + 1e-12)
        for m in range(max(lo, -max_m), min(hi, max_m) + 1):
            c = m * f_H + float(n) * f_L
            if c > 0 and abs(c - f) <= tol:
                out.append((m, n))
    out.sort(key=_rule_key)
    return out


def label_frequency(
    frequency_hz: float,
    f_L: float,
    f_H: float,
    tol_hz: float,
    *,
    max_m: int = 8,
    max_n: int = 8,
    half_integer: bool = False,
) -> tuple[int, Fraction] | None:
    """The combination chosen by the labelling rule, or None if nothing matches.

    See :func:`combinations_near` for the parameters.
    """
    found = combinations_near(
        frequency_hz, f_L, f_H, tol_hz, max_m=max_m, max_n=max_n, half_integer=half_integer
    )
    return found[0] if found else None


# --------------------------------------------------------------------------- peaks
@dataclass(frozen=True)
class SpectralLine:
    """One peak of a spectrum and its combination label.

    Attributes
    ----------
    frequency_hz : float
        Bin frequency of the peak (Hz).
    amplitude : float
        Amplitude at the peak, in the spectrum's units.
    m : int or None
        Multiple of f_H (None if unknown).
    n : Fraction or None
        Multiple of f_L, integer or half-integer (None if unknown).
    label : str
        Table 1 style with the Unicode minus ("f_H−f_L"), or ``"unknown"``.
    """

    frequency_hz: float
    amplitude: float
    m: int | None
    n: Fraction | None
    label: str

    @property
    def known(self) -> bool:
        """True when the peak matched a combination."""
        return self.m is not None

    @property
    def order(self) -> Fraction | None:
        """``|m| + |n|`` (None if unknown)."""
        return None if self.m is None else abs(self.m) + abs(self.n)

    @property
    def label_ascii(self) -> str:
        """Label with the ASCII hyphen as minus ("f_H-f_L")."""
        return UNKNOWN if self.m is None else combination_label(self.m, self.n, minus="-")

    @property
    def label_math(self) -> str:
        """Label as matplotlib mathtext ("$f_H-f_L$"), or "?" if unknown."""
        return "?" if self.m is None else combination_label(self.m, self.n, math_text=True)


def find_peaks(spectrum: Spectrum, threshold: float = 0.005) -> np.ndarray:
    """Bins of the local maxima above ``threshold`` times the largest non-DC amplitude.

    Parameters
    ----------
    spectrum : Spectrum
    threshold : float
        Relative to the largest amplitude at bins k >= 1, in (0, 1]. Default 0.005 (0.5 %).

    Returns
    -------
    ndarray of int, shape (n_peaks,)
        Increasing bin indices, never 0 (DC is not a line).

    Notes
    -----
    Two lines on adjacent bins cannot both be local maxima. With 70/90 Hz the lines are
    10 Hz apart, so use a record of at least two common periods (0.2 s, df <= 5 Hz);
    :func:`rotorred.signals.spectra.settled_spectrum` takes as many periods as fit.
    """
    if not isinstance(spectrum, Spectrum):
        checks.fail("spectrum", spectrum, "must be a Spectrum")
    threshold = checks.number("threshold", threshold, gt=0.0, le=1.0)
    a = np.asarray(spectrum.amplitudes, dtype=float)
    if a.size < 2:
        return np.zeros(0, dtype=int)
    a_max = a[1:].max()
    if a_max <= 0:
        return np.zeros(0, dtype=int)
    left = np.r_[a[1:] > a[:-1]]  # a[k] > a[k-1] for k >= 1
    right = np.r_[a[1:-1] >= a[2:], True]  # a[k] >= a[k+1], last bin has no right neighbour
    k = np.nonzero(left & right & (a[1:] >= threshold * a_max))[0] + 1
    return k


def label_lines(
    spectrum: Spectrum,
    f_L: float,
    f_H: float,
    *,
    threshold: float = 0.005,
    tol_hz: float | None = None,
    max_m: int = 8,
    max_n: int = 8,
    half_integer: bool = False,
) -> list[SpectralLine]:
    """Find the peaks of a spectrum and label each as a combination ``m f_H + n f_L``.

    Parameters
    ----------
    spectrum : Spectrum
    f_L, f_H : float
        Spool frequencies (Hz).
    threshold : float
        Peaks below ``threshold`` times the largest line are ignored (default 0.5 %).
    tol_hz : float, optional
        Matching tolerance (Hz); default half a bin (``spectrum.df / 2``), see the module
        docstring.
    max_m, max_n : int
        Bounds on ``|m|`` and ``|n|``.
    half_integer : bool
        Allow half-integer ``n`` (f_H + 3f_L/2, as in the paper's experiment, Table 2).

    Returns
    -------
    list of SpectralLine
        By increasing frequency.
    """
    if tol_hz is None:
        tol_hz = 0.5 * spectrum.df * (1.0 + 1e-9)
    lines = []
    for k in find_peaks(spectrum, threshold):
        f = float(spectrum.frequencies[k])
        mn = label_frequency(
            f, f_L, f_H, tol_hz, max_m=max_m, max_n=max_n, half_integer=half_integer
        )
        if mn is None:
            lines.append(SpectralLine(f, float(spectrum.amplitudes[k]), None, None, UNKNOWN))
        else:
            m, n = mn
            lines.append(
                SpectralLine(f, float(spectrum.amplitudes[k]), m, n, combination_label(m, n))
            )
    return lines


# --------------------------------------------------------------------------- tables
def format_table(
    lines: Iterable[SpectralLine],
    *,
    ascii: bool = False,
    amplitude_scale: float | None = None,
    amplitude_unit: str = "µm",
) -> str:
    """Table in the form of the paper's Table 1: ``Frequency (Hz) | Component``.

    Parameters
    ----------
    lines : iterable of SpectralLine
    ascii : bool
        ASCII hyphen instead of the Unicode minus.
    amplitude_scale : float, optional
        If given, add an amplitude column, amplitudes multiplied by this factor
        (1e6 for a spectrum in metres shown in µm).
    amplitude_unit : str
        Unit shown in the amplitude column header.

    Returns
    -------
    str
    """
    header = ["Frequency (Hz)", "Component"]
    rows = []
    for line in lines:
        label = line.label_ascii if ascii else line.label
        row = [f"{line.frequency_hz:.2f}", label]
        if amplitude_scale is not None:
            row.append(f"{line.amplitude * amplitude_scale:.4g}")
        rows.append(row)
    if amplitude_scale is not None:
        header.append(f"Amplitude ({amplitude_unit})")
    return render_table(header, rows)


def print_table(lines: Iterable[SpectralLine], **kwargs) -> None:
    """Print :func:`format_table` (same keyword arguments)."""
    print(format_table(lines, **kwargs))


@dataclass(frozen=True)
class LineMatch:
    """An expected line (e.g. from the paper) and the line found nearest to it.

    Attributes
    ----------
    expected_hz : float
        Expected frequency (Hz).
    expected_label : str or None
        Expected component (ASCII form), if given.
    found : SpectralLine or None
        Nearest found line within the tolerance, None if there is none.
    """

    expected_hz: float
    expected_label: str | None
    found: SpectralLine | None

    @property
    def found_hz(self) -> float | None:
        """Frequency of the found line (Hz), None if not found."""
        return None if self.found is None else self.found.frequency_hz

    @property
    def label_agrees(self) -> bool | None:
        """Whether the found line's combination equals the expected one (None if no label
        was expected; False if nothing was found)."""
        if self.expected_label is None:
            return None
        if self.found is None or not self.found.known:
            return False
        return parse_label(self.expected_label) == (self.found.m, self.found.n)


def compare_with_expected(
    lines: Sequence[SpectralLine],
    expected: Iterable[float | tuple[float, str]],
    tol_hz: float = 1.0,
) -> list[LineMatch]:
    """Pair each expected frequency with the nearest found line within ``tol_hz``.

    Parameters
    ----------
    lines : sequence of SpectralLine
        Found lines (from :func:`label_lines`).
    expected : iterable of float or (float, str)
        Expected frequencies (Hz), optionally with their component label
        (e.g. :data:`XU2016_TABLE1`).
    tol_hz : float
        Largest distance (Hz) for a match. The default 1 Hz covers the paper's Table 1:
        its frequencies are bins of width 1000/2048 = 0.488 Hz of a response whose spool
        frequencies were read as 69.58 and 90.33 Hz, so its lines lie up to 0.8 Hz from the
        70/90 Hz grid (269.2 Hz for 3f_H, 590.8 Hz for 5f_H+2f_L).

    Returns
    -------
    list of LineMatch
        In the order of ``expected``.
    """
    tol_hz = checks.positive("tol_hz", tol_hz, "Hz")
    lines = list(lines)
    freqs = np.array([line.frequency_hz for line in lines], dtype=float)
    out = []
    for i, item in enumerate(expected):
        if isinstance(item, tuple):
            if len(item) != 2 or not isinstance(item[1], str):
                checks.fail(f"expected[{i}]", item, "must be a frequency (Hz) or a (frequency, label) pair")
            f, label = item
            parse_label(label)  # validates the label
            label = label.replace(MINUS, "-").replace(" ", "")
        else:
            f, label = item, None
        f = checks.positive(f"expected[{i}]", f, "Hz")
        found = None
        if freqs.size:
            i = int(np.argmin(np.abs(freqs - f)))
            if abs(freqs[i] - f) <= tol_hz:
                found = lines[i]
        out.append(LineMatch(f, label, found))
    return out


def format_comparison(matches: Iterable[LineMatch], *, ascii: bool = False) -> str:
    """Table ``Paper (Hz) | Paper component | Ours (Hz) | Ours - paper (Hz) | Our component |
    Agrees``."""
    header = ["Paper (Hz)", "Paper component", "Ours (Hz)", "Ours - paper (Hz)",
              "Our component", "Agrees"]
    rows = []
    for mt in matches:
        exp_label = mt.expected_label or ""
        if not ascii:
            exp_label = exp_label.replace("-", MINUS)
        if mt.found is None:
            ours, diff, our_label = "-", "-", "not found"
        else:
            ours = f"{mt.found.frequency_hz:.2f}"
            diff = f"{mt.found.frequency_hz - mt.expected_hz:+.2f}"
            our_label = mt.found.label_ascii if ascii else mt.found.label
        agrees = {None: "", True: "yes", False: "NO"}[mt.label_agrees]
        rows.append([f"{mt.expected_hz:.2f}", exp_label, ours, diff, our_label, agrees])
    return render_table(header, rows)
