"""The transient, signal and scene results show themselves (rotorred.results.Result): a short repr, plot() returning
the Figure the command writes, and to_xarray() with units that round-trips through NetCDF and holds the result's own
arrays (checked against the result and against the NPZ writer's arrays: two paths)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rotorred as rr
from matplotlib.figure import Figure

from results_checks import assert_shows_itself
from rotorred.scenes.schema import load_scene


@pytest.fixture(scope="module")
def scene_result():
    """paper-rub on a short window (0.45 s from the settled state, recorded from 0.25 s), with the normal run."""
    from rotorred.scenes.run import run_scene

    sc = load_scene("paper-rub", {"solver.duration": 0.45, "solver.record_start": 0.25,
                                  "output.plot_window": [0.25, 0.35]})
    return run_scene(sc)


@pytest.fixture(scope="module")
def runup_result():
    """runup-rub shortened: from rest to 0.6 x the operating point in 1 s, an orbit snapshot at 20 Hz."""
    from rotorred.scenes.runup import run_runup

    return run_runup(load_scene("runup-rub", {"runup.to": 0.6, "runup.duration": 1.0, "runup.orbits_hz": [20.0]}),
                     progress=False)


@pytest.fixture(scope="module")
def transient_result(scene_result):
    """0.1 s of paper-rub's model with its plate, from the settled state, recording x, y and a rotation."""
    from rotorred.scenes.run import build_model, settled_state
    from rotorred import Initial, Loads, Operating, Recording, StepControl, simulate

    sc = scene_result.scene
    model = build_model(sc).model
    q0, v0 = settled_state(sc, model)
    return simulate(model, Operating.point(sc.speeds), 0.1, sc.solver.dt, loads=Loads(sc.unbalances),
                    contacts=sc.plates, recording=Recording([(14, "x"), (14, "y"), (18, "y"), (14, "theta_x")]),
                    start=Initial(q0, v0), control=StepControl(progress=False))


# --------------------------------------------------------------------------- transient
def test_transient_result_shows_itself(transient_result, tmp_path):
    res = transient_result
    assert_shows_itself(res, tmp_path, of=rr.TransientResult)
    text = repr(res)
    assert "newmark" in text and "node 14 theta_x: peak" in text and "plate 0 at node 18" in text


def test_transient_dataset_holds_the_record(transient_result):
    res = transient_result
    ds = res.to_xarray()
    np.testing.assert_array_equal(ds.time.values, res.t)
    for (node, d), y in res.outputs.items():
        if d.startswith("theta"):
            np.testing.assert_array_equal(ds.rotation.sel(rotation_output=f"{node}:{d}").values, y)
        else:
            np.testing.assert_array_equal(ds.displacement.sel(output=f"{node}:{d}").values, y)
    assert (ds.displacement.attrs["units"], ds.rotation.attrs["units"]) == ("m", "rad")
    ch = res.contacts[0]
    np.testing.assert_array_equal(ds.normal_force.isel(plate=0).values, ch.normal_force)
    np.testing.assert_array_equal(ds.contact_state.isel(plate=0).values, ch.state)
    assert int(ds.plate_node[0]) == 18 and ds.plate_clearance.values[0] == ch.plate.clearance
    assert ch.n_impacts() > 0  # the record touches: the contact panel is not empty


def test_transient_plot_draws_the_outputs_and_the_contact_forces(transient_result):
    res = transient_result
    fig = res.plot()
    displacements, rotations, forces = fig.axes
    assert [ln.get_label() for ln in displacements.lines] == ["node 14 X", "node 14 Y", "node 18 Y"]
    np.testing.assert_array_equal(displacements.lines[1].get_ydata(), 1e6 * res.outputs[(14, "y")])
    assert rotations.get_ylabel() == "Rotation (µrad)" and forces.get_ylabel() == "Force (N)"
    np.testing.assert_array_equal(forces.lines[0].get_ydata(), res.contacts[0].normal_force)
    ax = Figure().subplots()
    assert res.plot(ax=ax, t_window=(0.02, 0.05)) is ax.figure and len(ax.lines) == 3  # the displacements only
    assert ax.get_xlim() == pytest.approx((0.02, 0.05), abs=res.dt)


# --------------------------------------------------------------------------- signals
def test_spectrum_shows_itself(tmp_path):
    from rotorred.signals.spectra import settled_spectrum

    dt = 1e-4
    t = np.arange(20_000) * dt
    x = 3e-6 * np.cos(2 * np.pi * 90.0 * t) + 1e-6 * np.cos(2 * np.pi * 70.0 * t)
    spec = settled_spectrum(x, dt, 70.0, 90.0)
    assert_shows_itself(spec, tmp_path, of=rr.Spectrum)
    assert "largest amplitude 3e-06" in repr(spec).replace("3.00000", "3")  # the 90 Hz tone, on its bin
    ds = spec.to_xarray()
    np.testing.assert_array_equal(ds.amplitude.values, spec.amplitudes)
    np.testing.assert_array_equal(ds.frequency.values, spec.frequencies)
    assert ds.amplitude.attrs["units"] == "m" and spec.to_xarray("rad").amplitude.attrs["units"] == "rad"
    line = spec.plot(f_max=200.0).axes[0].lines[0]
    np.testing.assert_array_equal(line.get_ydata(), 1e6 * spec.amplitudes[spec.frequencies <= 200.0])


def _synthetic_track():
    """Order 1 of a spool run up at 20 rad/s^2 from 40 rad/s: x = 2 µm cos(phi + 0.3)."""
    from rotorred.signals.orders import angle_blocks, order_tracks

    t = np.linspace(0.0, 4.0, 40_001)
    phi = 40.0 * t + 10.0 * t ** 2
    blocks = angle_blocks(t, 2e-6 * np.cos(phi + 0.3), phi, revs_per_block=8)
    return order_tracks(blocks, "inner", [1.0])[0][0]


def test_order_track_shows_itself(tmp_path):
    track = _synthetic_track()
    assert_shows_itself(track, tmp_path, of=rr.OrderTrack)
    text = repr(track)
    assert "order 1 of the inner spool" in text and "angle-domain resampling" in text
    np.testing.assert_allclose(track.amplitude, 2e-6, rtol=1e-3)  # a tone on its order reads its amplitude
    ds = track.to_xarray()
    for name, values in (("time", track.t), ("speed", track.speed), ("amplitude", track.amplitude),
                         ("phase", track.phase)):
        np.testing.assert_array_equal(ds[name].values, values)
    line = track.plot().axes[0].lines[0]
    np.testing.assert_allclose(line.get_xdata(), track.speed / (2 * math.pi), rtol=1e-15)
    np.testing.assert_array_equal(line.get_ydata(), 1e6 * track.amplitude)


# --------------------------------------------------------------------------- scenes
def test_scene_result_shows_itself(scene_result, tmp_path):
    assert_shows_itself(scene_result, tmp_path, of=rr.SceneResult)
    text = repr(scene_result)
    assert "scene paper-rub" in text and "transient response at f_L = 70 Hz, f_H = 90 Hz" in text
    assert "plate 0 at node 18" in text and "without the rub" in text


def test_scene_dataset_holds_the_result_and_the_npz_arrays(scene_result):
    """Every record, spectrum and line of the dataset is the result's own, and the NPZ writer's arrays are the
    dataset's."""
    from rotorred.scenes.outputs import data_arrays

    res = scene_result
    ds = res.to_xarray()
    npz = data_arrays(res)
    for d in res.scene.output.dofs:
        label, key = f"{d[0]}:{d[1]}", f"{d[0]}_{d[1]}"
        np.testing.assert_array_equal(ds.displacement.sel(output=label).values, res.outputs[d])
        np.testing.assert_array_equal(ds.normal_displacement.sel(output=label).values, res.normal.outputs[d])
        np.testing.assert_array_equal(ds.amplitude.sel(output=label).values, res.spectra[d].amplitudes)
        np.testing.assert_array_equal(ds.normal_amplitude.sel(output=label).values, res.normal.spectra[d].amplitudes)
        np.testing.assert_array_equal(npz[f"rub_{key}"], ds.displacement.sel(output=label).values)
        np.testing.assert_array_equal(npz[f"normal_{key}"], ds.normal_displacement.sel(output=label).values)
        np.testing.assert_array_equal(npz[f"rub_amp_{key}"], ds.amplitude.sel(output=label).values)
        mine = ds.line_output.values == label
        assert list(ds.line_label.values[mine]) == [ln.label for ln in res.lines[d].lines]
        np.testing.assert_array_equal(ds.line_amplitude.values[mine], [ln.amplitude for ln in res.lines[d].lines])
    np.testing.assert_array_equal(npz["frequency"], ds.frequency.values)
    np.testing.assert_array_equal(npz["plate0_normal_force"], ds.normal_force.isel(plate=0).values)
    np.testing.assert_array_equal(npz["t"], ds.time.values)
    assert (float(ds.f_L), float(ds.f_H)) == (res.f_L, res.f_H) == (70.0, 90.0)
    fit = res.analysis.fit
    np.testing.assert_array_equal(ds.fit_amplitude.values, [ln.amplitude for ln in fit.lines])
    np.testing.assert_array_equal(npz["poincare_x"], ds.poincare_x.values)
    assert ds.attrs["table_dof"] == "14:y" and ds.attrs["classification"] == res.analysis.classification.label


@pytest.mark.parametrize("kind", ["waveforms", "spectra", "orbits", "poincare"])
def test_scene_plot_is_the_figure_the_command_writes(scene_result, kind, tmp_path):
    """plot(kind=...) draws the file ``rotorred run`` writes (its figure job), pixel for pixel, and into given axes
    every panel's series."""
    from matplotlib.image import imread

    from rotorred.plots.axes import save_figure
    from rotorred.plots.scene import scene_figures

    res = scene_result
    jobs = {job.args[0].name: job for job in scene_figures(res, tmp_path / "command")}
    name = {"spectra": "spectra_node13.png"}.get(kind, f"{kind}.png")
    written = jobs[name]()
    drawn = save_figure(res.plot(kind=kind), tmp_path / f"plot_{name}")
    np.testing.assert_array_equal(imread(written), imread(drawn))
    ax = Figure().subplots()
    assert res.plot(ax=ax, kind=kind) is ax.figure
    series = {"waveforms": 2 * len(res.scene.output.dofs), "orbits": 2 * len(res.scene.output.nodes),
              "spectra": 2 * len(res.scene.output.directions), "poincare": 1}[kind]
    assert len([ln for ln in ax.lines if not ln.get_label().startswith("_")]) == series


def test_scene_plot_options(scene_result):
    res = scene_result
    fig = res.plot(kind="spectra", node=18, f_max=200.0)
    assert fig.texts[0].get_text().endswith("amplitude spectra at node 18 (rub at node 18 (90 deg, clearance 13 um))")
    assert fig.axes[-1].get_xlim() == (0.0, 200.0)
    with pytest.raises(ValueError, match="kind"):
        res.plot(kind="bode")
    with pytest.raises(ValueError, match="node"):
        res.plot(kind="spectra", node=5)
    with pytest.raises(ValueError, match="node"):
        res.plot(kind="orbits", node=13)


def test_runup_result_shows_itself(runup_result, tmp_path):
    assert_shows_itself(runup_result, tmp_path, of=rr.RunupResult)
    for kind in ("orders", "waterfall", "orbits"):
        assert isinstance(runup_result.plot(kind=kind), Figure)
        ax = Figure().subplots()
        assert runup_result.plot(ax=ax, kind=kind) is ax.figure and (ax.lines or ax.collections)
    text = repr(runup_result)
    assert "run-up: inner 0 -> 42 Hz, outer 0 -> 54 Hz in 1 s" in text and "rub intervals: plate 0" in text


def test_runup_dataset_holds_the_result_and_the_npz_arrays(runup_result):
    from rotorred.scenes.runup_outputs import runup_arrays

    res = runup_result
    ds = res.to_xarray()
    npz = runup_arrays(res)
    for s, w in res.speeds.items():
        np.testing.assert_array_equal(ds.speed.sel(spool=s).values, w)
        np.testing.assert_allclose(npz[f"speed_{s}"], ds.speed.sel(spool=s).values / (2 * math.pi), rtol=1e-15)
    for (node, d), y in res.outputs.items():
        np.testing.assert_array_equal(npz[f"node{node}_{d}"], ds.displacement.sel(output=f"{node}:{d}").values)
    assert len(res.tracks) == ds.sizes["track"] == 2 * 2 * 6
    for k, (track, dof) in enumerate(zip(res.tracks, res.track_dofs)):
        n = len(track.t)
        np.testing.assert_array_equal(ds.track_amplitude.values[k, :n], track.amplitude)
        np.testing.assert_array_equal(ds.track_speed.values[k, :n], track.speed)
        assert np.all(np.isnan(ds.track_amplitude.values[k, n:]))
        assert (ds.track_spool.values[k], float(ds.track_order[k]), ds.track_output.values[k]) == (
            track.spool, track.order, f"{dof[0]}:{dof[1]}")
    for j, node in enumerate(ds.orbit_node.values):
        np.testing.assert_array_equal(ds.overall_radius.values[j], res.overall[int(node)][1])
    np.testing.assert_array_equal(ds.waterfall_amplitude.values, res.waterfall.amplitudes)
    np.testing.assert_array_equal(ds.critical_speed.values, [c.speed for c in res.critical_speeds])
    assert list(ds.rub_impacts.values) == [r.impacts for r in res.rubs] and res.rubs
    np.testing.assert_array_equal(ds.rub_speed_start.sel(spool="inner").values,
                                  [r.speed_start["inner"] for r in res.rubs])
