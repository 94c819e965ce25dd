"""What every output folder of a command must show of its provenance (tests/test_provenance.py and the command
tests of maps and branches use it)."""

from __future__ import annotations

import re
import shlex
import tomllib
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

#: a tracker reference ("issue 12"), which no output may hold
TRACKER = re.compile(r"\bissue \d+", re.IGNORECASE)
#: a CF name: letters, digits and underscores, starting with a letter
CF_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def assert_provenance(folder: Path, argv: list[str], summary: str, kind: str, since: datetime) -> str:
    """``folder`` holds ``<kind>.toml`` (valid TOML); ``summary`` starts (under an INCOMPLETE paragraph) with the
    rotorred version and a date after ``since``, the command line of ``argv`` and the resolved file's name; every NPZ,
    .mat and NetCDF file carries the same version, command, date and resolved TOML text; NetCDF files follow CF
    (units everywhere, CF names, Conventions); no file holds a tracker reference. Returns the resolved TOML text."""
    import rotorred

    command = shlex.join(["rotorred", *argv])
    text = (folder / summary).read_text()
    if text.startswith("INCOMPLETE"):
        text = text.split("\n\n", 1)[1]
    head = text.splitlines()[:3]
    version, _, date = head[0].partition(", ")
    assert version == f"rotorred {rotorred.__version__}", head
    when = datetime.strptime(date, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=timezone.utc)
    assert since.replace(microsecond=0) <= when <= datetime.now(timezone.utc), (date, since)
    assert head[1] == f"command: {command}" and head[2] == f"resolved {kind}: {kind}.toml", head
    file_text = (folder / f"{kind}.toml").read_text()
    assert file_text.startswith(f"# {head[0]}\n# {head[1]}\n")
    resolved = file_text.split("\n\n", 1)[1]
    tomllib.loads(resolved)
    expected = {"rotorred_version": rotorred.__version__, "rotorred_command": command, "rotorred_date": date,
                f"rotorred_{kind}": resolved}
    for path in folder.glob("*.npz"):
        with np.load(path) as npz:
            assert {k: str(npz[k]) for k in expected} == expected, path
    for path in folder.glob("*.mat"):
        _assert_mat(path, expected)
    for path in folder.glob("*.nc"):
        _assert_netcdf(path, expected)
    for path in folder.iterdir():
        if path.suffix in (".txt", ".csv", ".toml"):
            assert not TRACKER.search(path.read_text()), path
    return resolved


def _assert_mat(path: Path, expected: dict) -> None:
    from scipy.io import loadmat

    mat = loadmat(path)
    for name, value in expected.items():
        assert str(mat[name][0]) == value, (path, name)


def _assert_netcdf(path: Path, expected: dict) -> None:
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert {k: ds.attrs[k] for k in expected} == expected, path
        assert ds.attrs["Conventions"] == "CF-1.10"
        assert ds.attrs["source"] == f"rotorred {expected['rotorred_version']}"
        assert ds.attrs["history"] == f"{expected['rotorred_date']}: {expected['rotorred_command']}"
        missing = [n for n, v in ds.variables.items() if not v.attrs.get("units")]
        assert not missing, (path, missing)
        bad = [n for n in [*ds.variables, *ds.dims] if not CF_NAME.fullmatch(str(n))]
        assert not bad, (path, bad)
    import h5netcdf

    with h5netcdf.File(path, "r") as f:  # the file as CF reads it, without xarray's decoding
        coordinates = [v for n, v in f.variables.items() if v.dimensions == (n,)]
        assert all(v.dtype.kind in "fiu" for v in coordinates), (path, [v.name for v in coordinates])  # CF 1.2
        assert not [v.name for v in coordinates if "_FillValue" in v.attrs], path  # CF 5
        assert not any(TRACKER.search(str(v)) for v in ds.attrs.values()), path
