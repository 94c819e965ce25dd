"""Line fit at known frequencies: exact labels and amplitudes, standard errors, noise floor, merging, cost."""

import functools
import math
import time
from fractions import Fraction

import numpy as np
import pytest
from scipy.signal import butter, lfilter

from rotorred.checks import InputError
from rotorred.signals import linefit
from rotorred.signals.linefit import FitOptions, fit_frequencies, fit_lines, fit_peaks
from rotorred.signals.lines import line_label
from rotorred.signals.spectra import settled_spectrum

F_L = 70.0
F_H = 70.0 * math.sqrt(2.0)  # not commensurate with F_L
DT = 1e-4  # 10 kHz
N = 10_000  # T = 1 s: lines closer than 2/T = 2 Hz merge


def _frequency(m: Fraction, n: Fraction, f_L=F_L, f_H=F_H) -> float:
    return float(m) * f_H + float(n) * f_L


@functools.lru_cache(maxsize=1)
def _pool():
    """Combinations on the torus (f_H/3, f_L) that are the unique lowest-order one within 3 Hz.

    The label a fit gives a line is its lowest-order combination within the resolution; a line
    that is the unique lowest order within 3 Hz (> 2/T) has one right label.
    """
    combos = [(Fraction(a, 3), Fraction(b)) for a in range(-24, 25) for b in range(-8, 9)]
    combos = [(m, n, _frequency(m, n)) for m, n in combos if 0 < _frequency(m, n) < 4000]
    pool = []
    for m, n, f in combos:
        order = abs(m) + abs(n)
        if order > 5 or not 10.0 < f < 1000.0:
            continue
        rivals = [1 for m2, n2, f2 in combos if (m2, n2) != (m, n) and abs(f2 - f) < 3.0
                  and abs(m2) + abs(n2) <= order]
        if not rivals:
            pool.append((m, n, f))
    return pool


def _thirty_lines(seed=0):
    """30 lines of the pool, >= 3 Hz apart, 10 of them with fractional m; random amplitudes, phases."""
    rng = np.random.default_rng(seed)
    pool = _pool()
    fractional = [c for c in pool if c[0].denominator == 3]
    whole = [c for c in pool if c[0].denominator == 1]
    chosen = []
    for group, count in ((fractional, 10), (whole, 20)):
        for i in rng.permutation(len(group)):
            if len([c for c in chosen if c in group]) == count:
                break
            if all(abs(group[i][2] - c[2]) >= 3.0 for c in chosen):
                chosen.append(group[i])
    assert len(chosen) == 30
    amplitudes = rng.uniform(0.1, 1.0, 30)
    phases = rng.uniform(-np.pi, np.pi, 30)
    return chosen, amplitudes, phases


def _signal(t, chosen, amplitudes, phases):
    return sum(a * np.cos(2 * np.pi * f * t + p) for (_, _, f), a, p in zip(chosen, amplitudes, phases))


@pytest.fixture(scope="module")
def exact():
    t = np.arange(N) * DT
    chosen, amplitudes, phases = _thirty_lines()
    x = 0.3 + _signal(t, chosen, amplitudes, phases)
    return t, x, chosen, amplitudes, phases, fit_lines(t, x, F_L, F_H)


def _by_order(fit):
    return {ln.orders[0]: ln for ln in fit.lines}


# --------------------------------------------------------------------------- exact
def test_exact_labels_orders_and_torus(exact):
    t, x, chosen, *_ , fit = exact
    assert (fit.torus.k, fit.torus.j) == (3, 1)  # found, not given
    assert set(_by_order(fit)) == {(m, n) for m, n, _ in chosen}  # every label right, no other line
    for ln in fit.lines:
        assert all(isinstance(o, Fraction) for pair in ln.orders for o in pair)
        assert ln.frequency_hz == _frequency(ln.m, ln.n)  # exact by construction
    assert fit.mean == pytest.approx(0.3, abs=1e-12)


def test_exact_amplitudes_and_phases(exact):
    t, x, chosen, amplitudes, phases, fit = exact
    lines = _by_order(fit)
    amp_err = max(abs(lines[(m, n)].amplitude / a - 1) for (m, n, _), a in zip(chosen, amplitudes))
    phase_err = max(abs(np.angle(np.exp(1j * (lines[(m, n)].phase - p)))) for (m, n, _), p in zip(chosen, phases))
    print(f"exact: amplitude error {amp_err:.2e} relative, phase error {phase_err:.2e} rad, "
          f"unexplained {1.0 - fit.explained_share:.1e}")
    # The issue asks for 1e-9; measured 1.0e-13 and 6.4e-14 rad (round-off of frequencies times
    # t ~ 1 s and of a Cholesky solve with cond <= 3): asserted at 10x the measured error.
    assert amp_err < 1e-12 and phase_err < 1e-12
    assert 1.0 - fit.explained_share < 1e-15  # residual at round-off (measured 0 to 1e-16)
    assert sum(ln.share for ln in fit.lines) == pytest.approx(fit.explained_share, abs=0.02)


def test_exact_fit_is_the_least_squares_solution_of_the_design_matrix():
    """The closed-form normal equations equal numpy's lstsq on the explicit design matrix."""
    n, dt = 3000, 1e-3  # T = 3 s, resolution 2/T = 0.67 Hz
    t = 0.25 + np.arange(n) * dt  # a record that does not start at 0
    freqs = np.array([0.7, 1.5, 12.3, 13.0, 97.1, 499.2])  # down to 2/T from 0, from each other, from Nyquist
    x = np.random.default_rng(3).normal(size=n)
    fit = fit_frequencies(t, x, freqs)
    A = np.column_stack([np.ones(n), np.cos(2 * np.pi * np.outer(t, freqs)), np.sin(2 * np.pi * np.outer(t, freqs))])
    coef, *_ = np.linalg.lstsq(A, x, rcond=None)
    z = coef[1:7] - 1j * coef[7:]
    err = np.max(np.abs(fit.coefficients - z)) / np.max(np.abs(z))
    print(f"normal equations vs lstsq: {err:.1e}")
    assert err < 3e-12 and fit.mean == pytest.approx(coef[0], abs=1e-12)  # measured 2.5e-13 (10x margin)
    # Large-sieve bound: separation >= 2/T gives cond <= 3 for the exponentials; with the columns
    # scaled to unit norm the measured condition is 1.5-2.
    An = A / np.linalg.norm(A, axis=0)
    cond = np.linalg.cond(An.T @ An)
    print(f"cond of the normalised Gram matrix: {cond:.3f}")
    assert cond <= 3.0


# --------------------------------------------------------------------------- noise
def test_noise_40dB_amplitude_errors_within_three_standard_errors():
    t = np.arange(N) * DT
    chosen, amplitudes, phases = _thirty_lines()
    clean = _signal(t, chosen, amplitudes, phases)
    sigma = math.sqrt(np.mean(clean ** 2) / 1e4)  # SNR 40 dB
    x = clean + np.random.default_rng(7).normal(0.0, sigma, N)
    fit = fit_lines(t, x, F_L, F_H)
    lines = _by_order(fit)
    assert set(lines) == {(m, n) for m, n, _ in chosen} and (fit.torus.k, fit.torus.j) == (3, 1)
    ratios = np.array([(lines[(m, n)].amplitude - a) / lines[(m, n)].standard_error
                       for (m, n, _), a in zip(chosen, amplitudes)])
    print(f"40 dB: |error| / SE max {np.max(np.abs(ratios)):.2f}, mean square {np.mean(ratios ** 2):.2f}")
    assert np.all(np.abs(ratios) <= 3.0)
    # The standard errors are right, not merely large: (error / SE)^2 averages about 1 (0.4-2
    # holds for 30 chi-square(1) values with probability > 0.99), and SE is near sigma sqrt(2/N).
    assert 0.4 < np.mean(ratios ** 2) < 2.0
    se = np.array([ln.standard_error for ln in fit.lines])
    assert np.all(np.abs(se / (sigma * math.sqrt(2.0 / N)) - 1.0) < 0.3)


def test_pure_noise_has_no_labelled_line():
    t = np.arange(N) * DT
    fit = fit_lines(t, np.random.default_rng(11).normal(size=N), F_L, F_H)
    assert fit.lines == () and fit.unlabelled == ()
    assert abs(fit.explained_share) < 1e-12 and (fit.torus.k, fit.torus.j) == (1, 1)


def test_coloured_noise_is_not_explained_by_packing_lines():
    """Low-pass noise (a broadband response): without the local noise level, 100 lines would
    'explain' 40 % of it (measured); with it, at most a chance line or two survive."""
    t = np.arange(N) * DT
    b, a = butter(4, 400.0 * 2 * DT)
    x = lfilter(b, a, np.random.default_rng(0).normal(size=N))
    fit = fit_lines(t, x, F_L, F_H)
    print(f"coloured noise: {len(fit.lines)} lines, explained {fit.explained_share:.4f}")
    assert len(fit.lines) <= 2 and fit.explained_share < 0.05


def test_lines_are_never_closer_than_the_resolution(exact):
    fit = exact[-1]
    f = np.sort(fit.frequencies_hz)
    assert fit.resolution_hz == pytest.approx(2.0 / (N * DT))
    assert np.min(np.diff(f)) >= fit.resolution_hz and f[0] >= fit.resolution_hz
    cells = (0.5 / DT - 2 * fit.resolution_hz) / fit.resolution_hz
    assert fit.n_candidates <= linefit.FILL * cells


# --------------------------------------------------------------------------- FFT and merging
def test_commensurate_whole_periods_equal_fft_on_bin_amplitudes():
    f_L, f_H, dt = 70.0, 90.0, 1e-4
    t = np.arange(5000) * dt  # 5 common periods of 0.1 s
    rng = np.random.default_rng(5)
    orders = [(1, 0), (0, 1), (1, -1), (2, -1), (3, -2), (2, 0), (1, 1), (3, -1), (0, 2), (4, -1), (5, 1), (2, 2)]
    amplitudes = rng.uniform(0.1, 1.0, len(orders))
    x = sum(a * np.cos(2 * np.pi * (m * f_H + n * f_L) * t + p)
            for (m, n), a, p in zip(orders, amplitudes, rng.uniform(-np.pi, np.pi, len(orders))))
    fit = fit_lines(t, x, f_L, f_H)
    spectrum = settled_spectrum(x, dt, f_L, f_H)
    assert spectrum.window == "rectangular"
    rel = max(abs(ln.amplitude / spectrum.amplitude_at(ln.frequency_hz) - 1) for ln in fit.lines)
    print(f"fit vs FFT on-bin: {rel:.1e}")
    assert len(fit.lines) == len(orders) and rel < 1e-13  # issue: 1e-6; measured 1.1e-14 (10x margin)
    assert fit.torus.bases == (10.0,) and fit.torus.ratio == Fraction(9, 7)
    # Every label of a line on the 10 Hz grid is carried, first the lowest order (lines.py's rule).
    line_140 = next(ln for ln in fit.lines if ln.frequency_hz == 140.0)
    assert line_140.label == "2f_L" and "9f_H-9f_L" not in line_140.labels  # |m| <= 8
    assert len(line_140.labels) > 1


def test_candidates_closer_than_the_resolution_merge_into_one_line_with_both_labels():
    f_L, f_H = 70.0, 70.8  # 0.8 Hz apart
    rng = np.random.default_rng(2)
    for T, expected in ((1.0, 1), (4.0, 2)):  # 2/T = 2 Hz merges them; 0.5 Hz resolves them
        t = np.arange(int(T / DT)) * DT
        x = np.cos(2 * np.pi * f_L * t + 0.3) + 0.7 * np.cos(2 * np.pi * f_H * t - 1.0) + 1e-3 * rng.normal(size=t.size)
        fit = fit_lines(t, x, f_L, f_H, options=FitOptions(max_subharmonic=1))
        near = [ln for ln in fit.lines if abs(ln.frequency_hz - 70.4) < 1.0]
        assert len(near) == expected
        if expected == 1:
            assert near[0].labels[:2] == ("f_H", "f_L") and near[0].frequency_hz == f_H
        else:
            assert {ln.label for ln in near} == {"f_H", "f_L"}


# --------------------------------------------------------------------------- labels, inputs, cost
def test_fractional_orders_are_labelled_by_the_one_label_function():
    assert line_label(Fraction(1, 3), 0) == "f_H/3"
    assert line_label(Fraction(2, 3), -1) == "2f_H/3-f_L"
    assert line_label(-1, Fraction(4, 3)) == "4f_L/3-f_H"
    line = linefit.FittedLine(100.0, 1.0, 0.0, 0.1, 0.1, 0.5, ((Fraction(2, 3), Fraction(-1)), (Fraction(0), 2)))
    assert line.label == "2f_H/3-f_L" and line.labels == ("2f_H/3-f_L", "2f_L")


# --------------------------------------------------------------------------- FFT peaks as candidates
def _known_lines(t, f_L, f_H, orders, seed):
    rng = np.random.default_rng(seed)
    amplitudes = rng.uniform(0.1, 1.0, len(orders))
    x = sum(a * np.cos(2 * np.pi * (m * f_H + n * f_L) * t + p)
            for (m, n), a, p in zip(orders, amplitudes, rng.uniform(-np.pi, np.pi, len(orders))))
    return x, dict(zip(orders, amplitudes))


@pytest.mark.parametrize("f_H", [90.0, 70.0 * math.sqrt(2.0)])
def test_fft_peaks_feed_the_fit_two_paths_one_answer(f_H):
    """The lines proposed by the FFT's peaks and fitted (fit_peaks) are those fit_lines finds, with the same labels,
    frequencies and amplitudes, and both recover the known lines of a sum of sinusoids at m f_H + n f_L: at 70/90 Hz
    (commensurate, rectangular spectrum on bins) and 70/99 Hz (not commensurate: flat-top spectrum)."""
    f_L, dt = 70.0, 1e-4
    t = np.arange(6000) * dt  # 0.6 s: 6 common periods of 70/90 Hz
    orders = [(1, 0), (0, 1), (1, -1), (2, -1), (3, -2), (2, 0), (1, 1), (0, 2), (2, 1)]
    x, truth = _known_lines(t, f_L, f_H, orders, 3)
    peaks, full = fit_peaks(t, x, f_L, f_H), fit_lines(t, x, f_L, f_H, options=FitOptions(max_subharmonic=1))
    assert peaks.unlabelled == () and len(peaks.lines) == len(full.lines) == len(orders)
    for a, b in zip(peaks.lines, full.lines):
        m, n = a.orders[0]
        assert a.label == b.label == line_label(m, n) and a.frequency_hz == b.frequency_hz == m * f_H + n * f_L
        # the same least squares on the same samples: identical; against the truth measured 8.7e-15 (70/90 Hz) and
        # 4.4e-15 (70/99 Hz)
        assert a.amplitude == b.amplitude and a.phase == b.phase
        assert a.amplitude == pytest.approx(truth[(int(m), int(n))], rel=1e-13)
    assert peaks.explained_share == pytest.approx(1.0, abs=1e-12)


def test_fft_peaks_choose_the_lines_and_keep_the_unexplained_peaks():
    """Lines below the threshold are not fitted; a tone at no combination is an unlabelled peak at its bin; a
    half-integer multiple of f_L is labelled on the torus (1, 2) (the paper's experiment, f_H + 3f_L/2)."""
    f_L, f_H, dt = 70.0, 90.0, 1e-4
    t = np.arange(6000) * dt
    x = np.cos(2 * np.pi * 90.0 * t) + 0.3 * np.cos(2 * np.pi * 20.0 * t) + 0.001 * np.cos(2 * np.pi * 160.0 * t) \
        + 0.05 * np.cos(2 * np.pi * 195.0 * t)
    fit = fit_peaks(t, x, f_L, f_H)
    assert [ln.label for ln in fit.lines] == ["f_H-f_L", "f_H"]
    assert fit.lines[0].amplitude == pytest.approx(0.3, rel=1e-14)
    assert [(p.frequency_hz, round(p.amplitude, 12)) for p in fit.unlabelled] == [(195.0, 0.05)]
    half = fit_peaks(t, x, f_L, f_H, torus=(1, 2))
    assert [ln.label for ln in half.lines] == ["f_H-f_L", "f_H", "f_H+3f_L/2"] and half.unlabelled == ()
    assert half.lines[-1].amplitude == pytest.approx(0.05, rel=1e-13)  # measured 6e-15; 0.3: 4e-16
    low = fit_peaks(t, x, f_L, f_H, threshold=1e-4)
    assert "f_H+f_L" in [ln.label for ln in low.lines]  # 160 Hz at 0.1 %
    with pytest.raises(InputError, match="^spectrum = .*: must be a Spectrum of the last samples of x"):
        fit_peaks(t[:100], x[:100], f_L, f_H, spectrum=settled_spectrum(x, dt, f_L, f_H))
    silent = fit_peaks(t, np.zeros_like(t), f_L, f_H)
    assert silent.lines == () and silent.unlabelled == ()


def test_inputs_are_refused_with_the_one_message_form():
    t = np.arange(100) * 1e-3
    with pytest.raises(InputError, match=r"^f_L = -1.0: must be > 0 \(Hz\)$"):
        fit_lines(t, np.sin(t), -1.0, 2.0)
    with pytest.raises(InputError, match="must be uniformly sampled"):
        fit_lines(t ** 1.5, np.sin(t), 1.0, 2.0)
    with pytest.raises(InputError, match="must not be constant"):
        fit_lines(t, np.ones(100), 10.0, 20.0)
    with pytest.raises(InputError, match="torus"):
        fit_lines(t, np.sin(50 * t), 10.0, 20.0, options=FitOptions(torus=(0, 1)))


@pytest.mark.parametrize("n", [10_000, 100_000])
def test_cost(n):
    """Recorded timings (2-core VM): ~0.2 s for 1e4 and ~0.4 s for 1e5 samples with the torus search."""
    t = np.arange(n) * DT
    chosen, amplitudes, phases = _thirty_lines()
    x = _signal(t, chosen, amplitudes, phases) + np.random.default_rng(1).normal(0, 0.01, n)
    start = time.perf_counter()
    fit = fit_lines(t, x, F_L, F_H)
    elapsed = time.perf_counter() - start
    print(f"fit_lines N={n}: {elapsed:.3f} s, {len(fit.lines)} lines, tori {[(r.k, r.j) for r in fit.trials]}")
    assert (fit.torus.k, fit.torus.j) == (3, 1) and elapsed < 10.0  # generous: a loaded CI machine
