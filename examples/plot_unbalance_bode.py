"""
Unbalance response: Bode plot
=============================

The steady response of the rig to two unbalances, one on each spool, as the spools run up together at their
nominal ratio: amplitude and phase of each spool's synchronous response at two bearing nodes, with the
resonances at the critical speeds.
"""

# %%
# An unbalance of 10 g mm (1e-5 kg m) on the inner spool's disk (node 11) and one on the outer spool's (node 16),
# 60 degrees apart. The response is solved at 301 speeds of the inner spool, 0 to 9000 rpm, the outer spool at
# the rotor's ratio (1.286). Outputs: node 13 x (a bearing of the outer spool) and node 14 y.
import numpy as np

import rotorred as rr

rotor = rr.load_rotor("seed-rig")
ratio = rotor.speeds["outer"] / rotor.speeds["inner"]
unbalances = [rr.Unbalance(11, 1e-5), rr.Unbalance(16, 1e-5, np.pi / 3)]
outputs = [(13, "x"), (14, "y")]
operating = rr.Operating.line(np.linspace(0.0, 9000.0, 301), unit="rpm", ratios={"outer": ratio})
response = rr.unbalance_response(rotor, operating, unbalances, outputs)

# %%
# The largest amplitude of each output and the inner speed where it occurs.
rpm = response.speeds * 30 / np.pi
for out in outputs:
    peak = response.peak(out)
    k = int(np.argmax(peak))
    print(f"node {out[0]} {out[1]}: largest peak bound {1e6 * peak[k]:.2f} µm at {rpm[k]:.0f} rpm (inner)")

# %%
# Amplitude (µm) and phase (deg) against speed (rpm), one column an output, one curve an excited spool.
fig = response.plot(kind="bode")
