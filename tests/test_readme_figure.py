"""The README itself: at most 12 000 characters, its links resolve, and its one figure is what the command it names
draws (issue 36). Fast: one Campbell diagram, a few seconds."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
#: the README's size limit, in characters (issue 36)
MAX_CHARS = 12_000


def test_readme_is_short():
    text = README.read_text(encoding="utf-8")
    assert len(text) <= MAX_CHARS, len(text)


def test_readme_links_resolve():
    text = README.read_text(encoding="utf-8")
    targets = re.findall(r"\]\(([^)\s]+)\)", text)
    assert len(targets) >= 10
    for target in targets:
        if target.startswith(("http://", "https://")):
            continue
        assert (ROOT / target.split("#")[0]).exists(), target


def test_readme_figure_is_the_commands_figure(tmp_path):
    """The figure is `campbell.png` as the command the README names writes it: mean pixel difference below 0.005
    (measured: 0, the same bytes, on the machine that wrote it; the sweep to 11 000 rpm instead of 12 000 differs by
    0.025, so a new style, another sweep or another rotor fails here)."""
    from matplotlib.image import imread

    from rotorred.cli import main

    text = README.read_text(encoding="utf-8")
    image = re.search(r"!\[[^]]*\]\(([^)]+\.png)\)", text, re.S).group(1)
    command = re.search(r"`(rotorred campbell [^`]*)` writes it", text).group(1)
    args = shlex.split(command)[1:]
    assert args[-2:] == ["--out", "campbell"]
    assert main([*args[:-1], str(tmp_path / "campbell"), "-q"]) == 0
    drawn = imread(tmp_path / "campbell" / "campbell.png")
    kept = imread(ROOT / image)
    assert kept.shape == drawn.shape, (kept.shape, drawn.shape)
    difference = float(np.abs(kept - drawn).mean())
    assert difference < 0.005, (f"{image} is no longer what `{command}` draws (mean pixel difference "
                               f"{difference:.3f}): run the command and copy its campbell.png there")
