"""Harmonic balance of a rub scene: the periodic response of the (reduced) rotor with its rub plates at commensurate
spool speeds (docs/model.md §15).

The base frequency is ``f_0 = gcd(f_L, f_H)`` (10 Hz at the paper's 70/90 Hz): every spool's unbalance force is a
harmonic ``k_s = f_s / f_0`` of it, and so is every combination line ``m f_H + n f_L``. The linear system is the
scene's model (M, K at the speeds, C + sum_s Omega_s G_s) with two DOFs per plate (its rigid motion, ``m_p``,
``c_n``, ``c_t``, ``k_n``, ``k_t``); the unknowns are the Fourier coefficients of each rub disk's x, y and its plate's
u_n, u_t (:class:`rotorred.nonlinear.condensed.CondensedProblem`), the forces the paper's law
(:class:`rotorred.nonlinear.forces.PlateRub`). Every DOF's response is recovered from the solution.

Speeds without such an f_0 (no common period of at most 10 s: :func:`common_frequency`, the one rule) have a
quasi-periodic response: a scene's harmonic balance there solves the torus (:mod:`rotorred.scenes.torus_response`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from rotorred import checks
from rotorred.linear.harmonic import unbalance_forces
from rotorred.nonlinear.condensed import CondensedProblem
from rotorred.nonlinear.forces import PlateRub
from rotorred.nonlinear.fourier import Harmonics, basis

__all__ = ["RubProblem", "rub_problem", "base_frequency", "common_frequency", "contact_history", "augmented_matrices", "own_coordinate", "plate_rubs",
           "unknown_records"]


#: the longest common period of the spool speeds a periodic harmonic balance solves (s): f_0 >= 1 / 10 s
LONGEST_PERIOD = 10.0


def _fraction_gcd(frequencies_hz) -> float | None:
    """The greatest common divisor (Hz) of the frequencies, each read as a fraction with a denominator of at most 1000
    (within 1e-9 relative); None if one is no such fraction."""
    fractions = [Fraction(f).limit_denominator(1000) for f in frequencies_hz]
    if any(abs(float(fr) - f) > 1e-9 * abs(f) for f, fr in zip(frequencies_hz, fractions)):
        return None
    common = math.lcm(*(fr.denominator for fr in fractions))
    return math.gcd(*(int(fr * common) for fr in fractions)) / common


def common_frequency(frequencies_hz) -> float | None:
    """The base frequency f_0 (Hz) of a periodic response at the spool frequencies ``frequencies_hz`` (Hz): their
    greatest common divisor, each read as a fraction with a denominator of at most 1000 (within 1e-9 relative), if it
    is at least 1 / :data:`LONGEST_PERIOD` (a common period of at most 10 s); None otherwise (the speeds are
    incommensurate for harmonic balance: the response is quasi-periodic, on a torus,
    :func:`rotorred.scenes.quasi_periodic.torus_balance`)."""
    f0 = _fraction_gcd(frequencies_hz)
    return f0 if f0 is not None and f0 >= 1.0 / LONGEST_PERIOD else None


def base_frequency(frequencies_hz) -> float:
    """The base frequency f_0 (Hz) of :func:`common_frequency`; speeds without one are refused."""
    f0 = common_frequency(frequencies_hz)
    if f0 is None:
        gcd = _fraction_gcd(frequencies_hz)
        why = ("must be commensurate for a periodic harmonic balance" if gcd is None else
               f"must share a period of at most {LONGEST_PERIOD:g} s (their greatest common divisor is {gcd:.6g} Hz)")
        checks.fail("speeds", tuple(frequencies_hz), f"{why} (a quasi-periodic response: "
                    "rotorred.scenes.torus_balance.torus_rub_problem)", "Hz")
    return f0


@dataclass(frozen=True)
class RubProblem:
    """The harmonic-balance problem of a rub scene.

    Attributes
    ----------
    problem : CondensedProblem
    omega : float
        Base frequency 2 pi f_0 (rad/s).
    f0 : float
        Base frequency (Hz).
    n_model : int
        DOFs of the scene's model (the plates' DOFs follow them).
    model : SystemMatrices or ReducedSystem
    """

    problem: CondensedProblem
    omega: float
    f0: float
    n_model: int
    model: object

    def lines(self, z: np.ndarray, dof: tuple[int, str]) -> dict[float, float]:
        """Amplitude (m) of every harmonic k f_0 (Hz) of the model DOF ``dof`` = (node, direction) in the solution."""
        h = self.problem.harmonics
        y = self.coefficients(z, dof)
        out = {0.0: abs(y[0])}
        out.update({k * self.f0: math.hypot(y[2 * k - 1], y[2 * k]) for k in range(1, h.H + 1)})
        return out

    def coefficients(self, z: np.ndarray, dof: tuple[int, str]) -> np.ndarray:
        """The Fourier coefficients [a_0, a_1, b_1, ...] (m) of the model DOF ``dof`` = (node, direction)."""
        h = self.problem.harmonics
        coefficients = self.problem.recover(z, self.omega).reshape(h.size, -1)[:, :self.n_model]
        return coefficients @ self.model.output_rows([dof])[0]

    def waveform(self, z: np.ndarray, dof: tuple[int, str]) -> np.ndarray:
        """The model DOF ``dof`` over one period at the N AFT instants (m)."""
        return self.problem.harmonics.E @ self.coefficients(z, dof)

    def record(self, z: np.ndarray, t: np.ndarray, dofs) -> tuple[dict, tuple]:
        """The solution as a transient's record at the times ``t`` (s): each model DOF of ``dofs`` (m or rad), and a
        :class:`rotorred.transient.results.ContactHistory` per plate from the law at those instants (slip where the
        plate pushes, open elsewhere; stick is not modelled here, docs/model.md §15)."""
        h = self.problem.harmonics
        E = h.rows_at(self.omega * np.asarray(t, float))
        c = self.problem.recover(z, self.omega).reshape(h.size, -1)
        outputs = {d: E @ (c[:, :self.n_model] @ row) for d, row in zip(dofs, self.model.output_rows(list(dofs)))}
        v_c = self.omega * (h.nabla @ c)  # the coefficients of the velocities (d/dt)
        return outputs, tuple(contact_history(rub, E @ c[:, list(rub.dofs)], E @ v_c[:, list(rub.dofs)])
                              for rub in self.problem.forces)

    def final_state(self, z: np.ndarray):
        """The solution's state at t = 0 as a transient's start (:class:`rotorred.transient.results.FinalState`): the
        model's and the plates' displacements, velocities and accelerations from the Fourier series, the contact
        forces and slip directions of the law there. ``simulate(..., start=...)`` then runs on from the orbit."""
        from rotorred.transient.results import FinalState

        h, w = self.problem.harmonics, self.omega
        c = self.problem.recover(z, w).reshape(h.size, -1)
        k = np.arange(1, h.H + 1)[:, None]
        q = c[0] + c[1::2].sum(axis=0)
        v = w * (k * c[2::2]).sum(axis=0)
        a = -w * w * (k * k * c[1::2]).sum(axis=0)
        n, plates = self.n_model, len(self.problem.forces)
        plate = np.array([[[q[n + 2 * i + j], v[n + 2 * i + j], a[n + 2 * i + j]] for j in range(2)]
                          for i in range(plates)])
        forces, sgn = np.zeros((plates, 2)), np.zeros(plates)
        for i, rub in enumerate(self.problem.forces):
            f, _, _ = rub.evaluate(q[list(rub.dofs)][None, :], v[list(rub.dofs)][None, :])
            forces[i] = (-f[0, 2], f[0, 3])  # the force on (u_n, u_t) is (-P, T)
            sgn[i] = rub.slip_sign(v[list(rub.dofs)][None, :])[0] or 1.0
        return FinalState(0.0, q[:n], v[:n], a[:n], plate, forces, np.ones(plates, dtype=np.int64), sgn)

    def start_from_record(self, t: np.ndarray, records: dict) -> np.ndarray:
        """Coefficients of the unknowns fitted to a transient's settled record: ``records`` maps each unknown's
        position (0, 1, ... : disk x, disk y, plate u_n, plate u_t per plate) to its samples at ``t``, which must span
        whole periods 1 / f_0 at a constant step (the phase origin is t = 0, as the solution's).

        The fit is the DFT of the samples (the least-squares fit on uniform samples of whole periods), by the FFT:
        harmonic k of p periods is bin k p, turned to the phase origin by ``exp(-i k omega t_0)``."""
        h, m = self.problem.harmonics, self.problem.n
        t = np.asarray(t, float)
        n, p = len(t), self._periods(t)
        if h.H * p >= n / 2:
            checks.fail("t", f"{n} samples", f"must sample the {h.H} harmonics of f0 = {self.f0:g} Hz: more than "
                        f"{2 * h.H * p} over {p} period(s)")
        X = np.zeros((n, m))
        for j, x in records.items():
            X[:, j] = x
        k = np.arange(1, h.H + 1)
        S = np.fft.rfft(X, axis=0)[k * p] * np.exp(-1j * k * self.omega * t[0])[:, None]
        z = np.empty((h.size, m))
        z[0], z[1::2], z[2::2] = X.mean(axis=0), (2.0 / n) * S.real, (-2.0 / n) * S.imag
        return z.reshape(-1)

    def _periods(self, t: np.ndarray) -> int:
        """The whole periods 1 / f_0 that the samples ``t`` span at a constant step (an error naming ``t`` else)."""
        step = np.diff(t)
        if len(t) < 2 or np.ptp(step) > 1e-9 * abs(step[0]) or step[0] <= 0:
            checks.fail("t", f"{len(t)} samples", "must be at a constant step", "s")
        periods = len(t) * step[0] * self.f0
        if round(periods) < 1 or abs(periods - round(periods)) > 1e-6:
            checks.fail("t", f"{len(t)} samples of {step[0]:g} s", f"must span whole periods 1 / f0 = "
                        f"{1.0 / self.f0:g} s (spans {periods:.6g})", "s")
        return int(round(periods))


def rub_problem(scene, model, H: int, N: int, f0: float | None = None) -> RubProblem:
    """The harmonic-balance problem of ``scene`` (with rub plates) on ``model`` with ``H`` harmonics of the base
    frequency and ``N`` AFT samples a period.

    Parameters
    ----------
    scene : rotorred.scenes.schema.Scene
    model : SystemMatrices or ReducedSystem
        The scene's model (:func:`rotorred.scenes.run.build_model`); each rub node's x and y must be its own
        coordinates (a boundary node of a reduced model).
    H, N : int
    f0 : float, optional
        The base frequency (Hz), of which every spool frequency must be a whole multiple (to 1e-9); default their
        greatest common divisor (:func:`base_frequency`). A branch in speed at a fixed speed ratio keeps the orders.

    Returns
    -------
    RubProblem
    """
    if not scene.plates:
        checks.fail("rub", (), "must hold at least one plate: harmonic balance here is of the rub response")
    f = scene.frequencies_hz
    f0 = base_frequency(tuple(f.values())) if f0 is None else f0
    if any(abs(fs / f0 - round(fs / f0)) > 1e-9 * fs / f0 for fs in f.values()):
        checks.fail("f0", f0, f"must divide every spool frequency ({', '.join(f'{v:g}' for v in f.values())} Hz)", "Hz")
    h = basis(H, N)
    n = model.n_dof
    M, D, K = augmented_matrices(model, scene)
    dofs, forces = plate_rubs(model, scene)
    orders = {s: int(round(fs / f0)) for s, fs in f.items()}
    if any(k > H for k in orders.values()):
        checks.fail("H", H, f"must reach the spools' harmonics of f0 = {f0:g} Hz ({max(orders.values())})")
    phasors = unbalance_forces(model, scene.unbalances) if scene.unbalances else {}
    forcing = _forcing(h, n + 2 * len(scene.plates), phasors, orders)
    problem = CondensedProblem(M, D, K, h, dofs, forcing, forces)
    return RubProblem(problem, 2 * math.pi * f0, f0, n, model)


def contact_history(rub: PlateRub, q: np.ndarray, v: np.ndarray):
    """A balance's plate as a transient's :class:`rotorred.transient.results.ContactHistory`: the law of ``rub`` at
    the displacements ``q`` and velocities ``v`` of its unknowns (disk x, y, plate u_n, u_t; shape (n, 4), m and m/s)
    at n instants (slip where the plate pushes, open elsewhere; stick is not modelled here, docs/model.md §15)."""
    from rotorred.transient.contact import sliding_velocity
    from rotorred.transient.results import ContactHistory

    f, _, _ = rub.evaluate(q, v)
    P, T = -f[:, 2], f[:, 3]  # the force on (u_n, u_t) is (-P, T)
    plate = rub.plate
    return ContactHistory(plate, P, T, np.where(P > 0.0, 1, 0).astype(np.int8), q[:, 2], q[:, 3],
                          sliding_velocity(plate, rub.surface_speed, 1.0, v[:, 0], v[:, 1], v[:, 3]),
                          plate.clearance - q @ rub.gradient)


def augmented_matrices(model, scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, D, K of the model at the scene's speeds with two DOFs (u_n, u_t) for each plate."""
    n, p = model.n_dof, 2 * len(scene.plates)
    M, D, K = (np.zeros((n + p, n + p)) for _ in range(3))
    M[:n, :n], D[:n, :n], K[:n, :n] = model.M, model.damping(scene.speeds), model.stiffness(scene.speeds)
    for i, plate in enumerate(scene.plates):
        j = n + 2 * i
        M[j, j] = M[j + 1, j + 1] = plate.m_p
        D[j, j], D[j + 1, j + 1] = plate.c_n, plate.c_t
        K[j, j], K[j + 1, j + 1] = plate.k_n, plate.k_t
    return M, D, K


def plate_rubs(model, scene) -> tuple[tuple[int, ...], tuple[PlateRub, ...]]:
    """The unknowns (each plate's rub disk x, y and its u_n, u_t, numbered after the model's DOFs) and a
    :class:`PlateRub` for each plate, at its spool's rim speed."""
    n, dofs, forces = model.n_dof, [], []
    for i, plate in enumerate(scene.plates):
        x, y = (own_coordinate(model, (plate.node, d)) for d in ("x", "y"))
        spool = scene.rotor.spool_of[plate.node]
        rub = PlateRub((x, y, n + 2 * i, n + 2 * i + 1), plate, scene.speeds[spool] * (plate.disk_radius or 0.0))
        dofs += list(rub.dofs)
        forces.append(rub)
    return tuple(dofs), tuple(forces)


def unknown_records(plates, run) -> dict:
    """A run's records of the harmonic balance's unknowns, ``{position: samples}`` (each plate's disk x, y, u_n, u_t, as
    :func:`plate_rubs` numbers them): ``run`` is a transient's or a scene's result (``outputs`` holding each plate
    node's x and y, ``contacts`` each plate's history), for :meth:`RubProblem.start_from_record`."""
    records = {}
    for i, (plate, contact) in enumerate(zip(plates, run.contacts)):
        records.update({4 * i: run.outputs[(plate.node, "x")], 4 * i + 1: run.outputs[(plate.node, "y")],
                        4 * i + 2: contact.u_n, 4 * i + 3: contact.u_t})
    return records


def own_coordinate(model, dof) -> int:
    """The model coordinate that is ``dof`` itself (a unit output row), or an error naming the node."""
    row = model.output_rows([dof])[0]
    i = int(np.argmax(np.abs(row)))
    if row[i] != 1.0 or np.count_nonzero(row) != 1:
        checks.fail("rub.node", dof[0], "must be a node of the model's own coordinates (a boundary node of a "
                    "reduced model)")
    return i


def _forcing(h: Harmonics, n: int, phasors: dict, orders: dict):
    """forcing(omega): each spool's unbalance at its harmonic k_s of omega, F = Re((k_s omega)^2 F_s e^{i k_s omega t})."""
    def forcing(omega: float):
        F, dF = np.zeros((h.size, n)), np.zeros((h.size, n))
        for s, phasor in phasors.items():
            k = orders[s]
            F[2 * k - 1, :len(phasor)] = (k * omega) ** 2 * phasor.real
            F[2 * k, :len(phasor)] = -(k * omega) ** 2 * phasor.imag
            dF[2 * k - 1, :len(phasor)] = 2 * k * k * omega * phasor.real
            dF[2 * k, :len(phasor)] = -2 * k * k * omega * phasor.imag
        return F.reshape(-1), dF.reshape(-1)
    return forcing
