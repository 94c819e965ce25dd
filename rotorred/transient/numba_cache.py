"""numba's on-disk cache of rotorred's compiled functions: in the user's cache folder, kept in step with the code.

**Where.** Never inside the installed package: a cache written into ``site-packages/rotorred/__pycache__`` outlives
``pip uninstall`` (pip removes the files it installed, not the ones a run wrote), and the folder left behind then
shadows an editable install of the same package (``import rotorred._generated.tapered`` fails). The cache lives in
the first of these that can be written:

1. ``NUMBA_CACHE_DIR``, if set (numba's own setting);
2. :func:`user_cache_root`: ``<user cache folder>/numba/<rotorred version>``, the user cache folder from
   :mod:`platformdirs` (``~/.cache/rotorred`` on Linux, ``~/Library/Caches/rotorred`` on macOS,
   ``%LOCALAPPDATA%\\rotorred\\Cache`` on Windows; ``XDG_CACHE_HOME`` moves it on Linux);
3. :func:`temp_cache_root`: ``rotorred-numba-<user>`` under the system's temporary folder (a read-only home),
   announced by a logging warning (once per process).

Inside it, numba's layout: one sub-folder per source folder (its name and a hash of its absolute path), so two
installs of rotorred (a venv's and an editable checkout) never share or overwrite each other's entries.

**When it is stale.** numba keys the cache of an ``njit(cache=True)`` function on the stamp (modification time and
size) of its own source file only. The step kernel (:mod:`rotorred.transient.kernel`) compiles into itself
functions of other files: the contact law of :mod:`rotorred.transient.contact` and the sympy-generated code of
:mod:`rotorred._generated`.
:func:`register` puts :class:`RotorredCacheLocator` first in numba's list of cache locators. For a function
defined in a file of the rotorred package it returns the source stamp

    ("rotorred sources", sha256 of the rotorred version and of the contents of source_files())

which covers the function's own file (a test checks that every module with compiled code is in
:func:`source_files`). An upgrade, a regeneration of the generated modules or an edit of any of those files
invalidates every rotorred cache entry (numba then recompiles and overwrites it, in place); reinstalling the same
files (``pip install .`` again: new modification times, the same contents) does not.
"""

from __future__ import annotations

import functools
import hashlib
import logging
import os
import tempfile
from pathlib import Path

from numba.core import caching

from rotorred._version import __version__

#: the package directory whose functions this locator serves
PACKAGE = Path(__file__).resolve().parent.parent
#: files (relative to PACKAGE) that numba compiles into rotorred's kernels: every generated
#: module, and every module of rotorred that defines or wraps an njit function
KERNEL_SOURCES = ("transient/contact.py", "transient/contact_solve.py", "transient/kernel.py",
                  "transient/ramp_kernel.py", "transient/eigen_kernel.py", "nonlinear/sampled.py",
                  "nonlinear/forces.py", "transient/status.py",
                  "nonlinear/torus_krylov.py", "nonlinear/torus_toeplitz.py")
GENERATED = "_generated"


def source_files(package: Path = PACKAGE) -> list[Path]:
    """The files of the digest: ``_generated/*.py`` and :data:`KERNEL_SOURCES`, sorted."""
    generated = sorted((package / GENERATED).glob("*.py"))
    return generated + [package / rel for rel in KERNEL_SOURCES]


@functools.lru_cache(maxsize=8)
def _digest_of(package: str, stamps: tuple) -> str:
    h = hashlib.sha256(__version__.encode())
    for rel, mtime_ns, _size in stamps:
        h.update(rel.encode())
        h.update((Path(package) / rel).read_bytes() if mtime_ns is not None else b"<missing>")
    return h.hexdigest()


def _stamp(path: Path, package: Path) -> tuple:
    try:
        st = path.stat()
        return path.relative_to(package).as_posix(), st.st_mtime_ns, st.st_size
    except OSError:  # not on disk (a zipped install): numba's own stamp of the function's file still applies
        return path.relative_to(package).as_posix(), None, None


def source_digest(package: Path = PACKAGE) -> str:
    """sha256 of the rotorred version and of the names and contents of :func:`source_files`, re-read when a file's
    mtime or size changes."""
    return _digest_of(str(package), tuple(_stamp(p, package) for p in source_files(package)))


def user_cache_root() -> str:
    """The cache folder of compiled kernels: ``numba/<rotorred version>`` in the user cache folder of
    :func:`platformdirs.user_cache_dir` (``~/.cache/rotorred`` on Linux)."""
    import platformdirs

    return os.path.join(platformdirs.user_cache_dir("rotorred", appauthor=False), "numba", __version__)


def temp_cache_root() -> str:
    """The last-resort cache folder: ``rotorred-numba-<user>`` under the system's temporary folder."""
    user = str(os.getuid()) if hasattr(os, "getuid") else os.environ.get("USERNAME", "user")
    return os.path.join(tempfile.gettempdir(), f"rotorred-numba-{user}")


#: whether the fallback to the temporary folder has been announced in this process
_ANNOUNCED = []


class _FolderLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """A function's cache in ``root()/<numba's sub-folder for its source folder>`` (None if it cannot be written)."""

    @staticmethod
    def root() -> str:
        raise NotImplementedError

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(self.root(), self.get_suitable_cache_subpath(py_file))

    def get_cache_path(self):
        return self._cache_path


class _UserCacheLocator(_FolderLocator):
    """The user cache folder (:func:`user_cache_root`)."""

    root = staticmethod(user_cache_root)


class _TempDirLocator(_FolderLocator):
    """Last resort: a per-user folder under the system's temporary folder (announced once on stderr)."""

    root = staticmethod(temp_cache_root)

    @classmethod
    def from_function(cls, py_func, py_file):
        self = super().from_function(py_func, py_file)
        if self is not None and not _ANNOUNCED:
            _ANNOUNCED.append(True)
            logging.getLogger(__name__).warning(
                "the user cache folder %s is not writable; compiled kernels are cached in %s (set NUMBA_CACHE_DIR "
                "to choose)", user_cache_root(), temp_cache_root())
        return self


#: where the cache of a rotorred function may live, in order of preference; never the package's own folder
FALLBACKS = (getattr(caching, "UserProvidedCacheLocator", None) or caching._UserProvidedCacheLocator,  # numba 0.58-0.61
             _UserCacheLocator, _TempDirLocator)


class RotorredCacheLocator(caching._CacheLocator):
    """numba cache locator for rotorred's files: the first usable place of :data:`FALLBACKS`, with the
    source stamp extended by :func:`source_digest`."""

    def __init__(self, inner: caching._CacheLocator):
        self._inner = inner

    def ensure_cache_path(self):
        self._inner.ensure_cache_path()

    def get_cache_path(self):
        return self._inner.get_cache_path()

    def get_source_stamp(self):
        return "rotorred sources", source_digest()

    def get_disambiguator(self):
        return self._inner.get_disambiguator()

    @property
    def _py_file(self):
        """The function's source file (numba reads it to warn that a function cannot be cached)."""
        return self._inner._py_file

    @classmethod
    def from_function(cls, py_func, py_file):
        try:
            Path(py_file).resolve().relative_to(PACKAGE)
        except (ValueError, OSError):
            return None  # not rotorred's: numba's own locators decide
        for fallback in FALLBACKS:
            inner = fallback.from_function(py_func, py_file)
            if inner is not None:
                return cls(inner)
        return None


def register() -> None:
    """Put :class:`RotorredCacheLocator` first in numba's cache locators (idempotent).

    Call it before any ``njit(cache=True)`` decoration of a rotorred module: numba picks the locator
    of a function when the function is decorated.
    """
    impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
    if RotorredCacheLocator not in impl._locator_classes:
        impl._locator_classes.insert(0, RotorredCacheLocator)
