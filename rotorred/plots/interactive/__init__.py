"""Interactive views of the results: plotly figures for a notebook and one self-contained ``report.html`` a command.

One registry (:data:`VIEWS`) maps each result type to the module that draws it (``campbell``, ``response``,
``scene``, ``map``, ``branch``, ``runup``). A view module gives

- ``figures(result, **options)``: the result's figures, ``[(name, figure)]``, each a plain plotly figure dict
  (``{"data": [...], "layout": {...}}``: building one never imports plotly, so a command's report costs no import);
- ``report(result, **options)``: the :class:`~rotorred.plots.interactive.report.Report` of ``report.html``: those
  figures and what only interaction gives (a mode's shape when a Campbell point is clicked, a map point's orbit and
  spectrum), its data embedded compactly and its small script.

:func:`view` wraps one figure as a :class:`plotly.graph_objects.Figure` (which displays inline in Jupyter):
``Result.view(**options)`` (:meth:`rotorred.results.Result.view`) calls it. :func:`write_report` writes the report.
"""

from __future__ import annotations

import importlib
from pathlib import Path

from rotorred import checks

#: result type ("module.Class") -> the view module of this package that draws it
VIEWS = {
    "rotorred.linear.campbell.CampbellResult": "campbell",
    "rotorred.linear.harmonic.UnbalanceResponse": "response",
    "rotorred.scenes.run.SceneResult": "scene",
    "rotorred.transient.results.TransientResult": "scene",
    "rotorred.maps.run.MapRun": "map",
    "rotorred.scenes.branch.SceneBranch": "branch",
    "rotorred.nonlinear.continuation.Branch": "branch",
    "rotorred.scenes.runup.RunupResult": "runup",
}

__all__ = ["VIEWS", "view", "figures", "report_of", "write_report"]


def view_module(result):
    """The view module of ``result``'s type (the first of its classes that :data:`VIEWS` names).

    Raises
    ------
    InputError
        If no view draws this type.
    """
    for cls in type(result).__mro__:
        name = VIEWS.get(f"{cls.__module__}.{cls.__qualname__}")
        if name is not None:
            return importlib.import_module(f"{__name__}.{name}")
    kinds = sorted({k.rpartition(".")[2] for k in VIEWS})
    return checks.fail("result", type(result).__name__, "has no interactive view; these have one: " + ", ".join(kinds))


def figures(result, **options) -> list[tuple[str, dict]]:
    """The interactive figures of ``result``: ``[(name, figure dict)]``, the first the main one.

    Parameters
    ----------
    result : Result
        A result type of :data:`VIEWS`.
    **options
        Options of its view module's ``figures`` (e.g. ``operating_speed`` (rad/s) of a Campbell diagram).
    """
    return view_module(result).figures(result, **options)


def view(result, kind: str | None = None, **options):
    """One interactive figure of ``result`` as a :class:`plotly.graph_objects.Figure` (inline in Jupyter).

    Parameters
    ----------
    result : Result
        A result type of :data:`VIEWS`.
    kind : str, optional
        The figure's name (of :func:`figures`, e.g. ``"waveforms"``, ``"spectra_node14"``, ``"orbits"``); default the
        first, the result's main figure.
    **options
        Options of the type's view (:func:`figures`).

    Returns
    -------
    plotly.graph_objects.Figure
    """
    import plotly.graph_objects as go

    named = dict(figures(result, **options))
    if kind is None:
        kind = next(iter(named))
    checks.choice("kind", kind, named)
    return go.Figure(named[kind])


def report_of(result, **options):
    """The :class:`~rotorred.plots.interactive.report.Report` (``report.html``) of ``result``.

    Parameters
    ----------
    result : Result
        A result type of :data:`VIEWS`.
    **options
        Options of its view module's ``report`` (a Campbell diagram's ``model``, for the mode shapes shown on a
        click, and ``operating_speed`` (rad/s)).
    """
    return view_module(result).report(result, **options)


def write_report(result, path: str | Path, **options) -> Path:
    """Write ``report.html`` of ``result`` (:func:`report_of`) to ``path``, atomically
    (:func:`rotorred.writers.write_text`: a full disk is a :class:`rotorred.writers.ResourceFault`).

    Parameters
    ----------
    result : Result
    path : str or Path
        The HTML file.
    **options
        Options of :func:`report_of`.

    Returns
    -------
    Path
        ``path``.
    """
    return report_of(result, **options).write(path)
