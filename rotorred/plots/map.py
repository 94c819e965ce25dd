"""Figures of a response map (``rotorred map``): bifurcation diagram, spectral waterfall, 2-D heat map.

A map varies one or two scene keys over a grid, sweeping up and/or down with continuation, and
records per point the response class, the Poincaré samples of one displacement DOF and the
labelled spectral lines. These helpers draw them from plain numpy arrays (no xarray): the varied
values in SI, the samples and line amplitudes in m (plotted in µm by default, ``scale=1e6``,
``unit="µm"``), the line frequencies in Hz. Counts that differ from point to point (samples,
lines) come NaN-padded; a point whose row is all NaN (a failed run) is skipped. The varied values
are plotted as ``xscale * values``, so a caller shows a speed in Hz or rpm, a clearance in µm.

Every helper checks its arguments with :mod:`rotorred.checks` before drawing, draws into the
given axes or into a new :class:`matplotlib.figure.Figure` (no pyplot), and returns the Figure;
writing it is the caller's step (:func:`rotorred.plots.axes.save_figure`). They draw
:meth:`rotorred.maps.run.MapRun.plot`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
from matplotlib.figure import Figure

from rotorred import checks
from rotorred.plots.axes import DPI
from rotorred.plots.branch import laid_out, titled

__all__ = ["plot_bifurcation", "plot_waterfall", "plot_lines", "plot_heatmap", "CLASS_COLOURS"]

#: fixed colour of each response class (:data:`rotorred.signals.classify.KINDS`) and of a failed run
CLASS_COLOURS = {
    "periodic": "#1f77b4",  # blue
    "period-k": "#2ca02c",  # green
    "quasi-periodic": "#ff7f0e",  # orange
    "chaotic": "#d62728",  # red
    "unexplained": "#9467bd",  # purple
    "unsettled": "#7f7f7f",  # grey
    "failed": "#000000",  # black
}
#: colours of other categories of a heat map, in turn
_OTHER_COLOURS = ("#17becf", "#bcbd22", "#8c564b", "#e377c2", "#aec7e8", "#98df8a", "#ffbb78", "#ff9896")
#: colour of a sweep of a bifurcation diagram by label; other labels take the next of _OTHER_SWEEPS
_SWEEP_COLOURS = {"up": "tab:blue", "down": "tab:red"}
_OTHER_SWEEPS = ("tab:green", "tab:purple", "tab:brown", "tab:olive", "tab:cyan", "tab:pink")


# --------------------------------------------------------------------------- checks
def _padded(field: str, value, shape: tuple[int | str, ...], unit: str = "") -> np.ndarray:
    """A real 2-D float array of ``shape`` (a str entry: any length >= 1), NaN-padded (no infinities)."""
    wanted = "(" + ", ".join(str(s) for s in shape) + ")"
    if np.iscomplexobj(value):
        checks.fail(field, value, "must be an array of real numbers", unit)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        checks.fail(field, value, f"must be an array of numbers of shape {wanted}", unit)
    fits = arr.ndim == len(shape) and all(n == s if isinstance(s, int) else n >= 1 for n, s in zip(arr.shape, shape))
    if not fits:
        checks.fail(field, value, f"must have shape {wanted}", unit)
    if np.any(np.isinf(arr)):
        checks.fail(field, value, "must hold finite numbers or NaN (padding) only", unit)
    return arr


def _not_negative(field: str, arr: np.ndarray, unit: str) -> np.ndarray:
    """``arr`` if every finite entry is >= 0."""
    if np.any(arr[np.isfinite(arr)] < 0):
        checks.fail(field, arr, "must hold values >= 0 or NaN (padding) only", unit)
    return arr


def _grid(field: str, value) -> np.ndarray:
    """A 1-D grid of at least one value, strictly increasing or strictly decreasing."""
    v = checks.vector(field, value, min_len=1)
    step = np.diff(v)
    if not (np.all(step > 0) or np.all(step < 0)):
        checks.fail(field, value, "must be strictly increasing or strictly decreasing")
    return v


def _sweeps(samples, n: int) -> dict[str, np.ndarray]:
    """``{label: array (n, S)}`` from the mapping of sweeps, checked."""
    if not isinstance(samples, Mapping) or not samples:
        checks.fail("samples", samples, "must be a non-empty mapping sweep label -> array (n, S)")
    return {str(k): _padded(f"samples[{k!r}]", v, (n, "S"), "m") for k, v in samples.items()}


def _orders(orders) -> dict[str, float]:
    """``{label: slope}`` of the order lines, checked (slopes > 0)."""
    if orders is None:
        return {}
    if not isinstance(orders, Mapping):
        checks.fail("orders", orders, "must be a mapping label -> slope (frequency = slope * value)")
    return {str(k): checks.positive(f"orders[{k!r}]", v, "Hz per unit of values") for k, v in orders.items()}


def _categories(categories, z: np.ndarray) -> tuple[str, ...]:
    """The category names, checked, with ``z`` holding only their indices or -1."""
    if isinstance(categories, str) or not isinstance(categories, Sequence):
        checks.fail("categories", categories, "must be a list of category names")
    names = checks.sequence("categories", list(categories), lambda f, v: checks.string(f, v, empty=False),
                            min_len=1, unique=True)
    ok = np.isfinite(z) & (z == np.round(z)) & (z >= -1) & (z < len(names))
    if not np.all(ok):
        checks.fail("z", z, f"must hold category indices 0 to {len(names) - 1}, or -1 for missing")
    return names


# --------------------------------------------------------------------------- bifurcation diagram
def plot_bifurcation(values, samples, ax=None, *, xlabel: str, ylabel: str = "Poincaré samples", scale: float = 1e6,
                     unit: str = "µm", xscale: float = 1.0, title: str | None = None):
    """Bifurcation diagram: the Poincaré samples of each point as dots above its value, one colour per sweep.

    A periodic response shows as one dot per value, period-k as k dots, a quasi-periodic or chaotic
    one as a vertical smear. Sweeps are overlaid ("up" blue, "down" red, others in further colours):
    the first as dots, the others as rings of growing size, so where sweeps share a branch both show.

    Parameters
    ----------
    values : array_like, shape (n,)
        The varied key (SI), n >= 1.
    samples : mapping
        ``{sweep label: array shape (n, S)}``, e.g. ``{"up": ..., "down": ...}``: the Poincaré samples
        of one displacement DOF at each value (m), NaN-padded; an all-NaN row (a failed run) is skipped.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    xlabel : str
        Name and unit of the varied key as plotted, e.g. "Outer spool speed (Hz)".
    ylabel : str
        Name of the samples; the unit is appended.
    scale, unit : float, str
        Plotted samples are ``scale * samples`` in ``unit`` (default µm from m).
    xscale : float
        Plotted values are ``xscale * values`` (e.g. 1e6 for a clearance in µm).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale, xscale = checks.positive("scale", scale), checks.positive("xscale", xscale)
    values = checks.vector("values", values, min_len=1)
    sweeps = _sweeps(samples, values.size)
    fig, ax, new = laid_out(ax, (9, 5.5))
    for i, (label, s) in enumerate(sweeps.items()):
        _sweep_dots(ax, xscale * values, scale * s, label, _sweep_colour(label, i), i)
    if not any(np.isfinite(s).any() for s in sweeps.values()):
        _no_data(ax, "no Poincaré samples (every run failed)")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"{ylabel} ({unit})")
    ax.grid(True, alpha=0.3)
    if new:  # above the axes, under the figure's title
        ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=4, fontsize=8, frameon=False)
    else:  # inside: the title is the axes' own
        ax.legend(loc="best", fontsize=8)
    return titled(fig, ax, title, new)


def _sweep_colour(label: str, i: int) -> str:
    return _SWEEP_COLOURS.get(label, _OTHER_SWEEPS[i % len(_OTHER_SWEEPS)])


def _sweep_dots(ax, x: np.ndarray, y: np.ndarray, label: str, colour: str, i: int) -> None:
    """The finite samples of sweep ``i`` at their value: the first as dots, later ones as rings around them
    (so both show where the sweeps share a branch); the legend counts the points without samples."""
    xx = np.broadcast_to(x[:, None], y.shape)
    keep = np.isfinite(y)
    missing = int(np.sum(~keep.any(axis=1)))
    text = f"{label} ({missing} of {x.size} points without samples)" if missing else label
    style = dict(mfc=colour, mec="none", ms=3.0) if i == 0 else dict(mfc="none", mec=colour, mew=1.0, ms=4.0 + 2.0 * i)
    ax.plot(xx[keep], y[keep], "o", color=colour, label=text, linestyle="none", **style)


def _no_data(ax, text: str) -> None:
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", color="0.4")


# --------------------------------------------------------------------------- line amplitudes
def plot_lines(values, amplitudes, contact, impacts, ax=None, *, xlabel: str, xscale: float = 1.0,
               reach: float | None = None, n_lines: int = 4, scale: float = 1e6, unit: str = "µm",
               ylabel: str = "Line amplitude", title: str | None = None):
    """Labelled line amplitudes and the rub contact against the varied key (one sweep).

    Top: the spools' lines f_L and f_H, the ``n_lines`` other lines strongest over the map, and
    the sum of every other line. Bottom: the contact fraction (%) and the impacts in the record.
    ``reach`` (a clearance axis) marks the free orbit's reach, beyond which the settled free
    orbit touches nothing.

    Parameters
    ----------
    values : array_like, shape (n,)
        The varied key (SI), n >= 1.
    amplitudes : mapping
        ``{line label: array shape (n,)}``: amplitude (m) of that line at each point, 0 where the
        line is not among the point's lines, NaN for a failed point.
    contact, impacts : array_like, shape (n,)
        Contact fraction (0..1) and contact onsets per point (NaN for a failed point).
    ax : pair of matplotlib Axes, optional
        Where to draw the two panels, (top, bottom) (default: a new figure of two panels sharing x).
    xlabel : str
        Name and unit of the varied key as plotted.
    xscale : float
        Plotted values are ``xscale * values``.
    reach : float, optional
        Free orbit reach (SI, the key's unit), drawn as a dashed line at ``xscale * reach``.
    n_lines : int
        Other lines drawn besides f_L and f_H.
    scale, unit, ylabel : float, str, str
        Plotted amplitudes are ``scale * amplitudes`` in ``unit``.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale, xscale = checks.positive("scale", scale), checks.positive("xscale", xscale)
    values = checks.vector("values", values, min_len=1)
    if not isinstance(amplitudes, Mapping):
        checks.fail("amplitudes", amplitudes, "must be a mapping line label -> array (n,)")
    amps = {str(k): _not_negative(f"amplitudes[{k!r}]", _padded(f"amplitudes[{k!r}]", v, (values.size,), "m"), "m")
            for k, v in amplitudes.items()}
    contact = _padded("contact", contact, (values.size,))
    impacts = _padded("impacts", impacts, (values.size,))
    n_lines = checks.integer("n_lines", n_lines, ge=0)
    fig, (ax1, ax2), new = *_two_panels(ax), ax is None
    x = xscale * values
    spools = [k for k in ("f_L", "f_H") if k in amps]
    others = sorted((k for k in amps if k not in spools), key=lambda k: -float(np.nanmax(amps[k], initial=0.0)))
    for k in spools + others[:n_lines]:
        ax1.plot(x, scale * amps[k], "-o" if k in spools else "--s", ms=4, label=k)
    if others:
        total = np.sum([amps[k] for k in others], axis=0)
        ax1.plot(x, scale * total, ":", color="k", label=f"sum of the {len(others)} other lines")
    if not amps:
        _no_data(ax1, "no labelled lines (every run failed)")
    ax1.set_ylabel(f"{ylabel} ({unit})")
    ax1.grid(True, alpha=0.3)
    ax2.plot(x, 100 * contact, "-o", ms=4, color="C3", label="contact fraction")
    ax2.set_ylabel("Contact fraction of the record (%)")
    ax2.set_xlabel(xlabel)
    ax2.grid(True, alpha=0.3)
    ax3 = ax2.twinx()
    ax3.plot(x, impacts, "-^", ms=4, color="C4", label="impacts in the record")
    ax3.set_ylabel("Impacts")
    if reach is not None and np.isfinite(reach):
        for ax in (ax1, ax2):
            ax.axvline(xscale * reach, color="0.4", ls="--", lw=1.0, label=f"free orbit reach {xscale * reach:.3g}")
    h2, l2 = ax2.get_legend_handles_labels()
    h3, l3 = ax3.get_legend_handles_labels()
    ax2.legend(h2 + h3, l2 + l3, loc="upper right", fontsize=8)
    if amps:
        ax1.legend(loc="upper right", fontsize=8)
    return titled(fig, ax1, title, new)


def _two_panels(ax):
    """``(fig, (top, bottom))``: the given pair of axes, or a new figure of two panels sharing x."""
    if ax is None:
        fig = Figure(figsize=(9, 7.5), layout="constrained", dpi=DPI)
        return fig, fig.subplots(2, 1, sharex=True)
    if not (isinstance(ax, Sequence) or isinstance(ax, np.ndarray)) or len(ax) != 2:
        checks.fail("ax", ax, "must be a pair of axes (top, bottom): the lines figure has two panels")
    return ax[0].figure, tuple(ax)


# --------------------------------------------------------------------------- waterfall
def plot_waterfall(values, frequencies, amplitudes, ax=None, *, xlabel: str, f_max: float | None = None,
                   orders: Mapping[str, float] | None = None, dynamic_range: float = 1e4, scale: float = 1e6,
                   unit: str = "µm", xscale: float = 1.0, title: str | None = None):
    """Spectral waterfall seen from above: the lines of each point along its value, coloured by amplitude.

    Each point is a horizontal "slice" at ``y = xscale * value``: one dot per spectral line at its
    frequency, its colour (log scale) and size growing with the amplitude.

    Parameters
    ----------
    values : array_like, shape (n,)
        The varied key (SI), n >= 1.
    frequencies, amplitudes : array_like, shape (n, L)
        The labelled lines of each point: frequency (Hz, >= 0) and amplitude (m, >= 0), NaN-padded; a
        line is drawn where both are finite and the amplitude is > 0.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    xlabel : str
        Name and unit of the varied key as plotted, e.g. "Outer spool speed (Hz)" (on the vertical axis).
    f_max : float, optional
        Upper limit of the frequency axis (Hz); default 5 % above the highest line.
    orders : mapping, optional
        ``{label: slope}`` order lines, frequency (Hz) ``= slope * value`` (``value`` as given, not
        scaled), drawn dashed with their label, e.g. ``{"1× outer": 1.0}`` for a speed in Hz
        (``1 / (2 pi)`` for a speed in rad/s).
    dynamic_range : float
        The colour scale spans ``max / dynamic_range`` to ``max``; weaker lines take the lowest colour.
    scale, unit : float, str
        Amplitudes are shown as ``scale * amplitude`` in ``unit`` (default µm from m).
    xscale : float
        Plotted values are ``xscale * values``.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale, xscale = checks.positive("scale", scale), checks.positive("xscale", xscale)
    values = checks.vector("values", values, min_len=1)
    f = _not_negative("frequencies", _padded("frequencies", frequencies, (values.size, "L"), "Hz"), "Hz")
    a = _not_negative("amplitudes", _padded("amplitudes", amplitudes, f.shape, "m"), "m")
    f_max = None if f_max is None else checks.positive("f_max", f_max, "Hz")
    dynamic_range = checks.number("dynamic_range", dynamic_range, gt=1.0)
    orders = _orders(orders)
    fig, ax, new = laid_out(ax, (9, 6))
    y = np.broadcast_to(xscale * values[:, None], f.shape)
    keep = np.isfinite(f) & np.isfinite(a) & (a > 0) & (f <= (np.inf if f_max is None else f_max))
    top = f_max or _f_top(f[keep], values, orders)
    _line_dots(fig, ax, f[keep], y[keep], scale * a[keep], dynamic_range, unit)
    ax.set_xlim(0, top)
    _order_lines(ax, values, xscale, orders)
    ax.set_xlabel("Frequency (Hz)")
    ax.set_ylabel(xlabel)
    ax.grid(True, alpha=0.3)
    return titled(fig, ax, title, new)


def _line_dots(fig: Figure, ax, f: np.ndarray, y: np.ndarray, amp: np.ndarray, dynamic_range: float,
               unit: str) -> None:
    """The lines as dots, strongest on top, colour and size by log amplitude; a colour bar in ``unit``."""
    if not amp.size:
        _no_data(ax, "no spectral lines")
        return
    top = float(amp.max())
    norm = LogNorm(vmin=top / dynamic_range, vmax=top, clip=True)
    order = np.argsort(amp)
    size = 12.0 + 40.0 * norm(amp[order]).filled(0.0)
    dots = ax.scatter(f[order], y[order], c=amp[order], s=size, norm=norm, cmap="viridis", edgecolors="none")
    fig.colorbar(dots, ax=ax, label=f"Line amplitude ({unit})")


def _f_top(f: np.ndarray, values: np.ndarray, orders: dict[str, float]) -> float | None:
    """5 % above the highest line, else above the highest order line, else None (autoscale)."""
    tops = f if f.size else np.array([slope * values.max() for slope in orders.values()])
    return 1.05 * float(tops.max()) if tops.size and tops.max() > 0 else None


def _order_lines(ax, values: np.ndarray, xscale: float, orders: dict[str, float]) -> None:
    """Order lines ``frequency = slope * value`` across the range of values, dashed, labelled at the top."""
    v = np.array([values.min(), values.max()])
    f_hi = ax.get_xlim()[1]
    for label, slope in orders.items():
        ax.plot(slope * v, xscale * v, "--", lw=0.8, color="0.35", zorder=0)
        v_top = min(v[1], f_hi / slope)
        if v_top >= v[0]:
            ax.annotate(label, (slope * v_top, xscale * v_top), xytext=(-3, -3), textcoords="offset points",
                        ha="right", va="top", fontsize=8, color="0.25")
    ax.set_xlim(0, f_hi)


# --------------------------------------------------------------------------- heat map
def plot_heatmap(x, y, z, ax=None, *, xlabel: str, ylabel: str, zlabel: str, xscale: float = 1.0,
                 yscale: float = 1.0, categories: Sequence[str] | None = None, title: str | None = None):
    """A 2-D map over a grid of two varied keys: a continuous quantity, or a class per cell.

    Cells are drawn with ``pcolormesh``, their edges midway between the grid values (so a
    non-uniform grid, or a single row or column, shows each value at the centre of its cell).

    Parameters
    ----------
    x : array_like, shape (nx,)
        The first key (SI), strictly increasing or decreasing, nx >= 1.
    y : array_like, shape (ny,)
        The second key (SI), likewise.
    z : array_like, shape (ny, nx)
        The quantity at each grid point (NaN: blank); with ``categories``, the index of each
        point's category (integer, -1 for missing: blank).
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    xlabel, ylabel : str
        Names and units of the keys as plotted.
    zlabel : str
        Label of the colour bar (name and unit of ``z``).
    xscale, yscale : float
        Plotted values are ``xscale * x`` and ``yscale * y`` (e.g. 1e6 for a clearance in µm).
    categories : sequence of str, optional
        Names of the categories ``z`` indexes; class names take their :data:`CLASS_COLOURS`.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    xscale, yscale = checks.positive("xscale", xscale), checks.positive("yscale", yscale)
    x, y = _grid("x", x), _grid("y", y)
    z = _padded("z", z, (y.size, x.size))
    names = None if categories is None else _categories(categories, z)
    fig, ax, new = laid_out(ax, (8.5, 5.5))
    xe, ye = _edges(xscale * x), _edges(yscale * y)
    if names is None:
        _continuous(fig, ax, xe, ye, z, zlabel)
    else:
        _classes(fig, ax, xe, ye, z, names, zlabel)
    _grid_ticks(ax, xscale * x, yscale * y)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    return titled(fig, ax, title, new)


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges midway between grid values; the outer cells as wide as their neighbour (±10 % for one value)."""
    if v.size == 1:
        half = 0.1 * abs(v[0]) or 0.5
        return np.array([v[0] - half, v[0] + half])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _continuous(fig: Figure, ax, xe: np.ndarray, ye: np.ndarray, z: np.ndarray, zlabel: str) -> None:
    """``z`` on the viridis colour map, NaN blank, with a colour bar."""
    masked = np.ma.masked_invalid(z)
    if masked.count() == 0:
        _no_data(ax, "no values (every run failed)")
    mesh = ax.pcolormesh(xe, ye, masked, cmap="viridis", shading="flat")
    if masked.count() == 0:
        mesh.set_clim(0.0, 1.0)
    fig.colorbar(mesh, ax=ax, label=zlabel)


def _classes(fig: Figure, ax, xe: np.ndarray, ye: np.ndarray, z: np.ndarray, names: tuple[str, ...],
             zlabel: str) -> None:
    """Category indices in fixed colours (-1 blank), with a colour bar naming each category."""
    others = iter(_OTHER_COLOURS * (1 + len(names) // len(_OTHER_COLOURS)))
    cmap = ListedColormap([CLASS_COLOURS.get(n) or next(others) for n in names])
    norm = BoundaryNorm(np.arange(len(names) + 1) - 0.5, len(names))
    mesh = ax.pcolormesh(xe, ye, np.ma.masked_less(z, 0), cmap=cmap, norm=norm, shading="flat")
    bar = fig.colorbar(mesh, ax=ax, label=zlabel, ticks=np.arange(len(names)))
    bar.ax.set_yticklabels(names)
    bar.ax.tick_params(length=0)


def _grid_ticks(ax, x: np.ndarray, y: np.ndarray) -> None:
    """Ticks at the grid values of a short axis (up to 12 values), so each cell is labelled."""
    if x.size <= 12:
        ax.set_xticks(x)
    if y.size <= 12:
        ax.set_yticks(y)
