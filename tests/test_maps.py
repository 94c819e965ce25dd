"""Maps of the operating envelope (issue 12): a real LocalCluster gives the serial answer bit for bit,
a killed worker and an interrupted map change nothing, a warm start is the continuation of the run,
and bad input is refused before anything runs."""

from __future__ import annotations

import math
import os
from dataclasses import replace
import signal

import numpy as np
import pytest

from rotorred.checks import InputError
from rotorred.maps.execute import connect, local_cluster, run_points
from rotorred.maps.point import StartState, continued
from rotorred.maps.run import run_map
from rotorred.maps.spec import Axis, MapSpec
from rotorred.maps.store import PointStore, to_dataset
from rotorred.scenes.run import build_model, run_scene
from rotorred.scenes.schema import load_scene

#: paper-rub shortened: 1.0 s run, 0.4 s (four common periods at 70/90 Hz) recorded
SHORT = (("solver.duration", 1.0), ("solver.record_start", 0.6), ("output.plot_window", [0.6, 0.7]),
         ("output.plots", []), ("output.formats", []), ("output.compare_normal", False))


def _spec(**kw) -> MapSpec:
    """2 outer speeds x 2 clearances, up and down: 8 points, two of them at each speed-clearance pair."""
    return MapSpec("paper-rub", (Axis("speeds.outer", (89.0, 90.0)), Axis("rub.clearance", (20e-6, 40e-6))),
                   settings=SHORT, direction="both", **kw)


def _values(ds) -> dict:
    """Every variable but the wall time, as arrays (NaN-aware comparison below)."""
    return {name: ds[name].values for name in ds.data_vars if name != "wall_time"}


def _assert_same(a, b) -> None:
    va, vb = _values(a), _values(b)
    assert va.keys() == vb.keys()
    for name in va:
        if va[name].dtype.kind == "f":
            np.testing.assert_array_equal(va[name], vb[name], err_msg=name)  # bitwise, NaN == NaN
        else:
            assert (va[name] == vb[name]).all(), name


@pytest.fixture(scope="module")
def serial_run(tmp_path_factory):
    """The map run serially: its spec, dataset and the folder of its points."""
    spec = _spec()
    folder = tmp_path_factory.mktemp("serial")
    points = run_points(spec, PointStore(folder, spec))
    return spec, to_dataset(spec, points, (13, 14, 18)), folder


@pytest.fixture(scope="module")
def serial(serial_run):
    return serial_run[:2]


@pytest.fixture(scope="module")
def cluster():
    client = local_cluster(2)
    yield client
    cluster = client.cluster
    client.close()
    cluster.close()


def test_the_map_records_every_point(serial):
    spec, ds = serial
    assert ds["status"].shape == (2, 2, 2) and (ds["status"].values == "ok").all()
    assert set(ds["kind"].values.ravel()) <= {"periodic", "period-k", "quasi-periodic", "chaotic", "unexplained",
                                               "unsettled"}
    # continuation: the first point of each chain is cold, the others warm
    start = ds["start"].values
    assert (start[0, 0, :] == "cold").all() and (start[0, 1, :] == "warm").all()  # up: 89 then 90 Hz
    assert (start[1, 1, :] == "cold").all() and (start[1, 0, :] == "warm").all()  # down: 90 then 89 Hz
    assert (ds["contact_fraction"].values > 0).all() and (ds["n_impacts"].values > 0).all()
    assert np.isfinite(ds["peak_orbit"].values).all() and (ds["max_contact_force"].values > 0).all()
    assert ds["rub_clearance"].values.tolist() == [20e-6, 40e-6] and ds["speeds_outer"].attrs["units"] == "Hz"
    assert ds["rub_clearance"].attrs == {"units": "m", "long_name": "rub.clearance", "rotorred_key": "rub.clearance"}
    assert ds["status"].dims == ("direction", "speeds_outer", "rub_clearance")


def test_a_real_cluster_gives_the_serial_dataset_bit_for_bit(serial, cluster, tmp_path):
    """Two single-threaded workers, points in chains on both: every value equal to the serial run's
    (serial BLAS is pinned to one thread like the workers; at a chaotic point a rounding difference
    grows as e^(5 t), measured 7e-12 m at 2.6 s with a two-thread serial BLAS)."""
    spec, ref = serial
    points = run_points(spec, PointStore(tmp_path, spec), cluster)
    _assert_same(to_dataset(spec, points, (13, 14, 18)), ref)


def test_a_worker_killed_mid_map_changes_nothing(serial, tmp_path):
    """After the first point, one of the two worker processes exits; Dask reruns its tasks (and any lost
    result they need) on a restarted worker. The dataset equals the undisturbed serial one."""
    spec, ref = serial
    client = local_cluster(2)
    killed = []

    def kill_one(direction, index, point):
        if not killed:
            victim = sorted(client.scheduler_info()["workers"])[0]
            pid = client.run(os.getpid, workers=[victim])[victim]
            killed.append(pid)
            os.kill(pid, signal.SIGKILL)  # a hard kill, as when a node fails

    try:
        points = run_points(spec, PointStore(tmp_path, spec), client, on_point=kill_one)
    finally:
        cluster = client.cluster
        client.close()
        cluster.close()
    assert killed
    _assert_same(to_dataset(spec, points, (13, 14, 18)), ref)


def test_an_interrupted_map_resumes_to_the_same_dataset(serial, tmp_path, monkeypatch):
    """Ctrl-C after three points: the folder holds a consistent partial dataset marked INCOMPLETE;
    the same map run again runs only the five missing points and completes the dataset."""
    import xarray as xr

    import rotorred.maps.run as map_run

    spec, ref = serial
    real = map_run.run_points

    def interrupted(spec_, store, client, on_point):
        def stop(*args):
            on_point(*args)
            if len(store.read()) == 3:
                raise KeyboardInterrupt
        return real(spec_, store, client, on_point=stop)

    monkeypatch.setattr(map_run, "run_points", interrupted)
    first = run_map(spec, tmp_path / "out", workers=0, progress=False, figures=False)
    assert first.incomplete.startswith("interrupted") and first.n_run == 3
    assert (tmp_path / "out" / "INCOMPLETE").exists()
    partial = xr.open_dataset(tmp_path / "out" / "map.nc", engine="h5netcdf")
    assert int((partial["status"].values == "ok").sum()) == 3
    partial.close()
    monkeypatch.setattr(map_run, "run_points", real)
    second = run_map(spec, tmp_path / "out", workers=0, progress=False, figures=False)
    assert second.incomplete is None and (second.n_run, second.n_resumed) == (5, 3)
    assert not (tmp_path / "out" / "INCOMPLETE").exists()
    _assert_same(second.dataset, ref)
    done = xr.open_dataset(tmp_path / "out" / "map.nc", engine="h5netcdf")
    _assert_same(done, ref)
    done.close()


def test_a_map_folder_of_the_older_names_resumes(serial_run, tmp_path):
    """A folder written before map.nc took CF names (its points and points/spec.json as now; its map.nc with the
    dimensions named by the dotted keys and a tracker reference) resumes: no point runs again, and its map.nc is
    written again with the CF names and the same values."""
    import shutil

    import xarray as xr

    spec, ref, folder = serial_run
    out = tmp_path / "old"
    shutil.copytree(folder / "points", out / "points")
    old = ref.rename({"speeds_outer": "speeds.outer", "rub_clearance": "rub.clearance"})
    old.assign_attrs(rotorred_map="issue 12").to_netcdf(out / "map.nc", engine="h5netcdf")
    result = run_map(spec, out, workers=0, progress=False, figures=False)
    assert (result.n_run, result.n_resumed, result.incomplete) == (0, 8, None)
    with xr.open_dataset(out / "map.nc", engine="h5netcdf") as ds:
        assert set(ds.dims) == {"direction", "speeds_outer", "rub_clearance", "line", "sample", "node"}
        assert "rotorred_map" not in ds.attrs and ds.attrs["Conventions"] == "CF-1.10"
        _assert_same(ds, ref)


def test_a_warm_start_is_the_continuation_of_the_run():
    """One run of 0.6 s against two joined runs, split at a step where the disk presses on the plate; the
    second starts from the first's final state (the plates' own states, contact forces and slip modes
    with it) with the unbalances at the angles they reached (phase + Omega T).

    Not carried: the forcing restarts its rotation recurrence at the new phase, whose rounding drifts
    about linearly over the run. Measured: 1.4e-12 of the peak in the 10 ms after the junction,
    4.9e-11 over the whole run; 1.5e-11 and 5e-10 allowed. With the plates restarted at rest (as
    before they were carried) the same junction is off by 1.9e-3 of the peak within 10 ms."""
    base = {**dict(SHORT), "output.plot_window": [0.0, 0.1], "solver.record_start": 0.0}
    scene = load_scene("paper-rub", {**base, "solver.duration": 0.6})
    model = build_model(scene)
    whole = run_scene(scene, model, analyse=False)
    dt, d = scene.solver.dt, (14, "y")
    pressed = np.nonzero((whole.contacts[0].normal_force > 0) & (whole.t > 0.29))[0]
    split = int(pressed[3])  # a few steps into an impact
    T1 = split * dt
    first = run_scene(load_scene("paper-rub", {**base, "solver.duration": T1}), model, analyse=False)
    assert first.final.forces[0, 0] > 0.0  # the junction is in contact
    rest = load_scene("paper-rub", {**base, "solver.duration": 0.6 - T1})
    angles = tuple(math.remainder(u.phase + rest.speeds[rest.rotor.spool_of[u.node]] * T1, 2 * math.pi)
                   for u in rest.unbalances)
    peak = np.max(np.abs(whole.outputs[d]))

    def errors(initial):
        second = run_scene(continued(rest, StartState(None, angles)), model, analyse=False, initial=initial)
        err = np.abs(np.concatenate((first.outputs[d], second.outputs[d][1:])) - whole.outputs[d]) / peak
        return float(err[split:split + int(0.01 / dt)].max()), float(err.max())

    near, overall = errors(first.final)
    z = first.final
    at_rest, _ = errors(replace(z, plate=0 * z.plate, forces=0 * z.forces, mode=np.ones_like(z.mode)))
    print(f"continuation error {near:.1e} near the junction, {overall:.1e} overall; plates at rest {at_rest:.1e}")
    assert near < 1.5e-11 and overall < 5e-10
    assert at_rest > 1e-4


def test_bad_input_is_refused_before_anything_runs(tmp_path, capsys):
    from rotorred.cli import main

    cases = [
        (["--vary", "speeds.outr=80:90:3"], "scene 'paper-rub': speeds.outr = 80.0: unknown key; allowed keys are "
                                           "inner, outer"),
        (["--vary", "speeds.outer=80:90:1"], "--vary speeds.outer = '80:90:1': must be START:STOP:N with numbers "
                                            "START, STOP and an integer N >= 2"),
        (["--vary", "speeds.outer=a,b"], "--vary speeds.outer = 'a,b': must be numbers: START:STOP:N or v1,v2,..."),
        (["--vary", "speeds.outer=-5,90"], "scene 'paper-rub': speeds.outer = -5.0: must be >= 0 (Hz)"),
        (["--vary", "rub.clearance=0:1e-5:3", "--vary", "rub.clearance=0,1e-5"],
         "--vary = ['rub.clearance', 'rub.clearance']: must name each key once"),
        (["--vary", "speeds.outer=80,90", "--direction", "sideways"],
         "--direction = 'sideways': must be one of 'up', 'down', 'both'"),
        (["--vary", "speeds.outer=80,90", "--limit", "-1"], "--limit = -1.0: must be > 0 (s)"),
        (["--vary", "speeds.outer=80,90", "--ratio", "inner=x"],
         "--ratio = 'inner=x': must be SPOOL=R with a number R > 0, e.g. inner=0.7778"),
    ]
    for options, message in cases:
        out = tmp_path / "never"
        assert main(["map", "paper-rub", *options, "--out", str(out)]) == 2, options
        err = capsys.readouterr().err
        assert err.strip() == f"rotorred map: error: {message}", (options, err)
        assert not out.exists()  # nothing written, no worker started


def test_an_unreachable_scheduler_is_a_clear_error_not_a_hang():
    import time

    t0 = time.perf_counter()
    with pytest.raises(InputError, match=r"^--scheduler = 'tcp://127\.0\.0\.1:9': must be a reachable Dask "
                                         r"scheduler address \(tcp://host:port\); none answered within 1 s"):
        connect("tcp://127.0.0.1:9", timeout=1.0)
    assert time.perf_counter() - t0 < 10.0


def test_points_of_another_map_are_refused(tmp_path):
    spec = _spec()
    store = PointStore(tmp_path, spec)
    store.write("up", (0, 0), _point_for_store())
    with pytest.raises(InputError, match=r"^--out = .*: holds the points of a different map"):
        PointStore(tmp_path, _spec(cold=True))


def _point_for_store():
    from rotorred.maps.point import PointResult

    return PointResult("diverged", reason="test", peak_orbit=np.full(3, np.nan))
