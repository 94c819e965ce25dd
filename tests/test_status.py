"""One enumeration of the compiled loops' status codes (rotorred.transient.status): distinct codes, one message each,
and no kernel with codes of its own."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from rotorred.transient import status
from rotorred.transient.status import Status

TRANSIENT = Path(status.__file__).parent
#: the modules of the compiled loops and their helpers
KERNELS = ("kernel.py", "eigen_kernel.py", "ramp_kernel.py", "contact_solve.py")
CODES = {name: getattr(status, name) for name in status.__all__ if name.isupper()}


def test_every_code_is_distinct_and_mirrored_by_the_enum():
    assert len(set(CODES.values())) == len(CODES) == 7
    assert all(type(code) is int for code in CODES.values())  # numba reads them as constants
    assert {m.name: m.value for m in Status} == CODES
    assert status.RUNNING == 0  # a finished run (TransientResult.status)


def test_each_code_has_its_own_message():
    messages = [Status(code).message for code in CODES.values()]
    assert len(set(messages)) == len(messages) and all(messages)
    assert Status(status.NONFINITE).message == "a non-finite value"
    assert Status(status.NEWTON_FAILED).message == "the contact Newton iteration failed"
    assert Status(status.LIMIT).message == "a contact-node displacement beyond `displacement_limit`"
    assert Status(status.PASSES_FAILED).message == "the step at varying speed did not converge"
    with pytest.raises(ValueError):
        Status(len(CODES))


def _status_literals(tree: ast.Module) -> list[str]:
    """Where a module writes a status code as a number: a status name defined at module level, a literal assigned to
    ``status`` or to ``...[E_STATUS]``, compared with ``status``, or returned by a function returning status names."""
    found = []
    for node in tree.body:
        if isinstance(node, ast.Assign):
            names = [t.id for t in node.targets if isinstance(t, ast.Name)]
            names += [e.id for t in node.targets if isinstance(t, ast.Tuple) for e in t.elts if isinstance(e, ast.Name)]
            found += [f"line {node.lineno}: defines {n}" for n in names if n in CODES]

    def literal(value) -> bool:
        return isinstance(value, ast.Constant) and isinstance(value.value, int) and not isinstance(value.value, bool)

    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and literal(node.value):
            for target in node.targets:
                if isinstance(target, ast.Name) and target.id == "status":
                    found.append(f"line {node.lineno}: status = {node.value.value}")
                if isinstance(target, ast.Subscript) and isinstance(target.slice, ast.Name) \
                        and target.slice.id == "E_STATUS":
                    found.append(f"line {node.lineno}: [E_STATUS] = {node.value.value}")
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(isinstance(s, ast.Name) and s.id == "status" for s in sides) and any(map(literal, sides)):
                found.append(f"line {node.lineno}: status compared with a number")
        if isinstance(node, ast.FunctionDef):
            returns = [r.value for r in ast.walk(node) if isinstance(r, ast.Return) and r.value is not None]
            if any(isinstance(v, ast.Name) and v.id in CODES for v in returns):
                found += [f"line {v.lineno}: {node.name} returns {v.value}" for v in returns if literal(v)]
    return found


@pytest.mark.parametrize("module", KERNELS + ("newmark.py", "ramp.py", "results.py", "stepping.py"))
def test_no_module_has_status_numbers_of_its_own(module):
    tree = ast.parse((TRANSIENT / module).read_text(encoding="utf-8"))
    assert _status_literals(tree) == []


def test_the_check_finds_the_old_forms():
    """The forms the kernels had before the shared enumeration are found (the test above can fail)."""
    old = ("PASSES_FAILED = 5\nRUNNING, DONE, NONFINITE = 0, 1, 2\n"
           "def f(diag):\n    status = 0\n    diag.err[E_STATUS] = 4\n    if status == 5:\n        return RUNNING\n"
           "    return 5\n")
    assert len(_status_literals(ast.parse(old))) == 7


@pytest.mark.parametrize("module", KERNELS)
def test_kernels_take_their_codes_from_the_status_module(module):
    tree = ast.parse((TRANSIENT / module).read_text(encoding="utf-8"))
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and n.id in CODES}
    imported = {a.name for n in tree.body if isinstance(n, ast.ImportFrom) and n.module == "rotorred.transient.status"
                for a in n.names}
    assert used <= imported
