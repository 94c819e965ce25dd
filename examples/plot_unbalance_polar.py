"""
Unbalance response: polar plot
==============================

The same synchronous response as a polar (Nyquist) plot: the tip of each spool's response phasor as the speed
rises, the loop a resonance draws, with speeds marked along it.
"""

# %%
# The rig with an unbalance on its inner spool's disk (node 11), swept through the inner spool's forward
# critical speed near 3340 rpm (2800 to 3900 rpm, 441 speeds: a lightly damped resonance needs a fine grid),
# the outer spool at the nominal ratio. Outputs: node 13 x and node 14 y.
import numpy as np

import rotorred as rr

rotor = rr.load_rotor("seed-rig")
ratio = rotor.speeds["outer"] / rotor.speeds["inner"]
operating = rr.Operating.line(np.linspace(2800.0, 3900.0, 441), unit="rpm", ratios={"outer": ratio})
outputs = [(13, "x"), (14, "y")]
response = rr.unbalance_response(rotor, operating, [rr.Unbalance(11, 1e-5)], outputs)

for out in outputs:
    amplitude = response.amplitude(out, "inner")
    k = int(np.argmax(amplitude))
    print(f"node {out[0]} {out[1]}, 1x inner: largest amplitude {1e6 * amplitude[k]:.2f} µm at "
          f"{response.speeds[k] * 30 / np.pi:.0f} rpm, phase {np.degrees(response.phase(out, 'inner')[k]):.1f} deg")

# %%
# The polar plot: in-phase and quadrature parts in µm.
fig = response.plot(kind="polar")
