"""Faults of the long commands (issue 41): a map resumed after its scene changed, interrupts of map, continue and
run-ups, sizes before work, and inputs a command cannot honour. Each test first reproduced its example on main
(named in its docstring) and passes now.

Fault kinds tested here: :data:`FAULT_KINDS` (the README states their number)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rotorred.cli import main

#: a short paper-rub map point: 0.4 s run, 0.2 s recorded, no figures or files of the scene
SHORT = ["--set", "solver.duration=0.4", "--set", "solver.record_start=0.2", "--set", "output.plot_window=[0.2, 0.3]",
         "--set", "output.plots=[]", "--set", "output.formats=[]", "--set", "output.compare_normal=false"]

BUILTIN = Path(__file__).resolve().parents[1] / "rotorred" / "scenes" / "builtin"
PRESETS = Path(__file__).resolve().parents[1] / "rotorred" / "model" / "presets"


# --------------------------------------------------------------------------- 1. resume by content
@pytest.fixture()
def scene_file(tmp_path) -> Path:
    """paper-rub as a file of its own, its rotor a file of its own (the seed rig)."""
    shutil.copy(PRESETS / "seed-rig.toml", tmp_path / "rotor.toml")
    text = (BUILTIN / "paper-rub.toml").read_text().replace('preset = "seed-rig"', 'file = "rotor.toml"')
    (tmp_path / "scene.toml").write_text(text)
    return tmp_path / "scene.toml"


def _map(scene: Path, out: Path, *extra: str) -> int:
    return main(["map", str(scene), "--vary", "rub.clearance=20e-6", "--workers", "0", *SHORT, *extra, "--out",
                 str(out), "-q"])


def _files(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_map_resumed_after_its_scene_changed_refuses_naming_the_change(scene_file, tmp_path, capsys):
    """Issue 41's example: a map resumed after an edit of its scene file reused the old points and exited 0 (on main
    the second and third maps below exited 0, running no point). Now an edit of the scene's content, or of its rotor
    file's, refuses (exit 2) naming the key and both values, and leaves the folder as it was; the same content from
    another path, or with only a comment changed, resumes (no point runs again)."""
    out = tmp_path / "out"
    assert _map(scene_file, out) == 0
    before, written = _files(out), (out / "points" / "up" / "0.npz").stat().st_mtime_ns
    text = scene_file.read_text()
    scene_file.write_text(text.replace("mu_d = ", "mu_d = 0.1 #", 1))
    capsys.readouterr()
    assert _map(scene_file, out) == 2
    err = capsys.readouterr().err
    assert "holds the points of a different map (the scene's content differs at rub[0].mu_d (" in err, err
    assert "0.1 now)" in err and "remove" in err and _files(out) == before

    scene_file.write_text(text)
    rotor = scene_file.parent / "rotor.toml"
    rotor.write_text(rotor.read_text().replace("E = 2.1e11", "E = 2.0e11", 1))
    assert _map(scene_file, out) == 2
    err = capsys.readouterr().err
    assert "the scene's content differs at rotor.material[0].E (210000000000.0 in the points, 200000000000.0 now)" \
        in err, err
    assert _files(out) == before

    rotor.write_text(rotor.read_text().replace("E = 2.0e11", "E = 2.1e11", 1))
    moved = tmp_path / "elsewhere"
    moved.mkdir()
    shutil.copy(rotor, moved / "rotor.toml")
    (moved / "scene.toml").write_text("# the same scene, moved, a comment added\n" + text)
    assert _map(moved / "scene.toml", out) == 0
    assert (out / "points" / "up" / "0.npz").stat().st_mtime_ns == written  # not run again


def test_a_map_resumed_with_other_options_refuses_naming_them(scene_file, tmp_path, capsys):
    """--cold, --limit or a --set that changes a point refuse a resume, each named."""
    out = tmp_path / "out"
    assert _map(scene_file, out) == 0
    capsys.readouterr()
    assert _map(scene_file, out, "--cold") == 2
    assert "the start (--cold): False in the points, True now" in capsys.readouterr().err
    assert _map(scene_file, out, "--set", "rub.K_nr=4e10") == 2
    assert "rub[0].K_nr (50000000000.0 in the points, 40000000000.0 now)" in capsys.readouterr().err
