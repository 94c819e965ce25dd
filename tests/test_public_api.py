"""The public API: what ``rotorred.__all__`` reaches, what the CLI imports, and how public functions are shaped.

The CLI is the API's first client (issue 35): every ``rotorred/cli`` module imports rotorred only through names
in ``rotorred.__all__`` (and the CLI's own modules), so whatever a command does, a script can do with the same
names. Public functions and methods take at most :data:`MAX_PARAMETERS` parameters, grouping the rest in small
frozen option types.
"""

from __future__ import annotations

import ast
import re
import inspect
from pathlib import Path


import rotorred as rr

CLI = Path(rr.__file__).parent / "cli"
#: most parameters of a public function or method (self and cls not counted)
MAX_PARAMETERS = 10


def _rotorred_imports(path: Path) -> list[tuple[int, str, str]]:
    """(line, module, name) of every import of rotorred in a file: ``from rotorred.x import y`` gives (x, y),
    ``from rotorred import y`` gives ("rotorred", y), ``import rotorred.x`` gives (x, "")."""
    out = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "rotorred":
            out += [(node.lineno, node.module, a.name) for a in node.names]
        elif isinstance(node, ast.Import):
            out += [(node.lineno, a.name, "") for a in node.names if a.name.split(".")[0] == "rotorred"]
    return out


def _outside_the_api(path: Path) -> list[str]:
    bad = []
    for line, module, name in _rotorred_imports(path):
        if module == "rotorred.cli" or module.startswith("rotorred.cli."):
            continue  # the CLI's own modules
        if module == "rotorred" and (name in rr.__all__ or name == "__version__"):
            continue
        bad.append(f"{path.name}:{line}: from {module} import {name}" if name else f"{path.name}:{line}: import {module}")
    return bad


def test_the_cli_imports_rotorred_only_through_its_public_names():
    bad = [b for p in sorted(CLI.glob("*.py")) for b in _outside_the_api(p)]
    assert not bad, "the CLI reaches past rotorred.__all__:\n" + "\n".join(bad)


def test_the_import_check_sees_a_private_import(tmp_path):
    """The check above can fail: a private module, and a name of rotorred that is not public, are reported."""
    f = tmp_path / "x.py"
    f.write_text("from rotorred.linear.campbell import campbell\nfrom rotorred import _EXPORTS\n"
                 "from rotorred import Operating\nfrom rotorred.cli.options import out_dir\n")
    assert _outside_the_api(f) == ["x.py:1: from rotorred.linear.campbell import campbell",
                                   "x.py:2: from rotorred import _EXPORTS"]


def _public_callables():
    """(qualified name, function) of every public function and every public method of a public class."""
    for name in rr.__all__:
        obj = getattr(rr, name)
        if inspect.isfunction(obj):
            yield name, obj
        elif inspect.isclass(obj):
            for attr, member in vars(obj).items():
                if attr.startswith("_"):
                    continue
                if isinstance(member, (staticmethod, classmethod)):
                    member = member.__func__
                if inspect.isfunction(member):
                    yield f"{name}.{attr}", member


def _parameters(f) -> list[inspect.Parameter]:
    return [p for p in inspect.signature(f).parameters.values()
            if p.name not in ("self", "cls") and p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)]


def test_no_public_function_or_method_takes_more_than_ten_parameters():
    counts = {name: len(_parameters(f)) for name, f in _public_callables()}
    assert len(counts) > 100  # the introspection reaches the API
    over = {name: n for name, n in counts.items() if n > MAX_PARAMETERS}
    assert not over, over


def test_the_parameter_count_sees_a_long_signature():
    def long(a, b, c, d, e, f, g, h, i, j, k):  # noqa: E741
        pass
    assert len(_parameters(long)) == 11 > MAX_PARAMETERS


# --------------------------------------------------------------------------- docstrings: the API reference
def _sections(doc: str) -> dict[str, list[str]]:
    """numpydoc sections of a docstring: {"Parameters": lines, "Returns": lines, ...}, the summary under "summary"."""
    lines, out, current, i = inspect.cleandoc(doc or "").splitlines(), {}, "summary", 0
    while i < len(lines):
        if i + 1 < len(lines) and lines[i].strip() and set(lines[i + 1].strip()) == {"-"} \
                and len(lines[i + 1].strip()) >= 3:
            current, i = lines[i].strip(), i + 2
            out[current] = []
            continue
        out.setdefault(current, []).append(lines[i])
        i += 1
    return out


def _entries(section: list[str]) -> dict[str, str]:
    """``name : type`` entries of a section (``a, b : float`` gives both), name -> the type and description."""
    out, current = {}, []
    for line in section:
        if line and not line.startswith(" "):
            head, _, kind = line.partition(" : ")
            current = [n.strip().lstrip("*") for n in head.split(",")]
            for n in current:
                out[n] = kind
        else:
            for n in current:
                out[n] += " " + line.strip()
    return out


def _documentation_gaps(name: str, f) -> list[str]:
    doc = f.__doc__ or ""
    if not doc.strip():
        return [f"{name}: no docstring"]
    params = [p.name for p in _parameters(f)]
    if not params:
        return []
    documented = _entries(_sections(doc).get("Parameters", []))
    gaps = [f"{name}: parameter {p!r} not in its Parameters section" for p in params if p not in documented]
    gaps += [f"{name}: array parameter {p!r} gives no shape" for p, text in documented.items()
             if p in params and ("ndarray" in text or "array_like" in text) and "shape" not in text]
    return gaps


def test_every_public_callable_has_a_numpydoc_docstring_with_its_parameters_and_array_shapes():
    gaps = [g for name, f in _public_callables() for g in _documentation_gaps(name, f)]
    gaps += [f"{name}: no docstring" for name in rr.__all__
             if inspect.isclass(getattr(rr, name)) and not (getattr(rr, name).__doc__ or "").strip()]
    assert not gaps, "\n".join(gaps)


def test_the_docstring_check_sees_a_gap():
    def f(x, y):
        """Sum.

        Parameters
        ----------
        x : ndarray
            A vector.
        """
    assert _documentation_gaps("f", f) == ["f: parameter 'y' not in its Parameters section",
                                           "f: array parameter 'x' gives no shape"]


# --------------------------------------------------------------------------- result types
def _result_types() -> list[type]:
    from rotorred.results import Result

    return [getattr(rr, n) for n in rr.__all__
            if inspect.isclass(getattr(rr, n)) and issubclass(getattr(rr, n), Result) and getattr(rr, n) is not Result]


def test_every_exported_result_type_shows_itself_and_is_checked():
    """Each exported result type gives its own summary, plot and dataset, keeps Result's short repr (a dataclass
    declared ``repr=False``), and is checked by ``assert_shows_itself`` in a test module: a repr of at
    most 15 lines without arrays, a Figure from plot(), to_xarray() through NetCDF with units on every variable."""
    from rotorred.results import Result

    types = _result_types()
    assert len(types) >= 15
    shown = "".join(p.read_text() for p in Path(__file__).parent.glob("test_*.py") if p.name != Path(__file__).name)
    problems = []
    for cls in types:
        for method in ("summary", "plot", "to_xarray"):
            if getattr(cls, method) is getattr(Result, method):
                problems.append(f"{cls.__name__}.{method} is Result's (not implemented)")
        if cls.__repr__ is not Result.__repr__:
            problems.append(f"{cls.__name__} has its own __repr__ (a dataclass without repr=False?)")
        if not re.search(rf"assert_shows_itself\([^\n]*of=rr\.{cls.__name__}\b", shown):
            problems.append(f"{cls.__name__} is not checked by assert_shows_itself(..., of=rr.{cls.__name__})")
    assert not problems, "\n".join(problems)


# --- the CLI keeps its units and names them in every option's help (issue 35, Build 1) ------------------------------
#: options whose values carry no physical unit: counts, names, paths, DOFs, ratios, tolerances, choices
UNITLESS = {"--out", "--ratio", "--reference", "--reference-spool", "--modes", "--harmonics", "--samples", "--tol",
            "--model", "--boundary-nodes", "--refine", "--outputs", "--frf", "--reduce", "--direction", "--workers",
            "--scheduler"}
#: a unit named in a help text: a parenthesised or spelled-out SI or CLI unit
UNIT = re.compile(r"(?<![\w'])(rpm|Hz|rad/s|s|m|µm|kg m|N/m|degrees|deg)(?![\w'/])|scene units")


def _value_options():
    import argparse

    from rotorred.cli import build_parser

    for action in build_parser()._actions:
        if isinstance(action, argparse._SubParsersAction):
            for command, sub in action.choices.items():
                for option in sub._actions:
                    if option.option_strings and option.nargs != 0 and not isinstance(option, argparse._HelpAction):
                        yield command, option


def test_every_cli_option_with_a_physical_value_names_its_unit_in_its_help():
    """Every option of every command that takes a value is either unitless (listed above) or names its unit in its
    help (rpm, Hz, s, m, kg m, degrees, or the scene units of a scene key)."""
    checked, missing = 0, []
    for command, option in _value_options():
        name = option.option_strings[-1]
        if name in UNITLESS:
            continue
        checked += 1
        if not UNIT.search(option.help or ""):
            missing.append(f"{command} {name}: {option.help!r}")
    assert checked >= 12 and not missing, missing


def test_the_unit_check_can_fail():
    """The unit pattern finds no unit in a help that names none, and finds the scene units and rpm."""
    assert not UNIT.search("simulate a point that has not settled up to this time (default: the scene's duration)")
    assert UNIT.search("reference-spool speeds in rpm") and UNIT.search("fix a scene key (scene units: Hz ...)")
