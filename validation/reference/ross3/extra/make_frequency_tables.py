"""ROSS 3.1.0 reference data for a rotor whose bearings are tabulated against ``frequency``.

Run with the ROSS 3.1.0 virtual environment, never with the project's venv::

    cd validation/reference/ross3/extra
    /work/ross313/bin/python make_frequency_tables.py

ROSS's ``BearingElement`` takes its coefficient tables against the rotor ``speed``, the excitation (whirl)
``frequency``, or both. Its modal analysis (``run_modal(speed)`` without ``frequency`` or ``matched_whirl``) and its
unbalance response evaluate every table at frequency = speed (the synchronous diagonal). This script builds
``rs.compressor_example()`` with its two fluid-film bearings rebuilt as ``BearingElement``s whose tables (the same
numbers, pchip) lie on the ``frequency`` axis instead of ``speed``; the 12 seals keep their ``speed`` tables. It
saves the rotor (``frequency_rotor.toml``) and stores ROSS's whirl frequencies at five speeds, one below the tables
(extrapolated), two between tabulated points (pchip) and two on tabulated points, with the helpers of
``../make_ross_reference.py`` (dense eigensolver, lateral modes by kinetic energy, SI units).

It also checks that the rebuilt rotor has the eigenvalues of the original (speed tables) at the same speeds: in
ROSS's synchronous analyses a frequency table and a speed table of the same numbers are the same bearing.

Everything goes to ``frequency_reference.json`` next to this script.
"""

import datetime
import hashlib
import importlib.util
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.dont_write_bytecode = True  # leave no __pycache__ in ../
_spec = importlib.util.spec_from_file_location("make_ross_reference", HERE.parent / "make_ross_reference.py")
mrr = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mrr)
rs, f, flist, run_quiet, RPM = mrr.rs, mrr.f, mrr.flist, mrr.run_quiet, mrr.RPM

#: rotor speeds (rpm): below every bearing table (extrapolated), between tabulated points, on tabulated points
SPEEDS_RPM = (3000.0, 5000.0, 6000.0, 8500.0, 10000.0)
LATERAL = ("kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy")


def frequency_rotor():
    """compressor_example with its BearingElements' tables moved from the speed axis to the frequency axis."""
    original = rs.compressor_example()
    elements = []
    moved = []
    for el in original.elements:
        if type(el) is rs.BearingElement and el.speed is not None and np.size(el.speed) > 1:
            coefficients = {c: list(getattr(el, c)) for c in LATERAL + ("kzz", "czz", "mxx", "mxy", "myx", "myy",
                                                                        "mzz")}
            elements.append(rs.BearingElement(n=el.n, frequency=list(el.speed), tag=el.tag, n_link=el.n_link,
                                              interpolation=el.interpolation, **coefficients))
            moved.append(el.tag)
        else:
            elements.append(el)
    shafts = [e for e in elements if isinstance(e, rs.ShaftElement)]
    disks = [e for e in elements if isinstance(e, rs.DiskElement)]
    bearings = [e for e in elements if isinstance(e, rs.BearingElement)]
    rotor = rs.Rotor(shafts, disks, bearings)
    return original, rotor, moved


def max_relative_difference(a, b, speed):
    """Largest relative difference of the first 24 damped frequencies of two rotors at ``speed`` (dense)."""
    ma, _ = run_quiet(a.run_modal, speed=speed, num_modes=48, sparse=False)
    mb, _ = run_quiet(b.run_modal, speed=speed, num_modes=48, sparse=False)
    return f(np.max(np.abs(ma.wd - mb.wd) / np.abs(ma.wd)))


def main():
    t0 = time.time()
    (original, rotor, moved), build_msgs = run_quiet(frequency_rotor)
    layout = mrr.dof_layout(rotor)
    path = HERE / "frequency_rotor.toml"
    path.unlink(missing_ok=True)
    rotor.save(path)
    loaded, _ = run_quiet(rs.Rotor.load, path)
    speeds = [rpm * RPM for rpm in SPEEDS_RPM]
    axes = {b.tag: {"speed_rad_s": None if b.speed is None else flist(b.speed),
                    "frequency_rad_s": None if b.frequency is None else flist(b.frequency)}
            for b in rotor.bearing_elements}
    result = {
        "generator": "make_frequency_tables.py",
        "ross_version": rs.__version__,
        "python_version": platform.python_version(),
        "numpy_version": np.__version__,
        "scipy_version": __import__("scipy").__version__,
        "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": " ".join([sys.executable, Path(__file__).name, *sys.argv[1:]]),
        "units": "SI: rad/s, m, kg, N/m, N*s/m; log_dec dimensionless",
        "rotor": "rs.compressor_example() with its BearingElement tables on the frequency axis (seals on speed)",
        "bearings_on_frequency": moved,
        "table_axes": axes,
        "build_warnings": build_msgs,
        "toml": {"file": path.name, "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
                 **mrr.toml_sections(path),
                 "roundtrip_max_rel_diff_wd": max_relative_difference(rotor, loaded, speeds[1])},
        "same_as_speed_tables_max_rel_diff_wd": {f(s): max_relative_difference(original, rotor, s) for s in speeds},
        "modal": [mrr.modal_block(rotor, s, layout) for s in speeds],
    }
    for block in result["modal"]:
        print(f"{block['speed_rpm']:.0f} rpm: lateral wd[:8] = {np.round(block['lateral_wd'][:8], 3).tolist()}")
    print("same as speed tables:", result["same_as_speed_tables_max_rel_diff_wd"])
    result["seconds"] = round(time.time() - t0, 2)
    out = HERE / "frequency_reference.json"
    out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {out} in {result['seconds']} s")


if __name__ == "__main__":
    main()
