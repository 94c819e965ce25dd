"""A priori error estimates of a model and a time step: receptance errors over a frequency band.

The response of the outputs to forces at the input DOFs (unbalances, rub contacts) is the
receptance ``H(s) = R (s^2 M + s (C + sum_s Omega_s G_s) + K)^-1 B`` with ``R`` the output rows and
``B = (input rows)^T`` in model coordinates. Two errors are estimated with it, each relative to
the largest receptance of the output over the inputs (a unit force at each) at the spool speeds, where the
response's largest line sits (:func:`receptance_error`):

* **model error**: a reduced model against the full one at ``s = i omega``;
* **time-step error**: the average-acceleration Newmark step (the trapezoidal rule on (q, v)) answers a
  sampled harmonic force ``F e^(i omega t_n)`` in its steady state with exactly ``H(i omega_d)``,
  ``omega_d = (2/dt) tan(omega dt/2)`` (the bilinear map ``(z - 1)/(z + 1) = i tan(omega dt/2)``; docs/model.md
  §9), so its error is ``H(i omega_d) - H(i omega)`` of the stepped model.

The band's grid holds the damped natural frequencies of the full model in the band (where the
receptance peaks) besides a uniform grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from rotorred import checks
from rotorred.linear.modal import eigen
from rotorred.model import sparse
from rotorred.model.assembly import system_of

__all__ = ["ReceptanceError", "band_frequencies", "receptance", "warped", "receptance_error", "N_GRID"]

#: points of the uniform part of the band's grid
N_GRID = 400


@dataclass(frozen=True)
class ReceptanceError:
    """The worst relative receptance error over a band (:func:`receptance_error`).

    Attributes
    ----------
    error : float
        ``max |H - H_ref| / max |H_ref|`` of the worst output (the denominator: that output's largest
        receptance over the band and the inputs).
    frequency_hz : float
        Frequency of the worst error (Hz).
    output, input : (int, str)
        Output and input DOF of the worst error.
    """

    error: float
    frequency_hz: float
    output: tuple
    input: tuple


def band_frequencies(model, speeds: Mapping[str, float], f_max_hz: float, n_grid: int = N_GRID,
                     eigenvalues: np.ndarray | None = None) -> np.ndarray:
    """Angular frequencies (rad/s) of the band 0..``f_max_hz``: a uniform grid, the damped natural frequencies
    of ``model`` at ``speeds`` (rad/s) in the band and the spool speeds, ascending, shape (n,).

    ``eigenvalues``: those of ``model`` at ``speeds`` (:func:`rotorred.linear.modal.eigen`), when already at hand.
    """
    f_max_hz = checks.positive("f_max_hz", f_max_hz, "Hz")
    w_max = 2 * math.pi * f_max_hz
    if eigenvalues is None:  # a large model: its modes below the band's top only (sparse, docs/model.md §24)
        model = system_of(model, "model", sparse_ok=True)
        eigenvalues = eigen(model.M, model.damping(speeds), model.stiffness(speeds), below=w_max).eigenvalues
    natural = eigenvalues.imag[eigenvalues.imag <= w_max]
    spools = [w for w in speeds.values() if 0 < w <= w_max]
    return np.unique(np.concatenate([np.linspace(0.0, w_max, n_grid), natural, spools]))


def warped(omega: np.ndarray, dt: float | None) -> np.ndarray:
    """``(2/dt) tan(omega dt/2)``, the frequency at which the average-acceleration step responds to a sampled
    force of frequency ``omega`` (rad/s); ``omega`` itself for ``dt`` None (the continuous model)."""
    omega = np.asarray(omega, dtype=float)
    if dt is None:
        return omega
    if np.any(omega * dt >= math.pi):
        checks.fail("dt", dt, f"must resolve the band: omega dt < pi up to {omega.max() / (2 * math.pi):.4g} Hz", "s")
    return 2.0 / dt * np.tan(omega * dt / 2.0)


def receptance(model, speeds: Mapping[str, float], omega: np.ndarray, outputs: Sequence, inputs: Sequence,
               dt: float | None = None) -> np.ndarray:
    """Receptance of ``outputs`` to unit forces at ``inputs`` (m/N), shape (len(omega), n_out, n_in).

    Parameters
    ----------
    model : SystemMatrices or ReducedSystem
    speeds : dict
        Spool speeds (rad/s).
    omega : ndarray, shape (n,)
        Angular frequencies (rad/s).
    outputs, inputs : sequence of (int, str)
        Physical DOFs (node, direction).
    dt : float, optional
        Time step of the average-acceleration Newmark step: its steady-state receptance (:func:`warped`).
    """
    model = system_of(model, "model", sparse_ok=True)  # a large full model: one sparse LU a frequency
    R = model.output_rows(list(outputs))
    B = model.output_rows(list(inputs)).T
    s = 1j * warped(omega, dt)
    D, K = model.damping(speeds), model.stiffness(speeds)
    if sparse.is_sparse(model.M):
        return np.array([R @ sparse.solve(sk * sk * model.M + sk * D + K, B.astype(complex)) for sk in s])
    A = s[:, None, None] ** 2 * model.M + s[:, None, None] * D + K
    return R @ np.linalg.solve(A, np.broadcast_to(B, (len(s),) + B.shape))


def receptance_error(H: np.ndarray, H_ref: np.ndarray, omega: np.ndarray, outputs: Sequence,
                     inputs: Sequence, at: Sequence[float] | None = None) -> ReceptanceError:
    """The worst relative error of receptances ``H`` against ``H_ref`` (both from :func:`receptance` on ``omega``).

    Each output's error is relative to its largest reference receptance over the inputs and the band, or,
    with ``at`` (rad/s, frequencies of ``omega``), over the inputs at those frequencies: at the spool speeds,
    where the response's largest line (the unbalances') sits. An input that barely moves an output then does
    not count as a large relative error, and an error off the running speeds counts against the response's
    own size, not against a resonance peak the response never reaches.
    """
    rows = slice(None) if at is None else np.searchsorted(omega, np.asarray(at, dtype=float))
    scale = np.abs(H_ref[rows]).max(axis=(0, 2))
    scale = np.where(scale > 0, scale, 1.0)
    rel = np.abs(H - H_ref) / scale[None, :, None]
    k, o, i = np.unravel_index(int(np.argmax(rel)), rel.shape)
    return ReceptanceError(float(rel[k, o, i]), float(omega[k] / (2 * math.pi)), tuple(outputs[o]),
                           tuple(inputs[i]))
