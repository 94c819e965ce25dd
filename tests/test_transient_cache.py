"""numba's on-disk cache of rotorred's compiled functions lives in the user's cache folder, never in the package,
follows the generated code and the kernel's sources (rotorred.transient.numba_cache), and falls back to the
temporary folder when the user cache folder is not writable.

Each check runs a copy of the package in fresh subprocesses and calls one small compiled function,
``kernel._normal_law`` (defined in transient/contact.py), which compiles in the generated
``normal_residual`` of _generated/contact.py: numba's own cache key (the stamp of contact.py) would not see
a change of the generated file.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import rotorred
from rotorred.transient import numba_cache

PACKAGE = Path(__file__).resolve().parents[1] / "rotorred"

SNIPPET = """
import json
from rotorred.transient import kernel
r = kernel._normal_law(10.0, 2e-6, 0.01, 5e9, 1.0, 1e-8)
st = kernel._normal_law.stats
print(json.dumps({"R": float(r[0]), "hits": sum(st.cache_hits.values()), "misses": sum(st.cache_misses.values()),
                  "path": st.cache_path}))
"""


@pytest.fixture()
def package_copy(tmp_path):
    """A copy of the rotorred package (without caches) importable from ``tmp_path / "pkg"``."""
    shutil.copytree(PACKAGE, tmp_path / "pkg" / "rotorred", ignore=shutil.ignore_patterns("__pycache__"))
    return tmp_path / "pkg"


def run(root: Path, **env_changes) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "NUMBA_DISABLE_JIT")}
    env.update(PYTHONPATH=str(root), XDG_CACHE_HOME=str(root.parent / "xdg"))
    env.update(env_changes)
    out = subprocess.run([sys.executable, "-c", SNIPPET], cwd=root, env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.splitlines()[-1])


def _cache_files(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.suffix in (".nbi", ".nbc")]


def test_cache_is_reused_and_recompiled_when_the_generated_law_changes(package_copy, tmp_path):
    first = run(package_copy)
    again = run(package_copy)
    assert first["misses"] == 1 and first["hits"] == 0  # compiled into an empty cache
    assert again["hits"] == 1 and again["misses"] == 0 and again["R"] == first["R"]  # unchanged: loaded
    # the user cache folder (XDG_CACHE_HOME on Linux), keyed by the version; nothing written into the package
    assert Path(again["path"]).is_relative_to(tmp_path / "xdg" / "rotorred" / "numba" / rotorred.__version__)
    assert _cache_files(tmp_path / "xdg") and not _cache_files(package_copy)
    for source in numba_cache.source_files(package_copy / "rotorred"):  # a reinstall: new mtimes, same contents
        os.utime(source, ns=(source.stat().st_atime_ns, source.stat().st_mtime_ns + 10**9))
    reinstalled = run(package_copy)
    assert reinstalled["hits"] == 1 and reinstalled["misses"] == 0
    generated = package_copy / "rotorred" / "_generated" / "contact.py"
    text = generated.read_text()
    hertz = "    _t0 = K_nr*s**3.0\n"
    assert text.count(hertz) == 1  # normal_residual: the kernel's and harmonic balance's (compiled twice)
    generated.write_text(text.replace(hertz, "    _t0 = 2.0*K_nr*s**3.0\n", 1))  # twice the kernel's Hertz force
    changed = run(package_copy)
    assert changed["misses"] == 1 and changed["hits"] == 0  # recompiled, not loaded stale
    # R = F - K s^3 (1 + c rate): doubling the Hertz term gives 2 R - F (round-off of 1e-14 N at F = 10 N)
    assert changed["R"] == pytest.approx(2 * first["R"] - 10.0, abs=1e-12) and changed["R"] != first["R"]


def test_two_installs_keep_apart_and_an_upgrade_recompiles(package_copy, tmp_path):
    """A second copy of the package (another venv, or an editable checkout beside an installed one) has its own
    entries in the same user cache folder, and loading one never disturbs the other; a new version recompiles."""
    other = tmp_path / "other"
    shutil.copytree(package_copy, other)
    first, second = run(package_copy), run(other, XDG_CACHE_HOME=str(tmp_path / "xdg"))
    assert first["misses"] == 1 and second["misses"] == 1 and first["path"] != second["path"]
    assert run(package_copy)["hits"] == 1 and run(other, XDG_CACHE_HOME=str(tmp_path / "xdg"))["hits"] == 1
    init = package_copy / "rotorred" / "_version.py"
    init.write_text(init.read_text().replace(f'__version__ = "{rotorred.__version__}"', '__version__ = "99.0"'))
    upgraded = run(package_copy)
    assert upgraded["misses"] == 1 and upgraded["hits"] == 0 and "99.0" in Path(upgraded["path"]).parts


def test_cache_falls_back_when_the_user_cache_is_not_writable(package_copy, tmp_path):
    """With the user cache folder unusable (a file of that name: even root cannot create the folder) the cache goes
    under the temporary folder, and is reused there; the package folder is never written."""
    (tmp_path / "no-xdg").write_text("not a folder")
    (tmp_path / "tmp").mkdir()
    env = dict(XDG_CACHE_HOME=str(tmp_path / "no-xdg"), TMPDIR=str(tmp_path / "tmp"))
    temp, temp_again = run(package_copy, **env), run(package_copy, **env)
    assert Path(temp["path"]).is_relative_to(tmp_path / "tmp") and temp["misses"] == 1
    assert temp_again["hits"] == 1 and temp_again["misses"] == 0 and not _cache_files(package_copy)


def test_digest_covers_every_module_with_compiled_code():
    """Every file whose functions numba compiles is part of the cache's digest: found from the compiled functions
    themselves (every numba dispatcher in every rotorred module, by the file of its Python function: contact.py's laws
    are compiled in contact_solve.py), and by the text ``njit(``."""
    import importlib
    import inspect

    from numba.core.dispatcher import Dispatcher

    digest = {p.resolve() for p in numba_cache.source_files()}
    compiled = {p.resolve() for p in PACKAGE.rglob("*.py") if re.search(r"\bnjit\(", p.read_text())}
    compiled.discard((PACKAGE / "transient" / "numba_cache.py").resolve())  # describes njit, compiles nothing
    for path in PACKAGE.rglob("*.py"):
        name = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
        if name.startswith("rotorred.plots._"):  # the figure pool's fork-server preloads: nothing compiled there
            continue
        module = importlib.import_module(name)
        compiled |= {Path(inspect.getfile(d.py_func)).resolve() for d in vars(module).values()
                     if isinstance(d, Dispatcher)}
    assert (PACKAGE / "transient" / "contact.py").resolve() in compiled  # the case the text search missed
    assert compiled <= digest, sorted(map(str, compiled - digest))
    assert set((PACKAGE / "_generated").glob("*.py")) <= {p for p in numba_cache.source_files()}


def test_a_function_numba_cannot_cache_is_warned_about_not_crashed_on():
    """numba's check that a compiled result can be cached warns with the locator's ``_py_file``; without it a
    function numba declines to cache (it happened at NUMBA_OPT=0: "uses dynamic globals") raised AttributeError."""
    import warnings
    from types import SimpleNamespace

    from numba.core import caching
    from numba.core.errors import NumbaWarning

    from rotorred.transient import kernel

    impl = caching.CompileResultCacheImpl(kernel._matvec.py_func)
    assert isinstance(impl.locator, numba_cache.RotorredCacheLocator)
    uncachable = SimpleNamespace(lifted=(), library=SimpleNamespace(has_dynamic_globals=True),
                                 fndesc=SimpleNamespace(qualname="_matvec"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert impl.check_cachable(uncachable) is False
    assert [w for w in caught if issubclass(w.category, NumbaWarning) and "Cannot cache" in str(w.message)]
    assert impl.locator._py_file == kernel.__file__

