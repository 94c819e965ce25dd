"""Figure of a one-key sweep: line amplitudes and contact against the swept value (µm for clearances)."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from rotorred.signals.lines import parse_label

__all__ = ["plot_sweep"]


def plot_sweep(result, path, n_lines: int = 4) -> Path:
    """Line amplitudes (f_L, f_H, the ``n_lines`` strongest combinations) and contact fraction against the value.

    Parameters
    ----------
    result : rotorred.scenes.sweep.SweepResult
    path : str or Path
        PNG file to write.
    n_lines : int
        Combination lines drawn besides f_L and f_H.

    Returns
    -------
    Path
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    scale, xlabel = result.axis_scale, result.axis_label
    x = scale * result.values
    fig = Figure(figsize=(9, 7.5), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    node, d = result.dof
    labels = [k for k in ("f_L", "f_H") if k in result.amplitudes] + result.combinations()[:n_lines]
    for k in labels:
        style = "-o" if k in ("f_L", "f_H") else "--s"
        mathlabel = "$" + k + "$"
        ax1.plot(x, 1e6 * result.amplitudes[k], style, ms=4, label=f"{mathlabel} ({_line_hz(k, result):.0f} Hz)")
    ax1.plot(x, 1e6 * result.combination_total(), ":", color="k", label="sum of all combination lines")
    ax1.set_ylabel(f"Line amplitude at node {node} {d.upper()} (µm)")
    ax1.set_title(f"Spectral lines at node {node} {d.upper()}")
    ax1.grid(True, alpha=0.3)
    ax2.plot(x, 100 * result.contact_fraction, "-o", ms=4, color="C3", label="contact fraction")
    ax2.set_ylabel("Contact fraction of the window (%)")
    ax2.set_xlabel(xlabel)
    ax2.set_title("Rub contact")
    ax2.grid(True, alpha=0.3)
    ax3 = ax2.twinx()
    ax3.plot(x, result.n_combinations, "-^", ms=4, color="C4", label="number of combination lines")
    ax3.set_ylabel("Combination lines above threshold")
    if result.free_reach is not None and result.key.endswith("clearance"):
        for ax in (ax1, ax2):
            ax.axvline(scale * result.free_reach, color="0.4", ls="--", lw=1.0,
                       label=f"free orbit reach {scale * result.free_reach:.3g} µm")
    h2, l2 = ax2.get_legend_handles_labels()
    h3, l3 = ax3.get_legend_handles_labels()
    ax2.legend(h2 + h3, l2 + l3, loc="upper right", fontsize=8)
    ax1.legend(loc="upper right", fontsize=8)
    fig.suptitle(f"{result.scene_name}: sweep of {result.key} (f_L = {result.f_L:.4g} Hz, f_H = {result.f_H:.4g} Hz)")
    fig.savefig(path, dpi=120)
    return path


def _line_hz(label: str, result) -> float:
    m, n = parse_label(label)
    return m * result.f_H + float(n) * result.f_L
