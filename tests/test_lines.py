"""Line labels: one text form, the fit's rule reproduces the paper's Table 1, FFT peaks propose the lines."""

from fractions import Fraction

import numpy as np
import pytest

from rotorred.checks import InputError
from rotorred.signals.linefit import fit_peaks
from rotorred.signals.lines import (
    UNLABELLED,
    XU2016_TABLE1,
    compare_with_expected,
    find_peaks,
    format_comparison,
    format_table,
    line_label,
    parse_label,
)
from rotorred.signals.spectra import amplitude_spectrum, settled_spectrum

F_L, F_H = 70.0, 90.0  # the paper's operating point (4200 and 5400 rpm), Sec. 3


def _table1_combinations():
    """(m, n) of each Table 1 row, parsed from the labels (not typed as numbers)."""
    return [parse_label(label) for _, label in XU2016_TABLE1]


# --------------------------------------------------------------------------- labels
def test_label_text():
    assert line_label(1, -1) == "f_H-f_L"
    assert line_label(0, 2) == "2f_L"
    assert line_label(3, -2) == "3f_H-2f_L"
    assert line_label(1, Fraction(3, 2)) == "f_H+3f_L/2"
    assert line_label(-1, 2) == "2f_L-f_H"  # positive term first
    assert line_label(2, 0) == "2f_H" and line_label(0, 0) == "0"
    assert line_label(Fraction(1, 3), Fraction(-2, 3)) == "f_H/3-2f_L/3"


def test_labels_parse_back_and_bad_input_is_refused():
    for m in (-3, 0, 1, 2, Fraction(1, 3), Fraction(-5, 6)):
        for n in (Fraction(-5, 2), -1, 0, 1, Fraction(3, 2), Fraction(2, 3)):
            if m or n:
                assert parse_label(line_label(m, n)) == (m, n)
    for bad in ("", "f_X", "2f_H2f_L", "f_H+f_H", "f_L/0", "3", "f_H−f_L"):
        with pytest.raises(InputError, match="^label = .*: must look like"):
            parse_label(bad)
    with pytest.raises(InputError, match="^label = 3: must be a string"):
        parse_label(3)
    with pytest.raises(InputError, match=r"^m = 1\.5: must be an integer$"):
        line_label(1.5, 1)
    with pytest.raises(InputError, match=r"^n = 0\.25: must be an integer$"):
        line_label(1, 0.25)


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
    """Each Table 1 line of a synthetic signal is labelled with the paper's combination by the fit's rule, and the
    ambiguity of the 10 Hz grid is real: the 140 Hz line also carries 7f_H-7f_L."""
    x, dt, mns, freqs, amps = _synthetic()
    t = np.arange(x.size) * dt
    fit = fit_peaks(t, x, F_L, F_H)
    first = {ln.frequency_hz: ln.orders[0] for ln in fit.lines}
    for (m, n), (_, label) in zip(_table1_combinations(), XU2016_TABLE1):
        assert first[m * F_H + n * F_L] == (m, n), label
    line_140 = next(ln for ln in fit.lines if ln.frequency_hz == 140.0)
    assert line_140.labels == ("2f_L", "7f_H-7f_L")


def test_rule_beyond_table1():
    """Order comes first: 440 Hz is f_H+5f_L (order 6), not 8f_H-4f_L (order 12), although
    the latter has fewer multiples of f_L ("fewest f_L" alone would also reproduce Table 1,
    whose lines all have |n| <= 3). Where the order ties, fewer multiples of f_L wins
    (f_H is the rubbing spool)."""
    dt = 1e-4
    t = np.arange(10_000) * dt  # 1 s: df = 1 Hz
    tones = (80.0, 333.0, 440.0, 560.0, 650.0)
    x = sum(np.cos(2 * np.pi * f * t + k) for k, f in enumerate(tones))
    fit = fit_peaks(t, x, F_L, F_H)
    assert [ln.labels[:2] for ln in fit.lines] == [("4f_H-4f_L", "5f_L-3f_H"), ("f_H+5f_L", "8f_H-4f_L"),
                                                    ("7f_H-f_L", "8f_L"), ("8f_H-f_L", "f_H+8f_L")]
    assert [p.frequency_hz for p in fit.unlabelled] == [333.0]  # off the 10 Hz grid
    assert [p.frequency_hz for p in fit_peaks(t, x, F_L, F_H, max_m=0).unlabelled] == [80.0, 333.0, 440.0, 650.0]
    with pytest.raises(InputError, match=r"^f_H = nan: must be a finite number > 0 \(Hz\)$"):
        fit_peaks(t, x, F_L, float("nan"))
    with pytest.raises(InputError, match=r"^max_m = -1: must be an integer >= 0$"):
        fit_peaks(t, x, F_L, F_H, max_m=-1)


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
    fit = fit_peaks(np.arange(x.size) * dt, x, F_L, F_H, spectrum=s)
    by_freq = {line.frequency_hz: line for line in fit.lines}
    assert len(fit.lines) == len(freqs) - 1  # no spurious lines, none missed
    for (m, n), f, a in zip(mns, freqs, amps):
        if f == 333.0:
            continue
        line = by_freq[f]
        assert (line.m, line.n) == (m, n) and line.label == line_label(m, n)
        assert line.amplitude * 1e6 == pytest.approx(a, rel=1e-11)  # exact on-bin; measured 7.8e-13
    assert {label for _, label in XU2016_TABLE1} <= {line.label for line in fit.lines}  # 520 Hz as corrected
    # The off-grid line is found but not labelled.
    at_bin = pytest.approx(1e-6 * amps[-1], rel=1e-13)  # the peak's bin value; measured 1e-14
    assert [(p.frequency_hz, p.amplitude) for p in fit.unlabelled] == [(333.0, at_bin)]


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


def test_half_integer_only_on_the_half_torus():
    x, dt, mns, freqs, _ = _synthetic(extra_hz=[F_H + 1.5 * F_L], seed=5)
    t = np.arange(x.size) * dt
    off = fit_peaks(t, x, F_L, F_H)
    assert [p.frequency_hz for p in off.unlabelled] == [195.0]
    on = fit_peaks(t, x, F_L, F_H, torus=(1, 2))
    assert on.unlabelled == ()
    line = next(ln for ln in on.lines if ln.frequency_hz == 195.0)
    assert line.label == "f_H+3f_L/2" and (line.m, line.n) == (1, Fraction(3, 2))
    # The half torus changes no other label (integer lines have integer n first).
    assert [ln.label for ln in on.lines if ln.frequency_hz != 195.0] == [ln.label for ln in off.lines]


def test_table_and_comparison_output():
    x, dt, *_ = _synthetic(extra_hz=[333.0])
    fit = fit_peaks(np.arange(x.size) * dt, x, F_L, F_H)
    text = format_table(fit)
    assert text.splitlines()[0].split(" | ") == ["Frequency (Hz)", "Component"]
    rows = [[cell.strip() for cell in row.split("|")] for row in text.splitlines()[2:]]
    assert ["20.00", "f_H-f_L"] in rows and ["333.00", UNLABELLED] in rows
    assert "Amplitude (µm)" in format_table(fit, amplitude_scale=1e6)
    matches = compare_with_expected(fit.lines, XU2016_TABLE1)
    assert len(matches) == 24
    assert all(mt.found is not None and mt.label_agrees for mt in matches)
    assert [mt.found_hz for mt in matches][:2] == [20.0, 110.0]
    # The label as printed at 520 Hz does not agree; a missing line is reported.
    bad = compare_with_expected(fit.lines, [(520.0, "5f_H+2f_L"), 600.5])
    assert bad[0].label_agrees is False
    assert bad[1].found is None and bad[1].label_agrees is None
    table = format_comparison(bad)
    assert "NO" in table and "not found" in table
    with pytest.raises(InputError, match="^label = 'nonsense': must look like"):
        compare_with_expected(fit.lines, [(20.0, "nonsense")])
    with pytest.raises(InputError, match=r"^expected\[1\] = -5\.0: must be > 0 \(Hz\)$"):
        compare_with_expected(fit.lines, [20.0, -5.0])


def test_labels_on_flattop_fallback_for_incommensurate_speeds():
    """The paper's read-off speeds 69.58/90.33 Hz have no common period: the spectrum falls
    back to the flat-top window, its peaks lie within half a bin of the true frequencies, so
    each proposes its line, fitted at its exact frequency."""
    f_L, f_H, dt = 69.58, 90.33, 1e-4
    t = np.arange(20_000) * dt  # 2 s: df = 0.5 Hz, lines >= 20 Hz = 40 bins apart
    combos = [(0, 1, 0.3), (1, 0, 1.0), (1, -1, 0.05), (2, -1, 0.1), (3, -2, 0.04), (2, 1, 0.08)]
    x = sum(a * np.cos(2 * np.pi * (m * f_H + n * f_L) * t + m) for m, n, a in combos)
    s = settled_spectrum(x, dt, f_L, f_H)
    assert s.window == "flattop"
    fit = fit_peaks(t, x, f_L, f_H, spectrum=s)
    ordered = sorted(combos, key=lambda c: c[0] * f_H + c[1] * f_L)
    assert [(ln.m, ln.n) for ln in fit.lines] == [(m, n) for m, n, _ in ordered] and fit.unlabelled == ()
    for ln, (m, n, a) in zip(fit.lines, ordered):
        assert ln.frequency_hz == m * f_H + n * f_L
        assert ln.amplitude == pytest.approx(a, rel=3e-14)  # every line fitted: measured 3.1e-15
