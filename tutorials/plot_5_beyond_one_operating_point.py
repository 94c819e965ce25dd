"""
Beyond one operating point
==========================

A transient at one operating point answers one question. This tutorial takes the paper's rub model through the
analyses that look further, each in the form every analysis shares, ``(model, operating, loads, contacts,
options)``: the periodic solution by harmonic balance, its branch along a speed line with each point's
stability, a map of the operating envelope, a run-up through the critical speeds, and a speed ratio that is not
a ratio of small integers. Each uses small settings to build in seconds and says which to raise.
"""

# %%
# The model and its inputs
# ------------------------
# The paper-rub scene gives the rotor (with its damping), the unbalances and the rub plate; the model is its
# Craig–Bampton reduction with the rub disk kept physical.
import tempfile

import numpy as np

import rotorred as rr

scene = rr.load_scene("paper-rub")
model = rr.reduce_rotor(scene.rotor, extra_nodes=[18], n_modes=24)
loads, plates = rr.Loads(scene.unbalances), scene.plates
point = rr.Operating.point({"inner": 70.0, "outer": 90.0}, unit="Hz")

# %%
# The periodic solution by harmonic balance
# -----------------------------------------
# At commensurate speeds (70 and 90 Hz: base frequency 10 Hz) the settled rub response is periodic, and
# :func:`rotorred.harmonic_balance` solves for its Fourier coefficients directly: Newton from a short transient's
# last period, so it lands on the orbit the rotor settles onto. 50 harmonics of 10 Hz here (to 500 Hz);
# ``validation/hb_harmonics.py`` shows how the lines converge with more.
periodic = rr.harmonic_balance(model, point, loads, plates, rr.BalanceOptions(harmonics=50))
print(periodic)

# %%
# Its spectrum at the rub disk: amplitude of each harmonic of 10 Hz (µm).
fig_hb = periodic.plot()

# %%
# A branch along a speed line, with stability
# -------------------------------------------
# :func:`rotorred.continue_balance` follows that solution as the speeds change together (the outer spool at 9/7
# of the inner, so the base frequency moves with them) by pseudo-arclength continuation, and gives each point's
# stability from its Floquet multipliers. Inner 70 to 72 Hz, 40 harmonics; ``rotorred continue`` does the same
# from the command line (``--param speeds.inner=70:72``).
line = rr.Operating.line([70.0, 72.0], unit="Hz", ratios={"outer": 9 / 7})
branch = rr.continue_balance(model, line, loads, plates, rr.BranchOptions(harmonics=40, samples=256))
print(branch)

# %%
# Peak of the rub disk's y (µm) against the inner speed (Hz): stable solid, unstable dashed, the stability
# changes marked. Where a period-doubling appears, the rotor leaves this periodic orbit: the map below shows
# what it does instead.
fig_branch = branch.plot()

# %%
# A map of the operating envelope
# -------------------------------
# :func:`rotorred.envelope_map` runs transients along a speed line, each point from its neighbour's final state,
# up and down, and classifies each response (periodic, period-k, quasi-periodic, chaotic). Nine speeds of the
# inner spool here, each run 1.2 s, serial; ``MapOptions(limit=4.0)`` runs each point until settled or 4 s, and
# ``workers=None`` spreads the points over a Dask cluster of one worker per core.
speeds = np.linspace(70.0, 72.0, 9)
envelope = rr.envelope_map(model, rr.Operating.line(speeds, unit="Hz", ratios={"outer": 9 / 7}), loads, plates,
                           rr.MapOptions(duration=1.2, record_start=0.6, direction="both", workers=0,
                                         figures=False),
                           tempfile.mkdtemp(prefix="rotorred-envelope-"))
print(envelope)
fig_map = envelope.plot(kind="bifurcation")

# %%
# A run-up through the critical speeds
# ------------------------------------
# :func:`rotorred.runup` steps the model along a speed profile (here both spools from rest to 0.6 × the operating
# point in 3 s, the inner at 14 Hz/s) with the rub plate, and gives order tracks, the overall amplitude, a
# waterfall, the rub intervals and the critical speeds Campbell finds in the range. A slower ramp (the
# ``runup-rub`` scene takes 12 s to 1.2 ×) passes the criticals closer to their steady amplitude.
ramp = rr.Operating.ramp({"inner": 0.0, "outer": 0.0}, {"inner": 42.0, "outer": 54.0}, 3.0, unit="Hz")
run = rr.runup(model, ramp, loads, plates, rr.RunupOptions(start="rest"), progress=False)
print(run)
fig_runup = run.plot(kind="amplitude")

# %%
# Any speed ratio
# ---------------
# At outer 91.37 Hz the speeds have no common period: the response is not periodic, harmonic balance in one
# frequency does not apply, and the spectrum has no exact bins. The scene's analysis fits lines at exact
# combination frequencies on the torus it finds (here f_H/3, f_L) and classifies the response.
# ``rr.torus_balance`` then solves it on that 2-torus (``validation/hb_torus.py``, about 100 s).
quasi = rr.run_scene(rr.load_scene("paper-rub", {"speeds.outer": 91.37, "solver.duration": 3.0,
                                                 "solver.record_start": 2.0, "output.compare_normal": False,
                                                 "output.plot_window": [2.8, 2.9]}))
analysis = quasi.analysis
fit = analysis.fit
print(f"class: {analysis.classification.label}; torus f_H/{fit.torus.k}, f_L/{fit.torus.j}; "
      f"{len(fit.lines)} lines explain {100 * fit.explained_share:.1f} % of the variance")
for ln in sorted(fit.lines, key=lambda ln: -ln.amplitude)[:5]:
    print(f"{ln.frequency_hz:8.3f} Hz  {ln.label:>12}  {1e6 * ln.amplitude:6.3f} µm")
