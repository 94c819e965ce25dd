"""One-key sweeps are one-key maps (``rotorred sweep`` is ``rotorred map``): the clearance trend at the free
orbit's reach, one model for the whole sweep, the files, the command."""

from __future__ import annotations

import numpy as np
import pytest

import rotorred.maps.execute as execute
from rotorred.linear.harmonic import unbalance_response
from rotorred.model.operating import Operating
from rotorred.maps.run import run_map
from rotorred.maps.spec import Axis, MapSpec
from rotorred.scenes.reach import free_reach
from rotorred.scenes.run import build_model
from rotorred.scenes.schema import load_scene

#: paper-rub on a short window (the rub settles within 0.3 s from the settled linear state)
SHORT = {"solver.duration": 0.6, "solver.record_start": 0.4, "output.plot_window": [0.4, 0.5],
         "output.formats": [], "output.plots": []}
CLEARANCES = (60e-6, 45e-6, 10e-6)


def test_free_reach_against_the_harmonic_module():
    """max_t n.(x, y) at node 18 from an independent steady-state solution on a 10x finer time grid.

    Tolerance: sampling the periodic signal at dt misses its maximum by at most max|x''| dt^2 / 8
    <= (sum |Q| Omega^2) dt^2 / 8 (here ~2e-10 m, 5e-6 relative).
    """
    sc = load_scene("paper-rub", SHORT)
    model = build_model(sc)
    reach = free_reach(sc, model)
    ref = unbalance_response(model.model, Operating.line([sc.speeds["inner"]], "inner", ratios={"outer": 90.0 / 70.0}),
                             sc.unbalances, [(18, "y")])
    t = np.arange(0.0, 0.1, sc.solver.dt / 10)
    y = sum(np.real(ref.phasors[s][(18, "y")][0] * np.exp(1j * sc.speeds[s] * t)) for s in ref.phasors)
    bound = sum(abs(ref.phasors[s][(18, "y")][0]) * sc.speeds[s] ** 2 for s in ref.phasors) * sc.solver.dt ** 2 / 8
    assert abs(reach - np.max(y)) <= bound + 1e-15
    assert 20e-6 < reach < 80e-6  # the paper scene's clearance (13 um) lies below it


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A cold clearance sweep, serial, counting the structural models built."""
    calls = []
    original = execute.build_model

    def counting(scene):
        calls.append(scene.name)
        return original(scene)

    mp = pytest.MonkeyPatch()
    mp.setattr(execute, "build_model", counting)
    out = tmp_path_factory.mktemp("sweep") / "out"
    spec = MapSpec("paper-rub", (Axis("rub.clearance", CLEARANCES),), settings=tuple(SHORT.items()), cold=True)
    try:
        result = run_map(spec, out, workers=0, progress=False)
    finally:
        mp.undo()
    return result, calls, out


def test_no_lines_beyond_the_free_reach_and_lines_below(swept):
    """Beyond the free orbit's reach the plate is never touched and the fit finds f_L and f_H only (the
    linear response); below it the plate is struck and combination lines appear."""
    result, _, _ = swept
    ds = result.dataset.sel(direction="up")
    reach = ds["free_reach"].values
    assert np.ptp(reach) == 0.0  # the clearance does not change the free orbit
    far = np.array(CLEARANCES) > reach
    assert list(far) == [True, True, False]  # 60 and 45 um lie beyond the reach (~43 um), 10 um below
    labels = [set(str(x) for x in row if x) for row in ds["line_label"].values]
    for i in np.flatnonzero(far):
        assert ds["contact_fraction"].values[i] == 0 and ds["n_impacts"].values[i] == 0
        assert labels[i] == {"f_L", "f_H"}
    assert ds["contact_fraction"].values[2] > 0 and ds["n_impacts"].values[2] > 0
    assert len(labels[2] - {"f_L", "f_H"}) >= 30  # measured 58 (the map keeps the strongest 60 lines)


def test_one_model_for_the_whole_sweep(swept):
    _, calls, _ = swept
    assert len(calls) == 1


def test_sweep_files(swept):
    result, _, out = swept
    names = sorted(p.name for p in out.iterdir() if p.is_file() and not p.name.startswith("."))
    assert names == ["bifurcation.png", "lines.png", "map.csv", "map.nc", "map.txt", "map_lines.csv",
                     "waterfall.png"]
    header = (out / "map.csv").read_text().splitlines()[0].split(",")
    assert "free_reach (m)" in header and "contact_fraction (1)" in header and "status" in header


def test_rotorred_sweep_is_rotorred_map(tmp_path, capsys):
    """The command: its files, with the provenance (map.txt, map.nc, the base scene as scene.toml), and map.nc opens
    with xarray with CF names and units."""
    import xarray as xr
    from datetime import datetime, timezone

    from provenance_checks import assert_provenance
    from rotorred.cli import main

    args = ["sweep", "paper-rub", "--vary", "rub.clearance=60e-6,50e-6", "--cold", "--workers", "0",
            "--out", str(tmp_path)]
    for k, v in SHORT.items():
        args += ["--set", f"{k}={v!r}".replace("'", '"')]
    since = datetime.now(timezone.utc)
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "map of paper-rub: rub.clearance (2)" in out and "2 points run" in out
    assert (tmp_path / "map.nc").exists() and (tmp_path / "lines.png").exists()
    assert_provenance(tmp_path, args, "map.txt", "scene", since)
    base = load_scene(tmp_path / "scene.toml")  # paper-rub with the fixed settings, its own clearance
    assert base.solver.duration == SHORT["solver.duration"] and base.plates[0].clearance == 13e-6
    with xr.open_dataset(tmp_path / "map.nc") as ds:
        assert ds["status"].dims == ("direction", "rub_clearance")
        assert ds["rub_clearance"].values.tolist() == [60e-6, 50e-6] and ds["rub_clearance"].attrs["units"] == "m"
        assert all("." not in d for d in ds.dims) and all(v.attrs.get("units") for v in ds.variables.values())
    header = (tmp_path / "map.csv").read_text().splitlines()[0].split(",")
    assert header[:3] == ["direction", "rub.clearance (m)", "status"]


def test_no_plate_no_reach():
    assert free_reach(load_scene("paper-normal")) is None
