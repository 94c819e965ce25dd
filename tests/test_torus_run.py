"""``rotorred run SCENE --set solver.method=harmonic-balance`` at an incommensurate speed ratio solves the torus
(:mod:`rotorred.scenes.torus_response`): the command and the Python ``torus_balance`` give one answer, the summary
names the torus and its truncation, a commensurate ratio still goes the periodic way, a box too small for the
spools' orders is refused in the scene's key names.

paper-rub at outer 91.37 Hz (inner 70 Hz): the impacts lock to f_H/3, the torus is (f_L, f_H/3); a small box
(|k1| <= 4, |k2| <= 20) keeps each run near a second.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import rotorred as rr
from rotorred.cli import main
from rotorred.scenes.torus_response import torus_record

OUTER = "speeds.outer=91.37"
SMALL = ["--set", "solver.harmonics=[4,20]"]
TORUS = ["--set", "solver.method=harmonic-balance", "--set", OUTER] + SMALL
#: the summary's torus lines are printed to 6 significant digits
PRINTED = 1e-5


@pytest.fixture(scope="module")
def command(tmp_path_factory):
    """The command at 91.37 Hz with a small box, no figures: its exit status, summary and folder."""
    out = tmp_path_factory.mktemp("torus") / "o"
    status = main(["run", "paper-rub", *TORUS, "--set", "output.plots=[]", "--no-html", "--no-normal", "--out",
                       str(out), "-q"])
    return status, (out / "summary.txt").read_text(encoding="utf-8") if status == 0 else "", out


@pytest.fixture(scope="module")
def python_torus():
    """The same scene's torus from Python: ``torus_balance`` on the scene's model, loads, plates and settings."""
    scene = rr.load_scene("paper-rub", {"speeds.outer": 91.37})
    model = rr.build_model(scene).model
    options = rr.TorusOptions(orders=(4, 20), dt=scene.solver.dt, outputs=scene.output.dofs)
    return rr.torus_balance(model, scene.operating, rr.Loads(scene.unbalances), scene.plates, options)


def test_the_command_solves_the_torus_and_names_it(command):
    status, summary, _ = command
    assert status == 0
    assert "harmonic balance on a torus (f_L = 70 Hz, f_H/3 = 30.4567 Hz; spool orders inner (1, 0), outer (0, 3))" \
        in summary
    assert "orders |k1| <= 4 x |k2| <= 20 (185 orders in the band <= 1500 Hz), grid 16 x 256, 1476 unknowns" in summary
    assert re.search(r"\d+ Newton iterations \(\d+ GMRES\), relative residual [0-9.e-]+", summary)
    assert "Torus lines of node 14 Y" in summary


def _printed_lines(summary: str) -> dict:
    """The summary's torus lines of node 14 Y: {(k1, k2): amplitude (m)}."""
    block = summary.split("Torus lines of node 14 Y")[1].split("\n\n")[0]
    rows = re.findall(r"^\s*[0-9.e+-]+\s*\|\s*\((-?\d+), (-?\d+)\)\s*\|[^|]*\|\s*([0-9.e+-]+)\s*$", block, re.M)
    return {(int(k1), int(k2)): 1e-6 * float(a) for k1, k2, a in rows}


def test_the_command_and_torus_balance_give_one_answer(command, python_torus):
    """The node 14 Y lines the command prints are those of the Python call on the same scene (measured: equal to
    the printed 6 digits)."""
    printed = _printed_lines(command[1])
    assert len(printed) == 10
    j = python_torus.outputs.index((14, "y"))
    for order, amplitude in printed.items():
        k = next(i for i, o in enumerate(python_torus.orders) if tuple(o) == order)
        assert amplitude == pytest.approx(python_torus.amplitudes[k, j], rel=PRINTED)
    largest = np.sort(python_torus.amplitudes[:, j])[::-1][:10]
    assert sorted(printed.values(), reverse=True) == pytest.approx(largest, rel=PRINTED)


def _torus_csv(out) -> dict:
    """``torus.csv``: {(k1, k2): row} with the row's columns by name."""
    import csv

    with open(out / "torus.csv", encoding="utf-8") as f:
        return {(int(r["k1"]), int(r["k2"])): r for r in csv.DictReader(f)}


def test_the_command_writes_every_line_of_the_torus(command, python_torus):
    """``torus.csv`` holds every order's line at full precision: node 14 Y's amplitudes are the Python call's
    (measured: within 2.2e-16 relative), and its phases put together the record (the series at t = 2.1 s: measured
    5.8e-14 of the sum of the amplitudes)."""
    rows = _torus_csv(command[2])
    assert len(rows) == 185
    j = python_torus.outputs.index((14, "y"))
    for k, order in enumerate(python_torus.orders):
        row = rows[tuple(int(v) for v in order)]
        assert 1e-6 * float(row["node 14 y amplitude (um)"]) == pytest.approx(python_torus.amplitudes[k, j],
                                                                              rel=1e-14, abs=1e-20)
    t = 2.1
    series = sum(1e-6 * float(r["node 14 y amplitude (um)"]) * np.cos(2 * np.pi * float(r["frequency (Hz)"]) * t
                                                                      + float(r["node 14 y phase (rad)"]))
                 for r in rows.values())
    record, _ = torus_record(python_torus, np.array([t]), [(14, "y")])
    assert series == pytest.approx(record[(14, "y")][0], abs=1e-12 * python_torus.amplitudes[:, j].sum())


def test_the_record_is_the_torus_series(python_torus):
    """At t = 0 (the grid's first point, both angles 0) the record is the inverse 2-D FFT's sample of the torus, an
    independent synthesis of the same series (the rub disk's x and y, the plate's u_n, u_t)."""
    rp = python_torus.problem
    h, n = rp.problem.harmonics, len(rp.problem.dofs)
    grid = h.samples(python_torus.solution.z, n)[0]
    outputs, contacts = torus_record(python_torus, np.array([0.0, 0.5]), [(18, "x"), (18, "y")])
    assert outputs[(18, "x")][0] == pytest.approx(grid[0], rel=1e-12, abs=1e-15)
    assert outputs[(18, "y")][0] == pytest.approx(grid[1], rel=1e-12, abs=1e-15)
    assert contacts[0].u_n[0] == pytest.approx(grid[2], rel=1e-12, abs=1e-15)
    assert contacts[0].u_t[0] == pytest.approx(grid[3], rel=1e-12, abs=1e-15)


def test_a_commensurate_ratio_goes_the_periodic_way():
    scene = rr.load_scene("paper-rub", {"solver.method": "harmonic-balance", "solver.harmonics": 30,
                                        "solver.samples": 128})
    result = rr.run_scene(scene, compare_normal=False, analyse=False)
    assert "torus" not in result.counters and result.counters["f0"] == 10.0
    assert result.method == "harmonic-balance"


def test_a_box_without_the_spools_orders_is_refused(tmp_path, capsys):
    """The torus found (f_L, f_H/3) has the outer spool at order (0, 3): a box |k2| <= 2 cannot hold it; refused after
    the start's transient (the bases are found there) as solver.harmonics, exit 2, one line, nothing written."""
    out = tmp_path / "o"
    argv = ["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", OUTER, "--set",
            "solver.harmonics=[4,2]", "--set", "output.plots=[]", "--no-html", "--no-normal", "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("rotorred run: error: ") and "Traceback" not in err
    for token in ("solver.harmonics = [4, 2]", "must hold each spool's order", "30.4567", "91.37"):
        assert token in err, (token, err)
    assert not out.exists() or not any(out.iterdir())


def test_nearly_commensurate_speeds_are_refused(tmp_path, capsys):
    """Outer 105.001 Hz against 70 Hz (3/2 within 1e-5) shares no period of at most 10 s, but the torus's lines are
    closer than the start's 1 s record resolves: refused as speeds, exit 2, one line saying what to do instead."""
    out = tmp_path / "o"
    argv = ["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "speeds.outer=105.001", *SMALL,
            "--set", "output.plots=[]", "--no-html", "--no-normal", "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("rotorred run: error: speeds = {'inner': 70.0, 'outer': 105.001}: must give a torus whose "
                          "lines a 1 s record resolves"), err
    assert "share a period of at most 10 s" in err and 'solver.method = "newmark"' in err
    assert not out.exists() or not any(out.iterdir())


def test_a_tolerance_the_boxes_do_not_meet_is_said(tmp_path, capsys):
    """solver.tolerance on a torus doubles the box from solver.harmonics: from [4, 20] the response still changes by
    more than 0.05 at [16, 80] (measured 0.11), which the command says in one line, exit 3 (not converged)."""
    argv = ["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", OUTER, *SMALL, "--set",
            "solver.tolerance=0.05", "--set", "output.plots=[]", "--no-html", "--no-normal", "--out", str(tmp_path / "o")]
    assert main(argv) == 3
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("rotorred run: error: the torus did not meet the tolerance 0.05") and "Traceback" not in err
    assert "|k1| <= 16, |k2| <= 80" in err, err
    assert "solver.harmonics = [H1, H2]" in err and "a larger tolerance" in err, err  # what to do instead
