"""Provenance in every output folder: the version, command line, date and resolved input in the summaries and data
files, the resolved scene (or rotor) beside them, and that file passed back reproducing the data to the bit."""

from __future__ import annotations

import copy
import dataclasses
import math
import shlex
import shutil
import tomllib
from datetime import datetime, timezone
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import rotorred
from provenance_checks import assert_provenance
from rotorred.checks import InputError
from rotorred.cli import main
from rotorred.provenance import Provenance
from rotorred.scenes.resolved import scene_document, scene_toml
from rotorred.scenes.schema import builtin_scenes, load_scene, scene_from_dict, scene_from_toml
from rotorred.writers import toml_text, write_mat, write_netcdf, write_npz

ROOT = Path(__file__).resolve().parents[1]
ROSS3 = ROOT / "validation" / "reference" / "ross3"
#: paper-rub cut to 0.3 s, no figures: the short rub run of the command tests (as tests/test_cli_failures.py)
SHORT = ["--set", "solver.duration=0.3", "--set", "solver.record_start=0.1", "--set", "output.plot_window=[0.1, 0.2]",
         "--set", "output.plots=[]", "--set", 'output.formats=["npz", "mat", "csv"]']
#: NPZ entries that name the run, not its data: they differ between a run and its rerun
RUN_NAMES = ("rotorred_command", "rotorred_date")


def _now() -> datetime:
    return datetime.now(timezone.utc)


# --------------------------------------------------------------------------- the type
def test_provenance_of_a_command():
    before = _now().replace(microsecond=0)
    p = Provenance.of_command(["run", "my scene.toml", "--out", "out"], "scene", 'name = "x"\n')
    assert p.version == rotorred.__version__
    assert p.command == "rotorred run 'my scene.toml' --out out"  # shell-quoted: it can be typed again
    assert shlex.split(p.command)[1:] == ["run", "my scene.toml", "--out", "out"]
    assert before <= datetime.strptime(p.date, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=timezone.utc) <= _now()
    assert p.file_name == "scene.toml"
    assert p.attributes() == {"rotorred_version": p.version, "rotorred_command": p.command,
                              "rotorred_date": p.date, "rotorred_scene": 'name = "x"\n'}
    assert p.netcdf_attributes()["history"] == f"{p.date}: {p.command}"
    assert p.header_lines()[1] == f"command: {p.command}"
    assert tomllib.loads(p.file_text()) == {"name": "x"}
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.command = "other"  # noqa
    with pytest.raises(ValueError, match="kind = 'map': must be one of scene, rotor"):
        Provenance("1", "c", "d", "map", "")


# --------------------------------------------------------------------------- the writers
def test_npz_and_mat_carry_the_attributes(tmp_path):
    from scipy.io import loadmat

    arrays = {"t": np.linspace(0, 1, 5), "x": np.arange(5.0)}
    attributes = {"rotorred_version": "0.1.0", "rotorred_scene": 'name = "x"\n[speeds]\ninner = 70.0\n'}
    with np.load(write_npz(tmp_path / "a.npz", arrays, attributes)) as npz:
        assert sorted(npz.files) == ["rotorred_scene", "rotorred_version", "t", "x"]
        assert str(npz["rotorred_scene"]) == attributes["rotorred_scene"]
        np.testing.assert_array_equal(npz["x"], arrays["x"])
    mat = loadmat(write_mat(tmp_path / "a.mat", arrays, attributes))
    assert str(mat["rotorred_scene"][0]) == attributes["rotorred_scene"]
    with pytest.raises(ValueError, match=r"attribute names \['x'\] are also array keys"):
        write_npz(tmp_path / "b.npz", arrays, {"x": "clash"})
    with pytest.raises(TypeError, match="attribute 'n' = 3: must be a str"):
        write_mat(tmp_path / "b.mat", arrays, {"n": 3})
    assert not (tmp_path / "b.npz").exists() and not (tmp_path / "b.mat").exists()


def test_netcdf_follows_cf_and_refuses_a_dataset_that_does_not(tmp_path):
    import xarray as xr

    good = xr.Dataset({"peak": ("point", [1.0, 2.0], {"units": "m"})},
                      coords={"rub_clearance": ("point", [1e-5, 2e-5], {"units": "m"})})
    write_netcdf(tmp_path / "a.nc", good, {"rotorred_version": "0.1.0"})
    with xr.open_dataset(tmp_path / "a.nc", engine="h5netcdf") as ds:
        assert ds.attrs["Conventions"] == "CF-1.10" and ds.attrs["rotorred_version"] == "0.1.0"
    no_units = good.assign(count=("point", [1, 2]))
    with pytest.raises(ValueError, match=r"variables \['count'\] have no units"):
        write_netcdf(tmp_path / "b.nc", no_units)
    dotted = good.rename({"rub_clearance": "rub.clearance"})
    with pytest.raises(ValueError, match="name 'rub.clearance' must be letters, digits and underscores"):
        write_netcdf(tmp_path / "b.nc", dotted)
    assert not (tmp_path / "b.nc").exists()


def test_toml_text_reads_back_the_same_document():
    """Tables in tables as [a.b] blocks, arrays of tables in them as [[a.b]] blocks, floats to the bit."""
    doc = {"name": "x", "rotor": {"alpha": 0.1 + 0.2, "spool": [{"name": "inner", "elements": [{"L": 1 / 3}]}],
                                  "damping": {"beta": 2e-5}, "defaults": {"unbalance": [{"node": 1, "m_e": 1e-5}]},
                                  "empty": {}},
           "unbalance": [{"node": 11, "m_e": math.pi}]}
    text = toml_text(doc)
    assert tomllib.loads(text) == doc
    assert "[[rotor.spool]]" in text and "[rotor.damping]" in text and "[[rotor.defaults.unbalance]]" in text


# --------------------------------------------------------------------------- the resolved scene
def _same(a, b, path="scene") -> None:
    """Equal to the bit, field by field (Scene's own == cannot compare its arrays)."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        assert type(a) is type(b), path
        for f in dataclasses.fields(a):
            if f.compare:
                _same(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            _same(a[k], b[k], f"{path}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]")
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and np.array_equal(a, b), path
    else:
        assert type(a) is type(b) and a == b, (path, a, b)


def _assert_reproduces(scene) -> str:
    """The resolved scene read back is ``scene`` (but for where it came from), and resolves to the same text."""
    text = scene_toml(scene)
    back = scene_from_toml(text, source="elsewhere/scene.toml", base=Path("/nonexistent"))
    names = {"source": "", "rotor_source": ""}
    _same(dataclasses.replace(scene, **names), dataclasses.replace(back, **names))
    assert scene_toml(back) == text
    return text


@pytest.mark.parametrize("name", builtin_scenes())
def test_the_resolved_scene_reproduces_every_builtin_scene(name):
    text = _assert_reproduces(load_scene(name))
    doc = tomllib.loads(text)
    assert "preset" not in doc["rotor"] and doc["rotor"]["spool"]  # the rotor inline, not a preset's name
    assert doc["solver"]["start"] and "gravity" in doc["solver"]  # defaults written out


def _paper_rub() -> dict:
    return tomllib.loads(resources.files("rotorred.scenes.builtin").joinpath("paper-rub.toml").read_text())


def _variant(**changes) -> dict:
    """paper-rub's tables with ``section.key`` changes (None deletes the key)."""
    data = copy.deepcopy(_paper_rub())
    for path, value in changes.items():
        section, _, key = path.partition("__")
        target = data[section][0] if isinstance(data[section], list) else data[section]
        if value is None:
            target.pop(key)
        else:
            target[key] = value
    return data


PLATE_KEYS = {f"rub__plate_{k}": None for k in ("a", "b", "h", "E", "nu")}
VARIANTS = {
    "defaults: no [speeds], no plate numbers, default table": dict(
        speeds__inner=None, speeds__outer=None, output__table=None, output__f_max_hz=None, output__plot_window=None,
        rub__K_nr=None, rub__theta_deg=None, solver__modes=None, unbalance__phase_deg=None, **PLATE_KEYS),
    "clamped-free plate": dict(rub__bending="clamped-free", rub__a0=5e6, rub__b0=0.0, **PLATE_KEYS),
    "rigid plate, plate angle": dict(rub__bending="rigid", rub__theta_deg=33.3, **PLATE_KEYS),
    "harmonic balance": dict(solver__method="harmonic-balance", solver__harmonics=20, solver__samples=128),
    "tolerance, cutoff": dict(solver__modes=None, solver__cutoff_hz=800.0, solver__tolerance=1e-3),
    "hht, gravity, rest": dict(solver__method="hht", solver__alpha=-0.05, solver__gravity=9.81, solver__start="rest"),
}


@pytest.mark.parametrize("label", VARIANTS)
def test_the_resolved_scene_reproduces_scenes_with_and_without_their_defaults(label):
    _assert_reproduces(scene_from_dict(_variant(**VARIANTS[label])))


def test_the_resolved_scene_holds_the_overrides_and_the_speeds_that_defaulted():
    sc = load_scene("paper-rub", {"rub.clearance": 2e-5, "speeds.outer": 91.37})
    doc = scene_document(sc)
    assert doc["rub"][0]["clearance"] == 2e-5 and doc["speeds"]["outer"] == 91.37
    nominal = scene_document(scene_from_dict(_variant(speeds__inner=None, speeds__outer=None)))
    assert nominal["speeds"] == {"inner": 70.0, "outer": 90.0}  # the seed rig's 4200 and 5400 rpm, to the bit


def test_a_run_up_table_and_a_rotor_file_beside_the_scene_are_resolved(tmp_path):
    """A scene naming a rotor file by a relative path: its scene.toml holds the rotor itself, and reads back from
    another folder. A run-up given as a table keeps its table."""
    (tmp_path / "rig").mkdir()
    shutil.copy(ROSS3 / "compressor_example.toml", tmp_path / "rig" / "compressor.toml")  # a ROSS file, converted
    (tmp_path / "rig" / "scene.toml").write_text(
        'name = "ross"\n[rotor]\nfile = "compressor.toml"\n[speeds]\n'
        + "".join(f"{s} = 50.0\n" for s in _spools(tmp_path / "rig" / "compressor.toml"))
        + '[[unbalance]]\nnode = 5\nm_e = 1e-4\n[runup]\ntable = [[0.0, 0.0], [1.0, 40.0]]\n'
          '[solver]\nmodel = "full"\n[output]\nnodes = [5]\n')
    sc = load_scene(tmp_path / "rig" / "scene.toml")
    text = _assert_reproduces(sc)
    doc = tomllib.loads(text)
    assert "file" not in doc["rotor"] and doc["runup"]["table"] == [[0.0, 0.0], [1.0, 40.0]]


def _spools(path: Path) -> list[str]:
    from rotorred.model.rotor_file import load_rotor

    return [s.name for s in load_rotor(path).spools]


def test_an_inline_rotor_is_checked_like_a_rotor_file():
    data = _paper_rub()
    data["rotor"] = {"preset": "seed-rig", "spool": []}
    with pytest.raises(InputError, match=r"rotor = .*: must hold exactly one of preset .* or file .*, or the rotor "
                                         r"itself"):
        scene_from_dict(data)
    inline = tomllib.loads(scene_toml(load_scene("paper-rub")))
    inline["rotor"]["spool"][0]["elements"][0]["D_o"] = -0.02
    with pytest.raises(InputError, match=r"rotor\.spool\[0\]\.elements\[0\]\.D_o = -0.02: must be"):
        scene_from_dict(inline)


# --------------------------------------------------------------------------- the commands
def _data(path: Path) -> dict:
    with np.load(path) as npz:
        return {k: npz[k] for k in npz.files}


def _assert_same_data(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for k in a:
        if k not in RUN_NAMES:
            assert a[k].dtype == b[k].dtype and np.array_equal(a[k], b[k]), k  # to the bit (NaN-free records)


def test_run_with_overrides_writes_its_scene_and_reruns_to_the_bit(tmp_path):
    """paper-rub with --set overrides and --no-normal: scene.toml holds the overridden values (and no normal
    comparison); `rotorred run out/scene.toml` writes the same NPZ arrays, to the bit."""
    since = _now()
    first = ["run", "paper-rub", "--out", str(tmp_path / "a"), *SHORT, "--set", "rub.clearance=20e-6", "--no-normal"]
    assert main(first) == 0
    resolved = assert_provenance(tmp_path / "a", first, "summary.txt", "scene", since)
    doc = tomllib.loads(resolved)
    assert doc["rub"][0]["clearance"] == 2e-5 and doc["solver"]["duration"] == 0.3
    assert doc["output"]["compare_normal"] is False
    again = ["run", str(tmp_path / "a" / "scene.toml"), "--out", str(tmp_path / "b")]
    assert main(again) == 0
    assert_provenance(tmp_path / "b", again, "summary.txt", "scene", since)
    a, b = _data(tmp_path / "a" / "result.npz"), _data(tmp_path / "b" / "result.npz")
    _assert_same_data(a, b)
    assert "rub_14_y" in a and not any(k.startswith("normal_") for k in a)
    assert str(a["rotorred_scene"]) == str(b["rotorred_scene"])  # the resolved scene resolves to itself
    assert (tmp_path / "a" / "timeseries.csv").read_text() == (tmp_path / "b" / "timeseries.csv").read_text()


def test_a_scene_naming_a_rotor_file_reruns_from_another_folder(tmp_path, monkeypatch):
    """The scene names its rotor file by a relative path; its scene.toml holds the rotor, so it reruns from the
    output folder (where that path names nothing), to the bit."""
    rig = tmp_path / "rig"
    rig.mkdir()
    rig.joinpath("rig.toml").write_text(resources.files("rotorred.model.presets").joinpath("seed-rig.toml")
                                        .read_text())
    rig.joinpath("linear.toml").write_text(
        'name = "linear"\n[rotor]\nfile = "rig.toml"\nrayleigh_alpha = 40.0\n[[unbalance]]\nnode = 18\nm_e = 1e-3\n'
        '[solver]\nmodel = "full"\nduration = 0.5\nrecord_start = 0.3\n[output]\nnodes = [14]\nplots = []\n'
        'formats = ["npz"]\n')
    since = _now()
    first = ["run", str(rig / "linear.toml"), "--out", str(tmp_path / "a")]
    assert main(first) == 0
    resolved = assert_provenance(tmp_path / "a", first, "summary.txt", "scene", since)
    assert "file" not in tomllib.loads(resolved)["rotor"]
    shutil.rmtree(rig)  # the scene's rotor file is gone: the resolved scene needs none
    monkeypatch.chdir(tmp_path)
    again = ["run", "a/scene.toml", "--out", "b"]
    assert main(again) == 0
    _assert_same_data(_data(tmp_path / "a" / "result.npz"), _data(tmp_path / "b" / "result.npz"))


def test_a_run_up_writes_its_scene_and_reruns_to_the_bit(tmp_path):
    since = _now()
    first = ["run", "runup", "--out", str(tmp_path / "a"), "--set", "runup.to=0.3", "--set", "runup.duration=0.5",
             "--set", "runup.orbits_hz=[]", "--set", "output.plots=[]", "--set", 'output.formats=["npz", "mat"]']
    assert main(first) == 0
    assert_provenance(tmp_path / "a", first, "summary.txt", "scene", since)
    again = ["run", str(tmp_path / "a" / "scene.toml"), "--out", str(tmp_path / "b")]
    assert main(again) == 0
    _assert_same_data(_data(tmp_path / "a" / "result.npz"), _data(tmp_path / "b" / "result.npz"))


def test_campbell_writes_its_rotor_which_gives_the_same_diagram(tmp_path):
    since = _now()
    first = ["campbell", str(ROSS3 / "compressor_example.toml"), "--speeds", "0:6000:4", "--modes", "4",
             "--out", str(tmp_path / "a")]
    assert main(first) == 0
    resolved = assert_provenance(tmp_path / "a", first, "campbell.txt", "rotor", since)
    assert "ross_version" not in resolved  # the ROSS file as rotorred reads it: a rotorred rotor file
    assert "critical speeds of" in (tmp_path / "a" / "campbell.txt").read_text()
    again = ["campbell", str(tmp_path / "a" / "rotor.toml"), "--speeds", "0:6000:4", "--modes", "4",
             "--out", str(tmp_path / "b")]
    assert main(again) == 0
    assert (tmp_path / "a" / "campbell.csv").read_text() == (tmp_path / "b" / "campbell.csv").read_text()


@pytest.mark.parametrize("source, kind", [("seed-rig", "rotor"), ("paper-normal", "scene")])
def test_harmonic_writes_its_rotor_or_scene_which_gives_the_same_response(tmp_path, source, kind):
    since = _now()
    first = ["harmonic", source, "--speeds", "0:6300:11", "--out", str(tmp_path / "a")]
    assert main(first) == 0
    assert_provenance(tmp_path / "a", first, "harmonic.txt", kind, since)
    assert "max peak bound" in (tmp_path / "a" / "harmonic.txt").read_text()
    again = ["harmonic", str(tmp_path / "a" / f"{kind}.toml"), "--speeds", "0:6300:11", "--out", str(tmp_path / "b")]
    assert main(again) == 0
    assert (tmp_path / "a" / "response.csv").read_text() == (tmp_path / "b" / "response.csv").read_text()
