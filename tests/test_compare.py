"""Reduced against full (``rotorred compare``, :func:`rotorred.compare_models`): the measured reduction floors of the
paper-rub transient on a short run, the one error measure shared with validation/bench_pareto.py, bad input refused
before any run, and an interrupt keeping the runs done.

Short configuration (about 1 s in all): paper-rub on its own rig, 0.4 s simulated, record 0.2-0.4 s (two common
periods), dt 1e-4 and 5e-5 s, 8, 16 and 24 modes. Measured (spectral error against the full model at 5e-5 s, worst
of the ten largest lines of nodes 13, 14 and 18, x and y): CB 8 75.4 %, CB 16 1.33 %, CB 24 0.104 %; the full model
at 1e-4 s 3.97 %. The assertions hold each within 10x (CB 8's above 10 %: a wrong model, not a noisy one). The full
length figures (README "Run time against error: the rub transient") are in README "Reduced against full".
"""

from __future__ import annotations

import dataclasses
import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

import rotorred as rr
from results_checks import assert_shows_itself
from rotorred.cli import main

SHORT = {"solver.duration": 0.4, "solver.record_start": 0.2, "output.plot_window": [0.2, 0.3]}
SHORT_ARGS = ["--set", "solver.duration=0.4", "--set", "solver.record_start=0.2", "--set", "output.plot_window=[0.2,0.3]"]
#: measured on the short configuration (module docstring): spectral error of each model at dt 5e-5 s (-)
MEASURED = {"CB 8": 0.754, "CB 16": 0.0133, "CB 24": 0.00104}


@pytest.fixture(scope="module")
def short():
    scene = rr.load_scene("paper-rub", SHORT)
    return rr.compare_models(scene, rr.CompareOptions(modes=(8, 16, 24), dts=(1e-4, 5e-5), progress=False))


def test_the_reduction_floors_of_the_short_rub_run(short):
    """Each reduced model's spectral error at the finest dt (its reduction floor) within 10x of the measured one,
    falling with the modes; CB 8 is a wrong model (> 10 %), the orbit converges faster than the spectrum."""
    floors = short.floors()
    assert list(floors) == ["full", "CB 8", "CB 16", "CB 24"]
    for name, measured in MEASURED.items():
        e = floors[name].errors.spectral
        assert measured / 10 < e < 10 * measured, (name, e)
    assert floors["CB 8"].errors.spectral > 0.1
    assert floors["CB 8"].errors.spectral > floors["CB 16"].errors.spectral > floors["CB 24"].errors.spectral
    for name in MEASURED:
        assert floors[name].errors.orbit < floors[name].errors.spectral
    assert floors["full"].errors.spectral == 0.0 and short.reference is floors["full"]


def test_every_run_is_measured_with_its_size_and_time(short):
    """The reference first, then full at the coarser step, then each reduced model at each step; DOF counts are the
    rig's 80 and 24 boundary DOFs + k modes; every run is timed (build included) and the full coarse step's error is
    the time step's (3.97 % measured)."""
    runs = short.runs
    assert [(r.model, r.dt) for r in runs] == [("full", 5e-5), ("full", 1e-4), ("CB 8", 5e-5), ("CB 8", 1e-4),
                                               ("CB 16", 5e-5), ("CB 16", 1e-4), ("CB 24", 5e-5), ("CB 24", 1e-4)]
    assert [r.n_dof for r in runs[::2]] == [80, 32, 40, 48]
    assert all(r.wall > 0 and r.cpu >= 0 and 0 < r.build_time < r.wall for r in runs)
    assert [r.n_steps for r in runs[:2]] == [8000, 4000]
    assert 0.00397 < runs[1].errors.spectral < 0.397
    assert short.orbit_node == 18 and short.dofs == tuple((n, d) for n in (13, 14, 18) for d in "xy")
    assert short.sample_dt == 1e-4 and not short.interrupted
    assert runs[0].peak_radius == pytest.approx(220e-6, rel=0.05) and 0 < runs[0].contact_fraction < 0.5
    front = short.front()
    assert front[-1].errors.spectral == 0.0 and all(a.wall <= b.wall for a, b in zip(front, front[1:]))


def test_the_comparison_shows_itself(short, tmp_path):
    assert_shows_itself(short, tmp_path, of=rr.ModelComparison)
    ds = short.to_xarray()
    assert ds["dof_spectral_error"].shape == (8, 6) and ds["wall_time"].attrs["units"] == "s"
    np.testing.assert_allclose(ds["spectral_error"].values, ds["dof_spectral_error"].values.max(axis=1))


def _bench_pareto():
    name = "_test_compare_bench_pareto"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, Path(__file__).parents[1] / "validation" / "bench_pareto.py")
        sys.modules[name] = module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    return sys.modules[name]


def test_the_command_and_bench_pareto_measure_alike():
    """One implementation of the measure: bench_pareto's grid and compare_models give the same errors for the same
    runs (CB 8 against the full model at 2.5e-5 s, nodes 13 and 14, records resampled to 1e-4 s)."""
    bp = _bench_pareto()
    case = bp.paper_rub(1, t_end=0.2, n_periods=1)
    system = rr.assemble(case.rotor)
    ref = bp.reference(case, dt_ref=2.5e-5, system=system)
    row = bp.grid(case, ref, dts=(2.5e-5,), modes=(8,), methods=("newmark",), repeats=1, system=system)[-1]
    scene = rr.load_scene("paper-rub", {"solver.duration": 0.2, "solver.record_start": 0.1, "output.nodes": [13, 14],
                                        "output.plot_window": [0.1, 0.2]})
    got = rr.compare_models(scene, rr.CompareOptions(modes=(8,), dts=(1e-4, 2.5e-5), progress=False)).floors()["CB 8"]
    assert row.model == "CB 8" and row.errors.spectral > 0.01
    for measure in ("spectral", "orbit", "contact"):
        assert getattr(got.errors, measure) == pytest.approx(getattr(row.errors, measure), rel=1e-6), measure
    assert got.errors.worst_line == row.errors.worst_line


def test_a_linear_scene_compares_its_two_lines_not_its_round_off():
    """paper-normal (no rub, started settled: the harmonic response, no steps): only the 70 and 90 Hz lines are
    above the scene's line threshold, so the worst line is one of them; CB 24 against full measured 4.31e-5, CB 8
    2.30e-3 (asserted within 10x); no plate, so no contact error."""
    cmp = rr.compare_models(rr.load_scene("paper-normal"), rr.CompareOptions(modes=(8, 24), progress=False))
    floors = cmp.floors()
    for name, measured in (("CB 8", 2.30e-3), ("CB 24", 4.31e-5)):
        e = floors[name].errors
        assert measured / 10 < e.spectral < 10 * measured and e.worst_line.endswith((" 70 Hz", " 90 Hz")), e
        assert np.isnan(e.contact)
    assert cmp.reference.n_steps == 0 and cmp.orbit_node == 18  # the largest recorded orbit


# --------------------------------------------------------------------------- bad input, before any run
@pytest.fixture
def no_runs(monkeypatch):
    """Any time step fails the test: input must be refused before."""
    import rotorred.scenes.compare as compare

    def refuse(*args, **kwargs):
        raise AssertionError("a run started before the input was refused")
    monkeypatch.setattr(compare, "respond", refuse)


@pytest.mark.parametrize("argv, tokens", [
    (["--modes", "0,8"], ["--modes", "whole numbers"]),
    (["--modes", "8,2.5"], ["--modes", "2.5", "whole numbers"]),
    (["--modes", "8,500"], ["--modes", "500", "from 1 to 56", "interior DOFs"]),
    (["--modes", "8,8"], ["--modes", "once"]),
    (["--dt", "3e-5"], ["--dt", "3e-05", "whole fraction", "solver.duration = 0.4 s"]),
    (["--dt", "1e-4,4e-5"], ["--dt", "4e-05", "whole fraction", "coarsest dt"]),
    (["--dt=-1e-5"], ["--dt", "> 0", "(s)"]),
    (["--refine", "0"], ["--refine", "0", ">= 1"]),
])
def test_bad_input_is_refused_before_any_run(argv, tokens, tmp_path, capsys, no_runs):
    out = tmp_path / "out"
    status = main(["compare", "paper-rub", *SHORT_ARGS, *argv, "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2 and not out.exists(), err
    assert len(err.strip().splitlines()) == 1 and all(t in err for t in tokens), err


def test_a_scene_without_recorded_dofs_or_in_a_run_up_is_refused(no_runs):
    scene = rr.load_scene("paper-rub", SHORT)
    silent = dataclasses.replace(scene, output=dataclasses.replace(scene.output, nodes=()))
    with pytest.raises(rr.InputError, match=r"output.nodes = \[\]: must name at least one node"):
        rr.compare_models(silent)
    with pytest.raises(rr.InputError, match=r"runup = .*must not be given"):
        rr.compare_models(rr.load_scene("runup"))
    with pytest.raises(rr.InputError, match=r"solver.tolerance = 0.01: must not be given"):
        rr.compare_models(rr.load_scene("paper-rub", {**SHORT, "solver.tolerance": 0.01}))


# --------------------------------------------------------------------------- interrupts keep the runs done
def _interrupt_at(monkeypatch, call: int):
    import rotorred.scenes.compare as compare

    real, calls = compare._run, []

    def run(*args):
        calls.append(1)
        if len(calls) == call:
            raise KeyboardInterrupt
        return real(*args)
    monkeypatch.setattr(compare, "_run", run)


def test_an_interrupt_keeps_the_runs_done(monkeypatch, tmp_path, capsys):
    """Ctrl-C in the third run: the reference and the full coarse run are measured, written, the folder INCOMPLETE,
    exit 130; in the reference run nothing is kept (KeyboardInterrupt, the folder keeps its earlier result)."""
    _interrupt_at(monkeypatch, 3)
    out = tmp_path / "out"
    status = main(["compare", "paper-rub", *SHORT_ARGS, "--dt", "1e-4,5e-5", "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 130, err
    assert (out / "INCOMPLETE").exists() and "interrupted (SIGINT) after 2 runs" in err
    rows = (out / "compare.csv").read_text().splitlines()
    assert len(rows) == 3 and rows[2].startswith("full,0,80,0.0001")
    _interrupt_at(monkeypatch, 1)
    with pytest.raises(KeyboardInterrupt):
        rr.compare_models(rr.load_scene("paper-rub", SHORT), rr.CompareOptions(progress=False))


def test_the_command_writes_its_files_and_prints_a_table_with_units(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["compare", "paper-rub", *SHORT_ARGS, "--modes", "24", "--dt", "1e-4", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "dt (s)" in text and "wall (s)" in text and "spectral (%)" in text and "CB 24" in text
    assert {p.name for p in out.iterdir() if not p.name.startswith(".")} == {
        "compare.csv", "compare.png", "compare.txt", "scene.toml"}
    header = (out / "compare.csv").read_text().splitlines()[0]
    assert header.startswith("model,modes,DOFs,dt (s),steps,wall (s),CPU (s)") and "spectral error 14y (%)" in header
