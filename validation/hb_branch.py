"""The harmonic-balance branch of the rig in docs/analyses.md: paper-rub in the clearance from 45 to 5 um, 100 harmonics of
f_0 = 10 Hz, 2048 AFT samples, each point's stability from the monodromy matrix.

Run::

    python validation/hb_branch.py [--plot PATH]   # about 2 minutes; the same as
    rotorred continue paper-rub --param rub.clearance=45e-6:5e-6 --harmonics 100 --samples 2048 --out branch

Prints the command's summary (points, folds, stability changes and their kinds, times); ``--plot PATH`` copies its
figure (``branch.png``) to PATH (figures are never committed under docs/: the site's are drawn when it is built).
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

from rotorred.cli import main

ARGS = ["continue", "paper-rub", "--param", "rub.clearance=45e-6:5e-6", "--harmonics", "100", "--samples", "2048"]


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", default=None, help="copy the branch's figure to this path")
    figure = parser.parse_args().plot
    with tempfile.TemporaryDirectory() as tmp:
        status = main(ARGS + ["--out", str(Path(tmp) / "branch")])
        if status == 0 and figure:
            shutil.copyfile(Path(tmp) / "branch" / "branch.png", figure)
            print(f"copied the figure to {figure}")
    sys.exit(status)
