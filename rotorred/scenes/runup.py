"""Run a run-up (or coast-down) scene: the transient at the ``[runup]`` speeds, and what it shows.

:func:`run_runup` steps a scene's model through its speed profile, and :func:`runup` does the same from Python for a
model and an :class:`rotorred.model.operating.Operating` profile (a scene built from them). Either steps the model
(:mod:`rotorred.transient.ramp`) from rest or from the steady state at the initial speeds, then:

* order tracks of every spool's ``runup.orders`` at every recorded DOF (angle-domain resampling,
  :mod:`rotorred.signals.orders`), with block lengths that hold whole revolutions of both spools
  when their speed ratio is a fixed small fraction (9/7: 28 inner = 36 outer revolutions), so the
  other spool's lines fall on bins the Hann window nulls;
* the overall amplitude (largest orbit radius over two revolutions, one revolution apart) against the
  reference spool's speed, per node;
* a waterfall of the table DOF (:mod:`rotorred.signals.waterfall`);
* orbit snapshots at ``runup.orbits_hz``;
* rub intervals with their onset and end speeds;
* the Campbell critical speeds in the swept range (:func:`rotorred.linear.campbell.campbell`, at the
  profile's final speed ratio), for the amplitude plot.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from rotorred import checks
from rotorred.model.operating import Operating, checked as checked_operating
from rotorred.progress import INTERRUPTS, interrupt_name, stage
from rotorred.results import Result
from rotorred.scenes.run import SceneModel, build_model, explain_divergence, settled_state, table_dof
from rotorred.scenes.built import built_scene, checked_loads, load_nodes, plates_on, recorded_nodes, rotor_model
from rotorred.scenes.schema import OutputSpec, RunupSpec, Scene, SolverSpec
from rotorred.signals.orders import OrderTrack, angle_blocks, order_tracks, overall_amplitude
from rotorred.signals.waterfall import Waterfall, waterfall

#: a speed ratio counts as a fixed fraction p/q when it is one to this (relative) and q <= RATIO_DENOMINATOR
RATIO_RTOL, RATIO_DENOMINATOR = 1e-9, 12
#: contacts fewer than this many revolutions of the reference spool apart belong to one rub interval (impacts
#: recur every few revolutions in a rub, e.g. once in 2-3 at 70-80 Hz on the rig)
RUB_GAP_REVS = 10
#: speeds of the Campbell diagram behind the critical speeds
CAMPBELL_SPEEDS = 41


@dataclass(frozen=True)
class RubInterval:
    """A stretch of a run-up in which a plate touches at least once every :data:`RUB_GAP_REVS` revolutions of the
    reference spool.

    Attributes
    ----------
    plate : int
    node : int
    t_start, t_end : float
        First and last contact (s).
    speed_start, speed_end : dict of str to float
        Spool speeds there (Hz).
    impacts : int
        Contact onsets in the stretch.
    """

    plate: int
    node: int
    t_start: float
    t_end: float
    speed_start: dict
    speed_end: dict
    impacts: int


@dataclass(frozen=True)
class OrbitSnapshot:
    """The orbit of a node over two revolutions of the reference spool around the time it passes ``speed_hz``.

    Attributes
    ----------
    speed_hz : float
        Reference spool speed (Hz).
    t : float
        When the reference spool passes it (s).
    node : int
    x, y : ndarray
        Displacements (m) over the snapshot.
    """

    speed_hz: float
    t: float
    node: int
    x: np.ndarray
    y: np.ndarray


@dataclass(frozen=True, repr=False)
class RunupResult(Result):
    """A run-up scene's record and its analyses (:func:`run_runup`).

    Attributes
    ----------
    scene : Scene
    t : ndarray, shape (n,)
        Record times (s).
    speeds : dict of str to ndarray, shape (n,)
        Spool speeds at the record times (rad/s).
    outputs : dict of (int, str) to ndarray, shape (n,)
        Recorded DOFs (m or rad).
    contacts : tuple of ContactHistory
    tracks : tuple of OrderTrack
        Every spool's orders at every recorded DOF (``track.spool``, ``track.order``, ``dof`` in :attr:`track_dofs`).
    track_dofs : tuple of (int, str)
        The recorded DOF of each track.
    overall : dict of int to (ndarray, ndarray)
        Per node with x and y: (reference spool speed (rad/s), largest orbit radius (m)) per block.
    waterfall : Waterfall or None
        Of the table DOF.
    waterfall_dof : (int, str)
    orbits : tuple of OrbitSnapshot
    rubs : tuple of RubInterval
    critical_speeds : tuple of CriticalSpeed
        Critical speeds in the swept range of the reference spool (``speed`` in rad/s of the reference).
    campbell_ratio : dict of str to float
        Speed ratios of the Campbell diagram (the profile's final ones).
    campbell : CampbellResult
        The Campbell diagram of the swept range (:data:`CAMPBELL_SPEEDS` speeds of the reference spool).
    margins : tuple of SeparationMargin
        The API 684 amplification factor and separation margin of each critical speed
        (:func:`rotorred.linear.margins.separation_margins`; against the rotor file's operating range of the reference
        spool, without a verdict when it gives none).
    model_label : str
    n_steps : int
    counters : dict
    build_time, solve_time, analysis_time : float
        Wall times (s).
    incomplete : str or None
        Why the run stops early (a diverged or interrupted transient); the analyses cover the record up to then.
    interrupt : str
        The signal that ended the transient ("SIGINT", "SIGTERM": :func:`run_runup`'s ``interrupts``), or "".
    """

    scene: Scene
    t: np.ndarray
    speeds: dict
    outputs: dict
    contacts: tuple
    tracks: tuple
    track_dofs: tuple
    overall: dict
    waterfall: Waterfall | None
    waterfall_dof: tuple
    orbits: tuple
    rubs: tuple
    critical_speeds: tuple
    campbell_ratio: dict
    campbell: object
    margins: tuple
    model_label: str
    n_steps: int
    counters: dict
    build_time: float
    solve_time: float
    analysis_time: float
    incomplete: str | None = None
    interrupt: str = ""

    @property
    def reference(self) -> str:
        return self.scene.runup.reference

    def summary(self) -> list[str]:
        """The scene, the speeds swept, the steps, the largest orbit radius per node, the critical speeds, the rubs."""
        from rotorred.transient.results import shorten

        sc, hz = self.scene, 1.0 / (2 * math.pi)
        speeds = ", ".join(f"{s} {w[0] * hz:.4g} -> {w[-1] * hz:.4g} Hz" for s, w in self.speeds.items()) if len(
            self.t) else "no record"
        lines = [shorten(f"scene {sc.name}: {sc.description}"),
                 shorten(f"run-up: {speeds} in {self.t[-1] if len(self.t) else 0.0:.4g} s; {self.n_steps} steps of "
                         f"{sc.solver.dt:g} s, {self.counters.get('us_per_step', 0.0):.2f} µs/step"),
                 self.model_label.split(" (")[0]]  # its boundary nodes are a list
        if self.incomplete:
            lines.append(shorten(f"INCOMPLETE: {self.incomplete}"))
        for node, (speed, radius) in sorted(self.overall.items())[:4]:
            if len(radius):
                k = int(np.argmax(radius))
                lines.append(f"node {node}: largest orbit radius {1e6 * radius[k]:.4g} µm at {self.reference} "
                             f"{speed[k] * hz:.4g} Hz ({60 * speed[k] * hz:.5g} rpm)")
        lines.append(shorten(f"{len(self.tracks)} order tracks; critical speeds in the range: " + (", ".join(
            f"1x {c.spool} {c.whirl} {c.speed * hz:.4g} Hz" for c in self.critical_speeds) or "none")))
        if sc.plates:
            lines.append(shorten("rub intervals: " + (", ".join(
                f"plate {r.plate} {r.speed_start[self.reference]:.4g}-{r.speed_end[self.reference]:.4g} Hz"
                for r in self.rubs) if self.rubs else "none")))
        lines.append(f"model built in {self.build_time:.3g} s, solved in {self.solve_time:.3g} s, analysed in "
                     f"{self.analysis_time:.3g} s")
        return lines

    def plot(self, ax=None, kind: str = "amplitude", **options):
        """Draw one of the run-up's figures as ``rotorred run`` writes it (:func:`rotorred.plots.runup.draw_runup`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        kind : {"amplitude", "orders", "waterfall", "orbits"}
            "amplitude" (default: the largest orbit radius and the 1x tracks (µm) against the reference speed (Hz),
            per node, with the critical speeds and rubs), "orders" (every order track), "waterfall" (of the table
            DOF) or "orbits" (the snapshots at ``runup.orbits_hz``).
        **options
            ``node`` (int) of "amplitude" into a given ``ax``, ``dof`` of "orders".

        Returns
        -------
        matplotlib.figure.Figure

        Raises
        ------
        InputError
            If ``kind`` is unknown, or the result has no data for it.
        """
        from rotorred.plots.runup import draw_runup

        return draw_runup(self, kind, ax, **options)

    def to_xarray(self):
        """The run-up as an :class:`xarray.Dataset`.

        The record (:func:`rotorred.transient.results.record_dataset`: dimensions ``time``, ``output``, ``plate``)
        with ``speed`` (spool, time) in rad/s; the order tracks (dimensions ``track``, ``block``; shorter tracks
        padded with NaN): ``track_time`` (s), ``track_speed`` (rad/s, of the track's spool), ``track_amplitude``
        (m) and ``track_phase`` (rad), with ``track_spool``, ``track_order``, ``track_output``; the largest orbit
        radius ``overall_radius`` (orbit_node, overall_block) in m against ``overall_speed`` (rad/s, reference
        spool); the waterfall ``waterfall_amplitude`` (segment, waterfall_frequency) in m at ``segment_time`` (s);
        the critical speeds (dimension ``critical``: ``critical_speed`` and ``critical_frequency`` in rad/s,
        ``critical_log_dec``, ``critical_spool``, ``critical_whirl``); the rub intervals (dimension ``rub``:
        ``rub_plate``, ``rub_node``, ``rub_t_start``, ``rub_t_end`` (s), ``rub_impacts``, ``rub_speed_start`` and
        ``rub_speed_end`` (rub, spool) in Hz). Tracks at rotations go into ``rotation_track_*`` (rad). The orbit
        snapshots are slices of the record (not repeated).
        """
        from rotorred.transient.results import dof_groups, record_dataset

        ds = record_dataset(self.t, self.outputs, self.contacts, {
            "title": f"run-up {self.scene.name}", "scene": self.scene.name, "reference_spool": self.reference,
            "model": self.model_label, "n_steps": int(self.n_steps), "incomplete": self.incomplete or "",
            "campbell_ratio": ", ".join(f"{s} {r:.9g}" for s, r in self.campbell_ratio.items())})
        spools = list(self.speeds)
        data = {"speed": (("spool", "time"), np.array([self.speeds[s] for s in spools], float).reshape(
            len(spools), len(self.t)), {"units": "rad/s", "long_name": "spool speed"})}
        coords = {"spool": ("spool", np.array(spools, dtype=object), {"units": "1", "long_name": "spool"})}
        for prefix, units, dofs in dof_groups(list(dict.fromkeys(self.track_dofs))):
            data.update(self._track_variables(f"{prefix}track", [
                (tr, d) for tr, d in zip(self.tracks, self.track_dofs) if d in dofs], units))
        if self.overall:
            nodes = sorted(self.overall)
            coords["orbit_node"] = ("orbit_node", np.array(nodes, np.int64), {"units": "1", "long_name": "node"})
            data["overall_speed"] = ("overall_block", self.overall[nodes[0]][0], {
                "units": "rad/s", "long_name": f"mean speed of the {self.reference} spool over two revolutions"})
            data["overall_radius"] = (("orbit_node", "overall_block"), np.array([self.overall[n][1] for n in nodes]),
                                      {"units": "m", "long_name": "largest orbit radius over two revolutions"})
        w = self.waterfall
        if w is not None:
            units = "rad" if self.waterfall_dof[1].startswith("t") else "m"
            coords["waterfall_frequency"] = ("waterfall_frequency", w.frequencies, {"units": "Hz",
                                                                                    "long_name": "bin frequency"})
            data["segment_time"] = ("segment", w.t, {"units": "s", "long_name": "centre time of the segment"})
            data["waterfall_amplitude"] = (("segment", "waterfall_frequency"), w.amplitudes, {"units": units, (
                "long_name"): f"amplitude of {self.waterfall_dof[0]}:{self.waterfall_dof[1]} (Hann segments of "
                              f"{w.segment:.6g} s)"})
        cs = self.critical_speeds
        if cs:
            data.update({
                "critical_speed": ("critical", [c.speed for c in cs], {"units": "rad/s", "long_name": (
                    f"critical speed of the {self.reference} spool")}),
                "critical_frequency": ("critical", [c.frequency for c in cs], {"units": "rad/s", "long_name": (
                    "whirl frequency")}),
                "critical_log_dec": ("critical", [c.log_dec for c in cs], {"units": "1", "long_name": "log dec"}),
                "critical_spool": ("critical", np.array([c.spool for c in cs], dtype=object), {"units": "1", (
                    "long_name"): "spool of the 1x line"}),
                "critical_whirl": ("critical", np.array([c.whirl for c in cs], dtype=object), {"units": "1", (
                    "long_name"): "whirl"})})
        if self.rubs:
            rubs = self.rubs
            data.update({
                "rub_plate": ("rub", [r.plate for r in rubs], {"units": "1", "long_name": "plate"}),
                "rub_node": ("rub", [r.node for r in rubs], {"units": "1", "long_name": "node of the plate"}),
                "rub_t_start": ("rub", [r.t_start for r in rubs], {"units": "s", "long_name": "first contact"}),
                "rub_t_end": ("rub", [r.t_end for r in rubs], {"units": "s", "long_name": "last contact"}),
                "rub_impacts": ("rub", [r.impacts for r in rubs], {"units": "1", "long_name": "contact onsets"}),
                "rub_speed_start": (("rub", "spool"), [[r.speed_start[s] for s in spools] for r in rubs], {
                    "units": "Hz", "long_name": "spool speed at the first contact"}),
                "rub_speed_end": (("rub", "spool"), [[r.speed_end[s] for s in spools] for r in rubs], {
                    "units": "Hz", "long_name": "spool speed at the last contact"})})
        return ds.assign_coords(coords).assign(data)

    @staticmethod
    def _track_variables(dim: str, tracks: list, units: str) -> dict:
        """The variables of order tracks ``[(OrderTrack, dof), ...]`` along ``dim`` and ``block`` (NaN-padded)."""
        n = max((len(tr.t) for tr, _ in tracks), default=0)

        def padded(name):
            out = np.full((len(tracks), n), np.nan)
            for k, (tr, _) in enumerate(tracks):
                values = getattr(tr, name)
                out[k, :len(values)] = values
            return out

        block = (dim, "block" if dim == "track" else f"{dim}_block")
        return {f"{dim}_time": (block, padded("t"), {"units": "s", "long_name": "time at the block's centre"}),
                f"{dim}_speed": (block, padded("speed"), {"units": "rad/s", "long_name": "mean speed of the track's "
                                                                                       "spool over the block"}),
                f"{dim}_amplitude": (block, padded("amplitude"), {"units": units, "long_name": "amplitude of the order"}),
                f"{dim}_phase": (block, padded("phase"), {"units": "rad", "long_name": "phase against the spool's "
                                                                                     "spin angle"}),
                f"{dim}_spool": (dim, np.array([tr.spool for tr, _ in tracks], dtype=object), {"units": "1", (
                    "long_name"): "spool of the order"}),
                f"{dim}_order": (dim, [tr.order for tr, _ in tracks], {"units": "1", "long_name": (
                    "order (cycles per revolution of the spool)")}),
                f"{dim}_output": (dim, np.array([f"{d[0]}:{d[1]}" for _, d in tracks], dtype=object), {"units": "1", (
                    "long_name"): "recorded DOF"})}


# --------------------------------------------------------------------------- analyses
def block_revolutions(ratio: float, base: int) -> int:
    """Revolutions per order-tracking block: ``base``, raised to a multiple of ``q`` when the other spool turns
    ``ratio = p/q`` times as fast (q <= RATIO_DENOMINATOR), so the block holds whole revolutions of both."""
    if not ratio > 0:
        return base
    frac = Fraction(ratio).limit_denominator(RATIO_DENOMINATOR)
    if abs(float(frac) - ratio) > RATIO_RTOL * ratio:
        return base
    q = frac.denominator
    return q * math.ceil(base / q)


def _fixed_ratio(speeds: dict, s: str, other: str) -> float:
    """The ratio Omega_other / Omega_s when it is the same wherever both turn, else 0."""
    a, b = speeds[s], speeds[other]
    turning = (a > 0) & (b > 0)
    if not np.any(turning):
        return 0.0
    r = b[turning] / a[turning]
    return float(r[0]) if np.ptp(r) <= RATIO_RTOL * r[0] else 0.0


def tracks_of(scene: Scene, t: np.ndarray, speeds: dict, angles: dict, outputs: dict) -> tuple[tuple, tuple, dict]:
    """Order tracks of every spool and the overall amplitude against the reference spool's speed."""
    spec = scene.runup
    dofs = list(outputs)
    X = np.array([outputs[d] for d in dofs])
    tracks, track_dofs, overall = [], [], {}
    for s in speeds:
        if not np.any(speeds[s] > 0):
            continue
        others = [o for o in speeds if o != s]
        revs = spec.revs_per_block
        for o in others:
            revs = block_revolutions(_fixed_ratio(speeds, s, o), revs)
        blocks = angle_blocks(t, X, angles[s], revs, samples_per_rev=64)
        for j, per_order in enumerate(order_tracks(blocks, s, spec.orders)):
            tracks += per_order
            track_dofs += [dofs[j]] * len(per_order)
        if s == spec.reference:  # the overall amplitude revolution by revolution
            per_rev = angle_blocks(t, X, angles[s], 2, samples_per_rev=64)
            for node in sorted({d[0] for d in dofs}):
                if (node, "x") in dofs and (node, "y") in dofs:
                    overall[node] = (per_rev.speed, overall_amplitude(per_rev, dofs.index((node, "x")),
                                                                      dofs.index((node, "y"))))
    return tuple(tracks), tuple(track_dofs), overall


def rub_intervals(scene: Scene, t: np.ndarray, speeds: dict, contacts) -> tuple[RubInterval, ...]:
    """Stretches of contact, merged across gaps shorter than :data:`RUB_GAP_REVS` revolutions of the reference spool."""
    ref = speeds[scene.runup.reference]
    hz = {s: w / (2 * math.pi) for s, w in speeds.items()}
    out = []
    for k, ch in enumerate(contacts):
        touching = np.flatnonzero(ch.state != 0)
        if touching.size == 0:
            continue
        onsets = np.flatnonzero((ch.state[1:] != 0) & (ch.state[:-1] == 0)) + 1
        groups, start = [], touching[0]
        for a, b in zip(touching[:-1], touching[1:]):
            rev = 2 * math.pi / ref[a] if ref[a] > 0 else math.inf
            if t[b] - t[a] > RUB_GAP_REVS * rev:
                groups.append((start, a))
                start = b
        groups.append((start, touching[-1]))
        for i, j in groups:
            out.append(RubInterval(plate=k, node=ch.plate.node, t_start=float(t[i]), t_end=float(t[j]),
                                   speed_start={s: float(v[i]) for s, v in hz.items()},
                                   speed_end={s: float(v[j]) for s, v in hz.items()},
                                   impacts=int(np.count_nonzero((onsets >= i) & (onsets <= j))) + int(i == 0)))
    return tuple(out)


def orbit_snapshots(scene: Scene, t: np.ndarray, speeds: dict, outputs: dict) -> tuple[OrbitSnapshot, ...]:
    """Each node's orbit over two revolutions of the reference spool where it first passes each ``orbits_hz``."""
    ref = speeds[scene.runup.reference]
    out = []
    for f in scene.runup.orbits_hz:
        target = 2 * math.pi * f
        side = np.sign(ref - target)
        crossing = np.flatnonzero(side != side[0])
        if crossing.size == 0:
            continue
        i = int(crossing[0])
        half = 2 * math.pi / target  # one revolution either side
        window = (t >= t[i] - half) & (t <= t[i] + half)
        for node in scene.output.nodes:
            if (node, "x") in outputs and (node, "y") in outputs:
                out.append(OrbitSnapshot(speed_hz=f, t=float(t[i]), node=node, x=outputs[(node, "x")][window],
                                         y=outputs[(node, "y")][window]))
    return tuple(out)


def critical_speeds_in_range(scene: Scene, speeds: dict) -> tuple:
    """The Campbell diagram of the reference spool over the swept range (its lowest to its highest speed), at the
    profile's final ratios: (its critical speeds, the ratios, the diagram, their API 684 separation margins
    (:func:`rotorred.linear.margins.separation_margins`, against the rotor file's operating range of the reference
    spool when it gives one))."""
    from rotorred.linear.campbell import campbell
    from rotorred.linear.margins import OperatingRange, separation_margins

    ref = scene.runup.reference
    final = {s: float(v[-1]) for s, v in speeds.items()}
    if final[ref] <= 0:
        final = {s: float(np.max(v)) for s, v in speeds.items()}
    ratio = {s: w / final[ref] for s, w in final.items() if s != ref}
    low, top = float(np.min(speeds[ref])), float(np.max(speeds[ref]))
    cd = campbell(scene.rotor, Operating.line(np.linspace(low, top, CAMPBELL_SPEEDS), ref, ratios=ratio))
    given = scene.rotor.defaults.operating_range(ref)
    margins = separation_margins(scene.rotor, cd, None if given is None else OperatingRange(*given))
    return tuple(cd.critical_speeds), {ref: 1.0, **ratio}, cd, margins


# --------------------------------------------------------------------------- the run
def run_runup(scene: Scene, model: SceneModel | None = None, progress: bool | None = None,
              interrupts: Mapping[type[BaseException], str] = INTERRUPTS) -> RunupResult:
    """Step the scene through its speed profile and analyse the record (see the module docstring).

    A diverged transient does not raise: the result holds the record up to the failure, analysed,
    with ``incomplete`` saying when, where and why it stopped. Nor does an interrupt while the transient steps
    (``interrupts``): the result holds the record up to the last step taken, analysed, with ``incomplete`` and
    ``interrupt`` saying so; an interrupt before the stepping, before the record's second sample or in the analysis
    is raised as it came.

    Parameters
    ----------
    scene : Scene
        A scene with a ``[runup]`` (its speed profile, record step (s) and reference spool).
    model : SceneModel, optional
        The scene's model (:func:`rotorred.scenes.run.build_model`); default built here.
    progress : bool, optional
        Progress bar on stderr; None (default): shown on a terminal once the run has taken 1 s
        (:class:`rotorred.transient.options.StepControl`).
    interrupts : mapping of exception type to str
        The exceptions that end the transient where it is, and the signal each stands for (default SIGINT's
        ``KeyboardInterrupt``; empty: none, they propagate).

    Returns
    -------
    RunupResult

    Raises
    ------
    ValueError
        If the scene has no ``[runup]``.
    """
    from rotorred.transient.newmark import Initial, Loads, Recording, StepControl, simulate
    from rotorred.transient.ramp import interrupted_record
    from rotorred.transient.results import SimulationDiverged

    if scene.runup is None:
        raise ValueError(f"scene {scene.name!r} has no [runup]")
    model = model or build_model(scene)
    s, profile = scene.solver, scene.runup.profile
    at_t0 = dataclasses.replace(scene, operating=Operating.point(profile.speeds_at(0.0)))
    start = Initial(*settled_state(at_t0, model.model)) if s.start == "settled" else None
    t0 = time.perf_counter()
    incomplete, interrupt = None, ""
    stage("stepping %s through its speed profile: %d steps of %g s to %g s", scene.name, round(s.duration / s.dt),
          s.dt, s.duration)
    try:
        res = simulate(model.model, scene.runup.operating, s.duration, s.dt,
                       loads=Loads(scene.unbalances, s.gravity or None), contacts=scene.plates,
                       recording=Recording(scene.output.dofs, decimate=int(round(scene.runup.record_dt / s.dt))),
                       start=start, control=StepControl(progress=progress))
    except SimulationDiverged as exc:
        res, incomplete = exc.result, explain_divergence(scene, exc)
    except tuple(interrupts) as exc:
        res = interrupted_record(exc)
        if res is None or len(res.t) < 2:  # before the second recorded sample: nothing to keep
            raise
        interrupt = interrupt_name(exc, interrupts)
        incomplete = (f"interrupted ({interrupt}) at t = {res.final.t:.6g} s of solver.duration = {s.duration:g} s; "
                      f"the record up to there is kept")
    solve_time = time.perf_counter() - t0
    stage("analysing %s: order tracks, critical speeds, rub intervals", scene.name)
    return dataclasses.replace(analyse(scene, model, res, solve_time, incomplete), interrupt=interrupt)


@dataclass(frozen=True)
class RunupOptions:
    """The time step, the record and what a run-up shows (:func:`runup`; a scene's ``[solver]`` and ``[runup]``).

    Parameters
    ----------
    dt : float
        Time step (s), > 0; average-acceleration Newmark (docs/model.md §7).
    record_dt : float
        Record interval (s), a whole number of steps.
    orders : sequence of float
        Orders tracked for every spool (cycles per revolution), > 0.
    orbits_hz : sequence of float
        Speeds of the reference spool (Hz) where orbit snapshots are taken.
    revs_per_block : int
        Revolutions per block of the order tracks (:mod:`rotorred.signals.orders`), >= 1.
    nodes : sequence of int
        Nodes whose x and y are recorded (default: the unbalance and rub nodes); the last node's y is the table DOF
        of the waterfall.
    start : {"settled", "rest"}
        From the linear steady state at the first speeds, or from rest.
    """

    dt: float = 2e-5
    record_dt: float = 1e-4
    orders: tuple = (1.0,)
    orbits_hz: tuple = ()
    revs_per_block: int = 8
    nodes: tuple = ()
    start: str = "settled"

    def __post_init__(self):
        dt = checks.positive("options.dt", self.dt, "s")
        record_dt = checks.positive("options.record_dt", self.record_dt, "s")
        if abs(record_dt / dt - round(record_dt / dt)) > 1e-9 * record_dt / dt or record_dt < dt:
            checks.fail("options.record_dt", record_dt, f"must be a whole number of steps of {dt:g} s", "s")
        object.__setattr__(self, "orders", checks.sequence(
            "options.orders", tuple(self.orders), lambda f, v: checks.positive(f, v), min_len=1))
        object.__setattr__(self, "orbits_hz", checks.sequence(
            "options.orbits_hz", tuple(self.orbits_hz), lambda f, v: checks.positive(f, v, "Hz")))
        checks.integer("options.revs_per_block", self.revs_per_block, ge=1)
        object.__setattr__(self, "nodes", tuple(checks.integer(f"options.nodes[{k}]", n) for k, n in
                                                enumerate(self.nodes)))
        checks.choice("options.start", self.start, ("settled", "rest"))


def runup(model, operating: Operating, loads, contacts=(), options: RunupOptions = RunupOptions(),
          progress: bool | None = None) -> RunupResult:
    """A run-up or coast-down of ``model`` through the ``operating`` profile, and what it shows: order tracks, overall
    amplitude, waterfall, orbits, rub intervals and the Campbell critical speeds in range (the module docstring).

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        Built from a rotor (:func:`rotorred.model.assembly.system_of`).
    operating : Operating
        A speed profile (:meth:`Operating.ramp`, :meth:`Operating.profile`); a spool it leaves out follows the
        reference at the rule's ratio (:meth:`Operating.profile_for`). It ends at its last breakpoint.
    loads : Loads
        Unbalances and gravity (:class:`rotorred.transient.options.Loads`).
    contacts : sequence of RubPlate
        Rub plates (default none); a plate without ``disk_radius`` takes its disk's from the rotor.
    options : RunupOptions
        Time step, record, orders, orbits, recorded nodes and start.
    progress : bool, optional
        Progress bar on stderr (None: on a terminal once the run has taken 1 s).

    Returns
    -------
    RunupResult
        Its ``scene`` is the scene built from these inputs.

    Raises
    ------
    rotorred.checks.InputError
        For a bad input, before any computation.
    """
    system = rotor_model(model)
    operating = checked_operating(operating)
    if operating.kind != "profile":
        checks.fail("operating", operating.describe(), "must be a speed profile (Operating.ramp, Operating.profile)")
    loads = checked_loads(loads)
    profile, reference = operating.profile_for(system), operating.reference_of(system)
    plates = plates_on(contacts, system.rotor)
    nodes = recorded_nodes(options.nodes, load_nodes(loads, plates), system)
    scene = built_scene(system, f"run-up along {operating.describe()}",
                        {s: float(np.max(w)) for s, w in profile.speeds.items()},  # a scene's [speeds]: > 0
                        loads, plates,
                        SolverSpec(dt=options.dt, duration=profile.duration, record_start=0.0, start=options.start,
                                   gravity=loads.gravity or 0.0),
                        OutputSpec(nodes=nodes, table=(nodes[-1], "y")),
                        RunupSpec(profile, reference, options.orders, options.orbits_hz, options.record_dt,
                                  options.revs_per_block))
    return run_runup(scene, SceneModel(system, f"{system.n_dof}-DOF model", 0.0, ()), progress)


def analyse(scene: Scene, model: SceneModel, res, solve_time: float, incomplete: str | None) -> RunupResult:
    """Tracks, overall amplitude, waterfall, orbits, rub intervals and critical speeds of a run-up's record."""
    t0 = time.perf_counter()
    at = scene.runup.profile.at(res.t)
    speeds = {sp: v[0] for sp, v in at.items()}
    angles = {sp: v[2] for sp, v in at.items()}
    tracks, track_dofs, overall = tracks_of(scene, res.t, speeds, angles, res.outputs) if len(res.t) > 8 else ((), (), {})
    dof = table_dof(scene)
    f_top = max(float(np.max(v)) for v in speeds.values()) / (2 * math.pi)
    f_max = scene.output.f_max_hz or 4.0 * f_top
    segment = min(0.25, 0.5 * (res.t[-1] - res.t[0])) if len(res.t) > 16 else 0.0
    fall = waterfall(res.t, res.outputs[dof], segment, f_max) if segment > 0 and len(res.t) >= 32 else None
    criticals, ratio, diagram, margins = critical_speeds_in_range(scene, speeds)
    counters = {"us_per_step": res.us_per_step, "n_passes": res.n_passes, "n_factorizations": res.n_factorizations,
                "n_contact_steps": res.n_contact_steps, "n_substeps": res.n_substeps,
                "kernel_load_time": res.kernel_load_time, "kernel_compiled": res.kernel_compiled}
    return RunupResult(scene=scene, t=res.t, speeds=speeds, outputs=res.outputs, contacts=res.contacts, tracks=tracks,
                       track_dofs=track_dofs, overall=overall, waterfall=fall, waterfall_dof=dof,
                       orbits=orbit_snapshots(scene, res.t, speeds, res.outputs),
                       rubs=rub_intervals(scene, res.t, speeds, res.contacts), critical_speeds=criticals,
                       campbell_ratio=ratio, campbell=diagram, margins=margins, model_label=model.label, n_steps=res.n_steps, counters=counters,
                       build_time=model.build_time, solve_time=solve_time, analysis_time=time.perf_counter() - t0,
                       incomplete=incomplete)


__all__ = ["RunupResult", "RubInterval", "OrbitSnapshot", "OrderTrack", "RunupOptions", "run_runup", "runup",
           "block_revolutions"]
