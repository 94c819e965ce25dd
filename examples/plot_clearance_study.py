"""
Clearance study: lines and contact against the rub clearance
============================================================

The study the paper promises: the rub clearance against the response's spectral lines. A one-key map of
``rub.clearance`` on the paper's rub scene, every point from the scene's start (cold), with the line amplitudes
at node 14 y, the contact fraction and the free orbit's reach towards the plate. Beyond that reach the plate is
never touched and only f_L and f_H remain.
"""

# %%
# Ten clearances from 1 to 60 µm, each run 1.2 s from the settled linear state and analysed over its last
# 0.6 s (the scene as shipped runs 2.6 s; ``validation/clearance_study.py`` runs 15 clearances at that length and
# checks the trend). Serial (``workers=0``).
import tempfile

import numpy as np

import rotorred as rr

clearances = (1e-6, 5e-6, 10e-6, 13e-6, 20e-6, 30e-6, 40e-6, 45e-6, 50e-6, 60e-6)
spec = rr.MapSpec("paper-rub", (rr.Axis("rub.clearance", clearances),), cold=True,
                  settings=(("solver.duration", 1.2), ("solver.record_start", 0.6),
                            ("output.plot_window", [0.6, 0.7]), ("output.compare_normal", False)))
run = rr.run_map(spec, tempfile.mkdtemp(prefix="rotorred-clearance-"), workers=0, progress=False, figures=False)
print(run)

# %%
# Per clearance: contact fraction, contact onsets, and the sum of the fitted lines other than f_L and f_H.
ds = run.to_xarray().sel(direction="up")
reach = float(ds["free_reach"].values[0])
print(f"free orbit's reach towards the plate: {1e6 * reach:.2f} µm")
labels, amplitudes = ds["line_label"].values, np.nan_to_num(ds["line_amplitude"].values)
other = (labels != "") & (labels != "f_L") & (labels != "f_H")
for i, c in enumerate(clearances):
    print(f"{1e6 * c:5.0f} µm: contact {100 * float(ds['contact_fraction'][i]):5.2f} %, "
          f"{int(ds['n_impacts'][i]):3d} onsets, combination lines {other[i].sum():3d} summing to "
          f"{1e6 * amplitudes[i][other[i]].sum():6.2f} µm")

# %%
# Line amplitudes (µm) and contact against the clearance (µm), the free reach marked.
fig = run.plot(kind="lines")
