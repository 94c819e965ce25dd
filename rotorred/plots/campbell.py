"""Campbell diagram figure: whirl curves by direction, excitation lines, critical speeds (rpm, Hz)."""

from __future__ import annotations

import numpy as np
from matplotlib.transforms import blended_transform_factory

from rotorred.linear.campbell import CampbellResult, CriticalSpeed, excitation_label
from rotorred.plots.axes import axes

#: colour and line style of each whirl direction
WHIRL_STYLE = {
    "forward": dict(color="tab:blue", linestyle="-"),
    "backward": dict(color="tab:red", linestyle="--"),
    "mixed": dict(color="tab:purple", linestyle="-."),
    "planar": dict(color="tab:gray", linestyle=":"),
}
#: marker of a critical speed
CRITICAL_STYLE = dict(marker="o", linestyle="none", mfc="none", mec="black", ms=8, mew=1.5, zorder=5)


def draw_campbell(result: CampbellResult, ax=None, *, operating_speed: float | None = None, title: str | None = None,
                  max_frequency_hz: float | None = None, figsize: tuple[float, float] = (11.0, 6.0)):
    """Draw the Campbell diagram of ``result`` (:meth:`CampbellResult.plot`); return the Figure.

    Whirl curves coloured by whirl direction (mode number at the right end), the excitation lines labelled
    inline, the critical speeds (circles), grid points where a mode is unstable (crosses) and the stability
    limits (diamonds); speeds in rpm, frequencies in Hz, the other spool's speed on the top axis.

    Parameters
    ----------
    result : CampbellResult
    ax : matplotlib Axes, optional
        Axes to draw into; default a new figure of ``figsize`` (in), laid out tight.
    operating_speed : float, optional
        Reference-spool operating speed (rad/s), drawn as a vertical line.
    title : str, optional
        Default: "Campbell diagram - <rotor name>" with the speed ratios.
    max_frequency_hz : float, optional
        Upper limit of the frequency axis (Hz); default 10 % above the highest tracked curve.
    figsize : (float, float)
        Size of a new figure (in); the legend sits beside the diagram.

    Returns
    -------
    matplotlib.figure.Figure
    """
    new = ax is None
    fig, ax = axes(ax, figsize)
    top = max_frequency_hz or 1.1 * float(result.frequencies_hz.max())
    _whirl_curves(ax, result, max_frequency_hz)
    _mode_numbers(ax, result, top)
    rpm = result.speeds_rpm
    lo, hi = (float(rpm[0]), float(rpm[-1])) if len(rpm) > 1 else (0.0, 1.1 * float(rpm[0]))  # one: from rest
    if hi > lo:
        ax.set_xlim(lo, hi)
    ax.set_ylim(0, top)
    _excitation_lines(ax, result, top)
    if result.critical_speeds:
        ax.plot([c.speed_rpm for c in result.critical_speeds], [c.frequency_hz for c in result.critical_speeds],
                **CRITICAL_STYLE, label="critical speed")
    unstable = result.unstable
    if np.any(unstable):  # grid points where a mode's own motion grows
        ax.plot(np.broadcast_to(result.speeds_rpm[:, None], unstable.shape)[unstable], result.frequencies_hz[unstable],
                "x", color="tab:red", ms=6, mew=1.5, label="unstable (log dec < 0)", zorder=6)
    for c in result.stability_changes:
        ax.plot(c.speed_rpm, c.frequency_hz, "D", color="tab:red", ms=7, zorder=7,
                label=None if c is not result.stability_changes[0] else "stability limit")
    if operating_speed is not None:
        op = operating_speed * 30 / np.pi
        ax.axvline(op, color="tab:green", lw=1.2, label=f"operating point {op:.0f} rpm")
    _axes_and_legend(ax, result, title)
    if new:
        fig.tight_layout()
    return fig


def draw_critical_speed(critical: CriticalSpeed, ax=None, *, figsize: tuple[float, float] = (6.0, 4.5)):
    """Mark a critical speed (:meth:`CriticalSpeed.plot`) at (rpm, Hz) with its excitation line and a label;
    return the Figure.

    Drawn into the axes of a Campbell diagram (:func:`draw_campbell`, same units) it annotates that crossing;
    into a new figure it shows the excitation line from rest to twice the critical speed and the crossing on it.

    Parameters
    ----------
    critical : CriticalSpeed
    ax : matplotlib Axes, optional
        Axes to draw into; default a new figure of ``figsize`` (in).
    figsize : (float, float)
        Size of a new figure (in).

    Returns
    -------
    matplotlib.figure.Figure
    """
    new = ax is None
    fig, ax = axes(ax, figsize)
    x, y = critical.speed_rpm, critical.frequency_hz
    if new:
        ax.plot([0.0, 2.0 * x], [0.0, 2.0 * y], color="0.2", lw=1.0, linestyle=(0, (6, 2)), label=critical.line)
        ax.set_xlim(0.0, 2.0 * x)
        ax.set_ylim(0.0, 2.0 * y)
        ax.set_xlabel("speed of the reference spool (rpm)")
        ax.set_ylabel("whirl frequency (Hz)")
        ax.grid(True, alpha=0.3)
    ax.plot([x], [y], **CRITICAL_STYLE, label=None if not new else "critical speed")
    ax.annotate(f"{x:.0f} rpm, {y:.4g} Hz\nmode {critical.mode + 1} {critical.whirl}, log dec {critical.log_dec:.3g}",
                (x, y), xytext=(6, -6), textcoords="offset points", fontsize=8, va="top", zorder=6,
                bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85))
    if new:
        ax.set_title(f"critical speed on {critical.line}")
        ax.legend(loc="upper left", fontsize=8)
        fig.tight_layout()
    return fig


def _whirl_curves(ax, result: CampbellResult, max_frequency_hz: float | None) -> None:
    """One line per run of equal whirl direction of each mode; consecutive runs share their end point."""
    rpm, f_hz = result.speeds_rpm, result.frequencies_hz
    seen = set()
    for j in range(result.n_modes):
        w = result.whirl[:, j]
        start = 0
        for i in range(1, len(rpm) + 1):
            if i == len(rpm) or w[i] != w[start]:
                stop = min(i + 1, len(rpm))
                label = w[start] if w[start] not in seen else None
                seen.add(w[start])
                ax.plot(rpm[start:stop], f_hz[start:stop, j], lw=1.8, label=f"{label} whirl" if label else None,
                        marker="o" if len(rpm) == 1 else None, **WHIRL_STYLE[str(w[start])])
                start = i


#: least vertical distance between two mode numbers at the right end, as a share of the frequency axis
LABEL_GAP = 0.028


def _mode_numbers(ax, result: CampbellResult, top: float) -> None:
    """Each mode's number (from 1, as in the tables) at the right end of its curve, moved apart where curves end
    closer than :data:`LABEL_GAP` of the axis, with a leader to the curve's end when moved."""
    ends = result.frequencies_hz[-1]
    shown = [j for j in np.argsort(ends) if ends[j] <= top]
    gap = LABEL_GAP * top
    placed: list[float] = []
    for j in shown:  # upwards from the lowest end: each label at least one gap above the last
        placed.append(max(float(ends[j]), placed[-1] + gap) if placed else float(ends[j]))
    excess = (placed[-1] - top) if placed else 0.0
    if excess > 0:  # pushed past the top: shift down as far as the lowest label allows
        placed = [y - min(excess, placed[0]) for y in placed]
    x = float(result.speeds_rpm[-1])
    beside = blended_transform_factory(ax.transAxes, ax.transData)  # x: share of the axes' width, y: Hz
    for j, y in zip(shown, placed):
        moved = abs(y - ends[j]) > 1e-3 * gap
        ax.annotate(f"{j + 1}", (x, ends[j]), xytext=(1.025 if moved else 1.005, y), textcoords=beside,
                    fontsize=8, va="center", color="0.3", annotation_clip=False,
                    arrowprops=dict(arrowstyle="-", color="0.6", lw=0.6, shrinkA=1, shrinkB=0) if moved else None)


def _excitation_lines(ax, result: CampbellResult, top: float) -> None:
    """The excitation lines, each labelled inline where it is farthest from the curves and other labels; at
    one speed (a whirl table), drawn from rest to it."""
    rpm, f_hz = result.speeds_rpm, result.frequencies_hz
    x_max = float(rpm[-1])
    x0 = float(rpm[0]) if len(rpm) > 1 else 0.0
    line_rpm, line_speeds = (rpm, result.speeds) if len(rpm) > 1 else (np.array([0.0, x_max]),
                                                                       np.array([0.0, result.speeds[0]]))
    placed: list[tuple[float, float]] = []
    dashes = [(0, (6, 2)), (0, (1, 1.5)), (0, (6, 2, 1, 2)), (0, (3, 3)), (0, (8, 2, 1, 2, 1, 2))]
    for k, (spool, h, slope, offset) in enumerate(result.excitation_lines):
        label = excitation_label(h, spool)
        ax.plot(line_rpm, (slope * line_speeds + offset) / (2 * np.pi), color="0.2", lw=1.0,
                linestyle=dashes[k % len(dashes)], label=label)
        if x_max <= x0:
            continue
        # distances in axes fractions
        hz_per_rpm, hz0 = slope * np.pi / 30 / (2 * np.pi), offset / (2 * np.pi)
        x_end = min(x_max, (top - hz0) / hz_per_rpm) if hz_per_rpm > 0 else x_max
        best, x = -1.0, 0.5 * (x0 + x_end)
        for t in np.linspace(0.2, 0.9, 15):
            xc = x0 + t * (x_end - x0)
            yc = hz_per_rpm * xc + hz0
            gaps = [abs(np.interp(xc, rpm, f_hz[:, j]) - yc) / top for j in range(result.n_modes)]
            gaps += [np.hypot((xc - xp) / (x_max - x0), (yc - yp) / top) for xp, yp in placed]
            if min(gaps) > best:
                best, x = min(gaps), xc
        placed.append((x, hz_per_rpm * x + hz0))
        p0, p1 = ax.transData.transform([(x, hz_per_rpm * x + hz0), (x + 1.0, hz_per_rpm * (x + 1.0) + hz0)])
        angle = float(np.degrees(np.arctan2(p1[1] - p0[1], p1[0] - p0[0])))
        ax.text(x, hz_per_rpm * x + hz0, label, rotation=angle, rotation_mode="anchor", ha="center", va="center",
                fontsize=8.5, color="0.1", bbox=dict(boxstyle="round,pad=0.12", fc="white", ec="none", alpha=0.85),
                zorder=4)


def _axes_and_legend(ax, result: CampbellResult, title: str | None) -> None:
    """Axis labels (rpm, Hz), the other spool's speed on top, title with the speed ratios, legend."""
    ax.set_xlabel(f"speed of the {result.reference} spool (rpm)")
    ax.set_ylabel("whirl frequency (Hz)")
    fixed = result.fixed_speeds
    others = {s: r for s, r in result.speed_ratios.items() if s != result.reference and s not in fixed}
    ratio_text = ", ".join([f"Ω_{s}/Ω_{result.reference} = {r:.4g}" for s, r in others.items()]
                           + [f"{s} fixed at {w * 30 / np.pi:.6g} rpm" for s, w in fixed.items()])
    default_title = f"Campbell diagram — {result.rotor_name or 'rotor'}" + (f" ({ratio_text})" if ratio_text else "")
    ax.set_title(title or default_title)
    if len(others) == 1:
        (s, r), = others.items()
        if r > 0:
            sec = ax.secondary_xaxis("top", functions=(lambda x, r=r: x * r, lambda x, r=r: x / r))
            sec.set_xlabel(f"speed of the {s} spool (rpm)")
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    order = [f"{w} whirl" for w in WHIRL_STYLE]
    key = {lab: (order.index(lab) if lab in order else len(order)) for lab in labels}
    pairs = sorted(zip(handles, labels), key=lambda hl: key[hl[1]])
    ax.legend([h for h, _ in pairs], [lab for _, lab in pairs], loc="upper left", bbox_to_anchor=(1.03, 1.0),
              fontsize=9, title="curves (mode no. at right end)", title_fontsize=8.5)
