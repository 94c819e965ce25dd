"""
Bifurcation map over the outer speed
====================================

A small map of the operating envelope: the paper's rub scene with the inner spool at 70 Hz and the outer spool
stepped from 88 to 94 Hz, up and down, each point started from its neighbour's final state. The bifurcation
diagram plots each point's Poincaré samples (node 14 y, once per common period or per inner revolution) against
the outer speed: one dot a periodic response, k dots period-k, a band quasi-periodic or chaotic.
"""

# %%
# :class:`rotorred.MapSpec` names the scene and the varied key (``speeds.outer`` in Hz); :func:`rotorred.run_map`
# runs it, here serially (``workers=0``; by default on a Dask cluster of one worker per core), into a folder of
# files (``map.nc``, ``map.csv``, the figures). Small settings so that it runs in seconds: 13 speeds, each point
# run 1.2 s from its neighbour's state and sampled over its last 0.6 s. Too short a record to be called settled,
# so every point is classified "unsettled"; the README's map
# (``rotorred map paper-rub --vary speeds.outer=60:110:101 --direction both --limit 4``, ``limit=4.0`` here) runs
# each point until settled or 4 s and classifies it (periodic, period-k, quasi-periodic, chaotic).
import tempfile

import numpy as np

import rotorred as rr

speeds = tuple(np.round(np.linspace(88.0, 94.0, 13), 2))
spec = rr.MapSpec("paper-rub", (rr.Axis("speeds.outer", speeds),), direction="both",
                  settings=(("solver.duration", 1.2), ("solver.record_start", 0.6),
                            ("output.plot_window", [0.6, 0.7]), ("output.compare_normal", False)))
out = tempfile.mkdtemp(prefix="rotorred-map-")
run = rr.run_map(spec, out, workers=0, progress=False, figures=False)
print(run)

# %%
# The peak orbit radius at the rub disk (node 18) and the rub's contact fraction at each point, up and down.
# Where the two sweeps differ, the response depends on the way the speed was reached, or has not settled in
# 1.2 s: runs to settling (``limit``) tell which.
ds = run.to_xarray()
print("outer (Hz)  peak orbit up / down (µm)  contact up / down (%)")
for i, f in enumerate(speeds):
    up, down = ds.sel(direction="up").isel(speeds_outer=i), ds.sel(direction="down").isel(speeds_outer=i)
    orbit_up, orbit_down = (1e6 * float(d["peak_orbit"].sel(node=18)) for d in (up, down))
    print(f"{f:9.2f}  {orbit_up:10.1f} / {orbit_down:6.1f}"
          f"  {100 * float(up['contact_fraction']):13.2f} / {100 * float(down['contact_fraction']):5.2f}")

# %%
# The bifurcation diagram: Poincaré samples (µm) against the outer speed (Hz), up and down sweeps.
fig = run.plot(kind="bifurcation")
