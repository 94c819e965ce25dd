"""Installs that are not writable, and a missing pyFFTW (issue 17, item 5), each in a subprocess.

* A read-only copy of the package with a HOME that is not writable and no NUMBA_CACHE_DIR runs a short rub
  transient: numba's cache falls back to the temporary directory (rotorred.transient.numba_cache), announced
  by one line on stderr. As root, ``chmod`` does not stop writes (CAP_DAC_OVERRIDE), so the subprocess is
  started through ``setpriv`` without the capabilities that bypass file permissions (as
  shared/docs/reliability.md §3 does); the subprocess checks that it really cannot write into the package.
* With pyFFTW hidden (a ``sitecustomize`` that sets ``sys.modules['pyfftw'] = None``), the spectra fall back to
  numpy.fft with a one-line note, and ``rotorred run`` of a short scene works.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rotorred.transient.newmark import COMPILING_NOTE

PACKAGE = Path(__file__).resolve().parents[1] / "rotorred"

TRANSIENT = """
import json, logging, os
logging.basicConfig(format="%(message)s", level=logging.INFO)  # rotorred's warnings and stage lines on stderr
import rotorred
from rotorred.model.loads import Unbalance
from rotorred.model.rotor_file import load_rotor
from rotorred.transient.contact import RubPlate
from rotorred.model.operating import Operating
from rotorred.transient.newmark import Loads, Recording, simulate
rig = load_rotor("seed-rig")
res = simulate(rig, Operating.point(rig.speeds), 0.002, 2e-5, loads=Loads([Unbalance(18, 1e-3, 0.0)]),
               contacts=[RubPlate.for_rotor(rig, 18, clearance=0.0)], recording=Recording([(18, "y")]))
try:
    probe = os.path.join(os.path.dirname(rotorred.__file__), "probe")
    open(probe, "w").close()
    os.remove(probe)  # a writable package (the cache test's own checkout) keeps nothing of it
    writable = True
except OSError:
    writable = False
print(json.dumps({"ok": bool(res.success), "steps": res.n_steps, "contact": res.n_contact_steps,
                  "package_writable": writable, "home_writable": os.access(os.environ["HOME"], os.W_OK),
                  "load": res.kernel_load_time, "run": res.run_time, "compiled": res.kernel_compiled}))
"""

SETPRIV = ["setpriv", "--bounding-set=-dac_override,-dac_read_search,-fowner", "--"]


def _clean_env(**changes) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "NUMBA_DISABLE_JIT")}
    env.update(changes)
    return env


def _make_writable(path: Path) -> None:
    for p in [path, *path.rglob("*")]:
        if not p.is_symlink():
            p.chmod(p.stat().st_mode | stat.S_IWUSR)


def test_read_only_install_with_unwritable_home_runs(tmp_path):
    """A cold read-only install (nothing cached) compiles into the temporary directory, says so once, and runs."""
    prefix = []
    if os.geteuid() == 0:
        if shutil.which("setpriv") is None:
            pytest.skip("running as root without setpriv: chmod cannot make the package read-only for root")
        prefix = SETPRIV
    pkg, home, tmp = tmp_path / "pkg", tmp_path / "home", tmp_path / "tmp"
    shutil.copytree(PACKAGE, pkg / "rotorred", ignore=shutil.ignore_patterns("__pycache__"))
    home.mkdir()
    tmp.mkdir()
    try:
        for p in [pkg, *pkg.rglob("*"), home]:
            p.chmod(p.stat().st_mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
        out, again = (subprocess.run(prefix + [sys.executable, "-c", TRANSIENT], cwd=tmp, capture_output=True, text=True,
                                     env=_clean_env(PYTHONPATH=str(pkg), HOME=str(home), TMPDIR=str(tmp)), timeout=300)
                      for _ in range(2))
    finally:
        _make_writable(pkg)
        _make_writable(home)
    assert out.returncode == 0 and "Traceback" not in out.stderr, out.stderr
    report = json.loads(out.stdout.splitlines()[-1])
    assert report["ok"] and report["steps"] == 100 and report["contact"] > 0
    assert not report["package_writable"] and not report["home_writable"]  # the test meant what it says
    notes = [line for line in out.stderr.splitlines() if line.strip()]
    # where the cache went, then (a fresh cache) the compilation announced on its own line
    assert len(notes) == 2 and notes[0].startswith("the user cache folder ") and str(tmp) in notes[0], out.stderr
    assert notes[1] == COMPILING_NOTE, out.stderr
    assert report["load"] > 100 * report["run"]  # the compilation is timed apart from the 100 steps
    assert any((tmp / f"rotorred-numba-{os.getuid()}").rglob("*.nbi"))  # the cache is there for the next run
    # the next run loads the cache: no compilation note, and loading takes a fraction of compiling
    assert again.returncode == 0 and "compiling" not in again.stderr, again.stderr
    assert json.loads(again.stdout.splitlines()[-1])["load"] < 0.2 * report["load"]
    assert report["compiled"] and not json.loads(again.stdout.splitlines()[-1])["compiled"]


def test_a_cache_entry_that_cannot_be_loaded_is_compiled_and_said_so(tmp_path):
    """The kernel's cache index lists it but its code file is gone: numba compiles it again; the result and a stage
    line say it was compiled (it was predicted from the index alone, and a 9 s compilation went unsaid)."""
    env = _clean_env(NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    run = lambda: subprocess.run([sys.executable, "-c", TRANSIENT], capture_output=True, text=True, env=env,
                                 timeout=300)
    cold = run()
    assert cold.returncode == 0 and json.loads(cold.stdout.splitlines()[-1])["compiled"], cold.stderr
    code = list((tmp_path / "cache").rglob("*.nbc"))
    assert code and list((tmp_path / "cache").rglob("*.nbi"))
    for f in code:
        f.unlink()
    again = run()
    assert again.returncode == 0 and json.loads(again.stdout.splitlines()[-1])["compiled"], again.stderr
    assert COMPILING_NOTE not in again.stderr  # the index said cached ...
    assert "compiled the step kernel: its cache entry could not be loaded" in again.stderr  # ... and it was not


@pytest.fixture()
def no_pyfftw(tmp_path) -> dict:
    """Environment of a subprocess in which ``import pyfftw`` fails."""
    shim = tmp_path / "shim"
    shim.mkdir()
    (shim / "sitecustomize.py").write_text("import sys\nsys.modules['pyfftw'] = None  # hide pyFFTW\n")
    return _clean_env(PYTHONPATH=os.pathsep.join([str(shim), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))


SPECTRA = """
import json
import numpy as np
from rotorred.signals import spectra
t = np.arange(1000) * 1e-4
x = 3.0 * np.cos(2 * np.pi * 70 * t) + 0.5 * np.sin(2 * np.pi * 90 * t)
s = spectra.settled_spectrum(x, 1e-4, 70.0, 90.0)
amp = lambda f: float(s.amplitudes[np.argmin(np.abs(s.frequencies - f))])
print(json.dumps({"plan": type(spectra.rfft_plan(1000)).__name__, "a70": amp(70.0), "a90": amp(90.0)}))
"""


def test_spectra_fall_back_to_numpy_without_pyfftw(no_pyfftw):
    out = subprocess.run([sys.executable, "-c", SPECTRA], capture_output=True, text=True, env=no_pyfftw, timeout=120)
    assert out.returncode == 0 and "Traceback" not in out.stderr, out.stderr
    report = json.loads(out.stdout.splitlines()[-1])
    assert report["plan"] == "NumpyPlan"
    # on-bin tones read exactly (rectangular window on a whole number of common periods): round-off only
    assert report["a70"] == pytest.approx(3.0, rel=1e-12) and report["a90"] == pytest.approx(0.5, rel=1e-12)
    assert out.stderr.strip().splitlines() == [  # a logging warning: Python's last-resort handler prints it
        "pyFFTW is not installed; spectra use numpy.fft (same results; `pip install pyfftw` for the faster FFT)"]


def test_run_works_without_pyfftw(no_pyfftw, tmp_path):
    """`rotorred run` of a 0.3 s paper-rub writes its spectra and lines with numpy.fft."""
    cmd = [sys.executable, "-c", "import sys; from rotorred.cli import main; sys.exit(main())", "run", "paper-rub",
           "--out", str(tmp_path / "out"), "--set", "solver.duration=0.3", "--set", "solver.record_start=0.1",
           "--set", "output.plot_window=[0.1,0.2]", "--set", "output.plots=[]"]
    out = subprocess.run(cmd, capture_output=True, text=True, env=no_pyfftw, timeout=300)
    assert out.returncode == 0 and "Traceback" not in out.stderr, out.stderr
    assert "pyFFTW is not installed" in out.stderr
    lines = (tmp_path / "out" / "lines.csv").read_text().splitlines()
    assert len(lines) > 10 and np.isfinite(np.loadtxt(tmp_path / "out" / "spectra.csv", delimiter=",", skiprows=1)).all()
