"""
Run-up with rub: waterfall
==========================

The rig run up from rest with the rub plate 13 µm above the disk at node 18 (built-in scene ``runup-rub``): the
spectra of node 14 y against time, with the order lines of both spools. Through the critical speeds the rub turns
the response broadband.
"""

# %%
# :func:`rotorred.run_runup` steps the scene's reduced model along its speed profile (the spools accelerate
# together at the ratio 90/70, the inner at 7 Hz/s, as the scene does) and computes the order tracks, the
# overall amplitude, the waterfall, the rub intervals and Campbell's critical speeds in the range. Shortened here
# to 0.8 × the operating point (inner 56 Hz) in 8 s; the scene as shipped (``runup.to = 1.2``, 12 s) goes on to
# inner 84 Hz. The first run-up after an install compiles the varying-speed step (about 20 s, cached).
import rotorred as rr

scene = rr.load_scene("runup-rub", {"runup.to": 0.8, "runup.duration": 8.0, "runup.orbits_hz": [42.0]})
result = rr.run_runup(scene, progress=False)
print(result)

# %%
# Where the plate is touched: onset and end speeds of each rub interval, and the contact onsets in it.
for rub in result.rubs:
    print(f"plate {rub.plate} at node {rub.node}: rubs from inner {rub.speed_start['inner']:.2f} Hz to "
          f"{rub.speed_end['inner']:.2f} Hz ({rub.t_start:.2f}-{rub.t_end:.2f} s), {rub.impacts} contact onsets")

# %%
# The waterfall: frequency (Hz) against time (s), colour in dB re 1 µm, order lines white.
fig = result.plot(kind="waterfall")
