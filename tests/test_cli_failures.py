"""Failures during a run: divergence keeps its results, interrupts leave no traceback and no mixed folder,
two runs into one ``--out`` stay consistent (reliability.md sections 1, 2 and 4)."""

from __future__ import annotations

import csv
import io

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from rotorred.cli import main

#: paper-rub near a critical speed, from rest, with 4 kg m on the rub disk and the plate out of reach:
#: the disk passes 1 m (the transient's divergence limit) at t = 0.3486 s (reliability.md section 2)
DIVERGE = ["--set", "solver.start=rest", "--set", "rub.clearance=1.0", "--set", "speeds.inner=42.94111111111111",
           "--set", "speeds.outer=55.21", "--set", "solver.duration=0.5", "--set", "solver.record_start=0.1",
           "--set", "output.plot_window=[0.1, 0.2]", "--set", "output.formats=[\"npz\", \"csv\"]"]
#: a short rub scene (0.3 s), no figures: the earlier result of the interrupt tests
SHORT = ["--set", "solver.duration=0.3", "--set", "solver.record_start=0.1", "--set", "output.plot_window=[0.1, 0.2]",
         "--set", "output.plots=[]", "--set", "output.formats=[\"npz\", \"csv\"]"]


def test_diverging_run_keeps_its_partial_record(tmp_path, capsys):
    from datetime import datetime, timezone

    from provenance_checks import assert_provenance

    out = tmp_path / "div"
    since = datetime.now(timezone.utc)
    argv = ["run", "paper-rub", "--out", str(out), "--set", "unbalance[1].m_e=4.0", *DIVERGE]
    assert main(argv) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    # one error line, after the run's stage lines (what it was doing when it stopped)
    errors = [line for line in lines if line.startswith("rotorred run: error: ")]
    assert len(errors) == 1 and lines[-1] == errors[0] and "Traceback" not in "\n".join(lines), lines
    assert any(line.startswith("rotorred run: stepping paper-rub") for line in lines[:-1]), lines
    err = errors[0]
    # when, where and why, in scene key names
    assert "t = 0.3486 s" in err and "rub[0] (node 18, x)" in err and "exceeded 1 m" in err
    assert "displacement_limit" not in err and "INCOMPLETE" in err
    assert "the transient diverged" in (out / "INCOMPLETE").read_text()
    summary = (out / "summary.txt").read_text()
    assert summary.startswith("INCOMPLETE: the transient diverged at t = 0.3486 s")
    assert "WARNING: node 18 orbits" in summary  # the response left the small-displacement range
    npz = np.load(out / "result.npz")
    assert 0.34 < npz["t"][-1] < 0.3486 and np.all(np.isfinite(npz["rub_18_x"]))
    assert len((out / "timeseries.csv").read_text().splitlines()) == len(npz["t"]) + 1
    assert sorted((out / ".rotorred-files").read_text().split()) == sorted(
        ["INCOMPLETE", "report.html", "result.npz", "scene.toml", "summary.txt", "timeseries.csv"])
    assert_provenance(out, argv, "summary.txt", "scene", since)  # under the INCOMPLETE line, which stays first


def test_a_diverging_comparison_is_exit_3_in_one_line_and_writes_nothing(tmp_path, capsys):
    """Reliability finding 2 in `compare`: a run that diverged was an internal error (on main: "internal error
    (SceneDiverged: ...)", exit 1, a traceback log). Now exit 3, one line saying when, where and why, not promising a
    record kept: a comparison needs every run, and writes nothing."""
    out = tmp_path / "cmp"
    assert main(["compare", "paper-rub", "--modes", "8", "--out", str(out), "--set", "unbalance[1].m_e=4.0",
                 *DIVERGE, "-q"]) == 3
    err = capsys.readouterr().err
    assert err.startswith("rotorred compare: error: the transient diverged at t = 0.3486 s at rub[0] (node 18, x)")
    assert err.strip().endswith("nothing is written (a comparison needs every run)") and "is kept" not in err, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err and not out.exists()


def test_diverging_sweep_point_is_recorded_and_the_others_kept(tmp_path, capsys):
    """A one-key sweep (a map) with a value whose transient diverges: that point is recorded with the reason, the
    other is kept, exit 3."""
    out = tmp_path / "sweep"
    assert main(["sweep", "paper-rub", "--vary", "unbalance[1].m_e=1e-3,4.0", "--cold", "--workers", "0", *DIVERGE,
                 "--out", str(out)]) == 3
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and "rotorred sweep: error: 1 of 2 points failed" in captured.err
    rows = list(csv.reader(io.StringIO((out / "map.csv").read_text())))
    header = rows[0]
    status, reason, contact = (header.index(c) for c in ("status", "reason", "contact_fraction (1)"))
    first, second = rows[1:]
    assert len(rows) == 3 and first[status] == "ok" and second[status] == "diverged"
    assert "the transient diverged at t = 0.3486 s at rub[0] (node 18, x)" in second[reason]
    assert float(first[contact]) >= 0 and second[contact] == "nan"
    assert "diverged: the transient diverged" in (out / "map.txt").read_text()
    assert (out / "lines.png").exists()


# --------------------------------------------------------------------------- interrupts and concurrency
def _rotorred(*args, **kw) -> subprocess.Popen:
    """The command in a child process, with SIGINT at its default as in a terminal: a test run started in the
    background (``pytest &``) ignores SIGINT, and a child would inherit that and never see the interrupt."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONUNBUFFERED="1")
    return subprocess.Popen([sys.executable, "-c", "import sys; from rotorred.cli import main; sys.exit(main())", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL), **kw)


def _snapshot(folder: Path) -> dict:
    """Every entry of the folder (hidden ones too) with the hash of its bytes."""
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


@pytest.fixture(scope="module")
def earlier(tmp_path_factory) -> Path:
    """A folder holding a complete earlier result (clearance 13 um)."""
    out = tmp_path_factory.mktemp("earlier") / "out"
    assert main(["run", "paper-rub", "--out", str(out), "--no-normal", *SHORT]) == 0
    return out


def _wait_for(condition, proc, timeout=60.0) -> None:
    t0 = time.monotonic()
    while not condition():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < timeout
        time.sleep(0.005)


@pytest.mark.parametrize("when, sig, status", [("solving", signal.SIGINT, 130), ("writing", signal.SIGINT, 130),
                                               ("writing", signal.SIGTERM, 143)])
def test_interrupt_leaves_the_earlier_result(earlier, tmp_path, when, sig, status):
    out = tmp_path / "out"
    os.system(f"cp -a {earlier} {out}")
    before = _snapshot(out)
    if when == "solving":  # 60 s simulated at dt = 1e-6: interrupted once the stepping stage line shows
        proc = _rotorred("run", "paper-rub", "--out", str(out), *SHORT, "--set", "solver.duration=60",
                         "--set", "solver.dt=1e-6", "--set", "solver.record_start=59.7",
                         "--set", "output.plot_window=[59.7, 59.8]")
        line = ""
        while "rotorred run: stepping paper-rub" not in line:
            ch = proc.stderr.read(1)
            assert ch, (line, proc.communicate())
            line += ch
    else:  # a 1.5 s record (75 001 samples): interrupted once the first file is staged, while the CSVs are written
        proc = _rotorred("run", "paper-rub", "--out", str(out), *SHORT, "--set", "rub.clearance=20e-6",
                         "--set", "solver.duration=1.5")
        _wait_for(lambda: any(p.is_dir() and any(p.iterdir()) for p in out.glob(".rotorred-staging-*")), proc)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status, err
    assert "Traceback" not in err and "earlier result" in err
    assert _snapshot(out) == before  # the complete earlier result, no staging folder, no lock, nothing new


def test_ctrl_c_to_the_process_group_while_the_figure_pool_starts(tmp_path):
    """Ctrl-C in a terminal reaches the whole process group: the figure pool's fork server too, which imports
    matplotlib and builds the figures' frames for about a second before multiprocessing ignores SIGINT there. It used
    to print its own KeyboardInterrupt traceback beside the command's one line (measured: every SIGINT between 0.6
    and 1.4 s after the start). The server now ignores SIGINT from its first preloaded line; the command still gets it: exit 130, one
    line, no traceback from any process."""
    import psutil

    proc = _rotorred("run", "paper-rub", "--out", str(tmp_path / "out"), "--set", "solver.duration=0.4",
                     "--set", "solver.record_start=0.2", "--set", "output.plot_window=[0.2, 0.3]",
                     start_new_session=True)

    def server_preloading():  # the server has run 0.15 s of CPU: past Python's start (~0.05 s), in its imports
        try:
            return any("multiprocessing.forkserver" in " ".join(c.cmdline()) and sum(c.cpu_times()[:2]) >= 0.15
                       for c in psutil.Process(proc.pid).children(recursive=True))
        except psutil.Error:  # a child gone meanwhile
            return False

    _wait_for(server_preloading, proc)
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in out + err and "KeyboardInterrupt" not in out + err, err
    assert "interrupted (SIGINT)" in err


def test_two_runs_into_one_folder(tmp_path):
    """Both start at once with different clearances: the second refuses (the lock) or waits its turn;
    whatever ran leaves a consistent folder (summary, NPZ and CSV of one run)."""
    out = tmp_path / "same"
    procs = [_rotorred("run", "paper-rub", "--out", str(out), *SHORT, "--set", f"rub.clearance={c}")
             for c in ("13e-6", "20e-6")]
    results = [(p.wait(timeout=120), p.communicate()[1]) for p in procs]
    assert sorted(r[0] for r in results)[0] == 0 and {r[0] for r in results} <= {0, 4}, results
    for code, err in results:
        assert "Traceback" not in err
        if code == 4:
            assert "another rotorred run" in err and "choose another --out" in err
    summary = (out / "summary.txt").read_text()
    npz = np.load(out / "result.npz")
    force = float(summary.split("max normal force ")[1].split()[0])
    assert force == pytest.approx(npz["plate0_normal_force"].max(), rel=1e-3)
    widths = {len(row.split(",")) for row in (out / "timeseries.csv").read_text().splitlines()}
    assert len(widths) == 1 and len(npz["t"]) == len((out / "timeseries.csv").read_text().splitlines()) - 1
    assert not list(out.glob(".rotorred-staging-*")) and not (out / ".rotorred.lock").exists()


# --------------------------------------------------------------------------- internal errors, missing libraries
def test_internal_error_says_so_and_logs_the_traceback(tmp_path, monkeypatch, capsys):
    import rotorred.cli.campbell as command

    def broken(args):
        raise ZeroDivisionError("a bug")
    monkeypatch.setattr(command, "run", broken)
    out = tmp_path / "o"
    assert main(["campbell", "seed-rig", "--speeds", "0:6000:3", "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "internal error (ZeroDivisionError: a bug)" in err
    assert str(out / "rotorred-error.log") in err
    assert "Traceback" in (out / "rotorred-error.log").read_text()


def test_missing_optional_library_names_its_install_command(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib now raises ModuleNotFoundError
    monkeypatch.delitem(sys.modules, "rotorred.plots.campbell", raising=False)
    assert main(["campbell", "seed-rig", "--speeds", "0:6000:3", "--out", str(tmp_path / "o")]) == 4
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and "'matplotlib'" in err and "pip install matplotlib" in err
    assert not (tmp_path / "o").exists()  # the folder this run created is removed again


@pytest.mark.parametrize("preset", [None, "4"])
def test_a_command_runs_blas_on_one_thread_unless_told(monkeypatch, preset):
    """The command sets OPENBLAS/MKL/OMP_NUM_THREADS to 1 before numpy is imported (it spins against the figure
    workers on small matrices: rotorred.cli.ONE_THREAD), and leaves a value the environment gives alone."""
    from rotorred.cli import ONE_THREAD

    for name in ONE_THREAD:
        if preset is None:
            monkeypatch.delenv(name, raising=False)
        else:
            monkeypatch.setenv(name, preset)
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    assert all(os.environ[name] == (preset or "1") for name in ONE_THREAD)


def test_the_console_script_runs_main_then_freezes_the_heap(monkeypatch, tmp_path, capsys):
    """``rotorred`` (pyproject's console script, cli.entry) returns main's status and leaves the objects frozen for
    the collector (the interpreter's exit then does not walk them)."""
    import gc
    import tomllib

    from rotorred.cli import entry

    scripts = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts["rotorred"] == "rotorred.cli:entry"
    monkeypatch.setattr(sys, "argv", ["rotorred", "run", "no-such-scene", "--out", str(tmp_path / "o")])
    gc.unfreeze()
    try:
        assert entry() == 2 and gc.get_freeze_count() > 0
    finally:
        gc.unfreeze()
    assert "no-such-scene" in capsys.readouterr().err


def test_the_console_script_sets_the_collector_thresholds_and_freezes_what_is_left(monkeypatch):
    """``rotorred`` (cli.entry) runs the command with GC_THRESHOLDS (the collector's time in a first run: 0.31 s
    against 1.03 s with the defaults), returns its status, and leaves its objects frozen for the exit."""
    import gc

    import rotorred.cli as cli

    seen = []
    monkeypatch.setattr(cli, "main", lambda: seen.append(gc.get_threshold()) or 3)
    before = gc.get_threshold()
    try:
        assert cli.entry() == 3 and seen == [cli.GC_THRESHOLDS] and gc.get_freeze_count() > 0
    finally:
        gc.set_threshold(*before)
        gc.unfreeze()
