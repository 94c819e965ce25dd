"""Pieces shared by the interactive views: a figure's layout, a hover template, unit scales."""

from __future__ import annotations

import numpy as np

RPM = 30.0 / np.pi  #: rad/s -> rpm
MICRO = 1e6  #: m -> µm


def layout(title: str, x: str, y: str, **more) -> dict:
    """A figure's layout: ``title``, the axes' titles (with their units), hover on the closest point, legend on the
    right; ``more`` merged in (e.g. ``yaxis2``, ``shapes``)."""
    out = {"title": {"text": title, "font": {"size": 15}}, "hovermode": "closest",
           "xaxis": {"title": {"text": x}, "zeroline": False}, "yaxis": {"title": {"text": y}, "zeroline": False},
           "margin": {"l": 70, "r": 20, "t": 50, "b": 55}, "legend": {"font": {"size": 11}}}
    for key, value in more.items():
        out[key] = {**out[key], **value} if isinstance(out.get(key), dict) and isinstance(value, dict) else value
    return out


#: plotly's default colours, in its order
COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")


def color(k: int) -> str:
    """The ``k``-th colour of :data:`COLORS` (cycled)."""
    return COLORS[k % len(COLORS)]


def hover(*rows: str) -> str:
    """A hover template of ``rows`` (plotly's ``%{...}`` fields), one a line, without the trace box."""
    return "<br>".join(rows) + "<extra></extra>"


def figure(data: list, layout_: dict) -> dict:
    """A plotly figure dict."""
    return {"data": data, "layout": layout_}


def decimated(n: int, most: int) -> slice:
    """Every k-th of ``n`` samples so that at most ``most`` remain."""
    return slice(None, None, max(1, -(-n // most)))


def finite(values) -> np.ndarray:
    """``values`` as a float array (NaN kept: JSON null, a gap in a line)."""
    return np.asarray(values, dtype=float)
