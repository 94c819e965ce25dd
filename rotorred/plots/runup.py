"""Figures of a run-up (:class:`rotorred.scenes.runup.RunupResult`): amplitude against speed with the
critical speeds, order tracks, the waterfall with its order lines, and orbit snapshots.

Speeds are plotted in Hz of the reference spool (rpm on the top axis), displacements in µm.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.ticker import FuncFormatter, NullFormatter
from matplotlib.figure import Figure

from rotorred.plots.scene import _save, _stacked, plot_orbits

__all__ = ["plot_runup_amplitude", "plot_order_tracks", "plot_waterfall", "plot_orbit_snapshots", "plot_runup"]

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


def plot_runup_amplitude(result, path) -> Path:
    """Largest orbit radius (over two revolutions) and each spool's 1x track (y) against the reference speed,
    per node, with the critical speeds (Campbell) and the rub intervals."""
    nodes = sorted(result.overall)
    fig, axes = _stacked(10.0, 2.6, max(1, len(nodes)))
    fig.subplots_adjust(right=0.8)  # the legends beside the panels
    ref = result.reference
    for ax, node in zip(axes, nodes):
        speed, radius = result.overall[node]
        ax.plot(speed * HZ, 1e6 * radius, color="k", lw=1.0, label="orbit radius (max)")
        for track, dof in zip(result.tracks, result.track_dofs):
            if dof == (node, "y") and track.order == 1.0:
                f = track.speed * HZ
                if track.spool != ref:  # plot against the reference spool's speed at the block's time
                    f = np.interp(track.t, result.t, result.speeds[ref]) * HZ
                ax.plot(f, 1e6 * track.amplitude, lw=0.9, ls="--", label=f"1× {track.spool} (y)")
        _criticals(ax, result)
        _rubs(ax, result)
        ax.set_ylabel(f"node {node} (µm)")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    axes[-1].set_xlabel(f"{ref} spool speed (Hz)")
    _rpm_axis(axes[0])
    return _save(fig, Path(path), f"{result.scene.name}: amplitude against speed (critical speeds dotted)")


def plot_order_tracks(result, path) -> Path:
    """Every tracked order of every spool at each recorded DOF in y (or the first direction)."""
    dofs = [d for d in dict.fromkeys(result.track_dofs) if d[1] == "y"] or list(dict.fromkeys(result.track_dofs))
    fig, axes = _stacked(10.0, 2.4, max(1, len(dofs)))
    fig.subplots_adjust(right=0.8)
    ref = result.reference
    for ax, dof in zip(axes, dofs):
        for track, d in zip(result.tracks, result.track_dofs):
            if d != dof:
                continue
            f = np.interp(track.t, result.t, result.speeds[ref]) * HZ
            ax.plot(f, 1e6 * track.amplitude, lw=1.0, label=f"{track.order:g}× {track.spool}")
        _criticals(ax, result)
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(_PLAIN)  # plain numbers: no mathtext (slow, and its fonts)
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_ylabel(f"{dof[0]} {dof[1]} (µm)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    axes[-1].set_xlabel(f"{ref} spool speed (Hz)")
    method = result.tracks[0].method if result.tracks else ""
    _rpm_axis(axes[0])
    fig.text(0.01, 0.005, method, fontsize=6, color="0.4")
    return _save(fig, Path(path), f"{result.scene.name}: order tracks")


def plot_waterfall(result, path) -> Path:
    """Spectra of the table DOF against time (colour: dB re 1 µm, 80 dB range) with every spool's order lines."""
    w = result.waterfall
    fig = Figure(figsize=(8.0, 6.0))
    fig.subplots_adjust(left=0.1, right=0.88, bottom=0.1, top=0.88)
    ax = fig.subplots()
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
    fig.text(0.01, 0.01, f"Hann segments of {w.segment:g} s, 50 % overlap (pyFFTW); order lines white "
             "(solid: " + ", dashed: ".join(result.speeds) + ")", fontsize=7, color="0.35")
    return _save(fig, Path(path), f"{result.scene.name}: waterfall")


def plot_orbit_snapshots(result, path) -> Path:
    """The orbits at ``runup.orbits_hz``: one panel per speed, every node with x and y."""
    panels: dict[str, dict] = {}
    for o in result.orbits:
        panels.setdefault(f"{result.reference} {o.speed_hz:g} Hz (t = {o.t:.2f} s)", {})[f"node {o.node}"] = (o.x, o.y)
    clearance = {}
    if result.scene.plates:
        clearance = {title: result.scene.plates[0].clearance for title in panels}
    return plot_orbits(panels, path, title=f"{result.scene.name}: orbits during the run-up",
                       clearance=clearance or None)


def plot_runup(result, out) -> list[Path]:
    """Every figure of a run-up into ``out``; returns their paths."""
    out = Path(out)
    files = []
    if result.overall:
        files.append(plot_runup_amplitude(result, out / "runup_amplitude.png"))
    if result.tracks:
        files.append(plot_order_tracks(result, out / "order_tracks.png"))
    if result.waterfall is not None:
        files.append(plot_waterfall(result, out / "waterfall.png"))
    if result.orbits:
        files.append(plot_orbit_snapshots(result, out / "runup_orbits.png"))
    return files

