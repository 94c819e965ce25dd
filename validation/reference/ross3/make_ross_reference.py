"""Make independent reference numbers with ROSS 3.x for three ROSS example rotors.

Run with the interpreter of a virtual environment that has ROSS 3.x
(``ross-rotordynamics``) installed, never with the project's own venv::

    /work/ross313/bin/python make_ross_reference.py                 # ROSS 3.1.0
    /work/ross300/bin/python make_ross_reference.py --outdir ross_3.0.0   # ROSS 3.0.0

For each of ``rs.rotor_example()``, ``rs.compressor_example()`` and
``rs.coaxrotor_example()`` (the last one exists in ROSS 3.0.0 but was removed in
ROSS 3.1.0; it is skipped, and recorded as unavailable, where it is missing)
the script

* saves the rotor with ``rotor.save(<name>.toml)`` into the output folder,
  parses that TOML back with ``tomllib`` to list the element classes it holds,
  and tries ``rs.Rotor.load(<name>.toml)`` to check the round trip;
* runs ``rotor.run_modal`` at three speeds and stores, per mode, wd, wn, log
  decrement, damping ratio, ROSS's whirl direction and mode type, the kinetic
  energy fractions of the lateral (x, y, alpha, beta), axial (z) and torsional
  (theta) DOFs, and the orbit parameter kappa over the nodes;
* stores the bearing / seal coefficients ROSS used at each speed;
* for rotor_example and coaxrotor_example runs ``rotor.run_campbell`` on
  ``np.linspace(0, 1000, 21)`` and ``rotor.run_critical_speed``;
* writes everything to ``<outdir>/ross_reference.json``.

Everything is in SI units: rad/s, m, kg, N/m, N*s/m.
"""

import argparse
import datetime
import hashlib
import io
import json
import os
import platform
import sys
import time
import tomllib
import warnings
from contextlib import redirect_stdout, redirect_stderr
from pathlib import Path

import numpy as np

# ROSS (through CoolProp) prints a long REFPROP notice on import, partly from
# C code: silence file descriptors 1 and 2 while importing.
def _import_ross_quietly():
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        with redirect_stdout(io.StringIO()), redirect_stderr(io.StringIO()), \
                warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import ross
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(devnull)
        os.close(saved[0])
        os.close(saved[1])
    return ross


rs = _import_ross_quietly()

HERE = Path(__file__).resolve().parent
LATERAL = ("x", "y", "alpha", "beta")
AXIAL = ("z",)
TORSIONAL = ("theta",)
MIN_LATERAL = 16  # store modes until at least this many lateral ones are in
MIN_MODES = 24  # and at least this many modes in all
COEFS = ("kxx", "kxy", "kyx", "kyy", "kzz", "cxx", "cxy", "cyx", "cyy", "czz",
         "mxx", "mxy", "myx", "myy", "mzz")
RPM = np.pi / 30.0


def f(x):
    """Plain float (NaN -> None) for JSON."""
    x = float(np.real(x))
    return None if not np.isfinite(x) else x


def flist(a):
    return [f(x) for x in np.asarray(a).ravel()]


def run_quiet(fn, *args, **kwargs):
    """Call fn, returning (result, sorted unique warning messages)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn(*args, **kwargs)
    msgs = sorted({str(w.message) for w in caught})
    return out, msgs


# --------------------------------------------------------------------------
# model description
# --------------------------------------------------------------------------
def dof_layout(rotor):
    """Global DOF index -> (node, dof name), from the elements' own maps."""
    layout = {}
    for el in rotor.elements:
        for key, idx in getattr(el, "dof_global_index", {}).items():
            name, node = key.rsplit("_", 1)
            layout[int(idx)] = (int(node), name)
    assert sorted(layout) == list(range(rotor.ndof)), "DOF map has holes"
    return [layout[i] for i in range(rotor.ndof)]


def describe(rotor, layout):
    per_node = {}
    for node, name in layout:
        per_node.setdefault(node, []).append(name)
    dofs_per_node = {}
    for node, names in per_node.items():
        dofs_per_node.setdefault(len(names), []).append(node)

    shafts = []
    for sh in rotor.shaft_elements:
        shafts.append({
            "n": int(sh.n), "n_l": int(sh.n_l), "n_r": int(sh.n_r),
            "L": f(sh.L), "idl": f(sh.idl), "odl": f(sh.odl),
            "idr": f(sh.idr), "odr": f(sh.odr),
            "material": sh.material.name,
            "tapered": bool(not np.isclose(sh.idl, sh.idr)
                            or not np.isclose(sh.odl, sh.odr)),
            "shear_effects": bool(sh.shear_effects),
            "rotary_inertia": bool(sh.rotary_inertia),
            "gyroscopic": bool(sh.gyroscopic),
            "axial_force": f(getattr(sh, "axial_force", 0) or 0),
            "torque": f(getattr(sh, "torque", 0) or 0),
        })
    count_n = {}
    for s in shafts:
        count_n[s["n"]] = count_n.get(s["n"], 0) + 1
    layered = sorted(n for n, c in count_n.items() if c > 1)

    bearings = []
    for b in rotor.bearing_elements:
        entry = {
            "class": type(b).__name__, "tag": b.tag, "n": int(b.n),
            "n_link": None if b.n_link is None else int(b.n_link),
        }
        for axis in ("speed", "frequency"):
            a = getattr(b, axis, None)
            entry[f"{axis}_axis"] = None if a is None else flist(a)
        bearings.append(entry)

    kinds = {}
    for el in rotor.elements:
        kinds[type(el).__name__] = kinds.get(type(el).__name__, 0) + 1

    return {
        "rotor_class": type(rotor).__name__,
        "ndof": int(rotor.ndof),
        "number_dof": int(rotor.number_dof),
        "nodes": [int(n) for n in rotor.nodes],
        "nodes_pos": flist(rotor.nodes_pos),
        "dofs_per_node": {str(k): sorted(v) for k, v in dofs_per_node.items()},
        "dof_order_note": ("per 6-DOF node: x, y, z (axial), alpha (rot. about x),"
                           " beta (rot. about y), theta (torsion); extra nodes"
                           " (e.g. n_link supports with a PointMass) carry only"
                           " x, y, z"),
        "dof_layout": [[n, name] for n, name in layout],
        "element_counts": kinds,
        "shaft_elements": shafts,
        "shaft_tapered_count": sum(s["tapered"] for s in shafts),
        "shaft_layered_positions_n": layered,
        "materials": sorted({s["material"] for s in shafts}),
        "disk_elements": [
            {"n": int(d.n), "m": f(d.m), "Id": f(d.Id), "Ip": f(d.Ip), "tag": d.tag}
            for d in rotor.disk_elements
        ],
        "bearing_elements": bearings,
        "point_mass_elements": [
            {"n": int(p.n), "mx": f(p.mx), "my": f(p.my),
             "mz": f(getattr(p, "mz", np.nan)), "tag": p.tag}
            for p in rotor.point_mass_elements
        ],
        "rotor_parameters": {k: (v if not isinstance(v, (np.floating, np.integer))
                                 else float(v))
                             for k, v in getattr(rotor, "parameters", {}).items()},
    }


def toml_sections(path):
    """Element classes and counts found in a saved ROSS TOML."""
    data = tomllib.loads(path.read_text())
    kinds = {}
    for key, val in data.items():
        if isinstance(val, dict) and "_" in key and key != "parameters":
            cls = key.split("_", 1)[0]
            kinds[cls] = kinds.get(cls, 0) + 1
    return {"ross_version_in_file": data.get("ross_version"),
            "top_level_keys_sample": sorted(data)[:3],
            "element_classes": kinds}


def coefficients_at(rotor, speed):
    out = []
    for b in rotor.bearing_elements:
        K = np.asarray(b.K(speed))
        C = np.asarray(b.C(speed))
        M = np.asarray(b.M(speed))
        out.append({
            "tag": b.tag, "n": int(b.n),
            "kxx": f(K[0, 0]), "kxy": f(K[0, 1]), "kyx": f(K[1, 0]), "kyy": f(K[1, 1]),
            "kzz": f(K[2, 2]) if K.shape[0] > 2 else None,
            "cxx": f(C[0, 0]), "cxy": f(C[0, 1]), "cyx": f(C[1, 0]), "cyy": f(C[1, 1]),
            "czz": f(C[2, 2]) if C.shape[0] > 2 else None,
            "mxx": f(M[0, 0]), "mxy": f(M[0, 1]), "myx": f(M[1, 0]), "myy": f(M[1, 1]),
        })
    return out


# --------------------------------------------------------------------------
# modal analysis
# --------------------------------------------------------------------------
def mass_matrix(rotor, speed):
    try:
        return np.asarray(rotor.M(frequency=speed, speed=speed))
    except TypeError:
        return np.asarray(rotor.M(speed))


def classify(modal, M, layout, n_modes):
    """Kinetic-energy fractions per DOF family, own mode type, kappa stats."""
    names = np.array([name for _, name in layout])
    lat = np.isin(names, LATERAL)
    axi = np.isin(names, AXIAL)
    tor = np.isin(names, TORSIONAL)
    rows = []
    for j in range(n_modes):
        v = modal.evectors[: modal.ndof, j]
        e = {}
        for key, mask in (("lateral", lat), ("axial", axi), ("torsional", tor)):
            vm = v[mask]
            e[key] = float(np.real(np.conj(vm) @ M[np.ix_(mask, mask)] @ vm))
        tot = sum(e.values())
        frac = {k: val / tot for k, val in e.items()} if tot > 0 else e
        own = max(frac, key=frac.get)
        shape = modal.shapes[j]
        kappas = None
        if getattr(shape, "orbits", None):
            ks = np.array([o.kappa for o in shape.orbits])
            amp = np.array([o.major_axis for o in shape.orbits])
            kappas = {"min": f(ks.min()), "max": f(ks.max()),
                      "at_max_amplitude_node": f(ks[np.argmax(amp)])}
        # Amplitude-weighted whirl measure over all nodes' x, y translations:
        # x + i*y = F e^{i w t} + B e^{-i w t}, |F| = |u + i v|/2,
        # |B| = |u - i v|/2; forward_fraction = sum|F|^2 / sum(|F|^2 + |B|^2).
        # 1 = pure forward, 0 = pure backward, 0.5 = straight-line (standing).
        u, w = v[names == "x"], v[names == "y"]
        F2 = np.sum(np.abs(u + 1j * w) ** 2)
        B2 = np.sum(np.abs(u - 1j * w) ** 2)
        fwd = float(F2 / (F2 + B2)) if F2 + B2 > 0 else None
        rows.append({"energy_fraction": frac, "type": own.capitalize(),
                     "kappa": kappas, "forward_fraction": fwd})
    return rows


def whirl_label(fwd, mode_type):
    """Forward / Backward / Standing from the amplitude-weighted measure."""
    if mode_type != "Lateral" or fwd is None:
        return "None"
    if fwd > 0.6:
        return "Forward"
    if fwd < 0.4:
        return "Backward"
    return "Standing"


def modal_block(rotor, speed, layout):
    M = mass_matrix(rotor, speed)
    n = MIN_MODES
    while True:
        modal, msgs = run_quiet(rotor.run_modal, speed=speed,
                                num_modes=2 * n, sparse=False)
        n_have = len(modal.wd)
        cls = classify(modal, M, layout, n_have)
        n_lat = sum(c["type"] == "Lateral" for c in cls)
        if n_lat >= MIN_LATERAL or n_have < n or 2 * n >= 2 * rotor.ndof:
            break
        n += 8
    evalues = np.asarray(modal.evalues)
    whirl = [str(w) for w in modal.whirl_direction()]
    ross_type = [s.mode_type for s in modal.shapes]
    modes = []
    for j in range(n_have):
        modes.append({
            "index": j,
            "wd": f(modal.wd[j]), "wn": f(modal.wn[j]),
            "log_dec": f(modal.log_dec[j]),
            "damping_ratio": f(modal.damping_ratio[j]),
            "eigenvalue": [f(evalues[j].real), f(evalues[j].imag)],
            "ross_mode_type": ross_type[j],
            "ross_whirl_direction": whirl[j],
            "energy_type": cls[j]["type"],
            "energy_fraction": cls[j]["energy_fraction"],
            "kappa": cls[j]["kappa"],
            "forward_fraction": cls[j]["forward_fraction"],
            "whirl_weighted": whirl_label(cls[j]["forward_fraction"],
                                          cls[j]["type"]),
        })
    lat = [m for m in modes if m["energy_type"] == "Lateral"]

    # cross-check against ROSS's default ARPACK path (sparse=True)
    sparse_modal, _ = run_quiet(rotor.run_modal, speed=speed, num_modes=24)
    k = min(len(sparse_modal.wd), n_have)
    dev = np.max(np.abs(np.asarray(sparse_modal.wd[:k]) - modal.wd[:k])
                 / np.maximum(np.abs(modal.wd[:k]), 1e-12))
    n_real = int(np.sum(np.abs(evalues.imag) < 1e-9))
    # run_modal does not check the coefficient tables unless given a
    # frequency: ask ROSS's own check so that extrapolation is on record.
    check = getattr(rotor, "_check_coefficient_axes", None)
    if check is not None:
        _, axis_msgs = run_quiet(check, speed=speed, frequency=speed)
        msgs = sorted(set(msgs) | set(axis_msgs))
    return {
        "speed_rad_s": f(speed), "speed_rpm": f(speed / RPM),
        "call": f"rotor.run_modal(speed={speed!r}, num_modes={2 * n}, sparse=False)",
        "n_modes_stored": n_have,
        "wd": [m["wd"] for m in modes],
        "wn": [m["wn"] for m in modes],
        "log_dec": [m["log_dec"] for m in modes],
        "whirl_direction": whirl,
        "ross_mode_type": ross_type,
        "energy_type": [m["energy_type"] for m in modes],
        "lateral_indices": [m["index"] for m in lat],
        "lateral_wd": [m["wd"] for m in lat],
        "lateral_wn": [m["wn"] for m in lat],
        "lateral_log_dec": [m["log_dec"] for m in lat],
        "lateral_whirl_direction": [m["ross_whirl_direction"] for m in lat],
        "lateral_whirl_weighted": [m["whirl_weighted"] for m in lat],
        "lateral_forward_fraction": [m["forward_fraction"] for m in lat],
        "modes": modes,
        "real_eigenvalues_total": n_real,
        "real_eigenvalues_stored": int(np.sum(np.abs(evalues[:n_have].imag) < 1e-9)),
        "real_eigenvalues_note": ("count of real (overdamped, wd = 0) eigenvalues"
                                  " among all ROSS returned after its rigid-body"
                                  " filter |lambda| > 0.1; ROSS sorts them after"
                                  " every oscillatory mode (wd > 0)"),
        "sparse_default_check": {
            "call": f"rotor.run_modal(speed={speed!r}, num_modes=24)",
            "wd": flist(sparse_modal.wd),
            "max_rel_diff_vs_full_first_k": f(dev), "k": int(k),
        },
        "bearing_seal_coefficients_used": coefficients_at(rotor, speed),
        "ross_warnings": msgs,
    }


# --------------------------------------------------------------------------
# Campbell and critical speeds
# --------------------------------------------------------------------------
def campbell_block(rotor, speeds, frequencies):
    t0 = time.time()
    camp, msgs = run_quiet(rotor.run_campbell, speeds, frequencies=frequencies)
    wd = np.asarray(camp.wd)
    types = []
    for w in speeds:
        mr = camp.modal_results[w]
        types.append([s.mode_type for s in mr.shapes[:frequencies]])
    # 1X crossings of each tracked Campbell curve, by linear interpolation
    # (derived here from ROSS's wd table; not a ROSS API).
    crossings = []
    for j in range(wd.shape[1]):
        g = wd[:, j] - speeds
        for i in range(len(speeds) - 1):
            if g[i] == 0 or g[i] * g[i + 1] < 0:
                s = speeds[i] - g[i] * (speeds[i + 1] - speeds[i]) / (g[i + 1] - g[i])
                crossings.append({
                    "curve": j, "speed_rad_s": f(s),
                    "ross_mode_type_at_upper_speed": types[i + 1][j],
                    "whirl_value_at_upper_speed": f(camp.whirl_values[i + 1, j]),
                })
    return {
        "call": f"rotor.run_campbell(np.linspace(0, 1000, 21), frequencies={frequencies})",
        "speed_range_rad_s": flist(speeds),
        "wd": [flist(row) for row in wd],
        "log_dec": [flist(row) for row in np.asarray(camp.log_dec)],
        "whirl_values": [flist(row) for row in np.asarray(camp.whirl_values)],
        "whirl_values_legend": "0 forward, 0.5 mixed, 1 backward, null non-lateral",
        "ross_mode_type": types,
        "layout_note": "wd[i][j]: speed i, MAC-tracked curve j (ROSS's ordering)",
        "synchronous_crossings_derived": crossings,
        "seconds": round(time.time() - t0, 2),
        "ross_warnings": msgs,
    }


def critical_block(rotor, **kwargs):
    t0 = time.time()
    call = "rotor.run_critical_speed(" + ", ".join(
        f"{k}={v!r}" for k, v in kwargs.items()) + ")"
    try:
        res, msgs = run_quiet(rotor.run_critical_speed, **kwargs)
    except Exception as exc:  # record, don't fail
        return {"call": call, "error": repr(exc),
                "seconds": round(time.time() - t0, 2)}
    return {
        "call": call,
        "wn": flist(res.wn()), "wd": flist(res.wd()),
        "log_dec": flist(res.log_dec),
        "whirl_direction": [str(w) for w in res.whirl_direction],
        "note": ("ROSS's Newton iteration s = wd_i(s) per mode index i; it includes"
                 " torsional/axial modes and backward modes; index-tracked, so"
                 " check against the Campbell crossings"),
        "seconds": round(time.time() - t0, 2),
        "ross_warnings": msgs,
    }


# --------------------------------------------------------------------------
def compressor_speeds(rotor):
    """Two speeds that are tabulated points of every bearing and seal table."""
    axes = [np.asarray(b.speed, dtype=float) for b in rotor.bearing_elements
            if getattr(b, "speed", None) is not None and np.size(b.speed) > 1]
    lo = max(a.min() for a in axes)
    hi = min(a.max() for a in axes)
    print(f"compressor_example: coefficient speed axes, common range "
          f"{lo:.3f} .. {hi:.3f} rad/s ({lo / RPM:.0f} .. {hi / RPM:.0f} rpm)")
    for b in rotor.bearing_elements:
        a = np.asarray(b.speed, dtype=float)
        print(f"  {b.tag:>10s} n={b.n:<3d} {a.min():9.3f} .. {a.max():9.3f} rad/s,"
              f" {a.size} points")
    chosen = [6000 * RPM, 10000 * RPM]
    on_axis = {}
    for s in chosen:
        assert lo <= s <= hi
        on_axis[f(s)] = all(np.any(np.isclose(a, s, rtol=1e-9)) for a in axes)
    return chosen, {"common_range_rad_s": [f(lo), f(hi)],
                    "speed_axes_rad_s": {b.tag: flist(b.speed)
                                         for b in rotor.bearing_elements},
                    "chosen_speeds_on_every_table": on_axis,
                    "note": ("speed 0 is outside every table: ROSS extrapolates the"
                             " coefficients there (3.1.0: linearly from the end"
                             " slope), see bearing_seal_coefficients_used")}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--outdir", default=str(HERE),
                    help="output folder (relative to this script's folder)")
    args = ap.parse_args()
    outdir = Path(args.outdir)
    if not outdir.is_absolute():
        outdir = HERE / outdir
    outdir.mkdir(parents=True, exist_ok=True)

    result = {
        "generator": "make_ross_reference.py",
        "ross_version": rs.__version__,
        "python_version": platform.python_version(),
        "numpy_version": np.__version__,
        "scipy_version": __import__("scipy").__version__,
        "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(
            timespec="seconds"),
        "command": " ".join([sys.executable, Path(__file__).name, *sys.argv[1:]]),
        "units": "SI: rad/s, m, kg, N/m, N*s/m; log_dec dimensionless",
        "mode_type_note": (
            "ross_mode_type: ROSS's own Shape classification (Axial/Torsional if"
            " >90% of the significant DOFs are z/theta, else Lateral). energy_type:"
            " largest kinetic-energy share (v^H M v over x,y,alpha,beta | z |"
            " theta DOFs), computed here. lateral_* lists use energy_type."),
        "rotors": {},
    }

    for name in ("rotor_example", "compressor_example", "coaxrotor_example"):
        factory = getattr(rs, name, None)
        if factory is None:
            print(f"{name}: not available in ROSS {rs.__version__}")
            result["rotors"][name] = {
                "available": False,
                "reason": (f"rs.{name} does not exist in ROSS {rs.__version__} "
                           "(CoAxialRotor and coaxrotor_example were removed "
                           "after 3.0.0)"),
            }
            continue
        t0 = time.time()
        rotor, build_msgs = run_quiet(factory)
        layout = dof_layout(rotor)
        entry = {"available": True, "factory": f"rs.{name}()",
                 "model": describe(rotor, layout), "build_warnings": build_msgs}

        toml_path = outdir / f"{name}.toml"
        toml_path.unlink(missing_ok=True)
        rotor.save(toml_path)
        entry["toml"] = {"file": toml_path.name,
                         "sha256": hashlib.sha256(toml_path.read_bytes()).hexdigest(),
                         **toml_sections(toml_path)}
        try:
            loaded, _ = run_quiet(rs.Rotor.load, toml_path)
            s_chk = 0.0 if name != "compressor_example" else 6000 * RPM
            a, _ = run_quiet(rotor.run_modal, s_chk, num_modes=24)
            b, _ = run_quiet(loaded.run_modal, s_chk, num_modes=24)
            entry["toml"]["roundtrip"] = {
                "loaded_class": type(loaded).__name__,
                "speed": s_chk,
                "max_rel_diff_wd": f(np.max(np.abs(a.wd - b.wd) / np.abs(a.wd))),
            }
        except Exception as exc:
            entry["toml"]["roundtrip"] = {"error": repr(exc)}

        if name == "compressor_example":
            speeds, info = compressor_speeds(rotor)
            speeds = [0.0] + speeds
            entry["coefficient_tables"] = info
        else:
            speeds = [0.0, 500.0, 1000.0]

        entry["modal"] = [modal_block(rotor, s, layout) for s in speeds]
        for blk in entry["modal"]:
            print(f"{name} @ {blk['speed_rad_s']:.3f} rad/s: lateral wd[:8] = "
                  f"{np.round(blk['lateral_wd'][:8], 3).tolist()}")

        if name in ("rotor_example", "coaxrotor_example"):
            entry["campbell"] = campbell_block(rotor, np.linspace(0, 1000, 21), 16)
            # 16 modes from speed 0 (Newton per mode index); the
            # speed_range=(0, 1000) form iterates every mode of the model,
            # which for the coaxial rotor ran ~8 min and failed to converge.
            entry["critical_speeds"] = critical_block(rotor, num_modes=32)
            if name == "rotor_example":
                entry["critical_speeds_speed_range"] = critical_block(
                    rotor, speed_range=(0, 1000))
        entry["seconds"] = round(time.time() - t0, 2)
        result["rotors"][name] = entry

    out = outdir / "ross_reference.json"
    out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
