"""
Campbell diagram and critical speeds
====================================

The Campbell diagram of the paper's dual-rotor rig (preset ``seed-rig``): the whirl frequencies of its modes
against the speed of the inner spool, with the outer spool at the rig's nominal speed ratio, the excitation lines
1× inner and 1× outer, and the critical speeds where they cross (circles).
"""

# %%
# Sweep the inner spool from rest to 12 000 rpm in 61 speeds. The outer spool follows at the rotor's nominal
# ratio (5400 / 4200 rpm); speeds are given in rpm here, rad/s inside.
import numpy as np

import rotorred as rr

rotor = rr.load_rotor("seed-rig")
operating = rr.Operating.line(np.linspace(0.0, 12000.0, 61), unit="rpm")
cd = rr.campbell(rotor, operating, harmonics=(1,))
print(cd)

# %%
# The critical speeds: the speed of the inner spool where a whirl curve crosses an excitation line.
for c in cd.critical_speeds:
    print(f"{c.speed_rpm:8.0f} rpm  {c.line:>9}  mode {c.mode + 1}  {c.whirl:8}  {c.frequency_hz:6.1f} Hz")

# %%
# The diagram: speeds in rpm (the outer spool's on the top axis), frequencies in Hz, the operating point
# (4200 rpm) as a vertical line.
fig = cd.plot(operating_speed=4200 * np.pi / 30)
