"""A map's figures from its dataset: bifurcation diagram and waterfall along the continuation axis,
heat maps over two axes (:mod:`rotorred.plots.map`).

The figures along the continuation axis are drawn at the first value of the other axes:
``bifurcation.png`` (Poincare samples of the table DOF against the varied key, the up and down
sweeps in two colours), ``waterfall.png`` (each point's labelled lines; the spools' 1x order
lines when the key is a speed) and ``lines.png`` (the amplitudes of f_L, f_H and the strongest
other lines, the contact fraction and the impacts against the key, with the free orbit's reach
on a clearance axis: the one-key sweep's figure); for a 2-D map also ``class_map.png``,
``contact_map.png``, ``explained_map.png`` and ``amplitude_map.png`` (largest line) per sweep
direction.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rotorred.maps.spec import MapSpec
from rotorred.scenes.keys import key_unit, netcdf_name
from rotorred.plots.map import CLASS_COLOURS, plot_bifurcation, plot_heatmap, plot_lines, plot_waterfall

__all__ = ["map_figures"]

#: the class names of a class map, in legend order
CATEGORIES = tuple(CLASS_COLOURS)


def map_figures(ds, spec: MapSpec, folder: Path) -> list[Path]:
    """Write the map's figures into ``folder`` (module docstring)."""
    files = _along(ds, spec, folder)
    if len(spec.axes) >= 2:
        files += _heat_maps(ds, spec, folder)
    return files


def _first_of_the_rest(ds, spec: MapSpec, n_kept: int):
    """The dataset at index 0 of every axis after the first ``n_kept``, and a title suffix naming them."""
    rest = {netcdf_name(a.key): 0 for a in spec.axes[n_kept:]}
    text = ", ".join(f"{a.key} = {key_unit(a.key)[0] * a.values[0]:.4g} {key_unit(a.key)[1]}".rstrip()
                     for a in spec.axes[n_kept:])
    return ds.isel(rest), (f" at {text}" if text else "")


def _along(ds, spec: MapSpec, folder: Path) -> list[Path]:
    """Bifurcation diagram and waterfall along the continuation axis (the other axes at their first value)."""
    axis = spec.axes[0]
    scale, unit = key_unit(axis.key)
    sub, where = _first_of_the_rest(ds, spec, 1)
    samples = {str(d): sub["poincare_x"].sel(direction=d).values for d in sub["direction"].values}
    d = ds.attrs.get("table_dof", "")
    files = [plot_bifurcation(np.array(axis.values), samples, folder / "bifurcation.png", xlabel=axis.label,
                              xscale=scale, ylabel=f"Poincaré samples of {d}",
                              title=f"{spec.scene}: bifurcation diagram{where}")]
    first = str(sub["direction"].values[0])
    orders = ({f"1× {axis.key.split('.')[-1]}": 1.0} if axis.key.startswith("speeds.") else None)
    files.append(plot_waterfall(np.array(axis.values), sub["line_frequency"].sel(direction=first).values,
                                sub["line_amplitude"].sel(direction=first).values, folder / "waterfall.png",
                                xlabel=axis.label, xscale=scale, orders=orders,
                                title=f"{spec.scene}: labelled lines of {d} ({first} sweep){where}"))
    one = sub.sel(direction=first)
    reach = float(np.nanmedian(one["free_reach"].values)) if axis.key.endswith("clearance") else None
    files.append(plot_lines(np.array(axis.values), _by_label(one), one["contact_fraction"].values,
                            _impacts(one), folder / "lines.png", xlabel=axis.label,
                            xscale=scale, reach=None if reach is None or np.isnan(reach) else reach,
                            ylabel=f"Line amplitude of {d}",
                            title=f"{spec.scene}: lines and contact ({first} sweep){where}"))
    return files


def _impacts(one) -> np.ndarray:
    n = one["n_impacts"].values
    return np.where(n >= 0, n, np.nan).astype(float)


def _by_label(one) -> dict:
    """{line label: amplitude (m) per point}: 0 where a point has no such line, NaN where it has no result."""
    labels, amps = one["line_label"].values, one["line_amplitude"].values
    ok = one["status"].values == "ok"
    out = {}
    for i in range(labels.shape[0]):
        for label, a in zip(labels[i], amps[i]):
            if label:
                out.setdefault(str(label), np.where(ok, 0.0, np.nan))[i] = a
    return out


def _largest(amplitudes: np.ndarray) -> np.ndarray:
    """Largest line amplitude per point (last axis: lines, NaN-padded); NaN where a point has none."""
    none = np.all(np.isnan(amplitudes), axis=-1)
    return np.where(none, np.nan, np.max(np.nan_to_num(amplitudes, nan=0.0), axis=-1))


def _heat_maps(ds, spec: MapSpec, folder: Path) -> list[Path]:
    """Class, contact fraction, explained share and largest line amplitude over the first two axes."""
    ax, ay = spec.axes[0], spec.axes[1]
    (sx, _), (sy, _) = key_unit(ax.key), key_unit(ay.key)
    sub, where = _first_of_the_rest(ds, spec, 2)
    files = []
    for d in sub["direction"].values:
        one = sub.sel(direction=d)
        tag = "" if len(sub["direction"]) == 1 else f"_{d}"
        kind = np.where(one["status"].values == "ok", one["kind"].values, np.where(one["status"].values == "", "",
                                                                                    "failed"))
        index = np.vectorize(lambda k: CATEGORIES.index(k) if k in CATEGORIES else -1)(kind)
        grids = {"class": (index, "response class", CATEGORIES),
                 "contact": (one["contact_fraction"].values, "contact fraction", None),
                 "explained": (one["explained_share"].values, "explained share", None),
                 "amplitude": (1e6 * _largest(one["line_amplitude"].values), "largest line (µm)", None)}
        for name, (z, label, categories) in grids.items():
            files.append(plot_heatmap(np.array(ax.values), np.array(ay.values), np.asarray(z).T,
                                      folder / f"{name}_map{tag}.png", xlabel=ax.label, ylabel=ay.label,
                                      zlabel=label, xscale=sx, yscale=sy, categories=categories,
                                      title=f"{spec.scene}: {label} ({d} sweep){where}"))
    return files
