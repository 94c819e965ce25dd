"""Bode and polar plots of unbalance responses and FRFs, and the steady state at one operating point.

Amplitudes in µm (or m/N for FRFs), phases in degrees, speeds in rpm, frequencies in Hz. Each function draws
into the given axes (one panel) or into a new figure (one column of panels per output) and returns the Figure.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from rotorred import checks
from rotorred.linear.harmonic import FrequencyResponse, Output, SteadyState, UnbalanceResponse
from rotorred.plots.axes import DPI, axes

_RPM = 60.0 / (2.0 * math.pi)
_PHASE_TICKS = [-180, -90, 0, 90, 180]


def draw_bode(result: UnbalanceResponse, ax=None, *, title: str = ""):
    """Amplitude (µm, log) and phase (deg) of each output against the reference spool speed (rpm).

    One line per excited spool (at that spool's own frequency) and, with more than one excited spool, the
    peak bound (sum of magnitudes) dashed. A new figure has one column per output, amplitude above phase;
    a given ``ax`` gets the amplitudes of every output (the phases need a second axes).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if ax is not None:
        _amplitudes(ax, result, result.outputs)
        ax.set_xlabel(f"{result.reference_spool} speed (rpm)")
        ax.legend(fontsize=7, loc="best")
        return ax.figure
    n_out = len(result.outputs)
    fig = Figure(figsize=(4.2 * n_out + 1, 6.2), dpi=DPI)
    grid = fig.subplots(2, n_out, sharex=True, squeeze=False)
    for j, o in enumerate(result.outputs):
        _amplitudes(grid[0, j], result, [o])
        _phases(grid[1, j], result, o)
        grid[0, j].set_title(f"node {o[0]}, {o[1]}")
    grid[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle(title or "Unbalance response (Bode)")
    fig.tight_layout()
    return fig


def draw_polar(result: UnbalanceResponse, ax=None, *, title: str = ""):
    """Polar (Nyquist) plot: the phasor tip Re Q, Im Q (µm) of each output over the sweep.

    Each excited spool's phasor is drawn separately (the spools excite different frequencies); the
    largest-amplitude point and the sweep's end are labelled with the reference spool speed (rpm). A new
    figure has one panel per output; a given ``ax`` gets every output.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if ax is not None:
        _phasor_tips(ax, result, result.outputs)
        ax.legend(fontsize=7, loc="best")
        return ax.figure
    n_out = len(result.outputs)
    fig = Figure(figsize=(4.6 * n_out + 0.5, 4.8), dpi=DPI)
    row = fig.subplots(1, n_out, squeeze=False)[0]
    for ax_j, o in zip(row, result.outputs):
        _phasor_tips(ax_j, result, [o])
        ax_j.set_title(f"node {o[0]}, {o[1]}")
    row[0].legend(fontsize=7, loc="best")
    fig.suptitle((title or "Unbalance response (polar)") + f"; points labelled with the {result.reference_spool} speed")
    fig.tight_layout()
    return fig


def _name(o: Output, several: bool) -> str:
    """``"node 13 x: "`` when a panel holds several outputs, else nothing."""
    return f"node {o[0]} {o[1]}: " if several else ""


def _amplitudes(ax, result: UnbalanceResponse, outputs) -> None:
    """Amplitude (µm, log) of ``outputs`` against the reference speed (rpm), per excited spool and the peak bound."""
    rpm = result.speeds * _RPM
    several = len(outputs) > 1
    for o in outputs:
        for s in result.phasors:
            amp = 1e6 * result.amplitude(o, s)
            ax.semilogy(rpm[amp > 0], amp[amp > 0], label=f"{_name(o, several)}{s} unbalance (at {s} speed)")
        if len(result.phasors) > 1:
            pk = 1e6 * result.peak(o)
            ax.semilogy(rpm[pk > 0], pk[pk > 0], "k--", lw=1,
                        label=f"{_name(o, several)}peak bound (sum of magnitudes)")
    ax.set_ylabel("amplitude (µm)")
    ax.grid(True, which="both", alpha=0.3)


def _phases(ax, result: UnbalanceResponse, o: Output) -> None:
    """Phase (deg) of output ``o`` against the reference speed (rpm), per excited spool."""
    rpm = result.speeds * _RPM
    for s in result.phasors:
        ax.plot(rpm, np.degrees(result.phase(o, s)), label=f"{s} unbalance")
    ax.set_ylabel("phase (deg)")
    ax.set_ylim(-185, 185)
    ax.set_yticks(_PHASE_TICKS)
    ax.grid(True, alpha=0.3)
    ax.set_xlabel(f"{result.reference_spool} speed (rpm)")


def _phasor_tips(ax, result: UnbalanceResponse, outputs) -> None:
    """The phasor tips (µm) of ``outputs`` over the sweep, the largest and the last point labelled in rpm."""
    rpm = result.speeds * _RPM
    several = len(outputs) > 1
    for o in outputs:
        for s in result.phasors:
            Q = 1e6 * result.phasors[s][o]
            line, = ax.plot(Q.real, Q.imag, ".-", ms=2, lw=1, label=f"{_name(o, several)}{s} unbalance")
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
    ax.grid(True, alpha=0.3)


def draw_frf(frf: FrequencyResponse, ax=None, *, title: str = ""):
    """Bode plot of every FRF pair: |H| (m/N, log) and phase (deg) against frequency (Hz).

    A new figure has |H| above the phase; a given ``ax`` gets |H| only.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if ax is not None:
        _receptances(ax, frf)
        ax.set_xlabel("frequency (Hz)")
        return ax.figure
    fig = Figure(figsize=(7, 6), dpi=DPI)
    (ax_a, ax_p) = fig.subplots(2, 1, sharex=True)
    _receptances(ax_a, frf)
    f = frf.frequencies / (2 * math.pi)
    for o in frf.outputs:
        for i in frf.inputs:
            ax_p.plot(f, np.degrees(np.angle(frf.h(o, i))), label=_pair(o, i))
    ax_p.set_ylabel("phase (deg)")
    ax_p.set_xlabel("frequency (Hz)")
    ax_p.set_yticks(_PHASE_TICKS)
    ax_p.grid(True, alpha=0.3)
    speeds = ", ".join(f"{s} {w * _RPM:.0f} rpm" for s, w in frf.speeds.items()) or "not spinning"
    fig.suptitle(title or f"Receptance FRF ({speeds})")
    fig.tight_layout()
    return fig


def _pair(o: Output, i: Output) -> str:
    return f"node {o[0]} {o[1]} / node {i[0]} {i[1]}"


def _receptances(ax, frf: FrequencyResponse) -> None:
    """|H| (m/N, log) of every pair against frequency (Hz)."""
    f = frf.frequencies / (2 * math.pi)
    for o in frf.outputs:
        for i in frf.inputs:
            ax.semilogy(f, np.abs(frf.h(o, i)), label=_pair(o, i))
    ax.set_ylabel("|H| (m/N)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)


def draw_steady_state(state: SteadyState, ax=None, *, model=None, node: int | None = None, revolutions: float = 5.0,
                      title: str = "", figsize: tuple[float, float] = (8.0, 5.0)):
    """The steady state at one operating point (:meth:`SteadyState.plot`); return the Figure.

    With ``model`` and ``node``: the orbit (µm) of that node, x(t) and y(t) recovered from the model's
    coordinates (``model.output_rows``, a full or a reduced model), over ``revolutions`` revolutions of the
    slowest excited spool, with its start ``q(0)`` (a transient's initial condition) marked: the orbit's size
    and shape, the rosette two spools make. Without them: the amplitude |Q_s| of every model coordinate
    (log), one series per excited spool, against the coordinate's index: which coordinates (for a reduced
    model, which modes) carry the response.

    Parameters
    ----------
    state : SteadyState
    ax : matplotlib Axes, optional
        Axes to draw into; default a new figure of ``figsize`` (in).
    model : SystemMatrices or ReducedSystem, optional
        The model ``state`` was computed on.
    node : int, optional
        Node of the orbit (with ``model``).
    revolutions : float
        Length of the orbit, in revolutions of the slowest excited spool.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    new = ax is None
    fig, ax = axes(ax, figsize)
    if (model is None) != (node is None):
        checks.fail("node", node, "must be given with model, and model with node (the orbit of a node)")
    if model is None:
        _coordinate_amplitudes(ax, state)
    else:
        _orbit(ax, state, model.output_rows([(node, "x"), (node, "y")]), revolutions)
        ax.set_title(f"node {node}", loc="left", fontsize=9)
    speeds = ", ".join(f"{s} {w * _RPM:.0f} rpm" for s, w in state.speeds.items())
    ax.set_title(title or f"steady unbalance response ({speeds})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    if new:
        fig.tight_layout()
    return fig


def _coordinate_amplitudes(ax, state: SteadyState) -> None:
    """|Q_s| of every model coordinate per excited spool, as steps (log scale)."""
    for s, Q in state.phasors.items():
        amp = np.abs(Q)
        index = np.arange(len(amp))
        ax.semilogy(index[amp > 0], amp[amp > 0], ".", ms=5, label=f"{s} unbalance (at {s} speed)")
    ax.set_xlabel("model coordinate (index)")
    ax.set_ylabel("amplitude |Q| (m or rad; model coordinates)")


def _orbit(ax, state: SteadyState, rows: np.ndarray, revolutions: float) -> None:
    """x(t), y(t) (µm) of the node that ``rows`` reads, and its start point."""
    turning = [w for s, w in state.speeds.items() if s in state.phasors and w > 0]
    if not turning:  # at rest: the steady state is the origin
        t = np.zeros(1)
    else:
        t_end = revolutions * 2 * math.pi / min(turning)
        t = np.linspace(0.0, t_end, int(np.ceil(200 * revolutions * max(turning) / min(turning))) + 1)
    xy = 1e6 * np.array([rows @ state.displacement(tk) for tk in t])
    ax.plot(xy[:, 0], xy[:, 1], lw=1.0, label=f"orbit, {revolutions:g} revolutions")
    ax.plot(xy[:1, 0], xy[:1, 1], "o", color="tab:red", ms=5, label="t = 0 (initial condition)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (µm)")
    ax.set_ylabel("y (µm)")
