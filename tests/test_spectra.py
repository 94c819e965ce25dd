"""Amplitude spectra: exact on-bin amplitudes, stated window errors, plan reuse, record length."""

import math
import re

import numpy as np
import pytest

from rotorred.checks import InputError
from rotorred.signals import spectra
from rotorred.signals.spectra import (
    WINDOWS,
    NotCommensurateError,
    amplitude_spectrum,
    commensurate_record,
    plan_cache_info,
    rfft_plan,
    settled_spectrum,
)


def _dtft_window_gain(w, delta):
    """|W(delta)| / W(0) of a window by direct summation (independent of any FFT)."""
    j = np.arange(w.size)
    return abs(np.sum(w * np.exp(-2j * np.pi * delta * j / w.size))) / w.sum()


# --------------------------------------------------------------------------- amplitudes
@pytest.mark.parametrize("n", [4096, 1001])  # even and odd length
def test_rectangular_on_bin_amplitudes_exact(n):
    """a cos(2 pi k df t + phase) reads a on bin k; DC reads the offset; Nyquist reads a."""
    dt = 1e-4
    t = np.arange(n) * dt
    df = 1.0 / (n * dt)
    rng = np.random.default_rng(1)
    bins = [1, 7, 123, n // 2 - 1]
    amps = rng.uniform(0.1, 2.0, len(bins))
    phases = rng.uniform(0, 2 * np.pi, len(bins))
    offset = 0.37
    x = offset + sum(a * np.cos(2 * np.pi * k * df * t + p) for a, k, p in zip(amps, bins, phases))
    s = amplitude_spectrum(x, dt)
    assert s.window == "rectangular" and s.n_samples == n
    assert s.df == pytest.approx(df, rel=1e-15)
    assert s.frequencies.shape == (n // 2 + 1,)
    # 1e-12 relative: the FFT's rounding error is ~ eps * log2(n) * sum|a| ~ 1e-14 here.
    np.testing.assert_allclose(s.amplitudes[bins], amps, rtol=1e-12)
    assert s.amplitudes[0] == pytest.approx(offset, rel=1e-12)
    # No leakage: every other bin is at rounding level (1e-12 of the largest amplitude).
    others = np.delete(s.amplitudes, bins + [0])
    assert others.max() < 1e-12 * amps.max()
    if n % 2 == 0:  # a cos(pi j) at Nyquist reads a (single-sided factor 1 there)
        s_nyq = amplitude_spectrum(0.8 * np.cos(np.pi * np.arange(n)), dt)
        assert s_nyq.amplitudes[-1] == pytest.approx(0.8, rel=1e-12)


def test_float32_input_and_um_conversion():
    n, dt = 2000, 1e-3
    t = np.arange(n) * dt
    x = (5e-6 * np.cos(2 * np.pi * 50.0 * t)).astype(np.float32)  # bin 100
    s = amplitude_spectrum(x, dt)
    # float32 rounding: relative error ~ 1e-7 * log2(n); 1e-5 is a loose but failing bound.
    assert s.amplitudes_um[100] == pytest.approx(5.0, rel=1e-5)
    assert s.amplitude_at(50.0) == pytest.approx(5e-6, rel=1e-5)


def test_stated_window_errors_are_the_closed_forms():
    """The stated half-bin losses are the closed forms of Harris (1978): the rectangular
    kernel |sinc(1/2)| = 2/pi, the Hann kernel sinc(1/2) / (1 - 1/4) = 8/(3 pi); computed
    here by direct summation of the window (no FFT)."""
    n = 4096
    for name, closed in [("rectangular", 2 / np.pi), ("hann", 8 / (3 * np.pi))]:
        gain = _dtft_window_gain(spectra.window_values(name, n), 0.5)
        # Finite n: the sampled kernel differs from the continuous one by O(1/n^2) ~ 1e-7.
        assert gain == pytest.approx(closed, rel=1e-6)
        assert WINDOWS[name].max_scalloping_db == pytest.approx(-20 * np.log10(closed), rel=1e-12)
    assert WINDOWS["flattop"].max_scalloping_db < 0.02  # brief: flat-top < 0.02 dB


@pytest.mark.parametrize("name", ["rectangular", "hann", "flattop"])
def test_off_bin_amplitude_error_within_stated_bound(name):
    """A tone between bins reads within the window's stated dB error at its peak bin, and
    the worst offset (half a bin) uses most of the bound (so the bound is not loose)."""
    n, dt = 8192, 1e-4
    t = np.arange(n) * dt
    df = 1.0 / (n * dt)
    a = 1.7
    bound = WINDOWS[name].max_scalloping_db
    # Slack for the negative-frequency image and the other sidelobes at ~1000 bins: the
    # rectangular kernel's 1/(pi 2000) = 1.6e-4 relative there (1.4e-3 dB); Hann's and
    # HFT95's fall as 1/k^3 and faster, < 1e-8. Worst case used for all: 1.5e-3 dB.
    slack = 20 * np.log10(1 + 1.0 / (np.pi * 2000)) + 1e-6
    worst = 0.0
    for delta in np.linspace(0.0, 0.5, 11):
        f = (1000 + delta) * df
        s = amplitude_spectrum(a * np.cos(2 * np.pi * f * t + 0.3), dt, window=name)
        peak = s.amplitudes[1000:1002].max()
        err_db = 20 * np.log10(peak / a)
        assert abs(err_db) <= bound + slack, (name, delta, err_db)
        worst = max(worst, abs(err_db))
    # The bound is attained (within 10 %) at some offset: it is the window's real error.
    assert worst >= 0.9 * bound - slack
    # On-bin: exact for every window (the window kernel is 1 at offset 0, zero at other
    # bins for the cosine-sum windows; image at 2000 bins: rounding level).
    s = amplitude_spectrum(a * np.cos(2 * np.pi * 1000 * df * t + 0.3), dt, window=name)
    assert s.amplitudes[1000] == pytest.approx(a, rel=1e-9)


def test_bad_inputs():
    with pytest.raises(InputError, match=r"^dt = -1\.0: must be > 0 \(s\)$"):
        amplitude_spectrum(np.ones(8), -1.0)
    with pytest.raises(InputError, match=r"^dt = nan: must be a finite number > 0 \(s\)$"):
        amplitude_spectrum(np.ones(8), float("nan"))
    with pytest.raises(InputError, match=r"^window = 'kaiser': must be one of 'rectangular', 'hann', 'flattop'$"):
        amplitude_spectrum(np.ones(8), 1e-3, window="kaiser")
    with pytest.raises(InputError, match=r"^x = array of shape \(3,\): must hold finite numbers only$"):
        amplitude_spectrum(np.array([1.0, np.nan, 2.0]), 1e-3)
    with pytest.raises(InputError, match=r"^x = array of shape \(8,\): must be an array of real numbers$"):
        amplitude_spectrum(np.ones(8) * 1j, 1e-3)
    with pytest.raises(InputError, match=r"^x = array of shape \(2, 8\): must be a 1-D array of at least 2 values$"):
        amplitude_spectrum(np.ones((2, 8)), 1e-3)
    with pytest.raises(InputError, match=r"^x = array of shape \(1,\): must be a 1-D array of at least 2 values$"):
        amplitude_spectrum(np.ones(1), 1e-3)


# --------------------------------------------------------------------------- plan reuse
def test_plans_are_cached_and_reused():
    """The same (length, dtype) returns the same FFTW object; a different length or dtype
    builds a new one; spectra of the same length hit the cache."""
    p1 = rfft_plan(3000, np.float64)
    assert rfft_plan(3000, np.float64) is p1
    assert rfft_plan(3000, np.float32) is not p1
    assert rfft_plan(3001, np.float64) is not p1
    before = plan_cache_info()
    x = np.random.default_rng(0).standard_normal(3000)
    s1 = amplitude_spectrum(x, 1e-3)
    s2 = amplitude_spectrum(2 * x, 1e-3)
    after = plan_cache_info()
    assert after.misses == before.misses  # no new plan was built
    assert after.hits == before.hits + 2
    assert rfft_plan(3000, np.float64) is p1
    # The result is a copy, not the plan's output buffer (reused by the next call).
    np.testing.assert_allclose(s2.amplitudes, 2 * s1.amplitudes, rtol=1e-12, atol=1e-12)
    # And it agrees with numpy's FFT (an independent implementation).
    ref = np.abs(np.fft.rfft(x)) * 2 / x.size
    ref[0] /= 2
    ref[-1] /= 2
    np.testing.assert_allclose(s1.amplitudes, ref, rtol=1e-12, atol=1e-14)


# --------------------------------------------------------------------------- record length
def test_record_length_70_90_hz():
    rec = commensurate_record(70.0, 90.0, 1e-5)
    assert rec.ratio == (9, 7)
    assert rec.fundamental_hz == pytest.approx(10.0, rel=1e-15)
    assert rec.period == pytest.approx(0.1, rel=1e-15)
    assert rec.samples_per_period == 10000 and rec.n_samples == 10000
    # Largest whole number of periods in an available record; speeds given as Omega/(2 pi).
    f_L = (2 * np.pi * 70.0) / (2 * np.pi)
    f_H = (2 * np.pi * 90.0) / (2 * np.pi)
    rec = commensurate_record(f_L, f_H, 1e-5, n_available=123_456)
    assert rec.n_periods == 12 and rec.n_samples == 120_000
    assert rec.n_samples * 1e-5 == pytest.approx(12 * 0.1, rel=1e-12)
    assert rec.df == pytest.approx(10.0 / 12)
    assert commensurate_record(70, 90, 1e-5, n_periods=3).n_samples == 30000
    # Equal spools: T = 1 / f.
    assert commensurate_record(50.0, 50.0, 1e-3).samples_per_period == 20


def test_record_length_bad_inputs():
    with pytest.raises(NotCommensurateError, match="^n_available = 9999: must hold at least one common period"):
        commensurate_record(70, 90, 1e-5, n_available=9999)  # a window must be used: settled_spectrum falls back
    cases = [
        (dict(f_L=70, f_H=90, dt=-1e-5), "dt = -1e-05: must be > 0 (s)"),
        (dict(f_L=70, f_H=90, dt=0.0), "dt = 0.0: must be > 0 (s)"),
        (dict(f_L=float("nan"), f_H=90, dt=1e-5), "f_L = nan: must be a finite number > 0 (Hz)"),
        (dict(f_L=70, f_H=float("inf"), dt=1e-5), "f_H = inf: must be a finite number > 0 (Hz)"),
        (dict(f_L=-70, f_H=90, dt=1e-5), "f_L = -70: must be > 0 (Hz)"),
        (dict(f_L=70, f_H=90, dt=1e-5, n_available=9999),
         "n_available = 9999: must hold at least one common period T = 0.1 s = 10000 samples"),
        (dict(f_L=70, f_H=90, dt=1e-5, n_available=20000, n_periods=3),
         "n_periods = 3: must fit in n_available = 20000 samples: at most 2 periods of 10000 samples"),
        (dict(f_L=70, f_H=90, dt=1e-5, n_periods=0), "n_periods = 0: must be an integer >= 1"),
        (dict(f_L=70, f_H=90, dt=1e-5, rtol=0.5), "rtol = 0.5: must lie in (0, 0.01)"),
    ]
    for kwargs, message in cases:
        with pytest.raises(InputError, match="^" + re.escape(message) + "$"):
            commensurate_record(**kwargs)
    # Not commensurate (the paper's read-off 69.58 / 90.33 Hz) and T/dt not whole.
    with pytest.raises(NotCommensurateError, match=r"^f_H = 90\.33: must be commensurate with f_L = 69\.58 Hz"):
        commensurate_record(69.58, 90.33, 1e-5)
    with pytest.raises(NotCommensurateError, match=r"^f_H = 98\.99.*: must be commensurate with f_L = 70\.0 Hz"):
        commensurate_record(70.0, 70.0 * math.sqrt(2), 1e-5)
    with pytest.raises(NotCommensurateError, match=r"^dt = 3e-05: must divide the common period T = 0\.1 s into a "
                                                  r"whole number of samples \(T/dt = 3333\.3"):
        commensurate_record(70.0, 90.0, 3e-5)  # 0.1 / 3e-5 = 3333.33


def test_settled_spectrum_exact_and_fallback():
    dt = 1e-5
    t = np.arange(25_000) * dt  # 2.5 periods of 0.1 s
    amps = {(0, 1): 3.0, (1, 0): 60.0, (2, -1): 0.7, (1, 1): 2.0}
    x = 1e-6 * sum(
        a * np.cos(2 * np.pi * (m * 90.0 + n * 70.0) * t + m - n) for (m, n), a in amps.items()
    )
    s = settled_spectrum(x, dt, 70.0, 90.0)
    assert s.window == "rectangular" and s.n_samples == 20_000  # the last 2 periods
    assert "9/7" in s.note
    for (m, n), a in amps.items():
        assert s.amplitude_at(m * 90.0 + n * 70.0) * 1e6 == pytest.approx(a, rel=1e-12)
    # Incommensurate: flat-top over the whole record, amplitudes within its stated error
    # plus the sidelobe slack (HFT95 sidelobes < -95 dB = 1.8e-5 relative, per line).
    f_L, f_H = 69.58, 90.33
    y = 1e-6 * (3.0 * np.cos(2 * np.pi * f_L * t) + 60.0 * np.cos(2 * np.pi * f_H * t))
    s = settled_spectrum(y, dt, f_L, f_H)
    assert s.window == "flattop" and s.n_samples == t.size
    assert "f_H = 90.33: must be commensurate with f_L = 69.58 Hz" in s.note
    for f, a in [(f_L, 3.0), (f_H, 60.0)]:
        k = int(round(f / s.df))
        peak = s.amplitudes_um[k - 1 : k + 2].max()
        # Other line (20 Hz = 50 bins away) leaks < 60 * 1.8e-5 µm into the 3 µm line.
        assert abs(20 * np.log10(peak / a)) <= 0.0045 + 20 * np.log10(1 + 60 / a * 1.8e-5)
    with pytest.raises(InputError, match=r"^f_L = -1\.0: must be > 0 \(Hz\)$"):  # bad input is not a fallback
        settled_spectrum(y, dt, -1.0, f_H)


def test_spectra_never_write_into_the_callers_records():
    """Regression: a cached pyFFTW plan must not adopt a caller's array as its input buffer
    (a later call on another, misaligned record would then overwrite the first one)."""
    from rotorred.signals.spectra import settled_spectrum

    rng = np.random.default_rng(1)
    dt = 1e-4
    records = rng.standard_normal((6, 3001))
    kept = records.copy()
    for row in records:  # rows of a C array: alternately aligned and misaligned views
        settled_spectrum(row, dt, 70.0, 90.0)
    np.testing.assert_array_equal(records, kept)
