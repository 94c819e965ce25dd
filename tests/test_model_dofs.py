"""The one DOF-spec parser ("NODE:DIRECTION") and the DOF map."""

import re

import numpy as np
import pytest

import rotorred.model.assembly as assembly
from rotorred.checks import InputError
from rotorred.model.dofs import DIRECTION_ALIASES, DIRECTIONS, DofMap, checked_dof, direction_name, parse_dof

DIRS = "'x', 'y', 'theta_x' ('tx'), 'theta_y' ('ty')"


@pytest.mark.parametrize("text, expected", [
    ("13:x", (13, "x")), ("13:y", (13, "y")), ("13:theta_x", (13, "theta_x")), ("13:tx", (13, "theta_x")),
    ("0:ty", (0, "theta_y")), (" 7 : theta_y ", (7, "theta_y")),
])
def test_parse_dof(text, expected):
    assert parse_dof("--outputs", text) == expected
    assert parse_dof("--outputs", text, nodes=range(0, 20)) == expected


@pytest.mark.parametrize("text, message", [
    ("13x", f"--outputs = '13x': must be NODE:DIRECTION (e.g. '13:x') with DIRECTION one of {DIRS}"),
    ("x:13", f"--outputs = 'x:13': must be NODE:DIRECTION (e.g. '13:x') with DIRECTION one of {DIRS}"),
    ("-1:x", f"--outputs = '-1:x': must be NODE:DIRECTION (e.g. '13:x') with DIRECTION one of {DIRS}"),
    ("13:x:y", f"--outputs = '13:x:y': must be NODE:DIRECTION (e.g. '13:x') with DIRECTION one of {DIRS}"),
    ("13:z", f"--outputs = '13:z': direction must be one of {DIRS}"),
    ("99:x", "--outputs = '99:x': must name a node of the rotor (1-20); node 99 is not one"),
    (13, "--outputs = 13: must be a string"),
])
def test_parse_dof_refuses_with_the_field(text, message):
    with pytest.raises(InputError, match="^" + re.escape(message) + "$"):
        parse_dof("--outputs", text, nodes=range(1, 21))


def test_checked_dof_takes_pairs_and_text():
    assert checked_dof("outputs[0]", (np.int64(3), "tx")) == (3, "theta_x")
    assert checked_dof("outputs[0]", [3, "y"], nodes={3}) == (3, "y")
    assert checked_dof("outputs[0]", "3:y", nodes={3}) == (3, "y")
    for value, message in [((3,), "must be a (node, direction) pair"),
                           ((3.0, "x"), "must be a (node, direction) pair with an integer node"),
                           ((4, "x"), "must name a node of the rotor (3); node 4 is not one"),
                           ((3, "z"), f"direction must be one of {DIRS}")]:
        with pytest.raises(InputError, match=re.escape(f"outputs[0] = {value!r}: {message}")):
            checked_dof("outputs[0]", value, nodes={3})


def test_directions_and_aliases():
    assert DIRECTIONS == ("x", "y", "theta_x", "theta_y")
    assert DIRECTION_ALIASES == {"tx": "theta_x", "ty": "theta_y"}
    assert [direction_name(d) for d in DIRECTIONS + ("tx", "ty")] == ["X", "Y", "theta_x", "theta_y", "theta_x",
                                                                       "theta_y"]
    with pytest.raises(InputError, match=re.escape(f"direction = 'z': must be one of {DIRS}")):
        direction_name("z")


def test_dofmap_lives_in_dofs_and_is_reexported_by_assembly():
    assert assembly.DofMap is DofMap and assembly.DIRECTIONS is DIRECTIONS
    dofs = DofMap((5, 7, 9), n_internal=2)
    assert dofs.n_dof == 14 and dofs.index(7, "tx") == 6 and dofs.label(13) == "internal 1"
    assert dofs.checked_outputs([(9, "y"), "5:ty"]) == ((9, "y"), (5, "theta_y"))
    with pytest.raises(InputError, match=re.escape("outputs[1] = (8, 'x'): must name a node of the model (5, 7, 9); "
                                                   "node 8 is not one")):
        dofs.checked_outputs([(9, "y"), (8, "x")])
    with pytest.raises(InputError, match=re.escape("inputs = 3: must be a sequence of (node, direction) pairs")):
        dofs.checked_outputs(3, "inputs")
    with pytest.raises(InputError, match=re.escape("nodes = (1, 1): must not list an entry twice")):
        DofMap((1, 1))
    with pytest.raises(InputError, match=re.escape("n_internal = -1: must be an integer >= 0")):
        DofMap((1,), -1)
