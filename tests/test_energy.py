"""The discrete energy balance of a rub run, and the contact law's dissipation (docs/model.md §4).

Average-acceleration Newmark satisfies, per step and exactly (up to round-off), the mean of the
equations of motion at both ends dotted with the step's displacement increment:

    dq . (M (v1 - v0) / h + D (v0 + v1) / 2 + K (q0 + q1) / 2) = dq . ((F0 + F1) / 2 + B (f0 + f1) / 2),

with dq = h (v0 + v1) / 2, i.e. change of kinetic + strain energy + viscous work = trapezoidal work of
the forces; likewise for each plate's rigid DOFs. The contact forces' work on disk and plate is
-P dp + T ds (p the penetration, s = r.t - u_t the lateral slip); the normal part stores the Hertz
energy 2/5 K_nr delta^2.5 and the bending energy lam P^2 / 2 and dissipates the rest,

    D = P p' - d/dt (2/5 K_nr delta^2.5 + lam P^2 / 2) = c K_nr delta^1.5 p' delta',   delta' = p' - lam P',

which is not c K_nr delta^1.5 p'^2 (the formula docs/model.md stated before) when the plate bends.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotorred.scenes.run import build_model, settled_state
from rotorred.scenes.schema import load_scene
from rotorred.transient import kernel
from rotorred.transient.status import RUNNING
from rotorred.transient.matrices import contact_rows, force_columns, kernel_plates, plate_parameters, step_levels
from rotorred.transient.newmark import (Initial, Scheme, initial_state, initial_vector, record_buffers, record_plan,
                                        run_kernel)


def full_state_run(model, scene, t_end: float, dt: float) -> dict:
    """The pipeline of :func:`rotorred.transient.newmark.simulate` (Newmark, average acceleration), recording
    q and v (all model DOFs), the contact forces and the plates' displacements after every step."""
    scheme = Scheme("newmark")
    n = model.M.shape[0]
    speeds, plates = scene.speeds, tuple(scene.plates)
    M, K, D = np.asarray(model.M, float), np.asarray(model.K, float), np.asarray(model.damping(speeds), float)
    forces = force_columns(model, speeds, scene.rotor.spool_of, scene.unbalances, None)
    par, atol = plate_parameters(plates, speeds, scene.rotor.spool_of, scene.rotor, 1e-10)
    B = contact_rows(model, plates)
    levels = step_levels(M, D, K, B, forces, plates, dt, scheme.gamma, scheme.beta, 0.0, 5)
    q0, v0 = settled_state(scene, model)
    x0 = initial_vector(n, Initial(q0, v0))
    state = initial_state(M, D, K, B, par, plates, forces, x0)
    plan = record_plan(t_end, dt, 0.0, 1)
    record = record_buffers(plan, np.eye(2 * n), len(plates))  # rows on x = (q, v, a): q and v
    settings = kernel.Settings(t0=0.0, dt=dt, n_halvings=4, newton_tol=1e-10, max_newton=50, limit=1.0)
    diag = kernel.Diagnostics(counters=np.zeros(kernel.N_COUNTERS, dtype=np.int64), err=np.zeros(4))
    status, *_ = run_kernel(levels, kernel.Forcing(forces.kind, forces.omega), kernel_plates(M, B, par, atol),
                              state, record, settings, diag, plan.n_steps, 100_000, False)
    assert status == RUNNING and diag.counters[kernel.C_SUBSTEPS] == 0  # main steps only
    return dict(M=M, K=K, D=D, B=B, forces=forces, plates=plates, t=record.t, q=record.y[:, :n], v=record.y[:, n:],
                plate=record.plate, state=record.state, dt=dt)


def energy_balance(run: dict) -> dict:
    """Every term of the discrete energy balance (J), summed over the run."""
    M, K, D, B, h = run["M"], run["K"], run["D"], run["B"], run["dt"]
    q, v, t = run["q"], run["v"], run["t"]
    dq = np.diff(q, axis=0)
    vm = 0.5 * (v[1:] + v[:-1])
    Fa = np.array([run["forces"].at(tt) for tt in t])
    terms = {"unbalance work": np.sum(dq * 0.5 * (Fa[1:] + Fa[:-1])),
             "rotor viscous": np.sum(dq * (vm @ D.T)),
             "kinetic and strain": 0.5 * (v[-1] @ M @ v[-1] + q[-1] @ K @ q[-1] - v[0] @ M @ v[0] - q[0] @ K @ q[0]),
             "plate viscous": 0.0, "contact normal": 0.0, "friction": 0.0, "contact elastic": 0.0}
    r = q @ B  # contact DOFs (x, y of each plate's node)
    for k, p in enumerate(run["plates"]):
        P, T = run["plate"][:, k, kernel.R_P], run["plate"][:, k, kernel.R_T]
        u = run["plate"][:, k, [kernel.R_UN, kernel.R_UT]]
        du = np.diff(u, axis=0)
        w = np.zeros_like(u)  # plate velocities by the scheme's own rule, from rest: w1 = 2 du / h - w0
        for j in range(len(du)):
            w[j + 1] = 2.0 * du[j] / h - w[j]
        wm = 0.5 * (w[1:] + w[:-1])
        terms["plate viscous"] += np.sum(du[:, 0] * p.c_n * wm[:, 0] + du[:, 1] * p.c_t * wm[:, 1])
        terms["kinetic and strain"] += (0.5 * p.m_p * (w[-1] @ w[-1] - w[0] @ w[0])
                                        + 0.5 * (p.k_n * (u[-1, 0] ** 2 - u[0, 0] ** 2)
                                                 + p.k_t * (u[-1, 1] ** 2 - u[0, 1] ** 2)))
        pen = r[:, 2 * k:2 * k + 2] @ p.normal - p.clearance - u[:, 0]
        slip = r[:, 2 * k:2 * k + 2] @ p.tangent - u[:, 1]
        Pm, Tm = 0.5 * (P[1:] + P[:-1]), 0.5 * (T[1:] + T[:-1])
        terms["friction"] += -np.sum(Tm * np.diff(slip))  # the lateral motion's share of the friction work
        U = contact_elastic_energy(P, pen, p)
        terms["contact elastic"] += U[-1] - U[0]
        terms["contact normal"] += np.sum(Pm * np.diff(pen)) - (U[-1] - U[0])  # dissipated by the law
    return terms


def contact_elastic_energy(P, pen, plate) -> np.ndarray:
    """2/5 K_nr delta^2.5 + lam P^2 / 2 (J) with delta = max(0, p - w0 - lam P)."""
    lam = plate.compliance
    delta = np.maximum(0.0, pen - plate.offset - lam * P)
    return 0.4 * plate.K_nr * delta**2.5 + 0.5 * lam * P**2


@pytest.fixture(scope="module")
def rub_run():
    """0.1 s of paper-rub (reduced model, dt = 2e-5 s, from the settled state): 20 contacts of ~0.6 ms."""
    scene = load_scene("paper-rub")
    model = build_model(scene).model
    return full_state_run(model, scene, 0.1, 2e-5)


def test_discrete_energy_balance_closes(rub_run):
    """Unbalance work = rotor and plate viscous work + contact dissipation + friction work + change of kinetic
    and strain energy (contact elastic energy included), to 1e-9 of the unbalance work."""
    assert np.any(rub_run["state"] > 0) and not np.any(rub_run["state"] == 2)  # rubs, slips only (no stick reset)
    e = energy_balance(rub_run)
    supplied = e["unbalance work"]
    spent = (e["rotor viscous"] + e["plate viscous"] + e["contact normal"] + e["friction"] + e["kinetic and strain"]
             + e["contact elastic"])
    # measured 4.4e-13 of the unbalance work (round-off of 5000 steps); 1e-9 as the issue asks
    assert abs(supplied - spent) < 1e-9 * abs(supplied), (supplied - spent) / supplied
    assert e["contact normal"] > 0.0


def test_contact_dissipation_is_the_delta_rate_formula(rub_run):
    """The law dissipates c K_nr delta^1.5 p' delta' (delta' = p' - lam P'), not c K_nr delta^1.5 p'^2: the
    first, integrated along the run, matches the balance's contact dissipation; the second overstates it."""
    run = rub_run
    (plate,) = run["plates"]
    h = run["dt"]
    P = run["plate"][:, 0, kernel.R_P]
    r = run["q"] @ run["B"]
    u = run["plate"][:, 0, kernel.R_UN]
    pen = r @ plate.normal - plate.clearance - u
    pen_rate = (run["v"] @ run["B"]) @ plate.normal
    w = np.zeros_like(u)
    for j in range(len(u) - 1):
        w[j + 1] = 2.0 * (u[j + 1] - u[j]) / h - w[j]
    pen_rate = pen_rate - w
    delta = np.maximum(0.0, pen - plate.offset - plate.compliance * P)
    g = np.where(P > 0.0, plate.c * plate.K_nr * delta**1.5 * pen_rate, 0.0)
    corrected = np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(delta))  # int c K delta^1.5 p' d(delta)
    old = np.sum(0.5 * (g[1:] * pen_rate[1:] + g[:-1] * pen_rate[:-1]) * h)  # int c K delta^1.5 p'^2 dt
    balance = energy_balance(run)["contact normal"]
    # measured: corrected 8.6e-4 below the balance (trapezoidal quadrature over ~30-step contacts and their
    # edges), 1e-2 allowed; the old formula 36.5 % above it (42 % over 0-0.3 s), so 1.25 must fail for it
    assert abs(corrected - balance) < 1e-2 * balance, (corrected, balance)
    assert old > 1.25 * balance, (old, balance)

