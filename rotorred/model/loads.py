"""External loads: mass unbalance (and gravity)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Unbalance:
    """A mass unbalance at a node, rotating with the spool the node belongs to.

    The force on the node is ``m_e Omega^2 [cos(Omega t + phase), sin(Omega t + phase)]`` in (x, y),
    with Omega the speed of the node's spool (forward rotation, counter-clockwise in x-y).

    Parameters
    ----------
    node : int
    m_e : float
        Unbalance magnitude, mass times eccentricity (kg m), >= 0.
    phase : float
        Angular position at t = 0 (rad).
    """

    node: int
    m_e: float
    phase: float = 0.0

    def __post_init__(self):
        if not isinstance(self.node, int) or isinstance(self.node, bool):
            raise ValueError(f"`node` must be an integer node number, got {self.node!r}")
        if not (math.isfinite(self.m_e) and self.m_e >= 0):
            raise ValueError(f"`m_e` must be a finite number >= 0 (kg m), got {self.m_e!r}")
        if not math.isfinite(self.phase):
            raise ValueError(f"`phase` must be finite (rad), got {self.phase!r}")


def gravity_force(model, g: float) -> np.ndarray:
    """Force of gravity ``g`` (m/s^2) along -y in model coordinates, ``-g M e``.

    ``e`` is a rigid unit translation in y expressed in the model's coordinates (for a reduced
    model, the least-squares fit of the recovery rows, which is exact when every bearing node is
    on the boundary).

    Parameters
    ----------
    model : SystemMatrices or ReducedSystem
    g : float
        Gravity acceleration (m/s^2).

    Returns
    -------
    ndarray, shape (n,)
    """
    pairs = [(node, d) for node in model.full_dofs.nodes for d in ("x", "y", "theta_x", "theta_y")]
    R = model.output_rows(pairs)
    target = np.array([1.0 if d == "y" else 0.0 for _, d in pairs])
    e, *_ = np.linalg.lstsq(R, target, rcond=None)
    if np.max(np.abs(R @ e - target)) > 1e-8:
        raise ValueError("`gravity`: a rigid translation is not representable in this model's coordinates "
                         "(a reduced model must keep every bearing node on its boundary)")
    return -g * (model.M @ e)
