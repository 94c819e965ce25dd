"""External loads: mass unbalance (and gravity)."""

from __future__ import annotations

import math
from dataclasses import dataclass


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
