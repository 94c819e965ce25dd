"""The package's architecture: layers, import direction, no cycles, matplotlib confined, short functions.

The import graph is read from the source (every ``import`` and ``from ... import`` statement,
module-level or inside a function), so a lazy import counts like any other.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "rotorred"

#: the layers, bottom first; a module may import modules of its own layer package or of a lower layer
LAYERS = {
    "rotorred.checks": 0, "rotorred.writers": 0, "rotorred.progress": 0, "rotorred._version": -1,
    "rotorred.provenance": 0, "rotorred._generated": 0, "rotorred.results": 0,
    "rotorred.model": 1,
    "rotorred.linear": 2, "rotorred.signals": 2,
    "rotorred.transient": 3,
    "rotorred.nonlinear": 4,
    "rotorred.plots": 5,
    "rotorred.scenes": 6,
    "rotorred.maps": 7,
    "rotorred.cli": 8,
    # the public API (rotorred/__init__.py: the names of rotorred.__all__, loaded on first use), which the CLI, its
    # first client, imports: above every layer it exports from, below the CLI
    "rotorred": 7.5,
}
#: where matplotlib may be imported
MATPLOTLIB_ALLOWED = ("rotorred.plots", "rotorred.cli")
#: the plotting libraries confined there
PLOTTING = ("matplotlib", "plotly")
#: longest function allowed (lines of body, docstring excluded), and the compiled step loop's limit
MAX_FUNCTION_LINES = 80
MAX_KERNEL_LOOP_LINES = 150
KERNEL_LOOP = "rotorred.transient.kernel.run_steps"


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, ast.Module]:
    return {_module_name(p): ast.parse(p.read_text(), filename=str(p)) for p in sorted(PACKAGE.rglob("*.py"))}


MODULES = _modules()


#: the one upward import allowed: a result's ``plot`` method imports its drawing from rotorred.plots when called
#: (rotorred.results.Result), as xarray's ``.plot`` does, so that a result never loads matplotlib until it is drawn;
#: ``view``, its interactive (plotly) counterpart, likewise
PLOT_METHOD = "plot"
PLOT_METHODS = (PLOT_METHOD, "view")


def _plot_method_imports(tree: ast.Module) -> set[int]:
    """ids of the import statements inside a method named ``plot`` that import from rotorred.plots."""
    out = set()
    for cls in (n for n in ast.walk(tree) if isinstance(n, ast.ClassDef)):
        for fn in cls.body:
            if isinstance(fn, ast.FunctionDef) and fn.name in PLOT_METHODS:
                out |= {id(n) for n in ast.walk(fn) if isinstance(n, ast.ImportFrom)
                        and (n.module or "").startswith("rotorred.plots")}
    return out


def _imports(name: str, tree: ast.Module) -> set[str]:
    """Absolute names of every module ``name`` imports (relative imports resolved), but a result's ``plot`` method's
    import of its drawing (:data:`PLOT_METHOD`)."""
    package = name if (PACKAGE.parent / Path(*name.split(".")) / "__init__.py").exists() else name.rpartition(".")[0]
    out = set()
    allowed = _plot_method_imports(tree)
    for node in ast.walk(tree):
        if id(node) in allowed:
            continue
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parent + ([base] if base else []))
            submodules = {f"{base}.{a.name}" for a in node.names if f"{base}.{a.name}" in MODULES}
            out |= submodules
            if len(submodules) < len(node.names):  # some names are attributes of the module `base` itself
                out.add(base)
    return out


def _layer(module: str) -> tuple[str, int]:
    best = max((k for k in LAYERS if module == k or module.startswith(k + ".")), key=len)
    return best, LAYERS[best]


GRAPH = {m: {i for i in _imports(m, t) if i in MODULES and i != m} for m, t in MODULES.items()}


def test_every_module_has_a_layer():
    assert all(_layer(m)[0] != "rotorred" or m == "rotorred" for m in MODULES), \
        [m for m in MODULES if _layer(m)[0] == "rotorred" and m != "rotorred"]


def test_imports_point_downwards():
    bad = []
    for m, deps in GRAPH.items():
        pkg, rank = _layer(m)
        for d in deps:
            dpkg, drank = _layer(d)
            if dpkg != pkg and drank >= rank:
                bad.append(f"{m} ({pkg}, layer {rank}) imports {d} ({dpkg}, layer {drank})")
    assert not bad, "\n".join(bad)


def test_the_checker_sees_an_upward_import():
    """The rule above can fail: a linear module importing plots is reported."""
    tree = ast.parse("from rotorred.plots.campbell import plot_campbell\n")
    deps = {i for i in _imports("rotorred.linear.campbell", tree) if i in MODULES}
    assert "rotorred.plots.campbell" in deps and _layer("rotorred.plots.campbell")[1] > _layer("rotorred.linear")[1]


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles():
    assert _cycles(GRAPH) == []


def test_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_matplotlib_only_in_plots_and_cli():
    bad = [m for m, t in MODULES.items()
           if any(i.split(".")[0] in PLOTTING for i in _imports(m, t))
           and not m.startswith(MATPLOTLIB_ALLOWED)]
    assert not bad, bad


def test_import_rotorred_loads_neither_matplotlib_nor_numba():
    code = ("import sys, time; t = time.perf_counter(); import rotorred; dt = time.perf_counter() - t; "
            "assert 'matplotlib' not in sys.modules and 'numba' not in sys.modules, sorted(sys.modules); "
            "print(dt)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    print(f"import rotorred: {1e3 * float(out.stdout):.1f} ms")


def test_public_api_resolves():
    import rotorred

    for name in rotorred.__all__:
        assert getattr(rotorred, name) is not None, name
    with pytest.raises(AttributeError, match="no attribute 'nonexistent'"):
        rotorred.nonexistent  # noqa: B018


def _function_lengths():
    """(qualified name, body lines without docstring) of every function outside _generated/."""
    for m, tree in MODULES.items():
        if m.startswith("rotorred._generated"):
            continue
        stack = [(tree, m)]
        while stack:
            node, prefix = stack.pop()
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                    name = f"{prefix}.{child.name}"
                    stack.append((child, name))
                    if isinstance(child, ast.ClassDef):
                        continue
                    body = child.body
                    if body and isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None),
                                                                              ast.Constant):
                        body = body[1:]
                    if body:
                        yield name, body[-1].end_lineno - body[0].lineno + 1


def test_functions_are_short():
    lengths = dict(_function_lengths())
    too_long = {n: k for n, k in lengths.items()
                if k > (MAX_KERNEL_LOOP_LINES if n == KERNEL_LOOP else MAX_FUNCTION_LINES)}
    longest = sorted(lengths.items(), key=lambda kv: -kv[1])[:5]
    print("longest functions:", longest)
    assert not too_long, too_long


def test_only_a_plot_method_may_import_its_drawing_upwards():
    """A result's ``plot`` method importing rotorred.plots is allowed; the same import elsewhere is reported."""
    method = ast.parse("class R:\n    def plot(self, ax=None):\n        from rotorred.plots.campbell import plot_campbell\n")
    other = ast.parse("class R:\n    def draw(self, ax=None):\n        from rotorred.plots.campbell import plot_campbell\n")
    assert not {i for i in _imports("rotorred.linear.campbell", method) if i in MODULES}
    assert "rotorred.plots.campbell" in _imports("rotorred.linear.campbell", other)
