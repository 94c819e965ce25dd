"""One writer per output format: CSV, NPZ, MATLAB .mat, NetCDF, TOML and text.

Every file rotorred writes goes through this module. Each writer writes to a temporary file
beside the target and renames it into place (``os.replace``), so a reader never sees a
half-written file, and an interrupted write leaves the earlier file (or none) behind.

CSV: a header row, then one row per sample; floats with ``digits`` significant digits,
integers and strings as they are. Units belong in the header (``"amplitude (um)"``).

TOML (rotor files written by ``rotorred convert``, resolved scenes and rotors): floats with ``repr``, so a file read
back holds the same numbers to the last bit.

Faults of the machine (a full disk or quota, a file-size limit, a folder removed while the command runs, memory
that runs out while a file is built) are raised as one :class:`ResourceFault` naming the file, the earlier file left
as it was; an existing path that is a symlink, a FIFO, a device or any other non-regular file is refused
(:func:`check_target`), never replaced.

NPZ, .mat and NetCDF take an optional mapping of string attributes (the provenance of
:mod:`rotorred.provenance`): NPZ entries, .mat variables, NetCDF global attributes. NetCDF files follow the CF
conventions: :func:`write_netcdf` refuses a dataset without units on a variable or coordinate, or with a name CF
does not allow (a dot).

:class:`OutputFolder`: a command's result written into ``--out`` as a whole, under the operating system's
file lock against a second run (taken through filelock, the same on POSIX and Windows).
"""

from __future__ import annotations

import csv
import errno
import io
import math
import os
import re
import tempfile
from collections.abc import Callable, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np

__all__ = ["write_csv", "write_npz", "write_mat", "write_netcdf", "write_text", "write_toml", "toml_text",
           "exact_in_unit", "atomic_path", "render_table", "OutputFolder", "CF_CONVENTIONS", "read_netcdf", "LABELS_OF",
           "FolderBusy", "INCOMPLETE", "MANIFEST", "LOCK", "ResourceFault", "as_fault", "check_target",
           "non_regular"]


#: the name of an output folder's staging folder starts so (:class:`OutputFolder`)
_STAGING = ".rotorred-staging-"


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_UMASK = _umask()


class ResourceFault(OSError):
    """A file that could not be written for a reason of the machine, not of the input: a full disk or quota
    (``ENOSPC``, ``EDQUOT``), the file-size limit (``EFBIG``, ``ulimit -f``), a folder removed while the command ran
    (``ENOENT``), memory that ran out (``ENOMEM``, :class:`MemoryError`), or an existing non-regular file or symlink
    at the path. ``str()`` is the whole message, naming the file or the size; the command line exits 4 with it."""

    def __str__(self) -> str:
        return self.strerror or super().__str__()


#: errno of a fault of the machine (full disk, quota, file-size limit, memory, read-only or failing medium), whatever
#: raised it
_MACHINE = {code: text for name, text in (
    ("ENOSPC", "the disk is full"), ("EDQUOT", "the disk quota is used up"),
    ("EFBIG", "the file would exceed the file-size limit (ulimit -f) or the file system's largest file"),
    ("ENOMEM", "out of memory"), ("EROFS", "the file system is read-only"), ("EIO", "an input/output error of the disk"))
    if (code := getattr(errno, name, None)) is not None}  # (Windows has no EDQUOT)


def as_fault(exc: BaseException, file: str | Path | None = None) -> BaseException:
    """``exc`` as a :class:`ResourceFault` when it is a fault of the machine, else ``exc`` itself.

    Parameters
    ----------
    exc : BaseException
        A :class:`MemoryError`, or an :class:`OSError` whose errno is a full disk, a quota, the file-size limit,
        memory, a read-only file system or an I/O error (any other exception is returned as it is).
    file : str or Path, optional
        The file being written, named in the message instead of the exception's own file name (which may be a
        temporary one).

    Returns
    -------
    BaseException
    """
    if isinstance(exc, ResourceFault):
        return exc
    if isinstance(exc, MemoryError):
        size = str(exc).strip()
        what = f" while writing {str(file)!r}" if file is not None else ""
        return ResourceFault(errno.ENOMEM, f"out of memory{what}" + (f": {size}" if size else "")
                             + "; a smaller model, fewer points or a shorter record needs less", None)
    if isinstance(exc, OSError) and exc.errno in _MACHINE:
        name = file if file is not None else exc.filename
        return ResourceFault(exc.errno, (f"could not write {str(name)!r}: " if name else "")
                             + f"{_MACHINE[exc.errno]} ({exc.strerror or exc})", None if name is None else str(name))
    return exc


def non_regular(path: str | Path) -> str | None:
    """What is at ``path`` when it is not a regular file (``"a symbolic link"``, ``"a FIFO (named pipe)"``, ``"a
    character device"``, ...); None for a regular file or nothing. A symlink is one even when it points to a regular
    file: replacing it would cut the link."""
    import stat

    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return None
    if stat.S_ISREG(mode):
        return None
    kinds = ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
             (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"),
             (stat.S_ISDIR, "a folder"))
    return next((kind for test, kind in kinds if test(mode)), "not a regular file")


def check_target(path: str | Path, option: str = "") -> Path:
    """``path``, refused (:class:`ResourceFault`) when something other than a regular file is there
    (:func:`non_regular`). A missing path or a regular file is fine (the file is replaced as a whole).

    Parameters
    ----------
    path : str or Path
    option : str
        The option that named it (``"OUT"``, ``"--out"``), for the message.

    Returns
    -------
    Path
    """
    path = Path(path)
    try:
        kind = non_regular(path)
    except OSError as exc:
        raise as_fault(exc, path) from exc
    if kind is None:
        return path
    named = f"{option} = {str(path)!r}" if option else repr(str(path))
    raise ResourceFault(errno.EEXIST, f"{named} is {kind}: rotorred writes only regular files and does not replace "
                                      "it; remove it or choose another path", str(path))


@contextmanager
def atomic_path(path: str | Path, suffix: str = ""):
    """Yield a temporary path in ``path``'s folder; on success it replaces ``path``, on error it is removed.

    ``path`` must be missing or a regular file (:func:`check_target`). A fault of the machine while writing or
    renaming, or the folder gone, is raised as a :class:`ResourceFault` naming ``path``.
    """
    path = check_target(path)
    try:
        if not path.parent.name.startswith(_STAGING):  # an output folder's staging folder is never made again here
            path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".tmp{suffix}", dir=path.parent)
    except OSError as exc:
        raise _write_fault(exc, path) from exc
    try:  # from here on an interrupt (or any error) removes the temporary file
        if hasattr(os, "fchmod"):  # POSIX: mkstemp's 0600 -> what open() would give; Windows has a read-only flag
            os.fchmod(fd, 0o666 & ~_UMASK)
        os.close(fd)
        yield Path(tmp)
        check_target(path)  # nothing put there meanwhile
        os.replace(tmp, path)
    except BaseException as exc:
        Path(tmp).unlink(missing_ok=True)
        fault = _write_fault(exc, path)
        if fault is exc:
            raise
        raise fault from exc


def _write_fault(exc: BaseException, path: Path) -> BaseException:
    """A fault while writing ``path``: :func:`as_fault`, and its folder gone (``ENOENT``) as one too."""
    if isinstance(exc, FileNotFoundError) and not path.parent.is_dir():
        return ResourceFault(errno.ENOENT, f"could not write {str(path)!r}: its folder {str(path.parent)!r} no longer "
                                           "exists (removed while the command ran?)", str(path))
    return as_fault(exc, path)


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
    fmt = _numeric_format(columns, digits)
    if fmt is not None and columns and len(columns[0]):  # numbers only: one %-format per row, the same text
        rows = zip(*[c.tolist() for c in columns])  # Python floats and ints, each column its own type
        buf.write("\n".join([fmt % r for r in rows]) + "\n")
    else:
        for row in zip(*columns):
            w.writerow([_cell(v, digits) for v in row])
    return write_text(path, buf.getvalue())


def _numeric_format(columns: Sequence[Sequence], digits: int) -> str | None:
    """The %-format of a row when every column is a 1-D float or integer array (``_cell``'s text), else None.

    ``"%.9g" % x`` and ``f"{x:.9g}"`` are the same conversion, as are ``"%d" % i`` and ``str(i)``; formatting a
    whole row at once is about 2.5x faster than a cell at a time through the csv module (30 001 x 13: 0.28
    against 0.71 s; paper-rub's timeseries.csv, 30 001 x 17 with an integer column: 0.26 against 1.37 s).
    """
    if not all(isinstance(c, np.ndarray) and c.ndim == 1 and c.dtype.kind in "fiu" for c in columns):
        return None
    kinds = [c.dtype.kind for c in columns]
    return ",".join(f"%.{digits}g" if k == "f" else "%d" for k in kinds)


def write_npz(path: str | Path, arrays: Mapping[str, np.ndarray], attributes: Mapping[str, str] | None = None) -> Path:
    """Write ``arrays`` as an uncompressed NumPy ``.npz`` archive (keys as given).

    ``attributes`` (e.g. :meth:`rotorred.provenance.Provenance.attributes`) are added as 0-d string entries, read
    back with ``str(npz[name])``; a name that is also an array's key is refused (ValueError).

    SIGINT and SIGTERM are held back while numpy writes it (about 20 ms for paper-rub's): an interrupt inside
    ``zipfile.ZipFile`` leaves a half-built archive object whose destructor prints a traceback on the way out.
    """
    path = Path(path)
    entries = {**arrays, **{k: np.array(v) for k, v in _attributes(arrays, attributes, "write_npz").items()}}
    with atomic_path(path, ".npz") as tmp, signals_held():
        np.savez(tmp, **entries)
    return path


def write_mat(path: str | Path, arrays: Mapping[str, np.ndarray], attributes: Mapping[str, str] | None = None) -> Path:
    """Write ``arrays`` as an uncompressed MATLAB ``.mat`` file (one variable per key; like the NPZ: compressing
    paper-rub's took 0.17 s for 27 % less, 3.9 against 5.4 MB); ``attributes`` as char variables (names as
    :func:`write_npz`)."""
    from scipy.io import savemat

    path = Path(path)
    entries = {**arrays, **_attributes(arrays, attributes, "write_mat")}
    with atomic_path(path, ".mat") as tmp:
        savemat(tmp, entries, do_compression=False)
    return path


def _attributes(arrays: Mapping, attributes: Mapping[str, str] | None, writer: str) -> dict[str, str]:
    """The string ``attributes`` of a file of ``arrays``, checked: str values, no name of an array."""
    attributes = dict(attributes or {})
    clash = sorted(set(attributes) & set(arrays))
    if clash:
        raise ValueError(f"{writer}: attribute names {clash} are also array keys")
    for name, value in attributes.items():
        if not isinstance(value, str):
            raise TypeError(f"{writer}: attribute {name!r} = {value!r}: must be a str")
    return attributes


#: the CF conventions every NetCDF file follows (:func:`write_netcdf`)
CF_CONVENTIONS = "CF-1.10"
_CF_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def write_netcdf(path: str | Path, dataset, attributes: Mapping[str, str] | None = None) -> Path:
    """Write an :class:`xarray.Dataset` as NetCDF-4 (engine h5netcdf), following the CF conventions.

    ``attributes`` (e.g. :meth:`rotorred.provenance.Provenance.netcdf_attributes`) join the dataset's global
    attributes, with ``Conventions = "CF-1.10"``. The dataset must be CF-clean already: a ``units`` attribute on every
    variable and coordinate ("1" for a dimensionless one), and variable and dimension names of letters, digits and
    underscores, starting with a letter (CF 2.3: no dots, so ``rub_clearance`` for the key ``rub.clearance``).

    Two rules of CF are applied here, in the file only: a coordinate variable holds no ``_FillValue`` (CF 5; xarray
    writes NaN by default), and a dimension labelled by strings (``direction``: up, down; ``dof``) has no coordinate
    variable, which CF 1.2 wants numeric, but a string label variable ``<dim>_label`` (CF 6.1), marked with the
    attribute :data:`LABELS_OF`. :func:`read_netcdf` gives the dataset back as it was written.

    Raises
    ------
    ValueError
        For a dataset that is not (a bug of its builder): names the variable or dimension.
    """
    _check_cf(dataset)
    attrs = {**dataset.attrs, **dict(attributes or {}), "Conventions": CF_CONVENTIONS}
    cf = _labels_apart(dataset).assign_attrs(attrs)
    encoding = {name: {"_FillValue": None} for name in cf.coords}
    path = Path(path)
    # built in memory, then written by Python: HDF5 writing the file itself on a full disk (or at the file-size limit)
    # raised a RuntimeError and crashed (SIGSEGV) at exit. xarray before 2025 builds NetCDF-4 in memory with no engine
    try:
        with _local_locks():
            data = cf.to_netcdf(engine="h5netcdf", encoding=encoding)
    except MemoryError as exc:
        raise as_fault(exc, path) from exc
    except ValueError:  # an older xarray: HDF5 writes the file
        data = None
    with atomic_path(path, ".nc") as tmp:
        if data is None:
            cf.to_netcdf(tmp, engine="h5netcdf", encoding=encoding)
        else:
            tmp.write_bytes(data)
    return path


@contextmanager
def _local_locks():
    """xarray's write locks of this process, not a Dask cluster's: with a distributed client about (a map's), xarray
    takes a cluster lock named by the target, which for a file built in memory is no name the cluster knows."""
    try:
        import dask
    except ImportError:
        yield
        return
    with dask.config.set(scheduler="synchronous"):
        yield


#: the attribute of a label variable ``<dim>_label`` that names the dimension it labels (:func:`write_netcdf`)
LABELS_OF = "rotorred_labels"


def _labels_apart(dataset):
    """``dataset`` with each string dimension coordinate ``d`` renamed ``d_label`` (an auxiliary coordinate)."""
    labels = {d: f"{d}_label" for d in dataset.dims if d in dataset.coords and dataset[d].dtype.kind in "OUS"}
    out = dataset.drop_vars(list(labels))
    for d, name in labels.items():
        out = out.assign_coords({name: (d, dataset[d].values.astype(str), {**dataset[d].attrs, LABELS_OF: d})})
    return out


def read_netcdf(path: str | Path):
    """A NetCDF file of :func:`write_netcdf`, loaded, with each label variable a dimension coordinate again.

    Returns
    -------
    xarray.Dataset
    """
    import xarray as xr

    ds = xr.load_dataset(path, engine="h5netcdf")
    for name, var in list(ds.coords.items()):
        if LABELS_OF in var.attrs:
            dim = var.attrs[LABELS_OF]
            attrs = {k: v for k, v in var.attrs.items() if k != LABELS_OF}
            ds = ds.drop_vars(name).assign_coords({dim: (dim, var.values.astype(object), attrs)})
    return ds


def _check_cf(dataset) -> None:
    """Units on every variable and coordinate, CF names (:func:`write_netcdf`)."""
    for name in [*dataset.variables, *dataset.dims]:
        if not _CF_NAME.fullmatch(str(name)):
            raise ValueError(f"write_netcdf: name {name!r} must be letters, digits and underscores, starting with a "
                             "letter (CF 2.3)")
    missing = sorted(str(n) for n, v in dataset.variables.items() if not v.attrs.get("units"))
    if missing:
        raise ValueError(f"write_netcdf: variables {missing} have no units attribute (CF: \"1\" if dimensionless)")


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8)."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def write_toml(path: str | Path, document: Mapping, header: str = "") -> Path:
    """Write a TOML document (:func:`toml_text`), ``header`` as comment lines on top."""
    comments = "".join(f"# {line}".rstrip() + "\n" for line in header.splitlines())
    return write_text(path, comments + ("\n" if comments else "") + toml_text(document))


def toml_text(document: Mapping) -> str:
    """A TOML text of ``document``: its plain keys first, then a ``[name]`` block per table (its tables in turn as
    ``[name.sub]`` blocks, its arrays of tables as ``[[name.sub]]`` blocks) and a ``[[name]]`` block per item of an
    array of tables; tables inside an item of an array are inline, an array of them one a line. Floats are written
    with ``repr``, so reading the text back gives the same numbers to the last bit."""
    return "\n".join(_toml_blocks(document, ()))


def _toml_blocks(table: Mapping, path: tuple[str, ...]) -> list[str]:
    """The blocks of ``table`` at the key path ``path`` (:func:`toml_text`)."""
    plain = {k: v for k, v in table.items() if not _is_table(v) and not _is_tables(v)}
    dotted = ".".join(_toml_key(k) for k in path)
    blocks = []
    if not path:
        blocks += [_toml_lines(plain)] if plain else []
    elif plain or len(plain) == len(table):  # an empty table keeps its header
        blocks.append(f"[{dotted}]\n" + _toml_lines(plain))
    for key, value in table.items():
        if _is_table(value):
            blocks += _toml_blocks(value, (*path, key))
        elif _is_tables(value):
            name = ".".join(_toml_key(k) for k in (*path, key))
            blocks += [f"[[{name}]]\n" + _toml_lines(item) for item in value]
    return blocks


def _is_table(value) -> bool:
    return isinstance(value, Mapping)


def _is_tables(value) -> bool:
    return isinstance(value, (list, tuple)) and len(value) > 0 and all(isinstance(v, Mapping) for v in value)


def _toml_lines(table: Mapping) -> str:
    lines = []
    for key, value in table.items():
        if _is_tables(value):  # an array of inline tables, one a line
            items = "".join(f"  {_toml_value(v)},\n" for v in value)
            lines.append(f"{_toml_key(key)} = [\n{items}]")
        else:
            lines.append(f"{_toml_key(key)} = {_toml_value(value)}")
    return "".join(line + "\n" for line in lines)


def _toml_key(key: str) -> str:
    return key if key.replace("_", "").replace("-", "").isalnum() and key.isascii() else _toml_string(key)


def _toml_string(text: str) -> str:
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t")
    return f'"{escaped}"'


def _toml_value(value) -> str:
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"TOML value {value!r}: must be finite")
        return repr(value)
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + " }"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"TOML value {value!r}: a {type(value).__name__} has no TOML form")


def exact_in_unit(value: float, to_si: Callable[[float], float], estimate: float) -> float | None:
    """The number in another unit that reads back to ``value`` to the last bit, for writing it in that unit.

    Parameters
    ----------
    value : float
        The value as stored (SI, e.g. rad/s).
    to_si : callable
        The reader's conversion from the other unit (e.g. rpm to rad/s), exactly as the reader applies it.
    estimate : float
        ``value`` in the other unit, computed (e.g. ``value * 30 / pi``).

    Returns
    -------
    float or None
        Of the floats within 8 ulps of ``estimate`` that ``to_si`` takes to ``value``, the one of shortest ``repr``
        (the nearest to ``estimate`` among those); None when none does: a conversion by a factor below 1 misses
        some floats, whose value must then be written in SI.
    """
    candidates = [estimate]
    for direction in (math.inf, -math.inf):
        c = estimate
        for _ in range(8):
            c = math.nextafter(c, direction)
            candidates.append(c)
    exact = [c for c in candidates if to_si(c) == value]
    return min(exact, key=lambda c: (len(repr(c)), abs(c - estimate), c)) if exact else None


def render_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A plain-text table: columns padded to their widest cell, ``|`` between, a dashed rule under the header."""
    widths = [max([len(h)] + [len(r[i]) for r in rows]) for i, h in enumerate(header)]
    out = [" | ".join(h.ljust(w) for h, w in zip(header, widths)).rstrip(), "-|-".join("-" * w for w in widths)]
    out += [" | ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    return "\n".join(out)


# --------------------------------------------------------------------------- output folders
#: marker file of a folder whose result is incomplete (a diverged run, or a commit cut by a hard kill)
INCOMPLETE = "INCOMPLETE"
#: the names of the files of the folder's last committed result, one a line (hidden)
MANIFEST = ".rotorred-files"
#: the lock held by the run writing into the folder (hidden; removed when the run ends): the operating system's lock
#: on the file (:func:`_acquire_lock`), and the owner (``pid N``) written in it after its first byte
LOCK = ".rotorred.lock"


class FolderBusy(OSError):
    """Another rotorred run holds the lock of the output folder."""


def _acquire_lock(folder: Path):
    """An open file holding the lock of ``folder/.rotorred.lock`` (FolderBusy if another run holds it).

    The lock is the operating system's, taken through filelock (:func:`filelock.lock_descriptor`: ``flock`` of the
    whole file on POSIX, ``LockFileEx`` of its first byte on Windows), so a run that dies releases it with its
    process. The owner is written after the first byte, which Windows keeps unreadable to others while it is locked;
    a refused run reads it from there.

    The file is removed when the run ends (:func:`_release_lock`). On POSIX a run that opened it before then can still
    lock the removed file: it checks that the file it locked is the one at the path, and starts again if not (the
    holder removes the file while it holds the lock, so that check decides).

    Returns
    -------
    file object
        Unbuffered, binary; pass it to :func:`_release_lock`.

    Raises
    ------
    FolderBusy
        Another run holds the lock (the message names its owner when it could be read).
    OSError
        The file cannot be created or the file system has no locks (errno ``ENOSYS``, ``ENOLCK``).
    """
    from filelock import lock_descriptor

    path = folder / LOCK
    for _ in range(100):
        handle = open(os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_BINARY", 0), 0o666), "r+b", buffering=0)
        try:
            locked = lock_descriptor(handle.fileno(), blocking=False)
        except OSError as exc:  # no locks on this file system (or no flock in this Python)
            handle.close()
            if exc.errno == errno.ENOSYS:  # nobody can hold it: not left behind
                path.unlink(missing_ok=True)
            raise OSError(exc.errno, f"cannot lock it ({exc.strerror or exc})", str(path)) from exc
        if not locked:
            owner = _lock_owner(handle)
            handle.close()
            raise FolderBusy(f"--out = {str(folder)!r}: another rotorred run ({owner or 'unknown'}) is writing into "
                             f"this folder; wait for it to end or choose another --out")
        if os.name == "nt" or _is_at(path, handle):  # not removed meanwhile (Windows cannot remove an open file)
            # written, then cut after it: truncated to zero first, the file was flushed to disk when closed
            # (ext4's auto_da_alloc), 3.1-3.8 ms against 0.05 ms for taking and releasing the lock
            handle.seek(0)
            handle.write(f"\npid {os.getpid()}\n".encode("ascii"))
            handle.truncate()
            return handle
        handle.close()
    raise OSError(errno.EAGAIN, "cannot lock it: the lock file was replaced 100 times in a row", str(path))


def _is_at(path: Path, handle) -> bool:
    """Whether the file ``handle`` has open is the one at ``path``."""
    try:
        return os.path.samestat(os.fstat(handle.fileno()), os.stat(path))
    except FileNotFoundError:
        return False


def _lock_owner(handle) -> str:
    """The owner a lock file names (``pid N``), read after its first byte; empty when unreadable."""
    try:
        handle.seek(1)
        return handle.read(256).decode("utf-8", "replace").strip()
    except OSError:
        return ""


def _release_lock(path: Path, handle) -> None:
    """Remove the lock file ``path`` and release the lock ``handle`` holds (:func:`_acquire_lock`).

    POSIX: removed while still locked, so that no run can take the lock of a file about to go. Windows cannot remove
    an open file: removed once released, unless another run has opened it meanwhile (then it stays for that run).
    """
    from filelock import unlock_descriptor

    try:
        path.unlink(missing_ok=True)
        removed = True
    except OSError:  # Windows: the file is open
        removed = False
    try:
        unlock_descriptor(handle.fileno())
    except OSError:  # closing the file releases it too
        pass
    handle.close()
    if not removed:
        try:
            path.unlink(missing_ok=True)
        except OSError:
            pass


@contextmanager
def signals_held():
    """SIGINT and SIGTERM held back, then delivered on exit, so that a commit or an archive is not cut in half.

    Held back in Python: while inside, their handlers only note the signal, and the first one noted is raised again
    on exit, under the handlers restored. Masking them (``pthread_sigmask``) held them back from the calling thread
    only: the kernel then hands the signal to another thread (the figure pool's, a library's), and Python still runs
    its handler in the main thread at once. Outside the main thread, where handlers cannot be set, nothing is held.

    A signal as the handlers are set or restored (its own handler, raising, already in place) still restores both:
    the other one never keeps the noting handler, which would drop its signals for the rest of the run.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    noted: list[int] = []
    # read before any is set: a signal raised between setting one and noting what it replaced loses nothing
    previous_int, previous_term = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    try:
        for held in (signal.SIGINT, signal.SIGTERM):
            signal.signal(held, lambda signum, frame: noted.append(signum))
        yield
    finally:
        try:
            signal.signal(signal.SIGINT, signal.SIG_DFL if previous_int is None else previous_int)
        finally:  # also when SIGINT came right after its handler was restored
            signal.signal(signal.SIGTERM, signal.SIG_DFL if previous_term is None else previous_term)
            if noted:
                signal.raise_signal(noted[0])


class OutputFolder:
    """One result written into ``--out`` as a whole: locked, staged, then committed.

    Files are written into a hidden staging folder inside ``folder`` (:attr:`staging`); :meth:`commit`
    moves them into place with signals held back, removes the files of the earlier result that the
    new one does not have (listed in the hidden manifest), and writes the new manifest. An
    interrupt before the commit leaves the earlier result as it was; a hard kill during it leaves
    the :data:`INCOMPLETE` marker. Files in the folder that rotorred did not write are left alone.

    Use as a context manager: the lock is taken on entry (:class:`FolderBusy` if another run holds
    it), and on exit the staging folder and the lock are removed, and the folder too if this run
    created it and committed nothing. Both hold SIGINT and SIGTERM back (:func:`signals_held`): a signal
    as the folder is entered or left is raised once it is, never leaving the lock or the staging folder behind.

    Faults of the machine within the block (a full disk, the file-size limit, memory, the folder removed meanwhile)
    leave it as one :class:`ResourceFault` naming the file of the folder being written (not its staged name) or the
    size that could not be allocated; a symlink or another non-regular file where a file of the result goes is
    refused, not replaced (:func:`check_target`).
    """

    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        self.staging: Path | None = None
        self._created = False
        self._lock = None
        self._writing: Path | None = None  # the file of the folder staged last: the one a fault names
        self._identity: tuple[int, int] | None = None  # (device, inode) of the staging folder
        self.committed = False

    def __enter__(self) -> OutputFolder:
        self._created = not self.folder.exists()
        try:
            with signals_held():  # a signal here is raised once the lock and the staging folder are taken and noted
                self.folder.mkdir(parents=True, exist_ok=True)
                self._lock = _acquire_lock(self.folder)
                self.staging = Path(tempfile.mkdtemp(prefix=_STAGING, dir=self.folder))
                self._identity = _identity(self.staging)
        except BaseException:  # the lock released, and the folder removed if this run created it
            self.__exit__()
            raise
        return self

    def __exit__(self, exc_type=None, exc=None, tb=None) -> None:
        try:
            with signals_held():  # left whole: a signal cutting it left the lock, or the staging folder, behind
                fault = self._leave(exc)
        except BaseException:  # a signal as the hold began, before its handlers were set: left all the same
            self._leave(exc)
            raise
        if fault is not None and fault is not exc:
            raise fault from exc

    def _leave(self, exc: BaseException | None) -> BaseException | None:
        """Remove the staging folder and the lock, and the folder if this run created it and committed nothing (or it
        was removed meanwhile); ``exc`` as :meth:`_fault` names it. Twice is as once."""
        import shutil

        fault = None if exc is None else self._fault(exc)
        if self.staging is not None:
            shutil.rmtree(self.staging, ignore_errors=True)
        if self._lock is not None:
            _release_lock(self.folder / LOCK, self._lock)
            self._lock = None
        if (self._created and not self.committed) or isinstance(fault, _Vanished):  # (recreated by a writer: empty)
            try:
                self.folder.rmdir()
            except OSError:
                pass
        return fault

    def _fault(self, exc: BaseException) -> BaseException:
        """``exc`` as a :class:`ResourceFault` naming the folder's file (:func:`as_fault`), the folder gone as one."""
        if isinstance(exc, ResourceFault):  # a writer's, naming the staged file: the folder's is meant
            staging = str(self.staging)
            if staging in str(exc) or staging in str(exc.filename):
                return ResourceFault(exc.errno, str(exc).replace(staging, str(self.folder)),
                                     exc.filename and exc.filename.replace(staging, str(self.folder)))
            return exc
        if isinstance(exc, FileNotFoundError) and not self._still_there():
            return self._vanished()
        if isinstance(exc, MemoryError):
            return as_fault(exc)
        if not isinstance(exc, OSError):
            return exc
        if exc.filename is None:  # (matplotlib's PNG writer names none): the file being staged
            return as_fault(exc, self._writing)
        inside = Path(exc.filename).parent in (self.staging, self.folder)
        return as_fault(exc, self.folder / Path(exc.filename).name if inside else exc.filename)

    def _still_there(self) -> bool:
        """Whether the staging folder made on entry is still there (not removed, nor removed and made again by a
        writer's ``mkdir``)."""
        return self.staging is not None and _identity(self.staging) == self._identity

    def _vanished(self) -> ResourceFault:
        return _Vanished(errno.ENOENT, f"the output folder {str(self.folder)!r} no longer exists (removed while "
                                           f"the command ran?); nothing of this result was kept", str(self.folder))

    def staged(self, path: Path) -> Path:
        """Where a file of the result goes before the commit (its name in the staging folder).

        Raises
        ------
        ResourceFault
            The folder was removed meanwhile, or a symlink or another non-regular file is where the file goes.
        """
        name = Path(path).name
        if not self._still_there():
            raise self._vanished()
        self._writing = check_target(self.folder / name, "--out")
        return self.staging / name

    def commit(self, incomplete: str | None = None) -> list[Path]:
        """Move the staged files into the folder; ``incomplete``: the reason written to :data:`INCOMPLETE`.

        Returns
        -------
        list of Path
            The files of the result in the folder.
        """
        with signals_held():
            if not self._still_there():
                raise self._vanished()
            new = sorted(p.name for p in self.staging.iterdir() if not p.name.startswith("."))
            for name in new:  # refused before anything moves: the earlier result stays whole
                check_target(self.folder / name, "--out")
            marker = self.folder / INCOMPLETE
            write_text(marker, (incomplete or "a rotorred run was writing this folder and did not finish") + "\n")
            for name in _manifest(self.folder):
                if name not in new and name != INCOMPLETE and (self.folder / name).is_file():
                    (self.folder / name).unlink(missing_ok=True)
            for name in new:
                self._writing = self.folder / name
                os.replace(self.staging / name, self.folder / name)
            names = new + ([INCOMPLETE] if incomplete else [])
            write_text(self.folder / MANIFEST, "".join(f"{n}\n" for n in names))
            if not incomplete:
                marker.unlink()
            self.committed = True
        if not all((self.folder / n).is_file() for n in names):  # removed as it was committed: never listed as written
            raise self._vanished()
        return [self.folder / n for n in names]


class _Vanished(ResourceFault):
    """The output folder was removed while the command ran."""


def _identity(folder: Path) -> tuple[int, int] | None:
    """(device, inode) of ``folder``; None when it is not there."""
    try:
        st = os.stat(folder)
    except OSError:
        return None
    return st.st_dev, st.st_ino


def _manifest(folder: Path) -> list[str]:
    """The file names of the folder's last committed result."""
    try:
        return [n for n in (folder / MANIFEST).read_text(encoding="utf-8").splitlines()
                if n and "/" not in n and not n.startswith(".")]
    except (OSError, UnicodeDecodeError):
        return []
