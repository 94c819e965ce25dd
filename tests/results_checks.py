"""The checks every result type must pass (rotorred.results.Result): used by each result's tests."""

from __future__ import annotations

import re

import numpy as np

from rotorred.results import MAX_REPR_LINES, Result

#: what an array looks like in a repr: numpy's "array(", or four numbers in a row inside brackets
_ARRAY = re.compile(r"array\(|\[\s*[-+0-9.eE]+(?:[ ,]+[-+0-9.eE]+){3,}")


def assert_short_repr(result: Result) -> str:
    """repr is at most MAX_REPR_LINES lines, starts with the type's name and holds no array."""
    text = repr(result)
    lines = text.splitlines()
    assert 2 <= len(lines) <= MAX_REPR_LINES, text
    assert lines[0].startswith(type(result).__name__), text
    assert not _ARRAY.search(text), text
    assert max(map(len, lines)) <= 120, text
    return text


def assert_plots(result: Result, **options):
    """plot() returns a Figure with something drawn; plot(ax=ax) draws into the given axes."""
    from matplotlib.figure import Figure

    fig = result.plot(**options)
    assert isinstance(fig, Figure)
    assert fig.axes and any(ax.lines or ax.collections or ax.images or ax.patches for ax in fig.axes)
    given = Figure().subplots()
    assert result.plot(ax=given, **options) is given.figure
    assert given.lines or given.collections or given.images or given.patches
    return fig


def assert_dataset_round_trips(result: Result, tmp_path):
    """to_xarray() has named dimensions and units on every variable and coordinate, and round-trips through NetCDF."""
    from rotorred.writers import read_netcdf, write_netcdf

    ds = result.to_xarray()
    assert ds.data_vars
    for name, var in ds.variables.items():
        assert var.attrs.get("units"), f"{name} has no units"
    path = write_netcdf(tmp_path / f"{type(result).__name__}.nc", ds)
    back = read_netcdf(path)
    assert set(back.data_vars) == set(ds.data_vars)
    for name, var in ds.variables.items():
        assert back[name].dims == var.dims, name
        assert back[name].attrs["units"] == var.attrs["units"], name
        if np.issubdtype(var.dtype, np.number):
            np.testing.assert_array_equal(back[name].values, var.values, err_msg=name)
        else:
            assert [str(v) for v in np.ravel(back[name].values)] == [str(v) for v in np.ravel(var.values)], name
    return ds


def assert_shows_itself(result: Result, tmp_path, of: type, **plot_options):
    """All three: a short repr, a Figure, a dataset that round-trips through NetCDF, of a result of type ``of``
    (tests/test_public_api.py finds every exported result type named here)."""
    assert type(result) is of and isinstance(result, Result)
    assert_short_repr(result)
    assert_plots(result, **plot_options)
    assert_dataset_round_trips(result, tmp_path)
