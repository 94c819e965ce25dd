"""
Rub-impact: orbit and spectrum
==============================

The paper's rub (built-in scene ``paper-rub``: the rig at inner 70 Hz and outer 90 Hz, a plate 13 µm above the
high-pressure turbine disk at node 18). Left, the disk's orbit with and without the rub; right, the spectrum of
node 14 y with its lines labelled as combinations m f_H + n f_L, the form of the paper's Table 1.
"""

# %%
# :func:`rotorred.run_scene` runs the scene twice, with the plate and without it (the normal response), from
# the settled linear state, and records 2.0-2.6 s (a whole number of common periods, so every line falls on a
# bin).
import numpy as np
from matplotlib.figure import Figure

import rotorred as rr
from rotorred.plots.scene import draw_orbits, draw_spectra

scene = rr.load_scene("paper-rub")
result = rr.run_scene(scene)
print(result)

# %%
# The five strongest lines at node 14 y.
table = result.lines[(14, "y")].lines
for line in sorted(table, key=lambda ln: -ln.amplitude)[:5]:
    print(f"{line.frequency_hz:7.1f} Hz  {line.label:>10}  {1e6 * line.amplitude:6.3f} µm")

# %%
# The figure: orbits in µm with the plate's clearance as a dashed circle, and the amplitude spectrum up to
# 400 Hz (µm against Hz).
rub, normal = result.outputs, result.normal.outputs
fig = Figure(figsize=(12.0, 5.0), layout="constrained")
left, right = fig.subplots(1, 2, width_ratios=[1, 1.6])
draw_orbits({"normal": (normal[(18, "x")], normal[(18, "y")]), "rub": (rub[(18, "x")], rub[(18, "y")])}, ax=left,
            title="orbit of node 18 (rub disk)", clearance=scene.plates[0].clearance)
draw_spectra({"node 14 y, rub": result.spectra[(14, "y")]}, ax=right, lines={"node 14 y, rub": table},
             f_max=400.0, title="spectrum of node 14 y")
peak = np.hypot(rub[(18, "x")], rub[(18, "y")]).max()
print(f"largest orbit radius at node 18: {1e6 * peak:.1f} µm with the rub, "
      f"{1e6 * np.hypot(normal[(18, 'x')], normal[(18, 'y')]).max():.1f} µm without")
