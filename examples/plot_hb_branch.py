"""
Harmonic-balance branch with stability
======================================

The rig's periodic rub response followed by harmonic balance with pseudo-arclength continuation in the rub
clearance, from 45 µm (no contact) down to 27 µm, through its folds, each point's stability from its Floquet
multipliers: stable solid, unstable dashed, folds and stability changes marked.
"""

# %%
# :func:`rotorred.continue_scene` takes a scene, its model, the key to vary and :class:`rotorred.BranchOptions`
# (harmonics of the base frequency, 10 Hz here, and time samples of the alternating frequency-time method).
# Small settings: 40 harmonics and 256 samples; the README's branch
# (``rotorred continue paper-rub --param rub.clearance=45e-6:5e-6 --harmonics 100 --samples 2048``) uses 100
# and 2048 and goes on to 5 µm. The Floquet multipliers take most of the time (``stability=False`` skips them).
import rotorred as rr

scene = rr.load_scene("paper-rub")
model = rr.build_model(scene).model
branch = rr.continue_scene(scene, model, "rub.clearance", 45e-6, 27e-6, rr.BranchOptions(harmonics=40, samples=256))
print(branch)

# %%
# The folds (where the branch turns back) and the points where the stability changes, with their kind.
for value, smooth in branch.folds:
    print(f"turn at {1e6 * value:.2f} µm ({'a fold' if smooth else 'a corner: a contact starts or ends'})")
for before, after, kind in branch.bifurcations:
    print(f"{kind} between {1e6 * before:.2f} and {1e6 * after:.2f} µm")

# %%
# Peak of node 14 y (µm) against the clearance (µm).
fig = branch.plot()
