"""API 684 / API 617 amplification factors and separation margins of critical speeds (docs/model.md §21).

The one place of the standard's rule. For each critical speed of a Campbell diagram
(:class:`rotorred.linear.campbell.CriticalSpeed`) on a 1x line of a spool:

1. **The relevant excitation** (API 684 places the unbalance where the mode moves most): an unbalance on the
   excited spool at the node of that spool with the largest orbit in the mode at the critical speed
   (the modes of :func:`rotorred.mode_shapes`; the one of nearest frequency); its response is read at the same
   node, as the orbit's semi-major axis ``(|X + iY| + |X - iY|) / 2`` (a probe pair's largest reading). Its size
   does not matter (the response is linear).
2. **The amplification factor by the half-power method** (:func:`half_power`) on that unbalance response
   (:func:`rotorred.unbalance_response`) along the diagram's speed line: the response peak N_c, the speeds
   N_1 < N_c < N_2 where the amplitude is the peak's over sqrt(2), ``AF = N_c / (N_2 - N_1)``: the same in the
   reference spool's speed and the excited one's, which turns at a ratio to it (``Omega_s = a_s Omega``). The
   peak is refined by a bounded scalar search and N_1, N_2 by Brent's method, not read off a grid.
3. **The required separation margin** (:func:`required_margin`), from AF and the side of the operating range
   (minimum to maximum continuous speed of the reference spool, :class:`OperatingRange`) the peak lies on:

   - AF < 2.5: critically damped, no margin;
   - AF >= 2.5, below the minimum speed: SM = min(17 (1 - 1/(AF - 1.5)), 16) % of the minimum speed;
   - AF >= 2.5, above the maximum continuous speed: SM = min(10 + 17 (1 - 1/(AF - 1.5)), 26) % of it.

   The actual margin is the peak's distance from that end of the range, in % of it (negative inside the range);
   the critical speed meets the rule when actual >= required, or when no margin is required (even inside the
   range: a critically damped response needs no separation).

A crossing of a line h x Omega_s with h != 1, or of a spool held at a fixed speed, is not an unbalance resonance
along the line: it gets no AF (NaN) and no verdict. A crossing whose unbalance response has no peak near it (a
backward mode of an isotropic rotor, which a forward unbalance does not excite, or an overdamped one) gets no AF
and requires no margin (API's critical speed is a response peak). Margins are fractions inside (0.16), per cent
in the files.

References
----------
API Standard 617, 7th ed. (2002), 2.6.2.10; API RP 684, 2nd ed. (2005), SP6.8.2.1 and SP6.8.2.10 (as cited by
ROSS, petrobras/ross ``ross/api_report.py``, whose ``Report.unbalance_response`` implements the same rule).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from rotorred import checks
from rotorred.linear.campbell import CampbellResult, CriticalSpeed, modes_at
from rotorred.linear.harmonic import unbalance_response
from rotorred.linear.modes import node_motion
from rotorred.model.assembly import system_of
from rotorred.model.loads import Unbalance
from rotorred.model.operating import Operating

#: below this amplification factor a response is critically damped: no separation margin is required (API 617)
AF_CRITICALLY_DAMPED = 2.5
#: the required margin below the minimum speed is at most this (fraction of the minimum speed)
MAX_MARGIN_BELOW = 0.16
#: the required margin above the maximum continuous speed is at most this (fraction of that speed)
MAX_MARGIN_ABOVE = 0.26
#: size of the unbalance placed at the mode's largest orbit (kg m): any, the response is linear
PROBE_UNBALANCE = 1e-4
#: the response is sampled over [1 - b, 1 + b] x the critical speed, b = max(BAND_ZETAS x damping ratio,
#: MIN_BAND), widened x2 (up to MAX_BAND) until the half-power points lie inside
BAND_ZETAS, MIN_BAND, MAX_BAND = 8.0, 0.05, 0.9
#: the mode's response peak lies within max(PEAK_ZETAS x damping ratio, MIN_PEAK) x the critical speed of it (a
#: single-DOF system's at 1/sqrt(1 - 2 zeta^2) - 1 ~ zeta^2 for the unbalance response): a peak farther off is
#: another mode's
PEAK_ZETAS, MIN_PEAK = 2.0, 0.02
#: a peak whose half-power bandwidth (N_2 - N_1) / N_c exceeds OWN_BANDWIDTH x 2 zeta (a single-DOF system's: 2 zeta,
#: zeta the mode's damping ratio at the crossing) belongs to a better damped mode nearby, not to this one
OWN_BANDWIDTH = 3.0
#: samples of the response over the band (the peak and the half-power points are then refined)
BAND_SAMPLES = 41
#: a mode whose damping ratio at the crossing is below this is undamped: its AF, 1 / (2 zeta) > 5e7, is taken as
#: infinite (the rule's limit), as no sampled response resolves a peak that sharp (its solves are singular)
UNDAMPED_ZETA = 1e-8


@dataclass(frozen=True)
class OperatingRange:
    """The operating speed range of the reference spool: minimum to maximum continuous speed (rad/s).

    Parameters
    ----------
    minimum : float
        Minimum operating speed (rad/s), >= 0.
    maximum : float
        Maximum continuous speed (rad/s), >= ``minimum``.
    """

    minimum: float
    maximum: float

    def __post_init__(self):
        object.__setattr__(self, "minimum", checks.non_negative("minimum", self.minimum, "rad/s"))
        object.__setattr__(self, "maximum", checks.number("maximum", self.maximum, "rad/s", ge=self.minimum))

    def side_and_margin(self, speed: float) -> tuple[str, float]:
        """Where a critical speed lies and its margin from the range.

        Parameters
        ----------
        speed : float
            The critical speed N (rad/s of the reference spool).

        Returns
        -------
        side : str
            ``"below"`` or ``"above"``; inside the range, the nearer end's.
        margin : float
            (min - N) / min below, (N - max) / max above (fraction); negative inside the range.
        """
        below = (self.minimum - speed) / self.minimum if self.minimum > 0 else -math.inf
        above = (speed - self.maximum) / self.maximum if self.maximum > 0 else math.inf
        if below >= 0 and self.minimum > 0:
            return "below", below
        if above >= 0:
            return "above", above
        return ("below", below) if below >= above else ("above", above)  # inside: the nearer end, negative


@dataclass(frozen=True)
class HalfPower:
    """A response peak and its half-power points (speeds in rad/s).

    Attributes
    ----------
    peak_speed : float
        Speed of the peak N_c (rad/s).
    peak : float
        Amplitude there (the response's unit).
    lower, upper : float
        N_1 < N_c < N_2 where the amplitude is ``peak / sqrt(2)`` (rad/s).
    """

    peak_speed: float
    peak: float
    lower: float
    upper: float

    @property
    def amplification_factor(self) -> float:
        """AF = N_c / (N_2 - N_1) (-); infinite where the half-power points coincide (an undamped mode)."""
        width = self.upper - self.lower
        return self.peak_speed / width if width > 0 else math.inf


@dataclass(frozen=True)
class SeparationMargin:
    """The API 684 / API 617 verdict on one critical speed (module docstring).

    Attributes
    ----------
    critical : CriticalSpeed
    amplification_factor : float
        AF by the half-power method (-); infinite for an undamped mode; NaN where none is defined (``note`` says
        why).
    half_power : HalfPower or None
        The peak and half-power points of the unbalance response, in speeds of the reference spool (rad/s).
    unbalance_node : int or None
        Node of the unbalance and of the response read (the mode's largest orbit on the excited spool).
    side : str
        ``"below"`` the minimum speed, ``"above"`` the maximum continuous speed, or ``""`` without a range; a peak
        inside the range is named by the nearer end.
    required : float
        Required separation margin (fraction of the range's end); NaN where there is no verdict.
    actual : float
        The peak's (else the crossing's) distance from that end (fraction, negative inside the range); NaN without
        a range.
    meets : bool or None
        ``actual >= required``, or no margin required; None where there is no verdict (no range, or not an
        unbalance resonance).
    note : str
        Why there is no AF or no verdict ("" otherwise).
    """

    critical: CriticalSpeed
    amplification_factor: float
    half_power: HalfPower | None = None
    unbalance_node: int | None = None
    side: str = ""
    required: float = math.nan
    actual: float = math.nan
    meets: bool | None = None
    note: str = ""


def required_margin(amplification_factor: float, side: str) -> float:
    """The separation margin API 617 requires (fraction of the range's end) for a critical speed with this
    amplification factor on ``side`` of the operating range.

    Parameters
    ----------
    amplification_factor : float
        AF (-), > 0; infinite for an undamped mode.
    side : {"below", "above"}
        Below the minimum speed, or above the maximum continuous speed.

    Returns
    -------
    float
        0 if AF < 2.5; else min(0.17 (1 - 1/(AF - 1.5)), 0.16) below, min(0.10 + 0.17 (1 - 1/(AF - 1.5)), 0.26)
        above.
    """
    af = amplification_factor
    if math.isinf(af) and af > 0:  # undamped: the rule's limit, 17 (1 - 1/(AF - 1.5)) -> 17
        af = 1e300
    af = checks.number("amplification_factor", af, gt=0.0)
    side = checks.choice("side", side, ("below", "above"))
    if af < AF_CRITICALLY_DAMPED:
        return 0.0
    sm = 0.17 * (1.0 - 1.0 / (af - 1.5))
    return min(sm, MAX_MARGIN_BELOW) if side == "below" else min(0.10 + sm, MAX_MARGIN_ABOVE)


def half_power(amplitude: Callable[[np.ndarray], np.ndarray], speeds: np.ndarray, near: float,
               within: float = math.inf) -> HalfPower | None:
    """The response peak nearest ``near`` among the interior maxima of ``amplitude`` sampled at ``speeds`` (at most
    ``within`` from ``near``), refined, with its half-power points; None if there is no such maximum or the amplitude
    does not fall to peak / sqrt(2) on both sides within ``speeds``.

    Parameters
    ----------
    amplitude : callable
        ``amplitude(W)`` for speeds ``W`` (rad/s), ndarray shape (k,) -> ndarray shape (k,) (any unit).
    speeds : ndarray, shape (n,)
        Increasing speeds (rad/s) to sample.
    near : float
        The speed (rad/s) whose nearest peak is taken (the critical speed).
    within : float
        Farthest a peak may lie from ``near`` (rad/s): a wider sampling finds the half-power points, not another
        mode's peak.

    Returns
    -------
    HalfPower or None
    """
    A = np.asarray(amplitude(speeds), dtype=float)
    peaks = _interior_peaks(A, speeds, near, within)
    if not peaks:
        return None
    i = min(peaks, key=lambda k: abs(speeds[k] - near))
    one = lambda W: float(amplitude(np.array([W]))[0])  # noqa: E731 - the scalar form for the solvers
    found = minimize_scalar(lambda W: -one(W), bounds=(speeds[i - 1], speeds[i + 1]), method="bounded",
                            options={"xatol": 1e-11 * speeds[i]})
    Wp, peak = float(found.x), -float(found.fun)
    if peak < A[i]:  # the bounded search stopped short of the grid's best: keep the sample
        Wp, peak = float(speeds[i]), float(A[i])
    level = peak / math.sqrt(2.0)
    # the nearest samples below the level on each side of the refined peak; every sample between them and the peak
    # is at or above it (a peak sharper than the grid may leave even the best sample below the level)
    left = next((j for j in range(len(A) - 1, -1, -1) if speeds[j] < Wp and A[j] < level), None)
    right = next((j for j in range(len(A)) if speeds[j] > Wp and A[j] < level), None)
    if left is None or right is None:
        return None

    def gap(W):
        return one(W) - level

    lower = brentq(gap, speeds[left], min(float(speeds[left + 1]), Wp), xtol=1e-12 * Wp)
    upper = brentq(gap, max(float(speeds[right - 1]), Wp), speeds[right], xtol=1e-12 * Wp)
    return HalfPower(Wp, peak, float(lower), float(upper))


def _interior_peaks(A: np.ndarray, speeds: np.ndarray, near: float, within: float) -> list[int]:
    """The indices of the interior maxima of the samples ``A`` at ``speeds`` at most ``within`` from ``near``."""
    return [i for i in range(1, len(A) - 1)
            if A[i] >= A[i - 1] and A[i] >= A[i + 1] and A[i] > 0 and abs(speeds[i] - near) <= within]


def separation_margins(model, result: CampbellResult, operating_range: OperatingRange | None = None
                       ) -> tuple[SeparationMargin, ...]:
    """The amplification factor and the API 617 separation margin of every critical speed of ``result``.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        The model ``result`` was computed on (:func:`rotorred.campbell`).
    result : CampbellResult
        A Campbell diagram along a speed line (its ``operating``).
    operating_range : OperatingRange, optional
        Minimum to maximum continuous speed of the reference spool (rad/s); without it, AFs only (no verdict).

    Returns
    -------
    tuple of SeparationMargin
        One per critical speed, in the order of ``result.critical_speeds``.

    Raises
    ------
    InputError
        If ``result`` carries no speed line, or ``operating_range`` is not an :class:`OperatingRange`.
    """
    if not isinstance(result, CampbellResult) or result.operating is None:
        checks.fail("result", type(result).__name__, "must be a CampbellResult of rotorred.campbell (with its "
                    "operating speed line)")
    if operating_range is not None and not isinstance(operating_range, OperatingRange):
        checks.fail("operating_range", operating_range, "must be an OperatingRange(minimum, maximum) (rad/s)")
    sm = system_of(model, sparse_ok=True)
    return tuple(_margin(sm, result, c, operating_range) for c in result.critical_speeds)


def _margin(sm, result: CampbellResult, c: CriticalSpeed, rng: OperatingRange | None) -> SeparationMargin:
    """The :class:`SeparationMargin` of critical speed ``c`` (module docstring, steps 1-3)."""
    slope = result.speed_ratios[c.spool]
    if c.harmonic != 1.0 or slope <= 0.0:
        why = (f"{c.line}: not excited by unbalance (a 1x line is)" if c.harmonic != 1.0
               else f"{c.spool} is held at a fixed speed: no unbalance resonance along the line")
        return _verdict(c, None, None, rng, why, verdict=False)
    node = _antinode(sm, result, c)
    hp = None
    zeta = abs(c.damping_ratio)
    if zeta < UNDAMPED_ZETA:
        return _verdict(c, None, node, rng, f"undamped (damping ratio {c.damping_ratio:.2g}): AF infinite",
                        verdict=True, af=math.inf)
    band, near = max(BAND_ZETAS * zeta, MIN_BAND), max(PEAK_ZETAS * zeta, MIN_PEAK)
    amplitude = _response(sm, result, c.spool, node)
    while hp is None and band <= MAX_BAND:  # the peak near the crossing; its half-power points maybe farther
        W = np.linspace(c.speed * (1.0 - band), c.speed * (1.0 + band), BAND_SAMPLES)
        A = amplitude(W)
        if not _interior_peaks(A, W, c.speed, near * c.speed):
            # no sampled peak near the crossing: a wider band samples the same speeds more coarsely (the near
            # region lies inside the first band, band >= 2.5 near), so it is widened only to take in the
            # half-power points of a peak found (each band is 41 full solves)
            break
        hp = half_power(lambda V, W=W, A=A: A if V is W else amplitude(V), W, c.speed, near * c.speed)
        band *= 2.0
    if hp is not None and 0.0 < zeta and (hp.upper - hp.lower) / hp.peak_speed > OWN_BANDWIDTH * 2.0 * zeta:
        hp = None  # a peak this broad is a better damped mode's, not this one's
    why = "" if hp is not None else "no response peak of its own: not excited, or overdamped"
    return _verdict(c, hp, node, rng, why, verdict=True)


def _verdict(c, hp: HalfPower | None, node, rng: OperatingRange | None, note: str, verdict: bool,
             af: float | None = None) -> SeparationMargin:
    """The margin of ``c`` from its half-power points (speeds of the reference spool), or the ``af`` given, and the
    range."""
    af = af if af is not None else math.nan if hp is None else hp.amplification_factor
    if rng is None:
        return SeparationMargin(c, af, hp, node, note=note)
    side, actual = rng.side_and_margin(c.speed if hp is None else hp.peak_speed)
    if not verdict:
        return SeparationMargin(c, af, hp, node, side, math.nan, actual, None, note)
    required = 0.0 if math.isnan(af) else required_margin(af, side)
    # no margin required (AF < 2.5, or no peak): met wherever the critical speed lies, even inside the range
    return SeparationMargin(c, af, hp, node, side, required, actual, bool(required == 0.0 or actual >= required),
                            note)


def _antinode(sm, result: CampbellResult, c: CriticalSpeed) -> int:
    """The node of spool ``c.spool`` with the largest orbit in the mode (of nearest frequency) at the critical
    speed (the modes of :func:`rotorred.mode_shapes`, one eigen-solve)."""
    lam, shapes = modes_at(sm, _line(result, [c.speed]).lines(sm), c.speed, result.n_modes)
    nodes, spools, _, X, Y = node_motion(sm, shapes[:, [int(np.argmin(np.abs(lam.imag - c.frequency)))]])
    major = (np.abs(X + 1j * Y) + np.abs(X - 1j * Y))[0]
    on = [i for i, s in enumerate(spools) if s == c.spool]
    return int(nodes[on[int(np.argmax(major[on]))]])


def _line(result: CampbellResult, speeds) -> Operating:
    """``result``'s speed line at the reference speeds ``speeds`` (rad/s)."""
    op = result.operating
    return Operating(np.asarray(speeds, dtype=float), op.reference, op.ratios, op.fixed, unit=op.unit)


def _response(sm, result: CampbellResult, spool: str, node: int):
    """``amplitude(W)``: the semi-major axis of the orbit at ``node`` of the response to an unbalance there,
    at reference speeds ``W`` (rad/s) along ``result``'s line (:func:`rotorred.unbalance_response`)."""
    def amplitude(W: np.ndarray) -> np.ndarray:
        r = unbalance_response(sm, _line(result, W), [Unbalance(node, PROBE_UNBALANCE)], [(node, "x"), (node, "y")])
        X, Y = r.phasors[spool][(node, "x")], r.phasors[spool][(node, "y")]
        return (np.abs(X + 1j * Y) + np.abs(X - 1j * Y)) / 2.0
    return amplitude
