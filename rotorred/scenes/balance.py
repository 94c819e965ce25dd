"""The periodic rub response of a rotor by harmonic balance, from Python: at an operating point,
``harmonic_balance(model, operating, loads, contacts, options)``, and along a speed line, continued through its
folds with each point's stability, ``continue_balance(model, operating, loads, contacts, options)``.

The same problem as a scene's ``solver.method = "harmonic-balance"`` (docs/model.md §15,
:mod:`rotorred.scenes.harmonic_balance`): the spool speeds must be commensurate, the base frequency
``f_0`` is their greatest common divisor, each spool's unbalance is a harmonic of it, and the unknowns are
the Fourier coefficients of each rub disk's x, y and its plate's u_n, u_t. The speeds come from the
:class:`rotorred.model.operating.Operating` point by its one rule, the model through
:func:`rotorred.model.assembly.system_of`. The solution is found as a scene's is, by the same functions: Newton
from the fit of a short transient's last period (5 periods of f_0 from the settled linear state,
:func:`rotorred.scenes.run.start_record`), else a cold start up through coarser truncations
(:func:`rotorred.scenes.balance_harmonics.cold_solution`). A rub response can have several periodic solutions at
one operating point; starting from the transient finds the one the rotor settles onto from its linear orbit. (On
paper-rub at 20 harmonics, Newton from the linear response alone reached another: node 14 y's 130 Hz line 0.70 µm,
against 1.27 µm on the solution the transient leads to.)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from rotorred import checks
from rotorred.model.operating import Operating, checked as checked_operating
from rotorred.nonlinear.fourier import to_phasors
from rotorred.nonlinear.hb import coefficient_variables
from rotorred.results import Result, dof_coordinates, strongest_lines
from rotorred.scenes.balance_harmonics import cold_solution, samples_for
from rotorred.scenes.branch import BranchOptions, SceneBranch, check_key, continue_scene
from rotorred.scenes.built import balance_loads, built_scene, plates_on, recorded_nodes, rotor_model
from rotorred.scenes.harmonic_balance import RubProblem, rub_problem
from rotorred.scenes.run import start_record
from rotorred.scenes.schema import OutputSpec, SolverSpec
from rotorred.transient.contact import RubPlate
from rotorred.transient.options import Loads

__all__ = ["BalanceOptions", "RubBalance", "harmonic_balance", "continue_balance"]


@dataclass(frozen=True)
class BalanceOptions:
    """The truncation and accuracy of a harmonic balance, and the DOFs it reports (:func:`harmonic_balance`).

    Parameters
    ----------
    harmonics : int
        Harmonics H of the base frequency f_0, >= 1 (default 50; ``validation/hb_harmonics.py`` measures how the
        response converges with H).
    samples : int, optional
        AFT samples N a period, even and >= 2 H + 2; default 20.48 H rounded up to even (2048 for 100).
    dt : float
        Time step of the short transient the solution starts from (s), > 0; the step used is the next one at or below
        it that divides the period 1 / f_0.
    outputs : sequence of (int, str)
        Model DOFs (node, direction) reported; default x and y of every rub node.

    Every solution is solved to a relative residual of 1e-9 (:data:`rotorred.scenes.balance_harmonics.TOL`).
    """

    harmonics: int = 50
    samples: int | None = None
    dt: float = 2e-5
    outputs: Sequence[tuple[int, str]] = ()

    def __post_init__(self):
        H = checks.integer("options.harmonics", self.harmonics, ge=1)
        if self.samples is not None:
            N = checks.integer("options.samples", self.samples, ge=2 * H + 2)
            if N % 2:
                checks.fail("options.samples", N, "must be even")
        checks.positive("options.dt", self.dt, "s")
        object.__setattr__(self, "outputs", tuple(tuple(o) for o in self.outputs))

    @property
    def n_samples(self) -> int:
        """N: the samples given, or the default for the harmonics."""
        return self.samples if self.samples is not None else samples_for(self.harmonics)


@dataclass(frozen=True, repr=False)
class RubBalance(Result):
    """The periodic rub response of a rotor at an operating point (:func:`harmonic_balance`).

    Attributes
    ----------
    problem : RubProblem
        The condensed problem solved (its model, base frequency and harmonics).
    z : ndarray, shape ((2H + 1) n_u,)
        The solution: harmonic-major Fourier coefficients of the unknowns (m).
    start : str
        How the solution was started (:data:`rotorred.scenes.balance_harmonics.FROM_RECORD` or ``COLD``).
    residual : float
        Relative residual at ``z`` (-).
    outputs : tuple of (int, str)
        The model DOFs reported.
    operating : Operating
        The operating point.
    speeds : dict of str to float
        Speed of every spool there (rad/s).
    """

    problem: RubProblem
    z: np.ndarray
    start: str
    residual: float
    outputs: tuple
    operating: Operating
    speeds: Mapping[str, float]

    @property
    def H(self) -> int:
        """The highest harmonic of f_0."""
        return self.problem.problem.harmonics.H

    @property
    def frequencies(self) -> np.ndarray:
        """Frequency k f_0 of each harmonic k = 0..H, shape (H + 1,) (Hz)."""
        return np.arange(self.H + 1) * self.problem.f0

    @property
    def phasors(self) -> np.ndarray:
        """Complex amplitude ``Q_k = a_k - i b_k`` of each harmonic k and output, shape (H + 1, n_outputs) (m or rad):
        harmonic k of an output is ``Re(Q_k exp(2 pi i k f_0 t))``."""
        C = np.column_stack([self.problem.coefficients(self.z, dof) for dof in self.outputs])
        return to_phasors(C)

    @property
    def amplitudes(self) -> np.ndarray:
        """Amplitude of each harmonic k and output, shape (H + 1, n_outputs) (m or rad)."""
        return np.abs(self.phasors)

    def waveform(self, dof: tuple[int, str], t) -> np.ndarray:
        """The model DOF ``dof`` at the times ``t`` (s).

        Parameters
        ----------
        dof : (int, str)
            A model DOF (node, direction).
        t : array_like, shape (m,)
            Times (s); the phase origin is t = 0.

        Returns
        -------
        ndarray, shape (m,)
            Displacement (m) or rotation (rad).
        """
        return self.problem.record(self.z, np.asarray(t, float), [tuple(dof)])[0][tuple(dof)]

    def summary(self) -> list[str]:
        """The operating point, the truncation, the convergence and each output's strongest harmonics."""
        p = self.problem
        lines = [f"harmonic balance of {p.model.name or 'the rotor'} at {self.operating.describe()}",
                 f"f_0 = {p.f0:.6g} Hz, {self.H} harmonics, {p.problem.harmonics.N} samples a period; "
                 f"{len(p.problem.dofs)} unknowns",
                 f"relative residual {self.residual:.3g}; started by {self.start}"]
        return lines + strongest_lines(self.outputs, self.amplitudes, [f"{f:.6g} Hz" for f in self.frequencies])

    def plot(self, ax=None, *, title: str | None = None):
        """The amplitude of each harmonic of each output at its frequency (µm, log scale).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Where to draw (default: a new figure).
        title : str, optional

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.branch import plot_harmonics

        return plot_harmonics(self.frequencies, self.amplitudes, [f"node {n} {d}" for n, d in self.outputs], ax,
                              title=title)

    def to_xarray(self):
        """Dims harmonic, output: ``cos`` a_k, ``sin`` b_k and ``amplitude`` (m); ``frequency`` (Hz); the spool speeds
        (rad/s) on dim spool; f_0, the start and the residual as attributes."""
        import xarray as xr

        spools = list(self.speeds)
        return xr.Dataset(
            {**coefficient_variables(self.phasors, ("harmonic", "output")),
             "spool_speed": ("spool", np.array([self.speeds[s] for s in spools]),
                             {"units": "rad/s", "long_name": "spool speed"})},
            coords={"harmonic": ("harmonic", np.arange(self.H + 1), {"units": "1", "long_name": "harmonic k of f_0"}),
                    "frequency": ("harmonic", self.frequencies, {"units": "Hz", "long_name": "frequency k f_0"}),
                    "spool": ("spool", np.array(spools, dtype=object), {"units": "1", "long_name": "spool"}),
                    **dof_coordinates("output", self.outputs, "reported DOF")},
            attrs={"f0_hz": self.problem.f0, "start": self.start, "residual": self.residual})


def harmonic_balance(model, operating: Operating, loads: Loads, contacts: Sequence[RubPlate],
                     options: BalanceOptions = BalanceOptions()) -> RubBalance:
    """The periodic rub response of ``model`` at the ``operating`` point by harmonic balance (docs/model.md §15).

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        Built from a rotor (:func:`rotorred.model.assembly.system_of`); each rub node's x and y must be its own
        coordinates (a boundary node of a reduced model: ``reduce_rotor(rotor, extra_nodes=[node])``).
    operating : Operating
        One point whose spool speeds are commensurate (their greatest common divisor f_0 >= 0.1 Hz).
    loads : Loads
        The unbalances; no gravity (a static load has no periodic balance here).
    contacts : sequence of RubPlate
        At least one plate; a plate without ``disk_radius`` takes its disk's from the rotor.
    options : BalanceOptions
        Harmonics, AFT samples, tolerance and the DOFs reported.

    Returns
    -------
    RubBalance

    Raises
    ------
    rotorred.checks.InputError
        For a bad input, before any computation: incommensurate speeds, no plate, gravity, a rub node that is not a
        coordinate of the model.
    rotorred.nonlinear.hb.NotConverged
        If Newton does not reach a solution from the transient's record nor from a cold start.
    """
    system = rotor_model(model)
    operating = checked_operating(operating)
    speeds = operating.single(system)
    plates = plates_on(contacts, system.rotor, min_len=1)
    scene = built_scene(system, f"harmonic balance at {operating.describe()}", speeds, balance_loads(loads), plates,
                        SolverSpec(dt=options.dt, method="harmonic-balance"), OutputSpec())
    outputs = options.outputs or tuple((p.node, d) for p in plates for d in ("x", "y"))
    for k, dof in enumerate(outputs):
        system.full_dofs.checked_outputs([dof], f"options.outputs[{k}]")
    H, N = options.harmonics, options.n_samples
    rub_problem(scene, system, H, N)  # every check of the problem before the transient runs
    rp, z, start = cold_solution(scene, system, H, N, record=start_record(scene, system))
    residual = rp.problem.evaluate(z, rp.omega).relative
    return RubBalance(rp, z, start, residual, outputs, operating, dict(speeds))


def continue_balance(model, operating: Operating, loads: Loads, contacts: Sequence[RubPlate],
                     options: BranchOptions = BranchOptions(), *, nodes: Sequence[int] = (),
                     progress=None) -> SceneBranch:
    """The branch of the periodic rub response of ``model`` along the ``operating`` speed line, from its first speed
    to its last, by harmonic balance with pseudo-arclength continuation through the folds, with each point's Floquet
    stability (docs/model.md §15; :func:`rotorred.scenes.branch.continue_scene` in ``speeds.<reference>``).

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        Built from a rotor; each rub node's x and y must be its own coordinates.
    operating : Operating
        A speed line of at least two speeds (the first and last are the branch's ends), every other spool at a ratio
        to the reference (stated or nominal): along the branch every spool keeps its harmonic of the base frequency
        f_0, which moves with the speed. A spool at a fixed speed is refused (its harmonic would change along the
        line: the response is then quasi-periodic).
    loads : Loads
        The unbalances; no gravity.
    contacts : sequence of RubPlate
        At least one plate; a plate without ``disk_radius`` takes its disk's from the rotor.
    options : BranchOptions
        Harmonics, AFT samples, tolerance, stability and the most points.
    nodes : sequence of int
        Nodes whose x and y peaks the branch reports (default: the rub nodes); the first node's y is the response
        the branch is drawn by.
    progress : callable, optional
        As for :func:`rotorred.scenes.branch.continue_scene`.

    Returns
    -------
    SceneBranch
        Its values are the reference spool's speed (Hz).

    Raises
    ------
    rotorred.checks.InputError
        For a bad input, before any computation.
    """
    system = rotor_model(model)
    operating = checked_operating(operating)
    if operating.kind != "line":
        checks.fail("operating", operating.describe(), "must be a speed line of at least two speeds (its ends)")
    lines = operating.lines(system)
    fixed = [s for s, line in lines.items() if line.how == "fixed"]
    if fixed:
        checks.fail("operating", operating.describe(), f"must turn every spool at a ratio to the reference; {fixed} "
                    "at a fixed speed would change its harmonic of f_0 along the line (a quasi-periodic response)")
    reference = operating.reference_of(system)
    plates = plates_on(contacts, system.rotor, min_len=1)
    nodes = recorded_nodes(nodes, [p.node for p in plates], system, "nodes")
    scene = built_scene(system, f"branch along {operating.describe()}", operating.at(system, 0), balance_loads(loads),
                        plates, SolverSpec(method="harmonic-balance", harmonics=options.harmonics,
                                           samples=options.samples), OutputSpec(nodes=nodes, table=(nodes[0], "y")))
    key = f"speeds.{reference}"
    start, end = (float(operating.Omega[i]) / (2 * math.pi) for i in (0, -1))
    check_key(scene, key, start, end)
    return continue_scene(scene, system, key, start, end, options, progress=progress)

