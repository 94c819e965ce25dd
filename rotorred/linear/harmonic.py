"""Steady-state harmonic response: unbalance response over a speed sweep, FRFs, and the
steady state at one operating point in model coordinates (a transient's initial condition).

Each analysis takes ``(model, operating, ...)``: a :class:`~rotorred.model.rotor.Rotor`, its
:class:`~rotorred.model.assembly.SystemMatrices` or a reduced model
(:class:`~rotorred.linear.reduction.ReducedSystem`), read through
:func:`~rotorred.model.assembly.system_of` (``M, K, damping(speeds), spools, spool_of`` and
``output_rows(outputs)``), and the spool speeds as one :class:`~rotorred.model.operating.Operating`.

A physical force ``f`` at (node, direction) enters the model's coordinates as ``rowᵀ f`` with
``row = output_rows([(node, direction)])`` (virtual work; for a full model this is the unit vector,
for a reduced one the row of the recovery map T, i.e. ``Tᵀ f``).

Conventions
-----------
Unbalance ``m_e`` at phase ``phi`` on a node of spool ``s`` spinning at ``Omega_s`` gives
(:class:`rotorred.model.loads.Unbalance`) ``F = m_e Omega_s² [cos(Omega_s t + phi), sin(Omega_s t + phi)]``,
i.e. ``F = Re(F̂ e^{i Omega_s t})`` with the phasors ``F̂_x = m_e Omega_s² e^{i phi}``,
``F̂_y = -i m_e Omega_s² e^{i phi}``. The response is ``q(t) = Re(Q e^{i Omega_s t})`` with

    Q = (K - Omega_s² M + i Omega_s (C + sum_t Omega_t G_t))^-1 F̂,

where every spool ``t`` spins at its own speed ``Omega_t`` (Xu et al. 2016, Eq. 13, steady
state, F_L = 0). Along a speed line the spool speeds follow the reference speed by the one rule
:meth:`Operating.lines <rotorred.model.operating.Operating.lines>`, ``Omega_t = a_t Omega_ref + b_t`` (a stated or
nominal ratio, or a fixed speed).

Two spools at different speeds excite two different frequencies: their responses add in
time, ``q(t) = Re(Q_inner e^{i Omega_inner t}) + Re(Q_outer e^{i Omega_outer t})``, not as one
phasor. The result therefore keeps one phasor per excitation spool, and reports as
``peak`` the sum of the magnitudes over distinct frequencies (spools running at exactly the
same speed are first added as phasors): an upper bound of the peak displacement of the
two-frequency signal, reached only when the two cosines line up. With a commensurate ratio
such as 70:90 Hz the signal is periodic and the true peak lies somewhat below the bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from rotorred import checks, writers
from rotorred.model.assembly import system_of
from rotorred.model import sparse
from rotorred.model.loads import Unbalance
from rotorred.results import Result, dof_coordinates, label_coordinate
from rotorred.model.operating import Operating
from rotorred.model.operating import checked as checked_operating

Output = tuple[int, str]
#: significant digits of the CSV files
CSV_DIGITS = 10
#: most outputs (or FRF pairs) a repr lists, a line each
_LISTED = 8
_RPM = 60.0 / (2.0 * math.pi)


@dataclass(frozen=True, repr=False)
class UnbalanceResponse(Result):
    """Steady-state unbalance response over a speed sweep.

    Attributes
    ----------
    speeds : ndarray, shape (n,)
        Reference spool speed at each sweep point (rad/s).
    reference_spool : str
        The spool whose speed :attr:`speeds` gives.
    spool_speeds : dict of str to ndarray, shape (n,)
        Speed of every spool (rad/s) at each sweep point (:meth:`Operating.speeds`).
    outputs : tuple of (int, str)
        Requested physical DOFs (node, direction).
    phasors : dict of str to dict of (int, str) to ndarray, shape (n,), complex
        ``phasors[spool][output]``: complex amplitude Q (m) of the response to the unbalances
        of ``spool``, at that spool's frequency: ``q(t) = Re(Q e^{i Omega_spool t})``.
        Only spools carrying an unbalance appear.
    operating : Operating or None
        The speed line of the sweep.
    """

    speeds: np.ndarray
    reference_spool: str
    spool_speeds: Mapping[str, np.ndarray]
    outputs: tuple[Output, ...]
    phasors: Mapping[str, Mapping[Output, np.ndarray]]
    operating: Operating | None = None

    @property
    def excited_spools(self) -> tuple[str, ...]:
        """Spools carrying an unbalance."""
        return tuple(self.phasors)

    def amplitude(self, output: Output, spool: str) -> np.ndarray:
        """``|Q|`` (m) of ``output`` at ``spool``'s frequency, shape (n,).

        Parameters
        ----------
        output : (int, str)
            (node, direction) of a DOF of :attr:`outputs`, e.g. ``(13, "x")``.
        spool : str
            A spool carrying an unbalance (:attr:`excited_spools`).
        """
        return np.abs(self.phasors[spool][tuple(output)])

    def phase(self, output: Output, spool: str) -> np.ndarray:
        """arg Q (rad) of ``output`` at ``spool``'s frequency, shape (n,): ``q(t) = |Q| cos(Omega_s t + arg Q)``.

        Parameters
        ----------
        output : (int, str)
            (node, direction) of a DOF of :attr:`outputs`, e.g. ``(13, "x")``.
        spool : str
            A spool carrying an unbalance (:attr:`excited_spools`).
        """
        return np.angle(self.phasors[spool][tuple(output)])

    def peak(self, output: Output) -> np.ndarray:
        """Upper bound of the peak displacement (m) of ``output``, shape (n,).

        Phasors of spools at the same speed are added first; the magnitudes of the
        resulting distinct-frequency phasors are then summed.

        Parameters
        ----------
        output : (int, str)
            (node, direction) of a DOF of :attr:`outputs`, e.g. ``(13, "x")``.
        """
        output = tuple(output)
        total = np.zeros(len(self.speeds))
        spools = list(self.phasors)
        for k in range(len(self.speeds)):
            groups: dict[float, complex] = {}
            for s in spools:
                w = float(self.spool_speeds[s][k])
                groups[w] = groups.get(w, 0.0) + self.phasors[s][output][k]
            total[k] = sum(abs(v) for v in groups.values())
        return total

    def time_history(self, output: Output, t: np.ndarray) -> np.ndarray:
        """q(t) (m) of ``output`` at every sweep point, shape (n, len(t)); the superposed signal.

        Parameters
        ----------
        output : (int, str)
            (node, direction) of a DOF of :attr:`outputs`, e.g. ``(13, "x")``.
        t : array_like, shape (m,)
            Times (s).

        Returns
        -------
        ndarray, shape (n, m)
            ``sum_s Re(Q_s e^{i Omega_s t})`` (m) at each sweep point (row) and time (column).
        """
        t = np.asarray(t, dtype=float)
        out = np.zeros((len(self.speeds), len(t)))
        for s in self.phasors:
            Q = self.phasors[s][tuple(output)]
            w = self.spool_speeds[s]
            out += np.real(Q[:, None] * np.exp(1j * w[:, None] * t[None, :]))
        return out

    def write_csv(self, path: str | Path) -> Path:
        """Write the sweep as CSV: speeds in rpm, amplitudes in µm, phases in degrees.

        Columns: ``<spool> speed (rpm)`` for every spool, then for every output and excited
        spool ``node N dir @<spool> amplitude (um)`` and ``... phase (deg)``, then
        ``node N dir peak bound (um)``.

        Parameters
        ----------
        path : str or Path
            The CSV file to write.

        Returns
        -------
        Path
            ``path``.
        """
        path = Path(path)
        header = [f"{s} speed (rpm)" for s in self.spool_speeds]
        cols = [self.spool_speeds[s] * 60 / (2 * math.pi) for s in self.spool_speeds]
        for o in self.outputs:
            name = f"node {o[0]} {o[1]}"
            for s in self.phasors:
                header += [f"{name} @{s} amplitude (um)", f"{name} @{s} phase (deg)"]
                cols += [1e6 * self.amplitude(o, s), np.degrees(self.phase(o, s))]
            header.append(f"{name} peak bound (um)")
            cols.append(1e6 * self.peak(o))
        return writers.write_csv(path, header, cols, digits=CSV_DIGITS)

    def summary(self) -> list[str]:
        """The sweep, the excited spools, and the largest peak bound of each output."""
        rpm = self.speeds * _RPM
        top = int(np.argmax(self.speeds))
        ratios = [f"{s}/{self.reference_spool} = {w[top] / self.speeds[top]:.4g}" for s, w in self.spool_speeds.items()
                  if s != self.reference_spool and self.speeds[top] > 0]
        lines = [f"unbalances on the {', '.join(self.excited_spools)} spool(s); {len(rpm)} speeds of the "
                 f"{self.reference_spool} spool, {rpm.min():.6g}-{rpm.max():.6g} rpm"
                 + (f"; speed ratios {', '.join(ratios)}" if ratios else "")]
        for o in self.outputs[:_LISTED]:
            peak = self.peak(o)
            k = int(np.argmax(peak))
            lines.append(f"node {o[0]} {o[1]}: largest peak bound {1e6 * peak[k]:.4g} µm at {rpm[k]:.6g} rpm")
        if len(self.outputs) > _LISTED:
            lines.append(f"... {len(self.outputs) - _LISTED} more outputs")
        return lines

    def plot(self, ax=None, kind: str = "bode", **options):
        """Draw the response; return the Figure.

        ``kind="bode"`` (default): amplitude (µm, log) and phase (deg) against the reference speed (rpm), a
        column per output (:func:`rotorred.plots.harmonic.draw_bode`); ``kind="polar"``: the phasor tips
        (:func:`rotorred.plots.harmonic.draw_polar`). Into a given ``ax`` (one panel), Bode draws the
        amplitudes and polar the phasor tips of every output.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        kind : {"bode", "polar"}
            The kind of plot.
        **options
            ``title``.

        Returns
        -------
        matplotlib.figure.Figure

        Raises
        ------
        InputError
            If ``kind`` is neither ``"bode"`` nor ``"polar"``.
        """
        from rotorred.plots.harmonic import draw_bode, draw_polar

        draw = {"bode": draw_bode, "polar": draw_polar}[checks.choice("kind", kind, ("bode", "polar"))]
        return draw(self, ax, **options)

    def to_xarray(self):
        """The sweep as an :class:`xarray.Dataset`.

        Dimensions ``speed`` (coordinate: the reference spool's speed, rad/s), ``spool``, ``excited_spool``
        (spools carrying an unbalance) and ``output`` (labels ``"13:x"``, with coordinates ``node`` and
        ``direction``). Variables ``spool_speed`` (spool, speed) in rad/s, ``amplitude`` ``|Q|`` (m) and ``phase``
        arg Q (rad) (excited_spool, speed, output), and ``peak_bound`` (speed, output) in m (:meth:`peak`).
        """
        import xarray as xr

        excited, dims = self.excited_spools, ("excited_spool", "speed", "output")
        amplitude = np.array([[self.amplitude(o, s) for o in self.outputs] for s in excited]).transpose(0, 2, 1)
        phase = np.array([[self.phase(o, s) for o in self.outputs] for s in excited]).transpose(0, 2, 1)
        data = {
            "spool_speed": (("spool", "speed"), np.array([self.spool_speeds[s] for s in self.spool_speeds], float),
                            {"units": "rad/s", "long_name": "speed of the spool"}),
            "amplitude": (dims, amplitude, {"units": "m", "long_name": "amplitude |Q| of the response to the "
                                                                      "spool's unbalances, at the spool's speed"}),
            "phase": (dims, phase, {"units": "rad", "long_name": "phase arg Q, q(t) = |Q| cos(Omega t + arg Q)"}),
            "peak_bound": (("speed", "output"), np.array([self.peak(o) for o in self.outputs]).T,
                           {"units": "m", "long_name": "peak bound: sum of the magnitudes over distinct frequencies"}),
        }
        coords = {"speed": ("speed", self.speeds, {"units": "rad/s", "long_name": f"speed of the "
                                                                                  f"{self.reference_spool} spool"}),
                  "spool": label_coordinate("spool", list(self.spool_speeds), "spool"),
                  "excited_spool": label_coordinate("excited_spool", list(excited), "spool carrying an unbalance"),
                  **dof_coordinates("output", self.outputs, "response DOF")}
        return xr.Dataset(data, coords, attrs={"title": "unbalance response", "reference_spool": self.reference_spool})


@dataclass(frozen=True, repr=False)
class FrequencyResponse(Result):
    """Frequency response functions between physical DOFs at fixed spool speeds.

    Attributes
    ----------
    frequencies : ndarray, shape (n,)
        Excitation frequencies omega (rad/s).
    speeds : dict of str to float
        Spool speeds (rad/s) held during the sweep.
    inputs, outputs : tuple of (int, str)
        Force DOFs and response DOFs (node, direction).
    H : ndarray, shape (n, len(outputs), len(inputs)), complex
        Receptance (m/N): ``H[k, o, i]`` = displacement phasor at ``outputs[o]`` per unit
        force phasor at ``inputs[i]`` at ``frequencies[k]``. Use :meth:`h` to read one pair.
    operating : Operating or None
        The operating point where the spools turn.
    """

    frequencies: np.ndarray
    speeds: Mapping[str, float]
    inputs: tuple[Output, ...]
    outputs: tuple[Output, ...]
    H: np.ndarray
    operating: Operating | None = None

    def h(self, output: Output, input: Output) -> np.ndarray:  # noqa: A002 - FRF vocabulary
        """Receptance (m/N) from ``input`` to ``output``, shape (n,).

        Parameters
        ----------
        output : (int, str)
            (node, direction) of a response DOF of :attr:`outputs`.
        input : (int, str)
            (node, direction) of a force DOF of :attr:`inputs`.
        """
        return self.H[:, self.outputs.index(tuple(output)), self.inputs.index(tuple(input))]

    def write_csv(self, path: str | Path) -> Path:
        """Write ``|H|`` (m/N) and phase (deg) of every pair against frequency (Hz).

        Parameters
        ----------
        path : str or Path
            The CSV file to write.

        Returns
        -------
        Path
            ``path``.
        """
        path = Path(path)
        header, cols = ["frequency (Hz)"], [self.frequencies / (2 * math.pi)]
        for o in self.outputs:
            for i in self.inputs:
                name = f"node {o[0]} {o[1]} / node {i[0]} {i[1]}"
                header += [f"{name} |H| (m/N)", f"{name} phase (deg)"]
                cols += [np.abs(self.h(o, i)), np.degrees(np.angle(self.h(o, i)))]
        return writers.write_csv(path, header, cols, digits=CSV_DIGITS)

    def summary(self) -> list[str]:
        """The sweep, the spool speeds, and the largest ``|H|`` of each pair."""
        f = self.frequencies / (2 * math.pi)
        lines = [f"receptance of {len(self.outputs)} output(s) x {len(self.inputs)} input(s) at {len(f)} frequencies, "
                 f"{f.min():.4g}-{f.max():.4g} Hz",
                 "spool speeds: " + (", ".join(f"{s} {w * _RPM:.6g} rpm" for s, w in self.speeds.items())
                                     or "not spinning")]
        pairs = [(o, i) for o in self.outputs for i in self.inputs]
        for o, i in pairs[:_LISTED]:
            h = np.abs(self.h(o, i))
            k = int(np.argmax(h))
            lines.append(f"node {o[0]} {o[1]} / node {i[0]} {i[1]}: largest |H| {h[k]:.4g} m/N at {f[k]:.4g} Hz")
        if len(pairs) > _LISTED:
            lines.append(f"... {len(pairs) - _LISTED} more pairs")
        return lines

    def plot(self, ax=None, **options):
        """Bode plot of every pair, ``|H|`` (m/N, log) above the phase (deg) against frequency (Hz)
        (:func:`rotorred.plots.harmonic.draw_frf`; into a given ``ax``, ``|H|`` only).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            ``title``.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.harmonic import draw_frf

        return draw_frf(self, ax, **options)

    def to_xarray(self):
        """The FRFs as an :class:`xarray.Dataset`: dimensions ``frequency`` (coordinate in Hz), ``output`` and
        ``input`` (labels ``"13:x"``, with ``*_node`` and ``*_direction``), ``spool``; variables ``amplitude``
        ``|H|`` (m/N) and ``phase`` arg H (rad) (frequency, output, input), and ``spool_speed`` (spool) in rad/s."""
        import xarray as xr

        dims = ("frequency", "output", "input")
        data = {"amplitude": (dims, np.abs(self.H), {"units": "m/N", "long_name": "receptance |H|"}),
                "phase": (dims, np.angle(self.H), {"units": "rad", "long_name": "phase of the receptance, arg H"}),
                "spool_speed": ("spool", np.array(list(self.speeds.values()), float),
                                {"units": "rad/s", "long_name": "spool speed held during the sweep"})}
        coords = {"frequency": ("frequency", self.frequencies / (2 * math.pi),
                                {"units": "Hz", "long_name": "excitation frequency"}),
                  "spool": label_coordinate("spool", list(self.speeds), "spool"),
                  **dof_coordinates("output", self.outputs, "response DOF"),
                  **dof_coordinates("input", self.inputs, "force DOF")}
        return xr.Dataset(data, coords, attrs={"title": "receptance FRF"})


@dataclass(frozen=True, repr=False)
class SteadyState(Result):
    """Steady-state unbalance response at one operating point, in the model's own coordinates.

    Use it as the initial condition of a transient run, so the start-up transient of lightly
    damped modes need not die out first: ``q(0) = displacement(0)``, ``q'(0) = velocity(0)``.

    Attributes
    ----------
    speeds : dict of str to float
        Spool speeds (rad/s).
    phasors : dict of str to ndarray, shape (n,), complex
        Complex amplitude of every model coordinate (m, rad; modal coordinates of a reduced model) for the
        unbalances of each spool, at that spool's frequency ``speeds[spool]``.
    operating : Operating or None
        The operating point.
    """

    speeds: Mapping[str, float]
    phasors: Mapping[str, np.ndarray]
    operating: Operating | None = None

    def displacement(self, t: float) -> np.ndarray:
        """q(t) = sum_s Re(Q_s e^{i Omega_s t}) (model coordinates), shape (n,).

        Parameters
        ----------
        t : float
            Time (s).
        """
        return sum(np.real(Q * np.exp(1j * self.speeds[s] * t)) for s, Q in self.phasors.items())

    def velocity(self, t: float) -> np.ndarray:
        """q'(t) = sum_s Re(i Omega_s Q_s e^{i Omega_s t}) (m/s, rad/s), shape (n,).

        Parameters
        ----------
        t : float
            Time (s).
        """
        return sum(np.real(1j * self.speeds[s] * Q * np.exp(1j * self.speeds[s] * t))
                   for s, Q in self.phasors.items())

    def summary(self) -> list[str]:
        """The spool speeds, and the largest amplitude per excited spool."""
        lines = ["spool speeds: " + ", ".join(f"{s} {w * _RPM:.6g} rpm" for s, w in self.speeds.items())]
        for s, Q in self.phasors.items():
            k = int(np.argmax(np.abs(Q)))
            lines.append(f"{s} unbalance: {len(Q)} model coordinates, largest |Q| {abs(Q[k]):.4g} at coordinate {k}")
        return lines

    def plot(self, ax=None, **options):
        """Draw the steady state (:func:`rotorred.plots.harmonic.draw_steady_state`, its options); return the Figure.

        With ``model=`` and ``node=``, the node's orbit (µm) over a few revolutions, its start q(0) marked:
        what a rotordynamics engineer checks of a steady state (its size and shape, the rosette of two spools,
        the initial condition a transient starts from). By default, without a model (the result holds only
        model coordinates): the amplitude ``|Q|`` of every model coordinate per excited spool.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            Those of :func:`~rotorred.plots.harmonic.draw_steady_state` (``model``, ``node``, ...).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.harmonic import draw_steady_state

        return draw_steady_state(self, ax, **options)

    def to_xarray(self):
        """The phasors as an :class:`xarray.Dataset`: dimensions ``coordinate`` (index of the model's coordinate),
        ``excited_spool`` and ``spool``; variables ``amplitude`` ``|Q|`` and ``phase`` arg Q (rad) (excited_spool,
        coordinate), and ``spool_speed`` (spool) in rad/s. The amplitudes have the units of the model's
        coordinates, m and rad for a full model (its DOF order), those of the recovery map for a reduced one:
        the ``units`` attribute says "1" and ``comment`` says so."""
        import xarray as xr

        Q = np.array(list(self.phasors.values()))
        n = Q.shape[1] if Q.ndim == 2 else 0
        dims = ("excited_spool", "coordinate")
        comment = "in the units of each model coordinate: m (translations), rad (rotations) of a full model"
        data = {"amplitude": (dims, np.abs(Q), {"units": "1", "long_name": "amplitude |Q| of the model coordinate",
                                                "comment": comment}),
                "phase": (dims, np.angle(Q), {"units": "rad", "long_name": "phase arg Q, "
                                                                            "q(t) = |Q| cos(Omega t + arg Q)"}),
                "spool_speed": ("spool", np.array(list(self.speeds.values()), float),
                                {"units": "rad/s", "long_name": "spool speed"})}
        coords = {"coordinate": ("coordinate", np.arange(n), {"units": "1", "long_name": "model coordinate"}),
                  "spool": label_coordinate("spool", list(self.speeds), "spool"),
                  "excited_spool": label_coordinate("excited_spool", list(self.phasors), "spool carrying an unbalance")}
        return xr.Dataset(data, coords, attrs={"title": "steady unbalance response"})


def steady_state(model, operating: Operating, unbalances: Sequence[Unbalance]) -> SteadyState:
    """Steady-state unbalance response of ``model`` at the operating point ``operating``.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        Read through :func:`rotorred.model.assembly.system_of`; the spool of each node is the model's
        ``spool_of``.
    operating : Operating
        One operating point (:meth:`Operating.point`): the speed of every spool (rad/s) by
        :meth:`Operating.single`.
    unbalances : sequence of Unbalance
        Each rotates with the spool its node belongs to.

    Returns
    -------
    SteadyState
        Phasors of shape (n_dof,) in the model's coordinates.
    """
    model = system_of(model, sparse_ok=True)
    speeds = checked_operating(operating).single(model)
    forces = unbalance_forces(model, unbalances)
    matrices = _Matrices(model, speeds)
    phasors = {}
    for s, f in forces.items():
        w = speeds[s]
        if w == 0.0:
            phasors[s] = np.zeros(model.n_dof, dtype=complex)
            continue
        phasors[s] = matrices.solve(w, w * w * f)
    return SteadyState(speeds=speeds, phasors=phasors, operating=operating)


class _Matrices:
    """A model's dynamic stiffness at spool speeds ``speeds`` (rad/s), ``K - w^2 M + i w D`` for an excitation
    frequency ``w`` (rad/s): an internal loss factor eta is taken at ``w`` itself (viscous eta / |w|: the
    hysteretic force i sign(w) eta K_shaft in the rotating frame's terms, docs/model.md §19), else D and K are
    evaluated once."""

    def __init__(self, model, speeds):
        self.model, self.speeds = model, speeds
        self.fixed = None if model.frequency_dependent else (model.damping(speeds), model.stiffness(speeds))

    def dynamic_stiffness(self, w: float) -> np.ndarray:
        if self.fixed is not None:
            D, K = self.fixed
        elif w == 0.0:  # eta / |w| K w: the hysteretic force stays finite; at w = 0 its viscous form is not needed
            D, K = self.model.damping(self.speeds, np.inf), self.model.stiffness(self.speeds, np.inf)
        else:
            D, K = self.model.damping(self.speeds, w), self.model.stiffness(self.speeds, w)
        return K - w * w * self.model.M + 1j * w * D

    def solve(self, w: float, rhs: np.ndarray) -> np.ndarray:
        """``dynamic_stiffness(w)^-1 rhs``, ``rhs`` shape (n,) or (n, k): a dense LU, or a sparse one (SuperLU, a
        fill-reducing order of A + A^T: a beam model's banded matrix factorises in O(n)) for a sparse model."""
        return sparse.solve(self.dynamic_stiffness(w), np.asarray(rhs, complex))


def unbalance_forces(model, unbalances: Sequence[Unbalance]) -> dict[str, np.ndarray]:
    """Force phasor per unit Omega² of each spool's unbalances, in model coordinates: ``F(t) = Re(Omega^2 F e^{i Omega t})``
    with Omega the spool's speed; shape (n,), complex, per spool. The spool of each unbalance's node is the model's
    ``spool_of`` (:class:`rotorred.model.assembly.SpoolSpeedMixin`)."""
    spools = tuple(model.spools)
    dofs = model.full_dofs
    spool_of = model.spool_of
    if not spool_of:
        checks.fail("model", type(model).__name__, f"must know the spool of each node (built from a Rotor: assemble, "
                    f"reduce_rotor) to place unbalances on a model of {len(spools)} spools")
    if len(unbalances) == 0:
        checks.fail("unbalances", unbalances, "must hold at least one Unbalance")
    per_spool: dict[str, np.ndarray] = {}
    for k, u in enumerate(unbalances):
        if not isinstance(u, Unbalance):
            checks.fail(f"unbalances[{k}]", u, "must be an Unbalance")
        checks.node(f"unbalances[{k}].node", u.node, dofs.nodes, "a node of the model")
        s = spool_of.get(u.node)
        if s not in spools:
            checks.fail(f"unbalances[{k}].node", u.node, f"must lie on a spool of the model ({', '.join(spools)}), "
                        f"not {s!r}")
        rows = model.output_rows([(u.node, "x"), (u.node, "y")])
        # per unit Omega²: F_x = m_e e^{i phi}, F_y = -i m_e e^{i phi}
        f = u.m_e * np.exp(1j * u.phase) * (rows[0] - 1j * rows[1])
        per_spool[s] = per_spool.get(s, 0.0) + f
    return per_spool


def unbalance_response(model, operating: Operating, unbalances: Sequence[Unbalance],
                       outputs: Sequence[Output]) -> UnbalanceResponse:
    """Steady-state response to unbalances on any spool along a speed line.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        Read through :func:`rotorred.model.assembly.system_of`; the spool of each node is the model's
        ``spool_of``.
    operating : Operating
        The speed line (:meth:`Operating.line`) or point: ``Omega``, shape (n,), the reference spool's speeds
        (rad/s, >= 0); every spool's speed at each point by :meth:`Operating.speeds`.
    unbalances : sequence of Unbalance
        Each rotates with the spool its node belongs to.
    outputs : sequence of (int, str)
        Physical DOFs (node, direction) to report; any node of the full model.

    Returns
    -------
    UnbalanceResponse
        Phasors of shape (n,) per excited spool and output (m).

    Raises
    ------
    InputError
        If a spool's speed does not follow from ``operating`` (:meth:`Operating.lines`), ``outputs`` is empty,
        or an unbalance or an output names a DOF the model does not have.
    """
    model = system_of(model, sparse_ok=True)
    operating = checked_operating(operating)
    spool_speeds = operating.speeds(model)
    speeds = operating.Omega
    outputs = model.full_dofs.checked_outputs(outputs, "outputs")
    if not outputs:
        checks.fail("outputs", outputs, "must name at least one (node, direction) pair")
    per_spool = unbalance_forces(model, unbalances)
    R = model.output_rows(outputs)
    phasors = {s: np.zeros((len(speeds), len(outputs)), dtype=complex) for s in per_spool}
    for k in range(len(speeds)):
        at = {s: float(w[k]) for s, w in spool_speeds.items()}
        matrices = _Matrices(model, at)
        for s, f in per_spool.items():
            w = at[s]
            if w == 0.0:
                continue  # no unbalance force at rest
            phasors[s][k] = R @ matrices.solve(w, w * w * f)
    return UnbalanceResponse(
        speeds=speeds, reference_spool=operating.reference_of(model), spool_speeds=spool_speeds, outputs=outputs,
        phasors={s: {o: phasors[s][:, j].copy() for j, o in enumerate(outputs)} for s in phasors},
        operating=operating)


def response_error(reference: UnbalanceResponse, other: UnbalanceResponse, floor: float = 1e-3) -> float:
    """Worst relative phasor error of ``other`` against ``reference`` over the sweep.

    For every excited spool, output and sweep point the error is
    ``|Q_other - Q_ref| / max(|Q_ref|, floor * max_sweep |Q_ref|)``: relative to the
    amplitude at that point, except where the amplitude falls below ``floor`` times the
    output's peak over the sweep (at rest, or at an anti-resonance, where a relative error
    means nothing).

    Returns
    -------
    float
    """
    if set(reference.phasors) != set(other.phasors) or reference.outputs != other.outputs \
            or len(reference.speeds) != len(other.speeds):
        checks.fail("other", f"{len(other.speeds)} speeds, outputs {list(other.outputs)}, spools {list(other.phasors)}",
                    f"must have the excited spools, outputs and sweep of reference ({len(reference.speeds)} speeds, "
                    f"outputs {list(reference.outputs)}, spools {list(reference.phasors)})")
    worst = 0.0
    for s, per_output in reference.phasors.items():
        for o, Q in per_output.items():
            scale = np.abs(Q).max()
            if scale == 0.0:
                continue
            err = np.abs(other.phasors[s][o] - Q) / np.maximum(np.abs(Q), floor * scale)
            worst = max(worst, float(err.max()))
    return worst


def frequency_response(model, operating: Operating, inputs: Sequence[Output], outputs: Sequence[Output],
                       frequencies) -> FrequencyResponse:
    """Receptance FRFs H(omega) = R (K - omega² M + i omega (C + sum Omega_s G_s))^-1 Bᵀ.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        Read through :func:`rotorred.model.assembly.system_of`.
    operating : Operating
        The operating point where the spools turn during the sweep (:meth:`Operating.point`; the speed of
        every spool (rad/s) by :meth:`Operating.single`); ``Operating.point({spool: 0.0})`` for a rotor at rest.
    inputs, outputs : sequence of (int, str)
        Force and response DOFs (node, direction), any node of the full model.
    frequencies : array_like, shape (n,)
        Excitation frequencies (rad/s), >= 0.

    Returns
    -------
    FrequencyResponse
        ``H`` of shape (n, len(outputs), len(inputs)) (m/N).

    Raises
    ------
    InputError
        If ``operating`` is not one point, ``inputs`` or ``outputs`` is empty or names a DOF the model does not
        have, or a frequency is negative.
    """
    model = system_of(model, sparse_ok=True)
    speeds = checked_operating(operating).single(model)
    inputs = model.full_dofs.checked_outputs(inputs, "inputs")
    outputs = model.full_dofs.checked_outputs(outputs, "outputs")
    for name, pairs in (("inputs", inputs), ("outputs", outputs)):
        if not pairs:
            checks.fail(name, pairs, "must name at least one (node, direction) pair")
    w_all = checks.vector("frequencies", [frequencies] if np.ndim(frequencies) == 0 else frequencies, "rad/s",
                          ge=0.0)
    matrices = _Matrices(model, speeds)
    B = model.output_rows(inputs).T
    R = model.output_rows(outputs)
    H = np.empty((len(w_all), len(outputs), len(inputs)), dtype=complex)
    for k, w in enumerate(w_all):
        H[k] = R @ matrices.solve(w, B.astype(complex))
    return FrequencyResponse(frequencies=w_all, speeds=speeds, inputs=inputs, outputs=outputs, H=H,
                             operating=operating)
