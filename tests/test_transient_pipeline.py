"""The named steps of rotorred.transient.newmark.simulate, each on its own: force columns and their fold onto
the step end, the condensed contact operator, the step matrices per level, the initial state, the record
plan, and one compiled step against the textbook Newmark update."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotorred.model.assembly import DofMap, SystemMatrices, assemble
from rotorred.model.elements import Bearing, Disk, Material, ShaftElement
from rotorred.model.loads import Unbalance
from rotorred.model.rotor import Rotor, Spool
from rotorred.transient import kernel
from rotorred.transient.status import RUNNING
from rotorred.transient.contact import RubPlate, disk_force
from rotorred.transient.matrices import (contact_rows, fold_forcing, force_columns, kernel_plates,
                                         newmark_coefficients, plate_parameters, scalar_step, step_levels,
                                         step_matrices)
from rotorred.transient.newmark import (Initial, Scheme, initial_state, initial_vector, record_buffers, record_plan,
                                        run_kernel)
from rotorred.transient.plate import ClampedFreePlate

STEEL = Material("steel", 2.1e11, 7850.0, 0.3)


def small_rotor() -> Rotor:
    """A damped 3-element shaft with a disk and two bearings (16 DOFs)."""
    spool = Spool("shaft", tuple(ShaftElement(i, i + 1, 0.15, 0.03, 0.0, STEEL) for i in range(1, 4)),
                  speed=2 * math.pi * 50)
    return Rotor(spools=(spool,), disks=(Disk(3, 4.0, 0.02, 0.04, radius=0.1),),
                 bearings=(Bearing(k_xx=1e7, k_yy=1.5e7, c_xx=200.0, c_yy=200.0, node=1),
                           Bearing(k_xx=1e7, k_yy=1.5e7, c_xx=200.0, c_yy=200.0, node=4)))


def jeffcott(m=2.0, k=4e5, c=30.0) -> SystemMatrices:
    M = np.diag([m, m, 0.01, 0.01])
    K = np.diag([k, 1.3 * k, 100.0, 100.0])
    G = np.zeros((4, 4))
    G[2, 3], G[3, 2] = 0.02, -0.02
    return SystemMatrices(M=M, K=K, C=np.diag([c, c, 0.0, 0.0]), G={"shaft": G}, dofs=DofMap((1,)))


def time_functions(kinds, omegas, t):
    return np.array([1.0 if k == 0 else (math.cos(w * t) if k == 1 else math.sin(w * t)) for k, w in zip(kinds, omegas)])


def test_fold_forcing_equals_the_start_and_end_terms():
    """U w(tb) from the fold equals U1 w(tb) + U0 w(tb - h) for a constant and two (cos, sin) pairs, at any tb."""
    rng = np.random.default_rng(0)
    kinds = np.array([0, 1, 2, 1, 2])
    omegas = np.array([0.0, 300.0, 300.0, 520.0, 520.0])
    U1, U0 = rng.standard_normal((6, 5)), rng.standard_normal((6, 5))
    h = 2e-4
    U = fold_forcing(U1, U0, kinds, omegas, h)
    for tb in (0.0, 0.0137, 1.234):
        ref = U1 @ time_functions(kinds, omegas, tb) + U0 @ time_functions(kinds, omegas, tb - h)
        # O(1) entries; the reference's cos(W (tb - h)) at W tb = 640 rad carries 640 eps = 1.4e-13 (measured
        # difference 1.0e-13 at tb = 1.234 s, 1e-16 at tb = 0)
        np.testing.assert_allclose(U @ time_functions(kinds, omegas, tb), ref, rtol=0, atol=1e-12)
    # the fold is not the identity: without the start term the result would differ by O(1)
    assert np.max(np.abs(U - U1 - U0)) > 0.1


def test_force_columns_rotate_with_each_unbalance():
    """The columns of two unbalances (with phases) at one node give m_e W^2 (cos, sin)(W t + phase) summed."""
    system = jeffcott()
    W = 2 * math.pi * 30
    unb = [Unbalance(1, 2e-4, 0.4), Unbalance(1, 1e-4, -1.1)]
    forces = force_columns(system, {"shaft": W}, {1: "shaft"}, unb, gravity=None)
    assert list(forces.kind) == [1, 2] and forces.F.shape == (4, 2)
    for t in (0.0, 0.011, 0.3):
        ref = sum(u.m_e * W**2 * np.array([math.cos(W * t + u.phase), math.sin(W * t + u.phase), 0, 0]) for u in unb)
        # forces of 8 N and W t up to 57 rad: measured difference 1.2e-14 N
        np.testing.assert_allclose(forces.at(t), ref, rtol=0, atol=1e-13)


def _direct_penetration_change(system, D, plates, z, h, gamma, beta, alpha, c3):
    """Change of penetration and of v_rel / c3 of each plate caused by the forces z, by a direct solve of the step:
    A dq = (1 + alpha) B f(z) with A = c0 M + (1 + alpha)(c3 D + K); each plate moves by (1 + alpha) (P, -T) / A_plate."""
    c0 = newmark_coefficients(h, gamma, beta)[0]
    A = c0 * system.M + (1 + alpha) * (c3 * D + system.K)
    B = contact_rows(system, plates)
    f = np.column_stack(disk_force(z[0::2], z[1::2], np.array([p.normal[0] for p in plates]),
                                   np.array([p.normal[1] for p in plates]))).ravel()
    dr = B.T @ np.linalg.solve(A, (1 + alpha) * (B @ f))
    dp, dv = [], []
    for k, p in enumerate(plates):
        inv_n = scalar_step(p.m_p, p.c_n, p.k_n, h, gamma, beta, alpha)[3]
        inv_t = scalar_step(p.m_p, p.c_t, p.k_t, h, gamma, beta, alpha)[3]
        drk = dr[2 * k:2 * k + 2]
        dp.append(drk @ p.normal - (1 + alpha) * z[2 * k] * inv_n)
        dv.append(drk @ p.tangent + (1 + alpha) * z[2 * k + 1] * inv_t)
    return np.array(dp), np.array(dv)


@pytest.mark.parametrize("method,alpha_given", [("newmark", None), ("hht", -0.2)])
def test_contact_operator_matches_a_direct_solve(method, alpha_given):
    """Jp z and Jv z (the condensed contact operator of every level) equal the penetration and sliding-velocity
    changes of a direct solve of the step with the forces z, for two coupled plates at two nodes."""
    rotor = small_rotor()
    system = assemble(rotor)
    speeds = {"shaft": 2 * math.pi * 50}
    D = system.damping(speeds)
    plates = [RubPlate(node=3, theta=0.3, m_p=0.7, k_n=3e6, k_t=2e6, c_n=50.0, c_t=80.0, disk_radius=0.1),
              RubPlate(node=2, theta=2.2, m_p=0.4, bending=ClampedFreePlate(a0=2e6, b0=1.0), disk_radius=0.05)]
    scheme = Scheme(method, alpha=alpha_given)
    B = contact_rows(system, plates)
    forces = force_columns(system, speeds, rotor.spool_of, (), None)
    levels = step_levels(system.M, D, system.K, B, forces, plates, 1e-4, scheme.gamma, scheme.beta, scheme.alpha, 3)
    z = np.array([40.0, -6.0, 15.0, 2.5])
    for level in range(3):
        h = 1e-4 / 2**level
        c3 = newmark_coefficients(h, scheme.gamma, scheme.beta)[3]
        dp, dv = _direct_penetration_change(system, D, plates, z, h, scheme.gamma, scheme.beta, scheme.alpha, c3)
        assert levels.coef[level, 7] == h and levels.coef[level, 6] == scheme.alpha
        # measured agreement 2e-16 to 1.4e-14 relative (the operator is built from A^-1, the reference solves A)
        np.testing.assert_allclose(levels.Jp[level] @ z, dp, rtol=1e-13)
        np.testing.assert_allclose(levels.Jv[level] @ z, dv, rtol=1e-13)
        assert np.all(np.abs(levels.Jp[level][0, 2:]) > 0)  # the plates are coupled through the rotor


def test_step_levels_shapes():
    """One set of matrices per level, history on (q, v) for Newmark and on (q, v, a) for HHT."""
    system = jeffcott()
    B = contact_rows(system, [])
    forces = force_columns(system, {"shaft": 10.0}, {1: "shaft"}, [Unbalance(1, 1e-4)], 9.81)
    for method, alpha, n_hist in (("newmark", None, 8), ("hht", -0.1, 12)):
        scheme = Scheme(method, alpha=alpha)
        lv = step_levels(system.M, system.damping({"shaft": 10.0}), system.K, B, forces, [], 1e-3,
                         scheme.gamma, scheme.beta, scheme.alpha, 4)
        assert lv.H.shape == (4, 4, n_hist) and lv.UF.shape == (4, 3, 4) and lv.Jp.shape == (4, 0, 0)
        np.testing.assert_array_equal(lv.coef[:, 7], 1e-3 / 2.0 ** np.arange(4))


def test_initial_state_satisfies_the_equation_of_motion():
    """a0 = M^-1 (F(0) + B f(0) - D v0 - K q0) with a plate pressed at t = 0 (its force from the law), and the
    plate's acceleration balances that force."""
    system = jeffcott()
    speeds = {"shaft": 2 * math.pi * 20}
    plate = RubPlate(node=1, theta=0.5, clearance=-2e-6, K_nr=1e9, disk_radius=0.05)
    q0, v0 = np.array([1e-6, 2e-6, 0.0, 0.0]), np.array([0.01, -0.02, 0.0, 0.0])
    forces = force_columns(system, speeds, {1: "shaft"}, [Unbalance(1, 1e-4, 0.3)], None)
    par, _ = plate_parameters([plate], speeds, {1: "shaft"}, None, 1e-10)
    B = contact_rows(system, [plate])
    D = system.damping(speeds)
    st = initial_state(system.M, D, system.K, B, par, [plate], forces, initial_vector(4, Initial(q0, v0)))
    P, T = st.z
    assert P > 0 and T == pytest.approx(-plate.mu_d * P)  # pressed, slipping along +t (v_rel > 0)
    f = np.array(disk_force(P, T, *plate.normal))
    residual = system.M @ st.x[8:] - (forces.at(0.0) + B @ f - D @ v0 - system.K @ q0)
    # forces of ~6 N: round-off of the solve is ~1e-15 N (measured 0: M is diagonal here)
    assert np.max(np.abs(residual)) < 1e-14
    assert st.ps[0, 0, 2] == pytest.approx(P / plate.m_p) and st.ps[0, 1, 2] == pytest.approx(-T / plate.m_p)


@pytest.mark.parametrize("t_end,dt,start,every", [(0.01, 1e-4, 0.005, 7), (0.01, 3e-4, 0.0, 1), (1.0, 1e-5, 0.3, 10),
                                                  (0.01, 1e-4, 0.01, 3)])
def test_record_plan_counts(t_end, dt, start, every):
    """The plan's step and record counts equal a brute-force enumeration of the recorded step indices."""
    plan = record_plan(t_end, dt, start, every)
    n_steps = math.ceil(t_end / dt - 1e-9)
    assert plan.n_steps == n_steps
    recorded = [j for j in range(n_steps + 1) if j * dt >= start - 1e-9 * dt and (j - plan.first) % every == 0]
    assert plan.first == recorded[0] and plan.n_records == len(recorded)


def test_record_plan_counts_at_many_steps():
    """A run of 60 s at dt = 1e-6 recorded from 59.7 s: in floating point 59.7 / 1e-6 = 59700000.00000001, a
    rounding error (1e-8 steps) above the old fixed slack of 1e-9 steps, which started the record one
    step late (300 000 samples where the time axis had 300 001; a run died writing its CSV). The counts
    are checked against exact decimal arithmetic."""
    from fractions import Fraction as F

    for t_end, dt, start in (("60", "1e-6", "59.7"), ("1000", "1e-5", "999.3"), ("0.3", "0.1", "0.1"),
                             ("1", "3e-4", "0.25")):
        plan = record_plan(float(t_end), float(dt), float(start), 1)
        n, first = F(t_end) / F(dt), F(start) / F(dt)
        assert plan.n_steps == math.ceil(n) and plan.first == math.ceil(first)
        assert plan.n_records == plan.n_steps - plan.first + 1


def test_one_compiled_step_is_the_newmark_step():
    """Two steps of the kernel (no contact) equal q1 = Hq q0 + Hv v0 + Ha a0 + A^-1 F(t1) from step_matrices,
    for HHT (the form with the acceleration kept) and Newmark (the acceleration eliminated)."""
    system = jeffcott()
    speeds = {"shaft": 2 * math.pi * 25}
    D = system.damping(speeds)
    forces = force_columns(system, speeds, {1: "shaft"}, [Unbalance(1, 3e-4, 0.7)], None)
    q0, v0 = np.array([1e-5, -2e-5, 1e-4, 0.0]), np.array([0.003, 0.001, 0.0, 0.02])
    h = 1e-3
    for method, alpha in (("newmark", None), ("hht", -0.15)):
        sch = Scheme(method, alpha=alpha)
        levels = step_levels(system.M, D, system.K, contact_rows(system, []), forces, [], h, sch.gamma, sch.beta,
                             sch.alpha, 1)
        state = initial_state(system.M, D, system.K, contact_rows(system, []), np.zeros((0, kernel.N_PLATE_PAR)), [],
                              forces, initial_vector(4, Initial(q0, v0)))
        x = state.x.copy()
        record = record_buffers(record_plan(2 * h, h, 0.0, 1), np.eye(4), 0)
        settings = kernel.Settings(t0=0.0, dt=h, n_halvings=0, newton_tol=1e-10, max_newton=10, limit=1.0)
        diag = kernel.Diagnostics(np.zeros(kernel.N_COUNTERS, dtype=np.int64), np.zeros(4))
        plates = kernel_plates(system.M, contact_rows(system, []), np.zeros((0, kernel.N_PLATE_PAR)), np.zeros(0))
        status, *_ = run_kernel(levels, kernel.Forcing(forces.kind, forces.omega), plates, state, record, settings,
                                  diag, 2, 1, False)
        assert status == RUNNING and diag.counters[kernel.C_STEPS] == 2
        Ainv, Hq, Hv, Ha = step_matrices(system.M, D, system.K, h, sch.gamma, sch.beta, sch.alpha)
        c = newmark_coefficients(h, sch.gamma, sch.beta)
        for step in (1, 2):
            q, v, a = x[:4], x[4:8], x[8:]
            F1, F0 = forces.at(step * h), forces.at((step - 1) * h)
            q1 = Hq @ q + Hv @ v + Ha @ a + Ainv @ ((1 + sch.alpha) * F1 - sch.alpha * F0)
            x = np.concatenate([q1, c[3] * (q1 - q) + c[4] * v + c[5] * a, c[0] * (q1 - q) - c[1] * v - c[2] * a])
            # displacements of 1e-4 m: the two forms' round-off differs by 4e-20 m (measured)
            np.testing.assert_allclose(record.y[step], q1, rtol=0, atol=5e-19)
        np.testing.assert_allclose(state.x[:8], x[:8], rtol=3e-14)  # measured 2.8e-15 relative (velocities)
