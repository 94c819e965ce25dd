"""Results of :func:`rotorred.transient.newmark.simulate`, their packaging from the kernel's buffers, and the one
dataset of a record (:func:`record_dataset`: the transient's, a scene's and a run-up's)."""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

import numpy as np

from rotorred.results import Result, dof_coordinates
from rotorred.transient import kernel
from rotorred.transient.contact import STATE_NAMES, RubPlate, disk_force
from rotorred.transient.status import LIMIT, NONFINITE, Status


class SimulationDiverged(RuntimeError):
    """The transient diverged; ``result`` holds everything computed until then.

    Attributes
    ----------
    result : TransientResult
        Partial result (``success`` False); every recorded value is finite.
    time : float
        Time of the failing step (s).
    dof : str
        The DOF (or plate) where the failure was detected.
    cause : str
    """

    def __init__(self, message: str, result: TransientResult, time: float, dof: str, cause: str):
        super().__init__(message)
        self.result = result
        self.time = time
        self.dof = dof
        self.cause = cause


@dataclass(frozen=True)
class ContactHistory:
    """Recorded contact quantities of one plate, at the record times of the result.

    Attributes
    ----------
    plate : RubPlate
    normal_force : ndarray, shape (n_rec,)
        P (N), >= 0: the plate pushes the disk along -n with P.
    friction_force : ndarray, shape (n_rec,)
        T (N): friction on the disk along the plate tangent t = (-sin theta, cos theta).
    state : ndarray of int8, shape (n_rec,)
        0 open, 1 slip, 2 stick (:data:`rotorred.transient.contact.STATE_NAMES`).
    u_n, u_t : ndarray, shape (n_rec,)
        Plate rigid-body displacement along n and t (m).
    sliding_velocity : ndarray, shape (n_rec,)
        v_rel = Omega r + (x', y') . t - u_t' (m/s).
    gap : ndarray, shape (n_rec,)
        g = clearance + u_n - (x, y) . n (m), negative in contact.
    """

    plate: RubPlate
    normal_force: np.ndarray
    friction_force: np.ndarray
    state: np.ndarray
    u_n: np.ndarray
    u_t: np.ndarray
    sliding_velocity: np.ndarray
    gap: np.ndarray

    @property
    def force_xy(self) -> np.ndarray:
        """Force on the rotor node (F_x, F_y) (N), shape (n_rec, 2) (Eq. 12)."""
        c, s = self.plate.normal
        return np.column_stack(disk_force(self.normal_force, self.friction_force, c, s))

    def fraction(self, state: str) -> float:
        """Fraction of the records in ``state`` ("open", "slip" or "stick")."""
        code = {v: k for k, v in STATE_NAMES.items()}[state]
        return float(np.mean(self.state == code)) if len(self.state) else 0.0

    def n_impacts(self) -> int:
        """Number of contact onsets (open -> slip or stick) in the record."""
        touching = self.state != 0
        return int(np.count_nonzero(touching[1:] & ~touching[:-1]))


@dataclass(frozen=True)
class FinalState:
    """State after the last completed step (model coordinates).

    Attributes
    ----------
    t : float
        Time (s).
    q, v, a : ndarray, shape (n,)
        Displacement, velocity, acceleration.
    plate : ndarray, shape (n_p, 2, 3)
        Per plate, (normal, tangential) x (displacement (m), velocity (m/s), acceleration (m/s^2)).
    forces : ndarray, shape (n_p, 2)
        Per plate (P, T) (N).
    mode : ndarray of int64, shape (n_p,)
        Per plate, the contact law's branch the next step starts from: 1 slip, 2 stick.
    sgn : ndarray, shape (n_p,)
        Per plate, the slip direction sign(v_rel).

    A run continues another exactly from its ``final`` (``simulate(..., start=final)``).
    """

    t: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    plate: np.ndarray
    forces: np.ndarray
    mode: np.ndarray
    sgn: np.ndarray


@dataclass(frozen=True, repr=False)
class TransientResult(Result):
    """Result of :func:`simulate`.

    Attributes
    ----------
    t : ndarray, shape (n_rec,)
        Record times (s).
    outputs : dict of (int, str) to ndarray, shape (n_rec,)
        Displacement (m) or rotation (rad) of each requested (node, direction).
    contacts : tuple of ContactHistory
        One per plate, in the order given.
    success : bool
    status : int
        A code of :mod:`rotorred.transient.status`: ``RUNNING`` (0) when finished, else the failure
        (``Status(status).message`` says which).
    message : str
    final : FinalState
    method : str
    dt, gamma, beta, alpha : float
    n_steps : int
        Completed main steps.
    n_substeps : int
        Completed half-steps taken to cure failed steps.
    n_newton : int
        Newton iterations (all steps).
    n_contact_steps : int
        (Sub)steps where at least one plate touched.
    max_newton_per_solve : int
    n_factorizations : int
        Step matrices factorised (one per step size level).
    setup_time, run_time : float
        Wall time of the matrix preparation and of the step loop (s).
    run_cpu_time : float
        CPU time of the step loop (s).
    kernel_load_time : float
        Time to compile the step kernel (first run after an install) or load it from numba's cache,
        before the loop (s); not in ``run_time`` nor in µs per step.
    kernel_compiled : bool
        Whether the step kernel was compiled for this run (not loaded from numba's on-disk cache).
    n_passes : int
        Fixed-point passes of the steps at varying speeds (0 at constant speeds).
    states : ndarray, shape (n_rec, 2 n), or None
        With ``Recording(states=True)``: q and v (model coordinates) at the record times.
    step_form : str
        Which constant-speed step ran and why (``"eigenbasis, cond(P) = ..."``, ``"dense: ..."``); empty at
        varying speeds.
    """

    t: np.ndarray
    outputs: dict
    contacts: tuple
    success: bool
    status: int
    message: str
    final: FinalState
    method: str
    dt: float
    gamma: float
    beta: float
    alpha: float
    n_steps: int
    n_substeps: int
    n_newton: int
    n_contact_steps: int
    max_newton_per_solve: int
    n_factorizations: int
    setup_time: float
    run_time: float
    run_cpu_time: float = 0.0
    kernel_load_time: float = 0.0
    kernel_compiled: bool = False
    n_passes: int = 0
    states: np.ndarray | None = None
    step_form: str = ""

    @property
    def us_per_step(self) -> float:
        """Step-loop wall time per main step (µs)."""
        return 1e6 * self.run_time / max(self.n_steps, 1)

    @property
    def cpu_us_per_step(self) -> float:
        """Step-loop CPU time of this process per main step (µs); robust to other load on the machine."""
        return 1e6 * self.run_cpu_time / max(self.n_steps, 1)

    def summary(self) -> list[str]:
        """The scheme and steps, how it ended, the peak of each output (a few), the contacts, the cost."""
        span = f"{len(self.t)} records, t = {self.t[0]:.6g}-{self.t[-1]:.6g} s" if len(self.t) else "no record"
        lines = [f"{self.method}, {self.n_steps} steps of {self.dt:g} s to t = {self.final.t:.6g} s; {span}",
                 "finished" if self.success else shorten(f"stopped (status {self.status}): {self.message}")]
        lines += peak_lines(self.outputs)
        lines += [contact_line(k, ch) for k, ch in enumerate(self.contacts[:_LISTED])]
        lines.append(shorten(f"{self.us_per_step:.2f} µs/step; {self.n_newton} Newton iterations, "
                             f"{self.n_contact_steps} contact steps, {self.n_substeps} half-steps"
                             + (f"; {self.step_form}" if self.step_form else "")))
        return lines

    def plot(self, ax=None, **options):
        """The recorded outputs against time and, when recorded, each plate's contact forces
        (:func:`rotorred.plots.scene.draw_transient`); into a given ``ax``, the displacements.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            ``t_window`` (s), ``title``.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.scene import draw_transient

        return draw_transient(self, ax, **options)

    def to_xarray(self):
        """The record as an :class:`xarray.Dataset` (:func:`record_dataset`), with the scheme and how the run ended as
        attributes (``method``, ``dt`` (s), ``status``, ``message``, ``n_steps``); the states (``record_state``) are
        left out (model coordinates)."""
        return record_dataset(self.t, self.outputs, self.contacts, {
            "title": "transient record", "method": self.method, "dt": self.dt, "gamma": self.gamma, "beta": self.beta,
            "alpha": self.alpha, "status": int(self.status), "message": self.message, "n_steps": int(self.n_steps)})


#: outputs and plates a summary names one by one
_LISTED = 4
#: longest line of a summary
_WIDTH = 116


def shorten(text: str) -> str:
    """``text`` on one line of a summary (at most 116 characters, cut at a word with "...")."""
    return textwrap.shorten(text, _WIDTH, placeholder=" ...")


def peak_lines(outputs: dict) -> list[str]:
    """Lines of a summary: the largest |value| of each recorded DOF (the first :data:`_LISTED`; µm or µrad)."""
    lines = []
    for (node, d), y in list(outputs.items())[:_LISTED]:
        unit = "µrad" if d.startswith("t") else "µm"
        lines.append(f"node {node} {d}: peak {1e6 * float(np.max(np.abs(y), initial=0.0)):.4g} {unit}")
    if len(outputs) > _LISTED:
        lines.append(f"... {len(outputs) - _LISTED} more outputs")
    return lines


def contact_line(k: int, ch: ContactHistory) -> str:
    """A line of a summary: how much plate ``k`` touched, its impacts and its largest normal force."""
    touching = 100.0 * (1.0 - ch.fraction("open"))
    return (f"plate {k} at node {ch.plate.node}: contact in {touching:.3g} % of the records, {ch.n_impacts()} impacts, "
            f"largest normal force {float(np.max(ch.normal_force, initial=0.0)):.4g} N")


def dof_groups(dofs) -> list[tuple[str, str, list]]:
    """The recorded DOFs by what they measure, as a dataset names them: ``(prefix, units, dofs)``, ``("", "m",
    ...)`` for displacements (x, y) and ``("rotation_", "rad", ...)`` for rotations; groups without a DOF left out."""
    groups = [("", "m", [d for d in dofs if not d[1].startswith("t")]),
              ("rotation_", "rad", [d for d in dofs if d[1].startswith("t")])]
    return [g for g in groups if g[2]]


def record_dataset(t, outputs: dict, contacts=(), attrs: dict | None = None):
    """A record as an :class:`xarray.Dataset`: the one builder of the record of a transient
    (:meth:`TransientResult.to_xarray`), a scene and a run-up.

    Dimensions ``time`` (coordinate, s), ``output`` (the recorded displacements, labels ``"13:x"`` with ``node``
    and ``direction``), ``rotation_output`` (the recorded rotations, if any) and ``plate``. Variables
    ``displacement`` (time, output) in m and ``rotation`` (time, rotation_output) in rad; per plate (plate, time)
    ``normal_force`` and ``friction_force`` (N), ``contact_state`` (0 open, 1 slip, 2 stick), ``u_n``, ``u_t`` and
    ``gap`` (m), ``sliding_velocity`` (m/s), with the plates' ``plate_node``, ``plate_angle`` (rad) and
    ``plate_clearance`` (m).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Record times (s).
    outputs : dict of (int, str) to ndarray, shape (n,)
    contacts : sequence of ContactHistory
    attrs : dict, optional
        The dataset's attributes.
    """
    import xarray as xr


    data, coords = {}, {"time": ("time", np.asarray(t, float), {"units": "s", "long_name": "record time"})}
    for prefix, units, dofs in dof_groups(list(outputs)):
        name = "rotation" if prefix else "displacement"
        data[name] = (("time", f"{prefix}output"), np.array([outputs[d] for d in dofs], float).reshape(
            len(dofs), len(t)).T, {"units": units, "long_name": f"recorded {name}"})
        coords.update(dof_coordinates(f"{prefix}output", dofs, f"recorded DOF ({name})"))
    if contacts:
        flags = {"flag_values": np.array(sorted(STATE_NAMES), np.int8),
                 "flag_meanings": " ".join(STATE_NAMES[k] for k in sorted(STATE_NAMES))}
        for name, units, long_name, extra in (
                ("normal_force", "N", "normal force P of the plate on the disk (>= 0)", {}),
                ("friction_force", "N", "friction force T on the disk along the plate tangent", {}),
                ("contact_state", "1", "contact state", flags),
                ("u_n", "m", "plate displacement along its normal", {}),
                ("u_t", "m", "plate displacement along its tangent", {}),
                ("sliding_velocity", "m/s", "sliding velocity v_rel", {}),
                ("gap", "m", "gap, negative in contact", {})):
            values = np.array([getattr(ch, "state" if name == "contact_state" else name) for ch in contacts])
            data[name] = (("plate", "time"), values, {"units": units, "long_name": long_name, **extra})
        coords.update({
            "plate_node": ("plate", np.array([ch.plate.node for ch in contacts], np.int64),
                           {"units": "1", "long_name": "node of the rubbing disk"}),
            "plate_angle": ("plate", np.array([ch.plate.theta for ch in contacts], float),
                            {"units": "rad", "long_name": "angle theta of the plate's normal"}),
            "plate_clearance": ("plate", np.array([ch.plate.clearance for ch in contacts], float),
                                {"units": "m", "long_name": "radial clearance"})})
    return xr.Dataset(data, coords, attrs=dict(attrs or {}))


def contact_histories(plates, record: kernel.Record) -> tuple[ContactHistory, ...]:
    """One :class:`ContactHistory` per plate from the kernel's record buffers (the rows written)."""
    nr = int(record.count[0])
    columns = {"normal_force": kernel.R_P, "friction_force": kernel.R_T, "u_n": kernel.R_UN, "u_t": kernel.R_UT,
               "sliding_velocity": kernel.R_VREL, "gap": kernel.R_GAP}
    return tuple(ContactHistory(plate=p, state=record.state[:nr, k].copy(),
                                **{name: record.plate[:nr, k, col].copy() for name, col in columns.items()})
                 for k, p in enumerate(plates))


def failure(model, plates, status: int, err: np.ndarray, max_halvings: int, t_done: float) -> tuple[str, str, str]:
    """(message, dof, cause) of a run that stopped with ``status`` (the kernel's ``Diagnostics.err``)."""
    if status == NONFINITE:
        dof = _dof_label(model, int(err[kernel.E_DOF]))
    elif status == LIMIT:
        j = -int(err[kernel.E_DOF]) - 1
        dof = f"plate {j // 2} node {plates[j // 2].node} {'xy'[j % 2]}"
    else:
        k = int(err[kernel.E_PLATE])
        dof = f"plate {k} at node {plates[k].node}" if plates else "contact"
    cause = Status(status).message
    message = (f"diverged at t = {float(err[kernel.E_TIME]):.9g} s ({dof}): {cause}, not cured by halving the step "
               f"{max_halvings} times; results kept up to t = {t_done:.9g} s")
    return message, dof, cause


def _dof_label(model, i: int) -> str:
    if hasattr(model, "boundary_dofs") and hasattr(model, "full_dofs"):
        nb = len(model.boundary_dofs)
        if i < nb:
            return model.full_dofs.label(int(model.boundary_dofs[i]))
        return f"modal coordinate {i - nb}"
    return model.dofs.label(i)
