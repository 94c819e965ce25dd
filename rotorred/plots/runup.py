"""Figures of a run-up (:class:`rotorred.scenes.runup.RunupResult`): amplitude against speed with the
critical speeds, order tracks, the waterfall with its order lines, and orbit snapshots; and one order track
(:class:`rotorred.signals.orders.OrderTrack`).

Speeds are plotted in Hz of the reference spool (rpm on the top axis), displacements in µm. Each drawing draws into
the given axes or into a new figure and returns the Figure (:func:`draw_runup` picks one by its kind);
:func:`plot_runup` writes them all.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.ticker import FuncFormatter, NullFormatter
from matplotlib.figure import Figure

from rotorred import checks
from rotorred.plots.axes import save_figure
from rotorred.plots.scene import _figure, _stacked, draw_orbits

__all__ = ["draw_runup_amplitude", "draw_order_tracks", "draw_order_track", "draw_waterfall", "draw_orbit_snapshots",
           "draw_runup", "plot_runup", "RUNUP_FIGURES"]

HZ = 1.0 / (2 * math.pi)
_CRITICAL_STYLE = dict(color="0.45", ls=":", lw=1.0)
_PLAIN = FuncFormatter(lambda v, _: f"{v:g}")


def _rpm_axis(ax) -> None:
    """A top axis in rpm for an x axis in Hz."""
    top = ax.secondary_xaxis("top", functions=(lambda f: 60.0 * f, lambda r: r / 60.0))
    top.set_xlabel("rpm", fontsize=8)
    top.tick_params(labelsize=7)


def _criticals(ax, result) -> None:
    """Dotted vertical lines at the Campbell critical speeds, labelled with their line and whirl."""
    for c in result.critical_speeds:
        f = c.speed * HZ
        ax.axvline(f, **_CRITICAL_STYLE)
        ax.text(f, 0.98, f" 1× {c.spool} {c.whirl[:3]} {f:.1f} Hz", rotation=90, va="top", ha="right", fontsize=6,
                color="0.35", transform=ax.get_xaxis_transform())


def _rubs(ax, result) -> None:
    """Shaded spans where a plate rubs (reference spool's speeds)."""
    ref = result.reference
    for k, r in enumerate(result.rubs):
        lo, hi = sorted((r.speed_start[ref], r.speed_end[ref]))
        ax.axvspan(lo, max(hi, lo + 0.2), color="tab:red", alpha=0.12, lw=0,
                   label="rub" if k == 0 else None)


def _one(ax, items: list, option: str, given):
    """The items drawn: all of them in a new figure; into a given ``ax``, the one named by ``option`` (``given``,
    default the first)."""
    if given is None:
        return items if ax is None else items[:1]
    if given not in items:
        checks.fail(option, given, "must be one of " + ", ".join(map(str, items)))
    return [given]


def draw_runup_amplitude(result, ax=None, *, node: int | None = None):
    """Largest orbit radius (over two revolutions) and each spool's 1x track (y) against the reference speed,
    per node, with the critical speeds (Campbell) and the rub intervals; into a given ``ax``, of ``node`` (default
    the first). Returns the Figure."""
    nodes = _one(ax, sorted(result.overall), "node", node)
    if not nodes:
        checks.fail("result", "a run-up without x and y records", "has no orbit radius to draw")
    fig, axes = _figure(ax, lambda: _stacked(10.0, 2.6, max(1, len(nodes))),
                        None if ax is not None else f"{result.scene.name}: amplitude against speed (critical speeds "
                                                    "dotted)")
    if ax is None:
        fig.subplots_adjust(right=0.8)  # the legends beside the panels
    ref = result.reference
    for axis, node in zip(axes, nodes):
        speed, radius = result.overall[node]
        axis.plot(speed * HZ, 1e6 * radius, color="k", lw=1.0, label="orbit radius (max)")
        for track, dof in zip(result.tracks, result.track_dofs):
            if dof == (node, "y") and track.order == 1.0:
                f = track.speed * HZ
                if track.spool != ref:  # plot against the reference spool's speed at the block's time
                    f = np.interp(track.t, result.t, result.speeds[ref]) * HZ
                axis.plot(f, 1e6 * track.amplitude, lw=0.9, ls="--", label=f"1× {track.spool} (y)")
        _criticals(axis, result)
        _rubs(axis, result)
        axis.set_ylabel(f"node {node} (µm)")
        axis.grid(True, alpha=0.3)
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    axes[-1].set_xlabel(f"{ref} spool speed (Hz)")
    _rpm_axis(axes[0])
    return fig


def _track_axes(ax, ylabel: str) -> None:
    """Log amplitude axis of order tracks, plain tick numbers, grid and legend beside."""
    ax.set_yscale("log")
    ax.yaxis.set_major_formatter(_PLAIN)  # plain numbers: no mathtext (slow, and its fonts)
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)


def _track(ax, track, speed_hz: np.ndarray, scale: float) -> None:
    """One order track's amplitude (``scale`` times) against ``speed_hz`` (Hz)."""
    ax.plot(speed_hz, scale * track.amplitude, lw=1.0, label=f"{track.order:g}× {track.spool}")


def draw_order_tracks(result, ax=None, *, dof: tuple | None = None):
    """Every tracked order of every spool at each recorded DOF in y (or the first direction) against the reference
    spool's speed; into a given ``ax``, at ``dof`` (default the first). Returns the Figure."""
    dofs = [d for d in dict.fromkeys(result.track_dofs) if d[1] == "y"] or list(dict.fromkeys(result.track_dofs))
    dofs = _one(ax, dofs, "dof", None if dof is None else tuple(dof))
    fig, axes = _figure(ax, lambda: _stacked(10.0, 2.4, max(1, len(dofs))),
                        None if ax is not None else f"{result.scene.name}: order tracks")
    ref = result.reference
    for axis, d in zip(axes, dofs):
        for track, track_dof in zip(result.tracks, result.track_dofs):
            if track_dof == d:
                _track(axis, track, np.interp(track.t, result.t, result.speeds[ref]) * HZ, 1e6)
        _criticals(axis, result)
        _track_axes(axis, f"{d[0]} {d[1]} (µm)")
    axes[-1].set_xlabel(f"{ref} spool speed (Hz)")
    _rpm_axis(axes[0])
    if ax is None:
        fig.subplots_adjust(right=0.8)
        fig.text(0.01, 0.005, result.tracks[0].method if result.tracks else "", fontsize=6, color="0.4")
    return fig


def draw_order_track(track, ax=None, *, scale: float = 1e6, unit: str = "µm", title: str | None = None):
    """One order track's amplitude against its own spool's speed (Hz, rpm on top), as :func:`draw_order_tracks`
    draws it; amplitudes ``scale`` times (default µm from m). Returns the Figure."""
    fig, (axis,) = _figure(ax, lambda: _stacked(10.0, 2.4, 1), title)
    _track(axis, track, track.speed * HZ, checks.positive("scale", scale))
    _track_axes(axis, f"amplitude ({unit})")
    axis.set_xlabel(f"{track.spool} spool speed (Hz)")
    _rpm_axis(axis)
    if ax is None:
        fig.subplots_adjust(right=0.8)
        fig.text(0.01, 0.005, track.method, fontsize=6, color="0.4")
    return fig


def draw_waterfall(result, ax=None):
    """Spectra of the table DOF against time (colour: dB re 1 µm, 80 dB range) with every spool's order lines.
    Returns the Figure."""
    w = result.waterfall
    if w is None:
        checks.fail("result", "a run-up without a waterfall", "has a record too short for one")
    if ax is None:
        fig = Figure(figsize=(8.0, 6.0))
        fig.subplots_adjust(left=0.1, right=0.88, bottom=0.1, top=0.88)
        ax = fig.subplots()
        fig.suptitle(f"{result.scene.name}: waterfall")
        fig.text(0.01, 0.01, f"Hann segments of {w.segment:g} s, 50 % overlap (pyFFTW); order lines white "
                 "(solid: " + ", dashed: ".join(result.speeds) + ")", fontsize=7, color="0.35")
    fig = ax.figure
    db = 20.0 * np.log10(np.maximum(1e6 * w.amplitudes, 1e-12))  # dB re 1 µm
    top = float(db.max())
    mesh = ax.pcolormesh(w.frequencies, w.t, db, shading="nearest", cmap="viridis", vmin=top - 80.0, vmax=top)
    fig.colorbar(mesh, ax=ax, label=f"node {result.waterfall_dof[0]} {result.waterfall_dof[1]} (dB re 1 µm)")
    styles = ("-", "--", ":", "-.")
    for k, (spool, speed) in enumerate(result.speeds.items()):
        for j, order in enumerate(result.scene.runup.orders):
            ax.plot(order * speed * HZ, result.t, color="w", lw=0.8, ls=styles[k % 4], alpha=0.8)
            ax.text(order * speed[-1] * HZ, result.t[-1], f" {order:g}×{spool[0].upper()}", color="k", fontsize=7,
                    va="bottom", rotation=60)
    ax.set_xlim(0, w.frequencies[-1])
    ax.set_ylim(result.t[0], result.t[-1])
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("time (s)")
    return fig


def draw_orbit_snapshots(result, ax=None):
    """The orbits at ``runup.orbits_hz``: one panel per speed, every node with x and y (into a given ``ax``, all
    of them). Returns the Figure."""
    panels: dict[str, dict] = {}
    for o in result.orbits:
        panels.setdefault(f"{result.reference} {o.speed_hz:g} Hz (t = {o.t:.2f} s)", {})[f"node {o.node}"] = (o.x, o.y)
    if not panels:
        checks.fail("result", "a run-up without orbit snapshots", "passes none of runup.orbits_hz")
    clearance = {}
    if result.scene.plates:
        clearance = {title: result.scene.plates[0].clearance for title in panels}
    return draw_orbits(panels, ax, title=f"{result.scene.name}: orbits during the run-up", clearance=clearance or None)


#: a run-up's figures by kind: (file name, drawing function, whether the result has it); the first kind is
#: :func:`draw_runup`'s default
RUNUP_FIGURES = {
    "amplitude": ("runup_amplitude.png", draw_runup_amplitude, lambda r: bool(r.overall)),
    "orders": ("order_tracks.png", draw_order_tracks, lambda r: bool(r.tracks)),
    "waterfall": ("waterfall.png", draw_waterfall, lambda r: r.waterfall is not None),
    "orbits": ("runup_orbits.png", draw_orbit_snapshots, lambda r: bool(r.orbits)),
}


def draw_runup(result, kind: str = "amplitude", ax=None, **options):
    """One figure of a run-up, as ``rotorred run`` writes it (:data:`RUNUP_FIGURES`); returns the Figure.

    Parameters
    ----------
    result : rotorred.scenes.runup.RunupResult
    kind : {"amplitude", "orders", "waterfall", "orbits"}
        Amplitude against speed (default), the order tracks, the waterfall of the table DOF, the orbit snapshots.
    ax : matplotlib Axes, optional
    **options
        Options of the drawing (``node`` of "amplitude", ``dof`` of "orders").
    """
    return RUNUP_FIGURES[checks.choice("kind", kind, RUNUP_FIGURES)][1](result, ax, **options)


def plot_runup(result, out) -> list[Path]:
    """Every figure of a run-up the result has, drawn by its ``plot`` (:meth:`rotorred.scenes.runup.RunupResult.plot`)
    and written into ``out``; returns their paths."""
    out = Path(out)
    return [save_figure(result.plot(kind=kind), out / name) for kind, (name, _, has) in RUNUP_FIGURES.items()
            if has(result)]
