"""numba's on-disk cache of rotorred's compiled functions, kept in step with the code they inline.

numba keys the cache of an ``njit(cache=True)`` function on the stamp of its own source file
only. The step kernel (:mod:`rotorred.transient.kernel`) compiles into itself functions of
other files: the contact law of :mod:`rotorred.transient.contact` and the sympy-generated code
of :mod:`rotorred._generated`. Regenerating ``_generated/contact.py`` would then leave the
cached kernel (keyed on ``kernel.py``) stale, still evaluating the old law.

:func:`register` puts :class:`RotorredCacheLocator` first in numba's list of cache locators.
For a function defined in a file of the rotorred package it returns the source stamp

    (numba's stamp of the function's own file, sha256 of source_files(): _generated/*.py and KERNEL_SOURCES)

so any change of the generated modules or of the kernel's source modules invalidates every
rotorred cache entry (numba then recompiles and overwrites it). Functions of other packages are
left to numba's own locators.

Where the cache lives, first that works: ``NUMBA_CACHE_DIR`` if set; the ``__pycache__`` next to
the source (numba's default); numba's user-wide cache directory (a read-only install); a
``rotorred-numba-<uid>`` directory under the system's temporary directory, announced by one line on
stderr (once per process). A valid cache in a read-only package's ``__pycache__`` is not read (numba
uses a cache folder only where it can write): such an install compiles once per user.
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import tempfile
from pathlib import Path

from numba.core import caching

#: the package directory whose functions this locator serves
PACKAGE = Path(__file__).resolve().parent.parent
#: files (relative to PACKAGE) that numba compiles into rotorred's kernels: every generated
#: module, and every module of rotorred that defines or wraps an njit function
KERNEL_SOURCES = ("transient/contact.py", "transient/contact_solve.py", "transient/kernel.py",
                  "transient/ramp_kernel.py", "transient/eigen_kernel.py", "nonlinear/sampled.py",
                  "nonlinear/forces.py")
GENERATED = "_generated"


def source_files(package: Path = PACKAGE) -> list[Path]:
    """The files of the digest: ``_generated/*.py`` and :data:`KERNEL_SOURCES`, sorted."""
    generated = sorted((package / GENERATED).glob("*.py"))
    return generated + [package / rel for rel in KERNEL_SOURCES]


@functools.lru_cache(maxsize=8)
def _digest_of(package: str, stamps: tuple) -> str:
    h = hashlib.sha256()
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
    """sha256 of the names and contents of :func:`source_files`, re-read when a file's mtime or size changes."""
    return _digest_of(str(package), tuple(_stamp(p, package) for p in source_files(package)))


#: whether the fallback to the temporary directory has been announced in this process
_ANNOUNCED = []


def temp_cache_root() -> str:
    """The last-resort cache folder: ``rotorred-numba-<uid>`` under the system's temporary directory."""
    user = str(os.getuid()) if hasattr(os, "getuid") else "user"
    return os.path.join(tempfile.gettempdir(), f"rotorred-numba-{user}")


class _TempDirLocator(caching.UserWideCacheLocator):
    """Last resort: a per-user directory under the system's temporary directory (announced once on stderr)."""

    def __init__(self, py_func, py_file):
        super().__init__(py_func, py_file)
        self._cache_path = os.path.join(temp_cache_root(), self.get_suitable_cache_subpath(py_file))

    @classmethod
    def from_function(cls, py_func, py_file):
        self = super().from_function(py_func, py_file)
        if self is not None and not _ANNOUNCED:
            _ANNOUNCED.append(True)
            print(f"rotorred: the package folder and numba's user cache are not writable; compiled kernels are "
                  f"cached in {temp_cache_root()} (set NUMBA_CACHE_DIR to choose)", file=sys.stderr)
        return self


#: where the cache of a rotorred function may live, in order of preference
FALLBACKS = (caching.UserProvidedCacheLocator, caching.InTreeCacheLocator, caching.UserWideCacheLocator,
             _TempDirLocator)


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
        return self._inner.get_source_stamp(), source_digest()

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
