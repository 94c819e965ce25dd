"""Bode and polar plots (PNG) of unbalance responses and FRFs.

Amplitudes in µm (or m/N for FRFs), phases in degrees, speeds in rpm, frequencies in Hz.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rotorred.linear.harmonic import FrequencyResponse, UnbalanceResponse

_RPM = 60.0 / (2.0 * math.pi)


def plot_bode(result: UnbalanceResponse, path: str | Path, title: str = "") -> Path:
    """Amplitude (µm, log) and phase (deg) of each output against the reference spool speed (rpm).

    One line per excited spool (at that spool's own frequency) and, with more than one
    excited spool, the peak bound (sum of magnitudes) dashed.
    """
    path = Path(path)
    n_out = len(result.outputs)
    fig = Figure(figsize=(4.2 * n_out + 1, 6.2))
    axes = fig.subplots(2, n_out, sharex=True, squeeze=False)
    rpm = result.speeds * _RPM
    for j, o in enumerate(result.outputs):
        ax_a, ax_p = axes[0, j], axes[1, j]
        for s in result.phasors:
            amp = 1e6 * result.amplitude(o, s)
            ax_a.semilogy(rpm[amp > 0], amp[amp > 0], label=f"{s} unbalance (at {s} speed)")
            ax_p.plot(rpm, np.degrees(result.phase(o, s)), label=f"{s} unbalance")
        if len(result.phasors) > 1:
            pk = 1e6 * result.peak(o)
            ax_a.semilogy(rpm[pk > 0], pk[pk > 0], "k--", lw=1, label="peak bound (sum of magnitudes)")
        ax_a.set_title(f"node {o[0]}, {o[1]}")
        ax_a.set_ylabel("amplitude (µm)")
        ax_a.grid(True, which="both", alpha=0.3)
        ax_p.set_ylabel("phase (deg)")
        ax_p.set_ylim(-185, 185)
        ax_p.set_yticks([-180, -90, 0, 90, 180])
        ax_p.grid(True, alpha=0.3)
        ax_p.set_xlabel(f"{result.reference_spool} speed (rpm)")
    axes[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle(title or "Unbalance response (Bode)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def plot_polar(result: UnbalanceResponse, path: str | Path, title: str = "") -> Path:
    """Polar (Nyquist) plot: the phasor tip Re Q, Im Q (µm) of each output over the sweep.

    Each excited spool's phasor is drawn separately (the spools excite different
    frequencies); the largest-amplitude point and the sweep's end are labelled with the
    reference spool speed (rpm).
    """
    path = Path(path)
    n_out = len(result.outputs)
    fig = Figure(figsize=(4.6 * n_out + 0.5, 4.8))
    axes = fig.subplots(1, n_out, squeeze=False)
    rpm = result.speeds * _RPM
    for j, o in enumerate(result.outputs):
        ax = axes[0, j]
        for s in result.phasors:
            Q = 1e6 * result.phasors[s][o]
            line, = ax.plot(Q.real, Q.imag, ".-", ms=2, lw=1, label=f"{s} unbalance")
            marks = sorted({int(np.argmax(np.abs(Q))), len(Q) - 1})
            ax.plot(Q.real[marks], Q.imag[marks], "o", ms=4, color=line.get_color())
            for k in marks:
                ax.annotate(f"{rpm[k]:.0f} rpm", (Q.real[k], Q.imag[k]), fontsize=6,
                            color=line.get_color(), xytext=(3, 3), textcoords="offset points")
        ax.axhline(0, color="0.6", lw=0.6)
        ax.axvline(0, color="0.6", lw=0.6)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("Re Q (µm)")
        ax.set_ylabel("Im Q (µm)")
        ax.set_title(f"node {o[0]}, {o[1]}")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle((title or "Unbalance response (polar)") + f"; points labelled with the {result.reference_spool} speed")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def plot_frf(frf: FrequencyResponse, path: str | Path, title: str = "") -> Path:
    """Bode plot of every FRF pair: |H| (m/N, log) and phase (deg) against frequency (Hz)."""
    path = Path(path)
    fig = Figure(figsize=(7, 6))
    (ax_a, ax_p) = fig.subplots(2, 1, sharex=True)
    f = frf.frequencies / (2 * math.pi)
    for o in frf.outputs:
        for i in frf.inputs:
            h = frf.h(o, i)
            label = f"node {o[0]} {o[1]} / node {i[0]} {i[1]}"
            ax_a.semilogy(f, np.abs(h), label=label)
            ax_p.plot(f, np.degrees(np.angle(h)), label=label)
    ax_a.set_ylabel("|H| (m/N)")
    ax_a.grid(True, which="both", alpha=0.3)
    ax_a.legend(fontsize=7)
    ax_p.set_ylabel("phase (deg)")
    ax_p.set_xlabel("frequency (Hz)")
    ax_p.set_yticks([-180, -90, 0, 90, 180])
    ax_p.grid(True, alpha=0.3)
    speeds = ", ".join(f"{s} {w * _RPM:.0f} rpm" for s, w in frf.speeds.items()) or "not spinning"
    fig.suptitle(title or f"Receptance FRF ({speeds})")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path
