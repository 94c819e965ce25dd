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

**Reduced against full** (``rotorred compare``, ``validation/bench_pareto.py``: docs/model.md §22) measures a run
against a reference by the quantities an engineer reads off a rub response, each a relative error:

* ``spectral``: the ``n_lines`` largest spectral amplitudes of the reference (0 Hz excluded) of each DOF compared,
  those of at least ``threshold`` times the DOF's largest (a line, not round-off), the worst relative error over them
  all (the largest errors sit on small combination lines, not on the 1x lines);
  spectra by :func:`rotorred.signals.spectra.settled_spectrum` of the records resampled to a common interval
  (:func:`response_measures`);
* ``orbit``: the peak orbit radius ``max sqrt(x^2 + y^2)`` at one node;
* ``contact``: the fraction of the record in contact (slip or stick).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rotorred.signals.spectra import settled_spectrum

__all__ = ["RecordError", "record_error", "outputs_error", "N_LINES", "LINE_THRESHOLD", "ResponseMeasures",
           "response_measures", "MeasureErrors", "measure_errors", "resample"]


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


# --------------------------------------------------------------------------- reduced against full
#: spectral amplitudes compared per DOF (the reference's largest, 0 Hz excluded)
N_LINES = 10
#: smallest line compared, relative to the DOF's largest (a scene's default ``output.line_threshold``)
LINE_THRESHOLD = 0.005


@dataclass(frozen=True)
class ResponseMeasures:
    """What a run is compared by (:func:`response_measures`).

    Attributes
    ----------
    spectra : dict of (int, str) to ndarray, shape (n_bins,)
        Amplitude spectrum of each DOF compared (m; rad for a rotation), on the common-period bins.
    frequencies : ndarray, shape (n_bins,)
        Bin frequencies (Hz).
    peak_radius : float
        Peak orbit radius at the orbit node (m); NaN without one.
    contact_fraction : float
        Fraction of the record in contact (-); NaN without a rub plate.
    """

    spectra: dict
    frequencies: np.ndarray
    peak_radius: float
    contact_fraction: float


def resample(x: np.ndarray, step: int) -> np.ndarray:
    """Every ``step``-th sample of ``x``, counted back from its last (a record that starts at its window's start
    keeps the window's last sample).

    Parameters
    ----------
    x : ndarray, shape (n,)
    step : int
        >= 1.

    Returns
    -------
    ndarray, shape (ceil(n / step),)
    """
    return x[::-1][::step][::-1]


def response_measures(outputs: dict, dt: float, sample_dt: float, speeds_hz: tuple[float, float], dofs,
                      orbit_node: int | None = None, contact_fraction: float | None = None) -> ResponseMeasures:
    """The spectra of ``dofs``, the peak orbit radius at ``orbit_node`` and the contact fraction of one run.

    Parameters
    ----------
    outputs : dict of (int, str) to ndarray, shape (n,)
        The records (m or rad), sampled at ``dt`` over the compared window.
    dt : float
        Their sample interval (s).
    sample_dt : float
        The interval every compared run is resampled to (s); a whole multiple of ``dt``.
    speeds_hz : (float, float)
        (f_L, f_H), the spool frequencies (Hz) that choose the spectrum's record (:func:`settled_spectrum`).
    dofs : sequence of (int, str)
        The DOFs whose spectra are compared.
    orbit_node : int, optional
        Node whose x and y are in ``outputs``: its peak orbit radius.
    contact_fraction : float, optional
        Fraction of the record in contact (-).

    Returns
    -------
    ResponseMeasures

    Raises
    ------
    ValueError
        If ``dt`` does not divide ``sample_dt``.
    """
    step = int(round(sample_dt / dt))
    if step < 1 or abs(step * dt - sample_dt) > 1e-9 * sample_dt:
        raise ValueError(f"`dt` = {dt} s must divide the sample interval {sample_dt} s")
    f_L, f_H = speeds_hz
    spectra, freqs = {}, np.zeros(0)
    for d in dofs:
        spec = settled_spectrum(resample(outputs[d], step), sample_dt, f_L, f_H)
        spectra[d], freqs = spec.amplitudes, spec.frequencies
    radius = math.nan
    if orbit_node is not None:
        radius = float(np.hypot(outputs[(orbit_node, "x")], outputs[(orbit_node, "y")]).max())
    return ResponseMeasures(spectra=spectra, frequencies=freqs, peak_radius=radius,
                            contact_fraction=math.nan if contact_fraction is None else float(contact_fraction))


@dataclass(frozen=True)
class MeasureErrors:
    """Relative errors of a run against a reference (:func:`measure_errors`), each (-).

    Attributes
    ----------
    spectral : float
        Worst relative error of the reference's largest lines, over every DOF compared.
    orbit : float
        Of the peak orbit radius (NaN without an orbit node).
    contact : float
        Of the contact fraction (its absolute error when the reference has no contact; NaN without plates).
    worst_line : str
        Where ``spectral`` is: ``"13x 210 Hz"``.
    per_dof : dict of (int, str) to (float, float)
        Each DOF's worst relative line error and the frequency of that line (Hz).
    """

    spectral: float
    orbit: float
    contact: float
    worst_line: str = ""
    per_dof: dict = field(default_factory=dict)


def measure_errors(m: ResponseMeasures, ref: ResponseMeasures, n_lines: int = N_LINES,
                   threshold: float = LINE_THRESHOLD) -> MeasureErrors:
    """Relative errors of ``m`` against ``ref``: the worst of the ``n_lines`` largest lines of each DOF, orbit, contact.

    Parameters
    ----------
    m, ref : ResponseMeasures
        The run and the reference, on the same bins (same window and sample interval).
    n_lines : int
        Largest lines of the reference compared per DOF (0 Hz excluded).
    threshold : float
        Of those, only the bins of at least ``threshold`` times the DOF's largest are lines (-): a linear response's
        two lines are compared, not its round-off (a scene's ``output.line_threshold``). A DOF whose reference
        spectrum is 0 is not compared.

    Returns
    -------
    MeasureErrors
    """
    worst, where, per_dof = 0.0, "", {}
    for o, A_ref in ref.spectra.items():
        order = np.argsort(A_ref[1:])[::-1][:n_lines] + 1      # bin 0 (the mean) excluded
        if not A_ref[order[0]] > 0:
            continue
        order = order[A_ref[order] >= threshold * A_ref[order[0]]]
        rel = np.abs(m.spectra[o][order] - A_ref[order]) / A_ref[order]
        k = int(np.argmax(rel))
        per_dof[o] = (float(rel[k]), float(ref.frequencies[order[k]]))
        if rel[k] > worst:
            worst = float(rel[k])
            where = f"{o[0]}{o[1]} {ref.frequencies[order[k]]:.0f} Hz"
    orbit = abs(m.peak_radius - ref.peak_radius) / ref.peak_radius
    c, c_ref = m.contact_fraction, ref.contact_fraction
    contact = abs(c - c_ref) / c_ref if c_ref > 0 else abs(c)
    return MeasureErrors(spectral=worst, orbit=orbit, contact=contact, worst_line=where, per_dof=per_dof)
