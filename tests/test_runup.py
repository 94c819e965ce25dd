"""Transients at time-varying spool speeds (run-ups): against solve_ivp, against the classical passage
through resonance, against the constant-speed step, and the profile's own rules."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar
from scipy.special import fresnel

from rotorred.checks import InputError
from rotorred.linear.harmonic import unbalance_response
from rotorred.model.operating import Operating
from rotorred.model.assembly import DofMap, SystemMatrices
from rotorred.model.elements import Disk
from rotorred.model.loads import Unbalance
from rotorred.model.speeds import SpeedProfile
from rotorred.signals.orders import angle_blocks, order_tracks
from rotorred.transient import ramp_kernel
from rotorred.transient.energy import energy_balance
from rotorred.transient.newmark import Loads, Recording, Scheme, StepControl, simulate

# an overhung disk on a flexible support: x couples with theta_y, y with theta_x (N/m, N, N m)
MASS, I_D, I_P = 2.0, 0.02, 0.04
K_T, K_C, K_R = 2.0e5, 1.0e3, 2.0e3
C_T = 20.0
M_E = 1e-4  # unbalance (kg m)


def disk_rotor(c=C_T, k_c=K_C) -> SystemMatrices:
    """Four DOFs (x, y, theta_x, theta_y) of one node, with the disk's generated G and K_G; with k_c = 0 the
    translations are a Jeffcott rotor (a point mass on a massless shaft) and the tilts stay at rest."""
    disk = Disk(1, MASS, I_D, I_P)
    K = np.array([[K_T, 0, 0, k_c], [0, K_T, -k_c, 0], [0, -k_c, K_R, 0], [k_c, 0, 0, K_R]], float)
    C = np.diag([c, c, 0.0, 0.0])
    return SystemMatrices(M=disk.M(), K=K, C=C, G={"shaft": disk.G()}, dofs=DofMap((1,)), K_G={"shaft": disk.K_G()})


def hand_written_rhs(W0, alpha, c=C_T, k_c=K_C):
    """The same rotor's equations written out by hand, at Omega = W0 + alpha t (no generated matrix):

    m x'' + c x' + k x + k_c theta_y = m_e (Omega^2 cos phi + Omega' sin phi)
    m y'' + c y' + k y - k_c theta_x = m_e (Omega^2 sin phi - Omega' cos phi)
    I_d theta_x'' + I_p Omega theta_y' + I_p Omega' theta_y + k_r theta_x - k_c y = 0
    I_d theta_y'' - I_p Omega theta_x' + k_r theta_y + k_c x = 0

    with phi = W0 t + alpha t^2 / 2 (the disk's Lagrange equations with T_g = I_p Omega theta_x' theta_y).
    """
    def rhs(t, s):
        x, y, tx, ty, vx, vy, wx, wy = s
        W, phi = W0 + alpha * t, W0 * t + 0.5 * alpha * t * t
        fx = M_E * (W * W * math.cos(phi) + alpha * math.sin(phi))
        fy = M_E * (W * W * math.sin(phi) - alpha * math.cos(phi))
        return [vx, vy, wx, wy,
                (fx - c * vx - K_T * x - k_c * ty) / MASS,
                (fy - c * vy - K_T * y + k_c * tx) / MASS,
                (-I_P * W * wy - I_P * alpha * ty - K_R * tx + k_c * y) / I_D,
                (I_P * W * wx - K_R * ty - k_c * x) / I_D]

    def jac(t, s):
        W = W0 + alpha * t
        J = np.zeros((8, 8))
        J[:4, 4:] = np.eye(4)
        J[4, 4], J[4, 0], J[4, 3] = -c / MASS, -K_T / MASS, -k_c / MASS
        J[5, 5], J[5, 1], J[5, 2] = -c / MASS, -K_T / MASS, k_c / MASS
        J[6, 7], J[6, 3], J[6, 2], J[6, 1] = -I_P * W / I_D, -I_P * alpha / I_D, -K_R / I_D, k_c / I_D
        J[7, 6], J[7, 3], J[7, 0] = I_P * W / I_D, -K_R / I_D, -k_c / I_D
        return J

    return rhs, jac


@pytest.mark.parametrize("k_c", [0.0, K_C], ids=["jeffcott", "gyroscopic-disk"])
def test_run_up_through_the_critical_matches_solve_ivp(k_c):
    """Through the first critical speed (about 316 rad/s) at 400 rad/s^2 from 240 rad/s, from rest: every
    DOF against Radau (rtol 1e-10, atol 1e-16) of the hand-written equations, which share no code with
    the model (G and K_G here are the generated disk matrices). k_c = 0: the Jeffcott rotor (x, y; the
    tilts stay exactly at rest); k_c > 0: the disk's tilts couple in, with the gyroscopic and K_G terms.

    Measured: 6.2e-6 to 8.0e-6 of each DOF's peak with dt = 5e-6 s, 1.5e-6 to 2.0e-6 with 2.5e-6 s, an
    observed order of 2.00 (average acceleration is second order); the Jeffcott rotor alone 6.2e-6 and 1.55e-6. Asserted: 2e-5 at 2.5e-6 s (10x the
    measured; the issue asks 1e-4) and the order within 0.1 of 2."""
    W0, alpha, t_end = 240.0, 400.0, 0.45
    profile = SpeedProfile.ramp({"shaft": W0}, {"shaft": W0 + alpha * t_end}, t_end)
    outputs = [(1, d) for d in ("x", "y", "theta_x", "theta_y")]
    runs = [simulate(disk_rotor(k_c=k_c), Operating.profile(profile), t_end, dt, loads=Loads([Unbalance(1, M_E)]),
                     recording=Recording(outputs, decimate=decimate), control=StepControl(progress=False))
            for dt, decimate in ((5e-6, 20), (2.5e-6, 40))]
    np.testing.assert_allclose(runs[0].t, runs[1].t, rtol=0, atol=1e-12)
    rhs, jac = hand_written_rhs(W0, alpha, k_c=k_c)
    ref = solve_ivp(rhs, (0.0, t_end), np.zeros(8), method="Radau", rtol=1e-10, atol=1e-16, jac=jac, t_eval=runs[0].t)
    assert ref.success
    if k_c == 0.0:
        assert not np.any(runs[1].outputs[(1, "theta_x")]) and not np.any(runs[1].outputs[(1, "theta_y")])
        outputs = outputs[:2]
    for j, o in enumerate(outputs):
        peak = np.max(np.abs(ref.y[j]))
        coarse, fine = (np.max(np.abs(r.outputs[o] - ref.y[j])) / peak for r in runs)
        assert fine < 2e-5, (o, fine)
        assert abs(math.log2(coarse / fine) - 2.0) < 0.1, (o, coarse, fine)
    # the run crossed the critical speed: the peak is resonant, well above the static deflection m_e/m
    assert np.max(np.abs(ref.y[0])) > 10 * M_E / MASS


def cornu_peak() -> tuple[float, float]:
    """(u*, |F(u*)|): the largest distance of the Cornu spiral from its start,
    ``F(u) = int_-inf^u exp(i pi s^2 / 2) ds = C(u) + 1/2 + i (S(u) + 1/2)``."""
    def minus_dist(u):
        S, C = fresnel(u)
        return -math.hypot(C + 0.5, S + 0.5)
    opt = minimize_scalar(minus_dist, bounds=(0.5, 2.0), method="bounded", options={"xatol": 1e-12})
    return float(opt.x), float(-opt.fun)


@pytest.fixture(scope="module")
def passages():
    """An undamped Jeffcott rotor (omega = 100 rad/s) run up through its critical speed at rates
    lambda = Omega' / omega^2 of 1/400, 1/1600, 1/6400: peak amplitude and the speed at the peak
    (dt = 1e-4 s: Newmark's period error (omega dt)^2 / 12 = 8e-6 is below the speed errors)."""
    omega = 100.0
    K = np.diag([omega**2, omega**2, 1.0, 1.0])
    model = SystemMatrices(M=np.eye(4), K=K, C=np.zeros((4, 4)), G={"shaft": np.zeros((4, 4))}, dofs=DofMap((1,)),
                           K_G={"shaft": np.zeros((4, 4))})
    out = []
    for lam in (1 / 400, 1 / 1600, 1 / 6400):
        alpha = lam * omega**2
        t_end = (omega + 10 * math.sqrt(alpha)) / alpha
        profile = SpeedProfile.ramp({"shaft": 0.0}, {"shaft": alpha * t_end}, t_end)
        res = simulate(model, Operating.profile(profile), t_end, 1e-4, loads=Loads([Unbalance(1, 1.0)]),
                       recording=Recording([(1, "x"), (1, "y")]), control=StepControl(progress=False))
        r = np.hypot(res.outputs[(1, "x")], res.outputs[(1, "y")])
        k = int(np.argmax(r))
        out.append((lam, alpha, r[k], alpha * res.t[k]))
    return omega, out


def test_passage_through_resonance_against_the_asymptotic_closed_form(passages):
    """The classical result (Lewis 1932, Trans. ASME 54, 253-261; Markert & Seidler 2001, Int. J. Solids
    Struct. 38, 1975-1992): the faster the run-up, the lower the peak and the later (higher speed) it comes.

    For an undamped rotor, z = x + i y, z'' + omega^2 z = e (Omega^2 - i Omega') e^(i phi), the slowly
    varying amplitude near resonance is a Fresnel integral, so that as lambda = Omega'/omega^2 -> 0

        |z|max = e omega / 2 sqrt(pi / Omega') |F(u*)|,   Omega_peak = omega (1 + u* sqrt(pi lambda)),

    with u*, |F(u*)| the Cornu spiral's farthest point (computed here). Measured: the peak within
    2.60, 1.29, 0.64 % at lambda = 1/400, 1/1600, 1/6400, halving with sqrt(lambda) (observed exponent
    0.507, asserted 0.5 +- 0.05), and the speed at the peak within 9.4e-5, 1.0e-5, 8.2e-6 (asserted
    1e-3, 10x the largest)."""
    omega, out = passages
    u_star, f_star = cornu_peak()
    peak_err, speed_err = [], []
    for lam, alpha, peak, speed in out:
        peak_ref = 0.5 * omega * math.sqrt(math.pi / alpha) * f_star  # m_e / m = 1
        speed_ref = omega * (1 + u_star * math.sqrt(math.pi * lam))
        peak_err.append(abs(peak / peak_ref - 1))
        speed_err.append(abs(speed / speed_ref - 1))
    # the trend: lower and later peaks at higher rates
    peaks, speeds = [o[2] for o in out], [o[3] for o in out]
    assert peaks[0] < peaks[1] < peaks[2]
    assert speeds[0] > speeds[1] > speeds[2] > omega
    # the closed form, approached as lambda -> 0
    # the closed form, approached as lambda -> 0 with an error falling like sqrt(lambda) (the next term)
    orders = [math.log(peak_err[i] / peak_err[i + 1]) / math.log(4.0) for i in range(2)]
    assert all(abs(p - 0.5) < 0.05 for p in orders), orders
    assert peak_err[-1] < 0.01
    assert max(speed_err) < 1e-3, speed_err


def test_constant_profile_is_the_constant_speed_step():
    """A profile with one breakpoint runs the same equations as constant speeds: the same response to
    round-off (two independent step implementations)."""
    model = disk_rotor()
    kw = dict(loads=Loads([Unbalance(1, M_E)]), recording=Recording([(1, "x"), (1, "theta_y")]),
              control=StepControl(progress=False))
    a = simulate(model, Operating.point({"shaft": 300.0}), 0.2, 1e-5, **kw)
    b = simulate(model, Operating.profile(SpeedProfile.constant({"shaft": 300.0})), 0.2, 1e-5, **kw)
    for o in a.outputs:
        assert np.max(np.abs(a.outputs[o] - b.outputs[o])) < 1e-9 * np.max(np.abs(a.outputs[o]))


def test_profile_evaluation_compiled_equals_python():
    """The kernel's speed, acceleration and spin angle (left-limit acceleration at breakpoints) equal
    SpeedProfile.at, including on breakpoints and after the end."""
    profile = SpeedProfile(np.array([0.0, 0.3, 1.0, 1.7]), {"a": [10.0, 10.0, 80.0, 50.0], "b": [0.0, 5.0, 5.0, 90.0]})
    spools = ("a", "b")
    tk, W, Wd, Phi = profile.kernel_table(spools)
    table = ramp_kernel.ProfileTable(tk=tk, W=W, Wd=Wd, Phi=Phi, force_spool=np.zeros(0, np.int64),
                                     force_kind=np.zeros(0, np.int64))
    out = np.empty((2, 3))
    for t in (0.0, 0.1, 0.3, 0.65, 1.0, 1.7, 2.5):
        ramp_kernel._profile_at(t, table, out)
        ref = profile.at(t)
        for j, s in enumerate(spools):
            np.testing.assert_allclose(out[j], [float(v) for v in ref[s]], rtol=1e-14, atol=1e-12)
    # left limit: at t = 0.3 spool b ends its 0 -> 5 ramp at 5/0.3 rad/s^2
    assert profile.at(0.3)["b"][1] == pytest.approx(5 / 0.3)


@pytest.mark.parametrize("kwargs, field", [
    (dict(t=[0.0, 1.0], speeds={"a": [0.0, -1.0]}), "speeds['a']"),
    (dict(t=[0.5, 1.0], speeds={"a": [0.0, 1.0]}), "t[0]"),
    (dict(t=[0.0, 1.0, 1.0], speeds={"a": [0.0, 1.0, 2.0]}), "t"),
    (dict(t=[0.0, 1.0], speeds={"a": [0.0]}), "speeds['a']"),
    (dict(t=[0.0, 1.0], speeds={}), "speeds"),
])
def test_bad_profiles_name_the_field(kwargs, field):
    with pytest.raises(InputError) as e:
        SpeedProfile(**kwargs)
    assert e.value.field == field


def test_profile_needs_average_acceleration_and_K_G():
    model = disk_rotor()
    profile = SpeedProfile.ramp({"shaft": 0.0}, {"shaft": 100.0}, 1.0)
    with pytest.raises(InputError) as e:
        simulate(model, Operating.profile(profile), 0.1, 1e-4, scheme=Scheme("hht"),
                 control=StepControl(progress=False))
    assert e.value.field == "scheme.method"
    bare = SystemMatrices(M=model.M, K=model.K, C=model.C, G=model.G, dofs=model.dofs)
    with pytest.raises(InputError) as e:
        simulate(bare, Operating.profile(profile), 0.1, 1e-4, control=StepControl(progress=False))
    assert e.value.field == "model.K_G['shaft']"


def test_energy_balance_of_a_run_up():
    """The drive work equals the change of kinetic and strain energy plus the energy dissipated
    (docs/model.md, Eq. R5), from the recorded state, on the disk rotor through its critical speed.

    Measured: relative residual 3.7e-10, 1.4e-10, 6.9e-11 at dt = 1e-5, 5e-6, 2.5e-6 s (the record's
    quadrature); asserted 1.4e-9 at 5e-6 s (10x; the issue asks 1e-6). Leaving out the spin coupling
    (the K_G terms: Omega q'^T K_G q in the energy, the drive's torque d/dt q'^T K_G q) breaks the balance
    by 4.7e-5: the check sees the angular-acceleration terms."""
    W0, alpha, t_end = 240.0, 400.0, 0.45
    profile = SpeedProfile.ramp({"shaft": W0}, {"shaft": W0 + alpha * t_end}, t_end)
    model, loads, run_up = disk_rotor(), Loads([Unbalance(1, M_E)]), Operating.profile(profile)
    res = simulate(model, run_up, t_end, 5e-6, loads=loads, recording=Recording(states=True),
                   control=StepControl(progress=False))
    balance = energy_balance(model, res, run_up, loads)
    assert balance.relative_residual < 1.4e-9
    assert balance.damping[-1] > 0.5 * balance.drive[-1] > 0  # the drive's work is mostly dissipated
    without = energy_balance(dataclasses.replace(model, K_G={"shaft": np.zeros((4, 4))}), res, run_up, loads)
    assert without.relative_residual > 1e-5


def test_energy_balance_needs_the_recorded_state():
    model = disk_rotor()
    res = simulate(model, Operating.point({"shaft": 100.0}), 1e-3, 1e-4, control=StepControl(progress=False))
    with pytest.raises(InputError) as e:
        energy_balance(model, res, Operating.point({"shaft": 100.0}))
    assert e.value.field == "result.states"


def test_slow_ramp_is_the_steady_unbalance_response():
    """A slow run-up (250 rad/s over 250 s: lambda = Omega'/omega^2 = 1e-5 at the critical speed) tracked
    by order (1x, angle-domain resampling) equals the steady unbalance response of
    rotorred.linear.harmonic (frequency domain, another path) at each block's speed.

    Measured (dt = 1e-4 s): the peak (316.1 rad/s) within 0.022 %, the curve 5 % or more from the peak within
    9.6e-4 (Newmark's period error (omega dt)^2/12 = 8e-5 moves the resonance; at dt = 2e-4 s the error
    is 5e-3). Asserted: the peak within 0.22 %, the curve within 1e-2 (10x the measured; the issue's
    bounds are 2 % and 1 %)."""
    model, T = disk_rotor(), 250.0
    profile = SpeedProfile.ramp({"shaft": 200.0}, {"shaft": 450.0}, T)
    unbalances = [Unbalance(1, M_E)]
    res = simulate(model, Operating.profile(profile), T, 1e-4, loads=Loads(unbalances),
                   recording=Recording([(1, "x"), (1, "y")], decimate=5), control=StepControl(progress=False))
    blocks = angle_blocks(res.t, [res.outputs[(1, "x")], res.outputs[(1, "y")]], profile.at(res.t)["shaft"][2],
                          revs_per_block=16)
    track = order_tracks(blocks, "shaft", [1.0])[0][0]
    steady = unbalance_response(model, Operating.line(blocks.speed), unbalances, [(1, "x")])
    W, a, Q = blocks.speed, track.amplitude, np.abs(steady.phasors["shaft"][(1, "x")])
    keep = W > 220.0  # the start from rest has rung out
    W, a, Q = W[keep], a[keep], Q[keep]
    k = int(np.argmax(Q))
    assert abs(a[k - 3:k + 4].max() / Q[k] - 1) < 2.2e-3
    away = np.abs(W - W[k]) > 0.05 * W[k]
    assert np.max(np.abs(a[away] - Q[away]) / Q[away]) < 1e-2
    # the phase too: the track is the steady phasor (x ~ Re(Q e^(i phi)))
    phase_err = np.abs(np.angle(track.amplitude[keep] * np.exp(1j * track.phase[keep]) / steady.phasors["shaft"][(1, "x")][keep]))
    assert phase_err[away].max() < 3.7e-2  # measured 3.7e-3 rad


def test_runup_refuses_speed_dependent_bearings_on_a_varying_spool():
    """A run-up steps with constant bearing matrices: a bearing table on a spool whose speed varies is refused
    before any computation, naming the bearing."""
    from rotorred.model.assembly import assemble
    from rotorred.model.elements import BearingTable
    from rotorred.model.rotor_file import load_rotor

    rotor = load_rotor("nelson-mcvaugh")
    tables = tuple(BearingTable(node=b.node, speeds=(0.0, 1000.0), k_xx=(1e7, 2e7), k_yy=1e7) for b in rotor.bearings)
    model = assemble(dataclasses.replace(rotor, bearings=tables))
    with pytest.raises(InputError, match=r"^bearing at node \d+ = 'speed-dependent': is not supported when the speed "
                                         r"of spool 'shaft' varies in time"):
        simulate(model, Operating.profile(SpeedProfile.ramp({"shaft": 0.0}, {"shaft": 100.0}, 0.1)), 0.1, 1e-4)
