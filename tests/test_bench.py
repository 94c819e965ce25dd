"""Structural tests of the benchmark scripts in validation/ (tiny configurations; no timing assertions).

The benchmarks' numbers are printed by the scripts themselves; these tests only check that each
script's functions run on a tiny configuration and return the named fields with sane values, and
that bench_ross exits cleanly without ROSS.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from rotorred.signals.compare import ResponseMeasures, measure_errors

VALIDATION = Path(__file__).resolve().parents[1] / "validation"


def _load(name: str):
    key = f"_test_bench_{name}"
    if key in sys.modules:
        return sys.modules[key]
    spec = importlib.util.spec_from_file_location(key, VALIDATION / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[key] = module  # dataclasses need the module registered
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def bp():
    return _load("bench_pareto")


@pytest.fixture(scope="module")
def tiny(bp):
    """The paper-rub case on the unrefined rig, one common period after 0.1 s, and its reference."""
    from rotorred.model.assembly import assemble

    case = bp.paper_rub(1, t_end=0.2, n_periods=1)
    system = assemble(case.rotor)
    ref = bp.reference(case, dt_ref=2.5e-5, system=system)
    return case, system, ref


def test_paper_rub_config(bp):
    """The benchmark's case is the built-in scene paper-rub on the refined rotor."""
    from rotorred.scenes.schema import load_scene

    scene = load_scene("paper-rub")
    case = bp.paper_rub(2, t_end=0.3, n_periods=2)
    assert case.record_start == pytest.approx(0.1) and case.refine == 2
    assert case.speeds == pytest.approx(scene.speeds)
    assert case.speeds == pytest.approx({"inner": 2 * math.pi * 70, "outer": 2 * math.pi * 90})
    assert case.plates == scene.plates and case.unbalances == scene.unbalances
    assert case.rotor.rayleigh == scene.rotor.rayleigh
    assert len(case.rotor.nodes) == 2 * 18 + 2  # refined(2): 18 elements split in two


def test_steady_state_is_the_harmonic_solution(bp, tiny):
    """Without contact the run started from steady_state stays on it: q(0.1 s) = q(0) (period 0.1 s)."""
    case, system, _ = tiny
    q0, v0 = bp.steady_state(system, case)
    from rotorred.model.operating import Operating
    from rotorred.transient.newmark import Initial, Loads, StepControl, simulate
    res = simulate(system, Operating.point(case.speeds), 0.1, 1e-5, loads=Loads(case.unbalances),
                   start=Initial(q0=q0, v0=v0), control=StepControl(progress=False))
    # Newmark's phase error at 90 Hz and dt = 1e-5 s: (Omega dt)^2 / 12 per radian, ~1e-4 after 9 cycles
    assert np.max(np.abs(res.final.q - q0)) < 2e-3 * np.max(np.abs(q0))


def test_reference_and_grid_fields(bp, tiny):
    case, system, ref = tiny
    assert ref.dt == 2.5e-5 and ref.check_dt == 5e-5 and ref.n_dof == 80
    assert ref.measures.peak_radius > 0
    assert 0 < ref.measures.contact_fraction < 1          # it rubs, but not all the time
    assert set(ref.measures.spectra) == {(13, "x"), (13, "y"), (14, "x"), (14, "y")}
    rows = bp.grid(case, ref, dts=(2.5e-5,), modes=(8,), methods=("newmark", "hht"), repeats=1, system=system)
    assert [(r.model, r.method) for r in rows] == [("full", "newmark"), ("full", "hht"), ("CB 8", "newmark"),
                                                  ("CB 8", "hht")]
    full_nm = rows[0]
    # the full Newmark run at the reference dt is the reference itself
    assert full_nm.errors.spectral < 1e-12 and full_nm.errors.orbit < 1e-12 and full_nm.errors.contact < 1e-12
    for r in rows:
        assert r.wall > 0 and r.cpu >= 0 and r.us_per_step > 0 and r.n_steps == 8000 and r.repeats == 1
    for r in rows[1:]:
        assert r.errors.worst_line  # names the node, direction and frequency of the worst line
    assert rows[2].n_dof == 24 + 8 and rows[2].reduce_time > 0
    assert rows[1].errors.spectral > 0 and rows[2].errors.spectral > 0  # HHT and CB differ from the reference
    text = bp.format_table(rows, ref)
    assert "reference: full model, 80 DOF" in text and "CB 8" in text


def test_scene_checks(bp, tiny):
    """The scene as shipped and with the automatic mode count, against the (here unrefined) reference."""
    _, _, ref = tiny
    checks = bp.scene_checks(ref, t_end=0.2, n_periods=1)
    assert [c.label.split(":")[0] for c in checks] == ["as shipped", "automatic mode count"]
    for c in checks:
        assert c.errors is not None and c.wall > 0 and "Craig-Bampton" in c.label
        assert 0 < c.errors.spectral < 1  # reduced against the full model: a difference, but not a wrong one
    assert "as shipped" in bp.format_scene_checks(checks)


def test_errors_definition(bp):
    """Spectral error is the worst relative error over the reference's largest lines (DC excluded)."""
    f = np.arange(6) * 10.0
    ref = ResponseMeasures({(13, "x"): np.array([5.0, 1.0, 4.0, 0.5, 2.0, 0.1])}, f, 1e-4, 0.1)
    other = ResponseMeasures({(13, "x"): np.array([0.0, 1.1, 4.0, 0.5, 2.0, 0.1])}, f, 1.1e-4, 0.12)
    e = measure_errors(other, ref, n_lines=3)
    assert e.spectral == pytest.approx(0.1) and e.worst_line == "13x 10 Hz"
    assert e.orbit == pytest.approx(0.1) and e.contact == pytest.approx(0.2)
    # line 5 (0.1) is not among the three largest: changing it does not count
    other2 = ResponseMeasures({(13, "x"): np.array([5.0, 1.0, 4.0, 0.5, 2.0, 9.9])}, f, 1e-4, 0.1)
    assert measure_errors(other2, ref, n_lines=3).spectral == 0.0


def test_plot_writes_png(bp, tiny, tmp_path):
    case, system, ref = tiny
    rows = bp.grid(case, ref, dts=(5e-5, 2.5e-5), modes=(8,), methods=("newmark",), repeats=1, system=system)
    path = bp.plot(rows, str(tmp_path / "pareto.png"), ref)
    assert Path(path).stat().st_size > 10_000


def test_scaling_worker_fields():
    bs = _load("bench_scaling")
    assert bs.full_steps(296) == 34_000 and bs.full_steps(10_000) == 2000 and bs.full_steps(80) == 300_000
    row = bs.worker(1, 8, 2000, 1)
    assert row["n_dof"] == 32 and row["n_full"] == 80 and row["steps"] == 2000
    for key in ("us_per_step", "run_time", "setup_time", "model_time", "traced_mb", "rss_mb"):
        assert math.isfinite(row[key]) and row[key] > 0, key
    assert math.isnan(row["cpu_us_per_step"])  # too short a run to subtract the set-up's CPU time


def test_scaling_table_and_plot(tmp_path):
    bs = _load("bench_scaling")
    rows = [dict(refine=r, n_modes=k, n_dof=34 if k else 4 * (18 * r + 2), n_full=4 * (18 * r + 2), steps=1000,
                 us_per_step=1.0 if k else 3.0 * r * r, us_spread=(0.9, 1.1), cpu_us_per_step=0.8 if k else math.nan,
                 run_time=0.3, wall=0.4, setup_time=0.01, model_time=0.02, traced_mb=1.0 * r, rss_mb=190.0,
                 contact_steps=10) for r in (1, 2) for k in (None, 10)]
    s = bs.Scaling(rows=rows, compile={"compile": 20.0, "cache_load": 0.3, "first_cold": 20.1, "first_cached": 0.4,
                                       "run": 0.01})
    text = bs.format_table(s)
    assert "refined(2)   CB 10" in text and "compile into an empty numba cache 20.00 s" in text
    assert "CB 10: µs/step from 1.000 to 1.000" in text
    assert Path(bs.plot(s, str(tmp_path / "scaling.png"))).stat().st_size > 10_000


def test_ross_script_without_ross(monkeypatch, capsys):
    br = _load("bench_ross")
    monkeypatch.setattr(br, "import_ross", lambda: (None, "ModuleNotFoundError: No module named 'ross'"))
    assert br.main([]) == 0
    out = capsys.readouterr().out
    assert "ROSS is not available" in out and "rotorred[bench]" in out


def test_ross_comparison_when_installed():
    """With ROSS installed (the optional `bench` extra): Campbell and Newmark agree with ROSS.

    Skipped, with the reason shown, in an environment without ROSS.
    """
    br = _load("bench_ross")
    rs, why = br.import_ross()
    if rs is None:
        pytest.skip(f"ROSS not installed ({why}); install the `bench` extra to run this comparison")
    from rotorred.model.rotor_file import load_rotor

    rotor = load_rotor("nelson-mcvaugh")
    cc = br.compare_campbell(rs, rotor, rpm=np.array([0.0, 20000.0, 40000.0]), repeats=1)
    # same element formulation (Timoshenko, Cowper shear) on the same mesh: only round-off differs
    assert cc.max_rel_diff < 1e-7
    tc = br.compare_transient(rs, rotor, t_end=2e-3, repeats=1)
    # ROSS's own Newmark step from the same (consistent) start: identical up to round-off
    assert tc.diff_consistent < 1e-8
    # the public API starts from a = 0: an O(dt^2) different first step, visible but small
    assert 1e-8 < tc.diff_public < 1e-1


def test_sparse_bench_worker_table_and_plot(tmp_path):
    """validation/bench_sparse.py on the unrefined rig, both forms (no rub run): every task measured, a table and a
    plot."""
    bs = _load("bench_sparse")
    rows = [bs.worker(1, as_sparse, False) for as_sparse in (True, False)]
    assert all(r["n_dof"] == 80 and all(r[t] > 0 for t in bs.TASKS[:4]) for r in rows)
    text = bs.format_table(rows)
    assert "refined(1)   sparse" in text and "dense / sparse at refined(1)" in text
    assert Path(bs.plot(rows, str(tmp_path / "sparse.png"))).stat().st_size > 10_000
