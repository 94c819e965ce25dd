"""How far one record of a response is from another: the error measure of ``[solver] tolerance``.

A scene reports each recorded DOF's amplitude spectrum (its lines, the paper's Table 1) and its
peak; for a rubbing rotor a pointwise time-history error says little (a small phase drift of a
high line dominates it), so the error of a record ``x`` against a reference ``x_ref`` of the same
window is the larger of

* the **spectral error** ``max_f |A(f) - A_ref(f)| / max_f A_ref(f)`` over ``0 <= f <= f_max`` (every bin,
  relative to the DOF's largest line), spectra by :func:`rotorred.signals.spectra.settled_spectrum`;
* the **peak error** ``|max |x| - max |x_ref|| / max |x_ref|``.

Records of different time steps are compared on the reference's bins (the spectrum of the
other interpolated onto them when the bins differ, e.g. a windowed, non-commensurate record).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotorred.signals.spectra import settled_spectrum

__all__ = ["RecordError", "record_error", "outputs_error"]


@dataclass(frozen=True)
class RecordError:
    """The error of a record against a reference (module docstring).

    Attributes
    ----------
    error : float
        ``max(spectral, peak)``.
    spectral, peak : float
        The two measures.
    frequency_hz : float
        Bin of the largest spectral error (Hz).
    dof : tuple
        The DOF (for :func:`outputs_error`, the worst one).
    """

    error: float
    spectral: float
    peak: float
    frequency_hz: float
    dof: tuple = ()


def record_error(x: np.ndarray, dt: float, x_ref: np.ndarray, dt_ref: float, f_L: float, f_H: float,
                 f_max: float, dof: tuple = ()) -> RecordError:
    """Error of record ``x`` (sampled at ``dt``) against ``x_ref`` (at ``dt_ref``), both over the same window.

    Parameters
    ----------
    x, x_ref : ndarray, shape (n,), (n_ref,)
        Records (any units, the same for both).
    dt, dt_ref : float
        Sample intervals (s).
    f_L, f_H : float
        Spool frequencies (Hz), which choose the spectra's records (:func:`settled_spectrum`).
    f_max : float
        Highest frequency compared (Hz).
    """
    a = settled_spectrum(x, dt, f_L, f_H)
    r = settled_spectrum(x_ref, dt_ref, f_L, f_H)
    keep = r.frequencies <= f_max
    f = r.frequencies[keep]
    amp = a.amplitudes[: f.size] if np.array_equal(a.frequencies[: f.size], f) else np.interp(f, a.frequencies,
                                                                                               a.amplitudes)
    ref = r.amplitudes[keep]
    scale = float(ref.max()) if ref.size and ref.max() > 0 else 1.0
    diff = np.abs(amp - ref) / scale
    k = int(np.argmax(diff))
    peak_ref = float(np.max(np.abs(x_ref)))
    peak = abs(float(np.max(np.abs(x))) - peak_ref) / (peak_ref if peak_ref > 0 else 1.0)
    spectral = float(diff[k])
    return RecordError(max(spectral, peak), spectral, peak, float(f[k]), tuple(dof))


def outputs_error(outputs: dict, dt: float, reference: dict, dt_ref: float, f_L: float, f_H: float,
                  f_max: float) -> RecordError:
    """The worst :func:`record_error` over the DOFs of ``reference`` (dicts DOF -> record)."""
    errors = [record_error(outputs[d], dt, reference[d], dt_ref, f_L, f_H, f_max, d) for d in reference]
    return max(errors, key=lambda e: e.error)
