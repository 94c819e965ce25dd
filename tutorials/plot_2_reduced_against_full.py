"""
Reduced against full
====================

A rub transient needs many short time steps, and each costs in proportion to the model's size. A Craig–Bampton
model keeps the rub disk, the bearings and the inter-shaft bearing as physical nodes and replaces the rest by a
few fixed-interface modes. How many modes are enough depends on what you read: whirl frequencies converge with
few, a rub spectrum's small combination lines need more. This tutorial chooses the modes for the paper's rub
scene, compares the reduced model's spectra, orbits and run time with the full model's, and reads the
time-against-error front.
"""

# %%
# Choosing the modes
# ------------------
# :func:`rotorred.reduce_rotor` keeps the rotor's bearing nodes and the nodes you name (the rub disk, node 18)
# and, without ``n_modes``, adds fixed-interface modes until the whirl frequencies of the first modes are within
# 0.1 % of the full model's at four speeds. The scene's rotor is the paper's rig with the scene's damping.
import numpy as np
from matplotlib.figure import Figure

import rotorred as rr
from rotorred.plots.scene import draw_orbits, draw_spectra

scene = rr.load_scene("paper-rub")
automatic = rr.reduce_rotor(scene.rotor, extra_nodes=[18])
print(automatic)

# %%
# Ten modes meet the whirl-frequency target. The scene itself asks for 24 (``[solver] modes = 24``): the
# Performance page shows why, and the comparison at the end of this page shows it again.
#
# Full and reduced runs of the scene
# ----------------------------------
# The same scene on the full finite-element model (``solver.model = "full"``, 80 DOFs), on the automatic
# 10 modes and on the scene's 24. Each run starts from the settled linear state and records 2.0-2.6 s. The
# first run in a process loads the compiled step kernel from the disk cache (or compiles it, 15-25 s, on the
# first run after an install); µs per step is the stepping alone.
runs = {}
for label, settings in {"full (80 DOFs)": {"solver.model": "full"},
                        "CB 10 (34 DOFs)": {"solver.modes": 10},
                        "CB 24 (48 DOFs)": {"solver.modes": 24}}.items():
    r = rr.run_scene(rr.load_scene("paper-rub", {**settings, "output.compare_normal": False}), analyse=False)
    runs[label] = r
    print(f"{label}: model built in {r.build_time:.3f} s, {r.counters['us_per_step']:.2f} µs per step, "
          f"solved in {r.solve_time:.2f} s (of it {r.counters['kernel_load_time']:.2f} s loading the compiled step)")

# %%
# The spectra at node 14 y and the orbits of the rub disk. The reduced models' differences show in the small
# combination lines; the orbits lie on top of each other.
reference = runs["full (80 DOFs)"]
fig = Figure(figsize=(13.0, 5.0), layout="constrained")
left, right = fig.subplots(1, 2, width_ratios=[1.7, 1])
draw_spectra({label: r.spectra[(14, "y")] for label, r in runs.items()}, ax=left, f_max=450.0, log_y=True,
             dynamic_range=1e4, title="node 14 y: amplitude spectra")
draw_orbits({label: (r.outputs[(18, "x")], r.outputs[(18, "y")]) for label, r in runs.items()}, ax=right,
            title="node 18: orbits", clearance=scene.plates[0].clearance)

# %%
# The largest relative difference of the ten strongest lines of the full model's spectrum at node 14 y:
ref = reference.spectra[(14, "y")].amplitudes
strongest = np.argsort(ref[1:])[::-1][:10] + 1  # bins, 0 Hz left out
for label, r in runs.items():
    a = r.spectra[(14, "y")].amplitudes
    worst = np.max(np.abs(a[strongest] - ref[strongest]) / ref[strongest])
    print(f"{label}: worst of the 10 largest lines {100 * worst:.3g} %")

# %%
# The time-against-error front
# ----------------------------
# :func:`rotorred.compare_models` does this systematically: the full model at the finest step is the reference,
# every recorded DOF's ten largest lines are compared (and the orbit at the rub node, and the contact fraction),
# and each run's wall time is measured with its model's build. Two steps here; add ``dts=(4e-5, 2e-5, 1e-5)``
# for a wider front, or ``refine=4`` for a finer mesh (296 DOFs) where the reduced model pays off most.
comparison = rr.compare_models(scene, rr.CompareOptions(modes=(8, 10, 16, 24), dts=(4e-5, 2e-5), progress=False))
print(comparison.table())

# %%
# Each model a colour, each step a marker; the grey line is the front: for every error level, the fastest run
# that reaches it. Eight modes leave a 76 % floor that no step removes; 24 modes reach 0.1 %.
fig2 = comparison.plot()

# %%
# The same study from the command line writes ``compare.csv``, ``compare.png`` and ``compare.txt``::
#
#     rotorred compare paper-rub --modes 8,10,16,24 --dt 4e-5,2e-5 --out cmp
