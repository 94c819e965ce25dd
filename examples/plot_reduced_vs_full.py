"""
Reduced against full: run time against error
============================================

The paper's rub scene run on its full finite-element model (80 DOFs) and on Craig–Bampton models with 8, 16 and
24 fixed-interface modes, each at two time steps, every run measured against the full model at the finer step:
the spectral error (worst of the ten largest lines of each recorded DOF) against the wall time, and the front of
the runs no other beats in both.
"""

# %%
# :func:`rotorred.compare_models` takes a scene and :class:`rotorred.CompareOptions`. Two steps here,
# 4e-5 and 2e-5 s (the reference is the full model at 2e-5 s); ``rotorred compare`` gives the same from the
# command line, and ``dts=(2e-5, 1e-5, 5e-6)`` or ``refine=4`` (a finer mesh, 296 DOFs) make the longer study of
# the Performance page.
import rotorred as rr

scene = rr.load_scene("paper-rub")
comparison = rr.compare_models(scene, rr.CompareOptions(modes=(8, 16, 24), dts=(4e-5, 2e-5), progress=False))
print(comparison)

# %%
# Every run: DOFs, step, wall time and the three errors (spectral, orbit at the rub node, contact fraction).
print(comparison.table())

# %%
# Time against spectral error: each model a marker, the front joined.
fig = comparison.plot()
