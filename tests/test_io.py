"""Rotor TOML files: presets load, and bad files fail before any computation with a message
that names the field, the value and what is allowed."""

import pytest

from rotorred.model.rotor_file import RotorFileError, load_rotor, presets, rotor_from_toml

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
    with pytest.raises(RotorFileError, match="`element` must be one of"):
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


BAD = [
    ('D_i = 0.0, material = "steel", repeat = 4', 'D_i = 0.03, material = "steel", repeat = 4', "`D_i` must be smaller"),
    ("rho = 7850.0", "rho = -7850.0", "material\\[0\\].*`rho`"),
    ("nu = 0.3", "nu = 0.7", "`nu`"),
    ("E = 2.1e11", 'E = "hard"', "`E` must be a finite number"),
    ("[[disk]]\nnode = 3", "[[disk]]\nnode = 30", "`node` 30 does not exist"),
    ("[[bearing]]\nnode = 1", "[[bearing]]\nnode = 42", "bearings\\[0\\].*`node` 42 does not exist"),
    ("node_a = 12", "node_a = 5", "two different spools"),
    ("node_a = 12", "node_a = 99", "`node_a` 99 does not exist"),
    ('elements = [ { L = 0.1, D_o = 0.06', 'elements = [] #', "`elements` must be a non-empty list"),
    ("L = 0.1, D_o = 0.02", "L = -0.1, D_o = 0.02", "`L` must be a positive"),
    ("repeat = 4", "repeat = 0", "`repeat` must be >= 1"),
    ("repeat = 4", "repeat = 2.5", "`repeat` must be an integer"),
    ('material = "steel", repeat = 4', 'material = "titanium", repeat = 4', "`material` 'titanium' is not defined"),
    ("k = 1e7\nc = 100.0", "k = 1e7\nk_xx = 2e7", "give `k` \\(isotropic\\) or `k_xx`"),
    ("k = 1e7\nc = 100.0", "k = -1e7", "`k_xx` must be a finite number >= 0"),
    ("speed_rpm = 4200.0", "speed_rpm = -10.0", "`speed_rpm` must be >= 0"),
    ("first_node = 10", "first_node = 3", "node 3 belongs to spool 'inner' and to spool 'outer'"),
    ('name = "outer"', 'name = "inner"', "spool names must be unique"),
    ("rayleigh_beta = 1e-5", "rayleigh_gamma = 1e-5", "unknown key\\(s\\) \\['rayleigh_gamma'\\]"),
    ("thickness = 0.01", "thickness = 0.01\nm = 3.0", "either \\(m, I_d, I_p\\) or"),
    ("I_p = 0.02", "I_p = -0.02", "`I_p`"),
    ('name = "t"', 'name = "t"\ncolour = "red"', "rotor file: unknown key\\(s\\) \\['colour'\\]"),
    ("[[bearing]]\nnode = 1\n", "[[bearing]]\n", "missing required key\\(s\\) \\['node'\\]"),
    ("D_o = 0.2", "D_o = 0.2\nshape = 1", "unknown key\\(s\\) \\['shape'\\]"),
]


@pytest.mark.parametrize("old, new, message", BAD, ids=[b[2][:40] for b in BAD])
def test_bad_files(old, new, message):
    assert old in GOOD, old
    text = GOOD.replace(old, new, 1)
    with pytest.raises(RotorFileError, match=message):
        rotor_from_toml(text, source="bad.toml")


def test_spool_with_no_elements_message():
    text = GOOD.replace('elements = [ { L = 0.1, D_o = 0.06, D_i = 0.04, material = "steel", repeat = 2 } ]',
                        "elements = []")
    with pytest.raises(RotorFileError, match="spool\\[1\\] \\('outer'\\): `elements` must be a non-empty list"):
        rotor_from_toml(text)


def test_invalid_toml_and_missing_file(tmp_path):
    with pytest.raises(RotorFileError, match="not valid TOML"):
        rotor_from_toml("[[spool]\nname=", source="x.toml")
    with pytest.raises(FileNotFoundError, match="neither a preset"):
        load_rotor(tmp_path / "nope.toml")
