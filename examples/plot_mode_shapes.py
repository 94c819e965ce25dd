"""
Mode shapes at the operating point
==================================

The first six modes of the paper's rig at its operating point (inner spool 4200 rpm, outer 5400 rpm): each
spool's deflection along the axis, the orbits of nodes along it and the sense of whirl, with the mode's
frequency, whirl direction and log dec in its title.
"""

# %%
# :func:`rotorred.mode_shapes` solves the damped, gyroscopic eigenproblem at one operating point. Modes are
# numbered from 1 in frequency order, as the Campbell diagram numbers them.
import rotorred as rr

rotor = rr.load_rotor("seed-rig")
operating = rr.Operating.point({"inner": 4200.0, "outer": 5400.0}, unit="rpm")
shapes = rr.mode_shapes(rotor, operating)
for k in range(6):
    print(f"mode {k + 1}: {shapes.frequencies_hz[k]:7.2f} Hz  {shapes.whirl[k]:8}  "
          f"log dec {shapes.log_dec[k]:.4f}")

# %%
# One panel a mode; the inner spool and the outer spool in two colours, the orbits scaled so that the largest
# is 1.
fig = shapes.plot(modes=[1, 2, 3, 4, 5, 6])
