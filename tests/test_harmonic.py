"""Harmonic (unbalance) response: Jeffcott closed form, the settled state of a long solve_ivp
transient of a two-spool model, FRF consistency, reduced models, CSV/plots/CLI, bad input."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rotorred.model.assembly import DofMap, SystemMatrices, assemble
from rotorred.cli import main
from rotorred.model.elements import Bearing, Disk, IntershaftBearing, Material, ShaftElement
from rotorred.checks import InputError
from rotorred.linear.harmonic import frequency_response, response_error, steady_state, unbalance_response
from rotorred.model.dofs import parse_dof
from rotorred.plots.axes import save_figure
from rotorred.model.rotor_file import load_rotor
from rotorred.model.loads import Unbalance
from rotorred.model.operating import Operating
from rotorred.model.rotor import Rotor, Spool
from rotorred.linear.reduction import default_boundary_nodes, reduce, reduce_rotor

STEEL = Material("steel", 2.1e11, 7850.0, 0.3)
#: the two-spool rotors of this file at rest
AT_REST = Operating.point({"inner": 0.0, "outer": 0.0})


def jeffcott_closed_form(rho, zeta):
    """|r|/e = rho^2 / sqrt((1 - rho^2)^2 + (2 zeta rho)^2) and the phase lag atan2(2 zeta rho, 1 - rho^2)."""
    return rho**2 / np.sqrt((1 - rho**2) ** 2 + (2 * zeta * rho) ** 2), np.arctan2(2 * zeta * rho, 1 - rho**2)


# --- Jeffcott rotor --------------------------------------------------------------------------------------

def test_jeffcott_point_mass_matches_closed_form():
    """A rigid disk (m, k, c) alone: the harmonic solver against the closed form, amplitude and phase,
    and forward circular whirl (Q_y = -i Q_x)."""
    m, k, zeta, e = 10.0, 4e6, 0.03, 2e-5
    c = 2 * zeta * math.sqrt(k * m)
    system = SystemMatrices(M=np.diag([m, m, 0.1, 0.1]), K=np.diag([k, k, 1e5, 1e5]), C=np.diag([c, c, 0.0, 0.0]),
                            G={"shaft": np.zeros((4, 4))}, dofs=DofMap((7,)))
    w_n = math.sqrt(k / m)
    speeds = w_n * np.linspace(0.05, 3.0, 60)
    res = unbalance_response(system, Operating.line(speeds), [Unbalance(7, m * e, 0.4)], [(7, "x"), (7, "y")])
    amp, lag = jeffcott_closed_form(speeds / w_n, zeta)
    Qx, Qy = res.phasors["shaft"][(7, "x")], res.phasors["shaft"][(7, "y")]
    # one 4x4 complex solve per speed: round-off only
    np.testing.assert_allclose(np.abs(Qx) / e, amp, rtol=1e-12)
    np.testing.assert_allclose(np.exp(1j * (np.angle(Qx) - 0.4)), np.exp(-1j * lag), atol=1e-12)
    np.testing.assert_allclose(Qy, -1j * Qx, rtol=1e-12)
    np.testing.assert_allclose(res.peak((7, "x")), np.abs(Qx), rtol=1e-15)  # one spool: peak is |Q|


def test_jeffcott_finite_element_rotor_matches_closed_form():
    """A near-massless Euler-Bernoulli shaft with a midspan disk, stiff bearings and a damper at the disk:
    k = 1 / (L^3 / (48 E I) + 1 / (2 k_b)), the closed form holds up to the shaft's mass."""
    L, D, k_b, m = 0.6, 0.02, 1e9, 8.0
    light = Material("massless steel", 2.1e11, 1e-6, 0.3)  # 1e-6 kg/m^3: shaft mass 2.4e-11 of the disk's
    shaft = Spool("shaft", (ShaftElement(1, 2, L / 2, D, 0.0, light, shear="none"),
                            ShaftElement(2, 3, L / 2, D, 0.0, light, shear="none")))
    I = math.pi * D**4 / 64
    k = 1 / (L**3 / (48 * 2.1e11 * I) + 1 / (2 * k_b))
    zeta = 0.02
    c = 2 * zeta * math.sqrt(k * m)
    rotor = Rotor(spools=(shaft,), disks=(Disk(2, m, 0.01, 0.02),),
                  bearings=(Bearing(k_xx=k_b, k_yy=k_b, node=1), Bearing(k_xx=k_b, k_yy=k_b, node=3),
                            Bearing(c_xx=c, c_yy=c, node=2)))
    system = assemble(rotor)
    w_n = math.sqrt(k / m)
    speeds = w_n * np.linspace(0.1, 2.5, 49)
    e = 1e-5
    res = unbalance_response(system, Operating.line(speeds), [Unbalance(2, m * e)], [(2, "x")])
    amp, _ = jeffcott_closed_form(speeds / w_n, zeta)
    # By symmetry the midspan disk does not tilt, so its gyroscopic and rotary terms do not couple in;
    # Hermite elements are exact for the static condensation of a massless EB shaft. What is left is
    # the shaft's mass (2.4e-11 of the disk's, amplified by at most 1/(2 zeta) = 25 near resonance)
    # and round-off: 1e-8. (With rho = 1e-3 kg/m^3 the mismatch is 5e-8, as that mass ratio predicts.)
    np.testing.assert_allclose(res.amplitude((2, "x"), "shaft") / e, amp, rtol=1e-8)


# --- two spools: settled state of a long transient -------------------------------------------------------

def transient_two_spool() -> Rotor:
    """A small, well damped two-spool rotor: every mode decays at >= 70 1/s, so 0.3 s settles it."""
    inner = Spool("inner", (ShaftElement(1, 2, 0.2, 0.03, 0.0, STEEL), ShaftElement(2, 3, 0.2, 0.03, 0.0, STEEL)),
                  speed=2 * math.pi * 70)
    outer = Spool("outer", (ShaftElement(10, 11, 0.2, 0.06, 0.045, STEEL),), speed=2 * math.pi * 90, z0=0.1)
    c = 1e4
    return Rotor(spools=(inner, outer), disks=(Disk(2, 4.0, 0.02, 0.04), Disk(11, 2.0, 0.01, 0.02)),
                 bearings=(Bearing(k_xx=1e7, k_yy=1.2e7, c_xx=c, c_yy=c, node=1),  # anisotropic: elliptic orbits
                           Bearing(k_xx=1e7, k_yy=1.2e7, c_xx=c, c_yy=c, node=3),
                           Bearing(k_xx=8e6, k_yy=8e6, c_xx=c, c_yy=c, node=10)),
                 intershaft_bearings=(IntershaftBearing(k_xx=5e6, k_yy=5e6, c_xx=c / 3, c_yy=c / 3,
                                                        node_a=11, node_b=2),),
                 rayleigh=(0.0, 2e-5), name="transient two-spool")


def test_two_spool_response_is_the_settled_state_of_a_long_transient():
    rotor = transient_two_spool()
    system = assemble(rotor)
    n = system.n_dof
    speeds = rotor.speeds
    unbalances = [Unbalance(2, 1e-4, 0.3), Unbalance(11, 2e-4, 1.1)]
    outputs = [(2, "x"), (2, "y"), (11, "x"), (3, "y")]
    ratio = speeds["outer"] / speeds["inner"]
    res = unbalance_response(system, Operating.line([speeds["inner"]], ratios={"outer": ratio}), unbalances, outputs)
    # first-order form with the force written straight from the loads.py convention, in time
    M_inv = np.linalg.inv(system.M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-M_inv @ system.K, -M_inv @ system.damping(speeds)]])
    decay = np.min(-np.linalg.eigvals(A).real)

    def rhs(t, z):
        F = np.zeros(n)
        for u in unbalances:
            W = speeds[rotor.spool_of[u.node]]
            F[system.dofs.index(u.node, "x")] += u.m_e * W**2 * math.cos(W * t + u.phase)
            F[system.dofs.index(u.node, "y")] += u.m_e * W**2 * math.sin(W * t + u.phase)
        return A @ z + np.concatenate([np.zeros(n), M_inv @ F])

    T, window = 0.3, 0.05
    # Radau with the exact (constant) Jacobian; rtol 1e-8 and atol 1e-14 m (amplitudes ~1e-5 m)
    sol = solve_ivp(rhs, (0.0, T), np.zeros(2 * n), method="Radau", jac=A, rtol=1e-8, atol=1e-14,
                    dense_output=True)
    assert sol.success
    t = np.linspace(T - window, T, 400)
    q = sol.sol(t)[:n]
    leftover = math.exp(-decay * (T - window))
    assert leftover < 1e-7  # the start-up transient has died out (measured decay rate ~70 1/s)
    for o in outputs:
        ref = res.time_history(o, t)[0]
        got = q[system.dofs.index(*o)]
        # residual transient ~2.5e-8 plus integration error ~1e-8 (measured 2.6e-8 worst): 2e-7 is ~8x
        # margin, while a sign slip in the y force or a wrong spool frequency gives O(1) errors
        assert np.max(np.abs(got - ref)) / np.max(np.abs(ref)) < 2e-7, o
    # two different frequencies: the peak bound is the sum of the two magnitudes, and the settled
    # signal never exceeds it
    for o in outputs:
        bound = res.peak(o)[0]
        assert bound == pytest.approx(sum(abs(res.phasors[s][o][0]) for s in ("inner", "outer")), rel=1e-14)
        assert np.max(np.abs(q[system.dofs.index(*o)])) <= bound * (1 + 1e-6)


def test_steady_state_satisfies_the_equation_of_motion():
    """The model-coordinate steady state (a transient's initial condition) solves M q'' + D q' + K q = F(t)."""
    rotor = transient_two_spool()
    system = assemble(rotor)
    red = reduce_rotor(load_rotor("seed-rig"), (18,), n_modes=4)
    rig = load_rotor("seed-rig")
    for model, rotor_, unbalances in ((system, rotor, [Unbalance(2, 1e-4, 0.3), Unbalance(11, 2e-4, 1.1)]),
                                      (red, rig, [Unbalance(11, 1e-5), Unbalance(16, 1e-5, 2.0)])):
        speeds = rotor_.speeds
        st = steady_state(model, Operating.point(speeds), unbalances)
        D = model.damping(speeds)
        for t in (0.0, 0.0123, 0.5):
            acc = sum(np.real(-(speeds[s] ** 2) * Q * np.exp(1j * speeds[s] * t)) for s, Q in st.phasors.items())
            dofs = getattr(model, "full_dofs", None) or model.dofs
            F = np.zeros(dofs.n_dof)
            for u in unbalances:
                W = speeds[rotor_.spool_of[u.node]]
                F[dofs.index(u.node, "x")] += u.m_e * W**2 * math.cos(W * t + u.phase)
                F[dofs.index(u.node, "y")] += u.m_e * W**2 * math.sin(W * t + u.phase)
            F_model = model.project(F) if hasattr(model, "project") else F
            residual = model.M @ acc + D @ st.velocity(t) + model.K @ st.displacement(t) - F_model
            # round-off of a complex solve: residual ~ eps * ||K|| * ||q||
            assert np.max(np.abs(residual)) < 1e-9 * np.max(np.abs(F_model)), t
        # and it agrees with the sweep function at the same point
        out = (13, "x") if model is red else (2, "y")
        ref_speed = speeds["inner"]
        res = unbalance_response(model, Operating.line([ref_speed], ratios={"outer": speeds["outer"] / ref_speed}),
                                 unbalances, [out])
        for s in st.phasors:
            assert (model.output_rows([out]) @ st.phasors[s])[0] == pytest.approx(res.phasors[s][out][0], rel=1e-12)


def test_spools_at_the_same_speed_add_as_phasors():
    rotor = transient_two_spool()
    system = assemble(rotor)
    unbalances = [Unbalance(2, 1e-4, 0.0), Unbalance(11, 1e-4, math.pi)]
    res = unbalance_response(system, Operating.line([300.0, 500.0], ratios={"outer": 1.0}), unbalances, [(2, "x")])
    total = res.phasors["inner"][(2, "x")] + res.phasors["outer"][(2, "x")]
    np.testing.assert_allclose(res.peak((2, "x")), np.abs(total), rtol=1e-14)
    assert np.all(res.peak((2, "x")) < res.amplitude((2, "x"), "inner") + res.amplitude((2, "x"), "outer"))


# --- FRFs ------------------------------------------------------------------------------------------------

def test_frf_reciprocity_and_consistency_with_unbalance_response():
    rotor = transient_two_spool()
    system = assemble(rotor)
    w = np.linspace(10.0, 3000.0, 25)
    a, b = (2, "x"), (11, "y")
    frf = frequency_response(system, AT_REST, [a, b], [a, b], w)
    # not spinning: M, K, C symmetric, so H is symmetric (Maxwell-Betti reciprocity)
    np.testing.assert_allclose(frf.h(a, b), frf.h(b, a), rtol=1e-10)
    # spinning: the unbalance response is the FRF times the unbalance force phasors
    W = 400.0
    speeds = {"inner": W, "outer": W * 1.3}
    frf = frequency_response(system, Operating.point(speeds), [(2, "x"), (2, "y")], [(3, "y")], [W])
    u = Unbalance(2, 3e-5, 0.7)
    res = unbalance_response(system, Operating.line([W], ratios={"outer": 1.3}), [u], [(3, "y")])
    F = u.m_e * W**2 * np.exp(1j * u.phase) * np.array([1.0, -1j])
    expected = frf.H[0, 0] @ F
    assert res.phasors["inner"][(3, "y")][0] == pytest.approx(expected, rel=1e-10)
    assert set(res.phasors) == {"inner"}


# --- reduced models --------------------------------------------------------------------------------------

def test_reduced_model_with_every_mode_gives_the_full_response():
    rig = load_rotor("seed-rig")
    system = assemble(rig)
    boundary = default_boundary_nodes(rig, (18,))
    red = reduce(system, boundary, n_modes=system.n_dof - 4 * len(boundary))
    sweep = np.linspace(0.0, 600.0, 31)
    args = (Operating.line(sweep, ratios={"outer": 9 / 7}), [Unbalance(11, 1e-5), Unbalance(16, 1e-5, 1.0)],
            [(13, "x"), (14, "y"), (11, "x"), (3, "y")])  # 11 and 3 are interior nodes
    full, got = unbalance_response(system, *args), unbalance_response(red, *args)
    # same linear system in other coordinates: round-off of an 80-DOF complex solve (measured 4.8e-11)
    assert response_error(full, got) < 1e-9


# --- output: CSV, plots, CLI -----------------------------------------------------------------------------

def test_csv_and_plots(tmp_path):
    rotor = transient_two_spool()
    system = assemble(rotor)
    sweep = np.linspace(0.0, 500.0, 21)
    res = unbalance_response(system, Operating.line(sweep, ratios={"outer": 1.2}),
                             [Unbalance(2, 1e-4), Unbalance(11, 1e-4)], [(2, "x"), (11, "y")])
    path = res.write_csv(tmp_path / "r.csv")
    with path.open() as fh:
        rows = list(csv.reader(fh))
    header, data = rows[0], np.array(rows[1:], dtype=float)
    assert header[:2] == ["inner speed (rpm)", "outer speed (rpm)"]
    assert len(data) == 21
    np.testing.assert_allclose(data[:, 0], sweep * 60 / (2 * math.pi), rtol=1e-9)
    np.testing.assert_allclose(data[:, 1], 1.2 * sweep * 60 / (2 * math.pi), rtol=1e-9)
    col = header.index("node 11 y @outer amplitude (um)")
    np.testing.assert_allclose(data[:, col], 1e6 * res.amplitude((11, "y"), "outer"), rtol=1e-9)
    col = header.index("node 2 x peak bound (um)")
    np.testing.assert_allclose(data[:, col], 1e6 * res.peak((2, "x")), rtol=1e-9)
    frf = frequency_response(system, AT_REST, [(2, "x")], [(2, "x"), (11, "x")], np.linspace(0, 2000, 50))
    for p in (save_figure(res.plot(kind="bode"), tmp_path / "b.png"), save_figure(res.plot(kind="polar"), tmp_path / "p.png"),
              save_figure(frf.plot(), tmp_path / "f.png"), frf.write_csv(tmp_path / "f.csv")):
        assert p.stat().st_size > 1000
    assert (tmp_path / "b.png").read_bytes()[:4] == b"\x89PNG"


def test_cli_harmonic_full_and_reduced(tmp_path, capsys):
    out = tmp_path / "full"
    assert main(["harmonic", "seed-rig", "--speeds", "0:6300:41", "--out", str(out),
                 "--frf", "18:x>13:x", "--frequencies", "0:300:31"]) == 0
    for f in ("response.csv", "bode.png", "polar.png", "frf.csv", "frf.png"):
        assert (out / f).stat().st_size > 0
    text = capsys.readouterr().out
    assert "node 11 (inner) 1e-05 kg m" in text and "node 16 (outer) 1e-05 kg m" in text  # rig defaults
    header = (out / "response.csv").read_text().splitlines()[0]
    assert "node 13 x @inner amplitude (um)" in header and "node 14 y @outer phase (deg)" in header
    out = tmp_path / "red"
    assert main(["harmonic", "seed-rig", "--speeds", "0:6300:41", "--out", str(out), "--reduced",
                 "--modes", "6", "--outputs", "13:x,14:y", "--unbalance", "11:2e-5:90"]) == 0
    text = capsys.readouterr().out
    assert "Craig-Bampton model, 30 DOFs" in text and "node 11 (inner) 2e-05 kg m at 90 deg" in text
    assert (out / "bode.png").exists()


def test_cli_harmonic_takes_a_scene(tmp_path, capsys):
    from rotorred.scenes import schema as scene
    loaded = scene.load_scene("paper-normal")
    out = tmp_path / "scene"
    assert main(["harmonic", "paper-normal", "--speeds", "0:6300:21", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    # the scene's unbalances, outputs and model are the defaults
    for u in loaded.unbalances:
        assert f"node {u.node} ({loaded.rotor.spool_of[u.node]}) {u.m_e:g} kg m" in text
    header = (out / "response.csv").read_text().splitlines()[0]
    for node, direction in loaded.output.dofs:
        assert f"node {node} {direction} peak bound (um)" in header
    if loaded.solver.model == "reduced":
        assert "Craig-Bampton model" in text


@pytest.mark.parametrize("argv, message", [
    (["--unbalance", "99:1e-5"], "--unbalance = 99: must be a node of the rotor (1-20)"),
    (["--unbalance", "11"], "NODE:ME"),
    (["--unbalance", "11:-1e-5"], "--unbalance = -1e-05: must be >= 0 (kg m)"),
    (["--outputs", "13:z"], "direction must be one of"),
    (["--speeds", "0:100:-3"], "--speeds = '0:100:-3': must be START:STOP:COUNT (COUNT >= 1) or a comma list of "
                               "numbers (rpm)"),
    (["--reduced", "--modes", "-2"], "--modes = -2: must be an integer >= 0"),
    (["--reduced", "--cutoff", "50"], "below the frequency band"),
    (["--ratio", "fan=2"], "--ratio = 'fan': must be one of 'outer'"),
])
def test_cli_bad_input(tmp_path, capsys, argv, message):
    assert main(["harmonic", "seed-rig", "--speeds", "0:6300:11", "--out", str(tmp_path)] + argv) == 2
    assert message in capsys.readouterr().err


def test_bad_input_is_named():
    import dataclasses

    rotor = transient_two_spool()
    system = assemble(rotor)
    ub = [Unbalance(2, 1e-5)]
    line = Operating.line([100.0], ratios={"outer": 1.2})
    nodes = r"\(1-3, 10-11\)"
    with pytest.raises(InputError, match=rf"^unbalances\[0\]\.node = 99: must be a node of the model {nodes}$"):
        unbalance_response(system, line, [Unbalance(99, 1e-5)], [(2, "x")])
    with pytest.raises(InputError, match=rf"^outputs\[0\] = \(42, 'x'\): must name a node of the model {nodes}; "
                                         r"node 42 is not one$"):
        unbalance_response(system, line, ub, [(42, "x")])
    with pytest.raises(InputError, match=r"^operating = \[100\.0\]: must be an Operating \(Operating\.point, "):
        unbalance_response(system, [100.0], ub, [(2, "x")])
    # the ratio rule is Operating's: a reference at nominal speed 0 gives no ratio; every spool must be the model's
    with pytest.raises(InputError, match=r"^operating = 'point: first spool at 100 rad/s': must state the "
                                         r"speed of spool\(s\) \['outer'\]"):
        unbalance_response(assemble(rotor.with_speeds({"inner": 0.0})), Operating.line([100.0]), ub, [(2, "x")])
    with pytest.raises(InputError, match=r"^ratios spool = 'fan': must be one of 'outer'$"):
        unbalance_response(system, Operating.line([100.0], ratios={"outer": 1.2, "fan": 2.0}), ub, [(2, "x")])
    with pytest.raises(InputError, match=r"^ratios spool = 'inner': must be one of 'outer'$"):
        unbalance_response(system, Operating.line([100.0], ratios={"inner": 2.0}), ub, [(2, "x")])
    # the spool of each node comes from the model: one built by hand with two spools has none
    with pytest.raises(InputError, match=r"^model = 'SystemMatrices': must know the spool of each node \(built from "
                                         r"a Rotor: assemble, reduce_rotor\) to place unbalances on a model of 2 "
                                         r"spools$"):
        unbalance_response(dataclasses.replace(system, rotor=None), AT_REST, ub, [(2, "x")])
    with pytest.raises(InputError, match=r"^unbalances = \[\]: must hold at least one Unbalance$"):
        unbalance_response(system, line, [], [(2, "x")])
    with pytest.raises(InputError, match=r"^inputs\[0\] = \(2, 'z'\): direction must be one of 'x', 'y', "):
        frequency_response(system, AT_REST, [(2, "z")], [(2, "x")], [10.0])
    with pytest.raises(InputError, match=r"^--outputs = '13x': must be NODE:DIRECTION \(e\.g\. '13:x'\)"):
        parse_dof("--outputs", "13x")
    red = reduce_rotor(rotor, n_modes=0)  # every node of this small rotor is a boundary node
    with pytest.raises(InputError, match=rf"^unbalances\[0\]\.node = 99: must be a node of the model {nodes}$"):
        unbalance_response(red, line, [Unbalance(99, 1e-5)], [(2, "x")])
    # steady state and FRF run at one point, not along a line
    for analysis, args in ((steady_state, (ub,)), (frequency_response, ([(2, "x")], [(2, "x")], [10.0]))):
        with pytest.raises(InputError, match=r"^operating = 'line of 2 speeds: first spool 0-100 rad/s': must be one "
                                             r"operating point \(Operating\.point\), not a line$"):
            analysis(system, Operating.line([0.0, 100.0]), *args)
