"""What a command says: --version, -q and -v, stage lines before the work, help wrapped with examples that parse.

The progress itself (stage lines, tqdm bars) is rotorred.progress; the command line's levels and streams are
rotorred.cli.feedback.
"""

from __future__ import annotations

import importlib.metadata
import re
import shlex
import subprocess
import sys

import pytest

from rotorred.cli import EXAMPLES, build_parser, main

SHORT = ["--set", "solver.duration=0.3", "--set", "solver.record_start=0.1", "--set", "output.plot_window=[0.1, 0.2]",
         "--set", "output.plots=[]", "--set", "output.formats=[\"npz\"]", "--no-normal"]


def test_version_is_the_installed_distributions():
    """``rotorred --version`` prints the version pip installed (read from the distribution's metadata, a second
    path to the one number in rotorred/_version.py)."""
    out = subprocess.run([sys.executable, "-c", "import sys; from rotorred.cli import main; sys.exit(main())",
                          "--version"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == f"rotorred {importlib.metadata.version('rotorred')}"


def test_quiet_prints_nothing_but_errors(tmp_path, capsys):
    assert main(["run", "paper-rub", "--out", str(tmp_path / "q"), "-q", *SHORT]) == 0
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == ""
    assert (tmp_path / "q" / "result.npz").exists() and (tmp_path / "q" / "summary.txt").exists()
    assert main(["run", "paper-rub", "--out", str(tmp_path / "bad"), "-q", "--set", "rub.clearance=-1e-6"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.startswith("rotorred run: error: ")
    assert "rub[0].clearance" in captured.err


def test_run_says_what_it_does_in_order_and_verbose_adds_timings(tmp_path, capsys):
    """Stage lines on stderr, the first once the input is checked and before anything is computed; the report on
    stdout; -v adds the seconds since the start and the debug lines (the model, the kernel's cache)."""
    assert main(["run", "paper-rub", "--out", str(tmp_path / "o"), *SHORT]) == 0
    captured = capsys.readouterr()
    stages = captured.err.splitlines()
    expected = ["running paper-rub into", "building the model of paper-rub", "stepping paper-rub: newmark, 15000 steps",
                "analysing paper-rub", "writing the figures, data and summary"]
    found = [next(i for i, line in enumerate(stages) if line.startswith(f"rotorred run: {e}")) for e in expected]
    assert found == sorted(found) and found[0] == 0, stages
    assert "Peak amplitudes" in captured.out and "rotorred run:" not in captured.out
    assert main(["run", "paper-rub", "--out", str(tmp_path / "v"), "-v", *SHORT]) == 0
    verbose = capsys.readouterr().err.splitlines()
    timed = [line for line in verbose if re.match(r"rotorred run \[\s*\d+\.\d\d s\]: ", line)]
    assert len(timed) == len(verbose) > len(stages) and any("Craig-Bampton model" in line for line in verbose)


def _run_in_new_process(out) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", "import sys; from rotorred.cli import main; sys.exit(main())", "run",
                           "paper-rub", "--out", str(out), *SHORT], capture_output=True, text=True, timeout=600)


def test_the_summary_says_compiled_only_when_the_kernel_was_compiled(tmp_path):
    """The first of two new processes may compile the kernel (a cold cache), and then says so in its stage line and
    its summary alike; the second loads it from the cache and says neither (it said "compiled in 1.1 s" when a load
    took over 1 s)."""
    first, second = _run_in_new_process(tmp_path / "a"), _run_in_new_process(tmp_path / "b")
    assert first.returncode == 0 and second.returncode == 0, (first.stderr, second.stderr)
    said = "compiling the step kernel" in first.stderr
    assert ("step kernel compiled" in (tmp_path / "a" / "summary.txt").read_text()) == said
    assert "compiling the step kernel" not in second.stderr and "step kernel compiled" not in second.stdout
    assert "step kernel compiled" not in (tmp_path / "b" / "summary.txt").read_text()


@pytest.mark.parametrize("command", sorted(EXAMPLES))
def test_help_is_wrapped_and_its_examples_parse(command, monkeypatch, capsys):
    """``--help`` at 70 columns: no line of the description, options or exit statuses longer (examples are shown
    as written); every example parses, and the scene keys it names exist in its scene."""
    from rotorred.scenes.schema import load_scene, parse_setting

    monkeypatch.setenv("COLUMNS", "70")
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = capsys.readouterr().out
    assert "examples:" in text and "exit status:" in text
    long = [line for line in text.splitlines() if len(line) > 70 and not line.lstrip().startswith("rotorred ")]
    assert not long, long
    parser = build_parser()
    for example in EXAMPLES[command]:
        argv = shlex.split(example.split("#")[0])[1:]
        args = parser.parse_args(argv)
        scene = getattr(args, "scene", None)
        if scene is None or scene.endswith(".toml"):
            continue
        options = (getattr(args, "set", None) or []) + (getattr(args, "vary", None) or [])
        if getattr(args, "param", None):
            options.append(args.param.replace(":", ",", 1))
        for option in options:
            key, values = parse_setting(option.split(":")[0] if ":" in option else option)
            load_scene(scene, {key: values[0]})  # an unknown key or a bad value raises
