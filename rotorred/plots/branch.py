"""The figures of harmonic balance: a branch, the peak response against the varied key, stable solid, unstable
dashed, stability not computed grey, folds and corners marked (``rotorred continue``;
:class:`rotorred.scenes.branch.SceneBranch`, :class:`rotorred.nonlinear.continuation.Branch`); and a solution's
amplitudes per harmonic or line (:class:`rotorred.nonlinear.hb.PeriodicSolution`,
:class:`rotorred.nonlinear.torus.TorusSolution`).

Each draws into the given axes, or into a new figure (:func:`rotorred.plots.axes.axes`), and returns the Figure;
writing it is the caller's step (:func:`rotorred.plots.axes.save_figure`). A title goes above a new figure, or above the
given axes.
"""

from __future__ import annotations

import numpy as np

from rotorred import checks
from rotorred.plots.axes import axes

__all__ = ["plot_branch", "plot_harmonics", "laid_out", "titled"]


def titled(fig, ax, title: str | None, new: bool):
    """``fig`` with ``title`` above it (a ``new`` figure) or above ``ax`` (axes given by the caller); the figure."""
    if title:
        (fig.suptitle if new else ax.set_title)(title)
    return fig


def laid_out(ax, figsize: tuple[float, float]):
    """``(fig, ax, new)``: the given axes, or a new figure of ``figsize`` (in) laid out by constrained layout."""
    fig, ax_ = axes(ax, figsize)
    if ax is None:
        fig.set_layout_engine("constrained")
    return fig, ax_, ax is None


def plot_branch(values, peaks, stable, folds, ax=None, *, xlabel: str, ylabel: str, changes=(), xscale: float = 1.0,
                scale: float = 1e6, unit: str = "µm", title: str | None = None, breaks=()):
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
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
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
    breaks : sequence of int
        Positions ``i`` of points not joined to point ``i - 1`` (a stretch not traced between them).

    Returns
    -------
    matplotlib.figure.Figure
    """
    values = checks.vector("values", values, min_len=1)
    peaks = checks.vector("peaks", peaks, min_len=values.size, max_len=values.size)
    x, y = xscale * values, scale * peaks
    cut = [checks.integer("breaks", i, ge=1, le=values.size - 1) for i in breaks]
    fig, ax, new = laid_out(ax, (8, 5))
    xl, yl = np.insert(x, cut, np.nan), np.insert(y, cut, np.nan)  # NaN: the line stops there
    if stable is None:
        ax.plot(xl, yl, color="0.4", lw=1.5, label="branch (stability not computed)")
    else:
        stable = np.asarray(stable, float)
        _stability_segments(ax, xl, yl, np.insert(stable, cut, stable[np.asarray(cut, int) - 1]))
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
    return titled(fig, ax, title, new)


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


#: the most columns (DOFs) :func:`plot_harmonics` draws unless told which
MAX_COLUMNS = 6


def plot_harmonics(frequencies, amplitudes, labels, ax=None, *, columns=None, dynamic_range: float = 1e8,
                   scale: float = 1e6, unit: str = "µm", title: str | None = None):
    """A solution's amplitude of each harmonic (or line) at its frequency, a stem a column (DOF), on a log scale from
    the largest over ``dynamic_range`` up.

    Parameters
    ----------
    frequencies : array_like, shape (K,)
        Frequency of each harmonic or line (Hz, >= 0).
    amplitudes : array_like, shape (K, n)
        Its amplitude in each column (m); zeros are not drawn.
    labels : sequence of str, length n
        The columns' names (the legend).
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    columns : sequence of int, optional
        The columns drawn (default: all, or the :data:`MAX_COLUMNS` of largest amplitude).
    dynamic_range : float
        Amplitudes below the largest over this are not drawn (round-off, 1e-17 of a solution, is not shown).
    scale, unit : float, str
        Plotted amplitudes ``scale * amplitudes`` in ``unit`` (default µm from m).
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    f = checks.vector("frequencies", frequencies, min_len=1)
    A = scale * checks.array("amplitudes", amplitudes, (f.size, len(labels)), "m")
    dynamic_range = checks.number("dynamic_range", dynamic_range, gt=1.0)
    if columns is None:
        columns = np.sort(np.argsort(-A.max(axis=0))[:MAX_COLUMNS])
    fig, ax, new = laid_out(ax, (8, 5))
    floor = (float(A[:, columns].max()) or 1.0) / dynamic_range
    width = 0.3 * float(np.min(np.diff(np.unique(f)), initial=1.0) or 1.0) / max(len(columns), 1)
    for i, c in enumerate(columns):
        x, y = f + (i - (len(columns) - 1) / 2) * width, A[:, c]
        drawn = y > floor
        ax.vlines(x[drawn], floor, y[drawn], color=f"C{i}", lw=1.2)
        ax.plot(x[drawn], y[drawn], "o", ms=4, color=f"C{i}", label=labels[c])
    ax.set_yscale("log")
    ax.set_ylim(bottom=floor)
    ax.set_xlabel("Frequency (Hz)")
    ax.set_ylabel(f"Amplitude ({unit})")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return titled(fig, ax, title, new)
