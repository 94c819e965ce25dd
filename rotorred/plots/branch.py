"""A harmonic-balance branch: the peak response against the varied key, stable solid, unstable dashed, stability
not computed grey, folds and corners marked (``rotorred continue``; :class:`rotorred.scenes.branch.SceneBranch`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rotorred import checks
from rotorred.plots.scene import _path, _save

__all__ = ["plot_branch"]


def plot_branch(values, peaks, stable, folds, path, *, xlabel: str, ylabel: str, changes=(), xscale: float = 1.0,
                scale: float = 1e6, unit: str = "µm", title: str | None = None) -> Path:
    """The branch's peak response against the key.

    Parameters
    ----------
    values : array_like, shape (p,)
        The key at each point (SI), p >= 1.
    peaks : array_like, shape (p,)
        The peak response at each point (m).
    stable : array_like of bool or float, or None, shape (p,)
        Each point's stability (solid where stable, dashed where not, grey where NaN: not computed); None: not computed
        anywhere (one grey line).
    folds : sequence of (float, bool)
        Each turn (the key's value, smooth or a corner), marked on the branch.
    path : str or Path
        Output file (.png, .pdf, ...).
    xlabel, ylabel : str
        The key's and the response's names with their plotted units.
    changes : sequence of (float, float, str)
        Where stability changes between two points (their values) and how ("period-doubling", "Neimark-Sacker",
        "fold"), marked midway.
    xscale, scale : float
        Plotted key ``xscale * values``, response ``scale * peaks`` (default µm from m).
    unit : str
        The response's plotted unit (in ``ylabel``'s legend entries).
    title : str, optional

    Returns
    -------
    Path
    """
    values = checks.vector("values", values, min_len=1)
    peaks = checks.vector("peaks", peaks, min_len=values.size, max_len=values.size)
    x, y = xscale * values, scale * peaks
    fig = Figure(figsize=(8, 5), layout="constrained")
    ax = fig.subplots()
    if stable is None:
        ax.plot(x, y, color="0.4", lw=1.5, label="branch (stability not computed)")
    else:
        _stability_segments(ax, x, y, np.asarray(stable, float))
    for value, smooth in folds:
        i = int(np.argmin(np.abs(values - value)))
        ax.plot(xscale * value, y[i], "o" if smooth else "s", ms=8, mfc="none", mew=1.5,
                color="tab:red" if smooth else "tab:purple",
                label="fold (saddle-node)" if smooth else "corner (contact starts or ends)")
    markers = {"period-doubling": ("v", "tab:orange"), "Neimark-Sacker": ("^", "tab:green"), "fold": ("D", "tab:red")}
    for a, b, kind in changes:
        i, j = (int(np.argmin(np.abs(values - v))) for v in (a, b))
        marker, colour = markers.get(kind, ("x", "k"))
        ax.plot(xscale * (a + b) / 2, (y[i] + y[j]) / 2, marker, ms=9, color=colour, label=f"{kind} (stability changes)")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    ax.legend(unique.values(), unique.keys(), fontsize=8, loc="best")
    return _save(fig, _path(path), title)


#: a run of points drawn by their stability (1 stable, 0 unstable, NaN not computed): line style, colour, label
_RUNS = {1.0: ("-", "tab:blue", "stable"), 0.0: ("--", "tab:blue", "unstable"),
         None: ("-", "0.6", "stability not computed")}


def _stability_segments(ax, x: np.ndarray, y: np.ndarray, stable: np.ndarray) -> None:
    """The branch as runs of stable (solid), unstable (dashed) and not computed (grey, ``stable`` NaN) points, each run
    joined to the next."""
    state = [None if np.isnan(s) else float(bool(s)) for s in stable]
    start = 0
    for i in range(1, len(x) + 1):
        if i == len(x) or state[i] != state[start]:
            end = min(i + 1, len(x))  # overlap one point so that the runs join
            style, colour, label = _RUNS[state[start]]
            ax.plot(x[start:end], y[start:end], style, color=colour, lw=1.8, label=label)
            start = i
