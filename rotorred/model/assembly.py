"""Assembly of the global matrices M, K, C and one gyroscopic matrix per spool.

The equation of motion (Xu et al. 2016, Eq. 13, with two spools) is

    M q'' + (C + sum_s Omega_s G_s) q' + (K + sum_s Omega_s' K_G,s) q = F(t) + F_L,

where ``M = M_T + M_R`` (translational and rotary), ``K`` includes bearing stiffness,
``C`` bearing and (optional) Rayleigh shaft damping, ``G_s`` collects the shaft and disk
gyroscopic matrices of spool ``s`` per unit spin speed (1 rad/s), and ``K_G,s`` their
spin-acceleration matrices per unit angular acceleration (1 rad/s^2; zero at constant speed,
docs/model.md, Eq. R2). A spool's internal (rotating) damping adds ``C_r,s`` to the damping and
``-Omega_s N_s`` to the stiffness (:class:`RotatingDamping`, docs/model.md §19).

Matrices are built from COO triplets in one pass: dense ndarrays for a model of fewer than
:data:`rotorred.model.sparse.SPARSE_FROM` DOFs, ``scipy.sparse`` CSR matrices from that size on (a beam model's
matrices are banded); analyses with a sparse path solve a model of :data:`rotorred.model.sparse.SOLVE_SPARSE_FROM`
DOFs or more through its sparse twin (:func:`system_of`; docs/model.md §24).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np
from scipy.linalg import eigh
from scipy.sparse import coo_array

from rotorred.model import sparse

from rotorred import checks
from rotorred.model.dofs import DIRECTIONS, DofMap  # noqa: F401 - DofMap, DIRECTIONS re-exported here
from rotorred.model.elements import Bearing, BearingTable, IntershaftBearingTable
from rotorred.model.rotor import Rotor, node_ranges, plural, speed_text
from rotorred.results import Result

__all__ = ["SystemMatrices", "SpoolSpeedMixin", "TabulatedSupport", "RotatingDamping", "assemble", "system_of",
           "DofMap", "DIRECTIONS"]


@dataclass(frozen=True)
class TabulatedSupport:
    """A bearing whose coefficients depend on speed (:class:`~rotorred.model.elements.BearingTable`,
    :class:`~rotorred.model.elements.IntershaftBearingTable`), in a model.

    Attributes
    ----------
    table : BearingTable or IntershaftBearingTable
    spool : str
        The spool whose speed the table follows (the spool of the bearing's node; an inter-shaft table's ``speed_of``).
    rows : ndarray, shape (4, n)
        The bearing's deflection (x, y, theta_x, theta_y) as rows on the model's coordinates (:func:`_deflection_rows`).
    nominal : Bearing or IntershaftBearing
        The coefficients the model's ``K`` and ``C`` hold: the table at the rotor's speed of ``spool``.
    """

    table: BearingTable | IntershaftBearingTable
    spool: str
    rows: np.ndarray
    nominal: Bearing

    def on(self, T: np.ndarray) -> TabulatedSupport:
        """The same bearing in the coordinates ``p`` of ``q = T p`` (a reduced model; a column selection for
        supports)."""
        return dataclasses.replace(self, rows=self.rows @ T)

    def change(self, speeds: Mapping[str, float], matrix: str) -> np.ndarray:
        """The bearing's ``matrix`` (``"K"``: stiffness, ``"C"``: damping) at ``speeds`` (rad/s; a spool left out stands
        still, as in ``gyroscopic``) minus the nominal one, on the model's coordinates, shape (n, n)."""
        b = self.table.at(speeds.get(self.spool, 0.0))
        delta = b.block(matrix) - self.nominal.block(matrix)
        if sparse.is_sparse(self.rows):
            return (self.rows.T @ coo_array(delta) @ self.rows).tocsr()
        return self.rows.T @ delta @ self.rows


@dataclass(frozen=True)
class RotatingDamping:
    """A spool's internal (rotating) damping in a model (docs/model.md §19).

    In the frame turning with the spool its shaft elements are damped by ``sum_e (beta_e + eta_e / |omega|) K_e``;
    in the fixed frame that is the damping ``C(omega)`` and, at spool speed ``Omega``, the circulatory stiffness
    ``-Omega N(omega)`` (skew), with (derivations/internal_damping.py, ``J_e`` the element's rotation generator)

        C(omega) = C_v + C_h / |omega|,   N(omega) = N_v + N_h / |omega|.

    Attributes
    ----------
    C_v : ndarray, shape (n, n)
        ``sum_e beta_e K_e``, viscous (N s/m).
    N_v : ndarray, shape (n, n)
        ``sum_e beta_e K_e J_e`` (N s/m).
    C_h : ndarray, shape (n, n)
        ``sum_e eta_e K_e``, hysteretic (N/m).
    N_h : ndarray, shape (n, n)
        ``sum_e eta_e K_e J_e`` (N/m).
    """

    C_v: np.ndarray
    N_v: np.ndarray
    C_h: np.ndarray
    N_h: np.ndarray

    def on(self, T: np.ndarray) -> RotatingDamping:
        """The same damping in the coordinates ``p`` of ``q = T p`` (``T^T X T``; a column selection for supports)."""
        return RotatingDamping(*(T.T @ (X @ T) if sparse.is_sparse(X) else T.T @ X @ T
                                 for X in (self.C_v, self.N_v, self.C_h, self.N_h)))

    def at(self, frequency: float) -> tuple[np.ndarray, np.ndarray]:
        """(C, N) of the viscous damping equivalent at whirl frequency ``frequency`` (rad/s, > 0 where a loss factor
        is given): ``beta + eta / |frequency|`` for each element."""
        if not sparse.nonzero(self.C_h):
            return self.C_v, self.N_v
        w = abs(frequency)
        return self.C_v + self.C_h / w, self.N_v + self.N_h / w


class SpoolSpeedMixin:
    """The model protocol every analysis reads: ``spools``, ``nominal_speeds``, ``spool_of``, ``name``,
    ``gyroscopic(speeds)``, ``stiffness(speeds)`` and ``damping(speeds)`` of a model with attributes ``M``, ``K``,
    ``C``, ``G`` (dict spool -> gyroscopic matrix per unit speed), ``tables`` (its :class:`TabulatedSupport` s) and
    ``rotor`` (the rotor it was built from, or None); shared by the full :class:`SystemMatrices` and the reduced
    model (:class:`rotorred.linear.reduction.ReducedSystem`). :func:`system_of` turns a rotor into one."""

    @property
    def spools(self) -> tuple[str, ...]:
        """Spool names, in the order of ``G``."""
        return tuple(self.G)

    @property
    def name(self) -> str:
        """The rotor's name ("" for a model built by hand)."""
        return self.rotor.name if self.rotor is not None else ""

    @property
    def nominal_speeds(self) -> dict[str, float]:
        """The rotor's nominal spool speeds (rad/s); empty for a model built by hand."""
        return dict(self.rotor.speeds) if self.rotor is not None else {}

    @property
    def spool_of(self) -> dict[int, str]:
        """Spool of each node: the rotor's, or every node on the one spool of a single-spool model built by hand
        (empty for a model of several spools built by hand)."""
        if self.rotor is not None:
            return self.rotor.spool_of
        return {n: self.spools[0] for n in self.full_dofs.nodes} if len(self.spools) == 1 else {}

    def gyroscopic(self, speeds: Mapping[str, float]) -> np.ndarray:
        """``sum_s Omega_s G_s`` for spool speeds ``speeds`` (rad/s), shape (n, n)."""
        checks.keys("speeds", speeds, self.G)
        out = sparse.zeros_like(self.M)
        for name, Omega in speeds.items():
            if Omega:
                out += Omega * self.G[name]
        return out

    def damping(self, speeds: Mapping[str, float], frequency: float | None = None) -> np.ndarray:
        """``C(Omega) + sum_s Omega_s G_s`` (N s/m), shape (n, n), at spool speeds ``speeds`` (rad/s) (a loss factor
        at whirl ``frequency``, rad/s: :meth:`rotating_damping`)."""
        return self.dissipation(speeds, frequency) + self.gyroscopic(speeds)

    def dissipation(self, speeds: Mapping[str, float], frequency: float | None = None) -> np.ndarray:
        """``C(Omega)`` (N s/m), shape (n, n): ``C`` with the speed-dependent bearings' damping at ``speeds`` (rad/s)
        and the internal damping (:meth:`rotating_damping`, at whirl ``frequency``), without the gyroscopic terms
        (which do no work)."""
        if not self.tables and not self.rotating:
            return self.C
        out = self.C + self.rotating_damping(speeds, frequency)[0]
        for t in self.tables:
            out += t.change(speeds, "C")
        return out

    def stiffness(self, speeds: Mapping[str, float], frequency: float | None = None) -> np.ndarray:
        """``K(Omega)`` (N/m), shape (n, n): ``K`` with the speed-dependent bearings' stiffness at ``speeds`` (rad/s)
        and the circulatory stiffness of internal damping (:meth:`rotating_damping`, at whirl ``frequency``)."""
        if not self.tables and not self.rotating:
            return self.K
        checks.keys("speeds", speeds, self.G)
        out = self.K + self.rotating_damping(speeds, frequency)[1]
        for t in self.tables:
            out += t.change(speeds, "K")
        return out

    def rotating_damping(self, speeds: Mapping[str, float],
                         frequency: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The internal (rotating) damping in the fixed frame (docs/model.md §19): the damping ``sum_s C_s`` (N s/m)
        and the circulatory stiffness ``-sum_s Omega_s N_s`` (N/m, skew), shape (n, n) each, at spool speeds
        ``speeds`` (rad/s; a spool left out stands still). A loss factor eta enters as the viscous ``eta / |omega|``
        at the whirl ``frequency`` omega (rad/s); None: at :attr:`loss_frequency`."""
        C, N = sparse.zeros_like(self.M), sparse.zeros_like(self.M)
        w = self.loss_frequency if frequency is None else frequency
        for s, r in self.rotating.items():
            C_s, N_s = r.at(w)
            C += C_s
            N -= speeds.get(s, 0.0) * N_s
        return C, N

    @property
    def frequency_dependent(self) -> bool:
        """Whether the model's damping and stiffness depend on the whirl frequency: an internal loss factor (taken at
        the excitation frequency in a harmonic response, docs/model.md §19)."""
        return any(sparse.nonzero(r.C_h) for r in self.rotating.values())

    @property
    def speed_dependent(self) -> bool:
        """Whether the model's stiffness or damping depends on the speeds beyond the gyroscopic terms."""
        return bool(self.tables) or bool(self.rotating)


@dataclass(frozen=True)
class SystemMatrices(SpoolSpeedMixin):
    """Global matrices of a rotor.

    Attributes
    ----------
    M : ndarray, shape (n, n)
        Mass (translational + rotary), symmetric positive definite (kg; kg m^2 on rotations).
    K : ndarray, shape (n, n)
        Stiffness of shafts, bearings and inter-shaft bearings (N/m; N m/rad on rotations).
    C : ndarray, shape (n, n)
        Damping of bearings, inter-shaft bearings and Rayleigh shaft damping (N s/m; N m s/rad on rotations).
    G : dict of str to ndarray, shape (n, n)
        Skew-symmetric gyroscopic matrix of each spool per unit spin speed (1 rad/s; kg m^2): the
        model's damping at speeds ``Omega_s`` is ``C + sum_s Omega_s G_s``.
    dofs : DofMap
        The DOF numbering: node and direction of each coordinate.
    K_G : dict of str to ndarray, shape (n, n)
        Spin-acceleration matrix of each spool per unit angular acceleration (1 rad/s^2), ``A_s`` of
        ``G_s = A_s - A_s^T``; needed only when a spool's speed varies (empty for a model built by hand).
    tables : tuple of TabulatedSupport
        The bearings whose coefficients depend on speed; ``K`` and ``C`` hold them at the rotor's speeds,
        :meth:`stiffness` and :meth:`damping` at any speeds.
    supported_weight : ndarray, shape (n,), or None
        With supports: ``M e_y`` of the model before the fixed DOFs were removed (kg), e_y the unit rigid
        translation in y, on the remaining DOFs; gravity's consistent load is ``-g`` times it. None without supports.
    rotor : Rotor or None
        The rotor assembled (:func:`assemble`): its nominal speeds, spools and disks (:class:`SpoolSpeedMixin`);
        None for a model built by hand.
    rotating : dict of str to RotatingDamping
        Internal (rotating) damping of each spool that has some (empty: none); :meth:`dissipation` and
        :meth:`stiffness` hold it at given speeds (docs/model.md §19).
    loss_frequency : float
        Whirl frequency (rad/s) at which a loss factor is taken where an analysis has none of its own (Campbell,
        transients, harmonic balance): the model's first natural frequency at rest (docs/model.md §19); 0 without
        a loss factor.
    """

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    G: Mapping[str, np.ndarray]
    dofs: DofMap
    K_G: Mapping[str, np.ndarray] = field(default_factory=dict)
    tables: tuple[TabulatedSupport, ...] = ()
    supported_weight: np.ndarray | None = None
    rotor: Rotor | None = field(default=None, compare=False, repr=False)
    rotating: Mapping[str, RotatingDamping] = field(default_factory=dict)
    loss_frequency: float = 0.0

    @property
    def n_dof(self) -> int:
        """Number of coordinates ``n`` of the model."""
        return self.M.shape[0]

    @property
    def full_dofs(self) -> DofMap:
        """The physical DOF numbering (the model's own, here; a reduced model's full one)."""
        return self.dofs

    @property
    def is_sparse(self) -> bool:
        """Whether the matrices are ``scipy.sparse`` CSR arrays (a model of at least
        :data:`rotorred.model.sparse.SPARSE_FROM` DOFs) rather than dense ndarrays."""
        return sparse.is_sparse(self.M)

    def sparse(self) -> SystemMatrices:
        """The same model with CSR arrays (itself if it has them): for an analysis's sparse path. A model made by
        :func:`assemble` as it is gets its rotor's sparse assembly (equal to the bit to its own matrices, its
        ``loss_frequency`` kept: docs/model.md §24), any other model its matrices converted."""
        if self.is_sparse:
            return self
        if self.__dict__.get(_AS_ASSEMBLED) and self.rotor is not None:
            if "_twin" not in self.__dict__:  # made once, kept (an attribute, not a field: replace() drops it)
                twin = dataclasses.replace(_assembled(self.rotor, True), loss_frequency=self.loss_frequency)
                object.__setattr__(twin, _AS_ASSEMBLED, True)
                object.__setattr__(self, "_twin", twin)
            return self.__dict__["_twin"]
        c = sparse.csr
        return dataclasses.replace(
            self, M=c(self.M), K=c(self.K), C=c(self.C), G={k: c(v) for k, v in self.G.items()},
            K_G={k: c(v) for k, v in self.K_G.items()}, tables=tuple(dataclasses.replace(t, rows=c(t.rows))
                                                                     for t in self.tables),
            rotating={k: RotatingDamping(*(c(X) for X in (r.C_v, r.N_v, r.C_h, r.N_h))) for k, r in self.rotating.items()})

    def dense(self) -> SystemMatrices:
        """The same model with dense ndarrays (itself if it has them): for an analysis that has no sparse path."""
        if not self.is_sparse:
            return self
        d = sparse.dense
        return dataclasses.replace(
            self, M=d(self.M), K=d(self.K), C=d(self.C), G={k: d(v) for k, v in self.G.items()},
            K_G={k: d(v) for k, v in self.K_G.items()}, tables=tuple(dataclasses.replace(t, rows=d(t.rows))
                                                                     for t in self.tables),
            rotating={k: RotatingDamping(*(d(X) for X in (r.C_v, r.N_v, r.C_h, r.N_h))) for k, r in self.rotating.items()})

    def physical_index(self, node: int, direction: str) -> int:
        """Index of the physical DOF ``direction`` at ``node`` in this model's coordinates.

        Parameters
        ----------
        node : int
            A node of the model.
        direction : {"x", "y", "theta_x", "theta_y"}
            The DOF at the node (``"tx"``, ``"ty"`` also accepted; :data:`rotorred.model.dofs.DIRECTIONS`).

        Raises
        ------
        InputError
            If ``node`` is not a node of the model, ``direction`` is unknown or the DOF is fixed by a support.
        """
        return self.dofs.index(node, direction)

    def output_rows(self, outputs) -> np.ndarray:
        """Rows mapping model coordinates to physical DOFs.

        Parameters
        ----------
        outputs : sequence of (int, str)
            (node, direction) pairs.

        Returns
        -------
        ndarray, shape (len(outputs), n)
            ``rows @ q`` gives the physical displacements.
        """
        rows = np.zeros((len(outputs), self.n_dof))
        rows[np.arange(len(outputs)), self.output_index(outputs)] = 1.0
        return rows

    def output_index(self, outputs) -> np.ndarray:
        """The model coordinate of each physical DOF: ``q[index]`` are the displacements :meth:`output_rows` gives,
        with no row of n entries (a full model's outputs are its own coordinates).

        Parameters
        ----------
        outputs : sequence of (int, str)
            The physical DOFs, (node, direction) pairs as :meth:`output_rows` takes them.

        Returns
        -------
        ndarray of int, shape (len(outputs),)
            Indices into the model's coordinates.
        """
        return np.array([self.dofs.index(node, direction) for node, direction in outputs], dtype=int)

    def summary(self) -> list[str]:
        """Rotor, DOFs, spools and speed-dependent bearings: at most 9 lines, no arrays (``repr``)."""
        return model_summary(self)

    __repr__ = Result.__repr__


def model_summary(model) -> list[str]:
    """The lines of a model's ``repr`` (:class:`SystemMatrices` and the reduced model): its rotor and physical DOFs
    (three lines), its matrices, its spools' nominal speeds (at most 3 lines) and its bearing tables."""
    dofs = model.full_dofs
    shaft = [node for node in dofs.nodes if node not in dofs.translational]
    parts = [f"{plural(len(shaft), 'shaft node')} x 4"]
    parts += [f"{plural(len(dofs.translational), 'pedestal node')} x 2"] if dofs.translational else []
    parts += [f"less {len(dofs.fixed)} fixed by supports"] if dofs.fixed else []
    parts += [f"plus {dofs.n_internal} internal"] if dofs.n_internal else []
    of = f"rotor {model.name!r}" if model.rotor is not None else "a model built by hand"
    lines = [f"{dofs.n_dof} physical DOFs of {of}", ", ".join(parts), f"nodes {node_ranges(dofs.nodes, 80)}",
             f"M, K, C of shape ({model.n_dof}, {model.n_dof}); a G{' and a K_G' if model.K_G else ''} per spool"]
    speeds = [f"spool {s!r}, nominal {speed_text(w)}" for s, w in model.nominal_speeds.items()]
    lines += speeds if len(speeds) <= 3 else speeds[:2] + [f"... and {len(speeds) - 2} more spools"]
    if model.rotating:
        lines.append(f"internal (rotating) damping on spool{'s' * (len(model.rotating) > 1)} "
                     f"{', '.join(model.rotating)}")
    if model.tables:
        lines.append(f"{plural(len(model.tables), 'bearing')} tabulated against speed, at nodes "
                     f"{node_ranges(t.table.node for t in model.tables)}: K and C at the nominal speeds")
    return lines


class _Triplets:
    def __init__(self):
        self.rows: list[np.ndarray] = []
        self.cols: list[np.ndarray] = []
        self.vals: list[np.ndarray] = []

    def add(self, dofs: np.ndarray, block: np.ndarray):
        r, c = np.meshgrid(dofs, dofs, indexing="ij")
        self.rows.append(r.ravel())
        self.cols.append(c.ravel())
        self.vals.append(np.asarray(block, dtype=float).ravel())

    def matrix(self, n: int, as_sparse: bool):
        """The sum of the blocks, shape (n, n): a CSR array if ``as_sparse``, else a dense ndarray; the two equal to
        the bit: each entry summed in the order the blocks were added (``np.add.at``, as ``toarray`` sums), where
        ``tocsr`` would sum an entry's terms in the order of an unstable sort, and a round-off difference split a
        free spool's zero eigenvalues otherwise (its count of near-zero whirl frequencies, and with it the mode
        tracking, then differed: docs/model.md §24)."""
        if not self.vals:
            return coo_array((n, n)).tocsr() if as_sparse else np.zeros((n, n))
        rows, cols, vals = (np.concatenate(x) for x in (self.rows, self.cols, self.vals))
        if not as_sparse:
            return coo_array((vals, (rows, cols)), shape=(n, n)).toarray()
        keys, at = np.unique(rows.astype(np.int64) * n + cols, return_inverse=True)
        sums = np.zeros(len(keys))
        np.add.at(sums, at.ravel(), vals)
        return coo_array((sums, (keys // n, keys % n)), shape=(n, n)).tocsr()


def system_of(model, field_name: str = "model", *, sparse_ok: bool = False):
    """The model of an analysis: a :class:`Rotor` assembled (:func:`assemble`), or a :class:`SystemMatrices` or a
    reduced model (:class:`rotorred.linear.reduction.ReducedSystem`) as given.

    Every analysis reads its model through this one protocol (:class:`SpoolSpeedMixin`).

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        The model as the caller gives it.
    field_name : str
        The argument or key the error names.
    sparse_ok : bool
        Whether the caller has a sparse path: it gets a full model of at least
        :data:`rotorred.model.sparse.SOLVE_SPARSE_FROM` DOFs sparse (:meth:`SystemMatrices.sparse`), as it is
        otherwise; a caller without one gets it dense (:meth:`SystemMatrices.dense`).

    Returns
    -------
    SystemMatrices or ReducedSystem

    Raises
    ------
    rotorred.checks.InputError
        For anything else, naming ``field_name``.
    """
    if isinstance(model, Rotor):  # assembled sparse at once where it would be solved sparse
        solved_sparse = sparse_ok and _dof_map(model, supported=True).n_dof >= sparse.SOLVE_SPARSE_FROM
        model = assemble(model, as_sparse=True if solved_sparse else None)
    if not isinstance(model, SpoolSpeedMixin):
        checks.fail(field_name, type(model).__name__, "must be a Rotor, a SystemMatrices (assemble) or a "
                    "ReducedSystem (reduce_rotor)")
    if not isinstance(model, SystemMatrices):
        return model  # a reduced model: small and dense
    if not sparse_ok:
        return model.dense()
    return model.sparse() if model.n_dof >= sparse.SOLVE_SPARSE_FROM else model


def _dof_map(rotor: Rotor, supported: bool = False) -> DofMap:
    """The DOF numbering of ``rotor``: four per shaft node, two per pedestal node, then the elements' internal DOFs;
    less those its supports fix if ``supported``."""
    n_internal = sum(e.n_internal for s in rotor.spools for e in s.all_elements)
    fixed = frozenset((sp.node, d) for sp in rotor.supports for d in sp.fixed) if supported else frozenset()
    return DofMap(rotor.all_nodes, n_internal, translational=frozenset(p.node for p in rotor.pedestals), fixed=fixed)


def assemble(rotor: Rotor, as_sparse: bool | None = None) -> SystemMatrices:
    """Assemble the global matrices of ``rotor``.

    Parameters
    ----------
    rotor : Rotor
        The rotor; its tabulated bearings enter ``K`` and ``C`` at its nominal speeds (docs/model.md §10).
    as_sparse : bool, optional
        Sparse CSR matrices (True) or dense ones (False); default by size: sparse from
        :data:`rotorred.model.sparse.SPARSE_FROM` DOFs on.

    Returns
    -------
    SystemMatrices
        ``M``, ``K``, ``C``, ``G`` and ``K_G`` in the DOF order of :class:`rotorred.model.dofs.DofMap`.
    """
    as_sparse = _dof_map(rotor).n_dof >= sparse.SPARSE_FROM if as_sparse is None else bool(as_sparse)
    supported = _assembled(rotor, as_sparse)
    if any(sparse.nonzero(r.C_h) for r in supported.rotating.values()):
        supported = dataclasses.replace(supported, loss_frequency=first_natural_frequency(supported.M, supported.K))
    object.__setattr__(supported, _AS_ASSEMBLED, True)
    return supported


#: the mark :func:`assemble` leaves on the model it returns (an attribute, not a field: ``dataclasses.replace``, and
#: any other way of making a changed model, drops it); :meth:`SystemMatrices.sparse` of a marked model is its rotor's
#: sparse assembly
_AS_ASSEMBLED = "_as_assembled"


def _assembled(rotor: Rotor, as_sparse: bool) -> SystemMatrices:
    """:func:`assemble` but the loss frequency: the matrices of ``rotor``, sparse or dense, its supports applied."""
    dofs = _dof_map(rotor)
    n = dofs.n_dof
    next_internal = n - dofs.n_internal
    M, K, C, M_shaft, K_shaft = (_Triplets() for _ in range(5))
    parts = {s.name: [_Triplets() for _ in range(4)] for s in rotor.spools}  # C_v, N_v, C_h, N_h of RotatingDamping
    G = {s.name: _Triplets() for s in rotor.spools}
    K_G = {s.name: _Triplets() for s in rotor.spools}
    for s in rotor.spools:
        for e in s.all_elements:
            internal = np.arange(next_internal, next_internal + e.n_internal)
            next_internal += e.n_internal
            idx = np.concatenate([dofs.node_dofs(e.left), dofs.node_dofs(e.right), internal])
            Me, Ke = e.M(), e.K()
            M.add(idx, Me)
            K.add(idx, Ke)
            M_shaft.add(idx, Me)
            K_shaft.add(idx, Ke)
            G[s.name].add(idx, e.G())
            K_G[s.name].add(idx, e.K_G())
            beta, eta = s.internal_damping(e)
            if beta or eta:
                KJ = Ke @ e.spin_rotation()
                for triplets, factor, X in zip(parts[s.name], (beta, beta, eta, eta), (Ke, KJ, Ke, KJ)):
                    triplets.add(idx, factor * X)
    spool_of = rotor.spool_of
    for d in rotor.disks:
        idx = dofs.node_dofs(d.node)
        M.add(idx, d.M())
        G[spool_of[d.node]].add(idx, d.G())
        K_G[spool_of[d.node]].add(idx, d.K_G())
    for p in rotor.pedestals:
        M.add(dofs.node_dofs(p.node), p.M())
    tables = []
    for b in (*rotor.bearings, *rotor.intershaft_bearings):
        rows = _deflection_rows(dofs, b)
        if isinstance(b, (BearingTable, IntershaftBearingTable)):
            spool = _table_spool(b, spool_of)
            tables.append(TabulatedSupport(b, spool, coo_array(rows).tocsr() if as_sparse else rows,
                                           b.at(rotor.speeds[spool])))
            b = tables[-1].nominal
        idx = np.flatnonzero(np.any(rows != 0.0, axis=0))  # the DOFs the bearing's deflection reads
        K.add(idx, rows[:, idx].T @ b.block("K") @ rows[:, idx])
        C.add(idx, rows[:, idx].T @ b.block("C") @ rows[:, idx])
    Cm = C.matrix(n, as_sparse)
    alpha, beta = rotor.rayleigh
    if alpha or beta:
        Cm = Cm + (alpha * M_shaft.matrix(n, as_sparse) + beta * K_shaft.matrix(n, as_sparse))
    rotating = {k: RotatingDamping(*(t.matrix(n, as_sparse) for t in v)) for k, v in parts.items() if v[0].vals}
    free = SystemMatrices(M=M.matrix(n, as_sparse), K=K.matrix(n, as_sparse), C=Cm,
                          G={k: v.matrix(n, as_sparse) for k, v in G.items()}, dofs=dofs,
                          K_G={k: v.matrix(n, as_sparse) for k, v in K_G.items()}, tables=tuple(tables), rotor=rotor,
                          rotating=rotating)
    return _supported(free, rotor.supports)


#: generalised eigenvalues w^2 of (K, M) below this fraction of the largest are rigid-body motions (as in
#: rotorred.linear.campbell's rigid-body test)
_RIGID_RTOL = 1e-10


def first_natural_frequency(M: np.ndarray, K: np.ndarray) -> float:
    """The lowest natural frequency of the undamped model at rest, ``K phi = w^2 M phi`` (rad/s), rigid-body
    motions (w^2 <= 1e-10 max w^2) left out: where a loss factor is taken when an analysis has no whirl frequency
    of its own (docs/model.md §19)."""
    if sparse.is_sparse(M):
        return _first_natural_frequency_sparse(M, K)
    w2 = eigh(0.5 * (K + K.T), M, eigvals_only=True)
    w2 = np.sort(w2[w2 > _RIGID_RTOL * max(float(np.max(np.abs(w2))), 1e-300)])
    if not len(w2):
        checks.fail("internal_loss_factor", "given", "needs a rotor with an elastic mode (every mode is rigid)")
    return float(np.sqrt(w2[0]))


def _first_natural_frequency_sparse(M, K) -> float:
    """:func:`first_natural_frequency` of a sparse model: the lowest eigenpairs by shift-invert
    (:func:`rotorred.model.sparse.lowest_w2`), more until one is elastic; the largest w^2 that the rigid-body test
    compares with is bounded by the largest ratio of K's and M's diagonal entries (Rayleigh quotients of unit
    vectors, a lower bound of the largest w^2; rigid motions are round-off zeros far below both)."""
    K = 0.5 * (K + K.T)
    limit = _RIGID_RTOL * float(np.max(np.abs(K.diagonal()) / np.maximum(M.diagonal(), 1e-300)))
    k = 8
    while True:
        w2 = sparse.lowest_w2(K, M, k)[0]
        elastic = w2[w2 > limit]
        if len(elastic) or k >= M.shape[0]:
            break
        k *= 4
    if not len(elastic):
        checks.fail("internal_loss_factor", "given", "needs a rotor with an elastic mode (every mode is rigid)")
    return float(np.sqrt(elastic[0]))


def _deflection_rows(dofs: DofMap, b) -> np.ndarray:
    """A bearing's deflection (x, y, theta_x, theta_y) as rows on the DOFs, shape (4, n): its node's motion, less
    its pedestal's x, y (a pedestal does not tilt) or the other spool's node's motion (an inter-shaft bearing). The
    tilt rows are zero at a pedestal node, which has no rotations (docs/model.md §20)."""
    rows = np.zeros((4, dofs.n_dof))
    for node, sign in ((b.node_a, 1.0), (b.node_b, -1.0)) if hasattr(b, "node_b") else ((b.node, 1.0), (b.link, -1.0)):
        if node is not None:
            idx = dofs.node_dofs(node)
            rows[np.arange(len(idx)), idx] = sign
    return rows


def _table_spool(b, spool_of: Mapping[int, str]) -> str:
    """The spool whose speed a bearing table follows: an inter-shaft table's ``speed_of`` (default its node_a's), else
    its node's."""
    return getattr(b, "speed_of", None) or spool_of[b.node]


def _supported(system: SystemMatrices, supports) -> SystemMatrices:
    """``system`` without the DOFs the supports fix: their rows and columns removed (a pinned or clamped DOF is
    zero, exactly; docs/model.md §11)."""
    if not supports:
        return system
    dofs = DofMap(system.dofs.nodes, system.dofs.n_internal, translational=system.dofs.translational,
                  fixed=frozenset((sp.node, d) for sp in supports for d in sp.fixed))
    keep = dofs.free_in(system.dofs)

    def cut(X):
        return sparse.cut(X, keep, keep)

    e_y = np.zeros(system.n_dof)  # every node moves 1 in y
    e_y[[system.dofs.index(n, "y") for n in system.dofs.nodes]] = 1.0
    return SystemMatrices(M=cut(system.M), K=cut(system.K), C=cut(system.C), G={k: cut(v) for k, v in system.G.items()},
                          dofs=dofs, K_G={k: cut(v) for k, v in system.K_G.items()},
                          tables=tuple(dataclasses.replace(t, rows=t.rows[:, keep]) for t in system.tables),
                          supported_weight=(system.M @ e_y)[keep], rotor=system.rotor,
                          rotating={k: RotatingDamping(*(cut(X) for X in (r.C_v, r.N_v, r.C_h, r.N_h)))
                                    for k, r in system.rotating.items()})
