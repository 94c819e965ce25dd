"""ROSS 3.1.0 reference data for a rotor whose shaft elements use ROSS's Hutchinson shear coefficient.

Run with the ROSS 3.1.0 virtual environment, never with the project's venv::

    cd validation/reference/ross3/extra
    /work/ross313/bin/python make_hutchinson.py

ROSS's ``ShaftElement(shear_method_calc="hutchinson")`` computes kappa without the (1 + nu) factor of Hutchinson's
published formula (J. Appl. Mech. 68, 2001, Eq. 52). This script builds a short, thick, hollow shaft (where shear
matters) of 6 elements (L 0.1 m, outer diameter 0.1 m, inner 0.04 m) with two disks on stiff bearings (1e8 N/m),
every element with ``shear_method_calc="hutchinson"``, saves it (``hutchinson_rotor.toml``) and stores ROSS's kappa
of each element and its whirl frequencies at 0, 500 and 1000 rad/s, with the helpers of ``../make_ross_reference.py``.

Everything goes to ``hutchinson_reference.json`` next to this script.
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
rs, f, flist, run_quiet = mrr.rs, mrr.f, mrr.flist, mrr.run_quiet

SPEEDS = (0.0, 500.0, 1000.0)


def hutchinson_rotor():
    steel = rs.materials.steel
    shafts = [rs.ShaftElement(0.1, 0.04, 0.1, material=steel, shear_effects=True, rotary_inertia=True,
                              gyroscopic=True, shear_method_calc="hutchinson") for _ in range(6)]
    disks = [rs.DiskElement.from_geometry(n=n, material=steel, width=0.05, i_d=0.1, o_d=0.3) for n in (2, 4)]
    bearings = [rs.BearingElement(n=n, kxx=1e8, kyy=1e8, cxx=0.0) for n in (0, 6)]
    return rs.Rotor(shafts, disks, bearings)


def main():
    t0 = time.time()
    rotor, build_msgs = run_quiet(hutchinson_rotor)
    layout = mrr.dof_layout(rotor)
    path = HERE / "hutchinson_rotor.toml"
    path.unlink(missing_ok=True)
    rotor.save(path)
    result = {
        "generator": "make_hutchinson.py",
        "ross_version": rs.__version__,
        "python_version": platform.python_version(),
        "numpy_version": np.__version__,
        "scipy_version": __import__("scipy").__version__,
        "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "command": " ".join([sys.executable, Path(__file__).name, *sys.argv[1:]]),
        "units": "SI: rad/s, m, kg, N/m, N*s/m; log_dec dimensionless",
        "build_warnings": build_msgs,
        "toml": {"file": path.name, "sha256": hashlib.sha256(path.read_bytes()).hexdigest(), **mrr.toml_sections(path)},
        "shaft_elements": [{"n": int(e.n), "kappa": f(e.kappa), "phi": f(e.phi),
                            "Poisson": f(e.material.Poisson)} for e in rotor.shaft_elements],
        "modal": [mrr.modal_block(rotor, s, layout) for s in SPEEDS],
    }
    for block in result["modal"]:
        print(f"{block['speed_rad_s']:.0f} rad/s: lateral wd[:6] = {np.round(block['lateral_wd'][:6], 3).tolist()}")
    result["seconds"] = round(time.time() - t0, 2)
    out = HERE / "hutchinson_reference.json"
    out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {out} in {result['seconds']} s")


if __name__ == "__main__":
    main()
