"""Output a terminal cannot encode falls back to ASCII (issue 41, Build 6): µm -> um, × -> x, never a failure after
computing. On the issue's main, `campbell` under ``PYTHONIOENCODING=ascii`` printed logging's "--- Logging error ---"
traceback in place of its report (the critical speeds hold ``1× outer``).

Fault kinds tested here (counted in the README): an ASCII stdout (PYTHONIOENCODING), an ASCII locale without UTF-8
mode (LC_ALL=C, PYTHONUTF8=0, PYTHONCOERCECLOCALE=0), a non-ASCII error message on an ASCII stderr.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

_ASCII = {"PYTHONIOENCODING": "ascii"}
_C_LOCALE = {"LC_ALL": "C", "LANG": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0", "PYTHONIOENCODING": ""}


def _rotorred(args, env_extra, cwd) -> subprocess.CompletedProcess:
    env = {**os.environ, **env_extra, "MPLBACKEND": "Agg"}
    env = {k: v for k, v in env.items() if v != ""}
    script = "import sys; from rotorred.cli import entry; sys.exit(entry())"  # the console script's
    return subprocess.run([sys.executable, "-c", script, *args], cwd=cwd, capture_output=True, env=env, timeout=300)


@pytest.mark.parametrize("env", [_ASCII, _C_LOCALE], ids=["PYTHONIOENCODING=ascii", "LC_ALL=C"])
def test_a_report_with_times_signs_falls_back_to_ascii(tmp_path, env):
    """campbell's report ('1× outer', '1.25 × 128.6 Hz') on an ASCII stdout: exit 0, the report in ASCII, nothing
    else on stderr than the stage line; the files keep UTF-8."""
    done = _rotorred(["campbell", "seed-rig", "--speeds", "0:6000:5", "--out", "out"], env, tmp_path)
    out, err = done.stdout.decode("ascii"), done.stderr.decode("ascii")  # both ASCII: raises otherwise
    assert done.returncode == 0, err
    assert "1x outer" in out and "every mode below 1.25 x 128.6 Hz" in out and "wrote out/campbell.csv" in out, out
    assert err.splitlines() == ["rotorred campbell: whirl frequencies of seed-rig at 5 speeds, 7 modes tracked "
                                "(80 DOFs)"], err
    assert "1× outer" in (tmp_path / "out" / "campbell.txt").read_text(encoding="utf-8")


def test_an_error_message_with_non_ascii_falls_back_too(tmp_path):
    done = _rotorred(["campbell", "seed-rig", "--speeds", "0:6000µ:5", "--out", "out"], _ASCII, tmp_path)
    err = done.stderr.decode("ascii")
    assert done.returncode == 2 and err.startswith("rotorred campbell: error: --speeds = '0:6000u:5': must be "), err
    assert len(err.strip().splitlines()) == 1


def test_ascii_forms():
    from rotorred.progress import ascii_text

    assert ascii_text("4.2 µm, 1× outer, 90°, E − E₀ ≤ 2") == "4.2 um, 1x outer, 90deg, E - E0 <= 2"
    assert ascii_text("Ω_outer/Ω_inner, café, 2fₕ") == "Omega_outer/Omega_inner, cafe, 2fh"
    assert ascii_text("plain") == "plain" and ascii_text("☃") == "?"
