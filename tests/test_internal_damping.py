"""Internal (rotating) damping (issue 38, item 1; docs/model.md §19).

The Jeffcott rotor (a disk at the middle of a light shaft between pinned supports) with internal damping
c_i = beta k and external damping c_e at the disk becomes unstable at Omega = omega_n (1 + c_e / c_i)
(Genta 2005, Eq. 4.47; derivations/internal_damping.py): Campbell's onset speed against that closed form, and a
transient that grows above it and decays below it at the rate of the eigenvalue. VM261 (Zorzi & Nelson 1977, the
ANSYS verification case): forward critical speeds against the published ones, each forward mode unstable from its
forward critical speed, the backward modes stable.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import rotorred as rr
from rotorred.linear.modal import eigen
from rotorred.model.assembly import assemble
from rotorred.model.elements import Material, ShaftElement, Support

VM261 = Path(__file__).resolve().parents[1] / "validation" / "reference" / "vm261" / "vm261.toml"

E, D, L, M_DISK = 2.1e11, 0.02, 0.6, 10.0
#: the Jeffcott shaft's density (kg/m^3): its mass is 1.9e-8 of the disk's, so the model is the closed form's
#: two-DOF rotor to about that (measured onset error 1e-10); lighter still, the shaft's rotations would be taken for
#: rigid-body motions by the Campbell diagram's threshold (1e-10 of the largest w^2)
RHO_LIGHT = 1e-3


def jeffcott(beta: float = 1e-3, ratio: float = 0.5) -> tuple[rr.Rotor, float, float]:
    """The Jeffcott rotor with internal damping ``beta`` (s) and external damping ``c_e = ratio c_i``, its
    natural frequency omega_n = sqrt(k / m) (k = 48 EI / L^3, exact for two Euler-Bernoulli elements) and
    the closed-form onset speed omega_n (1 + c_e / c_i) (rad/s)."""
    light = Material("light", E=E, rho=RHO_LIGHT)
    elements = [ShaftElement(n, n + 1, L / 2, D, 0.0, light, shear="none", rotary_inertia=False) for n in (1, 2)]
    k = 48 * E * (math.pi * D**4 / 64) / L**3
    c_e = ratio * beta * k
    rotor = rr.Rotor(spools=(rr.Spool("shaft", elements, internal_damping_beta=beta),),
                     disks=(rr.Disk(2, M_DISK, 0.01, 0.02),),  # I_p > I_d: the tilt modes whirl above the speed
                     bearings=(rr.Bearing(node=2, c_xx=c_e, c_yy=c_e),),
                     supports=(Support(1, "pinned"), Support(3, "pinned")), name="jeffcott")
    omega_n = math.sqrt(k / M_DISK)
    return rotor, omega_n, omega_n * (1.0 + ratio)


@pytest.mark.parametrize("beta, ratio, grid", [(1e-3, 0.5, 21), (1e-4, 0.2, 17)])
def test_jeffcott_onset_speed_is_the_closed_form(beta, ratio, grid):
    """Campbell's onset speed (root of Re(lambda) between grid speeds) is omega_n (1 + c_e / c_i); the first grid
    puts the onset on a grid speed (log dec within round-off of 0 there), the second between two.
    Measured: 8e-11 relative."""
    rotor, omega_n, onset = jeffcott(beta, ratio)
    cd = rr.campbell(rotor, rr.Operating.line(np.linspace(0.0, 2.0 * omega_n, grid)), n_modes=2)
    changes = cd.stability_changes
    assert len(changes) == 1 and changes[0].onset and changes[0].whirl == "forward"
    assert abs(changes[0].speed / onset - 1.0) < 1e-7
    assert abs(changes[0].frequency / omega_n - 1.0) < 1e-7  # at the onset the forward whirl is at omega_n
    assert cd.onset_speeds == {changes[0].mode: changes[0].speed}
    forward = cd.whirl[:, changes[0].mode] == "forward"
    assert np.all(cd.unstable[:, changes[0].mode] == (cd.speeds > onset * (1 + 1e-6)) & forward)


def test_without_internal_damping_the_jeffcott_rotor_stays_stable():
    """The same rotor with beta = 0 (c_e kept): no onset, the fixed-frame damping alone."""
    rotor, omega_n, _ = jeffcott()
    c_e = rotor.bearings[0].c_xx
    spool = dataclasses.replace(rotor.spools[0], internal_damping_beta=0.0)
    bare = dataclasses.replace(rotor, spools=(spool,))
    assert not assemble(bare).rotating
    cd = rr.campbell(bare, rr.Operating.line(np.linspace(0.0, 3.0 * omega_n, 7)), n_modes=2)
    assert not cd.stability_changes and not cd.unstable.any() and c_e > 0


@pytest.mark.parametrize("factor", [0.9, 1.1])
def test_jeffcott_transient_grows_above_the_onset_and_decays_below(factor):
    """Started on the forward whirl mode (q = Re(v e^{lambda t}) at t = 0), the disk's orbit radius decays at
    0.9 x the onset speed and grows at 1.1 x, at the rate Re(lambda) of that mode's eigenvalue (the slope of
    log r over 2 s)."""
    rotor, omega_n, onset = jeffcott()
    Omega = factor * onset
    model = assemble(rotor)
    speeds = {"shaft": Omega}
    sol = eigen(model.M, model.damping(speeds), model.stiffness(speeds))
    k = int(np.argmax(sol.eigenvalues.real))  # the forward mode: the least damped
    lam, v = sol.eigenvalues[k], sol.modes[:, k] * 1e-5 / np.abs(sol.modes[:, k]).max()
    res = rr.simulate(model, rr.Operating.point(speeds), 2.0, 1e-4, start=rr.Initial(v.real, (lam * v).real),
                      recording=rr.Recording([(2, "x"), (2, "y")]))
    r = np.hypot(res.outputs[(2, "x")], res.outputs[(2, "y")])
    measured = float(np.polyfit(res.t, np.log(r), 1)[0])
    assert (measured > 0) == (factor > 1) and abs(lam.real) > 1.0
    assert abs(measured / lam.real - 1.0) < 1e-3


def test_vm261_critical_speeds_and_onsets():
    """VM261 (validation/reference/vm261): forward critical speeds within 2 % of 4950 and 10500 rpm (measured
    1.0 % and 0.24 %, the published numbers being read off a figure to 50 rpm); each of the two forward modes
    becomes unstable at its own forward critical speed (measured to 1e-12: there the rotating frame sees a static
    deflection, so the internal damping does no work), within 0.5 %; the backward modes stay stable."""
    rotor = rr.load_rotor(VM261)
    assert rotor.spools[0].internal_damping_beta == 2e-4
    cd = rr.campbell(rotor, rr.Operating.line(np.linspace(0.0, 16000.0, 33), unit="rpm"), n_modes=4)
    forward = [c for c in cd.critical_speeds if c.whirl == "forward"]
    assert [round(c.speed_rpm) for c in forward] == [5000, 10525]
    for c, published in zip(forward, (4950.0, 10500.0)):
        assert abs(c.speed_rpm / published - 1.0) < 0.02
    onsets = cd.onset_speeds
    assert sorted(onsets) == sorted(c.mode for c in forward)
    for c in forward:
        assert abs(onsets[c.mode] / c.speed - 1.0) < 0.005
        assert abs(onsets[c.mode] / c.speed - 1.0) < 1e-9  # measured
    backward = sorted({c.mode for c in cd.critical_speeds if c.whirl == "backward"})
    assert len(backward) == 2 and np.all(cd.log_dec[:, backward] > 0)


def test_rotating_damping_matrices():
    """Per element: K commutes with J (axisymmetric) for the Nelson, tapered and hierarchical elements, J^2 = -I;
    assembled: N_v = sum beta K J is skew, C_v = sum beta K; the circulatory stiffness enters ``stiffness(speeds)``
    as -Omega N_v and the damping C_v enters ``dissipation``, the spool's own speed only."""
    steel = Material("steel", E=2.1e11, rho=7800.0)
    for e in (ShaftElement(0, 1, 0.1, 0.05, 0.01, steel), ShaftElement(0, 1, 0.1, 0.05, 0.01, steel, D_o_right=0.04),
              ShaftElement(0, 1, 0.1, 0.05, 0.01, steel, element="hierarchical")):
        K, J = e.K(), e.spin_rotation()
        assert np.allclose(J @ J, -np.eye(len(J)), atol=0)
        assert np.abs(K @ J - J @ K).max() <= 1e-12 * np.abs(K).max()
    rotor = rr.load_rotor(VM261)
    model = assemble(rotor)
    r = model.rotating["shaft"]
    assert np.abs(r.N_v + r.N_v.T).max() <= 1e-12 * np.abs(r.N_v).max()
    spool = dataclasses.replace(rotor.spools[0], internal_damping_beta=0.0)
    bare = assemble(dataclasses.replace(rotor, spools=(spool,)))
    bearings = np.zeros_like(bare.K)
    for b in rotor.bearings:
        i = model.dofs.node_dofs(b.node)[:2]
        bearings[np.ix_(i, i)] += b.K
    assert np.allclose(r.C_v, 2e-4 * (bare.K - bearings), rtol=0, atol=1e-12 * np.abs(r.C_v).max())
    speeds = {"shaft": 700.0}
    assert np.array_equal(model.stiffness(speeds), model.K - 700.0 * r.N_v)
    assert np.array_equal(model.dissipation(speeds), model.C + r.C_v)
    assert np.array_equal(model.stiffness({}), model.K)  # a spool left out stands still
    assert model.speed_dependent and not bare.speed_dependent


def test_internal_damping_keys_round_trip_and_are_checked(tmp_path):
    """The spool's value is its elements' default, an element's own value overrides it; ``to_toml`` writes both
    back; a negative value is an input error naming the key."""
    text = VM261.read_text().replace("elements = [ { L = 0.254, D_o = 0.1016, repeat = 5 } ]",
                                     "elements = [ { L = 0.254, D_o = 0.1016, repeat = 4 },\n"
                                     "  { L = 0.254, D_o = 0.1016, internal_damping_beta = 0.0, "
                                     "internal_loss_factor = 0.01 } ]")
    from rotorred.model.rotor_file import rotor_from_toml

    rotor = rotor_from_toml(text)
    spool = rotor.spools[0]
    assert [spool.internal_damping(e) for e in spool.elements] == [(2e-4, 0.0)] * 4 + [(0.0, 0.01)]
    back = rr.load_rotor(rotor.to_toml(tmp_path / "back.toml"))
    assert back == rotor
    model = assemble(rotor)
    assert model.loss_frequency > 0
    bad = text.replace("internal_damping_beta = 2e-4", "internal_damping_beta = -1e-4")
    with pytest.raises(rr.InputError, match=r"spool\[0\]\.internal_damping_beta = -0.0001: must be >= 0"):
        rotor_from_toml(bad)


def test_jeffcott_run_up_through_the_onset_matches_solve_ivp():
    """Run up with unbalance from 0.8 to 1.2 x the onset speed: the disk's x and y against Radau (rtol 1e-10) of
    the Jeffcott rotor's equations written out by hand (no matrix of the model):

        m x'' + (c_e + c_i) x' + k x + Omega c_i y = m_e (Omega^2 cos phi + Omega' sin phi)
        m y'' + (c_e + c_i) y' + k y - Omega c_i x = m_e (Omega^2 sin phi - Omega' cos phi)

    (the circulatory term -Omega c_i J q changes with the speed at every step of the ramp kernel).
    Measured: 1.47e-4 and 3.72e-5 of the peak with dt = 2e-5 and 1e-5 s, an observed order of 1.98 (the step's
    own error, average acceleration being second order); asserted 1e-4 at 1e-5 s and the order within 0.1 of 2."""
    from scipy.integrate import solve_ivp

    beta = 1e-3
    rotor, omega_n, onset = jeffcott(beta)
    k, c_i = M_DISK * omega_n**2, beta * M_DISK * omega_n**2
    c = c_i + rotor.bearings[0].c_xx
    m_e, t_end = 1e-5, 1.0
    W0, W1 = 0.8 * onset, 1.2 * onset
    alpha = (W1 - W0) / t_end
    runs = [rr.simulate(rotor, rr.Operating.ramp({"shaft": W0}, {"shaft": W1}, t_end), t_end, dt,
                        loads=rr.Loads([rr.Unbalance(2, m_e)]), recording=rr.Recording([(2, "x"), (2, "y")],
                                                                                       decimate=decimate))
            for dt, decimate in ((2e-5, 50), (1e-5, 100))]

    def rhs(t, s):
        x, y, vx, vy = s
        W, phi = W0 + alpha * t, W0 * t + 0.5 * alpha * t * t
        fx = m_e * (W * W * math.cos(phi) + alpha * math.sin(phi))
        fy = m_e * (W * W * math.sin(phi) - alpha * math.cos(phi))
        return [vx, vy, (fx - c * vx - k * x - W * c_i * y) / M_DISK, (fy - c * vy - k * y + W * c_i * x) / M_DISK]

    ref = solve_ivp(rhs, (0.0, t_end), np.zeros(4), method="Radau", rtol=1e-10, atol=1e-16, t_eval=runs[0].t)
    assert ref.success
    for j, d in enumerate(("x", "y")):
        coarse, fine = (np.max(np.abs(r.outputs[(2, d)] - ref.y[j])) / np.max(np.abs(ref.y[j])) for r in runs)
        assert fine < 1e-4 and abs(math.log2(coarse / fine) - 2.0) < 0.1


@pytest.mark.parametrize("operating", ["point", "ramp"])
def test_energy_balance_with_internal_damping_closes(operating):
    """The energy balance of the Jeffcott rotor with unbalance (at 1.1 x the onset speed, and run up from 0.8 to 1.2
    x) closes with the energy dissipated by internal damping (W_internal > 0) and the work of its circulatory
    force: measured residual 8.9e-13 (point) and 9.5e-13 (ramp) of the largest term; asserted 1e-11. Leaving the
    circulatory work out would leave a residual of its own size (> 10 % of the largest term)."""
    rotor, omega_n, onset = jeffcott()
    op = (rr.Operating.point({"shaft": 1.1 * onset}) if operating == "point"
          else rr.Operating.ramp({"shaft": 0.8 * onset}, {"shaft": 1.2 * onset}, 0.5))
    loads = rr.Loads([rr.Unbalance(2, 1e-5)])
    run = rr.simulate(rotor, op, 0.5, 2e-5, loads=loads, recording=rr.Recording([(2, "x")], states=True))
    balance = rr.energy_balance(rotor, run, op, loads)
    assert balance.relative_residual < 1e-11
    assert np.all(np.diff(balance.internal) >= 0) and balance.internal[-1] > 0
    scale = max(np.abs(balance.drive).max(), balance.damping.max(), np.abs(balance.energy).max())
    assert np.abs(balance.circulatory).max() > 0.1 * scale
    assert "W_circulatory" in repr(balance) and float(balance.to_xarray()["internal"][-1]) == balance.internal[-1]


def test_harmonic_balance_linear_part_with_the_spin_following_omega():
    """Harmonic balance's linear part with the spin following omega (``D1`` = G, ``K1`` = -N: the circulatory
    stiffness grows with omega): the full and the condensed problem's linear response equal the unbalance response,
    and dR/domega the central difference of R. A rotor whose internal damping makes ``K`` depend on omega, which
    the unbalance response evaluates at each speed."""
    from rotorred.nonlinear.condensed import CondensedProblem

    rotor, omega_n, onset = jeffcott()
    rotor = dataclasses.replace(rotor, bearings=(rr.Bearing(node=2, k_xx=2e5, k_yy=3e5, c_xx=40.0, c_yy=40.0),))
    model = assemble(rotor)  # anisotropic bearing: the response has a backward part the internal damping acts on
    C_r, _ = model.rotating_damping({})
    N = model.rotating["shaft"].N_v
    f = 1e-5 * (model.output_rows([(2, "x")])[0] - 1j * model.output_rows([(2, "y")])[0])
    h = rr.Harmonics(1, 8)
    n = model.n_dof

    def forcing(omega):
        F, dF = np.zeros((3, n)), np.zeros((3, n))
        F[1], F[2], dF[1], dF[2] = omega**2 * f.real, -omega**2 * f.imag, 2 * omega * f.real, -2 * omega * f.imag
        return F.reshape(-1), dF.reshape(-1)

    common = dict(M=model.M, D=model.C + C_r, K=model.K, harmonics=h, forcing=forcing, D1=model.G["shaft"], K1=-N)
    full = rr.PeriodicProblem(**common)
    condensed = CondensedProblem(**common, dofs=tuple(int(model.dofs.index(2, d)) for d in ("x", "y")))
    omegas = np.array([0.5, 1.0, 1.3]) * onset
    ub = rr.unbalance_response(model, rr.Operating.line(omegas), [rr.Unbalance(2, 1e-5)], [(2, "x"), (2, "y")])
    for k, omega in enumerate(omegas):
        z = full.linear_response(omega).reshape(3, n)
        zc = condensed.linear_response(omega).reshape(3, 2)
        for j, d in enumerate(("x", "y")):
            expected = ub.phasors["shaft"][(2, d)][k]
            i = model.dofs.index(2, d)
            assert abs(z[1, i] - 1j * z[2, i] - expected) <= 1e-9 * abs(expected)
            assert abs(zc[1, j] - 1j * zc[2, j] - expected) <= 1e-9 * abs(expected)
        z = full.linear_response(omega)
        step = 1e-6 * omega
        numeric = (full.evaluate(z, omega + step).R - full.evaluate(z, omega - step).R) / (2 * step)
        assert np.abs(full.evaluate(z, omega).dR_domega - numeric).max() <= 1e-6 * np.abs(numeric).max()


def test_unbalance_response_of_an_isotropic_rotor_does_not_see_internal_damping():
    """On isotropic supports the unbalance whirl is forward, circular and synchronous: the rotating frame sees a
    static deflection, so internal damping (viscous or hysteretic) changes nothing (to round-off)."""
    rotor, omega_n, onset = jeffcott()
    bare = dataclasses.replace(rotor, spools=(dataclasses.replace(rotor.spools[0], internal_damping_beta=0.0),))
    lossy = dataclasses.replace(rotor, spools=(dataclasses.replace(rotor.spools[0], internal_damping_beta=0.0,
                                                                   internal_loss_factor=0.02),))
    op = rr.Operating.line(np.linspace(0.2, 2.0, 10) * omega_n)
    args = ([rr.Unbalance(2, 1e-5)], [(2, "x"), (2, "y")])
    reference = rr.unbalance_response(bare, op, *args)
    for other in (rotor, lossy):
        assert rr.linear.harmonic.response_error(reference, rr.unbalance_response(other, op, *args)) < 1e-9


def test_loss_factor_in_a_frequency_response_is_taken_at_the_excitation_frequency():
    """A loss factor eta is the viscous eta / |w| at the excitation frequency w: the receptance x/F_x of the
    Jeffcott rotor (pinned ends, disk in the middle) at spin Omega against the two-DOF closed form
    m s^2 + c_e s + k + eta k (s - i Omega) / |w| for the forward (+) and backward (-) parts of a force in x,
    x = F/2 (1/Z(w) + 1/conj(Z(-w))), with s = i w (measured: 1.8e-6 at w = omega_n, the shaft's mass, 2e-8 of the
    disk's, amplified by the resonance's 1 / eta)."""
    rotor, omega_n, onset = jeffcott(beta=0.0)
    eta = 0.02
    rotor = dataclasses.replace(rotor, spools=(dataclasses.replace(rotor.spools[0], internal_loss_factor=eta),))
    model = assemble(rotor)
    c_e, k = rotor.bearings[0].c_xx, M_DISK * omega_n**2
    Omega = 1.3 * omega_n
    w = np.array([0.5, 0.9, 1.0, 1.1, 2.0]) * omega_n
    H = rr.frequency_response(model, rr.Operating.point({"shaft": Omega}), [(2, "x")], [(2, "x")], w).H[:, 0, 0]

    def Z(w_signed):  # z = x + i y ~ e^{i w t}: m z'' + c_e z' + k z + eta k / |w| (z' - i Omega z)
        s = 1j * w_signed
        return M_DISK * s**2 + c_e * s + k + eta * k * (s - 1j * Omega) / abs(w_signed)

    expected = 0.5 * (1.0 / Z(w) + 1.0 / np.conj(Z(-w)))
    assert np.abs(H / expected - 1).max() < 2e-5
    # the first natural frequency at rest (3.7e-7 off: the light shaft's near-singular mass conditions eigh)
    assert model.loss_frequency == pytest.approx(omega_n, rel=4e-6)


def test_a_reduced_model_keeps_the_internal_damping():
    """Craig-Bampton (VM261, bearing nodes as the boundary): the projected rotating damping is T^T X T, each
    reduced onset speed is the reduced model's own forward critical speed (to 1e-9), and they approach the full
    model's as modes are added (measured 1.2e-2 with 2 fixed-interface modes, 2.7e-5 with 8; an odd count splits a
    pair of the isotropic shaft's x and y modes and makes the reduced rotor anisotropic)."""
    rotor = rr.load_rotor(VM261)
    full = assemble(rotor)
    op = rr.Operating.line(np.linspace(0.0, 16000.0, 17), unit="rpm")
    onsets = sorted(rr.campbell(full, op, n_modes=4).onset_speeds.values())
    errors = []
    for n_modes in (2, 8):
        red = rr.reduce_rotor(rotor, n_modes=n_modes)
        T = red.T
        assert np.allclose(red.rotating["shaft"].N_v, T.T @ full.rotating["shaft"].N_v @ T, rtol=0,
                           atol=1e-12 * np.abs(full.rotating["shaft"].N_v).max())
        cd = rr.campbell(red, op, n_modes=4)
        reduced = sorted(cd.onset_speeds.values())
        assert len(reduced) == len(onsets) == 2
        forward = [c.speed for c in cd.critical_speeds if c.whirl == "forward"]
        assert np.allclose(reduced, forward, rtol=1e-9, atol=0)
        errors.append(max(abs(a / b - 1) for a, b in zip(reduced, onsets)))
    assert errors[1] < errors[0] / 100 and errors[1] < 3e-4
