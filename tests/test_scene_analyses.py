"""The scene analyses from Python on (model, operating, loads, contacts, options): harmonic_balance, continue_balance
and runup."""

from __future__ import annotations

import numpy as np
import pytest

import rotorred as rr
from results_checks import assert_shows_itself

H, N = 20, 128  # coarse, as tests/test_branch.py: the machinery, not the rig's converged response


@pytest.fixture(scope="module")
def rig():
    scene = rr.load_scene("paper-rub", {"solver.method": "harmonic-balance", "solver.harmonics": H,
                                        "solver.samples": N})
    return scene, rr.build_model(scene)


@pytest.fixture(scope="module")
def balance(rig):
    scene, sm = rig
    return rr.harmonic_balance(sm.model, scene.operating, rr.Loads(scene.unbalances), scene.plates,
                               rr.BalanceOptions(H, N, outputs=[(14, "y"), (18, "x"), (18, "y")]))


def test_two_starts_one_solution(rig, balance):
    """The scene's harmonic balance (run_scene) and the function, given the scene's model, speeds, unbalances and
    plates, reach the same periodic solution by the same steps: at node 14 y and the rub node, over the scene's
    record, within 1e-9 of the peak (measured 0: one implementation), and the function's residual meets the
    tolerance (measured 4.2e-14)."""
    scene, sm = rig
    result = rr.run_scene(scene, sm, compare_normal=False, analyse=False)
    t = result.t
    for dof in [(14, "y"), (18, "x")]:
        x = result.outputs[dof]
        err = np.max(np.abs(balance.waveform(dof, t) - x)) / np.max(np.abs(x))
        assert err < 1e-9, (dof, err)
    assert balance.residual <= 1e-9 and balance.H == H and balance.problem.f0 == pytest.approx(10.0, rel=1e-12)


def test_the_amplitudes_are_the_waveforms_harmonics(balance):
    """The amplitude of each harmonic equals the DFT of the waveform sampled over one period (two paths; measured
    2.9e-21 m on a 2.5e-6 m peak, 1e-17 allowed: round-off)."""
    n = 4 * (H + 1)
    t = np.arange(n) / (n * balance.problem.f0)
    x = balance.waveform((14, "y"), t)
    dft = np.abs(np.fft.rfft(x)) / n * 2
    dft[0] /= 2
    np.testing.assert_allclose(balance.amplitudes[:, 0], dft[:H + 1], rtol=0, atol=1e-17)


def test_the_result_shows_itself(balance, tmp_path):
    assert_shows_itself(balance, tmp_path, of=rr.RubBalance)
    assert "f_0 = 10 Hz, 20 harmonics, 128 samples a period" in repr(balance)


def test_bad_input_is_refused_before_computing(rig):
    scene, sm = rig
    op = scene.operating
    with pytest.raises(rr.InputError, match=r"^loads.gravity = 9.81: must be None"):
        rr.harmonic_balance(sm.model, op, rr.Loads(scene.unbalances, gravity=9.81), scene.plates)
    with pytest.raises(rr.InputError, match=r"^contacts = \[\]: must hold at least 1"):
        rr.harmonic_balance(sm.model, op, rr.Loads(scene.unbalances), [])
    with pytest.raises(rr.InputError, match=r"^operating = 'line of 2 speeds"):
        rr.harmonic_balance(sm.model, rr.Operating.line([1.0, 2.0]), rr.Loads(scene.unbalances), scene.plates)
    with pytest.raises(rr.InputError, match=r"must be commensurate"):
        rr.harmonic_balance(sm.model, rr.Operating.point({"inner": 440.0, "outer": 565.4866776461628 * np.sqrt(1.01)}),
                            rr.Loads(scene.unbalances), scene.plates)
    with pytest.raises(rr.InputError, match=r"^options.samples = 41: must be an integer >= 42"):
        rr.BalanceOptions(20, 41)


def test_a_speed_line_is_the_scenes_branch_in_its_speed(rig):
    """continue_balance along the outer spool's speed line 90 -> 91 Hz (inner at the nominal ratio 70/90) is the
    scene's branch in speeds.outer (tests/test_branch.py): the same values within 1e-9 (measured 4.1e-11: the inner
    speed from the rotor's nominal ratio differs from the scene's 70 Hz in its last bits) and peaks within 1e-8
    (measured 1.2e-9: points solved to a residual of 1e-9 at those values); every spool keeps its harmonic of f_0."""
    scene, sm = rig
    branch = rr.continue_balance(sm.model, rr.Operating.line([90.0, 91.0], "outer", unit="Hz"),
                                 rr.Loads(scene.unbalances), scene.plates, rr.BranchOptions(H, N, stability=False),
                                 nodes=[14, 18])
    by_key = rr.continue_scene(scene, sm.model, "speeds.outer", 90.0, 91.0, rr.BranchOptions(H, N, stability=False))
    np.testing.assert_allclose(branch.values, by_key.values, rtol=1e-9)
    for dof in set(branch.dofs) & set(by_key.dofs):
        np.testing.assert_allclose(branch.peaks[:, branch.dofs.index(dof)], by_key.peaks[:, by_key.dofs.index(dof)],
                                   rtol=1e-8)
    assert branch.dofs[0] == (14, "y") and (18, "x") in branch.dofs
    assert branch.values[0] == 90.0 and branch.stopped.startswith("reached the end, speeds.outer = 91")
    np.testing.assert_allclose(branch.f0, branch.values / 9.0, rtol=1e-12)  # outer at 9 f_0, inner at 7


def test_a_speed_line_with_a_fixed_spool_is_refused(rig):
    scene, sm = rig
    with pytest.raises(rr.InputError, match=r"must turn every spool at a ratio to the reference; \['inner'\] at a "
                                            r"fixed speed"):
        rr.continue_balance(sm.model, rr.Operating.line([90.0, 91.0], "outer", fixed={"inner": 70.0}, unit="Hz"),
                            rr.Loads(scene.unbalances), scene.plates)
    with pytest.raises(rr.InputError, match=r"must be a speed line of at least two speeds"):
        rr.continue_balance(sm.model, scene.operating, rr.Loads(scene.unbalances), scene.plates)


def test_a_runup_from_python_is_the_scenes_runup(tmp_path):
    """runup(model, Operating.profile, ...) given a run-up scene's model, profile, loads, plates and options is the
    scene's run-up (run_runup): the same record at every recorded DOF and the same 1x order tracks (measured equal:
    one implementation, one scene built from the inputs), and a profile that gives only the reference spool is filled
    by the Operating rule to the scene's (the outer spool at 90/70 of the inner one)."""
    sc = rr.load_scene("runup-rub", {"runup.to": 0.4, "runup.duration": 0.5, "runup.orbits_hz": [20.0]})
    sm = rr.build_model(sc)
    by_scene = rr.run_runup(sc, sm, progress=False)
    r = sc.runup
    only_inner = rr.SpeedProfile(r.profile.t, {"inner": r.profile.speeds["inner"]})
    result = rr.runup(sm.model, rr.Operating.profile(only_inner), rr.Loads(sc.unbalances), sc.plates,
                      rr.RunupOptions(dt=sc.solver.dt, record_dt=r.record_dt, orders=r.orders, nodes=sc.output.nodes,
                                      orbits_hz=r.orbits_hz, revs_per_block=r.revs_per_block), progress=False)
    np.testing.assert_allclose(result.scene.runup.profile.speeds["outer"], r.profile.speeds["outer"], rtol=1e-15)
    for dof, x in by_scene.outputs.items():
        np.testing.assert_array_equal(result.outputs[dof], x)
    assert len(result.tracks) == len(by_scene.tracks) > 0
    for a, b in zip(result.tracks, by_scene.tracks):
        np.testing.assert_array_equal(a.amplitude, b.amplitude)
    assert_shows_itself(result, tmp_path, of=rr.RunupResult)


def test_a_scene_built_from_python_writes_a_scene_file_that_reads_back_to_it():
    """The scene runup builds from its inputs (and continue_balance's) is written by scene_toml, as a command's
    scene.toml is: its rotor inline (rotor_table), unbalances and plates from the objects, the profile as a table
    in Hz; reading the text back gives the same rotor, unbalances and plates to the bit, and the speeds and the
    profile within 1 ulp where no number of Hz reads back exactly (a scene file gives speeds in Hz only)."""
    from rotorred.scenes.schema import scene_from_toml

    sc = rr.load_scene("runup-rub", {"runup.to": 0.2, "runup.duration": 0.05, "runup.orbits_hz": []})
    u = [rr.Unbalance(11, 1e-5, 0.1234567), *sc.unbalances[1:]]  # a phase with no exact number of degrees or one
    result = rr.runup(sc.rotor, rr.Operating.profile(sc.runup.profile), rr.Loads(u), sc.plates,
                      rr.RunupOptions(dt=1e-4, record_dt=1e-4, nodes=(18,)), progress=False)
    back = scene_from_toml(rr.scene_toml(result.scene))
    assert back.rotor == sc.rotor and back.speeds == pytest.approx(result.scene.speeds, rel=2.3e-16)
    assert back.unbalances == tuple(u) and back.plates == sc.plates
    for s in sc.runup.profile.spools:
        np.testing.assert_allclose(back.runup.profile.speeds[s], result.scene.runup.profile.speeds[s], rtol=2.3e-16)


def test_a_map_along_a_speed_line_is_the_commands_map(tmp_path):
    """envelope_map along the outer spool's line 89, 90 Hz (inner at 7/9 of it) is ``rotorred map paper-rub --vary
    speeds.outer=89,90 --ratio inner=0.7778`` on the same settings: every numeric variable of the two datasets equal
    (measured: bit for bit; the model reaches the workers as its mode count and kept nodes, the scene through its
    file); the same call again resumes every point."""
    short = {"solver.duration": 1.0, "solver.record_start": 0.6, "output.plot_window": [0.6, 0.7],
             "output.plots": [], "output.formats": [], "output.compare_normal": False}
    sc = rr.load_scene("paper-rub", short)
    sm = rr.build_model(sc)
    args = (sm.model, rr.Operating.line([89.0, 90.0], "outer", ratios={"inner": 7 / 9}, unit="Hz"),
            rr.Loads(sc.unbalances), sc.plates,
            rr.MapOptions(dt=sc.solver.dt, duration=1.0, record_start=0.6, nodes=sc.output.nodes, table=(14, "y"),
                          workers=0, figures=False))
    ours = rr.envelope_map(*args, tmp_path / "python")
    spec = rr.MapSpec("paper-rub", (rr.Axis("speeds.outer", (89.0, 90.0)),), settings=tuple(short.items()),
                      ratios=(("inner", 7 / 9),))
    theirs = rr.run_map(spec, tmp_path / "command", workers=0, progress=False, figures=False)
    a, b = ours.to_xarray(), theirs.to_xarray()
    compared = 0
    for name in b.data_vars:
        if name != "wall_time" and np.issubdtype(b[name].dtype, np.number):
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
            compared += 1
    assert compared >= 15 and ours.n_run == 2
    assert rr.envelope_map(*args, tmp_path / "python").n_resumed == 2


@pytest.fixture(scope="module")
def torus(rig):
    """paper-rub at outer 91.37 Hz (inner 70 Hz), rubbing: torus_balance on the coarse set of
    tests/test_nonlinear_torus.py (|k1| <= 6, |k2| <= 30, grid 32 x 256), the torus found by the line fit of its
    start's transient (2-3 s)."""
    scene, sm = rig
    op = rr.Operating.point({"outer": 2 * np.pi * 91.37, "inner": 2 * np.pi * 70.0})
    return op, rr.torus_balance(sm.model, op, rr.Loads(scene.unbalances), scene.plates,
                                rr.TorusOptions(orders=(6, 30), f_max=None, outputs=[(14, "y"), (18, "x")]))


def test_the_torus_is_the_transients_lines(rig, torus):
    """The torus the start's line fit finds is (f_L, f_H/3); Newton converges from the record's least squares (measured
    7 iterations, residual 9e-15), and the three largest lines at node 14 Y equal those of an independent 3 s transient
    (rr.simulate, fitted on 2-3 s; measured f_H -0.15 %, 4f_H/3 -0.35 %, f_L -0.017 %, asserted as
    tests/test_nonlinear_torus.py)."""
    scene, sm = rig
    op, result = torus
    assert result.bases_hz == pytest.approx((70.0, 91.37 / 3), rel=1e-12)
    assert result.problem.spool_orders == {"inner": (1, 0), "outer": (0, 3)}
    assert result.start == "the transient's record (least squares)"
    assert result.solution.iterations <= 10 and result.solution.residual < 1e-10
    res = rr.simulate(sm.model, op, 3.0, scene.solver.dt, loads=rr.Loads(scene.unbalances), contacts=scene.plates,
                      recording=rr.Recording([(14, "y")], start=2.0), control=rr.StepControl(progress=False))
    fit = rr.fit_lines(res.t, res.outputs[(14, "y")], 70.0, 91.37)
    lines = {ln.label: ln for ln in fit.lines}
    for label, tol in (("f_H", 1.5e-2), ("4f_H/3", 3.5e-2), ("f_L", 2e-3)):
        k = int(np.argmin(np.abs(result.frequencies - lines[label].frequency_hz)))
        assert result.frequencies[k] == pytest.approx(lines[label].frequency_hz, rel=1e-9)
        assert result.amplitudes[k, 0] == pytest.approx(lines[label].amplitude, rel=tol), label


def test_the_torus_shows_itself(torus, tmp_path):
    assert_shows_itself(torus[1], tmp_path, of=rr.RubTorus)
    assert "bases f_1 = 70 Hz, f_2 = 30.4567 Hz; spool orders inner (1, 0), outer (0, 3)" in repr(torus[1])


def test_torus_bad_input_is_refused_before_computing(rig):
    scene, sm = rig
    op = rr.Operating.point({"outer": 2 * np.pi * 91.37, "inner": 2 * np.pi * 70.0})
    loads = rr.Loads(scene.unbalances)
    with pytest.raises(rr.InputError, match=r"^loads.gravity = 9.81: must be None"):
        rr.torus_balance(sm.model, op, rr.Loads(scene.unbalances, gravity=9.81), scene.plates)
    with pytest.raises(rr.InputError, match=r"^operating = 'line of 2 speeds"):
        rr.torus_balance(sm.model, rr.Operating.line([1.0, 2.0]), loads, scene.plates)
    with pytest.raises(rr.InputError, match=r"^options.bases = \(60.0, 30.45.*\): must hold each spool frequency as one "
                       r"order k1 f1 \+ k2 f2; 70 Hz is no order of the bases"):
        rr.torus_balance(sm.model, op, loads, scene.plates, rr.TorusOptions(bases=(60.0, 91.37 / 3)))
    with pytest.raises(rr.InputError, match=r"70 Hz is several orders: the bases are commensurate"):
        rr.torus_balance(sm.model, op, loads, scene.plates, rr.TorusOptions(bases=(70.0, 35.0)))
    with pytest.raises(rr.InputError, match=r"^options.bases = None: must be given where they cannot be found"):
        rr.torus_balance(sm.model, op, loads, scene.plates, rr.TorusOptions(start_window=None))
    with pytest.raises(rr.InputError, match=r"^options.grid\[1\] = 60: must be even and > 2 \* orders\[1\] = 60"):
        rr.TorusOptions(orders=(6, 30), grid=(32, 60))
