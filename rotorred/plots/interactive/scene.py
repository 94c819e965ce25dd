"""Interactive transient views: a scene's waveforms, spectra with every fitted line's label on hover, orbits and
Poincare section (:class:`rotorred.scenes.run.SceneResult`, the figures of ``rotorred run``), or a transient's
waveforms (:class:`rotorred.transient.results.TransientResult`)."""

from __future__ import annotations

import math

import numpy as np

from rotorred.model.dofs import direction_name
from rotorred.plots.interactive._layout import MICRO, color, decimated, figure, hover, layout
from rotorred.plots.interactive.report import Panel, Report

#: most samples a waveform or orbit trace embeds (every k-th sample beyond)
MOST_SAMPLES = 6000
#: most bins of a spectrum trace embedded
MOST_BINS = 6000
#: decades of amplitude a spectrum shows below its highest peak (as spectra_node<N>.png)
SPECTRUM_DECADES = 6


def figures(result) -> list[tuple[str, dict]]:
    """The figures of ``result``: "waveforms", then for a scene "spectra_node<N>" for each recorded node, "orbits"
    (x and y recorded) and "poincare" (the table DOF's samples), as ``rotorred run`` draws them.

    Parameters
    ----------
    result : SceneResult or TransientResult
    """
    if not hasattr(result, "scene"):
        return [("waveforms", _waveforms(result.t, {_dof_name(d): {"": x} for d, x in result.outputs.items()},
                                         "transient: recorded outputs", None))]
    sc = result.scene
    pairs = _pairs(result)
    out = [("waveforms", _waveforms(
        result.t, {_dof_name((n, d)): {label: r.outputs[(n, d)] for label, r in pairs}
                   for n in sc.output.nodes for d in sc.output.directions},
        f"{sc.name}: time waveforms ({_rub_text(sc)})", sc.output.plot_window))]
    if result.spectra:
        out += [(f"spectra_node{n}", _spectra(result, n)) for n in sc.output.nodes]
    if {"x", "y"} <= set(sc.output.directions):
        out.append(("orbits", _orbits(result, pairs)))
    a = result.analysis
    if a is not None and a.classification.poincare.x.size:
        out.append(("poincare", _poincare(result)))
    return out


def _pairs(result) -> list[tuple[str, object]]:
    case = "rub" if result.scene.plates else "response"
    return [("normal", result.normal), (case, result)] if result.normal is not None else [(case, result)]


def _dof_name(dof) -> str:
    return f"node {dof[0]} {direction_name(dof[1])}"


def _unit(name: str) -> str:
    return "µm" if name.endswith((" X", " Y")) else "µrad"


def _rub_text(sc) -> str:
    return "; ".join(f"rub at node {p.node}, clearance {1e6 * p.clearance:.3g} µm" for p in sc.plates) or "no rub"


def _waveforms(t, signals: dict, title: str, window) -> dict:
    """Every signal (µm or µrad) against time (s) in ``window`` (default the first 0.14 s, as waveforms.png)."""
    t = np.asarray(t)
    lo, hi = window or (t[0], min(t[-1], t[0] + 0.14)) if t.size else (0.0, 0.0)
    part = np.flatnonzero((t >= lo) & (t <= hi))
    pick = part[decimated(part.size, MOST_SAMPLES)]
    data = []
    for k, (name, series) in enumerate(signals.items()):
        for label, x in series.items():
            full = f"{name} {label}".strip()
            data.append({"type": "scatter", "mode": "lines", "x": t[pick], "y": MICRO * np.asarray(x)[pick],
                         "name": full, "line": {"width": 1.2, "dash": "dot" if label == "normal" else "solid",
                                                "color": color(k)},
                         "hovertemplate": hover(full, "t = %{x:.5~g} s", f"%{{y:.4~g}} {_unit(name)}")})
    return figure(data, layout(title, "time (s)", "displacement (µm) or rotation (µrad)"))


def _spectra(result, node: int) -> dict:
    """The amplitude spectra of ``node``'s directions (log amplitude, µm) with each fitted line marked, its label,
    frequency, amplitude and share on hover."""
    sc, data, known = result.scene, [], []
    for k, d in enumerate(sc.output.directions):
        dof, unit = (node, d), _unit(_dof_name((node, d)))
        for label, r in _pairs(result):
            s = r.spectra[dof]
            f, a = np.asarray(s.frequencies, float), np.asarray(s.amplitudes, float)
            pick = decimated(f.size, MOST_BINS)
            data.append({"type": "scatter", "mode": "lines", "x": f[pick], "y": MICRO * a[pick],
                         "name": f"{label} {direction_name(d)}",
                         "line": {"width": 1, "color": color(k), "dash": "dot" if label == "normal" else "solid"},
                         "hovertemplate": hover(f"{label} {direction_name(d)}", "%{x:.5~g} Hz", f"%{{y:.4~g}} {unit}")})
        lines = result.lines[dof].lines
        known += [ln.frequency_hz for ln in lines]
        data.append({"type": "scatter", "mode": "markers", "name": f"lines {direction_name(d)}",
                     "x": [ln.frequency_hz for ln in lines], "y": [MICRO * ln.amplitude for ln in lines],
                     "marker": {"symbol": "triangle-down", "size": 9, "color": color(k),
                                "line": {"width": 1, "color": "black"}},
                     "customdata": [[ln.label, ln.share] for ln in lines],
                     "hovertemplate": hover("%{customdata[0]}", "%{x:.6~g} Hz", f"%{{y:.4~g}} {unit}",
                                            "share %{customdata[1]:.3~g}")})
    f_max = sc.output.f_max_hz or max(1.1 * max(known, default=0.0), 3.0 * result.f_H)
    top = max((np.nanmax(t["y"]) for t in data if len(t["y"])), default=1.0)
    decades = np.log10(max(top, 1e-30))
    return figure(data, layout(f"{sc.name}: amplitude spectra at node {node} (hover a line: its label)",
                               "frequency (Hz)", "amplitude (µm or µrad)", xaxis={"range": [0, f_max]},
                               yaxis={"type": "log", "range": [decades - SPECTRUM_DECADES, decades + 0.3]}))


def _orbits(result, pairs) -> dict:
    """The orbit (y against x, µm) of every recorded node over the recorded window."""
    sc, data = result.scene, []
    n = result.t.size
    pick = decimated(n, MOST_SAMPLES)
    for k, node in enumerate(sc.output.nodes):
        for label, r in pairs:
            name = f"node {node} ({sc.rotor.spool_of[node]}) {label}"
            data.append({"type": "scatter", "mode": "lines", "name": name,
                         "line": {"width": 1, "color": color(k), "dash": "dot" if label == "normal" else "solid"},
                         "x": MICRO * np.asarray(r.outputs[(node, "x")])[pick],
                         "y": MICRO * np.asarray(r.outputs[(node, "y")])[pick],
                         "hovertemplate": hover(name, "x %{x:.4~g} µm, y %{y:.4~g} µm")})
    for p in sc.plates:
        angle = p.theta
        data.append({"type": "scatter", "mode": "markers", "name": f"plate at node {p.node}",
                     "x": [MICRO * p.clearance * math.cos(angle)], "y": [MICRO * p.clearance * math.sin(angle)],
                     "marker": {"symbol": "square", "size": 9, "color": "black"},
                     "hovertemplate": hover(f"rub plate at node {p.node}: {math.degrees(angle):g} deg, clearance "
                                            f"{1e6 * p.clearance:.3g} µm")})
    return figure(data, layout(f"{sc.name}: orbits over the recorded window ({_rub_text(sc)})", "x (µm)", "y (µm)",
                               yaxis={"scaleanchor": "x", "scaleratio": 1}))


def _poincare(result) -> dict:
    """The Poincare section of the table DOF (displacement against velocity), its class in the title."""
    a = result.analysis
    c = a.classification
    unit = _unit(_dof_name(a.dof))
    return figure([{"type": "scatter", "mode": "markers", "name": c.label, "x": MICRO * c.poincare.x,
                    "y": MICRO * c.poincare.velocity, "marker": {"size": 4},
                    "hovertemplate": hover(c.label, f"%{{x:.5~g}} {unit}", f"%{{y:.5~g}} {unit}/s")}],
                  layout(f"{result.scene.name}: Poincare section of {_dof_name(a.dof)}: {c.label}, once per "
                         f"{1.0 / c.poincare.frequency_hz:.4g} s", f"displacement ({unit})", f"velocity ({unit}/s)"))


def report(result) -> Report:
    """The report of a scene (or a transient): its figures, one after the other.

    Parameters
    ----------
    result : SceneResult or TransientResult
    """
    notes = {"waveforms": "Drag to zoom, double-click to reset; click the legend to hide a signal.",
             "orbits": "The orbit of each node; the squares are the rub plates at their clearance."}
    title = f"{result.scene.name}: transient" if hasattr(result, "scene") else "transient"
    panels = tuple(Panel(name, fig, notes.get(name, "Hover a triangle: the fitted line's label, frequency, amplitude "
                                               "and share." if name.startswith("spectra") else ""))
                   for name, fig in figures(result))
    return Report(title, tuple(result.summary()), panels)
