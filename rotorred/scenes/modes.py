"""The fewest Craig–Bampton modes for a scene's outputs and forces (docs/model.md §9).

A scene's response is forced at the unbalance and rub nodes and read at its recorded DOFs, so a
reduced model is as good as its receptance from those inputs to those outputs
(:mod:`rotorred.linear.accuracy`). With a rub plate the contact force has every frequency and the
receptance is compared over the band (``output.f_max_hz``, else :data:`BAND_FACTOR` x f_H); without one
the unbalances force only the spool speeds, and it is compared there. Modes are added from the number
of fixed-interface modes in that range until the error is at most the target. An unbalance node
inside the reduced model is also tried as a boundary node (the attachment of its force: its four DOFs
kept physical), and the smaller model wins; when no reduced model is smaller than the full one, the
full one is used.

This is the automatic mode count of a scene (``solver.modes = "auto"``, target :data:`AUTO_TARGET`) and
the model part of ``solver.tolerance`` (:mod:`rotorred.scenes.tolerance`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotorred.linear.accuracy import ReceptanceError, band_frequencies, receptance, receptance_error
from rotorred.linear.reduction import ModeLadder, default_boundary_nodes

__all__ = ["ModeChoice", "choose_modes", "band_hz", "input_dofs", "running", "model_frequencies", "AUTO_TARGET",
           "BAND_FACTOR"]

#: receptance error target of ``solver.modes = "auto"`` (the model's share, 1/4, of a 1 % tolerance)
AUTO_TARGET = 2.5e-3
#: the band's top without ``output.f_max_hz``: this many times the higher spool frequency (paper-rub's lines above
#: 0.5 % of the largest reach 6.8 f_H)
BAND_FACTOR = 8.0


@dataclass(frozen=True)
class ModeChoice:
    """The model :func:`choose_modes` chose.

    Attributes
    ----------
    model : ReducedSystem or SystemMatrices
        The reduced model, or the full one when no reduced model is smaller.
    extra_nodes : tuple of int
        Unbalance nodes made boundary nodes (attachment), beyond the scene's.
    error : ReceptanceError or None
        The reduced model's receptance error (None for the full model).
    target : float
    band_hz : float
        Top of the range compared (Hz): the band with a plate, the fastest spool without.
    """

    model: object
    extra_nodes: tuple
    error: ReceptanceError | None
    target: float
    band_hz: float

    @property
    def full(self) -> bool:
        return self.error is None

    def describe(self) -> str:
        """One line: the count, the error and where it is worst."""
        if self.full:
            return f"the full model: no reduced model smaller than it meets {self.target:.3g}"
        e = self.error
        text = (f"{self.model.n_modes} fixed-interface modes chosen automatically: receptance error {e.error:.2g} "
                f"(target {self.target:.3g}) over 0-{self.band_hz:.4g} Hz, worst at {e.output} from a force at "
                f"{e.input}, {e.frequency_hz:.4g} Hz")
        if self.extra_nodes:
            text += f"; unbalance node(s) {list(self.extra_nodes)} kept physical"
        return text


def band_hz(scene) -> float:
    """Top of the scene's frequency band (Hz): ``output.f_max_hz`` (at least the fastest spool, whose line every
    response has), else BAND_FACTOR x the fastest spool."""
    fastest = max(running(scene)) / (2 * math.pi)
    return max(scene.output.f_max_hz, fastest) if scene.output.f_max_hz else BAND_FACTOR * fastest


def running(scene) -> list[float]:
    """The spool speeds (rad/s) > 0."""
    return [w for w in scene.speeds.values() if w > 0]


def input_dofs(scene) -> list[tuple[int, str]]:
    """The DOFs forces act on: x and y of every unbalance and rub node."""
    nodes = sorted({u.node for u in scene.unbalances} | {p.node for p in scene.plates})
    return [(n, d) for n in nodes for d in ("x", "y")]


def model_frequencies(scene, system, band: np.ndarray | None = None) -> np.ndarray:
    """Frequencies (rad/s) a model is compared at: the band with a plate (``band`` when already computed by
    :func:`rotorred.linear.accuracy.band_frequencies`), the spool speeds without."""
    if scene.plates:
        return band if band is not None else band_frequencies(system, scene.speeds, band_hz(scene))
    return np.array(sorted(running(scene)))


def choose_modes(scene, system, target: float, band: np.ndarray | None = None) -> ModeChoice:
    """The smallest model of ``scene`` (module docstring) whose receptance error is at most ``target``.

    Parameters
    ----------
    scene : Scene
    system : SystemMatrices
        The scene's full model (``assemble(scene.rotor)``).
    target : float
        Relative receptance error (:func:`rotorred.linear.accuracy.receptance_error` at the spool speeds).
    band : ndarray, optional
        The band's frequencies (rad/s, :func:`rotorred.linear.accuracy.band_frequencies` of ``system``), when
        already at hand.
    """
    omega = model_frequencies(scene, system, band)
    inputs = input_dofs(scene)
    H_full = receptance(system, scene.speeds, omega, scene.output.dofs, inputs)
    options = [_fewest_modes(scene, system, omega, inputs, H_full, target, extra) for extra in _extra_options(scene)]
    options = [o for o in options if o is not None and o[0].n_dof < system.dofs.n_dof]
    top = float(omega[-1] / (2 * math.pi))
    if not options:
        return ModeChoice(system, (), None, target, top)
    model, err, extra = min(options, key=lambda o: o[0].n_dof)
    return ModeChoice(model, extra, err, target, top)


def _extra_options(scene) -> list[tuple[int, ...]]:
    """Extra boundary nodes to try: none, and the unbalance nodes that would be interior."""
    boundary = set(default_boundary_nodes(scene.rotor, tuple(scene.solver.boundary_nodes) +
                                          tuple(p.node for p in scene.plates)))
    forced = tuple(sorted({u.node for u in scene.unbalances} - boundary))
    return [()] + ([forced] if forced else [])


def _fewest_modes(scene, system, omega, inputs, H_full, target, extra):
    """(model, ReceptanceError, extra) of the fewest modes meeting ``target`` with ``extra`` boundary nodes, or
    None when every mode is needed."""
    nodes = tuple(sorted(set(scene.solver.boundary_nodes) | {p.node for p in scene.plates} | set(extra)))
    ladder = ModeLadder(system, default_boundary_nodes(scene.rotor, nodes))
    needed = int(np.count_nonzero(ladder.frequencies <= omega[-1]))  # every interior mode of the range
    for n in range(needed, ladder.n_interior + 1):
        model = ladder.model(n)
        err = receptance_error(receptance(model, scene.speeds, omega, scene.output.dofs, inputs), H_full, omega,
                               scene.output.dofs, inputs, at=running(scene))
        if err.error <= target:
            return model, err, extra
    return None
