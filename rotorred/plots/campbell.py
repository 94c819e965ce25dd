"""Campbell diagram figure: whirl curves by direction, excitation lines, critical speeds."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rotorred.linear.campbell import CampbellResult, excitation_label

#: colour and line style of each whirl direction
WHIRL_STYLE = {
    "forward": dict(color="tab:blue", linestyle="-"),
    "backward": dict(color="tab:red", linestyle="--"),
    "mixed": dict(color="tab:purple", linestyle="-."),
    "planar": dict(color="tab:gray", linestyle=":"),
}


def plot_campbell(result: CampbellResult, path: str | Path, *, operating_speed: float | None = None,
                  title: str | None = None, max_frequency_hz: float | None = None) -> Path:
    """Write the Campbell diagram of ``result`` as a PNG.

    Parameters
    ----------
    result : CampbellResult
    path : str or Path
        Output file (PNG).
    operating_speed : float, optional
        Reference-spool operating speed (rad/s), drawn as a vertical line.
    title : str, optional
        Default: "Campbell diagram - <rotor name>" with the speed ratios.
    max_frequency_hz : float, optional
        Upper limit of the frequency axis (Hz); default 10 % above the highest tracked curve.

    Returns
    -------
    Path
    """
    path = Path(path)
    fig = Figure(figsize=(11, 6), dpi=120)
    ax = fig.subplots()
    top = max_frequency_hz or 1.1 * float(result.frequencies_hz.max())
    _whirl_curves(ax, result, max_frequency_hz)
    ax.set_xlim(float(result.speeds_rpm[0]), float(result.speeds_rpm[-1]))
    ax.set_ylim(0, top)
    _excitation_lines(ax, result, top)
    if result.critical_speeds:
        ax.plot([c.speed_rpm for c in result.critical_speeds], [c.frequency_hz for c in result.critical_speeds],
                "o", mfc="none", mec="black", ms=8, mew=1.5, label="critical speed", zorder=5)
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
    fig.tight_layout()
    fig.savefig(path)
    return path


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
                        **WHIRL_STYLE[str(w[start])])
                start = i
        if f_hz[-1, j] <= (max_frequency_hz or np.inf):
            ax.annotate(f"{j}", (rpm[-1], f_hz[-1, j]), xytext=(3, 0), textcoords="offset points", fontsize=8,
                        va="center", color="0.3", annotation_clip=False)


def _excitation_lines(ax, result: CampbellResult, top: float) -> None:
    """The excitation lines, each labelled inline where it is farthest from the curves and other labels."""
    rpm, f_hz = result.speeds_rpm, result.frequencies_hz
    x_max = float(rpm[-1])
    placed: list[tuple[float, float]] = []
    dashes = [(0, (6, 2)), (0, (1, 1.5)), (0, (6, 2, 1, 2)), (0, (3, 3)), (0, (8, 2, 1, 2, 1, 2))]
    for k, (spool, h, slope, offset) in enumerate(result.excitation_lines):
        label = excitation_label(h, spool)
        ax.plot(rpm, (slope * result.speeds + offset) / (2 * np.pi), color="0.2", lw=1.0,
                linestyle=dashes[k % len(dashes)], label=label)
        # distances in axes fractions
        hz_per_rpm, hz0 = slope * np.pi / 30 / (2 * np.pi), offset / (2 * np.pi)
        x_end = min(x_max, (top - hz0) / hz_per_rpm) if hz_per_rpm > 0 else x_max
        best, x = -1.0, 0.5 * (float(rpm[0]) + x_end)
        for t in np.linspace(0.2, 0.9, 15):
            xc = float(rpm[0]) + t * (x_end - float(rpm[0]))
            yc = hz_per_rpm * xc + hz0
            gaps = [abs(np.interp(xc, rpm, f_hz[:, j]) - yc) / top for j in range(result.n_modes)]
            gaps += [np.hypot((xc - xp) / (x_max - rpm[0]), (yc - yp) / top) for xp, yp in placed]
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
    others = {s: r for s, r in result.speed_ratios.items() if s != result.reference}
    ratio_text = ", ".join(f"Ω_{s}/Ω_{result.reference} = {r:.4g}" for s, r in others.items())
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
