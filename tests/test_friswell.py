"""Friswell's textbook rotors, written as rotor files with the textbook's data (issue 18, "Published rotors").

Friswell, Penny, Garvey & Lees, *Dynamics of Rotating Machines* (Cambridge University Press, 2010), Examples 5.9.1,
5.9.2, 5.9.5 and 5.9.9, in validation/reference/friswell/ (E, G and rho as the book gives them, the shaft as
stations, disks from their dimensions). The book's printed tables were not available to us; the reference numbers
are those ROSS publishes for these examples with the book's model (six Timoshenko elements with gyroscopic effects):

* 5.9.1: ROSS's documentation of the example, docs/examples/example_05_09_01.rst (ROSS 1.x, 2019), rad/s to three
  decimals, https://github.com/petrobras/ross (the 2019 notebook of "Example 5.9.1 from Friswell");
* 5.9.2, 5.9.5, 5.9.9: ROSS's tests of the examples, ross/tests/test_examples.py (test_example1..., test_example2...,
  two decimals), pinned since its first commit of them (9a01394d, "Implementing some test examples from Frisswell
  textbook").

ROSS 3 inserts its torsional mode (650.41 rad/s) among these; the lateral values here are the 4-DOF model's. Each
value is asserted to half a unit of its last printed digit: the rounding of the reference, nothing more (measured:
every rotorred value rounds to the printed one).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rotorred.linear.campbell import campbell
from rotorred.model.operating import Operating
from rotorred.model.rotor_file import rotor_from_toml

FRISWELL = Path(__file__).resolve().parents[1] / "validation" / "reference" / "friswell"
BEARINGS_5_9_1 = "[[bearing]]\nnode = 0\nk = 1e6\n\n[[bearing]]\nnode = 6\nk = 1e6\n"


def example(name: str, bearings: str | None = None):
    """The rotor file of an example; ``bearings`` replaces Example 5.9.1's two bearings (its variants 5.9.2-5.9.7)."""
    text = (FRISWELL / f"{name}.toml").read_text()
    if bearings is not None:
        assert BEARINGS_5_9_1 in text
        text = text.replace(BEARINGS_5_9_1, bearings)
    return rotor_from_toml(text, source=name)


def whirl(rotor, rpm: float, n: int = 6):
    """The ``n`` lowest whirl frequencies (rad/s) and undamped natural frequencies |lambda| (rad/s) at ``rpm``."""
    result = campbell(rotor, Operating.line([rpm], unit="rpm"), n_modes=n)
    wd = result.frequencies[0]
    return wd, wd / np.sqrt(1.0 - result.damping_ratio[0] ** 2)


def assert_printed(values, printed, decimals):
    """``values`` round to ``printed``: within half a unit of the last printed digit (1e-9 for the binary ties)."""
    half = 0.5 * 10.0 ** -np.asarray(decimals, float) + 1e-9
    assert np.all(np.abs(np.asarray(values) - np.asarray(printed)) <= half), (values, printed)


# Example 5.9.1, isotropic bearings: ROSS docs/examples/example_05_09_01.rst, rad/s
@pytest.mark.parametrize("rpm, printed", [
    (0.0, [86.658, 86.658, 274.313, 274.313, 716.786, 716.786]),
    (4000.0, [85.389, 87.796, 251.785, 294.713, 600.179, 827.075]),
])
def test_example_5_9_1_isotropic_bearings(rpm, printed):
    wd, _ = whirl(example("example_5_9_1"), rpm)
    assert_printed(wd, printed, 3)


# Example 5.9.2, anisotropic bearings k_xx = 1, k_yy = 0.8 MN/m: ROSS tests/test_examples.py, rad/s
@pytest.mark.parametrize("rpm, printed", [
    (0.0, [82.65, 86.66, 254.52, 274.31, 679.49]),
    (4000.0, [82.33, 86.86, 239.64, 287.25, 583.49]),
])
def test_example_5_9_2_anisotropic_bearings(rpm, printed):
    bearings = BEARINGS_5_9_1.replace("k = 1e6", "k_xx = 1e6\nk_yy = 0.8e6")
    wd, _ = whirl(example("example_5_9_1", bearings), rpm, 5)
    assert_printed(wd, printed, 2)


# Example 5.9.5, damped bearings c = 3 kN s/m: ROSS tests/test_examples.py, Hz (natural and damped)
@pytest.mark.parametrize("rpm, natural, damped", [
    (0.0, [13.91, 13.91, 48.18, 48.18, 137.06, 137.06], [13.89, 13.89, 46.54, 46.54, 103.22, 103.22]),
    (4000.0, [13.70, 14.09, 43.61, 52.18, 122.37, 149.81], [13.68, 14.07, 41.98, 50.65, 104.25, 105.66]),
])
def test_example_5_9_5_damped_bearings(rpm, natural, damped):
    bearings = BEARINGS_5_9_1.replace("k = 1e6", "k = 1e6\nc = 3e3")
    wd, wn = whirl(example("example_5_9_1", bearings), rpm)
    order = np.argsort(wn)  # the book lists natural frequencies in their own order
    assert_printed(np.sort(wn) / (2 * np.pi), natural, 2)
    assert_printed(wd[order] / (2 * np.pi), damped, 2)


# Example 5.9.9, overhung rotor on 10 MN/m bearings at 0 and 1.0 m: ROSS tests/test_examples.py, rad/s
@pytest.mark.parametrize("rpm, printed, decimals", [
    (0.0, [90.14, 90.14, 630.73, 630.73, 830.43, 830.43], 2),
    (4000.0, [76.19, 103.91, 565.99, 634.23, 647.75, 1174.2], [2, 2, 2, 2, 2, 1]),
])
def test_example_5_9_9_overhung_rotor(rpm, printed, decimals):
    wd, _ = whirl(example("example_5_9_9"), rpm)
    assert_printed(wd, printed, decimals)
