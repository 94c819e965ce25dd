"""Least-squares fit of combination lines (m/k) f_H + (n/j) f_L at known frequencies.

A dual rotor driven by two spools at f_L and f_H (Hz) responds at combinations of them:
``m f_H + n f_L`` for the forced response (Xu et al. 2016, Table 1), and ``(m/k) f_H + (n/j) f_L``
with sub-harmonic orders k, j > 1 when rub impacts lock to a fraction of a spool frequency
(near 88-95 Hz the plate is struck once per three outer revolutions, f_H/3).
:func:`fit_lines` estimates the amplitude and phase of each such line by linear least squares on
the time record itself, not on FFT bins: the frequencies are exact by construction (they come
from the labels) and a line between bins loses nothing to scalloping. It finds the torus (k, j)
by itself, keeps only significant lines, and reports what the lines do not explain.
:func:`fit_peaks` fits the same lines, chosen by the peaks of an FFT amplitude spectrum instead of
by their significance (the scenes' lines above ``output.line_threshold``).

Model
    ``x(t_i) = mu + sum_l [C_l cos(2 pi f_l t_i) + S_l sin(2 pi f_l t_i)] + r_i`` on a uniform
    grid ``t_i = t_0 + i dt``, i = 0 .. N-1. Line l reads ``a_l cos(2 pi f_l t + phase_l)`` with
    ``a_l e^{i phase_l} = C_l - i S_l`` and t the record's own (absolute) time. The mean mu is a
    fitted column of ones, not a line.

Resolution: the merge rule
    Candidate frequencies closer than ``c / T`` (T = N dt, c = ``resolution``, default 2) are
    merged into one line carrying all their labels; the line sits at the frequency of its first
    label by the priority below. Rayleigh's criterion ``|df| T < 1`` (tidal analysis, t_tide's
    ``rc = 1``) is where two lines stop being separable at all; c = 2 is where the fit is
    guaranteed well conditioned: for frequencies at least c/T apart (from each other, from 0,
    from each other's mirror images -f and from the Nyquist alias) the large-sieve inequalities
    (Selberg; Montgomery and Vaughan 1974) bound the eigenvalues of the Gram matrix of the
    exponentials between N (1 - 1/c) and N (1 + 1/c), so cond <= (c + 1) / (c - 1) = 3.
    Candidates below c/T are not fitted (they cannot be told from an offset or a drift), and
    ``f_max`` defaults to the Nyquist frequency minus c/T.

Priority: the labelling rule
    ``(|m| + |n|, lcm of the denominators of m and n, |n|, -m)``. Every label of rotorred comes from this
    rule (:func:`fit_lines`, :func:`fit_peaks`), written by :func:`rotorred.signals.lines.line_label`. With
    f_L = 70 and f_H = 90 Hz every combination lies on a 10 Hz grid, so many ``(m, n)`` give one frequency
    (140 Hz = 2 f_L = 7 f_H - 7 f_L ...); the line carries them all, first the one of (1) the lowest order
    ``|m| + |n|``; (2) on a tie, whole orders before fractional ones; (3) then the fewest multiples of f_L:
    the rubbing disk (node 18) is on the high-pressure spool, so harmonics of f_H are the carrier and f_L
    the modulation (the paper's "fundamental modulated by the other rotor"); (4) then positive m. Rule (1)
    alone reproduces all 24 lines of the paper's Table 1 (each has a unique lowest-order combination within
    ``|m|, |n| <= 8``); rule (3) decides lines the paper does not list, e.g. 80 Hz = 4f_H-4f_L (not
    5f_L-3f_H) and 560 Hz = 7f_H-f_L (not 8f_L).

No packing
    Candidates have bounded orders (``|m| <= max_m``, ``|n| <= max_n`` as multiples of f_H and
    f_L) and at most ``FILL`` = 1/2 of the resolvable cells of width c/T below f_max hold a fitted
    line (at most ``max_lines``), the lowest orders first. Lines are then at least c/T apart and
    on average at least 2c/T apart: a broadband signal (noise, chaos) cannot be explained by a
    comb of lines at the resolution limit (each line takes about one Rayleigh cell of it, 1/(2c)
    = 1/4 of the band at most), and the significance test removes such lines anyway. The number
    of parameters stays below N/4.

Significance: the noise floor
    Each amplitude's standard error comes from the least-squares covariance
    ``sigma^2 (A^T A)^-1``, ``sigma^2 = RSS / (N - p)`` (residual variance, p parameters), by the
    delta method. That sigma^2 assumes a white residual; a coloured one (a broadband response,
    chaos) is stronger near some lines than on average, and the covariance of a line is set by
    the residual's level near its frequency. So sigma^2 is replaced, line by line, by the larger
    of itself and the residual's local level (the median of the residual's Hann spectrum over
    +-``LOCAL_BINS`` = 64 bins around the line, the bins next to fitted lines left out, converted
    to a variance as for white noise; 64 bins give the median to about 15 %). Without it, lines
    fitted in a coloured band pass ``a > 5 SE`` by the dozen and pack the band (measured on
    low-pass noise: 100 lines "explaining" 40 % of it). A line is kept when ``a > z SE`` with
    ``z`` = 5 (for a line of pure noise a/SE is Rayleigh distributed:
    ``P(a > 5 SE) = exp(-12.5) = 3.7e-6`` per candidate, below 1e-3 for the few hundred
    candidates of a fit) and ``a >= relative_floor * a_ref``, with ``a_ref = sqrt(2) rms(x - mean)``
    the amplitude of one sinusoid carrying the whole signal (default 1e-4, -80 dB: far above the
    ~1e-14 round-off of these fits, so a noise-free record keeps no spurious line). Failing
    lines are removed and the rest refitted until every kept line passes (the kept set only
    shrinks, so the loop ends; removing lines raises the residual, so no removed line would
    pass again).

Parsimony: ``max_kept``
    On a long record a line of 0.01 % of the energy is still many standard errors above the
    noise, so every significant line of a rich response can number in the hundreds (the rig at
    outer 88.8 Hz: 179 on 1.5 s). ``max_kept = L`` keeps the L largest amplitudes among the
    significant lines and refits them alone; the explained share is then that of those L lines
    (``1 - RSS / energy`` of their own fit, not a sum of shares taken from the larger fit), and
    ``LineFit.n_significant`` still says how many were significant.

Explained share
    ``1 - RSS / sum (x - mean(x))^2`` on the time record, RSS being the residual of the kept
    lines and the fitted mean. The mean is removed from the signal energy: an offset is not
    explained by any line. A line's share is ``N a^2 / 2 / sum (x - mean(x))^2``; the shares add
    up to the explained share when the lines are orthogonal (whole common periods).

Sub-harmonic torus (k, j), k, j = 1 .. ``max_subharmonic`` (6), found by the tool
    1. Fit the torus k = j = 1 and take its residual's strongest peaks (Hann spectrum by pyFFTW,
       local maxima above ``PEAK_FACTOR`` = 5 times the median amplitude, which for a white
       residual is exceeded with probability 2^-25 = 3e-8 per bin; frequencies refined by the
       Hann interpolation ``delta = (2 - R) / (1 + R)``).
    2. A torus is worth fitting when its new (fractional) candidates match more of the ten
       strongest peaks, within half a bin, than chance allows: a torus with candidates at density
       rho (per Hz) matches a random frequency with probability ``p = 2 rho tol``, and matching r
       of n peaks has the binomial tail probability ``P(R >= r)``; tori with ``P <= TORUS_ALPHA``
       (1e-2) are fitted, the ``N_TORI`` (3) least probable by chance. One stray tone among ten
       peaks has ``P = 1 - (1 - p)^10 > 1e-2`` for any torus with ``p > 1e-3``, so it never makes
       a torus: a sub-harmonic torus shows itself by several lines (f_H/3, 2f_H/3, f_H/3 + f_L,
       ...), and on a short record a torus with k = j = 6 has a candidate within half a bin of
       almost any one frequency. 1e-2, not smaller: on the rig's 0.6 s record at 88.8 Hz the
       f_H/3 torus matches 8 of 10 peaks at p = 0.36 (P = 6e-3).
    3. Keep the fit of least Bayesian information criterion ``N ln(RSS / N) + p ln N``
       (Schwarz 1978), RSS floored at ``(1e-10)^2`` of the signal energy so that round-off does
       not decide; ties (two tori that both explain everything, as f_H/2 and f_L/2 do at
       70/90 Hz, where both give a 5 Hz base) go to the lines of lowest total order
       ``sum |m| + |n|``, then to the smallest k j, then k + j.
    Why not only compare fits: the 35 tori cost 35 fits, and a torus that places a candidate on
    one stray tone lowers the BIC without counting the frequency it chose. Why not only read
    peaks: matching within half a bin cannot tell two tori that both match. The peaks choose
    which fits are worth making; the fits decide.

Cost
    The normal equations are assembled without the design matrix: the Gram matrix ``A^T A`` has
    a closed form (Dirichlet kernel sums), and ``A^T x`` and the fitted model are products of a
    table ``exp(i w_l j dt)``, j < 512, with per-chunk phases ``exp(i w_l t_c)`` (real matrix
    products). A fit costs O(N L + L^3) time and O(N + L^2) memory for L lines, against
    O(N L^2) and O(N L) for a QR of the N x 2L design matrix, and gives the same solution:
    Cholesky on a Gram matrix of condition <= 3 loses nothing.

References
----------
.. [1] Xu et al., "Dynamic Characteristics and Experimental Research of Dual-Rotor System with
   Rub-Impact Fault", Shock and Vibration 2016, 6239281, Table 1.
.. [2] R. Pawlowicz, B. Beardsley, S. Lentz, "Classical tidal harmonic analysis including error
   estimates in MATLAB using T_TIDE", Computers & Geosciences 28, 2002 (Rayleigh criterion).
.. [3] H. L. Montgomery, R. C. Vaughan, "Hilbert's inequality", J. London Math. Soc. 8, 1974
   (large sieve); A. Selberg, Collected papers II (lower bound).
.. [4] G. Schwarz, "Estimating the dimension of a model", Ann. Statist. 6(2), 1978.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import scipy.linalg
import scipy.special

from rotorred import checks
from rotorred.signals.lines import find_peaks, line_label
from rotorred.signals.spectra import Spectrum, amplitude_spectrum, settled_spectrum

__all__ = [
    "RESOLUTION", "Z_SIGNIFICANCE", "RELATIVE_FLOOR", "FILL", "MAX_LINES", "MAX_SUBHARMONIC",
    "PEAK_FACTOR", "N_TORI",
    "Torus", "FittedLine", "UnlabelledPeak", "TorusTrial", "LineFit", "FrequencyFit",
    "fit_lines", "fit_peaks", "fit_frequencies", "commensurate_ratio", "residual_peaks",
]

RESOLUTION = 2.0  #: c: candidates closer than c/T are one line (cond of the fit <= (c+1)/(c-1))
Z_SIGNIFICANCE = 5.0  #: a line is kept when its amplitude exceeds z standard errors
RELATIVE_FLOOR = 1e-4  #: ... and relative_floor * sqrt(2) rms(x - mean)
FILL = 0.5  #: at most this share of the resolvable cells below f_max holds a candidate line
MAX_LINES = 400  #: and at most this many candidate lines (cost O(N L + L^3))
MAX_SUBHARMONIC = 6  #: sub-harmonic orders k, j = 1 .. 6 are searched
PEAK_FACTOR = 5.0  #: a residual peak stands 5 times above the residual's median amplitude
N_SEARCH_PEAKS = 10  #: strongest residual peaks that choose the tori worth fitting
TORUS_ALPHA = 1e-2  #: a torus is fitted when it matches that many peaks with chance probability <= 1e-2
N_TORI = 3  #: tori fitted besides k = j = 1
ROUNDOFF = 1e-10  #: residuals below this share of the signal's rms count as zero in the BIC
COMMENSURATE_RTOL = 1e-9  #: as rotorred.signals.spectra.commensurate_record
COMMENSURATE_MAX_DENOMINATOR = 100
LOCAL_BINS = 64  #: the residual's local level is the median of +-64 Hann bins around a line
_CHUNK = 512  #: samples per chunk of the phasor products


# --------------------------------------------------------------------------- speeds
def commensurate_ratio(f_L: float, f_H: float) -> Fraction | None:
    """``f_H / f_L = p / q`` in lowest terms, or None when the speeds are not commensurate.

    Commensurate means ``|f_H/f_L - p/q| <= 1e-9 f_H/f_L`` with ``q <= 100``
    (``Fraction.limit_denominator``): the rule of :func:`rotorred.signals.spectra.commensurate_record`,
    which admits the rounding of ``Omega / (2 pi)`` and no physical mismatch.
    """
    f_L = checks.positive("f_L", f_L, "Hz")
    f_H = checks.positive("f_H", f_H, "Hz")
    r = f_H / f_L
    frac = Fraction(r).limit_denominator(COMMENSURATE_MAX_DENOMINATOR)
    return frac if abs(r - frac.numerator / frac.denominator) <= COMMENSURATE_RTOL * r else None


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class Torus:
    """The torus of the fitted lines: base frequencies ``f_H / k`` and ``f_L / j``.

    Attributes
    ----------
    f_L, f_H : float
        Spool frequencies (Hz).
    k, j : int
        Sub-harmonic orders of f_H and f_L (1 = the spool frequency itself).
    """

    f_L: float
    f_H: float
    k: int = 1
    j: int = 1

    @property
    def ratio(self) -> Fraction | None:
        """``f_H / f_L`` as p/q when commensurate (:func:`commensurate_ratio`), else None."""
        return commensurate_ratio(self.f_L, self.f_H)

    @property
    def bases(self) -> tuple[float, ...]:
        """Base frequencies (Hz): ``(f_H/k, f_L/j)``, or the one base ``gcd(f_H/k, f_L/j)`` when
        the speeds are commensurate (every line is then a multiple of it)."""
        r = self.ratio
        if r is None:
            return (self.f_H / self.k, self.f_L / self.j)
        p, q = r.numerator, r.denominator  # f_H = p g, f_L = q g
        return (float(Fraction(math.gcd(p * self.j, q * self.k), self.k * self.j)) * self.f_L / q,)

    @property
    def label(self) -> str:
        """``"f_H/3, f_L"``-style text of the bases, with ``" (common base 10 Hz)"`` if commensurate."""
        text = f"{line_label(Fraction(1, self.k), 0)}, {line_label(0, Fraction(1, self.j))}"
        return text + (f" (common base {self.bases[0]:.6g} Hz)" if self.ratio is not None else "")


@dataclass(frozen=True)
class FittedLine:
    """One line of a :class:`LineFit`: ``amplitude cos(2 pi frequency_hz t + phase)``, and its labels.

    Attributes
    ----------
    frequency_hz : float
        Exact frequency of the first label, ``m f_H + n f_L`` (Hz).
    amplitude : float
        Amplitude a of the line (units of the signal, m for a displacement).
    phase : float
        (rad), relative to the record's own time t.
    standard_error : float
        Standard error of the amplitude (units of the signal).
    phase_error : float
        Standard error of the phase (rad).
    share : float
        ``N amplitude^2 / 2`` over the signal energy (mean removed).
    orders : tuple of (Fraction, Fraction)
        Every ``(m, n)`` this line carries (closer than the resolution c/T), first by priority.
    """

    frequency_hz: float
    amplitude: float
    phase: float
    standard_error: float
    phase_error: float
    share: float
    orders: tuple[tuple[Fraction, Fraction], ...]

    @property
    def m(self) -> Fraction:
        """Multiple of f_H of the first label."""
        return self.orders[0][0]

    @property
    def n(self) -> Fraction:
        """Multiple of f_L of the first label."""
        return self.orders[0][1]

    @property
    def label(self) -> str:
        """First label (:func:`rotorred.signals.lines.line_label`: ``"2f_H/3-f_L"``)."""
        return line_label(self.m, self.n)

    @property
    def labels(self) -> tuple[str, ...]:
        """Every label the line carries, first by priority."""
        return tuple(line_label(m, n) for m, n in self.orders)

    @property
    def significance(self) -> float:
        """``amplitude / standard_error``."""
        return self.amplitude / self.standard_error if self.standard_error > 0 else math.inf


@dataclass(frozen=True)
class UnlabelledPeak:
    """A peak of the residual spectrum: what the lines did not explain.

    Attributes
    ----------
    frequency_hz : float
        Hann-interpolated frequency (Hz).
    amplitude : float
        Hann-interpolated amplitude (units of the signal).
    """

    frequency_hz: float
    amplitude: float


@dataclass(frozen=True)
class TorusTrial:
    """One torus fitted during the search: its orders, line count, explained share and BIC."""

    k: int
    j: int
    n_lines: int
    explained_share: float
    bic: float


@dataclass(frozen=True)
class LineFit:
    """Result of :func:`fit_lines` and :func:`fit_peaks`: the labelled lines of a record of N samples.

    Attributes
    ----------
    lines : tuple of FittedLine
        The lines (significant ones for :func:`fit_lines`, those at the spectrum's peaks for
        :func:`fit_peaks`), by increasing frequency.
    torus : Torus
        Torus of the lines (found, or as given).
    explained_share : float
        ``1 - RSS / sum (x - mean)^2`` on the time record (dimensionless; NaN for a constant record).
    mean : float
        Fitted offset (units of the signal).
    unlabelled : tuple of UnlabelledPeak
        What the lines do not explain: the strongest peaks of the residual, strongest first
        (:func:`fit_lines`), or the spectrum's peaks near no line, by frequency (:func:`fit_peaks`).
    residual : ndarray, shape (N,)
        ``x`` minus the fitted mean and lines (units of the signal).
    residual_spectrum : Spectrum
        Hann amplitude spectrum of the residual.
    trials : tuple of TorusTrial
        Tori fitted during the search (the chosen one included).
    t0, dt : float
        First sample time and sample interval (s).
    n_samples : int
        N.
    resolution_hz : float
        Merge distance c/T (Hz).
    noise_rms : float
        ``sqrt(RSS / (N - p))`` (units of the signal).
    n_candidates : int
        Candidate lines fitted before the significance test (after merging).
    n_significant : int
        Lines that passed the significance test before the ``max_kept`` cap (= ``len(lines)``
        without a cap; ``len(lines)`` for :func:`fit_peaks`).
    """

    lines: tuple[FittedLine, ...]
    torus: Torus
    explained_share: float
    mean: float
    unlabelled: tuple[UnlabelledPeak, ...]
    residual: np.ndarray
    residual_spectrum: Spectrum
    trials: tuple[TorusTrial, ...]
    t0: float
    dt: float
    n_samples: int
    resolution_hz: float
    noise_rms: float
    n_candidates: int
    n_significant: int

    @property
    def duration(self) -> float:
        """Record length T = N dt (s)."""
        return self.n_samples * self.dt

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Line frequencies (Hz), shape (L,)."""
        return np.array([ln.frequency_hz for ln in self.lines])

    def evaluate(self, t) -> np.ndarray:
        """The fitted model ``mean + sum a cos(2 pi f t + phase)`` at times ``t`` (s), shape of ``t``.

        Parameters
        ----------
        t : array_like, any shape
            Times (s), on the fitted record's own (absolute) clock.

        Returns
        -------
        ndarray, shape of ``t``
            The model, in the unit of the fitted signal (m for a displacement).

        Raises
        ------
        InputError
            If a time is not finite.
        """
        t = checks.array("t", t, unit="s")
        out = np.full(t.shape, self.mean)
        for ln in self.lines:
            out += ln.amplitude * np.cos(2.0 * np.pi * ln.frequency_hz * t + ln.phase)
        return out


@dataclass(frozen=True)
class FrequencyFit:
    """Result of :func:`fit_frequencies`: lines at given frequencies, no selection.

    Attributes
    ----------
    frequencies_hz : ndarray, shape (L,)
    coefficients : ndarray of complex, shape (L,)
        ``a e^{i phase}``: line l is ``Re(coefficients[l] exp(2 pi i f_l t))``.
    standard_errors : ndarray, shape (L,)
        Of the amplitudes.
    mean : float
    residual_rms : float
        rms of x minus the fitted mean and lines.
    explained_share : float
    """

    frequencies_hz: np.ndarray
    coefficients: np.ndarray
    standard_errors: np.ndarray
    mean: float
    residual_rms: float
    explained_share: float

    @property
    def amplitudes(self) -> np.ndarray:
        return np.abs(self.coefficients)

    @property
    def phases(self) -> np.ndarray:
        return np.angle(self.coefficients)


# --------------------------------------------------------------------------- the grid
@dataclass(frozen=True)
class _Grid:
    t0: float
    dt: float
    n: int

    @property
    def duration(self) -> float:
        return self.n * self.dt


def _record(t, x) -> tuple[_Grid, np.ndarray]:
    """The uniform grid of ``t`` (deviation <= 1e-6 dt from ``t_0 + i dt``) and ``x`` as float64."""
    t = checks.vector("t", t, "s", min_len=8, increasing=True)
    x = checks.vector("x", x, min_len=8)
    if x.shape != t.shape:
        checks.fail("x", x, f"must have the shape of t, {t.shape}")
    dt = (t[-1] - t[0]) / (t.size - 1)
    deviation = float(np.max(np.abs(t - (t[0] + dt * np.arange(t.size)))))
    if deviation > 1e-6 * dt:
        checks.fail("t", t, f"must be uniformly sampled (deviates {deviation:.3g} s from t_0 + i dt; "
                    f"allowed 1e-6 dt = {1e-6 * dt:.3g} s)", "s")
    return _Grid(float(t[0]), float(dt), int(t.size)), x


# --------------------------------------------------------------------------- least squares
def _dirichlet(omega: np.ndarray, grid: _Grid) -> np.ndarray:
    """``sum_i exp(i omega t_i)`` in closed form, elementwise (omega in rad/s)."""
    half = 0.5 * omega * grid.dt
    s = np.sin(half)
    ratio = np.divide(np.sin(grid.n * half), s, out=np.full(np.shape(half), float(grid.n)), where=s != 0.0)
    return np.exp(1j * (omega * grid.t0 + half * (grid.n - 1))) * ratio


def _gram(grid: _Grid, omega: np.ndarray) -> np.ndarray:
    """``A^T A`` of the columns [1, cos(w_l t), sin(w_l t)], shape (2L+1, 2L+1)."""
    L = omega.size
    dm = _dirichlet(omega[:, None] - omega[None, :], grid)
    dp = _dirichlet(omega[:, None] + omega[None, :], grid)
    d1 = _dirichlet(omega, grid)
    c, s = slice(1, L + 1), slice(L + 1, 2 * L + 1)
    G = np.empty((2 * L + 1, 2 * L + 1))
    G[0, 0] = grid.n
    G[0, c] = G[c, 0] = d1.real
    G[0, s] = G[s, 0] = d1.imag
    G[c, c] = 0.5 * (dm.real + dp.real)
    G[s, s] = 0.5 * (dm.real - dp.real)
    G[c, s] = 0.5 * (dp.imag - dm.imag)  # sum cos(w_a t) sin(w_b t)
    G[s, c] = G[c, s].T
    return G


def _phasors(grid: _Grid, omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``exp(i w j dt)`` for j < chunk, shape (chunk, L), and ``exp(i w t_c)`` per chunk start."""
    b = min(_CHUNK, grid.n)
    n_chunks = -(-grid.n // b)
    table = np.exp(1j * np.outer(np.arange(b) * grid.dt, omega))
    phases = np.exp(1j * np.outer(grid.t0 + np.arange(n_chunks) * (b * grid.dt), omega))
    return table, phases


def _project(x: np.ndarray, table: np.ndarray, phases: np.ndarray) -> np.ndarray:
    """``sum_i x_i exp(i w_l t_i)``, shape (L,)."""
    X = np.zeros(phases.shape[0] * table.shape[0])
    X[: x.size] = x
    X = X.reshape(phases.shape[0], table.shape[0])
    return (phases * (X @ table.real + 1j * (X @ table.imag))).sum(axis=0)


def _synthesize(z: np.ndarray, n: int, table: np.ndarray, phases: np.ndarray) -> np.ndarray:
    """``Re sum_l z_l exp(i w_l t_i)``, shape (n,)."""
    W = phases * z
    return (W.real @ table.real.T - W.imag @ table.imag.T).ravel()[:n]


@dataclass(frozen=True)
class _Solution:
    mean: float
    z: np.ndarray  # C - i S = a e^{i phase}
    var: np.ndarray  # (L, 3): var C, var S, cov(C, S), times sigma^2
    residual: np.ndarray
    rss: float

    @property
    def amplitude_errors(self) -> tuple[np.ndarray, np.ndarray]:
        """Standard errors of the amplitudes and phases (delta method)."""
        C, S = self.z.real, -self.z.imag
        vc, vs, cv = self.var.T
        a2 = C * C + S * S
        safe = np.where(a2 > 0, a2, 1.0)
        var_a = np.where(a2 > 0, (C * C * vc + S * S * vs + 2 * C * S * cv) / safe, 0.5 * (vc + vs))
        var_p = np.where(a2 > 0, (S * S * vc + C * C * vs - 2 * C * S * cv) / (safe * safe), np.inf)
        return np.sqrt(np.maximum(var_a, 0.0)), np.sqrt(np.maximum(var_p, 0.0))


def _solve(grid: _Grid, x: np.ndarray, freqs: np.ndarray) -> _Solution:
    """Least squares of x on [1, cos, sin] at ``freqs`` (Hz): normal equations, Cholesky."""
    omega = 2.0 * np.pi * np.asarray(freqs, dtype=float)
    L = omega.size
    table, phases = _phasors(grid, omega)
    b = _project(x, table, phases)
    factor = scipy.linalg.cho_factor(_gram(grid, omega), check_finite=False)
    coef = scipy.linalg.cho_solve(factor, np.concatenate(([x.sum()], b.real, b.imag)), check_finite=False)
    z = coef[1:L + 1] - 1j * coef[L + 1:]
    residual = x - coef[0] - _synthesize(z, grid.n, table, phases)
    rss = float(residual @ residual)
    sigma2 = rss / max(grid.n - (2 * L + 1), 1)
    inv = scipy.linalg.cho_solve(factor, np.eye(2 * L + 1), check_finite=False)
    i = np.arange(L)
    var = sigma2 * np.stack([inv[1 + i, 1 + i], inv[L + 1 + i, L + 1 + i], inv[1 + i, L + 1 + i]], axis=1)
    return _Solution(float(coef[0]), z, var, residual, rss)


def fit_frequencies(t, x, frequencies_hz, *, resolution: float = RESOLUTION) -> FrequencyFit:
    """Least-squares amplitudes and phases of lines at given frequencies (no selection, no merging).

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform sample times (s).
    x : array_like, shape (N,)
        Samples, any units.
    frequencies_hz : array_like, shape (L,)
        Line frequencies (Hz), each at least c/T from 0, from the Nyquist frequency and from the
        others (for c = 2 the condition of the fit is then <= 3; see the module docstring).
    resolution : float
        c >= 1.

    Returns
    -------
    FrequencyFit
    """
    grid, x = _record(t, x)
    freqs = checks.vector("frequencies_hz", frequencies_hz, "Hz", min_len=0, ge=0.0)
    resolution = checks.number("resolution", resolution, ge=1.0)
    limit = resolution / grid.duration
    nyquist = 0.5 / grid.dt
    ordered = np.sort(freqs)
    slack = 1e-9 * limit  # rounding of a window length chosen as exactly c / df
    if freqs.size and (ordered[0] < limit - slack or ordered[-1] > nyquist - limit + slack
                       or np.any(np.diff(ordered) < limit - slack)):
        checks.fail("frequencies_hz", frequencies_hz, f"must be at least c/T = {limit:.6g} Hz apart, from 0 and "
                    f"from the Nyquist frequency {nyquist:.6g} Hz", "Hz")
    sol = _solve(grid, x, freqs)
    energy = float(np.sum((x - x.mean()) ** 2))
    return FrequencyFit(freqs, sol.z, sol.amplitude_errors[0], sol.mean, math.sqrt(sol.rss / grid.n),
                        1.0 - sol.rss / energy if energy > 0 else math.nan)


# --------------------------------------------------------------------------- candidates
@dataclass(frozen=True)
class _Options:
    f_L: float
    f_H: float
    f_lo: float  # c/T
    f_hi: float  # f_max
    resolution_hz: float
    cap: int
    max_m: int
    max_n: int
    z: float
    floor: float  # relative_floor * a_ref (units of x)
    max_kept: int | None = None  # at most this many lines kept, the strongest


def _candidates(opts: _Options, k: int, j: int) -> tuple[np.ndarray, ...]:
    """Integer orders m' (of f_H/k), n' (of f_L/j), frequencies and denominators, by priority."""
    mp, nq = np.meshgrid(np.arange(-k * opts.max_m, k * opts.max_m + 1),
                         np.arange(-j * opts.max_n, j * opts.max_n + 1), indexing="ij")
    mp, nq = mp.ravel(), nq.ravel()
    f = (mp / k) * opts.f_H + (nq / j) * opts.f_L
    sel = (f >= opts.f_lo) & (f <= opts.f_hi)
    mp, nq, f = mp[sel], nq[sel], f[sel]
    den = np.lcm(k // np.gcd(mp, k), j // np.gcd(nq, j))
    order = np.lexsort((-mp * j, np.abs(nq) * k, den, np.abs(mp) * j + np.abs(nq) * k))
    return mp[order], nq[order], f[order], den[order]


def _merge(freqs: np.ndarray, resolution_hz: float, cap: int) -> tuple[np.ndarray, np.ndarray]:
    """Line of each candidate (in priority order; -1 if beyond the cap) and the line frequencies.

    A candidate closer than ``resolution_hz`` to a line joins it; otherwise it opens a new line
    while fewer than ``cap`` lines exist.
    """
    kept: list[float] = []  # sorted line frequencies
    kept_id: list[int] = []
    lines: list[float] = []
    line_of = np.full(freqs.size, -1)
    for i, f in enumerate(freqs.tolist()):
        pos = bisect.bisect_left(kept, f)
        near = [p for p in (pos - 1, pos) if 0 <= p < len(kept) and abs(kept[p] - f) < resolution_hz]
        if near:
            line_of[i] = kept_id[min(near, key=lambda p: abs(kept[p] - f))]
        elif len(lines) < cap:
            kept.insert(pos, f)
            kept_id.insert(pos, len(lines))
            line_of[i] = len(lines)
            lines.append(f)
    return line_of, np.array(lines)


# --------------------------------------------------------------------------- one torus
@dataclass(frozen=True)
class _TorusFit:
    k: int
    j: int
    freqs: np.ndarray
    orders: tuple[tuple[tuple[Fraction, Fraction], ...], ...]
    solution: _Solution
    errors: tuple[np.ndarray, np.ndarray]  # standard errors of amplitudes and phases
    n_candidates: int
    n_significant: int

    @property
    def total_order(self) -> Fraction:
        """Sum of ``|m| + |n|`` over the lines' first labels: the simpler description wins a tie."""
        return sum((abs(m) + abs(n) for (m, n), *_ in self.orders), Fraction(0))

    def bic(self, energy: float) -> float:
        n = self.solution.residual.size
        rss = max(self.solution.rss, ROUNDOFF ** 2 * energy, np.finfo(float).tiny)
        return n * math.log(rss / n) + (2 * self.freqs.size + 1) * math.log(n)


def _local_noise_scale(grid: _Grid, sol: _Solution, freqs: np.ndarray) -> np.ndarray:
    """``sqrt(max(1, sigma_local^2 / sigma^2))`` at each line: the residual's level near the line.

    The residual's Hann amplitudes are Rayleigh distributed for a locally white residual, with
    ``E[A^2] = 6 sigma^2 / N`` and ``median^2 = E[A^2] ln 2``, so ``sigma_local^2 = N median^2 /
    (6 ln 2)``, the median taken over +-``LOCAL_BINS`` bins around the line, leaving out the bins
    within one bin of any fitted line (the fit notches them).
    """
    sigma2 = sol.rss / max(grid.n - (2 * freqs.size + 1), 1)
    if freqs.size == 0 or sigma2 == 0.0:
        return np.ones(freqs.size)
    spec = amplitude_spectrum(sol.residual, grid.dt, window="hann")
    A = spec.amplitudes
    line_bins = np.rint(freqs / spec.df).astype(int)
    free = np.ones(A.size, dtype=bool)
    free[0] = False
    for offset in (-1, 0, 1):
        free[np.clip(line_bins + offset, 0, A.size - 1)] = False
    idx = line_bins[:, None] + np.arange(-LOCAL_BINS, LOCAL_BINS + 1)[None, :]
    inside = (idx >= 0) & (idx < A.size)
    idx = np.clip(idx, 0, A.size - 1)
    vals = np.where(inside & free[idx], A[idx], np.nan)
    empty = np.all(np.isnan(vals), axis=1)
    vals[empty] = 0.0  # no free bin near the line: the global level stands
    local = grid.n * np.nanmedian(vals, axis=1) ** 2 / (6.0 * math.log(2.0))
    return np.sqrt(np.maximum(1.0, local / sigma2))


def _significant(grid: _Grid, x: np.ndarray, freqs: np.ndarray, opts: _Options):
    """Indices of the significant lines among ``freqs``, their fit, standard errors, and the number
    of lines that were significant before the ``max_kept`` cap.

    Refitted without the failing lines until every kept line passes; then, when more than
    ``max_kept`` pass, the ``max_kept`` largest amplitudes are kept and refitted once.
    """
    keep = np.arange(freqs.size)
    while True:
        sol = _solve(grid, x, freqs[keep])
        scale = _local_noise_scale(grid, sol, freqs[keep])
        se_a, se_p = (e * scale for e in sol.amplitude_errors)
        a = np.abs(sol.z)
        ok = (a > opts.z * se_a) & (a >= opts.floor)
        if ok.all():
            break
        keep = keep[ok]
    n_significant = int(keep.size)
    if opts.max_kept is not None and keep.size > opts.max_kept:
        # The strongest, refitted alone. Not tested again: their significance was judged against
        # the noise of the full fit; the weaker significant lines now left in the residual are
        # not noise, and counting them as such would drop strong lines in a rich band.
        keep = np.sort(keep[np.argsort(-a, kind="stable")[:opts.max_kept]])
        sol = _solve(grid, x, freqs[keep])
        se_a, se_p = (e * _local_noise_scale(grid, sol, freqs[keep]) for e in sol.amplitude_errors)
    return keep, sol, (se_a, se_p), n_significant


def _fit_torus(grid: _Grid, x: np.ndarray, opts: _Options, k: int, j: int) -> _TorusFit:
    """Candidates of the torus (k, j), merged, fitted, reduced to the significant lines."""
    mp, nq, f, _ = _candidates(opts, k, j)
    line_of, line_freqs = _merge(f, opts.resolution_hz, opts.cap)
    keep, sol, errors, n_significant = _significant(grid, x, line_freqs, opts)
    return _torus_fit(k, j, mp, nq, line_of, line_freqs, keep, sol, errors, n_significant)


def _torus_fit(k: int, j: int, mp: np.ndarray, nq: np.ndarray, line_of: np.ndarray, line_freqs: np.ndarray,
               keep: np.ndarray, sol: _Solution, errors: tuple, n_significant: int) -> _TorusFit:
    """The :class:`_TorusFit` of the merged lines ``keep`` (increasing line indices), each with its labels."""
    by_line = np.argsort(line_of, kind="stable")  # candidates grouped by line, priority order kept
    starts = np.searchsorted(line_of[by_line], keep)
    ends = np.searchsorted(line_of[by_line], keep, side="right")
    orders = tuple(tuple((Fraction(int(mp[c]), k), Fraction(int(nq[c]), j)) for c in by_line[s:e])
                   for s, e in zip(starts, ends))
    return _TorusFit(k, j, line_freqs[keep], orders, sol, errors, int(line_freqs.size), n_significant)


# --------------------------------------------------------------------------- residual peaks
def residual_peaks(spectrum: Spectrum, *, f_min: float = 0.0, f_max: float | None = None,
                   floor: float = 0.0, n_peaks: int = 10) -> tuple[UnlabelledPeak, ...]:
    """Strongest peaks of a Hann amplitude spectrum that stand above its noise level.

    A peak is a local maximum in ``[f_min, f_max]`` above ``PEAK_FACTOR`` (5) times the median
    amplitude (for white noise the Hann amplitudes are Rayleigh distributed and exceed 5 medians
    with probability ``2^-25`` per bin) and above ``floor``. Its frequency and amplitude are refined
    by the Hann interpolation ``delta = (2 - R) / (1 + R)``, ``R`` the ratio of the peak to its
    larger neighbour, and ``a = A_k pi delta (1 - delta^2) / sin(pi delta)`` (exact for one tone).

    Parameters
    ----------
    spectrum : Spectrum
        With ``window == "hann"``.
    f_min, f_max : float
        Band searched (Hz); ``f_max`` default: the last bin.
    floor : float
        Smallest amplitude reported (units of the signal).
    n_peaks : int
        Number of peaks returned at most.

    Returns
    -------
    tuple of UnlabelledPeak
        Strongest first.
    """
    if not isinstance(spectrum, Spectrum) or spectrum.window != "hann":
        checks.fail("spectrum", spectrum, "must be a Spectrum with window 'hann'")
    n_peaks = checks.integer("n_peaks", n_peaks, ge=0)
    A = spectrum.amplitudes
    if A.size < 3:
        return ()
    k = np.arange(1, A.size - 1)
    f = k * spectrum.df
    f_max = spectrum.frequencies[-1] if f_max is None else f_max
    ok = ((A[k] > A[k - 1]) & (A[k] >= A[k + 1]) & (A[k] > PEAK_FACTOR * np.median(A[1:]))
          & (A[k] > floor) & (f >= f_min) & (f <= f_max))
    ks = k[ok][np.argsort(-A[k[ok]], kind="stable")][:n_peaks]
    peaks = []
    for kk in ks:
        side = 1 if A[kk + 1] >= A[kk - 1] else -1
        ratio = A[kk] / max(A[kk + side], np.finfo(float).tiny)
        delta = min(max((2.0 - ratio) / (1.0 + ratio), 0.0), 0.5)
        gain = 1.0 if delta == 0.0 else math.sin(math.pi * delta) / (math.pi * delta * (1.0 - delta * delta))
        peaks.append(UnlabelledPeak(float((kk + side * delta) * spectrum.df), float(A[kk] / gain)))
    return tuple(peaks)


# --------------------------------------------------------------------------- torus search
def _shortlist(peaks: tuple[UnlabelledPeak, ...], opts: _Options, tol_hz: float, max_sub: int) -> list[tuple[int, int]]:
    """Tori (k, j) != (1, 1) whose fractional candidates match more peaks than chance allows, best first.

    A torus with ``n_new`` fractional candidates over a band ``span`` matches a random frequency
    within ``tol_hz`` with probability ``p = n_new 2 tol_hz / span``; matching r of the n peaks has
    the binomial tail probability ``P(R >= r)``. Tori with ``P <= TORUS_ALPHA`` are kept, the least
    probable by chance first (then the most matched peak energy, then the simplest).
    """
    scored = []
    energy = np.array([p.amplitude ** 2 for p in peaks])
    where = np.array([p.frequency_hz for p in peaks])
    for k in range(1, max_sub + 1):
        for j in range(1, max_sub + 1):
            if (k, j) == (1, 1):
                continue
            _, _, f, den = _candidates(opts, k, j)
            new = f[den > 1]
            if new.size == 0:
                continue
            chance = min(1.0, new.size * 2.0 * tol_hz / max(new.max() - opts.f_lo, 2.0 * tol_hz))
            matched = np.abs(new[:, None] - where[None, :]).min(axis=0) <= tol_hz
            p_value = float(scipy.special.bdtrc(int(matched.sum()) - 1, where.size, chance))  # binomial survival function
            if matched.any() and p_value <= TORUS_ALPHA:
                scored.append((p_value, -float(energy[matched].sum()), k * j, k + j, k, (k, j)))
    return [kj for *_, kj in sorted(scored)[:N_TORI]]


def _search(grid: _Grid, x: np.ndarray, opts: _Options, max_sub: int, energy: float) -> tuple[_TorusFit, tuple]:
    """The torus of least BIC among k = j = 1 and the shortlisted tori, and all fits made."""
    base = _fit_torus(grid, x, opts, 1, 1)
    fits = [base]
    if max_sub > 1:
        spec = amplitude_spectrum(base.solution.residual, grid.dt, window="hann")
        peaks = residual_peaks(spec, f_min=opts.f_lo, f_max=opts.f_hi, floor=opts.floor, n_peaks=N_SEARCH_PEAKS)
        if peaks:
            fits += [_fit_torus(grid, x, opts, k, j) for k, j in _shortlist(peaks, opts, 0.5 / grid.duration, max_sub)]
    best = min(fits, key=lambda ft: (ft.bic(energy), ft.total_order, ft.k * ft.j, ft.k + ft.j, ft.k))
    return best, tuple(fits)


# --------------------------------------------------------------------------- the fit
def _options(grid: _Grid, x: np.ndarray, f_L, f_H, f_max, max_m, max_n, resolution, z, relative_floor,
             max_lines, max_kept=None, constant_ok: bool = False) -> _Options:
    f_L = checks.positive("f_L", f_L, "Hz")
    f_H = checks.positive("f_H", f_H, "Hz")
    resolution = checks.number("resolution", resolution, ge=1.0)
    f_lo = resolution / grid.duration
    top = 0.5 / grid.dt - f_lo
    if top <= f_lo:
        checks.fail("t", grid.n, f"must hold more samples: N = {grid.n} resolves no line between c/T and the "
                    "Nyquist frequency minus c/T")
    f_hi = top if f_max is None else checks.number("f_max", f_max, "Hz", gt=f_lo, le=top)
    cap = min(checks.integer("max_lines", max_lines, ge=1), int(FILL * (f_hi - f_lo) / f_lo))
    a_ref = math.sqrt(2.0 * np.mean((x - x.mean()) ** 2))
    if a_ref == 0.0 and not constant_ok:
        checks.fail("x", x, "must not be constant: there is no line to fit")
    return _Options(f_L, f_H, f_lo, f_hi, f_lo, max(cap, 1), checks.integer("max_m", max_m, ge=0),
                    checks.integer("max_n", max_n, ge=0), checks.positive("z", z),
                    checks.number("relative_floor", relative_floor, ge=0.0, lt=1.0) * a_ref,
                    None if max_kept is None else checks.integer("max_kept", max_kept, ge=1))


@dataclass(frozen=True)
class FitOptions:
    """How :func:`fit_lines` chooses, fits and keeps lines (the defaults are the module docstring's).

    Parameters
    ----------
    torus : (int, int), optional
        Sub-harmonic orders (k, j) to use; default: found (module docstring).
    f_max : float, optional
        Highest candidate frequency (Hz); default the Nyquist frequency minus c/T.
    max_m, max_n : int
        ``|m| <= max_m``, ``|n| <= max_n`` (multiples of f_H and f_L, fractions allowed).
    max_subharmonic : int
        Largest sub-harmonic order k, j searched (1 searches nothing).
    resolution : float
        c >= 1: candidates closer than c/T are one line (-).
    z : float
        Significance: a line needs ``amplitude > z * standard_error`` (-).
    relative_floor : float
        ... and ``amplitude >= relative_floor * sqrt(2) rms(x - mean)`` (-).
    max_lines : int
        Most candidate lines fitted.
    n_unlabelled : int
        Residual peaks reported.
    max_kept : int, optional
        Keep at most this many lines, the largest amplitudes among the significant ones, refitted
        alone (module docstring, "Parsimony"); default: every significant line.
    """

    torus: tuple[int, int] | None = None
    f_max: float | None = None
    max_m: int = 8
    max_n: int = 8
    max_subharmonic: int = MAX_SUBHARMONIC
    resolution: float = RESOLUTION
    z: float = Z_SIGNIFICANCE
    relative_floor: float = RELATIVE_FLOOR
    max_lines: int = MAX_LINES
    n_unlabelled: int = 10
    max_kept: int | None = None


def _checked_fit_options(options) -> FitOptions:
    if options is None:
        return FitOptions()
    if not isinstance(options, FitOptions):
        checks.fail("options", type(options).__name__, "must be a FitOptions")
    return options


def fit_lines(t, x, f_L: float, f_H: float, *, options: FitOptions | None = None) -> LineFit:
    """Fit the combination lines ``(m/k) f_H + (n/j) f_L`` of a record by least squares.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform sample times (s), N >= 8.
    x : array_like, shape (N,)
        Samples (any units, e.g. m).
    f_L, f_H : float
        Spool frequencies (Hz), > 0.
    options : FitOptions, optional
        The sub-harmonic orders, candidates, significance and parsimony of the fit (default ``FitOptions()``).

    Returns
    -------
    LineFit

    Raises
    ------
    InputError
        If the record is not uniform or too short, ``f_L`` or ``f_H`` is not > 0, or an option is out of range.
    """
    grid, x = _record(t, x)
    o = _checked_fit_options(options)
    opts = _options(grid, x, f_L, f_H, o.f_max, o.max_m, o.max_n, o.resolution, o.z, o.relative_floor, o.max_lines,
                    o.max_kept)
    max_sub = checks.integer("options.max_subharmonic", o.max_subharmonic, ge=1, le=12)
    energy = float(np.sum((x - x.mean()) ** 2))
    if o.torus is None:
        best, fits = _search(grid, x, opts, max_sub, energy)
    else:
        k, j = checks.sequence("options.torus", o.torus, lambda f, v: checks.integer(f, v, ge=1, le=12),
                               min_len=2, max_len=2)
        best = _fit_torus(grid, x, opts, k, j)
        fits = (best,)
    return _line_fit(grid, x, opts, best, fits, energy, checks.integer("options.n_unlabelled", o.n_unlabelled, ge=0))


def fit_peaks(t, x, f_L: float, f_H: float, *, spectrum: Spectrum | None = None, threshold: float = 0.005,
              torus=(1, 1), max_m: int = 8, max_n: int = 8, resolution: float = RESOLUTION) -> LineFit:
    """The lines at the peaks of an amplitude spectrum, labelled and fitted by least squares as :func:`fit_lines` does.

    The spectrum's peaks (:func:`rotorred.signals.lines.find_peaks`) only propose candidates: the lines are
    those of :func:`fit_lines` (the torus's candidates, merged within c/T, labelled by the priority of the module
    docstring) within half a bin of a peak, fitted together at their exact frequencies on the spectrum's samples.
    A peak no line is near is kept in ``unlabelled`` at its bin. Where :func:`fit_lines` keeps the same lines,
    both give the same labels, frequencies and amplitudes (to round-off on a commensurate record).

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform sample times (s).
    x : array_like, shape (N,)
        Samples (any units, e.g. m).
    f_L, f_H : float
        Spool frequencies (Hz), > 0.
    spectrum : Spectrum, optional
        Amplitude spectrum of the last ``spectrum.n_samples`` samples of ``x`` (the samples fitted), with
        ``spectrum.dt`` the sample interval; default :func:`rotorred.signals.spectra.settled_spectrum` (the last
        whole common periods on a rectangular window, else flat-top).
    threshold : float
        Peaks below ``threshold`` times the spectrum's largest non-DC amplitude are ignored, in (0, 1] (-;
        default 0.005, 0.5 %).
    torus : (int, int)
        Sub-harmonic orders (k, j) of the candidates ``(m/k) f_H + (n/j) f_L``; (1, 2) admits the half-integer
        multiples of f_L of the paper's experiment (f_H + 3f_L/2).
    max_m, max_n : int
        ``|m| <= max_m``, ``|n| <= max_n``.
    resolution : float
        c >= 1: candidates closer than c/T are one line (T the fitted duration).

    Returns
    -------
    LineFit
        The lines at the peaks, by increasing frequency (``n_significant``: how many); ``unlabelled`` the peaks at
        no line, by increasing frequency; ``explained_share`` that of these lines.

    Raises
    ------
    InputError
        If the record is not uniform, ``f_L`` or ``f_H`` is not > 0, ``spectrum`` is not of the record's last
        samples, or a setting is out of range.
    """
    grid, x = _record(t, x)
    f_L = checks.positive("f_L", f_L, "Hz")
    f_H = checks.positive("f_H", f_H, "Hz")
    if spectrum is None:
        spectrum = settled_spectrum(x, grid.dt, f_L, f_H)
    elif not isinstance(spectrum, Spectrum) or spectrum.n_samples > grid.n \
            or abs(spectrum.dt - grid.dt) > 1e-9 * grid.dt:
        checks.fail("spectrum", spectrum, f"must be a Spectrum of the last samples of x (at most {grid.n}, "
                    f"dt = {grid.dt:.6g} s)")
    n = spectrum.n_samples
    grid, x = _Grid(grid.t0 + (grid.n - n) * grid.dt, grid.dt, n), x[grid.n - n:]
    k, j = checks.sequence("torus", torus, lambda f, v: checks.integer(f, v, ge=1, le=12), min_len=2, max_len=2)
    opts = _options(grid, x, f_L, f_H, None, max_m, max_n, resolution, Z_SIGNIFICANCE, 0.0, MAX_LINES,
                    constant_ok=True)
    mp, nq, f, _ = _candidates(opts, k, j)
    line_of, line_freqs = _merge(f, opts.resolution_hz, opts.cap)
    tol = 0.5 * spectrum.df * (1.0 + 1e-9)  # a tone peaks within half a bin (windows of monotonic kernels)
    chosen, unlabelled = set(), []
    for b in find_peaks(spectrum, threshold):
        near = np.flatnonzero((np.abs(f - spectrum.frequencies[b]) <= tol) & (line_of >= 0))  # by priority
        if near.size:
            chosen.add(int(line_of[near[0]]))
        else:
            unlabelled.append(UnlabelledPeak(float(spectrum.frequencies[b]), float(spectrum.amplitudes[b])))
    keep = np.array(sorted(chosen), dtype=int)
    sol = _solve(grid, x, line_freqs[keep])
    scale = _local_noise_scale(grid, sol, line_freqs[keep])
    fit = _torus_fit(k, j, mp, nq, line_of, line_freqs, keep, sol, tuple(e * scale for e in sol.amplitude_errors),
                     int(keep.size))
    return _line_fit(grid, x, opts, fit, (fit,), float(np.sum((x - x.mean()) ** 2)), 0, tuple(unlabelled))


def _line_fit(grid: _Grid, x: np.ndarray, opts: _Options, best: _TorusFit, fits: tuple, energy: float,
              n_unlabelled: int, unlabelled: tuple[UnlabelledPeak, ...] | None = None) -> LineFit:
    """Assemble the :class:`LineFit` of the chosen torus fit; ``unlabelled`` default: the residual's strongest
    ``n_unlabelled`` peaks."""
    sol = best.solution
    se_a, se_p = best.errors
    a = np.abs(sol.z)
    lines = [FittedLine(float(f), float(ai), float(np.angle(zi)), float(sa), float(sp),
                        float(grid.n * ai * ai / 2.0 / energy) if energy > 0 else math.nan, orders)
             for f, ai, zi, sa, sp, orders in zip(best.freqs, a, sol.z, se_a, se_p, best.orders)]
    lines.sort(key=lambda ln: ln.frequency_hz)
    spec = amplitude_spectrum(sol.residual, grid.dt, window="hann")
    if unlabelled is None:
        unlabelled = residual_peaks(spec, f_min=opts.f_lo, f_max=opts.f_hi, floor=opts.floor, n_peaks=n_unlabelled)
    trials = tuple(TorusTrial(ft.k, ft.j, int(ft.freqs.size), _explained(ft.solution.rss, energy), ft.bic(energy))
                   for ft in fits)
    p = 2 * best.freqs.size + 1
    return LineFit(
        lines=tuple(lines), torus=Torus(opts.f_L, opts.f_H, best.k, best.j),
        explained_share=_explained(sol.rss, energy), mean=sol.mean, unlabelled=unlabelled, residual=sol.residual,
        residual_spectrum=spec, trials=trials, t0=grid.t0, dt=grid.dt, n_samples=grid.n,
        resolution_hz=opts.resolution_hz, noise_rms=math.sqrt(sol.rss / max(grid.n - p, 1)),
        n_candidates=best.n_candidates, n_significant=best.n_significant)


def _explained(rss: float, energy: float) -> float:
    """``1 - rss / energy``; NaN for a constant record (no energy to explain)."""
    return 1.0 - rss / energy if energy > 0 else math.nan
