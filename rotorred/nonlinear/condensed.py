"""Harmonic balance condensed onto the DOFs where the nonlinear forces act.

For ``M q'' + D(omega) q' + K q + f(q_c, q_c') = F(t)`` with ``f`` acting on a few DOFs ``c`` (a rub disk's x and y,
the plate's DOFs), the linear rest is eliminated harmonic by harmonic through the dynamic compliance: with
``Z_k = K - (k omega)^2 M + i k omega D(omega)`` and the complex amplitudes ``Q = a - i b`` of
``a cos(k omega t) + b sin(k omega t)``,

    Q_c = (Z_k^-1 F_k)_c - (Z_k^-1)_cc F_nl,k ,

so the unknowns are the coefficients of the ``c`` DOFs only and the residual is

    R(z_c, omega) = z_c - z_lin(omega) + G(omega) F_nl(z_c, omega),

with ``G`` the block-diagonal real form of ``(Z_k^-1)_cc`` (per harmonic ``[[Re H, Im H], [-Im H, Re H]]``).
Its Jacobian is analytic: ``I + G (T(df/dq) + omega T(df/dv)(nabla (x) I))``, and ``dR/domega`` uses
``dZ^-1/domega = -Z^-1 (dZ/domega) Z^-1``. The response of every DOF is recovered from the solution
(:meth:`CondensedProblem.recover`). The interface is :class:`rotorred.nonlinear.hb.PeriodicProblem`'s, so
:func:`rotorred.nonlinear.hb.solve_periodic` and :func:`rotorred.nonlinear.continuation.continue_branch` take it.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Callable, NamedTuple

import numpy as np

from rotorred.nonlinear.fourier import Harmonics, from_phasors, to_phasors
from rotorred.nonlinear.hb import (Evaluation, checked_matrices, checked_unknowns, force_coefficients, local_forces,
                                  sampled_forces)
from rotorred.nonlinear.lowrank import IdentityPlusLowRank
from rotorred.nonlinear.sampled import low_rank

__all__ = ["CondensedProblem", "ClearanceFamily", "dynamic_compliance", "real_form"]


class _Compliance(NamedTuple):
    """The compliance data of every harmonic k = 0..H at one omega, stacked on k: (Z_k^-1)_cc, its omega-derivative,
    the linear response's ``c`` rows and their omega-derivative, and the full linear response with the compliance
    columns (for recovery)."""

    H_cc: np.ndarray    # (H + 1, m, m) complex
    dH_cc: np.ndarray   # (H + 1, m, m)
    q_lin: np.ndarray   # (H + 1, m)
    dq_lin: np.ndarray  # (H + 1, m)
    Q_full: np.ndarray  # (H + 1, n)
    X: np.ndarray       # (H + 1, n, m): (Z_k^-1)[:, c]


def dynamic_compliance(Z: np.ndarray, dofs, f: np.ndarray | None = None):
    """``(Z_k^-1)[:, dofs]`` for a stack of dynamic stiffnesses ``Z`` (k, n, n), and with forces ``f`` (k, n) the linear
    responses ``Z_k^-1 f_k``, by one batched solve: ``(X, Q)``, shapes (k, n, len(dofs)) and (k, n) (Q None without f)."""
    k, n, c = Z.shape[0], Z.shape[1], list(dofs)
    rhs = np.zeros((k, n, len(c) + (f is not None)), complex)
    rhs[:, c, np.arange(len(c))] = 1.0
    if f is not None:
        rhs[:, :, -1] = f
    sol = np.linalg.solve(Z, rhs)
    return (sol[:, :, :len(c)], sol[:, :, -1] if f is not None else None)


def real_form(Hc: np.ndarray) -> np.ndarray:
    """The real form ``[[Re H, Im H], [-Im H, Re H]]`` of each complex block of ``Hc`` (k, c, c): (k, 2c, 2c), the
    action of ``H`` on the (cos, sin) coefficients of one order."""
    return np.concatenate([np.concatenate([Hc.real, Hc.imag], axis=2),
                           np.concatenate([-Hc.imag, Hc.real], axis=2)], axis=1)


@dataclass(frozen=True)
class CondensedProblem:
    """A forced system with nonlinear forces on a few DOFs, solved by harmonic balance on those DOFs.

    Parameters
    ----------
    M, D, K : ndarray, shape (n, n)
        Mass, velocity and stiffness matrices of the whole (linear) system (SI).
    harmonics : Harmonics
    dofs : tuple of int
        The DOFs ``c`` the nonlinear forces act on: the unknowns.
    forcing : callable
        ``forcing(omega) -> (F, dF_domega)``: harmonic-major coefficients of the external force on all n DOFs,
        shape ((2H + 1) n,).
    forces : tuple
        Nonlinear forces (:mod:`rotorred.nonlinear.forces`), their ``dofs`` numbered in the whole system and among
        ``dofs``.
    D1 : ndarray, shape (n, n), optional
        ``D(omega) = D + omega D1``.
    K1 : ndarray, shape (n, n), optional
        ``K(omega) = K + omega K1`` (the circulatory stiffness of internal damping per unit speed when the spin
        follows omega, docs/model.md §19).
    """

    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    harmonics: Harmonics
    dofs: tuple[int, ...]
    forcing: Callable[[float], tuple[np.ndarray, np.ndarray]]
    forces: tuple = ()
    D1: np.ndarray | None = None
    K1: np.ndarray | None = None
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        checked_unknowns(self, checked_matrices(self))

    @property
    def n(self) -> int:
        """The unknown DOFs a harmonic: len(dofs)."""
        return len(self.dofs)

    @property
    def size(self) -> int:
        return self.harmonics.size * self.n

    def samples(self, z: np.ndarray, omega: float) -> tuple[np.ndarray, np.ndarray]:
        """Displacements and velocities of the ``dofs`` at the AFT instants, shape (N, len(dofs)) each."""
        h = self.harmonics
        return h.motion(z, self.n, omega)

    def with_forces(self, forces: tuple) -> CondensedProblem:
        """This problem with other nonlinear forces on the same DOFs: a family's member (the clearance's), sharing the
        checked linear part and the compliance of the last frequency asked (the forces leave both)."""
        new = copy.copy(self)
        object.__setattr__(new, "forces", tuple(forces))
        object.__setattr__(new, "_local_forces", local_forces(forces, self.dofs))
        object.__setattr__(new, "_cache", dict(self._cache))
        return new

    def _compliance(self, omega: float) -> _Compliance:
        """Every harmonic's compliance data at ``omega`` (kept for the last omega asked: Newton iterates there), from
        one batched solve of the dynamic stiffnesses ``Z_k = K - (k omega)^2 M + i k omega D(omega)``."""
        if self._cache.get("omega") == omega:
            return self._cache["harmonics"]
        F, dF = self.forcing(omega)
        n, H, c = self.M.shape[0], self.harmonics.H, list(self.dofs)
        k = np.arange(H + 1)[:, None, None]
        D = self.velocity_matrix(omega)
        Z = self.stiffness_matrix(omega) - (k * omega) ** 2 * self.M + 1j * k * omega * D
        dZ = (-2.0 * k * k * omega * self.M + 1j * k * D + (0.0 if self.D1 is None else 1j * k * omega * self.D1)
              + (0.0 if self.K1 is None else self.K1))
        f, df = (to_phasors(G.reshape(self.harmonics.size, n)) for G in (F, dF))
        X, Q = dynamic_compliance(Z, c, f)
        Y = dynamic_compliance(Z.transpose(0, 2, 1), c)[0].transpose(0, 2, 1)  # (Z^-1)[c, :]
        out = _Compliance(H_cc=X[:, c], dH_cc=-Y @ dZ @ X, q_lin=Q[:, c],
                          dq_lin=(Y @ (df - (dZ @ Q[:, :, None])[:, :, 0])[:, :, None])[:, :, 0], Q_full=Q, X=X)
        self._cache.clear()
        self._cache.update(omega=omega, harmonics=out)
        return out

    def compliance_blocks(self, omega: float):
        """G(omega): the real block-diagonal form of (Z_k^-1)_cc over the harmonics, as blocks (:meth:`apply`)."""
        return self._blocks(omega)[0]

    def linear_response(self, omega: float) -> np.ndarray:
        """The coefficients of the ``dofs`` without the nonlinear forces."""
        return self._blocks(omega)[2]

    def evaluate(self, z: np.ndarray, omega: float) -> Evaluation:
        """The condensed residual at ``(z, omega)``, and its analytic derivatives on first use (:class:`Evaluation`).
        G is applied block by block (one block a harmonic), and ``T(df/dv) (nabla (x) I)`` as a permutation of
        columns: no dense product of size^3."""
        G, dG, z_lin, dz_lin = self._blocks(omega)
        q, v = self.samples(z, omega)
        h, m = self.harmonics, self.n
        f, dq, dv = sampled_forces(self._local_forces, q, v)
        F_nl = h.coefficients(f)

        def jacobian():
            factors = low_rank(h, dq, dv, omega, max_rank=self.size // 2)
            if factors is not None:  # I + G U V^T, solved by Woodbury
                transposed = (G[0].T, G[1].transpose(0, 2, 1))
                GU = factors.U.after(lambda X: self.apply(G, X), lambda X: self.apply(transposed, X))
                return IdentityPlusLowRank(GU, factors.V, factors.coupling(self._compliance(omega).H_cc))
            return np.eye(self.size) + self.apply(G, h.toeplitz(dq) + omega * h.times_derivative(h.toeplitz(dv), m))

        def parameter():
            dF_domega = h.coefficients(np.einsum("jab,jb->ja", dv, h.rates(z, m)))  # T(dv) (nabla (x) I) z
            return -dz_lin + self.apply(dG, F_nl) + self.apply(G, dF_domega)
        return Evaluation(z - z_lin + self.apply(G, F_nl), float(np.linalg.norm(z_lin)) or 1.0, jacobian, parameter,
                          sampled=(f, dq, dv))

    def apply(self, blocks, X: np.ndarray) -> np.ndarray:
        """``G X`` for G given by its blocks (:meth:`_blocks`): the m x m block of harmonic 0 and the (2m x 2m) ones of
        harmonics 1..H, on the harmonic-major rows of X (a vector or a matrix)."""
        G0, Gk = blocks
        m, H = self.n, self.harmonics.H
        X2 = X.reshape(self.size, -1)
        out = np.empty_like(X2)
        out[:m] = G0 @ X2[:m]
        out[m:] = np.matmul(Gk, X2[m:].reshape(H, 2 * m, -1)).reshape(H * 2 * m, -1)
        return out.reshape(X.shape)

    def _blocks(self, omega: float):
        """G and dG/domega as blocks, z_lin and dz_lin/domega, at ``omega`` (cached with the compliance)."""
        parts = self._compliance(omega)
        if "blocks" not in self._cache:
            self._cache["blocks"] = self._real_blocks(parts)
        return self._cache["blocks"]

    def _real_blocks(self, parts: _Compliance):
        """G, dG/domega as blocks (the real form [[Re H, Im H], [-Im H, Re H]] per harmonic) and z_lin, dz_lin/domega
        (harmonic-major) from the harmonics."""
        return ((parts.H_cc[0].real, real_form(parts.H_cc[1:])), (parts.dH_cc[0].real, real_form(parts.dH_cc[1:])),
                from_phasors(parts.q_lin).reshape(-1), from_phasors(parts.dq_lin).reshape(-1))

    @property
    def force_columns(self) -> list:
        """Each nonlinear force with the columns of its DOFs among the unknowns."""
        return list(self._local_forces)

    def velocity_matrix(self, omega: float) -> np.ndarray:
        """D(omega) = D + omega D1 (N s/m)."""
        return self.D if self.D1 is None else self.D + omega * self.D1

    def stiffness_matrix(self, omega: float) -> np.ndarray:
        """K(omega) = K + omega K1 (N/m)."""
        return self.K if self.K1 is None else self.K + omega * self.K1

    def recover(self, z: np.ndarray, omega: float) -> np.ndarray:
        """The harmonic-major coefficients of every DOF, shape ((2H + 1) n_all,), from the solution ``z``."""
        parts = self._compliance(omega)
        q, v = self.samples(z, omega)  # the forces only: no Toeplitz matrices
        F_nl = force_coefficients(self.harmonics, self._local_forces, q, v).reshape(self.harmonics.size, self.n)
        Q = parts.Q_full - (parts.X @ to_phasors(F_nl)[:, :, None])[:, :, 0]
        return from_phasors(Q).reshape(-1)


@dataclass(frozen=True)
class ClearanceFamily:
    """A :class:`CondensedProblem` at a fixed frequency, parameterised by the clearance of one of its rubs: the
    problem :func:`rotorred.nonlinear.continuation.continue_branch` follows in the clearance (the parameter takes the
    place of omega; ``dR/dclearance = G dF_nl/dclearance``, the forces' derivative by the DOF the clearance enters the
    gap with, ``PlateRub.clearance_dof``).

    Parameters
    ----------
    base : CondensedProblem
    omega : float
        The base frequency (rad/s).
    rub : int
        Index in ``base.forces`` of the rub (a force with ``with_clearance`` and ``clearance_dof``).
    """

    base: CondensedProblem
    omega: float
    rub: int = 0
    #: the continuation parameter's name and unit, for messages
    parameter = ("clearance", "m")

    @property
    def n(self) -> int:
        return self.base.n

    @property
    def size(self) -> int:
        return self.base.size

    @property
    def harmonics(self) -> Harmonics:
        return self.base.harmonics

    def at(self, clearance: float) -> CondensedProblem:
        """The problem at ``clearance`` (m), sharing the base's compliance at ``omega`` (the clearance leaves it)."""
        forces = list(self.base.forces)
        forces[self.rub] = forces[self.rub].with_clearance(clearance)
        self.base._blocks(self.omega)  # computed once, shared by every member
        return self.base.with_forces(forces)

    def samples(self, z: np.ndarray, clearance: float):
        return self.base.samples(z, self.omega)

    def linear_response(self, clearance: float) -> np.ndarray:
        return self.base.linear_response(self.omega)

    def evaluate(self, z: np.ndarray, clearance: float) -> Evaluation:
        ev = self.at(clearance).evaluate(z, self.omega)

        def dR_dclearance():  # G dF_nl/dclearance: the forces' derivative by the DOF the clearance enters the gap with
            rub, idx = self.base._local_forces[self.rub]
            dq = ev.sampled[1][:, :, idx[rub.clearance_dof]]
            return self.base.apply(self.base.compliance_blocks(self.omega), self.harmonics.coefficients(dq))
        return ev.with_parameter(dR_dclearance)
