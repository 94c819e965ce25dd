"""Reduced against full (:class:`rotorred.scenes.compare.ModelComparison`): run time against error, the front."""

from __future__ import annotations

from rotorred.plots.axes import axes

#: smallest error drawn on the logarithmic axis (%): a run that matches the reference to round-off sits here
ERROR_FLOOR_PCT = 1e-6
COLORS = ("black", "tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink",
          "tab:olive", "tab:cyan")


def draw_comparison(comparison, ax=None, *, title: str = "", figsize: tuple[float, float] = (9.0, 5.5)):
    """Wall time (s) against spectral error (%) of every run, log-log: each model's time steps joined and labelled
    with dt, the front (the runs nothing beats in both) as a grey step line, the reference's time a vertical line.

    Parameters
    ----------
    comparison : ModelComparison
    ax : matplotlib Axes, optional
        Axes to draw into; default a new figure of ``figsize`` (in).
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    new = ax is None
    fig, ax = axes(ax, figsize)
    ref = comparison.reference
    models = list(dict.fromkeys(r.model for r in comparison.runs))
    for k, model in enumerate(models):
        runs = sorted((r for r in comparison.runs if r.model == model and r is not ref), key=lambda r: r.dt)
        if not runs:
            continue
        err = [max(100 * r.errors.spectral, ERROR_FLOOR_PCT) for r in runs]
        color = COLORS[k % len(COLORS)]
        ax.loglog([r.wall for r in runs], err, "-o", color=color, ms=5, label=f"{model} ({runs[0].n_dof} DOFs)")
        for r, e in zip(runs, err):
            ax.annotate(f"{r.dt:g}", (r.wall, e), textcoords="offset points", xytext=(4, 3), fontsize=7, color=color)
    front = [r for r in comparison.front() if r is not ref]
    if front:
        ax.step([r.wall for r in front], [max(100 * r.errors.spectral, ERROR_FLOOR_PCT) for r in front], where="post",
                color="0.5", lw=2.5, alpha=0.35, zorder=0, label="front: nothing faster is as accurate")
    ax.axvline(ref.wall, color="black", ls="--", lw=0.8,
               label=f"reference: full ({ref.n_dof} DOFs), dt {ref.dt:g} s, {ref.wall:.3g} s")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time of a run (s): model build included, kernel load excluded")
    ax.set_ylabel(f"spectral error (%): worst of the {comparison.n_lines} largest lines")
    ax.set_title(title or f"reduced against full: scene {comparison.scene.name} (labels: dt in s)", fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7, loc="best")
    if new:
        fig.tight_layout()
    return fig
