"""What every result type shows of itself: a short repr, a figure and a labelled dataset.

A result type of rotorred (a Campbell diagram, an unbalance response, a transient record, a
branch, ...) derives from :class:`Result` and gives three things:

- :meth:`Result.summary` -- at most :data:`MAX_REPR_LINES` - 1 short lines: what was computed, on
  what, and the headline numbers; never an array. ``repr()`` is the type's name followed by them.
- :meth:`Result.plot` -- ``plot(ax=None, **options)`` draws the result into ``ax`` (a new figure
  when ``None``) and returns the matplotlib ``Figure``. The drawing lives in :mod:`rotorred.plots`;
  ``plot`` imports it when called, so that building a result never loads matplotlib.
- :meth:`Result.view` -- ``view(**options)``: the result as an interactive plotly ``Figure`` (inline in Jupyter),
  drawn by :mod:`rotorred.plots.interactive` (imported when called); ``_repr_html_`` shows the summary in a notebook.
- :meth:`Result.to_xarray` -- an :class:`xarray.Dataset` with named dimensions and a ``units``
  attribute on every variable and coordinate (``"1"`` for a dimensionless one), so that
  :func:`rotorred.writers.write_netcdf` writes it as CF NetCDF and reads it back as it was.

A dataclass result is declared ``@dataclass(frozen=True, repr=False)`` so that the generated
repr, which prints every array, does not replace :meth:`Result.__repr__`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

#: longest repr of a result (lines, the type's name included)
MAX_REPR_LINES = 15


class Result:
    """Base of the result types: a short :func:`repr`, :meth:`plot` and :meth:`to_xarray`."""

    def summary(self) -> list[str]:
        """What was computed, on what, and the headline numbers: a few short lines without arrays."""
        raise NotImplementedError(f"{type(self).__name__}.summary")

    def __repr__(self) -> str:  # (borrowed by types with a summary that are not results, e.g. Rotor)
        return "\n".join([f"{type(self).__name__}:"] + [f"  {line}" for line in _short_summary(self)])

    def _repr_html_(self) -> str:
        """The summary as a notebook shows it: the type's name and its lines, HTML-escaped."""
        import html

        return (f'<div class="rotorred-result"><strong>{html.escape(type(self).__name__)}</strong>'
                f'<pre>{html.escape(chr(10).join(_short_summary(self)))}</pre></div>')

    def plot(self, ax=None, **options):
        """Draw the result into ``ax`` (a new figure when None); return the matplotlib Figure.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            Options of the type's drawing function in :mod:`rotorred.plots`.

        Returns
        -------
        matplotlib.figure.Figure
        """
        raise NotImplementedError(f"{type(self).__name__}.plot")

    def view(self, **options):
        """The result as an interactive plotly Figure, which displays inline in Jupyter (the interactive counterpart
        of :meth:`plot`, what ROSS's ``plot`` returns: rotorred's ``plot(backend="plotly")``).

        Parameters
        ----------
        **options
            ``kind``, the figure's name (default the result's main figure: the Campbell diagram, the Bode plot, the
            waveforms, the class map, the branch, the amplitude against speed), and the options of the type's view in
            :mod:`rotorred.plots.interactive` (e.g. ``operating_speed`` (rad/s) of a Campbell diagram).

        Returns
        -------
        plotly.graph_objects.Figure

        Raises
        ------
        InputError
            If the type has no interactive view (:data:`rotorred.plots.interactive.VIEWS`) or ``kind`` is unknown.
        """
        from rotorred.plots.interactive import view

        return view(self, **options)

    def to_xarray(self):
        """The result as an :class:`xarray.Dataset` with named dimensions and ``units`` on every variable."""
        raise NotImplementedError(f"{type(self).__name__}.to_xarray")


def _short_summary(result) -> list[str]:
    """``result.summary()`` as text lines, cut to :data:`MAX_REPR_LINES` - 1."""
    lines = [str(line) for line in result.summary()]
    if len(lines) > MAX_REPR_LINES - 1:  # a bug of the type's summary: keep the repr short all the same
        lines = lines[: MAX_REPR_LINES - 2] + [f"... ({len(lines) - MAX_REPR_LINES + 2} more lines)"]
    return lines


def label_coordinate(dim: str, labels: Sequence[str], long_name: str) -> tuple:
    """A dimension coordinate of string labels for :meth:`Result.to_xarray` (``units`` "1")."""
    return (dim, np.array(labels, dtype=object), {"units": "1", "long_name": long_name})


def dof_coordinates(dim: str, dofs: Sequence[tuple[int, str]], long_name: str) -> dict:
    """Coordinates of a dimension of (node, direction) pairs for :meth:`Result.to_xarray`: labels ``"13:x"``, and
    the node and the direction (``<dim>_node``, ``<dim>_direction``; ``node`` and ``direction`` for ``output``)."""
    prefix = "" if dim == "output" else f"{dim}_"
    return {dim: label_coordinate(dim, [f"{n}:{d}" for n, d in dofs], long_name),
            f"{prefix}node": (dim, np.array([n for n, _ in dofs], np.int64), {"units": "1", "long_name": "node"}),
            f"{prefix}direction": (dim, np.array([d for _, d in dofs], dtype=object),
                                   {"units": "1", "long_name": "direction (x, y, tx, ty)"})}


def strongest_lines(outputs: Sequence[tuple[int, str]], amplitudes: np.ndarray, where: Sequence[str],
                    n: int = 3, shown: int = 8) -> list[str]:
    """Summary lines of each output's ``n`` strongest lines, ``"node 14 y: 2.79 µm at 91.37 Hz, ..."``, for the first
    ``shown`` outputs, then how many more.

    Parameters
    ----------
    outputs : sequence of (int, str)
        The DOFs (node, direction), one per column of ``amplitudes``.
    amplitudes : ndarray, shape (K, len(outputs))
        Amplitude of each line (m).
    where : sequence of str, length K
        Where each line is, e.g. ``"91.37 Hz"``.
    n, shown : int
        Lines per output, outputs listed.
    """
    lines = []
    for j, (node, direction) in enumerate(outputs[:shown]):
        top = np.argsort(-amplitudes[:, j])[:n]
        lines.append(f"node {node} {direction}: " + ", ".join(
            f"{1e6 * amplitudes[k, j]:.4g} µm at {where[k]}" for k in top if amplitudes[k, j] > 0))
    if len(outputs) > shown:
        lines.append(f"... {len(outputs) - shown} more outputs")
    return lines
