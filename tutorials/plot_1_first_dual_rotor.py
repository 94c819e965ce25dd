"""
Your first dual rotor
=====================

Write a rotor file for a two-spool machine, draw its Campbell diagram, read its critical speeds and check them
against the API 617 separation-margin rule with API 684's amplification factors. Everything runs from an empty
folder: the script writes the file it reads.
"""

# %%
# The rotor file
# --------------
# A rotor is a TOML file: lengths in m, masses in kg, stiffness in N/m, damping in N s/m, speeds in rpm. This
# machine has an inner (low-pressure) spool, a solid 25 mm shaft of ten 90 mm elements on bearings at both ends,
# and an outer (high-pressure) spool, a 60/45 mm tube described by stations (as a drawing gives it), held by a
# ground bearing at its front and by an inter-shaft bearing on the inner spool at its rear. Each spool carries two
# disks given by their dimensions. The ``[defaults]`` table gives the inner spool's operating range, which the
# separation margins are measured from.
import tempfile
from pathlib import Path

import numpy as np

import rotorred as rr

ROTOR = """
name = "my-first-dual-rotor"

[[material]]
name = "steel"
E = 2.05e11       # Pa
rho = 7800.0      # kg/m^3
nu = 0.29

[[spool]]
name = "inner"
first_node = 1
speed_rpm = 6000.0
material = "steel"
elements = [ { L = 0.09, D_o = 0.025, repeat = 10 } ]          # nodes 1-11, z = 0-0.9 m

[[spool]]
name = "outer"
first_node = 12
speed_rpm = 7800.0
material = "steel"
stations = [                                                    # nodes 12-17, z = 0.27-0.72 m
  { z = 0.27, D_o = 0.060, D_i = 0.045, n = 5 },
  { z = 0.72 },
]

[[disk]]
node = 3
D_o = 0.22
D_i = 0.025
thickness = 0.02
material = "steel"

[[disk]]
node = 9
D_o = 0.22
D_i = 0.025
thickness = 0.02
material = "steel"

[[disk]]
node = 13
D_o = 0.20
D_i = 0.060
thickness = 0.02
material = "steel"

[[disk]]
node = 16
D_o = 0.20
D_i = 0.060
thickness = 0.02
material = "steel"

[[bearing]]
node = 1
k = 3e7
c = 800.0

[[bearing]]
node = 11
k = 3e7
c = 800.0

[[bearing]]
node = 12
k = 2e7
c = 600.0

[[intershaft_bearing]]
node_a = 17
node_b = 9
k = 1e7
c = 500.0

[damping]
rayleigh_alpha = 25.0     # 1/s

[defaults]
operating_range_rpm = { inner = [5000.0, 6600.0] }
"""

folder = Path(tempfile.mkdtemp(prefix="first-rotor-"))
path = folder / "my-rotor.toml"
path.write_text(ROTOR)
rotor = rr.load_rotor(path)
print(rotor)

# %%
# A mistake in the file is refused before anything is computed, with the key's path, the value as written and
# what is allowed:
bad = folder / "bad-rotor.toml"
bad.write_text(ROTOR.replace("D_o = 0.060, D_i = 0.045", "D_o = 0.060, D_i = 0.065"))
try:
    rr.load_rotor(bad)
except rr.InputError as error:
    print(str(error).replace(str(folder), "<folder>"))

# %%
# The Campbell diagram
# --------------------
# :class:`rotorred.Operating` says how the spools turn: here a speed line of the inner spool from rest to
# 10 000 rpm, the outer spool at the rotor's nominal ratio 7800/6000. The diagram tracks every mode below
# 1.25 × the highest excitation frequency (at least 6) and finds where each whirl curve crosses the 1× line
# of each spool.
operating = rr.Operating.line(np.linspace(0.0, 10000.0, 81), unit="rpm")
cd = rr.campbell(rotor, operating)
print(cd)

# %%
# Forward and backward whirl in two colours, the excitation lines, the critical speeds (circles) and the
# operating range of the inner spool (the green line is its top, 6600 rpm).
fig = cd.plot(operating_speed=6600 * np.pi / 30)

# %%
# Critical speeds and API 617 margins
# -----------------------------------
# For each critical speed on a 1× line, :func:`rotorred.separation_margins` places an unbalance where the mode
# moves most, computes its response along the speed line, takes the amplification factor AF by the half-power
# method (API 684) and the separation margin API 617 requires for that AF on its side of the operating range
# (rad/s in the API; the file gave rpm).
low, high = rotor.defaults.operating_range("inner")
margins = rr.separation_margins(rotor, cd, rr.OperatingRange(low, high))
print(f"operating range {low * 30 / np.pi:.0f}-{high * 30 / np.pi:.0f} rpm of the inner spool")
print(" critical (rpm)  line       mode whirl      AF     side   required  actual  meets")
for m in margins:
    c = m.critical
    verdict = "-" if m.meets is None else ("yes" if m.meets else "NO")
    print(f"{c.speed_rpm:14.0f}  {c.line:9}  {c.mode + 1:4d} {c.whirl:9} {m.amplification_factor:6.2f}  "
          f"{m.side:6} {100 * m.required:7.1f} % {100 * m.actual:6.1f} %  {verdict}"
          + (f"  ({m.note})" if m.note else ""))

# %%
# A backward mode is not excited by a forward unbalance on an isotropic rotor: it has no response peak, so no AF
# and no margin required. A critical speed inside the operating range that is not critically damped
# (AF ≥ 2.5) fails the rule: move it by changing a bearing's stiffness or a disk, and run the script again.
#
# The same from the command line, with the CSV files and the figure::
#
#     rotorred campbell my-rotor.toml --speeds 0:10000:81 --out campbell
