"""The two reference problems of harmonic balance (pyHarm's published cases), with closed forms.

* :func:`duffing`: ``x'' + C x' + x + K3 x^3 = F cos(omega t)``; single-term closed form
  ``((1 - w^2 + 3/4 K3 A^2)^2 + (C w)^2) A^2 = F^2``.
* :func:`jeffcott`: a Jeffcott rotor (m = k = 1, c = C) with unbalance E_UNB (force E_UNB omega^2 rotating) in a
  circular clearance GAP with contact stiffness K_C, no friction; full annular rub
  ``((k - m w^2) r + K_C (r - GAP))^2 + (C w r)^2 = (E_UNB w^2)^2``.

Used by tests/test_nonlinear_hb.py and validation/bench_hb.py.
"""

from __future__ import annotations

import numpy as np

from rotorred.nonlinear.forces import CircularClearance, CubicSpring
from rotorred.nonlinear.fourier import Harmonics
from rotorred.nonlinear.hb import PeriodicProblem

__all__ = ["C", "K3", "F", "E_UNB", "GAP", "K_C", "duffing", "jeffcott"]

C, K3, F = 0.02, 0.1, 0.1  # damping, the Duffing oscillator's cubic stiffness and forcing
E_UNB, GAP, K_C = 0.05, 1.0, 100.0  # the Jeffcott rotor's unbalance, clearance, contact stiffness


def duffing(H: int, N: int = 128) -> PeriodicProblem:
    """The Duffing oscillator with ``H`` harmonics and ``N`` AFT samples."""
    h = Harmonics(H, N)

    def forcing(omega):
        f = np.zeros(h.size)
        f[1] = F
        return f, np.zeros(h.size)
    return PeriodicProblem(np.eye(1), C * np.eye(1), np.eye(1), h, forcing, (CubicSpring(0, K3),))


def jeffcott(H: int, N: int) -> PeriodicProblem:
    """The Jeffcott rotor in its clearance with ``H`` harmonics and ``N`` AFT samples (DOFs x, y)."""
    h = Harmonics(H, N)

    def forcing(omega):  # E_UNB omega^2 (cos, sin): the a_1 of x and the b_1 of y
        f, df = np.zeros(2 * h.size), np.zeros(2 * h.size)
        f[2], f[5] = E_UNB * omega**2, E_UNB * omega**2
        df[2], df[5] = 2 * E_UNB * omega, 2 * E_UNB * omega
        return f, df
    return PeriodicProblem(np.eye(2), C * np.eye(2), np.eye(2), h, forcing, (CircularClearance((0, 1), GAP, K_C),))
