"""Bad input through the command line: exit status 2, one message naming the key, the value and what is
allowed, no traceback, no file written, nothing computed (every case is refused in well under a second).

Each case is (argv, tokens): ``argv`` may name the inputs made by the ``inputs`` fixture as ``{d}/<file>``,
and every token must appear in the one-line message. The rotor files are the seed rig and the scene files
``paper-rub`` with one line changed (``R`` and ``S`` below); ``{ro}`` is a folder that cannot be written.
"""

from __future__ import annotations

import os
import re
from importlib import resources
from pathlib import Path

import pytest

from rotorred.cli import main

#: words of a message that says what is allowed
ALLOWED = re.compile(r"must|allowed|required|missing|--force|neither|unknown|expected|invalid", re.I)

#: rotor files: name -> (text to replace in seed-rig.toml, replacement)
R = {
    "E_neg": ("E = 2.1e11", "E = -5.0"), "rho_zero": ("rho = 7850.0", "rho = 0.0"), "nu": ("nu = 0.3", "nu = 0.7"),
    "mat_key": ("nu = 0.3", "nu = 0.3\nfoo = 1"), "D_i": ("D_i = 0.040", "D_i = 0.07"),
    "L_neg": ("L = 0.08", "L = -0.08"), "repeat0": ("repeat = 12", "repeat = 0"),
    "brass": ('material = "steel", repeat = 6', 'material = "brass", repeat = 6'),
    "first_node": ("first_node = 1", "first_node = -1"), "disk_node": ("node = 3", "node = 99"),
    "thickness": ("thickness = 0.015", "thickness = -0.015"), "c_neg": ("c = 1000.0", "c = -1.0"),
    "rpm_str": ("speed_rpm = 4200.0", 'speed_rpm = "fast"'),
    "shear": ('name = "inner"', 'name = "inner"\nshear = "bogus"'),
    "huge": ("repeat = 6 }", "repeat = 100000 }"),
    "E_huge": ("E = 2.1e11", "E = 1e300"), "rho_tiny": ("rho = 7850.0", "rho = 1e-300"),
}
#: scene files: name -> (text to replace in paper-rub.toml, replacement)
S = {
    "clearance": ("clearance = 13e-6", "clearance = -5e-06"), "section": ('name = "paper-rub"', 'name = "x"\n[foo]\nbar = 1'),
    "dt0": ("dt = 2e-5 ", "dt = 0.0 "), "rec": ("record_start = 2.0", "record_start = 3.5"),
    "model": ('model = "reduced"', 'model = "half"'), "out_node": ("nodes = [13, 14, 18]", "nodes = [13, 14, 99]"),
    "table": ('table = "14:y"', 'table = "14:q"'), "unb_node": ("node = 11", "node = 99"),
    "speed": ("inner = 70.0", "inner = -70.0"), "mu": ("mu_s = 0.2 ", 'mu_s = "x" '),
    "K_nr": ("K_nr = 5e10", "K_nr = -5.0"), "preset": ('preset = "seed-rig"', 'preset = "nope"'),
    "formats": ('formats = ["npz", "csv", "mat"]', 'formats = ["xls"]'),
    "plots": ('plots = ["waveforms", "spectra", "orbits", "poincare"]', 'plots = ["movie"]'),
    "threshold": ("line_threshold = 0.005", "line_threshold = 2.0"),
    "window": ("plot_window = [2.44, 2.58]", "plot_window = [5.0, 6.0]"), "modes": ("modes = 24 ", "modes = -3 "),
}

CASES = [
    # ---- rotor files (through campbell and harmonic)
    *[(["campbell", f"{{d}}/r_{k}.toml", "--speeds", "0:6000:3", "--out", "{d}/o"], [f"r_{k}.toml", new.split("\n")[-1]
      .split(" = ")[0].split(",")[-1].strip(" {"), new.split(" = ")[-1].split(",")[0].strip('"} ')])
      for k, (old, new) in R.items() if k not in ("huge", "brass", "E_huge", "rho_tiny")],
    (["campbell", "{d}/r_E_huge.toml", "--speeds", "0:6000:3", "--out", "{d}/o"], ["material[0].E", "1e+300", "1e+18"]),
    (["campbell", "{d}/r_rho_tiny.toml", "--speeds", "0:6000:3", "--out", "{d}/o"], ["material[0].rho", "1e-300"]),
    (["campbell", "{d}/r_brass.toml", "--speeds", "0:6000:3", "--out", "{d}/o"], ["material", "brass"]),
    (["campbell", "{d}/r_huge.toml", "--speeds", "0:6000:3", "--out", "{d}/o"], ["ROTOR", "DOFs", "--force"]),
    (["harmonic", "{d}/r_c_neg.toml", "--out", "{d}/o"], ["r_c_neg.toml", "c", "-1.0"]),  # k < 0: a seal's
    (["campbell", "{d}/missing.toml", "--speeds", "0:6000:3", "--out", "{d}/o"], ["missing.toml"]),
    # a binary or Latin-1 file, and a key given twice (reliability findings, section 9)
    (["campbell", "{d}/binary.toml", "--speeds", "0:6000:3", "--out", "{d}/o"], ["binary.toml", "UTF-8"]),
    (["run", "{d}/latin1.toml", "--out", "{d}/o"], ["latin1.toml", "UTF-8"]),
    (["run", "{d}/twice.toml", "--out", "{d}/o"], ["twice.toml", "name", "given once", "line 2"]),
    # ---- scene files (through run, and one through sweep (= map) and harmonic)
    *[(["run", f"{{d}}/s_{k}.toml", "--out", "{d}/o"], [f"s_{k}.toml", new.split("\n")[-1].split(" = ")[0],
                                                        new.split("\n")[-1].split(" = ")[-1].strip('[]" ').split(",")[-1].strip('" ')])
      for k, (old, new) in S.items()],
    (["sweep", "{d}/s_clearance.toml", "--vary", "rub.clearance=1e-6,-2e-6", "--out", "{d}/o"], ["rub[0].clearance"]),
    (["harmonic", "{d}/s_unb_node.toml", "--out", "{d}/o"], ["unbalance[0].node", "99"]),
    (["run", "{d}/missing.toml", "--out", "{d}/o"], ["missing.toml"]),
    (["run", "nosuch-scene", "--out", "{d}/o"], ["nosuch-scene"]),
    # ---- --set
    (["run", "paper-rub", "--set", "rub.clearance", "--out", "{d}/o"], ["--set", "rub.clearance"]),
    (["run", "paper-rub", "--set", "rub.foo=1", "--out", "{d}/o"], ["foo", "1"]),
    (["run", "paper-rub", "--set", "rub.clearance=1e-6,2e-6", "--out", "{d}/o"], ["--set", "rub.clearance=1e-6,2e-6"]),
    (["run", "paper-rub", "--set", "solver.dt=-1e-5", "--out", "{d}/o"], ["solver.dt", "-1e-05"]),
    # ---- absurd sizes: refused with the estimate, before anything is computed
    (["run", "paper-rub", "--set", "solver.duration=1e6", "--out", "{d}/o"], ["solver.duration", "1000000.0", "steps",
                                                                             "--force"]),
    (["run", "paper-rub", "--set", "solver.dt=1e-12", "--out", "{d}/o"], ["solver.duration", "steps", "--force"]),
    (["run", "paper-normal", "--set", "solver.duration=1e6", "--out", "{d}/o"], ["solver.record_start", "memory"]),
    (["sweep", "paper-rub", "--vary", "rub.clearance=1e-6,2e-6", "--set", "solver.duration=1e6", "--out", "{d}/o"],
     ["solver.duration", "steps"]),
    (["map", "paper-rub", "--vary", "speeds.outer=60:110:101", "--limit", "1e4", "--out", "{d}/o"],
     ["--vary", "speeds.outer=<101 values>", "steps in all", "--force"]),
    (["campbell", "seed-rig", "--speeds", "0:1000:1000000000", "--out", "{d}/o"], ["--speeds", "COUNT"]),
    # ---- solver.method = "harmonic-balance"
    (["run", "paper-rub", "--set", "solver.harmonics=50", "--out", "{d}/o"], ["solver.harmonics", "harmonic-balance"]),
    (["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "solver.samples=1001", "--out", "{d}/o"],
     ["solver.samples", "1001", "even"]),
    (["run", "paper-normal", "--set", "solver.method=harmonic-balance", "--out", "{d}/o"], ["solver.method", "rub plate"]),
    (["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "solver.gravity=9.81", "--out", "{d}/o"],
     ["solver.gravity", "9.81"]),
    # at incommensurate speeds the torus: its truncation a pair of orders and of grid sizes
    (["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "speeds.outer=91.37", "--set",
      "solver.harmonics=100", "--out", "{d}/o"], ["solver.harmonics", "100", "pair [H1, H2]", "incommensurate"]),
    (["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "solver.harmonics=[4,20]", "--out",
      "{d}/o"], ["solver.harmonics", "[4, 20]", "period of at most 10 s"]),
    (["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "speeds.outer=91.37", "--set",
      "solver.samples=[16,64]", "--out", "{d}/o"], ["solver.samples", "[16, 64]", "pair [N1, N2]"]),
    (["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "speeds.outer=91.37", "--set",
      "solver.harmonics=[4,20]", "--set", "solver.samples=[8,64]", "--out", "{d}/o"], ["solver.samples[0]", "8", ">= 10"]),
    (["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "solver.tolerance=0.01", "--set",
      "solver.harmonics=50", "--out", "{d}/o"], ["solver.harmonics", "solver.tolerance"]),
    (["run", "paper-rub", "--set", "solver.method=hht", "--set", "solver.tolerance=0.01", "--out", "{d}/o"],
     ["solver.tolerance", "harmonic-balance"]),
    (["run", "paper-rub", "--set", "solver.method=harmonic-balance", "--set", "solver.harmonics=5", "--set",
      "solver.samples=64", "--out", "{d}/o"], ["solver.harmonics", "at least 9"]),
    # ---- continue (harmonic-balance branches)
    (["continue", "paper-rub", "--param", "rub.clearance=20e-6", "--out", "{d}/o"], ["--param", "KEY=START:STOP"]),
    (["continue", "paper-rub", "--param", "rub.clearance=2e-5:2e-5", "--out", "{d}/o"], ["--param", "different"]),
    (["continue", "paper-rub", "--param", "rub.mu_s=0.1:0.2", "--out", "{d}/o"], ["--param", "rub.mu_s", "rub.k_n"]),
    (["continue", "paper-rub", "--param", "rub.mu_d=0.15:0.2", "--out", "{d}/o"], ["--param", "room", "mu_s = 0.2"]),
    (["continue", "paper-rub", "--param", "speeds.middle=80:90", "--out", "{d}/o"], ["speeds.middle", "inner"]),
    (["continue", "paper-normal", "--param", "rub.clearance=2e-5:1e-5", "--out", "{d}/o"], ["SCENE", "rub plate"]),
    (["continue", "paper-rub", "--param", "rub.clearance=2e-5:1e-5", "--samples", "1023", "--out", "{d}/o"],
     ["--samples", "1023", "even"]),
    (["continue", "paper-rub", "--param", "rub.clearance=2e-5:1e-5", "--harmonics", "0", "--out", "{d}/o"],
     ["--harmonics", "0"]),
    (["continue", "paper-rub", "--set", "speeds.outer=91.37", "--param", "rub.clearance=2e-5:1e-5", "--out", "{d}/o"],
     ["speeds", "91.37", "greatest common divisor"]),
    # ---- campbell options
    (["campbell", "seed-rig", "--speeds", "0:12000", "--out", "{d}/o"], ["--speeds", "0:12000"]),
    (["campbell", "seed-rig", "--speeds=-100:100:5", "--out", "{d}/o"], ["--speeds", "-100:100:5", "rpm"]),
    (["campbell", "seed-rig", "--speeds", "5,3", "--out", "{d}/o"], ["--speeds", "5,3", "increasing"]),
    (["campbell", "seed-rig", "--speeds", "0:6000:3", "--modes", "0", "--out", "{d}/o"], ["--modes", "0"]),
    (["campbell", "seed-rig", "--speeds", "0:6000:3", "--harmonics", "0", "--out", "{d}/o"], ["--harmonics", "0"]),
    (["campbell", "seed-rig", "--speeds", "0:6000:3", "--harmonics", "x", "--out", "{d}/o"], ["--harmonics", "x"]),
    (["campbell", "seed-rig", "--speeds", "0:6000:3", "--ratio", "-1", "--out", "{d}/o"], ["--ratio", "-1"]),
    (["campbell", "seed-rig", "--speeds", "0:6000:3", "--ratio", "outer=x", "--out", "{d}/o"],
     ["--ratio", "outer=x", "SPOOL=R"]),
    (["campbell", "seed-rig", "--speeds", "0:6000:3", "--ratio", "outer=1.2,outer=1.3", "--out", "{d}/o"],
     ["--ratio", "outer=1.3", "once"]),
    (["campbell", "seed-rig", "--speeds", "0:6000:3", "--reference", "mid", "--out", "{d}/o"], ["--reference", "mid"]),
    # ---- harmonic options (all checked before the sweep: reliability.md section 8)
    (["harmonic", "seed-rig", "--speeds=-100:100:5", "--out", "{d}/o"], ["--speeds", "-100:100:5", "rpm"]),
    (["harmonic", "seed-rig", "--reduced", "--cutoff=-1", "--out", "{d}/o"], ["--cutoff", "-1", "Hz"]),
    (["harmonic", "seed-rig", "--modes", "-1", "--reduced", "--out", "{d}/o"], ["--modes", "-1"]),
    (["harmonic", "seed-rig", "--unbalance", "99:1e-5", "--out", "{d}/o"], ["--unbalance", "99"]),
    (["harmonic", "seed-rig", "--unbalance", "11", "--out", "{d}/o"], ["--unbalance", "11"]),
    (["harmonic", "seed-rig", "--outputs", "99:x", "--out", "{d}/o"], ["--outputs", "99"]),
    (["harmonic", "seed-rig", "--outputs", "13:q", "--out", "{d}/o"], ["--outputs", "13:q"]),
    (["harmonic", "seed-rig", "--frf", "18:x", "--out", "{d}/o"], ["--frf", "18:x"]),
    (["harmonic", "seed-rig", "--frf", "18:x>99:x", "--out", "{d}/o"], ["--frf", "99"]),
    (["harmonic", "seed-rig", "--frf", "18:x>13:x", "--frequencies", "0:500", "--out", "{d}/o"],
     ["--frequencies", "0:500"]),
    (["harmonic", "seed-rig", "--frf", "18:x>13:x", "--frequencies=-5:5:3", "--out", "{d}/o"],
     ["--frequencies", "-5:5:3", "Hz"]),
    (["harmonic", "seed-rig", "--ratio", "abc", "--out", "{d}/o"], ["--ratio", "abc"]),
    (["harmonic", "seed-rig", "--reference-spool", "mid", "--out", "{d}/o"], ["--reference-spool", "mid"]),
    (["harmonic", "seed-rig", "--reduced", "--boundary-nodes", "99", "--out", "{d}/o"], ["--boundary-nodes", "99"]),
    # ---- sweep (= map) options
    (["sweep", "paper-rub", "--vary", "rub.clearance=1e-6,2e-6", "--set", "output.table=[99, \"y\"]", "--out",
      "{d}/o"], ["output.table", "99"]),
    (["sweep", "paper-rub", "--set", "rub.clearance=1e-6,2e-6", "--out", "{d}/o"],
     ["--set", "rub.clearance=1e-6,2e-6", "--vary"]),
    (["sweep", "paper-rub", "--vary", "rub.clearance=1e-6,2e-6", "--set", "solver.dt=1e-5,2e-5", "--out", "{d}/o"],
     ["--set", "solver.dt=1e-5,2e-5"]),
    (["sweep", "paper-rub", "--vary", "rub.clearance=1:2:1", "--out", "{d}/o"], ["--vary rub.clearance", "1:2:1"]),
    # ---- --out problems, in every command: an existing file, below a file, empty, not writable
    *[([*cmd, "--out", out], ["--out", token]) for cmd in (["run", "paper-rub"],
                                                          ["sweep", "paper-rub", "--vary", "rub.clearance=1e-6,2e-6"],
                                                          ["campbell", "seed-rig", "--speeds", "0:6000:3"],
                                                          ["harmonic", "seed-rig"],
                                                          ["map", "paper-rub", "--vary", "rub.clearance=1e-6,2e-6"],
                                                          ["continue", "paper-rub", "--param", "rub.clearance=45e-6:4e-5"],
                                                          ["compare", "paper-rub"], ["modes", "seed-rig", "--speed", "3000"])
      for out, token in (("{d}/afile", "afile"), ("{d}/afile/sub", "afile"), ("", "''"), ("{ro}/sub", "ro"))],
]


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """The bad rotor and scene files, a file ``afile`` and a read-only folder ``ro``."""
    d = tmp_path_factory.mktemp("inputs")
    rig = resources.files("rotorred.model.presets").joinpath("seed-rig.toml").read_text()
    rub = resources.files("rotorred.scenes.builtin").joinpath("paper-rub.toml").read_text()
    for prefix, base, table in (("r", rig, R), ("s", rub, S)):
        for name, (old, new) in table.items():
            assert old in base, (name, old)
            (d / f"{prefix}_{name}.toml").write_text(base.replace(old, new, 1))
    (d / "afile").write_text("not a folder")
    (d / "binary.toml").write_bytes(b"\x89PNG\r\n\x1a\n")
    (d / "latin1.toml").write_bytes('name = "r\u00e9sum\u00e9"\n[rotor]\npreset = "seed-rig"\n'.encode("latin-1"))
    (d / "twice.toml").write_text('name = "a"\nname = "b"\n[rotor]\npreset = "seed-rig"\n')
    (d / "ro").mkdir()
    os.chmod(d / "ro", 0o555)
    return d


def _files(root: Path) -> set:
    return {(str(p), p.stat().st_mtime_ns) for p in root.rglob("*")}


@pytest.mark.parametrize("argv, tokens", CASES, ids=[f"{i:02d}-{c[0][0]}-{c[1][0]}" for i, c in enumerate(CASES)])
def test_bad_input_is_refused_cleanly(argv, tokens, inputs, tmp_path, monkeypatch, capsys):
    ro = str(inputs / "ro")
    if os.geteuid() == 0:  # root writes anywhere: make the folder look read-only to the check
        real = os.access
        monkeypatch.setattr(os, "access", lambda p, mode, *a, **k: False if str(p) == ro else real(p, mode, *a, **k))
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)  # a default output folder would land here
    argv = [a.format(d=inputs, ro=ro) for a in argv]
    before = _files(inputs) | _files(work)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    assert err.startswith(f"rotorred {argv[0]}: error: "), err
    for token in tokens:
        assert token in err, (token, err)
    assert ALLOWED.search(err), err
    assert _files(inputs) | _files(work) == before, "files written"


def test_there_are_at_least_60_kinds():
    assert len(CASES) >= 60


def test_the_readme_states_the_number_of_bad_inputs():
    """The README's sentence on bad input gives the number of :data:`CASES`, each a distinct case."""
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    assert len({(tuple(argv), tuple(tokens)) for argv, tokens in CASES}) == len(CASES)
    assert re.search(rf"`tests/test_cli_bad_input.py` gives the commands {len(CASES)} bad\s+inputs", text)
