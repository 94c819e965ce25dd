"""Line labelling: the rule reproduces the paper's Table 1, peaks are found and labelled."""

import re
from fractions import Fraction

import numpy as np
import pytest

from rotorred.checks import InputError
from rotorred.signals.lines import (
    MINUS,
    UNKNOWN,
    XU2016_TABLE1,
    combination_label,
    combinations_near,
    compare_with_expected,
    find_peaks,
    format_comparison,
    format_table,
    label_frequency,
    label_lines,
    parse_label,
)
from rotorred.signals.spectra import amplitude_spectrum, settled_spectrum

F_L, F_H = 70.0, 90.0  # the paper's operating point (4200 and 5400 rpm), Sec. 3


def _table1_combinations():
    """(m, n) of each Table 1 row, parsed from the labels (not typed as numbers)."""
    return [parse_label(label) for _, label in XU2016_TABLE1]


# --------------------------------------------------------------------------- labels
def test_label_text_both_minus_signs():
    assert combination_label(1, -1) == "f_H" + MINUS + "f_L"
    assert combination_label(1, -1, minus="-") == "f_H-f_L"
    assert combination_label(0, 2) == "2f_L"
    assert combination_label(3, -2, minus="-") == "3f_H-2f_L"
    assert combination_label(1, Fraction(3, 2), minus="-") == "f_H+3f_L/2"
    assert combination_label(-1, 2, minus="-") == "2f_L-f_H"  # positive term first
    assert combination_label(2, 0) == "2f_H"
    assert combination_label(2, -1, math_text=True) == "$2f_H-f_L$"
    for m in range(-4, 5):
        for k in range(-8, 9):
            n = Fraction(k, 2)
            if m == 0 and n == 0:
                continue
            for minus in (MINUS, "-"):
                assert parse_label(combination_label(m, n, minus=minus)) == (m, n)
    for bad in ["", "2f_H+3f_H", "f_H/2", "f_L/3", "f_H-", "3 Hz"]:
        with pytest.raises(InputError, match=f"^label = {re.escape(repr(bad))}: must look like 'f_H-f_L', "):
            parse_label(bad)
    with pytest.raises(InputError, match="^label = 3: must be a string$"):
        parse_label(3)
    with pytest.raises(InputError, match=r"^m = 1\.5: must be an integer$"):
        combination_label(1.5, 1)
    with pytest.raises(InputError, match=r"^n = 0\.25: must be an integer or half-integer$"):
        combination_label(1, 0.25)
    with pytest.raises(InputError, match=r"^n = nan: must be a finite number$"):
        combination_label(1, float("nan"))


def test_table1_data_is_consistent_with_70_90_hz():
    """Every Table 1 label, evaluated at 70/90 Hz, is within 1 Hz of the printed frequency
    (the paper's bins are 0.488 Hz wide and its spool frequencies were 69.58/90.33 Hz,
    which moves its lines up to 0.8 Hz off the 70/90 grid). The paper prints 520 Hz as
    5f_H+2f_L = 590 Hz; XU2016_TABLE1 carries the corrected 5f_H+f_L, checked here."""
    assert len(XU2016_TABLE1) == 24
    for (f_paper, label), (m, n) in zip(XU2016_TABLE1, _table1_combinations()):
        assert abs(m * F_H + n * F_L - f_paper) <= 1.0, label
    m, n = parse_label("5f_H+2f_L")  # as printed at 520 Hz
    assert m * F_H + n * F_L == 590.0


def test_rule_reproduces_all_24_table1_labels():
    """At the exact grid frequency of each row, the rule picks the paper's combination, and
    the lowest order alone decides (no tie among the candidates within |m|, |n| <= 8)."""
    tol = 0.5  # half the 1 Hz bin of a 1 s record; the grid is exact at 70/90 Hz
    n_ambiguous = 0
    for (m, n), (_, label) in zip(_table1_combinations(), XU2016_TABLE1):
        f = m * F_H + float(n) * F_L
        for half in (False, True):
            cands = combinations_near(f, F_L, F_H, tol, half_integer=half)
            assert cands[0] == (m, n), (label, cands[:3])
            order = [abs(a) + abs(b) for a, b in cands]
            assert len(order) == 1 or order[0] < order[1], (label, cands[:2])  # no tie
            n_ambiguous += len(cands) > 1
    # The grid ambiguity is real: for half the rows other (m, n) within the bounds give the
    # same frequency, e.g. 140 Hz = 2f_L = 7f_H-7f_L.
    assert n_ambiguous == 24
    assert combinations_near(140.0, F_L, F_H, tol) == [(0, 2), (7, -7)]


def test_rule_beyond_table1():
    """Order comes first: 440 Hz is f_H+5f_L (order 6), not 8f_H-4f_L (order 12), although
    the latter has fewer multiples of f_L ("fewest f_L" alone would also reproduce Table 1,
    whose lines all have |n| <= 3). Where the order ties, fewer multiples of f_L wins
    (f_H is the rubbing spool)."""
    assert combinations_near(440.0, F_L, F_H, 0.5) == [(1, 5), (8, -4)]
    assert combinations_near(80.0, F_L, F_H, 0.5)[:2] == [(4, -4), (-3, 5)]
    assert combinations_near(560.0, F_L, F_H, 0.5)[:2] == [(7, -1), (0, 8)]
    assert label_frequency(650.0, F_L, F_H, 0.5) == (8, -1)  # not f_H+8f_L
    assert label_frequency(333.0, F_L, F_H, 0.5) is None  # off the 10 Hz grid
    assert label_frequency(20.0, F_L, F_H, 0.5, max_m=0) is None  # bound respected
    with pytest.raises(InputError, match=r"^tol_hz = 0\.0: must be > 0 \(Hz\)$"):
        label_frequency(20.0, F_L, F_H, 0.0)
    with pytest.raises(InputError, match=r"^f_H = nan: must be a finite number > 0 \(Hz\)$"):
        label_frequency(20.0, F_L, float("nan"), 0.5)
    with pytest.raises(InputError, match=r"^max_m = -1: must be an integer >= 0$"):
        label_frequency(20.0, F_L, F_H, 0.5, max_m=-1)


# --------------------------------------------------------------------------- synthetic
def _synthetic(extra_hz=(), seed=3, periods=10, dt=1e-5):
    """Sum of the 24 Table 1 combinations plus f_L and f_H, random amplitudes and phases,
    frequencies computed from the parsed (m, n) at 70/90 Hz; plus `extra_hz` tones."""
    rng = np.random.default_rng(seed)
    mns = [(0, Fraction(1)), (1, Fraction(0))] + _table1_combinations()
    freqs = [m * F_H + float(n) * F_L for m, n in mns] + list(extra_hz)
    # Log-uniform 1e-2 .. 1 of the largest: all above the 0.5 % threshold.
    amps = 10 ** rng.uniform(-2, 0, len(freqs))
    amps[1] = 1.5  # f_H is the largest line (the outer rotor's unbalance response)
    t = np.arange(periods * int(round(0.1 / dt))) * dt
    phases = rng.uniform(0, 2 * np.pi, len(freqs))
    x = sum(a * np.cos(2 * np.pi * f * t + p) for a, f, p in zip(amps, freqs, phases))
    return 1e-6 * x, dt, mns, freqs, amps


def test_synthetic_table1_signal_every_line_found_and_labelled():
    x, dt, mns, freqs, amps = _synthetic(extra_hz=[333.0])
    s = settled_spectrum(x, dt, F_L, F_H)
    assert s.window == "rectangular" and s.df == pytest.approx(1.0)
    lines = label_lines(s, F_L, F_H)
    by_freq = {round(line.frequency_hz, 6): line for line in lines}
    assert len(lines) == len(freqs)  # no spurious peaks, none missed
    for (m, n), f, a in zip(mns, freqs, amps):
        line = by_freq[round(f, 6)]
        assert (line.m, line.n) == (m, n)
        assert line.label == combination_label(m, n)
        assert line.amplitude * 1e6 == pytest.approx(a, rel=1e-9)  # exact on-bin
    # The paper's labels, in both spellings (520 Hz as corrected).
    labelled = {line.label_ascii for line in lines}
    assert {label for _, label in XU2016_TABLE1} <= labelled
    assert by_freq[20.0].label == "f_H" + MINUS + "f_L"
    assert by_freq[520.0].label_ascii == "5f_H+f_L"
    # The off-grid line is found but not labelled.
    off = by_freq[333.0]
    assert off.label == UNKNOWN and off.m is None and not off.known


def test_threshold_and_peaks():
    x, dt, *_ = _synthetic()
    s = amplitude_spectrum(x[-20000:], dt)  # two 0.1 s periods: df = 5 Hz
    k = find_peaks(s, threshold=0.005)
    assert 0 not in k
    assert len(k) == 26
    # With one period (df = 10 Hz) lines on adjacent bins (130, 140, 150, 160 Hz ...)
    # cannot all be local maxima: the documented reason for >= 2 periods.
    assert len(find_peaks(amplitude_spectrum(x[-10000:], dt))) < 26
    # A higher threshold keeps only lines above it (relative to the largest line).
    a = s.amplitudes
    k_hi = find_peaks(s, threshold=0.3)
    assert set(k_hi) == {i for i in k if a[i] >= 0.3 * a[1:].max()}
    with pytest.raises(InputError, match=r"^threshold = 1\.5: must lie in \(0, 1\]$"):
        find_peaks(s, threshold=1.5)


def test_half_integer_only_when_enabled():
    x, dt, mns, freqs, _ = _synthetic(extra_hz=[F_H + 1.5 * F_L], seed=5)
    s = settled_spectrum(x, dt, F_L, F_H)
    off = {line.frequency_hz: line for line in label_lines(s, F_L, F_H)}
    assert off[195.0].label == UNKNOWN
    on_lines = label_lines(s, F_L, F_H, half_integer=True)
    on = {line.frequency_hz: line for line in on_lines}
    assert on[195.0].label == "f_H+3f_L/2"
    assert (on[195.0].m, on[195.0].n) == (1, Fraction(3, 2))
    # Enabling half-integers changes no other label (integer lines have integer n first).
    for f, line in off.items():
        if f != 195.0:
            assert on[f].label == line.label


def test_table_and_comparison_output():
    x, dt, *_ = _synthetic()
    s = settled_spectrum(x, dt, F_L, F_H)
    lines = label_lines(s, F_L, F_H)
    text = format_table(lines)
    assert text.splitlines()[0].split(" | ") == ["Frequency (Hz)", "Component"]
    assert "20.00 " in text and "f_H" + MINUS + "f_L" in text
    ascii_text = format_table(lines, ascii=True, amplitude_scale=1e6)
    assert MINUS not in ascii_text and "Amplitude (µm)" in ascii_text
    matches = compare_with_expected(lines, XU2016_TABLE1)
    assert len(matches) == 24
    assert all(mt.found is not None and mt.label_agrees for mt in matches)
    assert [mt.found_hz for mt in matches][:2] == [20.0, 110.0]
    # The label as printed at 520 Hz does not agree; a missing line is reported.
    bad = compare_with_expected(lines, [(520.0, "5f_H+2f_L"), 600.5])
    assert bad[0].label_agrees is False
    assert bad[1].found is None and bad[1].label_agrees is None
    table = format_comparison(bad, ascii=True)
    assert "NO" in table and "not found" in table
    with pytest.raises(InputError, match="^label = 'nonsense': must look like"):
        compare_with_expected(lines, [(20.0, "nonsense")])
    with pytest.raises(InputError, match=r"^expected\[1\] = -5\.0: must be > 0 \(Hz\)$"):
        compare_with_expected(lines, [20.0, -5.0])


def test_labels_on_flattop_fallback_for_incommensurate_speeds():
    """The paper's read-off speeds 69.58/90.33 Hz have no common period: the spectrum falls
    back to the flat-top window, peaks lie within half a bin of the true frequencies, and
    the default tolerance (half a bin) still labels each line."""
    f_L, f_H, dt = 69.58, 90.33, 1e-4
    t = np.arange(20_000) * dt  # 2 s: df = 0.5 Hz, lines >= 20 Hz = 40 bins apart
    combos = [(0, 1, 0.3), (1, 0, 1.0), (1, -1, 0.05), (2, -1, 0.1), (3, -2, 0.04), (2, 1, 0.08)]
    x = sum(a * np.cos(2 * np.pi * (m * f_H + n * f_L) * t + m) for m, n, a in combos)
    s = settled_spectrum(x, dt, f_L, f_H)
    assert s.window == "flattop"
    lines = label_lines(s, f_L, f_H)
    assert [(ln.m, ln.n) for ln in lines] == sorted(
        [(m, n) for m, n, _ in combos], key=lambda mn: mn[0] * f_H + mn[1] * f_L
    )
    for ln, (m, n, a) in zip(lines, sorted(combos, key=lambda c: c[0] * f_H + c[1] * f_L)):
        assert abs(ln.frequency_hz - (m * f_H + n * f_L)) <= 0.5 * s.df
        # HFT95: within 0.0045 dB, plus leakage < 1e-4 absolute (5 other lines of amplitude
        # <= 1 times sidelobes below -95 dB = 1.8e-5).
        assert abs(20 * np.log10(ln.amplitude / a)) <= 0.0045 + 20 * np.log10(1 + 1e-4 / a)
