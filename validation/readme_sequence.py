"""The README's two commands as a new user runs them: one after the other, in one shell, on this checkout.

The steps, each printed with its exit status and wall time:

1. the README's first command as written (make a venv, ``pip install .``, ``rotorred run --out out``);
2. the README's test command as written (``pip install -e ".[test]"``, ``python -m pytest -q``);
3. ``rotorred run --out o2`` (the editable install, after the first install's run);
4. ``pip install .`` again, then ``rotorred run --out o3``.

With ``--reverse``: the test command first, then the first command, then ``rotorred run --out o2``.

The commands are read from the README's "Two commands" section (its two ``bash`` blocks), not copied here, so
this checks what a user reads. Every step runs even if an earlier one failed; the exit status is that of the first
failed step (0 if all passed). ``.ci/run`` runs this script on its clean checkout.

Run it from a clean checkout (it creates ``.venv``, ``out``, ``o2`` and ``o3`` there)::

    python3 validation/readme_sequence.py
"""

from __future__ import annotations

import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: marks a step's start (``MARK k``) and end (``MARK k status``) in the shell's output; the steps are timed here
MARK = "@@rotorred-step"


def readme_commands(readme: Path = ROOT / "README.md") -> list[str]:
    """The shell lines of the README's "Two commands" section: one string a fenced ``bash`` block."""
    text = readme.read_text(encoding="utf-8")
    section = text.split("## Two commands", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```bash\n(.*?)```", section, flags=re.S)
    if len(blocks) != 2:
        raise SystemExit(f"README.md: the 'Two commands' section has {len(blocks)} bash blocks, expected 2")
    return ["\n".join(line for line in b.splitlines() if line.strip() and not line.lstrip().startswith("#"))
            for b in blocks]


def steps(reverse: bool = False) -> list[tuple[str, str]]:
    """(name, shell text) of each step, in order (``reverse``: the test command first)."""
    first, tests = readme_commands()
    if reverse:
        return [("README's test command", tests), ("README's first command", first),
                ("rotorred run --out o2", "rotorred run --out o2")]
    return [("README's first command", first), ("README's test command", tests),
            ("rotorred run --out o2", "rotorred run --out o2"),
            ("pip install . again, then rotorred run --out o3", "pip install . && rotorred run --out o3")]


def script(named_steps: list[tuple[str, str]]) -> str:
    """One bash script running every step in the same shell (a ``{ ...; }`` group, not a subshell, so that the
    venv's ``activate`` carries over), printing :data:`MARK` lines at each step's start and end (with its status)."""
    lines = ["cd " + _quote(str(ROOT))]
    for k, (name, text) in enumerate(named_steps, 1):
        lines += [f"echo {_quote(f'=== step {k}: {name}')}", f"echo {MARK} {k}", "{", text, "}",
                  f'echo "{MARK} {k} $?"']
    return "\n".join(lines) + "\n"


def _quote(text: str) -> str:
    return "'" + text.replace("'", "'\\''") + "'"


def main() -> int:
    named = steps(reverse="--reverse" in sys.argv[1:])
    proc = subprocess.Popen(["bash", "-c", script(named)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            bufsize=1)
    results, started = {}, {}
    for line in proc.stdout:
        if line.startswith(MARK):
            _, k, *rc = line.split()
            if not rc:
                started[int(k)] = time.perf_counter()
                continue
            results[int(k)] = (int(rc[0]), time.perf_counter() - started[int(k)])
            print(f"=== step {k}: exit {rc[0]} ({results[int(k)][1]:.1f} s)", flush=True)
        else:
            print(line, end="", flush=True)
    proc.wait()
    print("\nThe README's commands in sequence, one shell:")
    status = 0
    for k, (name, _) in enumerate(named, 1):
        rc, seconds = results.get(k, (None, float("nan")))
        print(f"  step {k}: {name}: " + ("did not run" if rc is None else f"exit {rc}, {seconds:.1f} s"))
        if status == 0 and rc != 0:
            status = rc if isinstance(rc, int) and rc > 0 else 1
    return status


if __name__ == "__main__":
    sys.exit(main())
