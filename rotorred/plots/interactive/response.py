"""Interactive unbalance response: Bode (amplitude and phase against speed) and polar plots of every output at every
excited spool's frequency, with hover (:class:`rotorred.linear.harmonic.UnbalanceResponse`)."""

from __future__ import annotations

import numpy as np

from rotorred.plots.interactive._layout import MICRO, RPM, color, figure, hover, layout
from rotorred.plots.interactive.report import Panel, Report


def figures(result) -> list[tuple[str, dict]]:
    """The Bode and the polar plot of ``result``.

    Parameters
    ----------
    result : UnbalanceResponse
    """
    return [("bode", bode_figure(result)), ("polar", polar_figure(result))]


def _series(result):
    """(name, speed (rpm), spool speed (rpm), amplitude (µm), phase (deg)) of every output and excited spool."""
    rpm = result.speeds * RPM
    for spool in result.excited_spools:
        for out in result.outputs:
            name = f"node {out[0]} {out[1]}, 1× {spool}"
            yield (name, rpm, result.spool_speeds[spool] * RPM, MICRO * result.amplitude(out, spool),
                   np.degrees(result.phase(out, spool)))


def bode_figure(result) -> dict:
    """Amplitude (µm) above, phase (deg) below, against the reference spool's speed (rpm)."""
    data = []
    tip = hover("%{meta}", f"{result.reference_spool} %{{x:.6~g}} rpm (excited spool %{{customdata[0]:.6~g}} rpm)",
                "amplitude %{customdata[1]:.4~g} µm, phase %{customdata[2]:.4~g} deg")
    for k, (name, rpm, spool_rpm, amp, phase) in enumerate(_series(result)):
        custom = np.column_stack([spool_rpm, amp, phase])
        common = {"type": "scatter", "mode": "lines", "x": rpm, "meta": name, "customdata": custom,
                  "hovertemplate": tip, "legendgroup": name, "line": {"color": color(k)}}
        data.append({**common, "y": amp, "name": name})
        data.append({**common, "y": phase, "yaxis": "y2", "showlegend": False})
    return figure(data, layout(f"unbalance response - Bode ({result.reference_spool} speed)", "",
                               "amplitude (µm)", height=620,
                               xaxis={"anchor": "y2", "title": {"text": f"{result.reference_spool} speed (rpm)"}},
                               yaxis={"domain": [0.42, 1.0]},
                               yaxis2={"domain": [0.0, 0.36], "anchor": "x", "title": {"text": "phase (deg)"},
                                       "range": [-185, 185], "dtick": 90}))


def polar_figure(result) -> dict:
    """Each response's phasor tip (amplitude µm, phase deg) over the sweep."""
    data = []
    for k, (name, rpm, spool_rpm, amp, phase) in enumerate(_series(result)):
        data.append({"type": "scatterpolar", "mode": "lines+markers", "r": amp, "theta": phase, "name": name,
                     "customdata": rpm, "marker": {"size": 3}, "line": {"color": color(k)},
                     "hovertemplate": hover(name, f"{result.reference_spool} %{{customdata:.6~g}} rpm",
                                            "%{r:.4~g} µm at %{theta:.4~g} deg")})
    return figure(data, {"title": {"text": "unbalance response - polar (amplitude µm, phase deg)"},
                         "polar": {"angularaxis": {"direction": "counterclockwise"}}, "height": 560,
                         "legend": {"font": {"size": 11}}})


def report(result, title: str = "") -> Report:
    """The unbalance-response report: Bode and polar plots.

    Parameters
    ----------
    result : UnbalanceResponse
    title : str
        The page's title (default "unbalance response").
    """
    return Report(title or "unbalance response", tuple(result.summary()),
                  (Panel("bode", bode_figure(result), "Hover a curve: speed, amplitude and phase; click the legend to "
                                                      "hide a response."), Panel("polar", polar_figure(result))))
