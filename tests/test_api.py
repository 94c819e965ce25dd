"""The public API: the README's Python example runs, and its names are the modules' own objects."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def _python_example() -> str:
    text = README.read_text()
    section = text[text.index("## Python\n"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_readme_example_runs(capsys):
    code = _python_example()
    assert 8 <= len(code.strip().splitlines()) <= 16  # "about 10 lines"
    namespace: dict = {}
    exec(compile(code, str(README), "exec"), namespace)
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


def test_exports_are_the_modules_objects():
    import rotorred
    from rotorred.linear.campbell import campbell
    from rotorred.scenes.run import run_scene
    from rotorred.transient.newmark import simulate

    assert rotorred.simulate is simulate and rotorred.campbell is campbell and rotorred.run_scene is run_scene
    assert "simulate" in dir(rotorred) and "load_scene" in rotorred.__all__


def test_readme_rotor_file_error_example():
    """The README's example of a rotor-file error is what the loader says."""
    import pytest

    from rotorred.model.rotor_file import RotorFileError, rotor_from_toml

    text = (Path(__file__).resolve().parents[1] / "rotorred" / "model" / "presets" / "seed-rig.toml").read_text()
    bad = text.replace("D_o = 0.065, D_i = 0.040", "D_o = 0.065, D_i = 0.070")
    assert bad != text
    example = re.search(r"e\.g\. `(rig\.toml: spool.*?)`", README.read_text(), re.S).group(1)
    with pytest.raises(RotorFileError) as info:
        rotor_from_toml(bad, source="rig.toml")
    assert str(info.value) == " ".join(example.split())
