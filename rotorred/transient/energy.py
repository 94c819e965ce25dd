"""Energy balance of a transient, from its recorded state: the work the drive must do to follow the speeds.

With the spin angle ``psi_s`` of each spool as a coordinate whose speed ``Omega_s`` is prescribed,
the kinetic energy of the lateral motion and its coupling to the spin is
``T = 1/2 q'^T M q' + sum_s Omega_s q'^T K_G,s q`` (+ the rigid spin ``1/2 J_s Omega_s^2``, whose
change the drive supplies exactly and which is left out of both sides). Lagrange's equation
of ``psi_s`` gives the torque the drive applies beyond ``J_s Omega_s'``,
``tau_s = d/dt (q'^T K_G,s q)``, and the unbalance forces do the work ``q'^T F_u`` that the drive
supplies through the eccentric masses. The energy ``E = T + 1/2 q^T K q`` then obeys
(docs/model.md, Eq. R5)

    E(t) - E(0) = W_drive - W_damping - W_internal + W_circulatory + W_gravity + W_contact,
    W_drive = int q'^T F_u dt + sum_s int Omega_s d(q'^T K_G,s q),
    W_damping = int q'^T C q' dt,  W_gravity = int q'^T F_g dt,  W_contact = int q'^T B f dt,

and, with internal (rotating) damping (docs/model.md §19: the damping C_r,s and the circulatory stiffness
-Omega_s N_s of each spool in the fixed frame), W_internal = int q'^T (sum_s C_r,s) q' dt dissipated by it and
W_circulatory = int q'^T (sum_s Omega_s N_s) q dt, the work of its circulatory force (what the drive feeds the
whirl through the internal damping: positive where a forward whirl is slower than the spin),

every integral evaluated from the records with the trapezoidal rule in ``q`` (``sum f_avg . dq``),
the rule of the average-acceleration step. The residual is that of the quadrature: second
order in the record interval.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotorred import checks
from rotorred.model.assembly import system_of
from rotorred.model.operating import Operating
from rotorred.model.speeds import SpeedProfile
from rotorred.results import Result
from rotorred.transient.matrices import contact_rows, force_columns
from rotorred.transient.options import Loads
from rotorred.transient.ramp import forces_at, profile_table
from rotorred.transient.stepping import operating_speeds


@dataclass(frozen=True, repr=False)
class EnergyBalance(Result):
    """Energies and works of a transient at its record times (J), each shape (n_rec,), from 0 at t = 0.

    Attributes
    ----------
    t : ndarray
        Record times (s).
    energy : ndarray
        ``E(t) - E(0)``: kinetic (with the spin coupling) plus strain energy.
    drive, damping, gravity, contact : ndarray
        ``W_drive`` (unbalances and spin coupling), ``W_damping`` (dissipated, >= 0 for C >= 0), the work
        of gravity and of the contact forces on the rotor.
    internal, circulatory : ndarray
        With internal damping (docs/model.md §19): ``W_internal``, dissipated by its fixed-frame damping
        (>= 0), and ``W_circulatory``, the work of its circulatory force; zero without.
    """

    t: np.ndarray
    energy: np.ndarray
    drive: np.ndarray
    damping: np.ndarray
    gravity: np.ndarray
    contact: np.ndarray
    internal: np.ndarray | None = None
    circulatory: np.ndarray | None = None

    def __post_init__(self):
        for name in ("internal", "circulatory"):
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.zeros_like(self.t, dtype=float))

    @property
    def residual(self) -> np.ndarray:
        """``E - E0 - (W_drive - W_damping - W_internal + W_circulatory + W_gravity + W_contact)`` (J)."""
        return self.energy - (self.drive - self.damping - self.internal + self.circulatory + self.gravity
                              + self.contact)

    @property
    def relative_residual(self) -> float:
        """Largest ``|residual|`` over the largest of ``|W_drive|``, W_damping and ``|E - E0|`` (-)."""
        scale = max(np.max(np.abs(self.drive)), np.max(np.abs(self.damping)), np.max(np.abs(self.energy)))
        return float(np.max(np.abs(self.residual)) / scale) if scale > 0 else 0.0

    def summary(self) -> list[str]:
        """The span, the final energy and works, and the residual of the balance."""
        lines = [f"{len(self.t)} records, t = {self.t[0]:.6g}-{self.t[-1]:.6g} s",
                 f"at the end: E - E0 = {self.energy[-1]:.4g} J, W_drive = {self.drive[-1]:.4g} J, "
                 f"W_damping = {self.damping[-1]:.4g} J"]
        others = [f"{name} = {w[-1]:.4g} J" for name, w in (("W_gravity", self.gravity), ("W_contact", self.contact),
                                                              ("W_internal", self.internal),
                                                              ("W_circulatory", self.circulatory)) if np.any(w != 0)]
        if others:
            lines.append("at the end: " + ", ".join(others))
        lines.append(f"residual: largest {np.max(np.abs(self.residual)):.3g} J, relative {self.relative_residual:.3g}")
        return lines

    def plot(self, ax=None, **options):
        """The terms of the balance (J) against time (s) (:func:`rotorred.plots.energy.draw_energy`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            ``title``, ``figsize`` (in).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.energy import draw_energy

        return draw_energy(self, ax, **options)

    def to_xarray(self):
        """The balance as an :class:`xarray.Dataset`: dimension ``time`` (coordinate, s); variables ``energy``,
        ``drive``, ``damping``, ``gravity``, ``contact``, ``internal``, ``circulatory`` and ``residual`` (J), as the
        attributes of the same names."""
        import xarray as xr

        terms = {"energy": "E - E0: kinetic (with the spin coupling) plus strain energy",
                 "drive": "work of the drive W_drive (unbalances and spin coupling)",
                 "damping": "energy dissipated by damping W_damping", "gravity": "work of gravity W_gravity",
                 "contact": "work of the contact forces W_contact",
                 "internal": "energy dissipated by internal (rotating) damping W_internal",
                 "circulatory": "work of internal damping's circulatory force W_circulatory",
                 "residual": "E - E0 - (W_drive - W_damping - W_internal + W_circulatory + W_gravity + W_contact)"}
        return xr.Dataset({name: ("time", getattr(self, name), {"units": "J", "long_name": text})
                           for name, text in terms.items()},
                          {"time": ("time", self.t, {"units": "s", "long_name": "record time"})},
                          attrs={"title": "energy balance of a transient",
                                 "relative_residual": self.relative_residual})


def _trapezoid_work(force: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Cumulative ``sum_k (f_k + f_k+1)/2 . (q_k+1 - q_k)`` for rows of ``force`` and ``q``, from 0."""
    inc = np.einsum("ij,ij->i", 0.5 * (force[1:] + force[:-1]), np.diff(q, axis=0))
    return np.concatenate([[0.0], np.cumsum(inc)])


def energy_balance(model, result, operating: Operating, loads: Loads = Loads()) -> EnergyBalance:
    """The energy balance (Eq. R5) of ``result``, a :func:`~rotorred.transient.newmark.simulate` run with
    ``recording=Recording(states=True)`` and the same model, operating condition and loads.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        As given to ``simulate`` (:func:`rotorred.model.assembly.system_of`).
    result : TransientResult
        Recorded with ``Recording(states=True)`` (every step, ``decimate = 1``, for the step's own quadrature).
    operating : Operating
        As given to ``simulate``: a point or a profile, every spool's speed by its ratio rule.
    loads : Loads
        As given to ``simulate``: the unbalances and gravity.

    Returns
    -------
    EnergyBalance

    Raises
    ------
    InputError
        If ``result`` has no recorded states.
    """
    if result.states is None:
        checks.fail("result.states", None, "must be recorded: run simulate(..., recording=Recording(states=True))")
    model = system_of(model)
    speeds, profile = operating_speeds(model, operating)
    profile = profile or SpeedProfile.constant(speeds)
    unbalances, gravity, spool_of = loads.unbalances, loads.gravity, model.spool_of
    n = model.M.shape[0]
    q, v = result.states[:, :n], result.states[:, n:]
    spools = model.spools
    unit = force_columns(model, {s: 1.0 for s in spools}, spool_of, unbalances, gravity)
    F = forces_at(unit, profile_table(profile, spools, unit), result.t)  # (n_rec, n)
    gravity_columns = [j for j, s in enumerate(unit.spool) if s is None]
    F_g = unit.F[:, gravity_columns].sum(axis=1) if gravity_columns else np.zeros(n)
    F_u = F - F_g
    K_G = {s: np.asarray(model.K_G.get(s, np.zeros((n, n))), float) for s in spools}
    W = profile.speed(result.t)
    # bearing tables sit on spools of constant speed (a run-up of their spool is refused): K, C at the first speeds
    first = {s: float(W[s][0]) for s in spools}
    C_r, K_c = model.rotating_damping(first)  # internal damping: its dissipation and circulatory work apart
    K, C = model.stiffness(first) - K_c, model.dissipation(first) - C_r
    N = {s: r.at(model.loss_frequency)[1] for s, r in model.rotating.items()}
    circulatory = sum((W[s][:, None] * (q @ N_s.T) for s, N_s in N.items()), np.zeros_like(q))
    coupling = {s: np.einsum("ij,ij->i", v, q @ K_G[s].T) for s in spools}  # q'^T K_G,s q
    energy = (0.5 * np.einsum("ij,ij->i", v @ model.M, v) + 0.5 * np.einsum("ij,ij->i", q @ K, q)
              + sum(W[s] * coupling[s] for s in spools))
    spin = sum(np.concatenate([[0.0], np.cumsum(0.5 * (W[s][1:] + W[s][:-1]) * np.diff(coupling[s]))])
               for s in spools)
    f_contact = np.zeros_like(q)
    if result.contacts:
        B = contact_rows(model, [c.plate for c in result.contacts])
        f_contact = np.column_stack([c.force_xy for c in result.contacts]) @ B.T
    return EnergyBalance(t=result.t, energy=energy - energy[0], drive=_trapezoid_work(F_u, q) + spin,
                         damping=_trapezoid_work(v @ C.T, q),
                         gravity=_trapezoid_work(np.broadcast_to(F_g, q.shape), q),
                         contact=_trapezoid_work(f_contact, q), internal=_trapezoid_work(v @ C_r.T, q),
                         circulatory=_trapezoid_work(circulatory, q))
