"""The linear results show themselves (issue 35, item 4): a short repr with the headline numbers, plot() returning
a Figure, to_xarray() with units that round-trips through NetCDF and holds the result's own numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rotorred as rr

from rotorred.checks import InputError
from rotorred.linear.campbell import WHIRL_LABELS, campbell
from rotorred.linear.harmonic import frequency_response, steady_state, unbalance_response
from rotorred.model.assembly import assemble
from rotorred.model.loads import Unbalance
from rotorred.model.operating import Operating
from rotorred.model.rotor_file import load_rotor
from rotorred.transient.energy import energy_balance
from rotorred.transient.newmark import Loads, Recording, StepControl, simulate
from results_checks import assert_plots, assert_short_repr, assert_shows_itself

OUTPUTS = [(13, "x"), (14, "y")]


# --- the results, from the seed rig (80 DOFs) on short grids ---------------------------------------------------
@pytest.fixture(scope="module")
def rig():
    rotor = load_rotor("seed-rig")
    unbalances = [Unbalance(11, 1e-5), Unbalance(16, 1e-5, math.pi / 3)]
    return rotor, assemble(rotor), unbalances


@pytest.fixture(scope="module")
def diagram(rig):
    return campbell(rig[0], Operating.line(np.linspace(0.0, 1200.0, 9)))


@pytest.fixture(scope="module")
def response(rig):
    rotor, model, unbalances = rig
    ratio = rotor.speeds["outer"] / rotor.speeds["inner"]
    return unbalance_response(model, Operating.line(np.linspace(0.0, 900.0, 31), ratios={"outer": ratio}),
                              unbalances, OUTPUTS)


@pytest.fixture(scope="module")
def frf(rig):
    rotor, model, _ = rig
    return frequency_response(model, Operating.point(rotor.speeds), [(18, "x")], OUTPUTS,
                              2 * np.pi * np.linspace(0.0, 300.0, 41))


@pytest.fixture(scope="module")
def state(rig):
    rotor, model, unbalances = rig
    return steady_state(model, Operating.point(rotor.speeds), unbalances)


@pytest.fixture(scope="module")
def balance(rig):
    rotor, model, unbalances = rig
    nominal, loads = Operating.point(rotor.speeds), Loads(unbalances)
    run = simulate(model, nominal, 0.01, 1e-4, loads=loads, recording=Recording(states=True),
                   control=StepControl(progress=False))
    return energy_balance(model, run, nominal, loads)


# --- the three checks on each type -----------------------------------------------------------------------------
def test_campbell_result_shows_itself(diagram, tmp_path):
    assert_shows_itself(diagram, tmp_path, of=rr.CampbellResult, operating_speed=440.0)
    text = repr(diagram)
    first = diagram.critical_speeds[0]
    assert f"{first.speed_rpm:.6g} rpm: {first.line}, mode {first.mode + 1}" in text
    assert f"{len(diagram.critical_speeds)} critical speeds" in text


def test_a_whirl_table_and_a_diagram_without_critical_speeds_show_themselves(rig, tmp_path):
    """One speed (the whirl table of `rotorred campbell --speeds 3000`): its points, the lines from rest; a sweep
    below every crossing: no critical speed, an empty `critical` dimension in the dataset."""
    table = campbell(rig[0], Operating.line([300.0]))
    assert_shows_itself(table, tmp_path, of=rr.CampbellResult)
    assert "at 2864.79 rpm of the inner spool" in repr(table)
    below = campbell(rig[0], Operating.line([0.0, 20.0, 40.0]))
    assert below.critical_speeds == ()
    assert_shows_itself(below, tmp_path, of=rr.CampbellResult)
    assert below.to_xarray().sizes["critical"] == 0


def test_critical_speed_shows_itself_and_marks_a_diagram(diagram, tmp_path):
    critical = diagram.critical_speeds[0]
    assert_shows_itself(critical, tmp_path, of=rr.CriticalSpeed)
    fig = diagram.plot()
    ax = fig.axes[0]
    n_lines = len(ax.lines)
    assert critical.plot(ax=ax) is fig
    (mark,) = ax.lines[n_lines:]  # one marker, at (rpm, Hz) as the diagram's axes
    np.testing.assert_allclose(mark.get_xydata(), [[critical.speed_rpm, critical.frequency_hz]])


def test_unbalance_response_shows_itself_in_both_kinds(response, tmp_path):
    assert_shows_itself(response, tmp_path, of=rr.UnbalanceResponse)  # Bode, the default
    assert_plots(response, kind="polar")
    bode, polar = response.plot(), response.plot(kind="polar")
    assert len(bode.axes) == 2 * len(OUTPUTS) and len(polar.axes) == len(OUTPUTS)
    with pytest.raises(InputError) as e:
        response.plot(kind="nyquist")
    assert e.value.field == "kind"
    peak = response.peak(OUTPUTS[1])
    assert f"node 14 y: largest peak bound {1e6 * peak.max():.4g} µm" in repr(response)


def test_frequency_response_shows_itself(frf, tmp_path):
    assert_shows_itself(frf, tmp_path, of=rr.FrequencyResponse)
    assert len(frf.plot().axes) == 2


def test_steady_state_shows_itself_and_a_node_orbit(state, rig, tmp_path):
    assert_shows_itself(state, tmp_path, of=rr.SteadyState)
    model = rig[1]
    fig = state.plot(model=model, node=13, revolutions=2.0)
    orbit = fig.axes[0].lines[0].get_xydata()  # µm
    x, y = model.output_rows([(13, "x"), (13, "y")])
    start = 1e6 * np.array([x @ state.displacement(0.0), y @ state.displacement(0.0)])
    np.testing.assert_allclose(orbit[0], start, rtol=1e-12)
    # two spools: the orbit stays within the sum of the two phasors' magnitudes, and comes near it
    bound = 1e6 * sum(abs(x @ Q) for Q in state.phasors.values())
    assert 0.5 * bound < np.abs(orbit[:, 0]).max() <= bound * (1 + 1e-12)
    with pytest.raises(InputError):
        state.plot(node=13)  # an orbit needs the model


def test_energy_balance_shows_itself(balance, tmp_path):
    assert_shows_itself(balance, tmp_path, of=rr.EnergyBalance)
    assert f"relative {balance.relative_residual:.3g}" in repr(balance)


def test_reprs_are_short_for_many_outputs(rig):
    """A sweep of 16 outputs still has a short repr (the outputs beyond the first few counted)."""
    rotor, model, unbalances = rig
    outputs = [(n, d) for n in (2, 5, 8, 11, 13, 14, 16, 18) for d in "xy"]
    many = unbalance_response(model, Operating.line([0.0, 400.0], ratios={"outer": 1.2}), unbalances, outputs)
    assert "... 8 more outputs" in assert_short_repr(many)


# --- the dataset holds the result's own numbers --------------------------------------------------------------
def test_campbell_dataset_is_the_result(diagram):
    ds = diagram.to_xarray()
    np.testing.assert_array_equal(ds["speed"].values, diagram.speeds)
    np.testing.assert_array_equal(ds["frequency"].values, diagram.frequencies_hz)
    assert ds["frequency"].attrs["units"] == "Hz" and ds["speed"].attrs["units"] == "rad/s"
    np.testing.assert_array_equal(ds["log_dec"].values, diagram.log_dec)
    np.testing.assert_array_equal(np.array(WHIRL_LABELS)[ds["whirl"].values], diagram.whirl)
    np.testing.assert_array_equal(ds["tracking_mac"].values[1:], diagram.tracking_mac)
    assert np.isnan(ds["tracking_mac"].values[0]).all()
    cs = diagram.critical_speeds
    np.testing.assert_array_equal(ds["critical_speed"].values, [c.speed for c in cs])
    np.testing.assert_array_equal(ds["critical_frequency"].values, [c.frequency_hz for c in cs])
    # Hz back to rad/s: f / 2 pi and its product by 2 pi are two roundings, so 2 ulp at most (the sparse path's
    # frequencies met 1 ulp, 1.4e-16, on 2 of 16: x / 2 pi * 2 pi == x does not hold for every float)
    np.testing.assert_allclose(ds["critical_frequency"].values * 2 * np.pi, [c.frequency for c in cs], rtol=4.5e-16)
    assert list(ds["critical_spool"].values) == [c.spool for c in cs]
    assert [WHIRL_LABELS[k] for k in ds["critical_whirl"].values] == [c.whirl for c in cs]
    assert dict(zip(ds["spool"].values, ds["speed_ratio"].values)) == diagram.speed_ratios
    one = cs[-1].to_xarray()
    assert float(one["speed"]) == cs[-1].speed and float(one["frequency"]) == cs[-1].frequency_hz
    assert WHIRL_LABELS[int(one["whirl"])] == cs[-1].whirl and one.attrs["line"] == cs[-1].line


def test_unbalance_dataset_is_the_result(response):
    ds = response.to_xarray()
    np.testing.assert_array_equal(ds["speed"].values, response.speeds)
    for s in response.excited_spools:
        for o in response.outputs:
            at = dict(excited_spool=s, output=f"{o[0]}:{o[1]}")
            np.testing.assert_array_equal(ds["amplitude"].sel(at).values, response.amplitude(o, s))
            np.testing.assert_array_equal(ds["phase"].sel(at).values, response.phase(o, s))
    for o in response.outputs:
        np.testing.assert_array_equal(ds["peak_bound"].sel(output=f"{o[0]}:{o[1]}").values, response.peak(o))
    for s, w in response.spool_speeds.items():
        np.testing.assert_array_equal(ds["spool_speed"].sel(spool=s).values, w)
    assert list(ds["node"].values) == [13, 14] and list(ds["direction"].values) == ["x", "y"]


def test_frf_dataset_is_the_result(frf):
    ds = frf.to_xarray()
    np.testing.assert_allclose(ds["frequency"].values, np.linspace(0.0, 300.0, 41), rtol=1e-14)  # Hz
    h = frf.h((14, "y"), (18, "x"))
    at = dict(output="14:y", input="18:x")
    np.testing.assert_array_equal(ds["amplitude"].sel(at).values, np.abs(h))
    np.testing.assert_array_equal(ds["phase"].sel(at).values, np.angle(h))
    assert ds["amplitude"].attrs["units"] == "m/N"


def test_steady_state_dataset_is_the_result(state):
    ds = state.to_xarray()
    for s, Q in state.phasors.items():
        back = ds["amplitude"].sel(excited_spool=s).values * np.exp(1j * ds["phase"].sel(excited_spool=s).values)
        np.testing.assert_allclose(back, Q, rtol=1e-12, atol=1e-12 * np.abs(Q).max())
    assert {s: float(ds["spool_speed"].sel(spool=s)) for s in state.speeds} == state.speeds


def test_energy_dataset_is_the_result(balance):
    ds = balance.to_xarray()
    np.testing.assert_array_equal(ds["time"].values, balance.t)
    for name in ("energy", "drive", "damping", "gravity", "contact", "residual"):
        np.testing.assert_array_equal(ds[name].values, getattr(balance, name))
        assert ds[name].attrs["units"] == "J"
