"""The README's harmonic-balance branch of the rig: paper-rub in the clearance from 45 to 5 um, 100 harmonics of
f_0 = 10 Hz, 2048 AFT samples, each point's stability from the monodromy matrix.

Run::

    python validation/hb_branch.py           # about 2 minutes; the same as
    rotorred continue paper-rub --param rub.clearance=45e-6:5e-6 --harmonics 100 --samples 2048 --out branch

Prints the command's summary (points, folds, stability changes and their kinds, times) and copies its figure to
docs/images/branch_clearance.png.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from rotorred.cli import main

ARGS = ["continue", "paper-rub", "--param", "rub.clearance=45e-6:5e-6", "--harmonics", "100", "--samples", "2048"]
FIGURE = Path(__file__).resolve().parents[1] / "docs" / "images" / "branch_clearance.png"


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        status = main(ARGS + ["--out", str(Path(tmp) / "branch")])
        if status == 0:
            shutil.copyfile(Path(tmp) / "branch" / "branch.png", FIGURE)
            print(f"copied the figure to {FIGURE}")
    sys.exit(status)
