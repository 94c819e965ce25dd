"""Harmonic balance of the paper's rub (issue 20): the plate law in the AFT, and the rig at 70/90 Hz against the
transient (the independent reference: a Newmark run of the same model, settled)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotorred.checks import InputError
from rotorred.nonlinear.condensed import ClearanceFamily
from rotorred.nonlinear.forces import PlateRub
from rotorred.nonlinear.hb import solve_periodic
from rotorred.scenes.balance_harmonics import FROM_RECORD, cold_solution
from rotorred.scenes.harmonic_balance import base_frequency, rub_problem, unknown_records
from rotorred.scenes.run import build_model, run_scene, start_record
from rotorred.scenes.schema import load_scene
from rotorred.transient.contact import disk_force, normal_force, sliding_velocity
from rotorred.transient.newmark import Loads, Recording, simulate


@pytest.fixture(scope="module")
def paper_rub():
    scene = load_scene("paper-rub")
    return scene, build_model(scene)


def test_plate_rub_is_the_transients_law_at_every_sample(paper_rub):
    """At 64 random states of disk and plate, the sampled force equals the transient's scalar path sample by sample
    (normal_force, sliding_velocity, disk_force: the same generated law; measured 2.3e-15 relative, 45 samples in
    contact), and its analytic derivatives equal central differences (measured 3.6e-10 of the largest)."""
    scene, _ = paper_rub
    plate = scene.plates[0]
    Omega = scene.speeds["outer"]
    rub = PlateRub((0, 1, 2, 3), plate, Omega * plate.disk_radius)
    rng = np.random.default_rng(1)
    q = rng.normal(0, 1e-5, (64, 4)) + [0.0, 2e-5, 0.0, 0.0]
    v = rng.normal(0, 1e-2, (64, 4))
    f, dq, dv = rub.evaluate(q, v)
    n = plate.normal
    assert np.count_nonzero(f[:, 2]) > 20  # many samples in contact
    for j in range(64):
        P, _ = normal_force(q[j, :2] @ n - q[j, 2] - plate.clearance, v[j, :2] @ n - v[j, 2], plate)
        T = -plate.mu_d * math.copysign(1.0, sliding_velocity(plate, Omega, plate.disk_radius, *v[j, :2], v[j, 3])) * P
        Fx, Fy = disk_force(P, T, n[0], n[1])
        assert np.max(np.abs(f[j] - [-Fx, -Fy, -P, T])) <= 2.3e-14 * max(np.max(np.abs(f[j])), 1e-300)
    for d, x, eps in ((dq, q, 1e-11), (dv, v, 1e-8)):
        numeric = np.stack([(rub.evaluate(*((x + eps * e, v) if d is dq else (q, x + eps * e)))[0]
                             - rub.evaluate(*((x - eps * e, v) if d is dq else (q, x - eps * e)))[0]) / (2 * eps)
                            for e in np.eye(4)], axis=2)
        assert np.max(np.abs(numeric - d)) < 3.6e-9 * np.max(np.abs(d))


def test_the_base_frequency_is_the_spools_gcd():
    assert base_frequency((70.0, 90.0)) == 10.0 and base_frequency((70.0, 91.5)) == 0.5
    with pytest.raises(ValueError, match=r"greatest common divisor is 0\.01 Hz"):
        base_frequency((70.0, 91.37))


def test_clearance_derivative_is_analytic(paper_rub):
    """d R / d clearance of the condensed rig problem equals central differences in the clearance (measured 3.2e-11 of
    its largest entry at a step of 1e-10 m; 5.2e-9 at 1e-9 m, 2.6e-10 at 1e-11 m: the differences' own error)."""
    scene, sm = paper_rub
    rp = rub_problem(scene, sm.model, 20, 128)
    family = ClearanceFamily(rp.problem, rp.omega)
    z = 1.3 * rp.problem.linear_response(rp.omega)  # deeper in contact than the linear response
    ev = family.evaluate(z, 13e-6)
    eps = 1e-10
    numeric = (family.evaluate(z, 13e-6 + eps).R - family.evaluate(z, 13e-6 - eps).R) / (2 * eps)
    assert np.max(np.abs(numeric - ev.dR_domega)) < 3.2e-10 * np.max(np.abs(ev.dR_domega))


def test_the_rigs_jacobian_is_the_identity_plus_few_outer_products(paper_rub):
    """The condensed rig problem's Jacobian is I + G U V^T with one term a contact sample (the rub's derivative is rank
    one), solved by Woodbury; it equals the dense one built from the Toeplitz matrices (measured 3.4e-15 of its largest
    entry, H = 100, N = 2048, at 0.4 times the linear response: 199 of 2048 samples in contact; at 0.7 times, 611
    contact samples, more than half the 804 unknowns, it is the dense one)."""
    from rotorred.nonlinear.hb import sampled_forces
    from rotorred.nonlinear.lowrank import IdentityPlusLowRank

    scene, sm = paper_rub
    rp = rub_problem(scene, sm.model, 100, 2048)
    p, h, omega = rp.problem, rp.problem.harmonics, rp.omega
    assert not isinstance(p.evaluate(0.7 * p.linear_response(omega), omega).dR_dz, IdentityPlusLowRank)
    z = 0.4 * p.linear_response(omega)
    ev = p.evaluate(z, omega)
    q, v = p.samples(z, omega)
    _, dq, dv = sampled_forces(p.force_columns, q, v)
    contact = np.count_nonzero(np.abs(dq).sum(axis=(1, 2)))
    assert isinstance(ev.dR_dz, IdentityPlusLowRank) and ev.dR_dz.rank == contact < p.size // 2
    dense = np.eye(p.size) + p.apply(p.compliance_blocks(omega),
                                     h.toeplitz(dq) + omega * h.times_derivative(h.toeplitz(dv), p.n))
    assert np.max(np.abs(np.asarray(ev.dR_dz) - dense)) < 3.5e-14 * np.max(np.abs(dense))


def test_the_rigs_rub_response_equals_the_settled_transient(paper_rub):
    """paper-rub at 70/90 Hz: harmonic balance (100 harmonics of f_0 = 10 Hz, 2048 AFT samples) started from the
    settled transient's last period converges (3 Newton iterations) to the periodic orbit whose 10 largest lines at
    node 14 Y equal the transient's line fit within 1 % (measured 0.29 %; 60 harmonics leave 4.5 % at 330 Hz, 150
    harmonics 0.15 %: the impacts need the harmonics). Started from the solution (its state at t = 0), a transient
    is still on it 0.5 s later: its last period within 7.8e-4 of the solution's coefficients (measured)."""
    scene, sm = paper_rub
    result = run_scene(scene, sm, compare_normal=False)
    rp = rub_problem(scene, sm.model, 100, 2048)
    period = 1.0 / rp.f0
    window = result.t >= result.t[-1] - period + 1e-9  # the last period, whole
    records = unknown_records(scene.plates, result)
    z0 = rp.start_from_record(result.t[window], {j: x[window] for j, x in records.items()})
    solution = solve_periodic(rp.problem, z0, rp.omega)
    z, iterations = solution.z, solution.iterations
    lines = rp.lines(z, (14, "y"))
    largest = sorted(result.analyses[(14, "y")].fit.lines, key=lambda ln: -ln.amplitude)[:10]
    errors = [abs(lines[round(ln.frequency_hz, 6)] / ln.amplitude - 1) for ln in largest]
    assert iterations <= 5 and max(errors) < 1e-2, errors
    # the solution as a transient's start (RubProblem.final_state): 0.5 s later the transient is still on it
    again = simulate(sm.model, scene.operating, 0.5, scene.solver.dt, loads=Loads(scene.unbalances),
                     contacts=scene.plates, recording=Recording([(18, "x"), (18, "y")], start=0.4),
                     start=rp.final_state(z))
    window = again.t >= again.t[-1] - period + 1e-9
    records = unknown_records(scene.plates, again)
    settled = rp.start_from_record(again.t[window], {j: x[window] for j, x in records.items()})
    assert np.linalg.norm(settled - z) < 7.8e-3 * np.linalg.norm(z)
    # a scene's cold solution (Newton from a 5-period transient's last period) is this orbit (measured 4.5e-16)
    _, z_cold, how = cold_solution(scene, sm.model, 100, 2048, record=start_record(scene, sm.model))
    assert how == FROM_RECORD and np.linalg.norm(z_cold - z) < 1e-8 * np.linalg.norm(z)


def test_the_fit_of_a_record_is_the_dft_of_whole_periods(paper_rub):
    """RubProblem.start_from_record (by the FFT) equals the mean of x cos k theta and x sin k theta, twice, over the
    samples (the definition, written out) on one and on two whole periods of uniform samples starting off the phase
    origin (measured 2.7e-13 of the largest coefficient), and refuses a record that is not whole periods."""
    scene, sm = paper_rub
    rp = rub_problem(scene, sm.model, 100, 2048)
    h, rng = rp.problem.harmonics, np.random.default_rng(5)
    for periods, t0 in ((1, 0.4), (2, 0.0123)):
        t = t0 + 2e-5 * np.arange(1, 5000 * periods + 1)
        records = {j: rng.standard_normal(t.size) for j in range(4)}
        rows = h.rows_at(rp.omega * t)
        weights = np.full(h.size, 2.0 / t.size)
        weights[0] = 1.0 / t.size
        expected = np.column_stack([weights * (rows.T @ records[j]) for j in range(4)]).reshape(-1)
        got = rp.start_from_record(t, records)
        assert np.max(np.abs(got - expected)) < 2.7e-12 * np.max(np.abs(expected))
    with pytest.raises(InputError, match="whole periods"):
        rp.start_from_record(t[:-7], {j: x[:-7] for j, x in records.items()})
