"""A map's points on disk, written one by one as they finish, and the labelled dataset built from them.

Layout of ``--out``
    ``points/<direction>/<i>_<j>....npz``: one file per finished point (written atomically by
    :func:`rotorred.writers.write_npz`, so a killed run leaves whole files only), with the
    state the next point of its chain starts from. ``spec.json`` holds what defines every point, by content
    (:meth:`PointStore.identity`): the resolved scene of the first grid point (every key, the rotor's tables
    inline; not the scene's path), the varied keys and their values, the ratios, the start, the limit and the
    rotorred version. The same map resumes (the same scene file moved, or with only its comments changed, too); a
    run whose identity differs in anything is refused, naming what differs (the scene's keys with both values),
    before any point runs: the folder keeps its points, and removing ``points/`` runs the map from the start.
    ``map.nc``, ``map.csv``, ``map_lines.csv`` and the figures are rebuilt from the points.

Dataset (:func:`to_dataset`, xarray)
    Dimensions: ``direction`` ("up", "down"), one per varied key (named by
    :func:`rotorred.scenes.keys.netcdf_name`, ``rub.clearance`` -> ``rub_clearance``, the key itself in the
    coordinate's ``long_name`` and ``rotorred_key``, values in the scene's units), ``line`` (strongest first),
    ``sample`` (Poincare samples, the last ones) and ``node`` (output nodes). Points not run (yet) are missing:
    status "", NaN, -1. Every variable and coordinate carries CF ``units`` ("1" when dimensionless, strings
    included) and ``long_name``; the dataset carries the scene, the fixed settings and the table DOF as attributes.
    The points on disk hold no names of the dataset, so a folder written before the names changed resumes.
"""

from __future__ import annotations

import json
from dataclasses import fields, replace
from pathlib import Path

import numpy as np

from rotorred.maps.point import N_LINES, N_SAMPLES, PointResult, StartState
from rotorred.maps.spec import MapSpec
from rotorred.scenes.keys import cf_units, netcdf_name
from rotorred.transient.results import FinalState
from rotorred.writers import write_csv, write_npz, write_text

__all__ = ["PointStore", "to_dataset", "write_tables", "SCALARS", "point_bytes", "check_map_size"]

#: the per-point scalars: name -> (dtype, missing value, units, long name). CF units: "1" for every dimensionless
#: variable, counts and the string variables (status, reason, kind, start) included
SCALARS = {
    "status": ("U8", "", "1", "ok, diverged or failed"),
    "reason": ("U1000", "", "1", "why the point has no results"),
    "kind": ("U14", "", "1", "response class of the table DOF"),
    "subharmonic": ("i8", -1, "1", "k of a period-k response"),
    "period": ("f8", np.nan, "s", "period of a periodic response"),
    "settling_time": ("f8", np.nan, "s", "measured settling time (NaN: not settled)"),
    "explained_share": ("f8", np.nan, "1", "share of the energy the labelled lines explain"),
    "torus_k": ("i8", -1, "1", "sub-harmonic order of f_H"),
    "torus_j": ("i8", -1, "1", "sub-harmonic order of f_L"),
    "poincare_frequency": ("f8", np.nan, "Hz", "Poincare section frequency"),
    "contact_fraction": ("f8", np.nan, "1", "fraction of the record in contact (first plate)"),
    "n_impacts": ("i8", -1, "1", "contact onsets in the record (first plate)"),
    "max_contact_force": ("f8", np.nan, "N", "largest normal contact force (first plate)"),
    "free_reach": ("f8", np.nan, "m", "reach of the settled no-rub orbit towards the first plate"),
    "start": ("U4", "", "1", "cold (scene's start) or warm (neighbour's final state)"),
    "simulated": ("f8", np.nan, "s", "simulated time, segments run until settled included"),
    "wall_time": ("f8", np.nan, "s", "wall time of the point"),
}
#: per-point vectors: name -> (dimension, length, dtype, missing, units, long name)
VECTORS = {
    "line_frequency": ("line", N_LINES, "f8", np.nan, "Hz", "labelled line frequency"),
    "line_amplitude": ("line", N_LINES, "f8", np.nan, "m", "labelled line amplitude"),
    "line_phase": ("line", N_LINES, "f8", np.nan, "rad", "labelled line phase"),
    "line_label": ("line", N_LINES, "U40", "", "1", "labelled line combination"),
    "poincare_x": ("sample", N_SAMPLES, "f8", np.nan, "m", "Poincare samples of the table DOF"),
    "poincare_velocity": ("sample", N_SAMPLES, "f8", np.nan, "m/s", "Poincare samples of its velocity"),
}


def _point_name(direction: str, index: tuple[int, ...]) -> str:
    return f"{direction}/" + "_".join(str(i) for i in index) + ".npz"


#: the fields of the transient's FinalState kept with a point, the start of its chain's next point
_FINAL = tuple(f.name for f in fields(FinalState))


def _arrays(p: PointResult) -> dict:
    arrays = {name: np.array(getattr(p, name)) for name in SCALARS if name not in ("torus_k", "torus_j")}
    arrays.update(torus_k=np.array(p.torus[0]), torus_j=np.array(p.torus[1]), peak_orbit=p.peak_orbit,
                  **{name: np.asarray(getattr(p, name)) for name in VECTORS})
    if p.final is not None:
        arrays.update({f"final_{name}": np.asarray(getattr(p.final.state, name)) for name in _FINAL},
                      final_phases=np.array(p.final.phases))
    return arrays


def _point(arrays) -> PointResult:
    final = None
    if "final_q" in arrays:
        state = FinalState(**{name: arrays[f"final_{name}"] for name in _FINAL})
        final = StartState(replace(state, t=float(state.t)), tuple(float(p) for p in arrays["final_phases"]))
    scalars = {name: arrays[name].item() for name in SCALARS if name not in ("torus_k", "torus_j")}
    vectors = {name: arrays[name] for name in VECTORS}
    vectors["line_label"] = tuple(str(s) for s in vectors["line_label"])
    return PointResult(**scalars, **vectors, torus=(int(arrays["torus_k"]), int(arrays["torus_j"])),
                       peak_orbit=arrays["peak_orbit"], final=final)


def point_bytes(n_nodes: int) -> int:
    """Memory of one point in the map's dataset (bytes): its scalars, vectors and the peak orbit of ``n_nodes``
    nodes, as :func:`to_dataset` holds them."""
    scalars = sum(np.dtype(dtype).itemsize for dtype, *_ in SCALARS.values())
    vectors = sum(n * np.dtype(dtype).itemsize for _, n, dtype, *_ in VECTORS.values())
    return scalars + vectors + 8 * n_nodes


def check_map_size(spec: MapSpec, workers: int = 1, force: bool = False) -> None:
    """Refuse a map beyond the size limits of a run (:mod:`rotorred.scenes.budget`), unless ``force``: first at once,
    from its first grid point's scene before any other is read (a grid of 1e5 points is answered at once), then point
    by point (:meth:`MapSpec.check_size`).

    At once: the first point's own estimate (naming its key), its steps times the grid points
    (:meth:`MapSpec.check_steps`), and the memory of ``workers`` points' records and models at once and of the map's
    dataset (:func:`point_bytes`, times 3: the dataset, its tables and NetCDF).

    Parameters
    ----------
    spec : MapSpec
        The map.
    workers : int
        Points run at once, >= 1.
    force : bool
        Let a map beyond the limits go on.

    Raises
    ------
    InputError
        Naming the key or ``--vary``, the estimate and ``--force``; or a point's scene is invalid.
    """
    import math

    from rotorred.scenes import budget

    scene = spec.scene_at((0,) * len(spec.axes))
    one = budget.scene_estimate(scene).check(force=force)
    spec.check_steps(math.prod(spec.shape) * spec.steps_at(scene), force)
    at_once = max(1, min(int(workers), spec.n_points))
    dataset = 3 * spec.n_points * point_bytes(len(scene.output.nodes))
    fields = {"steps": ("--vary", spec.described), "memory": ("--vary", spec.described), "dofs": one.fields["dofs"]}
    budget.Estimate(0, at_once * one.samples, at_once * one.record_bytes + dataset, one.n_dof,
                    at_once * one.model_bytes, fields, "recorded samples at once and the map's dataset").check(force)
    spec.check_size(force)


class PointStore:
    """The finished points of one map in ``folder/points``: written as they finish, read back on resume."""

    def __init__(self, folder: str | Path, spec: MapSpec):
        self.root = Path(folder) / "points"
        self.spec = spec
        self._check_spec()

    def identity(self) -> dict:
        """What defines every point of the map, by content (module docstring): ``scene`` (the resolved scene of the
        first grid point, TOML text), ``axes``, ``ratios``, ``cold``, ``limit`` and ``rotorred`` (the version)."""
        from rotorred.provenance import package_version
        from rotorred.scenes.resolved import scene_toml

        s = self.spec
        return {"scene": scene_toml(s.scene_at((0,) * len(s.axes))),
                "axes": [[a.key, list(a.values)] for a in s.axes], "ratios": [list(r) for r in s.ratios],
                "cold": s.cold, "limit": s.limit, "rotorred": package_version()}

    def _check_spec(self) -> None:
        from rotorred import checks

        path = self.root / "spec.json"
        if not path.exists():
            return
        try:
            kept = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, ValueError):
            kept = None
        differences = _differences(kept, self.identity())
        if differences:
            checks.fail("--out", str(self.root.parent), f"holds the points of a different map ({'; '.join(differences)}"
                        f"); choose another --out, or remove {self.root} to run this map from the start")

    def write(self, direction: str, index: tuple[int, ...], point: PointResult) -> Path:
        """Write one finished point (atomically)."""
        path = self.root / _point_name(direction, index)
        if not (self.root / "spec.json").exists():
            write_text(self.root / "spec.json", json.dumps(self.identity(), sort_keys=True, indent=1))
        return write_npz(path, _arrays(point))

    def read(self) -> dict:
        """Every finished point: {(direction, index): PointResult}."""
        out = {}
        for direction in ("up", "down"):
            for path in sorted((self.root / direction).glob("*.npz")):
                index = tuple(int(i) for i in path.stem.split("_"))
                with np.load(path) as arrays:
                    out[(direction, index)] = _point(dict(arrays))
        return out


#: what each field of a map's identity is, as a refusal names it
_IDENTITY_NAMES = {"axes": "the varied keys or their values (--vary)", "ratios": "the speed ratios (--ratio)",
                   "cold": "the start (--cold)", "limit": "the time limit (--limit)", "rotorred": "the rotorred version"}


def _differences(kept, now: dict) -> list[str]:
    """What differs between the identity of the points on disk (``kept``, parsed ``spec.json``) and ``now``: a
    phrase per field, the scene's by its keys (at most 3, with both values)."""
    if not isinstance(kept, dict) or set(kept) != set(now):
        return ["points/spec.json is not one this rotorred version writes, so the points cannot be told to be of "
                "this map"]
    out = [f"{name}: {kept[field]!r} in the points, {now[field]!r} now" for field, name in _IDENTITY_NAMES.items()
           if kept[field] != now[field]]
    if kept["scene"] != now["scene"]:
        out.insert(0, "the scene's content differs at " + _scene_differences(kept["scene"], now["scene"]))
    return out


def _scene_differences(kept: str, now: str, most: int = 3) -> str:
    """The keys at which two resolved scenes (TOML text) differ, with both values: ``rub[0].mu_d (0.3 in the points,
    0.2 now)``."""
    from rotorred.checks import InputError
    from rotorred.model.rotor_file import read_toml

    def flat(value, path=""):
        if isinstance(value, dict):
            return {k: v for key, item in value.items() for k, v in flat(item, f"{path}.{key}" if path else key).items()}
        if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            return {k: v for i, item in enumerate(value) for k, v in flat(item, f"{path}[{i}]").items()}
        return {path: value}

    try:
        a, b = flat(read_toml(kept)), flat(read_toml(now))
    except InputError:
        return "its text"
    keys = [k for k in sorted(set(a) | set(b)) if a.get(k, "<none>") != b.get(k, "<none>")]
    shown = [f"{k} ({a.get(k, '<none>')!r} in the points, {b.get(k, '<none>')!r} now)" for k in keys[:most]]
    return ", ".join(shown) + (f" and {len(keys) - most} more keys" if len(keys) > most else "")


def _padded(values, n: int, dtype: str, missing):
    out = np.full(n, missing, dtype=dtype)
    values = np.asarray(values)[:n]
    out[:values.size] = values
    return out


def to_dataset(spec: MapSpec, points: dict, nodes: tuple[int, ...], attrs: dict | None = None):
    """The labelled dataset of a map's points (module docstring), missing points left blank."""
    import xarray as xr

    dirs = spec.directions
    shape = (len(dirs), *spec.shape)
    dims = ("direction", *(netcdf_name(a.key) for a in spec.axes))
    data = {name: np.full(shape, missing, dtype=dtype) for name, (dtype, missing, *_) in SCALARS.items()}
    data.update({name: np.full((*shape, n), missing, dtype=dtype) for name, (_, n, dtype, missing, *_) in VECTORS.items()})
    data["peak_orbit"] = np.full((*shape, len(nodes)), np.nan)
    for (direction, index), p in points.items():
        at = (dirs.index(direction), *index)
        arrays = _arrays(p)
        for name in SCALARS:
            data[name][at] = arrays[name]
        for name, (_, n, dtype, missing, *_) in VECTORS.items():
            data[name][at] = _padded(arrays[name], n, dtype, missing)
        if p.peak_orbit.size:  # none for a point without results
            data["peak_orbit"][at] = p.peak_orbit
    variables = {name: (dims, data[name], {"units": u, "long_name": ln}) for name, (_, _, u, ln) in SCALARS.items()}
    variables.update({name: ((*dims, dim), data[name], {"units": u, "long_name": ln})
                      for name, (dim, _, _, _, u, ln) in VECTORS.items()})
    variables["peak_orbit"] = ((*dims, "node"), data["peak_orbit"], {"units": "m", "long_name": "largest orbit radius"})
    coords = {"direction": ("direction", list(dirs), {"units": "1", "long_name": "sweep direction (up, down)"}),
              "node": ("node", list(nodes), {"units": "1", "long_name": "output node"})}
    for a in spec.axes:
        name = netcdf_name(a.key)
        coords[name] = (name, np.array(a.values), {"units": cf_units(a.key), "long_name": a.key, "rotorred_key": a.key})
    return xr.Dataset(variables, coords=coords, attrs=dict(attrs or {}))


def write_tables(ds, folder: Path) -> list[Path]:
    """``map.csv`` (one row per point) and ``map_lines.csv`` (one row per point and line), tidy: a varied key's column
    named by the key (its ``rotorred_key``), a number's with its units (not an integer's, nor a string's)."""
    keys = [k for k in ds.dims if k not in ("direction", "line", "sample", "node")]
    flat = ds.drop_dims(["line", "sample", "node"]).to_dataframe().reset_index()
    flat = flat[flat["status"] != ""]
    header = [_column(ds, c) for c in flat.columns]
    orbit = ds["peak_orbit"].stack(point=("direction", *keys)).transpose("point", "node")
    done = (ds["status"] != "").stack(point=("direction", *keys)).values
    extra = [f"peak orbit node {n} (um)" for n in ds["node"].values]
    columns = [flat[c].to_numpy() for c in flat.columns] + [1e6 * orbit.values[done, i] for i in range(len(extra))]
    files = [write_csv(folder / "map.csv", header + extra, columns)]
    lines = ds[["line_frequency", "line_amplitude", "line_phase", "line_label"]].to_dataframe().reset_index()
    lines = lines[lines["line_label"] != ""]
    lines["line_amplitude"] *= 1e6
    header = [c for c in lines.columns if c != "line"]
    named = {"line_frequency": "frequency (Hz)", "line_amplitude": "amplitude (um)", "line_phase": "phase (rad)",
             "line_label": "label"}
    files.append(write_csv(folder / "map_lines.csv", [named.get(c, _column(ds, c)) for c in header],
                           [lines[c].to_numpy() for c in header]))
    return files


def _column(ds, name: str) -> str:
    """A CSV column's header: the varied key as the scene writes it, the units of a float (``"free_reach (m)"``)."""
    if name not in ds.variables:
        return name
    v = ds[name]
    label = v.attrs.get("rotorred_key", name)
    return f"{label} ({v.attrs['units']})" if v.dtype.kind == "f" and v.attrs.get("units") else label
