"""Clearance sweeps: the trend at the free orbit's reach, model reuse, files, CLI."""

from __future__ import annotations

import numpy as np
import pytest

import rotorred.scenes.sweep as sweep_mod
from rotorred.linear.harmonic import unbalance_response
from rotorred.scenes.run import build_model
from rotorred.scenes.schema import load_scene
from rotorred.scenes.sweep import free_reach, sweep, write_sweep

#: paper-rub on a short window (the rub settles within 0.3 s from the settled linear state)
SHORT = {"solver.duration": 0.6, "solver.record_start": 0.4, "output.plot_window": [0.4, 0.5],
         "output.formats": [], "output.plots": []}


def test_free_reach_against_the_harmonic_module():
    """max_t n.(x, y) at node 18 from an independent steady-state solution on a 10x finer time grid.

    Tolerance: sampling the periodic signal at dt misses its maximum by at most max|x''| dt^2 / 8
    <= (sum |Q| Omega^2) dt^2 / 8 (here ~2e-10 m, 5e-6 relative).
    """
    sc = load_scene("paper-rub", SHORT)
    model = build_model(sc)
    reach = free_reach(sc, model)
    ref = unbalance_response(model.model, sc.unbalances, [sc.speeds["inner"]], ratios={"outer": 90.0 / 70.0},
                             outputs=[(18, "y")], spool_of=sc.rotor.spool_of, reference_spool="inner")
    t = np.arange(0.0, 0.1, sc.solver.dt / 10)
    y = sum(np.real(ref.phasors[s][(18, "y")][0] * np.exp(1j * sc.speeds[s] * t)) for s in ref.phasors)
    bound = sum(abs(ref.phasors[s][(18, "y")][0]) * sc.speeds[s] ** 2 for s in ref.phasors) * sc.solver.dt ** 2 / 8
    assert abs(reach - np.max(y)) <= bound + 1e-15
    assert 20e-6 < reach < 80e-6  # the paper scene's clearance (13 um) lies below it


@pytest.fixture(scope="module")
def result(monkeypatch_module):
    calls = []
    original = sweep_mod.build_model

    def counting(scene):
        calls.append(scene.name)
        return original(scene)
    monkeypatch_module.setattr(sweep_mod, "build_model", counting)
    res = sweep("paper-rub", "rub.clearance", [60e-6, 45e-6, 10e-6], settings=SHORT)
    return res, calls


@pytest.fixture(scope="module")
def monkeypatch_module():
    mp = pytest.MonkeyPatch()
    yield mp
    mp.undo()


def test_no_lines_beyond_the_free_reach_and_lines_below(result):
    res, _ = result
    far = res.values > res.free_reach
    assert list(far) == [True, True, False]  # 60 and 45 um lie beyond the reach (~43 um), 10 um below
    assert np.all(res.contact_fraction[far] == 0) and np.all(res.n_combinations[far] == 0)
    assert np.all(res.n_impacts[far] == 0)
    assert res.contact_fraction[2] > 0 and res.n_impacts[2] > 0 and res.n_combinations[2] >= 18
    # beyond the reach the lines are the linear ones: identical for both clearances
    for k in ("f_L", "f_H"):
        assert res.amplitudes[k][0] == res.amplitudes[k][1] > 0
    assert res.combination_total()[2] > 0.1 * res.amplitudes["f_H"][2]


def test_one_model_for_the_whole_sweep(result):
    _, calls = result
    assert len(calls) == 1


def test_write_sweep(result, tmp_path):
    res, _ = result
    files = write_sweep(res, tmp_path)
    assert sorted(f.name for f in files) == ["sweep.csv", "sweep.png", "sweep.txt"]
    header = (tmp_path / "sweep.csv").read_text().splitlines()[0].split(",")
    assert header[:5] == ["rub.clearance (SI)", "contact fraction", "impacts", "combination lines", "peak (um)"]
    assert header[-1] == "status"  # "ok", or "failed: <why>" for a diverged value (tests/test_cli_failures.py)
    assert [row.rsplit(",", 1)[1] for row in (tmp_path / "sweep.csv").read_text().splitlines()[1:]] == ["ok"] * 3
    data = np.loadtxt(tmp_path / "sweep.csv", delimiter=",", skiprows=1, usecols=range(len(header) - 1))
    np.testing.assert_allclose(data[:, 0], res.values, rtol=1e-8)
    np.testing.assert_allclose(data[:, header.index("f_H (um)")], 1e6 * res.amplitudes["f_H"], rtol=1e-5)


def test_sweep_validates_every_value_before_computing(monkeypatch):
    def boom(*a, **k):
        raise AssertionError("computed before validating all values")
    monkeypatch.setattr(sweep_mod, "run_scene", boom)
    with pytest.raises(ValueError, match=r"rub\[0\]\.clearance = -5e-06: must be >= 0 \(m\)"):
        sweep("paper-rub", "rub.clearance", [20e-6, -5e-6], settings=SHORT)


def test_cli_sweep(tmp_path, capsys):
    from rotorred.cli import main
    args = ["sweep", "paper-rub", "--set", "rub.clearance=60e-6,50e-6", "--out", str(tmp_path)]
    for k, v in SHORT.items():
        args += ["--set", f"{k}={v!r}".replace("'", '"')]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "sweep of rub.clearance over 2 values" in out and (tmp_path / "sweep.png").exists()
    # two swept keys are refused
    assert main(["sweep", "paper-rub", "--set", "rub.clearance=1e-6,2e-6", "--set", "solver.dt=1e-5,2e-5",
                 "--out", str(tmp_path)]) == 2
    assert "sweep one key" in capsys.readouterr().err


def test_no_plate_no_reach():
    assert free_reach(load_scene("paper-normal")) is None
