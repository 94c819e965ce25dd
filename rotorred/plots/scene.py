"""Drawings of waveforms, spectra, orbits and Poincare sections (matplotlib, Agg; plain arrays in), and a scene's
figures (:class:`rotorred.scenes.run.SceneResult`, :class:`rotorred.transient.results.TransientResult`).

Every drawing takes SI arrays (s, m, Hz), plots displacements in µm by default (``scale=1e6``, ``unit="µm"``),
draws into the given axes (``ax``; every panel's series in it) or into a new figure of its own panels, and returns
the Figure; :func:`write_figure` draws one and writes it (:func:`rotorred.plots.axes.save_figure`), the figure jobs of
``rotorred run`` (:func:`scene_figures`). Figures are built with :class:`matplotlib.figure.Figure` (no pyplot
state, no GUI; ``savefig`` renders with Agg), so the drawings are safe in scripts, tests and threads.

Data may be one panel or several:

* one panel: ``{"normal": y1, "rub": y2}``;
* several panels (stacked, or side by side for orbits):
  ``{"node 13 (inner)": {"normal": y1, "rub": y2}, "node 14 (outer)": {...}}``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from functools import partial
from typing import TYPE_CHECKING, NamedTuple
from pathlib import Path

import numpy as np

from rotorred import checks
from rotorred.model.dofs import direction_name
from rotorred.plots.axes import save_figure
from rotorred.plots.branch import titled

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from rotorred.signals.linefit import FittedLine

__all__ = ["draw_waveforms", "draw_spectra", "draw_orbits", "draw_poincare", "draw_scene", "draw_transient",
           "write_figure", "plot_scene", "scene_drawings", "scene_figures", "record_figures", "analysis_figures",
           "scene_frames", "prepare_frames", "SCENE_KINDS"]


# --------------------------------------------------------------------------- helpers
def _panels(data, what: str) -> dict[str, dict[str, object]]:
    """Normalise one-panel or multi-panel mappings to {panel title: {label: item}}."""
    if not isinstance(data, Mapping) or not data:
        checks.fail(what, data, "must be a non-empty mapping label -> data")
    nested = [isinstance(v, Mapping) for v in data.values()]
    if all(nested):
        out = {}
        for title, series in data.items():
            if not series:
                checks.fail(f"{what}[{title!r}]", series, "must not be empty")
            out[str(title)] = dict(series)
        return out
    if any(nested):
        checks.fail(what, data, "mixes panels (mappings) and series; use one form")
    return {"": dict(data)}


def _vector(name: str, y, n: int | None = None) -> np.ndarray:
    y = np.asarray(y, dtype=float)
    if y.ndim != 1 or y.size < 2:
        checks.fail(name, y, "must be a 1-D array of at least 2 samples")
    if n is not None and y.size != n:
        checks.fail(name, y, f"must have {n} samples (the length of t), not {y.size}")
    return y


def _path(path) -> Path:
    p = Path(path)
    if not p.suffix:
        checks.fail("path", str(path), "must have a file extension (e.g. .png)")
    p.parent.mkdir(parents=True, exist_ok=True)
    return p


#: fixed figure margins in inches (left, right, bottom, top) and the gap between panels: room for the figure
#: title, each panel's title and the axis labels. Constrained layout measured every text of a figure at each
#: draw, about 0.2 s a figure here.
_MARGINS, _GAP = (0.8, 0.25, 0.6, 0.95), 0.6
#: panel sizes in inches, (width, height): a waveform and a spectrum panel (stacked), an orbit panel (side by side,
#: its height the figure's) and the Poincare plot (its width the axes' and right margin, its height the figure's)
_WAVEFORM_PANEL, _SPECTRUM_PANEL, _ORBIT_PANEL, _POINCARE_PANEL = (9, 2.6), (10, 3.4), (4.6, 5.3), (5.35, 5.0)


#: frames (an empty figure and its panels) built ahead of their figures by :func:`prepare_frames`, by frame key
#: (``("stacked", *args)`` of :func:`_stacked`, ``("side", *args)`` of :func:`_side_by_side`); each is used once
_PREPARED: dict[tuple, list] = {}
#: ticks made on each axis of a prepared frame (paper-rub's axes draw 7 to 10)
_PREPARED_TICKS = 10


def _stacked(width: float, panel_height: float, n: int) -> tuple[Figure, np.ndarray]:
    """A figure of ``n`` panels one above the other sharing x, with fixed margins (:data:`_MARGINS`): a prepared
    one (:func:`prepare_frames`) if there is one."""
    return _prepared(("stacked", width, panel_height, n)) or _stacked_frame(width, panel_height, n)


def _stacked_frame(width: float, panel_height: float, n: int) -> tuple[Figure, np.ndarray]:
    from matplotlib.figure import Figure

    left, right, bottom, top = _MARGINS
    height = panel_height * n + bottom + top - _GAP
    fig = Figure(figsize=(width, height))
    fig.subplots_adjust(left=left / width, right=1 - right / width, bottom=bottom / height, top=1 - top / height,
                        hspace=_GAP / (panel_height - _GAP))
    return fig, fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]


def _side_by_side(panel_width: float, height: float, n: int,
                  margins: tuple[float, float, float, float] = _MARGINS) -> tuple[Figure, np.ndarray]:
    """A figure of ``n`` panels in a row, each with its own axis labels, with fixed ``margins`` (in, as
    :data:`_MARGINS`): a prepared one (:func:`prepare_frames`) if there is one."""
    key = ("side", panel_width, height, n, tuple(margins))
    return _prepared(key) or _side_by_side_frame(*key[1:])


def _side_by_side_frame(panel_width: float, height: float, n: int,
                        margins: tuple[float, float, float, float]) -> tuple[Figure, np.ndarray]:
    from matplotlib.figure import Figure

    left, right, bottom, top = margins
    gap = left  # the next panel's y label and tick labels
    width = panel_width * n + left + right - gap
    fig = Figure(figsize=(width, height))
    fig.subplots_adjust(left=left / width, right=1 - right / width, bottom=bottom / height, top=1 - top / height,
                        wspace=gap / (panel_width - gap))
    return fig, fig.subplots(1, n, squeeze=False)[0]


def _prepared(key: tuple):
    """A prepared frame of ``key``, taken (used once), or None."""
    frames = _PREPARED.get(key)
    return frames.pop() if frames else None


def prepare_frames(keys: Sequence[tuple]) -> None:
    """Build the frames of ``keys`` (:func:`scene_frames`) ahead of their figures, each with its ticks made: the
    figure helpers then take them instead of building their own, and draw the same pixels.

    The figure pool's fork server prepares a scene's frames while the solve runs, and the workers it forks inherit
    them (:mod:`rotorred.plots._fork_server`): building paper-rub's six frames took 0.38 s, and drawing its figures
    into them 1.11 s against 1.37 s into new ones.
    """
    build = {"stacked": _stacked_frame, "side": _side_by_side_frame}
    for key in keys:
        fig, axes = build[key[0]](*key[1:])
        for ax in axes:
            ax.xaxis.get_major_ticks(_PREPARED_TICKS)
            ax.yaxis.get_major_ticks(_PREPARED_TICKS)
        _PREPARED.setdefault(tuple(key), []).append((fig, axes))


def write_figure(path, drawing) -> Path:
    """Draw ``drawing()`` (a callable returning a Figure: a drawing of :func:`scene_drawings`) and write it to ``path``
    (:func:`rotorred.plots.axes.save_figure`, its folder made); returns the path. A figure job of ``rotorred run``."""
    return save_figure(drawing(), _path(path))


def _figure(ax, frame, title: str | None):
    """``(figure, panels)``: a new ``frame`` (:func:`_stacked` or :func:`_side_by_side`, a callable) titled ``title``,
    or the figure of the given ``ax`` and ``ax`` as its one panel (titled ``title``)."""
    if ax is not None:
        return titled(ax.figure, ax, title, new=False), np.array([ax])
    fig, panels = frame()
    return titled(fig, None, title, new=True), panels


def _arranged(panels: dict[str, dict], merge: bool) -> dict[str, dict[str, tuple[str, object]]]:
    """``{panel title: {label shown: (its panel, item)}}``: the panels as they are or, with ``merge`` (into a given
    axes), every series in one panel (title ""), a label found in two panels prefixed with its panel's title."""
    if not merge:
        return {panel: {label: (panel, item) for label, item in series.items()} for panel, series in panels.items()}
    labels = [label for series in panels.values() for label in series]
    twice = {label for label in labels if labels.count(label) > 1}
    return {"": {(f"{panel}: {label}" if label in twice and panel else label): (panel, item)
                 for panel, series in panels.items() for label, item in series.items()}}


def _of_panel(value, panel: str):
    """``value``, or its entry for ``panel`` when it is a mapping ``{panel title: value}``."""
    return value[panel] if isinstance(value, Mapping) else value


# --------------------------------------------------------------------------- waveforms
def draw_waveforms(
    t,
    signals,
    ax=None,
    *,
    title: str | None = None,
    t_window: tuple[float, float] | None = None,
    scale: float | Mapping[str, float] = 1e6,
    unit: str | Mapping[str, str] = "µm",
    quantity: str | Mapping[str, str] = "Displacement",
):
    """Time histories, one panel per group, sharing the time axis.

    Parameters
    ----------
    t : array_like, shape (n,)
        Time (s).
    signals : mapping
        ``{label: y}`` or ``{panel title: {label: y}}``, each ``y`` shape (n,) in SI (m).
    ax : matplotlib Axes, optional
        Draw every panel's series into it (with the first panel's axis label); default a new figure of stacked
        panels.
    title : str, optional
        Figure title (the title of ``ax`` when given).
    t_window : (float, float), optional
        Time range shown (s), e.g. the paper's (2.44, 2.58).
    scale, unit : float, str, or mappings {panel title: value}
        Plotted values are ``scale * y`` in ``unit`` (default µm from m), for every panel or per panel.
    quantity : str or mapping {panel title: str}
        Name on the y axis.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = _vector("t", t)
    panels = _panels(signals, "signals")
    for panel in panels:
        checks.positive("scale", _of_panel(scale, panel))
    if t_window is not None:
        lo, hi = checks.sequence("t_window", list(t_window), lambda f, v: checks.number(f, v, "s"), min_len=2,
                                 max_len=2)
        if not lo < hi:
            checks.fail("t_window", t_window, "must be (start, end) with start < end", "s")
        keep = (t >= lo) & (t <= hi)
        if keep.sum() < 2:
            checks.fail("t_window", t_window, "must hold at least 2 samples of t", "s")
    else:
        keep = np.ones(t.size, dtype=bool)
    panels = _arranged(panels, merge=ax is not None)
    fig, axes = _figure(ax, lambda: _stacked(*_WAVEFORM_PANEL, len(panels)), title)
    for axis, (panel, series) in zip(axes, panels.items()):
        for label, (source, y) in series.items():
            y = _vector(f"signals[{label!r}]", y, t.size)
            axis.plot(t[keep], _of_panel(scale, source) * y[keep], lw=1.0, label=str(label))
        source = next(iter(series.values()))[0]
        axis.set_ylabel(f"{_of_panel(quantity, source)} ({_of_panel(unit, source)})")
        if panel:
            axis.set_title(panel, y=1.0)  # a fixed position: placing it measured every tick label
        axis.grid(True, alpha=0.3)
        axis.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("Time (s)")
    axes[-1].set_xlim(t[keep][0], t[keep][-1])
    return fig


# --------------------------------------------------------------------------- spectra
def _spectrum_arrays(name: str, item) -> tuple[np.ndarray, np.ndarray]:
    if hasattr(item, "frequencies") and hasattr(item, "amplitudes"):  # a rotorred.signals.spectra.Spectrum
        return np.asarray(item.frequencies, float), np.asarray(item.amplitudes, float)
    if isinstance(item, Sequence) and len(item) == 2:
        f = _vector(f"{name} frequencies", item[0])
        a = _vector(f"{name} amplitudes", item[1], f.size)
        return f, a
    checks.fail(f"spectra[{name!r}]", type(item).__name__, "must be a Spectrum or (frequencies Hz, amplitudes)")


def draw_spectra(
    spectra,
    ax=None,
    *,
    lines: Mapping[str, Sequence[FittedLine]] | None = None,
    title: str | None = None,
    f_max: float | None = None,
    log_y: bool = False,
    dynamic_range: float = 1e6,
    scale: float = 1e6,
    unit: str = "µm",
):
    """Single-sided amplitude spectra, optionally with combination labels at the peaks.

    Parameters
    ----------
    spectra : mapping
        ``{label: spectrum}`` or ``{panel title: {label: spectrum}}``; a spectrum is a
        :class:`rotorred.signals.spectra.Spectrum` or a pair ``(frequencies (Hz), amplitudes (m))``.
    ax : matplotlib Axes, optional
        Draw every panel's series into it; default a new figure of stacked panels.
    lines : mapping, optional
        ``{label: [FittedLine, ...]}`` (``LineFit.lines``, e.g. of :func:`rotorred.signals.linefit.fit_peaks`) for
        the series of the same label; each line is marked and labelled ("2f_H−f_L").
    title : str, optional
    f_max : float, optional
        Upper frequency shown (Hz); default: the largest labelled line plus 10 %, or all.
    log_y : bool
        Logarithmic amplitude axis (as the paper's Fig. 11).
    dynamic_range : float
        With ``log_y``, the axis spans ``max / dynamic_range`` to ``max`` (rounding-level
        bins of an exact on-bin spectrum would otherwise stretch it to 1e-20).
    scale, unit : float, str
        Plotted amplitudes are ``scale * amplitude`` in ``unit`` (default µm from m).

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale = checks.positive("scale", scale)
    panels = _panels(spectra, "spectra")
    lines = {} if lines is None else dict(lines)
    checks.number("dynamic_range", dynamic_range, gt=1.0)
    all_labels = {str(k) for series in panels.values() for k in series}
    for key in lines:
        if str(key) not in all_labels:
            checks.fail(f"lines[{key!r}]", key, f"lines key must be a series of spectra ({sorted(all_labels)})")
    if f_max is None:
        known = [ln.frequency_hz for seq in lines.values() for ln in seq]
        f_max = 1.1 * max(known) if known else None
    else:
        checks.positive("f_max", f_max, "Hz")
    panels = _arranged(panels, merge=ax is not None)
    fig, axes = _figure(ax, lambda: _stacked(*_SPECTRUM_PANEL, len(panels)), title)
    for axis, (panel, series) in zip(axes, panels.items()):
        top = 0.0
        n_series = len(series)
        for i, (label, (_, item)) in enumerate(series.items()):
            f, a = _spectrum_arrays(str(label), item)
            show = f <= f_max if f_max is not None else np.ones(f.size, bool)
            # Earlier series are drawn wider, so a line shared by "normal" and "rub" shows
            # both colours instead of the later one hiding the earlier.
            lw = 0.9 + 1.6 * (n_series - 1 - i)
            (handle,) = axis.plot(f[show], scale * a[show], lw=lw, label=str(label))
            top = max(top, float(np.max(scale * a[show][f[show] > 0], initial=0.0)))
            shown = [ln for ln in lines.get(str(label), ()) if f_max is None or ln.frequency_hz <= f_max]
            _label_lines(axis, shown, scale, handle.get_color())
        if log_y:
            axis.set_yscale("log")
            axis.set_ylim(top / dynamic_range, top * 30)  # headroom for rotated labels
        else:
            axis.set_ylim(0, top * 1.35 if top > 0 else 1)
        axis.set_ylabel(f"Amplitude ({unit})")
        if panel:
            axis.set_title(panel, y=1.0)  # a fixed position: placing it measured every tick label
        axis.grid(True, alpha=0.3, which="both" if not log_y else "major")
        axis.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("Frequency (Hz)")
    axes[-1].set_xlim(0, f_max if f_max is not None else None)
    return fig


def _label_lines(ax, lines: Sequence[FittedLine], scale: float, color) -> None:
    """Mark ``lines`` (one marker artist for all) and write each one's label above it, rotated."""
    if not lines:
        return
    from matplotlib.transforms import ScaledTranslation

    f = np.array([ln.frequency_hz for ln in lines])
    y = scale * np.array([ln.amplitude for ln in lines])
    ax.plot(f, y, "v", ms=4, ls="none", color=color)
    above = ax.transData + ScaledTranslation(0, 6 / 72, ax.figure.dpi_scale_trans)  # 6 points above the marker
    for fk, yk, ln in zip(f, y, lines):
        ax.text(fk, yk, plot_label(ln.label), transform=above, rotation=90, ha="center", va="bottom", fontsize=8,
                color=color, clip_on=False)


def plot_label(label: str) -> str:
    """A line label (:func:`rotorred.signals.lines.line_label`) as plain text with Unicode subscripts and minus,
    ``"2f_H-f_L"`` -> ``"2fₕ−fₗ"``.

    Rendered as ordinary text: mathtext labels took about 1.2 s of the 4.4 s that the figures of
    ``paper-rub`` took (some 330 labels).
    """
    return label.replace("f_H", "f\u2095").replace("f_L", "f\u2097").replace("-", "\u2212")


# --------------------------------------------------------------------------- orbits
def draw_orbits(
    orbits,
    ax=None,
    *,
    title: str | None = None,
    clearance: float | Mapping[str, float] | None = None,
    scale: float = 1e6,
    unit: str = "µm",
):
    """Orbits (y against x) with equal axes, e.g. normal and rub overlaid.

    Parameters
    ----------
    orbits : mapping
        ``{label: (x, y)}`` or ``{panel title: {label: (x, y)}}``; ``x``, ``y`` shape (n,)
        in SI (m). Panels are placed side by side.
    ax : matplotlib Axes, optional
        Draw every panel's orbits into it (the first clearance given); default a new figure of panels side by side.
    title : str, optional
    clearance : float or mapping, optional
        Radial clearance (m), drawn as a dashed circle about the origin: one value for every
        panel, or ``{panel title: radius}`` (e.g. only for the rubbing node).
    scale, unit : float, str
        Plotted values are ``scale * x`` in ``unit`` (default µm from m).

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale = checks.positive("scale", scale)
    panels = _panels(orbits, "orbits")
    if clearance is None:
        clearances = {}
    elif isinstance(clearance, Mapping):
        unknown = set(map(str, clearance)) - set(panels)
        if unknown:
            checks.fail("clearance", sorted(unknown), "keys must be panels of orbits; these are not panels")
        clearances = {str(k): v for k, v in clearance.items()}
    else:
        clearances = {panel: clearance for panel in panels}
    for panel, radius in clearances.items():
        checks.positive("clearance", radius, "m")
    if ax is not None and clearances:
        clearances = {"": next(iter(clearances.values()))}
    panels = _arranged(panels, merge=ax is not None)
    fig, axes = _figure(ax, lambda: _side_by_side(*_ORBIT_PANEL, len(panels)), title)
    for axis, (panel, series) in zip(axes, panels.items()):
        for label, (_, xy) in series.items():
            if not (isinstance(xy, Sequence) and len(xy) == 2):
                checks.fail(f"orbits[{label!r}]", type(xy).__name__, "must be a pair (x, y)")
            x = _vector(f"orbits[{label!r}] x", xy[0])
            y = _vector(f"orbits[{label!r}] y", xy[1], x.size)
            axis.plot(scale * x, scale * y, lw=0.9, label=str(label))
        radius = clearances.get(panel)
        if radius is not None:
            from matplotlib.patches import Circle

            axis.add_patch(
                Circle((0, 0), scale * radius, fill=False, ls="--", lw=1.0, color="0.4",
                       label=f"clearance {scale * radius:.3g} {unit}")
            )
        axis.set_aspect("equal", adjustable="datalim")
        axis.set_xlabel(f"X ({unit})")
        axis.set_ylabel(f"Y ({unit})")
        axis.axhline(0, color="0.8", lw=0.6, zorder=0)
        axis.axvline(0, color="0.8", lw=0.6, zorder=0)
        if panel:
            axis.set_title(panel, y=1.0)  # a fixed position: placing it measured every tick label
        axis.grid(True, alpha=0.3)
        axis.legend(loc="upper right", fontsize=8)
    return fig


# --------------------------------------------------------------------------- Poincare section
#: smallest axis span of a Poincare plot, relative to the largest |value| on that axis: the samples of a
#: periodic response agree to round-off, and autoscaling would zoom into it (offset tick labels)
SPAN_MIN = 0.05


def _span_at_least(ax, x: np.ndarray, y: np.ndarray, rel: float) -> None:
    """Widen each axis about its centre to at least ``rel`` times the largest |value| on it."""
    for values, set_lim in ((x, ax.set_xlim), (y, ax.set_ylim)):
        lo, hi = float(np.min(values)), float(np.max(values))
        need = rel * max(abs(lo), abs(hi))
        if hi - lo < need:
            mid = 0.5 * (lo + hi)
            set_lim(mid - need, mid + need)


#: margins of a Poincare plot (in, as :data:`_MARGINS`): on the left, velocity tick labels of up to 7 characters
#: ("−150000" µm/s) and the axis label; at the top, a title of two lines and no panel title
_POINCARE_MARGINS = (1.05, 0.25, 0.6, 0.75)


def draw_poincare(x, velocity, ax=None, *, title: str | None = None, label: str = "", scale: float = 1e6,
                  unit: str = "µm"):
    """Poincare section: the sampled displacement against the sampled velocity, one dot per sample.

    A periodic response shows as k points (period-k), a quasi-periodic one as a closed curve, a
    chaotic one as a cloud (:mod:`rotorred.signals.classify`).

    Parameters
    ----------
    x, velocity : array_like, shape (n,)
        Samples in SI (m and m/s, or rad and rad/s), n >= 1.
    ax : matplotlib Axes, optional
        Draw into it; default a new figure.
    title, label : str
        Figure title; legend text of the samples (e.g. the class and section frequency).
    scale, unit : float, str
        Plotted values are ``scale * x`` in ``unit`` and ``scale * velocity`` in ``unit``/s.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale = checks.positive("scale", scale)
    x = checks.vector("x", x, min_len=1)
    velocity = checks.vector("velocity", velocity, min_len=x.size, max_len=x.size)
    fig, (ax,) = _figure(ax, lambda: _side_by_side(*_POINCARE_PANEL, 1, margins=_POINCARE_MARGINS), title)
    ax.plot(scale * x, scale * velocity, ".", ms=4 if x.size < 200 else 2, label=f"{label} ({x.size} samples)".strip())
    _span_at_least(ax, scale * x, scale * velocity, SPAN_MIN)
    ax.ticklabel_format(useOffset=False)
    ax.set_xlabel(f"displacement ({unit})")
    ax.set_ylabel(f"velocity ({unit}/s)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize=8)
    return fig


# --------------------------------------------------------------------------- a scene's figures
def plot_scene(result, out: str | Path) -> list[Path]:
    """The figures a scene's ``output.plots`` asks for, written into ``out``: waveforms, spectra, orbits,
    the Poincare section of the table DOF (each of :func:`scene_figures` drawn here, one after the other).

    Parameters
    ----------
    result : rotorred.scenes.run.SceneResult
    out : str or Path

    Returns
    -------
    list of Path
    """
    return [job() for job in scene_figures(result, out)]


class LineMark(NamedTuple):
    """What a spectrum plot shows of a :class:`rotorred.signals.linefit.FittedLine` (a figure job carries these, so
    a worker needs neither the signals modules nor pyFFTW to draw it)."""

    frequency_hz: float
    amplitude: float
    label: str


def _marks(fit) -> list[LineMark]:
    return [LineMark(float(ln.frequency_hz), float(ln.amplitude), ln.label) for ln in fit.lines]


def _pair(spectrum) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(spectrum.frequencies, float), np.asarray(spectrum.amplitudes, float)


def scene_figures(result, out: str | Path) -> list[partial]:
    """The figures of :func:`plot_scene` as jobs: each a ``functools.partial`` of :func:`write_figure`, its file and
    its drawing (:func:`scene_drawings`: a drawing function and plain arrays), which draws and writes one file when
    called (in this process or, pickled, in a :class:`rotorred.plots.pool.FigurePool` worker) and returns its path:
    :func:`record_figures` and :func:`analysis_figures`.

    Parameters
    ----------
    result : rotorred.scenes.run.SceneResult
        The result, with its ``normal`` (no-rub) companion overlaid when present.
    out : str or Path
        Output folder.

    Returns
    -------
    list of functools.partial
    """
    return record_figures(result, out) + analysis_figures(result, out)


def scene_frames(scene) -> list[tuple]:
    """The frame keys (:func:`prepare_frames`) of the figures :func:`scene_figures` draws for ``scene``: known before
    it is solved (the Poincare plot's, drawn when the analysis has samples).

    Parameters
    ----------
    scene : Scene
        The scene; its ``output`` (plots, nodes, directions) sets the frames.

    Returns
    -------
    list of tuple
        One key a figure, for :class:`rotorred.plots.pool.FigurePool`'s ``frames``.
    """
    output = scene.output
    plots, n_nodes, n_directions = output.plots, len(output.nodes), len(output.directions)
    keys = []
    if "waveforms" in plots:
        keys.append(("stacked", *_WAVEFORM_PANEL, n_nodes * n_directions))
    if "spectra" in plots:
        keys += [("stacked", *_SPECTRUM_PANEL, n_directions)] * n_nodes
    if "orbits" in plots and {"x", "y"} <= set(output.directions):
        keys.append(("side", *_ORBIT_PANEL, n_nodes, _MARGINS))
    if "poincare" in plots:
        keys.append(("side", *_POINCARE_PANEL, 1, _POINCARE_MARGINS))
    return keys


#: the kinds of a scene's figures (``output.plots``), in the order they are drawn; the first is
#: :func:`draw_scene`'s default
SCENE_KINDS = ("waveforms", "spectra", "orbits", "poincare")
#: the kinds drawn from the record, its spectra and lines alone (:func:`record_figures`)
_RECORD_KINDS = ("waveforms", "spectra", "orbits")


def record_figures(result, out: str | Path) -> list[partial]:
    """The figures of :func:`scene_figures` drawn from the record, its spectra and lines alone (waveforms, spectra,
    orbits, as the scene asks): they can be drawn while the line fit, settling and class are computed."""
    kinds = [k for k in _RECORD_KINDS if k in result.scene.output.plots]
    return [partial(write_figure, Path(out) / name, drawing) for name, drawing in scene_drawings(result, kinds)]


def analysis_figures(result, out: str | Path) -> list[partial]:
    """The figures of :func:`scene_figures` drawn from the table DOF's analysis (the Poincare section): none while
    ``result`` has none."""
    kinds = [k for k in SCENE_KINDS if k not in _RECORD_KINDS and k in result.scene.output.plots]
    return [partial(write_figure, Path(out) / name, drawing) for name, drawing in scene_drawings(result, kinds)]


def scene_drawings(result, kinds) -> list[tuple[str, partial]]:
    """``(file name, drawing)`` of each figure of ``kinds`` (of :data:`SCENE_KINDS`) that ``result`` has the data for.

    A drawing is a ``functools.partial`` of a drawing function (:func:`draw_waveforms`, :func:`draw_spectra`,
    :func:`draw_orbits`, :func:`draw_poincare`) and plain arrays: called, it returns the Figure (``ax=``, and any
    option of its function, may be given). "spectra" is one figure per node (``spectra_node13.png``), "orbits" needs
    x and y, "poincare" the table DOF's Poincare samples (:attr:`rotorred.scenes.run.SceneResult.analysis`).

    Parameters
    ----------
    result : rotorred.scenes.run.SceneResult
        With its ``normal`` (no-rub) companion overlaid when present.
    kinds : sequence of str
    """
    sc = result.scene
    case = "rub" if sc.plates else "response"
    pairs = [("normal", result.normal), (case, result)] if result.normal is not None else [(case, result)]
    drawings = []
    speeds, rub_text = _texts(sc)
    translational = [d for d in sc.output.directions if d in ("x", "y")]
    if "waveforms" in kinds:
        window = sc.output.plot_window or (result.t[0], min(result.t[-1], result.t[0] + 0.14))
        signals = {f"node {n} {direction_name(d)}": {label: r.outputs[(n, d)] for label, r in pairs}
                   for n in sc.output.nodes for d in sc.output.directions}
        drawings.append(("waveforms.png", partial(draw_waveforms, result.t, signals, t_window=window,
                                                  title=f"{sc.name}: time waveforms ({speeds}; {rub_text})",
                                                  unit="µm" if translational else "µrad")))
    if "spectra" in kinds and result.spectra:
        f_max = sc.output.f_max_hz
        for n in sc.output.nodes:
            spectra, lines = {}, {}
            for d in sc.output.directions:
                panel = f"node {n} {direction_name(d)}"
                spectra[panel] = {f"{label} {direction_name(d)}": _pair(r.spectra[(n, d)]) for label, r in pairs}
                lines[f"{case} {direction_name(d)}"] = _marks(result.lines[(n, d)])
            if f_max is None:
                known = [ln.frequency_hz for ls in lines.values() for ln in ls]
                f_max_n = max(1.1 * max(known, default=0.0), 3.0 * result.f_H)
            else:
                f_max_n = f_max
            drawings.append((f"spectra_node{n}.png", partial(
                draw_spectra, spectra, lines=lines, f_max=f_max_n,
                title=f"{sc.name}: amplitude spectra at node {n} ({rub_text})")))
    if "orbits" in kinds and {"x", "y"} <= set(sc.output.directions):
        orbits = {}
        for n in sc.output.nodes:
            title = f"node {n} ({sc.rotor.spool_of[n]})"
            for p in sc.plates:
                if p.node == n:
                    title += f", plate at {math.degrees(p.theta):g} deg"
            orbits[title] = {label: (r.outputs[(n, "x")], r.outputs[(n, "y")]) for label, r in pairs}
        drawings.append(("orbits.png", partial(draw_orbits, orbits,
                                               title=f"{sc.name}: orbits over the recorded window ({rub_text})")))
    if "poincare" in kinds and result.analysis is not None and result.analysis.classification.poincare.x.size:
        drawings.append(("poincare.png", _scene_poincare(result, speeds, rub_text)))
    return drawings


def draw_scene(result, kind: str = SCENE_KINDS[0], ax=None, *, node: int | None = None, **options):
    """One figure of a scene's result, as ``rotorred run`` writes it (:func:`scene_drawings`); returns the Figure.

    Parameters
    ----------
    result : rotorred.scenes.run.SceneResult
    kind : {"waveforms", "spectra", "orbits", "poincare"}
        Waveforms of every recorded DOF (default), the spectra of one node, the orbits of every node (x and y
        recorded), the Poincare section of the table DOF (when the analysis has samples).
    ax : matplotlib Axes, optional
        Draw every panel's series into it (untitled unless ``title`` is given); default a new figure of the file's
        panels.
    node : int, optional
        The node of "spectra" (default the first recorded).
    **options
        Options of the drawing function (e.g. ``t_window``, ``f_max``, ``log_y``, ``title``).
    """
    kind = checks.choice("kind", kind, SCENE_KINDS)
    drawings = dict(scene_drawings(result, [kind]))
    if kind == "spectra":
        nodes = result.scene.output.nodes
        node = nodes[0] if node is None else node
        if node not in nodes:
            checks.fail("node", node, "must be a recorded node: one of " + ", ".join(map(str, nodes)))
        drawings = {name: d for name, d in drawings.items() if name == f"spectra_node{node}.png"}
    elif node is not None:
        checks.fail("node", node, f"is an option of kind='spectra' only, not of {kind!r}")
    if not drawings:
        checks.fail("kind", kind, "has no data in this result (orbits need x and y, spectra a complete record, the "
                    "Poincare section the table DOF's samples)")
    if ax is not None:
        options.setdefault("title", None)  # the file's title is the figure's, too long for one axes
    return next(iter(drawings.values()))(ax=ax, **options)


def draw_transient(result, ax=None, *, t_window: tuple[float, float] | None = None, title: str | None = None):
    """The recorded outputs of a transient against time (displacements in µm, rotations in µrad) and, when recorded,
    each plate's normal and friction force (N) (:func:`draw_waveforms`); returns the Figure.

    Parameters
    ----------
    result : rotorred.transient.results.TransientResult
    ax : matplotlib Axes, optional
        Draw the first panel's series into it (the displacements, else the rotations, else the contact forces);
        default a new figure with a panel of each.
    t_window : (float, float), optional
        Time range shown (s).
    title : str, optional
    """
    panels, scales, units, quantities = {}, {}, {}, {}
    for (n, d), y in result.outputs.items():
        panel = "rotations" if d.startswith("t") else "displacements"
        panels.setdefault(panel, {})[f"node {n} {direction_name(d)}"] = y
        scales[panel], units[panel] = 1e6, "µrad" if panel == "rotations" else "µm"
        quantities[panel] = "Rotation" if panel == "rotations" else "Displacement"
    if result.contacts:
        panels["contact forces"] = {f"plate {k} (node {ch.plate.node}) {name}": force
                                    for k, ch in enumerate(result.contacts)
                                    for name, force in (("normal", ch.normal_force), ("friction", ch.friction_force))}
        scales["contact forces"], units["contact forces"], quantities["contact forces"] = 1.0, "N", "Force"
    if not panels:
        checks.fail("result", "a transient without outputs or contacts", "has nothing recorded to draw")
    if ax is not None:
        panels = dict([next(iter(panels.items()))])
    title = title or f"transient ({result.method}, dt = {result.dt:g} s, {result.n_steps} steps)"
    return draw_waveforms(result.t, panels, ax, t_window=t_window, scale=scales, unit=units, quantity=quantities,
                          title=title)


def _texts(sc) -> tuple[str, str]:
    """The speeds and the rub, as a figure's title says them."""
    rub_text = "; ".join(f"rub at node {p.node} ({math.degrees(p.theta):g} deg, clearance {1e6 * p.clearance:.3g} um)"
                         for p in sc.plates) or "no rub"
    return ", ".join(f"{w / (2 * math.pi):.4g} Hz" for w in sc.speeds.values()), rub_text


def _scene_poincare(result, speeds: str, rub_text: str) -> partial:
    """The Poincare section of the table DOF, labelled with its class and section frequency (a drawing)."""
    a = result.analysis
    c = a.classification
    rot = a.dof[1].startswith("theta")
    return partial(draw_poincare, c.poincare.x, c.poincare.velocity, scale=1e6, unit="µrad" if rot else "µm",
                   label=f"{c.label}, once per {1.0 / c.poincare.frequency_hz:.4g} s "
                         f"({c.poincare.frequency_hz:.6g} Hz)",
                   title=f"{result.scene.name}: Poincare section of node {a.dof[0]} {direction_name(a.dof[1])}\n"
                         f"({speeds}; {rub_text})")
