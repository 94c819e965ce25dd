"""
Coming from ROSS
================

A rotor saved by ROSS 3 (``rotor.save("my_rotor.toml")``) is a rotor file for rotorred as it is, without ROSS
installed, and ``rotorred convert`` (:func:`rotorred.convert_ross`) writes it in rotorred's own format to go on
from there. This tutorial reads ROSS's compressor example as ROSS saved it, checks its whirl frequencies against
the ones ROSS computed, draws its Campbell diagram, converts it, and reads the converted file back.
"""

# %%
# The ROSS file
# -------------
# With ROSS installed, ``ross.compressor_example().save("compressor_example.toml")`` writes this file; the
# repository keeps the one ROSS 3.1.0 saved, with the numbers ROSS computed from it
# (``validation/reference/ross3/``, made by its ``make_ross_reference.py``).
import json
import tempfile
from pathlib import Path

import numpy as np

import rotorred as rr

here = [Path.cwd(), Path.cwd().parent, Path(rr.__file__).resolve().parents[1]]
ross3 = next(p / "validation" / "reference" / "ross3" for p in here
             if (p / "validation" / "reference" / "ross3").is_dir())
ross_file = ross3 / "compressor_example.toml"
text = ross_file.read_text()
print(f"{ross_file.name}: {len(text.splitlines())} lines; its first entries:")
print("\n".join(text.splitlines()[6:14]))

# %%
# Read as it is
# -------------
# :func:`rotorred.load_rotor` recognises a ROSS file. ROSS's nodes keep their numbers; its shaft becomes one spool
# ``"rotor"``, its layered elements sleeves, its disks disks, its bearings and seals bearings with their
# coefficient tables against speed (monotone cubic between the table's speeds and ROSS's end tangents outside, as
# ROSS evaluates them). What rotorred cannot represent (magnetic bearings, couplings, gears, axial force) is
# refused by name.
rotor = rr.load_rotor(ross_file)
print(rotor)

# %%
# The same numbers as ROSS
# ------------------------
# ROSS's modal analysis at 0, 6000 and 10 000 rpm gave the damped whirl frequencies below (``lateral_wd``,
# rad/s). rotorred's Campbell diagram at each of these speeds, 16 modes, against ROSS's 16 lowest:
reference = json.loads((ross3 / "ross_reference.json").read_text())["rotors"]["compressor_example"]
for block in reference["modal"]:
    at = rr.campbell(rotor, rr.Operating.line([block["speed_rad_s"]]), n_modes=16)
    ours, theirs = np.sort(at.frequencies[0]), np.sort(np.array(block["lateral_wd"]))[:16]
    print(f"{block['speed_rpm']:7.0f} rpm: lowest {ours[0] / (2 * np.pi):7.2f} Hz "
          f"(ROSS {theirs[0] / (2 * np.pi):7.2f}); largest relative difference of the 16: "
          f"{np.max(np.abs(ours / theirs - 1)):.1e}")

# %%
# Two codes that build the same matrices agree to rounding. ``tests/test_ross_files.py`` asserts it for five
# rotors ROSS saved, with their critical speeds.
#
# The Campbell diagram
# --------------------
# Over 0–10 000 rpm, the 12 lowest modes tracked (``n_modes``). The seals' negative direct stiffness and the
# heavily damped seal modes (damping ratio up to 0.86) are kept as ROSS keeps them; the speeds go beyond the
# bearing tables' range, where the coefficients follow the tables' end tangents, and the summary says so.
cd = rr.campbell(rotor, rr.Operating.line(np.linspace(0.0, 10000.0, 41), unit="rpm"), n_modes=12)
print(cd)
fig = cd.plot(max_frequency_hz=600.0)

# %%
# Converted to rotorred's format
# ------------------------------
# :func:`rotorred.convert_ross` (the command ``rotorred convert compressor_example.toml my_rotor.toml``) writes a
# rotorred rotor file: units in its header, layered elements as ``sleeves``, tables in rpm with
# ``interpolation = "pchip"``; read back it is the same rotor to the last bit.
folder = Path(tempfile.mkdtemp(prefix="from-ross-"))
converted = folder / "compressor.toml"
rr.convert_ross(ross_file, converted)
written = converted.read_text()
print("\n".join(written.splitlines()[:12]))
print(f"... {len(written.splitlines())} lines; the same rotor read back: {rr.load_rotor(converted) == rotor}")

# %%
# From here the file is yours: edit it (a bearing, a disk, a second spool: see "Your first dual rotor") and run
# every analysis of rotorred on it, from the command line or from Python::
#
#     rotorred campbell compressor.toml --speeds 0:10000:41 --out campbell
