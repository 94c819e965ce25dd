"""The options of a transient (:func:`rotorred.transient.newmark.simulate`): small frozen types, checked when built.

- :class:`Loads`: the unbalances and gravity.
- :class:`Scheme`: the time integration (Newmark-β or HHT-α, and the form of the constant-speed step).
- :class:`Recording`: what is recorded, from when, how often.
- :class:`StepControl`: the contact Newton iteration, step halving, divergence limit and progress.
- :class:`Initial`: a start from a given displacement and velocity (another run's ``final`` state, a
  :class:`~rotorred.transient.results.FinalState`, is the other kind of start).

Each type checks its fields when it is built and names a bad one by the parameter of ``simulate`` it is
given as: ``Recording(decimate=0)`` raises ``recording.decimate = 0: must be an integer >= 1``. What needs
the model or the run (an output's node, a record start after ``t_end``, the length of ``q0``) is checked
by ``simulate`` before any computation, under the same names. SI units throughout.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from rotorred import checks
from rotorred.model.dofs import checked_dof
from rotorred.model.loads import Unbalance

#: the time-integration methods of :class:`Scheme`
METHODS = ("newmark", "hht")

#: the constant-speed step's forms: "auto" (the eigenbasis where it applies, else dense), "eigen", "dense"
STEPS = ("auto", "eigen", "dense")


@contextmanager
def within(prefix: str):
    """Re-raise an :class:`~rotorred.checks.InputError` of the block with its field under ``prefix``."""
    try:
        yield
    except checks.InputError as exc:
        raise exc.within(prefix) from None


def _instances(field: str, items, cls) -> tuple:
    """``items`` (a list or tuple) as a tuple, each a ``cls``."""
    def one(name, item):
        if not isinstance(item, cls):
            checks.fail(name, item, f"must be {'an' if cls.__name__[0] in 'AEIOU' else 'a'} {cls.__name__}")
        return item
    return checks.sequence(field, items, one)


@dataclass(frozen=True)
class Loads:
    """The external loads of a transient: unbalances and gravity.

    Parameters
    ----------
    unbalances : sequence of Unbalance
        Each rotates at the speed of its node's spool, with its phase (:class:`rotorred.model.loads.Unbalance`).
    gravity : float, optional
        Gravity acceleration along -y (m/s^2), e.g. 9.81; None (default) or 0: no gravity.
    """

    unbalances: Sequence[Unbalance] = ()
    gravity: float | None = None

    def __post_init__(self):
        with within("loads"):
            object.__setattr__(self, "unbalances", _instances("unbalances", self.unbalances, Unbalance))
            if self.gravity is not None:
                object.__setattr__(self, "gravity", checks.number("gravity", self.gravity, "m/s^2"))


@dataclass(frozen=True)
class Scheme:
    """The time-integration scheme.

    Parameters
    ----------
    method : {"newmark", "hht"}
        ``"newmark"``: the Newmark-β family, average acceleration by default (unconditionally stable, no
        numerical damping, second order). ``"hht"``: Hilber–Hughes–Taylor α, second order, damping the
        highest modes.
    gamma, beta : float, optional
        Newmark parameters (-), gamma >= 1/2, beta > 0; default 1/2, 1/4. With ``"hht"`` they follow from
        alpha, ``gamma = 1/2 - alpha``, ``beta = (1 - alpha)^2 / 4``, and may be given only with those values.
    alpha : float, optional
        HHT-α parameter (-), -1/3 <= alpha <= 0, default -0.05, with ``"hht"``; 0 (or None) with ``"newmark"``.
    step : {"auto", "eigen", "dense"}
        The constant-speed step: ``"eigen"`` steps the linear part in the eigenbasis of the average-acceleration
        amplification matrix, O(n) per step (:mod:`rotorred.transient.eigen_kernel`), the same recurrence as
        ``"dense"`` (O(n^2)) to rounding; ``"auto"`` (default) takes it wherever it applies and pays, and
        the dense step elsewhere. ``TransientResult.step_form`` says which ran and why.

    Built, the three parameters hold their values: ``Scheme().gamma == 0.5``.
    """

    method: str = "newmark"
    gamma: float | None = None
    beta: float | None = None
    alpha: float | None = None
    step: str = "auto"

    def __post_init__(self):
        with within("scheme"):
            gamma, beta, alpha = _coefficients(checks.choice("method", self.method, METHODS), self.gamma,
                                               self.beta, self.alpha)
            object.__setattr__(self, "step", checks.choice("step", self.step, STEPS))
        for name, value in (("gamma", gamma), ("beta", beta), ("alpha", alpha)):
            object.__setattr__(self, name, value)

    @property
    def average_acceleration(self) -> bool:
        """Whether this is Newmark's average acceleration (gamma = 1/2, beta = 1/4)."""
        return self.method == "newmark" and self.gamma == 0.5 and self.beta == 0.25


def _coefficients(method: str, gamma, beta, alpha) -> tuple[float, float, float]:
    """(gamma, beta, alpha) of Newmark (gamma >= 1/2, beta > 0; default average acceleration) or of HHT-α
    (-1/3 <= alpha <= 0, gamma and beta following from it)."""
    if method == "newmark":
        if alpha is not None and alpha != 0.0:
            checks.fail("alpha", alpha, "must not be given with method = 'newmark' (it applies to 'hht' only)")
        return (checks.number("gamma", 0.5 if gamma is None else gamma, ge=0.5),
                checks.positive("beta", 0.25 if beta is None else beta), 0.0)
    alpha = checks.number("alpha", -0.05 if alpha is None else alpha, ge=-1.0 / 3.0, le=0.0)
    implied = {"gamma": 0.5 - alpha, "beta": 0.25 * (1.0 - alpha) ** 2}
    for name, value in (("gamma", gamma), ("beta", beta)):
        if value is not None and value != implied[name]:
            checks.fail(name, value, "must not be given with method = 'hht' (it follows from alpha: "
                        f"{implied[name]:g})")
    return implied["gamma"], implied["beta"], alpha


@dataclass(frozen=True)
class Recording:
    """What a transient records, from when and how often.

    Parameters
    ----------
    outputs : sequence of (int, str)
        (node, direction) pairs (or ``"NODE:DIRECTION"`` texts) to record, direction one of ``x, y, theta_x,
        theta_y`` (m or rad); the nodes are checked against the model by ``simulate``.
    start : float
        Record from this time on (s), 0 <= start <= t_end.
    decimate : int
        Record every ``decimate``-th step, >= 1.
    states : bool
        Also record the whole state (q, v) in model coordinates (``TransientResult.states``), e.g. for
        :func:`rotorred.transient.energy.energy_balance`.
    """

    outputs: Sequence[tuple[int, str]] = ()
    start: float = 0.0
    decimate: int = 1
    states: bool = False

    def __post_init__(self):
        with within("recording"):
            object.__setattr__(self, "outputs", checks.sequence("outputs", self.outputs, checked_dof))
            object.__setattr__(self, "start", checks.non_negative("start", self.start, "s"))
            object.__setattr__(self, "decimate", checks.integer("decimate", self.decimate, ge=1))
            object.__setattr__(self, "states", checks.boolean("states", self.states))


@dataclass(frozen=True)
class StepControl:
    """How each step is solved and the run watched.

    Parameters
    ----------
    newton_tol : float
        Relative step tolerance of the contact Newton iteration (-), > 0.
    max_newton : int
        Newton iterations per solve before the step is halved, >= 1.
    max_halvings : int
        How many times a failing step may be halved, >= 0; a step that fails at the last is a divergence
        (:class:`~rotorred.transient.results.SimulationDiverged`).
    displacement_limit : float
        A contact-node displacement beyond this (m) is reported as divergence, > 0.
    chunk_steps : int, optional
        Steps per compiled call (the progress bar's granularity), >= 1; default max(2000, min(steps, 100 000)).
    progress : bool, optional
        Progress bar on stderr; None (default): shown on a terminal once a run has taken 1 s.
    """

    newton_tol: float = 1e-10
    max_newton: int = 50
    max_halvings: int = 4
    displacement_limit: float = 1.0
    chunk_steps: int | None = None
    progress: bool | None = None

    def __post_init__(self):
        with within("control"):
            object.__setattr__(self, "newton_tol", checks.positive("newton_tol", self.newton_tol))
            object.__setattr__(self, "max_newton", checks.integer("max_newton", self.max_newton, ge=1))
            object.__setattr__(self, "max_halvings", checks.integer("max_halvings", self.max_halvings, ge=0))
            object.__setattr__(self, "displacement_limit",
                               checks.positive("displacement_limit", self.displacement_limit, "m"))
            if self.chunk_steps is not None:
                object.__setattr__(self, "chunk_steps", checks.integer("chunk_steps", self.chunk_steps, ge=1))
            if self.progress is not None:
                object.__setattr__(self, "progress", checks.boolean("progress", self.progress))


@dataclass(frozen=True, eq=False)
class Initial:
    """A start from a given displacement and velocity, the plates at rest.

    Parameters
    ----------
    q0, v0 : array_like, shape (n,), optional
        Initial displacement (m, rad) and velocity (m/s, rad/s) in model coordinates (a reduced model's
        own coordinates); default 0. Their length is checked against the model by ``simulate``.

    The acceleration at t = 0 follows from the equation of motion; a plate already pressed at t = 0
    starts slipping with the law's force.
    """

    q0: np.ndarray | None = None
    v0: np.ndarray | None = None

    def __post_init__(self):
        with within("start"):
            for name in ("q0", "v0"):
                value = getattr(self, name)
                if value is not None:
                    vec = np.array(checks.array(name, value))  # a copy: the caller's array stays writable
                    if vec.ndim != 1:
                        checks.fail(name, value, "must be a 1-D array (one value per model coordinate)")
                    vec.setflags(write=False)
                    object.__setattr__(self, name, vec)


__all__ = ["Loads", "Scheme", "Recording", "StepControl", "Initial", "METHODS", "STEPS"]
