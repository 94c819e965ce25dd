"""Craig–Bampton reduction of a (multi-spool) rotor model.

The full DOFs are split into boundary DOFs ``b`` (all four physical DOFs of each boundary
node: bearings, inter-shaft bearings, the rub node, any node the user names) and interior
DOFs ``i``. The Craig–Bampton basis (Craig & Bampton 1968, AIAA J. 6(7), Eqs. 8–14) is

    q = T p,   T = [[I, 0], [Psi, Phi]]   (rows in (b, i) order),
    Psi = -K_ii^-1 K_ib           static constraint modes,
    K_ii Phi = M_ii Phi Lambda    fixed-interface normal modes (Phi^T M_ii Phi = I),

computed on the non-spinning, undamped system. The reduced coordinates are
``p = [boundary physical DOFs..., modal coordinates...]``, so a boundary DOF keeps its
physical meaning and the rub force, bearing forces and inter-shaft forces act on it
directly. M, K, C and every spool's G are projected with the same T
(``M_r = T^T M T`` and so on), so the reduced equation of motion has the same form as the
full one, ``M_r p'' + (C_r + sum_s Omega_s G_r,s) p' + K_r p = T^T F``. ``T`` is also the
recovery map: any physical DOF, boundary or interior, is ``T[row] @ p``.

With no interior mode kept the basis is Guyan's static condensation; with every interior
mode kept ``T`` is square and invertible and the reduced eigenvalues equal the full ones.

How many modes: given by count (``n_modes``), by cutoff frequency (``cutoff``, keep the
fixed-interface modes with omega <= cutoff), or, by default, the smallest count whose whirl
frequencies meet a relative error ``target`` against the full model over a frequency band
(or over the first ``n_check`` whirl modes) at a few spin speeds. The choice is recorded in
:class:`ModeSelection`.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rotorred import checks
from rotorred.linear.harmonic import response_error, unbalance_response
from rotorred.linear.modal import WHIRL_MAX_DAMPING_RATIO, eigen  # noqa: F401 - WHIRL_MAX_DAMPING_RATIO also read here
from rotorred.model.assembly import (RotatingDamping, SpoolSpeedMixin, SystemMatrices, TabulatedSupport, assemble,
                                     model_summary, system_of)
from rotorred.model.dofs import DofMap
from rotorred.model.operating import Operating
from rotorred.model.sparse import cut, is_sparse, lowest_w2, nonzero
from rotorred.model.operating import checked as checked_operating
from rotorred.model.rotor import Rotor, node_ranges
from rotorred.results import Result

#: default relative whirl-frequency error target of the automatic mode count (0.1 %)
DEFAULT_TARGET = 1e-3
#: default number of whirl modes checked by the automatic mode count when no band is given
DEFAULT_N_CHECK = 8
#: default spin-speed factors (times the nominal speeds) at which the automatic count is checked
DEFAULT_SPEED_FACTORS = (0.0, 0.5, 1.0, 1.5)


@dataclass(frozen=True)
class ModeSelection:
    """How the number of fixed-interface modes was chosen.

    Attributes
    ----------
    method : {"count", "cutoff", "auto"}
        ``"count"``: given ``n_modes``; ``"cutoff"``: modes with omega <= ``cutoff``;
        ``"auto"``: smallest count meeting ``target``.
    n_modes : int
        Number of fixed-interface modes kept.
    n_interior_dofs : int
        Number of interior DOFs (the most modes there are).
    cutoff : float or None
        Cutoff frequency (rad/s) for ``"cutoff"``.
    target : float or None
        Relative whirl-frequency error target for ``"auto"``.
    band : tuple of float or None
        Frequency band (rad/s) whose full-model whirl modes were checked (``"auto"``).
    n_check : int or None
        Number of lowest whirl modes checked when no band was given (``"auto"``).
    check_speeds : tuple of dict
        Spool speeds (rad/s) at which the error was checked (``"auto"``).
    error : float or None
        Worst relative whirl-frequency error reached (``"auto"``).
    response_target, response_error : float or None
        Relative unbalance-response error target and the error reached, when a
        :class:`ResponseCheck` was part of the automatic choice.
    history : tuple of (int, float, float or None)
        (modes, whirl error, response error or None when not evaluated) for every count
        tried (``"auto"``).
    """

    method: str
    n_modes: int
    n_interior_dofs: int
    cutoff: float | None = None
    target: float | None = None
    band: tuple[float, float] | None = None
    n_check: int | None = None
    check_speeds: tuple = ()
    error: float | None = None
    response_target: float | None = None
    response_error: float | None = None
    history: tuple = ()

    def describe(self) -> str:
        """One-line human description, frequencies in Hz."""
        if self.method == "count":
            return f"{self.n_modes} fixed-interface modes (given count)"
        if self.method == "cutoff":
            return (f"{self.n_modes} fixed-interface modes below the cutoff "
                    f"{self.cutoff / (2 * math.pi):.1f} Hz")
        what = (f"whirl modes in {self.band[0] / (2 * math.pi):.1f}-{self.band[1] / (2 * math.pi):.1f} Hz"
                if self.band is not None else f"the first {self.n_check} whirl modes")
        text = (f"{self.n_modes} fixed-interface modes chosen automatically: worst whirl-frequency error "
                f"{100 * self.error:.3g} % (target {100 * self.target:.3g} %) over {what} "
                f"at {len(self.check_speeds)} speeds")
        if self.response_target is not None:
            text += (f"; worst unbalance-response error {100 * self.response_error:.3g} % "
                     f"(target {100 * self.response_target:.3g} %)")
        return text


@dataclass(frozen=True)
class ResponseCheck:
    """An unbalance-response accuracy requirement for the automatic mode count.

    The reduced model's unbalance response along ``operating`` must match the full model's
    within ``target`` (see :func:`rotorred.linear.harmonic.response_error`).

    Parameters
    ----------
    unbalances : tuple of Unbalance
    operating : Operating
        The speed line of the sweep (:class:`rotorred.model.operating.Operating`; speeds in rad/s).
    outputs : tuple of (int, str)
        Physical DOFs checked.
    target : float
        Relative error target (default 5e-3, i.e. 0.5 %).
    """

    unbalances: tuple
    operating: Operating
    outputs: tuple
    target: float = 5e-3

    def __post_init__(self):
        object.__setattr__(self, "unbalances", tuple(self.unbalances))
        object.__setattr__(self, "operating", checked_operating(self.operating))
        object.__setattr__(self, "outputs", tuple(tuple(o) for o in self.outputs))
        object.__setattr__(self, "target", checks.positive("target", self.target))

    def run(self, model):
        """Unbalance response of ``model`` for this check."""
        return unbalance_response(model, self.operating, self.unbalances, self.outputs)


@dataclass(frozen=True)
class ReducedSystem(SpoolSpeedMixin):
    """A Craig–Bampton reduced model, with the same interface as :class:`SystemMatrices`.

    Reduced coordinates are ``p = [boundary physical DOFs..., modal coordinates...]``.

    Attributes
    ----------
    M, K, C : ndarray, shape (m, m)
        Reduced mass (kg), stiffness (N/m) and damping (N s/m): ``T^T X T``.
    G : dict of str to ndarray, shape (m, m)
        Reduced gyroscopic matrix of each spool per unit spin speed (1 rad/s): ``T^T G_s T``.
    T : ndarray, shape (n, m)
        Recovery map, full physical coordinates ``q = T p``.
    full_dofs : DofMap
        DOF numbering of the full model (``T``'s rows).
    boundary_nodes : tuple of int
        Boundary nodes, in full DOF order.
    boundary_dofs : ndarray of int, shape (4 * len(boundary_nodes),)
        Full indices of the boundary DOFs; reduced coordinate ``j`` is full DOF
        ``boundary_dofs[j]`` for ``j < len(boundary_dofs)``.
    n_modes : int
        Number of fixed-interface modes kept.
    interior_frequencies : ndarray, shape (n_modes,)
        Natural frequencies of the kept fixed-interface modes (rad/s).
    selection : ModeSelection
        Record of how ``n_modes`` was chosen.
    K_G : dict of str to ndarray, shape (m, m)
        Reduced spin-acceleration matrix of each spool per unit angular acceleration (1 rad/s^2):
        ``T^T K_G,s T``.
    tables : tuple of TabulatedSupport
        The full model's speed-dependent bearings on the reduced coordinates (rows ``R T``): their change with
        speed is exact when the bearing's node is a boundary node, as the constraint and fixed-interface modes
        do not depend on a boundary node's supports.
    supported_weight : ndarray, shape (m,), or None
        ``T^T`` times the full model's ``supported_weight`` (a rotor with pinned or clamped supports).
    rotor : Rotor or None
        The rotor of the full model (:class:`rotorred.model.assembly.SpoolSpeedMixin`).
    rotating : dict of str to RotatingDamping
        The full model's internal (rotating) damping projected, ``T^T X T`` of each of its matrices.
    loss_frequency : float
        The full model's (rad/s; :class:`rotorred.model.assembly.SystemMatrices`).
    """

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    G: Mapping[str, np.ndarray]
    T: np.ndarray
    full_dofs: DofMap
    boundary_nodes: tuple[int, ...]
    boundary_dofs: np.ndarray
    n_modes: int
    interior_frequencies: np.ndarray
    selection: ModeSelection
    K_G: Mapping[str, np.ndarray] = field(default_factory=dict)
    tables: tuple[TabulatedSupport, ...] = ()
    supported_weight: np.ndarray | None = None
    rotor: Rotor | None = field(default=None, compare=False, repr=False)
    rotating: Mapping[str, RotatingDamping] = field(default_factory=dict)
    loss_frequency: float = 0.0
    _bpos: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "_bpos", {int(d): j for j, d in enumerate(self.boundary_dofs)})

    @property
    def n_dof(self) -> int:
        """Number of reduced coordinates (boundary DOFs plus modes)."""
        return self.M.shape[0]

    @property
    def n_boundary_dofs(self) -> int:
        """Number of boundary (physical) DOFs."""
        return len(self.boundary_dofs)

    def physical_index(self, node: int, direction: str) -> int:
        """Index of the boundary DOF ``direction`` at ``node`` in reduced coordinates.

        Parameters
        ----------
        node : int
            A boundary node (:attr:`boundary_nodes`).
        direction : {"x", "y", "theta_x", "theta_y"}
            The DOF at the node (``"tx"``, ``"ty"`` also accepted).

        Raises
        ------
        InputError
            If ``node`` is not a boundary node (its DOFs are then not reduced coordinates;
            use :meth:`output_rows` to recover them).
        """
        full = self.full_dofs.index(node, direction)
        if full not in self._bpos:
            checks.fail("node", node, f"must be a boundary node of the reduced model {list(self.boundary_nodes)}; "
                        "output_rows recovers the DOFs of interior nodes")
        return self._bpos[full]

    def output_rows(self, outputs) -> np.ndarray:
        """Rows of ``T`` mapping reduced coordinates to physical DOFs (any node).

        Parameters
        ----------
        outputs : sequence of (int, str)
            (node, direction) pairs.

        Returns
        -------
        ndarray, shape (len(outputs), m)
            ``rows @ p`` gives the physical displacements.
        """
        idx = [self.full_dofs.index(node, direction) for node, direction in outputs]
        return self.T[idx, :].copy()

    def recover(self, p: np.ndarray) -> np.ndarray:
        """Full physical coordinates ``T p``; ``p`` shape (m,) or (m, k) -> (n,) or (n, k).

        Parameters
        ----------
        p : ndarray, shape (m,) or (m, k)
            Reduced coordinates (boundary DOFs in m or rad, then modal coordinates), one column per instant.

        Returns
        -------
        ndarray, shape (n,) or (n, k)
            Physical displacements (m) and rotations (rad) in the full model's DOF order.
        """
        return self.T @ p

    def project(self, F: np.ndarray) -> np.ndarray:
        """Generalised force ``T^T F`` of a full force vector ``F``, shape (n,) or (n, k).

        Parameters
        ----------
        F : ndarray, shape (n,) or (n, k)
            Forces (N) and moments (N m) on the full model's DOFs, one column per instant.

        Returns
        -------
        ndarray, shape (m,) or (m, k)
            The force on the reduced coordinates.
        """
        return self.T.T @ F

    def summary(self) -> list[str]:
        """Size, kept nodes and modes, how they were chosen, the full model: at most 12 lines, no arrays (``repr``)."""
        f = self.interior_frequencies / (2 * math.pi)
        lines = [f"Craig-Bampton model: {self.n_dof} coordinates = {self.n_boundary_dofs} boundary DOFs + "
                 f"{self.n_modes} modes",
                 f"kept nodes {node_ranges(self.boundary_nodes, 80)}",
                 f"fixed-interface modes at {f[0]:.4g}-{f[-1]:.4g} Hz" if len(f) else "no fixed-interface mode"]
        lines += textwrap.wrap(self.selection.describe(), 100)[:3]
        full = model_summary(self)
        return lines + [f"of {full[0]}"] + full[3:]

    __repr__ = Result.__repr__


def default_boundary_nodes(rotor: Rotor, extra_nodes: Sequence[int] = ()) -> tuple[int, ...]:
    """Bearing nodes and their pedestals, both nodes of every inter-shaft bearing, and ``extra_nodes``, in DOF
    order.

    Parameters
    ----------
    rotor : Rotor
        The rotor to reduce.
    extra_nodes : sequence of int
        Further nodes to keep, e.g. rub or output nodes.

    Returns
    -------
    tuple of int
        The boundary nodes of a Craig–Bampton reduction (:func:`reduce_rotor`).

    Raises
    ------
    InputError
        If a node of ``extra_nodes`` is not a shaft node of ``rotor``.
    """
    extra = [checks.node(f"extra_nodes[{i}]", n, rotor.spool_of) for i, n in enumerate(extra_nodes)]
    nodes = {b.node for b in rotor.bearings} | {b.link for b in rotor.bearings if b.link is not None}
    for b in rotor.intershaft_bearings:
        nodes.update((b.node_a, b.node_b))
    nodes.update(extra)
    return tuple(n for n in rotor.all_nodes if n in nodes)


def _boundary(system: SystemMatrices, boundary_nodes) -> tuple[tuple[int, ...], np.ndarray, np.ndarray]:
    dofs = system.dofs
    requested = list(boundary_nodes)
    if not requested:
        checks.fail("boundary_nodes", boundary_nodes, "must name at least one node")
    chosen = {checks.node(f"boundary_nodes[{i}]", n, dofs.nodes, "a node of the model")
              for i, n in enumerate(requested)}
    nodes = tuple(n for n in dofs.nodes if n in chosen)
    b = np.concatenate([dofs.node_dofs(n) for n in nodes])
    mask = np.ones(dofs.n_dof, dtype=bool)
    mask[b] = False
    return nodes, b, np.flatnonzero(mask)


@dataclass(frozen=True)
class _Basis:
    """Everything needed to build T for any number of modes."""

    b: np.ndarray
    i: np.ndarray
    Psi: np.ndarray            # (n_i, n_b)
    Phi: np.ndarray            # (n_i, n_i), mass-normalised, ascending frequency
    omega: np.ndarray          # (n_i,) rad/s

    def T(self, n_modes: int) -> np.ndarray:
        n = len(self.b) + len(self.i)
        nb = len(self.b)
        T = np.zeros((n, nb + n_modes))
        T[self.b, np.arange(nb)] = 1.0
        T[np.ix_(self.i, np.arange(nb))] = self.Psi
        T[np.ix_(self.i, nb + np.arange(n_modes))] = self.Phi[:, :n_modes]
        return T


def _basis(system: SystemMatrices, b: np.ndarray, i: np.ndarray, n_modes: int | None = None) -> _Basis:
    """The constraint modes and the lowest ``n_modes`` fixed-interface modes (None: all; a dense model gets all).

    A sparse model (:attr:`SystemMatrices.is_sparse`) is never made dense: ``Psi`` by a sparse LU of ``K_ii`` and
    the modes by shift-invert Lanczos (:func:`rotorred.model.sparse.lowest_w2`)."""
    K, M = system.K, system.M
    K_ii, M_ii, K_ib = cut(K, i, i), cut(M, i, i), cut(K, i, b)
    if len(i) == 0:
        return _Basis(b, i, np.zeros((0, len(b))), np.zeros((0, 0)), np.zeros(0))
    if is_sparse(K):
        Psi = -_sparse_solve(system, b, K_ii, K_ib.toarray())
        lam, Phi = lowest_w2(K_ii, M_ii, len(i) if n_modes is None else max(n_modes, 1))
        return _Basis(b, i, Psi, Phi, np.sqrt(np.clip(lam, 0.0, None)))
    try:
        chol = sla.cho_factor(K_ii)
    except np.linalg.LinAlgError:
        _not_restrained(system, b)
    Psi = -sla.cho_solve(chol, K_ib)
    lam, Phi = sla.eigh(K_ii, M_ii)
    omega = np.sqrt(np.clip(lam, 0.0, None))
    return _Basis(b, i, Psi, Phi, omega)


#: a pivot of K_ii's sparse LU at or below this fraction of the largest makes K_ii singular (a free interior part);
#: round-off of a stiffness matrix with pivots spanning 1e6 is ~1e-16 of its largest
_SINGULAR_PIVOT = 1e-13


def _sparse_solve(system, b: np.ndarray, K_ii, rhs: np.ndarray) -> np.ndarray:
    """``K_ii^-1 rhs`` by a sparse LU (a fill-reducing order of K_ii + K_ii^T, pivots on the diagonal: those of a
    symmetric LDL^T). A pivot at or below ``_SINGULAR_PIVOT`` times the largest is a free interior part (the
    dense path's Cholesky fails there: a pivot of round-off size, of either sign)."""
    try:
        lu = spla.splu(sp.csc_array(K_ii), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:  # exactly singular
        _not_restrained(system, b)
    pivots = lu.U.diagonal()
    if np.min(pivots) <= _SINGULAR_PIVOT * np.max(np.abs(pivots)):
        _not_restrained(system, b)
    out = lu.solve(rhs)
    if not np.all(np.isfinite(out)):
        _not_restrained(system, b)
    return out


def _not_restrained(system, b: np.ndarray):
    """Refuse a boundary that leaves the interior free (K_ii singular)."""
    checks.fail("boundary_nodes", sorted({system.dofs.node_of(int(d)) for d in b}), "must restrain the "
                "interior part of the model when fixed: it is not restrained (K_ii is singular); add a node "
                "of each free part")


def _project(system: SystemMatrices, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict, dict]:
    def p(X):
        return T.T @ (X @ T) if is_sparse(X) else T.T @ X @ T  # a sparse X: X @ T is dense, (n, m)

    def symmetric(X):
        return 0.5 * (X + X.T)

    # the symmetric parts stay exactly symmetric (round-off symmetrised away); K's skew part, the bearings'
    # cross-coupled stiffness k_xy != k_yx, is projected on its own and kept
    Mr, Kr = symmetric(p(system.M)), symmetric(p(symmetric(system.K)))
    K_skew = 0.5 * (system.K - system.K.T)
    if nonzero(K_skew):
        X = p(K_skew)
        Kr = Kr + 0.5 * (X - X.T)
    return (Mr, Kr, p(system.C), {s: p(G) for s, G in system.G.items()},
            {s: p(KG) for s, KG in system.K_G.items()})



def whirl_frequencies(model, speeds: Mapping[str, float], n_modes: int | None = None,
                      below: float | None = None) -> np.ndarray:
    """Damped whirl frequencies Im(lambda) (rad/s) of ``model`` at spool speeds ``speeds``, ascending.

    Heavily damped eigenvalues (damping ratio >= ``WHIRL_MAX_DAMPING_RATIO``, e.g. the
    high-frequency shaft modes that stiffness-proportional Rayleigh damping makes
    overdamped) do not whirl visibly and are left out, in the full and reduced model alike.
    A sparse model gives its lowest ``n_modes`` and every one below ``below`` (rad/s) only
    (:func:`rotorred.linear.modal.eigen`); a dense one all.
    """
    return eigen(model.M, model.damping(speeds), model.stiffness(speeds), n_modes=n_modes,
                 max_damping_ratio=WHIRL_MAX_DAMPING_RATIO, below=below).eigenvalues.imag


def whirl_error(reference: Sequence[np.ndarray], model, speeds_list: Sequence[Mapping[str, float]],
                band: tuple[float, float] | None = None, n_check: int | None = None) -> float:
    """Worst relative whirl-frequency error of ``model`` against reference frequencies.

    The j-th lowest frequency of ``model`` is compared with the j-th lowest reference
    frequency (Craig–Bampton is a Ritz method, so a missing mode shows as a large error at
    its index rather than being skipped).

    Parameters
    ----------
    reference : sequence of ndarray
        Reference (full-model) whirl frequencies (rad/s), ascending, one array per speed.
    model : SystemMatrices or ReducedSystem
    speeds_list : sequence of dict
        Spool speeds (rad/s), one dict per entry of ``reference``.
    band : (float, float), optional
        Only reference frequencies in ``[band[0], band[1]]`` (rad/s) count.
    n_check : int, optional
        Only the ``n_check`` lowest reference frequencies count (used when ``band`` is None).

    Returns
    -------
    float
        max_j |omega_model,j - omega_ref,j| / omega_ref,j (inf when the model has too few modes).
    """
    worst = 0.0
    for ref, speeds in zip(reference, speeds_list):
        if band is not None:
            sel = np.flatnonzero((ref >= band[0]) & (ref <= band[1]))
        else:
            sel = np.arange(min(n_check, len(ref)))
        if len(sel) == 0:
            continue
        got = whirl_frequencies(model, speeds)
        if len(got) <= sel[-1]:
            return math.inf
        worst = max(worst, float(np.max(np.abs(got[sel] - ref[sel]) / ref[sel])))
    return worst


def reduce(system: SystemMatrices, boundary_nodes: Sequence[int], n_modes: int | None = None,
           cutoff: float | None = None, *, band: tuple[float, float] | None = None,
           target: float = DEFAULT_TARGET, check_speeds: Sequence[Mapping[str, float]] | None = None,
           n_check: int | None = None, response: ResponseCheck | None = None) -> ReducedSystem:
    """Craig–Bampton reduction of ``system`` with all DOFs of ``boundary_nodes`` kept.

    Parameters
    ----------
    system : SystemMatrices
        Full model.
    boundary_nodes : sequence of int
        Nodes whose four physical DOFs stay as reduced coordinates.
    n_modes : int, optional
        Number of fixed-interface modes to keep (0 gives Guyan reduction).
    cutoff : float, optional
        Keep the fixed-interface modes with natural frequency <= ``cutoff`` (rad/s).
        Must not lie below the upper end of ``band`` when a band is given.
    band : (float, float), optional
        Frequency band of interest (rad/s), 0 <= band[0] < band[1]. The automatic count
        checks the full-model whirl modes in this band.
    target : float
        Relative whirl-frequency error target of the automatic count (default 1e-3).
    check_speeds : sequence of dict, optional
        Spool speeds (rad/s) at which the automatic count is checked (default: non-spinning).
    n_check : int, optional
        Without a band, the automatic count checks the ``n_check`` lowest whirl modes
        (default 8).
    response : ResponseCheck, optional
        An extra requirement of the automatic count: the unbalance response must also meet
        ``response.target`` against the full model.

    Returns
    -------
    ReducedSystem

    Notes
    -----
    With neither ``n_modes`` nor ``cutoff`` the number of modes is chosen automatically:
    the full model's whirl frequencies are computed at ``check_speeds`` and modes are added
    in ascending fixed-interface frequency until the worst relative error (see
    :func:`whirl_error`) is at most ``target`` and, with ``response``, the unbalance
    response error is at most ``response.target``.

    References
    ----------
    R. R. Craig, M. C. C. Bampton, "Coupling of substructures for dynamic analyses",
    AIAA Journal 6(7), 1968, 1313–1319.
    """
    system = system_of(system, "system", sparse_ok=True)  # from SOLVE_SPARSE_FROM DOFs: the sparse path
    n_modes, cutoff, band, target, n_check, check_speeds = _checked_options(
        system, n_modes, cutoff, band, target, n_check, check_speeds)
    ladder = ModeLadder(system, boundary_nodes)
    n_i = ladder.n_interior

    if n_modes is not None:
        if n_modes > n_i:
            checks.fail("n_modes", n_modes, f"must be <= {n_i}, the number of interior DOFs")
        selection = ModeSelection("count", n_modes, n_i)
    elif cutoff is not None:
        n_modes = ladder.count_below(cutoff)
        selection = ModeSelection("cutoff", n_modes, n_i, cutoff=float(cutoff), band=band)
    else:
        if check_speeds is None:
            check_speeds = ({s: 0.0 for s in system.G},)
        if band is None and n_check is None:
            n_check = DEFAULT_N_CHECK
        reference = [whirl_frequencies(system, s, n_modes=n_check, below=None if band is None else band[1])
                     for s in check_speeds]
        full_response = response.run(system) if response is not None else None
        history = []
        resp_err = None
        for n in range(n_i + 1):
            trial = ladder.model(n)
            err = whirl_error(reference, trial, check_speeds, band=band, n_check=n_check)
            resp_err = None
            if response is not None and err <= target:
                resp_err = response_error(full_response, response.run(trial))
            history.append((n, err, resp_err))
            if err <= target and (response is None or resp_err <= response.target):
                break
        n_modes = n
        selection = ModeSelection("auto", n, n_i, target=float(target), band=band,
                                  n_check=None if band is not None else n_check,
                                  check_speeds=tuple(check_speeds), error=err,
                                  response_target=None if response is None else float(response.target),
                                  response_error=resp_err, history=tuple(history))
    return ladder.model(n_modes, selection)


def _checked_options(system: SystemMatrices, n_modes, cutoff, band, target, n_check, check_speeds):
    """The options of :func:`reduce`, checked: (n_modes, cutoff, band, target, n_check, check_speeds)."""
    if n_modes is not None and cutoff is not None:
        checks.fail("cutoff", cutoff, f"must not be given together with n_modes = {n_modes!r}: give one or the "
                    "other", "rad/s")
    if n_modes is not None:
        n_modes = checks.integer("n_modes", n_modes, ge=0)
    if band is not None:
        band = tuple(float(x) for x in checks.vector("band", band, "rad/s", min_len=2, max_len=2, ge=0.0,
                                                     increasing=True))
    if cutoff is not None:
        cutoff = checks.positive("cutoff", cutoff, "rad/s")
        if band is not None and cutoff < band[1]:
            checks.fail("cutoff", cutoff, f"must not lie below the frequency band of interest, which ends at "
                        f"{band[1]:.6g} rad/s ({band[1] / (2 * math.pi):.4g} Hz; the cutoff is "
                        f"{cutoff / (2 * math.pi):.4g} Hz): it must be at least the band's upper end, 1.5-2x is "
                        "usual", "rad/s")
    target = checks.positive("target", target)
    if n_check is not None:
        n_check = checks.integer("n_check", n_check, ge=1)
    if check_speeds is not None:
        check_speeds = tuple(dict(checks.table(f"check_speeds[{k}]", s)) for k, s in enumerate(check_speeds))
        for k, s in enumerate(check_speeds):
            checks.keys(f"check_speeds[{k}]", s, system.G)
    return n_modes, cutoff, band, target, n_check, check_speeds


#: fixed-interface modes a sparse model's ladder computes first (:meth:`ModeLadder._ensure` adds more as needed)
_FIRST_SPARSE_MODES = 24


class ModeLadder:
    """The Craig–Bampton models of ``system`` with the boundary ``boundary_nodes`` and any number of fixed-interface
    modes, all from one basis: the constraint modes and the interior eigen-decomposition are computed once (an
    automatic mode count tries many counts).

    Parameters
    ----------
    system : SystemMatrices
    boundary_nodes : sequence of int
        Nodes whose four physical DOFs stay as reduced coordinates.
    """

    def __init__(self, system: SystemMatrices, boundary_nodes: Sequence[int]):
        self.system = system
        self.nodes, b, i = _boundary(system, boundary_nodes)
        self.basis = _basis(system, b, i, _FIRST_SPARSE_MODES)

    def _ensure(self, n_modes: int):
        """Hold at least ``n_modes`` fixed-interface modes (a sparse model's are computed as needed, doubling)."""
        have = len(self.basis.omega)
        if n_modes > have and have < self.n_interior:
            k = min(self.n_interior, max(n_modes, 2 * have))
            self.basis = _basis(self.system, self.basis.b, self.basis.i, k)

    def count_below(self, cutoff: float) -> int:
        """Number of fixed-interface modes of natural frequency <= ``cutoff`` (rad/s)."""
        while self.basis.omega[-1:].max(initial=-1.0) <= cutoff and len(self.basis.omega) < self.n_interior:
            self._ensure(2 * len(self.basis.omega))
        return int(np.count_nonzero(self.basis.omega <= cutoff))

    @property
    def n_interior(self) -> int:
        """Interior DOFs: the most fixed-interface modes there are."""
        return len(self.basis.i)

    @property
    def frequencies(self) -> np.ndarray:
        """Fixed-interface natural frequencies (rad/s), ascending, shape (n_interior,) (a sparse model's: those computed
        so far, the lowest)."""
        return self.basis.omega

    def model(self, n_modes: int, selection: ModeSelection | None = None) -> ReducedSystem:
        """The model with the lowest ``n_modes`` fixed-interface modes (``selection`` default: a given count)."""
        selection = selection or ModeSelection("count", n_modes, self.n_interior)
        self._ensure(n_modes)
        return _make(self.system, self.nodes, self.basis, self.basis.T(n_modes), n_modes, selection)


def _make(system, nodes, basis: _Basis, T, n_modes, selection) -> ReducedSystem:
    Mr, Kr, Cr, Gr, KGr = _project(system, T)
    return ReducedSystem(M=Mr, K=Kr, C=Cr, G=Gr, T=T, full_dofs=system.dofs, boundary_nodes=nodes,
                         boundary_dofs=basis.b.copy(), n_modes=n_modes,
                         interior_frequencies=basis.omega[:n_modes].copy(), selection=selection, K_G=KGr,
                         tables=tuple(t.on(T) for t in system.tables),
                         supported_weight=None if system.supported_weight is None else T.T @ system.supported_weight,
                         rotor=system.rotor, rotating={s: r.on(T) for s, r in system.rotating.items()},
                         loss_frequency=system.loss_frequency)


def reduce_rotor(rotor: Rotor, extra_nodes: Sequence[int] = (), n_modes: int | None = None,
                 cutoff: float | None = None, *, band: tuple[float, float] | None = None,
                 target: float = DEFAULT_TARGET, speed_factors: Sequence[float] = DEFAULT_SPEED_FACTORS,
                 n_check: int | None = None, response: ResponseCheck | None = None,
                 system: SystemMatrices | None = None) -> ReducedSystem:
    """Craig–Bampton reduction of ``rotor`` with the default boundary.

    The boundary is every bearing node, both nodes of every inter-shaft bearing and
    ``extra_nodes`` (for the seed rig pass ``(18,)``, the rub node). The automatic mode
    count is checked at the nominal spool speeds times each of ``speed_factors``
    (default 0, 0.5, 1, 1.5).

    Parameters
    ----------
    rotor : Rotor
        The rotor to reduce.
    extra_nodes : sequence of int
        Additional boundary nodes (e.g. the rub node, output nodes).
    n_modes : int, optional
        Number of fixed-interface modes to keep (0 gives Guyan reduction).
    cutoff : float, optional
        Keep the fixed-interface modes with natural frequency <= ``cutoff`` (rad/s).
    band : (float, float), optional
        Frequency band of interest (rad/s) whose whirl modes the automatic count checks.
    target : float
        Relative whirl-frequency error target of the automatic count (-).
    n_check : int, optional
        Without a band, the automatic count checks the ``n_check`` lowest whirl modes.
    response : ResponseCheck, optional
        An extra requirement of the automatic count: the unbalance response error at most ``response.target``.
        (All as in :func:`reduce`, whose Notes give the automatic count.)
    speed_factors : sequence of float
        Factors (>= 0, -) of the nominal speeds at which the automatic count is checked.
    system : SystemMatrices, optional
        ``assemble(rotor)`` if already at hand.

    Returns
    -------
    ReducedSystem

    Raises
    ------
    InputError
        If a node of ``extra_nodes`` is not a node of ``rotor``, or a setting of :func:`reduce` is out of range.
    """
    factors = tuple(float(f) for f in checks.vector("speed_factors", speed_factors, ge=0.0))
    boundary = default_boundary_nodes(rotor, extra_nodes)
    if system is None:
        system = assemble(rotor)
    nominal = rotor.speeds
    check = [{s: f * w for s, w in nominal.items()} for f in factors]
    return reduce(system, boundary, n_modes=n_modes, cutoff=cutoff, band=band, target=target,
                  check_speeds=check, n_check=n_check, response=response)
