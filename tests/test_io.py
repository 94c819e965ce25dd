"""Rotor TOML files: presets load, and bad files fail before any computation with a message
that names the field, the value and what is allowed."""

import math

import numpy as np
import pytest

from rotorred.model.rotor_file import RotorFileError, load_rotor, presets, rotor_from_toml
from rotor_files import assert_refused

GOOD = """
name = "t"
[[material]]
name = "steel"
E = 2.1e11
rho = 7850.0
nu = 0.3
[[spool]]
name = "inner"
first_node = 1
speed_rpm = 4200.0
elements = [ { L = 0.1, D_o = 0.02, D_i = 0.0, material = "steel", repeat = 4 } ]
[[spool]]
name = "outer"
first_node = 10
z0 = 0.1
elements = [ { L = 0.1, D_o = 0.06, D_i = 0.04, material = "steel", repeat = 2 } ]
[[disk]]
node = 3
m = 2.0
I_d = 0.01
I_p = 0.02
[[disk]]
node = 11
D_o = 0.2
D_i = 0.06
thickness = 0.01
material = "steel"
[[bearing]]
node = 1
k = 1e7
c = 100.0
[[bearing]]
node = 5
k_xx = 1e7
k_yy = 2e7
k_xy = -1e6
[[intershaft_bearing]]
node_a = 12
node_b = 4
k = 5e6
[damping]
rayleigh_beta = 1e-5
"""


def test_good_file():
    r = rotor_from_toml(GOOD)
    assert r.spool("inner").nodes == (1, 2, 3, 4, 5)
    assert r.spool("outer").nodes == (10, 11, 12)
    assert r.speeds["inner"] == pytest.approx(4200 * 3.141592653589793 / 30)
    assert r.positions[12] == pytest.approx(0.3)
    disk = r.disk_at(11)
    assert disk.radius == pytest.approx(0.1)
    assert disk.I_p == pytest.approx(disk.m * (0.1**2 + 0.03**2) / 2)
    (b0, b1) = r.bearings
    assert (b0.k_xx, b0.k_yy, b0.c_xx) == (1e7, 1e7, 100.0)
    assert (b1.k_yy, b1.k_xy, b1.k_yx) == (2e7, -1e6, 0.0)
    assert r.rayleigh == (0.0, 1e-5)


def test_element_formulation_per_spool_and_element():
    text = GOOD.replace('first_node = 10\n', 'first_node = 10\nelement = "hierarchical"\n', 1)
    r = rotor_from_toml(text)
    assert {e.element for e in r.spool("outer").elements} == {"hierarchical"}
    assert {e.element for e in r.spool("inner").elements} == {"nelson"}
    bad = GOOD.replace('repeat = 4 }', 'repeat = 4, element = "p7" }', 1)
    with pytest.raises(RotorFileError, match=r"spool\[0\]\.elements\[0\]\.element = 'p7': must be one of 'nelson', "
                                             r"'hierarchical'"):
        rotor_from_toml(bad)


def test_presets():
    """The Nelson-McVaugh preset holds the geometry of validation/reference (bore read as a diameter):
    its mass is computed here from the reference's stations, diameters and disk."""
    import json
    import math
    from pathlib import Path

    assert {"seed-rig", "nelson-mcvaugh"} <= set(presets())
    nm = load_rotor("nelson-mcvaugh")
    ref = json.loads((Path(__file__).resolve().parents[1] / "validation/reference/nelson_mcvaugh_rotor.json").read_text())
    z = [v / 100 for v in ref["stations_cm"]]
    D_o = [v / 100 for v in ref["element_outer_diameter_cm"]]
    D_i = [v / 100 for v in ref["element_inner_diameter_cm"]]
    shaft = sum(ref["material"]["rho_kg_m3"] * math.pi / 4 * (o**2 - i**2) * (b - a)
                for a, b, o, i in zip(z[:-1], z[1:], D_o, D_i))
    assert nm.mass == pytest.approx(shaft + ref["disk"]["m_kg"], rel=1e-12)
    assert load_rotor("seed-rig").nodes == tuple(range(1, 21))


# Each bad file: (text replaced, replacement, the message: the file, the key path, the value as written
# in the file's units and what is allowed).
BAD = [
    ('D_i = 0.0, material = "steel", repeat = 4', 'D_i = 0.03, material = "steel", repeat = 4',
     "bad.toml: spool[0].elements[0].D_i = 0.03: must be < D_o = 0.02 (m)"),
    ("rho = 7850.0", "rho = -7850.0", "bad.toml: material[0].rho = -7850.0: must lie in [1e-09, 1e+06] (kg/m^3)"),
    ("nu = 0.3", "nu = 0.7", "bad.toml: material[0].nu = 0.7: must lie in (-1, 0.5)"),
    ("nu = 0.3", "nu = 0.3\nG = 8e10", "bad.toml: material[0].G = 80000000000.0: must not be given with nu "
     "(G = E / (2 (1 + nu)) fixes one by the other) (Pa)"),
    ("first_node = 1\n", 'first_node = 1\nrotary_inertia = "no"\n',
     "bad.toml: spool[0].elements[0].rotary_inertia = 'no': must be true or false"),
    ("nu = 0.3", "G = 5e10", "bad.toml: material[0].G = 50000000000.0: must be > E / 3 = 7e+10 so that "
     "nu = E / (2 G) - 1 < 0.5 (Pa)"),
    ("E = 2.1e11", 'E = "hard"', "bad.toml: material[0].E = 'hard': must be a finite number in (0, 1e+18] (Pa)"),
    ("[[disk]]\nnode = 3", "[[disk]]\nnode = 30",
     "bad.toml: disk[0].node = 30: must be a node of the rotor (1-5, 10-12)"),
    ("[[bearing]]\nnode = 1", "[[bearing]]\nnode = 42",
     "bad.toml: bearing[0].node = 42: must be a node of the rotor (1-5, 10-12)"),
    ("node_a = 12", "node_a = 5", "bad.toml: intershaft_bearing[0].node_b = 4: must be on another spool than "
     "node_a = 5 (both are on spool 'inner'); an inter-shaft bearing joins two different spools"),
    ("node_a = 12", "node_a = 99",
     "bad.toml: intershaft_bearing[0].node_a = 99: must be a node of the rotor (1-5, 10-12)"),
    ('elements = [ { L = 0.1, D_o = 0.06', 'elements = [] #',
     "bad.toml: spool[1].elements = []: must be a non-empty array of tables"),
    ("L = 0.1, D_o = 0.02", "L = -0.1, D_o = 0.02", "bad.toml: spool[0].elements[0].L = -0.1: must be > 0 (m)"),
    ("repeat = 4", "repeat = 0", "bad.toml: spool[0].elements[0].repeat = 0: must be an integer >= 1"),
    ("repeat = 4", "repeat = 2.5", "bad.toml: spool[0].elements[0].repeat = 2.5: must be an integer >= 1"),
    ('material = "steel", repeat = 4', 'material = "titanium", repeat = 4',
     "bad.toml: spool[0].elements[0].material = 'titanium': must be one of 'steel'"),
    ("k = 1e7\nc = 100.0", "k = 1e7\nk_xx = 2e7",
     "bad.toml: bearing[0].k_xx = 20000000.0: must not be given with k: give k (isotropic) or k_xx, k_yy"),
    ("k = 1e7\nc = 100.0", "k = 1e7\nc = -100.0", "bad.toml: bearing[0].c = -100.0: must be >= 0 (N s/m)"),
    ("speed_rpm = 4200.0", "speed_rpm = -10.0", "bad.toml: spool[0].speed_rpm = -10.0: must be >= 0 (rpm)"),
    ("first_node = 10", "first_node = 3",
     "bad.toml: spool[1].nodes = (3, 4, 5): must not include node 3, which belongs to spool 'inner'"),
    ('name = "outer"', 'name = "inner"',
     "bad.toml: spool[1].name = 'inner': must differ from the names of the other spools"),
    ("rayleigh_beta = 1e-5", "rayleigh_gamma = 1e-5",
     "bad.toml: damping.rayleigh_gamma = 1e-05: unknown key; allowed keys are rayleigh_alpha, rayleigh_beta"),
    ("thickness = 0.01", "thickness = 0.01\nm = 3.0", "bad.toml: disk[1].m = 3.0: must not be given with D_o, "
     "thickness, material: give either (m, I_d, I_p) or (D_o, D_i, thickness, material)"),
    ("I_p = 0.02", "I_p = -0.02", "bad.toml: disk[0].I_p = -0.02: must be >= 0 (kg m^2)"),
    ('name = "t"', 'name = "t"\ncolour = "red"', "bad.toml: colour = 'red': unknown key; allowed keys are bearing, "
     "damping, defaults, description, disk, intershaft_bearing, material, name, pedestal, spool, support"),
    ("[[bearing]]\nnode = 1\n", "[[bearing]]\n", "bad.toml: bearing[0].node: missing; required"),
    ("k = 1e7\nc = 100.0", "speed_rpm = [0.0, 3000.0]\nk = [1e7, 2e7, 3e7]",
     "bad.toml: bearing[0].k = [10000000.0, 20000000.0, 30000000.0]: must be a 1-D array of 2 values (N/m)"),
    ("k = 1e7\nc = 100.0", "speed_rpm = [3000.0, 0.0]\nk = 1e7", "bad.toml: bearing[0].speed_rpm = [3000.0, "
     "0.0]: must be strictly increasing; entry 0 = 3000 is followed by 0 (rpm)"),
    ("k = 1e7\nc = 100.0", "speed_rpm = [0.0, 3000.0]\nk = 1e7\nc_xx = [100.0, -1.0]",
     "bad.toml: bearing[0].c_xx = [100.0, -1.0]: must hold values >= 0 only (N s/m)"),
    ("k = 1e7\nc = 100.0", "k = 1e7\nextrapolate = \"linear\"",
     "bad.toml: bearing[0].extrapolate = 'linear': needs speed_rpm: only a table against speed interpolates and "
     "extrapolates"),
    ("k = 1e7\nc = 100.0", "speed_rpm = [0.0, 3000.0]\nk = 1e7\ninterpolation = \"cubic\"",
     "bad.toml: bearing[0].interpolation = 'cubic': must be one of 'linear', 'pchip'"),
    ("k = 1e7\nc = 100.0", "speed_rpm = [0.0, 3000.0]\nfrequency_rpm = [0.0, 3000.0]\nk = 1e7",
     "bad.toml: bearing[0].frequency_rpm = [0.0, 3000.0]: must not be given with speed_rpm: a table has one axis"),
    ("k = 1e7\nc = 100.0", "frequency_rpm = [0.0, 3000.0]\nk = 1e7\nk_tt = [1e3, -2.0]\nc_tt = [1.0, -2.0]",
     "bad.toml: bearing[0].c_tt = [1.0, -2.0]: must hold values >= 0 only (N m s/rad)"),
    ("[[intershaft_bearing]]\nnode_a = 12", "[[intershaft_bearing]]\nfrequency_rpm = [0.0, 1.0]\nnode_a = 12",
     "bad.toml: intershaft_bearing[0].frequency_rpm = [0.0, 1.0]: unknown key; allowed keys are c, c_tt, c_txtx, "
     "c_txty, c_tytx, c_tyty, c_xx, c_xy, c_yx, c_yy, extrapolate, interpolation, k, k_tt, k_txtx, k_txty, k_tytx, "
     "k_tyty, k_xx, k_xy, k_yx, k_yy, name, node_a, node_b, speed_of, speed_rad_s, speed_rpm"),
    ("[[intershaft_bearing]]\nnode_a = 12", "[[intershaft_bearing]]\nspeed_of = \"inner\"\nnode_a = 12",
     "bad.toml: intershaft_bearing[0].speed_of = 'inner': needs speed_rpm: only a table follows a spool's speed"),
    ("first_node = 1\n", "first_node = 1\nnodes = [1, 2, 3, 4, 5]\n",
     "bad.toml: spool[0].nodes = [1, 2, 3, 4, 5]: must not be given with first_node: give one of the two"),
    ("first_node = 1\n", "", "bad.toml: spool[0].first_node: missing; required (or nodes)"),
    ("first_node = 1\n", "nodes = [1, 2, 3, 4]\n",
     "bad.toml: spool[0].nodes = [1, 2, 3, 4]: must hold 5 entries, not 4"),
    ("first_node = 1\n", "nodes = [1, 2, 7, 2, 5]\n",
     "bad.toml: spool[0].nodes = [1, 2, 7, 2, 5]: must not list an entry twice"),
    ("speed_rpm = 4200.0", "speed_rpm = 4200.0\nspeed_rad_s = 440.0",
     "bad.toml: spool[0].speed_rad_s = 440.0: must not be given with speed_rpm: give one of the two"),
    ("speed_rpm = 4200.0", "speed_rad_s = -1.0", "bad.toml: spool[0].speed_rad_s = -1.0: must be >= 0 (rad/s)"),
    ("D_o = 0.2", "D_o = 0.2\nshape = 1", "bad.toml: disk[1].shape = 1: unknown key; allowed keys are D_i, D_o, I_d, "
     "I_p, m, material, name, node, radius, thickness"),
]


@pytest.mark.parametrize("old, new, message", BAD, ids=[b[2][10:50] for b in BAD])
def test_bad_files(old, new, message):
    assert_refused(GOOD, old, new, message)


def test_nodes_and_speeds_in_si_as_a_written_rotor_gives_them():
    """A spool may list its node numbers in place of first_node (any order, as a refined rotor's), its speed and a
    bearing table's speeds may be given in rad/s (speed_rad_s), the same rotor as in rpm."""
    text = GOOD.replace("first_node = 10\n", "nodes = [10, 12, 11]\n").replace(
        "k = 1e7\nc = 100.0", "speed_rad_s = [0.0, 300.0]\nk = [1e7, 2e7]", 1)
    r = rotor_from_toml(text.replace("speed_rpm = 4200.0", f"speed_rad_s = {4200 * math.pi / 30!r}"))
    assert r.spool("outer").nodes == (10, 12, 11) and r.positions[11] == pytest.approx(0.3)
    assert r.bearings[0].speeds == (0.0, 300.0) and r.bearings[0].k_yy == (1e7, 2e7)
    assert r.spool("inner").speed == rotor_from_toml(GOOD).spool("inner").speed


def test_shear_modulus_in_place_of_poisson_ratio():
    """A material given by E, G and rho (the textbooks' data) is the material of nu = E / (2 G) - 1: the same
    element matrices (measured: identical; 1e-14 allowed for the rounding of nu = E / (2 G) - 1), and G is used
    as given."""
    import numpy as np

    E = 2.1e11
    by_g = rotor_from_toml(GOOD.replace("nu = 0.3", f"G = {E / 2.6!r}"))
    by_nu = rotor_from_toml(GOOD)
    (m_g,), (m_nu,) = {e.material for e in by_g.spools[0].elements}, {e.material for e in by_nu.spools[0].elements}
    assert m_g.G == E / 2.6 and m_g.G_s == E / 2.6 and abs(m_g.nu - 0.3) < 1e-15
    for a, b in zip(by_g.spools[0].elements, by_nu.spools[0].elements):
        for K_g, K_nu in ((a.K(), b.K()), (a.M(), b.M())):
            assert np.max(np.abs(K_g - K_nu)) <= 1e-14 * np.max(np.abs(K_nu))
    friswell = rotor_from_toml(GOOD.replace("nu = 0.3", "G = 81.2e9").replace("E = 2.1e11", "E = 211e9"))
    steel = friswell.spools[0].elements[0].material
    assert steel.G_s == 81.2e9 and steel.nu == pytest.approx(211.0 / (2 * 81.2) - 1.0, rel=1e-15)


def test_rotary_inertia_per_spool_and_element():
    text = GOOD.replace("first_node = 1\n", "first_node = 1\nrotary_inertia = false\n")
    text = text.replace('material = "steel", repeat = 4 }', 'material = "steel", repeat = 3 }, '
                        '{ L = 0.1, D_o = 0.02, material = "steel", rotary_inertia = true }')
    r = rotor_from_toml(text)
    assert [e.rotary_inertia for e in r.spool("inner").elements] == [False, False, False, True]
    assert all(e.rotary_inertia for e in r.spool("outer").elements)


def test_spool_with_no_elements_message():
    text = GOOD.replace('elements = [ { L = 0.1, D_o = 0.06, D_i = 0.04, material = "steel", repeat = 2 } ]',
                        "elements = []")
    with pytest.raises(RotorFileError,
                       match=r"^<string>: spool\[1\]\.elements = \[\]: must be a non-empty array of tables$"):
        rotor_from_toml(text)


def test_invalid_toml_and_missing_file(tmp_path):
    with pytest.raises(RotorFileError, match=r"^x\.toml: line 1 = '\[\[spool\]': must be valid TOML: Expected"):
        rotor_from_toml("[[spool]\nname=", source="x.toml")
    with pytest.raises(FileNotFoundError, match="neither a preset"):
        load_rotor(tmp_path / "nope.toml")


def test_bearing_table_against_speed():
    """``speed_rpm`` makes a bearing a table against its spool's speed: lists per coefficient, numbers held at every
    speed, ``k`` setting both direct terms; read in rpm, kept in rad/s."""
    from rotorred.model.elements import BearingTable

    text = GOOD.replace("k = 1e7\nc = 100.0", "speed_rpm = [0.0, 3000.0, 6000.0]\nk = [1e7, 2e7, 4e7]\n"
                        "c_xx = [100.0, 200.0, 300.0]\nk_xy = 5e5", 1)
    b = rotor_from_toml(text).bearings[0]
    assert isinstance(b, BearingTable) and b.extrapolate == "hold"
    linear = rotor_from_toml(text.replace("k_xy = 5e5", 'k_xy = 5e5\nextrapolate = "linear"')).bearings[0]
    assert linear.at(300 * math.pi).k_xx == pytest.approx(6e7, rel=1e-14) and b.at(300 * math.pi).k_xx == 4e7
    assert b.speeds == pytest.approx((0.0, 100 * math.pi, 200 * math.pi), rel=1e-15)
    assert b.k_xx == b.k_yy == (1e7, 2e7, 4e7) and b.c_xx == (100.0, 200.0, 300.0)
    assert b.k_xy == (5e5,) * 3 and b.c_yy == (0.0,) * 3
    at = b.at(150 * math.pi)  # 4500 rpm: half way between the last two speeds
    assert (at.k_xx, at.k_yy, at.c_xx, at.k_xy) == pytest.approx((3e7, 3e7, 250.0, 5e5), rel=1e-15)


STATIONS = """
name = "stations"
[[material]]
name = "steel"
E = 2.1e11
rho = 7850.0
[[spool]]
name = "s"
first_node = 0
material = "steel"
stations = [
  { z = 0.1, D_o = 0.04 },
  { z = 0.3, D_o = 0.06, D_i = 0.02, n = 2 },
  { z = 0.5, D_o = 0.06, D_o_end = 0.03, n = 3 },
  { z = 0.8 },
]
"""


def test_stations_are_the_elements_they_describe():
    """A shaft given as stations (z, D_o, D_i; a section runs to the next station, tapering to D_o_end) is the chain
    of elements it describes: the same elements as the element list written by hand, the taper split along its
    line, the first z the spool's start."""
    from rotorred.model.assembly import assemble

    by_stations = rotor_from_toml(STATIONS)
    by_elements = rotor_from_toml(STATIONS.replace(
        'material = "steel"\nstations = [', 'z0 = 0.1\nelements = [\n'
        '  { L = 0.2, D_o = 0.04, material = "steel" },\n'
        '  { L = 0.1, D_o = 0.06, D_i = 0.02, material = "steel", repeat = 2 },\n'
        '  { L = 0.1, D_o = 0.06, D_o_right = 0.05, material = "steel" },\n'
        '  { L = 0.1, D_o = 0.05, D_o_right = 0.04, material = "steel" },\n'
        '  { L = 0.1, D_o = 0.04, D_o_right = 0.03, material = "steel" },\n]\n#').split("#")[0] + "\n")
    a, b = by_stations.spools[0], by_elements.spools[0]
    assert a.nodes == b.nodes == tuple(range(7)) and a.z0 == b.z0 == 0.1
    for x, y in zip(a.elements, b.elements):
        assert (x.L, x.D_o, x.D_i, x.D_o_right, x.D_i_right) == pytest.approx((y.L, y.D_o, y.D_i, y.D_o_right, y.D_i_right),
                                                                              rel=1e-14)
    K1, K2 = assemble(by_stations).K, assemble(by_elements).K
    assert np.abs(K1 - K2).max() <= 1e-12 * np.abs(K2).max()


def test_nelson_mcvaugh_from_its_station_table():
    """The Nelson-McVaugh rotor written as its sources give it (stations in cm, element diameters) through the
    stations form has the preset's whirl speeds (the preset lists the same elements by length): measured 2.5e-11
    (element lengths as differences of stations round differently; the x-y pairs at rest are degenerate, which
    round-off splits); asserted 2.5e-10."""
    import json
    from pathlib import Path

    from rotorred.linear.campbell import campbell
    from rotorred.model.operating import Operating

    ref = json.loads((Path(__file__).resolve().parents[1] / "validation/reference/nelson_mcvaugh_rotor.json").read_text())
    preset = load_rotor("nelson-mcvaugh")
    z = [v / 100 for v in ref["stations_cm"]]
    rows = [f"  {{ z = {z[k]!r}, D_o = {ref['element_outer_diameter_cm'][k] / 100!r}, "
            f"D_i = {ref['element_inner_diameter_cm'][k] / 100!r} }}," for k in range(len(z) - 1)]
    from importlib import resources
    text = resources.files("rotorred.model.presets").joinpath("nelson-mcvaugh.toml").read_text()
    head, _, tail = text.partition("elements = [")
    _, _, tail = tail.partition("]\n")
    stations = head.replace("z0 = 0.0\n", 'material = "steel"\n') + "stations = [\n" + "\n".join(rows) + \
        f"\n  {{ z = {z[-1]!r} }},\n]\n" + tail
    from_stations = rotor_from_toml(stations)
    speeds = np.linspace(0.0, 5000.0, 6)
    a = campbell(from_stations, Operating.line(speeds), n_modes=6).frequencies
    b = campbell(preset, Operating.line(speeds), n_modes=6).frequencies
    assert np.max(np.abs(a / b - 1)) < 2.5e-10


@pytest.mark.parametrize("old, new, message", [
    ("{ z = 0.3,", "{ z = 0.1,", "bad.toml: spool[0].stations[1].z = 0.1: must be > the previous station's z = 0.1 (m)"),
    ("{ z = 0.8 }", "{ z = 0.8, D_o = 0.03 }", "bad.toml: spool[0].stations[3].D_o = 0.03: unknown key; allowed keys are z"),
    ('material = "steel"\nstations', 'z0 = 0.0\nmaterial = "steel"\nstations',
     "bad.toml: spool[0].z0 = 0.0: must not be given with stations: the first station's z is the start"),
    ('material = "steel"\nstations', 'stations', "bad.toml: spool[0].stations[0].material: missing; required (or "
     "spool[0].material for every section)"),
    ("D_o_end = 0.03", "D_o_end = -0.03", "bad.toml: spool[0].stations[2].D_o_end = -0.03: must be > 0 (m)"),
    ("{ z = 0.1, D_o = 0.04 }", "{ D_o = 0.04 }", "bad.toml: spool[0].stations[0].z: missing; required"),
])
def test_bad_stations(old, new, message):
    assert_refused(STATIONS, old, new, message)
