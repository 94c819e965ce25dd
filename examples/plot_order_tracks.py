"""
Order tracks through a critical speed
=====================================

A run-up from Python with the step-level API: the rig's reduced model driven along a speed ramp by
:func:`rotorred.simulate`, its record resampled in the angle of each spool (computed order tracking) and the 1×
order of each spool tracked at the rub disk (node 18 y). The outer spool's line passes its forward critical speed
(Campbell: 1× outer, inner 42.9 Hz).
"""

# %%
# The ``runup`` scene gives the rotor, its speeds (rad/s) and unbalances. The ramp takes the inner spool from 30
# to 60 Hz in 2 s (15 Hz/s, twice the scene's rate: a shorter run; a slower ramp, e.g. 4 s, peaks closer to the
# steady resonance), the outer spool following at 90/70.
import numpy as np
from matplotlib.figure import Figure

import rotorred as rr

scene = rr.load_scene("runup")
model = rr.reduce_rotor(scene.rotor, extra_nodes=[18], n_modes=24)
ramp = rr.SpeedProfile.ramp({s: 30 / 70 * w for s, w in scene.speeds.items()},
                            {s: 60 / 70 * w for s, w in scene.speeds.items()}, 2.0)
run = rr.simulate(model, rr.Operating.profile(ramp), 2.0, 2e-5, loads=rr.Loads(scene.unbalances),
                  recording=rr.Recording([(18, "y")], decimate=5))

# %%
# Angle-domain resampling: blocks of 9 revolutions of each spool, then the 1× order of each.
angles = ramp.at(run.t)
tracks = {}
for spool in ("inner", "outer"):
    blocks = rr.angle_blocks(run.t, [run.outputs[(18, "y")]], angles[spool][2], revs_per_block=9)
    tracks[spool] = rr.order_tracks(blocks, spool, [1.0])[0][0]
for spool, track in tracks.items():
    k = int(np.argmax(track.amplitude))
    inner_hz = np.interp(track.t[k], run.t, angles["inner"][0]) / (2 * np.pi)
    print(f"1x {spool}: peak {1e6 * track.amplitude[k]:.1f} µm at {spool} {track.speed[k] / (2 * np.pi):.1f} Hz "
          f"(inner {inner_hz:.1f} Hz)")

# %%
# Each track (µm) against its own spool's speed (Hz), one panel a spool.
fig = Figure(figsize=(11.0, 4.2), layout="constrained")
for ax, (spool, track) in zip(fig.subplots(1, 2), tracks.items()):
    track.plot(ax=ax, title=f"node 18 y: 1× {spool}")
