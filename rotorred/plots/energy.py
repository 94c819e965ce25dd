"""The energy balance of a transient (:class:`rotorred.transient.energy.EnergyBalance`) against time."""

from __future__ import annotations

import numpy as np

from rotorred.plots.axes import axes
from rotorred.transient.energy import EnergyBalance


def draw_energy(balance: EnergyBalance, ax=None, *, title: str = "", figsize: tuple[float, float] = (8.0, 5.0)):
    """The terms of the balance E - E0 = W_drive - W_damping + W_gravity + W_contact (J) against time (s), with
    internal damping also - W_internal + W_circulatory.

    ``E - E0`` solid black, the drive's work, the energy dissipated by damping (W_damping, drawn positive),
    the works of gravity and of the contacts, the energy dissipated by internal damping and the work of its
    circulatory force (each where not zero everywhere), and the residual of the balance,
    whose largest magnitude and relative size (:attr:`EnergyBalance.relative_residual`) the legend gives.

    Parameters
    ----------
    balance : EnergyBalance
    ax : matplotlib Axes, optional
        Axes to draw into; default a new figure of ``figsize`` (in).
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    new = ax is None
    fig, ax = axes(ax, figsize)
    t = balance.t
    ax.plot(t, balance.energy, color="black", lw=1.8, label="E − E₀ (kinetic + strain)")
    ax.plot(t, balance.drive, lw=1.2, label="W_drive (unbalances, spin coupling)")
    ax.plot(t, balance.damping, lw=1.2, label="W_damping (dissipated)")
    for work, name in ((balance.gravity, "W_gravity"), (balance.contact, "W_contact"),
                       (balance.internal, "W_internal (dissipated by internal damping)"),
                       (balance.circulatory, "W_circulatory (internal damping's circulatory force)")):
        if np.any(work != 0):
            ax.plot(t, work, lw=1.2, label=name)
    residual = balance.residual
    ax.plot(t, residual, color="tab:red", lw=0.8, ls=":",
            label=f"residual (max {np.max(np.abs(residual)):.2g} J, relative {balance.relative_residual:.2g})")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("energy, work (J)")
    ax.set_title(title or "energy balance: E − E₀ = W_drive − W_damping + W_gravity + W_contact")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    if new:
        fig.tight_layout()
    return fig
