"""The free orbit's reach towards a rub plate: the clearance below which the rub can start.

Without contact the settled response is linear; the largest displacement of the rub node along
the plate's normal over one common period of the spools is the clearance at which the free
orbit first touches. A clearance above it cannot be touched from the settled free orbit (a
transient from rest, or a coexisting rub response reached by continuation, still can).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from rotorred.scenes.run import SceneModel, build_model, settled_response
from rotorred.scenes.schema import Scene

__all__ = ["free_reach"]


def free_reach(scene: Scene, model=None) -> float | None:
    """Reach of the settled no-rub orbit towards the first plate at its node (m), None without plates.

    ``max_t n . (x(t), y(t))`` over one common period of the spools (sampled at ``solver.dt``; the
    ratio of the speeds is taken to a denominator of at most 100), from the harmonic (linear
    steady-state) solution, plus gravity's static deflection.

    Parameters
    ----------
    scene : Scene
    model : SceneModel or SystemMatrices or ReducedSystem, optional
        Built for the scene when not given.
    """
    if not scene.plates:
        return None
    if model is None:
        model = build_model(scene)
    m = model.model if isinstance(model, SceneModel) else model
    plate = scene.plates[0]
    rows = m.output_rows([(plate.node, "x"), (plate.node, "y")])
    f = [w / (2 * math.pi) for w in scene.speeds.values() if w > 0]
    ratio = Fraction(max(f) / min(f)).limit_denominator(100)
    period = ratio.denominator / min(f)
    t = np.arange(0.0, period, min(scene.solver.dt, period / 2000))
    return float(np.max(plate.normal @ settled_response(scene, m, rows, t)))
