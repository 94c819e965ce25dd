"""Rigid-body motions of a model: the null space of K, each vector judged against its own spool's frequencies.

A free (or singly supported) spool moves without deforming anything: its translations and tilts are eigenvectors of
K phi = w^2 M phi with w^2 = 0, computed as round-off. Which computed w^2 are zero is decided per spool, against the
spool's own first elastic w^2 (its shaft, sleeves and disks free-free, without bearings), not against the model's
largest w^2, which is the stiffest bearing's: bearings of 1e15 N/m put it 1e10 times above a shaft's bending w^2
(docs/model.md §20). Campbell keeps the modes in this null space off the critical speeds
(:func:`rotorred.linear.campbell.rigid_body_share`); a ROSS file's load reports its first elastic frequency.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg as sla

from rotorred.model import sparse
from rotorred.model.assembly import assemble
from rotorred.model.elements import Material
from rotorred.model.rotor import Rotor

__all__ = ["RIGID_RTOL", "NULL_RTOL", "RHO_REFERENCE", "null_space", "rigid_body_motions", "own_elastic_w2",
           "elastic_scale_w2"]

#: generalised eigenvalues w^2 of (K, M) below this fraction of the spool's own first elastic w^2 (its shaft and
#: disks free-free, no bearing; :func:`own_elastic_w2`) span the null space of K: w below 1e-4 of that frequency
RIGID_RTOL = 1e-8
#: density (kg/m^3) of the shaft the threshold's scale is computed with (:func:`elastic_scale_w2`): steel's, so that
#: the scale is the shaft's geometry and stiffness, not its mass distribution (a near-massless Jeffcott shaft under a
#: heavy disk has a free-free w^2 far above its supported disk mode's)
RHO_REFERENCE = 7850.0
#: ... or below this fraction of the largest w^2 of the model: the round-off of the eigen-solve (about 45 eps),
#: under which no w^2 is distinguishable from zero; alone, it is the rule of a model built by hand (no rotor)
NULL_RTOL = 1e-14


def null_space(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The eigenpairs of K phi = w^2 M phi and which of them are rigid-body motions.

    A vector is rigid when w^2 <= max(RIGID_RTOL sum_s e_s w2_s, NULL_RTOL max|w^2|): e_s is the share of its
    squared displacement on spool s's nodes, w2_s the first elastic w^2 of spool s's shaft free-free at the reference
    density (:func:`elastic_scale_w2`).

    Parameters
    ----------
    model : SystemMatrices or ReducedSystem
        The model (its ``rotor`` gives the spools; a model built by hand uses the round-off rule alone).

    Returns
    -------
    w2 : ndarray, shape (n,), or (k,) for a sparse model
        Eigenvalues w^2 (rad^2/s^2), ascending. A sparse model gives its lowest k only (:func:`_lowest_of_sparse`).
    phi : ndarray, shape (n, n), or (n, k)
        M-orthonormal eigenvectors, columns.
    rigid : ndarray of bool, shape (n,), or (k,)
        Whether each is a rigid-body motion.
    """
    own = elastic_scale_w2(model.rotor) if model.rotor is not None else {}
    if sparse.is_sparse(model.M):
        w2, phi, largest = _lowest_of_sparse(model, own)
    else:
        w2, phi = sla.eigh(model.K, model.M)
        largest = float(np.max(np.abs(w2)))
    limit = np.full(len(w2), NULL_RTOL * max(largest, 1e-300))
    if own:
        candidates = np.flatnonzero(w2 <= RIGID_RTOL * max(own.values()))
        shares = _spool_shares(model, phi[:, candidates])  # (n_spools, candidates)
        scale = np.array([own[s] for s in model.spools]) @ shares
        limit[candidates] = np.maximum(limit[candidates], RIGID_RTOL * scale)
    return w2, phi, w2 <= limit


def _lowest_of_sparse(model, own: dict[str, float]) -> tuple[np.ndarray, np.ndarray, float]:
    """The lowest eigenpairs of a sparse model, enough to hold every rigid-body motion (4 per spool and 2 per pedestal
    at most, with margin; more while the highest found is still rigid), and a bound of its largest w^2 (the largest
    ratio of K's and M's diagonal entries, Rayleigh quotients of unit vectors: at most the largest w^2, so the
    round-off rule compares with a smaller value; it matters only for a model built by hand). ``own``: each spool's
    :func:`elastic_scale_w2` (empty for a model built by hand), computed once by :func:`null_space`."""
    K = 0.5 * (model.K + model.K.T)
    largest = float(np.max(np.abs(K.diagonal()) / np.maximum(model.M.diagonal(), 1e-300)))
    top = max(RIGID_RTOL * max(own.values()) if own else 0.0, NULL_RTOL * largest)
    k = 4 * len(model.spools) + 2 * len(model.full_dofs.translational) + 4
    while True:
        w2, phi = sparse.lowest_w2(K, model.M, k)
        if w2[-1] > top or k >= model.n_dof:
            return w2, phi, largest
        k *= 2


def rigid_body_motions(model) -> np.ndarray:
    """The rigid-body motions of a model, M-orthonormal, shape (n, r) (:func:`null_space`): a free spool's
    translations and tilts; r = 0 when every spool is held.

    Parameters
    ----------
    model : SystemMatrices or ReducedSystem

    Returns
    -------
    ndarray, shape (n, r)
    """
    _, phi, rigid = null_space(model)
    return phi[:, rigid]


def own_elastic_w2(rotor: Rotor) -> dict[str, float]:
    """Each spool's own first elastic w^2 (rad^2/s^2): the fifth eigenvalue of its shaft elements, sleeves and disks,
    free-free and without bearings (the first four are its rigid translations and tilts).

    Parameters
    ----------
    rotor : Rotor

    Returns
    -------
    dict of str to float
        Spool name -> w^2 (rad^2/s^2).
    """
    out = {}
    for s in rotor.spools:
        alone = assemble(Rotor((s,), disks=tuple(d for d in rotor.disks if d.node in set(s.nodes))))
        if alone.is_sparse:
            w2 = sparse.lowest_w2(alone.K, alone.M, 5)[0]
        else:
            w2 = sla.eigh(alone.K, alone.M, eigvals_only=True, subset_by_index=(0, min(4, alone.n_dof - 1)))
        out[s.name] = float(w2[-1])
    return out


def elastic_scale_w2(rotor: Rotor) -> dict[str, float]:
    """The scale of each spool's elastic w^2 for the rigid-body test (rad^2/s^2): the first elastic w^2 of its shaft
    elements and sleeves, free-free, without bearings or disks, every material at the density :data:`RHO_REFERENCE`
    (docs/model.md §20).

    Parameters
    ----------
    rotor : Rotor

    Returns
    -------
    dict of str to float
        Spool name -> w^2 (rad^2/s^2).
    """
    def reference(e):
        m = e.material
        return dataclasses.replace(e, material=Material(m.name, m.E, RHO_REFERENCE, G=m.G))

    shafts = [dataclasses.replace(s, elements=tuple(map(reference, s.elements)),
                                  sleeves=tuple(map(reference, s.sleeves))) for s in rotor.spools]
    return own_elastic_w2(Rotor(tuple(shafts)))


def _spool_shares(model, vectors: np.ndarray) -> np.ndarray:
    """Share of each vector's squared physical displacement on each spool's nodes, shape (n_spools, n_vectors),
    columns summing to 1 (a pedestal's share is left out). ``vectors`` on the model's coordinates (recovered by
    ``T`` for a reduced model)."""
    T = getattr(model, "T", None)
    full = vectors if T is None else T @ vectors
    dofs, spool_of = model.full_dofs, model.spool_of
    squares = np.abs(full) ** 2
    out = np.array([sum((squares[dofs.node_dofs(n)].sum(axis=0) for n in dofs.nodes if spool_of.get(n) == s),
                        np.zeros(vectors.shape[1])) for s in model.spools])
    return out / np.maximum(out.sum(axis=0), 1e-300)
