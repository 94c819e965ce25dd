"""Inputs whose results would be meaningless, refused before computing, and results that are not finite, refused
before writing (issue 41, Build 4 for `harmonic`, `campbell` and `modes`; docs/model.md, "Physical bounds of command
inputs").

On the issue's main, `harmonic` with an absurd unbalance, speed or ratio wrote a response.csv of NaN/inf with exit 0,
and `campbell --ratio 1e300` printed UNSTABLE lines at frequencies of 1e76 Hz and more.

Bad-input kinds tested here (counted in the README), 22: 13 absurd or non-finite magnitudes (harmonic: unbalance,
speed, ratio, a spool's speed on the line, FRF frequencies, cutoff, a non-finite speed; campbell: ratio, a spool's
ratio, harmonic order, speed; modes: speed, ratio), 2 non-finite results (harmonic response, campbell whirl frequency),
4 conflicting options (harmonic: --modes, --cutoff, --boundary-nodes without --reduced, --frequencies without --frf)
and 3 mode counts beyond the model named by their option (campbell --reduce, --modes; harmonic --modes).
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

import rotorred
from rotorred import checks
from rotorred.cli import main

_HARMONIC = [  # (arguments, the option the one error line names)
    (["--speeds", "0:6000:5", "--unbalance", "11:1e300"], "--unbalance = '11:1e300': must be at most 1000 kg m"),
    (["--speeds", "0:1e300:5"], "--speeds = '0:1e300:5': must be at most 1e+06 rpm"),
    (["--speeds", "0:6000:5", "--ratio", "1e300"], "--ratio = '1e300': must be at most 100 "),
    (["--speeds", "0:600000:5", "--ratio", "50"],
     "the speed of spool 'outer' (rpm) = 30000000.0: must be at most 1e+06 rpm (twice the fastest machine rotors"),
    (["--speeds", "0:6000:5", "--frf", "18:x>13:x", "--frequencies", "0:1e9:3"],
     "--frequencies = '0:1e9:3': must be at most 1e+06 Hz"),
    (["--speeds", "0:6000:5", "--reduced", "--cutoff", "1e300"], "--cutoff = 1e+300: must be at most 1e+06 Hz"),
    (["--speeds", "0:inf:5"], "--speeds = '0:inf:5': must be START:STOP:COUNT"),
]

_CAMPBELL = [
    (["--speeds", "0:6000:5", "--ratio", "1e300", "--modes", "6"], "--ratio = '1e300': must be at most 100 "),
    (["--speeds", "0:6000:5", "--ratio", "outer=1e300"], "--ratio outer = 1e+300: must be at most 100 "),
    (["--speeds", "0:6000:5", "--harmonics", "1e9"], "--harmonics = '1e9': must be at most 1000 "),
    (["--speeds", "0:1e9:5"], "--speeds = '0:1e9:5': must be at most 1e+06 rpm"),
]


@pytest.mark.parametrize("args, expected", [
    (["--speed", "1e300"], "the speed of spool 'inner' (rpm) = 1e+300: must be at most 1e+06 rpm"),
    (["--speed", "3000", "--ratio", "1e300"], "--ratio = '1e300': must be at most 100 "),
], ids=["--speed 1e300", "--ratio 1e300"])
def test_modes_refuses_meaningless_magnitudes_before_computing(tmp_path, capsys, args, expected):
    """`modes` (a command of issue 38) printed 67 modes at up to 6e136 Hz for --speed 1e300, exit 0: every command
    that builds its speed line by options.speed_line has each spool bounded."""
    out = tmp_path / "out"
    assert main(["modes", "seed-rig", *args, "--out", str(out)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"rotorred modes: error: {expected}"), captured.err
    assert captured.out == "" and not out.exists()


def _refused(command, args, expected, tmp_path, capsys) -> None:
    """Exit 2, one line on stderr naming the option and its bound, nothing computed (no stage line), no --out."""
    out = tmp_path / "out"
    assert main([command, "seed-rig", *args, "--out", str(out)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert lines == [lines[0]] and lines[0].startswith(f"rotorred {command}: error: {expected}"), captured.err
    assert "UNSTABLE" not in captured.out and captured.out == "" and not out.exists()


@pytest.mark.parametrize("args, expected", _HARMONIC, ids=[a[-1] for a, _ in _HARMONIC])
def test_harmonic_refuses_meaningless_magnitudes_before_computing(tmp_path, capsys, args, expected):
    _refused("harmonic", args, expected, tmp_path, capsys)


@pytest.mark.parametrize("args, expected", _CAMPBELL, ids=[" ".join(a) for a, _ in _CAMPBELL])
def test_campbell_refuses_meaningless_magnitudes_before_computing(tmp_path, capsys, args, expected):
    _refused("campbell", args, expected, tmp_path, capsys)


def test_a_message_gives_the_bound_and_why(tmp_path, capsys):
    assert main(["campbell", "seed-rig", "--speeds", "0:6000:5", "--ratio", "1e300", "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.strip().endswith(f"must be at most 100 ({checks.BOUNDS['ratio'].why})")


def test_the_bounds_hold_at_the_bound_and_convert_units():
    """At the bound accepted, just beyond refused; a speed in rad/s or Hz is bounded by the same speed."""
    for kind, bound in checks.BOUNDS.items():
        unit = bound.unit
        assert checks.bounded("x", bound.limit, bound.limit, kind)[()] == bound.limit
        with pytest.raises(checks.InputError, match=re.escape(f"x = {bound.limit * 1.000001!r}: must be at most")):
            checks.bounded("x", bound.limit * 1.000001, bound.limit * 1.000001, kind, unit)
    checks.bounded("x", 0, 1e6 * np.pi / 30, "speed", "rad/s")
    checks.bounded("x", 0, 1e6 / 60, "speed", "Hz")
    for unit, value in (("rad/s", 1e6 * np.pi / 30 * 1.000001), ("Hz", 1e6 / 60 * 1.000001)):
        with pytest.raises(checks.InputError, match=re.escape(f"{1e6 / (60 if unit == 'Hz' else 30 / np.pi):.6g} "
                                                              f"{unit} = 1e+06 rpm")):
            checks.bounded("x", value, value, "speed", unit)
    with pytest.raises(checks.InputError, match="must be finite"):
        checks.bounded("x", "nan", [1.0, np.nan], "ratio")
    for kind, bound in checks.BOUNDS.items():  # a least magnitude: at it accepted, just below refused
        if bound.least:
            assert checks.bounded("x", bound.least, bound.least, kind)[()] == bound.least
            with pytest.raises(checks.InputError, match="must be at least"):
                checks.bounded("x", bound.least * 0.999999, bound.least * 0.999999, kind)


def test_the_bounds_are_the_documented_ones():
    """Each bound of checks.BOUNDS is in the table of docs/model.md with its value."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "model.md").read_text(encoding="utf-8")
    section = text[text.index("## 23. Physical bounds of command inputs"):]
    rows = {"speed": "| 1e6 rpm", "ratio": "| 100 |", "unbalance": "| 1000 kg m |", "harmonic": "| 1000 |",
            "frequency": "| 1e6 Hz |", "clearance": "| 0.1 m |", "tolerance": "| 0.01, and at least 1e-14 |",
            "step": "| 0.01 s, and at least 1e-9 s |", "refine": "| 100 |"}
    assert set(rows) == set(checks.BOUNDS)
    for kind, cell in rows.items():
        assert cell in section, kind
        assert float(cell.strip("| ").split()[0].rstrip(",")) == checks.BOUNDS[kind].limit
        if checks.BOUNDS[kind].least:
            assert float(cell.split("at least ")[1].split()[0]) == checks.BOUNDS[kind].least


@pytest.mark.parametrize("args, expected", [
    (["continue", "paper-rub", "--param", "speeds.outer=90:1e300"],
     "--param = 'speeds.outer=90:1e300': must be at most 16666.7 Hz = 1e+06 rpm (" + checks.BOUNDS["speed"].why),
    (["continue", "paper-rub", "--param", "rub.clearance=45e-6:1e300"],
     "--param = 'rub.clearance=45e-6:1e300': must be at most 0.1 m (" + checks.BOUNDS["clearance"].why),
    (["continue", "paper-rub", "--param", "rub.clearance=45e-6:40e-6", "--tol", "1e300"],
     "--tol = 1e+300: must be at most 0.01 (" + checks.BOUNDS["tolerance"].why),
    (["continue", "paper-rub", "--param", "rub.clearance=45e-6:40e-6", "--tol", "1e-300"],
     "--tol = 1e-300: must be at least 1e-14 (" + checks.BOUNDS["tolerance"].why),
    (["compare", "paper-rub", "--refine", "1000000000"],
     "--refine = 1000000000: must be at most 100 (" + checks.BOUNDS["refine"].why),
    (["compare", "paper-rub", "--dt", "2e-5,1e300"], "--dt = '2e-5,1e300': must be at most 0.01 s ("),
    (["compare", "paper-rub", "--dt", "1e-300"], "--dt = '1e-300': must be at least 1e-09 s ("),
])
def test_continue_and_compare_refuse_absurd_option_values_naming_the_bound(tmp_path, capsys, args, expected):
    """Issue 41: `continue` and `compare` had no bounds on their options' magnitudes (on main: `continue --param
    speeds.outer=90:1e300` an internal error (OverflowError), `--param rub.clearance=45e-6:1e300` and `--tol 1e300`
    exit 0 with overflow warnings, `--tol 1e-300` "the matrix is singular", `compare --refine 1e9` killed for its
    memory (exit 137), `--dt 1e300` an internal error (SceneDiverged)). Now each is refused before any work (exit 2, one
    line naming the option, its value, the bound and why; no traceback, no --out). `run` has no number of its own: its
    values are scene keys (`--set`), the scene loader's."""
    out = tmp_path / "o"
    assert main([*args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"rotorred {args[0]}: error: {expected}") and len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err and not out.exists()


def test_a_non_finite_response_is_refused_before_writing(tmp_path, capsys, monkeypatch):
    """A response holding NaN (as an absurd input gave on main): exit 2 naming the output, the spool and the speeds;
    no response.csv of NaN, no --out."""
    real = rotorred.unbalance_response

    def with_nan(*args, **kwargs):
        result = real(*args, **kwargs)
        result.phasors["outer"][(14, "y")][3] = np.nan
        return result

    monkeypatch.setattr(rotorred, "unbalance_response", with_nan)
    out = tmp_path / "out"
    assert main(["harmonic", "seed-rig", "--speeds", "0:6000:5", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("rotorred harmonic: error: the response at node 14 y to the outer unbalances is nan at "
                          "inner 4500 rpm, outer 5785.71 rpm (1 of 5 values not finite): nothing written"), err
    assert not out.exists()


def test_a_non_finite_whirl_frequency_is_refused_before_writing(tmp_path, capsys, monkeypatch):
    real = rotorred.campbell

    def with_inf(*args, **kwargs):
        result = real(*args, **kwargs)
        frequencies = result.frequencies.copy()
        frequencies[2, 1] = np.inf
        return dataclasses.replace(result, frequencies=frequencies)

    monkeypatch.setattr(rotorred, "campbell", with_inf)
    out = tmp_path / "out"
    assert main(["campbell", "seed-rig", "--speeds", "0:6000:5", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("rotorred campbell: error: the whirl frequency (Hz) is inf for mode 2 at 3000 rpm of "
                          "inner"), err
    assert not out.exists()


def test_bounded_values_still_run(tmp_path, capsys):
    """Within the bounds the commands run as before (a ratio of 2, an unbalance of 1 kg m)."""
    out = tmp_path / "out"
    assert main(["harmonic", "seed-rig", "--speeds", "0:6000:5", "--ratio", "2", "--unbalance", "11:1", "--out",
                 str(out), "-q"]) == 0
    assert (out / "response.csv").is_file() and "nan" not in (out / "response.csv").read_text()


_CONFLICTS = [  # options the command would ignore: refused, naming the option and what it needs
    (["--modes", "8"], "--modes = 8: applies to the reduced model only: add --reduced"),
    (["--cutoff", "300"], "--cutoff = 300.0: applies to the reduced model only: add --reduced"),
    (["--boundary-nodes", "18"], "--boundary-nodes = '18': applies to the reduced model only: add --reduced"),
    (["--frequencies", "0:100:11"], "--frequencies = '0:100:11': applies with --frf only"),
]


@pytest.mark.parametrize("args, expected", _CONFLICTS, ids=[a[0] for a, _ in _CONFLICTS])
def test_harmonic_refuses_options_it_would_ignore(tmp_path, capsys, args, expected):
    """On main each was silently ignored (the full model solved, no FRF), exit 0."""
    _refused("harmonic", ["--speeds", "0:6000:5", *args], expected, tmp_path, capsys)


@pytest.mark.parametrize("command, args, expected", [
    ("campbell", ["--reduce", "1000000"], "--reduce = 1000000: must be <= 60"),
    ("campbell", ["--modes", "1000000"], "--modes = 1000000: must be <= 80"),
    ("harmonic", ["--reduced", "--modes", "100000"], "--modes = 100000: must be <= 56"),
], ids=["campbell --reduce", "campbell --modes", "harmonic --modes"])
def test_a_mode_count_beyond_the_model_names_the_option(tmp_path, capsys, command, args, expected):
    """On main the message named the function's parameter (`n_modes = 1000000: ...`), not the option typed."""
    out = tmp_path / "out"
    assert main([command, "seed-rig", "--speeds", "0:6000:5", *args, "--out", str(out)]) == 2
    errors = [line for line in capsys.readouterr().err.splitlines() if ": error: " in line]
    assert len(errors) == 1 and errors[0].startswith(f"rotorred {command}: error: {expected}"), errors
    assert not out.exists()
