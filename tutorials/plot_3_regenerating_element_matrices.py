"""
Regenerating the element matrices
=================================

rotorred's shaft-element matrices are not typed in: they are derived by sympy from shape functions and energy
integrals (``derivations/``) and written as Python code into ``rotorred/_generated/``. This tutorial checks that
the checked-in code is what the derivation gives, then, in a copy of the sources in a temporary folder (never
the repository's files), changes one term of the strain energy, regenerates the code, reads the change in the
generated source and sees it move a Campbell diagram.
"""

# %%
# Checking the generated code
# ---------------------------
# ``python -m derivations`` writes every generated module and ``python -m derivations --check`` exits 1 when a
# checked-in module differs from a fresh derivation (a test runs it; all four modules take about a minute, the
# internal-damping and tapered elements most of it). Here the same check for the Timoshenko element, the module
# this tutorial changes: the derivation's text against the file in the installed package.
import difflib
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import derivations
import rotorred as rr
from derivations import TARGETS

relative, derive = next((rel, fn) for rel, fn in TARGETS if rel.endswith("timoshenko.py"))
start = time.perf_counter()
fresh = derive()
installed = Path(rr.__file__).parent / "_generated" / "timoshenko.py"
print(f"{relative}: derived in {time.perf_counter() - start:.1f} s, "
      f"{'current' if fresh == installed.read_text() else 'STALE: run python -m derivations'}")

# %%
# The term to change
# ------------------
# The strain energy of the element (``derivations/timoshenko.py``) is bending plus shear,
# ``U = 1/2 ∫ [EI (ψ'²) + κGA (γ²)] dz``, with κGA written through the shear parameter φ = 12 EI / (κGA L²):
source = Path(derivations.__file__).parent / "timoshenko.py"
line = next(ln for ln in source.read_text().splitlines() if ln.strip().startswith("kGA ="))
print(line.strip())

# %%
# Copy the derivations and the package into a temporary folder and halve the shear term there: the shear strain
# energy of an element with half the shear stiffness κGA (the interpolation keeps its φ, so this is a
# deliberately inconsistent element: an experiment, not a model).
work = Path(tempfile.mkdtemp(prefix="rotorred-derivations-"))
skip = shutil.ignore_patterns("__pycache__", "*.pyc")
shutil.copytree(Path(derivations.__file__).parent, work / "derivations", ignore=skip)
shutil.copytree(Path(rr.__file__).parent, work / "rotorred", ignore=skip)
copy = work / "derivations" / "timoshenko.py"
copy.write_text(copy.read_text().replace("kGA = 12 * E * I / (phi * L**2)",
                                         "kGA = 6 * E * I / (phi * L**2)  # the shear term halved"))

# %%
# Regenerate in the copy
# ----------------------
# In a new process whose import path starts with the copy, derive the Timoshenko module and write it into the
# copy's ``rotorred/_generated/`` (``python -m derivations --root <copy>`` does this for every module).
env = {**os.environ, "PYTHONPATH": str(work)}
regenerate = ("import pathlib, derivations.timoshenko as t; "
              "pathlib.Path('rotorred/_generated/timoshenko.py').write_text(t.module_text()); "
              "print('derived by', t.__file__)")
print(subprocess.run([sys.executable, "-c", regenerate], cwd=work, env=env, check=True, capture_output=True,
                     text=True).stdout.strip())

# %%
# What changed in the generated code: the stiffness matrix's shear part, nothing else.
new = (work / "rotorred" / "_generated" / "timoshenko.py").read_text().splitlines()
diff = list(difflib.unified_diff(installed.read_text().splitlines(), new, "installed", "regenerated", n=0, lineterm=""))
changed = [ln for ln in diff if ln.startswith(("+", "-")) and not ln.startswith(("+++", "---"))]
print(f"{len(changed)} lines differ; the first ones:")
print("\n".join(ln[:150] for ln in diff[:9]))

# %%
# A Campbell diagram with the changed element
# -------------------------------------------
# The copy's ``rotorred`` imports the regenerated module. A new process computes the rig's Campbell diagram with
# it and hands the whirl frequencies back through a file; this process computes the original.
speeds = np.linspace(0.0, 12000.0, 41)
campbell = ("import numpy as np, rotorred as rr; "
            "cd = rr.campbell(rr.load_rotor('seed-rig'), rr.Operating.line(np.linspace(0.0, 12000.0, 41), "
            "unit='rpm'), n_modes=10); "
            "np.savez('campbell.npz', f=cd.frequencies_hz, c=[c.speed_rpm for c in cd.critical_speeds]); "
            "print('rotorred from', rr.__file__)")
print(subprocess.run([sys.executable, "-c", campbell], cwd=work, env=env, check=True, capture_output=True,
                     text=True).stdout.strip())
changed_cd = np.load(work / "campbell.npz")
original = rr.campbell(rr.load_rotor("seed-rig"), rr.Operating.line(speeds, unit="rpm"), n_modes=10)

f0, f1 = original.frequencies_hz[0], changed_cd["f"][0]
for k in range(8):
    print(f"mode {k + 1} at rest: {f0[k]:7.2f} Hz -> {f1[k]:7.2f} Hz ({100 * (f1[k] / f0[k] - 1):+.2f} %)")
print("first critical speeds (rpm):", np.round([c.speed_rpm for c in original.critical_speeds[:6]]), "->",
      np.round(changed_cd["c"][:6]))

# %%
# The rig's shafts are slender (φ is small), so halving the shear term moves its whirl frequencies by tenths of a
# per cent: the modes held by the bearings barely, the shaft-bending modes most. The figure gives the change of
# each tracked mode's whirl frequency along the speed line. (Shear matters on stubby rotors, whose bending
# wavelengths are short against the shaft's diameter.) Nothing in the repository changed: the copy is in
# ``work``, and ``python -m derivations --check`` in the repository still reports its modules current.
from matplotlib.figure import Figure

fig = Figure(figsize=(8.0, 4.8), layout="constrained")
ax = fig.subplots()
change = 100 * (changed_cd["f"] / original.frequencies_hz - 1)
for k in range(change.shape[1]):
    ax.plot(speeds, change[:, k], label=f"mode {k + 1} ({original.whirl[-1, k]})",
            ls="-" if original.whirl[-1, k] == "forward" else "--")
ax.set_xlabel("speed of the inner spool (rpm)")
ax.set_ylabel("change of the whirl frequency (%)")
ax.set_title("seed-rig: whirl frequencies with the shear term halved, against the element as derived")
ax.grid(alpha=0.3)
ax.legend(fontsize=7, ncol=2)

# %%
# The experiment is over: remove the copy.
shutil.rmtree(work)
