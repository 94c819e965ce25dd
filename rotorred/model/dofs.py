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

    4 DOFs per shaft node, (x, y, theta_x, theta_y), 2 per pedestal node (``translational``: x, y), nodes in
    ``nodes`` order; the DOFs a support fixes (``fixed``) are left out and the others numbered on in that
    order; then the internal (bubble) DOFs of hierarchical shaft elements, ``n_internal`` of them, after all
    nodal DOFs. Without fixed DOFs and pedestals a node's DOFs are ``4 * position + direction``. Code that
    needs physical DOFs uses :meth:`index` or :meth:`node_dofs`, never ``n_dof // 4``.

    Parameters
    ----------
    nodes : tuple of int
        Node numbers in DOF order.
    n_internal : int
        Number of internal DOFs (0 for a model of Nelson elements only).
    fixed : frozenset of (int, str)
        (node, direction) pairs held by supports (:class:`rotorred.model.elements.Support`): not DOFs
        of the model.
    translational : frozenset of int
        Nodes with x and y only: pedestals (:class:`rotorred.model.elements.Pedestal`).
    """

    nodes: tuple[int, ...]
    n_internal: int = 0
    fixed: frozenset = frozenset()
    translational: frozenset = frozenset()
    _pos: dict = field(init=False, repr=False, compare=False)
    _index: dict = field(init=False, repr=False, compare=False)
    _free: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "nodes", checks.sequence("nodes", tuple(self.nodes), checks.integer, unique=True))
        object.__setattr__(self, "n_internal", checks.integer("n_internal", self.n_internal, ge=0))
        object.__setattr__(self, "_pos", {n: i for i, n in enumerate(self.nodes)})
        fixed = frozenset(checked_dof(f"fixed[{i}]", d, self._pos, "the model")
                          for i, d in enumerate(sorted(self.fixed, key=str)))
        object.__setattr__(self, "fixed", fixed)
        translational = frozenset(checks.node(f"translational[{i}]", n, self._pos, "a node of the model")
                                  for i, n in enumerate(sorted(self.translational)))
        object.__setattr__(self, "translational", translational)
        free = tuple((n, d) for n in self.nodes for d in self.directions(n) if (n, d) not in fixed)
        object.__setattr__(self, "_free", free)
        object.__setattr__(self, "_index", {nd: i for i, nd in enumerate(free)})

    @property
    def n_dof(self) -> int:
        """Number of DOFs."""
        return len(self._free) + self.n_internal

    @property
    def nodal(self) -> np.ndarray:
        """Indices of all nodal DOFs, shape (n_nodes, 4): row k is node ``nodes[k]``; -1 where a DOF is fixed."""
        return np.array([[self._index.get((n, d), -1) for d in DIRECTIONS] for n in self.nodes], dtype=int)

    @property
    def pairs(self) -> tuple[tuple[int, str], ...]:
        """(node, direction) of each nodal DOF, in DOF order (fixed DOFs and pedestals' rotations are not DOFs)."""
        return self._free

    def directions(self, node: int) -> tuple[str, ...]:
        """The directions a node has (fixed or not): x, y for a pedestal node, all four for a shaft node."""
        return DIRECTIONS[:2] if node in self.translational else DIRECTIONS

    def node_dofs(self, node: int) -> np.ndarray:
        """Global indices of the free DOFs of ``node``, in DOF order, shape (4,) (2 for a pedestal node; fewer where a
        support fixes some)."""
        self._node_pos(node)
        return np.array([self._index[(node, d)] for d in DIRECTIONS if (node, d) in self._index], dtype=int)

    def index(self, node: int, direction: str) -> int:
        """Global index of ``direction`` at ``node``: ``"x"``, ``"y"``, ``"theta_x"`` (``"tx"``) or
        ``"theta_y"`` (``"ty"``)."""
        if not isinstance(direction, str) or direction not in _OFFSET:
            checks.fail("direction", direction, f"must be one of {_DIRECTIONS_TEXT}")
        self._node_pos(node)
        direction = DIRECTION_ALIASES.get(direction, direction)
        if direction not in self.directions(node):
            checks.fail("node", node, f"must be a shaft node to have {direction}; node {node} is a pedestal node "
                        "(x and y only)")
        if (node, direction) in self.fixed:
            checks.fail("node", node, f"must be a node whose {direction} is free; a support fixes {direction} there "
                        "(its displacement is zero, not a DOF of the model)")
        return self._index[(node, direction)]

    def is_fixed(self, node: int, direction: str) -> bool:
        """Whether a support fixes ``direction`` at ``node``."""
        return (node, DIRECTION_ALIASES.get(direction, direction)) in self.fixed

    def free_in(self, full: DofMap) -> np.ndarray:
        """This map's DOFs as indices of ``full`` (the same nodes and internal DOFs, nothing fixed), shape (n_dof,):
        ``X[np.ix_(k, k)]`` takes a matrix assembled on ``full`` to this map."""
        nodal = [full.index(n, d) for n, d in self._free]
        start = full.n_dof - full.n_internal
        return np.array(nodal + list(range(start, start + self.n_internal)), dtype=int)

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
        if dof >= len(self._free):
            return f"internal {dof - len(self._free)}"
        node, direction = self._free[dof]
        return f"node {node} {direction}"

    def node_of(self, dof: int) -> int | None:
        """The node of a global DOF (None for an internal DOF)."""
        return self._free[dof][0] if dof < len(self._free) else None

    def _node_pos(self, node: int) -> int:
        try:
            return self._pos[node]
        except (KeyError, TypeError):
            checks.fail("node", node, f"must be a node of the model ({checks.ranges_text(self.nodes)})")
