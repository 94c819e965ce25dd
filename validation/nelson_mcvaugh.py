"""Nelson-McVaugh rotor: Campbell whirl speeds against an independent code (ROSS 3.1.0).

Inputs: the preset ``nelson-mcvaugh`` (validation/reference/nelson_mcvaugh_rotor.json: bores read as
diameters, Cowper shear coefficient, isotropic bearings 4.378e7 N/m at stations 10 and 14, disk at
station 4). Reference: validation/reference/nelson_mcvaugh_ross_computed.json, computed with ROSS (not
published numbers), case "ID_as_diameter(ANSYS table)|shear=True"; and the cross-coupled
orthotropic bearing case (k_xx = k_yy = 3.503e7, k_xy = k_yx = -0.8756e7 N/m).

Run: ``python validation/nelson_mcvaugh.py [--plot PATH]``. Prints rpm x mode: ours, reference, rel. error.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
from pathlib import Path

import numpy as np

from rotorred.linear.campbell import campbell
from rotorred.model.operating import Operating
from rotorred.model.elements import Bearing
from rotorred.model.rotor_file import load_rotor

REFERENCE = Path(__file__).resolve().parent / "reference" / "nelson_mcvaugh_ross_computed.json"

CASES = {
    "isotropic": "ID_as_diameter(ANSYS table)|shear=True",
    "orthotropic": "ortho_crosscoupled_bearings(Kyy=Kzz=3.503e7,Kyz=-0.8756e7)|ID_as_diameter|shear=True",
}
N_MODES = 6


def rotor(case: str = "isotropic"):
    """The Nelson-McVaugh rotor with the bearings of ``case``."""
    r = load_rotor("nelson-mcvaugh")
    if case == "isotropic":
        return r
    if case == "orthotropic":
        # ROSS's y, z are our x, y; k_xy = k_yx, so the sign convention of the cross terms does not matter
        bearings = tuple(Bearing(k_xx=3.503e7, k_yy=3.503e7, k_xy=-0.8756e7, k_yx=-0.8756e7, node=b.node)
                         for b in r.bearings)
        return dataclasses.replace(r, bearings=bearings, name=f"{r.name} (cross-coupled bearings)")
    raise ValueError(f"`case` must be one of {list(CASES)}, got {case!r}")


def reference(case: str = "isotropic") -> tuple[np.ndarray, np.ndarray]:
    """(speeds (rpm), shape (n,); whirl speeds (rpm), shape (n, 6)) of the ROSS computation."""
    data = json.loads(REFERENCE.read_text())[CASES[case]]
    keys = [k for k in data if k.endswith("rpm_rpm")]
    rpm = np.array([float(k[: -len("rpm_rpm")]) for k in keys])
    values = np.array([data[k][:N_MODES] for k in keys])
    order = np.argsort(rpm)
    if case == "isotropic":  # the brief's speeds: 0, 4000, 10000, 40000 rpm
        order = [i for i in order if rpm[i] in (0, 4000, 10000, 40000)]
    return rpm[order], values[order]


def whirl_speeds(case: str = "isotropic") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(speeds (rpm), ours (rpm), reference (rpm)); whirl speeds shape (n_speeds, 6), sorted per speed."""
    rpm, ref = reference(case)
    result = campbell(rotor(case), Operating.line(rpm, unit="rpm"), n_modes=N_MODES + 2)
    ours = np.sort(result.frequencies, axis=1)[:, :N_MODES] * 30 / math.pi
    return rpm, ours, ref


def max_rel_error(case: str = "isotropic") -> float:
    """Largest |ours - reference| / reference over the speeds and the first six whirl speeds."""
    _, ours, ref = whirl_speeds(case)
    return float(np.max(np.abs(ours - ref) / ref))


def _table(case: str) -> str:
    rpm, ours, ref = whirl_speeds(case)
    lines = [f"Nelson-McVaugh, {case} bearings: whirl speeds (rpm), ours vs ROSS [{CASES[case]}]",
             f"{'speed rpm':>10} {'mode':>4} {'ours':>12} {'reference':>12} {'rel. error':>11}"]
    for i, s in enumerate(rpm):
        for j in range(N_MODES):
            lines.append(f"{s:10.0f} {j:4d} {ours[i, j]:12.2f} {ref[i, j]:12.1f} "
                         f"{(ours[i, j] - ref[i, j]) / ref[i, j]:11.2e}")
    lines.append(f"max |rel. error| = {np.max(np.abs(ours - ref) / ref):.2e} "
                 f"(reference printed to 0.1 rpm: rounding <= {0.05 / ref.min():.1e})")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plot", metavar="PATH", help="write the Campbell diagram (isotropic case) as a PNG")
    args = p.parse_args(argv)
    for case in CASES:
        print(_table(case))
        print()
    if args.plot:
        result = campbell(rotor("isotropic"), Operating.line(np.linspace(0, 40000, 81), unit="rpm"),
                          n_modes=N_MODES, harmonics=(1, 2))
        from rotorred.plots.axes import save_figure

        print(f"wrote {save_figure(result.plot(), args.plot)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
