"""Quasi-periodic harmonic balance of a rub scene: the response on a two-dimensional torus at incommensurate spool
speeds (docs/model.md §15).

The two base frequencies are the spools' or their sub-harmonics: near 88-95 Hz on the outer spool of ``paper-rub``
the impacts lock to ``f_H / 3``, and the torus is ``(f_L, f_H / 3)``. They come from the torus the signal layer finds
in a transient (:class:`rotorred.signals.linefit.Torus`: bases ``f_L / j`` and ``f_H / k``) or from the user. Each
spool's unbalance forces the order ``(k_1, k_2)`` of its frequency (``(j, 0)`` and ``(0, k)``), so both angles are
forced and the torus needs no phase condition. The linear system, the unknowns (each rub disk's x, y and its plate's
u_n, u_t) and the forces are those of the periodic problem (:func:`rotorred.scenes.harmonic_balance.rub_problem`);
the harmonic balance is :class:`rotorred.nonlinear.torus.TorusProblem`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotorred import checks
from rotorred.linear.harmonic import unbalance_forces
from rotorred.nonlinear.torus import TorusHarmonics, TorusProblem
from rotorred.scenes.harmonic_balance import augmented_matrices, plate_rubs
from rotorred.signals.linefit import Torus

__all__ = ["TorusRubProblem", "torus_rub_problem", "torus_rub_problem_on", "torus_bases"]

#: a spool frequency is an order of the bases when ``|k . f - f_s| <= ORDER_RTOL f_s``
ORDER_RTOL = 1e-9
#: where several orders hold a spool's frequency, the lowest is its order if the others are this many times higher
#: (|k_1| + |k_2|): a torus commensurate far out in its box (the response there periodic, of a long period, read on
#: the torus), not one commensurate at low orders (refused: a periodic harmonic balance)
LOWEST_MARGIN = 4


def torus_bases(torus) -> tuple[float, float]:
    """The base frequencies ``(f_1, f_2)`` (Hz) of a torus given as the signal layer's
    :class:`rotorred.signals.linefit.Torus` (``(f_L / j, f_H / k)``) or as two frequencies (Hz)."""
    if isinstance(torus, Torus):
        return torus.f_L / torus.j, torus.f_H / torus.k
    f = checks.sequence("torus", tuple(np.ravel(torus)), lambda name, v: checks.positive(name, v, "Hz"), min_len=2,
                        max_len=2)
    return float(f[0]), float(f[1])


def _spool_order(h: TorusHarmonics, bases: tuple[float, float], f_s: float) -> tuple[int, int]:
    """The order (k_1, k_2) of the truncated set whose frequency is ``f_s`` (Hz): the one order, or where several are
    (bases commensurate within the box: 91 Hz on (70, 91/3) Hz is 13:10, so (1, 0) and (12, -30) are both 70 Hz) the
    lowest, if every other is at least :data:`LOWEST_MARGIN` times higher (|k_1| + |k_2|); else an error."""
    f = h.frequencies(bases)
    hits = np.flatnonzero(np.abs(np.abs(f) - f_s) <= ORDER_RTOL * f_s)
    height = np.abs(h.orders[hits]).sum(axis=1)
    at = np.argsort(height, kind="stable")
    if hits.size == 0 or (hits.size > 1 and LOWEST_MARGIN * height[at[0]] > height[at[1]]):
        why = "is no order of the bases in the truncated set" if hits.size == 0 else \
            "is several orders: the bases are commensurate (a periodic harmonic balance)"
        checks.fail("torus", bases, f"must hold each spool frequency as one order k1 f1 + k2 f2; {f_s:.9g} Hz {why}",
                    "Hz")
    return tuple(int(k) for k in h.orders[hits[at[0]]])


@dataclass(frozen=True)
class TorusRubProblem:
    """The torus harmonic-balance problem of a rub scene.

    Attributes
    ----------
    problem : TorusProblem
    bases_hz : (float, float)
        Base frequencies (f_1, f_2) (Hz).
    spool_orders : dict of str to (int, int)
        The order of each spool's frequency.
    n_model : int
        DOFs of the scene's model (the plates' DOFs follow them).
    model : SystemMatrices or ReducedSystem
    """

    problem: TorusProblem
    bases_hz: tuple[float, float]
    spool_orders: dict
    n_model: int
    model: object

    def output_rows(self, dofs) -> np.ndarray:
        """The rows of the model DOFs ``dofs`` ((node, direction) each) on the problem's DOFs, the model's then the
        plates': shape (len(dofs), n_all), for :meth:`TorusProblem.recover`'s ``outputs``."""
        rows = np.zeros((len(dofs), self.problem.M.shape[0]))
        rows[:, :self.n_model] = self.model.output_rows(list(dofs))
        return rows

    def lines(self, z: np.ndarray, dof: tuple[int, str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every order's line at the model DOF ``dof`` = (node, direction): orders (K, 2), frequencies ``|k . f|``
        (Hz, shape (K,)) and amplitudes (m, shape (K,); the mean's absolute value for (0, 0))."""
        y = self.problem.recover(z, self.output_rows([dof]))[:, 0]
        h = self.problem.harmonics
        return h.orders, np.abs(h.frequencies(self.bases_hz)), np.abs(y)

    def amplitudes_at(self, z: np.ndarray, dof: tuple[int, str], frequencies_hz) -> np.ndarray:
        """The amplitude (m) of the line at each of ``frequencies_hz`` (each an order's frequency within 1e-9
        relative, else an error), at the model DOF ``dof``."""
        orders, f, a = self.lines(z, dof)
        out = []
        for target in np.ravel(frequencies_hz):
            hit = np.flatnonzero(np.abs(f - target) <= ORDER_RTOL * max(target, 1.0))
            if hit.size != 1:
                checks.fail("frequencies_hz", float(target), "must be the frequency of one order of the torus", "Hz")
            out.append(a[hit[0]])
        return np.array(out)

    def start_from_record(self, t: np.ndarray, records: dict, within: tuple[int, int] | None = None) -> np.ndarray:
        """Coefficients of the unknowns fitted by least squares to a transient's settled record: ``records`` maps each
        unknown's position (0, 1, ...: disk x, disk y, plate u_n, plate u_t per plate) to its samples at ``t`` (s, a
        uniform grid; phase origin t = 0, as the solution's). The record must resolve the orders' lines (at least
        2 / T apart: :meth:`rotorred.nonlinear.torus.TorusHarmonics.fit`); ``within = (h1, h2)`` fits only the orders
        of that smaller box (the rest start at 0)."""
        h, m = self.problem.harmonics, self.problem.n
        w = tuple(2 * math.pi * f for f in self.bases_hz)
        z = np.zeros((h.size, m))
        for j, x in records.items():
            z[:, checks.integer("records key", j, ge=0, le=m - 1)] = h.fit(np.asarray(t), np.asarray(x), w, within)
        return z.reshape(-1)


def _check_plates(scene) -> None:
    if not scene.plates:
        checks.fail("rub", (), "must hold at least one plate: harmonic balance here is of the rub response")


def torus_rub_problem(scene, model, torus, H1: int, H2: int, N1: int, N2: int,
                      f_max: float | None = None) -> TorusRubProblem:
    """The torus harmonic-balance problem of ``scene`` (with rub plates) on ``model``.

    Parameters
    ----------
    scene : rotorred.scenes.schema.Scene
    model : SystemMatrices or ReducedSystem
        The scene's model (:func:`rotorred.scenes.run.build_model`); each rub node's x and y must be its own
        coordinates.
    torus : rotorred.signals.linefit.Torus or (float, float)
        The torus the signal layer found (bases ``(f_L / j, f_H / k)``), or the base frequencies ``(f_1, f_2)`` (Hz).
    H1, H2 : int
        Largest orders ``|k_1|``, ``|k_2|`` of the box.
    N1, N2 : int
        AFT grid.
    f_max : float, optional
        Keep only the orders whose line is at most ``f_max`` (Hz) (a band in the box).

    Returns
    -------
    TorusRubProblem
    """
    _check_plates(scene)
    bases = torus_bases(torus)
    w_max = None if f_max is None else 2 * math.pi * checks.positive("f_max", f_max, "Hz")
    w = tuple(2 * math.pi * f for f in bases) if w_max else None
    return torus_rub_problem_on(scene, model, bases, TorusHarmonics(H1, H2, N1, N2, w_max, w))


def torus_rub_problem_on(scene, model, torus, harmonics: TorusHarmonics,
                         spool_orders: dict | None = None) -> TorusRubProblem:
    """The torus harmonic-balance problem of ``scene`` on ``model`` on the orders and grid ``harmonics``: a branch
    keeps its orders while the speeds move its bases (:func:`rotorred.scenes.torus_branch.continue_torus`).

    Parameters
    ----------
    scene : rotorred.scenes.schema.Scene
    model : SystemMatrices or ReducedSystem
        As :func:`torus_rub_problem`'s.
    torus : rotorred.signals.linefit.Torus or (float, float)
        The torus, or the base frequencies ``(f_1, f_2)`` (Hz).
    harmonics : TorusHarmonics
        The orders (each spool's frequency one of them) and the AFT grid.
    spool_orders : dict of str to (int, int), optional
        The order each spool forces, kept along a branch (where a speed makes the bases commensurate within the
        orders, several orders hold its frequency: the branch keeps the one it started on); default: the one order
        of ``harmonics`` at each spool's frequency (an error if none or several).

    Returns
    -------
    TorusRubProblem
    """
    _check_plates(scene)
    bases = torus_bases(torus)
    w = tuple(2 * math.pi * f for f in bases)
    h = harmonics
    n, p = model.n_dof, 2 * len(scene.plates)
    M, D, K = augmented_matrices(model, scene)
    dofs, forces = plate_rubs(model, scene)
    orders = dict(spool_orders) if spool_orders is not None else \
        {s: _spool_order(h, bases, f_s) for s, f_s in scene.frequencies_hz.items()}
    Q = np.zeros((h.n_orders, n + p), complex)
    phasors = unbalance_forces(model, scene.unbalances) if scene.unbalances else {}
    for s, phasor in phasors.items():  # F = Re(Omega_s^2 F_s e^{i Omega_s t}) at the spool's order
        Q[h.index(*orders[s]), :n] += scene.speeds[s] ** 2 * phasor
    problem = TorusProblem(M, D, K, h, w, dofs, h.from_phasors(Q), forces)
    return TorusRubProblem(problem, bases, orders, n, model)
