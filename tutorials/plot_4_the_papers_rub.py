"""
The paper's rub
===============

Xu et al. (Shock and Vibration 2016, 6239281) simulate a dual-rotor rig at 4200 and 5400 rpm (inner 70 Hz,
outer 90 Hz) with the high-pressure turbine disk rubbing a casing plate, and list the combination lines
m f_H + n f_L of the outer rotor's Y response in their Table 1. The built-in scene ``paper-rub`` is that case;
this tutorial runs it, puts its lines beside the paper's Table 1 and draws the orbits and spectra, rub against
normal.
"""

# %%
# The scene
# ---------
# A scene is a TOML file (built-in ones by name): the rotor (the ``seed-rig`` preset, whose dimensions the paper
# does not give and docs/model.md argues), the speeds, the unbalances, the rub plate (Hertz contact with
# Hunt–Crossley damping and Coulomb friction on a plate that bends, the paper's Eqs. 10–12), the solver and the
# outputs. :func:`rotorred.scene_toml` writes it resolved, every default filled in; after the rotor's tables:
import numpy as np

import rotorred as rr
from rotorred.signals.lines import XU2016_TABLE1, compare_with_expected, format_comparison

scene = rr.load_scene("paper-rub")
text = rr.scene_toml(scene)
print(text[text.index("[speeds]"):text.index("[output]")])

# %%
# Running it
# ----------
# :func:`rotorred.run_scene` builds the Craig–Bampton model (24 modes, the rub disk kept physical), starts from
# the settled linear response (the state the unbalances alone reach), runs the rub transient to 2.6 s at
# dt = 2e-5 s and records 2.0–2.6 s: six common periods of 0.1 s, so every line m f_H + n f_L falls on a bin of
# the spectrum. It also runs the same scene without the plate (the normal response) and analyses the record
# (line fit, settling, classification). ``rotorred run`` does the same and writes the figures and data files.
result = rr.run_scene(scene)
print(result)

# %%
# Table 1
# -------
# The lines of node 14 y above 0.5 % of the largest, labelled as the combinations they are (the scene's analysis:
# peaks of the spectrum, fitted by least squares at exact combination frequencies), each paired with the
# paper's row within 1 Hz (the paper read its lines off bins of 0.49 Hz at spools of 69.58 and 90.33 Hz).
fit = result.lines[(14, "y")]
matches = compare_with_expected(fit.lines, XU2016_TABLE1)
print(format_comparison(matches))
print(f"{sum(m.label_agrees is True for m in matches)} of {len(matches)} rows of Table 1 found with the paper's "
      f"label")

# %%
# Orbits
# ------
# The orbits at the recorded nodes (µm), normal and with the rub. The plate sits 13 µm above the disk at node 18
# (its normal along +y, 90 deg): the rub throws the disk's orbit away from it, to 220 µm on the far side, and
# the orbit closes only over the common period of 7 inner and 9 outer revolutions (0.1 s).
fig_orbits = result.plot(kind="orbits")

# %%
# Spectra
# -------
# The spectra of node 14 (x and y), rub against normal: without the rub only f_L and f_H; with it, the
# combination lines of Table 1, labelled.
fig_spectra = result.plot(kind="spectra", node=14, f_max=650.0)

# %%
# How the rub changes the response: the largest displacement of each recorded DOF with and without it.
for dof in scene.output.dofs:
    rub, normal = np.abs(result.outputs[dof]).max(), np.abs(result.normal.outputs[dof]).max()
    print(f"node {dof[0]} {dof[1]}: {1e6 * normal:7.2f} µm normal, {1e6 * rub:7.2f} µm with the rub "
          f"({100 * (rub / normal - 1):+.0f} %)")
for plate in result.contacts:
    print(f"plate at node {plate.plate.node}: contact {100 * (1 - plate.fraction('open')):.2f} % of the record, "
          f"{plate.n_impacts()} impacts, largest normal force {plate.normal_force.max():.0f} N")

# sphinx_gallery_thumbnail_number = 2
