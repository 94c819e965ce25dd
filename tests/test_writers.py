"""The one CSV writer: a numeric table is written row by row with one %-format, the same text as cell by cell."""

from __future__ import annotations

import numpy as np
import pytest

import rotorred.writers as writers
from rotorred.writers import write_csv


def _cell_by_cell(header, columns, digits=9) -> str:
    """The general path of write_csv, cell by cell (``_cell``), as the reference text."""
    rows = [",".join(header)] + [",".join(writers._cell(v, digits) for v in row) for row in zip(*columns)]
    return "\n".join(rows) + "\n"


def test_numeric_rows_are_written_as_cell_by_cell(tmp_path):
    rng = np.random.default_rng(3)
    floats = [np.linspace(2.0, 2.6, 501), rng.standard_normal(501) * 1e-5, rng.standard_normal(501) * 1e12]
    floats[1][[3, 7, 11]] = [np.nan, np.inf, -np.inf]
    floats[2][5] = -0.0
    ints = [np.arange(501), -np.arange(501, dtype=np.int32) * 7, np.arange(501, dtype=np.uint8)]
    mixed = [floats[0], ints[1], floats[1], ints[2]]  # each column keeps its type: integers stay integers
    for header, columns, digits in ((["t (s)", "x (m)", "F (N)"], floats, 9), (["a", "b", "c"], ints, 9),
                                    (["t", "x", "F"], floats, 17), (["t", "i", "x", "state"], mixed, 9)):
        assert writers._numeric_format(columns, digits) is not None
        path = write_csv(tmp_path / "a.csv", header, columns, digits=digits)
        assert path.read_text() == _cell_by_cell(header, columns, digits)


def test_text_columns_take_the_general_path_and_integers_stay_integers(tmp_path):
    mixed = [np.arange(3), np.array([0.5, 1.5, 2.5])]
    text = [np.array([1.0, 2.0]), ["ok", "failed: a, b"]]  # quoted by the csv module
    assert writers._numeric_format(text, 9) is None and writers._numeric_format([np.zeros((2, 2))], 9) is None
    assert write_csv(tmp_path / "m.csv", ["i", "x"], mixed).read_text() == "i,x\n0,0.5\n1,1.5\n2,2.5\n"
    assert write_csv(tmp_path / "t.csv", ["x", "s"], text).read_text() == 'x,s\n1,ok\n2,"failed: a, b"\n'
    assert write_csv(tmp_path / "e.csv", ["x"], [np.zeros(0)]).read_text() == "x\n"


def test_an_interrupt_while_the_npz_is_written_waits_for_it(tmp_path, monkeypatch):
    """SIGTERM (or SIGINT) arriving inside numpy's savez is held back until the archive is complete: cut inside
    zipfile, a half-built archive object printed a traceback from its destructor on an interrupted run."""
    import os
    import signal
    import threading

    from rotorred import writers

    order = []
    real = np.savez

    def savez(*args, **kw):
        os.kill(os.getpid(), signal.SIGTERM)  # delivered now unless held back
        real(*args, **kw)
        order.append("written")

    def handler(signum, frame):
        order.append("signal")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez", savez)
    previous = signal.signal(signal.SIGTERM, handler)
    other = threading.Event()  # another live thread, as the command has (the figure pool's): the signal may go to it
    thread = threading.Thread(target=other.wait)
    thread.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            writers.write_npz(tmp_path / "a.npz", {"x": np.arange(3.0)})
    finally:
        signal.signal(signal.SIGTERM, previous)
        other.set()
        thread.join()
    assert order == ["written", "signal"]
    assert not list(tmp_path.iterdir())  # interrupted before its commit: no file, no temporary left


def test_netcdf_is_cf_in_the_file_and_reads_back_as_written(tmp_path):
    """A string dimension coordinate is written as a label variable (CF 6.1; a coordinate variable is numeric,
    CF 1.2), no coordinate variable has a _FillValue (CF 5), and read_netcdf gives the dataset back identical."""
    import h5netcdf
    import xarray as xr

    from rotorred.writers import LABELS_OF, read_netcdf, write_netcdf

    ds = xr.Dataset({"peak": (("direction", "rub_clearance"), np.array([[1.0, np.nan], [3.0, 4.0]]), {"units": "m"}),
                     "status": ("direction", np.array(["ok", "diverged"], dtype=object), {"units": "1"})},
                    coords={"direction": ("direction", np.array(["up", "down"], dtype=object), {"units": "1"}),
                            "rub_clearance": ("rub_clearance", [1e-5, 2e-5], {"units": "m"})})
    write_netcdf(tmp_path / "a.nc", ds)
    with h5netcdf.File(tmp_path / "a.nc", "r") as f:
        assert "direction" not in f.variables and f.variables["direction_label"].attrs[LABELS_OF] == "direction"
        assert "_FillValue" not in f.variables["rub_clearance"].attrs
        assert "_FillValue" in f.variables["peak"].attrs  # data keep xarray's NaN fill
    back = read_netcdf(tmp_path / "a.nc")
    assert back.identical(ds.assign_attrs(Conventions="CF-1.10"))
    assert back.sel(direction="down")["peak"].values.tolist() == [3.0, 4.0]


class _Interrupted(BaseException):
    """This test's SIGINT (a BaseException as KeyboardInterrupt and rotorred.cli.Terminated are; not
    KeyboardInterrupt itself, which would stop pytest if it escaped)."""


@pytest.fixture()
def sigint_raises():
    """SIGINT raises :class:`_Interrupted` in this test."""
    import signal

    def handler(signum, frame):
        raise _Interrupted(signum)

    previous = signal.signal(signal.SIGINT, handler)
    yield
    signal.signal(signal.SIGINT, previous)


def _sigint() -> None:
    import signal

    signal.raise_signal(signal.SIGINT)  # its handler runs at the next bytecode: here


@pytest.mark.parametrize("moment", ["the lock just taken", "the staging folder just made", "the exit's hold not yet "
                                    "begun", "the staging folder just removed", "the lock file just removed"])
def test_an_interrupt_as_an_output_folder_is_entered_or_left_leaves_no_lock_nor_staging(tmp_path, monkeypatch,
                                                                                       sigint_raises, moment):
    """A SIGINT between _acquire_lock's return and the lock's assignment left ``.rotorred.lock`` behind (tests/
    test_faults.py's random moments, CI: a run-up interrupted at 0.08 s); so did one between mkdtemp's return and the
    staging folder's assignment (the staging folder), one after the staging folder's removal on exit (the lock), and
    one inside _release_lock (the lock's file open, held until collected, and the folder this run made). Each is now
    held back until the folder is entered or left whole, and one that comes as the exit's hold begins, before its
    handlers are set, leaves it all the same: the interrupt is raised, and nothing of the run is left."""
    import shutil
    import tempfile
    from contextlib import contextmanager

    import filelock

    out = tmp_path / "o"
    if moment == "the lock just taken":
        real_acquire = writers._acquire_lock
        monkeypatch.setattr(writers, "_acquire_lock", lambda folder: (real_acquire(folder), _sigint())[0])
    elif moment == "the staging folder just made":
        real_mkdtemp = tempfile.mkdtemp
        monkeypatch.setattr(tempfile, "mkdtemp", lambda *a, **kw: (real_mkdtemp(*a, **kw), _sigint())[0])
    elif moment == "the staging folder just removed":
        real_rmtree = shutil.rmtree
        monkeypatch.setattr(shutil, "rmtree", lambda *a, **kw: (real_rmtree(*a, **kw), _sigint())[0])
    elif moment == "the lock file just removed":  # POSIX: after the unlink, before the unlock and the close
        real_unlock = filelock.unlock_descriptor
        monkeypatch.setattr(filelock, "unlock_descriptor", lambda fd: (_sigint(), real_unlock(fd))[1])
    real_held = writers.signals_held

    @contextmanager
    def late():  # the signal before the hold's handlers are set
        _sigint()
        with real_held():
            yield

    folder = writers.OutputFolder(out)
    with pytest.raises(_Interrupted):
        with folder:
            if moment == "the exit's hold not yet begun":
                monkeypatch.setattr(writers, "signals_held", late)
    monkeypatch.undo()
    assert folder._lock is None  # the lock's file closed: released
    # made by this run, which committed nothing: removed, so nothing is left in it
    assert not out.exists(), sorted(p.name for p in out.iterdir())
    with writers.OutputFolder(out):  # the lock is free
        pass


def test_a_signal_as_the_held_signals_are_restored_restores_the_other_too(monkeypatch, sigint_raises):
    """A SIGINT right after signals_held had restored SIGINT's handler, before SIGTERM's: the exception left the
    noting handler on SIGTERM, so every later SIGTERM of the run was dropped. Both are restored now."""
    import signal

    ours, term = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    real = signal.signal

    def setting(signum, handler):
        was = real(signum, handler)
        if signum == signal.SIGINT and handler is ours:  # restored: the signal comes now
            _sigint()
        return was

    monkeypatch.setattr(signal, "signal", setting)
    with pytest.raises(_Interrupted):
        with writers.signals_held():
            pass
    monkeypatch.undo()
    assert signal.getsignal(signal.SIGINT) is ours and signal.getsignal(signal.SIGTERM) is term
