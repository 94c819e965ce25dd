"""validation/peak_memory.py: a subprocess's peak memory is its own, not its parent's (ru_maxrss carries it)."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from validation_scripts import ROOT, load_validation

pytestmark = pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="VmHWM is Linux's")

#: a child that prints its own peak (MB) by validation/peak_memory.py
CHILD = ("import importlib.util as u, sys; s = u.spec_from_file_location('pm', sys.argv[1]); m = u.module_from_spec(s); "
         "s.loader.exec_module(m); print(m.own_peak_mb())")


def test_a_subprocess_reports_its_own_peak_not_its_parents():
    """A child of a process that peaked at 300 MB or more: ru_maxrss printed the parent's peak (on main,
    bench_sparse's worker printed 1229.5 MB after its parent's 1.2 GB, its own 87.7); own_peak_mb prints the child's
    own, a bare interpreter's (about 10 MB)."""
    pm = load_validation("peak_memory")
    big = np.ones(300 * 2**20 // 8)  # touched: resident
    del big
    parent = pm.own_peak_mb()
    done = subprocess.run([sys.executable, "-c", CHILD, str(ROOT / "validation" / "peak_memory.py")],
                          capture_output=True, text=True, check=True)
    child = float(done.stdout)
    assert parent >= 300 and child < 60, (parent, child)
    with pytest.raises(RuntimeError, match="may be this process's peak"):
        child_of = subprocess.Popen([sys.executable, "-c", "pass"])
        pm.child_peak_mb(os.wait4(child_of.pid, 0)[2])  # a small child's wait4 ru_maxrss: this process's peak
