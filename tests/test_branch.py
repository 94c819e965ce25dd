"""Harmonic-balance branches of a rub scene (rotorred.scenes.branch, ``rotorred continue``): every point solves the
problem built independently from the scene at that value, the folds are where the branch turns, stability changes
are classified by the critical multiplier, an interrupt keeps the points, and the command writes its files."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
from datetime import datetime, timezone

import numpy as np
import pytest

from rotorred.cli import main
from rotorred.nonlinear.continuation import ContinuationOptions, continue_branch
from rotorred.nonlinear.examples import jeffcott
from rotorred.scenes.branch import BranchOptions, SceneBranch, continue_scene
from rotorred.scenes.harmonic_balance import rub_problem
from rotorred.scenes.run import build_model
from rotorred.scenes.schema import load_scene
from rotorred.scenes.torus_branch import TorusBranch

H, N = 20, 128  # coarse: the tests check the machinery, validation/hb_rig.py the rig at 100 harmonics


@pytest.fixture(scope="module")
def rig():
    scene = load_scene("paper-rub")
    return scene, build_model(scene).model


def _residual(scene, model, z) -> float:
    rp = rub_problem(scene, model, H, N)
    return rp.problem.evaluate(z, rp.omega).relative


def test_a_clearance_branch_solves_the_scene_at_each_clearance_and_turns_at_its_folds(rig):
    """From 45 um (out of contact: the linear response) to 25 um: each of 5 points solves the problem built from the
    scene loaded with that clearance (relative residual below the branch's 1e-9), the branch turns an even number of
    times (it goes on down: 4 smooth folds at 20 harmonics, 2 at 100 in validation/hb_rig.py), each fold within a step
    of its nearest point, and the peak at 45 um is the linear response's."""
    scene, model = rig
    branch = continue_scene(scene, model, "rub.clearance", 45e-6, 25e-6, BranchOptions(H, N, stability=False))
    assert branch.stopped == "reached the end, clearance = 2.5e-05 m" and branch.end == "reached"
    for i in np.linspace(0, len(branch.values) - 1, 5).astype(int):
        at = load_scene("paper-rub", {"rub.clearance": float(branch.values[i])})
        assert _residual(at, model, branch.z[i]) < 1e-9
    assert len(branch.folds) >= 2 and len(branch.folds) % 2 == 0 and all(smooth for _, smooth in branch.folds)
    for value, _ in branch.folds:
        near = np.argsort(np.abs(branch.values - value))[:3]
        assert np.min(np.abs(branch.values[near] - value)) < 0.05 * value
    free = rub_problem(load_scene("paper-rub", {"rub.clearance": 45e-6}), model, H, N)
    free_z = free.problem.linear_response(free.omega)
    assert branch.peaks[0, 0] == pytest.approx(np.max(np.abs(free.waveform(free_z, branch.dofs[0]))), rel=1e-9)


def test_a_speed_branch_keeps_the_speed_ratio_and_solves_the_scene_at_each_speed(rig):
    """From 90 to 91 Hz on the outer spool, the inner one at 7/9 of it: each point solves the problem built from the
    scene loaded at those two speeds (measured below 1e-9), its base frequency is the outer speed / 9."""
    scene, model = rig
    branch = continue_scene(scene, model, "speeds.outer", 90.0, 91.0, BranchOptions(H, N, stability=False))
    assert branch.stopped.startswith("reached the end, speeds.outer = 91")
    assert np.allclose(branch.f0, branch.values / 9, rtol=1e-12)
    for i in (0, len(branch.values) // 2, len(branch.values) - 1):
        f = float(branch.values[i])
        at = load_scene("paper-rub", {"speeds.outer": f, "speeds.inner": f * 7 / 9})
        rp = rub_problem(at, model, H, N, f0=f / 9)
        assert rp.problem.evaluate(branch.z[i], rp.omega).relative < 1e-9


def test_a_branch_in_the_plates_stiffness_solves_the_scene_at_each_stiffness(rig):
    """From 2e8 to 2e9 N/m of the plate's supports (rub.k_n): each of 3 points solves the problem built from the scene
    loaded with that stiffness (measured below 1e-9, the branch's tolerance), the base frequency stays 10 Hz, and the
    peak falls as the plate stiffens (the plate gives less, the disk is held nearer its clearance)."""
    scene, model = rig
    branch = continue_scene(scene, model, "rub.k_n", 2e8, 2e9, BranchOptions(H, N, stability=False))
    assert branch.stopped.startswith("reached the end, rub.k_n = 2e+09 N/m") and branch.unit == "N/m"
    assert np.all(branch.f0 == 10.0)
    for i in (0, len(branch.values) // 2, len(branch.values) - 1):
        at = load_scene("paper-rub", {"rub.k_n": float(branch.values[i])})
        assert _residual(at, model, branch.z[i]) < 1e-9
    assert branch.peaks[-1, 0] < branch.peaks[0, 0]


def test_a_value_the_plate_refuses_is_no_solution_not_a_crash(rig):
    """Along rub.mu_d (bounded by mu_s = 0.2): past the bound the family has no problem, an infinite residual (a failed
    step for the corrector, which keeps its points), a Jacobian that raises LinAlgError and a NaN linear response;
    at the bound itself dR/dmu_d is one-sided and equals the central difference a hair inside (measured 7.4e-10
    relative: both are differences with a step of 1e-6)."""
    from scipy.linalg import LinAlgError

    from rotorred.scenes.branch import SceneFamily

    scene, model = rig
    family = SceneFamily(scene, model, "rub.mu_d", H, N, 0.15)
    z = family.linear_response(0.15 * family.scale)
    past = family.evaluate(z, 0.25 * family.scale)
    assert past.relative == np.inf and np.isnan(family.linear_response(0.25 * family.scale)).all()
    with pytest.raises(LinAlgError):
        past.dR_dz
    at_bound = family.evaluate(z, 0.2 * family.scale).dR_domega
    inside = family.evaluate(z, 0.2 * (1 - 1e-5) * family.scale).dR_domega
    assert np.linalg.norm(at_bound - inside) < 7e-9 * np.linalg.norm(inside)


def test_stability_changes_are_classified_by_the_critical_multiplier():
    """A multiplier leaving the unit circle near -1 is a period-doubling, near +1 a fold, elsewhere a Neimark-Sacker;
    no change, no report."""
    values = np.arange(6.0)
    critical = np.array([0.5, -1.2, -0.9, 0.5 + 0.6j, 0.8 + 0.8j, 1.3])
    branch = SceneBranch("paper-rub", "rub.clearance", "m", values, values, ((18, "y"),), np.zeros((6, 1)),
                         np.zeros((6, 4)), np.zeros((6, 3)), critical, (), "reached the end", np.ones(6, int), 0.0, 0.0,
                         0.0, end="reached")
    assert [kind for _, _, kind in branch.bifurcations] == ["period-doubling", "period-doubling", "Neimark-Sacker"]
    assert [(a, b) for a, b, _ in branch.bifurcations] == [(0.0, 1.0), (1.0, 2.0), (3.0, 4.0)]
    assert list(branch.stable) == [True, False, True, True, False, False]


def test_an_interrupt_keeps_the_points_so_far():
    """SIGINT during a continuation (raised by the progress report at the 6th point) ends it there: 6 points kept,
    each a solution, and the branch says where it stopped."""
    problem = jeffcott(5, 128)

    def progress(points, omega):
        if points == 6:
            raise KeyboardInterrupt
    branch = continue_branch(problem, problem.linear_response(0.5), 0.5, 12.0,
                             ContinuationOptions(ds=0.1, stability=False), progress=progress)
    assert len(branch.omega) == 6 and branch.stopped.startswith("interrupted (SIGINT) at omega = ")
    assert branch.interrupt == "SIGINT"
    assert max(problem.evaluate(z, w).relative for z, w in zip(branch.z, branch.omega)) < 1e-10


def test_a_corner_step_that_newton_does_not_move_is_no_point(monkeypatch):
    """Past a corner the step in omega alone takes the first candidate Newton reaches. One reached from the corner's
    own solution without an iteration at a step shorter than the first (omega moved by 1e-13 rad/s: the old
    coefficients' residual there 5.3e-13, within 1e-10) is the same point and is passed over; from the linear
    response, or for a step Newton has to correct (1e-3 rad/s: 1 iteration, to 1.4e-16), it is the next point. At the
    first step it is a point (a flat branch): with the linear response made useless, ``_past_a_corner`` at ds = 1e-13
    returns the corner's solution at omega + ds, not at a shorter step."""
    import rotorred.nonlinear.continuation as continuation
    problem, tol = jeffcott(5, 128), 1e-10
    omega = 0.5
    found = continuation._solved(problem, problem.linear_response(omega), omega, tol)
    y = np.append(found.z, omega)
    point = continuation._Point(y, continuation._tangent(problem, y, None, 1.0, found.evaluation), found.iterations)
    assert continuation._candidate(problem, point, None, point.y[:-1], omega + 1e-13, 0.1, tol, own=True) is None
    same = continuation._candidate(problem, point, None, point.y[:-1], omega + 1e-13, 0.1, tol)
    assert same is not None and same.iterations == 0
    moved = continuation._candidate(problem, point, None, point.y[:-1], omega + 1e-3, 0.1, tol, own=True)
    assert moved is not None and moved.iterations >= 1
    monkeypatch.setattr(type(problem), "linear_response", lambda self, w: np.full(self.size, 1e3))
    flat = continuation._past_a_corner(problem, point, None, 1e-13, tol)
    assert flat is not None and flat.y[-1] == omega + 1e-13 and flat.iterations == 0


def test_after_a_corner_the_next_step_in_omega_alone_comes_after_one_failed_arclength_step(monkeypatch):
    """Where the branch goes on in corners (a point reached by a step in omega alone, its arclength steps failing), the
    next point tries that omega step again after the first failed arclength step, instead of after six halvings and
    the search from the largest step: with every arclength step made to fail, a point reached by a corner step of
    1e-3 rad/s gets its next at omega + 1e-3 after 1 arclength attempt; a point reached by an arclength step gets the
    search's first step (omega + ds) after 7. Each point is a solution to the tolerance."""
    import rotorred.nonlinear.continuation as continuation
    problem, tol = jeffcott(5, 128), 1e-10
    omega = 0.5
    found = continuation._solved(problem, problem.linear_response(omega), omega, tol)
    y = np.append(found.z, omega)
    t = continuation._tangent(problem, y, None, 1.0, found.evaluation)
    attempts = []

    def failing(*args, **kwargs):
        attempts.append(1)
        return None
    monkeypatch.setattr(continuation, "_arclength", failing)
    for corner, expected, tries in ((1e-3, omega + 1e-3, 1), (0.0, omega + 0.1, 7)):
        attempts.clear()
        point = continuation._Point(y, t, found.iterations, corner=corner)
        nxt, _, why = continuation._step(problem, point, None, 0.1, 1e-6, 0.5, tol)
        assert why == "" and nxt.y[-1] == expected and len(attempts) == tries
        assert nxt.corner == expected - omega and problem.evaluate(nxt.y[:-1], nxt.y[-1]).relative < tol


def test_a_branch_that_crawls_stops_saying_where_and_one_that_walks_does_not(monkeypatch):
    """``ContinuationOptions(stall=share)``: a branch whose steps are held to 1 % of its first (real points, each
    converged) moved 0.09 ds over its last 10 points, within 0.009 rad/s of omega = 0.5 (1.8 %): with a share of 5 % it
    ends as stalled after 10 points, saying where; with 0.1 % it goes on (the span too wide), and held to 20 % of its
    first step (1.8 ds over 10 points) too (it walks)."""
    import rotorred.nonlinear.continuation as continuation
    problem, traced = jeffcott(5, 128), continuation._step
    assert continuation.STALL_POINTS == 10

    def held(share):
        def step(problem, point, previous, ds, ds_min, ds_max, tol, curved=False):
            cap = share * 0.1
            return traced(problem, point, previous, min(ds, cap), ds_min, min(ds_max, cap), tol, curved)
        return step

    def branch(share, stall):
        monkeypatch.setattr(continuation, "_step", held(share))
        return continue_branch(problem, problem.linear_response(0.5), 0.5, 12.0,
                               ContinuationOptions(ds=0.1, stability=False, max_points=30, stall=stall))
    crawl = branch(0.01, 0.05)
    assert len(crawl.omega) == 10 and crawl.stopped.startswith(
        f"the branch stalled at {continuation._at(problem, crawl.omega[-1])}: its last 10 points lie within ")
    assert "less than its first step ds = 0.1; start another branch past it" in crawl.stopped
    assert max(problem.evaluate(z, w).relative for z, w in zip(crawl.z, crawl.omega)) < 1e-10
    assert branch(0.01, 1e-3).stopped.startswith("stopped at max_points = 30")
    assert branch(0.2, 0.05).stopped.startswith("stopped at max_points = 30")


def test_rotorred_continue_writes_the_branch(tmp_path):
    """The command writes branch.csv (a row a point, the key first), branch_lines.csv, branch.nc (the same values,
    labelled), branch.png and branch.txt (with the folds); the multipliers are computed (finite)."""
    import xarray as xr

    from provenance_checks import assert_provenance

    out = tmp_path / "b"
    since = datetime.now(timezone.utc)
    argv = ["continue", "paper-rub", "--param", "rub.clearance=45e-6:25e-6", "--harmonics", str(H), "--samples", str(N),
            "--out", str(out)]
    assert main(argv) == 0
    assert {p.name for p in out.iterdir()} >= {"branch.csv", "branch_lines.csv", "branch.nc", "branch.png",
                                               "branch.txt", "scene.toml"}
    resolved = assert_provenance(out, argv, "branch.txt", "scene", since)  # the base scene: paper-rub's clearance
    assert load_scene(out / "scene.toml").plates[0].clearance == load_scene("paper-rub").plates[0].clearance
    assert "rub.clearance=45e-6:25e-6" in (out / "branch.txt").read_text() and resolved
    with open(out / "branch.csv", newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0][0] == "rub.clearance (m)" and rows[0][2] == "peak 14y (um)"
    ds = xr.open_dataset(out / "branch.nc", engine="h5netcdf")
    values = np.array([float(r[0]) for r in rows[1:]])
    assert np.allclose(ds["rub_clearance"].values, values, rtol=1e-8)
    assert ds["rub_clearance"].attrs["rotorred_key"] == "rub.clearance" and ds["rub_clearance"].attrs["units"] == "m"
    assert np.allclose(ds["peak"].values[:, 0] * 1e6, [float(r[2]) for r in rows[1:]], rtol=1e-8)
    assert np.isfinite(ds["critical_multiplier_re"].values).all()
    assert "µm (fold)" in (out / "branch.txt").read_text()
    ds.close()


#: the child of the interrupt tests: ``rotorred`` with one library function wrapped so that its CALL-th call says so
#: on stderr ("parked ...") and waits there for the test's signal (up to 60 s), which then arrives in that function,
#: in that phase, with a known number of points done: no sleep in the test races the command
PARKED = """
import signal, sys, time
import importlib
from rotorred.cli import main
module, name, call = sys.argv.pop(1), sys.argv.pop(1), int(sys.argv.pop(1))
module = importlib.import_module(module)
original, calls = getattr(module, name), []
def parked(*args, **kwargs):
    calls.append(1)
    if len(calls) == call:
        print(f"parked at call {call} of {name}", file=sys.stderr, flush=True)
        end = time.monotonic() + 60
        while time.monotonic() < end:
            time.sleep(0.01)
        sys.exit("no signal came")
    return original(*args, **kwargs)
setattr(module, name, parked)
sys.exit(main())
"""
#: a short clearance branch: 45 to 40 um at 20 harmonics, the free orbit (stable) grazing the plate near 43 um, where
#: it loses stability; about a dozen points
SHORT_BRANCH = ["paper-rub", "--param", "rub.clearance=45e-6:40e-6", "--harmonics", str(H), "--samples", str(N)]


def _interrupted(out, where: tuple[str, str, int], sig) -> tuple[subprocess.CompletedProcess, list, object]:
    """``rotorred continue SHORT_BRANCH`` parked at ``where`` (module, function, call), sent ``sig`` there: the
    finished process, branch.csv's rows and branch.nc (loaded)."""
    import xarray as xr

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-c", PARKED, *map(str, where), "continue", *SHORT_BRANCH, "--out",
                             str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # as in a terminal
    line = proc.stderr.readline()
    while line.startswith("rotorred continue: "):  # the command's stage lines before it parks
        line = proc.stderr.readline()
    assert line.startswith("parked"), (line, proc.communicate())
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=120)
    done = subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)
    with open(out / "branch.csv", newline="") as f:
        rows = list(csv.reader(f))[1:]
    with xr.open_dataset(out / "branch.nc", engine="h5netcdf") as ds:
        return done, rows, ds.load()


def _traced_and_known(text: str) -> tuple[int, int]:
    """The points traced and those with their stability, as an interrupted branch's summary says."""
    traced = int(text.split(" points traced")[0].rsplit(" ", 1)[1])
    known = int(text.split("stability computed for ")[1].split()[0])
    return traced, known


def _said_interrupted(done, out, signal_name: str, status: int, phase: str) -> str:
    """Checks of what an interrupted ``continue`` says (exit status, one error line, no "reached the end" in the
    printout or branch.txt, the signal and the phase in both); branch.txt's text."""
    assert done.returncode == status, done.stderr
    assert "Traceback" not in done.stderr and f"rotorred continue: error: interrupted ({signal_name})" in done.stderr
    text = (out / "branch.txt").read_text()
    for said in (done.stdout, text):
        assert "reached the end" not in said and f"interrupted ({signal_name}) while {phase}" in said
    return text


def test_sigint_in_the_stability_phase_keeps_every_point_traced(tmp_path):
    """SIGINT while the 6th point's multipliers are computed: exit 130; branch.csv, branch.nc and branch.txt hold every
    point traced (to the first past 40 um: the whole range), the first 5 with their stability (both stable and
    unstable: the grazing), the others marked unknown alike in each (CSV "unknown", NetCDF flag -1, NaN multiplier);
    the printout and branch.txt say the branch was interrupted by SIGINT, where and how many points have their
    stability, and never that it reached the end."""
    out = tmp_path / "b"
    done, rows, ds = _interrupted(out, ("rotorred.scenes.branch", "floquet_by_monodromy", 6), signal.SIGINT)
    text = _said_interrupted(done, out, "SIGINT", 130, "computing stability")
    assert text.startswith("INCOMPLETE: interrupted (SIGINT)") and (out / "INCOMPLETE").exists()
    traced, known = _traced_and_known(text)
    values = np.array([float(r[0]) for r in rows])
    assert (traced, known) == (len(rows), 5) and len(rows) > known
    assert values[0] == 45e-6 and values[-1] <= 40e-6 < values[-2]  # the whole range traced
    assert f"at rub.clearance = {values[known]:.9g} m" in text  # the first point without its stability
    mu = np.array([float(r[-3]) for r in rows])
    stable = [r[-2] for r in rows]
    assert np.isfinite(mu[:known]).all() and np.isnan(mu[known:]).all()
    assert stable[:known] == [str(int(m < 1)) for m in mu[:known]] and {"0", "1"} <= set(stable[:known])
    assert set(stable[known:]) == {"unknown"}
    assert np.allclose(ds["rub_clearance"].values, values, rtol=1e-8) and ds.attrs["interrupted"] == "SIGINT"
    assert ds.attrs["end"] == "interrupted"  # the tracing reached its end; the signal ended the stability
    assert list(ds["stable"].values) == [int(s) if s != "unknown" else -1 for s in stable]
    assert ds["stable"].attrs["flag_meanings"] == "stable unstable unknown"
    assert np.isnan(ds["critical_multiplier_re"].values[known:]).all()
    assert np.isnan(ds["critical_multiplier_im"].values[known:]).all()
    assert text.count("| unknown") == traced - known  # every point shown: fewer than 25


def test_sigterm_while_tracing_keeps_the_points_so_far(tmp_path):
    """SIGTERM in the 6th continuation step: exit 143, the 6 points traced written (the branch short of 40 um), none
    with its stability (marked unknown), and the printout and branch.txt say SIGTERM ended the tracing there."""
    out = tmp_path / "b"
    done, rows, ds = _interrupted(out, ("rotorred.nonlinear.continuation", "_step", 6), signal.SIGTERM)
    text = _said_interrupted(done, out, "SIGTERM", 143, "tracing")
    values = np.array([float(r[0]) for r in rows])
    assert _traced_and_known(text) == (len(rows), 0) and len(rows) == 6 and values[-1] > 40e-6
    assert f"at rub.clearance = {values[-1]:.9g} m" in text
    assert {r[-2] for r in rows} == {"unknown"} and list(ds["stable"].values) == [-1] * 6
    assert ds.attrs["interrupted"] == "SIGTERM" and ds.attrs["stopped"] == text.splitlines()[0][len("INCOMPLETE: "):]
    assert ds.attrs["end"] == "interrupted"


def test_a_harmonic_balance_scene_records_its_periodic_solution(rig):
    """solver.method = "harmonic-balance": the record at the scene's times is the cold start's periodic solution, so
    the line fit of node 14 Y equals the solution's own harmonics on the 8 largest lines (measured 2.2e-14 of the
    largest: the fit is least squares on an exactly periodic record), the normal run is the linear steady state, and
    the contact is slip while the plate pushes (P > 0), open elsewhere."""
    from rotorred.scenes.balance_harmonics import cold_solution
    from rotorred.scenes.run import build_model, run_scene, start_record

    scene = load_scene("paper-rub", {"solver.method": "harmonic-balance", "solver.harmonics": H,
                                     "solver.samples": N})
    result = run_scene(scene, build_model(scene), compare_normal=True)
    assert result.method == "harmonic-balance" and result.normal.method == "harmonic"
    model = build_model(scene).model
    rp, z, _ = cold_solution(scene, model, H, N, record=start_record(scene, model))
    exact = rp.lines(z, (14, "y"))
    fitted = sorted(result.analyses[(14, "y")].fit.lines, key=lambda ln: -ln.amplitude)[:8]
    largest = max(exact.values())
    assert max(abs(ln.amplitude - exact[round(ln.frequency_hz, 6)]) for ln in fitted) < 2e-13 * largest
    contact = result.contacts[0]
    assert np.array_equal(contact.state == 1, contact.normal_force > 0) and 0 < np.mean(contact.state) < 0.5


def test_the_tolerance_chooses_the_harmonics_by_the_convergence_of_the_response(rig):
    """solver.tolerance with method "harmonic-balance": the first truncation of the ladder whose response changes from
    the one before by at most the tolerance is returned (the earlier ones changed by more), its solution solves its
    problem, and the change bounds the error of what is returned: against the next truncation, solved here from it,
    the error is below the estimate (measured at tol = 0.05: 100 harmonics, estimate 0.027, error 0.0030), and the
    observed order of the ladder's changes is above 1 (measured 3.9), the condition under which it does."""
    from rotorred.nonlinear.hb import solve_periodic
    from rotorred.scenes.balance_harmonics import balance_to_tolerance, padded, response_change, samples_for

    scene, model = rig
    dofs, tol = scene.output.dofs, 0.05
    rp, z, choice = balance_to_tolerance(scene, model, tol, dofs)
    assert choice.estimate <= tol and all(change > tol for _, change in choice.steps[:-1])
    assert (rp.problem.harmonics.H, rp.problem.harmonics.N) == (choice.harmonics, choice.samples)
    assert rp.problem.evaluate(z, rp.omega).relative < 1e-9
    fine = rub_problem(scene, model, 2 * choice.harmonics, samples_for(2 * choice.harmonics))
    z_fine = solve_periodic(fine.problem, padded(z, fine), fine.omega, tol=1e-9).z
    error = response_change(rp, z, fine, z_fine, dofs)
    assert error < choice.estimate
    assert np.log2(choice.steps[-2][1] / choice.estimate) > 1.0


def test_a_harmonic_balance_scene_with_a_tolerance_says_what_it_chose(tmp_path, capsys):
    """``rotorred run`` with solver.tolerance and method "harmonic-balance" prints the harmonics chosen and the
    estimate behind them, and writes that solution's record."""
    status = main(["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "solver.tolerance=0.05",
                   "--set", "output.plots=[]", "--no-normal", "--out", str(tmp_path / "o")])
    out = capsys.readouterr().out
    assert status == 0
    assert "solver.tolerance = 0.05: 100 harmonics and 2048 AFT samples a period" in out
    assert "response: harmonic balance, 100 harmonics of f0 = 10 Hz" in out


def test_the_cold_solution_through_coarser_truncations_is_the_cold_start_at_its_own(rig):
    """cold_solution (a cold start at 25 harmonics, Newton at 50) reaches the solution the cold start at 50 harmonics
    reaches by itself (measured 1.4e-12 apart, both solved to 1e-9), for less (validation/hb_rig.py times them)."""
    from rotorred.scenes.balance_harmonics import COLD, cold_solution
    from rotorred.scenes.branch import cold_start

    scene, model = rig
    rp, z, how = cold_solution(scene, model, 50, 1024)
    assert (rp.problem.harmonics.H, rp.problem.harmonics.N, how) == (50, 1024, COLD)
    direct = cold_start(rp.problem, rp.omega)
    assert rp.problem.evaluate(z, rp.omega).relative < 1e-9
    assert np.linalg.norm(z - direct) < 1e-10 * np.linalg.norm(direct)


def test_the_file_formats_page_lists_every_end_code_and_attribute_of_branch_nc(rig):
    """docs/maps.md names each code a branch may end with (continuation.ENDS) and each attribute of both kinds of
    ``branch.nc`` (a periodic branch's to_xarray, built here on a short branch)."""
    from pathlib import Path

    from rotorred.nonlinear.continuation import ENDS
    text = " ".join((Path(__file__).parents[1] / "docs" / "maps.md").read_text(encoding="utf-8").split())
    assert all(f"`{code}`" in text for code in ENDS)
    scene, model = rig
    branch = continue_scene(scene, model, "rub.clearance", 45e-6, 40e-6,
                            BranchOptions(harmonics=H, samples=N, max_points=2, stability=False))
    torus = TorusBranch("paper-rub", "rub.clearance", "m", np.array([2e-5, 1.9e-5]), np.full((2, 2), 30.0),
                        np.array([[0, 0], [1, 0]]), (14, "y"), np.ones((2, 2)), np.zeros((2, 6)), (), "reached",
                        np.array([0, 2]), np.ones(2), np.ones(2), "test", end="reached")
    names = set(branch.to_xarray().attrs) | set(torus.to_xarray().attrs)
    assert {"end", "gaps", "truncation", "bifurcations"} <= names
    assert all(f"`{name}`" in text for name in names)
