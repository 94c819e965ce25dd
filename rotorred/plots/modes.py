"""Mode shapes figure: each mode's deflection along the axis for every spool, node orbits and the whirl sense."""

from __future__ import annotations

import math

import numpy as np

from rotorred import checks
from rotorred.linear.modes import ModeShapes
from rotorred.plots.axes import axes

#: most modes a new figure shows (the lowest)
MAX_PANELS = 12
#: colours of the spools, in the rotor's order
SPOOL_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown")


def draw_mode_shapes(result: ModeShapes, ax=None, *, mode: int = 1, modes=None, orbits: int = 6,
                     figsize: tuple[float, float] | None = None):
    """Draw the mode shapes of ``result`` (:meth:`ModeShapes.plot`); return the Figure.

    Each panel is one mode: for every spool (a colour), its deflection along the axis at the instant the largest
    orbit is at the end of its major axis, projected on that axis (so a planar mode draws as its shape, a circular
    one as its radius with sign), and the orbits of ``orbits`` nodes along each spool as ellipses seen obliquely
    (the major-axis direction up, the other in-plane direction along z), each with a dot at t = 0 and an arrow in
    the sense of motion; the title gives the mode's number, frequency, whirl and log dec.

    Parameters
    ----------
    result : ModeShapes
    ax : matplotlib Axes, optional
        Axes to draw mode ``mode`` into; default a new figure with one panel per mode (``modes``).
    mode : int
        The mode drawn into ``ax`` (number from 1).
    modes : sequence of int, optional
        The modes of a new figure (numbers from 1); default the lowest :data:`MAX_PANELS`.
    orbits : int
        Orbits drawn along each spool (>= 0).
    figsize : (float, float), optional
        Size of a new figure (in); default 4.2 x 3 in a panel.

    Returns
    -------
    matplotlib.figure.Figure
    """
    orbits = checks.integer("orbits", orbits, ge=0)
    if ax is not None:
        _draw_mode(ax, result, checks.integer("mode", mode, ge=1, le=result.n_modes) - 1, orbits)
        return ax.figure
    numbers = list(range(1, min(result.n_modes, MAX_PANELS) + 1)) if modes is None else \
        [checks.integer("modes", k, ge=1, le=result.n_modes) for k in modes]
    cols = min(3, len(numbers))
    rows = math.ceil(len(numbers) / cols)
    fig, _ = axes(None, figsize or (4.2 * cols, 3.0 * rows))
    fig.clear()
    panels = fig.subplots(rows, cols, squeeze=False).ravel()
    for panel, k in zip(panels, numbers):
        _draw_mode(panel, result, k - 1, orbits)
    for panel in panels[len(numbers):]:
        panel.set_visible(False)
    fig.suptitle(f"mode shapes - {result.rotor_name or 'rotor'} at "
                 + ", ".join(f"{s} {w * 30 / math.pi:.6g} rpm" for s, w in result.speeds.items()))
    fig.tight_layout()
    return fig


def _draw_mode(ax, result: ModeShapes, k: int, orbits: int) -> None:
    """Mode row ``k`` into ``ax``: each spool's deflection and orbits."""
    u, v = _frame(result, k)
    span = float(np.ptp(result.z)) or 1.0
    width = 0.5 * span / max(orbits, 1)  # the in-plane axis drawn along z: an orbit's half width
    for i, spool in enumerate(dict.fromkeys(result.node_spools)):
        color = SPOOL_COLORS[i % len(SPOOL_COLORS)]
        cols = result.spool_nodes(spool)
        z = result.z[cols]
        d = _along(result.X[k, cols], result.Y[k, cols], u)
        ax.plot(z, d, "-", color=color, lw=1.6, label=spool)
        ax.plot(z, np.zeros_like(z), ":", color=color, lw=0.8)
        for j in np.unique(np.linspace(0, len(cols) - 1, orbits).round().astype(int)) if orbits else ():
            _orbit(ax, z[j], result.X[k, cols[j]], result.Y[k, cols[j]], u, v, width, color)
    rigid = " (rigid)" if k in result.rigid_modes else ""
    ax.set_title(f"mode {k + 1}: {result.frequencies_hz[k]:.4g} Hz, {result.whirl[k]}, "
                 f"log dec {result.log_dec[k]:.3g}{rigid}", fontsize=9)
    ax.set_xlabel("z (m)")
    ax.set_ylabel("deflection (-)")
    ax.set_ylim(-1.25, 1.25)
    ax.grid(True, alpha=0.3)
    if len(set(result.node_spools)) > 1:
        ax.legend(fontsize=7, loc="upper right")


def _frame(result: ModeShapes, k: int) -> tuple[complex, complex]:
    """Unit directions (as x + i y) of the largest orbit's major axis at t = 0 (drawn up) and the one 90 degrees
    ahead of it about +z (drawn along z)."""
    j = int(np.argmax(result.semi_major[k]))
    at_zero = complex(result.X[k, j].real + 1j * result.Y[k, j].real)
    u = at_zero / abs(at_zero) if abs(at_zero) > 0 else 1.0 + 0j
    return u, 1j * u


def _along(X, Y, u: complex) -> np.ndarray:
    """Displacement at t = 0 (Re X, Re Y) projected on the direction ``u``."""
    return np.real(np.conj(u) * (np.real(X) + 1j * np.real(Y)))


def _orbit(ax, z0: float, X: complex, Y: complex, u: complex, v: complex, width: float, color: str) -> None:
    """The orbit of one node, centred on (z0, 0): its component along ``u`` up, along ``v`` scaled to ``width``
    along z; a dot at t = 0 and an arrow in the sense of motion."""
    phase = np.linspace(0.0, 2.0 * np.pi, 73)
    w = (X * np.exp(1j * phase)).real + 1j * (Y * np.exp(1j * phase)).real  # x + i y over one period
    up, side = np.real(np.conj(u) * w), np.real(np.conj(v) * w)
    ax.plot(z0 + width * side, up, "-", color=color, lw=0.8, alpha=0.8)
    ax.plot(z0 + width * side[0], up[0], "o", color=color, ms=2.5)
    if np.hypot(side[9] - side[0], up[9] - up[0]) > 1e-9:
        ax.annotate("", xy=(z0 + width * side[9], up[9]), xytext=(z0 + width * side[0], up[0]),
                    arrowprops=dict(arrowstyle="-|>", color=color, lw=0.9, mutation_scale=9))
