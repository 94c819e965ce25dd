"""Single-sided amplitude spectra of response signals, computed with pyFFTW (or numpy.fft without it).

The spectrum of a real record ``x[j] = x(j dt)``, ``j = 0 .. N-1``, windowed by ``w``, is
read as an amplitude spectrum: a sinusoid ``a cos(2 pi f t + phase)`` whose frequency ``f``
lies on a bin (``f = k df``, ``df = 1 / (N dt)``, ``0 < k < N/2``) reads ``a`` at bin ``k``,
in the signal's own units::

    A_k = 2 |X_k| / sum(w),  0 < k < N/2 ;   A_0 = |X_0| / sum(w) ;   A_{N/2} = |X_{N/2}| / sum(w)

with ``X = rfft(w x)``. A tone between two bins reads less than ``a`` at the nearest bin by
the window's *scalloping loss*. The error is stated for every window in :data:`WINDOWS`:

============  ========================  =================================================
window        on-bin tone               worst off-bin tone (half a bin)
============  ========================  =================================================
rectangular   exact (no leakage)        -3.92 dB  (20 log10(2/pi))
hann          exact                     -1.42 dB  (20 log10(8/(3 pi)))
flattop       exact                     within +-0.0045 dB  (Heinzel's HFT95, 0.0044 dB)
============  ========================  =================================================

The default is the rectangular window on a record whose length is an integer number of the
common period of the two spools (:func:`commensurate_record`): the settled response of a
dual rotor at f_L and f_H is periodic with ``T = 1 / gcd(f_L, f_H)`` when f_H / f_L is
rational (70 and 90 Hz give 0.1 s), so every combination ``m f_H + n f_L`` then lies exactly
on a bin and the rectangular window reads it exactly, with no leakage. When the spool
frequencies are not commensurate, or ``T / dt`` is not an integer, :func:`settled_spectrum`
falls back to the flat-top window (amplitude within 0.0045 dB of the true value anywhere
between bins), and says so in :attr:`Spectrum.note`.

FFT plans are built once per ``(length, dtype)`` with :func:`pyfftw.builders.rfft` and kept
in an explicit cache (:func:`rfft_plan`, :func:`plan_cache_info`). The pyFFTW
``interfaces`` cache is not used: the builders objects are kept here directly, so plan
reuse is an identity that can be checked (``rfft_plan(n) is rfft_plan(n)``). Without pyFFTW
the plans are :class:`NumpyPlan` objects over :func:`numpy.fft.rfft`, with a one-line note on
stderr (:data:`NO_PYFFTW_NOTE`, a logging warning, once per process).

References
----------
.. [1] G. Heinzel, A. Ruediger, R. Schilling, "Spectrum and spectral density estimation by
   the Discrete Fourier transform (DFT), including a comprehensive list of window functions
   and some new flat-top windows", Max-Planck-Institut fuer Gravitationsphysik, 2002
   (flat-top window HFT95: flatness 0.0044 dB, sidelobes -95 dB).
.. [2] F. J. Harris, "On the use of windows for harmonic analysis with the discrete Fourier
   transform", Proc. IEEE 66(1), 1978 (scalloping loss, Table 1).
.. [3] Xu et al., "Dynamic Characteristics and Experimental Research of Dual-Rotor System with
   Rub-Impact Fault", Shock and Vibration 2016, 6239281 (Sec. 3, Table 1: combination
   frequencies of 70 and 90 Hz).
"""

from __future__ import annotations

import logging
import math
import threading
import textwrap
from dataclasses import dataclass, replace
from fractions import Fraction

import sys

import numpy as np

from rotorred import checks
from rotorred.results import Result


def _import_pyfftw():
    """pyFFTW's builders, or None when it is not installed (the spectra then use numpy.fft).

    ``import pyfftw`` also imports dask.array (1.2 s) when dask is installed, for an interface
    rotorred does not use; dask is hidden from it unless something has imported dask already.
    """
    hide = "dask" not in sys.modules
    if hide:
        sys.modules["dask"] = None  # `import dask` raises ImportError: pyfftw skips its dask interface
    try:
        import pyfftw
        import pyfftw.builders
    except ImportError:
        return None
    finally:
        if hide and sys.modules.get("dask", False) is None:
            del sys.modules["dask"]
    return pyfftw


pyfftw = _import_pyfftw()  # optional: the spectra fall back to numpy.fft (same values, slower for long records)

#: the one-line warning logged (once per process) when pyFFTW is missing
NO_PYFFTW_NOTE = ("pyFFTW is not installed; spectra use numpy.fft "
                  "(same results; `pip install pyfftw` for the faster FFT)")
_NOTED = []

__all__ = [
    "WINDOWS",
    "WindowInfo",
    "PlanCacheInfo",
    "Spectrum",
    "CommensurateRecord",
    "NotCommensurateError",
    "amplitude_spectrum",
    "commensurate_record",
    "settled_spectrum",
    "window_values",
    "rfft_plan",
    "rfft",
    "plan_cache_info",
    "plan_cache_clear",
]


# --------------------------------------------------------------------------- windows
@dataclass(frozen=True)
class WindowInfo:
    """A spectral window and its stated amplitude error.

    Attributes
    ----------
    name : str
    cosine_coefficients : tuple of float
        ``w[j] = sum_k c_k cos(2 pi k j / N)`` (periodic, "DFT-even" form), k = 0, 1, ...
    max_scalloping_db : float
        Largest amplitude error (dB, magnitude) of a single tone read at its nearest bin,
        over all offsets from a bin (0 .. half a bin), for a tone many bins from DC and
        from other tones. Zero error on-bin for every window. Rectangular and Hann: the
        closed-form half-bin losses 3.9224 and 1.4236 dB; flat-top: a bound above
        Heinzel's 0.0044 dB.
    description : str
    """

    name: str
    cosine_coefficients: tuple[float, ...]
    max_scalloping_db: float
    description: str


#: Windows offered by :func:`amplitude_spectrum`, with their stated amplitude error.
WINDOWS: dict[str, WindowInfo] = {
    "rectangular": WindowInfo(
        "rectangular",
        (1.0,),
        # 20 log10(|sinc(1/2)|) = 20 log10(2/pi) = -3.92 dB at half a bin [2].
        -20.0 * math.log10(2.0 / math.pi),
        "exact on-bin, no leakage for on-bin tones; -3.92 dB at half a bin",
    ),
    "hann": WindowInfo(
        "hann",
        (0.5, -0.5),
        # 20 log10(sinc(1/2) / (1 - 1/4)) = 20 log10(8 / (3 pi)) = -1.42 dB [2].
        20.0 * math.log10(3.0 * math.pi / 8.0),
        "scalloping loss up to 1.42 dB at half a bin",
    ),
    "flattop": WindowInfo(
        "flattop",
        # HFT95 [1]: flatness 0.0044 dB, NENBW 3.8112 bins, sidelobes -95 dB.
        (1.0, -1.9383379, 1.3045202, -0.4028270, 0.0350665),
        0.0045,
        "HFT95 flat-top: amplitude within 0.0045 dB anywhere between bins",
    ),
}


def window_values(name: str, n: int) -> np.ndarray:
    """Periodic (DFT-even) window of length ``n``.

    Parameters
    ----------
    name : {"rectangular", "hann", "flattop"}
    n : int
        Record length (samples), >= 1.

    Returns
    -------
    ndarray, shape (n,)
    """
    info = _window_info(name)
    n = checks.integer("n", n, ge=1)
    z = 2.0 * np.pi * np.arange(n) / n
    w = np.zeros(n)
    for k, c in enumerate(info.cosine_coefficients):
        w += c * np.cos(k * z)
    return w


def _window_info(name: str) -> WindowInfo:
    return WINDOWS[checks.choice("window", name, WINDOWS)]


# --------------------------------------------------------------------------- FFT plans
class NumpyPlan:
    """The interface of a ``pyfftw.FFTW`` rfft plan (``input_array``, ``output_array``, ``execute()``)
    computed with :func:`numpy.fft.rfft`: used when pyFFTW is not installed."""

    def __init__(self, shape: tuple, dtype):
        self.input_array = np.zeros(shape, dtype=dtype)
        ctype = np.complex64 if np.dtype(dtype) == np.float32 else np.complex128
        self.output_array = np.zeros((shape[0] // 2 + 1,) + tuple(shape[1:]), dtype=ctype)

    def execute(self):
        self.output_array[:] = np.fft.rfft(self.input_array, axis=0)

    __call__ = execute


def _new_plan(shape: tuple, dtype):
    """A pyFFTW plan along the first axis of arrays of ``shape``, or a :class:`NumpyPlan` with a one-line note on
    stderr (once) when pyFFTW is missing."""
    if pyfftw is None:
        if not _NOTED:
            _NOTED.append(True)
            logging.getLogger(__name__).warning(NO_PYFFTW_NOTE)
        return NumpyPlan(shape, dtype)
    a = pyfftw.empty_aligned(shape, dtype=dtype)
    return pyfftw.builders.rfft(a, axis=0, planner_effort="FFTW_ESTIMATE", threads=1, avoid_copy=False)


_PLAN_LOCK = threading.Lock()
_PLANS: dict[tuple[tuple, str], tuple[object, threading.Lock]] = {}
_PLAN_STATS = {"hits": 0, "misses": 0}


@dataclass(frozen=True)
class PlanCacheInfo:
    """Counters of the rfft plan cache (as :func:`functools.lru_cache` reports them)."""

    hits: int
    misses: int
    size: int


def rfft_plan(n: int, dtype=np.float64):
    """The cached pyFFTW real-to-complex plan for records of length ``n`` and ``dtype``.

    The first call for a ``(n, dtype)`` pair builds the plan (``FFTW_ESTIMATE``, one thread,
    aligned internal input array); later calls return the same object.

    Parameters
    ----------
    n : int
        Record length (samples), >= 1.
    dtype : {numpy.float64, numpy.float32}

    Returns
    -------
    pyfftw.FFTW (or NumpyPlan without pyFFTW)
        Fill ``plan.input_array``, call ``plan.execute()`` and copy ``plan.output_array``,
        shape (n // 2 + 1,), complex (as :func:`amplitude_spectrum` does).
    """
    checks.integer("n", n, ge=1)
    return _plan_entry((int(n),), dtype)[0]


def _plan_entry(shape: tuple, dtype) -> tuple[object, threading.Lock]:
    checks.choice("dtype", np.dtype(dtype).name, ("float64", "float32"))
    dtype = np.dtype(dtype)
    key = (shape, dtype.str)
    with _PLAN_LOCK:
        entry = _PLANS.get(key)
        if entry is not None:
            _PLAN_STATS["hits"] += 1
            return entry
        _PLAN_STATS["misses"] += 1
        entry = (_new_plan(shape, dtype), threading.Lock())
        _PLANS[key] = entry
        return entry


def plan_cache_info() -> PlanCacheInfo:
    """Hits, misses and size of the rfft plan cache."""
    with _PLAN_LOCK:
        return PlanCacheInfo(_PLAN_STATS["hits"], _PLAN_STATS["misses"], len(_PLANS))


def plan_cache_clear() -> None:
    """Forget every cached plan and reset the counters."""
    with _PLAN_LOCK:
        _PLANS.clear()
        _PLAN_STATS["hits"] = 0
        _PLAN_STATS["misses"] = 0


def rfft(x: np.ndarray) -> np.ndarray:
    """The real FFT of a 1-D record ``x`` (float64 or float32), or of each column of a 2-D one, on its cached plan
    (thread-safe), shape (len(x) // 2 + 1,) + x.shape[1:], complex, unnormalised (numpy's ``rfft`` convention)."""
    if x.ndim not in (1, 2) or len(x) < 1:
        checks.fail("x", f"an array of shape {x.shape}", "must be a record (n,) or records side by side (n, k), n >= 1")
    plan, lock = _plan_entry(x.shape, x.dtype)
    with lock:  # the plan owns its input/output arrays; one caller at a time
        # Copy into the plan's own aligned input: calling ``plan(input_array=x)`` would let the
        # plan adopt ``x`` as its input buffer, and a later call would overwrite the caller's array.
        plan.input_array[:] = x
        plan.execute()
        return plan.output_array.copy()


# --------------------------------------------------------------------------- spectrum
@dataclass(frozen=True, repr=False)
class Spectrum(Result):
    """Single-sided amplitude spectrum of a real record.

    Attributes
    ----------
    frequencies : ndarray, shape (n // 2 + 1,)
        Bin frequencies ``k df`` (Hz).
    amplitudes : ndarray, shape (n // 2 + 1,)
        Peak amplitude of the sinusoid at each bin, in the signal's units
        (a cos(2 pi f t) reads a on its bin).
    window : str
        Window used, a key of :data:`WINDOWS`.
    df : float
        Bin width ``1 / (n dt)`` (Hz).
    dt : float
        Sample interval (s).
    n_samples : int
        Record length n.
    max_amplitude_error_db : float
        Stated worst amplitude error of the window for a tone between bins (dB); zero for
        an on-bin tone.
    note : str
        How the record and window were chosen (empty for :func:`amplitude_spectrum`).
    """

    frequencies: np.ndarray
    amplitudes: np.ndarray
    window: str
    df: float
    dt: float
    n_samples: int
    max_amplitude_error_db: float
    note: str = ""

    @property
    def amplitudes_um(self) -> np.ndarray:
        """Amplitudes in µm, for a signal in metres (``1e6 * amplitudes``)."""
        return 1e6 * self.amplitudes

    @property
    def duration(self) -> float:
        """Record duration ``n dt`` (s)."""
        return self.n_samples * self.dt

    def amplitude_at(self, frequency_hz: float) -> float:
        """Amplitude at the bin nearest to ``frequency_hz``.

        Parameters
        ----------
        frequency_hz : float
            Frequency (Hz), 0 to the last bin's.

        Returns
        -------
        float
            In the signal's units (m for a displacement).

        Raises
        ------
        InputError
            If ``frequency_hz`` is outside 0 to the last bin's frequency.
        """
        frequency_hz = checks.number("frequency_hz", frequency_hz, "Hz", ge=0.0, le=float(self.frequencies[-1]))
        return float(self.amplitudes[int(round(frequency_hz / self.df))])

    def summary(self) -> list[str]:
        """The record, the window and its amplitude error, the largest line, and the note."""
        k = 1 + int(np.argmax(self.amplitudes[1:])) if len(self.amplitudes) > 1 else 0
        lines = [f"amplitude spectrum of {self.n_samples} samples of {self.dt:.6g} s ({self.duration:.6g} s): "
                 f"bins of {self.df:.6g} Hz up to {self.frequencies[-1]:.6g} Hz",
                 f"{self.window} window: amplitude error up to {self.max_amplitude_error_db:.3g} dB between bins, "
                 "none on a bin",
                 f"largest amplitude {self.amplitudes[k]:.6g} (the signal's units) at {self.frequencies[k]:.6g} Hz; "
                 f"mean {self.amplitudes[0]:.4g}"]
        return lines + textwrap.wrap(self.note, 110, max_lines=4, placeholder=" ...")

    def plot(self, ax=None, *, label: str = "amplitude", **options):
        """Draw the spectrum (:func:`rotorred.plots.scene.draw_spectra`) against frequency (Hz).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        label : str
            The line's label in the legend.
        **options
            ``f_max`` (Hz), ``log_y``, ``scale`` and ``unit`` (default µm from m), ``title``.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.scene import draw_spectra

        return draw_spectra({label: self}, ax, **options)

    def to_xarray(self, units: str = "m"):
        """The spectrum as an :class:`xarray.Dataset`: dimension ``frequency`` (coordinate, Hz), variable
        ``amplitude`` in ``units``, scalars ``df`` (Hz) and ``dt`` (s); window, samples, amplitude error and note as
        attributes.

        Parameters
        ----------
        units : str
            The signal's units, which a Spectrum does not know (UDUNITS text); default "m", as rotorred's
            displacements.

        Returns
        -------
        xarray.Dataset
        """
        import xarray as xr

        return xr.Dataset(
            {"amplitude": ("frequency", self.amplitudes, {"units": units, "long_name": "peak amplitude of the bin"}),
             "df": ((), self.df, {"units": "Hz", "long_name": "bin width"}),
             "dt": ((), self.dt, {"units": "s", "long_name": "sample interval"})},
            {"frequency": ("frequency", self.frequencies, {"units": "Hz", "long_name": "bin frequency"})},
            attrs={"title": "amplitude spectrum", "window": self.window, "n_samples": int(self.n_samples),
                   "max_amplitude_error_db": self.max_amplitude_error_db, "note": self.note})


def _check_signal(x) -> np.ndarray:
    """A finite real 1-D record of at least 2 samples, as float64 (float32 records stay float32)."""
    x = np.asarray(x)
    checked = checks.vector("x", x, min_len=2)
    return x if x.dtype == np.float32 else checked


def amplitude_spectrum(x, dt: float, window: str = "rectangular") -> Spectrum:
    """Single-sided amplitude spectrum of a real record.

    Parameters
    ----------
    x : array_like, shape (n,)
        Real samples ``x(j dt)``, any units (float32 is kept, anything else becomes float64).
    dt : float
        Sample interval (s), > 0.
    window : {"rectangular", "hann", "flattop"}
        See :data:`WINDOWS` for the amplitude error of each.

    Returns
    -------
    Spectrum
        ``frequencies`` (Hz) and ``amplitudes`` (units of ``x``), shape (n // 2 + 1,).

    Raises
    ------
    InputError
        If ``x`` is not a finite real vector of at least 2 samples, ``dt`` is not > 0, or ``window`` is unknown.

    Notes
    -----
    ``A_k = c_k |rfft(w x)_k| / sum(w)`` with ``c_k = 2`` except at DC and (for even n) the
    Nyquist bin, where ``c_k = 1``. The mean is not removed: a constant offset reads at 0 Hz.
    """
    info = _window_info(window)
    dt = checks.positive("dt", dt, "s")
    x = _check_signal(x)
    n = x.size
    w = window_values(window, n)
    xw = x if window == "rectangular" else (x * w).astype(x.dtype, copy=False)
    X = rfft(np.ascontiguousarray(xw))
    amplitudes = np.abs(X).astype(np.float64) * (2.0 / w.sum())
    amplitudes[0] *= 0.5
    if n % 2 == 0:
        amplitudes[-1] *= 0.5
    df = 1.0 / (n * dt)
    return Spectrum(
        frequencies=np.arange(amplitudes.size) * df,
        amplitudes=amplitudes,
        window=window,
        df=df,
        dt=dt,
        n_samples=n,
        max_amplitude_error_db=info.max_scalloping_db,
    )


# --------------------------------------------------------------------------- record length
class NotCommensurateError(checks.InputError):
    """The spool frequencies have no common period that is a whole number of samples
    (an :class:`rotorred.checks.InputError`, so a ``ValueError``)."""


@dataclass(frozen=True)
class CommensurateRecord:
    """A record length holding a whole number of common periods of two spools.

    Attributes
    ----------
    fundamental_hz : float
        Common fundamental ``gcd(f_L, f_H) = f_L / q = f_H / p`` (Hz).
    ratio : tuple of int
        ``(p, q)`` with ``f_H / f_L = p / q`` in lowest terms.
    period : float
        Common period ``T = 1 / fundamental_hz`` (s).
    samples_per_period : int
        ``T / dt`` (an integer within the tolerance).
    n_periods : int
        Number of common periods in the record.
    n_samples : int
        ``n_periods * samples_per_period``.
    """

    fundamental_hz: float
    ratio: tuple[int, int]
    period: float
    samples_per_period: int
    n_periods: int
    n_samples: int

    @property
    def df(self) -> float:
        """Bin width of the record ``1 / (n_periods T)`` (Hz)."""
        return self.fundamental_hz / self.n_periods


def commensurate_record(
    f_L: float,
    f_H: float,
    dt: float,
    *,
    n_available: int | None = None,
    n_periods: int | None = None,
    max_denominator: int = 100,
    rtol: float = 1e-9,
) -> CommensurateRecord:
    """Choose a record length on which both spool frequencies fall on bins.

    The settled response to two spools at ``f_L`` and ``f_H`` contains only combinations
    ``m f_H + n f_L``; when ``f_H / f_L = p / q`` (lowest terms) these are multiples of
    ``f_0 = f_L / q = gcd(f_L, f_H)``, so the response is periodic with ``T = 1 / f_0``
    (70 and 90 Hz: p/q = 9/7, f_0 = 10 Hz, T = 0.1 s). A record of ``k T / dt`` samples then
    has every combination on a bin.

    Parameters
    ----------
    f_L, f_H : float
        Spool frequencies (Hz), > 0 (``Omega / (2 pi)`` for speeds in rad/s).
    dt : float
        Sample interval (s), > 0.
    n_available : int, optional
        Samples available; the record is the largest whole number of periods that fits.
    n_periods : int, optional
        Number of common periods wanted (default 1 when ``n_available`` is not given).
        With ``n_available`` too, it must fit.
    max_denominator : int
        Largest ``q`` accepted in ``f_H / f_L = p / q``.
    rtol : float
        Relative tolerance of both tests: ``|f_H/f_L - p/q| <= rtol f_H/f_L`` and
        ``|T/dt - round(T/dt)| <= rtol T/dt``. The default 1e-9 admits rounding in
        ``Omega / (2 pi)`` and in ``dt`` (~1e-16 relative) but no physical mismatch: a
        relative period error e shifts the k-th bin by ``k e`` bins, so with e = 1e-9 a
        record of 1e6 bins is still within 1e-3 bins of exact.

    Returns
    -------
    CommensurateRecord

    Raises
    ------
    NotCommensurateError
        (a ValueError) for frequencies not commensurate within ``rtol`` with ``q <=
        max_denominator``, or ``T / dt`` not an integer within ``rtol``.
        Also when ``n_available`` holds no whole common period (e.g. 70 and 81 Hz: T = 1 s).
    ValueError
        For bad inputs, or ``n_periods`` that do not fit in ``n_available``.
    """
    f_L = checks.positive("f_L", f_L, "Hz")
    f_H = checks.positive("f_H", f_H, "Hz")
    dt = checks.positive("dt", dt, "s")
    max_denominator = checks.integer("max_denominator", max_denominator, ge=1)
    rtol = checks.number("rtol", rtol, gt=0.0, lt=1e-2)
    if n_available is not None:
        n_available = checks.integer("n_available", n_available, ge=1)
    if n_periods is not None:
        n_periods = checks.integer("n_periods", n_periods, ge=1)

    r = f_H / f_L
    frac = Fraction(r).limit_denominator(max_denominator)
    p, q = frac.numerator, frac.denominator
    if abs(r - p / q) > rtol * r:
        raise NotCommensurateError(
            "f_H", f_H, f"must be commensurate with f_L = {f_L!r} Hz: f_H/f_L = {r!r} is not a ratio p/q with "
            f"q <= max_denominator = {max_denominator} within rtol = {rtol} (nearest {p}/{q}); use a window "
            "(e.g. window='flattop') instead", "Hz")
    f0 = f_L / q
    period = 1.0 / f0
    spp_float = period / dt
    spp = int(round(spp_float))
    if spp < 1 or abs(spp_float - spp) > rtol * spp_float:
        raise NotCommensurateError(
            "dt", dt, f"must divide the common period T = {period!r} s into a whole number of samples "
            f"(T/dt = {spp_float!r}, tolerance rtol = {rtol}); choose dt = T/N or use a window "
            "(e.g. window='flattop')", "s")
    if n_available is None:
        k = 1 if n_periods is None else int(n_periods)
    else:
        k_max = int(n_available) // spp
        if k_max < 1:  # no common period on this record: a window must be used (settled_spectrum falls back)
            raise NotCommensurateError("n_available", n_available, f"must hold at least one common period T = "
                                       f"{period!r} s = {spp} samples")
        if n_periods is None:
            k = k_max
        elif n_periods > k_max:
            checks.fail("n_periods", n_periods, f"must fit in n_available = {n_available} samples: at most {k_max} "
                        f"periods of {spp} samples")
        else:
            k = int(n_periods)
    return CommensurateRecord(
        fundamental_hz=f0,
        ratio=(p, q),
        period=period,
        samples_per_period=spp,
        n_periods=k,
        n_samples=k * spp,
    )


def settled_spectrum(
    x,
    dt: float,
    f_L: float,
    f_H: float,
    *,
    n_periods: int | None = None,
    fallback_window: str = "flattop",
    max_denominator: int = 100,
    rtol: float = 1e-9,
) -> Spectrum:
    """Spectrum of the settled (final) part of a response to two spools.

    Takes the last whole number of common periods of ``x`` (:func:`commensurate_record`)
    and uses the rectangular window, which is exact on-bin. If the spool frequencies are
    not commensurate or the period is not a whole number of samples, it uses all of ``x``
    with ``fallback_window`` instead, and says so in ``note``.

    Parameters
    ----------
    x : array_like, shape (n,)
        Response samples, any units; the end of the record is taken as settled.
    dt : float
        Sample interval (s).
    f_L, f_H : float
        Spool frequencies (Hz).
    n_periods : int, optional
        Number of common periods to use (default: as many as fit).
    fallback_window : {"flattop", "hann", "rectangular"}
    max_denominator, rtol
        See :func:`commensurate_record`.

    Returns
    -------
    Spectrum
    """
    _window_info(fallback_window)
    x = _check_signal(x)
    try:
        rec = commensurate_record(
            f_L, f_H, dt, n_available=x.size, n_periods=n_periods,
            max_denominator=max_denominator, rtol=rtol,
        )
    except NotCommensurateError as err:
        # Only "no common period on the sample grid" falls back; input errors propagate.
        msg = str(err)
        spec = amplitude_spectrum(x, dt, window=fallback_window)
        return _with_note(spec, f"{fallback_window} window on all {x.size} samples: {msg}")
    spec = amplitude_spectrum(x[-rec.n_samples:], dt, window="rectangular")
    p, q = rec.ratio
    note = (
        f"rectangular window on the last {rec.n_periods} common period(s) "
        f"T = {rec.period:.6g} s (f_H/f_L = {p}/{q}, gcd = {rec.fundamental_hz:.6g} Hz), "
        f"{rec.n_samples} samples: combinations m f_H + n f_L are on bins"
    )
    return _with_note(spec, note)


def _with_note(spec: Spectrum, note: str) -> Spectrum:
    return replace(spec, note=note)

