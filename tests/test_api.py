"""The public API: the Python examples of the site's pages run (docs/python.md, docs/analyses.md), the rotor-file error
example of docs/rotor-files.md is what the loader says, and the exported names are the modules' own objects."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

DOCS = Path(__file__).resolve().parents[1] / "docs"
#: the page of the Python examples (the README's "Python" section before the site)
PYTHON = DOCS / "python.md"


def _python_example(which: int = 0) -> str:
    return re.findall(r"```python\n(.*?)```", PYTHON.read_text(encoding="utf-8"), re.S)[which]


def test_readme_example_runs(capsys):
    code = _python_example()
    assert 8 <= len(code.strip().splitlines()) <= 16  # "about 10 lines"
    namespace: dict = {}
    exec(compile(code, str(PYTHON), "exec"), namespace)
    out = capsys.readouterr().out.splitlines()
    # critical speeds, then five labelled lines of the rub response at node 18 y
    assert out[0].startswith("[") and "rpm" in out[0]
    lines = out[1:]
    assert len(lines) == 5
    labels = [ln.split()[2] for ln in lines]
    # f_H (the outer spool's unbalance) is the strongest line at node 14 y, and the rub adds combinations
    assert labels[0] == "f_H" and "unknown" not in labels
    assert any(lab not in ("f_L", "f_H") for lab in labels)
    res = namespace["res"]
    assert res.success and res.contacts[0].fraction("open") < 1.0  # the plate is touched
    assert np.all(np.isfinite(res.outputs[(14, "y")]))


def test_readme_results_example_runs(capsys, tmp_path, monkeypatch):
    """The second block of docs/python.md, after the first: a summary, a figure and a CF NetCDF file from a result."""
    from rotorred.writers import read_netcdf

    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(_python_example(0), str(PYTHON), "exec"), namespace)
    capsys.readouterr()
    exec(compile(_python_example(1), str(PYTHON), "exec"), namespace)
    out = capsys.readouterr().out
    assert out.startswith("CampbellResult:") and "critical speed" in out and "TransientResult:" in out
    assert len(out.splitlines()) <= 2 * 15 and "array(" not in out
    assert (tmp_path / "campbell.png").stat().st_size > 10_000
    ds = read_netcdf(tmp_path / "campbell.nc")
    assert ds["frequency"].attrs["units"] == "Hz" and ds["speed"].attrs["units"] == "rad/s"
    np.testing.assert_array_equal(ds["frequency"].values, namespace["cd"].frequencies_hz)


def test_exports_are_the_modules_objects():
    import rotorred
    from rotorred.linear.campbell import campbell
    from rotorred.scenes.run import run_scene
    from rotorred.transient.newmark import simulate

    assert rotorred.simulate is simulate and rotorred.campbell is campbell and rotorred.run_scene is run_scene
    assert "simulate" in dir(rotorred) and "load_scene" in rotorred.__all__


def test_readme_rotor_file_error_example():
    """docs/rotor-files.md's example of a rotor-file error is what the loader says."""
    import pytest

    from rotorred.model.rotor_file import RotorFileError, rotor_from_toml

    text = (Path(__file__).resolve().parents[1] / "rotorred" / "model" / "presets" / "seed-rig.toml").read_text()
    bad = text.replace("D_o = 0.065, D_i = 0.040", "D_o = 0.065, D_i = 0.070")
    assert bad != text
    example = re.search(r"e\.g\. `(rig\.toml: spool.*?)`", (DOCS / "rotor-files.md").read_text(encoding="utf-8"),
                        re.S).group(1)
    with pytest.raises(RotorFileError) as info:
        rotor_from_toml(bad, source="rig.toml")
    assert str(info.value) == " ".join(example.split())


def test_readme_runup_example_runs(capsys):
    """The run-up block of docs/analyses.md: the 1x outer track at the rub disk peaks after the outer line's critical
    speed (Campbell: inner 42.9 Hz, outer 55.2 Hz), as a passage through resonance does."""
    page = DOCS / "analyses.md"
    text = page.read_text(encoding="utf-8")
    section = text[text.index("## Run-ups and coast-downs"):]
    section = section[:section.index("\n## ", 1)]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    namespace: dict = {}
    exec(compile(code, str(page), "exec"), namespace)
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1 and out[0].startswith("1x outer peak")
    track = namespace["track"]
    f_peak = track.speed[track.amplitude.argmax()] / (2 * np.pi)
    assert 55.2 < f_peak < 60.0
