"""Campbell diagram: closed-form rigid rotor, Nelson-McVaugh vs ROSS, two spools, MAC tracking,
critical speeds against an independent formulation, the seed rig's margins, CLI and bad input."""

from __future__ import annotations

import csv
import dataclasses
import importlib.util
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from rotorred.checks import InputError
from rotorred.model.assembly import assemble
from rotorred.linear.campbell import CampbellResult, campbell, whirl_direction
from rotorred.plots.axes import save_figure
from rotorred.model.elements import Bearing, Disk, IntershaftBearing, Material, ShaftElement
from rotorred.model.operating import Operating
from rotorred.linear.modal import eigen
from rotorred.model.rotor import Rotor, Spool
from rotorred.model.rotor_file import load_rotor
from test_operating import three_spools

VALIDATION = Path(__file__).resolve().parents[1] / "validation"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, VALIDATION / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


nelson = _load("nelson_mcvaugh")


# --- a rigid rotor with closed-form whirl ---------------------------------------------------------
# Disk (m, I_d, I_p) at the middle of a uniform shaft of length 2a, bearings k at both ends (+-a).
# The shaft moves as a rigid body when E -> inf; its mass and inertia are included in the closed form:
#   m = m_disk + rho A L,  I_d = I_d,disk + rho A L^3/12 + rho I L,  I_p = I_p,disk + 2 rho I L
# (cubic Timoshenko shape functions reproduce rigid-body motion, so the consistent mass matrix gives
# these exactly). By symmetry translation and tilt decouple:
#   cylindrical  m w^2 = 2 k,   conical  I_d w^2 -+ I_p Omega w - k_theta = 0,  k_theta = 2 k a^2.
# With I_d > m a^2 the forward conical curve starts below the cylindrical pair and crosses it.
A_HALF, K_BRG, M_DISK, ID_DISK, IP_DISK, D_SHAFT = 0.1, 1.0e6, 10.0, 0.2, 0.4, 0.05


def rigid_rotor(E: float, c: float = 0.0) -> Rotor:
    steel = Material("stiff steel", E=E, rho=7850.0, nu=0.3)
    L = 2 * A_HALF / 4
    shaft = Spool("shaft", tuple(ShaftElement(i, i + 1, L, D_SHAFT, 0.0, steel) for i in range(4)), speed=100.0)
    return Rotor((shaft,), disks=(Disk(2, M_DISK, ID_DISK, IP_DISK),),
                 bearings=(Bearing(k_xx=K_BRG, k_yy=K_BRG, c_xx=c, c_yy=c, node=0),
                           Bearing(k_xx=K_BRG, k_yy=K_BRG, c_xx=c, c_yy=c, node=4)), name="rigid")


def rigid_body_properties() -> tuple[float, float, float]:
    rho, L = 7850.0, 2 * A_HALF
    A, I = math.pi * D_SHAFT**2 / 4, math.pi * D_SHAFT**4 / 64
    return M_DISK + rho * A * L, ID_DISK + rho * A * L**3 / 12 + rho * I * L, IP_DISK + 2 * rho * I * L


def conical_roots(Omega: float) -> tuple[float, float]:
    """(backward, forward) roots of I_d w^2 +- I_p Omega w - k_theta = 0, by brentq."""
    _, I_d, I_p = rigid_body_properties()
    k_theta = 2 * K_BRG * A_HALF**2
    hi = (I_p * Omega + math.sqrt(k_theta * I_d)) / I_d * 2 + 1.0
    backward = brentq(lambda w: I_d * w * w + I_p * Omega * w - k_theta, 0.0, hi)
    forward = brentq(lambda w: I_d * w * w - I_p * Omega * w - k_theta, 0.0, hi)
    return backward, forward


SPEEDS_RIGID = np.linspace(0.0, 500.0, 51)  # rad/s; grid step 10 rad/s, no grid point at a crossing


def _rigid_errors(E: float) -> tuple[float, CampbellResult]:
    result = campbell(rigid_rotor(E), Operating.line(SPEEDS_RIGID), n_modes=4)
    m, _, _ = rigid_body_properties()
    w_cyl = math.sqrt(2 * K_BRG / m)
    expected = np.array([[*conical_roots(W), w_cyl, w_cyl] for W in SPEEDS_RIGID])
    return float(np.max(np.abs(result.frequencies - expected) / expected)), result


def test_rigid_rotor_tilt_campbell_matches_closed_form_and_tracks_through_crossing():
    # Shaft E = 100 x steel. Residual flexibility: the cylindrical mode sees the bearings (2k) in series
    # with the shaft (48 E I / L^3 at mid-span), so w drops by ~ k L^3 / (48 E I) = 2.6e-5 (relative);
    # measured: cylindrical 2.4e-5, conical up to 5.4e-5 (backward at 500 rad/s). Tolerance: 3x the ratio.
    E = 2.1e13
    flex = K_BRG * (2 * A_HALF) ** 3 / (48 * E * math.pi * D_SHAFT**4 / 64)
    err, result = _rigid_errors(E)
    assert err < 3 * flex
    # the mismatch is the shaft's residual flexibility, first order in 1/E: 10x stiffer -> ~10x smaller
    err_stiffer, _ = _rigid_errors(10 * E)
    assert err / 12 < err_stiffer < err / 8
    # columns 0, 1 are the backward and forward conical modes, 2, 3 the cylindrical pair
    assert np.all(result.whirl[:, 0] == "backward") and np.all(result.whirl[:, 1] == "forward")
    # the forward conical curve really crosses the cylindrical pair: sorting by frequency would
    # swap the columns after the crossing; MAC tracking keeps each curve continuous
    assert result.frequencies[0, 1] < result.frequencies[0, 2] and result.frequencies[-1, 1] > result.frequencies[-1, 3]
    assert result.tracking_mac.min() > 0.99


def test_rigid_rotor_critical_speeds_closed_form():
    _, result = _rigid_errors(2.1e14)
    m, I_d, I_p = rigid_body_properties()
    k_theta = 2 * K_BRG * A_HALF**2
    # 1x line meets: backward conical at I_d W^2 + I_p W^2 = k_theta; cylindrical pair at W^2 = 2k/m;
    # forward conical never (I_p > I_d: it rises faster than 1x)
    backward = brentq(lambda W: (I_d + I_p) * W * W - k_theta, 1.0, 1e4)
    cylindrical = brentq(lambda W: m * W * W - 2 * K_BRG, 1.0, 1e4)
    crit = result.critical_speeds
    assert [c.mode for c in crit] == [0, 2, 3]
    assert crit[0].whirl == "backward" and {crit[1].whirl, crit[2].whirl} == {"forward", "backward"}
    expected = [backward, cylindrical, cylindrical]
    # same residual-flexibility error as the whirl frequencies (err < 1e-5 with this shaft)
    for c, W in zip(crit, expected):
        assert abs(c.speed - W) / W < 2e-5
        # on the 1x line; the pair's eigenvalues carry ~eps w_max^2 / w ~ 1e-8 roundoff in this stiff model
        assert abs(c.frequency - c.speed) / W < 1e-7
        assert c.spool == "shaft" and c.harmonic == 1.0


def test_log_decrement_of_damped_rigid_rotor():
    # bearing damping c: cylindrical m x'' + 2c x' + 2k x = 0 (unaffected by spin);
    # conical at rest I_d th'' + 2 c a^2 th' + k_theta th = 0; log dec = 2 pi zeta / sqrt(1 - zeta^2)
    c = 150.0
    result = campbell(rigid_rotor(2.1e14, c=c), Operating.line([0.0, 200.0, 400.0]), n_modes=4)
    m, I_d, _ = rigid_body_properties()
    k_theta = 2 * K_BRG * A_HALF**2
    zeta_cyl = 2 * c / (2 * math.sqrt(2 * K_BRG * m))
    zeta_con = 2 * c * A_HALF**2 / (2 * math.sqrt(k_theta * I_d))
    delta = lambda z: 2 * math.pi * z / math.sqrt(1 - z * z)  # noqa: E731
    # residual shaft flexibility (~1e-6) and the bearing damping acting through it: 1e-5
    assert np.allclose(result.log_dec[:, 2:], delta(zeta_cyl), rtol=1e-5)
    assert np.allclose(result.log_dec[0, :2], delta(zeta_con), rtol=1e-5)
    w_d = math.sqrt(2 * K_BRG / m) * math.sqrt(1 - zeta_cyl**2)
    assert np.allclose(result.frequencies[:, 2:], w_d, rtol=1e-5)
    assert zeta_cyl > 0.01  # the check is not trivially satisfied by an undamped result


# --- whirl direction -------------------------------------------------------------------------------
def test_whirl_direction_convention():
    # x + i y = e^{+i w t}: X = 1, Y = -i (x = cos, y = sin: counter-clockwise, with the spin about +z)
    x_rows, y_rows = np.array([0, 2]), np.array([1, 3])
    forward = np.array([1, -1j, 0.5, -0.5j])
    backward = np.array([1, 1j, 0.5, 0.5j])
    planar = np.array([1, 0.3, 0.5, 0.15])
    mixed = np.array([1, -1j, 0.5, 0.5j])  # second node backward with 20 % of sum |X|^2 + |Y|^2
    mostly_backward = np.array([1, 1j, 0.07, -0.07j])  # a forward node with 0.5 % of it
    elliptic = np.array([1, -0.2j, 0.5, -0.1j])  # forward ellipses
    modes = np.column_stack([forward, backward, planar, mixed, mostly_backward, elliptic])
    assert whirl_direction(modes, x_rows, y_rows) == ["forward", "backward", "planar", "mixed", "backward",
                                                      "forward"]


def test_orthotropic_modes_at_rest_are_planar_and_elliptic_when_spinning():
    # cross-coupled (symmetric) bearings: at rest the modes are straight lines in the bearings'
    # principal directions; spinning makes them elliptic
    result = campbell(nelson.rotor("orthotropic"), Operating.line([0.0, 10000.0], unit="rpm"), n_modes=4)
    assert list(result.whirl[0]) == ["planar"] * 4
    assert set(result.whirl[1]) <= {"forward", "backward", "mixed"}
    assert "forward" in result.whirl[1] and "backward" in result.whirl[1]


# --- Nelson-McVaugh against ROSS ---------------------------------------------------------------------


@pytest.mark.parametrize("case", ["isotropic", "orthotropic"])
def test_nelson_mcvaugh_whirl_speeds_match_ross(case):
    # the reference is printed to 0.1 rpm (<= 4e-6 relative); both codes use the same Timoshenko
    # element with Cowper's kappa, so the agreement is at that rounding level: 1e-5 leaves 2.5x margin
    # (the brief asks for 0.1 %)
    rpm, ours, ref = nelson.whirl_speeds(case)
    assert len(rpm) == 4 and ours.shape == (4, 6)
    assert np.max(np.abs(ours - ref) / ref) < 1e-5


rig = _load("campbell_rig")
undamped_critical_speeds = rig.undamped_critical_speeds


def _check_critical_speeds(result, rotor, spool, harmonic):
    """Critical speeds of ``result`` on line ``harmonic`` x ``spool`` against the Hermitian formulation."""
    ours = np.sort([c.speed for c in result.critical_speeds if c.spool == spool and c.harmonic == harmonic])
    exact = undamped_critical_speeds(rotor, result.speed_ratios, spool, harmonic, result.speeds[-1])
    # every crossing found is an exact critical speed; the eigh reference (Cholesky of K, whose condition
    # number is ~1e9 for these meshes) is accurate to ~1e-9, brentq to 1e-10: 1e-8
    assert len(ours) >= 2
    assert all(np.min(np.abs(exact - W)) < 1e-8 * W for W in ours)
    # every exact critical on a tracked curve is found: tracked curves pass through (W, c W) there
    slope = harmonic * result.speed_ratios[spool]
    for W in exact:
        on_curve = [np.interp(W, result.speeds, result.frequencies[:, j]) for j in range(result.n_modes)]
        if np.min(np.abs(np.array(on_curve) - slope * W)) < 1e-3 * slope * W:
            assert np.min(np.abs(ours - W)) < 1e-8 * W


def test_critical_speeds_match_hermitian_formulation():
    rotor = nelson.rotor("isotropic")
    result = campbell(rotor, Operating.line(np.linspace(0, 40000, 41), unit="rpm"), n_modes=6, harmonics=(1, 2))
    for h in (1.0, 2.0):
        _check_critical_speeds(result, rotor, "shaft", h)


# --- two spools ------------------------------------------------------------------------------------
def two_spool_rotor(intershaft: bool = True) -> Rotor:
    steel = Material("steel", E=2.1e11, rho=7850.0, nu=0.3)
    inner = Spool("inner", tuple(ShaftElement(i, i + 1, 0.1, 0.02, 0.0, steel) for i in range(1, 7)),
                  speed=300.0)
    outer = Spool("outer", tuple(ShaftElement(i, i + 1, 0.06, 0.06, 0.04, steel) for i in range(10, 13)),
                  speed=400.0, z0=0.25)
    disks = (Disk(3, 4.0, 0.02, 0.04), Disk(6, 4.0, 0.02, 0.04), Disk(11, 3.0, 0.015, 0.03))
    bearings = (Bearing(k_xx=2e7, k_yy=2e7, node=1), Bearing(k_xx=2e7, k_yy=2e7, node=7),
                Bearing(k_xx=2e6, k_yy=2e6, node=10), Bearing(k_xx=1e6, k_yy=1e6, node=13))
    isb = (IntershaftBearing(k_xx=1e7, k_yy=1e7, c_xx=200.0, c_yy=200.0, node_a=13, node_b=5),) if intershaft else ()
    return Rotor((inner, outer), disks=disks, bearings=bearings, intershaft_bearings=isb, name="two-spool")


SPEEDS_2 = np.linspace(0.0, 2000.0, 11)


def _same_curves(curves: np.ndarray, pool: np.ndarray, rtol: float) -> bool:
    """Every column of ``curves`` (n_speeds, k) equals, at every speed, some column of ``pool``."""
    return all(np.any(np.all(np.isclose(pool, curves[:, [j]], rtol=rtol), axis=0)) for j in range(curves.shape[1]))


@pytest.mark.parametrize("ratio", [0.0, 1.3])
def test_uncoupled_spools_each_equal_the_spool_alone(ratio):
    # without the inter-shaft bearing every tracked curve is a curve of the inner spool alone at Omega
    # or of the outer spool alone at ratio x Omega (ratio 0: outer at rest, its curves flat)
    rotor = two_spool_rotor(intershaft=False)
    full = campbell(rotor, Operating.line(SPEEDS_2, ratios={"outer": ratio}), n_modes=8)
    inner = campbell(rotor.only_spool("inner"), Operating.line(SPEEDS_2), n_modes=8).frequencies
    if ratio > 0:
        outer = campbell(rotor.only_spool("outer"), Operating.line(ratio * SPEEDS_2), n_modes=8).frequencies
    else:
        outer = np.tile(campbell(rotor.only_spool("outer"), Operating.line(SPEEDS_2[:2]), n_modes=8).frequencies[0],
                        (len(SPEEDS_2), 1))
    # the same matrices solved as one block-diagonal problem: roundoff only (1e-9)
    assert _same_curves(full.frequencies, np.hstack([inner, outer]), rtol=1e-9)
    # both spools contribute curves (otherwise the check would be one-sided) ...
    of_outer = [j for j in range(8) if _same_curves(full.frequencies[:, [j]], outer, 1e-9)]
    assert 2 <= len(of_outer) <= 6
    # ... and the outer spool's curves depend on the ratio: they are not those at the inner speed
    if ratio > 0:
        at_inner_speed = campbell(rotor.only_spool("outer"), Operating.line(SPEEDS_2), n_modes=8).frequencies
        assert not _same_curves(full.frequencies[:, of_outer], at_inner_speed, 1e-6)


def test_ratio_one_uses_the_sum_of_the_gyroscopic_matrices():
    # every tracked curve is an eigenfrequency of M q'' + (C + Omega sum_s r_s G_s) q' + K q = 0
    rotor = two_spool_rotor()
    sm = assemble(rotor)
    same = campbell(rotor, Operating.line(SPEEDS_2, ratios={"outer": 1.0}), n_modes=8)
    other = campbell(rotor, Operating.line(SPEEDS_2, ratios={"outer": 1.3}), n_modes=8)
    for i, W in enumerate(SPEEDS_2):
        shared = eigen(sm.M, sm.C + W * (sm.G["inner"] + sm.G["outer"]), sm.K).frequencies
        own = eigen(sm.M, sm.C + W * sm.G["inner"] + 1.3 * W * sm.G["outer"], sm.K).frequencies
        assert np.allclose(shared[np.argmin(np.abs(shared[:, None] - same.frequencies[i]), axis=0)],
                           same.frequencies[i], rtol=1e-10)
        assert np.allclose(own[np.argmin(np.abs(own[:, None] - other.frequencies[i]), axis=0)],
                           other.frequencies[i], rtol=1e-10)
    # the lowest 8 at rest, and the ratio matters once spinning
    assert np.allclose(same.frequencies[0], eigen(sm.M, sm.C, sm.K, n_modes=8).frequencies, rtol=1e-10)
    assert np.max(np.abs(other.frequencies[-1] - same.frequencies[-1]) / same.frequencies[-1]) > 1e-3


def test_reference_spool_choice_is_only_the_x_axis():
    rotor = two_spool_rotor()
    by_inner = campbell(rotor, Operating.line(SPEEDS_2, ratios={"outer": 1.3}), n_modes=6)
    by_outer = campbell(rotor, Operating.line(1.3 * SPEEDS_2, "outer", ratios={"inner": 1 / 1.3}), n_modes=6)
    assert by_outer.speed_ratios == pytest.approx({"inner": 1 / 1.3, "outer": 1.0})
    assert np.allclose(by_outer.frequencies, by_inner.frequencies, rtol=1e-10)
    # the same physical critical speeds, on the other spool's axis
    a = np.array([c.speed for c in by_inner.critical_speeds])
    b = np.array([c.speed for c in by_outer.critical_speeds])
    assert len(a) == len(b) > 0 and np.allclose(1.3 * a, b, rtol=1e-8)
    # default ratio = nominal speeds 400/300
    assert campbell(rotor, Operating.line(SPEEDS_2[:2]), n_modes=2).speed_ratios["outer"] == pytest.approx(400 / 300)


def test_two_spool_critical_speeds_match_hermitian_formulation():
    rotor = dataclasses.replace(two_spool_rotor(), intershaft_bearings=(
        IntershaftBearing(k_xx=1e7, k_yy=1e7, node_a=13, node_b=5),))  # undamped for the exact check
    result = campbell(rotor, Operating.line(np.linspace(0.0, 3000.0, 31), ratios={"outer": 1.3}), n_modes=6)
    for spool in ("inner", "outer"):
        _check_critical_speeds(result, rotor, spool, 1.0)


# --- the seed rig ----------------------------------------------------------------------------------
def test_seed_rig_operating_point_is_10_percent_from_every_critical_speed():
    result = rig.rig_campbell()
    assert result.speed_ratios["outer"] == pytest.approx(90 / 70)
    assert {c.spool for c in result.critical_speeds} == {"inner", "outer"}
    # every 1x critical speed of the undamped rig (Hermitian formulation, all modes, to 1e-8) is found by
    # the undamped Campbell with the same tracked modes, and the damped one has the same crossings:
    # the margin check below covers all of them
    missing, shift = rig.completeness(result)
    assert missing == 0
    # bearing damping (log dec <= 0.2, zeta <= 0.03) moves the crossings by a few zeta^2 (measured 0.44 %)
    assert shift < 0.02
    assert len(result.critical_speeds) >= 8
    assert rig.min_margin(result) >= rig.REQUIRED_MARGIN
    assert result.tracking_mac.min() > 0.9


# --- output ----------------------------------------------------------------------------------------
def test_csv_and_png(tmp_path):
    result = campbell(rigid_rotor(2.1e13), Operating.line(SPEEDS_RIGID[:6]), n_modes=4)
    assert isinstance(result, CampbellResult)
    rows = list(csv.reader(result.to_csv(tmp_path / "c.csv").open()))
    assert rows[0] == ["speed_rpm", "mode", "frequency_hz", "whirl", "log_dec", "stable"]
    assert len(rows) == 1 + 6 * 4
    assert float(rows[2][2]) == pytest.approx(result.frequencies[0, 1] / (2 * math.pi), rel=1e-8)
    png = save_figure(result.plot(), tmp_path / "c.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError):
        result.frequencies[0, 0] = 1.0  # results are read-only


def test_cli_writes_csv_png_and_prints_critical_speeds(tmp_path, capsys):
    from rotorred.cli import main

    assert main(["campbell", "nelson-mcvaugh", "--speeds", "0:30000:16", "--modes", "4",
                 "--harmonics", "1,2", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "critical speeds" in out and "1× shaft" in out and "2× shaft" in out
    assert (tmp_path / "campbell.csv").read_text().startswith("speed_rpm,mode,frequency_hz,whirl,log_dec,stable\n")
    assert (tmp_path / "campbell.png").stat().st_size > 10_000


@pytest.mark.parametrize("speeds, message", [
    ("100:0:5", "--speeds = '100:0:5': must hold strictly increasing values (rpm)"),
    ("0:100:1", "--speeds = '0:100:1': must be START:STOP:COUNT (COUNT >= 2) or a comma list of numbers (rpm)"),
    ("-5:100:3", "--speeds = '-5:100:3': must hold values >= 0 (rpm)"),
    ("0:100", "START:STOP:COUNT"),
    ("a:100:3", "--speeds = 'a:100:3': must be START:STOP:COUNT (COUNT >= 2) or a comma list of numbers (rpm)"),
])
def test_cli_bad_speeds(tmp_path, capsys, speeds, message):
    from rotorred.cli import main

    assert main(["campbell", "nelson-mcvaugh", f"--speeds={speeds}", "--out", str(tmp_path)]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "campbell.csv").exists()


# --- bad input -------------------------------------------------------------------------------------
LINE = Operating.line([0.0, 100.0])


@pytest.mark.parametrize("operating, kwargs, message", [
    (Operating.line([0.0, 2.0, 1.0]), {},
     "operating.Omega = [0.0, 2.0, 1.0]: must be strictly increasing; entry 1 = 2 is followed by 1 (rad/s)"),
    ([0.0, 100.0], {}, "operating = [0.0, 100.0]: must be an Operating (Operating.point, Operating.line, "
                       "Operating.profile; rotorred.model.operating)"),
    (Operating.ramp({"inner": 0.0}, {"inner": 100.0}, 1.0), {},
     "operating = 'profile of 2 breakpoint(s) over 1 s, spools inner 0-100 rad/s': must be a point or a speed line "
     "for speeds(); a profile gives speeds in time (profile_for)"),
    (LINE, dict(n_modes=0), "n_modes = 0: must be an integer >= 1"),
    (LINE, dict(n_modes=2.5), "n_modes = 2.5: must be an integer >= 1"),
    (LINE, dict(n_modes=10_000), "n_modes = 10000: must be <= 44, the number of DOFs"),
    (LINE, dict(harmonics=()), "harmonics = (): must be a 1-D array of at least 1 value"),
    (LINE, dict(harmonics=(1, -2)), "harmonics = (1, -2): must hold values > 0 only"),
    (Operating.line([0.0, 100.0], "fan"), {}, "reference = 'fan': must be one of 'inner', 'outer'"),
    (Operating.line([0.0, 100.0], ratios={"fan": 1.0}), {}, "ratios spool = 'fan': must be one of 'outer'"),
])
def test_bad_input(operating, kwargs, message):
    with pytest.raises(InputError, match="^" + re.escape(message) + "$"):
        campbell(two_spool_rotor(), operating, **kwargs)


def test_zero_reference_speed_needs_the_other_spools_stated():
    """A reference spool of nominal speed 0 gives no ratio: the rule of Operating.lines names the spool to state;
    stated, the diagram runs, from a reference at rest too."""
    still = two_spool_rotor().with_speeds({"inner": 0.0})
    with pytest.raises(InputError, match=r"^operating = 'line of 2 speeds: first spool 0-1 rad/s': must state the "
                                         r"speed of spool\(s\) \['outer'\] \(ratios= or fixed=\): the nominal speed "
                                         r"of the reference spool 'inner' is 0"):
        campbell(still, Operating.line([0.0, 1.0]))
    assert campbell(still, Operating.line([0.0, 1.0], ratios={"outer": 1.5}), n_modes=2).speed_ratios["outer"] == 1.5


# --- a spool held at a fixed speed: horizontal excitation lines --------------------------------------------------
K_A = 0.5 * K_BRG  # spool a's bearings: its modes apart from spool b's


def two_rigid_spools() -> Rotor:
    """Two uncoupled copies of the rigid rotor: spool ``a`` on bearings K_A (nodes 0-4), ``b`` on K_BRG (10-14)."""
    steel = Material("stiff steel", E=2.1e14, rho=7850.0, nu=0.3)
    L = 2 * A_HALF / 4
    spools = tuple(Spool(name, tuple(ShaftElement(first + i, first + i + 1, L, D_SHAFT, 0.0, steel) for i in range(4)),
                         speed=100.0) for name, first in (("a", 0), ("b", 10)))
    bearings = tuple(Bearing(k_xx=k, k_yy=k, node=n)
                     for k, first in ((K_A, 0), (K_BRG, 10)) for n in (first, first + 4))
    return Rotor(spools, disks=(Disk(2, M_DISK, ID_DISK, IP_DISK), Disk(12, M_DISK, ID_DISK, IP_DISK)),
                 bearings=bearings, name="two rigid spools")


def test_a_spool_at_a_fixed_speed_gives_critical_speeds_where_the_whirl_equals_h_times_its_speed():
    """Spool b swept (0-500 rad/s), spool a held at W_a = 200 rad/s. Closed forms of the rigid rotor (conical
    I_d w^2 -+ I_p Omega w - k_theta = 0, cylindrical m w^2 = 2 k):
    - the horizontal line 1x a (w = W_a) meets b's backward conical curve where I_d W_a^2 + I_p Omega W_a = k_theta;
    - the line 1x b (w = Omega) meets a's flat curves (its modes at W_a: conical roots with k_theta,a = 2 K_A a^2,
      cylindrical sqrt(2 K_A / m)) at Omega = their frequency, and b's own curves as for one spool.
    Eight critical speeds, each off by the residual shaft flexibility (measured 2.8e-6 on 1x b; 9.8e-6 on 1x a,
    where the backward curve is shallow, so a frequency error moves the crossing more; 1e-4 and 3e-5 allowed, where
    a line at the wrong offset is off by O(1)); on the horizontal line the whirl frequency is W_a (measured 1e-11,
    1e-7 allowed), and a's curves are its modes at W_a at every speed (measured 2.4e-6)."""
    m, I_d, I_p = rigid_body_properties()
    W_a = 200.0
    k_theta, k_theta_a = 2 * K_BRG * A_HALF ** 2, 2 * K_A * A_HALF ** 2
    result = campbell(two_rigid_spools(), Operating.line(SPEEDS_RIGID, "b", fixed={"a": W_a}), n_modes=8)
    assert result.reference == "b" and result.speed_ratios == {"a": 0.0, "b": 1.0} and result.fixed_speeds == {"a": W_a}
    assert result.excitation_lines == (("a", 1.0, 0.0, W_a), ("b", 1.0, 1.0, 0.0))
    on_a = [c for c in result.critical_speeds if c.spool == "a"]
    assert len(on_a) == 1
    assert on_a[0].speed == pytest.approx((k_theta - I_d * W_a ** 2) / (I_p * W_a), rel=1e-4)
    assert on_a[0].whirl == "backward" and abs(on_a[0].frequency / W_a - 1) < 1e-7
    assert on_a[0].spool_speed == pytest.approx(W_a, rel=1e-7)
    a_backward, a_forward = (brentq(lambda w, s=s: I_d * w * w + s * I_p * W_a * w - k_theta_a, 0.0, 1e4)
                             for s in (1, -1))
    expected = sorted([a_backward, a_forward, math.sqrt(2 * K_A / m), math.sqrt(2 * K_A / m),
                       math.sqrt(k_theta / (I_d + I_p)), math.sqrt(2 * K_BRG / m), math.sqrt(2 * K_BRG / m)])
    on_b = [c.speed for c in result.critical_speeds if c.spool == "b"]
    assert len(on_b) == len(expected)
    np.testing.assert_allclose(on_b, expected, rtol=3e-5)
    # a's curves are flat, its modes at W_a at every speed of the line
    for w in (a_backward, a_forward, math.sqrt(2 * K_A / m)):
        assert np.all(np.min(np.abs(result.frequencies / w - 1), axis=1) < 2e-5)


def test_one_speed_is_a_row_of_the_diagram_and_its_damping_ratio_is_the_eigenvalues():
    """One speed gives the whirl table: the same frequencies, whirl and log dec as that speed in a grid (two
    runs), and a damping ratio equal to -Re(lambda)/|lambda| of an independent eigen-solve of the damped,
    gyroscopic system at that speed. Measured: the same to the last bit (the same solve at that speed), zeta
    to 2.2e-16 relative; 1e-13 and 2e-15 allowed."""
    from rotorred.linear.modal import eigen
    from rotorred.model.assembly import assemble
    from rotorred.model.rotor_file import load_rotor

    rig = load_rotor("seed-rig")
    Omega = 3000 * math.pi / 30
    one = campbell(rig, Operating.point({"inner": Omega}), n_modes=6)
    grid = campbell(rig, Operating.line(np.linspace(0.0, Omega, 4)), n_modes=6)
    assert one.critical_speeds == () and one.tracking_mac.shape == (0, 6)
    order = np.argsort(grid.frequencies[-1])  # tracked from rest: the columns may be ordered otherwise
    np.testing.assert_allclose(one.frequencies[0], grid.frequencies[-1][order], rtol=1e-13)
    np.testing.assert_allclose(one.log_dec[0], grid.log_dec[-1][order], rtol=1e-13)
    assert list(one.whirl[0]) == list(grid.whirl[-1][order])
    sm = assemble(rig)
    ratios = {s: w / rig.speeds["inner"] for s, w in rig.speeds.items()}
    lam = eigen(sm.M, sm.C + Omega * sm.gyroscopic(ratios), sm.K, n_modes=6).eigenvalues
    lam = lam[np.argsort(lam.imag)][:6]
    np.testing.assert_allclose(one.damping_ratio[0], -lam.real / np.abs(lam), rtol=2e-15)


def test_cli_one_speed_prints_the_whirl_table(tmp_path, capsys):
    from rotorred.cli import main

    assert main(["campbell", "seed-rig", "--speeds", "3000", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "whirl frequencies of seed-rig at 3000 rpm of inner (outer at 1.286x)" in out
    assert "damping ratio" in out and "critical speeds" not in out
    assert len((tmp_path / "campbell.csv").read_text().splitlines()) == 1 + 6
    assert not (tmp_path / "campbell.png").exists()  # one speed is a table, not a diagram


def test_critical_speeds_csv_and_a_shared_line_listed_once(tmp_path):
    """At speed ratio 1 the lines 1x inner and 1x outer coincide: each crossing is listed once, as many as the
    sign changes of omega_j - Omega on the grid. The CSV holds every critical speed with its margin to the
    operating point, (n_c - n_op) / n_op, and the damping ratio delta / sqrt(delta^2 + 4 pi^2)."""
    from rotorred.model.rotor_file import load_rotor

    rig = load_rotor("seed-rig")
    speeds = np.linspace(0.0, 12000.0, 61) * math.pi / 30
    one = campbell(rig, Operating.line(speeds, ratios={"outer": 1.0}), n_modes=6)
    g = one.frequencies - speeds[:, None]
    assert len(one.critical_speeds) == int(np.sum(g[:-1] * g[1:] < 0)) == 6
    assert all(c.line == "1× inner = 1× outer" for c in one.critical_speeds)
    result = campbell(rig, Operating.line(speeds), n_modes=6)
    op = rig.speeds["inner"]
    rows = list(csv.reader(result.critical_speeds_to_csv(tmp_path / "c.csv", op).open()))
    assert rows[0][:2] == ["inner speed (rpm)", "excitation"] and rows[0][8] == "margin to operating point (%)"
    assert rows[0][9:] == ["amplification_factor", "required_margin_pct", "actual_margin_pct", "meets_api"]
    assert len(rows) == 1 + len(result.critical_speeds) >= 10
    for row, c in zip(rows[1:], result.critical_speeds):
        assert float(row[0]) == pytest.approx(c.speed_rpm, rel=1e-8) and row[1] == c.line
        assert float(row[8]) == pytest.approx(100 * (c.speed - op) / op, abs=1e-4)
        assert float(row[7]) == pytest.approx(-math.cos(math.atan2(2 * math.pi, -c.log_dec)), rel=1e-8)  # -Re/|lambda|
        assert row[9:] == [""] * 4  # no margins given (tests/test_margins.py)


def test_a_free_free_spool_lists_no_rigid_body_critical_speeds():
    """A free-free steel shaft (no bearings): its rigid-body modes (frequency ~1e-4 Hz at rest) used to be
    reported as critical speeds at ~0.01 rpm. They are now listed apart, and every critical speed is a
    bending mode. The first bending pair at rest is checked against the Euler-Bernoulli free-free beam,
    beta L from cos(beta L) cosh(beta L) = 1 by brentq: Timoshenko lies 0.65 % below it at D/L = 1/20
    (shear and rotary inertia), so it must lie within 0 to 1 % below."""
    steel = Material("steel", E=2.1e11, rho=7850.0, nu=0.3)
    n, L, D = 20, 1.0, 0.05
    free = Rotor((Spool("shaft", tuple(ShaftElement(i, i + 1, L / n, D, 0.0, steel) for i in range(n)),
                        speed=100.0),), name="free-free")
    result = campbell(free, Operating.line(np.linspace(0.0, 2000.0 * math.pi, 41)), n_modes=8)  # to 60 000 rpm
    assert result.rigid_modes and all(result.frequencies_hz[0, j] < 1e-2 for j in result.rigid_modes)
    assert result.critical_speeds and all(c.frequency_hz > 100.0 for c in result.critical_speeds)
    from rotorred.cli.campbell import format_critical_speeds
    assert "rigid-body modes (a free or singly supported spool; not critical speeds): modes 1, 2" in \
        format_critical_speeds(result)
    assert campbell(rigid_rotor(2.1e11), Operating.line(SPEEDS_RIGID), n_modes=4).rigid_modes == ()  # held by bearings
    bl = brentq(lambda x: math.cos(x) * math.cosh(x) - 1.0, 4.0, 5.0)
    A, I = math.pi * D ** 2 / 4, math.pi * D ** 4 / 64
    f_eb = bl ** 2 / (2 * math.pi * L ** 2) * math.sqrt(steel.E * I / (steel.rho * A))
    bending = min(result.frequencies_hz[0, j] for j in range(result.n_modes) if j not in result.rigid_modes)
    assert 0.0 < (f_eb - bending) / f_eb < 0.01


def test_unstable_mode_and_its_stability_limit_against_the_characteristic_polynomial(tmp_path):
    """The rigid rotor on bearings with cross-coupled stiffness k_xy = -k_yx = 3e5 N/m and damping c = 300 N s/m:
    the forward conical mode is unstable at rest and stable above the speed where Re(lambda) = 0. For the
    forward whirl phi = theta_x + i theta_y the rigid rotor's equation is
    I_d phi'' + (c_t - i I_p Omega) phi' + (k_t - i k_xt) phi = 0 (c_t, k_t, k_xt = 2 a^2 (c, k, k_xy)), whose
    roots (numpy.roots) give Re(lambda) at each speed; brentq finds its zero. Measured agreement 2.0e-6
    (the shaft is stiff, not rigid: E = 2.1e13); 2e-5 allowed. The mode is flagged in the table, the CSV
    (stable = no) and the plot."""
    from rotorred.cli.campbell import format_critical_speeds

    c, kxy = 300.0, 3e5
    rotor = dataclasses.replace(rigid_rotor(2.1e13), bearings=tuple(
        Bearing(k_xx=K_BRG, k_yy=K_BRG, k_xy=kxy, k_yx=-kxy, c_xx=c, c_yy=c, node=n) for n in (0, 4)))
    result = campbell(rotor, Operating.line(np.linspace(0.0, 1500.0, 31)), n_modes=4)
    _, I_d, I_p = rigid_body_properties()
    kt, ct, kxt = (2 * A_HALF ** 2 * v for v in (K_BRG, c, kxy))

    def growth(W):
        r = np.roots([I_d, ct - 1j * I_p * W, kt - 1j * kxt])
        return float(r.real[r.imag > 0].max())

    limit = brentq(growth, 1.0, 1500.0)
    (change,) = [s for s in result.stability_changes if s.mode == 0]
    assert change.whirl == "forward" and not change.onset  # unstable below, stable above
    assert abs(change.speed / limit - 1) < 2e-5
    assert change.frequency == pytest.approx(kxy / c, rel=2e-5)  # neutral where c w = k_xy
    assert "UNSTABLE: mode 1 (forward" in format_critical_speeds(result)  # modes numbered from 1
    rows = list(csv.reader(result.to_csv(tmp_path / "c.csv").open()))
    assert rows[1][:2] == ["0", "1"] and rows[1][-1] == "no"  # mode 1 (column 0) at rest
    assert save_figure(result.plot(), tmp_path / "c.png").stat().st_size > 10_000
    stable = campbell(rigid_rotor(2.1e13), Operating.line(np.linspace(0.0, 1500.0, 31)), n_modes=4)
    assert stable.stability_changes == () and not np.any(stable.unstable)  # undamped: log dec 0 to round-off


def test_three_spools_take_ratios_by_name():
    """Ratios to the reference spool by name, for any number of spools: the same diagram as a rotor whose
    nominal speeds have those ratios (two paths, equal to the last bit); a spool without a ratio keeps its
    nominal one; where the rotor gives none, the message names every missing spool."""
    from rotorred.cli.campbell import ratios_to_reference

    speeds = np.linspace(0.0, 800.0, 9)
    by_name = campbell(three_spools((100.0, 0.0, 0.0)), Operating.line(speeds, ratios={"b": 1.5, "c": 0.5}), n_modes=6)
    by_nominal = campbell(three_spools((100.0, 150.0, 50.0)), Operating.line(speeds), n_modes=6)
    assert by_name.speed_ratios == {"a": 1.0, "b": 1.5, "c": 0.5}
    np.testing.assert_array_equal(by_name.frequencies, by_nominal.frequencies)
    assert [c.line for c in by_name.critical_speeds] == [c.line for c in by_nominal.critical_speeds]
    assert campbell(three_spools((100.0, 150.0, 50.0)), Operating.line(speeds, ratios={"c": 2.0})).speed_ratios == \
        {"a": 1.0, "b": 1.5, "c": 2.0}
    with pytest.raises(InputError, match=r"^operating = .*: must state the speed of spool\(s\) \['c'\] \(ratios= or "
                                         r"fixed=\): the nominal speed of the reference spool 'a' is 0"):
        campbell(three_spools((0.0, 0.0, 0.0)), Operating.line(speeds, ratios={"b": 1.5}))
    with pytest.raises(InputError, match=r"^--ratio = 1\.5: must be SPOOL=R for rotor 'three' with 3 spool\(s\)"):
        ratios_to_reference(1.5, three_spools((100.0, 0.0, 0.0)), None)


def test_campbell_of_the_craig_bampton_model_converges_to_the_full_one(tmp_path, capsys):
    """The rig's Campbell (8 tracked modes, 0-12000 rpm) from its Craig-Bampton model against the full model: the
    largest whirl-frequency difference falls as interior modes are kept (measured 0.95, 0.21, 4.6e-4 with 4,
    8, 16 modes); with 16 the whirl directions all agree and the critical speeds agree to 1.2e-4 (4.6e-3 and
    1.2e-3 allowed). The command prints the comparison."""
    from rotorred.cli import main
    from rotorred.linear.reduction import reduce_rotor
    from rotorred.model.rotor_file import load_rotor

    rig = load_rotor("seed-rig")
    speeds = np.linspace(0.0, 12000.0, 61) * math.pi / 30
    full = campbell(rig, Operating.line(speeds), n_modes=8)
    errors = []
    for n in (4, 8, 16):
        reduced = campbell(reduce_rotor(rig, n_modes=n), Operating.line(speeds), n_modes=8)
        errors.append(float(np.max(np.abs(reduced.frequencies / full.frequencies - 1))))
    assert errors[0] > errors[1] > errors[2] and errors[2] < 4.6e-3
    assert (reduced.whirl == full.whirl).all() and len(reduced.critical_speeds) == len(full.critical_speeds)
    assert max(abs(a.speed / b.speed - 1) for a, b in zip(reduced.critical_speeds, full.critical_speeds)) < 1.2e-3
    # the rotor and its assembled model are one model (system_of): the same diagram, to the last bit
    np.testing.assert_array_equal(campbell(assemble(rig), Operating.line(speeds), n_modes=8).frequencies,
                                  full.frequencies)
    assert main(["campbell", "seed-rig", "--speeds", "0:12000:61", "--reduce", "16", "--out", str(tmp_path)]) == 0
    assert "reduced model against the full one: whirl frequencies within" in capsys.readouterr().out


def test_ratio_option_reads_repeated_and_comma_separated_items():
    """One parser of SPOOL=R (rotorred.cli.options.spool_ratios) for campbell, harmonic and map: repeated
    options and comma lists give the same ratios; a bare number stays the two-spool form."""
    from rotorred.cli.campbell import parse_ratio

    assert parse_ratio(["b=1.5", "c=0.5"]) == parse_ratio(["b=1.5,c=0.5"]) == {"b": 1.5, "c": 0.5}
    assert parse_ratio(["1.2857"]) == 1.2857 and parse_ratio([]) is None


def test_the_commands_speed_line_is_operatings_rule_and_names_the_options():
    """campbell and harmonic build their Operating with cli.options.speed_line: the spools not given by --ratio follow
    the nominal ratio (Operating.lines); a spool the rotor gives no ratio for, an unknown spool or reference, is
    refused naming the option."""
    from rotorred.cli.options import speed_line

    rig = load_rotor("seed-rig")
    line = speed_line(rig, [0.0, 6000.0], None, None, "rpm")
    assert line.speeds(rig)["outer"] == pytest.approx([0.0, 6000.0 * math.pi / 30 * 90 / 70], rel=1e-15)
    assert speed_line(rig, [100.0], "outer", {"inner": 0.5}, "rad/s").at(rig) == {"inner": 50.0, "outer": 100.0}
    with pytest.raises(InputError, match=r"^--ratio = None: must state the speed of spool\(s\) \['outer'\] .*the "
                                         r"nominal speed of the reference spool 'inner' is 0"):
        speed_line(rig.with_speeds({"inner": 0.0}), [0.0, 100.0], None, None, "rpm")
    with pytest.raises(InputError, match=r"^--reference-spool = 'mid': must be one of 'inner', 'outer'$"):
        speed_line(rig, [0.0], "mid", None, "rpm", ("--reference-spool", "--ratio"))
    with pytest.raises(InputError, match=r"^--ratio = 'inner': must be one of 'outer'$"):
        speed_line(rig, [0.0], None, {"inner": 2.0}, "rpm")


def test_mass_proportional_damping_leaves_no_overdamped_pair_as_a_mode():
    """With the paper scenes' Rayleigh damping (alpha = 40 1/s) the inner shaft's lowest modes are
    overdamped; their real eigenvalue pairs split by round-off into complex pairs of tiny imaginary
    part, which were tracked as modes at ~0 Hz with log decs of 1e8 and gave 'critical speeds' at
    0.01 Hz. Eigenvalues with a damping ratio >= 0.99 are not whirl modes (modal.WHIRL_MAX_DAMPING_RATIO):
    the damped rig then has the undamped rig's eight 1x critical speeds below 84 Hz (inner), each within
    1.5 % (measured 0.006-0.144 %: the damping ratios are 1.2-6.2 %)."""
    import dataclasses

    from rotorred.model.rotor_file import load_rotor

    rig = load_rotor("seed-rig")
    damped = dataclasses.replace(rig, rayleigh=(40.0, 2e-5))
    speeds = np.linspace(0.0, 2 * np.pi * 84.0, 41)
    line = Operating.line(speeds, "inner", ratios={"outer": 90 / 70})
    found = [campbell(r, line).critical_speeds for r in (rig, damped)]
    assert len(found[0]) == len(found[1]) == 8
    for a, b in zip(sorted(found[0], key=lambda c: c.speed), sorted(found[1], key=lambda c: c.speed)):
        assert (a.spool, a.whirl) == (b.spool, b.whirl)
        assert abs(b.speed / a.speed - 1) < 1.5e-2
        assert b.log_dec < 2 * np.pi * 0.5


# --- speed-dependent bearings (issue 18 item 12) ----------------------------------------------------------------
TABLE_RPM = (0.0, 5000.0, 10000.0, 20000.0)


@pytest.fixture(scope="module")
def tabulated():
    """Nelson-McVaugh on fluid-film-like bearings: soft at rest, 10x stiffer at 20000 rpm, growing cross-coupling."""
    from rotorred.model.elements import BearingTable

    rotor = load_rotor("nelson-mcvaugh")
    speeds = tuple(v * math.pi / 30 for v in TABLE_RPM)
    tables = tuple(BearingTable(node=b.node, speeds=speeds, k_xx=(2e6, 5e6, 1e7, 2e7), k_yy=(3e6, 6e6, 1.2e7, 2.5e7),
                                k_xy=(0.0, 1e5, 2e5, 4e5), k_yx=(0.0, -1e5, -2e5, -4e5), c_xx=(200.0, 300.0, 400.0, 500.0),
                                c_yy=200.0) for b in rotor.bearings)
    return rotor, dataclasses.replace(rotor, bearings=tables)


def _with_bearings_at(rotor, tabulated_rotor, Omega):
    """The rotor with constant bearings: each table evaluated at ``Omega`` (the path that bypasses the model's tables)."""
    return dataclasses.replace(rotor, bearings=tuple(t.at(Omega) for t in tabulated_rotor.bearings))


def test_speed_dependent_bearings_at_a_speed_equal_the_rotor_rebuilt_with_those_coefficients(tabulated):
    """``stiffness(speeds)`` and ``damping(speeds)`` of a model with bearing tables are the matrices of the rotor
    assembled with constant bearings at that speed (two paths: the tables' change added to K, C at the rotor's
    speed; a fresh assembly). Measured: equal to the last bit; asserted to 1e-15 of the largest entry."""
    rotor, rt = tabulated
    sm = assemble(rt)
    assert sm.speed_dependent and not assemble(rotor).speed_dependent
    for Omega in (0.0, 300.0, 800.0, 1500.0, 3000.0):  # 3000 rad/s: above the table (held)
        ref = assemble(_with_bearings_at(rotor, rt, Omega))
        K, D = sm.stiffness({"shaft": Omega}), sm.damping({"shaft": Omega})
        assert np.abs(K - ref.K).max() <= 1e-15 * np.abs(ref.K).max()
        assert np.abs(D - ref.damping({"shaft": Omega})).max() <= 1e-15 * np.abs(ref.K).max() ** 0.5


def test_speed_dependent_bearings_critical_speeds_against_an_independent_root_finder(tabulated):
    """Each critical speed Omega_c of the Campbell diagram with bearing tables solves omega(Omega) = Omega where
    omega is the mode's whirl speed of the rotor rebuilt with constant bearings at Omega (brentq on that, a path
    that never sees the tables). Measured: 1.5e-10 and 5e-11 (the diagram's own root tolerance); asserted 2e-9.
    The tables matter: with the coefficients at rest the lowest crossing is at half the speed."""
    rotor, rt = tabulated
    speeds = np.linspace(0.0, 25000 * math.pi / 30, 101)
    res = campbell(rt, Operating.line(speeds), n_modes=6)
    assert len(res.critical_speeds) == 2
    for c in res.critical_speeds:
        def g(Omega):
            sm = assemble(_with_bearings_at(rotor, rt, Omega))
            lam = eigen(sm.M, sm.damping({"shaft": Omega}), sm.K).eigenvalues
            f = lam.imag[lam.imag > 0]
            return f[np.argmin(abs(f - c.frequency))] - Omega
        ref = brentq(g, 0.9 * c.speed, 1.1 * c.speed, xtol=1e-12, rtol=1e-14)
        assert c.speed == pytest.approx(ref, rel=2e-9)
    at_rest = campbell(_with_bearings_at(rotor, rt, 0.0), Operating.line(speeds), n_modes=6).critical_speeds
    assert min(c.speed for c in res.critical_speeds) > 1.4 * min(c.speed for c in at_rest)  # 9331 against 4646 rpm


def test_speed_dependent_bearings_in_a_reduced_model(tabulated):
    """A Craig-Bampton model keeps the bearing nodes physical, so the tables act on it exactly: its critical speeds
    converge to the full model's with the mode count. Measured: 4.4e-4 with 4 modes, 4.8e-6 with 8; asserted 5e-3
    and 5e-5."""
    from rotorred.linear.reduction import reduce_rotor

    _, rt = tabulated
    speeds = np.linspace(0.0, 25000 * math.pi / 30, 101)
    full = campbell(rt, Operating.line(speeds), n_modes=6).critical_speeds
    for n_modes, tol in ((4, 5e-3), (8, 5e-5)):
        red = campbell(reduce_rotor(rt, n_modes=n_modes), Operating.line(speeds), n_modes=6).critical_speeds
        assert len(red) == len(full)
        assert max(abs(a.speed / b.speed - 1) for a, b in zip(red, full)) < tol


def test_cli_campbell_of_a_rotor_file_with_bearing_tables(tmp_path, capsys):
    """End to end: a rotor file's bearings tabulated against speed (speed_rpm lists) give the critical speeds of the
    tables (those of test_speed_dependent_bearings_... to 1e-6: the same rotor, the same diagram), and the sweep
    beyond the tables' 20000 rpm is said, bearing by bearing."""
    from importlib import resources

    from rotorred.cli import main

    text = resources.files("rotorred.model.presets").joinpath("nelson-mcvaugh.toml").read_text()
    table = ("speed_rpm = [0.0, 5000.0, 10000.0, 20000.0]\nk_xx = [2e6, 5e6, 1e7, 2e7]\nk_yy = [3e6, 6e6, 1.2e7, 2.5e7]\n"
             "k_xy = [0.0, 1e5, 2e5, 4e5]\nk_yx = [0.0, -1e5, -2e5, -4e5]\nc_xx = [200.0, 300.0, 400.0, 500.0]\n"
             "c_yy = 200.0")
    assert text.count("k = 4.3780e+07\nc = 0.0") == 2
    path = tmp_path / "fluid-film.toml"
    path.write_text(text.replace("k = 4.3780e+07\nc = 0.0", table))
    assert main(["campbell", str(path), "--speeds", "0:25000:101", "--modes", "6", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    for node in (10, 14):
        assert (f"bearing at node {node}: coefficients tabulated for 0-20000 rpm of its spool; the speeds leave that "
                "range, where the end values are held") in out
    rows = [line.split() for line in out.splitlines() if re.match(r"\s+\d+\.\d\s+1× shaft", line)]
    assert [float(r[0]) for r in rows] == pytest.approx([9330.8, 10992.8], abs=0.06)  # printed to 0.1 rpm
    within = campbell(load_rotor(path), Operating.line(np.linspace(0.0, 20000, 41), unit="rpm"), n_modes=6)
    assert within.beyond_tables == ()


# --- the default number of tracked modes (issue 34 item 5) ------------------------------------------------------
def _critical_speed_rows(tmp_path, capsys, name, argv):
    """``rotorred campbell`` with ``argv``: (the rows of critical_speeds.csv, the printout)."""
    from rotorred.cli import main

    out = tmp_path / name
    assert main(["campbell", *argv, "--out", str(out)]) == 0
    return list(csv.reader((out / "critical_speeds.csv").open())), capsys.readouterr().out


@pytest.mark.parametrize("argv", [
    ["seed-rig", "--speeds", "0:12000:61"],
    ["seed-rig", "--speeds", "0:12000:61", "--ratio", "1"],  # a backward mode drops below a forward one
    ["seed-rig", "--speeds", "0:12000:31", "--ratio", "outer=1.5", "--harmonics", "0.5,1,2"],
    ["nelson-mcvaugh", "--speeds", "0:40000:41", "--harmonics", "1,3"],
])
def test_default_lists_the_critical_speeds_of_thirty_modes(tmp_path, capsys, argv):
    """The default number of modes lists the same critical speeds as ``--modes 30`` (every mode to several times
    the highest excitation frequency): the same critical_speeds.csv, row by row (the same solves: measured
    byte-identical; 1e-9 allowed for the Brent refinement's round-off). The former default of 6 modes dropped some
    in each case (measured: 12 of 16, 6 of 8, 34 of 54, 8 of 9). The printout says how many modes and why."""
    default, printed = _critical_speed_rows(tmp_path, capsys, "default", argv)
    thirty, _ = _critical_speed_rows(tmp_path, capsys, "thirty", [*argv, "--modes", "30"])
    n = int(re.search(r"^tracked (\d+) modes: every mode below 1\.25 × ", printed, re.M).group(1))
    assert n < 30 and len(default) == len(thirty) > 1
    assert default[0] == thirty[0]
    for a, b in zip(default[1:], thirty[1:]):
        assert a[1:2] + a[3:4] + a[5:6] == b[1:2] + b[3:4] + b[5:6]  # excitation, mode, whirl
        np.testing.assert_allclose([float(v) for v in a[:1] + a[2:3] + a[4:5] + a[6:8]],
                                   [float(v) for v in b[:1] + b[2:3] + b[4:5] + b[6:8]], rtol=1e-9)
    six, _ = _critical_speed_rows(tmp_path, capsys, "six", [*argv, "--modes", "6"])
    assert len(six) < len(default)


def _coverage_cases():
    rig = load_rotor("seed-rig")
    rpm = np.linspace(0.0, 12000.0, 61)
    return [(rig, Operating.line(rpm, unit="rpm"), (1,)),
            (rig, Operating.line(rpm, ratios={"outer": 1.0}, unit="rpm"), (1,)),
            (rig, Operating.line(np.linspace(3000.0, 9000.0, 25), "outer", unit="rpm"), (1, 2)),
            (load_rotor("nelson-mcvaugh"), Operating.line(np.linspace(0.0, 40000.0, 41), unit="rpm"), (0.5, 1)),
            # a spool held fixed above the swept one's top speed gives the highest excitation frequency
            (rig, Operating.line(np.linspace(0.0, 3000.0, 16), "outer", fixed={"inner": 9000.0}, unit="rpm"), (1,))]


@pytest.mark.parametrize("case", range(5))
def test_default_tracks_every_mode_below_the_highest_excitation_frequency(case):
    """The rule, against an independent full eigen-solve (modal.eigen, every mode) at each grid speed: every whirl
    frequency below the highest excitation frequency h_max x max_s(Omega_s) at the top speed is one of the tracked
    frequencies there (to 1e-9); the count is the most modes below 1.25 x that frequency at the first and last
    speed (at least 6), or more where that count left one out (the rig at ratio 1: its 254 Hz backward mode drops
    below the 206 Hz forward one, so 8 counted modes miss the critical speed at 9588 rpm that the default finds)."""
    from rotorred.linear.campbell import DEFAULT_MARGIN, MIN_DEFAULT_MODES, default_mode_count
    from rotorred.linear.modal import WHIRL_MAX_DAMPING_RATIO

    rotor, operating, harmonics = _coverage_cases()[case]
    result = campbell(rotor, operating, harmonics=harmonics)
    spool_speeds = operating.speeds(rotor)
    limit = max(harmonics) * max(w[-1] for w in spool_speeds.values())
    mc = result.mode_count
    assert mc.limit == pytest.approx(limit, rel=1e-14) and mc.margin == DEFAULT_MARGIN
    sm = assemble(rotor)
    below_ends = []
    for i in range(operating.n_points):
        at = {s: w[i] for s, w in spool_speeds.items()}
        f = eigen(sm.M, sm.damping(at), sm.stiffness(at), max_damping_ratio=WHIRL_MAX_DAMPING_RATIO).eigenvalues.imag
        for w in f[f < limit]:
            assert np.min(np.abs(result.frequencies[i] / w - 1)) < 1e-9, (i, w)
        if i in (0, operating.n_points - 1):
            below_ends.append(int(np.sum(f < DEFAULT_MARGIN * limit)))
    counted = max(MIN_DEFAULT_MODES, *below_ends)
    assert mc.below == tuple(below_ends)
    assert default_mode_count(rotor, operating, harmonics=harmonics) == \
        dataclasses.replace(mc, n_modes=counted, grown_at=None)
    if mc.grown_at is None:
        assert result.n_modes == counted
    else:
        assert result.n_modes > counted
        fewer = campbell(rotor, operating, n_modes=counted, harmonics=harmonics)
        assert {c.speed for c in fewer.critical_speeds} < {c.speed for c in result.critical_speeds}
    assert (mc.grown_at is not None) == (case == 1)
    if case == 4:  # the fixed inner spool's line, horizontal at 9000 rpm, is above the outer's up to 3000 rpm
        assert mc.spool == "inner" and mc.limit == pytest.approx(9000 * math.pi / 30, rel=1e-14)


def test_modes_option_overrides_the_default(tmp_path, capsys):
    """``--modes N`` (``n_modes=N``) tracks N modes, whatever the rule gives (more or fewer), and says so."""
    from rotorred.cli import main

    rig = load_rotor("seed-rig")
    speeds = np.linspace(0.0, 12000 * math.pi / 30, 13)
    default = campbell(rig, Operating.line(speeds))
    for n in (3, default.n_modes + 2):
        given = campbell(rig, Operating.line(speeds), n_modes=n)
        assert given.n_modes == n and given.mode_count is None
    assert main(["campbell", "seed-rig", "--speeds", "0:12000:13", "--modes", "3", "--out", str(tmp_path)]) == 0
    assert "tracked 3 modes (--modes)" in capsys.readouterr().out
    rows = list(csv.reader((tmp_path / "campbell.csv").open()))[1:]
    assert {int(r[1]) for r in rows} == {1, 2, 3}  # numbered from 1


def test_default_mode_count_at_rest_and_bad_margin():
    """No spool turning at the top speed (one speed, at rest) gives no excitation line: the default's minimum of
    6 modes; a margin below 1 would leave out modes the lines cross."""
    from rotorred.cli.campbell import format_mode_count
    from rotorred.linear.campbell import default_mode_count

    rig = load_rotor("seed-rig")
    rest = campbell(rig, Operating.point({"inner": 0.0}))
    assert rest.n_modes == 6 and rest.mode_count.limit == 0.0 and rest.mode_count.below == (0,)
    assert format_mode_count(rest).startswith("tracked 6 modes: the default's minimum (6), as no spool turns at 0 rpm")
    with pytest.raises(InputError, match=r"^margin = 0\.5: must be >= 1$"):
        default_mode_count(rig, Operating.line([0.0, 100.0]), margin=0.5)
    wide = default_mode_count(rig, Operating.line([0.0, 600.0]), margin=2.0)
    assert wide.n_modes > default_mode_count(rig, Operating.line([0.0, 600.0])).n_modes


def test_modes_that_become_oscillating_along_the_sweep_are_reported_not_tracked():
    """ROSS's compressor example over 0-10 000 rpm: near-overdamped pairs (its seals and bearings) turn into whirl modes
    below the highest excitation frequency (166.7 Hz) from about 5000 rpm on. No curve tracked from the first speed can
    follow them, and growing the count for them grew it to every mode and failed naming ``n_modes`` ("221 must be <=
    220"), an option never given. They are reported instead (``ModeCount.born``). Checked against the dense state- space
    eigenvalues (scipy), independent of the tracking: at 0 rpm there are two whirl modes (damping ratio < 0.99) below
    the limit, the count the default rule made; at each speed where modes are born there are more, at least two plus
    those born there; each born mode is an eigenvalue there (measured relative distance 6e-12 to 1.2e-11: the dense
    state-space solve's own round-off), heavily damped (measured 0.916-0.950); the tracked curves at 0 rpm are the six
    lowest whirl modes there."""
    import scipy.linalg

    from rotorred.linear.modal import WHIRL_MAX_DAMPING_RATIO

    rotor = load_rotor(Path(__file__).parents[1] / "validation" / "reference" / "ross3" / "compressor_example.toml")
    Omega = np.linspace(0.0, 10000 * math.pi / 30, 21)
    result = campbell(rotor, Operating.line(Omega))
    count = result.mode_count
    assert result.n_modes == 6 and count.grown_at is None and len(count.born) >= 2
    sm = assemble(rotor)

    def whirl(W):
        speeds = {s: W for s in sm.spools}
        D, K = sm.damping(speeds), sm.stiffness(speeds)
        Minv = np.linalg.inv(sm.M)
        n = sm.n_dof
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ D]])
        lam = scipy.linalg.eigvals(A)
        lam = lam[lam.imag > 0]
        return lam[-lam.real / np.abs(lam) < WHIRL_MAX_DAMPING_RATIO]

    at_rest = np.sort(whirl(0.0).imag)
    assert np.sum(at_rest < count.limit) == 2 == max(count.below)
    for W in sorted({b[0] for b in count.born}):
        here = whirl(W)
        born = [(w, zeta) for V, w, zeta in count.born if V == W]
        assert np.sum(here.imag < count.limit) >= 2 + len(born), W
        for w, zeta in born:
            assert w < count.limit and 0.85 < zeta < WHIRL_MAX_DAMPING_RATIO
            assert np.min(np.abs(here - complex(-zeta * w / math.sqrt(1 - zeta ** 2), w))) < 1.2e-10 * w
    at_rest = at_rest[:6]
    np.testing.assert_allclose(np.sort(result.frequencies[0]), at_rest, rtol=1e-9)
