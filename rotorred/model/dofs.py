"""Physical degrees of freedom: the directions at a node, their short spellings, the global DOF
numbering (:class:`DofMap`) and the one parser of ``"NODE:DIRECTION"`` text (:func:`parse_dof`).

DOF order at a node: (x, y, theta_x, theta_y); z is the shaft axis. Wherever a user names a DOF
(a rotor file's ``[defaults]``, a scene's ``output.table``, a command option such as
``--outputs``) it is written ``"13:x"`` or ``"13:tx"`` and read by :func:`parse_dof`; code passes
(node, direction) pairs, checked by :func:`checked_dof`.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass, field

import numpy as np

from rotorred import checks

__all__ = ["DIRECTIONS", "DIRECTION_ALIASES", "DofMap", "parse_dof", "checked_dof", "direction_name"]

#: the four DOFs of a node, in DOF order
DIRECTIONS = ("x", "y", "theta_x", "theta_y")
#: short spellings accepted wherever a direction is given: ``tx`` = theta_x, ``ty`` = theta_y
DIRECTION_ALIASES = {"tx": "theta_x", "ty": "theta_y"}
_OFFSET = {**{d: i for i, d in enumerate(DIRECTIONS)}, **{a: DIRECTIONS.index(d) for a, d in DIRECTION_ALIASES.items()}}
_DIRECTIONS_TEXT = "'x', 'y', 'theta_x' ('tx'), 'theta_y' ('ty')"
_DOF_RE = re.compile(r"\s*(\d+)\s*:\s*([A-Za-z_]+)\s*")


def direction_name(direction: str) -> str:
    """The paper's name of a direction, for labels: ``"x"`` -> ``"X"``, ``"y"`` -> ``"Y"``; rotations
    (``"theta_x"`` or ``"tx"``, ``"theta_y"`` or ``"ty"``) keep their canonical names."""
    if not isinstance(direction, str) or direction not in _OFFSET:
        checks.fail("direction", direction, f"must be one of {_DIRECTIONS_TEXT}")
    direction = DIRECTION_ALIASES.get(direction, direction)
    return {"x": "X", "y": "Y"}.get(direction, direction)


def parse_dof(field: str, text, nodes: Collection[int] | None = None) -> tuple[int, str]:
    """Read a DOF written ``"NODE:DIRECTION"``: ``"13:x"`` -> (13, "x"), ``"13:tx"`` -> (13, "theta_x").

    Parameters
    ----------
    field : str
        What the user wrote it in, for the message (``"--outputs"``, ``"output.table"``,
        ``"defaults.outputs[1]"``).
    text : str
        ``NODE:DIRECTION`` with DIRECTION one of x, y, theta_x (tx), theta_y (ty).
    nodes : collection of int, optional
        The nodes that exist; if given, the node must be one of them.

    Returns
    -------
    (int, str)
        Node number and canonical direction name.

    Raises
    ------
    rotorred.checks.InputError
        ``<field> = '<text>': <what is allowed>``.
    """
    checks.string(field, text)
    match = _DOF_RE.fullmatch(text)
    if match is None:
        checks.fail(field, text, f"must be NODE:DIRECTION (e.g. '13:x') with DIRECTION one of {_DIRECTIONS_TEXT}")
    node, direction = int(match.group(1)), match.group(2)
    direction = DIRECTION_ALIASES.get(direction, direction)
    if direction not in DIRECTIONS:
        checks.fail(field, text, f"direction must be one of {_DIRECTIONS_TEXT}")
    if nodes is not None and node not in nodes:
        checks.fail(field, text, f"must name a node of the rotor ({checks.ranges_text(nodes)}); node {node} is not one")
    return node, direction


def checked_dof(field: str, value, nodes: Collection[int] | None = None, what: str = "the rotor") -> tuple[int, str]:
    """A (node, direction) pair, or ``"NODE:DIRECTION"`` text (:func:`parse_dof`); returns (int, str).

    ``nodes``, if given, are the nodes that exist (of ``what``, for the message).
    """
    if isinstance(value, str):
        return parse_dof(field, value, nodes)
    if not (isinstance(value, (tuple, list)) and len(value) == 2):
        checks.fail(field, value, "must be a (node, direction) pair")
    node, direction = value
    if not isinstance(node, (int, np.integer)) or isinstance(node, (bool, np.bool_)):
        checks.fail(field, value, "must be a (node, direction) pair with an integer node")
    if nodes is not None and node not in nodes:
        checks.fail(field, value, f"must name a node of {what} ({checks.ranges_text(nodes)}); node {node} is not one")
    direction = DIRECTION_ALIASES.get(direction, direction) if isinstance(direction, str) else direction
    if direction not in DIRECTIONS:
        checks.fail(field, value, f"direction must be one of {_DIRECTIONS_TEXT}")
    return int(node), str(direction)


@dataclass(frozen=True)
class DofMap:
    """Global DOF numbering.

    4 DOFs per node, (x, y, theta_x, theta_y), nodes in ``nodes`` order, indices
    ``4 * position + direction``; then the internal (bubble) DOFs of hierarchical shaft
    elements, ``n_internal`` of them, after all nodal DOFs. Code that needs physical DOFs uses
    :meth:`index` or :meth:`node_dofs`, never ``n_dof // 4``.

    Parameters
    ----------
    nodes : tuple of int
        Node numbers in DOF order.
    n_internal : int
        Number of internal DOFs (0 for a model of Nelson elements only).
    """

    nodes: tuple[int, ...]
    n_internal: int = 0
    _pos: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "nodes", checks.sequence("nodes", tuple(self.nodes), checks.integer, unique=True))
        object.__setattr__(self, "n_internal", checks.integer("n_internal", self.n_internal, ge=0))
        object.__setattr__(self, "_pos", {n: i for i, n in enumerate(self.nodes)})

    @property
    def n_dof(self) -> int:
        """Number of DOFs."""
        return 4 * len(self.nodes) + self.n_internal

    @property
    def nodal(self) -> np.ndarray:
        """Indices of all nodal DOFs as an array, shape (n_nodes, 4): row k is node ``nodes[k]``."""
        return np.arange(4 * len(self.nodes)).reshape(-1, 4)

    def node_dofs(self, node: int) -> np.ndarray:
        """Global indices of the 4 DOFs of ``node``, shape (4,)."""
        return 4 * self._node_pos(node) + np.arange(4)

    def index(self, node: int, direction: str) -> int:
        """Global index of ``direction`` at ``node``: ``"x"``, ``"y"``, ``"theta_x"`` (``"tx"``) or
        ``"theta_y"`` (``"ty"``)."""
        if not isinstance(direction, str) or direction not in _OFFSET:
            checks.fail("direction", direction, f"must be one of {_DIRECTIONS_TEXT}")
        return 4 * self._node_pos(node) + _OFFSET[direction]

    def checked_outputs(self, outputs, name: str = "outputs") -> tuple[tuple[int, str], ...]:
        """Validate (node, direction) pairs (or ``"NODE:DIRECTION"`` texts) naming nodes of this model.

        Raises :class:`rotorred.checks.InputError` naming ``name[i]``, the entry and what is allowed.
        """
        if isinstance(outputs, (str, bytes)) or not hasattr(outputs, "__iter__"):
            checks.fail(name, outputs, "must be a sequence of (node, direction) pairs")
        return tuple(checked_dof(f"{name}[{i}]", o, self._pos, "the model") for i, o in enumerate(outputs))

    def label(self, dof: int) -> str:
        """Human label of a global DOF, e.g. ``"node 18 y"``."""
        checks.integer("dof", dof, ge=0, le=self.n_dof - 1)
        if dof >= 4 * len(self.nodes):
            return f"internal {dof - 4 * len(self.nodes)}"
        return f"node {self.nodes[dof // 4]} {DIRECTIONS[dof % 4]}"

    def _node_pos(self, node: int) -> int:
        try:
            return self._pos[node]
        except (KeyError, TypeError):
            checks.fail("node", node, f"must be a node of the model ({checks.ranges_text(self.nodes)})")
