"""
Poincaré sections: periodic, quasi-periodic, chaotic
====================================================

The rub response at node 14 y sampled once per revolution of the inner spool (70 Hz), at three speeds of the
outer spool: 90 Hz (the paper's point: periodic with a common period of 7 inner revolutions, so 7 points),
91.37 Hz (quasi-periodic on the torus f_H/3, f_L: the samples trace an invariant curve, with sparse excursions
where the impacts fall) and 82 Hz (chaotic: a cloud; ``validation/chaos_evidence.py`` gives the 0–1 test and the
divergence rate there).
"""

# %%
# Each point is the paper-rub scene at another outer speed, run from the settled linear state to 6 s; the
# samples are taken from 2 s on (280 samples). A longer ``solver.duration`` fills the curve and the cloud.
import numpy as np
from matplotlib.figure import Figure

import rotorred as rr
from rotorred.plots.scene import draw_poincare

F_INNER = 70.0
sections = {}
for f_outer in (90.0, 91.37, 82.0):
    scene = rr.load_scene("paper-rub", {"speeds.outer": f_outer, "solver.duration": 6.0, "solver.record_start": 2.0,
                                        "output.nodes": [14], "output.compare_normal": False,
                                        "output.plot_window": [5.9, 6.0]})
    result = rr.run_scene(scene, analyse=False)
    p = rr.poincare_samples(result.t, result.outputs[(14, "y")], F_INNER)
    sections[f_outer] = p
    distinct = 1 + np.count_nonzero(np.diff(np.sort(p.x)) > 1e-8)  # groups of samples 10 nm or more apart
    print(f"outer {f_outer:5.2f} Hz: {len(p.x)} samples in {distinct} groups 10 nm apart, displacement "
          f"{1e6 * p.x.min():.2f} to {1e6 * p.x.max():.2f} µm (spline error < {1e6 * p.interpolation_error:.0e} µm)")

# %%
# Sampled displacement (µm) against sampled velocity (µm/s), one panel a speed.
fig = Figure(figsize=(13.0, 4.4), layout="constrained")
for ax, (f_outer, p) in zip(fig.subplots(1, 3), sections.items()):
    draw_poincare(p.x, p.velocity, ax=ax, title=f"outer {f_outer:g} Hz", label="node 14 y, once per inner rev")
