"""The settled linear state of a scene: the unbalances' steady state and gravity's static deflection, the start of
its transients and harmonic balances (``solver.start = "settled"``) and a linear scene's settled response.

Apart from :mod:`rotorred.scenes.run` so that the solvers a run calls (:mod:`rotorred.scenes.quasi_periodic`) start
from it without importing the run.
"""

from __future__ import annotations

import numpy as np

from rotorred.linear.harmonic import SteadyState, steady_state
from rotorred.model.loads import gravity_force
from rotorred.scenes.schema import Scene

__all__ = ["scene_steady_state", "settled_state", "settled_response"]


def scene_steady_state(scene: Scene, model) -> SteadyState | None:
    """Linear steady state of the scene's unbalances, per spool (None without unbalances)."""
    if not scene.unbalances:
        return None
    return steady_state(model, scene.operating, scene.unbalances)


def _static_deflection(scene: Scene, model) -> np.ndarray | None:
    """Gravity's static deflection in model coordinates (None without gravity)."""
    if not scene.solver.gravity:
        return None
    return np.linalg.solve(model.stiffness(scene.speeds), gravity_force(model, scene.solver.gravity))


def settled_state(scene: Scene, model) -> tuple[np.ndarray, np.ndarray]:
    """Linear steady state at t = 0: (q0, v0) in model coordinates.

    Sum of the per-spool unbalance phasors (``K - Omega^2 M + i Omega (C + sum Omega_s G_s)``
    solved per spool) and gravity's static deflection.
    """
    q0 = np.zeros(model.M.shape[0])
    v0 = np.zeros_like(q0)
    steady = scene_steady_state(scene, model)
    if steady is not None:
        q0 += steady.displacement(0.0)
        v0 += steady.velocity(0.0)
    static = _static_deflection(scene, model)
    if static is not None:
        q0 += static
    return q0, v0


def settled_response(scene: Scene, model, rows: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Settled linear response ``rows @ q(t)`` (unbalances and gravity), shape (len(rows), len(t)).

    Parameters
    ----------
    rows : ndarray, shape (k, n)
        Output rows in model coordinates (``model.output_rows(...)``).
    t : ndarray, shape (m,)
        Times (s).
    """
    y = np.zeros((rows.shape[0], len(t)))
    steady = scene_steady_state(scene, model)
    for s, P in (steady.phasors.items() if steady is not None else ()):
        y += np.real((rows @ P)[:, None] * np.exp(1j * steady.speeds[s] * t)[None, :])
    static = _static_deflection(scene, model)
    if static is not None:
        y += (rows @ static)[:, None]
    return y
