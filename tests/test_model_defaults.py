"""A rotor file's [defaults] table: read, validated like every other table, carried on the Rotor."""

import math
import re

import pytest

from rotorred.checks import InputError
from rotorred.model.loads import Unbalance
from rotorred.model.rotor import AnalysisDefaults, Rotor
from rotorred.model.rotor_file import RotorFileError, load_rotor, rotor_from_toml

BASE = """
name = "d"
[[material]]
name = "steel"
E = 2.1e11
rho = 7850.0
[[spool]]
name = "inner"
first_node = 1
speed_rpm = 3000.0
elements = [ { L = 0.1, D_o = 0.02, material = "steel", repeat = 4 } ]
[[spool]]
name = "outer"
first_node = 10
elements = [ { L = 0.1, D_o = 0.06, D_i = 0.04, material = "steel", repeat = 2 } ]
[[bearing]]
node = 1
k = 1e7
[[bearing]]
node = 5
k = 1e7
[[intershaft_bearing]]
node_a = 12
node_b = 4
k = 5e6
"""

DEFAULTS = """
[defaults]
unbalance = [ { node = 3, m_e = 2e-5, phase_deg = 90.0 }, { node = 11, m_e = 1e-5 } ]
outputs = ["3:x", "3:ty", "11:y"]
boundary_nodes = [3, 11]
"""


def test_a_rotor_file_with_defaults():
    rotor = rotor_from_toml(BASE + DEFAULTS)
    d = rotor.defaults
    assert d.unbalances == (Unbalance(3, 2e-5, math.pi / 2), Unbalance(11, 1e-5, 0.0))
    assert d.outputs == ((3, "x"), (3, "theta_y"), (11, "y"))
    assert d.boundary_nodes == (3, 11)


def test_defaults_are_empty_without_the_table():
    assert rotor_from_toml(BASE).defaults == AnalysisDefaults() == AnalysisDefaults((), (), ())
    assert load_rotor("nelson-mcvaugh").defaults == AnalysisDefaults()


def test_copies_keep_the_defaults():
    rotor = rotor_from_toml(BASE + DEFAULTS)
    assert rotor.refined(3).defaults == rotor.defaults
    assert rotor.with_speeds({"outer": 100.0}).defaults == rotor.defaults
    assert rotor.without_intershaft_bearings().defaults == rotor.defaults
    inner = rotor.only_spool("inner").defaults  # only the defaults on the spool's own nodes
    assert inner.unbalances == (Unbalance(3, 2e-5, math.pi / 2),)
    assert inner.outputs == ((3, "x"), (3, "theta_y")) and inner.boundary_nodes == (3,)


def test_seed_rig_preset_defaults():
    """The values rotorred harmonic used to hard-code for the seed rig now come from its preset file."""
    d = load_rotor("seed-rig").defaults
    assert d.unbalances == (Unbalance(11, 1e-5), Unbalance(16, 1e-5))
    assert d.outputs == ((13, "x"), (13, "y"), (14, "x"), (14, "y"))
    assert d.boundary_nodes == (18,)


BAD = [
    ("node = 3, m_e", "node = 30, m_e", "defaults.unbalance[0].node = 30: must be a node of the rotor (1-5, 10-12)"),
    ("m_e = 2e-5", "m_e = -2e-5", "defaults.unbalance[0].m_e = -2e-05: must be >= 0 (kg m)"),
    ("phase_deg = 90.0", 'phase_deg = "up"', "defaults.unbalance[0].phase_deg = 'up': must be a finite number (deg)"),
    ("phase_deg = 90.0", "phase = 1.0", "defaults.unbalance[0].phase = 1.0: unknown key; allowed keys are m_e, node, "
     "phase_deg"),
    ("{ node = 11, m_e = 1e-5 }", "{ node = 11 }", "defaults.unbalance[1].m_e: missing; required"),
    ('"11:y"', '"12:z"', "defaults.outputs[2] = '12:z': direction must be one of 'x', 'y', 'theta_x' ('tx'), "
     "'theta_y' ('ty')"),
    ('"11:y"', '"7:y"', "defaults.outputs[2] = '7:y': must name a node of the rotor (1-5, 10-12); node 7 is not one"),
    ('"11:y"', '"11y"', "defaults.outputs[2] = '11y': must be NODE:DIRECTION (e.g. '13:x')"),
    ('"11:y"', '"3:x"', "defaults.outputs = ['3:x', '3:ty', '3:x']: must not list an entry twice"),
    ("boundary_nodes = [3, 11]", "boundary_nodes = [3, 42]",
     "defaults.boundary_nodes[1] = 42: must be a node of the rotor (1-5, 10-12)"),
    ("boundary_nodes = [3, 11]", "boundary_nodes = 3", "defaults.boundary_nodes = 3: must be a list"),
    ("boundary_nodes = [3, 11]", "boundary = [3]", "defaults.boundary = [3]: unknown key; allowed keys are "
     "boundary_nodes, operating_range_rad_s, operating_range_rpm, outputs, unbalance"),
    ("unbalance = [", "unbalance = 3 #[", "defaults.unbalance = 3: must be an array of tables"),
]


@pytest.mark.parametrize("old, new, message", BAD, ids=[b[2][:40] for b in BAD])
def test_bad_defaults_are_refused_with_the_key_path(old, new, message):
    assert old in DEFAULTS, old
    with pytest.raises(RotorFileError, match="^" + re.escape("rig.toml: " + message)):
        rotor_from_toml(BASE + DEFAULTS.replace(old, new, 1), source="rig.toml")


def test_defaults_table_must_be_a_table():
    with pytest.raises(RotorFileError, match=r"^<string>: defaults = 3: must be a table$"):
        rotor_from_toml("defaults = 3\n" + BASE)


def test_rotor_checks_the_nodes_of_its_defaults():
    rotor = rotor_from_toml(BASE)
    with pytest.raises(InputError, match=r"^defaults\.unbalances\[0\]\.node = 8: must be a node of the rotor "
                                         r"\(1-5, 10-12\)$"):
        Rotor(rotor.spools, defaults=AnalysisDefaults(unbalances=(Unbalance(8, 1e-5),)))
    with pytest.raises(InputError, match=r"^defaults\.outputs\[0\] = \(8, 'x'\): must name a node of the rotor "
                                         r"\(1-5, 10-12\); node 8 is not one$"):
        Rotor(rotor.spools, defaults=AnalysisDefaults(outputs=((8, "x"),)))
    with pytest.raises(InputError, match=r"^defaults\.boundary_nodes\[0\] = 8: must be a node of the rotor"):
        Rotor(rotor.spools, defaults=AnalysisDefaults(boundary_nodes=(8,)))
    with pytest.raises(InputError, match=r"^defaults = \{\}: must be an AnalysisDefaults$"):
        Rotor(rotor.spools, defaults={})


def test_analysis_defaults_check_their_entries():
    assert AnalysisDefaults(outputs=["3:tx", (4, "ty")], boundary_nodes=[5]).outputs == ((3, "theta_x"),
                                                                                          (4, "theta_y"))
    with pytest.raises(InputError, match=r"^unbalances\[0\] = \(11, 1e-05\): must be an Unbalance$"):
        AnalysisDefaults(unbalances=[(11, 1e-5)])
    with pytest.raises(InputError, match=r"^outputs\[0\] = \(3, 'z'\): direction must be one of"):
        AnalysisDefaults(outputs=[(3, "z")])
    with pytest.raises(InputError, match=r"^boundary_nodes\[0\] = -1: must be an integer >= 0$"):
        AnalysisDefaults(boundary_nodes=[-1])
    with pytest.raises(InputError, match=r"^boundary_nodes = \(3, 3\): must not list an entry twice$"):
        AnalysisDefaults(boundary_nodes=[3, 3])
