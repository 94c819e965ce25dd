"""The rotor model: spools of shaft elements, disks, bearings and inter-shaft bearings.

A :class:`Rotor` holds one or more :class:`Spool` s. Each spool is a chain of shaft
elements on user-visible node numbers and spins at its own speed; the gyroscopic term of
the assembled system is ``sum_s Omega_s G_s`` (Xu et al. 2016, Eq. 13, with one G per spool).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Mapping

from rotorred.model.elements import Bearing, Disk, IntershaftBearing, ShaftElement


@dataclass(frozen=True)
class Spool:
    """A shaft spinning at its own speed.

    Parameters
    ----------
    name : str
        E.g. ``"inner"`` (low pressure) or ``"outer"`` (high pressure).
    elements : tuple of ShaftElement
        A chain: each element's ``right`` node is the next element's ``left``.
    speed : float
        Nominal operating speed (rad/s), >= 0.
    z0 : float
        Axial position of the first node (m).
    """

    name: str
    elements: tuple[ShaftElement, ...]
    speed: float = 0.0
    z0: float = 0.0

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"spool `name` must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "elements", tuple(self.elements))
        if not self.elements:
            raise ValueError(f"spool {self.name!r}: `elements` must hold at least one shaft element, got none")
        for i, (a, b) in enumerate(zip(self.elements[:-1], self.elements[1:])):
            if a.right != b.left:
                raise ValueError(
                    f"spool {self.name!r}: elements must form a chain; element {i} ends at node {a.right} "
                    f"but element {i + 1} starts at node {b.left}")
        nodes = self.nodes
        if len(set(nodes)) != len(nodes):
            raise ValueError(f"spool {self.name!r}: a node appears twice in the chain {nodes}")
        if not (math.isfinite(self.speed) and self.speed >= 0):
            raise ValueError(f"spool {self.name!r}: `speed` must be >= 0 rad/s, got {self.speed!r}")
        if not math.isfinite(self.z0):
            raise ValueError(f"spool {self.name!r}: `z0` must be finite, got {self.z0!r}")

    @property
    def nodes(self) -> tuple[int, ...]:
        """Node numbers along the spool, in axial order."""
        return (self.elements[0].left, *(e.right for e in self.elements))

    @property
    def positions(self) -> dict[int, float]:
        """Axial position of each node (m)."""
        z = {self.elements[0].left: self.z0}
        for e in self.elements:
            z[e.right] = z[e.left] + e.L
        return z


@dataclass(frozen=True)
class Rotor:
    """A (multi-spool) rotor.

    Parameters
    ----------
    spools : tuple of Spool
    disks : tuple of Disk
    bearings : tuple of Bearing
        Node-to-ground bearings.
    intershaft_bearings : tuple of IntershaftBearing
        Bearings between nodes of two different spools.
    rayleigh : tuple of float, optional
        (alpha (1/s), beta (s)) of the shafts' Rayleigh damping C = alpha M_shaft + beta K_shaft;
        disks and bearings are not included.
    name : str
    """

    spools: tuple[Spool, ...]
    disks: tuple[Disk, ...] = ()
    bearings: tuple[Bearing, ...] = ()
    intershaft_bearings: tuple[IntershaftBearing, ...] = ()
    rayleigh: tuple[float, float] = (0.0, 0.0)
    name: str = ""

    def __post_init__(self):
        for f in ("spools", "disks", "bearings", "intershaft_bearings", "rayleigh"):
            object.__setattr__(self, f, tuple(getattr(self, f)))
        if not self.spools:
            raise ValueError("`spools` must hold at least one spool, got none")
        names = [s.name for s in self.spools]
        if len(set(names)) != len(names):
            raise ValueError(f"spool names must be unique, got {names}")
        owner: dict[int, str] = {}
        for s in self.spools:
            for n in s.nodes:
                if n in owner:
                    raise ValueError(f"node {n} belongs to spool {owner[n]!r} and to spool {s.name!r}")
                owner[n] = s.name
        known = sorted(owner)
        for i, d in enumerate(self.disks):
            if d.node not in owner:
                raise ValueError(f"disks[{i}] ({d.name or 'unnamed'}): `node` {d.node} does not exist; "
                                 f"nodes are {_ranges(known)}")
        for i, b in enumerate(self.bearings):
            if b.node not in owner:
                raise ValueError(f"bearings[{i}] ({b.name or 'unnamed'}): `node` {b.node} does not exist; "
                                 f"nodes are {_ranges(known)}")
        for i, b in enumerate(self.intershaft_bearings):
            for attr in ("node_a", "node_b"):
                n = getattr(b, attr)
                if n not in owner:
                    raise ValueError(f"intershaft_bearings[{i}] ({b.name or 'unnamed'}): `{attr}` {n} does not "
                                     f"exist; nodes are {_ranges(known)}")
            if owner[b.node_a] == owner[b.node_b]:
                raise ValueError(f"intershaft_bearings[{i}]: nodes {b.node_a} and {b.node_b} are both on spool "
                                 f"{owner[b.node_a]!r}; an inter-shaft bearing joins two different spools")
        if len(self.rayleigh) != 2 or not all(math.isfinite(v) and v >= 0 for v in self.rayleigh):
            raise ValueError(f"`rayleigh` must be (alpha >= 0, beta >= 0), got {self.rayleigh!r}")

    # --- topology -----------------------------------------------------------------
    @property
    def nodes(self) -> tuple[int, ...]:
        """All node numbers in DOF order: spool by spool, axially."""
        return tuple(n for s in self.spools for n in s.nodes)

    @property
    def spool_of(self) -> dict[int, str]:
        """Spool name of each node."""
        return {n: s.name for s in self.spools for n in s.nodes}

    @property
    def positions(self) -> dict[int, float]:
        """Axial position of each node (m)."""
        z: dict[int, float] = {}
        for s in self.spools:
            z.update(s.positions)
        return z

    @property
    def speeds(self) -> dict[str, float]:
        """Nominal speed of each spool (rad/s)."""
        return {s.name: s.speed for s in self.spools}

    def spool(self, name: str) -> Spool:
        """The spool called ``name``."""
        for s in self.spools:
            if s.name == name:
                return s
        raise ValueError(f"spool {name!r} does not exist; spools are {[s.name for s in self.spools]}")

    def disk_at(self, node: int) -> Disk:
        """The disk at ``node``."""
        for d in self.disks:
            if d.node == node:
                return d
        raise ValueError(f"there is no disk at node {node}; disks are at {[d.node for d in self.disks]}")

    @property
    def mass(self) -> float:
        """Total mass of shafts and disks (kg)."""
        return sum(e.mass for s in self.spools for e in s.elements) + sum(d.m for d in self.disks)

    # --- derived models -------------------------------------------------------------
    def refined(self, n: int) -> Rotor:
        """Return a copy with every shaft element split into ``n`` equal elements.

        The original nodes keep their numbers; new nodes are numbered from
        ``max(nodes) + 1`` on, element by element along each spool.
        """
        if not isinstance(n, int) or isinstance(n, bool) or n < 1:
            raise ValueError(f"`n` must be an integer >= 1, got {n!r}")
        if n == 1:
            return self
        next_node = max(self.nodes) + 1
        spools = []
        for s in self.spools:
            elements = []
            for e in s.elements:
                new = list(range(next_node, next_node + n - 1))
                next_node += n - 1
                elements.extend(e.split(n, new))
            spools.append(dataclasses.replace(s, elements=tuple(elements)))
        return dataclasses.replace(self, spools=tuple(spools), name=f"{self.name} refined({n})")

    def with_speeds(self, speeds: Mapping[str, float]) -> Rotor:
        """Return a copy whose spools have the nominal speeds ``speeds`` (rad/s)."""
        unknown = set(speeds) - {s.name for s in self.spools}
        if unknown:
            raise ValueError(f"unknown spool(s) {sorted(unknown)}; spools are {[s.name for s in self.spools]}")
        spools = tuple(dataclasses.replace(s, speed=float(speeds.get(s.name, s.speed))) for s in self.spools)
        return dataclasses.replace(self, spools=spools)

    def without_intershaft_bearings(self) -> Rotor:
        """Return a copy with no inter-shaft bearing."""
        return dataclasses.replace(self, intershaft_bearings=())

    def only_spool(self, name: str) -> Rotor:
        """Return the spool ``name`` alone, with its disks and ground bearings."""
        s = self.spool(name)
        nodes = set(s.nodes)
        return dataclasses.replace(
            self, spools=(s,), disks=tuple(d for d in self.disks if d.node in nodes),
            bearings=tuple(b for b in self.bearings if b.node in nodes), intershaft_bearings=(),
            name=f"{self.name} [{name}]")


def _ranges(nodes: list[int]) -> str:
    """'1-13, 14-20' for a sorted list of node numbers."""
    if not nodes:
        return "none"
    out, start, prev = [], nodes[0], nodes[0]
    for n in nodes[1:] + [None]:
        if n is not None and n == prev + 1:
            prev = n
            continue
        out.append(f"{start}" if start == prev else f"{start}-{prev}")
        if n is not None:
            start = prev = n
    return ", ".join(out)
