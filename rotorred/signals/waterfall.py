"""Waterfall (spectrogram) of a run-up: amplitude spectra of overlapping time segments (pyFFTW).

Each segment of ``segment`` seconds (50 % overlap) is Hann-windowed and transformed by
:func:`rotorred.signals.spectra.amplitude_spectrum` (pyFFTW plans, cached per length); the spectra
are read against the time of the segment's centre, and the order lines ``k Omega_s(t) / 2 pi``
of each spool are drawn over them by the plot.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotorred import checks
from rotorred.signals.spectra import amplitude_spectrum


@dataclass(frozen=True)
class Waterfall:
    """Spectra of overlapping segments.

    Attributes
    ----------
    t : ndarray, shape (n_segments,)
        Centre time of each segment (s).
    frequencies : ndarray, shape (n_bins,)
        Bin frequencies (Hz).
    amplitudes : ndarray, shape (n_segments, n_bins)
        Peak amplitude of each bin (signal units; Hann window, up to 1.42 dB scalloping).
    segment : float
        Segment length (s); the bin width is 1 / segment.
    """

    t: np.ndarray
    frequencies: np.ndarray
    amplitudes: np.ndarray
    segment: float


def waterfall(t, x, segment: float = 0.25, f_max: float | None = None) -> Waterfall:
    """The waterfall of ``x`` sampled at the uniform times ``t`` (s).

    Parameters
    ----------
    t : array_like, shape (n,)
        Uniform sample times (s).
    x : array_like, shape (n,)
    segment : float
        Segment length (s), 50 % overlap.
    f_max : float, optional
        Keep the bins up to this frequency (Hz).
    """
    t = checks.vector("t", t, "s", min_len=4, increasing=True)
    x = checks.array("x", x, t.shape)
    segment = checks.positive("segment", segment, "s")
    dt = (t[-1] - t[0]) / (len(t) - 1)
    m = int(round(segment / dt))
    if m < 8 or m > len(t):
        checks.fail("segment", segment, f"must hold 8 to {len(t)} samples of {dt:g} s (the record)", "s")
    hop = m // 2
    starts = range(0, len(t) - m + 1, hop)
    spectra = [amplitude_spectrum(x[i:i + m], dt, "hann") for i in starts]
    f = spectra[0].frequencies
    keep = f <= (f_max if f_max is not None else f[-1])
    return Waterfall(t=np.array([t[i] + 0.5 * (m - 1) * dt for i in starts]), frequencies=f[keep],
                     amplitudes=np.array([s.amplitudes[keep] for s in spectra]), segment=m * dt)
