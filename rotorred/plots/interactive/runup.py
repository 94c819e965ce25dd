"""Interactive run-up (:class:`rotorred.scenes.runup.RunupResult`, ``rotorred run`` of a scene with ``[runup]``):
the largest orbit radius against speed with the critical speeds and rub intervals, the order tracks, and the
waterfall as a heat map (frequency against the reference spool's speed)."""

from __future__ import annotations

import numpy as np

from rotorred.model.dofs import direction_name
from rotorred.plots.interactive._layout import MICRO, RPM, figure, hover, layout
from rotorred.plots.interactive.report import Panel, Report


def figures(result) -> list[tuple[str, dict]]:
    """Amplitude against speed, order tracks and (when the run has one) the waterfall.

    Parameters
    ----------
    result : RunupResult
    """
    out = [("amplitude", amplitude_figure(result)), ("orders", orders_figure(result))]
    if result.waterfall is not None:
        out.append(("waterfall", waterfall_figure(result)))
    return out


def _critical_marks(result) -> tuple[list, list]:
    """Vertical lines at the critical speeds (rpm of the reference spool) and their labels."""
    shapes, notes = [], []
    for c in result.critical_speeds:
        x = c.speed * RPM
        shapes.append({"type": "line", "x0": x, "x1": x, "y0": 0, "y1": 1, "yref": "paper",
                       "line": {"color": "grey", "dash": "dot", "width": 1}})
        notes.append({"x": x, "y": 1, "yref": "paper", "text": f"{c.line} m{c.mode + 1}", "showarrow": False,
                      "textangle": -90, "xanchor": "right", "yanchor": "top", "font": {"size": 9, "color": "grey"},
                      "hovertext": f"critical speed {x:.6g} rpm: mode {c.mode + 1} on {c.line}, {c.whirl} whirl, "
                                   f"{c.frequency_hz:.5g} Hz"})
    return shapes, notes


def amplitude_figure(result) -> dict:
    """The largest orbit radius of each node (µm) against the reference spool's speed (rpm), critical speeds
    dotted, rub intervals shaded."""
    ref = result.reference
    data = []
    for node, (speed, radius) in result.overall.items():
        data.append({"type": "scatter", "mode": "lines", "x": np.asarray(speed) * RPM, "y": MICRO * np.asarray(radius),
                     "name": f"node {node}", "hovertemplate": hover(f"node {node}", f"{ref} %{{x:.6~g}} rpm",
                                                                    "largest orbit radius %{y:.4~g} µm")})
    shapes, notes = _critical_marks(result)
    for r in result.rubs:
        x0, x1 = sorted((60.0 * r.speed_start[ref], 60.0 * r.speed_end[ref]))  # (Hz)
        shapes.append({"type": "rect", "x0": x0, "x1": x1, "y0": 0, "y1": 1, "yref": "paper", "line": {"width": 0},
                       "fillcolor": "red", "opacity": 0.12})
    return figure(data, layout(f"{result.scene.name}: amplitude against speed (critical speeds dotted, rub shaded)",
                               f"{ref} speed (rpm)", "largest orbit radius (µm)", shapes=shapes, annotations=notes))


def orders_figure(result) -> dict:
    """Every order track (amplitude µm or µrad) against its spool's speed (rpm)."""
    data = []
    for track, dof in zip(result.tracks, result.track_dofs):
        name = f"{track.order:g}× {track.spool}, node {dof[0]} {direction_name(dof[1])}"
        data.append({"type": "scatter", "mode": "lines", "x": np.asarray(track.speed) * RPM,
                     "y": MICRO * np.asarray(track.amplitude), "name": name,
                     "visible": True if track.order == 1 else "legendonly",
                     "hovertemplate": hover(name, f"{track.spool} %{{x:.6~g}} rpm", "%{y:.4~g} µm (µrad)")})
    return figure(data, layout(f"{result.scene.name}: order tracks (click the legend: more orders)",
                               "spool speed (rpm)", "order amplitude (µm; µrad for a rotation)"))


def waterfall_figure(result) -> dict:
    """The waterfall of the table DOF as a heat map: frequency (Hz) across, the reference speed (rpm) up, amplitude
    (µm) in colour."""
    w, ref = result.waterfall, result.reference
    speed = np.interp(w.t, result.t, np.asarray(result.speeds[ref])) * RPM
    n, d = result.waterfall_dof
    return figure([{"type": "heatmap", "x": w.frequencies, "y": speed, "z": MICRO * np.asarray(w.amplitudes),
                    "colorscale": "Viridis", "colorbar": {"title": {"text": "µm"}},
                    "hovertemplate": hover("%{x:.5~g} Hz", f"{ref} %{{y:.6~g}} rpm", "%{z:.4~g} µm")}],
                  layout(f"{result.scene.name}: waterfall of node {n} {direction_name(d)}", "frequency (Hz)",
                         f"{ref} speed (rpm)"))


def report(result) -> Report:
    """The run-up's report.

    Parameters
    ----------
    result : RunupResult
    """
    return Report(f"{result.scene.name}: run-up", tuple(result.summary()),
                  tuple(Panel(name, fig) for name, fig in figures(result)))
