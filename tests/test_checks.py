"""rotorred.checks: one message form for every refused input, and the errors survive pickling."""

import math
import pickle
import re

import numpy as np
import pytest

from rotorred import checks
from rotorred.checks import MISSING, InputError
from rotorred.model.rotor_file import RotorFileError
from rotorred.scenes.schema import SceneError
from rotorred.signals.spectra import NotCommensurateError


def message(call, *args, **kwargs) -> str:
    with pytest.raises(InputError) as info:
        call(*args, **kwargs)
    return str(info.value)


# --------------------------------------------------------------------------- scalars
@pytest.mark.parametrize("kwargs, value, expected", [
    ({}, "fast", "solver.dt = 'fast': must be a finite number (s)"),
    ({}, True, "solver.dt = True: must be a finite number (s)"),
    ({}, math.nan, "solver.dt = nan: must be a finite number (s)"),
    ({"gt": 0}, math.inf, "solver.dt = inf: must be a finite number > 0 (s)"),
    ({"gt": 0}, 0.0, "solver.dt = 0.0: must be > 0 (s)"),
    ({"ge": 0}, -1e-06, "solver.dt = -1e-06: must be >= 0 (s)"),
    ({"le": 2}, 3, "solver.dt = 3: must be <= 2 (s)"),
    ({"lt": 2}, 2.0, "solver.dt = 2.0: must be < 2 (s)"),
    ({"ge": 0, "le": 1}, 1.5, "solver.dt = 1.5: must lie in [0, 1] (s)"),
    ({"gt": -1, "lt": 0.5}, 0.5, "solver.dt = 0.5: must lie in (-1, 0.5) (s)"),
    ({"gt": 0, "le": 1}, np.float64(0.0), "solver.dt = 0.0: must lie in (0, 1] (s)"),
])
def test_number_messages(kwargs, value, expected):
    assert message(checks.number, "solver.dt", value, "s", **kwargs) == expected


def test_number_returns_a_float():
    for v in (3, np.int32(3), np.float32(3.0), 3.0):
        out = checks.number("x", v, ge=0)
        assert out == 3.0 and type(out) is float
    assert checks.positive("x", 2) == 2.0 and checks.non_negative("x", 0) == 0.0


def test_positive_and_non_negative_messages():
    assert message(checks.positive, "rub[0].m_p", 0.0, "kg") == "rub[0].m_p = 0.0: must be > 0 (kg)"
    assert message(checks.non_negative, "rub[0].clearance", -1e-06, "m") == \
        "rub[0].clearance = -1e-06: must be >= 0 (m)"
    assert message(checks.positive, "nu", -1, "-") == "nu = -1: must be > 0"  # unit "-" is not shown


def test_integer_messages():
    assert checks.integer("n", np.int64(4)) == 4 and type(checks.integer("n", np.int64(4))) is int
    assert message(checks.integer, "n", 2.5) == "n = 2.5: must be an integer"
    assert message(checks.integer, "n", True) == "n = True: must be an integer"
    assert message(checks.integer, "n", 2.0, ge=1) == "n = 2.0: must be an integer >= 1"
    assert message(checks.integer, "n", 0, ge=1) == "n = 0: must be an integer >= 1"
    assert message(checks.integer, "n", 9, ge=0, le=8) == "n = 9: must be an integer in [0, 8]"
    assert message(checks.integer, "n", 9, le=8) == "n = 9: must be an integer <= 8"


def test_choice_string_boolean_messages():
    assert checks.choice("solver.model", "full", ("reduced", "full")) == "full"
    assert message(checks.choice, "solver.model", "modal", ("reduced", "full")) == \
        "solver.model = 'modal': must be one of 'reduced', 'full'"
    assert message(checks.choice, "solver.model", 3, ("reduced", "full")) == \
        "solver.model = 3: must be one of 'reduced', 'full'"
    assert message(checks.string, "name", 3) == "name = 3: must be a string"
    assert checks.string("name", "") == ""
    assert message(checks.string, "name", "", empty=False) == "name = '': must be a non-empty string"
    assert checks.boolean("output.compare_normal", np.bool_(True)) is True
    assert message(checks.boolean, "output.compare_normal", 1) == "output.compare_normal = 1: must be true or false"


# --------------------------------------------------------------------------- containers
def test_table_and_tables_messages():
    assert checks.table("damping", {"a": 1}) == {"a": 1}
    assert message(checks.table, "damping", [1]) == "damping = [1]: must be a table"
    assert checks.tables("rub", [{"node": 1}]) == ({"node": 1},)
    assert message(checks.tables, "rub", {"node": 1}) == "rub = {'node': 1}: must be an array of tables"
    assert message(checks.tables, "rub", [{"node": 1}, 2]) == "rub[1] = 2: must be a table"
    assert message(checks.tables, "spool", [], min_len=1) == "spool = []: must be a non-empty array of tables"
    assert message(checks.tables, "spool", [{}], min_len=2) == "spool = [{}]: must be an array of at least 2 tables"


def test_sequence_messages():
    assert checks.sequence("nodes", [1, 2], checks.integer) == (1, 2)
    assert message(checks.sequence, "nodes", 3) == "nodes = 3: must be a list"
    assert message(checks.sequence, "nodes", [1, "a"], checks.integer) == "nodes[1] = 'a': must be an integer"
    assert message(checks.sequence, "nodes", [], min_len=1) == "nodes = []: must hold at least 1 entry, not 0"
    assert message(checks.sequence, "w", [1, 2, 3], min_len=2, max_len=2) == "w = [1, 2, 3]: must hold 2 entries, not 3"
    assert message(checks.sequence, "w", [1], min_len=2, max_len=3) == "w = [1]: must hold 2 to 3 entries, not 1"
    assert message(checks.sequence, "nodes", [1, 1], unique=True) == "nodes = [1, 1]: must not list an entry twice"


def test_array_and_vector_messages():
    np.testing.assert_array_equal(checks.array("K", [[1, 2], [3, 4]], shape=(2, 2)), [[1.0, 2.0], [3.0, 4.0]])
    assert message(checks.array, "K", [[1, 2]], shape=(2, 2), unit="N/m") == \
        "K = [[1, 2]]: must have shape (2, 2) (N/m)"
    assert message(checks.array, "K", ["a"]) == "K = ['a']: must be an array of numbers"
    assert message(checks.array, "K", [1j]) == "K = [1j]: must be an array of real numbers"
    assert message(checks.array, "K", np.array([1.0, np.inf])) == \
        "K = array of shape (2,): must hold finite numbers only"
    np.testing.assert_array_equal(checks.vector("speeds", (0, 1, 2), ge=0, increasing=True), [0.0, 1.0, 2.0])
    assert message(checks.vector, "speeds", [], "rad/s") == \
        "speeds = []: must be a 1-D array of at least 1 value (rad/s)"
    assert message(checks.vector, "speeds", 3.0, "rad/s") == \
        "speeds = 3.0: must be a 1-D array of at least 1 value (rad/s)"
    assert message(checks.vector, "band", [1, 2, 3], min_len=2, max_len=2) == \
        "band = [1, 2, 3]: must be a 1-D array of 2 values"
    assert message(checks.vector, "x", [1], min_len=2, max_len=4) == "x = [1]: must be a 1-D array of 2 to 4 values"
    assert message(checks.vector, "h", [1, 0], gt=0) == "h = [1, 0]: must hold values > 0 only"
    assert message(checks.vector, "s", [0, -1], ge=0, unit="Hz") == "s = [0, -1]: must hold values >= 0 only (Hz)"
    assert message(checks.vector, "s", [0, 2, 2], increasing=True) == \
        "s = [0, 2, 2]: must be strictly increasing; entry 1 = 2 is followed by 2"


def test_node_keys_and_ranges():
    assert checks.ranges_text([14, 1, 2, 3, 20, 15]) == "1-3, 14-15, 20"
    assert checks.ranges_text([]) == "none"
    assert checks.node("rub[0].node", np.int64(18), range(1, 21)) == 18
    assert message(checks.node, "rub[0].node", 99, range(1, 21)) == \
        "rub[0].node = 99: must be a node of the rotor (1-20)"
    assert message(checks.node, "rub[0].node", "18", range(1, 21)) == "rub[0].node = '18': must be an integer"
    assert message(checks.node, "n", 5, {1, 2}, "a node of the model") == "n = 5: must be a node of the model (1-2)"
    checks.keys("solver", {"dt": 1}, {"dt", "duration"}, required={"dt"})
    assert message(checks.keys, "solver", {"step": 1}, {"dt", "duration"}) == \
        "solver.step = 1: unknown key; allowed keys are dt, duration"
    assert message(checks.keys, "", {"colour": "red"}, {"name"}) == "colour = 'red': unknown key; allowed keys are name"
    assert message(checks.keys, "rub[0]", {}, {"node", "clearance"}, required={"node", "clearance"}) == \
        "rub[0].clearance: missing; required"


def test_fail_and_value_formatting():
    assert message(checks.fail, "--speeds", "0:12000", "must be START:STOP:COUNT", "rpm") == \
        "--speeds = '0:12000': must be START:STOP:COUNT (rpm)"
    assert checks.fmt_value(np.float64(0.5)) == "0.5" and checks.fmt_value(np.zeros((2, 3))) == "array of shape (2, 3)"
    long = checks.fmt_value("x" * 200)
    assert len(long) == 80 and long.endswith("...")
    assert checks.join("rub[0]", "clearance") == "rub[0].clearance"
    assert checks.join("spool", "[1]") == "spool[1]" and checks.join("", "dt") == "dt" and checks.join("a", "") == "a"


# --------------------------------------------------------------------------- the error
def test_input_error_attributes_within_and_from_source():
    err = InputError("clearance", -1e-06, "must be >= 0", "m")
    assert isinstance(err, ValueError)
    assert str(err) == "clearance = -1e-06: must be >= 0 (m)"
    inner = err.within("rub[0]")
    assert (inner.field, inner.value, inner.requirement, inner.unit) == \
        ("rub[0].clearance", -1e-06, "must be >= 0", "m")
    assert str(inner.within("")) == "rub[0].clearance = -1e-06: must be >= 0 (m)"
    named = inner.from_source("paper-rub.toml")
    assert named.source == "paper-rub.toml"
    assert str(named) == "paper-rub.toml: rub[0].clearance = -1e-06: must be >= 0 (m)"
    assert str(named.within("scene")) == "paper-rub.toml: scene.rub[0].clearance = -1e-06: must be >= 0 (m)"
    assert str(InputError("rotor", MISSING, "required")) == "rotor: missing; required"
    assert str(InputError("rotor", MISSING, "required").from_source("s.toml")) == "s.toml: rotor: missing; required"


@pytest.mark.parametrize("cls", [InputError, RotorFileError, SceneError, NotCommensurateError])
def test_subclasses_keep_their_type_through_within_and_from_source(cls):
    err = cls("dt", 3e-05, "must divide the period", "s")
    assert isinstance(err, InputError) and isinstance(err, ValueError)
    moved = err.within("solver").from_source("a.toml")
    assert type(moved) is cls
    assert str(moved) == "a.toml: solver.dt = 3e-05: must divide the period (s)"


@pytest.mark.parametrize("err", [
    InputError("rub[0].clearance", -1e-06, "must be >= 0", "m", "paper-rub.toml"),
    RotorFileError("spool[0].elements[1].D_i", 0.03, "must be < D_o = 0.02", "m", "rig.toml"),
    SceneError("output.table", "18:y", "must be a recorded DOF"),
    NotCommensurateError("f_H", 90.33, "must be commensurate with f_L = 69.58 Hz", "Hz"),
    InputError("rotor", MISSING, "required"),
    InputError("x", np.arange(3.0), "must hold finite numbers only"),
], ids=["input", "rotor-file", "scene", "not-commensurate", "missing", "array"])
def test_errors_survive_pickling(err):
    back = pickle.loads(pickle.dumps(err))
    assert type(back) is type(err)
    assert str(back) == str(err)
    assert (back.field, back.requirement, back.unit, back.source) == (err.field, err.requirement, err.unit, err.source)


def test_missing_is_one_object_after_pickling():
    assert pickle.loads(pickle.dumps(MISSING)) is MISSING
    back = pickle.loads(pickle.dumps(InputError("rotor", MISSING, "required")))
    assert back.value is MISSING


def test_errors_from_a_loader_are_input_errors():
    """One ``except InputError`` catches the rotor-file and scene errors."""
    from rotorred.model.rotor_file import rotor_from_toml
    from rotorred.scenes.schema import scene_from_dict

    for call in (lambda: rotor_from_toml("name = 3\n", source="r.toml"),
                 lambda: scene_from_dict({"rotor": {"preset": "seed-rig"}, "speeds": {"inner": -1.0}}, source="s")):
        with pytest.raises(InputError) as info:
            call()
        assert re.match(r"^(r\.toml|s): [a-z]", str(info.value))
