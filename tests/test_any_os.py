"""Any OS (issue 34, item 2): rotorred itself uses nothing that only POSIX systems have.

Commands run end to end in a child process where rotorred's own modules cannot import ``fcntl`` or another module
Windows lacks (:data:`POSIX_ONLY`), see ``os`` and ``signal`` without the functions Windows lacks (``os.fchmod``,
``os.statvfs``, ``os.getuid``, ...), and cannot open or list anything under ``/proc``. The libraries they call are
left as they are: psutil is the one that knows each operating system, and on Linux it reads ``/proc`` itself; the
memory guard's test stands psutil's report in for another platform's (``psutil.virtual_memory`` replaced, so nothing
reads ``/proc`` for it). A blocked attempt of rotorred's is listed on stderr (``any-os: blocked ...``): a ``/proc``
read that rotorred caught and worked around would otherwise pass unseen.

The output lock (filelock's native lock, :mod:`rotorred.writers`): a second run into a folder in use is refused
naming the owner, the lock of a killed run is free, the lock file is removed when the run ends.
"""

from __future__ import annotations

import errno
import os
import stat
import subprocess
import sys
from types import SimpleNamespace

import pytest

from rotorred.writers import LOCK, FolderBusy, OutputFolder, write_text

#: modules that Windows lacks (some of them macOS too)
POSIX_ONLY = ("fcntl", "resource", "pwd", "grp", "termios", "tty", "pty", "posix", "syslog", "crypt", "spwd", "nis",
              "ossaudiodev", "_posixsubprocess", "_posixshmem")
#: functions and constants of ``os`` and ``signal`` that Windows lacks (sched_getaffinity: macOS too)
OS_ONLY = ("fchmod", "fchown", "chown", "lchown", "getuid", "geteuid", "getgid", "getegid", "getgroups", "setuid",
           "getpgid", "getpgrp", "setsid", "setpgid", "fork", "forkpty", "killpg", "nice", "statvfs", "fstatvfs",
           "ST_RDONLY", "sysconf", "sysconf_names", "confstr", "pathconf", "fpathconf", "sched_getaffinity",
           "sched_setaffinity", "getloadavg", "uname", "sync", "mkfifo", "mknod", "wait3", "wait4", "WNOHANG",
           "O_NOFOLLOW", "O_CLOEXEC", "O_NONBLOCK", "pipe2", "posix_fadvise", "getrusage")
SIGNAL_ONLY = ("SIGKILL", "SIGHUP", "SIGQUIT", "SIGALRM", "SIGUSR1", "SIGUSR2", "SIGCHLD", "SIGPIPE", "SIGCONT",
               "SIGSTOP", "SIGTSTP", "alarm", "setitimer", "getitimer", "pause", "pthread_kill", "pthread_sigmask",
               "siginterrupt", "sigwait", "sigpending")

#: run in the child: the restrictions, then ``rotorred.cli.main`` on the arguments (or, with ANY_OS_PROBE set, that
#: code compiled as a file of the rotorred package); ANY_OS_MEMORY (bytes): what psutil reports as available
HARNESS = r"""
import builtins, errno, importlib.util, os, signal, sys, sysconfig, types

POSIX_ONLY, OS_ONLY, SIGNAL_ONLY = %r, %r, %r
PACKAGE = importlib.util.find_spec("rotorred").submodule_search_locations[0] + os.sep
STDLIB = tuple({sysconfig.get_paths()[k] + os.sep for k in ("stdlib", "platstdlib")})
blocked = []


def by_rotorred(frame):
    # the innermost caller that is not the standard library: rotorred's own code, or a library's (psutil, numba)
    while frame is not None:
        name = frame.f_code.co_filename
        if name.startswith(PACKAGE):
            return True
        if not (name.startswith("<") or name.startswith(STDLIB)) or "-packages" in name:
            return False
        frame = frame.f_back
    return False


def audit(event, args):
    if event not in ("open", "os.listdir", "os.scandir") or not args or not isinstance(args[0], (str, bytes)):
        return
    path = os.path.abspath(os.fsdecode(args[0]))
    if (path == "/proc" or path.startswith("/proc/")) and by_rotorred(sys._getframe(1)):
        blocked.append(f"{event} {path}")
        raise FileNotFoundError(errno.ENOENT, "No such file or directory (no /proc here)", path)


class Without(types.ModuleType):
    # a module as rotorred's code sees it: without the names Windows lacks
    def __init__(self, module, missing):
        super().__init__(module.__name__, module.__doc__)
        self.__dict__.update(_module=module, _missing=frozenset(missing))

    def __getattr__(self, name):
        if name in self._missing:
            raise AttributeError(f"module {self.__name__!r} has no attribute {name!r} (not on every OS)")
        return getattr(self._module, name)


SEEN = {id(os): Without(os, OS_ONLY), id(signal): Without(signal, SIGNAL_ONLY)}
real_import = builtins.__import__


def guarded_import(name, globals=None, locals=None, fromlist=(), level=0):
    if not str((globals or {}).get("__name__", "")).startswith("rotorred"):
        return real_import(name, globals, locals, fromlist, level)
    if level == 0 and name.partition(".")[0] in POSIX_ONLY:
        blocked.append(f"import {name}")
        raise ModuleNotFoundError(f"No module named {name!r} (not on every OS)", name=name)
    module = real_import(name, globals, locals, fromlist, level)
    return SEEN.get(id(module), module)


sys.addaudithook(audit)
builtins.__import__ = guarded_import
if os.environ.get("ANY_OS_MEMORY"):
    import psutil
    available = int(os.environ["ANY_OS_MEMORY"])
    psutil.virtual_memory = lambda: types.SimpleNamespace(total=2 * available, available=available)
try:
    if os.environ.get("ANY_OS_PROBE"):
        exec(compile(os.environ["ANY_OS_PROBE"], PACKAGE + "_any_os_probe.py", "exec"), {"__name__": "rotorred._probe"})
        code = 0
    else:
        from rotorred.cli import main
        code = main()
finally:
    for what in blocked:
        print(f"any-os: blocked {what}", file=sys.stderr)
sys.exit(code)
""" % (POSIX_ONLY, OS_ONLY, SIGNAL_ONLY)

#: paper-rub shortened to 0.3 s (0.2 s recorded), no figures: everything runs in the restricted process
SHORT = ["--set", "solver.duration=0.3", "--set", "solver.record_start=0.1", "--set", "output.plot_window=[0.1, 0.2]",
         "--set", "output.plots=[]", "--set", "output.formats=[\"npz\", \"csv\"]"]


def _restricted(*args, memory: int | None = None, probe: str | None = None, timeout: float = 300):
    """Run ``rotorred ARGS`` (or ``probe``) in a child process under the restrictions; the completed process."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONUNBUFFERED="1")
    env.pop("ANY_OS_MEMORY", None)
    env.pop("ANY_OS_PROBE", None)
    if memory is not None:
        env["ANY_OS_MEMORY"] = str(memory)
    if probe is not None:
        env["ANY_OS_PROBE"] = probe
    return subprocess.run([sys.executable, "-c", HARNESS, *args], capture_output=True, text=True, env=env,
                          timeout=timeout)


def _blocked(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("any-os: blocked")]


# --------------------------------------------------------------------------- the restrictions bite
def test_the_restrictions_refuse_what_posix_alone_has():
    """Code of the rotorred package cannot import fcntl, sees no os.fchmod, os.statvfs, os.getuid nor signal.SIGKILL,
    and cannot read /proc; a library (psutil) still reads /proc, and os and signal keep what every OS has."""
    probe = """
import os, signal
try:
    import fcntl
    raise SystemExit("fcntl imported")
except ImportError:
    pass
for name in ("fchmod", "statvfs", "getuid", "sched_getaffinity", "sysconf"):
    assert not hasattr(os, name), name
assert not hasattr(signal, "SIGKILL") and signal.SIGTERM and signal.SIGINT
assert os.path.join("a", "b") and os.replace and os.getpid() > 0
try:
    open("/proc/meminfo").read()
    raise SystemExit("/proc read")
except FileNotFoundError:
    pass
import psutil
assert psutil.virtual_memory().available > 0
"""
    done = _restricted(probe=probe)
    assert done.returncode == 0, done.stderr
    assert _blocked(done.stderr) == ["any-os: blocked import fcntl", "any-os: blocked open /proc/meminfo"]


def test_the_former_memory_guard_is_caught():
    """The memory guard as it was (``/proc/meminfo``, else ``os.sysconf``, else 2^62 bytes) switched itself off
    under the restrictions, as on Windows, and exited 0: the blocked read is what shows it."""
    probe = """
import os
def available_memory():
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return 1 << 62
assert available_memory() == 1 << 62
"""
    done = _restricted(probe=probe)
    assert done.returncode == 0, done.stderr
    assert _blocked(done.stderr) == ["any-os: blocked open /proc/meminfo"]


# --------------------------------------------------------------------------- commands end to end
def test_run_writes_its_files(tmp_path):
    out = tmp_path / "run"
    done = _restricted("run", "paper-rub", "--no-normal", *SHORT, "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert not _blocked(done.stderr), done.stderr
    names = {p.name for p in out.iterdir()}
    assert {"result.npz", "timeseries.csv", "summary.txt", ".rotorred-files"} <= names, names
    assert LOCK not in names and not any(n.startswith(".rotorred-staging-") for n in names)
    assert len((out / "timeseries.csv").read_text().splitlines()) == 10_002  # 0.2 s at dt = 2e-5, and the header


def test_map_of_two_points_writes_its_files(tmp_path):
    out = tmp_path / "map"
    done = _restricted("map", "paper-rub", "--vary", "speeds.outer=89:90:2", "--set", "solver.duration=0.5",
                       "--set", "solver.record_start=0.3", "--set", "output.plot_window=[0.3, 0.4]",
                       "--set", "output.compare_normal=false", "--cold", "--workers", "0", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert not _blocked(done.stderr), done.stderr
    rows = (out / "map.csv").read_text().splitlines()
    assert len(rows) == 3 and (out / "map.nc").stat().st_size > 0, rows
    assert any(p.suffix == ".png" for p in out.iterdir()) and not (out / LOCK).exists()


def test_the_memory_guard_refuses_an_absurd_run_from_psutils_report(tmp_path):
    """psutil reports 8 GiB available (as another OS would through it); 1000 s recorded at dt = 2e-5 needs about
    48 GiB: refused before computing, exit 2, naming the memory and psutil's figure; nothing written."""
    out = tmp_path / "absurd"
    done = _restricted("run", "paper-rub", "--no-normal", *SHORT, "--set", "solver.duration=1000",
                       "--set", "solver.record_start=0", "--out", str(out), memory=8 << 30)
    assert done.returncode == 2, done.stderr
    assert "memory" in done.stderr and "the 8 GiB available" in done.stderr and "--force" in done.stderr
    assert "Traceback" not in done.stderr and not _blocked(done.stderr)
    assert not out.exists()


def test_a_second_run_into_a_locked_folder_is_refused_naming_the_owner(tmp_path):
    """This process holds the folder's lock; the restricted run into it exits 4 naming this process."""
    out = tmp_path / "busy"
    with OutputFolder(out):
        done = _restricted("run", "paper-rub", "--no-normal", *SHORT, "--out", str(out))
        assert done.returncode == 4, done.stderr
        assert f"another rotorred run (pid {os.getpid()})" in done.stderr and "choose another --out" in done.stderr
        assert not _blocked(done.stderr)
        assert (out / LOCK).exists()
    assert not out.exists()  # created by the holder, which committed nothing


# --------------------------------------------------------------------------- the lock (rotorred.writers)
def test_the_lock_is_hidden_names_its_owner_and_goes_with_the_run(tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    with OutputFolder(out) as folder:
        lock = out / LOCK
        assert lock.name.startswith(".") and lock.read_bytes()[1:].decode().strip() == f"pid {os.getpid()}"
        with pytest.raises(FolderBusy, match=rf"another rotorred run \(pid {os.getpid()}\)"):
            OutputFolder(out).__enter__()  # another open file: refused within one process too
        write_text(folder.staged(out / "a.txt"), "a\n")
        folder.commit()
    assert sorted(p.name for p in out.iterdir()) == [".rotorred-files", "a.txt"]
    with OutputFolder(out):  # free again
        pass
    assert not (out / LOCK).exists()


def test_the_lock_of_a_killed_run_is_free(tmp_path):
    """A run killed while it holds the lock leaves the file with its pid, not the lock: the next run takes it."""
    out = tmp_path / "o"
    child = subprocess.Popen([sys.executable, "-c", "import sys, time; from rotorred.writers import OutputFolder\n"
                              f"with OutputFolder({str(out)!r}):\n    print('locked', flush=True); time.sleep(60)"],
                             stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "locked"
        with pytest.raises(FolderBusy, match=rf"\(pid {child.pid}\)"):
            OutputFolder(out).__enter__()
    finally:
        child.kill()
        child.wait(timeout=30)
    assert (out / LOCK).read_bytes()[1:].decode().strip() == f"pid {child.pid}"  # left behind by the kill
    with OutputFolder(out):
        assert (out / LOCK).read_bytes()[1:].decode().strip() == f"pid {os.getpid()}"
    assert not (out / LOCK).exists()


def test_a_file_system_without_locks_is_a_clear_error(tmp_path, monkeypatch):
    """filelock's ENOSYS (no flock here): an OSError naming the lock file, which the commands report with exit 4."""
    import filelock

    def no_locks(fd, blocking=True):
        raise OSError(errno.ENOSYS, "fcntl is unavailable")
    monkeypatch.setattr(filelock, "lock_descriptor", no_locks)
    with pytest.raises(OSError, match="cannot lock it") as caught:
        OutputFolder(tmp_path / "o").__enter__()
    assert caught.value.filename == str(tmp_path / "o" / LOCK) and caught.value.errno == errno.ENOSYS
    assert not (tmp_path / "o").exists()  # the folder it had created removed, with the lock file


def test_files_get_open_s_mode_where_there_is_fchmod_and_are_written_where_there_is_none(tmp_path, monkeypatch):
    """With os.fchmod a file gets the mode open() would give (not mkstemp's 0600); without it (Windows, which has
    only a read-only flag) it is still written whole."""
    path = write_text(tmp_path / "a.txt", "a\n")
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~_umask()
    monkeypatch.delattr(os, "fchmod")
    path = write_text(tmp_path / "b.txt", "b\n")
    assert path.read_text() == "b\n" and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.txt"]


# --------------------------------------------------------------------------- the memory guard (rotorred.scenes.budget)
def test_available_memory_is_psutils(monkeypatch):
    import psutil

    from rotorred.checks import InputError
    from rotorred.scenes import budget

    monkeypatch.setattr(psutil, "virtual_memory", lambda: SimpleNamespace(available=3 << 30, total=4 << 30))
    assert budget.available_memory() == 3 << 30
    estimate = budget.Estimate(10, 10, 2 << 30, 8, 0, {"memory": ("solver.record_start", 0.0)})
    with pytest.raises(InputError, match=r"more than 0.5 x the 3 GiB available"):
        estimate.check()
    assert estimate.check(memory=5 << 30) is estimate


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
