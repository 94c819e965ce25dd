"""Campbell diagram: whirl frequencies against speed, whirl direction, critical speeds.

The x-axis is the speed Omega of a *reference* spool along a speed line
(:class:`rotorred.model.operating.Operating`); every spool ``s`` turns at ``Omega_s = a_s Omega + b_s`` by the
one ratio rule :meth:`Operating.lines`: at a ratio (``a_s``, ``b_s = 0``; the reference has ``a = 1``) or at a
fixed speed (``a_s = 0``, ``b_s``). At each speed the damped eigenproblem

    M q'' + (C + sum_s Omega_s G_s) q' + K q = 0

(Xu et al. 2016, Eq. 13 with one gyroscopic matrix per spool) is solved with
:func:`rotorred.linear.modal.eigen`. Modes are followed from speed to speed by the modal assurance
criterion (MAC, :func:`rotorred.linear.modal.mac`) with an optimal one-to-one assignment
(:func:`scipy.optimize.linear_sum_assignment`), so a curve keeps its identity where two curves
cross. A critical speed is a speed where a tracked curve omega_j(Omega) meets an excitation line
``h Omega_s = h (a_s Omega + b_s)`` (harmonic ``h`` of spool ``s``; horizontal for a spool at a fixed speed); it is
bracketed on the speed grid and refined with
:func:`scipy.optimize.brentq`, solving the eigenproblem at the intermediate speeds. A speed where a
tracked mode's log decrement changes sign (it becomes unstable, or stable again) is refined the same
way, on Re(lambda) = 0 (:class:`StabilityChange`). Rigid-body modes of a free or singly supported
spool (:func:`rigid_body_share`) give neither.

By default (``n_modes=None``) the tracked modes are every mode below ``DEFAULT_MARGIN`` times the highest
excitation frequency of the sweep (the largest ``h Omega_s`` at the top speed), counted from the eigenvalues at
the first and the last speed, at least ``MIN_DEFAULT_MODES`` (:func:`default_mode_count`); the tracked curves are
then checked at every grid speed to leave no untracked mode below that frequency, and more are tracked if one does.

Whirl direction (spin about +z): at a node with complex amplitudes X, Y of x and y,
``x + i y = (X + iY)/2 e^{i w t} + conj(X - iY)/2 e^{-i w t}``, so the forward (counter-clockwise,
with the spin) amplitude is |X + iY| and the backward one |X - iY|. A mode is forward (backward) if
the nodes whirling backward (forward) carry at most 1 % of sum_n |X_n|^2 + |Y_n|^2, else mixed; planar
if every orbit is a line. The eigenvectors of a multiple eigenvalue (an isotropic rotor at rest) are
rotated into the forward/backward pair that the gyroscopic split selects as Omega -> 0+.

Cost: one dense eigen-solve of the 2n state matrix per grid speed (modes for the MAC); crossings are
refined by Newton iterations on the quadratic eigenproblem (one (n+1)^2 complex solve each), with
the full eigen-solve as fallback. The default number of modes costs two more eigen-solves (the first and
last speed), and the tracking of the extra modes (their MAC and critical speeds).

References
----------
Xu, Wang, Jiang, Han, Li, Shock and Vibration 2016, 6239281, Eq. 13.
Allemang, "The modal assurance criterion - twenty years of use and abuse", Sound and Vibration 37 (2003).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import brentq, linear_sum_assignment

from rotorred import checks, writers
from rotorred.linear.modal import WHIRL_MAX_DAMPING_RATIO, eigen, mac
from rotorred.model.assembly import SystemMatrices, system_of
from rotorred.model.sparse import is_sparse
from rotorred.model.operating import Operating, SpoolLine
from rotorred.model.operating import checked as checked_operating
from rotorred.model.rigid import rigid_body_motions
from rotorred.progress import stage
from rotorred.results import Result

WHIRL_LABELS = ("forward", "backward", "mixed", "planar")

#: a mode whirls forward (backward) if the nodes whirling the other way carry at most this share of
#: sum_n (|X_n|^2 + |Y_n|^2); otherwise it is "mixed". Near a node of the mode shape of an anisotropic
#: rotor the orbit of a node with ~1 % of the largest amplitude often turns the other way: that does not
#: make the mode "mixed" (such nodes carry ~1e-4 of the sum).
_MIXED_SHARE = 0.01
#: (|X+iY|^2 - |X-iY|^2) / (|X+iY|^2 + |X-iY|^2) below this in magnitude is a straight-line (planar)
#: orbit; roundoff in an eigenvector of unit norm is ~1e-13 at the significant nodes.
_PLANAR_TOL = 1e-9
#: eigenvalues closer than this (relative) are treated as one multiple eigenvalue, whose
#: eigenvectors are any basis of a subspace; such a basis is rotated into forward/backward orbits.
_DEGENERATE_RTOL = 1e-7
#: weight of the frequency jump (relative) added to -MAC in the tracking cost, only to break ties
#: between candidates of equal MAC (e.g. inside a multiple eigenvalue).
_FREQ_TIEBREAK = 1e-3
#: the default number of tracked modes covers every mode below this multiple of the highest excitation
#: frequency at the top speed (docs/model.md §16): a curve just above that frequency at the first and the last
#: speed, where the modes are counted, may dip below it between them (gyroscopics, speed-dependent bearings),
#: and the diagram also shows the modes whose critical speeds lie up to ~25 % beyond the top speed
DEFAULT_MARGIN = 1.25
#: the default tracks at least this many modes (the former fixed default): a diagram over a low speed range,
#: or the whirl table at one speed (at rest: no excitation at all), still shows the lowest modes
MIN_DEFAULT_MODES = 6


class _PointOnTheDiagram:
    """A point of a Campbell diagram: ``speed`` of the reference spool and whirl ``frequency`` (rad/s)."""

    speed: float
    frequency: float

    @property
    def speed_rpm(self) -> float:
        """Speed of the reference spool (rpm)."""
        return self.speed * 30.0 / math.pi

    @property
    def frequency_hz(self) -> float:
        """Whirl frequency (Hz)."""
        return self.frequency / (2.0 * math.pi)


@dataclass(frozen=True, repr=False)
class CriticalSpeed(_PointOnTheDiagram, Result):
    """A crossing of a whirl curve with an excitation line h x Omega_s (Omega_s = a_s Omega + b_s).

    Attributes
    ----------
    speed : float
        Speed of the reference spool (rad/s).
    spool : str
        The spool whose excitation line is crossed.
    harmonic : float
        Multiple h of that spool's speed (-).
    mode : int
        Column of :attr:`CampbellResult.frequencies` (0-based tracked mode); the files and printouts number it
        from 1 (``mode + 1``), as :func:`rotorred.mode_shapes` numbers the modes at the first speed.
    frequency : float
        Whirl frequency at the crossing (rad/s) = h x speed of ``spool``.
    whirl : str
        ``"forward"``, ``"backward"``, ``"mixed"`` or ``"planar"``.
    log_dec : float
        Logarithmic decrement of the mode at the crossing (-).
    same_line : tuple of str
        Other excitations on the same line (equal slope and offset), e.g. ``("1× outer",)`` for ``1× inner``
        at speed ratio 1: the crossing is listed once.
    """

    speed: float
    spool: str
    harmonic: float
    mode: int
    frequency: float
    whirl: str
    log_dec: float
    same_line: tuple[str, ...] = ()

    @property
    def spool_speed(self) -> float:
        """Speed of the excited spool at the crossing (rad/s)."""
        return self.frequency / self.harmonic

    @property
    def line(self) -> str:
        """Label of the excitation line, e.g. ``"1× inner"``, or ``"1× inner = 1× outer"`` for a shared line."""
        return " = ".join((excitation_label(self.harmonic, self.spool), *self.same_line))

    @property
    def damping_ratio(self) -> float:
        """Damping ratio of the mode at the crossing, delta / sqrt(delta^2 + 4 pi^2) (-)."""
        return self.log_dec / math.sqrt(self.log_dec ** 2 + 4.0 * math.pi ** 2)

    def summary(self) -> list[str]:
        """Where the curve meets which line, and the mode there."""
        lines = [f"{self.speed_rpm:.6g} rpm of the reference spool on {self.line} "
                 f"({self.spool} at {self.spool_speed * 30.0 / math.pi:.6g} rpm)",
                 f"mode {self.mode + 1}, {self.whirl} whirl at {self.frequency_hz:.6g} Hz",
                 f"log dec {self.log_dec:.4g}, damping ratio {self.damping_ratio:.4g}"]
        return lines

    def plot(self, ax=None, **options):
        """Mark the crossing (rpm, Hz) with its excitation line; into a Campbell diagram's axes it annotates
        that critical speed (:func:`rotorred.plots.campbell.draw_critical_speed`, its options).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            ``figsize`` (in) of a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.campbell import draw_critical_speed

        return draw_critical_speed(self, ax, **options)

    def to_xarray(self):
        """Scalars ``speed`` (reference spool, rad/s), ``spool_speed`` (rad/s), ``frequency`` (Hz), ``harmonic``,
        ``mode``, ``whirl`` (:data:`WHIRL_LABELS` flags), ``log_dec``; the line and spool as attributes."""
        import xarray as xr

        return xr.Dataset(
            {"speed": ((), self.speed, {"units": "rad/s", "long_name": "speed of the reference spool"}),
             "spool_speed": ((), self.spool_speed, {"units": "rad/s", "long_name": f"speed of the {self.spool} spool"}),
             "frequency": ((), self.frequency_hz, {"units": "Hz", "long_name": "whirl frequency"}),
             "harmonic": ((), self.harmonic, {"units": "1", "long_name": f"multiple of the {self.spool} speed"}),
             "mode": ((), self.mode, {"units": "1", "long_name": "tracked mode (column of the Campbell result)"}),
             "whirl": ((), _whirl_codes(self.whirl), _WHIRL_ATTRS),
             "log_dec": ((), self.log_dec, {"units": "1", "long_name": "logarithmic decrement"})},
            attrs={"title": "critical speed", "line": self.line, "spool": self.spool})


@dataclass(frozen=True)
class StabilityChange(_PointOnTheDiagram):
    """A speed where a tracked mode's log decrement crosses zero.

    Attributes
    ----------
    speed : float
        Speed of the reference spool (rad/s), found by Brent's method on Re(lambda) = 0.
    mode : int
        Column of :attr:`CampbellResult.frequencies`.
    frequency : float
        Whirl frequency there (rad/s).
    whirl : str
    onset : bool
        True where the mode becomes unstable as the speed rises (log dec > 0 below, < 0 above),
        False where it becomes stable again.
    """

    speed: float
    mode: int
    frequency: float
    whirl: str
    onset: bool


@dataclass(frozen=True)
class ModeCount:
    """How many modes :func:`campbell` tracks by default, and why (:func:`default_mode_count`).

    Attributes
    ----------
    n_modes : int
        Modes to track: the most of ``below`` (at least ``MIN_DEFAULT_MODES``), at most the number of
        oscillating modes at the first and the last speed.
    limit : float
        Highest excitation frequency of the sweep, ``harmonic`` x the speed of ``spool`` at the top speed
        (rad/s); 0 if no spool turns there.
    margin : float
        The count covers every mode below ``margin`` x ``limit`` (-).
    spool : str
        Spool whose excitation line is the highest ("" if none turns).
    harmonic : float
        Highest excitation order (multiple of the spool speed).
    top_speed : float
        Top speed of the reference spool (rad/s).
    speeds : tuple of float
        Reference speeds where the modes were counted: the first and the last (one if the sweep has one
        speed) (rad/s).
    below : tuple of int
        Number of modes below ``margin`` x ``limit`` at each of ``speeds``.
    grown_at : float or None
        Set by :func:`campbell` if a mode below ``limit`` was left untracked at this reference speed (rad/s)
        with the counted modes (their order changed along the sweep), so more were tracked; ``n_modes``
        is then the number finally tracked.
    born : tuple of (float, float, float)
        Set by :func:`campbell`: the modes below ``limit`` that become oscillating along the sweep (a pair
        overdamped at the speed before, damping ratio at least ``WHIRL_MAX_DAMPING_RATIO``, turned into a whirl
        mode; or a mode descending from one), each as (reference speed (rad/s), frequency (rad/s), damping ratio
        (-)) where it first appears: no curve tracked from the first speed can follow them, so they are reported,
        not tracked, and more modes are not tracked for them (docs/model.md §21).
    """

    n_modes: int
    limit: float
    margin: float
    spool: str
    harmonic: float
    top_speed: float
    speeds: tuple[float, ...]
    below: tuple[int, ...]
    grown_at: float | None = None
    born: tuple[tuple[float, float, float], ...] = ()

    @property
    def limit_hz(self) -> float:
        """Highest excitation frequency (Hz)."""
        return self.limit / (2.0 * math.pi)


@dataclass(frozen=True, repr=False)
class CampbellResult(Result):
    """Whirl frequencies of tracked modes against the speed of a reference spool.

    Attributes
    ----------
    speeds : ndarray, shape (n_speeds,)
        Speed of the reference spool (rad/s).
    frequencies : ndarray, shape (n_speeds, n_modes)
        Damped whirl frequency Im(lambda) of each tracked mode (rad/s); column j follows one mode
        (by MAC), numbered by its frequency order at ``speeds[0]``.
    log_dec : ndarray, shape (n_speeds, n_modes)
        Logarithmic decrement -2 pi Re(lambda) / Im(lambda) (-).
    whirl : ndarray of str, shape (n_speeds, n_modes)
        ``"forward"``, ``"backward"``, ``"mixed"`` (nodes whirl in both directions) or
        ``"planar"`` (straight-line orbits, e.g. an anisotropic rotor at rest).
    tracking_mac : ndarray, shape (n_speeds - 1, n_modes)
        MAC between a tracked mode's shapes at consecutive speeds (1 = unchanged shape).
    critical_speeds : tuple of CriticalSpeed
        Sorted by speed.
    reference : str
        Name of the reference spool.
    speed_ratios : dict of str to float
        ``dOmega_s / dOmega`` of each spool (-): its ratio to the reference spool (1 for the reference), 0 for a
        spool held at a fixed speed.
    harmonics : tuple of float
        Multiples of each spool's speed used as excitation lines (-).
    rotor_name : str
    stability_changes : tuple of StabilityChange
        Speeds where a (non rigid-body) mode's log decrement crosses zero, sorted by speed: where it
        becomes unstable (a negative log dec: the rotor's own motion grows) and stable again.
    rigid_modes : tuple of int
        Tracked modes that are rigid-body modes of a free or singly supported spool (most of their
        kinetic energy in the null space of K at the first speed, :func:`rigid_body_share`). No
        critical speed is reported where a mode is rigid at either end of a speed interval.
    beyond_tables : tuple of (int, float, float, str)
        Speed-dependent bearings (:class:`rotorred.model.elements.BearingTable`) whose table the sweep leaves:
        (node, the table's lowest and highest speed (rad/s), its ``extrapolate``: "hold" or "linear").
    mode_count : ModeCount or None
        Why ``n_modes`` modes were tracked, when chosen by default (``n_modes=None``); None when given.
    fixed_speeds : dict of str to float
        Speed of each spool held at a fixed speed along the sweep (rad/s); its excitation lines are horizontal,
        h x that speed. Spool ``s`` turns at ``speed_ratios[s] * speeds + fixed_speeds.get(s, 0)``.
    operating : Operating or None
        The speed line the diagram was computed on (:class:`rotorred.model.operating.Operating`).
    """

    speeds: np.ndarray
    frequencies: np.ndarray
    log_dec: np.ndarray
    whirl: np.ndarray
    tracking_mac: np.ndarray
    critical_speeds: tuple[CriticalSpeed, ...]
    reference: str
    speed_ratios: Mapping[str, float]
    harmonics: tuple[float, ...]
    rotor_name: str = ""
    rigid_modes: tuple[int, ...] = ()
    stability_changes: tuple[StabilityChange, ...] = ()
    beyond_tables: tuple[tuple[int, float, float, str], ...] = ()
    mode_count: ModeCount | None = None
    fixed_speeds: Mapping[str, float] = field(default_factory=dict)
    operating: Operating | None = None

    def __post_init__(self):
        for f in ("speeds", "frequencies", "log_dec", "whirl", "tracking_mac"):
            a = np.array(getattr(self, f))
            a.setflags(write=False)
            object.__setattr__(self, f, a)
        object.__setattr__(self, "speed_ratios", dict(self.speed_ratios))
        object.__setattr__(self, "fixed_speeds", dict(self.fixed_speeds))

    @property
    def n_modes(self) -> int:
        """Number of tracked modes (columns of :attr:`frequencies`)."""
        return self.frequencies.shape[1]

    @property
    def speeds_rpm(self) -> np.ndarray:
        """Reference speeds (rpm), shape (n_speeds,)."""
        return self.speeds * 30.0 / np.pi

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Whirl frequencies (Hz), shape (n_speeds, n_modes)."""
        return self.frequencies / (2.0 * np.pi)

    @property
    def excitation_lines(self) -> tuple[tuple[str, float, float, float], ...]:
        """(spool, harmonic, slope, offset) of each excitation line of a turning spool: frequency (rad/s) =
        slope x reference speed + offset; the offset is h x the speed of a spool held at a fixed speed, else 0."""
        return tuple((s, h, h * r, h * self.fixed_speeds.get(s, 0.0)) for s, r in self.speed_ratios.items()
                     if r > 0 or self.fixed_speeds.get(s, 0.0) > 0 for h in self.harmonics)

    def critical_speeds_to_csv(self, path: str | Path, operating_speed: float | None = None,
                               margins: Sequence | None = None) -> Path:
        """Write the critical speeds, one row each: the reference spool's speed (rpm), the excitation line,
        the excited spool's speed (rpm), the mode, its frequency (Hz), whirl, log dec and damping ratio at
        the crossing, and the margin to ``operating_speed`` (rad/s of the reference spool), in % of it
        (positive: the critical speed lies above the operating point; empty without one); then the API 617
        columns ``amplification_factor``, ``required_margin_pct``, ``actual_margin_pct``, ``meets_api`` (yes/no)
        of ``margins`` (empty where a margin has none, and without ``margins``).

        Parameters
        ----------
        path : str or Path
            The CSV file to write.
        operating_speed : float, optional
            Operating speed of the reference spool (rad/s), > 0 for a margin; None or 0: no margin.
        margins : sequence of SeparationMargin, optional
            One per critical speed (:func:`rotorred.separation_margins`).

        Returns
        -------
        Path
            ``path``.
        """
        def margin(c):
            return "" if not operating_speed else f"{100.0 * (c.speed - operating_speed) / operating_speed:.4f}"

        cs = self.critical_speeds
        header = [f"{self.reference} speed (rpm)", "excitation", "excited spool speed (rpm)", "mode",
                  "frequency (Hz)", "whirl", "log dec", "damping ratio", "margin to operating point (%)"]
        columns = [np.array([c.speed_rpm for c in cs]), [c.line for c in cs],
                   np.array([c.spool_speed * 30.0 / math.pi for c in cs]), np.array([c.mode + 1 for c in cs], int),
                   np.array([c.frequency_hz for c in cs]), [c.whirl for c in cs], np.array([c.log_dec for c in cs]),
                   np.array([c.damping_ratio for c in cs]), [margin(c) for c in cs]]
        api = [(_cell(m.amplification_factor), _cell(100 * m.required), _cell(100 * m.actual),
                "" if m.meets is None else "yes" if m.meets else "no") for m in margins or ()] or [("",) * 4] * len(cs)
        header += ["amplification_factor", "required_margin_pct", "actual_margin_pct", "meets_api"]
        columns += [list(col) for col in zip(*api)] if cs else [[], [], [], []]
        return writers.write_csv(path, header, columns)

    @property
    def unstable(self) -> np.ndarray:
        """Where a mode's log dec is negative beyond round-off (< -NEUTRAL_LOG_DEC), shape (n_speeds, n_modes)."""
        return self.log_dec < -NEUTRAL_LOG_DEC

    @property
    def onset_speeds(self) -> dict[int, float]:
        """Onset speed of each mode that becomes unstable along the sweep: the reference spool's speed (rad/s) of its
        first :class:`StabilityChange` with ``onset`` (the root of Re(lambda) = 0, e.g. from internal damping,
        docs/model.md §19), by mode."""
        out: dict[int, float] = {}
        for c in self.stability_changes:
            if c.onset:
                out.setdefault(c.mode, c.speed)
        return out

    @property
    def damping_ratio(self) -> np.ndarray:
        """Damping ratio zeta = -Re(lambda)/abs(lambda) = delta / sqrt(delta^2 + 4 pi^2), shape (n_speeds, n_modes)."""
        return self.log_dec / np.sqrt(self.log_dec ** 2 + 4.0 * np.pi ** 2)

    def summary(self) -> list[str]:
        """The sweep, the modes tracked, the frequency range, the first critical speeds and the stability."""
        rpm = self.speeds_rpm
        others = [f"{s}/{self.reference} = {r:.4g}" for s, r in self.speed_ratios.items()
                  if s != self.reference and s not in self.fixed_speeds]
        others += [f"{s} fixed at {w * 30 / np.pi:.6g} rpm" for s, w in self.fixed_speeds.items()]
        sweep = f"{len(rpm)} speeds of the {self.reference} spool, {rpm[0]:.6g}-{rpm[-1]:.6g} rpm" if len(rpm) > 1 \
            else f"{rpm[0]:.6g} rpm of the {self.reference} spool"
        lines = [f"{self.rotor_name or 'rotor'}: {self.n_modes} modes tracked at {sweep}",
                 (f"speed ratios {', '.join(others)}; " if others else "") + "excitation lines "
                 + ", ".join(excitation_label(h, s) for s, h, _, _ in self.excitation_lines)]
        if self.mode_count is not None:
            mc = self.mode_count
            lines.append(f"modes: every mode below {mc.margin:g} x {mc.limit_hz:.4g} Hz "
                         f"({excitation_label(mc.harmonic, mc.spool)} at the top speed), at least {MIN_DEFAULT_MODES}")
            if mc.born:
                lines.append(f"{len(mc.born)} mode(s) below {mc.limit_hz:.4g} Hz become oscillating along the sweep "
                             f"(overdamped before; not tracked), the first at {mc.born[0][0] * 30 / math.pi:.6g} rpm")
        f = self.frequencies_hz
        lines.append(f"whirl frequencies {f.min():.4g}-{f.max():.4g} Hz")
        lines += self._critical_lines(5) + [self._stability_line()]
        if self.rigid_modes:
            lines.append("rigid-body modes (no critical speeds): " + ", ".join(str(j + 1) for j in self.rigid_modes))
        if self.beyond_tables:
            lines.append(f"the speeds leave the table of {len(self.beyond_tables)} speed-dependent bearing(s)")
        return lines

    def _critical_lines(self, most: int) -> list[str]:
        """The number of critical speeds and the first ``most`` of them, a line each."""
        cs = self.critical_speeds
        lines = [f"{len(cs)} critical speeds" + (":" if cs else " in the speed range")]
        lines += [f"  {c.speed_rpm:.6g} rpm: {c.line}, mode {c.mode + 1} {c.whirl} at {c.frequency_hz:.4g} Hz, "
                  f"log dec {c.log_dec:.3g}" for c in cs[:most]]
        if len(cs) > most:
            lines.append(f"  ... {len(cs) - most} more (critical_speeds)")
        return lines

    def _stability_line(self) -> str:
        """Stable over the sweep, or where which modes change stability."""
        if self.stability_changes:
            return "stability: " + "; ".join(
                f"mode {c.mode + 1} {'unstable above' if c.onset else 'stable above'} {c.speed_rpm:.6g} rpm"
                for c in self.stability_changes[:3]) + ("; ..." if len(self.stability_changes) > 3 else "")
        if np.any(self.unstable):
            unstable = ", ".join(str(j + 1) for j in np.flatnonzero(self.unstable.any(axis=0)))
            return f"UNSTABLE: modes {unstable} (log dec < 0)"
        return "stable over the sweep (no log dec < 0)"

    def plot(self, ax=None, **options):
        """Draw the Campbell diagram (:func:`rotorred.plots.campbell.draw_campbell`); return the Figure.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            Those of :func:`~rotorred.plots.campbell.draw_campbell`: ``operating_speed`` (rad/s),
            ``title``, ``max_frequency_hz`` (Hz), ``figsize`` (in).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.campbell import draw_campbell

        return draw_campbell(self, ax, **options)

    def to_xarray(self):
        """The diagram as an :class:`xarray.Dataset`.

        Dimensions ``speed`` (coordinate: the reference spool's speed, rad/s), ``mode`` (0-based tracked mode),
        ``spool``, ``critical`` (the critical speeds) and ``stability_change``. Variables ``frequency``
        (speed, mode) in Hz (:attr:`frequencies_hz`), ``log_dec``, ``whirl`` (flags of :data:`WHIRL_LABELS`),
        ``tracking_mac`` (MAC with the previous speed, NaN at the first), ``rigid`` (mode), ``speed_ratio``
        (spool), and ``critical_*`` / ``stability_*`` per crossing (speeds in rad/s of the reference spool,
        frequencies in Hz).
        """
        import xarray as xr

        mac = np.vstack([np.full((1, self.n_modes), np.nan), self.tracking_mac])
        sm, one = ("speed", "mode"), {"units": "1"}
        data = {
            "frequency": (sm, self.frequencies_hz, {"units": "Hz", "long_name": "damped whirl frequency"}),
            "log_dec": (sm, self.log_dec, {**one, "long_name": "logarithmic decrement"}),
            "whirl": (sm, _whirl_codes(self.whirl), _WHIRL_ATTRS),
            "tracking_mac": (sm, mac, {**one, "long_name": "MAC of the mode's shape with the previous speed"}),
            "rigid": ("mode", np.isin(np.arange(self.n_modes), self.rigid_modes).astype(np.int8),
                      {**one, "long_name": "rigid-body mode of a free or singly supported spool (1)"}),
            "speed_ratio": ("spool", np.array(list(self.speed_ratios.values()), float),
                            {**one, "long_name": f"speed over the {self.reference} spool's speed"}),
            **_critical_variables(self.critical_speeds, self.reference),
            **_stability_variables(self.stability_changes, self.reference),
        }
        coords = {"speed": ("speed", self.speeds,
                            {"units": "rad/s", "long_name": f"speed of the {self.reference} spool"}),
                  "mode": ("mode", np.arange(self.n_modes), {**one, "long_name": "tracked mode"}),
                  "spool": ("spool", np.array(list(self.speed_ratios), dtype=object), {**one, "long_name": "spool"})}
        return xr.Dataset(data, coords, attrs={
            "title": "Campbell diagram", "rotor": self.rotor_name, "reference_spool": self.reference,
            "harmonics": np.array(self.harmonics, float)})

    def to_csv(self, path: str | Path) -> Path:
        """Write one row per (speed, mode): ``speed_rpm,mode,frequency_hz,whirl,log_dec,stable``
        (``mode``: the tracked mode numbered from 1, in frequency order at the first speed, as
        :func:`rotorred.mode_shapes` numbers them; ``stable``: ``no`` where the log dec is below ``-NEUTRAL_LOG_DEC``).

        Speeds with 10 significant digits, frequencies with 9, log decrements with 6. The
        diagram itself is drawn by :meth:`plot`.

        Parameters
        ----------
        path : str or Path
            The CSV file to write.

        Returns
        -------
        Path
            ``path``.
        """
        n_s, n_m = self.frequencies.shape
        speed = np.repeat(self.speeds_rpm, n_m)
        mode = np.tile(np.arange(1, n_m + 1), n_s)  # numbered from 1, as rotorred modes numbers them
        # mixed precision: frequency and log dec are formatted here, the speed by the writer (digits=10)
        freq = [f"{v:.9g}" for v in self.frequencies_hz.ravel()]
        log_dec = [f"{v:.6g}" for v in self.log_dec.ravel()]
        stable = ["no" if v < -NEUTRAL_LOG_DEC else "yes" for v in self.log_dec.ravel()]
        return writers.write_csv(path, ["speed_rpm", "mode", "frequency_hz", "whirl", "log_dec", "stable"],
                                 [speed, mode, freq, [str(w) for w in self.whirl.ravel()], log_dec, stable], digits=10)


def _cell(value: float) -> str:
    """A number of the API 617 columns (6 significant digits), empty for NaN (none defined)."""
    return "" if math.isnan(value) else f"{value:.6g}"


#: attributes of a whirl-direction variable: CF flags, the codes' meanings in :data:`WHIRL_LABELS` order
_WHIRL_ATTRS = {"units": "1", "long_name": "whirl direction",
                "flag_values": np.arange(len(WHIRL_LABELS), dtype=np.int8), "flag_meanings": " ".join(WHIRL_LABELS)}


def _whirl_codes(whirl) -> np.ndarray:
    """The index in :data:`WHIRL_LABELS` of each whirl label, same shape (int8)."""
    return np.vectorize(WHIRL_LABELS.index, otypes=[np.int8])(np.asarray(whirl, dtype=object)) if np.size(whirl) \
        else np.zeros(np.shape(whirl), np.int8)


def _critical_variables(cs: Sequence[CriticalSpeed], reference: str) -> dict:
    """The ``critical_*`` variables of :meth:`CampbellResult.to_xarray`, along the dimension ``critical``."""
    one = {"units": "1"}
    return {
        "critical_speed": ("critical", np.array([c.speed for c in cs], float),
                           {"units": "rad/s", "long_name": f"critical speed of the {reference} spool"}),
        "critical_frequency": ("critical", np.array([c.frequency_hz for c in cs], float),
                               {"units": "Hz", "long_name": "whirl frequency at the critical speed"}),
        "critical_spool": ("critical", np.array([c.spool for c in cs], dtype=object),
                           {**one, "long_name": "spool whose excitation line is crossed"}),
        "critical_harmonic": ("critical", np.array([c.harmonic for c in cs], float),
                              {**one, "long_name": "multiple of that spool's speed"}),
        "critical_mode": ("critical", np.array([c.mode for c in cs], np.int64), {**one, "long_name": "mode"}),
        "critical_whirl": ("critical", _whirl_codes([c.whirl for c in cs]), _WHIRL_ATTRS),
        "critical_log_dec": ("critical", np.array([c.log_dec for c in cs], float),
                             {**one, "long_name": "logarithmic decrement at the critical speed"}),
    }


def _stability_variables(sc: Sequence[StabilityChange], reference: str) -> dict:
    """The ``stability_*`` variables of :meth:`CampbellResult.to_xarray`, along the dimension ``stability_change``."""
    one = {"units": "1"}
    return {
        "stability_speed": ("stability_change", np.array([c.speed for c in sc], float),
                            {"units": "rad/s", "long_name": f"speed of the {reference} spool where a mode's log dec "
                                                            "crosses zero"}),
        "stability_mode": ("stability_change", np.array([c.mode for c in sc], np.int64), {**one, "long_name": "mode"}),
        "stability_onset": ("stability_change", np.array([c.onset for c in sc], np.int8),
                            {**one, "long_name": "1: unstable above, 0: stable above"}),
    }


def excitation_label(harmonic: float, spool: str) -> str:
    """``"1× inner"``, ``"0.5× outer"``."""
    return f"{harmonic:g}× {spool}"


# --- whirl direction ---------------------------------------------------------------------------

def _xy_rows(model) -> tuple[np.ndarray, np.ndarray]:
    """The x and y displacement of every node from the model's coordinates (:func:`_take`): their row indices for
    a full model, the rows of ``T`` (n_nodes, m) for a Craig-Bampton model (its interior nodes recovered)."""
    full = isinstance(model, SystemMatrices)
    dofs = model.dofs if full else model.full_dofs
    moving = [n for n in dofs.nodes if not dofs.is_fixed(n, "x")]  # a supported node does not whirl
    x = np.array([dofs.index(n, "x") for n in moving])
    y = np.array([dofs.index(n, "y") for n in moving])
    return (x, y) if full else (model.T[x], model.T[y])


def _take(rows: np.ndarray, A: np.ndarray) -> np.ndarray:
    """``A[rows]`` for index rows, ``rows @ A`` for a matrix of rows."""
    return rows @ A if np.ndim(rows) == 2 else A[rows]


def whirl_direction(modes: np.ndarray, x_rows: np.ndarray, y_rows: np.ndarray) -> list[str]:
    """Classify the whirl of each mode from its node orbits.

    Parameters
    ----------
    modes : ndarray, shape (n, k), complex
        Mode shapes (columns).
    x_rows, y_rows : ndarray of int, shape (n_nodes,), or ndarray, shape (n_nodes, n)
        Rows of the x and y displacement of each node, or matrices giving them from the coordinates
        (a reduced model's rows of T).

    Returns
    -------
    list of str, length k
        ``"forward"`` if the nodes whirling forward (``|X + iY|`` > ``|X - iY|``) carry all but at most 1 % of
        the mode's orbit size sum_n (|X_n|^2 + |Y_n|^2), ``"backward"`` likewise, ``"mixed"`` otherwise,
        ``"planar"`` if every orbit is a straight line (``|X + iY|`` = ``|X - iY|``).
    """
    X, Y = _take(x_rows, modes), _take(y_rows, modes)
    f2, b2 = np.abs(X + 1j * Y) ** 2, np.abs(X - 1j * Y) ** 2
    amp = f2 + b2  # = 2 (|X|^2 + |Y|^2)
    d = (f2 - b2) / np.where(amp > 0, amp, 1.0)
    fwd = np.sum(np.where(d > _PLANAR_TOL, amp, 0.0), axis=0)
    bwd = np.sum(np.where(d < -_PLANAR_TOL, amp, 0.0), axis=0)
    out = []
    for f, b in zip(fwd, bwd):
        if f == 0 and b == 0:
            out.append("planar")
        elif b <= _MIXED_SHARE * (f + b):
            out.append("forward")
        elif f <= _MIXED_SHARE * (f + b):
            out.append("backward")
        else:
            out.append("mixed")
    return out


def modes_at(sm, lines: Mapping[str, SpoolLine], Omega: float, n_modes: int):
    """The lowest ``n_modes`` modes at reference speed ``Omega`` (rad/s) as :func:`campbell` numbers its columns
    at its first speed (the same eigen-solve, the same forward/backward basis of a multiple eigenvalue).

    Parameters
    ----------
    sm : SystemMatrices or ReducedSystem
        The model (:func:`rotorred.model.assembly.system_of`).
    lines : dict of str to SpoolLine
        Each spool's speed line (:meth:`Operating.lines`).
    Omega : float
        Speed of the reference spool (rad/s).
    n_modes : int
        Number of modes (>= 1).

    Returns
    -------
    eigenvalues : ndarray, shape (n_modes,), complex
    shapes : ndarray, shape (n, n_modes), complex
        In the model's coordinates (a reduced model's: recover with its ``T``).
    """
    solver = _Solver(sm, lines, min(sm.n_dof, 2 * n_modes + 4))
    lam, shapes = solver.solve(Omega)
    return lam[:n_modes], shapes[:, :n_modes]


def _canonical_basis(lam: np.ndarray, modes: np.ndarray, x_rows, y_rows) -> np.ndarray:
    """Rotate the eigenvectors of each multiple eigenvalue into forward/backward orbits.

    For a multiple eigenvalue (e.g. an isotropic rotor at rest) any basis of the eigenspace is
    valid and LAPACK returns an arbitrary one. The basis that extremises the forward content
    ||F w||^2 / ||w||^2, F w = (X_n + i Y_n)_n, is the limit of the forward and backward whirl modes as
    the gyroscopic split goes to zero; the most forward vector goes to the higher frequency.
    """
    modes = modes.copy()
    k = len(lam)
    j = 0
    while j < k:
        e = j + 1
        while e < k and abs(lam[e] - lam[j]) <= _DEGENERATE_RTOL * abs(lam[j]):
            e += 1
        if e - j > 1:
            Q = np.linalg.qr(modes[:, j:e])[0]  # orthonormal basis of the eigenspace
            FQ = _take(x_rows, Q) + 1j * _take(y_rows, Q)
            V = np.linalg.eigh(FQ.conj().T @ FQ)[1]  # ascending forward content
            W = Q @ V
            modes[:, j:e] = W / np.linalg.norm(W, axis=0)
        j = e
    return modes


# --- the analysis ------------------------------------------------------------------------------

class _Solver:
    """Eigen-solves of one rotor along the speed axis (matrices assembled once; speed-dependent bearings evaluated
    at each speed)."""

    def __init__(self, sm, lines: Mapping[str, SpoolLine], n_candidates: int):
        self.sm, self.lines = sm, dict(lines)
        self.M = sm.M
        self.n_candidates = n_candidates
        self.x_rows, self.y_rows = _xy_rows(sm)

    def matrices(self, Omega: float) -> tuple[np.ndarray, np.ndarray]:
        """(D, K) at reference speed ``Omega`` (rad/s): damping with the gyroscopic terms, and stiffness, each with
        the speed-dependent bearings at their spools' speeds."""
        speeds = {s: float(line.at(Omega)) for s, line in self.lines.items()}
        return self.sm.damping(speeds), self.sm.stiffness(speeds)

    def solve(self, Omega: float):
        D, K = self.matrices(Omega)
        sol = eigen(self.M, D, K, n_modes=self.n_candidates, max_damping_ratio=WHIRL_MAX_DAMPING_RATIO)
        return sol.eigenvalues, _canonical_basis(sol.eigenvalues, sol.modes, self.x_rows, self.y_rows)

    def local(self, Omega: float, lam0: complex, v0: np.ndarray, max_iter: int = 12):
        """Eigenpair of (lam^2 M + lam D + K) v = 0 near (lam0, v0) by Newton's method, or None.

        Unknowns (v, lam) with the normalisation v0^H v = v0^H v0; each step solves the bordered
        system [[Q(lam), Q'(lam) v], [v0^H, 0]] [dv; dlam] = -[Q(lam) v; 0], Q' = 2 lam M + D.
        Converges quadratically from a close start; returns None if it does not converge (e.g. at a
        multiple eigenvalue, where the bordered matrix is singular).
        """
        D, K = self.matrices(Omega)
        if is_sparse(self.M):
            return _local_sparse(self.M, D, K, (lam0, v0), max_iter)
        n = len(v0)
        lam, v = complex(lam0), v0.astype(complex)
        J = np.zeros((n + 1, n + 1), complex)
        J[n, :n] = v0.conj()
        rhs = np.zeros(n + 1, complex)
        previous = np.inf
        for _ in range(max_iter):
            J[:n, :n] = lam * lam * self.M + lam * D + K
            J[:n, n] = (2.0 * lam * self.M + D) @ v
            rhs[:n] = -(J[:n, :n] @ v)
            try:
                step = np.linalg.solve(J, rhs)
            except np.linalg.LinAlgError:
                return None
            if not np.all(np.isfinite(step)):
                return None
            v, lam = v + step[:n], lam + step[n]
            if _converged(step, v, lam, previous):
                return lam, v / np.linalg.norm(v)
            previous = abs(step[n])
        return None


def _converged(step: np.ndarray, v: np.ndarray, lam: complex, previous: float, floor: float = 1e-9) -> bool:
    """Whether a Newton step of :meth:`_Solver.local` (``step`` = (dv, dlam)) is at round-off level: a residual test
    relative to ||K|| would accept a wrong eigenvalue of a soft mode on a stiff structure; so below 1e-13 |lam|, or
    stagnating below ``floor`` |lam| (the round-off floor of Q(lam) v when ||K|| >> |lam|^2 ||M||)."""
    d = abs(step[-1])
    return bool(np.linalg.norm(step[:-1]) <= 1e-7 * np.linalg.norm(v) and (
        d <= 1e-13 * abs(lam) or (d <= floor * abs(lam) and d >= 0.5 * previous)))


#: the most sparse LUs of one local Newton solve (:func:`_local_sparse`); a dense one takes up to 12 Newton steps
_MAX_FACTORISATIONS = 5
#: a sparse model's local Newton solve stagnates at up to this relative step: the round-off floor of Q(lam) v grows
#: with ||K|| / (|lam|^2 ||M||), and a fine mesh is stiff (measured 1e-9 to 6e-8 for the lowest mode, 15 Hz, of the
#: rig refined(128))
_SPARSE_FLOOR = 1e-7


def _local_sparse(M, D, K, start: tuple[complex, np.ndarray], max_iter: int):
    """:meth:`_Solver.local` of a sparse model: the bordered Newton system factorised by a sparse LU at the start
    only (a chord method: the residual is exact, so the fixed point is; it converges linearly at a rate of the
    distance from the start), factorised again where a step does not shrink the last one by half, at most
    ``_MAX_FACTORISATIONS`` times (a start that Newton's method does not take to a root quickly: None)."""
    lam0, v0 = start
    lam, v = complex(lam0), v0.astype(complex)
    border = sp.csr_array(v0.conj()[None, :])
    previous, lu, factorisations = np.inf, None, 0
    for _ in range(3 * max_iter):
        Q = (lam * lam) * M + lam * D + K
        if lu is None:
            factorisations += 1
            if factorisations > _MAX_FACTORISATIONS:
                return None
            column = sp.csr_array(((2.0 * lam) * (M @ v) + D @ v)[:, None])
            try:
                lu = spla.splu(sp.block_array([[Q, column], [border, None]], format="csc"), permc_spec="MMD_AT_PLUS_A")
            except RuntimeError:  # exactly singular
                return None
        step = lu.solve(np.concatenate([-(Q @ v), [0.0]]))
        if not np.all(np.isfinite(step)):
            return None
        v, lam = v + step[:-1], lam + step[-1]
        if _converged(step, v, lam, previous, _SPARSE_FLOOR):
            return lam, v / np.linalg.norm(v)
        if abs(step[-1]) > 0.5 * previous:
            lu = None  # the chord is too far from the root: a Newton step
        previous = abs(step[-1])
    return None


def _assign(prev_modes, prev_freq, lam, modes):
    """Columns of ``modes`` continuing each of ``prev_modes`` (one-to-one, max total MAC)."""
    m = mac(prev_modes, modes)
    jump = np.abs(lam.imag[None, :] - prev_freq[:, None]) / prev_freq[:, None]
    rows, cols = linear_sum_assignment(-m + _FREQ_TIEBREAK * jump)
    return cols[np.argsort(rows)], m[rows, cols][np.argsort(rows)]


def campbell(model, operating: Operating, *, n_modes: int | None = None,
             harmonics: Sequence[float] = (1,)) -> CampbellResult:
    """Campbell diagram of ``model`` along the speed line ``operating``, with critical speeds.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        The rotor (assembled here), its assembled model, or a Craig-Bampton model
        (:func:`rotorred.linear.reduction.reduce_rotor`) solved in place of the full one; whirl directions are
        then read from the recovered physical shapes (T v). Read through
        :func:`rotorred.model.assembly.system_of`.
    operating : Operating
        The speed line (:meth:`Operating.line`) or point (:meth:`Operating.point`): its ``Omega``, shape
        (n_speeds,), the reference spool's speeds (rad/s), >= 0 and strictly increasing, is the x-axis; every
        spool turns at ``a_s Omega + b_s`` by :meth:`Operating.lines` (a stated ratio, a fixed speed, or the
        ratio of the nominal speeds). One speed gives the whirl frequencies, directions and damping there (no
        crossing can be found, so no critical speed).
    n_modes : int, optional
        Number of modes tracked: the lowest ``n_modes`` at ``Omega[0]``. Default: every mode below
        ``DEFAULT_MARGIN`` x the highest excitation frequency at the top speed (:func:`default_mode_count`),
        and more if, at a grid speed, a mode below that frequency (without the margin) is not among them;
        the result's ``mode_count`` says how many and why.
    harmonics : sequence of float
        Excitation lines h x Omega_s (rad/s) for each h (> 0, -) and each turning spool s (default 1x); a spool
        at a fixed speed gives horizontal lines.

    Returns
    -------
    CampbellResult

    Raises
    ------
    InputError
        If ``model`` or ``operating`` is not one the analysis takes, the speeds are not increasing, a spool's
        speed does not follow (:meth:`Operating.lines`), or ``n_modes`` or a harmonic is out of range.
    """
    Omega, h, lines, reference, sm = _setup(model, operating, harmonics)
    n_available = sm.n_dof  # at most one frequency per DOF
    count = None
    if n_modes is None:
        count = _mode_count(sm, lines, Omega, h, DEFAULT_MARGIN)
        n_modes = count.n_modes
    else:
        n_modes = checks.integer("n_modes", n_modes, ge=1)
        if n_modes > n_available:
            checks.fail("n_modes", n_modes, f"must be <= {n_available}, the number of DOFs")
    stage("whirl frequencies of %s at %d speed%s, %d modes tracked (%d DOFs)", sm.name or "the rotor", len(Omega),
          "s" * (len(Omega) > 1), n_modes, n_available)
    solver = _Solver(sm, lines, min(n_available, 2 * n_modes + 4))
    solved = {}  # eigen-solves of the grid speeds, kept for a second tracking with more modes
    while True:
        cover = None if count is None else (count.limit, count.margin * count.limit)
        lam_all, shapes, tracking, missed, born = _track(solver, Omega, n_modes, cover, solved)
        if count is not None:
            count = replace(count, born=born)
        if missed is None or n_modes >= n_available:
            break
        i, needed = missed  # a mode below the limit left out (the modes' order changed): track more
        n_modes = min(n_available, max(n_modes + 1, needed))
        count = replace(count, n_modes=n_modes, grown_at=float(Omega[i]))
        if n_modes + 4 > solver.n_candidates < n_available:  # too few candidates kept: solve again
            solver.n_candidates = min(n_available, 2 * n_modes + 4)
            solved.clear()

    n_s = len(Omega)
    freq = lam_all.imag
    log_dec = -2.0 * np.pi * lam_all.real / freq
    whirl = np.array([whirl_direction(s, solver.x_rows, solver.y_rows) for s in shapes], dtype="<U8")

    null = rigid_body_motions(sm)
    is_rigid = np.array([rigid_body_share(sm.M, null, v) > RIGID_SHARE for v in shapes])  # (n_s, n_modes)
    crit = []
    for spool, hh, slope, offset, same in _distinct_lines(lines, h):
        g = freq - (slope * Omega + offset)[:, None]
        for j in range(n_modes):
            for i in range(n_s - 1):
                if is_rigid[i, j] or is_rigid[i + 1, j]:
                    continue  # a rigid-body mode has no critical speed
                if g[i, j] == 0 and i > 0:
                    continue  # counted as the right end of interval i - 1
                if g[i, j] * g[i + 1, j] > 0:
                    continue
                found = _refine(solver, Omega, lam_all, shapes, whirl, (i, j), (spool, hh, slope, offset))
                if found is not None:
                    crit.append(replace(found, same_line=same))
    crit.sort(key=lambda c: (c.speed, c.mode))
    changes = _stability_changes(solver, Omega, lam_all, shapes, whirl, log_dec, is_rigid)
    return CampbellResult(speeds=Omega, frequencies=freq, log_dec=log_dec, whirl=whirl, tracking_mac=tracking,
                          critical_speeds=tuple(crit), reference=reference,
                          speed_ratios={s: line.slope for s, line in lines.items()},
                          harmonics=h, rotor_name=sm.name,
                          rigid_modes=tuple(int(j) for j in np.flatnonzero(is_rigid[0])),
                          stability_changes=changes, beyond_tables=_beyond_tables(sm, lines, Omega),
                          mode_count=count,
                          fixed_speeds={s: line.offset for s, line in lines.items() if line.how == "fixed"},
                          operating=operating)


def default_mode_count(model, operating: Operating, *, harmonics: Sequence[float] = (1,),
                       margin: float = DEFAULT_MARGIN) -> ModeCount:
    """How many modes :func:`campbell` tracks by default: every mode below ``margin`` x the highest excitation
    frequency of the sweep.

    The highest excitation frequency is the largest h Omega_s over the harmonics h and the turning spools s at
    the top speed Omega_top of the reference spool (Omega_s = a_s Omega_top + b_s, :meth:`Operating.lines`). A
    whirl frequency moves with speed (gyroscopic stiffening of forward whirl and softening of backward whirl,
    speed-dependent bearings), so the modes below ``margin`` x that frequency are counted from the eigenvalues at
    the first and at the last speed, and the larger count is kept (at least ``MIN_DEFAULT_MODES``, at most the
    number of oscillating modes at those speeds). :func:`campbell` then checks at every grid speed that no
    untracked mode lies below the highest excitation frequency, and tracks more if one does
    (:attr:`ModeCount.grown_at`); this function solves the two speeds only.

    Parameters
    ----------
    model, operating, harmonics
        As for :func:`campbell` (speeds in rad/s).
    margin : float
        Multiple of the highest excitation frequency below which every mode is counted (>= 1, -);
        default ``DEFAULT_MARGIN``.

    Returns
    -------
    ModeCount

    Raises
    ------
    InputError
        As :func:`campbell`, or if ``margin`` < 1.
    """
    Omega, h, lines, _, sm = _setup(model, operating, harmonics)
    return _mode_count(sm, lines, Omega, h, checks.number("margin", margin, ge=1.0))


def _setup(model, operating, harmonics):
    """The model (:func:`system_of`), the checked reference speeds (rad/s, strictly increasing), harmonics
    (sorted, distinct), each spool's speed line (:meth:`Operating.lines`) and the reference spool."""
    sm = system_of(model, sparse_ok=True)
    operating = checked_operating(operating)
    operating.speeds(sm)  # refuses a profile
    Omega = checks.vector("operating.Omega", operating.Omega.tolist(), "rad/s", min_len=1, ge=0.0, increasing=True)
    h = tuple(sorted(set(float(v) for v in checks.vector("harmonics", harmonics, gt=0.0))))
    lines = operating.lines(sm)
    return Omega, h, lines, operating.reference_of(sm), sm


def _mode_count(sm, lines: Mapping[str, SpoolLine], Omega: np.ndarray, h: tuple[float, ...],
                margin: float) -> ModeCount:
    """:func:`default_mode_count` of the model ``sm`` (one full eigen-solve at the first and at the last speed)."""
    top = float(Omega[-1])
    at_top = {s: float(line.at(top)) for s, line in lines.items()}
    spool, w = max(((s, w) for s, w in at_top.items() if w > 0), key=lambda sw: sw[1], default=("", 0.0))
    limit = max(h) * w
    solver = _Solver(sm, lines, sm.n_dof)
    ends = tuple(sorted({float(Omega[0]), top}))
    below, available = [], []
    for W in ends:  # a sparse model: the lowest modes, every one below the limit (modal.eigen)
        lam = eigen(solver.M, *solver.matrices(W), max_damping_ratio=WHIRL_MAX_DAMPING_RATIO,
                    below=margin * limit, n_modes=MIN_DEFAULT_MODES if is_sparse(solver.M) else None).eigenvalues
        below.append(int(np.sum(lam.imag < margin * limit)))
        available.append(sm.n_dof if is_sparse(solver.M) else len(lam))
    n = max(1, min(max(MIN_DEFAULT_MODES, *below), *available))
    return ModeCount(n_modes=n, limit=limit, margin=margin, spool=spool, harmonic=max(h), top_speed=top,
                     speeds=ends, below=tuple(below))


def _track(solver: _Solver, Omega: np.ndarray, n_modes: int, cover: tuple[float, float] | None, solved: dict):
    """The lowest ``n_modes`` modes at ``Omega[0]`` followed by MAC (:func:`_assign`) along ``Omega``; ``solved``
    holds the eigen-solve of each grid speed (index: (eigenvalues, modes)) and is filled where it has none.

    Returns (eigenvalues (n_s, n_modes), shapes per speed, tracking MAC (n_s - 1, n_modes), missed, born). With
    ``cover`` = (limit, covered) (rad/s), ``missed`` is (first speed index where an untracked mode lies below
    ``limit``, the most modes below ``covered`` at a speed), or None if every mode below ``limit`` is tracked;
    only modes that descend from the first speed's count (:func:`_descends`): ``born`` lists the others below
    ``limit`` where each lineage first appears, (speed, frequency (rad/s), damping ratio), as
    :attr:`ModeCount.born`.
    """
    n_s = len(Omega)
    lam_all = np.empty((n_s, n_modes), complex)
    shapes = []
    tracking = np.ones((n_s - 1, n_modes))
    first, needed, born = None, 0, []
    cur = descends = None
    for i in range(n_s):
        if i not in solved:
            solved[i] = solver.solve(Omega[i])
        lam, modes = solved[i]
        if len(lam) < n_modes:
            checks.fail("n_modes", n_modes, f"must be <= {len(lam)}, the number of oscillating modes at "
                        f"{Omega[i]:g} rad/s")
        if i == 0:
            cols = np.arange(n_modes)
        else:
            cols, tracking[i - 1] = _assign(cur, lam_all[i - 1].imag, lam, modes)
        lam_all[i], cur = lam[cols], modes[:, cols]
        shapes.append(cur)
        if cover is not None:
            previous = None if i == 0 else solved[i - 1]
            descends, new = _descends(previous, descends, modes, cols)
            untracked = np.ones(len(lam), bool)
            untracked[cols] = False
            if first is None and np.any(lam.imag[untracked & descends] < cover[0]):
                first = i
            born += [(float(Omega[i]), float(lam[j].imag), float(-lam[j].real / abs(lam[j])))
                     for j in np.flatnonzero(new & untracked & (lam.imag < cover[0]))]
            needed = max(needed, int(np.sum(lam.imag[descends] < cover[1])))
    return lam_all, shapes, tracking, None if first is None else (first, needed), tuple(born)


#: a mode at a grid speed continues a mode of the speed before if their MAC is at least this (else it was not
#: oscillating there: an overdamped pair turned into a whirl mode)
BORN_MAC = 0.5


def _descends(previous, descends_before, modes: np.ndarray, tracked: np.ndarray):
    """Which modes of a grid speed descend from the first speed's oscillating modes, and which begin there.

    A mode descends if it continues (MAC >= :data:`BORN_MAC`, its best match) a mode of the speed before that
    descends; every mode of the first speed (``previous`` None) and every tracked column ``tracked`` descends. A
    mode matching none of the speed before's begins there (``new``); one continuing a mode that began later
    neither descends nor begins. Returns (descends, new), boolean arrays of shape (n_modes_here,).
    """
    n = modes.shape[1]
    if previous is None:
        return np.ones(n, bool), np.zeros(n, bool)
    m = mac(previous[1], modes)  # (n_before, n)
    best, match = m.max(axis=0), m.argmax(axis=0)
    continues = best >= BORN_MAC
    descends = continues & descends_before[match]
    descends[tracked] = True
    return descends, ~continues & ~descends


def _beyond_tables(sm, lines: Mapping[str, SpoolLine], Omega: np.ndarray) -> tuple[tuple[int, float, float, str], ...]:
    """The speed-dependent bearings of ``sm`` whose spool's speeds along the sweep leave their table."""
    out = []
    for t in sm.tables:
        spool_speeds = lines[t.spool].at(Omega)
        if not (t.table.covers(float(spool_speeds.min())) and t.table.covers(float(spool_speeds.max()))):
            out.append((t.table.node, t.table.speeds[0], t.table.speeds[-1], t.table.extrapolate))
    return tuple(out)


#: |log dec| at most this is neutral: an undamped mode, whose computed log dec is round-off (up to 2e-9
#: measured on a stiff undamped rotor, tests/test_campbell.py); a damping ratio of 1.6e-7
NEUTRAL_LOG_DEC = 1e-6
#: a tracked mode with more than this share of its kinetic energy in the null space of K is a rigid-body mode
RIGID_SHARE = 0.5


def rigid_body_share(M: np.ndarray, null: np.ndarray, modes: np.ndarray) -> np.ndarray:
    """Share of each mode's kinetic energy in the rigid-body motions ``null`` (:func:`rigid_body_motions`),
    ``|null^T M v|^2 / (v^H M v)``: 1 for a rigid-body mode, 0 for a mode M-orthogonal to them (every mode
    of a spool held by bearings). Shape (n_modes,); ``modes`` shape (n, n_modes), complex."""
    if null.shape[1] == 0:
        return np.zeros(modes.shape[1])
    Mv = M @ modes
    energy = np.real(np.einsum("ij,ij->j", modes.conj(), Mv))
    return np.sum(np.abs(null.T @ Mv) ** 2, axis=0) / energy


def _distinct_lines(lines: Mapping[str, SpoolLine], harmonics: tuple[float, ...]):
    """(spool, h, slope, offset, other labels on the line) of each distinct excitation line h x Omega_s =
    h a_s Omega + h b_s of a turning spool: lines of equal slope and offset (1x inner and 1x outer at speed ratio 1)
    are one line, crossed once."""
    out = []
    for s, line in lines.items():
        if line.slope <= 0 and line.offset <= 0:
            continue  # a spool at rest along the whole line excites nothing
        for hh in harmonics:
            slope, offset = hh * line.slope, hh * line.offset
            for k, (_, _, other, other_offset, same) in enumerate(out):
                if math.isclose(slope, other, rel_tol=1e-12) and math.isclose(offset, other_offset, rel_tol=1e-12):
                    out[k] = out[k][:4] + ((*same, excitation_label(hh, s)),)
                    break
            else:
                out.append((s, hh, slope, offset, ()))
    return out


def _root(solver: _Solver, Omega, lam_grid, shapes, i: int, j: int, f):
    """Speed W in [Omega_i, Omega_i+1] where ``f(lam_j(W), W)`` = 0 (Brent), mode j tracked by MAC; returns
    (W, lam, shape) there.

    At intermediate speeds the eigenpair is found by Newton's method started from the linear
    interpolation of the bracketing eigenpairs; it is accepted if its shape has MAC >= 0.9 with a
    bracketing shape, otherwise the full eigenproblem is solved and the candidate with the largest
    MAC to the bracketing shapes is taken.
    """
    a, b = Omega[i], Omega[i + 1]
    va, vb = shapes[i][:, j], shapes[i + 1][:, j]
    vb = vb * np.exp(-1j * np.angle(np.vdot(va, vb)))  # align phases for interpolation
    ends = np.column_stack([va, vb])
    found = {}

    def pick(W):
        t = (W - a) / (b - a)
        lam0 = (1 - t) * lam_grid[i, j] + t * lam_grid[i + 1, j]
        pair = solver.local(W, lam0, (1 - t) * va + t * vb)
        if pair is None or mac(ends, pair[1][:, None]).max() < 0.9:
            lam, modes = solver.solve(W)
            k = int(np.argmax(mac(ends, modes).sum(axis=0)))
            pair = lam[k], modes[:, k]
        found[W] = pair
        return pair[0]

    def g(W):
        if W == a:
            return f(lam_grid[i, j], a)
        if W == b:
            return f(lam_grid[i + 1, j], b)
        return f(pick(W), W)

    # rtol 1e-10: the eigenvalues themselves carry ~1e-12 relative roundoff
    root = brentq(g, a, b, xtol=1e-12 * max(b, 1.0), rtol=1e-10)
    if root == a:
        return root, lam_grid[i, j], shapes[i][:, j]
    if root == b:
        return root, lam_grid[i + 1, j], shapes[i + 1][:, j]
    if root not in found:
        pick(root)
    return (root, *found[root])


def _stability_changes(solver: _Solver, Omega, lam_grid, shapes, whirl, log_dec, is_rigid):
    """Where each tracked mode's log dec changes sign between grid speeds: the root of Re(lambda) (:func:`_root`).

    A change is between two grid speeds where the log dec is beyond round-off (|log dec| > ``NEUTRAL_LOG_DEC``) with
    opposite signs, not round-off about an undamped mode's zero; grid speeds between them within round-off of zero
    (a root on the grid itself) are crossed: the root is refined in the first interval where Re(lambda) changes sign.
    """
    out = []
    for j in range(log_dec.shape[1]):
        clear = [i for i in range(len(Omega)) if abs(log_dec[i, j]) > NEUTRAL_LOG_DEC]
        for i, k in zip(clear[:-1], clear[1:]):
            if log_dec[i, j] * log_dec[k, j] > 0 or is_rigid[i:k + 1, j].any():
                continue
            at = next(m for m in range(i, k) if lam_grid[m + 1, j].real == 0.0
                      or np.sign(lam_grid[m, j].real) != np.sign(lam_grid[m + 1, j].real))
            root, lam, _ = _root(solver, Omega, lam_grid, shapes, at, j, lambda lam, W: lam.real)
            w = str(whirl[i, j]) if len(set(whirl[i:k + 1, j])) == 1 else "mixed"
            out.append(StabilityChange(float(root), j, float(lam.imag), w, bool(log_dec[i, j] > 0)))
    return tuple(sorted(out, key=lambda c: (c.speed, c.mode)))


#: a refined crossing whose whirl frequency is off its excitation line by more than this share of |lambda| is none:
#: the sign change that bracketed it was a jump of the tracked curve between two modes (Brent's method then converges
#: on the jump), seen where round-off splits a free spool's zero eigenvalues into a varying count of tiny whirl
#: frequencies (docs/model.md §24)
_CROSSING_TOL = 1e-6


def _refine(solver: _Solver, Omega, lam_grid, shapes, whirl, at: tuple[int, int], line) -> CriticalSpeed | None:
    """The crossing of whirl curve j with the excitation line ``line`` = (spool, harmonic, slope, offset), frequency
    slope x Omega + offset, in [Omega_i, Omega_i+1], ``at`` = (i, j) (:func:`_root`); None where the root found is
    not on the line (a jump of the tracked curve, :data:`_CROSSING_TOL`)."""
    (i, j), (spool, harmonic, slope, offset) = at, line
    root, lam, shape = _root(solver, Omega, lam_grid, shapes, i, j, lambda lam, W: lam.imag - (slope * W + offset))
    if abs(lam.imag - (slope * root + offset)) > _CROSSING_TOL * abs(lam):
        return None
    if whirl[i, j] == whirl[i + 1, j]:
        label = str(whirl[i, j])  # also right inside a multiple eigenvalue, where the shape is any basis vector
    else:
        label = whirl_direction(shape[:, None], solver.x_rows, solver.y_rows)[0]
    return CriticalSpeed(speed=float(root), spool=spool, harmonic=harmonic, mode=j, frequency=float(lam.imag),
                         whirl=label, log_dec=float(-2.0 * np.pi * lam.real / lam.imag))
