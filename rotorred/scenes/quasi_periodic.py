"""The quasi-periodic rub response of a rotor by harmonic balance on a torus, from Python:
``torus_balance(model, operating, loads, contacts, options)`` (docs/model.md §15).

At spool speeds that are not commensurate the steady response lies on a two-dimensional torus of two base frequencies:
the spools' own or their sub-harmonics (near 88-95 Hz on the outer spool of ``paper-rub`` the impacts lock to
``f_H / 3``). The operating point is read by the one rule of :class:`rotorred.model.operating.Operating`, the model
through :func:`rotorred.model.assembly.system_of`. The steps:

1. a transient from the settled linear state over the options' start window, recording the rub disks and plates;
2. the bases: the options' own, or the torus the signal layer's line fit finds in that record
   (:func:`rotorred.signals.linefit.fit_lines`, bases ``f_L / j`` and ``f_H / k``);
3. the torus problem of :func:`rotorred.scenes.torus_balance.torus_rub_problem`, started from the record fitted by
   least squares on a small box of orders, and solved by Newton (:func:`rotorred.nonlinear.torus.solve_torus`).

With no start window the solution starts from the linear response (enough where the rub is light or absent).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from rotorred import checks
from rotorred.checks import InputError
from rotorred.model.operating import Operating, checked as checked_operating
from rotorred.nonlinear.hb import coefficient_variables
from rotorred.nonlinear.torus import TorusSolution, solve_torus
from rotorred.nonlinear.torus_truncation import TorusTruncation, torus_to_tolerance
from rotorred.results import Result, dof_coordinates, strongest_lines
from rotorred.scenes.built import balance_loads, built_scene, plates_on, rotor_model
from rotorred.scenes.harmonic_balance import unknown_records
from rotorred.scenes.settled import settled_state
from rotorred.scenes.schema import OutputSpec, SolverSpec
from rotorred.scenes.torus_balance import TorusRubProblem, torus_bases, torus_rub_problem
from rotorred.signals.linefit import fit_lines
from rotorred.transient.contact import RubPlate
from rotorred.transient.options import Initial, Loads, Recording, StepControl

__all__ = ["TorusOptions", "RubTorus", "torus_balance", "default_grid"]

#: how often a tolerance may double the orders (:attr:`TorusOptions.ladder`)
DOUBLINGS = 2
#: the coarse torus (H1, H2, N1, N2) a larger box is started through from the record, and its Newton tolerance
COARSE, COARSE_TOL = (10, 40, 32, 256), 1e-6
#: how the solution was started
FROM_RECORD, FROM_LINEAR = "the transient's record (least squares)", "the linear response"


def default_grid(H1: int, H2: int) -> tuple[int, int]:
    """The AFT grid ``(N_1, N_2)`` for the box ``|k_1| <= H1``, ``|k_2| <= H2``: the powers of two at or above
    ``4 H1`` and ``8 H2``, the grids ``validation/hb_torus.py`` converges on for the rig's rub ((16, 70) -> (64, 1024))
    and ``tests/test_nonlinear_torus.py`` uses ((6, 30) -> (32, 256))."""
    return 1 << max(3, math.ceil(math.log2(4 * H1))), 1 << max(3, math.ceil(math.log2(8 * H2)))


@dataclass(frozen=True)
class TorusOptions:
    """The torus, its truncation and its start for :func:`torus_balance`.

    Parameters
    ----------
    bases : (float, float), optional
        Base frequencies ``(f_1, f_2)`` (Hz); every turning spool's frequency must be an order ``k_1 f_1 + k_2 f_2``
        of them. Default: the torus the line fit finds in the start's transient (two turning spools).
    orders : (int, int)
        The box of orders ``|k_1| <= H1``, ``|k_2| <= H2`` (default (16, 70): 1.27 % on the rig's ten largest lines,
        ``validation/hb_torus.py``).
    grid : (int, int), optional
        The AFT grid ``(N_1, N_2)``, each even and > 2 H_i; default :func:`default_grid`.
    f_max : float, optional
        Keep only the orders whose line is at most ``f_max`` (Hz); default 1500 Hz, None for the whole box.
    start_window : (float, float), optional
        The transient's recorded window ``(t_0, t_1)`` (s): it runs to ``t_1`` from the settled linear state and the
        start is fitted on ``[t_0, t_1]``; default (2, 3) s. None: start from the linear response, no transient.
    start_orders : (int, int)
        The box of orders fitted to the record (default (4, 30)); its lines must be at least 2 / (t_1 - t_0) apart.
    dt : float
        Time step of the start's transient (s), > 0.
    tol : float
        Relative residual Newton must reach (-).
    outputs : sequence of (int, str)
        Model DOFs (node, direction) reported; default x and y of every rub node.
    tolerance : float, optional
        Choose the orders by the convergence of the outputs' response (docs/model.md §25): ``orders`` is the first
        truncation, each next doubles both bounds (at most :data:`DOUBLINGS` times, the grid
        :func:`default_grid` of each), and the first whose response changes from the one before by at most
        ``tolerance`` (relative, the largest over the outputs) is returned; ``grid`` must then not be given.
    """

    bases: tuple[float, float] | None = None
    orders: tuple[int, int] = (16, 70)
    grid: tuple[int, int] | None = None
    f_max: float | None = 1500.0
    start_window: tuple[float, float] | None = (2.0, 3.0)
    start_orders: tuple[int, int] = (4, 30)
    dt: float = 2e-5
    tol: float = 1e-10
    outputs: Sequence[tuple[int, str]] = ()
    tolerance: float | None = None

    def __post_init__(self):
        if self.bases is not None:
            object.__setattr__(self, "bases", torus_bases(self.bases))
        H = _pair("options.orders", self.orders, 1)
        object.__setattr__(self, "orders", H)
        if self.grid is not None:
            grid = _pair("options.grid", self.grid, 4)
            for i in range(2):
                if grid[i] % 2 or grid[i] <= 2 * H[i]:
                    checks.fail(f"options.grid[{i}]", grid[i], f"must be even and > 2 * orders[{i}] = {2 * H[i]}")
            object.__setattr__(self, "grid", grid)
        if self.f_max is not None:
            checks.positive("options.f_max", self.f_max, "Hz")
        if self.start_window is not None:
            t = checks.sequence("options.start_window", list(self.start_window), min_len=2, max_len=2)
            t0 = checks.non_negative("options.start_window[0]", t[0], "s")
            t1 = checks.number("options.start_window[1]", t[1], "s", gt=t0)
            object.__setattr__(self, "start_window", (t0, t1))
        object.__setattr__(self, "start_orders", _pair("options.start_orders", self.start_orders, 0))
        checks.positive("options.dt", self.dt, "s")
        checks.number("options.tol", self.tol, gt=0.0, lt=1.0)
        object.__setattr__(self, "outputs", tuple(tuple(o) for o in self.outputs))
        if self.tolerance is not None:
            checks.number("options.tolerance", self.tolerance, gt=0.0, lt=1.0)
            if self.grid is not None:
                checks.fail("options.grid", self.grid, "must not be given with options.tolerance (each truncation "
                            "takes default_grid of its orders)")

    @property
    def ladder(self) -> tuple[tuple[int, int], ...]:
        """The truncations tried with a tolerance: ``orders`` doubled :data:`DOUBLINGS` times."""
        return tuple((self.orders[0] << j, self.orders[1] << j) for j in range(DOUBLINGS + 1))

    @property
    def n_grid(self) -> tuple[int, int]:
        """``(N_1, N_2)``: the grid given, or :func:`default_grid` of the orders."""
        return self.grid if self.grid is not None else default_grid(*self.orders)


def _pair(field: str, value, low: int) -> tuple[int, int]:
    pair = checks.sequence(field, list(np.ravel(value)), min_len=2, max_len=2)
    return tuple(checks.integer(f"{field}[{i}]", v, ge=low) for i, v in enumerate(pair))


@dataclass(frozen=True, repr=False)
class RubTorus(Result):
    """The quasi-periodic rub response of a rotor at an operating point (:func:`torus_balance`).

    Attributes
    ----------
    problem : TorusRubProblem
        The problem solved (its model, bases and orders).
    solution : TorusSolution
        Newton's solution: the coefficients of the unknowns, iterations and residual.
    start : str
        How the solution was started (:data:`FROM_RECORD` or :data:`FROM_LINEAR`).
    outputs : tuple of (int, str)
        The model DOFs reported.
    operating : Operating
        The operating point.
    speeds : dict of str to float
        Speed of every spool there (rad/s).
    solve_time : float
        Wall time of the start's transient and Newton's solve (s).
    truncation : TorusTruncation, optional
        What ``options.tolerance`` chose (None without one).
    """

    problem: TorusRubProblem
    solution: TorusSolution
    start: str
    outputs: tuple
    operating: Operating
    speeds: Mapping[str, float]
    solve_time: float
    truncation: TorusTruncation | None = None

    @property
    def bases_hz(self) -> tuple[float, float]:
        """The base frequencies ``(f_1, f_2)`` (Hz)."""
        return self.problem.bases_hz

    @property
    def orders(self) -> np.ndarray:
        """The order ``(k_1, k_2)`` of each line, shape (K, 2)."""
        return self.problem.problem.harmonics.orders

    @property
    def frequencies(self) -> np.ndarray:
        """The frequency ``|k_1 f_1 + k_2 f_2|`` of each order's line, shape (K,) (Hz)."""
        return np.abs(self.problem.problem.harmonics.frequencies(self.bases_hz))

    @property
    def phasors(self) -> np.ndarray:
        """Complex amplitude ``Q_k = a_k - i b_k`` of each order and output, shape (K, n_outputs) (m or rad): the line
        of order k is ``Re(Q_k exp(i (k_1 theta_1 + k_2 theta_2)))`` with ``theta_i = 2 pi f_i t``."""
        return self.problem.problem.recover(self.solution.z, self.problem.output_rows(self.outputs))

    @property
    def amplitudes(self) -> np.ndarray:
        """Amplitude of each order's line and output, shape (K, n_outputs) (m or rad)."""
        return np.abs(self.phasors)

    def summary(self) -> list[str]:
        """The operating point, the torus, the truncation, the convergence and each output's strongest lines."""
        h, s = self.problem.problem.harmonics, self.solution
        f1, f2 = self.bases_hz
        lines = [f"harmonic balance on a torus of {self.problem.model.name or 'the rotor'} at "
                 f"{self.operating.describe()}",
                 f"bases f_1 = {f1:.6g} Hz, f_2 = {f2:.6g} Hz; spool orders "
                 + ", ".join(f"{sp} {k}" for sp, k in self.problem.spool_orders.items()),
                 f"{h.n_orders} orders (|k1| <= {h.H1}, |k2| <= {h.H2}), grid {h.N1} x {h.N2}; "
                 f"{len(self.problem.problem.dofs)} unknowns",
                 f"{s.iterations} Newton iterations ({sum(s.krylov)} GMRES), relative residual {s.residual:.3g}; "
                 f"{self.solve_time:.3g} s", f"started from {self.start}"]
        if self.truncation is not None:
            lines.append(self.truncation.describe())
        where = [f"{f:.6g} Hz {tuple(int(v) for v in k)}" for f, k in zip(self.frequencies, self.orders)]
        return lines + strongest_lines(self.outputs, self.amplitudes, where)

    def plot(self, ax=None, *, title: str | None = None):
        """The amplitude of each order's line of each output at its frequency (µm, log scale).

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
        """Dims order, output: ``cos`` a_k, ``sin`` b_k and ``amplitude`` (m); the orders' ``k1``, ``k2`` and
        ``frequency`` (Hz); the bases (Hz) on dim base, the spool speeds (rad/s) on dim spool; the start, the Newton
        iterations and the residual as attributes."""
        import xarray as xr

        spools = list(self.speeds)
        return xr.Dataset(
            {**coefficient_variables(self.phasors, ("order", "output")),
             "base_frequency": ("base", np.array(self.bases_hz), {"units": "Hz", "long_name": "base frequencies"}),
             "spool_speed": ("spool", np.array([self.speeds[s] for s in spools]),
                             {"units": "rad/s", "long_name": "spool speed"})},
            coords={"k1": ("order", self.orders[:, 0], {"units": "1", "long_name": "order of f_1"}),
                    "k2": ("order", self.orders[:, 1], {"units": "1", "long_name": "order of f_2"}),
                    "frequency": ("order", self.frequencies, {"units": "Hz", "long_name": "|k1 f_1 + k2 f_2|"}),
                    "spool": ("spool", np.array(spools, dtype=object), {"units": "1", "long_name": "spool"}),
                    **dof_coordinates("output", self.outputs, "reported DOF")},
            attrs={"start": self.start, "iterations": self.solution.iterations,
                   "residual": self.solution.residual})


def torus_balance(model, operating: Operating, loads: Loads, contacts: Sequence[RubPlate],
                  options: TorusOptions = TorusOptions()) -> RubTorus:
    """The quasi-periodic rub response of ``model`` at the ``operating`` point by harmonic balance on a torus
    (docs/model.md §15).

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        Built from a rotor (:func:`rotorred.model.assembly.system_of`); each rub node's x and y must be its own
        coordinates (a boundary node of a reduced model: ``reduce_rotor(rotor, extra_nodes=[node])``).
    operating : Operating
        One point; every turning spool's frequency must be one order of the torus's bases.
    loads : Loads
        The unbalances; no gravity.
    contacts : sequence of RubPlate
        At least one plate; a plate without ``disk_radius`` takes its disk's from the rotor.
    options : TorusOptions
        The bases (default: found in the start's transient), the orders, the grid, the start and the DOFs reported.

    Returns
    -------
    RubTorus

    Raises
    ------
    rotorred.checks.InputError
        For a bad input, before the transient: not one point, no plate, gravity, a rub node that is not a coordinate
        of the model, a spool frequency that is no order of the bases; after the transient, if no bases were given and
        its line fit finds no torus of two incommensurate bases.
    rotorred.transient.results.SimulationDiverged
        If the start's transient diverges (it carries what was computed).
    rotorred.nonlinear.hb.NotConverged
        If Newton does not reach ``options.tol``.
    """
    system = rotor_model(model)
    operating = checked_operating(operating)
    if not isinstance(options, TorusOptions):
        checks.fail("options", type(options).__name__, "must be a TorusOptions")
    speeds = operating.single(system)
    plates = plates_on(contacts, system.rotor, min_len=1)
    scene = built_scene(system, f"torus harmonic balance at {operating.describe()}", speeds, balance_loads(loads),
                        plates, SolverSpec(dt=options.dt, method="harmonic-balance"), OutputSpec())
    outputs = options.outputs or tuple((p.node, d) for p in plates for d in ("x", "y"))
    for k, dof in enumerate(outputs):
        system.full_dofs.checked_outputs([dof], f"options.outputs[{k}]")
    turning = sorted(w / (2 * math.pi) for w in speeds.values() if w > 0)
    if options.bases is None and (options.start_window is None or len(turning) != 2):
        checks.fail("options.bases", None, "must be given where they cannot be found in a transient (a start window "
                    f"and exactly two turning spools; here {len(turning)} turning"
                    + (", no start window)" if options.start_window is None else ")"), "Hz")
    # bases given: the problem, with every check of it, before the transient runs
    rp = None if options.bases is None else _problem(scene, system, options.bases, options)
    t0 = time.perf_counter()
    record = None if options.start_window is None else _start_record(scene, system, operating, options)
    if rp is None:
        rp = _problem(scene, system, _found_bases(record, plates[0].node, turning), options)
    if record is None:
        z0, start = rp.problem.linear_response(), FROM_LINEAR
    else:
        try:
            z0 = rp.start_from_record(record.t, unknown_records(plates, record), within=options.start_orders)
        except InputError as exc:  # the start's lines closer than the record resolves
            checks.fail("options.start_orders", options.start_orders, "must give lines the start window "
                        f"{options.start_window} s resolves: their frequencies {exc.requirement}", exc.unit)
        z0, start = _through_coarse(scene, system, rp, z0, options), FROM_RECORD
    if options.tolerance is None:
        solution, choice = solve_torus(rp.problem, z0, tol=options.tol), None
    else:
        problems = {options.orders: rp}

        def build(H1, H2):
            if (H1, H2) not in problems:
                problems[(H1, H2)] = _problem(scene, system, rp.bases_hz,
                                              replace(options, orders=(H1, H2), tolerance=None))
            return problems[(H1, H2)].problem
        rows = rp.output_rows(outputs)  # every box's problem has the same DOFs
        _, solution, choice = torus_to_tolerance(
            build, options.ladder, z0, options.tolerance,
            lambda problem, z: problem.recover(z, rows), newton_tol=options.tol)
        rp = problems[choice.orders]
    return RubTorus(rp, solution, start, outputs, operating, dict(speeds), time.perf_counter() - t0, choice)


def _through_coarse(scene, system, rp: TorusRubProblem, z0: np.ndarray, options: TorusOptions) -> np.ndarray:
    """The record's start carried to ``rp``'s orders through the coarse torus :data:`COARSE` (solved from it first,
    docs/model.md §25) where ``rp``'s box is larger in both bounds; else ``z0``. On the rig a box of |k1| <= 32,
    |k2| <= 80 from the record alone did not converge at 14 µm of clearance (40 Newton steps, relative residual 0.37);
    through the coarse torus it does."""
    H1, H2, N1, N2 = COARSE
    if not (options.orders[0] > H1 and options.orders[1] > H2):
        return z0
    coarse = torus_rub_problem(scene, system, rp.bases_hz, H1, H2, N1, N2, options.f_max)
    z_c = solve_torus(coarse.problem, rp.problem.harmonics.transfer(z0, rp.problem.n, coarse.problem.harmonics),
                      tol=max(options.tol, COARSE_TOL)).z
    return coarse.problem.harmonics.transfer(z_c, rp.problem.n, rp.problem.harmonics)


def _problem(scene, system, bases, options: TorusOptions) -> TorusRubProblem:
    """The torus problem on ``bases`` (Hz) with the options' orders, grid and band; a spool frequency that is no
    order of the bases is refused as ``options.bases``."""
    try:
        return torus_rub_problem(scene, system, bases, *options.orders, *options.n_grid, options.f_max)
    except InputError as exc:
        if exc.field != "torus":
            raise
        checks.fail("options.bases", bases, exc.requirement, exc.unit)


def _start_record(scene, system, operating: Operating, options: TorusOptions):
    """The transient from the settled linear state to ``t_1``, recording each plate node's x and y from ``t_0``."""
    from rotorred.transient.newmark import simulate  # numba only when a transient runs

    t0, t1 = options.start_window
    nodes = [(p.node, d) for p in scene.plates for d in ("x", "y")]
    return simulate(system, operating, t1, options.dt, loads=Loads(scene.unbalances), contacts=scene.plates,
                    recording=Recording(nodes, start=t0), start=Initial(*settled_state(scene, system)),
                    control=StepControl(progress=False))


def _found_bases(record, node: int, turning: list[float]) -> tuple[float, float]:
    """The torus the line fit finds in the record at ``node`` y, with the two turning spools' frequencies (Hz)."""
    fit = fit_lines(record.t, record.outputs[(node, "y")], turning[0], turning[1])
    torus = fit.torus
    if torus is None or torus.ratio is not None:
        found = "no torus" if torus is None else f"the commensurate torus ({torus.label})"
        checks.fail("options.bases", None, f"must be given: the start's line fit at node {node} y found {found}, not "
                    "two incommensurate bases (a periodic response: harmonic_balance)", "Hz")
    return torus_bases(torus)
