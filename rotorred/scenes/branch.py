"""Branches of a rub scene's periodic response: harmonic balance with pseudo-arclength continuation in a scene key,
its folds, and the stability of each point (docs/model.md §15).

Keys (:data:`KEYS`):

- ``rub.clearance`` (m): the clearance of the scene's plate, at its speeds (:class:`ClearanceFamily`, analytic
  dR/dclearance);
- ``speeds.<spool>`` (Hz): that spool's speed, every other spool's scaled with it (the scene's speed ratio kept, so
  the base frequency ``f_0`` moves with the speed and each spool stays at its harmonic of it);
- ``rub.<number>`` (:data:`PLATE_KEYS`): a number of the plate, its supports' stiffness ``k_n`` (N/m), its contact
  stiffness ``K_nr`` (N/m^1.5), friction ``mu_d`` ... at the scene's speeds.

For the last two (:class:`SceneFamily`) the problem is built again at each value (the model's speed-dependent
matrices, the unbalance forcing, the rim speed; the plate's DOFs and law) and dR/dvalue is a central difference of
the residual (a step of 1e-6 of the value: the tangent and the folds need no more). The value is carried scaled, in
metres like the unknowns, so that the arclength weighs both alike. The speed ratio itself is not a key: between two
commensurate ratios the response is quasi-periodic, on a torus (:mod:`rotorred.scenes.torus_balance`), not a
periodic branch.

The first point is found cold (:func:`cold_start`): Newton from the linear response; where that fails (the linear
orbit goes deep into the plate), a continuation in the clearance from where the linear orbit just reaches the plate
down to the plate's clearance. Each point's stability is from the monodromy matrix of the whole linearised system
(:func:`rotorred.nonlinear.stability.floquet_by_monodromy`, ``STABILITY_SUBSTEPS`` intervals an AFT sample).

An interrupt (SIGINT's ``KeyboardInterrupt``, or the exceptions the caller names: ``interrupts``) while the branch is
traced or its stability computed ends it there and keeps every point traced: its ``stopped`` says so (the signal,
where, how many points traced and how many with their stability), ``interrupt`` names the signal, and the points
whose stability was not computed have a NaN multiplier (:attr:`SceneBranch.known` False). An interrupt during the cold
start (no point yet) is raised as it came.
"""

from __future__ import annotations

import dataclasses
import textwrap
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from rotorred import checks
from rotorred.model.operating import Operating
from rotorred.nonlinear.condensed import ClearanceFamily
from rotorred.nonlinear.continuation import ENDS, ContinuationOptions, continue_branch, stability_variable
from rotorred.nonlinear.hb import Evaluation, NotConverged, solve_periodic
from rotorred.nonlinear.stability import floquet_by_monodromy
from rotorred.progress import INTERRUPTS, interrupt_name
from rotorred.results import Result
from rotorred.scenes.harmonic_balance import RubProblem, base_frequency, rub_problem
from rotorred.scenes.keys import cf_units, netcdf_name
from rotorred.writers import signals_held

__all__ = ["KEYS", "PLATE_KEYS", "BranchOptions", "SceneFamily", "SceneBranch", "check_key", "cold_start", "continue_scene", "dof_name",
           "scene_at"]

#: the plate's numbers a branch follows besides its clearance, and their units: the supports' (Eq. 7), the law's
#: (Eq. 8) and the rim's; not mu_s (harmonic balance sees sliding only) nor the bending model's (a fitted whole)
PLATE_KEYS = {"rub.k_n": "N/m", "rub.k_t": "N/m", "rub.c_n": "N s/m", "rub.c_t": "N s/m", "rub.m_p": "kg",
              "rub.K_nr": "N/m^1.5", "rub.c": "s/m", "rub.mu_d": "-", "rub.disk_radius": "m"}
#: the keys a branch follows, and their units
KEYS = {"rub.clearance": "m", "speeds.<spool>": "Hz", **PLATE_KEYS}
#: the relative step of the central difference in dR/dvalue
STEP = 1e-6
#: intervals of the monodromy product a sample interval of the AFT: the rig's orbit reached by continuation at 13 um
#: (H = 100, N = 2048) has its largest multiplier 0.780, 1.034, 0.640, 0.698, 0.674, 0.676, 0.679, 0.678 with 256 to
#: 32768 intervals a period: settled from 4 N (the transient's orbit: 0.773 to 0.662, settled from 1024)
STABILITY_SUBSTEPS = 4


@dataclass(frozen=True)
class SceneFamily:
    """The rub problem of ``scene`` along a scene ``key``: ``speeds.<spool>`` (Hz, every spool scaled with it) or a
    number of the (first) plate, ``rub.<number>`` (:data:`PLATE_KEYS`).

    Parameters
    ----------
    scene : Scene
    model : SystemMatrices or ReducedSystem
    key : str
    H, N : int
    reference : float
        The value (in the key's unit) that sets the scale of the carried parameter ``s = scale value``: ``scale``
        (m per unit) is the norm of the linear response there over that value (:meth:`parameter_value` gives the
        value back).
    """

    scene: object
    model: object
    key: str
    H: int
    N: int
    reference: float
    _problems: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        group, _, name = self.key.partition(".")
        if group == "speeds" and name not in self.scene.speeds:
            checks.fail("key", self.key, f"must name a spool of the rotor ({', '.join(self.scene.speeds)})")
        checks.positive("reference", self.reference, KEYS.get(self.key, "Hz"))
        object.__setattr__(self, "parameter", (self.key, KEYS.get(self.key, "Hz")))
        rp = self.at(self.reference)
        object.__setattr__(self, "scale", float(np.linalg.norm(rp.problem.linear_response(rp.omega)))
                           / self.reference)

    def parameter_value(self, s: float) -> float:
        """The key's value of the carried parameter ``s``."""
        return s / self.scale

    def at(self, value: float) -> RubProblem:
        """The rub problem at ``value`` (the last few kept: Newton and its differences revisit them)."""
        value = float(value)
        if value not in self._problems:
            if len(self._problems) >= 6:
                self._problems.pop(next(iter(self._problems)))
            scene, f0 = scene_at(self.scene, self.key, value)
            self._problems[value] = rub_problem(scene, self.model, self.H, self.N, f0=f0)
        return self._problems[value]

    @property
    def n(self) -> int:
        return self.at(self.reference).problem.n

    @property
    def size(self) -> int:
        return self.at(self.reference).problem.size

    @property
    def harmonics(self):
        return self.at(self.reference).problem.harmonics

    def linear_response(self, s: float) -> np.ndarray:
        """The linear response at the carried value ``s``; NaN where the plate refuses the value (no problem there:
        Newton from it fails, as at :meth:`evaluate`)."""
        rp = self._valid(s / self.scale)
        return np.full(self.size, np.nan) if rp is None else rp.problem.linear_response(rp.omega)

    def evaluate(self, z: np.ndarray, s: float) -> Evaluation:
        """The residual at ``z`` and the carried value ``s``; where the plate refuses the value (past one of its bounds,
        mu_d above mu_s), no solution: an infinite residual, which the corrector takes for a failed step (a smaller
        one follows, and the points so far are kept)."""
        f = s / self.scale
        rp = self._valid(f)
        if rp is None:
            return Evaluation(np.full(len(z), np.inf), 1.0, _refused, _refused)

        def dR_ds():  # central, or one-sided at a bound (the value itself where the plate refuses the step)
            (up, p_up), (down, p_down) = ((v, q) if q is not None else (f, rp)
                                          for v, q in ((v, self._valid(v)) for v in (f * (1.0 + STEP), f * (1.0 - STEP))))
            R_up, R_down = (q.problem.evaluate(z, q.omega).R for q in (p_up, p_down))
            return (R_up - R_down) / ((up - down) * self.scale)
        return rp.problem.evaluate(z, rp.omega).with_parameter(dR_ds)

    def _valid(self, value: float) -> RubProblem | None:
        """:meth:`at`, or None where the plate refuses ``value``."""
        try:
            return self.at(value)
        except checks.InputError:
            return None


def _refused():
    raise sla.LinAlgError("no problem at this value: the plate refuses it")


@dataclass(frozen=True, repr=False)
class SceneBranch(Result):
    """A branch of a rub scene's periodic response.

    Attributes
    ----------
    scene : str
        The scene's name.
    key, unit : str
        The varied scene key and its unit (:data:`KEYS`).
    values : ndarray, shape (p,)
        The key at each point (``unit``: m for a clearance, Hz for a speed).
    f0 : ndarray, shape (p,)
        Base frequency of each point (Hz).
    dofs : tuple of (int, str)
        The output DOFs (the scene's).
    peaks : ndarray, shape (p, len(dofs))
        Largest ``|q(t)|`` over the period of each output DOF (m).
    z : ndarray, shape (p, (2H + 1) m)
        Each point's solution: the Fourier coefficients of the unknowns (:class:`RubProblem`; its ``final_state``
        starts a transient on it).
    lines : ndarray, shape (p, H + 1)
        Amplitude of each harmonic k f_0 of ``dofs[0]`` (m).
    critical : ndarray of complex, shape (p,)
        The Floquet multiplier of largest modulus at each point (NaN where stability was not computed).
    folds : tuple of (float, bool)
        Each turn of the branch: the key's value and whether it is smooth (a saddle-node) or a corner (a contact's
        start or end).
    stopped : str
        Why the branch ended ("reached the end, ...", or where and why it stopped; "interrupted (SIGINT) while ..."
        with where, the points traced and those with their stability).
    iterations : ndarray, shape (p,)
        Newton iterations of each point.
    start_time, solve_time, stability_time : float
        Wall time of the cold start, the continuation and the stability of every point (s).
    interrupt : str
        The signal that ended the branch ("SIGINT", "SIGTERM": the caller's ``interrupts``), or "".
    end : str
        Why the branch ended as a code, one of :data:`rotorred.nonlinear.continuation.ENDS` ("interrupted" also where
        a signal ended the stability after the branch); keyword-only.
    """

    scene: str
    key: str
    unit: str
    values: np.ndarray
    f0: np.ndarray
    dofs: tuple
    peaks: np.ndarray
    z: np.ndarray
    lines: np.ndarray
    critical: np.ndarray
    folds: tuple
    stopped: str
    iterations: np.ndarray
    start_time: float
    solve_time: float
    stability_time: float
    interrupt: str = ""
    end: str = field(kw_only=True)

    def __post_init__(self):
        checks.choice("end", self.end, ENDS)

    @property
    def known(self) -> np.ndarray:
        """Whether each point's stability was computed (its multiplier not NaN)."""
        return ~np.isnan(self.critical)

    @property
    def multipliers(self) -> np.ndarray:
        """The largest Floquet multiplier modulus of each point (NaN where not computed)."""
        return np.abs(self.critical)

    @property
    def stable(self) -> np.ndarray:
        """Whether each point is stable (largest multiplier modulus below 1; False where not computed)."""
        return self.multipliers < 1.0

    @property
    def bifurcations(self) -> tuple:
        """Where stability changes between two points: (the key's values at both, the kind) with the kind from the
        critical multiplier of the unstable one: "period-doubling" (it leaves the unit circle near -1, its angle
        within 10 degrees of 180), "fold" (near +1, within 10 degrees of 0: a saddle-node, smooth or at a corner),
        else "Neimark-Sacker" (a complex pair: a second frequency, the torus)."""
        out = []
        for i in range(len(self.values) - 1):
            a, b = self.critical[i], self.critical[i + 1]
            if np.isnan(a) or np.isnan(b) or (abs(a) < 1.0) == (abs(b) < 1.0):
                continue
            angle = abs(np.degrees(np.angle(b if abs(b) >= 1.0 else a)))
            kind = "period-doubling" if angle > 170.0 else "fold" if angle < 10.0 else "Neimark-Sacker"
            out.append((float(self.values[i]), float(self.values[i + 1]), kind))
        return tuple(out)

    @property
    def interrupted(self) -> bool:
        """Whether a signal ended the branch (:attr:`interrupt`)."""
        return bool(self.interrupt)

    @property
    def flags(self) -> np.ndarray:
        """Each point's :data:`rotorred.nonlinear.continuation.STABILITY_FLAGS` value: 1 stable, 0 unstable, -1 not
        computed; shape (p,), int8."""
        return stability_variable(self.stable, self.known)[1]

    @property
    def shown(self) -> tuple[float, str]:
        """The key's shown scale and unit: a clearance in µm, any other key in its own unit (Hz, N/m, ...)."""
        return (1e6, "µm") if self.key == "rub.clearance" else (1.0, self.unit)

    def summary(self) -> list[str]:
        """The key's range, the peak's range (µm), the turns, the stability and its changes, why the branch
        stopped, and the times."""
        xs, xu = self.shown
        p, known = len(self.values), int(np.count_nonzero(self.known))
        turns = [f"{xs * v:.6g}{'' if smooth else ' (corner)'}" for v, smooth in self.folds]
        stability = (f"{int(np.count_nonzero(self.stable))} of {p} points stable" if known == p else
                     "stability not computed" if known == 0 else f"stability computed for {known} of {p} points")
        changes = ", ".join(f"{kind} near {xs * (a + b) / 2:.6g}" for a, b, kind in self.bifurcations[:3])
        return [f"harmonic-balance branch of {self.scene} in {self.key} ({xu}): {p} points from "
                f"{xs * self.values[0]:.6g} to {xs * self.values[-1]:.6g}",
                f"peak |{dof_name(self.dofs[0])}| from {1e6 * np.min(self.peaks[:, 0]):.4g} to "
                f"{1e6 * np.max(self.peaks[:, 0]):.4g} µm; {self.lines.shape[1] - 1} harmonics",
                f"turns: {len(turns)}" + (f", at {', '.join(turns[:4])}" if turns else "")
                + (f" and {len(turns) - 4} more" if len(turns) > 4 else ""),
                f"{stability}; stability changes: {len(self.bifurcations)}" + (f" ({changes})" if changes else ""),
                *textwrap.wrap(f"{'INCOMPLETE: ' if self.interrupted else 'stopped: '}{self.stopped}", 110),
                f"times: cold start {self.start_time:.3g} s, continuation {self.solve_time:.3g} s, stability "
                f"{self.stability_time:.3g} s"]

    def plot(self, ax=None, *, dof: int = 0, title: str | None = None):
        """The peak of output DOF ``dofs[dof]`` (µm) against the key: stable solid, unstable dashed, stability not
        computed grey, folds, corners and stability changes marked (:func:`rotorred.plots.branch.plot_branch`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        dof : int
            Position of the output DOF in :attr:`dofs`.
        title : str, optional
            Default: the scene's (and INCOMPLETE with the signal of an interrupted branch).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.branch import plot_branch

        xs, xu = self.shown
        stable = None if not self.known.any() else np.where(self.known, self.stable, np.nan)
        if title is None:
            title = f"{self.scene}: harmonic-balance branch" + (
                f" (INCOMPLETE: interrupted by {self.interrupt})" if self.interrupted else "")
        return plot_branch(self.values, self.peaks[:, dof], stable, self.folds, ax, xlabel=f"{self.key} ({xu})",
                           ylabel=f"peak |{dof_name(self.dofs[dof])}| (µm)", changes=self.bifurcations, xscale=xs,
                           title=title)

    def to_xarray(self):
        """The branch as ``branch.nc`` holds it: dims point, dof, harmonic; the key's coordinate named
        :func:`rotorred.scenes.keys.netcdf_name` (``rub_clearance``), the key itself in its ``long_name`` and
        ``rotorred_key``; CF ``units`` on every variable and coordinate ("1" when dimensionless)."""
        import xarray as xr

        return xr.Dataset(
            {"peak": (("point", "dof"), self.peaks, {"units": "m", "long_name": "largest |q(t)| over the period"}),
             "line": (("point", "harmonic"), self.lines,
                      {"units": "m", "long_name": f"amplitude of harmonic k f0 of {dof_name(self.dofs[0])}"}),
             "critical_multiplier_re": ("point", self.critical.real, {
                 "units": "1", "long_name": "Floquet multiplier of largest modulus, real part"}),
             "critical_multiplier_im": ("point", self.critical.imag, {
                 "units": "1", "long_name": "Floquet multiplier of largest modulus, imaginary part"}),
             "stable": stability_variable(self.stable, self.known),
             "f0": ("point", self.f0, {"units": "Hz", "long_name": "base frequency"}),
             "iterations": ("point", self.iterations, {"units": "1", "long_name": "Newton iterations of the point"})},
            coords={netcdf_name(self.key): ("point", self.values, {"units": cf_units(self.key), "long_name": self.key,
                                                                   "rotorred_key": self.key}),
                    "dof": ("dof", [dof_name(d) for d in self.dofs], {"units": "1", "long_name": "output DOF"}),
                    "harmonic": ("harmonic", np.arange(self.lines.shape[1]),
                                 {"units": "1", "long_name": "harmonic k of f0"})},
            attrs={"scene": self.scene, "stopped": self.stopped, "end": self.end, "interrupted": self.interrupt or "no",
                   "folds": "; ".join(f"{v:.9g} {'fold' if s else 'corner'}" for v, s in self.folds),
                   "bifurcations": "; ".join(f"{kind} between {a:.9g} and {b:.9g}"
                                             for a, b, kind in self.bifurcations)})


def dof_name(dof) -> str:
    """An output DOF's name: node and direction, ``14y``."""
    return f"{dof[0]}{dof[1]}"


def check_key(scene, key: str, start: float, end: float | None = None) -> None:
    """Refuse, before anything is computed, a key the branch cannot follow in ``scene`` (:data:`KEYS`), a scene
    without a plate or with a ``[runup]``, speeds that are not commensurate at ``start`` (for a speed key) or now, and a plate's number the
    plate refuses at ``start`` or ``end``.

    Parameters
    ----------
    scene : Scene
        The rub scene the branch starts from.
    key : str
        The varied key: ``"rub.clearance"``, ``"speeds.<spool>"`` or a plate's number (:data:`KEYS`).
    start : float
        The key's first value, > 0 (its unit in :data:`KEYS`: m for a clearance, Hz for a speed).
    end : float, optional
        The key's last value, > 0 (same unit).

    Raises
    ------
    InputError
        Naming ``--param`` (or the scene, or the plate's field) and what is allowed.
    """
    if not scene.plates:
        checks.fail("SCENE", scene.name, "must have a rub plate ([[rub]]): the branch is of the rub response")
    if getattr(scene, "runup", None) is not None:
        checks.fail("SCENE", scene.name, "has a [runup], which a branch cannot honour (its points are periodic "
                    "responses at steady speeds): run the run-up with `rotorred run`, or follow a scene without [runup]")
    spools = tuple(scene.speeds)
    allowed = ("rub.clearance",) + tuple(f"speeds.{s}" for s in spools) + tuple(PLATE_KEYS)
    if key not in allowed:
        checks.fail("--param", key, f"must be one of {', '.join(allowed)}")
    if key.startswith("rub.") and len(scene.plates) != 1:
        checks.fail("--param", key, f"needs a scene with one rub plate (this one has {len(scene.plates)})")
    for value in (start,) + (() if end is None else (end,)):
        checks.positive("--param", value, KEYS.get(key, "Hz"))  # the carried parameter is > 0
    if key in PLATE_KEYS:
        name = key.partition(".")[2]
        for value in (start,) + (() if end is None else (end,)):
            scene.plates[0].with_(**{name: value})  # the plate's own check, naming the field
        if end is not None:  # the branch ends at its first point past END: the plate must take one
            past = end + 0.01 * (end - start)
            try:
                scene.plates[0].with_(**{name: past})
            except checks.InputError as error:
                checks.fail("--param", end, f"must leave the branch room to pass it ({key} = {past:g} just past it: "
                            f"{error})")
    f = scene.frequencies_hz
    factor = start / f[key.partition(".")[2]] if key.startswith("speeds.") else 1.0
    base_frequency(tuple(v * factor for v in f.values()))


def cold_start(problem, omega: float, tol: float = 1e-9) -> np.ndarray:
    """A periodic solution of the condensed rub ``problem`` at ``omega`` from nothing: Newton from the linear
    response; if that fails, a continuation in the first plate's clearance from where the linear orbit just reaches
    the plate down to its clearance, and Newton there from the nearest point.

    Raises
    ------
    NotConverged
        If neither reaches a solution (with the residual and where).
    """
    z_lin = problem.linear_response(omega)
    try:
        return solve_periodic(problem, z_lin, omega, tol=tol).z
    except NotConverged:
        pass
    family = ClearanceFamily(problem, omega)
    rub, idx = problem.force_columns[0]
    reach = float(np.max(problem.samples(z_lin, omega)[0][:, idx] @ rub.gradient))
    clearance = rub.plate.clearance
    scale = max(float(np.linalg.norm(z_lin)), reach)
    branch = continue_branch(family, z_lin, max(1.05 * reach, 1.05 * clearance), clearance,
                             ContinuationOptions(ds=0.05 * scale, ds_min=1e-10 * scale, ds_max=0.12 * scale,
                                                 stability=False, tol=tol),
                             interrupts={})  # no point of the branch yet: an interrupt is raised as it came
    i = int(np.argmin(np.abs(branch.omega - clearance)))
    return solve_periodic(family.at(clearance), branch.z[i], omega, tol=tol).z


@dataclass(frozen=True)
class BranchOptions:
    """The truncation, accuracy and extent of a branch (:func:`continue_scene`).

    Parameters
    ----------
    harmonics : int
        Harmonics H of the base frequency f_0, >= 1 (default 50).
    samples : int
        AFT samples N a period, even and >= 2 H + 2 (default 1024).
    tol : float
        Relative residual of every point, > 0 (-).
    stability : bool
        Floquet multipliers of every point (monodromy; the slow part).
    max_points : int
        Most points traced, >= 2.
    """

    harmonics: int = 50
    samples: int = 1024
    tol: float = 1e-9
    stability: bool = True
    max_points: int = 400

    def __post_init__(self):
        H = checks.integer("harmonics", self.harmonics, ge=1)
        N = checks.integer("samples", self.samples, ge=2 * H + 2)
        if N % 2:
            checks.fail("samples", N, "must be even")
        checks.positive("tol", self.tol)
        checks.boolean("stability", self.stability)
        checks.integer("max_points", self.max_points, ge=2)

    def estimate(self, scene):
        """The work and memory of a branch of ``scene`` with these options
        (:func:`rotorred.scenes.budget.branch_estimate`); check it with its ``check(force)``.

        Parameters
        ----------
        scene : Scene
            A validated scene with rub plates.

        Returns
        -------
        rotorred.scenes.budget.Estimate
        """
        from rotorred.scenes.budget import branch_estimate

        return branch_estimate(scene, self.harmonics, self.samples, self.max_points, self.stability)


def continue_scene(scene, model, key: str, start: float, end: float, options: BranchOptions = BranchOptions(), *,
                   progress=None, interrupts: Mapping[type[BaseException], str] = INTERRUPTS) -> SceneBranch:
    """The branch of ``scene``'s rub response on ``model`` as ``key`` goes from ``start`` to ``end``.

    Parameters
    ----------
    scene : Scene
        With rub plates, at commensurate speeds.
    model : SystemMatrices or ReducedSystem
        The scene's model (:func:`rotorred.scenes.run.build_model`).
    key : str
        ``rub.clearance``, ``speeds.<spool>`` or a plate's number ``rub.<number>`` (:data:`KEYS`).
    start, end : float
        The key's first and last value (in its unit, :data:`KEYS`).
    options : BranchOptions
        Harmonics, AFT samples, tolerance, stability and the most points.
    progress : callable, optional
        ``progress(points, value)`` as the branch grows (last with every point traced), then ``progress(0, None)`` as
        the stability starts and ``progress(i, None)`` as each point's is found.
    interrupts : mapping of exception type to str
        The exceptions that end the branch where it is (tracing or stability), every point traced kept, and the
        signal each stands for (default: SIGINT's ``KeyboardInterrupt``).

    Returns
    -------
    SceneBranch

    Raises
    ------
    InputError
        If ``options`` is not a :class:`BranchOptions`, or the branch cannot follow ``key`` in ``scene``
        (:func:`check_key`).
    NotConverged
        If no periodic solution is found at ``start`` (:func:`cold_start`).
    """
    if not isinstance(options, BranchOptions):
        checks.fail("options", type(options).__name__, "must be a BranchOptions")
    H, N, tol, stability = options.harmonics, options.samples, options.tol, options.stability
    family, to_value, rub_at = _family(scene, model, key, start, end, H, N)
    t0 = time.perf_counter()
    first = rub_at(start)
    z0 = cold_start(first.problem, first.omega, tol)
    t1 = time.perf_counter()
    s_start, s_end = to_value(start, inverse=True), to_value(end, inverse=True)
    scale = max(float(np.linalg.norm(z0)), abs(s_end - s_start))  # the steps: a few hundred along a branch
    branch = continue_branch(family, z0, s_start, s_end,
                             ContinuationOptions(ds=0.01 * scale, ds_min=1e-10 * scale, ds_max=0.015 * scale,
                                                 max_points=options.max_points, tol=tol, curved=True, stability=False),
                             interrupts=interrupts,
                             progress=None if progress is None else (lambda p, s: progress(p, to_value(s))))
    t2 = time.perf_counter()
    values, dofs, interrupt = np.array([to_value(s) for s in branch.omega]), _output_dofs(scene), branch.interrupt
    critical, outputs, t3 = np.full(len(values), complex(np.nan, np.nan)), None, None
    if progress is not None and len(values):
        progress(len(values), values[-1])  # the points traced, the last one included
    try:
        with signals_held():  # a few ms a point, and the branch's files need every point's outputs
            outputs = _outputs(rub_at, values, branch.z, dofs)
        t3 = time.perf_counter()
        if stability and not interrupt:
            _stability(rub_at, values, branch.z, critical, progress)
    except tuple(interrupts) as exc:
        if outputs is None:  # before the signals were held: nothing to keep
            raise
        interrupt = interrupt_name(exc, interrupts)
    stability_time = 0.0 if t3 is None else time.perf_counter() - t3
    stopped = branch.stopped if not interrupt else _interrupted(
        interrupt, key, values, critical, stability, None if branch.interrupt else branch.stopped)
    return SceneBranch(scene.name, key, KEYS.get(key, "Hz"), values, outputs[0], dofs, outputs[1], branch.z, outputs[2],
                       critical, tuple((to_value(f.omega), f.smooth) for f in branch.folds), stopped,
                       branch.iterations, t1 - t0, t2 - t1, stability_time, interrupt,
                       end="interrupted" if interrupt else branch.end)


def scene_at(scene, key: str, value: float):
    """``scene`` with ``key`` at ``value``: a spool's speed (Hz) with every other spool at its ratio to it in the scene
    (a speed line, :meth:`rotorred.model.operating.Operating.line`), or a number of the first plate
    (``rub.clearance`` and :data:`PLATE_KEYS`); and the base frequency (Hz) to build it with (None: its speeds'
    own)."""
    group, _, name = key.partition(".")
    if group == "speeds":
        ratios = {s: w / scene.speeds[name] for s, w in scene.speeds.items() if s != name}
        line = Operating.line([value], name, ratios=ratios, unit="Hz")
        f = scene.frequencies_hz
        return (dataclasses.replace(scene, operating=Operating.point(line.at(scene.rotor))),
                value * base_frequency(tuple(f.values())) / f[name])
    plates = (scene.plates[0].with_(**{name: value}),) + tuple(scene.plates[1:])
    return dataclasses.replace(scene, plates=plates), None


def _family(scene, model, key: str, start: float, end: float, H: int, N: int):
    """The continuation family of ``key``, the map from its carried parameter to the key's value (``inverse``: back),
    and ``rub_at(value) -> RubProblem``."""
    check_key(scene, key, start, end)
    if key == "rub.clearance":
        rp = rub_problem(scene, model, H, N)
        family = ClearanceFamily(rp.problem, rp.omega)
        return family, (lambda v, inverse=False: v), (lambda v: dataclasses.replace(rp, problem=family.at(v)))
    family = SceneFamily(scene, model, key, H, N, start)
    scale = family.scale
    return family, (lambda v, inverse=False: v * scale if inverse else v / scale), family.at


def _output_dofs(scene) -> tuple:
    """The scene's output DOFs, its table DOF (the response it is judged by) first."""
    dofs = tuple(scene.output.dofs)
    table = scene.output.table
    return dofs if table is None else (table,) + tuple(d for d in dofs if d != table)


def _outputs(rub_at, values, z, dofs):
    """Each point's f_0 (Hz), the peak of each of ``dofs`` (m) and the harmonics of ``dofs[0]`` (m), from its problem
    (``rub_at``: a speed's built anew; :func:`_stability` builds it again, 0.03-0.14 ms a point on the rig, rather
    than hold every point's problem)."""
    f0, peaks, lines = np.empty(len(values)), np.empty((len(values), len(dofs))), []
    for i, (v, zi) in enumerate(zip(values, z)):
        rp = rub_at(v)
        f0[i], peaks[i] = rp.f0, [np.max(np.abs(rp.waveform(zi, d))) for d in dofs]
        lines.append(list(rp.lines(zi, dofs[0]).values()))
    return f0, peaks, np.array(lines)


def _stability(rub_at, values, z, critical, progress) -> None:
    """The Floquet multiplier of largest modulus of each point, into ``critical`` as each is found (an interrupt
    leaves those found)."""
    if progress is not None:
        progress(0, None)
    for i, (v, zi) in enumerate(zip(values, z)):
        rp = rub_at(v)
        mu = floquet_by_monodromy(rp.problem, zi, rp.omega, STABILITY_SUBSTEPS).multipliers
        critical[i] = mu[np.argmax(np.abs(mu))]
        if progress is not None:
            progress(i + 1, None)


def _interrupted(signal: str, key: str, values, critical, stability: bool, traced: str | None) -> str:
    """Why an interrupted branch ended: the ``signal``, the phase and the key's value there (the last point traced, or
    the first without its stability), the points traced and those with their stability. ``traced``: why the tracing
    ended (None: the signal ended it)."""
    unit, known = KEYS.get(key, "Hz"), int(np.count_nonzero(~np.isnan(critical)))
    if traced is None:
        phase, at = "tracing", values[-1]
    else:  # in the stability, or as the points' outputs were computed (the signal held back till then)
        phase, at = "computing stability" if stability else "after tracing", values[min(known, len(values) - 1)]
    if not stability:
        with_stability = "stability not asked"
    else:
        with_stability = f"stability computed for {known} ({len(values) - known} unknown)"
    text = f"interrupted ({signal}) while {phase}, at {key} = {at:.9g} {unit}: {len(values)} points traced, " \
           f"{with_stability}"
    if traced is not None and not traced.startswith("reached the end"):
        text += f"; the tracing had stopped early: {traced}"
    return text
