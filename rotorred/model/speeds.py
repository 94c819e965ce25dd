"""Spool speeds that vary in time: run-ups, coast-downs and tables of measured speeds.

A :class:`SpeedProfile` gives each spool's speed ``Omega_s(t)`` as a piecewise-linear function
of time through breakpoints ``(t_k, Omega_s,k)``: between breakpoints the angular acceleration
``Omega_s'`` is constant, and the spin angle ``phi_s(t) = int_0^t Omega_s dt`` is piecewise
quadratic and exact. After the last breakpoint each speed stays constant. A linear ramp has
two breakpoints; a constant speed has one.

At a breakpoint the acceleration jumps; it takes the value of the segment that ends there
(the left limit), so that a time step ending on a breakpoint sees the acceleration it had
during the step (docs/model.md, Eq. R4).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from rotorred import checks


@dataclass(frozen=True)
class SpeedProfile:
    """Piecewise-linear spool speeds ``Omega_s(t)`` (rad/s) through breakpoints at times ``t`` (s).

    Parameters
    ----------
    t : array_like, shape (k,)
        Breakpoint times (s): ``t[0] = 0``, strictly increasing.
    speeds : dict of str to array_like, shape (k,)
        Speed of each spool at the breakpoints (rad/s), >= 0.

    Examples
    --------
    >>> SpeedProfile.ramp({"inner": 0.0, "outer": 0.0}, {"inner": 528.0, "outer": 679.0}, 6.0)
    """

    t: np.ndarray
    speeds: Mapping[str, np.ndarray]

    def __post_init__(self):
        t = checks.vector("t", self.t, "s", ge=0.0, increasing=True)
        if t[0] != 0.0:
            checks.fail("t[0]", float(t[0]), "must be 0 (a run starts at t = 0)", "s")
        table = checks.table("speeds", self.speeds)
        if not table:
            checks.fail("speeds", dict(table), "must give the speed of at least one spool", "rad/s")
        speeds = {}
        for name, values in table.items():
            w = checks.vector(f"speeds[{name!r}]", values, "rad/s", min_len=len(t), max_len=len(t), ge=0.0)
            speeds[str(name)] = w
        t.setflags(write=False)
        for w in speeds.values():
            w.setflags(write=False)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "speeds", speeds)

    # ------------------------------------------------------------------------------- constructors
    @classmethod
    def constant(cls, speeds: Mapping[str, float]) -> SpeedProfile:
        """Every spool at a constant speed (rad/s).

        Parameters
        ----------
        speeds : dict of str to float
            Speed of each spool (rad/s), >= 0.
        """
        return cls(np.zeros(1), {s: [w] for s, w in dict(speeds).items()})

    @classmethod
    def ramp(cls, start: Mapping[str, float], end: Mapping[str, float], duration: float,
             hold: float = 0.0) -> SpeedProfile:
        """A linear ramp from ``start`` to ``end`` speeds (rad/s) over ``duration`` (s), after ``hold`` (s) at ``start``.

        A coast-down is a ramp with ``end`` below ``start``.

        Parameters
        ----------
        start, end : dict of str to float
            Speed of each spool at the start and at the end of the ramp (rad/s), >= 0; ``end`` names
            the spools of ``start``.
        duration : float
            Length of the ramp (s), > 0.
        hold : float
            Time at the ``start`` speeds before the ramp begins (s), >= 0.

        Raises
        ------
        InputError
            If ``duration`` is not > 0, ``hold`` < 0, a speed < 0, or the spools of ``end`` differ.
        """
        duration = checks.positive("duration", duration, "s")
        hold = checks.non_negative("hold", hold, "s")
        checks.keys("end", end, tuple(start), required=tuple(start))
        if hold:
            t = [0.0, hold, hold + duration]
            return cls(np.array(t), {s: [w, w, end[s]] for s, w in start.items()})
        return cls(np.array([0.0, duration]), {s: [w, end[s]] for s, w in start.items()})

    # ------------------------------------------------------------------------------- evaluation
    @property
    def spools(self) -> tuple[str, ...]:
        """Names of the spools the profile gives, in its order."""
        return tuple(self.speeds)

    @property
    def duration(self) -> float:
        """Time of the last breakpoint (s): the speeds are constant after it."""
        return float(self.t[-1])

    def _segment(self, t: np.ndarray) -> np.ndarray:
        """Segment index of each time: the ``k`` with ``t_k < t <= t_k+1`` (0 for t <= 0; the last beyond the end)."""
        return np.clip(np.searchsorted(self.t, t, side="left") - 1, 0, len(self.t) - 1)

    def accelerations(self) -> dict[str, np.ndarray]:
        """Angular acceleration of each spool on each segment (rad/s^2), shape (k,); the last (after the end) is 0."""
        out = {}
        for s, w in self.speeds.items():
            a = np.zeros(len(self.t))
            a[:-1] = np.diff(w) / np.diff(self.t)
            out[s] = a
        return out

    def angles_at_breakpoints(self) -> dict[str, np.ndarray]:
        """Spin angle ``int_0^t_k Omega dt`` of each spool at the breakpoints (rad), shape (k,) (trapezoids: exact)."""
        return {s: np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(self.t))])
                for s, w in self.speeds.items()}

    def at(self, t) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """``(Omega, Omega', phi)`` of each spool at times ``t`` (s): speed (rad/s), acceleration (rad/s^2)
        and spin angle (rad), each of the shape of ``t``.

        Parameters
        ----------
        t : float or array_like, shape (m,)
            Time(s) (s); before 0 the speeds are those at 0, after :attr:`duration` those at the end.
        """
        t = np.asarray(t, dtype=float)
        k = self._segment(t)
        tau = t - self.t[k]
        acc, ang = self.accelerations(), self.angles_at_breakpoints()
        return {s: (w[k] + acc[s][k] * tau, acc[s][k] + 0.0 * tau, ang[s][k] + w[k] * tau + 0.5 * acc[s][k] * tau**2)
                for s, w in self.speeds.items()}

    def speed(self, t) -> dict[str, np.ndarray]:
        """Speed of each spool at times ``t`` (rad/s), each of the shape of ``t``.

        Parameters
        ----------
        t : float or array_like, shape (m,)
            Time(s) (s); before 0 the speeds are those at 0, after :attr:`duration` those at the end.
        """
        return {s: v[0] for s, v in self.at(t).items()}

    def speeds_at(self, t: float) -> dict[str, float]:
        """Speeds at one time ``t`` (s), as the ``speeds`` dict of a constant-speed analysis (rad/s).

        Parameters
        ----------
        t : float
            Time (s).
        """
        return {s: float(v[0]) for s, v in self.at(float(t)).items()}

    def kernel_table(self, spools) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The breakpoint table of the compiled step, spools in the order ``spools``.

        Parameters
        ----------
        spools : sequence of str, length n_s
            Spool names, each one the profile gives (the model's order).

        Returns
        -------
        t : ndarray, shape (k,)
            Breakpoint times (s).
        W, W_dot, phi : ndarray, shape (n_s, k)
            Speed at the breakpoints (rad/s), acceleration on the segment that starts there
            (rad/s^2; 0 on the last), spin angle at the breakpoints (rad).
        """
        acc, ang = self.accelerations(), self.angles_at_breakpoints()
        return (np.array(self.t), np.array([self.speeds[s] for s in spools]), np.array([acc[s] for s in spools]),
                np.array([ang[s] for s in spools]))
