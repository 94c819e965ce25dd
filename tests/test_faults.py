"""Faults of the long commands (issue 41): a map resumed after its scene changed, interrupts of map, continue and
run-ups (and of every other command, from its first imports on), a Dask cluster lost or not Dask, sizes before work,
and inputs a command cannot honour. Each test first reproduced its example on main
(named in its docstring) and passes now.

Fault kinds tested here: :data:`FAULT_KINDS` (31; docs/commands.md states their number)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rotorred.cli import main

#: the fault kinds these tests try, each at least once (docs/commands.md states their number)
FAULT_KINDS = (
    # 1. a map resumed after a change: its scene's content, its rotor file's content, --cold, a --set
    "resume: scene content", "resume: rotor content", "resume: --cold", "resume: --set",
    # 3. sizes: 1e5 map points, 1e9 values (map --vary, run --set), --workers above the cores, continue's memory
    # and monodromy steps
    "size: 1e5 points", "size: 1e9 --vary", "size: 1e9 --set", "size: --workers", "size: --harmonics",
    "size: --samples",
    # 2. interrupts: SIGINT and SIGTERM at random moments of map, continue, run-up; a worker or the scheduler lost;
    # an error raised from an interrupt
    "SIGINT map", "SIGTERM map", "SIGINT continue", "SIGTERM continue", "SIGINT run-up", "SIGTERM run-up",
    "Dask worker killed", "Dask scheduler killed", "--scheduler not Dask", "SIGINT Dask map", "interrupt inside an import",
    # ... and at the first imports, before a command runs; in every other command (campbell, harmonic, modes)
    "signal at the first imports", "SIGINT or SIGTERM campbell", "SIGINT or SIGTERM harmonic",
    "SIGINT or SIGTERM modes",
    # 4. inputs: [runup] in map and continue, --ratio against --set speeds, run-up and steady steps a revolution,
    # run-up beyond the small-displacement range
    "map [runup]", "continue [runup]", "--ratio with --set speeds", "run-up steps a revolution",
    "steady steps a revolution", "run-up small displacement",
)

#: a short paper-rub map point: 0.4 s run, 0.2 s recorded, no figures or files of the scene
SHORT = ["--set", "solver.duration=0.4", "--set", "solver.record_start=0.2", "--set", "output.plot_window=[0.2, 0.3]",
         "--set", "output.plots=[]", "--set", "output.formats=[]", "--set", "output.compare_normal=false"]

BUILTIN = Path(__file__).resolve().parents[1] / "rotorred" / "scenes" / "builtin"
PRESETS = Path(__file__).resolve().parents[1] / "rotorred" / "model" / "presets"


# --------------------------------------------------------------------------- 1. resume by content
@pytest.fixture()
def scene_file(tmp_path) -> Path:
    """paper-rub as a file of its own, its rotor a file of its own (the seed rig)."""
    shutil.copy(PRESETS / "seed-rig.toml", tmp_path / "rotor.toml")
    text = (BUILTIN / "paper-rub.toml").read_text().replace('preset = "seed-rig"', 'file = "rotor.toml"')
    (tmp_path / "scene.toml").write_text(text)
    return tmp_path / "scene.toml"


def _map(scene: Path, out: Path, *extra: str) -> int:
    return main(["map", str(scene), "--vary", "rub.clearance=20e-6", "--workers", "0", *SHORT, *extra, "--out",
                 str(out), "-q"])


def _files(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_map_resumed_after_its_scene_changed_refuses_naming_the_change(scene_file, tmp_path, capsys):
    """Issue 41's example: a map resumed after an edit of its scene file reused the old points and exited 0 (on main
    the second and third maps below exited 0, running no point). Now an edit of the scene's content, or of its rotor
    file's, refuses (exit 2) naming the key and both values, and leaves the folder as it was; the same content from
    another path, or with only a comment changed, resumes (no point runs again)."""
    out = tmp_path / "out"
    assert _map(scene_file, out) == 0
    before, written = _files(out), (out / "points" / "up" / "0.npz").stat().st_mtime_ns
    text = scene_file.read_text()
    scene_file.write_text(text.replace("mu_d = ", "mu_d = 0.1 #", 1))
    capsys.readouterr()
    assert _map(scene_file, out) == 2
    err = capsys.readouterr().err
    assert "holds the points of a different map (the scene's content differs at rub[0].mu_d (" in err, err
    assert "0.1 now)" in err and "remove" in err and _files(out) == before

    scene_file.write_text(text)
    rotor = scene_file.parent / "rotor.toml"
    rotor.write_text(rotor.read_text().replace("E = 2.1e11", "E = 2.0e11", 1))
    assert _map(scene_file, out) == 2
    err = capsys.readouterr().err
    assert "the scene's content differs at rotor.material[0].E (210000000000.0 in the points, 200000000000.0 now)" \
        in err, err
    assert _files(out) == before

    rotor.write_text(rotor.read_text().replace("E = 2.0e11", "E = 2.1e11", 1))
    moved = tmp_path / "elsewhere"
    moved.mkdir()
    shutil.copy(rotor, moved / "rotor.toml")
    (moved / "scene.toml").write_text("# the same scene, moved, a comment added\n" + text)
    assert _map(moved / "scene.toml", out) == 0
    assert (out / "points" / "up" / "0.npz").stat().st_mtime_ns == written  # not run again


def test_a_map_resumed_with_other_options_refuses_naming_them(scene_file, tmp_path, capsys):
    """--cold, --limit or a --set that changes a point refuse a resume, each named."""
    out = tmp_path / "out"
    assert _map(scene_file, out) == 0
    capsys.readouterr()
    assert _map(scene_file, out, "--cold") == 2
    assert "the start (--cold): False in the points, True now" in capsys.readouterr().err
    assert _map(scene_file, out, "--set", "rub.K_nr=4e10") == 2
    assert "rub[0].K_nr (50000000000.0 in the points, 40000000000.0 now)" in capsys.readouterr().err


# --------------------------------------------------------------------------- 3. sizes before work
def _limited(*args: str, memory: int = 3 << 30, timeout: float = 60.0):
    """``rotorred ARGS`` in a child process limited to ``memory`` bytes of address space: (exit status, stderr,
    seconds)."""
    import resource
    import subprocess
    import sys
    import time

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))

    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", "import sys; from rotorred.cli import main; sys.exit(main())", *args],
                          capture_output=True, text=True, timeout=timeout, preexec_fn=limit)
    return done.returncode, done.stderr, time.perf_counter() - t0


def test_a_map_of_a_hundred_thousand_points_is_answered_at_once(tmp_path):
    """Issue 41: a --vary of 100 000 points did not answer in 90 s (on main: no answer in 20 s, every point's scene
    read before the size check). Now the map's estimate from its first point refuses it at once (exit 2), naming
    --vary, the points, the steps and --force; nothing is written."""
    status, err, seconds = _limited("map", "paper-rub", "--vary", "rub.clearance=1e-6:1e-4:100000", "--workers", "0",
                                    *SHORT, "--out", str(tmp_path / "big"), "-q", timeout=30)
    assert status == 2 and seconds < 15, (status, err, seconds)
    assert err.startswith("rotorred map: error: --vary = 'rub.clearance=<100000 values> (100000 points)': gives "
                          "2e+09 steps in all") and "use --force" in err, err
    assert not (tmp_path / "big").exists()


@pytest.mark.parametrize("command", ["map", "run"])
def test_a_billion_values_are_refused_not_a_memory_error(tmp_path, command):
    """Issue 41: --vary KEY=START:STOP:1e9 ended in a MemoryError (on main: "internal error (MemoryError)", exit 1,
    within 3 GiB of address space). Now refused before the list is made, in every option of that form."""
    option = "--vary" if command == "map" else "--set"
    status, err, _ = _limited(command, "paper-rub", option, "rub.clearance=1e-6:1e-4:1000000000", "--out",
                              str(tmp_path / "o"), "-q")
    assert status == 2 and "MemoryError" not in err, err
    assert f"{option} rub.clearance = '1e-6:1e-4:1000000000': must have N <= 1e+06 values" in err


def test_more_workers_than_cores_are_capped_with_a_warning(caplog):
    """--workers above the cores: warned and capped unless --force (on main: 100 worker processes on 2 cores)."""
    import argparse
    import logging
    import os

    from rotorred.cli.map import workers

    cores = os.cpu_count()
    args = argparse.Namespace(workers=cores + 98, scheduler=None, force=False)
    with caplog.at_level(logging.WARNING, logger="rotorred"):
        assert workers(args) == cores
    assert f"--workers = {cores + 98} is more than the {cores} cores of this machine: capped at {cores}" in caplog.text
    assert workers(argparse.Namespace(workers=cores + 98, scheduler=None, force=True)) == cores + 98
    assert workers(argparse.Namespace(workers=None, scheduler=None, force=False)) == cores
    assert workers(argparse.Namespace(workers=0, scheduler=None, force=False)) == 0


@pytest.mark.parametrize("options, named", [(["--harmonics", "100000", "--samples", "200002", "--no-stability"], "--harmonics = 100000"),
                                            (["--harmonics", "20", "--samples", "100000000"], "--samples = 100000000")])
def test_a_branch_beyond_the_limits_is_refused_before_work(tmp_path, options, named):
    """Issue 41: `continue` had no size check (on main both were internal errors, MemoryError of 298 GiB and 30.5 GiB,
    exit 1, with a traceback log in --out). Now its estimate (unknowns, Jacobians, monodromy steps) refuses at once
    (exit 2) naming the option and --force."""
    status, err, seconds = _limited("continue", "paper-rub", "--param", "rub.clearance=45e-6:40e-6", *options,
                                    "--out", str(tmp_path / "b"), "-q")
    assert status == 2 and seconds < 15, (status, err, seconds)
    assert err.startswith(f"rotorred continue: error: {named}: gives a run beyond the limits") and "--force" in err


# --------------------------------------------------------------------------- 2. interrupts at random moments
#: the commands interrupted: a 1-point map (serial), a short clearance branch (10 harmonics), a 1-s run-up to 0.3 x
#: its speeds; each with an option that the interrupted runs change, so that their result differs from the earlier
INTERRUPTED = {
    "map": (["map", "paper-rub", "--vary", "rub.clearance=20e-6", "--workers", "0", *SHORT,
             "--set", "solver.duration=0.3", "--set", "solver.record_start=0.1", "--set", "output.plot_window=[0.1, 0.2]"],
            []),
    "continue": (["continue", "paper-rub", "--param", "rub.clearance=45e-6:40e-6", "--harmonics", "10", "--samples",
                  "64"], ["--tol", "1e-8"]),
    "runup": (["run", "runup", "--set", "runup.duration=1.0", "--set", "runup.to=0.3",
               "--set", "runup.orbits_hz=[10.0, 20.0]", "--set", "output.plots=[]"], ["--set", "runup.to=0.31"]),
}
#: the commands without work to keep, each interrupted at a few moments: the folder keeps its earlier result or holds
#: the complete new one
OTHERS = {
    "campbell": (["campbell", "seed-rig", "--speeds", "0:6000:11"], ["--speeds", "0:6000:13"]),
    "harmonic": (["harmonic", "seed-rig", "--speeds", "0:6000:11"], ["--speeds", "0:6000:13"]),
    "modes": (["modes", "seed-rig", "--speed", "3000"], ["--speed", "3100"]),
}
COMMANDS = {**INTERRUPTED, **OTHERS}
#: a signal's exit statuses: the command's (it caught the signal), or the signal's own (-2, -15: it came after the
#: command had returned, while the process ended; its result is then complete)
SIGNALS = {"SIGINT": (130, -2), "SIGTERM": (143, -15)}
#: the earliest moment of an interrupt (s) after the fork of the command's process: once the console script's handlers
#: are set (they are its first statement). The moments before, in Python's start and rotorred's first imports, are
#: test_a_signal_during_the_first_imports_is_one_line_and_its_status's
START = 0.005


class _Forked:
    """``rotorred ARGS -q`` (the console script, :func:`rotorred.cli.entry`) in a child forked from this process, its
    stdout and stderr into files: a process start-up without Python's start and the imports, and with the compiled
    kernels this process has loaded (:func:`_warm`). SIGINT as in a terminal (Python's KeyboardInterrupt).

    Once the command has returned, the child says so and waits until :meth:`communicate` lets it exit, as a Python
    process's end takes its time: a signal then has the action entry leaves it (the process ends by it, -2 or -15),
    and none is sent to a process that has already exited (a parent descheduled between its check and the signal
    would lose it, and see exit 0)."""

    def __init__(self, *args: str):
        import os
        import tempfile

        self.files = [tempfile.TemporaryFile() for _ in range(2)]
        returned, self._go = os.pipe(), os.pipe()
        self.pid = os.fork()
        if self.pid == 0:
            os.close(returned[0])
            os.close(self._go[1])
            self._child(args, returned[1], self._go[0])
        os.close(returned[1])
        os.close(self._go[0])
        self._returned = returned[0]
        self.returncode = None

    def _child(self, args, returned: int, go: int):
        import io
        import os
        import signal
        import sys
        import traceback

        status = 1
        try:
            for fd, f in zip((1, 2), self.files):
                os.dup2(f.fileno(), fd)
            sys.stdout, sys.stderr = (io.TextIOWrapper(io.FileIO(fd, "w", closefd=False), line_buffering=True)
                                      for fd in (1, 2))
            signal.signal(signal.SIGINT, signal.default_int_handler)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            sys.argv = ["rotorred", *args, "-q"]
            from rotorred.cli import entry

            status = entry()
        except BaseException:  # noqa: BLE001 -- what a real process would print
            traceback.print_exc()
        finally:
            for stream in (sys.stdout, sys.stderr):
                stream.flush()
            os.write(returned, b"r")
            os.read(go, 1)  # as an interpreter's end: a signal now has its own action (entry's)
            os._exit(status)

    def ended(self) -> bool:
        """Whether the command has returned (its process then waits for :meth:`communicate`)."""
        import select

        return bool(select.select([self._returned], [], [], 0)[0])

    def send_signal(self, sig) -> None:
        import os

        os.kill(self.pid, sig)

    def communicate(self, timeout: float = 120.0) -> tuple[str, str]:
        """Wait for the command (its process killed after ``timeout`` s), let its process exit: (stdout, stderr); its
        status in ``returncode``."""
        import os
        import select
        import signal

        if not select.select([self._returned], [], [], timeout)[0]:
            os.kill(self.pid, signal.SIGKILL)
        try:
            os.write(self._go[1], b"g")
        except BrokenPipeError:  # ended by a signal after it returned
            pass
        for fd in (self._returned, self._go[1]):
            os.close(fd)
        self.returncode = os.waitstatus_to_exitcode(os.waitpid(self.pid, 0)[1])
        texts = []
        for f in self.files:
            f.seek(0)
            texts.append(f.read().decode("utf-8", "replace"))
            f.close()
        return texts[0], texts[1]


#: the kinds whose command this process has run (its modules imported, its kernels loaded)
_WARMED: set = set()


def _warm(kind: str, scratch: Path) -> None:
    """Run ``kind``'s command once in this process (its imports and compiled kernels then serve every child forked from
    it and from the pool processes forked from it)."""
    import os

    if kind not in _WARMED:
        assert main([*COMMANDS[kind][0], "--out", str(scratch / f"warm-{kind}-{os.getpid()}"), "-q"]) == 0
        _WARMED.add(kind)


@pytest.fixture()
def no_tqdm_monitor():
    """No tqdm monitor thread in this process while the test forks (a thread holding a lock at a fork leaves it held
    in the child)."""
    import tqdm

    interval = tqdm.tqdm.monitor_interval
    tqdm.tqdm.monitor_interval = 0
    if tqdm.tqdm.monitor is not None:
        tqdm.tqdm.monitor.exit()
        tqdm.tqdm.monitor = None
    yield
    tqdm.tqdm.monitor_interval = interval


def _earlier(kind: str, out: Path) -> float:
    """The earlier result of ``kind`` into ``out`` (a forked child of a warm process) and the seconds it took."""
    import time

    _warm(kind, out.parent)
    t0 = time.perf_counter()
    proc = _Forked(*COMMANDS[kind][0], "--out", str(out))
    _, err = proc.communicate()
    assert proc.returncode == 0, err
    return time.perf_counter() - t0


def _snapshot(folder: Path) -> dict:
    import hashlib

    if not folder.exists():
        return {}
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _consistent_partial(kind: str, out: Path) -> str:
    """What is wrong with ``out`` as a partial result marked INCOMPLETE ("" if nothing)."""
    import csv

    import xarray as xr

    from rotorred import writers

    if not (out / writers.MANIFEST).exists():
        return "no manifest"
    listed = (out / writers.MANIFEST).read_text().split()
    if writers.INCOMPLETE not in listed or not all((out / name).exists() for name in listed):
        return f"manifest {listed} against {sorted(p.name for p in out.iterdir())}"
    if kind == "map":
        with xr.open_dataset(out / "map.nc", engine="h5netcdf") as ds:
            done = int((ds["status"].values != "").sum())
        kept = len(list((out / "points").rglob("*.npz")))
        return "" if done == kept else f"map.nc holds {done} points, points/ {kept}"
    if kind == "continue":
        with open(out / "branch.csv", newline="") as f:
            rows = len(list(csv.reader(f))) - 1
        with xr.open_dataset(out / "branch.nc", engine="h5netcdf") as ds:
            points = ds.sizes["point"]
        text = (out / "branch.txt").read_text()
        return "" if rows == points and "INCOMPLETE: interrupted" in text else f"{rows} rows, {points} points"
    return "" if (out / "summary.txt").read_text().count("INCOMPLETE") else "summary.txt not marked"


def _one_interrupt(kind: str, earlier: Path, out: Path, sig: str, delay: float) -> str:
    """Run ``kind`` into ``out`` (a copy of ``earlier``, or new for a map), send ``sig`` after ``delay`` s; what went
    wrong ("" if nothing)."""
    import signal
    import time

    args, changed = COMMANDS[kind]
    _warm(kind, out.parent)
    while True:  # a moment after the command ended (a machine less busy than when it was measured): earlier
        shutil.rmtree(out, ignore_errors=True)
        if kind != "map":
            shutil.copytree(earlier, out)
        before = _snapshot(out)
        proc = _Forked(*args, *changed, "--out", str(out))
        time.sleep(delay)
        if not proc.ended():
            proc.send_signal(getattr(signal, sig))  # microseconds after the check: it was running
            break
        proc.communicate()
        if proc.returncode != 0:
            return f"{kind} without a signal: exit {proc.returncode}"
        delay = START + 0.6 * (delay - START)
    _, err = proc.communicate()
    said = f"{kind} {sig} at {delay:.2f} s: exit {proc.returncode}, {err.strip()[-300:]!r}"
    if proc.returncode not in SIGNALS[sig] or "Traceback" in err or "internal error" in err:
        return said
    leftovers = [p.name for p in out.glob(".rotorred*") if p.name != ".rotorred-files"] if out.exists() else []
    if leftovers:
        return f"{said}; left {leftovers}"
    now = _snapshot(out)
    committed = {k: v for k, v in now.items() if not k.startswith("points/")}
    points = [k for k in now if k.startswith("points/") and k.endswith(".npz")]
    if committed == {k: v for k, v in before.items() if not k.startswith("points/")} and not points:
        return ""  # the earlier result (a map's: none, and no point finished)
    from rotorred import writers

    if not (out / writers.MANIFEST).exists():
        return "no manifest"
    listed = (out / writers.MANIFEST).read_text().split()
    if writers.INCOMPLETE not in listed and all((out / name).exists() for name in listed) \
            and _complete(kind, out, before):
        return ""  # the signal came after the commit: the new result, complete
    wrong = _consistent_partial(kind, out)
    return f"{said}; {wrong}" if wrong else ""


def _complete(kind: str, out: Path, before: dict) -> bool:
    """Whether ``out`` holds the command's complete new result: every file of the earlier one written again."""
    now = _snapshot(out)
    return set(before) <= set(now) and all(now[k] != v for k, v in before.items() if k.endswith(".txt"))


def test_sigint_and_sigterm_at_random_moments_leave_the_earlier_or_a_partial_result(tmp_path, no_tqdm_monitor):
    """Issue 41: SIGINT and SIGTERM at 10 random moments (seed 41) of a short map, continue and run-up, two at a time:
    every exit 130 (SIGINT) or 143 (SIGTERM) (or the signal's own, -2 or -15, when it came after the command had
    returned), no traceback, no staging folder or lock left, and every folder its earlier result, a consistent partial
    one marked INCOMPLETE (a run-up's: its record up to the signal), or (the signal after the commit) the complete new
    one; a map's finished point is never left without its dataset. On main a SIGTERM, or a SIGINT as the map was
    written, left the finished point without map.nc, and a run-up interrupted as it stepped kept nothing of its run.

    Each command runs in a child forked from a pool process forked from this one, which has run each command once
    (its imports done, its kernels loaded): the moments fall in the command's own work, from START s on (the first
    imports: test_a_signal_during_the_first_imports_is_one_line_and_its_status); this took 115-130 s with a fresh
    Python process for each moment, most of it in imports."""
    import multiprocessing
    import random
    from concurrent.futures import ProcessPoolExecutor

    for kind in INTERRUPTED:
        _warm(kind, tmp_path)
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as pool:  # not threads: a thread
        # waiting for the GIL between the check that the command runs and the signal could send it after it ended
        took = dict(zip(INTERRUPTED, pool.map(_earlier, INTERRUPTED,
                                              [tmp_path / f"{kind}-earlier" for kind in INTERRUPTED])))
        rng = random.Random(41)
        cases = [(kind, tmp_path / f"{kind}-earlier", tmp_path / f"{kind}-{i}", rng.choice(list(SIGNALS)),
                  rng.uniform(START, 0.9 * took[kind])) for kind in INTERRUPTED for i in range(10)]
        wrong = [w for w in pool.map(_one_interrupt, *zip(*cases)) if w]
    assert not wrong, "\n".join(wrong)


def test_the_other_commands_interrupted_at_random_moments_keep_the_earlier_or_write_the_new_result(tmp_path,
                                                                                                   no_tqdm_monitor):
    """Issue 41: `harmonic`, `campbell` (and `modes`, `convert`) were not under the interrupt wrapper of map, continue
    and run: a signal raised again from an import became an internal error there (exit 1; reproduced on main by
    test_an_error_raised_from_an_interrupt_is_the_interrupt through `convert`), and one lost in a library an exit 0.
    Now every command is, in rotorred.cli.main. SIGINT or SIGTERM at 2 random moments (seed 41) of each exits 130 or
    143 (or -2, -15 after it returned), no traceback, and its folder keeps its earlier result or holds the complete
    new one (these moments held on main too: this guards the wrapper's place)."""
    import multiprocessing
    import random
    from concurrent.futures import ProcessPoolExecutor

    for kind in OTHERS:
        _warm(kind, tmp_path)
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as pool:
        took = dict(zip(OTHERS, pool.map(_earlier, OTHERS, [tmp_path / f"{kind}-earlier" for kind in OTHERS])))
        rng = random.Random(41)
        cases = [(kind, tmp_path / f"{kind}-earlier", tmp_path / f"{kind}-{i}", rng.choice(list(SIGNALS)),
                  rng.uniform(START, 0.9 * took[kind])) for kind in OTHERS for i in range(2)]
        wrong = [w for w in pool.map(_one_interrupt, *zip(*cases)) if w]
    assert not wrong, "\n".join(wrong)


# --------------------------------------------------------------------------- 2. a Dask cluster lost under a map
@pytest.fixture()
def dask_cluster():
    """A scheduler and one worker without a nanny, each a process of its own: {"address", "scheduler", "worker"}."""
    import os
    import socket
    import subprocess
    import sys

    from distributed import Client

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
    procs = {"scheduler": subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host",
                                            "127.0.0.1", "--port", str(port), "--no-dashboard"], **quiet)}
    procs["worker"] = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads",
                                        "1", "--no-nanny", "--no-dashboard"], **quiet)
    with Client(address, timeout="30s") as client:
        client.wait_for_workers(1, timeout=60)
    yield {"address": address, **procs}
    for p in procs.values():
        p.kill()
        p.wait()


@pytest.mark.parametrize("victim", ["worker", "scheduler", "Ctrl-C"])
def test_a_dask_cluster_lost_under_a_map_writes_the_points_done_marked_incomplete(dask_cluster, tmp_path, monkeypatch,
                                                                                  capsys, victim):
    """Issue 41: killing the only worker or the scheduler gave internal errors and no dataset (on main: the map with
    its only worker killed waited for ever; with its scheduler killed, an internal error, exit 1, no map.nc), and so
    did Ctrl-C on a Dask map (worker tracebacks, no INCOMPLETE marker). Now the map ends there with exit 3 (130 for
    SIGINT's KeyboardInterrupt, raised as the first point's result comes back from the worker), one line saying the
    Dask cluster was lost (or the signal), and map.nc holds the point done, the folder INCOMPLETE; the same command
    resumes it."""
    import signal

    import xarray as xr

    import rotorred.maps.execute as execute
    import rotorred.maps.run as map_run

    real = map_run.run_points
    monkeypatch.setattr(execute, "NO_WORKER_WAIT", 3.0, raising=False)  # absent on main

    def killing(spec, store, client, on_point):
        def kill(*args):
            on_point(*args)
            if victim == "Ctrl-C":
                raise KeyboardInterrupt
            dask_cluster[victim].send_signal(signal.SIGKILL)
        return real(spec, store, client, on_point=kill)

    monkeypatch.setattr(map_run, "run_points", killing)
    out = tmp_path / "out"
    status = main(["map", "paper-rub", "--vary", "rub.clearance=20e-6,30e-6,40e-6", "--scheduler",
                   dask_cluster["address"], *SHORT, "--out", str(out), "-q"])
    err = capsys.readouterr().err
    said = "interrupted (SIGINT)" if victim == "Ctrl-C" else "the Dask cluster was lost"
    assert status == (130 if victim == "Ctrl-C" else 3), err
    assert err.startswith(f"rotorred map: error: {said}") and "after 1 of 3 points" in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert (out / "INCOMPLETE").read_text().startswith(said)
    with xr.open_dataset(out / "map.nc", engine="h5netcdf") as ds:
        assert list(ds["status"].values.ravel()) == ["ok", "", ""]


def test_a_scheduler_address_where_no_dask_answers_is_refused_naming_it(tmp_path, capsys):
    """Issue 41: a --scheduler that is not Dask gave an internal error (on main: a web server's reply read as a Dask
    frame, "out of memory: Unable to allocate 3.01 EiB", exit 4). Now refused (exit 2), one line naming --scheduler
    and what answered; nothing written."""
    import socket
    import threading

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)

    def answer():
        while True:
            try:
                conn, _ = server.accept()
            except OSError:
                return
            with conn:
                conn.sendall(b"HTTP/1.0 200 OK\r\nContent-Type: text/plain\r\n\r\nhello")

    threading.Thread(target=answer, daemon=True).start()
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    out = tmp_path / "o"
    try:
        status = main(["map", "paper-rub", "--vary", "rub.clearance=20e-6,30e-6", "--scheduler", address, *SHORT,
                       "--out", str(out), "-q"])
    finally:
        server.close()
    err = capsys.readouterr().err
    assert status == 2, err
    assert err.startswith(f"rotorred map: error: --scheduler = {address!r}: must be a Dask scheduler's address "
                          "(tcp://host:port); what answered there does not speak Dask's protocol ("), err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


# --------------------------------------------------------------------------- 4. inputs a command cannot honour
@pytest.mark.parametrize("command", [["map", "runup-rub", "--vary", "rub.clearance=20e-6,30e-6", "--workers", "0"],
                                     ["continue", "runup-rub", "--param", "rub.clearance=45e-6:40e-6"]])
def test_a_run_up_scene_is_refused_where_its_runup_cannot_be_honoured(tmp_path, capsys, command):
    """Issue 41: `map` on a run-up scene ignored [runup] (on main: the map ran its points at the scene's steady speeds,
    exit 0). Now map and continue refuse it before anything runs (exit 2), naming [runup] and `rotorred run`."""
    out = tmp_path / "o"
    assert main([*command, "--out", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert "has a [runup], which a " in err and "cannot honour" in err and "rotorred run" in err, err
    assert not out.exists()


def test_a_ratio_that_conflicts_with_a_fixed_speed_is_refused_naming_both(tmp_path, capsys):
    """Issue 41: --ratio silently overrode --set speeds.* while map.nc recorded the overridden value (on main: exit 0).
    Now refused (exit 2) naming both options and their values."""
    out = tmp_path / "o"
    assert main(["map", "paper-rub", "--vary", "speeds.outer=89,90", "--ratio", "inner=0.7778", "--set",
                 "speeds.inner=60", "--workers", "0", *SHORT, "--out", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert "--ratio = 'inner=0.7778': conflicts with --set speeds.inner=60: both set the inner spool's speed" in err, err
    assert not out.exists()


def test_run_ups_say_what_a_steady_run_says_of_a_long_step_and_a_large_orbit(tmp_path, capsys):
    """Issue 41: run-ups gave neither the small-displacement warning of a steady run nor a warning at a few steps a
    revolution (on main: a run-up at 3.7 steps a revolution with orbits of 0.7 m said neither, exit 0). Now the
    step's warning comes before computing, from one implementation (budget.step_warnings) for steady runs, run-ups and
    maps, and the run-up's summary warns of each node beyond the small-displacement range as a steady run's does."""
    runup = ["runup", "--set", "runup.duration=1.0", "--set", "runup.to=0.3", "--set", "runup.orbits_hz=[10.0, 20.0]",
             "--set", "output.plots=[]"]
    assert main(["run", *runup, "--set", "solver.dt=0.01", "--set", "runup.record_dt=0.01", "--set",
                 "unbalance[1].m_e=3.5", "--out", str(tmp_path / "r")]) == 0
    captured = capsys.readouterr()
    assert "warning: solver.dt = 0.01 s gives 3.7 steps a revolution of the outer spool at 27 Hz (its highest in the " \
           "run-up), fewer than 20" in captured.err, captured.err
    assert "WARNING: node 18 orbits " in captured.out and "beyond the model's small-displacement range" in captured.out
    assert "WARNING: node 18 orbits " in (tmp_path / "r" / "summary.txt").read_text()
    assert main(["run", *runup, "--out", str(tmp_path / "fine")]) == 0  # the scene's own step: 1852 a revolution
    captured = capsys.readouterr()
    assert "steps a revolution" not in captured.err and "WARNING" not in captured.out
    assert main(["run", "paper-rub", "--set", "solver.dt=0.01", "--set", "solver.duration=2.0", "--set",
                 "solver.record_start=1.0", "--set", "output.plots=[]", "--set", "output.plot_window=[1.0, 1.5]",
                 "--out", str(tmp_path / "steady")]) == 0
    assert "warning: solver.dt = 0.01 s gives 1.11 steps a revolution of the outer spool at 90 Hz, fewer than 20" \
        in capsys.readouterr().err


def test_an_error_raised_from_an_interrupt_is_the_interrupt(monkeypatch, tmp_path, capsys):
    """A signal that comes as a module is imported or a class made is raised again as another error, its cause the
    interrupt (seen at random moments: ``ImportError: initialization failed``, ``RuntimeError: Error calling
    __set_name__``, each an internal error, exit 1, before): every command (here `convert`, through the one wrapper of
    rotorred.cli.main) reports the interrupt itself, and another error stays what it is."""
    import rotorred.cli.convert as convert
    from rotorred.cli import Terminated

    def importing(args):
        try:
            raise Terminated()
        except Terminated as exc:
            raise ImportError("initialization failed") from exc

    monkeypatch.setattr(convert, "run", importing)
    assert main(["convert", "a.toml", str(tmp_path / "b.toml")]) == 143
    err = capsys.readouterr().err
    assert err == "rotorred convert: error: terminated (SIGTERM); the output folder keeps its earlier result\n", err
    monkeypatch.setattr(convert, "run", lambda args: int("x"))
    assert main(["convert", "a.toml", str(tmp_path / "b.toml")]) == 1  # an internal error: no interrupt in its chain
    assert "internal error (ValueError" in capsys.readouterr().err


def test_an_error_after_a_signal_a_library_swallowed_is_the_interrupt(monkeypatch, tmp_path, capsys):
    """A SIGINT as matplotlib draws markers came back from its extension as ``ValueError: Invalid bounding box``, the
    interrupt not in its chain (seen once at a random moment of ``modes``: an internal error with its traceback, exit
    130): an error raised after a signal came is reported as that signal."""
    import os
    import signal
    import time

    import rotorred.cli.convert as convert

    def drawing(args):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)
        except KeyboardInterrupt:
            pass  # swallowed, as an extension does
        raise ValueError("Invalid bounding box")

    monkeypatch.setattr(convert, "run", drawing)
    assert main(["convert", "a.toml", str(tmp_path / "b.toml")]) == 130
    err = capsys.readouterr().err
    assert "internal error" not in err and "interrupted (SIGINT)" in err, err


#: a child that sends itself ``SIG`` as it first imports ``MODULE`` (an import hook), then runs the console script
SELF_SIGNAL = """
import os, signal, sys
MODULE, SIG = sys.argv[1], getattr(signal, sys.argv[2])
class Hook:
    def find_spec(self, name, path=None, target=None):
        if name == MODULE:
            sys.meta_path.remove(self)
            os.kill(os.getpid(), SIG)
        return None
sys.meta_path.insert(0, Hook())
sys.argv = ["rotorred", *sys.argv[3:]]
from rotorred.cli import entry
sys.exit(entry())
"""


@pytest.mark.parametrize("module, sig, command", [
    ("numpy", "SIGINT", ["--version"]),                               # parsing: the parser's imports
    ("rotorred.cli.map", "SIGTERM", ["run", "paper-rub"]),            # a command module, as the parser is built
    ("scipy", "SIGINT", ["campbell", "seed-rig", "--speeds", "0:6000:5"]),  # inside a command (not run, map, continue)
    ("scipy", "SIGTERM", ["campbell", "seed-rig", "--speeds", "0:6000:5"]),
    ("rotorred.model.rotor_file", "SIGTERM", ["convert", "a.toml", "b.toml"]),
])
def test_a_signal_during_the_first_imports_is_one_line_and_its_status(tmp_path, module, sig, command):
    """Issue 41: a signal in the first ~0.6 s of a command, as rotorred's modules were imported and before its handlers
    existed, gave Python's KeyboardInterrupt traceback (exit -2) or a silent death by SIGTERM (exit -15) (on main: the
    first two cases below; SIGINT at the import of numpy as the parser is built: a traceback). The console script
    now sets the handlers first: a signal from then on, at the import of any module, in parsing or inside `campbell`
    or `convert` (commands without work to keep: these cases held on main too), exits 130 or 143 with one line, no
    traceback, nothing written."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", SELF_SIGNAL, module, sig, *command,
                           *(["--out", str(tmp_path / "o")] if command[0] in ("run", "campbell") else [])],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == SIGNALS[sig][0], (done.returncode, done.stderr)
    err = done.stderr.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    assert err.startswith("rotorred") and ("interrupted (SIGINT)" if sig == "SIGINT" else "terminated (SIGTERM)") in err
    assert not (tmp_path / "o").exists() and not (tmp_path / "b.toml").exists()


def test_the_readme_states_the_number_of_fault_kinds():
    """docs/commands.md's sentence on the faults tested, and the README's, give the number of FAULT_KINDS, each named once."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "commands.md").read_text(encoding="utf-8")
    assert len(set(FAULT_KINDS)) == len(FAULT_KINDS)
    assert f"`tests/test_faults.py` tries\n{len(FAULT_KINDS)} kinds of fault" in text
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    assert f"`tests/test_faults.py` tries {len(FAULT_KINDS)} kinds of fault (its `FAULT_KINDS`" in readme
