"""One writer per output format: CSV, NPZ, MATLAB .mat and text.

Every file rotorred writes goes through this module. Each writer writes to a temporary file
beside the target and renames it into place (``os.replace``), so a reader never sees a
half-written file, and an interrupted write leaves the earlier file (or none) behind.

CSV: a header row, then one row per sample; floats with ``digits`` significant digits,
integers and strings as they are. Units belong in the header (``"amplitude (um)"``).
"""

from __future__ import annotations

import csv
import io
import os
import tempfile
from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np

__all__ = ["write_csv", "write_npz", "write_mat", "write_text", "atomic_path", "render_table"]


@contextmanager
def atomic_path(path: str | Path, suffix: str = ""):
    """Yield a temporary path in ``path``'s folder; on success it replaces ``path``, on error it is removed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".tmp{suffix}", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _cell(value, digits: int) -> str:
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.{digits}g}"
    if isinstance(value, np.integer):
        return str(int(value))
    return str(value)


def write_csv(path: str | Path, header: Sequence[str], columns: Sequence[Sequence], digits: int = 9) -> Path:
    """Write equal-length ``columns`` under ``header`` as CSV.

    Parameters
    ----------
    path : str or Path
    header : sequence of str, length k
        Column names, with units.
    columns : sequence of k sequences of equal length n
        Column values: floats are written with ``digits`` significant digits.
    digits : int
        Significant digits of floats.

    Returns
    -------
    Path
    """
    if len(header) != len(columns):
        raise ValueError(f"write_csv: {len(header)} header names for {len(columns)} columns")
    lengths = {len(c) for c in columns}
    if len(lengths) > 1:
        raise ValueError(f"write_csv: columns of different lengths {sorted(lengths)}")
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for row in zip(*columns):
        w.writerow([_cell(v, digits) for v in row])
    return write_text(path, buf.getvalue())


def write_npz(path: str | Path, arrays: Mapping[str, np.ndarray]) -> Path:
    """Write ``arrays`` as an uncompressed NumPy ``.npz`` archive (keys as given)."""
    path = Path(path)
    with atomic_path(path, ".npz") as tmp:
        np.savez(tmp, **arrays)
    return path


def write_mat(path: str | Path, arrays: Mapping[str, np.ndarray]) -> Path:
    """Write ``arrays`` as a compressed MATLAB ``.mat`` file (one variable per key)."""
    from scipy.io import savemat

    path = Path(path)
    with atomic_path(path, ".mat") as tmp:
        savemat(tmp, dict(arrays), do_compression=True)
    return path


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8)."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def render_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A plain-text table: columns padded to their widest cell, ``|`` between, a dashed rule under the header."""
    widths = [max([len(h)] + [len(r[i]) for r in rows]) for i, h in enumerate(header)]
    out = [" | ".join(h.ljust(w) for h, w in zip(header, widths)).rstrip(), "-|-".join("-" * w for w in widths)]
    out += [" | ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    return "\n".join(out)
