"""Scene files: loading, validation (every error names the key), settings, documentation."""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import pytest

from rotorred.scenes import schema as scene_mod
from rotorred.scenes.schema import (SceneError, apply_settings, builtin_scenes, load_scene, parse_setting,
                            scene_from_dict)

DOCS = Path(__file__).resolve().parents[1] / "docs" / "scenes.md"

#: a small valid scene: the seed rig, two unbalances, one plate, a short window
BASE = {
    "name": "small",
    "rotor": {"preset": "seed-rig"},
    "speeds": {"inner": 70.0, "outer": 90.0},
    "unbalance": [{"node": 11, "m_e": 1e-4}, {"node": 18, "m_e": 1e-3, "phase_deg": 30.0}],
    "rub": [{"node": 18, "clearance": 20e-6, "theta_deg": 90.0}],
    "solver": {"model": "reduced", "modes": 6, "dt": 2e-5, "duration": 0.5, "record_start": 0.3},
    "output": {"nodes": [13, 14], "directions": ["x", "y"]},
}


def _with(path: str, value):
    """BASE with one key set ("section.key", "section[0].key" or "key"); value None deletes it."""
    data = copy.deepcopy(BASE)
    parts = path.split(".")
    target = data
    for p in parts[:-1]:
        m = re.fullmatch(r"(\w+)\[(\d+)\]", p)
        target = target[m.group(1)][int(m.group(2))] if m else target.setdefault(p, {})
    if value is None:
        target.pop(parts[-1])
    else:
        target[parts[-1]] = value
    return data


def test_base_scene_is_valid_and_converted_to_si():
    sc = scene_from_dict(BASE)
    assert sc.speeds["inner"] == pytest.approx(2 * math.pi * 70.0, rel=1e-15)
    assert sc.speeds["outer"] == pytest.approx(2 * math.pi * 90.0, rel=1e-15)
    assert sc.unbalances[1].phase == pytest.approx(math.radians(30.0), rel=1e-15)
    plate = sc.plates[0]
    assert plate.theta == pytest.approx(math.pi / 2, rel=1e-15)
    # the disk radius comes from the rotor's disk at node 18 (125 mm rim of the seed rig)
    assert plate.disk_radius == sc.rotor.disk_at(18).radius == pytest.approx(0.125)
    assert sc.output.dofs == ((13, "x"), (13, "y"), (14, "x"), (14, "y"))
    assert not sc.is_linear and sc.without_rub().is_linear


def test_builtin_scenes_load():
    assert {"paper-normal", "paper-rub"} <= set(builtin_scenes())
    normal, rub = load_scene("paper-normal"), load_scene("paper-rub")
    for sc in (normal, rub):
        assert sc.frequencies_hz == pytest.approx({"inner": 70.0, "outer": 90.0}, rel=1e-14)
        assert sc.solver.model == "reduced"
        assert sc.solver.record_start <= 2.44 and sc.solver.duration >= 2.58  # the paper's window
    assert normal.plates == () and [p.node for p in rub.plates] == [18]
    # both scenes differ only by the rub plate
    assert normal.unbalances == rub.unbalances and normal.rotor.rayleigh == rub.rotor.rayleigh


def test_rayleigh_override_applies_to_the_rotor():
    sc = scene_from_dict(_with("rotor.rayleigh_alpha", 7.0))
    assert sc.rotor.rayleigh == (7.0, 0.0)


def test_rotor_file_relative_to_the_scene(tmp_path):
    from importlib import resources
    text = resources.files("rotorred.model.presets").joinpath("seed-rig.toml").read_text()
    (tmp_path / "rig.toml").write_text(text)
    lines = ['name = "f"', '[rotor]', 'file = "rig.toml"', '[[unbalance]]', 'node = 11', 'm_e = 1e-4',
             '[solver]', 'duration = 0.5', 'record_start = 0.3']
    (tmp_path / "s.toml").write_text("\n".join(lines))
    sc = load_scene(tmp_path / "s.toml")
    assert sc.rotor_source == str(tmp_path / "rig.toml") and len(sc.rotor.nodes) == 20


# Each bad scene: (what is wrong, path, value, the message after the source: the key path, the value as
# written in the scene's units and what is allowed).
BAD = [
    ("unknown top-level key", "colour", "red", "colour = 'red': unknown key; allowed keys are description, name, "
     "output, rotor, rub, runup, solver, speeds, unbalance"),
    ("unknown solver key", "solver.step", 1e-5, "solver.step = 1e-05: unknown key; allowed keys are alpha, "
     "boundary_nodes, cutoff_hz, dt, duration, gravity, harmonics, method, model, modes, record_start, samples, "
     "start"),
    ("unknown rub key", "rub[0].gap", 1e-5, "rub[0].gap = 1e-05: unknown key; allowed keys are K_nr, a0, b0, "),
    ("unknown unbalance key", "unbalance[0].mass", 1.0,
     "unbalance[0].mass = 1.0: unknown key; allowed keys are m_e, node, phase_deg"),
    ("wrong type: string for a number", "solver.dt", "fast", "solver.dt = 'fast': must be a finite number > 0 (s)"),
    ("wrong type: boolean for a number", "rub[0].clearance", True,
     "rub[0].clearance = True: must be a finite number >= 0 (m)"),
    ("missing rotor table", "rotor", None, "rotor: missing; required"),
    ("both preset and file", "rotor.file", "x.toml", "rotor = {'preset': 'seed-rig', 'file': 'x.toml'}: must hold "
     "exactly one of preset (nelson-mcvaugh, ross-coaxial, seed-rig) or file (a rotor TOML path)"),
    ("unknown preset", "rotor.preset", "jet-engine",
     "rotor.preset = 'jet-engine': must be one of 'nelson-mcvaugh', 'ross-coaxial', 'seed-rig'"),
    ("missing rotor file", "rotor", {"file": "/nonexistent/rig.toml"},
     "rotor.file = '/nonexistent/rig.toml': must be an existing rotor TOML file"),
    ("negative Rayleigh damping", "rotor.rayleigh_alpha", -1.0, "rotor.rayleigh_alpha = -1.0: must be >= 0 (1/s)"),
    ("missing node", "unbalance[0].node", 99, "unbalance[0].node = 99: must be a node of the rotor (1-20)"),
    ("negative unbalance", "unbalance[0].m_e", -1e-4, "unbalance[0].m_e = -0.0001: must be >= 0 (kg m)"),
    ("missing m_e", "unbalance[0].m_e", None, "unbalance[0].m_e: missing; required"),
    ("rub at a node without disk", "rub[0].node", 5, "rub[0].node = 5: must carry a disk with a radius (rub plates "
     "face a disk: disks with a radius are at nodes [3, 11, 16, 18]), or give rub[0].disk_radius"),
    ("negative clearance", "rub[0].clearance", -10e-6, "rub[0].clearance = -1e-05: must be >= 0 (m)"),
    ("missing clearance", "rub[0].clearance", None, "rub[0].clearance: missing; required"),
    ("mu_d above mu_s", "rub[0].mu_d", 0.5, "rub[0].mu_d = 0.5: must not exceed rub[0].mu_s = 0.2"),
    ("zero plate mass", "rub[0].m_p", 0.0, "rub[0].m_p = 0.0: must be > 0 (kg)"),
    ("unknown bending model", "rub[0].bending", "curved",
     "rub[0].bending = 'curved': must be one of 'navier', 'clamped-free', 'rigid'"),
    ("key of another bending model", "rub[0].a0", 5e6, "rub[0].a0 = 5000000.0: must not be given with "
     "rub[0].bending = 'navier', whose keys are plate_E, plate_a, plate_b, plate_eta, plate_h, plate_nu, plate_xi"),
    ("Poisson ratio out of range", "rub[0].plate_nu", 0.6, "rub[0].plate_nu = 0.6: must lie in (-1, 0.5)"),
    ("angle as a string", "rub[0].theta_deg", "up", "rub[0].theta_deg = 'up': must be a finite number (deg)"),
    ("rub as a table, not an array", "rub", {"node": 18, "clearance": 1e-5},
     "rub = {'node': 18, 'clearance': 1e-05}: must be an array of tables"),
    ("dt zero", "solver.dt", 0.0, "solver.dt = 0.0: must be > 0 (s)"),
    ("dt negative", "solver.dt", -1e-5, "solver.dt = -1e-05: must be > 0 (s)"),
    ("duration shorter than the window start", "solver.duration", 0.2,
     "solver.duration = 0.2: must exceed solver.record_start = 0.3, the start of the recorded window"),
    ("duration not a whole number of steps", "solver.duration", 0.500003,
     "solver.duration = 0.500003: must be a whole number of steps of solver.dt = 2e-05; it is 25000.1 steps (s)"),
    ("unknown model", "solver.model", "modal", "solver.model = 'modal': must be one of 'reduced', 'full'"),
    ("negative mode count", "solver.modes", -1, "solver.modes = -1: must be \"auto\" or an integer >= 0"),
    ("modes and cutoff together", "solver.cutoff_hz", 500.0,
     "solver.cutoff_hz = 500.0: must not be given together with solver.modes = 6"),
    ("unknown start", "solver.start", "cold", "solver.start = 'cold': must be one of 'settled', 'rest'"),
    ("alpha without hht", "solver.alpha", -0.1,
     "solver.alpha = -0.1: must not be given unless solver.method = \"hht\""),
    ("boundary node missing", "solver.boundary_nodes", [3, 42],
     "solver.boundary_nodes[1] = 42: must be a node of the rotor (1-20)"),
    ("unknown spool", "speeds.middle", 50.0, "speeds.middle = 50.0: unknown key; allowed keys are inner, outer"),
    ("no spool turns", "speeds", {"inner": 0.0, "outer": 0.0},
     "speeds = {'inner': 0.0, 'outer': 0.0}: must give at least one spool of inner, outer a speed > 0 (Hz)"),
    ("negative speed", "speeds.inner", -70.0, "speeds.inner = -70.0: must be >= 0 (Hz)"),
    ("unknown direction", "output.directions", ["x", "z"],
     "output.directions[1] = 'z': must be one of 'x', 'y', 'theta_x', 'theta_y'"),
    ("unknown plot", "output.plots", ["bode"],
     "output.plots[0] = 'bode': must be one of 'waveforms', 'spectra', 'orbits'"),
    ("unknown format", "output.formats", ["xlsx"], "output.formats[0] = 'xlsx': must be one of 'npz', 'csv', 'mat'"),
    ("missing output node", "output.nodes", [13, 77], "output.nodes[1] = 77: must be a node of the rotor (1-20)"),
    ("output node twice", "output.nodes", [13, 13], "output.nodes = [13, 13]: must not list an entry twice"),
    ("orbits without y", "output.directions", ["x"], "output.plots = ['waveforms', 'spectra', 'orbits', 'poincare']: must not ask "
     "for \"orbits\" unless output.directions holds both \"x\" and \"y\""),
    ("plot window outside the record", "output.plot_window", [0.1, 0.2], "output.plot_window = [0.1, 0.2]: must be "
     "[start, end] inside the recorded window [0.3, 0.5] with start < end (s)"),
    ("table DOF not recorded", "output.table", "18:y",
     "output.table = '18:y': must be a recorded DOF (one of output.nodes x output.directions)"),
    ("table DOF not a DOF", "output.table", "18y", "output.table = '18y': must be NODE:DIRECTION (e.g. '13:x')"),
    ("threshold out of range", "output.line_threshold", 2.0, "output.line_threshold = 2.0: must lie in (0, 1]"),
    ("compare_normal not boolean", "output.compare_normal", "yes",
     "output.compare_normal = 'yes': must be true or false"),
    ("no load", "unbalance", [], "unbalance = []: must hold at least one entry unless solver.gravity is given: "
     "the scene has no load"),
]


@pytest.mark.parametrize("what, path, value, message", BAD, ids=[b[0] for b in BAD])
def test_bad_scene_fails_with_a_message_naming_the_key(what, path, value, message):
    data = _with(path, value)
    with pytest.raises(SceneError) as exc:
        scene_from_dict(data)
    assert str(exc.value).startswith("<string>: " + message), str(exc.value)


def test_bad_scene_fails_before_any_computation(tmp_path, monkeypatch, capsys):
    """The CLI reports a bad scene (exit status 2, the key named) without assembling anything."""
    import rotorred.model.assembly
    import rotorred.scenes.run
    from rotorred.cli import main

    def boom(*args, **kwargs):
        raise AssertionError("computation started for a bad scene")
    monkeypatch.setattr(rotorred.scenes.run, "build_model", boom)
    monkeypatch.setattr(rotorred.scenes.run, "assemble", boom)
    monkeypatch.setattr(rotorred.model.assembly, "assemble", boom)
    path = tmp_path / "bad.toml"
    path.write_text('[rotor]\npreset = "seed-rig"\n[[unbalance]]\nnode = 11\nm_e = 1e-4\n'
                    '[[rub]]\nnode = 18\nclearance = -5e-6\n')
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{path}: rub[0].clearance = -5e-06: must be >= 0 (m)" in err
    assert not (tmp_path / "out").exists()


def test_invalid_toml_is_reported(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[rotor\npreset = 1")
    with pytest.raises(SceneError, match=r"^.*broken\.toml: line 1 = '\[rotor': must be valid TOML: "):
        load_scene(path)


def test_unknown_scene_name():
    with pytest.raises(FileNotFoundError, match="neither a built-in scene"):
        load_scene("no-such-scene")


def test_parse_setting_lists_ranges_and_words():
    assert parse_setting("rub.clearance=1e-6,2e-6") == ("rub.clearance", [1e-6, 2e-6])
    key, values = parse_setting("rub.clearance=0:60e-6:4")
    assert key == "rub.clearance" and values == pytest.approx([0.0, 20e-6, 40e-6, 60e-6], rel=1e-15, abs=0)
    assert parse_setting("solver.model=full") == ("solver.model", ["full"])
    assert parse_setting("output.table=14:y") == ("output.table", ["14:y"])
    assert parse_setting("output.plot_window=[0.4, 0.5]") == ("output.plot_window", [[0.4, 0.5]])
    for bad in ("rub.clearance", "=3", "rub.clearance=0:1:x", "rub.clearance=0:1:1"):
        with pytest.raises(ValueError, match="--set"):
            parse_setting(bad)


def test_apply_settings_sets_every_plate_or_one():
    two = copy.deepcopy(BASE)
    two["rub"].append({"node": 16, "clearance": 30e-6})
    every = apply_settings(two, {"rub.clearance": 5e-6})
    assert [r["clearance"] for r in every["rub"]] == [5e-6, 5e-6]
    one = apply_settings(two, {"rub[1].clearance": 7e-6, "solver.dt": 1e-5})
    assert [r["clearance"] for r in one["rub"]] == [20e-6, 7e-6] and one["solver"]["dt"] == 1e-5
    assert [r["clearance"] for r in two["rub"]] == [20e-6, 30e-6]  # the input is not modified
    with pytest.raises(ValueError, match="has 2 \\[\\[rub\\]\\] entries"):
        apply_settings(two, {"rub[2].clearance": 1e-6})
    # an unknown key set by --set is caught by the validation
    with pytest.raises(SceneError, match=r"^<string>: solver\.speed = 3: unknown key"):
        scene_from_dict(apply_settings(BASE, {"solver.speed": 3}))


def test_load_scene_with_settings():
    sc = load_scene("paper-rub", {"rub.clearance": 30e-6, "solver.model": "full"})
    assert sc.plates[0].clearance == 30e-6 and sc.solver.model == "full"


def test_every_key_is_documented():
    """docs/scenes.md names every key the loader accepts (in backquotes)."""
    text = DOCS.read_text()
    keys = (scene_mod._TOP_KEYS | scene_mod._ROTOR_KEYS | scene_mod._UNBALANCE_KEYS | scene_mod._RUB_KEYS
            | scene_mod._SOLVER_KEYS | scene_mod._OUTPUT_KEYS)
    missing = sorted(k for k in keys if not any(f"`{form}`" in text for form in (k, f"[{k}]", f"[[{k}]]")))
    assert not missing, f"undocumented scene keys: {missing}"


def test_an_error_in_the_scene_rotor_file_names_that_file(tmp_path):
    from importlib import resources
    text = resources.files("rotorred.model.presets").joinpath("seed-rig.toml").read_text()
    (tmp_path / "rig.toml").write_text(text.replace("rho = 7850.0", "rho = -7850.0"))
    (tmp_path / "s.toml").write_text('[rotor]\nfile = "rig.toml"\n[[unbalance]]\nnode = 11\nm_e = 1e-4\n')
    with pytest.raises(SceneError) as info:
        load_scene(tmp_path / "s.toml")
    assert str(info.value) == f"{tmp_path / 'rig.toml'}: material[0].rho = -7850.0: must lie in [1e-09, 1e+06] (kg/m^3)"
    assert info.value.source == str(tmp_path / "rig.toml") and info.value.field == "material[0].rho"


def test_scene_values_are_checked_as_written_before_conversion():
    """Speeds in Hz and angles in degrees appear in the message as the user wrote them."""
    with pytest.raises(SceneError, match=r"^<string>: unbalance\[1\]\.phase_deg = 'north': must be a finite number "
                                         r"\(deg\)$"):
        scene_from_dict(_with("unbalance[1].phase_deg", "north"))
    with pytest.raises(SceneError, match=r"^<string>: speeds\.outer = nan: must be a finite number >= 0 \(Hz\)$"):
        scene_from_dict(_with("speeds.outer", float("nan")))


def test_set_errors_name_the_option():
    with pytest.raises(ValueError, match=r"^--set = 'rub\.clearance': must be KEY=VALUES"):
        parse_setting("rub.clearance")
    with pytest.raises(ValueError, match=r"^--set rub\.clearance = '0:1:1': must be START:STOP:N with numbers "
                                         r"START, STOP and an integer N >= 2$"):
        parse_setting("rub.clearance=0:1:1")
    with pytest.raises(ValueError, match=r"^--set = 'a\.b\.c': must be KEY or SECTION\.KEY"):
        apply_settings(BASE, {"a.b.c": 1})


def test_any_speed_ratio_is_accepted_with_the_default_record():
    """Outer 81 Hz, inner 70 Hz: the common period is 1 s, longer than the 0.6 s record. The scene
    loads (the line fit needs no whole period); the spectrum falls back to a window and says so."""
    import numpy as np
    from rotorred.signals.spectra import settled_spectrum
    sc = load_scene("paper-rub", {"speeds.outer": 81.0})
    assert sc.solver.duration - sc.solver.record_start == pytest.approx(0.6)
    spec = settled_spectrum(np.cos(2 * np.pi * 81.0 * np.arange(30_000) * 2e-5), 2e-5, 70.0, 81.0)
    assert spec.note.startswith("flattop window on all 30000 samples: n_available = 30000: must hold at least one "
                                "common period T = 1.0 s")
