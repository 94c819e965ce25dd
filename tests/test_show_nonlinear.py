"""The nonlinear and map results show themselves (rotorred.results.Result): a short repr, a Figure, a dataset with
units that round-trips through NetCDF; and each dataset holds the result's own numbers, checked against a second path
(the waveform's spectrum, the recovered torus, the scene's problem at that value, the points on disk)."""

from __future__ import annotations

import numpy as np
import pytest

import rotorred as rr
from matplotlib.figure import Figure

from results_checks import assert_dataset_round_trips, assert_plots, assert_short_repr, assert_shows_itself
from rotorred.maps.spec import Axis, MapSpec
from rotorred.maps.store import PointStore
from rotorred.nonlinear.continuation import ContinuationOptions, continue_branch
from rotorred.nonlinear.examples import F, duffing, jeffcott
from rotorred.nonlinear.forces import CubicSpring
from rotorred.nonlinear.hb import solve_periodic
from rotorred.nonlinear.torus import TorusHarmonics, TorusProblem, alias_free_grid, solve_torus
from rotorred.scenes.harmonic_balance import rub_problem
from rotorred.scenes.schema import load_scene

#: paper-rub shortened as in tests/test_maps.py: 1.0 s run, 0.4 s recorded
SHORT = (("solver.duration", 1.0), ("solver.record_start", 0.6), ("output.plot_window", [0.6, 0.7]),
         ("output.plots", []), ("output.formats", []), ("output.compare_normal", False))


@pytest.fixture(scope="module", params=["jeffcott", "duffing"])
def periodic(request):
    """The Jeffcott rotor in its clearance (2 DOFs, 5 harmonics) at omega = 0.98, in contact on its circular orbit
    (harmonic 1 alone); the Duffing oscillator (1 DOF, 7 harmonics) at omega = 1.6, on its lower branch (odd
    harmonics)."""
    problem, omega = (jeffcott(5, 128), 0.98) if request.param == "jeffcott" else (duffing(7), 1.6)
    return problem, solve_periodic(problem, problem.linear_response(omega), omega)


@pytest.fixture(scope="module")
def duffing_branch():
    """The Duffing oscillator with 3 harmonics from omega = 0.5 to 2.5: two folds, stable and unstable points."""
    problem = duffing(3)
    z0 = np.zeros(problem.size)
    z0[1] = F / (1 - 0.25)  # the linear response at omega = 0.5
    return problem, continue_branch(problem, z0, 0.5, 2.5, ContinuationOptions(ds=0.1, ds_max=0.2))


@pytest.fixture(scope="module")
def torus():
    """A cubic oscillator forced at two incommensurate frequencies (3 x 3 orders)."""
    h = TorusHarmonics(3, 3, *alias_free_grid(3, 3, 3))
    w = (0.8, 0.8 * np.sqrt(2.0))
    Q = np.zeros((h.n_orders, 1), complex)
    Q[h.index(1, 0)], Q[h.index(0, 1)] = 0.15, 0.1
    problem = TorusProblem(np.eye(1), 0.2 * np.eye(1), np.eye(1), h, w, (0,), h.from_phasors(Q),
                           (CubicSpring(0, 0.5),))
    return problem, solve_torus(problem, problem.linear_response())


@pytest.fixture(scope="module")
def scene_branch():
    """paper-rub's clearance branch from 45 to 40 um at 20 harmonics, with stability: the free orbit grazing the plate
    near 43 um and losing stability there."""
    from rotorred.scenes.branch import BranchOptions, continue_scene
    from rotorred.scenes.run import build_model

    scene = load_scene("paper-rub")
    model = build_model(scene).model
    return scene, model, continue_scene(scene, model, "rub.clearance", 45e-6, 40e-6, BranchOptions(20, 128))


@pytest.fixture(scope="module")
def map_run(tmp_path_factory):
    """A two-point clearance sweep of the shortened paper-rub, run serially, its figures written."""
    from rotorred.maps.run import run_map

    spec = MapSpec("paper-rub", (Axis("rub.clearance", (20e-6, 40e-6)),), settings=SHORT, direction="up")
    out = tmp_path_factory.mktemp("map")
    return spec, out, run_map(spec, out, workers=0, progress=False)


def test_a_periodic_solution_shows_itself(periodic, tmp_path):
    problem, solution = periodic
    assert_shows_itself(solution, tmp_path, of=rr.PeriodicSolution)
    text = repr(solution)
    assert f"omega = {solution.omega:g} rad/s" in text and f"{problem.n} DOFs, {problem.harmonics.H} harmonics" in text


def test_a_periodic_solutions_dataset_is_its_coefficients_and_its_waveforms_spectrum(periodic):
    """cos and sin are the coefficients a_k, b_k read from z's harmonic-major layout; the amplitude of each harmonic
    is the one of the waveform sampled over a period, by the FFT (measured 2.2e-16 and 1.4e-17 m, amplitudes 1.0 and
    0.064 m); a nonlinear solution: Newton iterated, and harmonics other than 1 (Duffing's 3 at 4.7e-6 of its 1)."""
    problem, solution = periodic
    ds = solution.to_xarray()
    n, H = problem.n, problem.harmonics.H
    for k in range(1, H + 1):
        for d in range(n):
            assert ds["cos"].values[k, d] == solution.z[(2 * k - 1) * n + d]
            assert ds["sin"].values[k, d] == solution.z[2 * k * n + d]
    assert (ds["cos"].values[0] == solution.z[:n]).all() and (ds["sin"].values[0] == 0).all()
    q = problem.samples(solution.z, solution.omega)[0]  # (N, n) over one period
    spectrum = np.abs(np.fft.rfft(q, axis=0)) / len(q)
    by_fft = np.vstack([spectrum[0], 2 * spectrum[1:H + 1]])
    np.testing.assert_allclose(ds["amplitude"].values, by_fft, rtol=0, atol=2e-15)
    np.testing.assert_allclose(ds["frequency"].values, np.arange(H + 1) * solution.omega / (2 * np.pi), rtol=1e-15)
    assert float(ds["omega"]) == solution.omega and ds.attrs["iterations"] == solution.iterations > 0
    if problem.n == 2:  # the Jeffcott rotor in contact: its orbit reaches past the clearance, 1
        assert ds["amplitude"].values[1].max() > 1.0
    else:
        assert ds["amplitude"].values[3, 0] > 1e-6 * ds["amplitude"].values[1, 0]


def test_a_branch_shows_itself(duffing_branch, tmp_path):
    problem, branch = duffing_branch
    assert_shows_itself(branch, tmp_path, of=rr.Branch)
    text = repr(branch)
    assert "in omega (rad/s)" in text and "turns: 2, at omega = " in text and "stopped: reached the end" in text


def test_a_branch_figure_breaks_its_line_where_told():
    """``plot_branch(..., breaks)``: no line joins a point to the one before it at each break (a NaN between them in
    the drawn data), with stability (its runs) and without; a break that is no point's is refused."""
    from rotorred.checks import InputError
    from rotorred.plots.branch import plot_branch
    values, peaks = np.linspace(1.0, 2.0, 6), np.linspace(1e-6, 2e-6, 6)
    for stable in (None, np.array([1, 1, 1, 0, 0, 0], float)):
        fig = plot_branch(values, peaks, stable, (), xlabel="w (rad/s)", ylabel="peak (µm)", breaks=[2, 4])
        x = np.concatenate([line.get_xdata() for line in fig.axes[0].lines])
        assert np.isnan(x).sum() == 2 and np.all(np.isin(values, x))
    with pytest.raises(InputError, match="breaks"):
        plot_branch(values, peaks, None, (), xlabel="w (rad/s)", ylabel="peak (µm)", breaks=[6])


def test_a_branchs_dataset_is_its_points_folds_and_stability(duffing_branch):
    """The amplitude of harmonic 1 of each point is Branch.amplitude (read from z by its own index rule); the
    parameter is omega; the stability flag is the sign of the largest Floquet exponent; the folds are the branch's."""
    problem, branch = duffing_branch
    ds = branch.to_xarray()
    for k in (0, 1, 3):  # |a - i b| and hypot(a, b): measured 2.5e-16 apart
        np.testing.assert_allclose(ds["amplitude"].values[:, k, 0], branch.amplitude(0, k), rtol=3e-15, atol=0)
    np.testing.assert_array_equal(ds["parameter"].values, branch.omega)
    assert ds["parameter"].attrs == {"units": "rad/s", "long_name": "omega"}
    np.testing.assert_array_equal(ds["stable"].values == 1, branch.max_real < 0)
    assert set(ds["stable"].values) == {0, 1}  # both kinds: the unstable middle part between the folds
    np.testing.assert_array_equal(ds["fold_parameter"].values, [f.omega for f in branch.folds])
    assert len(branch.folds) == 2 and ds["fold_smooth"].values.tolist() == [1, 1]


def test_an_interrupted_branch_says_so_in_short_lines(tmp_path):
    """SIGINT at the 6th point: the repr says where it stopped, in lines of at most 120 characters; 6 points drawn."""
    problem = jeffcott(5, 128)

    def progress(points, omega):
        if points == 6:
            raise KeyboardInterrupt
    branch = continue_branch(problem, problem.linear_response(0.5), 0.5, 12.0, ContinuationOptions(ds=0.1),
                             progress=progress)
    text = assert_short_repr(branch)
    assert "stopped: interrupted (SIGINT) at omega = " in text and "6 points from 0.5 to" in text
    assert len(assert_plots(branch).axes[0].lines[0].get_xdata()) == 6


def test_a_branch_in_a_family_shows_the_familys_parameter(scene_branch, tmp_path):
    """A family's parameter (its name and unit) labels the dataset's coordinate, its values the carried ones (the
    clearance, m: not scaled); stability not computed is -1."""
    from rotorred.nonlinear.condensed import ClearanceFamily

    scene, model, _ = scene_branch
    rp = rub_problem(scene, model, 20, 128)
    family = ClearanceFamily(rp.problem, rp.omega)
    z = rp.problem.linear_response(rp.omega)
    scale = float(np.linalg.norm(z))
    branch = continue_branch(family, z, 45e-6, 44e-6,
                             ContinuationOptions(ds=0.05 * scale, ds_min=1e-10 * scale, ds_max=0.12 * scale,
                                                 stability=False, tol=1e-9))
    ds = assert_dataset_round_trips(branch, tmp_path)
    assert ds["parameter"].attrs["long_name"] == "clearance" and ds["parameter"].attrs["units"] == "m"
    np.testing.assert_array_equal(ds["parameter"].values, branch.omega)
    assert (ds["stable"].values == -1).all() and "stability not computed" in assert_short_repr(branch)
    assert "in clearance (m)" in repr(branch)
    assert_plots(branch)


def test_a_torus_shows_itself(torus, tmp_path):
    assert_shows_itself(torus[1], tmp_path, of=rr.TorusSolution)
    assert "w = (0.8, 1.13137" in repr(torus[1])


def test_a_torus_dataset_is_its_coefficients_and_the_recovered_lines(torus):
    """The amplitude of each order is the complex amplitude the problem recovers from the solution through the
    compliance and the forces (measured 2e-16 against 0.27); the orders' k1, k2 and frequencies k . w / 2 pi."""
    problem, solution = torus
    ds = solution.to_xarray()
    recovered = problem.recover(solution.z)[:, 0]
    np.testing.assert_allclose(ds["amplitude"].values[:, 0], np.abs(recovered), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(ds["cos"].values[1:, 0], solution.z[1::2])
    np.testing.assert_array_equal(ds["k1"].values, problem.harmonics.orders[:, 0])
    np.testing.assert_allclose(ds["frequency"].values, problem.frequencies / (2 * np.pi), rtol=1e-15)
    np.testing.assert_array_equal(ds["history"].values, solution.history)


def test_a_scene_branch_shows_itself(scene_branch, tmp_path):
    branch = scene_branch[2]
    assert_shows_itself(branch, tmp_path, of=rr.SceneBranch)
    text = repr(branch)
    assert "branch of paper-rub in rub.clearance (µm)" in text and "from 45 to 39.7" in text


def test_a_scene_branchs_dataset_is_the_scene_solved_at_each_value(scene_branch):
    """The peak at a point is the largest |q(t)| of the waveform of the problem built from the scene loaded at that
    clearance (measured 0 m: the same waveform), the stability flag the multiplier's modulus below 1."""
    scene, model, branch = scene_branch
    ds = branch.to_xarray()
    np.testing.assert_array_equal(ds["rub_clearance"].values, branch.values)
    for i in (0, len(branch.values) // 2, len(branch.values) - 1):
        rp = rub_problem(load_scene("paper-rub", {"rub.clearance": float(branch.values[i])}), model, 20, 128)
        peak = np.max(np.abs(rp.waveform(branch.z[i], branch.dofs[0])))
        assert ds["peak"].values[i, 0] == pytest.approx(peak, rel=1e-12)
    np.testing.assert_array_equal(ds["stable"].values == 1, np.abs(branch.critical) < 1)
    assert set(ds["stable"].values) == {0, 1}


def test_a_map_shows_itself_in_each_of_its_figures(map_run, tmp_path):
    spec, out, run = map_run
    assert_shows_itself(run, tmp_path, of=rr.MapRun)
    assert "map of paper-rub over rub.clearance (2 values)" in repr(run)
    for kind in ("waterfall", "bifurcation"):
        assert_plots(run, kind=kind)
    top, bottom = Figure().subplots(2, 1)
    assert run.plot((top, bottom), kind="lines") is top.figure and top.lines and bottom.lines
    with pytest.raises(ValueError, match=r"^kind = 'heatmap': needs a map of two varied keys"):
        run.plot(kind="heatmap")
    with pytest.raises(ValueError, match=r"^kind = 'bode': must be one of bifurcation, lines, waterfall, heatmap$"):
        run.plot(kind="bode")
    assert {p.name for p in out.glob("*.png")} == {"bifurcation.png", "lines.png", "waterfall.png"}


def test_a_maps_dataset_is_its_points_on_disk(map_run):
    """Every point's class, contact fraction and strongest line in the dataset are the ones of the point file."""
    spec, out, run = map_run
    ds = run.to_xarray().sel(direction="up")
    points = PointStore(out, spec).read()
    assert len(points) == 2
    for (direction, (i,)), p in points.items():
        one = ds.isel(rub_clearance=i)
        assert str(one["kind"].values) == p.kind and float(one["contact_fraction"]) == p.contact_fraction
        assert float(one["line_amplitude"][0]) == p.line_amplitude[0]
