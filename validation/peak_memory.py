"""Peak resident memory of a benchmark's processes, for the scripts of validation/ (bench_sparse.py imports it by
path).

``resource.getrusage(RUSAGE_SELF).ru_maxrss`` is not a process's own peak on Linux: ``exec`` keeps the larger of it
and the peak of the memory map it replaces, which for a child started by :mod:`subprocess` (``vfork``: the child
borrows its parent's map until it execs) is the parent's. A child of a parent that had peaked at 625 MB printed
625 MB while its own peak (``VmHWM``) was 11 MB. Its own is ``VmHWM`` in ``/proc/self/status``: the peak of the
memory map the process has had since its ``exec``.
"""

from __future__ import annotations

import resource
import sys


def own_peak_mb() -> float:
    """This process's peak resident memory (MB) since it was started (``exec``): ``VmHWM`` of ``/proc/self/status``.

    Where there is no ``/proc`` (macOS, BSD), ``ru_maxrss`` instead (kB on Linux and BSD, bytes on macOS), which may
    be its parent's peak (this module's docstring).
    """
    try:
        with open("/proc/self/status", encoding="ascii", errors="replace") as status:
            return next(float(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024.0
    except (OSError, StopIteration, ValueError, IndexError):
        return _mb(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)


def child_peak_mb(usage: resource.struct_rusage) -> float:
    """The peak resident memory (MB) of a child process that has ended, from its ``os.wait4`` ``usage``.

    Its ``ru_maxrss`` is the larger of its own peak and this process's at the child's ``exec`` (the module's
    docstring); this process's peak only grows, so a value above this process's peak now is the child's own.

    Raises
    ------
    RuntimeError
        The value is not above this process's peak: it may be this process's, not the child's.
    """
    child, own = _mb(usage.ru_maxrss), own_peak_mb()
    if child <= own:
        raise RuntimeError(f"the child's peak resident memory ({child:.1f} MB) is not above this process's "
                           f"({own:.1f} MB): it may be this process's peak, carried across exec, not the child's")
    return child


def _mb(maxrss: int) -> float:
    """``ru_maxrss`` in MB: bytes on macOS, kB elsewhere."""
    return maxrss / (2**20 if sys.platform == "darwin" else 1024.0)
