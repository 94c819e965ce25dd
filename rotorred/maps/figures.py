"""A map's figures from its dataset (:meth:`rotorred.maps.run.MapRun.plot`): bifurcation diagram and waterfall along
the continuation axis, heat maps over two axes (drawn by :mod:`rotorred.plots.map`).

The figures along the continuation axis are drawn at the first value of the other axes:
``bifurcation.png`` (Poincare samples of the table DOF against the varied key, the up and down
sweeps in two colours), ``waterfall.png`` (each point's labelled lines; the spools' 1x order
lines when the key is a speed) and ``lines.png`` (the amplitudes of f_L, f_H and the strongest
other lines, the contact fraction and the impacts against the key, with the free orbit's reach
on a clearance axis: the one-key sweep's figure), the last two of one sweep (the first);
for a 2-D map also ``class_map.png``, ``contact_map.png``, ``explained_map.png`` and
``amplitude_map.png`` (largest line) per sweep direction.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rotorred import checks
from rotorred.maps.spec import MapSpec
from rotorred.scenes.keys import key_unit, netcdf_name
from rotorred.plots.axes import save_figure
from rotorred.plots.map import CLASS_COLOURS, plot_bifurcation, plot_heatmap, plot_lines, plot_waterfall

__all__ = ["KINDS", "QUANTITIES", "draw", "map_figures"]

#: the class names of a class map, in legend order
CATEGORIES = tuple(CLASS_COLOURS)
#: the figures of a map (:func:`draw`), the first the default
KINDS = ("bifurcation", "lines", "waterfall", "heatmap")
#: the quantities of a heat map and their labels
QUANTITIES = {"class": "response class", "contact": "contact fraction", "explained": "explained share",
              "amplitude": "largest line (µm)"}


def map_figures(run, folder: Path) -> list[Path]:
    """Write the figures of ``run`` (a :class:`rotorred.maps.run.MapRun`) into ``folder`` (module docstring), each
    drawn by ``run.plot``."""
    files = [save_figure(run.plot(kind=kind), folder / f"{kind}.png") for kind in ("bifurcation", "waterfall", "lines")]
    if len(run.spec.axes) >= 2:
        directions = [str(d) for d in run.dataset["direction"].values]
        for d in directions:
            tag = "" if len(directions) == 1 else f"_{d}"
            files += [save_figure(run.plot(kind="heatmap", direction=d, quantity=q), folder / f"{q}_map{tag}.png")
                      for q in QUANTITIES]
    return files


def draw(ds, spec: MapSpec, kind: str = "bifurcation", ax=None, *, direction: str | None = None,
         quantity: str = "class"):
    """One figure of a map's dataset ``ds`` (:func:`rotorred.maps.store.to_dataset`) into ``ax`` (a new figure when
    None; a pair of axes for "lines"): the Figure.

    Parameters
    ----------
    ds : xarray.Dataset
    spec : MapSpec
    kind : {"bifurcation", "lines", "waterfall", "heatmap"}
        The figure (module docstring); "heatmap" needs two varied keys.
    ax : matplotlib Axes or pair of Axes, optional
        Axes to draw into; default a new figure.
    direction : str, optional
        The sweep of "lines", "waterfall" and "heatmap" (default: the first).
    quantity : {"class", "contact", "explained", "amplitude"}
        The heat map's quantity.
    """
    if kind not in KINDS:
        checks.fail("kind", kind, f"must be one of {', '.join(KINDS)}")
    directions = [str(d) for d in ds["direction"].values]
    direction = directions[0] if direction is None else direction
    if direction not in directions:
        checks.fail("direction", direction, f"must be a sweep of the map ({', '.join(directions)})")
    if kind == "bifurcation":
        return _bifurcation(ds, spec, ax)
    if kind == "heatmap":
        return _heat_map(ds, spec, ax, direction, quantity)
    return (_waterfall if kind == "waterfall" else _lines)(ds, spec, ax, direction)


def _first_of_the_rest(ds, spec: MapSpec, n_kept: int):
    """The dataset at index 0 of every axis after the first ``n_kept``, and a title suffix naming them."""
    rest = {netcdf_name(a.key): 0 for a in spec.axes[n_kept:]}
    text = ", ".join(f"{a.key} = {key_unit(a.key)[0] * a.values[0]:.4g} {key_unit(a.key)[1]}".rstrip()
                     for a in spec.axes[n_kept:])
    return ds.isel(rest), (f" at {text}" if text else "")


def _bifurcation(ds, spec: MapSpec, ax):
    """The Poincare samples of every sweep along the continuation axis (the other axes at their first value)."""
    axis = spec.axes[0]
    sub, where = _first_of_the_rest(ds, spec, 1)
    samples = {str(d): sub["poincare_x"].sel(direction=d).values for d in sub["direction"].values}
    return plot_bifurcation(np.array(axis.values), samples, ax, xlabel=axis.label, xscale=key_unit(axis.key)[0],
                            ylabel=f"Poincaré samples of {ds.attrs.get('table_dof', '')}",
                            title=f"{spec.scene}: bifurcation diagram{where}")


def _waterfall(ds, spec: MapSpec, ax, direction: str):
    """The labelled lines of one sweep along the continuation axis; the spools' 1x order lines on a speed axis."""
    axis = spec.axes[0]
    sub, where = _first_of_the_rest(ds, spec, 1)
    orders = ({f"1× {axis.key.split('.')[-1]}": 1.0} if axis.key.startswith("speeds.") else None)
    return plot_waterfall(np.array(axis.values), sub["line_frequency"].sel(direction=direction).values,
                          sub["line_amplitude"].sel(direction=direction).values, ax, xlabel=axis.label,
                          xscale=key_unit(axis.key)[0], orders=orders,
                          title=f"{spec.scene}: labelled lines of {ds.attrs.get('table_dof', '')} ({direction} sweep)"
                                f"{where}")


def _lines(ds, spec: MapSpec, ax, direction: str):
    """Line amplitudes, contact and impacts of one sweep along the continuation axis, the free orbit's reach on a
    clearance axis."""
    axis = spec.axes[0]
    sub, where = _first_of_the_rest(ds, spec, 1)
    one = sub.sel(direction=direction)
    reach = float(np.nanmedian(one["free_reach"].values)) if axis.key.endswith("clearance") else None
    return plot_lines(np.array(axis.values), _by_label(one), one["contact_fraction"].values, _impacts(one), ax,
                      xlabel=axis.label, xscale=key_unit(axis.key)[0],
                      reach=None if reach is None or np.isnan(reach) else reach,
                      ylabel=f"Line amplitude of {ds.attrs.get('table_dof', '')}",
                      title=f"{spec.scene}: lines and contact ({direction} sweep){where}")


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


def _heat_map(ds, spec: MapSpec, ax, direction: str, quantity: str):
    """Class, contact fraction, explained share or largest line amplitude of one sweep over the first two axes."""
    if len(spec.axes) < 2:
        checks.fail("kind", "heatmap", "needs a map of two varied keys (this one varies one: see kind='lines')")
    if quantity not in QUANTITIES:
        checks.fail("quantity", quantity, f"must be one of {', '.join(QUANTITIES)}")
    ax_, ay = spec.axes[0], spec.axes[1]
    sub, where = _first_of_the_rest(ds, spec, 2)
    one = sub.sel(direction=direction)
    categories = None
    if quantity == "class":
        status = one["status"].values
        kind = np.where(status == "ok", one["kind"].values, np.where(status == "", "", "failed"))
        z, categories = np.vectorize(lambda k: CATEGORIES.index(k) if k in CATEGORIES else -1)(kind), CATEGORIES
    elif quantity == "amplitude":
        z = 1e6 * _largest(one["line_amplitude"].values)
    else:
        z = one[{"contact": "contact_fraction", "explained": "explained_share"}[quantity]].values
    label = QUANTITIES[quantity]
    return plot_heatmap(np.array(ax_.values), np.array(ay.values), np.asarray(z).T, ax, xlabel=ax_.label,
                        ylabel=ay.label, zlabel=label, xscale=key_unit(ax_.key)[0], yscale=key_unit(ay.key)[0],
                        categories=categories, title=f"{spec.scene}: {label} ({direction} sweep){where}")
