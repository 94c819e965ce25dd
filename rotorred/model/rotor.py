"""The rotor model: spools of shaft elements, disks, bearings and inter-shaft bearings.

A :class:`Rotor` holds one or more :class:`Spool` s. Each spool is a chain of shaft
elements on user-visible node numbers and spins at its own speed; the gyroscopic term of
the assembled system is ``sum_s Omega_s G_s`` (Xu et al. 2016, Eq. 13, with one G per spool).
A rotor also carries its :class:`AnalysisDefaults` (a rotor file's ``[defaults]`` table): the
unbalances, output DOFs and extra reduction boundary nodes an analysis uses when none are given.

Validation (:mod:`rotorred.checks`) names attributes (``disks[0].node``); the rotor-file loader
renames them to the file's keys (``disk[0].node``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

from rotorred import checks
from rotorred.model.dofs import checked_dof
from rotorred.model.elements import (Bearing, BearingTable, Disk, IntershaftBearing, IntershaftBearingTable, Pedestal,
                                     ShaftElement, Support)
from rotorred.model.loads import Unbalance
from rotorred.model.rotor_writer import rotor_table
from rotorred.results import Result
from rotorred.writers import write_toml


@dataclass(frozen=True)
class AnalysisDefaults:
    """What an analysis of a rotor uses when the user gives nothing else (a rotor file's ``[defaults]``).

    Parameters
    ----------
    unbalances : tuple of Unbalance
        Default unbalances (e.g. of ``rotorred harmonic``).
    outputs : tuple of (int, str)
        Default response DOFs (node, direction).
    boundary_nodes : tuple of int
        Extra boundary nodes of a Craig-Bampton reduced model (e.g. the rub node).
    operating_ranges : tuple of (str, float, float)
        (spool, minimum speed, maximum continuous speed) (rad/s): the operating range of a spool, which the API 617
        separation margins of its critical speeds are measured from (``rotorred campbell``, docs/model.md §21).

    All are empty by default; :class:`Rotor` checks that their nodes and spools exist.
    """

    unbalances: tuple[Unbalance, ...] = ()
    outputs: tuple[tuple[int, str], ...] = ()
    boundary_nodes: tuple[int, ...] = ()
    operating_ranges: tuple[tuple[str, float, float], ...] = ()

    def __post_init__(self):
        unbalances = checks.sequence("unbalances", _tuple(self.unbalances), _unbalance)
        outputs = checks.sequence("outputs", _tuple(self.outputs), checked_dof, unique=True)
        boundary = checks.sequence("boundary_nodes", _tuple(self.boundary_nodes), _node_number, unique=True)
        ranges = checks.sequence("operating_ranges", _tuple(self.operating_ranges), _operating_range)
        object.__setattr__(self, "unbalances", unbalances)
        object.__setattr__(self, "outputs", outputs)
        object.__setattr__(self, "boundary_nodes", boundary)
        object.__setattr__(self, "operating_ranges", ranges)
        if len({r[0] for r in ranges}) < len(ranges):
            checks.fail("operating_ranges", ranges, "must give each spool's range once")

    def operating_range(self, spool: str) -> tuple[float, float] | None:
        """(minimum, maximum continuous) speed of ``spool`` (rad/s), or None if not given.

        Parameters
        ----------
        spool : str
            A spool's name.
        """
        return next(((lo, hi) for s, lo, hi in self.operating_ranges if s == spool), None)

    def check_spools(self, spools: Collection[str]) -> None:
        """InputError naming the entry if an operating range's spool is not one of ``spools``."""
        for i, (s, _, _) in enumerate(self.operating_ranges):
            checks.choice(f"operating_ranges[{i}].spool", s, sorted(spools))

    def check_nodes(self, nodes: Collection[int]) -> None:
        """InputError naming the entry if a node is not one of ``nodes``."""
        for i, u in enumerate(self.unbalances):
            checks.node(f"unbalances[{i}].node", u.node, nodes)
        for i, o in enumerate(self.outputs):
            checked_dof(f"outputs[{i}]", o, nodes)
        for i, n in enumerate(self.boundary_nodes):
            checks.node(f"boundary_nodes[{i}]", n, nodes)

    def restricted(self, nodes: Collection[int], spools: Collection[str] = ()) -> AnalysisDefaults:
        """The defaults whose nodes are among ``nodes`` and operating ranges of ``spools`` (e.g. of one spool)."""
        return AnalysisDefaults(tuple(u for u in self.unbalances if u.node in nodes),
                                tuple(o for o in self.outputs if o[0] in nodes),
                                tuple(n for n in self.boundary_nodes if n in nodes),
                                tuple(r for r in self.operating_ranges if r[0] in spools))


def _tuple(value):
    """``tuple(value)`` for a list, generator or other non-string iterable; anything else as is (for the check)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return value
    return tuple(value)


def _unbalance(field_: str, value) -> Unbalance:
    if not isinstance(value, Unbalance):
        checks.fail(field_, value, "must be an Unbalance")
    return value


def _node_number(field_: str, value) -> int:
    return checks.integer(field_, value, ge=0)


def _operating_range(field_: str, value) -> tuple[str, float, float]:
    """(spool, minimum, maximum) with 0 <= minimum <= maximum (rad/s)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 3:
        checks.fail(field_, value, "must be (spool, minimum, maximum continuous speed) (rad/s)")
    lo = checks.non_negative(f"{field_}.minimum", value[1], "rad/s")
    return (checks.string(f"{field_}.spool", value[0], empty=False), lo,
            checks.number(f"{field_}.maximum", value[2], "rad/s", ge=lo))


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
    sleeves : tuple of ShaftElement, optional
        Concentric elements over spans of the chain (a sleeve shrunk on the shaft, ROSS's layered
        elements): each joins the two nodes of an element of the chain, has its length, and adds its
        matrices to that element's (the two act in parallel). They add no node.
    internal_damping_beta : float
        Internal (rotating) viscous damping of its elements (s), >= 0: ``beta K`` in the frame turning with the
        spool (docs/model.md §19); an element's own value overrides it. Default 0.
    internal_loss_factor : float
        Internal hysteretic damping of its elements, loss factor (-), >= 0; an element's own value overrides it.
        Default 0.
    """

    name: str
    elements: tuple[ShaftElement, ...]
    speed: float = 0.0
    z0: float = 0.0
    sleeves: tuple[ShaftElement, ...] = ()
    internal_damping_beta: float = 0.0
    internal_loss_factor: float = 0.0

    def __post_init__(self):
        checks.string("name", self.name, empty=False)
        elements = checks.sequence("elements", _tuple(self.elements), _shaft_element, min_len=1)
        object.__setattr__(self, "elements", elements)
        for i, (a, b) in enumerate(zip(elements[:-1], elements[1:])):
            if a.right != b.left:
                checks.fail(f"elements[{i + 1}].left", b.left,
                            f"must be {a.right}, the right node of elements[{i}]: the elements form a chain")
        seen = {elements[0].left}
        for i, e in enumerate(elements):
            if e.right in seen:
                checks.fail(f"elements[{i}].right", e.right, "must not repeat a node of the chain")
            seen.add(e.right)
        object.__setattr__(self, "speed", checks.non_negative("speed", self.speed, "rad/s"))
        object.__setattr__(self, "z0", checks.number("z0", self.z0, "m"))
        object.__setattr__(self, "sleeves", checks.sequence("sleeves", _tuple(self.sleeves), _shaft_element))
        self._check_sleeves()
        for key, unit in (("internal_damping_beta", "s"), ("internal_loss_factor", "-")):
            object.__setattr__(self, key, checks.non_negative(key, getattr(self, key), unit))

    def internal_damping(self, element: ShaftElement) -> tuple[float, float]:
        """The internal damping of one of its elements: the element's own values, else the spool's.

        Parameters
        ----------
        element : ShaftElement
            An element (or sleeve) of the spool.

        Returns
        -------
        (float, float)
            beta (s) and the loss factor eta (-).
        """
        beta, eta = element.internal_damping_beta, element.internal_loss_factor
        return (self.internal_damping_beta if beta is None else beta,
                self.internal_loss_factor if eta is None else eta)

    def _check_sleeves(self) -> None:
        """Each sleeve lies on an element of the chain: the same two nodes and the same length."""
        spans = {(e.left, e.right): e for e in self.elements}
        for i, sleeve in enumerate(self.sleeves):
            under = spans.get((sleeve.left, sleeve.right))
            if under is None:
                checks.fail(f"sleeves[{i}].left", sleeve.left, f"must be the left node of an element of the chain, "
                            f"with right = {sleeve.right} its right node: a sleeve lies on one element")
            if abs(sleeve.L - under.L) > 1e-9 * under.L:
                checks.fail(f"sleeves[{i}].L", sleeve.L, f"must equal the length {under.L!r} of the element "
                            f"{sleeve.left}-{sleeve.right} it lies on", "m")

    @property
    def all_elements(self) -> tuple[ShaftElement, ...]:
        """The chain's elements and the sleeves on them: every element the assembly adds."""
        return self.elements + self.sleeves

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

    def summary(self) -> list[str]:
        """Its name, nodes, elements, length and nominal speed: two lines, no arrays (``repr``)."""
        sleeves = f" (+ {len(self.sleeves)} sleeves)" if self.sleeves else ""
        length = sum(e.L for e in self.elements)
        return [f"{self.name!r}: nodes {node_ranges(self.nodes)}; {len(self.elements)} elements{sleeves}; "
                f"{length:.4g} m from z0 = {self.z0:.4g} m",
                f"nominal speed {speed_text(self.speed)}"]

    __repr__ = Result.__repr__


def speed_text(Omega: float) -> str:
    """A spool speed for people: ``"4200 rpm (439.8 rad/s)"`` of ``Omega`` (rad/s)."""
    return f"{Omega * 30.0 / math.pi:.6g} rpm ({Omega:.6g} rad/s)"


def plural(n: int, noun: str) -> str:
    """``"1 disk"``, ``"3 disks"``: a count for people."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def node_ranges(nodes, width: int = 48) -> str:
    """Node numbers as runs (``"1-13, 21-44"``, :func:`rotorred.checks.ranges_text`), cut to ``width`` characters."""
    text = checks.ranges_text(nodes)
    return text if len(text) <= width else text[:width - 4].rsplit(", ", 1)[0] + ", ..."


@dataclass(frozen=True)
class Rotor:
    """A (multi-spool) rotor.

    Parameters
    ----------
    spools : tuple of Spool
    disks : tuple of Disk
    bearings : tuple of Bearing or BearingTable
        Node-to-ground bearings; a :class:`BearingTable`'s coefficients follow the speed of its node's spool.
    intershaft_bearings : tuple of IntershaftBearing or IntershaftBearingTable
        Bearings between nodes of two different spools; an :class:`IntershaftBearingTable`'s coefficients follow the
        speed of its ``speed_of`` spool.
    rayleigh : tuple of float, optional
        (alpha (1/s), beta (s)) of the shafts' Rayleigh damping C = alpha M_shaft + beta K_shaft;
        disks and bearings are not included.
    name : str
    defaults : AnalysisDefaults
        Default unbalances, outputs and extra boundary nodes of analyses (empty by default);
        kept by :meth:`refined`, :meth:`with_speeds` and the other copies.
    supports : tuple of Support
        Pinned or clamped nodes (at most one support a node): their fixed DOFs are not DOFs of the model.
    pedestals : tuple of Pedestal
        Off-shaft nodes (x, y) with mass, numbered apart from the spools' nodes; bearings at them hold them to
        ground, bearings with ``link`` join a shaft node to them.
    """

    spools: tuple[Spool, ...]
    disks: tuple[Disk, ...] = ()
    bearings: tuple[Bearing | BearingTable, ...] = ()
    intershaft_bearings: tuple[IntershaftBearing | IntershaftBearingTable, ...] = ()
    rayleigh: tuple[float, float] = (0.0, 0.0)
    name: str = ""
    defaults: AnalysisDefaults = field(default_factory=AnalysisDefaults)
    supports: tuple[Support, ...] = ()
    pedestals: tuple[Pedestal, ...] = ()

    def __post_init__(self):
        for name, cls in (("spools", Spool), ("disks", Disk), ("bearings", (Bearing, BearingTable)),
                          ("intershaft_bearings", (IntershaftBearing, IntershaftBearingTable)), ("supports", Support),
                          ("pedestals", Pedestal)):
            object.__setattr__(self, name, checks.sequence(name, _tuple(getattr(self, name)), _instance(cls)))
        if not self.spools:
            checks.fail("spools", self.spools, "must hold at least one spool")
        rayleigh = checks.sequence("rayleigh", _tuple(self.rayleigh), min_len=2, max_len=2)
        object.__setattr__(self, "rayleigh", (checks.non_negative("rayleigh[0]", rayleigh[0], "1/s"),
                                              checks.non_negative("rayleigh[1]", rayleigh[1], "s")))
        checks.string("name", self.name)
        if not isinstance(self.defaults, AnalysisDefaults):
            checks.fail("defaults", self.defaults, "must be an AnalysisDefaults")
        self._check_topology()

    def _check_topology(self) -> None:
        """Spool names unique, no node on two spools, every referenced node exists."""
        owner = self._spool_owners()
        for i, d in enumerate(self.disks):
            checks.node(f"disks[{i}].node", d.node, owner)
        pedestals = self._checked_pedestals(owner)
        for i, b in enumerate(self.bearings):
            checks.node(f"bearings[{i}].node", b.node, set(owner) | set(pedestals))
            if b.link is not None and b.link not in pedestals:
                checks.fail(f"bearings[{i}].link", b.link, f"must be a pedestal node ({checks.ranges_text(pedestals)})"
                            if pedestals else "must be a pedestal node; the rotor has no [[pedestal]]")
            if isinstance(b, BearingTable) and b.node in pedestals:
                checks.fail(f"bearings[{i}].node", b.node, "must be a shaft node for a bearing tabulated against "
                            "speed (its spool's speed); node {} is a pedestal".format(b.node))
            if b.node in pedestals and b.tilts:
                checks.fail(f"bearings[{i}].node", b.node, "must be a shaft node for a bearing with tilt coefficients; "
                            f"node {b.node} is a pedestal, which has no rotations (x and y only)")
        self._check_supports(owner)
        for i, b in enumerate(self.intershaft_bearings):
            checks.node(f"intershaft_bearings[{i}].node_a", b.node_a, owner)
            checks.node(f"intershaft_bearings[{i}].node_b", b.node_b, owner)
            if owner[b.node_a] == owner[b.node_b]:
                checks.fail(f"intershaft_bearings[{i}].node_b", b.node_b,
                            f"must be on another spool than node_a = {b.node_a} (both are on spool "
                            f"{owner[b.node_a]!r}); an inter-shaft bearing joins two different spools")
            if getattr(b, "speed_of", None) is not None and b.speed_of not in owner.values():
                checks.fail(f"intershaft_bearings[{i}].speed_of", b.speed_of, "must name a spool of the rotor ("
                            f"{', '.join(repr(s.name) for s in self.spools)})")
        try:
            self.defaults.check_nodes(owner)
            self.defaults.check_spools(set(owner.values()))
        except checks.InputError as exc:
            raise exc.within("defaults") from None

    def _spool_owners(self) -> dict[int, str]:
        """The spool of each shaft node; spool names unique, no node on two spools."""
        owner: dict[int, str] = {}
        for i, s in enumerate(self.spools):
            if s.name in [t.name for t in self.spools[:i]]:
                checks.fail(f"spools[{i}].name", s.name, "must differ from the names of the other spools")
            for n in s.nodes:
                if n in owner:
                    checks.fail(f"spools[{i}].nodes", s.nodes, f"must not include node {n}, which belongs to "
                                f"spool {owner[n]!r}")
                owner[n] = s.name
        return owner

    def _checked_pedestals(self, owner: dict[int, str]) -> set[int]:
        """The pedestal nodes: each on no spool and not given twice."""
        pedestals: set[int] = set()
        for i, p in enumerate(self.pedestals):
            if p.node in owner:
                checks.fail(f"pedestals[{i}].node", p.node, f"must be a node of no spool (node {p.node} is on spool "
                            f"{owner[p.node]!r}); a pedestal is an off-shaft node")
            if p.node in pedestals:
                checks.fail(f"pedestals[{i}].node", p.node, "must not be given twice")
            pedestals.add(p.node)
        return pedestals

    def _check_supports(self, owner: dict[int, str]) -> None:
        """Supports on shaft nodes, one a node, and no bearing at a supported node."""
        supported: dict[int, str] = {}
        for i, sp in enumerate(self.supports):
            checks.node(f"supports[{i}].node", sp.node, owner)
            if sp.node in supported:
                checks.fail(f"supports[{i}].node", sp.node, f"must not carry a second support (node {sp.node} is "
                            f"already {supported[sp.node]})")
            supported[sp.node] = sp.kind
        for i, b in enumerate(self.bearings):
            if b.node in supported:
                checks.fail(f"bearings[{i}].node", b.node, f"must not be a {supported[b.node]} node: the support fixes "
                            "its x and y, so a bearing there would carry no motion")

    # --- topology -----------------------------------------------------------------
    @property
    def nodes(self) -> tuple[int, ...]:
        """The shaft nodes in DOF order: spool by spool, axially."""
        return tuple(n for s in self.spools for n in s.nodes)

    @property
    def all_nodes(self) -> tuple[int, ...]:
        """Every node in DOF order: the shaft nodes (:attr:`nodes`), then the pedestal nodes."""
        return self.nodes + tuple(p.node for p in self.pedestals)

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
        """The spool called ``name``.

        Parameters
        ----------
        name : str
            Name of a spool of the rotor.

        Raises
        ------
        InputError
            If no spool is called ``name``.
        """
        checks.choice("spool", name, [s.name for s in self.spools])
        return next(s for s in self.spools if s.name == name)

    def disk_at(self, node: int) -> Disk:
        """The disk at ``node``.

        Parameters
        ----------
        node : int
            A node that carries a disk.

        Raises
        ------
        InputError
            If no disk is at ``node``.
        """
        for d in self.disks:
            if d.node == node:
                return d
        checks.fail("node", node, f"must carry a disk; disks are at nodes {[d.node for d in self.disks]}")

    @property
    def mass(self) -> float:
        """Total mass of shafts and disks (kg)."""
        return sum(e.mass for s in self.spools for e in s.all_elements) + sum(d.m for d in self.disks)

    # --- showing and writing ---------------------------------------------------------
    def summary(self) -> list[str]:
        """Name, spools (nodes, nominal speeds), counts of elements, disks and bearings, damping and defaults: at
        most 13 lines, no arrays (``repr``)."""
        elements = sum(len(s.elements) for s in self.spools)
        lines = [f"{self.name!r}: {plural(len(self.spools), 'spool')}, {len(self.nodes)} shaft nodes, {elements} shaft "
                 f"elements, mass {self.mass:.4g} kg"]
        spools = [f"spool {s.name!r}: nodes {node_ranges(s.nodes)}; {len(s.elements)} elements; {speed_text(s.speed)}"
                  for s in self.spools]
        lines += spools if len(spools) <= 6 else spools[:5] + [f"... and {len(spools) - 5} more spools"]
        tables = sum(isinstance(b, BearingTable) for b in self.bearings)
        lines.append(f"{plural(len(self.disks), 'disk')}, {plural(len(self.bearings), 'bearing')} ({tables} tabulated "
                     f"against speed), {plural(len(self.intershaft_bearings), 'inter-shaft bearing')}")
        if self.supports or self.pedestals:
            lines.append(f"{plural(len(self.supports), 'support')} (pinned or clamped nodes), "
                         f"{plural(len(self.pedestals), 'pedestal')}")
        if self.rayleigh != (0.0, 0.0):
            lines.append(f"shaft damping: Rayleigh alpha {self.rayleigh[0]:.4g} 1/s, beta {self.rayleigh[1]:.4g} s")
        internal = [s.name for s in self.spools if any(any(s.internal_damping(e)) for e in s.all_elements)]
        if internal:
            lines.append(f"internal (rotating) damping on spool{'s' * (len(internal) > 1)} {', '.join(internal)}")
        d = self.defaults
        if d.unbalances or d.outputs or d.boundary_nodes:
            lines.append(f"defaults: {plural(len(d.unbalances), 'unbalance')}, {plural(len(d.outputs), 'output')}, "
                         "boundary nodes "
                         f"{node_ranges(d.boundary_nodes)}")
        return lines

    __repr__ = Result.__repr__

    # --- writing --------------------------------------------------------------------
    def to_toml(self, path: str | Path, header: str = "") -> Path:
        """Write the rotor as a rotor file, which :func:`rotorred.load_rotor` reads back to an equal rotor (every
        number to the bit; :func:`rotorred.model.rotor_writer.rotor_table` says how).

        Parameters
        ----------
        path : str or Path
            The file to write (.toml), replaced atomically.
        header : str, optional
            Text written on top as comment lines (``# ...``).

        Returns
        -------
        Path
            ``path``.
        """
        return write_toml(path, rotor_table(self), header)

    # --- derived models -------------------------------------------------------------
    def refined(self, n: int) -> Rotor:
        """Return a copy with every shaft element split into ``n`` equal elements.

        The original nodes keep their numbers; new nodes are numbered from
        ``max(nodes) + 1`` on, element by element along each spool.

        Parameters
        ----------
        n : int
            Number of elements each shaft element (and sleeve) becomes, >= 1; 1 returns the rotor itself.

        Raises
        ------
        InputError
            If ``n`` < 1.
        """
        n = checks.integer("n", n, ge=1)
        if n == 1:
            return self
        next_node = max(self.all_nodes) + 1
        spools = []
        for s in self.spools:
            elements, new_nodes = [], {}
            for e in s.elements:
                new = new_nodes[e.left, e.right] = list(range(next_node, next_node + n - 1))
                next_node += n - 1
                elements.extend(e.split(n, new))
            sleeves = [part for e in s.sleeves for part in e.split(n, new_nodes[e.left, e.right])]
            spools.append(dataclasses.replace(s, elements=tuple(elements), sleeves=tuple(sleeves)))
        return dataclasses.replace(self, spools=tuple(spools), name=f"{self.name} refined({n})")

    def with_speeds(self, speeds: Mapping[str, float]) -> Rotor:
        """Return a copy whose spools have the nominal speeds ``speeds`` (rad/s).

        Parameters
        ----------
        speeds : dict of str to float
            Nominal speed of each spool given (rad/s); a spool left out keeps its speed.

        Raises
        ------
        InputError
            If ``speeds`` names a spool the rotor does not have.
        """
        checks.keys("speeds", speeds, [s.name for s in self.spools])
        spools = tuple(dataclasses.replace(s, speed=float(speeds.get(s.name, s.speed))) for s in self.spools)
        return dataclasses.replace(self, spools=spools)

    def without_intershaft_bearings(self) -> Rotor:
        """Return a copy with no inter-shaft bearing."""
        return dataclasses.replace(self, intershaft_bearings=())

    def only_spool(self, name: str) -> Rotor:
        """Return the spool ``name`` alone, with its disks and ground bearings.

        Its supports, and the pedestals its bearings stand on, stay; inter-shaft bearings go.

        Parameters
        ----------
        name : str
            Name of a spool of the rotor.

        Raises
        ------
        InputError
            If no spool is called ``name``.
        """
        s = self.spool(name)
        nodes = set(s.nodes)
        linked = {b.link for b in self.bearings if b.node in nodes and b.link is not None}  # its pedestals
        return dataclasses.replace(
            self, spools=(s,), disks=tuple(d for d in self.disks if d.node in nodes),
            bearings=tuple(b for b in self.bearings if b.node in nodes or b.node in linked), intershaft_bearings=(),
            supports=tuple(sp for sp in self.supports if sp.node in nodes),
            pedestals=tuple(p for p in self.pedestals if p.node in linked),
            name=f"{self.name} [{name}]", defaults=self.defaults.restricted(nodes, {name}))



def _instance(cls):
    """Item check of :func:`rotorred.checks.sequence`: an instance of ``cls`` (a class or a tuple of classes)."""
    names = " or ".join(c.__name__ for c in (cls if isinstance(cls, tuple) else (cls,)))

    def check(field_: str, value):
        if not isinstance(value, cls):
            checks.fail(field_, value, f"must be a {names}")
        return value
    return check


def _shaft_element(field_: str, value) -> ShaftElement:
    return _instance(ShaftElement)(field_, value)
