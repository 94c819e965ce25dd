"""The one operating-point type (rotorred.model.operating.Operating) and its ratio rule."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import rotorred as rr
from rotorred.checks import InputError
from rotorred.model.assembly import SystemMatrices, system_of
from rotorred.model.elements import Bearing, Disk, Material, ShaftElement
from rotorred.model.loads import Unbalance
from rotorred.model.operating import Operating, from_rad_s, to_rad_s
from rotorred.model.rotor import Rotor, Spool
from rotorred.model.speeds import SpeedProfile


def three_spools(speeds=(100.0, 150.0, 50.0)) -> Rotor:
    """Three coaxial-free spools a, b, c of four elements, a disk and two bearings each (nominal speeds rad/s)."""
    steel = Material("steel", E=2.1e11, rho=7850.0, nu=0.3)
    spools = tuple(Spool(name, tuple(ShaftElement(first + i, first + i + 1, 0.1, 0.03, 0.0, steel) for i in range(4)),
                         speed=w) for name, first, w in zip(("a", "b", "c"), (0, 10, 20), speeds))
    disks = tuple(Disk(first + 2, 5.0, 0.02, 0.04) for first in (0, 10, 20))
    bearings = tuple(Bearing(k_xx=1e7, k_yy=1e7, c_xx=50.0, c_yy=50.0, node=n) for n in (0, 4, 10, 14, 20, 24))
    return Rotor(spools, disks=disks, bearings=bearings, name="three")


def test_units_convert_exactly_both_ways():
    """rpm, Hz and rad/s: 30/pi and 2 pi, and back to the same number."""
    assert to_rad_s(3000.0, "rpm") == pytest.approx(100 * math.pi, rel=1e-15)
    assert to_rad_s(50.0, "Hz") == pytest.approx(100 * math.pi, rel=1e-15)
    np.testing.assert_allclose(from_rad_s(to_rad_s(np.array([0.0, 1234.5]), "rpm"), "rpm"), [0.0, 1234.5], rtol=1e-15)
    with pytest.raises(InputError, match=r"^unit = 'rps': must be one of 'rad/s', 'rpm', 'Hz'"):
        to_rad_s(1.0, "rps")


def test_line_follows_nominal_ratios_stated_ratios_and_fixed_speeds():
    """Omega_s = a_s Omega + b_s: the nominal ratio where nothing is stated, a stated ratio, a fixed speed."""
    rotor = three_spools()
    W = np.array([0.0, 10.0, 20.0])
    assert {s: v.tolist() for s, v in Operating.line(W).speeds(rotor).items()} == \
        {"a": [0.0, 10.0, 20.0], "b": [0.0, 15.0, 30.0], "c": [0.0, 5.0, 10.0]}
    op = Operating.line(W, "b", ratios={"a": 2.0}, fixed={"c": 7.0})
    assert {s: v.tolist() for s, v in op.speeds(rotor).items()} == \
        {"a": [0.0, 20.0, 40.0], "b": [0.0, 10.0, 20.0], "c": [7.0, 7.0, 7.0]}
    assert [line.how for line in op.lines(rotor).values()] == ["ratio", "reference", "fixed"]
    # the same through an assembled and a reduced model: the protocol carries the rotor's nominal speeds
    for model in (system_of(rotor), rr.reduce_rotor(rotor, n_modes=4)):
        assert {s: v.tolist() for s, v in Operating.line(W).speeds(model).items()}["b"] == [0.0, 15.0, 30.0]


def test_zero_reference_speed():
    """A reference at rest: a stated ratio gives 0, a fixed spool keeps its speed; a point can hold the reference at
    0 with the others turning; when the nominal reference speed is 0 every other spool must be stated."""
    rotor = three_spools((0.0, 150.0, 50.0))
    assert Operating.point({"a": 0.0, "b": 300.0, "c": 20.0}).at(rotor) == {"a": 0.0, "b": 300.0, "c": 20.0}
    assert Operating.line([0.0, 5.0], ratios={"b": 2.0}, fixed={"c": 3.0}).at(rotor, 0) == \
        {"a": 0.0, "b": 0.0, "c": 3.0}
    with pytest.raises(InputError, match=r"must state the speed of spool\(s\) \['c'\] \(ratios= or fixed=\): the "
                                         r"nominal speed of the reference spool 'a' is 0"):
        Operating.line([0.0, 5.0], ratios={"b": 2.0}).speeds(rotor)


def test_point_line_profile_and_their_errors():
    rotor = three_spools()
    p = Operating.point({"b": 3000.0, "a": 1500.0}, unit="rpm")
    assert p.kind == "point" and p.reference_of(rotor) == "b"
    assert p.single(rotor) == pytest.approx({"a": 50 * math.pi, "b": 100 * math.pi, "c": 100 * math.pi / 3}, rel=1e-14)
    line = Operating.line([0.0, 100.0])
    assert line.kind == "line"
    with pytest.raises(InputError, match=r"^operating = 'line of 2 speeds: first spool 0-100 rad/s': must be one "
                                         r"operating point"):
        line.single(rotor)
    with pytest.raises(InputError, match=r"^ratios spool = 'd': must be one of 'b', 'c'"):
        Operating.line([1.0], ratios={"d": 1.0}).speeds(rotor)
    with pytest.raises(InputError, match=r"^fixed = .*must not name a spool that ratios also names \(b\)"):
        Operating.line([1.0], ratios={"b": 1.0}, fixed={"b": 2.0})
    with pytest.raises(InputError, match=r"^Omega = .*must hold values >= 0 only \(rpm\)"):
        Operating.line([-1.0], unit="rpm")
    ramp = Operating.ramp({"a": 0.0}, {"a": 100.0}, 2.0)
    assert ramp.kind == "profile"
    full = ramp.profile_for(rotor)
    assert {s: w.tolist() for s, w in full.speeds.items()} == {"a": [0.0, 100.0], "b": [0.0, 150.0], "c": [0.0, 50.0]}
    with pytest.raises(InputError, match=r"must be a point or a speed line for speeds\(\)"):
        ramp.speeds(rotor)
    const = Operating.point({"a": 10.0}).profile_for(rotor)
    assert isinstance(const, SpeedProfile) and const.speeds_at(5.0) == {"a": 10.0, "b": 15.0, "c": 5.0}


def test_repr_is_one_short_line():
    text = repr(Operating.line(np.linspace(0, 12000, 61), "inner", ratios={"outer": 1.3}, unit="rpm"))
    assert text == "Operating(line of 61 speeds: inner 0-12000 rpm; outer at ratio 1.3)"


# --- every analysis reads its spool speeds from the Operating by the one rule ----------------------------------------
@dataclasses.dataclass(frozen=True)
class _Recording(SystemMatrices):
    """An assembled model that records the spool speeds (rad/s) its speed-dependent matrices are asked for."""

    calls: list = dataclasses.field(default_factory=list, compare=False, repr=False)

    @classmethod
    def of(cls, rotor: Rotor) -> _Recording:
        sm = system_of(rotor)
        return cls(**{f.name: getattr(sm, f.name) for f in dataclasses.fields(SystemMatrices)})

    def damping(self, speeds):
        self.calls.append(dict(speeds))
        return super().damping(speeds)

    def stiffness(self, speeds):
        self.calls.append(dict(speeds))
        return super().stiffness(speeds)

    def taken(self) -> list[dict]:
        """The speeds of the calls since the last ``taken``, each rounded to 1e-9 rad/s (a float key)."""
        out, self.calls[:] = [{s: round(w, 9) for s, w in c.items()} for c in self.calls], []
        return out


def _linear_analyses(model, operating):
    """Each analysis of rotorred.linear run on ``model`` at ``operating`` (a point runs at every point analysis)."""
    unbalances = [Unbalance(2, 1e-4), Unbalance(12, 1e-4, 1.0), Unbalance(22, 1e-4, 2.0)]
    out = {"campbell": lambda: rr.campbell(model, operating, n_modes=4),
           "unbalance_response": lambda: rr.unbalance_response(model, operating, unbalances, [(2, "x"), (12, "y")])}
    if operating.kind == "point":
        out["steady_state"] = lambda: rr.steady_state(model, operating, unbalances)
        out["frequency_response"] = lambda: rr.frequency_response(model, operating, [(2, "x")], [(22, "y")],
                                                                  [10.0, 200.0])
    return out


@pytest.mark.parametrize("operating, reference, line, grid", [
    # points with the reference at rest: a spool held at a fixed speed turns, one at the nominal ratio stands
    (Operating.line([0.0], "a", fixed={"b": 300.0}), "a", lambda W: {"a": W, "b": 300.0, "c": 0.5 * W}, [0.0]),
    (Operating.point({"c": 0.0, "a": 40.0}), "c", lambda W: {"a": 40.0, "b": 3.0 * W, "c": W}, [0.0]),
    # a line from a reference at rest: a stated ratio, a fixed speed
    (Operating.line([0.0, 40.0, 80.0], "b", ratios={"a": 2.0}, fixed={"c": 30.0}), "b",
     lambda W: {"a": 2.0 * W, "b": W, "c": 30.0}, [0.0, 40.0, 80.0]),
])
def test_every_linear_analysis_computes_at_the_operatings_spool_speeds(operating, reference, line, grid):
    """Campbell, unbalance response, steady state and FRF, given the same Operating, ask the three-spool model (nominal
    speeds 100, 150, 50 rad/s) for its matrices at the spool speeds written out here by hand (Eq. O1, docs/model.md
    §17: ``line``, at the reference speeds ``grid``): each at every point of the operating condition and at no other
    speed; the Campbell diagram's root refinement between grid speeds stays on the line."""
    model = _Recording.of(three_spools())
    expected = {tuple(line(W).items()) for W in grid}
    for name, run in _linear_analyses(model, operating).items():
        result = run()
        calls = {tuple(c.items()) for c in model.taken()}
        assert result.operating is operating, name
        if name == "campbell":
            assert expected <= calls, name
            for c in map(dict, calls):
                assert c == pytest.approx(line(c[reference]), rel=1e-12, abs=1e-9), (name, c)
        else:
            assert calls == expected, name


@pytest.mark.parametrize("operating, line", [
    # the reference at rest: a spool held at a fixed speed turns, one at the nominal ratio stands
    (Operating.line([0.0], "a", fixed={"b": 300.0}), lambda W: {"a": W, "b": 300.0, "c": 0.5 * W}),
    # the reference at rest, another spool given: the third follows the reference at its nominal ratio 3
    (Operating.point({"c": 0.0, "a": 40.0}), lambda W: {"a": 40.0, "b": 3.0 * W, "c": W}),
    # every spool turning: b fixed, c at the nominal ratio 1/3 of the reference b
    (Operating.point({"b": 240.0, "a": 70.0}), lambda W: {"a": 70.0, "b": W, "c": W / 3.0}),
])
def test_simulate_runs_at_the_operatings_spool_speeds(operating, line):
    """simulate given an Operating point asks the three-spool model for its matrices at the spool speeds the rule
    gives (written out here by hand) and at no other, and its unbalance forces turn at those speeds: started on the
    settled unbalance response at those speeds (a phasor solve by hand, one per spool), a damped run stays on it
    (measured: within 3.9e-7 of each output's largest amplitude over 0.02 s; asserted 4e-6; every spool 1 % faster
    moves it by 3-8 %)."""
    model = _Recording.of(three_spools())
    speeds = line(operating.Omega[0])
    unbalances = [Unbalance(2, 1e-4), Unbalance(12, 2e-4, 1.0), Unbalance(22, 3e-4, 2.0)]
    outputs = [(2, "x"), (12, "y"), (22, "x")]
    D = model.damping(speeds)
    q0, v0 = np.zeros(model.n_dof), np.zeros(model.n_dof)
    phasors = []
    for s, W in speeds.items():  # F = m_e W^2 e^(i phase) (1, -i) on the unbalance's node, x(t) = Re(X e^(i W t))
        F = np.zeros(model.n_dof, complex)
        for u in unbalances:
            if model.spool_of[u.node] == s:
                F[model.dofs.index(u.node, "x")] += u.m_e * W**2 * np.exp(1j * u.phase)
                F[model.dofs.index(u.node, "y")] += -1j * u.m_e * W**2 * np.exp(1j * u.phase)
        X = np.linalg.solve(model.K - W**2 * model.M + 1j * W * D, F)
        phasors.append((W, X))
        q0, v0 = q0 + X.real, v0 - W * X.imag
    model.taken()
    res = rr.simulate(model, operating, 0.02, 1e-5, loads=rr.Loads(unbalances), recording=rr.Recording(outputs),
                      start=rr.Initial(q0, v0), control=rr.StepControl(progress=False))
    assert {tuple(c.items()) for c in model.taken()} == {tuple({s: round(w, 9) for s, w in speeds.items()}.items())}
    for o in outputs:
        row = model.output_rows([o])[0]
        settled = sum((row @ X * np.exp(1j * W * res.t)).real for W, X in phasors)
        assert np.max(np.abs(res.outputs[o] - settled)) <= 4e-6 * np.max(np.abs(settled)), o  # 0 on a spool at rest


def test_simulate_fills_a_spool_its_profile_leaves_out_by_the_rule():
    """A run-up that gives spool a only (or a and b) runs b and c at their nominal ratios 1.5 and 0.5 to a: the same
    history, to the last bit, as the profile that gives every spool so; b at ratio 1 instead changes b's output by 86 %
    of its largest value (measured)."""
    rotor = three_spools()
    unbalances = rr.Loads([Unbalance(2, 1e-4), Unbalance(12, 2e-4, 1.0), Unbalance(22, 3e-4, 2.0)])
    recording = rr.Recording([(2, "x"), (12, "y"), (22, "x")])

    def history(operating):
        res = rr.simulate(rotor, operating, 0.05, 2e-5, loads=unbalances, recording=recording,
                          control=rr.StepControl(progress=False))
        return np.array(list(res.outputs.values()))

    full = history(Operating.ramp({"a": 20.0, "b": 30.0, "c": 10.0}, {"a": 100.0, "b": 150.0, "c": 50.0}, 0.05))
    np.testing.assert_array_equal(history(Operating.ramp({"a": 20.0}, {"a": 100.0}, 0.05)), full)
    np.testing.assert_array_equal(history(Operating.ramp({"a": 20.0, "b": 30.0}, {"a": 100.0, "b": 150.0}, 0.05)),
                                  full)
    other = history(Operating.ramp({"a": 20.0, "b": 20.0}, {"a": 100.0, "b": 100.0}, 0.05))
    assert np.max(np.abs(other[1] - full[1])) > 0.3 * np.max(np.abs(full[1]))


@pytest.mark.parametrize("operating, expected", [
    # the reference at rest: the spools at the nominal ratio stand still too, a given spool turns
    (Operating.point({"c": 0.0, "a": 2 * np.pi * 20.0}), {"a": 2 * np.pi * 20.0, "b": 0.0, "c": 0.0}),
    # every spool turning: c follows the reference b at its nominal ratio 1/3
    (Operating.point({"b": 2 * np.pi * 30.0, "a": 2 * np.pi * 20.0}),
     {"a": 2 * np.pi * 20.0, "b": 2 * np.pi * 30.0, "c": 2 * np.pi * 10.0}),
])
def test_harmonic_balance_runs_at_the_operatings_spool_speeds(operating, expected):
    """harmonic_balance (its start's transient and the balance itself) asks the three-spool model for its matrices
    at the spool speeds the rule gives, written out here by hand, and at no other; the base frequency is their
    greatest common divisor (20 and 10 Hz)."""
    rotor = three_spools()
    model = _Recording.of(rotor)
    unbalances = [u for u in (Unbalance(2, 1e-4), Unbalance(12, 1e-4, 1.0), Unbalance(22, 1e-4, 2.0))
                  if expected[model.spool_of[u.node]] > 0]
    model.taken()
    result = rr.harmonic_balance(model, operating, rr.Loads(unbalances), [rr.RubPlate(node=2, disk_radius=0.1)],
                                 rr.BalanceOptions(harmonics=8, samples=64, dt=1e-4))
    assert {tuple(c.items()) for c in model.taken()} == {tuple({s: round(w, 9) for s, w in expected.items()}.items())}
    assert result.speeds == pytest.approx(expected, rel=1e-15)
    assert result.problem.f0 == pytest.approx(min(w for w in expected.values() if w > 0) / (2 * np.pi), rel=1e-12)


@pytest.mark.parametrize("operating, expected, bases", [
    # the reference c at rest, a and b given: the torus of a's and b's frequencies (20 Hz, 10 sqrt(2) Hz)
    (Operating.point({"c": 0.0, "a": 2 * np.pi * 20.0, "b": 2 * np.pi * 10.0 * np.sqrt(2.0)}),
     {"a": 2 * np.pi * 20.0, "b": 2 * np.pi * 10.0 * np.sqrt(2.0), "c": 0.0}, (20.0, 10.0 * np.sqrt(2.0))),
    # every spool turning: c follows the reference b at its nominal ratio 1/3, the order (0, 1) of the bases
    (Operating.point({"b": 2 * np.pi * 10.0 * np.sqrt(2.0), "a": 2 * np.pi * 20.0}),
     {"a": 2 * np.pi * 20.0, "b": 2 * np.pi * 10.0 * np.sqrt(2.0), "c": 2 * np.pi * 10.0 * np.sqrt(2.0) / 3.0},
     (20.0, 10.0 * np.sqrt(2.0) / 3.0)),
])
def test_torus_balance_runs_at_the_operatings_spool_speeds(operating, expected, bases):
    """torus_balance (its start's transient and the balance on the torus) asks the three-spool model for its matrices
    at the spool speeds the rule gives, written out here by hand, and at no other; each turning spool's frequency is
    the order of the bases it must be (a (1, 0), b (0, 1) or (0, 3), c (0, 1)), and a spool at rest is order (0, 0)."""
    model = _Recording.of(three_spools())
    unbalances = [u for u in (Unbalance(2, 1e-4), Unbalance(12, 1e-4, 1.0), Unbalance(22, 1e-4, 2.0))
                  if expected[model.spool_of[u.node]] > 0]
    model.taken()
    result = rr.torus_balance(model, operating, rr.Loads(unbalances), [rr.RubPlate(node=2, disk_radius=0.1)],
                              rr.TorusOptions(bases=bases, orders=(2, 6), f_max=None, start_window=(1.0, 2.0),
                                              start_orders=(1, 1), dt=1e-4))
    assert {tuple(c.items()) for c in model.taken()} == {tuple({s: round(w, 9) for s, w in expected.items()}.items())}
    assert result.speeds == pytest.approx(expected, rel=1e-15)
    k_b = (0, 1) if expected["c"] == 0 else (0, 3)
    assert result.problem.spool_orders == {"a": (1, 0), "b": k_b, "c": (0, 1) if expected["c"] > 0 else (0, 0)}


def test_continue_balance_keeps_the_operatings_ratios_along_its_branch():
    """continue_balance along a's speed line (b, c at the nominal ratios 1.5 and 0.5) asks the three-spool model for
    its matrices only at speeds on the line: b = 1.5 a and c = 0.5 a at every call (to the 1e-9 rad/s the recording
    rounds to), a from 20 Hz on."""
    rotor = three_spools()
    model = _Recording.of(rotor)
    model.taken()
    branch = rr.continue_balance(model, Operating.line([20.0, 20.2], "a", unit="Hz"), rr.Loads([Unbalance(2, 1e-4)]),
                                 [rr.RubPlate(node=2, disk_radius=0.1)],
                                 rr.BranchOptions(harmonics=8, samples=64, stability=False, max_points=6))
    calls = model.taken()
    assert len(calls) > 3 and len(branch.values) >= 2
    for c in calls:
        assert c["b"] == pytest.approx(1.5 * c["a"], abs=2e-9) and c["c"] == pytest.approx(0.5 * c["a"], abs=2e-9)
        assert c["a"] >= 2 * np.pi * 20.0 * (1 - 1e-6)


def test_runup_fills_the_spools_its_profile_leaves_out_by_the_rule():
    """runup along a ramp of spool a from rest (a zero reference speed) to 100 rad/s: its scene's profile turns b and c
    at the nominal ratios 1.5 and 0.5 to a at every breakpoint (written out here by hand), and the model is asked for
    its matrices only at speeds on that line."""
    model = _Recording.of(three_spools())
    model.taken()
    result = rr.runup(model, Operating.ramp({"a": 0.0}, {"a": 100.0}, 0.05), rr.Loads([Unbalance(2, 1e-4)]), (),
                      rr.RunupOptions(dt=1e-4, record_dt=1e-4, nodes=(2,), orbits_hz=()), progress=False)
    p = result.scene.runup.profile
    np.testing.assert_array_equal(p.speeds["a"], [0.0, 100.0])
    np.testing.assert_allclose(p.speeds["b"], 1.5 * p.speeds["a"], rtol=1e-15)
    np.testing.assert_allclose(p.speeds["c"], 0.5 * p.speeds["a"], rtol=1e-15)
    for c in model.taken():
        assert c["b"] == pytest.approx(1.5 * c["a"], abs=1e-9) and c["c"] == pytest.approx(0.5 * c["a"], abs=1e-9)


def test_envelope_map_runs_each_point_at_the_rules_speeds(tmp_path):
    """envelope_map along spool a's line from rest (a zero reference speed) with b at the stated ratio 2 and c fixed at
    30 rad/s: the scene of each point (as its worker reads it) turns the spools at the speeds written out here by hand
    (to the 1e-12 a speed's round trip through Hz allows), and both points run."""
    run = rr.envelope_map(three_spools(), Operating.line([0.0, 50.0], "a", ratios={"b": 2.0}, fixed={"c": 30.0}),
                          rr.Loads([Unbalance(12, 1e-4), Unbalance(22, 1e-4)]), (),
                          rr.MapOptions(dt=1e-4, duration=0.05, record_start=0.03, nodes=(12, 22), table=(22, "y"),
                                        workers=0, figures=False), tmp_path / "map")
    assert run.n_run == 2 and run.n_failed == 0
    for i, W in enumerate((0.0, 50.0)):
        assert run.spec.scene_at((i,)).speeds == pytest.approx({"a": W, "b": 2.0 * W, "c": 30.0}, rel=1e-12, abs=1e-12)


def test_a_scene_reads_its_speeds_by_the_rule(tmp_path):
    """A scene's [speeds] is an Operating point: with the outer spool given alone, the inner follows it at the seed
    rig's nominal ratio 70/90 (the rule of Operating.point, written out here by hand), and the scene's operating point
    gives another analysis the same speeds; the outer spool given at rest stops the inner too, which is refused (no
    spool turns)."""
    text = (Path(rr.__file__).parent / "scenes" / "builtin" / "paper-normal.toml").read_text(encoding="utf-8")
    assert "inner = 70.0\nouter = 90.0\n" in text
    path = tmp_path / "one-spool.toml"
    path.write_text(text.replace("inner = 70.0\nouter = 90.0\n", "outer = 100.0\n"), encoding="utf-8")
    scene = rr.load_scene(path)
    expected = {"inner": 2 * np.pi * 100.0 * 70.0 / 90.0, "outer": 2 * np.pi * 100.0}
    assert scene.speeds == pytest.approx(expected, rel=1e-15) and list(scene.speeds) == ["inner", "outer"]
    assert scene.operating.reference == "outer"
    assert rr.campbell(scene.rotor, scene.operating, n_modes=2).operating is scene.operating
    (tmp_path / "resolved.toml").write_text(rr.scene_toml(scene), encoding="utf-8")
    assert rr.load_scene(tmp_path / "resolved.toml").speeds == scene.speeds  # to the bit, the reference first
    path.write_text(text.replace("inner = 70.0\nouter = 90.0\n", "outer = 0.0\n"), encoding="utf-8")
    with pytest.raises(InputError, match=r"speeds = \{'outer': 0.0\}: must give at least one spool of inner, outer a "
                                         r"speed > 0"):
        rr.load_scene(path)
