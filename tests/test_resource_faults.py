"""Faults of the machine and dangerous output paths (issue 41, Build 3): every writer under a full disk (the file-size
limit, ``RLIMIT_FSIZE``), a folder removed mid-run, memory that runs out, and a symlink, FIFO or device node where a
file goes. Each ends in one exit-4 line naming the file or the size, no traceback, no crash, the earlier result kept.

Fault kinds tested here (counted in the README), 23: the file-size limit in each of 7 writers (CSV, NPZ, MAT, NetCDF,
text, TOML, PNG figure) and in 5 commands (harmonic, campbell, run, map, convert); a full disk and a used-up quota
(ENOSPC, EDQUOT); the output folder removed mid-run (seen when staging, when a writer writes into the staging
folder, and removed and made again before the commit: 3); an allocation failure; 5 non-regular targets (a FIFO, a
symlink, a device node at convert's OUT; a symlink inside --out; a FIFO put at the path while the file is written).
"""

from __future__ import annotations

import errno
import os
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from rotorred import writers
from rotorred.checks import fmt_value
from rotorred.cli import main

ROSS_FILE = Path(__file__).resolve().parents[1] / "validation" / "reference" / "ross3" / "rotor_example.toml"

#: the file-size limit of the full-disk runs (bytes): below every payload, above the lock file's few bytes
LIMIT = 2048

_WRITE = {  # payload of about 800 kB, far beyond LIMIT, written by each writer
    "csv": "writers.write_csv(path, ['a (m)'], [np.arange(1e5)])",
    "npz": "writers.write_npz(path, {'a': np.arange(1e5)})",
    "mat": "writers.write_mat(path, {'a': np.arange(1e5)})",
    "nc": "writers.write_netcdf(path, xr.Dataset({'a': ('n', np.arange(1e5), {'units': 'm'})}))",
    "txt": "writers.write_text(path, 'x' * 800_000)",
    "toml": "writers.write_toml(path, {'a': list(np.arange(1e5))})",
    # a figure is written by matplotlib into the staging folder of an OutputFolder, as every command writes one
    "png": "with writers.OutputFolder(Path(path).parent) as folder:\n"
           "    save_figure(figure(), folder.staged(path))\n"
           "    folder.commit()",
}


def _under_limit(code: str, cwd: Path, limit: int = LIMIT) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh Python whose file-size limit is ``limit`` bytes (SIGXFSZ as Python leaves it:
    ignored, so a write beyond the limit fails with EFBIG)."""
    pytest.importorskip("resource", reason="RLIMIT_FSIZE needs POSIX")
    head = textwrap.dedent(f"""\
        import resource, sys
        from pathlib import Path
        import numpy as np, xarray as xr
        import matplotlib
        matplotlib.use("Agg")
        from rotorred import writers, save_figure
        from rotorred.cli import main
        def figure():
            import matplotlib.pyplot as plt
            fig, ax = plt.subplots()
            ax.imshow(np.random.default_rng(0).random((400, 400)))
            return fig
        resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, resource.RLIM_INFINITY))
        """)
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONFAULTHANDLER": ""}
    return subprocess.run([sys.executable, "-c", head + code], cwd=cwd, capture_output=True, text=True, env=env,
                          timeout=300)


@pytest.mark.parametrize("kind", sorted(_WRITE))
def test_a_full_disk_in_each_writer_is_one_fault_naming_the_file(tmp_path, kind):
    """The writer raises a ResourceFault whose message names the file and the file-size limit; the earlier file at
    that path is kept, no temporary is left, nothing is printed (NetCDF: no HDF5 diagnostics), no crash (HDF5
    writing the file itself raised a RuntimeError and then crashed with SIGSEGV at exit)."""
    path = tmp_path / f"out.{kind}"
    path.write_text("earlier\n")
    code = (f"path = {str(path)!r}\ntry:\n{textwrap.indent(_WRITE[kind], '    ')}\n"
            "except writers.ResourceFault as exc:\n    print('FAULT', exc)\n")
    done = _under_limit(code, tmp_path)
    assert done.returncode == 0, (done.returncode, done.stderr[-2000:])
    assert done.stdout.startswith("FAULT could not write ") and repr(str(path)) in done.stdout, done.stdout
    assert "file-size limit" in done.stdout and done.stderr == ""
    assert path.read_text() == "earlier\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def _one_error_line(done: subprocess.CompletedProcess, command: str) -> str:
    lines = done.stderr.strip().splitlines()
    errors = [line for line in lines if ": error: " in line]
    assert done.returncode == 4, (done.returncode, done.stderr[-3000:])
    assert len(errors) == 1 and errors[0].startswith(f"rotorred {command}: error: "), lines
    assert "Traceback" not in done.stderr and all(line.startswith(f"rotorred {command}") for line in lines), lines
    return errors[0]


_SHORT = ["--set", "solver.duration=2.3", "--set", "output.plot_window=[2.1,2.2]"]  # paper-normal, 0.3 s recorded


@pytest.mark.parametrize("command, args", [
    ("harmonic", ["seed-rig", "--speeds", "0:6000:31"]),
    ("campbell", ["seed-rig", "--speeds", "0:6000:5"]),
    ("run", ["paper-normal", *_SHORT]),  # CSV, NPZ, MAT, PNG, text
    ("map", ["paper-normal", "--vary", "speeds.outer=80:90:2", *_SHORT]),  # NetCDF (the points resumed: no Dask)
], ids=["harmonic", "campbell", "run", "map"])
def test_a_full_disk_during_a_command_keeps_the_earlier_result(tmp_path, command, args):
    """A command whose files exceed the file-size limit: exit 4, one line naming a file of --out (not its staged
    name) and the limit, no traceback, no crash; --out holds the earlier result unchanged."""
    import re

    out = tmp_path / "out"
    assert main([command, *args, "--out", str(out), "-q"]) == 0
    earlier = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    done = _under_limit(f"sys.exit(main({[command, *args, '--out', str(out)]!r}))", tmp_path)
    line = _one_error_line(done, command)
    named = re.search(r"could not write '([^']+)': the file would exceed the file-size limit", line)
    assert named and Path(named.group(1)).parent == out and not Path(named.group(1)).name.startswith("."), line
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == earlier


def test_a_full_disk_during_convert_keeps_the_earlier_file(tmp_path):
    target = tmp_path / "rotor.toml"
    target.write_text("# earlier\n")
    done = _under_limit(f"sys.exit(main(['convert', {str(ROSS_FILE)!r}, {str(target)!r}]))", tmp_path, limit=512)
    line = _one_error_line(done, "convert")
    assert repr(str(target)) in line and "file-size limit" in line, line
    assert target.read_text() == "# earlier\n" and sorted(p.name for p in tmp_path.iterdir()) == ["rotor.toml"]


def test_an_output_folder_removed_mid_run_is_one_fault_and_nothing_listed(tmp_path, monkeypatch, capsys):
    """--out's parent removed while the response is computed: exit 4, one line naming the folder, no file listed as
    written (the folder was recreated, and the result written into it, before)."""
    import shutil

    import rotorred

    parent = tmp_path / "parent"
    out = parent / "out"
    real = rotorred.unbalance_response

    def removing(*args, **kwargs):
        shutil.rmtree(parent)
        return real(*args, **kwargs)

    monkeypatch.setattr(rotorred, "unbalance_response", removing)
    assert main(["harmonic", "seed-rig", "--speeds", "0:6000:5", "--out", str(out)]) == 4
    captured = capsys.readouterr()
    assert "wrote" not in captured.out
    errors = [line for line in captured.err.splitlines() if ": error: " in line]
    assert len(errors) == 1 and repr(str(out)) in errors[0] and "no longer exists" in errors[0], captured.err
    assert not parent.exists()


def test_an_allocation_failure_is_one_fault_naming_the_size(tmp_path, monkeypatch, capsys):
    """numpy's MemoryError (an array too large to allocate) inside a command: exit 4 (not an internal error with a
    log file), one line saying out of memory and the size."""
    import rotorred

    def too_large(*args, **kwargs):
        return np.zeros((10**8, 10**8))  # 80 PB: refused by the allocator at once

    monkeypatch.setattr(rotorred, "unbalance_response", too_large)
    out = tmp_path / "out"
    assert main(["harmonic", "seed-rig", "--speeds", "0:6000:5", "--out", str(out)]) == 4
    err = capsys.readouterr().err
    errors = [line for line in err.splitlines() if ": error: " in line]
    assert len(errors) == 1 and "out of memory" in errors[0] and "PiB" in errors[0], err
    assert not out.exists() and not (tmp_path / "rotorred-error.log").exists()


def _device(path: Path) -> bool:
    """A character device node (1, 3: /dev/null's numbers) at ``path``, if this user may make one."""
    try:
        os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, 3))
        return True
    except (PermissionError, AttributeError, OSError):
        return False


@pytest.mark.parametrize("kind", ["fifo", "symlink", "device"])
def test_convert_refuses_a_non_regular_target(tmp_path, kind, capsys):
    """`convert` replaced a FIFO, a symlink (cutting the link) or a device node at OUT with a regular file; now exit 2,
    one line naming OUT and what is there, nothing read or written, the thing left as it was."""
    target, linked = tmp_path / "rotor.toml", tmp_path / "linked.toml"
    if kind == "fifo" and not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs on this system")
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "symlink":
        linked.write_text("# kept\n")
        target.symlink_to(linked)
    elif not _device(target):
        pytest.skip("no permission to make a device node")
    before = os.lstat(target)
    assert main(["convert", str(ROSS_FILE), str(target)]) == 2
    err = capsys.readouterr().err.strip()
    # OUT as every error shows a value (a long path cut at 80 characters: pytest-xdist's workers' paths are)
    assert err.startswith(f"rotorred convert: error: OUT = {fmt_value(str(target))}: must be a new path or a regular "
                          "file; this is a ") and "\n" not in err, err
    after = os.lstat(target)
    assert (after.st_ino, stat.S_IFMT(after.st_mode)) == (before.st_ino, stat.S_IFMT(before.st_mode))
    if kind == "symlink":
        assert linked.read_text() == "# kept\n"


def test_a_symlink_where_a_result_file_goes_is_refused_and_the_earlier_result_kept(tmp_path, capsys):
    """A symlink named like a file of the result inside --out (campbell.csv -> elsewhere): exit 4 naming it, nothing
    of the folder replaced, the link and its target untouched."""
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere.csv"
    assert main(["campbell", "seed-rig", "--speeds", "0:6000:5", "--out", str(out), "-q"]) == 0
    earlier = {p.name: p.read_bytes() for p in out.iterdir() if p.name != "campbell.csv"}
    (out / "campbell.csv").unlink()
    elsewhere.write_text("mine\n")
    (out / "campbell.csv").symlink_to(elsewhere)
    assert main(["campbell", "seed-rig", "--speeds", "0:3000:5", "--out", str(out), "-q"]) == 4
    err = capsys.readouterr().err.strip()
    assert err.startswith("rotorred campbell: error: --out = ") and repr(str(out / "campbell.csv")) in err, err
    assert "symbolic link" in err and "\n" not in err
    assert (out / "campbell.csv").is_symlink() and elsewhere.read_text() == "mine\n"
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.name != "campbell.csv"} == earlier


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_atomic_path_refuses_a_target_replaced_meanwhile(tmp_path):
    """A FIFO put at the path while the temporary file is written is not replaced either."""
    path = tmp_path / "a.txt"
    with pytest.raises(writers.ResourceFault, match="FIFO"):
        with writers.atomic_path(path) as tmp:
            tmp.write_text("x")
            os.mkfifo(path)
    assert stat.S_ISFIFO(os.lstat(path).st_mode) and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


@pytest.mark.parametrize("code, says", [(errno.ENOSPC, "the disk is full"),
                                        (getattr(errno, "EDQUOT", None), "the disk quota is used up")],
                         ids=["ENOSPC", "EDQUOT"])
def test_a_full_disk_or_quota_says_disk_and_names_the_file(tmp_path, monkeypatch, capsys, code, says):
    """ENOSPC and EDQUOT (no file-size limit can make them) from the writes of the staging folder: exit 4, one line
    saying disk and naming the file of --out."""
    if code is None:
        pytest.skip("no EDQUOT on this system")
    real = Path.write_text

    def full(self, *args, **kwargs):
        if ".rotorred-staging-" in str(self):
            raise OSError(code, os.strerror(code))
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", full)
    out = tmp_path / "out"
    assert main(["harmonic", "seed-rig", "--speeds", "0:6000:5", "--out", str(out)]) == 4
    err = capsys.readouterr().err
    errors = [line for line in err.splitlines() if ": error: " in line]
    assert errors == [f"rotorred harmonic: error: could not write {str(out / 'response.csv')!r}: {says} "
                      f"({os.strerror(code)})"], err
    assert not out.exists()


def test_a_fault_within_the_folder_block_names_the_right_file(tmp_path):
    """A fault of a file outside the folder (a cache) keeps its own name; one without a name (matplotlib's PNG
    writer) names the file being staged; one naming a staged file names the folder's."""
    out = tmp_path / "out"
    for raised, named in ((OSError(errno.ENOSPC, "No space left on device", "/elsewhere/cache.bin"),
                           "/elsewhere/cache.bin"),
                          (OSError(errno.EFBIG, "File too large"), str(out / "a.png")),
                          (OSError(errno.EDQUOT, "Disk quota exceeded", "STAGED/b.csv"), str(out / "b.csv"))):
        with pytest.raises(writers.ResourceFault) as caught:
            with writers.OutputFolder(out) as folder:
                folder.staged("a.png")
                if raised.filename == "STAGED/b.csv":
                    raised.filename = str(folder.staged("b.csv"))
                raise raised
        assert str(caught.value).startswith(f"could not write {named!r}: "), str(caught.value)
    assert not out.exists()


def test_a_folder_removed_before_a_writer_writes_into_its_staging_is_not_made_again(tmp_path):
    """A command that writes into ``folder.staging`` itself (map does) after --out's parent was removed: the writer's
    mkdir made the staging folder and --out again, and the commit listed the files as written; now one fault naming
    the folder's file, and nothing made again."""
    import shutil

    parent = tmp_path / "parent"
    with pytest.raises(writers.ResourceFault) as caught:
        with writers.OutputFolder(parent / "out") as folder:
            shutil.rmtree(parent)
            writers.write_text(folder.staging / "map.txt", "x\n")
            folder.commit()
    assert str(caught.value).startswith(f"could not write {str(parent / 'out' / 'map.txt')!r}: its folder "), \
        caught.value
    assert "no longer exists" in str(caught.value) and not parent.exists()


def test_a_folder_removed_and_made_again_is_not_committed_into(tmp_path):
    """--out removed and made again (empty) while the command ran: the commit refuses (the staging folder it made is
    gone), and leaves the new folder as it found it."""
    import shutil

    out = tmp_path / "out"
    with pytest.raises(writers.ResourceFault, match="no longer exists"):
        with writers.OutputFolder(out) as folder:
            writers.write_text(folder.staged("a.txt"), "x\n")
            shutil.rmtree(out)
            out.mkdir()
            (out / "theirs.txt").write_text("theirs\n")
            folder.commit()
    assert sorted(p.name for p in out.iterdir()) == ["theirs.txt"]
