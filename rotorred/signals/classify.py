"""Classification of a dual-rotor response: periodic, period-k, quasi-periodic, chaotic, unsettled.

Every rule works on the settled part of the record (from the settling time of
:func:`rotorred.signals.settling.settling_time` to the end) and on the line fit of that part
(:func:`rotorred.signals.linefit.fit_lines`, torus found by the tool). In order:

1. **unsettled**: the record has not settled (:class:`rotorred.signals.settling.Settling`), and
   rule 2 does not hold on its last half. A chaotic response never settles line by line, so
   rule 2 is tried first on the last half; anything else that has not settled is not
   classified as if it had.
2. **chaotic**: three independent tests all hold. (a) The residual is large: the lines explain
   less than ``explained_min`` (0.9) of the energy. (b) It is broadband: the residual's ten
   strongest peaks (each with +-1 bin) hold less than ``broadband_max`` (0.9) of the residual's
   Hann spectral energy, so the residual is not a few missed lines (a torus the search did not
   reach): a stationary line holds at least 98 % of its Hann spectral energy within +-1 bin of
   its peak (100 % on a bin, 98 % half a bin off), a chaotic residual 57-87 % in its ten
   strongest peaks (measured on the Duffing oscillator, 1000 down to 150 forcing periods: the
   shorter the record, the more line-like its peaks). (c) The 0-1 test for chaos (Gottwald and
   Melbourne) on the Poincare samples gives ``K >= chaos_K`` (0.8): K tends to 1 for chaos and
   to 0 for periodic and quasi-periodic motion (with probability one); 0.8 leaves room for the
   finite-sample K of chaos (measured 0.83-0.99 on 190-250 Duffing samples, 0.95-0.99 on 500)
   and of regular motion (|K| < 0.1).
3. **periodic / period-k**: the lines explain at least ``explained_min`` and the frequencies of
   the lines that carry at least 0.1 % of the energy (a chance line, 5 standard errors, can pass
   the significance test on a long record; it must not decide the structure) span a
   one-dimensional lattice: all are multiples of one fundamental f_1, computed exactly with
   fractions (for commensurate speeds ``f_H/f_L = p/q`` every line is ``u g``, u a fraction,
   ``g = gcd(f_L, f_H)``, and ``f_1 = gcd(u) g``). The forcing repeats every ``1/g``; the response
   every ``k/g`` with k the denominator of ``f_1 / g``: k = 1 is **periodic** with period
   ``1/g``, k > 1 is **period-k**, period ``k/g``. For speeds that are not commensurate the same
   holds along the one combination ``a f_H + b f_L`` (a, b coprime integers) the lines lie on.
   The 0.9 threshold: the tori that describe the rig's response off 70/90 Hz explain 91-97 %
   of its energy, the ones that do not describe it at most 84 %.
4. **quasi-periodic**: the lines explain at least ``explained_min`` and span a two-dimensional
   lattice (two incommensurate base frequencies ``f_H/k``, ``f_L/j``), confirmed on the Poincare
   section: the samples taken once per period of ``f_H/k`` (every k revolutions of the outer
   spool), ordered by the phase ``theta = 2 pi (f_L/j) t`` of the other base, lie on one closed
   curve: Fourier series in theta with as many harmonics as the lines need (H,
   the largest multiple of ``f_L/j`` among them) explain at least ``explained_min`` of their
   variance. With fewer than ``4 (2H + 1)`` samples the curve cannot be tested and
   the line fit alone decides.
5. **unexplained**: none of the above. The lines explain too little and the residual is not
   chaotic by rules 2b-2c (e.g. a torus of higher order, or three frequencies): the response is
   said to be unexplained rather than labelled by force.

Poincare samples
    The state is sampled once per period of the section frequency: ``g = gcd(f_L, f_H)`` for
    commensurate speeds (a period-k response shows k points), else ``f_H / k``, once per k
    revolutions of the outer spool, k the torus's sub-harmonic order of f_H (the section of the
    anchors, once per revolution, when k = 1). Once per revolution, a 2-torus with k = 3 would
    show three interleaved closed curves, and the 0-1 test reads their interleaving as
    irregular (measured K = 0.86 on the rig at outer 88.8 Hz, 8 s); once per k revolutions the
    samples lie on one closed curve. Sample times are whole multiples of the period
    in the record's own time, so the section is at phase 0 of that base. x (and y) are
    interpolated by a not-a-knot cubic spline and the velocity is its derivative. For the
    complete cubic spline the error is at most ``5/384 h^4 max|x''''|``, and
    ``(sqrt(3)/216 + 1/24) h^3 max|x''''|`` for the derivative (Hall and Meyer 1976);
    ``max|x''''|`` is estimated by the fourth differences of the samples, so the stated bounds
    are ``5/384 max|Delta^4 x|`` (about ``(5/384) (2 pi f dt)^4`` of the amplitude of a line at
    f) and ``0.0497 max|Delta^4 x| / h``. The not-a-knot end conditions disturb the first and
    last intervals (measured: 2x the value bound, 3x the derivative bound at the end node),
    decaying by ``2 - sqrt(3)`` = 0.27 per interval, so no sample is taken within
    ``END_INTERVALS`` = 10 intervals of either end (0.27^10 = 2e-6).

References
----------
.. [1] G. A. Gottwald, I. Melbourne, "On the implementation of the 0-1 test for chaos",
   SIAM J. Appl. Dyn. Syst. 8(1), 2009 (arXiv:0906.1418); "On the validity of the 0-1 test for
   chaos", Nonlinearity 22, 2009 (arXiv:0906.1415).
.. [2] C. A. Hall, W. W. Meyer, "Optimal error bounds for cubic spline interpolation",
   J. Approx. Theory 16, 1976.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from functools import reduce

import numpy as np
import scipy.fft

from rotorred import checks
from rotorred.signals.linefit import FitOptions, LineFit, Torus, commensurate_ratio, fit_lines
from rotorred.signals.settling import Settling, settling_time

__all__ = ["EXPLAINED_MIN", "CHAOS_K", "BROADBAND_MAX", "STRUCTURE_SHARE", "ZERO_ONE_MIN_SAMPLES",
           "PoincareSamples", "Classification", "poincare_samples", "zero_one_test", "classify"]

EXPLAINED_MIN = 0.9  #: regular motion: the lines (or the Poincare curve) explain >= 90 %
CHAOS_K = 0.8  #: chaotic: 0-1 test K >= 0.8
BROADBAND_MAX = 0.9  #: broadband residual: its 10 strongest peaks (+-1 bin) hold < 90 % of its energy
STRUCTURE_SHARE = 1e-3  #: lines with >= 0.1 % of the energy decide periodic / quasi-periodic
ZERO_ONE_MIN_SAMPLES = 100  #: fewer Poincare samples: no 0-1 test (K = NaN)
END_INTERVALS = 10  #: no Poincare sample within 10 intervals of the record's ends (spline end effects)
KINDS = ("periodic", "period-k", "quasi-periodic", "chaotic", "unexplained", "unsettled")


# --------------------------------------------------------------------------- Poincare section
@dataclass(frozen=True)
class PoincareSamples:
    """The state sampled once per period of ``frequency_hz``.

    Attributes
    ----------
    frequency_hz : float
        Section frequency (Hz).
    times : ndarray, shape (n,)
        Sample times (s), whole multiples of ``1 / frequency_hz``.
    x, velocity : ndarray, shape (n,)
        Interpolated response and its time derivative (units of x, and per s).
    y : ndarray or None, shape (n,)
        Second channel (units of ``x``), if given.
    interpolation_error, velocity_error : float
        Bounds of the spline errors (module docstring), units of x and x/s.
    """

    frequency_hz: float
    times: np.ndarray
    x: np.ndarray
    velocity: np.ndarray
    y: np.ndarray | None
    interpolation_error: float
    velocity_error: float


def poincare_samples(t, x, frequency_hz: float, *, t_start: float | None = None, y=None) -> PoincareSamples:
    """Sample a record once per period of ``frequency_hz`` by cubic-spline interpolation.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform sample times (s), N >= 5.
    x : array_like, shape (N,)
        Response (any units).
    frequency_hz : float
        Section frequency (Hz), below the sampling rate.
    t_start : float, optional
        First time considered (s); default ``t[0]``.
    y : array_like, shape (N,), optional
        Second channel (e.g. the other direction of the same node).

    Returns
    -------
    PoincareSamples

    Raises
    ------
    InputError
        If ``t`` is not increasing or has fewer than 5 samples, ``x`` (or ``y``) is not of its shape,
        ``frequency_hz`` is not in (0, 1/dt) or ``t_start`` lies outside the record.
    """
    from scipy.interpolate import CubicSpline  # 0.2 s to import: after a scene's record, not before it

    t = checks.vector("t", t, "s", min_len=5, increasing=True)
    x = checks.vector("x", x, min_len=5)
    if x.shape != t.shape or (y is not None and np.shape(y) != t.shape):
        checks.fail("x", x, f"must have the shape of t, {t.shape} (and so must y)")
    dt = (t[-1] - t[0]) / (t.size - 1)
    f = checks.number("frequency_hz", frequency_hz, "Hz", gt=0.0, lt=1.0 / dt)
    start = t[0] if t_start is None else checks.number("t_start", t_start, "s", ge=t[0], le=t[-1])
    lo, hi = max(start, t[0] + END_INTERVALS * dt), t[-1] - END_INTERVALS * dt
    times = np.arange(math.ceil(lo * f - 1e-9), math.floor(hi * f + 1e-9) + 1) / f
    times = times[(times >= lo) & (times <= hi)]
    spline = CubicSpline(t, x)
    fourth = float(np.max(np.abs(np.diff(x, 4))))
    y_s = None if y is None else CubicSpline(t, checks.vector("y", y))(times)
    return PoincareSamples(f, times, spline(times), spline(times, 1), y_s, 5.0 / 384.0 * fourth,
                           (math.sqrt(3.0) / 216.0 + 1.0 / 24.0) * fourth / dt)


def zero_one_test(phi, *, n_c: int = 100, seed: int = 0) -> float:
    """Gottwald-Melbourne 0-1 test for chaos: K near 1 for chaos, near 0 for regular motion.

    ``p_c(n) = sum_{j<=n} phi_j cos(j c)``, ``q_c(n) = sum_{j<=n} phi_j sin(j c)``; the mean square
    displacement ``M_c(n)`` for ``n <= N/10``, less its oscillatory part
    ``mean(phi)^2 (1 - cos n c) / (1 - cos c)``, is correlated with n; K is the median of the
    correlations over ``n_c`` values of c drawn uniformly in (pi/5, 4 pi/5) (fixed ``seed``, so K is
    reproducible). The recipe of Gottwald and Melbourne 2009; the autocorrelation is computed by FFT.

    Parameters
    ----------
    phi : array_like, shape (N,)
        An observable sampled once per period (Poincare samples, not an oversampled record),
        N >= 100 (Gottwald and Melbourne recommend N >= 1000).
    n_c : int
        Number of values of c.
    seed : int

    Returns
    -------
    float
        K in [-1, 1].
    """
    phi = checks.vector("phi", phi, min_len=ZERO_ONE_MIN_SAMPLES)
    n_c = checks.integer("n_c", n_c, ge=1)
    N = phi.size
    n_cut = N // 10
    c = np.random.default_rng(checks.integer("seed", seed, ge=0)).uniform(np.pi / 5, 4 * np.pi / 5, n_c)
    P = np.cumsum(phi * np.exp(1j * np.outer(c, np.arange(1, N + 1))), axis=1)
    size = scipy.fft.next_fast_len(2 * N)
    F = scipy.fft.fft(P, size, axis=1)
    R = scipy.fft.ifft(np.abs(F) ** 2, axis=1)[:, 1:n_cut + 1].real  # sum_i conj(P_i) P_{i+n}
    sq = np.concatenate((np.zeros((n_c, 1)), np.cumsum(np.abs(P) ** 2, axis=1)), axis=1)
    n = np.arange(1, n_cut + 1)
    head = sq[:, N][:, None] - sq[:, n]  # sum_{i>=n} |P_i|^2
    tail = sq[:, N - n]  # sum_{i<N-n} |P_i|^2
    M = (head + tail - 2.0 * R) / (N - n)
    D = M - phi.mean() ** 2 * (1.0 - np.cos(np.outer(c, n))) / (1.0 - np.cos(c))[:, None]
    Dc = D - D.mean(axis=1, keepdims=True)
    nc = n - n.mean()
    K = (Dc @ nc) / np.sqrt(np.maximum((Dc * Dc).sum(axis=1) * (nc @ nc), np.finfo(float).tiny))
    return float(np.median(K))


# --------------------------------------------------------------------------- structure of the lines
def _fraction_gcd(values) -> Fraction:
    """Greatest common divisor of fractions (the largest f with every value an integer multiple of f)."""
    return reduce(lambda a, b: Fraction(math.gcd(a.numerator * b.denominator, b.numerator * a.denominator),
                                        a.denominator * b.denominator), (abs(Fraction(v)) for v in values))


def _lattice(orders: list[tuple[Fraction, Fraction]], f_L: float, f_H: float):
    """Rank of the lines' lattice and, for rank 1, (reference frequency, k, fundamental (Hz)).

    Rank 1: every line is an integer multiple of ``f_1 = gcd * f_ref``, f_ref the forcing
    frequency along the lattice (``gcd(f_L, f_H)``, or ``|a f_H + b f_L|``); k = denominator.
    """
    if not orders:
        return 0, None
    ratio = commensurate_ratio(f_L, f_H)
    if ratio is not None:
        p, q = ratio.numerator, ratio.denominator
        g = _fraction_gcd([m * p + n * q for m, n in orders])
        return 1, (f_L / q, g.denominator, float(g) * f_L / q)
    m0, n0 = orders[0]
    if any(m * n0 - n * m0 != 0 for m, n in orders):
        return 2, None
    scale = Fraction(math.lcm(m0.denominator, n0.denominator))
    a, b = m0 * scale, n0 * scale
    d = math.gcd(int(a), int(b))
    a, b = int(a) // d, int(b) // d  # primitive integer direction
    lam = _fraction_gcd([m / a if a else n / b for m, n in orders])
    f_ref = abs(a * f_H + b * f_L)
    return 1, (f_ref, lam.denominator, float(lam) * f_ref)


def _section_frequency(torus: Torus) -> float:
    """gcd(f_L, f_H) when commensurate, else f_H / k: once per period of the torus's f_H base (Hz)."""
    ratio = torus.ratio
    return torus.f_L / ratio.denominator if ratio is not None else torus.f_H / torus.k


def _curve_share(samples: PoincareSamples, torus: Torus, orders) -> float | None:
    """Share of the Poincare samples' variance that k closed curves in the phase of f_L/j explain.

    Sampled once per revolution of f_H, a line ``(m'/k) f_H + (n'/j) f_L`` reads
    ``exp(2 pi i m' r / k) exp(i n' theta)`` at revolution number r, ``theta = 2 pi (f_L/j) t``:
    the samples of each residue ``r mod k`` lie on one closed curve, a Fourier series in theta
    with H harmonics (H the largest ``|n'|``); sampled once per k revolutions (the section of
    :func:`classify`, at f_H / k), every sample lies on one curve. None when a curve has fewer than
    ``4 (2H + 1)`` samples.
    """
    H = max((abs(int(n * torus.j)) for _, n in orders), default=0)
    n_curves = max(1, round(torus.k * samples.frequency_hz / torus.f_H))  # k at f_H, 1 at f_H / k
    revolution = np.rint(samples.times * samples.frequency_hz).astype(int)
    theta = 2.0 * np.pi * (torus.f_L / torus.j) * samples.times
    h = np.arange(1, H + 1)
    rss, var = 0.0, float(np.sum((samples.x - samples.x.mean()) ** 2))
    for r in range(n_curves):
        group = revolution % n_curves == r
        if group.sum() < 4 * (2 * H + 1):
            return None
        A = np.hstack([np.ones((group.sum(), 1)), np.cos(np.outer(theta[group], h)), np.sin(np.outer(theta[group], h))])
        coef, *_ = np.linalg.lstsq(A, samples.x[group], rcond=None)
        rss += float(np.sum((samples.x[group] - A @ coef) ** 2))
    return 1.0 - rss / var if var > 0 else 1.0


def _peak_share(fit: LineFit) -> float:
    """Share of the residual's Hann spectral energy in its 10 strongest peaks (+-1 bin each)."""
    spec = fit.residual_spectrum
    power = spec.amplitudes[1:] ** 2
    total = float(power.sum())
    if total == 0.0:
        return 1.0
    mask = np.zeros(power.size, dtype=bool)
    for peak in fit.unlabelled[:10]:
        k = int(round(peak.frequency_hz / spec.df)) - 1
        mask[max(k - 1, 0):k + 2] = True
    return float(power[mask].sum()) / total


# --------------------------------------------------------------------------- classification
@dataclass(frozen=True)
class Classification:
    """Result of :func:`classify`.

    Attributes
    ----------
    kind : str
        One of ``"periodic"``, ``"period-k"``, ``"quasi-periodic"``, ``"chaotic"``,
        ``"unexplained"``, ``"unsettled"``.
    subharmonic : int or None
        k of a periodic (1) or period-k response.
    period : float or None
        Period of a periodic or period-k response (s).
    torus : Torus
        Torus of the line fit.
    explained_share : float
        Of the line fit on the part classified (-).
    zero_one_K : float
        0-1 test on the Poincare samples of x (NaN with fewer than 100 samples).
    curve_share : float or None
        Share of the Poincare samples a smooth closed curve explains (rank-2 lattices only).
    residual_peak_share : float
        Share of the residual's spectral energy in its 10 strongest peaks (-).
    poincare : PoincareSamples
    fit : LineFit
        Line fit of the part classified (the settled part, or the last half).
    settling : Settling
    rules : tuple of str
        Each rule's outcome, in words.
    """

    kind: str
    subharmonic: int | None
    period: float | None
    torus: Torus
    explained_share: float
    zero_one_K: float
    curve_share: float | None
    residual_peak_share: float
    poincare: PoincareSamples
    fit: LineFit
    settling: Settling
    rules: tuple[str, ...]

    @property
    def label(self) -> str:
        """``"period-2"`` for a period-k response, else :attr:`kind`."""
        return f"period-{self.subharmonic}" if self.kind == "period-k" else self.kind


def _evidence(t: np.ndarray, x: np.ndarray, y, f_L: float, f_H: float, start: float, options):
    """Line fit, Poincare samples, 0-1 test K and residual peak share of the record from ``start``."""
    part = t >= start
    fit = fit_lines(t[part], x[part], f_L, f_H, options=options)
    samples = poincare_samples(t[part], x[part], _section_frequency(fit.torus), y=None if y is None else y[part])
    K = zero_one_test(samples.x) if samples.x.size >= ZERO_ONE_MIN_SAMPLES else math.nan
    return fit, samples, K, _peak_share(fit)


def _regular_kind(fit: LineFit, samples: PoincareSamples, explained_min: float, rules: list[str]):
    """(kind, k, period, curve_share) of a response its lines explain; rules appended."""
    orders = [ln.orders[0] for ln in fit.lines if ln.share >= STRUCTURE_SHARE]
    rank, periodic = _lattice(orders, fit.torus.f_L, fit.torus.f_H)
    if rank == 1:
        f_ref, k, f_1 = periodic
        rules.append(f"rule 3: the lines are multiples of {f_1:.6g} Hz; the forcing repeats at {f_ref:.6g} Hz, "
                     f"the response every {k} forcing period(s)")
        return ("periodic" if k == 1 else "period-k"), k, k / f_ref, None
    curve = _curve_share(samples, fit.torus, orders) if rank == 2 else None
    if rank == 2 and (curve is None or curve >= explained_min):
        rules.append("rule 4: lines on a 2-torus " + fit.torus.label + "; Poincare curve " +
                     ("not testable (too few samples): the line fit decides" if curve is None
                      else f"explains {curve:.4f} >= {explained_min:g}"))
        return "quasi-periodic", None, None, curve
    rules.append(f"rule 4: lattice of rank {rank}; Poincare curve share {curve} < {explained_min:g}")
    return "unexplained", None, None, curve


def classify(t, x, f_L: float, f_H: float, *, y=None, settling: Settling | None = None,
             explained_min: float = EXPLAINED_MIN, chaos_K: float = CHAOS_K, broadband_max: float = BROADBAND_MAX,
             options: FitOptions | None = None) -> Classification:
    """Classify a response as periodic, period-k, quasi-periodic, chaotic, unexplained or unsettled.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform sample times (s).
    x : array_like, shape (N,)
        Response (any units, e.g. m).
    f_L, f_H : float
        Spool frequencies (Hz).
    y : array_like, shape (N,), optional
        Second channel (units of ``x``), sampled into the Poincare section too.
    settling : Settling, optional
        Of this record; default :func:`rotorred.signals.settling.settling_time` with its defaults.
    explained_min, chaos_K, broadband_max : float
        Thresholds of the rules (-; module docstring).
    options : FitOptions, optional
        Of :func:`rotorred.signals.linefit.fit_lines`.

    Returns
    -------
    Classification

    Raises
    ------
    InputError
        If ``t`` is not increasing or has fewer than 32 samples, a threshold is out of range, or ``settling``
        is not a :class:`Settling`.
    """
    t = checks.vector("t", t, "s", min_len=32, increasing=True)
    x = checks.vector("x", x, min_len=32)
    y = None if y is None else checks.vector("y", y)
    explained_min = checks.number("explained_min", explained_min, gt=0.0, lt=1.0)
    chaos_K = checks.number("chaos_K", chaos_K, gt=0.0, le=1.0)
    broadband_max = checks.number("broadband_max", broadband_max, gt=0.0, le=1.0)
    if settling is None:
        settling = settling_time(t, x, f_L, f_H, options=options)
    elif not isinstance(settling, Settling):
        checks.fail("settling", settling, "must be a Settling (from settling_time)")
    start = settling.time if settling.settled else 0.5 * (t[0] + t[-1])
    fit, samples, K, peak_share = _evidence(t, x, y, f_L, f_H, start, options)
    eta = fit.explained_share
    rules = [f"rule 1: {settling.reason}"]
    chaotic = eta < explained_min and peak_share < broadband_max and K >= chaos_K
    rules.append(f"rule 2: explained {eta:.4f} {'<' if eta < explained_min else '>='} {explained_min:g}, "
                 f"residual peak share {peak_share:.3f} {'<' if peak_share < broadband_max else '>='} "
                 f"{broadband_max:g}, 0-1 test K = {K:.3f} {'>=' if K >= chaos_K else '<'} {chaos_K:g}"
                 f"{': chaotic' if chaotic else ''}")
    kind, k, period, curve = ("chaotic", None, None, None) if chaotic else ("unsettled", None, None, None)
    if not chaotic and settling.settled:
        if eta >= explained_min:
            kind, k, period, curve = _regular_kind(fit, samples, explained_min, rules)
        else:
            kind = "unexplained"
            rules.append(f"rule 5: the lines explain {eta:.4f} < {explained_min:g} and the residual is not chaotic")
    return Classification(kind, k, period, fit.torus, eta, K, curve, peak_share, samples, fit, settling,
                          tuple(rules))
