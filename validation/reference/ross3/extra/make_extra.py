"""Extra ROSS 3.1.0 reference data for rotorred's ROSS-TOML reader.

Run with the ROSS 3.1.0 virtual environment, never with the project's venv::

    cd validation/reference/ross3/extra
    /work/ross313/bin/python make_extra.py

It follows the conventions of ``../make_ross_reference.py`` and imports its
helpers by path (dense eigensolver ``rotor.run_modal(speed=w, num_modes=2N,
sparse=False)``, lateral modes classified by the kinetic-energy split over the
x, y, alpha, beta DOFs, amplitude-weighted whirl label, SI units).

Rotors built here, each saved with ``rotor.save(<name>.toml)``:

* ``tapered_rotor``: 8 steel shaft elements, 3 of them tapered (one hollow,
  with both diameters changing), 2 disks, 2 constant bearings.
* ``pedestal_rotor``: rotor_example's shaft and disks; each end bearing links
  the shaft node to a support node (``n_link``) that carries a PointMass and a
  spring to ground (the pattern of ROSS's coaxial example).
* ``damped_rotor``: rotor_example's shaft and disks on lightly damped,
  speed-tabulated bearings (5 speeds, ``interpolation="pchip"``) with
  cross-coupled stiffness; also critical speeds and a 41-speed Campbell.
* ``unsupported_element``: rotor_example-like rotor with an element class a
  lateral 4-DOF reader does not know (a ``CouplingElement``; a
  ``MagneticBearingElement`` is saved by ROSS as a plain ``BearingElement``,
  see ``unsupported_attempts``).

Everything goes to ``extra_reference.json`` next to this script.
"""

import argparse
import copy
import datetime
import hashlib
import importlib.util
import json
import platform
import signal
import sys
import time
import tomllib
import traceback
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
PARENT = HERE.parent

# ---------------------------------------------------------------------------
# import the helpers of ../make_ross_reference.py by path (it also imports
# ROSS quietly)
# ---------------------------------------------------------------------------
sys.dont_write_bytecode = True  # leave no __pycache__ in ../
_spec = importlib.util.spec_from_file_location(
    "make_ross_reference", PARENT / "make_ross_reference.py")
mrr = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mrr)
rs = mrr.rs
f, flist, run_quiet = mrr.f, mrr.flist, mrr.run_quiet

STEEL = rs.materials.steel  # ROSS "Steel": rho 7810, E 211e9, G_s 81.2e9
CAMPBELL_SPEEDS = np.linspace(0, 1000, 41)
CAMPBELL_FREQUENCIES = 16
CRITICAL_TIMEOUT_S = 180
RPM = mrr.RPM


# ---------------------------------------------------------------------------
# rotor definitions
# ---------------------------------------------------------------------------
# (L, idl, odl, idr, odr) of the tapered rotor's shaft elements
TAPERED_GEOMETRY = [
    (0.10, 0.00, 0.05, 0.00, 0.05),  # 0 journal stub
    (0.15, 0.00, 0.05, 0.00, 0.08),  # 1 tapered, solid, od 0.05 -> 0.08
    (0.20, 0.00, 0.08, 0.00, 0.08),  # 2
    (0.20, 0.00, 0.08, 0.00, 0.08),  # 3
    (0.20, 0.02, 0.08, 0.03, 0.06),  # 4 tapered, hollow, id 0.02 -> 0.03, od 0.08 -> 0.06
    (0.20, 0.03, 0.06, 0.03, 0.06),  # 5 hollow
    (0.15, 0.00, 0.06, 0.00, 0.05),  # 6 tapered, solid, od 0.06 -> 0.05
    (0.10, 0.00, 0.05, 0.00, 0.05),  # 7 journal stub
]


def build_tapered():
    shaft = [rs.ShaftElement(L=L, idl=idl, odl=odl, idr=idr, odr=odr,
                             material=STEEL, shear_effects=True,
                             rotary_inertia=True, gyroscopic=True)
             for L, idl, odl, idr, odr in TAPERED_GEOMETRY]
    disks = [
        rs.DiskElement.from_geometry(n=3, material=STEEL, width=0.07,
                                     i_d=0.08, o_d=0.28),
        rs.DiskElement.from_geometry(n=5, material=STEEL, width=0.05,
                                     i_d=0.06, o_d=0.22),
    ]
    bearings = [rs.BearingElement(n=n, kxx=1e7, kyy=1.2e7, cxx=100, cyy=100)
                for n in (1, 7)]
    return rs.Rotor(shaft, disks, bearings)


def example_shaft_and_disks():
    """rotor_example's 6 shaft elements and 2 disks (fresh copies)."""
    ex = rs.rotor_example()
    return copy.deepcopy(ex.shaft_elements), copy.deepcopy(ex.disk_elements)


def build_pedestal():
    shaft, disks = example_shaft_and_disks()
    bearings = [
        rs.BearingElement(n=0, n_link=7, kxx=1e6, kyy=1e6, cxx=0, cyy=0),
        rs.BearingElement(n=6, n_link=8, kxx=1e6, kyy=1e6, cxx=0, cyy=0),
        rs.BearingElement(n=7, kxx=1e8, kyy=1e8, cxx=0, cyy=0),
        rs.BearingElement(n=8, kxx=1e8, kyy=1e8, cxx=0, cyy=0),
    ]
    point_masses = [rs.PointMass(n=7, m=20), rs.PointMass(n=8, m=20)]
    return rs.Rotor(shaft, disks, bearings, point_masses)


# speed-tabulated bearing of damped_rotor; deliberately not linear in speed,
# so that PCHIP and linear interpolation differ between the tabulated points
DAMPED_TABLE = {
    "speed": [0.0, 250.0, 500.0, 750.0, 1000.0],
    "kxx": [1.00e6, 1.30e6, 1.55e6, 1.80e6, 2.00e6],
    "kyy": [0.80e6, 1.05e6, 1.25e6, 1.45e6, 1.60e6],
    "kxy": [1.0e4, 1.5e4, 2.5e4, 3.5e4, 5.0e4],
    "kyx": [-1.0e4, -1.5e4, -2.5e4, -3.5e4, -5.0e4],
    "cxx": [100.0, 130.0, 150.0, 170.0, 200.0],
    "cyy": [100.0, 130.0, 150.0, 170.0, 200.0],
}


def build_damped():
    shaft, disks = example_shaft_and_disks()
    bearings = [rs.BearingElement(n=n, interpolation="pchip", **DAMPED_TABLE)
                for n in (0, 6)]
    return rs.Rotor(shaft, disks, bearings)


def build_coupling():
    """rotor_example-like: 3 + 3 shaft elements joined by a flexible coupling."""
    shaft = [rs.ShaftElement(0.25, 0, 0.05, material=STEEL, shear_effects=True,
                             rotary_inertia=True, gyroscopic=True)
             for _ in range(6)]
    coupling = rs.CouplingElement(
        m_l=2.0, m_r=2.0, Ip_l=0.01, Ip_r=0.01,
        kt_x=1e8, kt_y=1e8, kt_z=1e8, kr_x=1e5, kr_y=1e5, kr_z=1e5,
        o_d=0.1, L=0.1)
    elements = shaft[:3] + [coupling] + shaft[3:]  # numbered in list order
    disks = [rs.DiskElement.from_geometry(n=n, material=STEEL, width=0.07,
                                          i_d=0.05, o_d=0.28) for n in (2, 5)]
    bearings = [rs.BearingElement(n=n, kxx=1e6, kyy=0.8e6, cxx=0)
                for n in (0, 7)]
    return rs.Rotor(elements, disks, bearings)


def build_amb():
    """rotor_example with both bearings replaced by PID magnetic bearings."""
    shaft, disks = example_shaft_and_disks()
    amb = [rs.MagneticBearingElement(
        n=n, g0=0.5e-3, i0=2.0, ag=4e-4, nw=200, k_amp=1.0, k_sense=1e4,
        kp_pid=1.1, kd_pid=1e-3, ki_pid=0.0) for n in (0, 6)]
    return rs.Rotor(shaft, disks, amb)


def build_gear():
    """rotor_example with the second disk replaced by a GearElement."""
    shaft, disks = example_shaft_and_disks()
    gear = rs.GearElement(n=4, m=5.0, Id=0.02, Ip=0.04, n_teeth=30,
                          pitch_diameter=0.2)
    bearings = [rs.BearingElement(n=n, kxx=1e6, kyy=0.8e6, cxx=0)
                for n in (0, 6)]
    return rs.Rotor(shaft, [disks[0], gear], bearings)


def build_multirotor():
    from ross.multi_rotor.multi_rotor import two_shaft_rotor_example
    return two_shaft_rotor_example()


# ---------------------------------------------------------------------------
# model description
# ---------------------------------------------------------------------------
SHAFT_FIELDS = ("L", "idl", "odl", "idr", "odr", "axial_force", "torque",
                "shear_effects", "rotary_inertia", "gyroscopic",
                "shear_method_calc", "alpha", "beta")
SHAFT_DERIVED = ("m", "A", "Ie", "A_l", "A_r", "Ie_l", "Ie_r", "phi", "kappa",
                 "beam_cg", "Im", "volume")
COUPLING_FIELDS = ("m_l", "m_r", "Ip_l", "Ip_r", "Id_l", "Id_r", "kt_x", "kt_y",
                   "kt_z", "kr_x", "kr_y", "kr_z", "ct_x", "ct_y", "ct_z",
                   "cr_x", "cr_y", "cr_z", "o_d", "L")
TABLE_KEYS = ("kxx", "kxy", "kyx", "kyy", "kzz", "cxx", "cxy", "cyx", "cyy",
              "czz", "mxx", "mxy", "myx", "myy", "mzz")


def jsonable(v):
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return f(v)
    if isinstance(v, (list, tuple, np.ndarray)):
        return [jsonable(x) for x in v]
    if v is None or isinstance(v, str):
        return v
    return repr(v)


def local_matrices(el):
    """Element matrices of one shaft element as ROSS builds them (12x12)."""
    order = sorted(el.dof_mapping().items(), key=lambda kv: kv[1])
    out = {"dof_order": [k for k, _ in order]}
    for name in ("M", "K", "G"):
        try:
            out[name] = [flist(row) for row in np.asarray(getattr(el, name)())]
        except Exception as exc:  # noqa: BLE001
            out[name] = repr(exc)
    return out


def describe(rotor, layout):
    per_node = {}
    for node, name in layout:
        per_node.setdefault(node, []).append(name)
    dofs_per_node = {}
    for node, names in per_node.items():
        dofs_per_node.setdefault(len(names), []).append(node)

    shafts = []
    for sh in rotor.shaft_elements:
        e = {"class": type(sh).__name__, "tag": sh.tag, "n": int(sh.n),
             "n_l": int(sh.n_l), "n_r": int(sh.n_r)}
        if isinstance(sh, rs.CouplingElement):
            e.update({k: jsonable(getattr(sh, k, None)) for k in COUPLING_FIELDS})
            e["note"] = ("CouplingElement: lumped masses/inertias at n_l and n_r"
                         " joined by translational (kt_*) and rotational (kr_*)"
                         " springs; o_d and L are for drawing only")
        else:
            e.update({k: jsonable(getattr(sh, k, None)) for k in SHAFT_FIELDS})
            m = sh.material
            e["material"] = {"name": m.name, "rho": f(m.rho), "E": f(m.E),
                             "G_s": f(m.G_s), "Poisson": f(m.Poisson)}
            e["tapered"] = bool(not np.isclose(sh.idl, sh.idr)
                                or not np.isclose(sh.odl, sh.odr))
            e["ross_derived"] = {k: jsonable(getattr(sh, k, None))
                                 for k in SHAFT_DERIVED}
            if e["tapered"]:
                e["element_matrices"] = local_matrices(sh)
        shafts.append(e)

    bearings = []
    for b in rotor.bearing_elements:
        e = {"class": type(b).__name__, "tag": b.tag, "n": int(b.n),
             "n_link": None if b.n_link is None else int(b.n_link),
             "interpolation": getattr(b, "interpolation", None)}
        kinds = set()
        for axis in ("speed", "frequency"):
            a = getattr(b, axis, None)
            e[f"{axis}_axis"] = None if a is None else flist(a)
        for key in TABLE_KEYS:
            coef = getattr(b, f"{key}_interpolated", None)
            if coef is not None:
                kinds.add(coef.kind)
            e[key] = jsonable(getattr(b, key, None))
        e["table_kind"] = sorted(kinds)
        bearings.append(e)

    kinds = {}
    for el in rotor.elements:
        kinds[type(el).__name__] = kinds.get(type(el).__name__, 0) + 1

    return {
        "rotor_class": type(rotor).__name__,
        "ndof": int(rotor.ndof),
        "number_dof": int(rotor.number_dof),
        "nodes": [int(n) for n in rotor.nodes],
        "nodes_pos": flist(rotor.nodes_pos),
        "link_nodes": [int(n) for n in getattr(rotor, "link_nodes", [])],
        "dofs_per_node": {str(k): sorted(v) for k, v in dofs_per_node.items()},
        "dof_order_note": ("per 6-DOF node: x, y, z (axial), alpha (rot. about x),"
                           " beta (rot. about y), theta (torsion); support nodes"
                           " (n_link targets carrying a PointMass) carry only"
                           " x, y, z"),
        "dof_layout": [[n, name] for n, name in layout],
        "element_counts": kinds,
        "shaft_elements": shafts,
        "shaft_tapered_count": sum(bool(s.get("tapered")) for s in shafts),
        "disk_elements": [
            {"class": type(d).__name__, "tag": d.tag, "n": int(d.n),
             "m": f(d.m), "Id": f(d.Id), "Ip": f(d.Ip)}
            for d in rotor.disk_elements
        ],
        "bearing_elements": bearings,
        "point_mass_elements": [
            {"tag": p.tag, "n": int(p.n), "m": jsonable(p.m), "mx": f(p.mx),
             "my": f(p.my), "mz": f(p.mz),
             "dof_global_index": {k: int(v) for k, v in p.dof_global_index.items()}}
            for p in rotor.point_mass_elements
        ],
        "rotor_parameters": jsonable_dict(getattr(rotor, "parameters", {})),
    }


def jsonable_dict(d):
    return {k: jsonable(v) for k, v in d.items()}


def coefficient_matrices(rotor, speed):
    """Lateral K, C, M (2x2, x/y) of each bearing as ROSS evaluates them
    in run_modal(speed): synchronous, frequency = speed."""
    out = []
    for b in rotor.bearing_elements:
        K = np.asarray(b.K(speed))
        C = np.asarray(b.C(speed))
        M = np.asarray(b.M(speed))
        out.append({
            "tag": b.tag, "class": type(b).__name__, "n": int(b.n),
            "n_link": None if b.n_link is None else int(b.n_link),
            "K": [flist(K[i, :2]) for i in range(2)],
            "C": [flist(C[i, :2]) for i in range(2)],
            "M": [flist(M[i, :2]) for i in range(2)],
            "kzz": f(K[2, 2]), "czz": f(C[2, 2]), "mzz": f(M[2, 2]),
            "extrapolated": bool(any(
                getattr(b, f"{k}_interpolated").extrapolates(speed, speed)
                for k in TABLE_KEYS)),
        })
    return out


# ---------------------------------------------------------------------------
# TOML save / load
# ---------------------------------------------------------------------------
def section_prefixes(path):
    data = tomllib.loads(path.read_text())
    prefixes = {}
    keys = []
    for key, val in data.items():
        if isinstance(val, dict) and key != "parameters":
            keys.append(key)
            cls = key.split("_", 1)[0]
            prefixes[cls] = prefixes.get(cls, 0) + 1
    return data, {"ross_version_in_file": data.get("ross_version"),
                  "section_prefixes": prefixes, "section_keys": keys}


def save_and_check(rotor, path, check_speed=0.0):
    path.unlink(missing_ok=True)
    rotor.save(path)
    _, info = section_prefixes(path)
    try:
        shown = path.relative_to(HERE).as_posix()
    except ValueError:
        shown = str(path)
    entry = {"file": shown,
             "sha256": hashlib.sha256(path.read_bytes()).hexdigest(), **info}
    try:
        loaded, msgs = run_quiet(rs.Rotor.load, path)
        a, _ = run_quiet(rotor.run_modal, check_speed, num_modes=24, sparse=False)
        b, _ = run_quiet(loaded.run_modal, check_speed, num_modes=24, sparse=False)
        k = min(len(a.wd), len(b.wd))
        entry["roundtrip"] = {
            "call": f"rs.Rotor.load(path).run_modal({check_speed!r}, num_modes=24,"
                    " sparse=False) vs the original",
            "loaded_class": type(loaded).__name__,
            "loaded_element_classes": sorted({type(e).__name__
                                              for e in loaded.elements}),
            "speed": check_speed,
            "max_rel_diff_wd": f(np.max(np.abs(a.wd[:k] - b.wd[:k])
                                        / np.abs(a.wd[:k]))),
            "ross_warnings": msgs,
        }
    except Exception as exc:  # noqa: BLE001
        entry["roundtrip"] = {"error": repr(exc)}
    return entry


# ---------------------------------------------------------------------------
# analyses
# ---------------------------------------------------------------------------
def modal_blocks(rotor, speeds, layout):
    blocks = []
    for s in speeds:
        blk = mrr.modal_block(rotor, float(s), layout)
        blk["bearing_coefficients_matrices"] = coefficient_matrices(rotor, float(s))
        blocks.append(blk)
    return blocks


def nearest_lateral_mode(rotor, speed, layout, target):
    """Dense modal at `speed`; the lateral mode whose wd is nearest `target`."""
    M = mrr.mass_matrix(rotor, speed)
    n = min(48, rotor.ndof)
    modal, _ = run_quiet(rotor.run_modal, speed=speed, num_modes=2 * n,
                         sparse=False)
    cls = mrr.classify(modal, M, layout, len(modal.wd))
    best = None
    for j, c in enumerate(cls):
        if c["type"] != "Lateral":
            continue
        d = abs(modal.wd[j] - target)
        if best is None or d < best[0]:
            best = (d, j, c)
    if best is None:
        return None
    _, j, c = best
    return {"wd": f(modal.wd[j]), "log_dec": f(modal.log_dec[j]),
            "forward_fraction": c["forward_fraction"],
            "whirl_weighted": mrr.whirl_label(c["forward_fraction"], c["type"]),
            "ross_whirl_direction": str(modal.whirl_direction()[j])}


def campbell_block(rotor, layout, speeds=CAMPBELL_SPEEDS,
                   frequencies=CAMPBELL_FREQUENCIES):
    t0 = time.time()
    camp, msgs = run_quiet(rotor.run_campbell, speeds, frequencies=frequencies)
    wd = np.asarray(camp.wd)
    whirl = np.asarray(camp.whirl_values, dtype=float)
    types = [[s.mode_type for s in camp.modal_results[w].shapes[:frequencies]]
             for w in speeds]
    # this script's energy type and amplitude-weighted whirl for every entry,
    # from the eigenvectors ROSS keeps (already reordered to the MAC-tracked
    # curves by run_campbell)
    fwd_frac, weighted, energy = [], [], []
    for w in speeds:
        mr = camp.modal_results[w]
        cls = mrr.classify(mr, mrr.mass_matrix(rotor, float(w)), layout,
                           frequencies)
        fwd_frac.append([c["forward_fraction"] for c in cls])
        energy.append([c["type"] for c in cls])
        weighted.append([mrr.whirl_label(c["forward_fraction"], c["type"])
                         for c in cls])
    crossings = []
    for j in range(wd.shape[1]):
        g = wd[:, j] - speeds
        for i in range(len(speeds) - 1):
            if g[i] == 0 or g[i] * g[i + 1] < 0:
                s = speeds[i] - g[i] * (speeds[i + 1] - speeds[i]) / (g[i + 1] - g[i])
                lateral = types[i][j] == "Lateral" and types[i + 1][j] == "Lateral"
                wv = whirl[i:i + 2, j]
                ross_label = ("Forward" if np.all(wv == 0) else
                              "Backward" if np.all(wv == 1) else "Mixed")
                entry = {
                    "curve": j, "speed_rad_s": f(s),
                    "bracket_rad_s": [f(speeds[i]), f(speeds[i + 1])],
                    "ross_mode_type": [types[i][j], types[i + 1][j]],
                    "ross_whirl_values_bracket": flist(wv),
                    "ross_whirl_label": ross_label if lateral else "None",
                    "energy_type_bracket": [energy[i][j], energy[i + 1][j]],
                    "forward_fraction_bracket": [fwd_frac[i][j],
                                                 fwd_frac[i + 1][j]],
                    "whirl_weighted_bracket": [weighted[i][j],
                                               weighted[i + 1][j]],
                }
                if lateral:
                    entry["check_at_crossing"] = nearest_lateral_mode(
                        rotor, float(s), layout, float(s))
                    entry["whirl_weighted"] = (entry["check_at_crossing"] or {}).get(
                        "whirl_weighted")
                crossings.append(entry)
    crossings.sort(key=lambda c: c["speed_rad_s"])
    # stability onset: where a curve's log decrement changes sign (both
    # neighbours farther than 1e-6 from zero, to skip undamped-rotor noise)
    ld = np.asarray(camp.log_dec, dtype=float)
    sign_changes = []
    for j in range(ld.shape[1]):
        for i in range(len(speeds) - 1):
            a, b = ld[i, j], ld[i + 1, j]
            if abs(a) > 1e-6 and abs(b) > 1e-6 and a * b < 0:
                t = -a / (b - a)
                sign_changes.append({
                    "curve": j,
                    "speed_rad_s": f(speeds[i] + t * (speeds[i + 1] - speeds[i])),
                    "wd_rad_s": f(wd[i, j] + t * (wd[i + 1, j] - wd[i, j])),
                    "log_dec_bracket": [f(a), f(b)],
                    "ross_mode_type": [types[i][j], types[i + 1][j]],
                    "ross_whirl_values_bracket": flist(whirl[i:i + 2, j]),
                })
    return {
        "call": (f"rotor.run_campbell(np.linspace(0, 1000, {len(speeds)}),"
                 f" frequencies={frequencies})"),
        "speed_range_rad_s": flist(speeds),
        "wd": [flist(row) for row in wd],
        "log_dec": [flist(row) for row in np.asarray(camp.log_dec)],
        "whirl_values": [flist(row) for row in whirl],
        "whirl_values_legend": "0 forward, 0.5 mixed, 1 backward, null non-lateral",
        "ross_mode_type": types,
        "energy_type": energy,
        "forward_fraction": fwd_frac,
        "whirl_weighted": weighted,
        "layout_note": ("wd[i][j]: speed i, MAC-tracked curve j (ROSS's ordering);"
                        " energy_type, forward_fraction, whirl_weighted: this"
                        " script's classification of the same eigenvectors"),
        "synchronous_crossings_derived": crossings,
        "synchronous_crossings_note": (
            "where curve j crosses wd = speed, by linear interpolation between the"
            " two bracketing Campbell speeds (computed here, not a ROSS API)."
            " ross_whirl_label: ROSS's whirl_values at both bracketing speeds"
            " (Forward if both 0, Backward if both 1, else Mixed)."
            " check_at_crossing: dense run_modal at the crossing speed, lateral"
            " mode nearest wd = speed, with the amplitude-weighted whirl label"
            " of ../make_ross_reference.py (whirl_weighted)."),
        "log_dec_sign_changes_derived": sign_changes,
        "log_dec_sign_changes_note": (
            "where curve j's log decrement changes sign between two Campbell"
            " speeds (linear interpolation; computed here, not a ROSS API);"
            " negative log_dec = unstable mode"),
        "seconds": round(time.time() - t0, 2),
        "ross_warnings": msgs,
    }


class _Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise _Timeout()


def critical_block(rotor, layout, timeout=CRITICAL_TIMEOUT_S, **kwargs):
    call = "rotor.run_critical_speed(" + ", ".join(
        f"{k}={v!r}" for k, v in kwargs.items()) + ")"
    t0 = time.time()
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(timeout)
    try:
        res, msgs = run_quiet(rotor.run_critical_speed, **kwargs)
    except _Timeout:
        return {"call": call, "error": f"not finished within {timeout} s (stopped)",
                "seconds": round(time.time() - t0, 2)}
    except Exception as exc:  # noqa: BLE001
        return {"call": call, "error": repr(exc),
                "seconds": round(time.time() - t0, 2)}
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    seconds = round(time.time() - t0, 2)
    wd = np.asarray(res.wd())
    # classify each critical speed's mode (same index, same sparse call as ROSS)
    num_modes = kwargs.get("num_modes", 12)
    if kwargs.get("speed_range") is not None:
        num_modes = (rotor.ndof - 4) * 2
    types, weighted = [], []
    for s in wd:
        modal, _ = run_quiet(rotor.run_modal, float(s), num_modes)
        M = mrr.mass_matrix(rotor, float(s))
        cls = mrr.classify(modal, M, layout, len(modal.wd))
        j = int(np.argmin(np.abs(modal.wd - s)))
        types.append(cls[j]["type"])
        weighted.append(mrr.whirl_label(cls[j]["forward_fraction"], cls[j]["type"]))
    return {
        "call": call,
        "wn": flist(res.wn()), "wd": flist(wd),
        "log_dec": flist(res.log_dec),
        "damping_ratio": flist(res.damping_ratio),
        "whirl_direction": [str(w) for w in res.whirl_direction],
        "energy_type": types,
        "whirl_weighted": weighted,
        "note": ("ROSS's Newton iteration s = wd_i(s) per mode index i (sparse"
                 " run_modal); it includes torsional/axial and backward modes."
                 " energy_type / whirl_weighted: this script's classification of"
                 " the mode nearest wd at that speed"),
        "seconds": seconds,
        "ross_warnings": msgs,
    }


def interpolation_check(rotor, speeds):
    """ROSS's kxx/kxy/cxx at `speeds` against scipy PCHIP and linear."""
    from scipy.interpolate import PchipInterpolator
    b = rotor.bearing_elements[0]
    axis = np.asarray(b.speed, dtype=float)
    out = []
    for s in speeds:
        row = {"speed_rad_s": f(s)}
        for key in ("kxx", "kyy", "kxy", "kyx", "cxx"):
            table = np.asarray(getattr(b, key), dtype=float)
            row[key] = {
                "ross": f(getattr(b, f"{key}_interpolated")(s)),
                "scipy_pchip": f(PchipInterpolator(axis, table)(s)),
                "linear": f(np.interp(s, axis, table)),
            }
        out.append(row)
    return {"bearing": b.tag, "speed_axis": flist(axis), "values": out,
            "note": ("inside the table ROSS equals scipy.interpolate."
                     "PchipInterpolator; outside it extrapolates linearly from"
                     " the PCHIP end slope")}


# ---------------------------------------------------------------------------
def run_rotor(name, rotor, speeds, outdir, campbell=True, extra=None):
    t0 = time.time()
    layout = mrr.dof_layout(rotor)
    entry = {"model": describe(rotor, layout)}
    entry["toml"] = save_and_check(rotor, outdir / f"{name}.toml")
    entry["modal"] = modal_blocks(rotor, speeds, layout)
    for blk in entry["modal"]:
        print(f"{name} @ {blk['speed_rad_s']:.1f} rad/s: lateral wd[:6] = "
              f"{np.round(blk['lateral_wd'][:6], 3).tolist()}"
              f" log_dec = {np.round(blk['lateral_log_dec'][:6], 4).tolist()}")
    if campbell:
        entry["campbell"] = campbell_block(rotor, layout)
    if extra:
        extra(entry, rotor, layout)
    entry["seconds"] = round(time.time() - t0, 2)
    return entry


def damped_extra(entry, rotor, layout):
    entry["interpolation_check"] = interpolation_check(
        rotor, [0.0, 300.0, 700.0, 1100.0])
    entry["critical_speeds"] = critical_block(rotor, layout, num_modes=32)
    print("damped_rotor critical speeds (num_modes=32):",
          np.round(entry["critical_speeds"].get("wd", []), 3).tolist(),
          entry["critical_speeds"]["seconds"], "s")
    entry["critical_speeds_speed_range"] = critical_block(
        rotor, layout, speed_range=(0, 1000))
    print("damped_rotor critical speeds (speed_range=(0, 1000)):",
          np.round(entry["critical_speeds_speed_range"].get("wd", []), 3).tolist(),
          entry["critical_speeds_speed_range"].get("error", ""),
          entry["critical_speeds_speed_range"]["seconds"], "s")


def attempt(name, build, outdir, speeds=None):
    """Build, save and reload a rotor with a kind a 4-DOF reader lacks."""
    rec = {"name": name}
    try:
        rotor, msgs = run_quiet(build)
        rec["built"] = True
        rec["rotor_class"] = type(rotor).__name__
        rec["element_classes_in_python"] = {}
        for el in rotor.elements:
            k = type(el).__name__
            rec["element_classes_in_python"][k] = (
                rec["element_classes_in_python"].get(k, 0) + 1)
        rec["build_warnings"] = msgs
    except Exception as exc:  # noqa: BLE001
        rec.update(built=False, error=repr(exc))
        return rec, None
    path = outdir / f"{name}.toml"
    try:
        rec["toml"] = save_and_check(rotor, path, check_speed=100.0)
        rec["saved"] = True
    except Exception as exc:  # noqa: BLE001
        rec.update(saved=False, error=repr(exc),
                   traceback=traceback.format_exc(limit=3))
        path.unlink(missing_ok=True)
        return rec, None
    py = set(rec["element_classes_in_python"])
    in_file = set(rec["toml"]["section_prefixes"])
    rec["classes_lost_in_toml"] = sorted(py - in_file)
    rec["classes_kept_in_toml"] = sorted(py & in_file)
    return rec, rotor


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--outdir", default=str(HERE))
    args = ap.parse_args()
    outdir = Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    (outdir / "unsupported_attempts").mkdir(exist_ok=True)
    t_start = time.time()

    result = {
        "generator": "make_extra.py (imports ../make_ross_reference.py by path)",
        "ross_version": rs.__version__,
        "python_version": platform.python_version(),
        "numpy_version": np.__version__,
        "scipy_version": __import__("scipy").__version__,
        "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(
            timespec="seconds"),
        "command": " ".join([sys.executable, Path(__file__).name, *sys.argv[1:]]),
        "units": "SI: rad/s, m, kg, N/m, N*s/m; log_dec dimensionless",
        "conventions": (
            "as ../ross_reference.json: dense run_modal(speed, num_modes=2N,"
            " sparse=False); lateral_* lists are modes whose kinetic energy is"
            " mostly in x, y, alpha, beta; whirl_weighted from forward_fraction"
            " (Forward > 0.6, Backward < 0.4, else Standing);"
            " bearing_coefficients_matrices: 2x2 lateral K, C, M of each"
            " bearing as ROSS evaluates them at that speed (frequency = speed)"),
        "rotors": {},
    }

    # 1. tapered rotor
    result["rotors"]["tapered_rotor"] = run_rotor(
        "tapered_rotor", build_tapered(), [0.0, 500.0, 1000.0], outdir)

    # 2. pedestal rotor (bearings linked to support nodes with point masses)
    result["rotors"]["pedestal_rotor"] = run_rotor(
        "pedestal_rotor", build_pedestal(), [0.0, 500.0, 1000.0], outdir)

    # 3. damped rotor with speed-tabulated bearings
    result["rotors"]["damped_rotor"] = run_rotor(
        "damped_rotor", build_damped(), [0.0, 300.0, 700.0], outdir,
        extra=damped_extra)

    # 4. element kinds a lateral 4-DOF reader does not know
    attempts = []
    amb_rec, amb_rotor = attempt("magnetic_bearing", build_amb,
                                 outdir / "unsupported_attempts")
    attempts.append(amb_rec)
    coup_rec, coup_rotor = attempt("coupling", build_coupling,
                                   outdir / "unsupported_attempts")
    attempts.append(coup_rec)
    gear_rec, _ = attempt("gear", build_gear, outdir / "unsupported_attempts")
    attempts.append(gear_rec)
    mr_rec, _ = attempt("multirotor_two_shaft_example", build_multirotor,
                        outdir / "unsupported_attempts")
    attempts.append(mr_rec)
    amb_rec["note"] = (
        "MagneticBearingElement.save is BearingElement.save, which names the"
        " section after the base class when an __init__ argument is not an"
        " instance attribute (here controller_transfer_function): the file"
        " holds a BearingElement_ section with a 50-point frequency table plus"
        " the AMB parameters (g0, i0, ag, nw, kp_pid, ...) as extra keys, and"
        " rs.Rotor.load rebuilds a plain BearingElement (same eigenvalues)")
    coup_rec["note"] = (
        "CouplingElement keeps its class name; it occupies a shaft-element slot"
        " (n -> n+1) with lumped masses and springs, no material or diameters")
    gear_rec["note"] = (
        "GearElement (a DiskElement subclass) keeps its class name; on a single"
        " Rotor it acts as a disk (m, Id, Ip); gear geometry is extra data")
    mr_rec["note"] = (
        "MultiRotor has no save of its own: Rotor.save writes the elements of"
        " both shafts flat (element numbers skip node 4, gears at nodes 4 and"
        " 5), with no MultiRotor marker and no gear-mesh data;"
        " rs.Rotor.load fails")
    for rec in attempts:
        print(f"attempt {rec['name']}: saved={rec.get('saved')},"
              f" prefixes={rec.get('toml', {}).get('section_prefixes')},"
              f" lost={rec.get('classes_lost_in_toml')},"
              f" load={rec.get('toml', {}).get('roundtrip', {}).get('error', 'ok')}")

    # the chosen file: the first kind whose class name survives in the TOML
    chosen = None
    for rec, build in ((amb_rec, build_amb), (coup_rec, build_coupling),
                       (gear_rec, build_gear)):
        if rec.get("saved") and not rec.get("classes_lost_in_toml"):
            unknown = set(rec["toml"]["section_prefixes"]) - {
                "ShaftElement", "DiskElement", "BearingElement", "SealElement",
                "PointMass"}
            if unknown:
                chosen = (rec["name"], build, sorted(unknown))
                break
    entry = run_rotor("unsupported_element", chosen[1](), [0.0, 500.0, 1000.0],
                      outdir)
    entry["chosen_kind"] = chosen[0]
    entry["unsupported_classes_in_toml"] = chosen[2]
    entry["section_prefixes"] = entry["toml"]["section_prefixes"]
    entry["attempts"] = attempts
    entry["attempts_note"] = (
        "each attempt is saved in unsupported_attempts/<name>.toml and reloaded"
        " with rs.Rotor.load; classes_lost_in_toml are Python classes whose"
        " name does not appear as a section prefix in the file")
    # the magnetic-bearing rotor is a loadable rotor with frequency-tabulated
    # bearings: keep its modal results too
    if amb_rotor is not None:
        layout = mrr.dof_layout(amb_rotor)
        entry["magnetic_bearing_variant"] = {
            "file": amb_rec["toml"]["file"],
            "model": describe(amb_rotor, layout),
            "modal": modal_blocks(amb_rotor, [0.0, 500.0, 1000.0], layout),
        }
        for blk in entry["magnetic_bearing_variant"]["modal"]:
            print(f"magnetic_bearing @ {blk['speed_rad_s']:.1f}: lateral wd[:6] ="
                  f" {np.round(blk['lateral_wd'][:6], 3).tolist()}")
    result["rotors"]["unsupported_element"] = entry

    # 5. compressor_example coefficients: already in ../ross_reference.json
    ref = json.loads((PARENT / "ross_reference.json").read_text())
    comp = ref["rotors"]["compressor_example"]
    want = [0.0, 628.3185307179587, 1047.1975511965977]
    have = [blk["speed_rad_s"] for blk in comp["modal"]]
    toml_sha = hashlib.sha256((PARENT / "compressor_example.toml").read_bytes()
                              ).hexdigest()
    result["compressor_example_coefficients"] = {
        "recomputed": False,
        "where": ("../ross_reference.json: rotors.compressor_example.modal[i]."
                  "bearing_seal_coefficients_used, i = 0, 1, 2"),
        "speeds_requested_rad_s": want,
        "speeds_in_reference_rad_s": have,
        "all_requested_speeds_present": all(
            any(np.isclose(w, h, rtol=1e-12, atol=0) for h in have) for w in want),
        "entries_per_speed": [len(blk["bearing_seal_coefficients_used"])
                              for blk in comp["modal"]],
        "fields": "tag, n, kxx, kxy, kyx, kyy, kzz, cxx, cxy, cyx, cyy, czz, mxx, mxy, myx, myy",
        "reference_generated": {k: ref.get(k) for k in
                                ("ross_version", "date_utc", "command")},
        "compressor_toml_sha256_now": toml_sha,
        "compressor_toml_sha256_in_reference":
            comp.get("toml", {}).get("sha256"),
    }

    result["seconds_total"] = round(time.time() - t_start, 1)
    out = outdir / "extra_reference.json"
    out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {out} ({result['seconds_total']} s)")


if __name__ == "__main__":
    main()
