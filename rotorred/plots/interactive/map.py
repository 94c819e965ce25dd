"""Interactive map of the operating envelope (:class:`rotorred.maps.run.MapRun`): the class map (one marker a point,
a colour a class; hover: class, settling, explained share, contact) and the bifurcation diagram (the Poincare samples
of the table DOF against the first key); in the report a click on a point draws its orbit in the phase plane of the
table DOF (from its labelled lines, its Poincare samples on it) and its line spectrum.

A map stores, per point, the labelled lines (frequency, amplitude, phase) and the Poincare samples of the table DOF
(:mod:`rotorred.maps.point`), not its time record: the orbit drawn is ``x(t) = sum a cos(2 pi f t + phase)`` against
its derivative, over :data:`ORBIT_PERIODS` periods of the lowest line, :data:`ORBIT_PER_CYCLE` samples a period of
the highest.
"""

from __future__ import annotations

import numpy as np

from rotorred.plots.interactive._layout import MICRO, decimated, figure, hover, layout
from rotorred.plots.interactive.report import Panel, Report

#: Poincare samples of a point drawn in the bifurcation diagram (the last ones), and embedded for its orbit
BIFURCATION_SAMPLES, ORBIT_SAMPLES = 100, 400
#: periods of the lowest line the orbit of a clicked point spans, and its samples: at least ORBIT_POINTS,
#: ORBIT_PER_CYCLE a period of the highest line, at most ORBIT_MOST
ORBIT_PERIODS, ORBIT_POINTS, ORBIT_PER_CYCLE, ORBIT_MOST = 20, 2000, 40, 40000
#: colours of the classes
CLASS_COLORS = {"periodic": "#1f77b4", "quasi-periodic": "#2ca02c", "chaotic": "#d62728", "unexplained": "#9467bd",
                "unsettled": "#7f7f7f", "failed": "#000000", "period-2": "#e377c2", "period-3": "#bcbd22",
                "period-4": "#17becf"}
_DIRECTION_COLORS = {"up": "#1f77b4", "down": "#ff7f0e"}


def points(dataset) -> list[dict]:
    """Every point of the map's dataset, in order: its index (direction, key indices), direction, key values, class
    label, settling time (s, NaN: not settled), explained share, contact fraction, impacts, lines (Hz, m, rad,
    label) and Poincare samples (m, m/s) of the table DOF."""
    ds = dataset
    keys = list(ds["status"].dims[1:])
    directions = ds["direction_label" if "direction_label" in ds.variables else "direction"].values  # (as read back)
    out = []
    for index in np.ndindex(ds["status"].shape):
        at = dict(zip(ds["status"].dims, index))
        value = {k: float(ds[k].values[at[k]]) for k in keys}
        status = str(ds["status"].values[index])
        kind = str(ds["kind"].values[index]) or ("failed" if status and status != "ok" else "")
        if kind == "period-k":
            kind = f"period-{int(ds['subharmonic'].values[index])}"
        labels = ds["line_label"].values[index]
        keep = np.flatnonzero((labels != "") & np.isfinite(ds["line_frequency"].values[index]))
        px, pv = ds["poincare_x"].values[index], ds["poincare_velocity"].values[index]
        ok = np.isfinite(px) & np.isfinite(pv)
        out.append({"index": index, "direction": str(directions[index[0]]), "value": value,
                    "kind": kind or "not run", "settling": float(ds["settling_time"].values[index]),
                    "explained": float(ds["explained_share"].values[index]),
                    "contact": float(ds["contact_fraction"].values[index]),
                    "impacts": int(ds["n_impacts"].values[index]),
                    "lines": (ds["line_frequency"].values[index][keep], ds["line_amplitude"].values[index][keep],
                              ds["line_phase"].values[index][keep], labels[keep]),
                    "poincare": (px[ok], pv[ok])})
    return out


def _key_title(ds, key: str) -> str:
    unit, name = ds[key].attrs.get("units", ""), ds[key].attrs.get("long_name", key)
    return f"{name} ({unit})" if unit and unit != "1" else name


def figures(result) -> list[tuple[str, dict]]:
    """The class map and the bifurcation diagram of ``result``.

    Parameters
    ----------
    result : MapRun
    """
    pts = points(result.dataset)
    return [("classes", class_figure(result.dataset, pts)), ("bifurcation", bifurcation_figure(result.dataset, pts))]


def _hover_row(p: dict) -> list:
    settling = "not settled" if not np.isfinite(p["settling"]) else f"settled after {p['settling']:.3g} s"
    explained = "-" if not np.isfinite(p["explained"]) else f"{p['explained']:.3f}"
    contact = "-" if not np.isfinite(p["contact"]) else f"{p['contact']:.3g}"
    where = ", ".join(f"{k} = {v:.6g}" for k, v in p["value"].items())
    return [p["kind"], settling, explained, contact, p["impacts"], f"{where} ({p['direction']})"]


_POINT_HOVER = hover("%{customdata[6]}", "class %{customdata[1]}, %{customdata[2]}",
                     "explained share %{customdata[3]}",
                     "contact %{customdata[4]} of the time, %{customdata[5]} impacts",
                     "(click: its orbit and spectrum)")


def class_figure(ds, pts: list[dict]) -> dict:
    """One marker a point, a trace a class: against the first key and the sweep direction (one key) or the second
    key (two keys; the down sweep's markers open)."""
    keys = list(ds["status"].dims[1:])
    data = []
    for kind in dict.fromkeys(p["kind"] for p in pts):
        group = [(i, p) for i, p in enumerate(pts) if p["kind"] == kind]
        x = [p["value"][keys[0]] for _, p in group]
        y = [p["direction"] for _, p in group] if len(keys) == 1 else [p["value"][keys[1]] for _, p in group]
        data.append({"type": "scatter", "mode": "markers", "name": kind, "x": x, "y": y, "meta": "points",
                     "marker": {"size": 11, "color": CLASS_COLORS.get(kind, "#8c564b"), "line": {"width": 1},
                                "symbol": ["circle-open" if len(keys) > 1 and p["direction"] == "down" else "circle"
                                           for _, p in group]},
                     "customdata": [[i, *_hover_row(p)] for i, p in group], "hovertemplate": _POINT_HOVER})
    ytitle = "sweep direction" if len(keys) == 1 else _key_title(ds, keys[1])
    return figure(data, layout(f"class map of {ds.attrs.get('scene', 'the map')} (table DOF "
                               f"{ds.attrs.get('table_dof', '')}; click a point: its orbit and spectrum)",
                               _key_title(ds, keys[0]), ytitle))


def bifurcation_figure(ds, pts: list[dict]) -> dict:
    """The last :data:`BIFURCATION_SAMPLES` Poincare samples of each point (µm) against the first key, a trace a
    point (``meta`` its index), coloured by sweep direction."""
    keys = list(ds["status"].dims[1:])
    data, shown = [], set()
    for i, p in enumerate(pts):
        x = p["poincare"][0][-BIFURCATION_SAMPLES:]
        if not x.size:
            continue
        d = p["direction"]
        row = _hover_row(p)
        data.append({"type": "scatter", "mode": "markers", "x": np.full(x.size, p["value"][keys[0]]),
                     "y": MICRO * x, "name": f"{d} sweep", "legendgroup": d, "showlegend": d not in shown,
                     "marker": {"size": 3, "color": _DIRECTION_COLORS.get(d, "#444")}, "meta": i,
                     "hovertemplate": hover(row[5], f"class {row[0]}, {row[1]}", f"explained share {row[2]}",
                                            f"contact {row[3]} of the time, {row[4]} impacts", "%{y:.4~g} µm")})
        shown.add(d)
    return figure(data, layout(f"bifurcation diagram: Poincare samples of {ds.attrs.get('table_dof', 'the table DOF')}",
                               _key_title(ds, keys[0]), "Poincare samples (µm)"))


def report(result) -> Report:
    """The map's report: class map, bifurcation diagram, and the orbit and spectrum of a clicked point.

    Parameters
    ----------
    result : MapRun
    """
    ds = result.dataset
    pts = points(ds)
    data = {"dof": ds.attrs.get("table_dof", ""), "periods": ORBIT_PERIODS, "samples": ORBIT_POINTS,
            "per_cycle": ORBIT_PER_CYCLE, "most": ORBIT_MOST,
            "points": [{"title": f"{_hover_row(p)[5]}: {p['kind']}", "f": p["lines"][0], "a": p["lines"][1],
                        "p": p["lines"][2], "l": p["lines"][3],
                        "px": p["poincare"][0][decimated(p["poincare"][0].size, ORBIT_SAMPLES)],
                        "pv": p["poincare"][1][decimated(p["poincare"][1].size, ORBIT_SAMPLES)]} for p in pts]}
    panels = (Panel("classes", class_figure(ds, pts), "Hover a point: its class, settling, explained share and "
                                                      "contact; click it: its orbit and spectrum below."),
              Panel("bifurcation", bifurcation_figure(ds, pts)),
              Panel("orbit", figure([], layout("click a point: its orbit", "x (µm)", "dx/dt (µm/s)")), row=1),
              Panel("spectrum", figure([], layout("click a point: its spectrum", "frequency (Hz)", "amplitude (µm)")),
                    row=1))
    return Report(f"map of {ds.attrs.get('scene', '')}", tuple(result.summary()), panels, data, _SCRIPT)


#: a click on a point: its phase-plane orbit from its lines (with its Poincare samples) and its line spectrum
_SCRIPT = r"""
(function () {
  const D = RR.data, orbit = RR.div('orbit'), spectrum = RR.div('spectrum');
  const margin = {l: 70, r: 20, t: 50, b: 55};
  function show(i) {
    const P = D.points[i], f = P.f, a = P.a, ph = P.p;
    const low = Math.min(...f.filter((v) => v > 0)), T = isFinite(low) ? D.periods / low : 1;
    const n = Math.min(D.most, Math.max(D.samples, Math.ceil(D.per_cycle * Math.max(...f, 0) * T)));
    const x = [], v = [];
    for (let s = 0; s <= n; s++) {
      const t = T * s / n;
      let xs = 0, vs = 0;
      for (let k = 0; k < f.length; k++) {
        const w = 2 * Math.PI * f[k], arg = w * t + ph[k];
        xs += a[k] * Math.cos(arg); vs -= a[k] * w * Math.sin(arg);
      }
      x.push(1e6 * xs); v.push(1e6 * vs);
    }
    Plotly.react(orbit, [
      {type: 'scatter', mode: 'lines', x: x, y: v, name: 'from the lines', line: {width: 1},
       hovertemplate: '%{x:.4~g} µm, %{y:.4~g} µm/s<extra></extra>'},
      {type: 'scatter', mode: 'markers', x: P.px.map((u) => 1e6 * u), y: P.pv.map((u) => 1e6 * u),
       name: 'Poincare samples', marker: {size: 4, color: 'black'},
       hovertemplate: '%{x:.4~g} µm, %{y:.4~g} µm/s<extra></extra>'}],
      {title: {text: 'orbit of ' + D.dof + ' (phase plane) - ' + P.title, font: {size: 13}}, margin: margin,
       hovermode: 'closest', xaxis: {title: {text: 'displacement (µm)'}}, yaxis: {title: {text: 'velocity (µm/s)'}},
       legend: {orientation: 'h', y: -0.2}}, RR.config);
    const top = Math.max(...f, 1);
    Plotly.react(spectrum, [{type: 'bar', x: f, y: a.map((u) => 1e6 * u), width: f.map(() => top / 150),
       customdata: P.l, name: 'lines', hovertemplate: '%{customdata}<br>%{x:.6~g} Hz<br>%{y:.4~g} µm<extra></extra>'}],
      {title: {text: 'line spectrum of ' + D.dof + ' - ' + P.title, font: {size: 13}}, margin: margin,
       hovermode: 'closest', xaxis: {title: {text: 'frequency (Hz)'}}, yaxis: {title: {text: 'amplitude (µm)'}}},
      RR.config);
  }
  Promise.all(RR.drawn).then(() => {
    RR.div('classes').on('plotly_click', (ev) => show(ev.points[0].customdata[0]));
    RR.div('bifurcation').on('plotly_click', (ev) => show(ev.points[0].data.meta));
    if (D.points.length) show(0);
  });
})();
"""
