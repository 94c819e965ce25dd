"""The scene pipeline: harmonic vs time stepping, only what is needed, spectra, files, CLI, the paper."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest

from rotorred.linear.harmonic import unbalance_response
from rotorred.model.operating import Operating
from rotorred.scenes.outputs import write_outputs
from rotorred.scenes.run import build_model, harmonic_outputs, run_scene, settled_state
from rotorred.scenes.schema import scene_from_dict

ROOT = Path(__file__).resolve().parents[1]

#: a short linear scene on the full seed-rig model; alpha = 40 1/s makes every mode decay with
#: sigma >= alpha / 2 = 20 1/s, so a start-up from rest has settled to e^-34 after 1.7 s
LINEAR = {
    "name": "linear",
    "rotor": {"preset": "seed-rig", "rayleigh_alpha": 40.0, "rayleigh_beta": 2e-5},
    "speeds": {"inner": 70.0, "outer": 90.0},
    "unbalance": [{"node": 11, "m_e": 1e-4}, {"node": 18, "m_e": 1e-3, "phase_deg": 40.0}],
    "solver": {"model": "full", "dt": 2e-5, "duration": 0.5, "record_start": 0.3},
    "output": {"nodes": [13, 14], "directions": ["x", "y"], "plot_window": [0.3, 0.4]},
}


def _scene(**changes):
    data = copy.deepcopy(LINEAR)
    for path, value in changes.items():
        section, _, key = path.partition("__")
        if key:
            data.setdefault(section, {})[key] = value
        else:
            data[section] = value
    return scene_from_dict(data)


@pytest.fixture(scope="module")
def linear():
    sc = _scene()
    return sc, run_scene(sc)


def test_linear_settled_scene_gets_the_harmonic_solution(linear):
    sc, res = linear
    assert res.method == "harmonic" and res.n_steps == 0 and res.contacts == ()
    # only the requested DOFs, only the recorded window
    assert list(res.outputs) == [(13, "x"), (13, "y"), (14, "x"), (14, "y")]
    assert res.t[0] == pytest.approx(0.3, abs=1e-12) and res.t[-1] == pytest.approx(0.5, abs=1e-12)
    assert len(res.t) == 10001 and all(len(v) == len(res.t) for v in res.outputs.values())


def test_spectrum_reads_the_phasor_amplitudes_exactly(linear):
    """The spectral lines at f_L and f_H equal |Q| of the independent harmonic module.

    The record (0.2 s, two common periods) puts both tones on bins, where the rectangular window
    reads them exactly; the only error is rounding (1e-9 relative).
    """
    sc, res = linear
    model = build_model(sc).model
    ref = unbalance_response(model, Operating.line([sc.speeds["inner"]], "inner", ratios={"outer": 90.0 / 70.0}),
                             sc.unbalances, sc.output.dofs)
    for d in sc.output.dofs:
        spec = res.spectra[d]
        for spool, f in (("inner", 70.0), ("outer", 90.0)):
            assert spec.amplitude_at(f) == pytest.approx(abs(ref.phasors[spool][d][0]), rel=1e-9)
        assert sorted(ln.label for ln in res.lines[d].lines) == ["f_H", "f_L"]


def test_spectra_leave_the_records_unchanged(linear):
    """The recorded arrays are not overwritten by the FFT (pyFFTW plans adopt aligned inputs)."""
    sc, res = linear
    again = harmonic_outputs(sc, build_model(sc).model, res.t)
    for d in sc.output.dofs:
        np.testing.assert_array_equal(res.outputs[d], again[d])


def test_startup_from_rest_converges_to_the_harmonic_solution(linear):
    """Independent check of the harmonic path: Newmark time stepping from rest.

    Tolerance: the start-up transient has decayed to e^-34 by 1.7 s (sigma >= 20 1/s); what is
    left is Newmark's period error, a relative frequency error (Omega dt)^2 / 12, i.e. a phase
    drift of Omega t (Omega dt)^2 / 12 for the fastest tone by t = 2 s; twice that bounds the
    difference relative to the peak.
    """
    sc, res = linear
    rest = _scene(solver={"model": "full", "dt": 2e-5, "duration": 2.0, "record_start": 1.7, "start": "rest"},
                  output={"nodes": [13, 14], "directions": ["x", "y"], "plots": [], "formats": []})
    res_rest = run_scene(rest)
    assert res_rest.method == "transient" and res_rest.n_steps == 100_000
    assert res_rest.counters["n_contact_steps"] == 0 and res_rest.contacts == ()  # no plate, no contact work
    harmonic = harmonic_outputs(rest, build_model(rest).model, res_rest.t)
    w = 2 * math.pi * 90.0
    tol = 2 * w * 2.0 * (w * 2e-5) ** 2 / 12
    for d in rest.output.dofs:
        err = np.max(np.abs(res_rest.outputs[d] - harmonic[d])) / np.max(np.abs(harmonic[d]))
        assert err < tol, (d, err, tol)


def test_settled_state_is_the_harmonic_solution_at_t0(linear):
    sc, _ = linear
    model = build_model(sc).model
    q0, v0 = settled_state(sc, model)
    R = model.output_rows(sc.output.dofs)
    t = np.array([0.0, 1e-7])
    y = harmonic_outputs(sc, model, t)
    for j, d in enumerate(sc.output.dofs):
        assert R[j] @ q0 == pytest.approx(y[d][0], rel=1e-12)
        # velocity against a central difference of the harmonic solution (error O(Omega^2 h) ~ 1e-4)
        assert R[j] @ v0 == pytest.approx((y[d][1] - y[d][0]) / 1e-7, rel=1e-3)


@pytest.fixture(scope="module")
def rub():
    """paper-rub on a short window: 0.6 s from the settled state (the rub settles in < 0.3 s)."""
    from rotorred.scenes.schema import load_scene
    sc = load_scene("paper-rub", {"solver.duration": 0.6, "solver.record_start": 0.4,
                                  "output.plot_window": [0.4, 0.54]})
    return sc, run_scene(sc)


def test_rub_scene_records_contact_and_a_normal_comparison(rub):
    sc, res = rub
    assert res.method == "transient" and len(res.contacts) == 1
    assert 0 < res.contact_fraction() < 0.5
    assert res.n_impacts() >= 2  # at least one impact per common period of 0.1 s
    assert res.normal is not None and res.normal.method == "harmonic"
    # combination lines appear with the rub, and only f_L, f_H without it
    labels = {ln.label for ln in res.lines[(14, "y")].lines}
    assert {"f_H-f_L", "2f_H", "3f_H-2f_L"} <= labels
    assert {ln.label for ln in res.normal.lines[(14, "y")].lines} <= {"f_L", "f_H"}


def test_rub_beyond_the_free_orbit_is_the_linear_response():
    """A plate that is never reached changes nothing: the transient stays on the harmonic solution."""
    from rotorred.scenes.schema import load_scene
    sc = load_scene("paper-rub", {"rub.clearance": 60e-6, "solver.duration": 0.3, "solver.record_start": 0.1,
                                  "output.plot_window": [0.1, 0.2], "solver.model": "full"})
    res = run_scene(sc)
    assert res.contact_fraction() == 0 and res.n_impacts() == 0
    # tolerance: Newmark's phase drift of the 90 Hz tone by 0.3 s, (Omega dt)^2 / 12 * Omega t, doubled
    w = 2 * math.pi * 90.0
    tol = 2 * w * 0.3 * (w * 2e-5) ** 2 / 12
    for d in sc.output.dofs:
        ref = res.normal.outputs[d]
        assert np.max(np.abs(res.outputs[d] - ref)) / np.max(np.abs(ref)) < tol


def test_write_outputs(rub, tmp_path):
    from scipy.io import loadmat
    sc, res = rub
    files = write_outputs(res, tmp_path)
    names = {f.name for f in files}
    assert {"waveforms.png", "spectra_node13.png", "spectra_node14.png", "spectra_node18.png", "orbits.png",
            "result.npz", "result.mat", "timeseries.csv", "spectra.csv", "lines.csv", "linefit.csv", "poincare.csv",
            "summary.txt"} == names
    for f in files:
        assert f.stat().st_size > 0
    # no poincare.png: 0.2 s at a 10 Hz section holds no sample 10 spline intervals from the ends
    assert res.analysis.classification.poincare.x.size == 0
    npz = np.load(tmp_path / "result.npz")
    mat = loadmat(tmp_path / "result.mat")
    for key in ("t", "rub_14_y", "normal_14_y", "rub_amp_14_y", "frequency", "plate0_normal_force", "plate0_state"):
        assert key in npz and key in mat
        np.testing.assert_array_equal(np.ravel(mat[key]), np.ravel(npz[key]))
    np.testing.assert_array_equal(npz["rub_14_y"], res.outputs[(14, "y")])
    header = (tmp_path / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "t (s)" and "rub node 14 y (um)" in header and "plate 0 state" in header
    column = header.index("rub node 14 y (um)")
    csv_y = np.loadtxt(tmp_path / "timeseries.csv", delimiter=",", skiprows=1, usecols=column)
    np.testing.assert_allclose(csv_y, 1e6 * res.outputs[(14, "y")], rtol=1e-8, atol=1e-12)
    summary = (tmp_path / "summary.txt").read_text()
    assert "Frequency (Hz) | Component" in summary and "impacts" in summary and "contact" in summary


def test_cli_run(tmp_path, capsys):
    from rotorred.cli import main
    path = tmp_path / "linear.toml"
    path.write_text('name = "cli"\n[rotor]\npreset = "seed-rig"\n[[unbalance]]\nnode = 18\nm_e = 1e-3\n'
                    '[solver]\nmodel = "full"\nduration = 0.5\nrecord_start = 0.3\n'
                    '[output]\nnodes = [14]\nplots = ["spectra"]\nformats = ["npz"]\n')
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "harmonic steady state" in out and "wall time" in out
    # the result's files, and the hidden manifest naming them (rotorred.writers.OutputFolder); no lock, no staging
    assert sorted(p.name for p in (tmp_path / "out").iterdir() if not p.name.startswith(".")) == [
        "report.html", "result.npz", "scene.toml", "spectra_node14.png", "summary.txt"]
    assert (tmp_path / "out" / ".rotorred-files").read_text().split() == ["report.html", "result.npz", "scene.toml",
                                                                          "spectra_node14.png", "summary.txt"]
    assert sorted(p.name for p in (tmp_path / "out").iterdir() if p.name.startswith(".")) == [".rotorred-files"]


def _load_validation(name: str):
    from validation_scripts import load_validation

    return load_validation(name)


def test_paper_reproduction():
    """The paper's signatures with the built-in scenes (validation/paper_reproduction.py)."""
    v = _load_validation("paper_reproduction")
    # normal state: only f_L and f_H above 1 % at nodes 13 and 14
    for node in (13, 14):
        for d in ("x", "y"):
            labels = {ln.label for ln in v.normal_lines(node, d)}
            assert "f_H" in labels and labels <= {"f_L", "f_H"}, (node, d, labels)
    # rub: all 24 Table 1 components, each with the paper's label (24/24 is what validation/paper_reproduction.py
    # measures; a missing line is a change of the model or the spectra, not noise, so no margin is allowed)
    assert v.n_table1_found() == 24
    # the orbit at the rub node contracts on the plate side; the inner rotor changes less than the outer
    rub_reach, normal_reach = v.plate_side_reach(18)
    assert rub_reach < normal_reach
    assert v.relative_change(13) < v.relative_change(14)
    # the settled response is periodic with 0.1 s (transients have decayed): measured 8.4e-7 of the peak
    assert v.period_mismatch() < 1e-5
    # against an independent reference, the same scene at half the time step: the Table 1 line amplitudes
    # move by 2.0e-4 of the largest line (measured); 1e-3 allowed
    assert v.reference_line_error((("solver.dt", 1e-5),))[0] < 1e-3


def test_gravity_settled_state_matches_time_stepping():
    """With gravity, the harmonic path adds the static sag K^-1 F_g; time stepping from the same settled
    state (a plate 1 m away forces the transient path) must stay on it.

    Tolerance as above: Newmark's phase drift of the 90 Hz tone over 0.3 s, doubled, relative to the
    unbalance amplitude; the static part is exact for Newmark (a constant load is integrated exactly).
    """
    base = dict(solver={"model": "full", "dt": 2e-5, "duration": 0.3, "record_start": 0.1, "gravity": 9.81},
                output={"nodes": [14, 18], "directions": ["x", "y"], "plots": [], "formats": [],
                        "plot_window": [0.1, 0.2]})
    harmonic = run_scene(_scene(**base))
    stepped = run_scene(_scene(**base, rub=[{"node": 18, "clearance": 1.0}]))
    assert harmonic.method == "harmonic" and stepped.method == "transient" and stepped.contact_fraction() == 0
    sag = np.mean(harmonic.outputs[(18, "y")])
    assert sag < -1e-5  # the seed rig sags tens of micrometres at the HP turbine disk
    w = 2 * math.pi * 90.0
    tol = 2 * w * 0.3 * (w * 2e-5) ** 2 / 12
    for d in harmonic.outputs:
        amp = np.max(np.abs(harmonic.outputs[d] - np.mean(harmonic.outputs[d])))
        assert np.max(np.abs(stepped.outputs[d] - harmonic.outputs[d])) < tol * amp + 1e-12 * abs(sag)


def test_figures_drawn_by_worker_processes_are_the_figures_drawn_here(rub, tmp_path):
    """The command draws its figures in a FigurePool while it writes the data files: the same files, pixel for
    pixel, as drawing them here; a failing figure fails the write (its error, not a lost file)."""
    import pickle

    from matplotlib.image import imread

    from rotorred.plots.pool import FigurePool
    from rotorred.plots.scene import scene_figures

    sc, res = rub
    here = write_outputs(res, tmp_path / "here")
    with FigurePool(workers=1) as pool:
        there = write_outputs(res, tmp_path / "there", pool=pool)
    assert [f.name for f in here] == [f.name for f in there]
    for a, b in zip(here, there):
        if a.suffix == ".png":
            np.testing.assert_array_equal(imread(a), imread(b))
    jobs = scene_figures(res, tmp_path / "jobs")
    assert len(jobs) == 5 and all(pickle.loads(pickle.dumps(job)).args[1].func is job.args[1].func for job in jobs)
    import functools

    path, drawing = jobs[0].args
    bad = functools.partial(jobs[0].func, path, functools.partial(  # 1 sample: refused
        drawing.func, res.t[:1], *drawing.args[1:], **drawing.keywords))
    with FigurePool(workers=1) as pool, pytest.raises(Exception, match="at least 2 samples"):
        pool.submit(bad).result()


def test_the_record_figures_are_drawn_before_the_analysis_and_are_the_same(rub, tmp_path):
    """run_scene's on_record gets the result once, before the analysis (no analyses yet, the record and the normal run
    there); the figures submitted from it and the analysis' figure afterwards are the files and pixels that
    write_outputs draws from the whole result at once."""
    from matplotlib.image import imread

    from rotorred.plots.pool import FigurePool
    from rotorred.scenes.outputs import submit_figures

    sc, whole = rub
    seen, drawing = [], []
    with FigurePool(workers=1) as pool:
        def on_record(partial):
            seen.append(partial)
            drawing.extend(submit_figures(partial, tmp_path / "early", pool, "record"))
        res = run_scene(sc, on_record=on_record)
        early = write_outputs(res, tmp_path / "early", pool=pool, drawing=drawing)
    assert len(seen) == 1 and seen[0].analyses == {} and seen[0].normal is not None and res.analyses
    at_once = write_outputs(whole, tmp_path / "whole")
    assert [f.name for f in early] == [f.name for f in at_once]
    for a, b in zip(early, at_once):
        if a.suffix == ".png":
            np.testing.assert_array_equal(imread(a), imread(b))


def _requested_frames(result, folder, monkeypatch) -> list[tuple]:
    """The frame keys the figures of ``result`` ask for when drawn (none prepared)."""
    from rotorred.plots import scene as figures

    asked = []
    monkeypatch.setattr(figures, "_prepared", lambda key: asked.append(key))
    figures.plot_scene(result, folder)
    monkeypatch.undo()
    return asked


@pytest.fixture(scope="module")
def paper_rub():
    """paper-rub as ``rotorred run`` solves it (its six figures, the Poincare plot's among them)."""
    from rotorred.scenes.schema import load_scene
    sc = load_scene("paper-rub", {})
    return sc, run_scene(sc)


def test_scene_frames_are_the_frames_its_figures_ask_for(paper_rub, rub, tmp_path, monkeypatch):
    """scene_frames reads from the scene alone (before it is solved) the frames its figures are drawn into: paper-rub's
    six figures; the Poincare plot's frame unused when the analysis has no samples (a record of 0.2 s: 2 at 10 Hz);
    a scene of one direction without orbits and Poincare plot."""
    from rotorred.plots.scene import scene_frames

    sc, res = paper_rub
    assert sorted(_requested_frames(res, tmp_path / "paper", monkeypatch)) == sorted(scene_frames(sc)) and len(
        scene_frames(sc)) == 6
    short, res = rub
    asked = _requested_frames(res, tmp_path / "short", monkeypatch)
    assert sorted(asked + [scene_frames(short)[-1]]) == sorted(scene_frames(short)) and scene_frames(short)[-1][:2] == (
        "side", 5.35)
    one = _scene(output__directions=["y"], output__plots=["waveforms", "spectra"])
    asked = _requested_frames(run_scene(one), tmp_path / "one", monkeypatch)
    assert sorted(asked) == sorted(scene_frames(one)) == [("stacked", 9, 2.6, 2), ("stacked", 10, 3.4, 1),
                                                          ("stacked", 10, 3.4, 1)]


def test_prepared_frames_draw_the_same_figures(paper_rub, tmp_path, monkeypatch):
    """Figures drawn into frames prepared ahead (prepare_frames, as the figure pool's fork server does) are the
    figures drawn into new ones, pixel for pixel, and use every frame prepared for them: none is built then."""
    from matplotlib.image import imread

    from rotorred.plots import scene as figures

    sc, res = paper_rub
    fresh = figures.plot_scene(res, tmp_path / "fresh")
    figures.prepare_frames(figures.scene_frames(sc))
    monkeypatch.setattr(figures, "_stacked_frame", None)  # building a frame now fails
    monkeypatch.setattr(figures, "_side_by_side_frame", None)
    prepared = figures.plot_scene(res, tmp_path / "prepared")
    assert not any(figures._PREPARED.values())
    assert [f.name for f in fresh] == [f.name for f in prepared] and len(fresh) == 6
    for a, b in zip(fresh, prepared):
        np.testing.assert_array_equal(imread(a), imread(b))


def test_the_figure_pool_prepares_the_frames_before_its_workers_draw(paper_rub, tmp_path):
    """FigurePool(frames=...): its workers start with the frames built (by the fork server), and drawing the scene's
    figures uses them all."""
    import functools

    from rotorred.plots.pool import FigurePool
    from rotorred.plots.scene import scene_frames

    sc, res = paper_rub
    count = functools.partial(eval, "sum(map(len, __import__('rotorred.plots.scene', fromlist=['_']).\
_PREPARED.values()))")  # a job that counts a worker's prepared frames
    with FigurePool(workers=1, frames=scene_frames(sc)) as pool:
        before = pool.submit(count).result()
        files = write_outputs(res, tmp_path, pool=pool)
        after = pool.submit(count).result()
    assert (before, after) == (6, 0) and len([f for f in files if f.suffix == ".png"]) == 6


def test_a_dead_figure_worker_costs_no_figure(rub, tmp_path):
    """A worker killed while the figures are drawn (out of memory, a signal): its figures are drawn here instead,
    and the files are all there."""
    import os
    import signal

    from rotorred.plots.pool import FigurePool

    sc, res = rub
    with FigurePool(workers=1) as pool:
        pid = pool.submit(os.getpid).result()
        os.kill(pid, signal.SIGKILL)
        files = write_outputs(res, tmp_path, pool=pool)
    assert {"waveforms.png", "orbits.png", "spectra_node14.png"} <= {f.name for f in files}
    assert all(f.stat().st_size > 0 for f in files)


def test_a_figure_pool_left_on_an_error_ends_its_workers():
    """Leaving a FigurePool on an error (Ctrl-C, a refused file) ends its workers at once, drawing or not, before the
    caller removes what they write into; so does leaving one whose workers are still starting (the fork server
    importing matplotlib), after which it draws in the calling process."""
    import os

    from rotorred.plots.pool import FigurePool

    pool = FigurePool(workers=1)
    with pytest.raises(KeyboardInterrupt), pool:
        pid = pool.submit(os.getpid).result()  # handed over by the pool's thread, drawn in a worker
        processes = list(pool._executor._processes.values())
        raise KeyboardInterrupt
    assert pid != os.getpid() and [p.pid for p in processes] == [pid]
    assert not any(p.is_alive() for p in processes)
    starting = FigurePool(workers=1)
    with pytest.raises(RuntimeError), starting:
        raise RuntimeError("refused")
    assert starting._executor is None and starting.submit(os.getpid).result() == os.getpid()  # drawn here now


def test_a_stopped_figure_pool_leaves_its_workers_cpu_time_to_the_caller():
    """The fork server leaves without the interpreter's teardown (rotorred.plots._fork_server) once the pool stops, and
    only after reaping its workers: their CPU time counts as the caller's children's, as ``time`` and the benchmarks
    read it. A worker sums 2e7 integers (its CPU time measured here, the same sum)."""
    import functools
    import resource
    import time
    from multiprocessing import forkserver

    from rotorred.plots.pool import FigurePool

    job = functools.partial(sum, range(20_000_000))
    t0 = time.process_time()
    expected = job()
    cpu = time.process_time() - t0
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    with FigurePool(workers=1) as pool:
        assert pool.submit(job).result() == expected
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    assert getattr(forkserver._forkserver, "_forkserver_pid", None) is None  # stopped and waited for
    assert after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime > 0.5 * cpu
