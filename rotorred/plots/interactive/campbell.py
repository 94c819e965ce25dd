"""Interactive Campbell diagram: every tracked mode's whirl frequency against speed, hover with its number, whirl,
log dec and damping ratio, excitation lines, critical speeds, stability changes and the operating point; in the
report, a click on a point draws that mode's shape at that speed (each spool's deflection along the axis and node
orbits with the whirl sense, as :func:`rotorred.plots.modes.draw_mode_shapes` draws them)."""

from __future__ import annotations

import base64
import math

import numpy as np

from rotorred.plots.interactive._layout import RPM, figure, hover, layout
from rotorred.plots.interactive.report import Panel, Report

#: marker of a point by its whirl; an unstable point (log dec < 0) is an "x"
SYMBOLS = {"forward": "circle", "backward": "circle-open", "mixed": "diamond", "planar": "square-open"}
#: mode shapes are embedded as int8: amplitude (largest orbit 1) x QUANTUM
QUANTUM = 127
#: orbits drawn along each spool in the mode-shape panel
ORBITS = 6
#: most speeds whose mode shapes a report embeds (every k-th of the diagram's, the first and last among them): one
#: eigen-solve each, as costly as the diagram's own; a click shows the shape at the nearest of them
SHAPE_SPEEDS = 16


def figures(result, operating_speed: float | None = None) -> list[tuple[str, dict]]:
    """The Campbell diagram of ``result`` (:class:`rotorred.linear.campbell.CampbellResult`).

    Parameters
    ----------
    result : CampbellResult
    operating_speed : float, optional
        Operating speed of the reference spool (rad/s), marked by a vertical line.
    """
    return [("campbell", campbell_figure(result, operating_speed))]


def campbell_figure(result, operating_speed: float | None = None) -> dict:
    """The Campbell diagram as a plotly figure dict: one trace per mode (``meta`` "mode": one point a row of
    ``campbell.csv``), then the excitation lines, critical speeds and stability changes."""
    rpm, hz = result.speeds_rpm, result.frequencies_hz
    data = [_mode_trace(result, j) for j in range(result.n_modes)]
    top = float(np.nanmax(hz)) * 1.08 if hz.size else 1.0
    for spool, h, slope, offset in result.excitation_lines:
        from rotorred.linear.campbell import excitation_label

        x = np.array([rpm[0], rpm[-1]])
        data.append({"type": "scatter", "mode": "lines", "x": x, "y": (slope * x / RPM + offset) / (2 * math.pi),
                     "name": excitation_label(h, spool), "line": {"dash": "dot", "color": "grey", "width": 1},
                     "hoverinfo": "name", "meta": "excitation"})
    data += _critical_traces(result)
    shapes, notes = [], []
    if operating_speed:
        x0 = operating_speed * RPM
        shapes.append({"type": "line", "x0": x0, "x1": x0, "y0": 0, "y1": 1, "yref": "paper",
                       "line": {"color": "green", "dash": "dash", "width": 1.5}})
        notes.append({"x": x0, "y": 1, "yref": "paper", "text": f"operating point {x0:.6g} rpm", "showarrow": False,
                      "yanchor": "bottom", "font": {"color": "green", "size": 11}})
    title = f"Campbell diagram - {result.rotor_name or 'rotor'} (click a point: its mode shape)"
    return figure(data, layout(title, f"{result.reference} speed (rpm)", "whirl frequency (Hz)",
                               yaxis={"range": [0, top]}, shapes=shapes, annotations=notes))


def _mode_trace(result, j: int) -> dict:
    """Mode ``j``'s curve: hover with speed, frequency, number, whirl, log dec, damping ratio."""
    whirl, log_dec, zeta = result.whirl[:, j], result.log_dec[:, j], result.damping_ratio[:, j]
    unstable = result.unstable[:, j]
    rigid = j in result.rigid_modes
    symbols = ["x" if u else SYMBOLS.get(str(w), "circle") for w, u in zip(whirl, unstable)]
    custom = [[j + 1, str(w), _num(d), _num(z), "UNSTABLE" if u else ""]
              for w, d, z, u in zip(whirl, log_dec, zeta, unstable)]
    return {"type": "scatter", "mode": "lines+markers", "x": result.speeds_rpm, "y": result.frequencies_hz[:, j],
            "name": f"mode {j + 1}" + (" (rigid body)" if rigid else ""), "legendgroup": f"mode {j + 1}",
            "marker": {"symbol": symbols, "size": [10 if u else 6 for u in unstable]}, "line": {"width": 1.5},
            "customdata": custom, "meta": "mode",
            "hovertemplate": hover("mode %{customdata[0]}: %{customdata[1]} whirl %{customdata[4]}",
                                   "%{x:.6~g} rpm", "%{y:.5~g} Hz", "log dec %{customdata[2]:.4~g}",
                                   "damping ratio %{customdata[3]:.4~g}")}


def _num(value) -> float | None:
    return float(value) if np.isfinite(value) else None


def _critical_traces(result) -> list[dict]:
    """The critical speeds (diamonds) and the speeds where a mode's stability changes (stars)."""
    out = []
    cs = result.critical_speeds
    if cs:
        out.append({"type": "scatter", "mode": "markers", "name": "critical speeds", "meta": "critical",
                    "x": [c.speed_rpm for c in cs], "y": [c.frequency_hz for c in cs],
                    "marker": {"symbol": "diamond", "size": 10, "color": "black"},
                    "customdata": [[c.line, c.mode + 1, c.whirl, _num(c.log_dec), _num(c.damping_ratio)] for c in cs],
                    "hovertemplate": hover("critical speed %{x:.6~g} rpm on %{customdata[0]}",
                                           "mode %{customdata[1]}, %{customdata[2]} whirl, %{y:.5~g} Hz",
                                           "log dec %{customdata[3]:.4~g}, damping ratio %{customdata[4]:.4~g}")})
    sc = result.stability_changes
    if sc:
        out.append({"type": "scatter", "mode": "markers", "name": "stability change", "meta": "stability",
                    "x": [c.speed_rpm for c in sc], "y": [c.frequency_hz for c in sc],
                    "marker": {"symbol": "star", "size": 13, "color": "red"},
                    "customdata": [[c.mode + 1, "becomes unstable" if c.onset else "becomes stable"] for c in sc],
                    "hovertemplate": hover("mode %{customdata[0]} %{customdata[1]}", "at %{x:.6~g} rpm, %{y:.5~g} Hz")})
    return out


def report(result, model=None, operating_speed: float | None = None) -> Report:
    """The Campbell report: the diagram and, with ``model``, the mode-shape panel a click fills.

    Parameters
    ----------
    result : CampbellResult
    model : Rotor, SystemMatrices or ReducedSystem, optional
        The model the diagram was computed on: its mode shapes at every speed are embedded (int8, the largest orbit
        127) for the click; without it the panel says how to get them.
    operating_speed : float, optional
        Operating speed of the reference spool (rad/s).
    """
    shapes = mode_shape_data(result, model) if model is not None and result.operating is not None else None
    note = ("Hover a point: its speed, frequency, mode, whirl, log dec and damping ratio; click the legend to hide a "
            "mode; x marks an unstable point (log dec < 0); diamonds are critical speeds.")
    panels = (Panel("campbell", campbell_figure(result, operating_speed), note),
              Panel("shape", figure([], layout("click a point of the Campbell diagram: its mode shape", "z (m)",
                                               "deflection (-)", yaxis={"range": [-1.3, 1.3]})),
                    "" if shapes else "mode shapes need the model: campbell_report(result, model=...)"))
    return Report(f"Campbell diagram - {result.rotor_name or 'rotor'}", tuple(result.summary()), panels,
                  {"shapes": shapes, "orbits": ORBITS}, _SCRIPT)


def mode_shape_data(result, model) -> dict:
    """Each tracked mode's shape at :data:`SHAPE_SPEEDS` speeds of ``result`` ("at": their indices): {"q": base64 of
    int8, shape (len(at), n_modes,
    n_nodes, 4) (Re X, Im X, Re Y, Im Y, scaled as :class:`rotorred.ModeShapes` scales them: the largest orbit's
    semi-major axis :data:`QUANTUM`), "z" (m), "spool" (index of each node), "spools", "nodes"}: the modes of
    :func:`rotorred.linear.campbell.modes_at` (one eigen-solve a speed), each Campbell column matched to the one
    with the closest eigenvalue."""
    from scipy.optimize import linear_sum_assignment

    from rotorred.linear.campbell import modes_at
    from rotorred.linear.modes import _scaled, node_motion
    from rotorred.model.assembly import system_of

    sm = system_of(model, sparse_ok=True)
    lines = result.operating.lines(sm)
    n = min(result.n_modes + 2, sm.n_dof)
    q, at = None, _shape_speeds(len(result.speeds), SHAPE_SPEEDS)
    for row, i in enumerate(at):
        Omega = result.speeds[i]
        lam, vectors = modes_at(sm, lines, float(Omega), n)
        nodes, node_spools, z, X, Y = node_motion(sm, vectors)
        cost = np.abs(_eigenvalues(result.frequencies[i], result.log_dec[i])[:, None] - lam[None, :])
        rows, cols = linear_sum_assignment(np.nan_to_num(cost, nan=1e300))
        X, Y = _scaled(X[cols], Y[cols])
        if q is None:
            q = np.zeros((len(at), result.n_modes, len(nodes), 4), np.int8)
        q[row, rows] = np.rint(QUANTUM * np.stack([X.real, X.imag, Y.real, Y.imag], axis=-1)).astype(np.int8)
    spools = list(dict.fromkeys(node_spools))
    return {"q": base64.b64encode(q.tobytes()).decode("ascii"), "shape": list(q.shape), "quantum": QUANTUM, "at": at,
            "z": z, "spool": [spools.index(s) for s in node_spools], "spools": spools, "nodes": nodes,
            "rpm": result.speeds_rpm, "hz": result.frequencies_hz, "whirl": result.whirl, "log_dec": result.log_dec}


def _shape_speeds(n: int, most: int) -> list[int]:
    """Indices of at most ``most`` of ``n`` speeds, evenly spread, the first and the last among them."""
    return sorted({int(round(k)) for k in np.linspace(0, n - 1, min(n, most))})


def _eigenvalues(omega, log_dec) -> np.ndarray:
    """lambda = -delta omega / (2 pi) + i omega of each mode (1/s)."""
    omega = np.asarray(omega, float)
    return -np.nan_to_num(np.asarray(log_dec, float)) * omega / (2 * math.pi) + 1j * omega


#: the click on a Campbell point: that mode's shape at that speed (the geometry of plots/modes.py's _draw_mode)
_SCRIPT = r"""
(function () {
  const S = RR.data.shapes, campbell = RR.div('campbell'), panel = RR.div('shape');
  if (!S) return;
  const raw = atob(S.q), q = new Int8Array(raw.length);
  for (let i = 0; i < raw.length; i++) q[i] = (raw.charCodeAt(i) << 24) >> 24;
  const [, nM, nN] = S.shape, colors = ['#1f77b4', '#ff7f0e', '#2ca02c', '#9467bd', '#8c564b'];
  function node(i, k, n) {
    const o = ((i * nM + k) * nN + n) * 4, s = 1 / S.quantum;
    return [q[o] * s, q[o + 1] * s, q[o + 2] * s, q[o + 3] * s];
  }
  function draw(clicked, k) {
    let r = 0;
    S.at.forEach((a, t) => { if (Math.abs(a - clicked) < Math.abs(S.at[r] - clicked)) r = t; });
    const i = S.at[r], X = [...Array(nN).keys()].map((n) => node(r, k, n));
    const major = X.map(([xr, xi, yr, yi]) => (Math.hypot(xr - yi, xi + yr) + Math.hypot(xr + yi, xi - yr)) / 2);
    const j = major.indexOf(Math.max(...major));
    let [ur, ui] = [X[j][0], X[j][2]];
    const m = Math.hypot(ur, ui);
    if (m > 0) { ur /= m; ui /= m; } else { ur = 1; ui = 0; }
    const zs = S.z, span = (Math.max(...zs) - Math.min(...zs)) || 1, width = 0.5 * span / Math.max(RR.data.orbits, 1);
    const data = [], notes = [];
    S.spools.forEach((name, s) => {
      const cols = [...Array(nN).keys()].filter((n) => S.spool[n] === s), color = colors[s % colors.length];
      data.push({type: 'scatter', mode: 'lines+markers', name: name, x: cols.map((n) => zs[n]), legendgroup: name,
                 y: cols.map((n) => ur * X[n][0] + ui * X[n][2]), line: {color: color, width: 2}, marker: {size: 4},
                 customdata: cols.map((n) => S.nodes[n]), hovertemplate: 'node %{customdata}, z = %{x:.4~g} m<br>' +
                 'deflection %{y:.3f}<extra>' + name + '</extra>'});
      const picks = [...new Set([...Array(RR.data.orbits).keys()].map((t) =>
        Math.round(t * (cols.length - 1) / Math.max(RR.data.orbits - 1, 1))))];
      picks.forEach((p) => {
        const n = cols[p], [xr, xi, yr, yi] = X[n], ox = [], oy = [];
        for (let t = 0; t <= 72; t++) {
          const ph = 2 * Math.PI * t / 72, c = Math.cos(ph), s = Math.sin(ph);
          const wr = xr * c - xi * s, wi = yr * c - yi * s;
          ox.push(zs[n] + width * (ur * wi - ui * wr)); oy.push(ur * wr + ui * wi);
        }
        data.push({type: 'scatter', mode: 'lines', x: ox, y: oy, showlegend: false, legendgroup: name,
                   hoverinfo: 'skip', line: {color: color, width: 1}, opacity: 0.8});
        if (Math.hypot(ox[9] - ox[0], oy[9] - oy[0]) > 1e-9)
          notes.push({x: ox[9], y: oy[9], ax: ox[0], ay: oy[0], axref: 'x', ayref: 'y', xref: 'x', yref: 'y', text: '',
                      showarrow: true, arrowhead: 2, arrowsize: 1.2, arrowwidth: 1.2, arrowcolor: color});
      });
    });
    const fmt = (v, p) => (v === null ? '-' : String(Number(v.toPrecision(p))));
    const title = 'mode ' + (k + 1) + ' at ' + fmt(S.rpm[i], 6) + ' rpm: ' + fmt(S.hz[i][k], 5) +
      ' Hz, ' + S.whirl[i][k] + ' whirl, log dec ' + fmt(S.log_dec[i][k], 4) +
      (i === clicked ? '' : ' (the nearest speed with its shape)');
    Plotly.react(panel, data, {title: {text: title, font: {size: 14}}, hovermode: 'closest', annotations: notes,
      xaxis: {title: {text: 'z (m)'}}, yaxis: {title: {text: 'deflection (-), orbits with the whirl sense (arrows)'},
      range: [-1.3, 1.3]}, margin: {l: 70, r: 20, t: 50, b: 55}}, RR.config);
  }
  Promise.all(RR.drawn).then(() => {
    campbell.on('plotly_click', (ev) => {
      const p = ev.points[0];
      if (p.data.meta === 'mode') draw(p.pointIndex, p.customdata[0] - 1);
    });
    draw(0, 0);
  });
})();
"""
