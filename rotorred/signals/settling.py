"""Measured settling: when the line amplitudes of a response stop changing.

A rotor started from rest, or after a change of speed, carries a transient (free vibration at
its natural frequencies, a slow drift of the orbit centre) that decays into the settled
response. :func:`settling_time` measures when that has happened instead of assuming it from a
fixed record start.

Method
    1. Fit the lines on the last quarter of the record (:func:`rotorred.signals.linefit.fit_lines`,
       torus found or given), or take a given ``reference`` fit of the record's end (a longer
       record resolves more: a scene passes its fit of the last whole common periods, where the
       last quarter of a 0.6 s record would resolve only 13 Hz): their frequencies, and those of the residual's strongest peaks (the
       unlabelled lines, at their interpolated frequencies, when at least c/T from every line and,
       for commensurate speeds, from every multiple of the torus's base: a peak nearer a multiple
       of the base than the resolution is that multiple's leakage, not a tone of its own),
       are tracked, unchanged, in every window. Tracking the unlabelled lines too keeps a
       settled component the torus does not explain from leaking into the lines' coefficients
       (by ``1 / (pi df W)`` for a component df from a line) and making them beat from window to
       window.
    2. Window length: at least ``c / df_min`` (c = 2, df_min the closest pair of tracked
       frequencies, or the lowest one's distance from 0), so that they stay resolved in every
       window (the fit's condition stays <= 3, see :mod:`rotorred.signals.linefit`); and, for
       commensurate speeds, a whole number of periods of the torus's common base, at least
       ``N_BASE_PERIODS`` = 2 (docs/benchmarks.md's two common periods at 70/90 Hz): every line is then
       orthogonal to the others in every window; for speeds that are not commensurate, at least
       ``n_cycles`` = 10 periods of the slowest labelled line, so that the window mean square of
       a component ripples by at most ``1 / (2 pi n_cycles)`` = 1.6 % (0.8 % in rms) from the
       non-whole number of cycles. Windows step back from the end by ``W / 4``, the resolution
       of the settling time.
    3. In each window fit the tracked lines (:func:`rotorred.signals.linefit.fit_frequencies`) and
       form its state ``s = (a_l, sqrt(2) mean, sqrt(2) rms(residual))``: the line amplitudes,
       the offset and the residual level, all on the amplitude scale of a sinusoid (a line of
       amplitude a has rms a / sqrt(2)). The residual and the offset are included because a
       rotor's transient is mostly free vibration at frequencies that are not lines, and a drift
       of the orbit centre. The phases are left out: a component whose true frequency differs
       by delta from the line that tracks it (any unexplained line within the resolution of the
       last-quarter fit) turns its phase by ``2 pi delta t`` in a settled response.
    4. Relative change of window i against the last window:
       ``d_i = |s_i - s_last| / |s_last without the offset|``.
    5. A window agrees with the last when ``d <= tol``, or when the change is within
       ``Z_CHANGE`` = 3 standard errors of the two window fits (least-squares errors of the
       amplitudes, offset and residual level): a change smaller than the estimates' own scatter
       is not measured. This matters when the residual is large: a settled component that no
       tracked frequency fits exactly (an unexplained tone) makes the window amplitudes scatter
       by a few per cent, within their standard errors.
    6. Settled from the earliest window from which every later window agrees, provided
       that run spans at least two disjoint windows (the last window alone agrees with itself):
       otherwise the response has not settled by the end of the record (``settled = False``).
       The settling time is the start of that earliest window.

Tolerance
    ``tol`` = 0.02, the 2 % settling time of control engineering (``4 tau`` for a first-order
    decay): amplitudes within 2 % (0.17 dB) of their final values, finer than a Hann spectrum
    reads a line between bins (1.42 dB).

References
----------
.. [1] K. Ogata, *Modern Control Engineering*, 5th ed., Sec. 5-3 (2 % settling time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotorred import checks
from rotorred.signals.linefit import FitOptions, LineFit, fit_frequencies, fit_lines

__all__ = ["TOLERANCE", "N_CYCLES", "STEP_FRACTION", "Z_CHANGE", "Settling", "settling_time"]

TOLERANCE = 0.02  #: 2 % settling: window states within 2 % of the last window's
N_CYCLES = 10  #: window = 10 periods of the slowest labelled line (or longer, to resolve the lines)
N_BASE_PERIODS = 2  #: for commensurate speeds: at least 2 whole periods of the common base
STEP_FRACTION = 0.25  #: windows step back by W/4
Z_CHANGE = 3.0  #: a change within 3 standard errors of the window fits is not a measured change


@dataclass(frozen=True)
class Settling:
    """Result of :func:`settling_time`.

    Attributes
    ----------
    settled : bool
        True when the run of windows agreeing with the last one spans two disjoint windows.
    time : float
        Settling time (s): start of the earliest agreeing window; NaN when not settled.
    tol : float
        Relative tolerance used (-).
    window, step : float
        Window length and step (s).
    starts : ndarray, shape (n_windows,)
        Window start times (s), increasing.
    changes : ndarray, shape (n_windows,)
        Relative change of each window's state against the last window (the last is 0).
    frequencies_hz : ndarray, shape (L,)
        Tracked frequencies (Hz): the reference's lines and unlabelled peaks.
    reference : LineFit or None
        Fit on the last quarter of the record that chose the lines.
    reason : str
        Why the response is (not) settled, in words.
    """

    settled: bool
    time: float
    tol: float
    window: float
    step: float
    starts: np.ndarray
    changes: np.ndarray
    frequencies_hz: np.ndarray
    reference: LineFit | None
    reason: str


def _tracked(reference: LineFit) -> np.ndarray:
    """Frequencies (Hz) of the reference's lines and of its residual peaks at least c/T from them
    (and, for commensurate speeds, from every multiple of the torus's base)."""
    freqs = list(reference.frequencies_hz)
    bases = reference.torus.bases
    for peak in reference.unlabelled:
        f = peak.frequency_hz
        near_lattice = len(bases) == 1 and abs(f - bases[0] * round(f / bases[0])) < reference.resolution_hz
        if not near_lattice and all(abs(f - g) >= reference.resolution_hz for g in freqs):
            freqs.append(f)
    return np.sort(np.array(freqs))


def _reference(t: np.ndarray, x: np.ndarray, f_L: float, f_H: float, reference: LineFit | None,
               options) -> LineFit:
    """The given reference fit, checked against the record, or the fit of the record's last quarter."""
    if reference is None:
        quarter = t.size // 4
        return fit_lines(t[-quarter:], x[-quarter:], f_L, f_H, options=options)
    if not isinstance(reference, LineFit):
        checks.fail("reference", reference, "must be a LineFit (from fit_lines)")
    if not np.allclose((reference.torus.f_L, reference.torus.f_H), (f_L, f_H), rtol=1e-12, atol=0.0):
        checks.fail("reference", f"f_L = {reference.torus.f_L:g}, f_H = {reference.torus.f_H:g}",
                    f"must be fitted at this record's spool frequencies (f_L = {f_L:g}, f_H = {f_H:g})", "Hz")
    t_end = reference.t0 + (reference.n_samples - 1) * reference.dt
    if reference.t0 < t[0] - 0.5 * reference.dt or abs(t_end - t[-1]) > 0.5 * reference.dt:
        checks.fail("reference", f"{reference.t0:g} to {t_end:g}",
                    f"must be a fit of the end of this record ({t[0]:g} to {t[-1]:g})", "s")
    return reference


def _default_window(reference: LineFit, tracked: np.ndarray, n_cycles: float, resolution: float) -> float:
    """Default window (s): long enough to resolve the tracked frequencies (``c / df_min``, df_min
    the closest pair or the lowest one's distance from 0) and ``N_BASE_PERIODS`` whole periods of
    the common base (commensurate speeds), or ``n_cycles`` periods of the slowest labelled line."""
    resolved = resolution / float(np.diff(np.r_[0.0, np.sort(tracked)]).min())
    bases = reference.torus.bases
    if len(bases) == 1:
        period = 1.0 / bases[0]
        return period * max(N_BASE_PERIODS, math.ceil(resolved / period - 1e-9))
    lines = reference.frequencies_hz
    return max(n_cycles / float((lines if lines.size else tracked).min()), resolved)


def _window_states(t: np.ndarray, x: np.ndarray, freqs: np.ndarray, n_window: int, n_step: int,
                   resolution: float):
    """Start indices (from the end back), states, shape (n_windows, L + 2), and their standard errors.

    The standard error of a state is ``sqrt(sum SE(a_l)^2 + 2 sigma^2 / n + sigma^2 / n)``: the
    amplitudes' (least squares), the offset's and the residual level's (``rms / sqrt(2 n)``), on
    the state's sqrt(2) scale.
    """
    starts = np.arange(t.size - n_window, -1, -n_step)
    states, errors = [], []
    for i0 in starts:
        fit = fit_frequencies(t[i0:i0 + n_window], x[i0:i0 + n_window], freqs, resolution=resolution)
        extra = math.sqrt(2.0) * np.array([fit.mean, fit.residual_rms])
        states.append(np.concatenate((fit.amplitudes, extra)))
        sigma2 = fit.residual_rms ** 2 * n_window / max(n_window - 2 * freqs.size - 1, 1)
        errors.append(math.sqrt(float(np.sum(fit.standard_errors ** 2)) + 3.0 * sigma2 / n_window))
    return starts, np.array(states), np.array(errors)


def _not_settled(reason: str, tol: float, reference: LineFit | None, freqs: np.ndarray,
                 window: float = math.nan, step: float = math.nan) -> Settling:
    return Settling(False, math.nan, tol, window, step, np.zeros(0), np.zeros(0), freqs, reference, reason)


def settling_time(t, x, f_L: float, f_H: float, *, tol: float = TOLERANCE, window: float | None = None,
                  n_cycles: float = N_CYCLES, reference: LineFit | None = None,
                  options: FitOptions | None = None) -> Settling:
    """When the line amplitudes (and the offset and residual level) of a response stop changing.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform sample times (s).
    x : array_like, shape (N,)
        Response (any units, e.g. m).
    f_L, f_H : float
        Spool frequencies (Hz).
    tol : float
        Relative tolerance of the window states, in (0, 1) (-); default 0.02 (module docstring).
    window : float, optional
        Window length (s); default: module docstring, step 2.
    n_cycles : float
        Periods of the slowest labelled line in a default window (speeds not commensurate), > 0 (-).
    reference : LineFit, optional
        A fit of the end of this record (same f_L, f_H) that chooses the tracked lines, in place
        of the fit of the last quarter (``options`` are then not used for it).
    options : FitOptions, optional
        Of :func:`rotorred.signals.linefit.fit_lines` (``torus``: the sub-harmonic orders, default found on the last
        quarter of the record; ``resolution``, ``z``, ...).

    Returns
    -------
    Settling

    Raises
    ------
    InputError
        If ``t`` is not increasing or has fewer than 32 samples, or ``tol``, ``n_cycles`` or ``window`` is out of
        range.
    """
    t = checks.vector("t", t, "s", min_len=32, increasing=True)
    x = checks.vector("x", x, min_len=32)
    tol = checks.number("tol", tol, gt=0.0, lt=1.0)
    n_cycles = checks.positive("n_cycles", n_cycles)
    reference = _reference(t, x, f_L, f_H, reference, options)
    freqs = _tracked(reference)
    if freqs.size == 0:
        return _not_settled("no significant line on the last quarter of the record to track", tol, reference, freqs)
    dt = (t[-1] - t[0]) / (t.size - 1)
    resolution = (options or FitOptions()).resolution
    w = (_default_window(reference, freqs, n_cycles, resolution) if window is None
         else checks.positive("window", window, "s"))
    n_window = int(math.ceil(w / dt - 1e-9))
    n_step = max(1, int(round(STEP_FRACTION * n_window)))
    if 2 * n_window > t.size:
        return _not_settled(f"record too short: {t.size * dt:.4g} s holds fewer than two windows of {w:.4g} s",
                            tol, reference, freqs, w, n_step * dt)
    starts, states, errors = _window_states(t, x, freqs, n_window, n_step, resolution)
    scale = np.linalg.norm(np.delete(states[0], -2))
    changes = np.linalg.norm(states - states[0], axis=1) / scale
    allowed = np.maximum(tol, Z_CHANGE * np.hypot(errors, errors[0]) / scale)
    run = int(np.argmax(changes > allowed)) if np.any(changes > allowed) else changes.size
    last_agreeing = run - 1
    settled = last_agreeing * n_step >= n_window
    order = slice(None, None, -1)  # report in increasing time
    if not settled:
        reason = (f"not settled: the window from {t[starts[run]]:.4g} s differs from the last by {changes[run]:.3g} "
                  f"> {allowed[run]:.3g} (tol = {tol:g} or 3 standard errors), less than two windows ({2 * w:.4g} s) "
                  "before the end" if run < changes.size
                  else f"record too short: the windows span less than two windows of {w:.4g} s")
        return Settling(False, math.nan, tol, w, n_step * dt, t[starts][order], changes[order], freqs, reference,
                        reason)
    t_s = float(t[starts[last_agreeing]])
    reason = (f"settled from {t_s:.4g} s: every window from there on is within tol = {tol:g} of the last "
              f"(window {w:.4g} s, step {n_step * dt:.4g} s)")
    return Settling(True, t_s, tol, w, n_step * dt, t[starts][order], changes[order], freqs, reference, reason)
