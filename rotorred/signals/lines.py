"""Labels of the combination lines ``m f_H + n f_L`` of a dual-rotor response, FFT peaks, and the paper's Table 1.

A rub on one spool of a twin-spool rotor makes the response contain combinations
``m f_H + n f_L`` of the two spool frequencies (Xu et al. 2016, Sec. 3, Table 1; the
experiment, Table 2, adds half-integer ``n`` such as ``f_H + 3 f_L / 2``), and sub-harmonic
orders ``(m/k) f_H + (n/j) f_L`` where impacts lock to a fraction of a spool frequency.
The lines themselves, their amplitudes and the choice of label among the combinations at one
frequency come from the least-squares line fit (:mod:`rotorred.signals.linefit`, the one source
of labels); this module holds what the fit's lines are written and read with:

Labels
    :func:`line_label` is the one place that writes a label: ASCII, as in the paper's Table 1,
    positive terms first, f_H before f_L, coefficient 1 omitted, fractional orders as
    ``3f_L/2`` or ``2f_H/3``: ``"f_H-f_L"``, ``"2f_L-f_H"``, ``"f_H+3f_L/2"``.
    :func:`parse_label` reads it back. Figures render the same text with subscripts and a
    minus sign (:func:`rotorred.plots.scene.plot_label`).

Peaks
    :func:`find_peaks` gives the local maxima of an amplitude spectrum (``A[k] > A[k-1]`` and
    ``A[k] >= A[k+1]``), other than the DC bin, at least ``threshold`` times the largest non-DC
    amplitude (default 0.5 %). They are only candidates: :func:`rotorred.signals.linefit.fit_peaks`
    labels each by the fit's rule and fits the lines at their exact frequencies.

Table 1
    :data:`XU2016_TABLE1` and :func:`compare_with_expected` pair the paper's lines with a fit's.

References
----------
.. [1] Xu et al., "Dynamic Characteristics and Experimental Research of Dual-Rotor System with
   Rub-Impact Fault", Shock and Vibration 2016, 6239281, Tables 1 and 2.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction
from typing import Iterable, Sequence

import numpy as np

from rotorred import checks
from rotorred.signals.spectra import Spectrum
from rotorred.writers import render_table

__all__ = [
    "UNLABELLED",
    "XU2016_TABLE1",
    "LineMatch",
    "line_label",
    "parse_label",
    "find_peaks",
    "format_table",
    "compare_with_expected",
    "format_comparison",
]

UNLABELLED = "unlabelled"  #: the label column of a peak that no line explains (tables, CSV files)

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
def _order(name: str, value) -> Fraction:
    """An order as a Fraction: an int or a ``fractions.Fraction`` (not a float: f_L/3 has no exact float)."""
    if isinstance(value, Fraction):
        return value
    return Fraction(checks.integer(name, value))


def _term(coefficient: Fraction, symbol: str) -> str:
    """``|coefficient|`` times ``symbol`` without sign: f_H, 2f_H, f_L/2, 3f_L/2."""
    a = abs(coefficient)
    num = "" if a.numerator == 1 else str(a.numerator)
    den = "" if a.denominator == 1 else f"/{a.denominator}"
    return f"{num}{symbol}{den}"


def line_label(m, n) -> str:
    """The label of the line ``m f_H + n f_L``: the one text form of every line's label.

    Parameters
    ----------
    m, n : int or Fraction
        Multiples of f_H and f_L (dimensionless; ``Fraction(1, 3)`` is f_H/3, a sub-harmonic order).

    Returns
    -------
    str
        ASCII, positive terms first, f_H before f_L, coefficient 1 omitted: ``"f_H-f_L"``,
        ``"2f_L-f_H"``, ``"f_H+3f_L/2"``; ``"0"`` for m = n = 0.

    Examples
    --------
    >>> line_label(3, -2)
    '3f_H-2f_L'
    >>> line_label(Fraction(2, 3), -1)
    '2f_H/3-f_L'
    """
    terms = [(c, s) for c, s in ((_order("m", m), "f_H"), (_order("n", n), "f_L")) if c != 0]
    if not terms:
        return "0"
    terms.sort(key=lambda cs: cs[0] < 0)  # stable: positive first, f_H before f_L
    text = ""
    for i, (c, s) in enumerate(terms):
        text += ("-" if c < 0 else "" if i == 0 else "+") + _term(c, s)
    return text


_TERM_RE = re.compile(r"([+-]?)(\d*)f_([HL])(?:/(\d+))?")


def parse_label(label: str) -> tuple[Fraction, Fraction]:
    """Inverse of :func:`line_label`: ``"3f_H-2f_L"`` -> ``(Fraction(3), Fraction(-2))``.

    Returns
    -------
    m, n : Fraction
        Multiples of f_H and f_L.
    """
    checks.string("label", label)
    m, n = Fraction(0), Fraction(0)
    pos = 0
    seen = set()
    for match in _TERM_RE.finditer(label):
        if match.start() != pos or (pos > 0 and not match.group(1)) or match.group(3) in seen \
                or match.group(4) == "0":
            break
        seen.add(match.group(3))
        coefficient = Fraction(int(match.group(2) or 1), int(match.group(4) or 1))
        if match.group(1) == "-":
            coefficient = -coefficient
        if match.group(3) == "H":
            m = coefficient
        else:
            n = coefficient
        pos = match.end()
    if pos != len(label) or pos == 0:
        checks.fail("label", label, "must look like 'f_H-f_L', '2f_H+f_L', 'f_H+3f_L/2' or '2f_H/3' (as line_label "
                    "writes it)")
    return m, n


# --------------------------------------------------------------------------- peaks
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


# --------------------------------------------------------------------------- tables
def format_table(fit, *, amplitude_scale: float | None = None, amplitude_unit: str = "µm") -> str:
    """Table in the form of the paper's Table 1: ``Frequency (Hz) | Component``, the fit's lines then the peaks
    it left unlabelled (:data:`UNLABELLED`), by increasing frequency.

    Parameters
    ----------
    fit : rotorred.signals.linefit.LineFit
    amplitude_scale : float, optional
        If given, add an amplitude column, amplitudes multiplied by this factor
        (1e6 for a signal in metres shown in µm).
    amplitude_unit : str
        Unit shown in the amplitude column header.

    Returns
    -------
    str
    """
    header = ["Frequency (Hz)", "Component"]
    items = sorted([(ln.frequency_hz, ln.label, ln.amplitude) for ln in fit.lines]
                   + [(p.frequency_hz, UNLABELLED, p.amplitude) for p in fit.unlabelled])
    rows = []
    for f, label, amplitude in items:
        row = [f"{f:.2f}", label]
        if amplitude_scale is not None:
            row.append(f"{amplitude * amplitude_scale:.4g}")
        rows.append(row)
    if amplitude_scale is not None:
        header.append(f"Amplitude ({amplitude_unit})")
    return render_table(header, rows)


@dataclass(frozen=True)
class LineMatch:
    """An expected line (e.g. from the paper) and the line found nearest to it.

    Attributes
    ----------
    expected_hz : float
        Expected frequency (Hz).
    expected_label : str or None
        Expected component (:func:`line_label` form), if given.
    found : rotorred.signals.linefit.FittedLine or None
        Nearest found line within the tolerance, None if there is none.
    """

    expected_hz: float
    expected_label: str | None
    found: object | None

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
        if self.found is None:
            return False
        return parse_label(self.expected_label) == (self.found.m, self.found.n)


def compare_with_expected(
    lines: Sequence,
    expected: Iterable[float | tuple[float, str]],
    tol_hz: float = 1.0,
) -> list[LineMatch]:
    """Pair each expected frequency with the nearest found line within ``tol_hz``.

    Parameters
    ----------
    lines : sequence of rotorred.signals.linefit.FittedLine
        Found lines (``LineFit.lines``).
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


def format_comparison(matches: Iterable[LineMatch]) -> str:
    """Table ``Paper (Hz) | Paper component | Ours (Hz) | Ours - paper (Hz) | Our component | Agrees``."""
    header = ["Paper (Hz)", "Paper component", "Ours (Hz)", "Ours - paper (Hz)",
              "Our component", "Agrees"]
    rows = []
    for mt in matches:
        if mt.found is None:
            ours, diff, our_label = "-", "-", "not found"
        else:
            ours = f"{mt.found.frequency_hz:.2f}"
            diff = f"{mt.found.frequency_hz - mt.expected_hz:+.2f}"
            our_label = mt.found.label
        agrees = {None: "", True: "yes", False: "NO"}[mt.label_agrees]
        rows.append([f"{mt.expected_hz:.2f}", mt.expected_label or "", ours, diff, our_label, agrees])
    return render_table(header, rows)
