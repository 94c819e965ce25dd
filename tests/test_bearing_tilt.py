"""Tilt stiffness and damping on every bearing kind, and inter-shaft bearing tables (issue 38, item 3;
docs/model.md §20)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rotorred.checks import InputError
from rotorred.linear.campbell import campbell
from rotorred.linear.modal import eigen
from rotorred.linear.reduction import reduce_rotor
from rotorred.model.assembly import assemble
from rotorred.model.elements import (Bearing, BearingTable, Disk, IntershaftBearing, IntershaftBearingTable, Material,
                                     Pedestal, ShaftElement)
from rotorred.model.operating import Operating
from rotorred.model.rotor import Rotor, Spool
from rotorred.model.rotor_file import RotorFileError, rotor_from_toml

#: a soft, nearly massless stub from the disk's node 0 to a free node 1: it holds nothing (its end is free) and its own
#: modes lie near 1.5e6 rad/s, far above the disk's (a stiff stub puts them so high that the state matrix's eigenvalues
#: lose the disk's to round-off)
STUB = Material("stub", E=1e3, rho=1e-6, nu=0.3)
m, I_d, I_p = 10.0, 0.05, 0.1  # the disk (kg, kg m^2)


def disk_on_a_tilt_spring(k_t: float, c_t: float = 0.0, q: float = 0.0) -> Rotor:
    """A rigid disk at node 0 held by a bearing of 1e6 N/m in x and y and of ``k_t`` (N m/rad) in tilt, with tilt
    damping ``c_t`` and skew cross-coupled tilt stiffness k_txty = -k_tytx = ``q``; a stub shaft to a free node 1."""
    spool = Spool("s", (ShaftElement(0, 1, 0.05, 0.05, 0.0, STUB),))
    bearing = Bearing(node=0, k_xx=1e6, k_yy=1e6, k_txtx=k_t, k_tyty=k_t, k_txty=q, k_tytx=-q, c_txtx=c_t, c_tyty=c_t)
    return Rotor((spool,), disks=(Disk(0, m, I_d, I_p),), bearings=(bearing,))


def tilt_roots(k_t: float, c_t: float, q: float, Omega: float) -> np.ndarray:
    """The closed form: with phi = theta_x + i theta_y the disk's tilt obeys I_d phi'' + (c_t - i I_p Omega) phi' +
    (k_t - i q) phi = 0 (its conjugate for theta_x - i theta_y); the two roots with Im > 0, sorted by Im."""
    roots = np.roots([I_d, c_t - 1j * I_p * Omega, k_t - 1j * q])
    roots = np.concatenate([roots, roots.conj()])
    return np.sort_complex(roots[roots.imag > 0] * 1j)[::-1] / 1j  # by Im, lowest first


def test_a_disk_on_a_tilt_spring_whirls_at_sqrt_k_over_I_d_and_splits_with_speed():
    """At rest the tilt modes are at sqrt(k_t / I_d) = 632.46 rad/s (the translation at sqrt(k / m) = 316.23 rad/s);
    with speed they split into the roots of I_d w^2 -+ I_p Omega w - k_t = 0; with tilt damping and skew
    cross-coupled tilt stiffness, the roots of the complex quadratic. Measured against the closed form: 1.6e-12
    relative at worst, the translation 4.9e-12 (the stub's mass); asserted 1.6e-11 and 5e-11."""
    k_t = 2e4
    errors = []
    for c_t, q in ((0.0, 0.0), (6.0, 3e3)):
        model = assemble(disk_on_a_tilt_spring(k_t, c_t, q))
        for Omega in (0.0, 500.0, 1500.0):
            lam = eigen(model.M, model.damping({"s": Omega}), model.K, n_modes=4).eigenvalues
            exact = tilt_roots(k_t, c_t, q, Omega)
            ours = np.array([lam[np.argmin(np.abs(lam - r))] for r in exact])
            errors.append(np.max(np.abs(ours / exact - 1)))
            assert np.min(np.abs(lam / (math.sqrt(1e6 / m) * 1j) - 1)) < 5e-11  # the translation, apart
    assert math.sqrt(k_t / I_d) == pytest.approx(tilt_roots(k_t, 0.0, 0.0, 0.0).imag[0], rel=1e-15)
    assert max(errors) < 1.6e-11


def test_campbell_of_the_disk_on_a_tilt_spring_crosses_at_the_closed_form_critical_speeds():
    """On 0-800 rad/s the disk's 1x crossings are the translation's pair at sqrt(k / m) = 316.23 rad/s and the
    backward tilt mode's at w = sqrt(k_t / (I_d + I_p)) = 365.15 rad/s (I_d w^2 + I_p w^2 - k_t = 0); the forward
    tilt mode never meets 1x (I_p > I_d, a disk). Campbell finds them within 5e-11 (measured 5.0e-12 and 4.3e-13)."""
    k_t = 2e4
    result = campbell(disk_on_a_tilt_spring(k_t), Operating.line(np.linspace(0.0, 800.0, 41)), n_modes=4)
    found = [(c.whirl, c.speed) for c in result.critical_speeds]
    assert [w for w, _ in found] == ["backward", "forward", "backward"]
    exact = [math.sqrt(1e6 / m)] * 2 + [math.sqrt(k_t / (I_d + I_p))]
    assert np.max(np.abs(np.array([s for _, s in found]) / exact - 1)) < 5e-11


def test_tilt_on_a_pedestal_link_acts_to_ground_and_an_intershaft_bearing_on_the_relative_tilt():
    """A pedestal does not tilt: a linked bearing's tilt terms act on the shaft node alone, and the translational
    ones on the relative deflection as before. An inter-shaft bearing's tilt terms act on theta_a - theta_b. A tilt
    term at a pedestal node is refused."""
    steel = Material("steel", 2.1e11, 7850.0)
    a = Spool("a", tuple(ShaftElement(i, i + 1, 0.1, 0.03, 0.0, steel) for i in range(3)))
    b = Spool("b", tuple(ShaftElement(i, i + 1, 0.1, 0.06, 0.04, steel) for i in range(10, 12)))
    rotor = Rotor((a, b), bearings=(Bearing(node=0, link=20, k_xx=1e7, k_yy=1e7, k_txtx=3e4, k_tyty=4e4, c_tytx=2.0),
                                    Bearing(node=20, k_xx=1e8, k_yy=1e8), Bearing(node=3, k_xx=1e7, k_yy=1e7)),
                  intershaft_bearings=(IntershaftBearing(node_a=2, node_b=11, k_xx=1e6, k_yy=1e6, k_txtx=5e3,
                                                         k_tyty=6e3),),
                  pedestals=(Pedestal(20, 5.0),))
    full, bare = assemble(rotor), assemble(dataclasses.replace(rotor, bearings=(
        Bearing(node=0, link=20, k_xx=1e7, k_yy=1e7), *rotor.bearings[1:]), intershaft_bearings=(
        IntershaftBearing(node_a=2, node_b=11, k_xx=1e6, k_yy=1e6),)))
    dK, dC = full.K - bare.K, full.C - bare.C
    i = full.dofs.index
    expected = {(i(0, "tx"), i(0, "tx")): 3e4, (i(0, "ty"), i(0, "ty")): 4e4,
                (i(2, "tx"), i(2, "tx")): 5e3, (i(11, "tx"), i(11, "tx")): 5e3, (i(2, "tx"), i(11, "tx")): -5e3,
                (i(11, "tx"), i(2, "tx")): -5e3, (i(2, "ty"), i(2, "ty")): 6e3, (i(11, "ty"), i(11, "ty")): 6e3,
                (i(2, "ty"), i(11, "ty")): -6e3, (i(11, "ty"), i(2, "ty")): -6e3}
    want = np.zeros_like(dK)
    for (r, c), v in expected.items():
        want[r, c] = v
    assert np.array_equal(dK, want)
    assert np.flatnonzero(dC).tolist() == [i(0, "ty") * full.n_dof + i(0, "tx")] and dC[i(0, "ty"), i(0, "tx")] == 2.0
    with pytest.raises(InputError, match=r"^bearings\[1\]\.node = 20: must be a shaft node for a bearing with tilt "
                                         r"coefficients; node 20 is a pedestal, which has no rotations"):
        dataclasses.replace(rotor, bearings=(rotor.bearings[0], Bearing(node=20, k_xx=1e8, k_tyty=1.0),
                                             rotor.bearings[2]))


def dual_rotor(table: IntershaftBearingTable) -> Rotor:
    """Two steel spools on ground bearings, joined by ``table``."""
    steel = Material("steel", 2.1e11, 7850.0)
    inner = Spool("inner", tuple(ShaftElement(i, i + 1, 0.1, 0.03, 0.0, steel) for i in range(8)), speed=300.0)
    outer = Spool("outer", tuple(ShaftElement(i, i + 1, 0.1, 0.07, 0.05, steel) for i in range(20, 24)), speed=500.0,
                  z0=0.2)
    return Rotor((inner, outer), disks=(Disk(4, 3.0, 0.01, 0.02), Disk(22, 5.0, 0.03, 0.05)),
                 bearings=(Bearing(node=0, k_xx=1e7, k_yy=1e7, c_xx=200.0, c_yy=200.0),
                           Bearing(node=8, k_xx=1e7, k_yy=1e7, c_xx=200.0, c_yy=200.0),
                           Bearing(node=20, k_xx=2e7, k_yy=2e7, c_xx=300.0, c_yy=300.0)),
                 intershaft_bearings=(table,))


TABLE = IntershaftBearingTable(24, 6, (0.0, 400.0, 800.0, 1200.0), k_xx=(2e6, 5e6, 7e6, 8e6), k_yy=(2e6, 4e6, 6e6, 7e6),
                               k_xy=(0.0, 1e5, 3e5, 4e5), c_xx=(400.0, 300.0, 250.0, 240.0), c_yy=300.0,
                               k_txtx=(1e3, 2e3, 3e3, 3e3), k_tyty=1e3, speed_of="outer", interpolation="pchip")


def test_an_intershaft_table_follows_the_named_spools_speed_only():
    """The inter-shaft table of two spools, against the outer spool's speed: at each operating point the model's
    matrices equal those of the rotor rebuilt with the constant bearing ``table.at(Omega_outer)`` (exact, 0), so the
    whirl roots are the rebuilt rotor's; the inner spool's speed moves the gyroscopic terms only. A Craig-Bampton
    model (the bearing's nodes on the boundary) carries the table exactly: its whirl roots at each point are those of
    the rebuilt rotor's Craig-Bampton model within 1.5e-11 (measured 1.5e-12, 12 modes)."""
    rotor = dual_rotor(TABLE)
    model = assemble(rotor)
    reduced = reduce_rotor(rotor, n_modes=12)
    errors = []
    assert len(model.tables) == 1 and model.tables[0].spool == "outer"
    for speeds in ({"inner": 300.0, "outer": 500.0}, {"inner": 900.0, "outer": 150.0}, {"inner": 0.0, "outer": 1500.0},
                   {"inner": 1000.0, "outer": 1000.0}):
        rebuilt = assemble(dataclasses.replace(rotor, intershaft_bearings=(TABLE.at(speeds["outer"]),)))
        assert np.array_equal(model.stiffness(speeds), rebuilt.K) or \
            np.max(np.abs(model.stiffness(speeds) - rebuilt.K)) <= 1e-15 * np.max(np.abs(rebuilt.K))
        assert np.max(np.abs(model.dissipation(speeds) - rebuilt.C)) <= 1e-15 * np.max(np.abs(rebuilt.C))
        cb = eigen(reduced.M, reduced.damping(speeds), reduced.stiffness(speeds), n_modes=8).eigenvalues
        again = reduce_rotor(dataclasses.replace(rotor, intershaft_bearings=(TABLE.at(speeds["outer"]),)), n_modes=12)
        exact = eigen(again.M, again.damping(speeds), again.K, n_modes=8).eigenvalues
        errors.append(np.max(np.abs(cb / exact - 1)))
    assert max(errors) < 1.5e-11
    inner_only = [model.stiffness({"inner": w, "outer": 500.0}) for w in (0.0, 800.0)]
    assert np.array_equal(*inner_only)


def test_intershaft_tables_and_tilt_in_a_rotor_file():
    """A rotor file gives an inter-shaft table with speed_rpm and speed_of, tilt terms by k_tt / c_tt or one by
    one; a speed_of naming no spool and a shorthand given with its direct terms are refused by name."""
    text = """
[[material]]
name = "steel"
E = 2.1e11
rho = 7850.0
[[spool]]
name = "inner"
first_node = 0
speed_rpm = 3000.0
material = "steel"
elements = [{ L = 0.1, D_o = 0.03, repeat = 8 }]
[[spool]]
name = "outer"
first_node = 20
speed_rpm = 5000.0
material = "steel"
elements = [{ L = 0.1, D_o = 0.07, D_i = 0.05, repeat = 4 }]
[[bearing]]
node = 0
k = 1e7
k_tt = 2e4
c_tt = 3.0
[[bearing]]
node = 20
k = 2e7
k_txty = 500.0
[[intershaft_bearing]]
node_a = 24
node_b = 6
speed_rpm = [0.0, 6000.0, 12000.0]
speed_of = "outer"
k = [2e6, 4e6, 5e6]
k_tt = [1e3, 2e3, 2e3]
interpolation = "pchip"
"""
    rotor = rotor_from_toml(text, "r.toml")
    first, second = rotor.bearings
    assert (first.k_txtx, first.k_tyty, first.c_txtx, first.c_tyty, second.k_txty) == (2e4, 2e4, 3.0, 3.0, 500.0)
    table = rotor.intershaft_bearings[0]
    assert isinstance(table, IntershaftBearingTable) and table.speed_of == "outer"
    assert table.at(600.0 * math.pi / 30.0 * 10).k_tyty == 2e3
    with pytest.raises(RotorFileError, match=r"^r\.toml: intershaft_bearing\[0\]\.speed_of = 'fan': must name a "
                                             r"spool of the rotor \('inner', 'outer'\)$"):
        rotor_from_toml(text.replace('speed_of = "outer"', 'speed_of = "fan"'), "r.toml")
    with pytest.raises(RotorFileError, match=r"^r\.toml: bearing\[0\]\.k_txtx = 1\.0: must not be given with k_tt: "
                                             r"give k_tt \(isotropic\) or k_txtx, k_tyty$"):
        rotor_from_toml(text.replace("k_tt = 2e4", "k_tt = 2e4\nk_txtx = 1.0"), "r.toml")
    with pytest.raises(RotorFileError, match=r"^r\.toml: bearing\[0\]\.c_tyty = -1\.0: must be >= 0 \(N m s/rad\)$"):
        rotor_from_toml(text.replace("c_tt = 3.0", "c_txtx = 3.0\nc_tyty = -1.0"), "r.toml")


def test_a_tabulated_intershaft_bearing_names_its_nodes_when_extrapolation_turns_damping_negative():
    """Linear extrapolation of a falling direct damping below 0 is refused at the speed asked, naming both nodes."""
    table = IntershaftBearingTable(1, 12, (100.0, 200.0), c_xx=(100.0, 50.0), extrapolate="linear")
    with pytest.raises(InputError, match=r"gives c_xx = -50 at 400 rad/s for the bearing at nodes 1-12, below 0"):
        table.at(400.0)
    assert BearingTable(3, (0.0, 1.0), c_txtx=(1.0, 2.0)).at(0.5).c_txtx == 1.5
