"""Interactive branch of periodic solutions: amplitude against the continuation parameter, stable solid, unstable
dashed, not computed dotted; folds and bifurcations marked with their values on hover
(:class:`rotorred.scenes.branch.SceneBranch`, ``rotorred continue``;
:class:`rotorred.nonlinear.continuation.Branch`)."""

from __future__ import annotations

import numpy as np

from rotorred.plots.interactive._layout import MICRO, color, figure, hover, layout
from rotorred.plots.interactive.report import Panel, Report

#: line of a stretch by its stability flag (1 stable, 0 unstable, -1 not computed)
_DASH = {1: ("solid", "stable"), 0: ("dash", "unstable"), -1: ("dot", "stability not computed")}


def figures(result) -> list[tuple[str, dict]]:
    """The branch of ``result``.

    Parameters
    ----------
    result : SceneBranch or Branch
    """
    return [("branch", branch_figure(result))]


def _scene_branch(result):
    """x, {name: y (µm)}, flags, hover columns, folds [(x, text)], bifurcations [(x, text)], titles of a
    SceneBranch."""
    xs, xu = result.shown
    x = xs * np.asarray(result.values, float)
    ys = {f"node {n} {d}": MICRO * result.peaks[:, k] for k, (n, d) in enumerate(result.dofs)}
    custom = np.column_stack([result.f0, result.multipliers])
    folds = [(xs * v, f"{'fold' if smooth else 'corner'} at {result.key} = {xs * v:.6g} {xu}")
             for v, smooth in result.folds]
    bifs = [(xs * (a + b) / 2, f"{kind} between {xs * a:.6g} and {xs * b:.6g} {xu}")
            for a, b, kind in result.bifurcations]
    return (x, ys, result.flags, custom, folds, bifs, f"{result.key} ({xu})", "peak of q(t) over a period (µm)",
            f"harmonic-balance branch of {result.scene} in {result.key}",
            ("f_0 %{customdata[0]:.6~g} Hz", "largest Floquet multiplier |µ| %{customdata[1]:.4~g}"))


def _plain_branch(result):
    """The same of a :class:`rotorred.nonlinear.continuation.Branch`: the largest sum of harmonic amplitudes."""
    name, unit = result.parameter
    x = np.asarray(result.values, float)
    amplitude = np.abs(result.phasors).sum(axis=1).max(axis=1)
    flags = np.where(result.known, np.where(result.stable, 1, 0), -1)
    custom = np.column_stack([result.omega, result.max_real])
    folds = [(f.value, f"{'fold' if f.smooth else 'corner'} at {name} = {f.value:.6g} {unit}") for f in result.folds]
    changes = np.flatnonzero(np.diff(flags) != 0)
    bifs = [(x[i:i + 2].mean(), f"stability changes between {x[i]:.6g} and {x[i + 1]:.6g} {unit}")
            for i in changes if flags[i] >= 0 and flags[i + 1] >= 0]
    return (x, {"sum of harmonic amplitudes (largest DOF)": amplitude}, flags, custom, folds, bifs,
            f"{name} ({unit})", "sum of |Q_k| (m or rad)", "branch of periodic solutions",
            ("omega %{customdata[0]:.6~g} rad/s", "largest Floquet exponent real part %{customdata[1]:.4~g} 1/s"))


def branch_figure(result) -> dict:
    """The branch: one trace a stretch of equal stability and output, folds (triangles) and bifurcations (stars)."""
    x, ys, flags, custom, folds, bifs, xtitle, ytitle, title, extra = (
        _scene_branch(result) if hasattr(result, "peaks") else _plain_branch(result))
    data, shown = [], set()
    for k, (name, y) in enumerate(ys.items()):
        for lo, hi in _stretches(flags):
            dash, state = _DASH[int(flags[lo])]
            part = slice(lo, min(hi + 2, len(x)))  # each stretch joins the next one's first point
            data.append({"type": "scatter", "mode": "lines", "x": x[part], "y": y[part],
                         "name": f"{name}, {state}", "legendgroup": f"{name} {state}",
                         "showlegend": (name, state) not in shown, "customdata": custom[part],
                         "line": {"dash": dash, "width": 2, "color": color(k)},
                         "hovertemplate": hover(f"{name}: {state}", f"{xtitle} %{{x:.6~g}}", "%{y:.4~g}", *extra)})
            shown.add((name, state))
        if k == 0:
            data += _marks(x, y, folds, bifs)
    return figure(data, layout(title + " (stable solid, unstable dashed)", xtitle, ytitle))


def _marks(x, y, folds, bifs) -> list[dict]:
    """Folds (triangles) and bifurcations (stars) on the curve ``y`` (at its point nearest each value)."""
    out = []
    for marks, symbol, label in ((folds, "triangle-up", "folds"), (bifs, "star", "bifurcations")):
        if marks:
            at = [int(np.argmin(np.abs(x - m[0]))) for m in marks]
            out.append({"type": "scatter", "mode": "markers", "name": label, "x": [m[0] for m in marks],
                        "y": y[at], "text": [m[1] for m in marks], "hovertemplate": hover("%{text}"),
                        "marker": {"symbol": symbol, "size": 12, "color": "black" if label == "folds" else "red"}})
    return out


def _stretches(flags) -> list[tuple[int, int]]:
    """(first, last) index of each run of equal flags."""
    flags = np.asarray(flags)
    if not flags.size:
        return []
    cuts = np.flatnonzero(np.diff(flags) != 0) + 1
    starts = np.concatenate([[0], cuts])
    ends = np.concatenate([cuts - 1, [flags.size - 1]])
    return list(zip(starts.tolist(), ends.tolist()))


def report(result) -> Report:
    """The branch's report.

    Parameters
    ----------
    result : SceneBranch or Branch
    """
    return Report(getattr(result, "scene", "") and f"branch of {result.scene}" or "branch", tuple(result.summary()),
                  (Panel("branch", branch_figure(result), "Hover the branch: the value, the amplitude and the "
                                                          "stability; folds (triangles) and bifurcations (stars) "
                                                          "with their values."),))
