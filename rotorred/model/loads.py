"""External loads: mass unbalance (and gravity)."""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from dataclasses import dataclass

import numpy as np

from rotorred import checks

#: keys of an unbalance table (a scene's ``[[unbalance]]``, a rotor file's ``[defaults]`` ``unbalance``)
UNBALANCE_KEYS = ("node", "m_e", "phase_deg", "phase_rad")


@dataclass(frozen=True)
class Unbalance:
    """A mass unbalance at a node, rotating with the spool the node belongs to.

    The force on the node is ``m_e Omega^2 [cos(Omega t + phase), sin(Omega t + phase)]`` in (x, y),
    with Omega the speed of the node's spool (forward rotation, counter-clockwise in x-y).

    Parameters
    ----------
    node : int
        The shaft node the unbalance sits at; it turns with that node's spool.
    m_e : float
        Unbalance magnitude, mass times eccentricity (kg m), >= 0.
    phase : float
        Angular position at t = 0 (rad).
    """

    node: int
    m_e: float
    phase: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "node", checks.integer("node", self.node))
        object.__setattr__(self, "m_e", checks.non_negative("m_e", self.m_e, "kg m"))
        object.__setattr__(self, "phase", checks.number("phase", self.phase, "rad"))


def unbalance_from_table(field: str, table, nodes: Collection[int]) -> Unbalance:
    """An :class:`Unbalance` from a file table ``{node = 11, m_e = 1e-5, phase_deg = 90.0}``.

    ``m_e`` in kg m, ``phase_deg`` in degrees (default 0) or ``phase_rad`` in radians (what a written rotor holds
    when no degree value reads back to its phase exactly); ``node`` must be one of ``nodes``.
    Values are checked as written (degrees) before the phase is converted to radians.
    """
    table: Mapping = checks.table(field, table)
    checks.keys(field, table, UNBALANCE_KEYS, required=("node", "m_e"))
    node = checks.node(f"{field}.node", table["node"], nodes)
    m_e = checks.non_negative(f"{field}.m_e", table["m_e"], "kg m")
    if "phase_rad" in table:
        if "phase_deg" in table:
            checks.fail(f"{field}.phase_rad", table["phase_rad"],
                        "must not be given with phase_deg: give one of the two")
        return Unbalance(node, m_e, checks.number(f"{field}.phase_rad", table["phase_rad"], "rad"))
    phase_deg = checks.number(f"{field}.phase_deg", table.get("phase_deg", 0.0), "deg")
    return Unbalance(node, m_e, math.radians(phase_deg))


def gravity_force(model, g: float) -> np.ndarray:
    """Force of gravity ``g`` (m/s^2) along -y in model coordinates, ``-g M e``.

    ``e`` is a rigid unit translation in y expressed in the model's coordinates (1 on every y of a full model; for a
    reduced model, the least-squares fit of the recovery rows, which is exact when every bearing node is
    on the boundary). A model with supports carries ``M e`` of the rotor before its fixed DOFs were removed
    (``supported_weight``): the fixed DOFs' share of the consistent load acts on their free neighbours.

    Parameters
    ----------
    model : SystemMatrices or ReducedSystem
    g : float
        Gravity acceleration (m/s^2).

    Returns
    -------
    ndarray, shape (n,)
    """
    g = checks.number("g", g, "m/s^2")
    if model.supported_weight is not None:  # supports remove DOFs that move with a rigid translation
        return -g * model.supported_weight
    pairs = list(model.full_dofs.pairs)
    if hasattr(model, "output_index"):  # a full model: its DOFs are its coordinates, e is 1 on every y, 0 elsewhere
        e = np.zeros(model.n_dof)
        e[model.output_index([p for p in pairs if p[1] == "y"])] = 1.0
        return -g * (model.M @ e)
    R = model.output_rows(pairs)
    target = np.array([1.0 if d == "y" else 0.0 for _, d in pairs])
    e, *_ = np.linalg.lstsq(R, target, rcond=None)
    if np.max(np.abs(R @ e - target)) > 1e-8:
        checks.fail("g", g, "needs a model that represents a rigid translation: a reduced model must keep every "
                    "bearing node on its boundary", "m/s^2")
    return -g * (model.M @ e)
