"""Mode shapes at one operating point: each mode's motion along every spool, its node orbits and whirl sense
(docs/model.md §21).

At one operating point (every spool at its speed, :class:`rotorred.model.operating.Operating`) the damped
eigenproblem ``(lambda^2 M + lambda (C + sum_s Omega_s G_s) + K) v = 0`` is solved as :func:`rotorred.campbell`
solves it at its first speed (:func:`rotorred.linear.campbell.modes_at`): the same modes, in the same order (by
frequency), with the same whirl, log decrement and rigid-body flags, taken from a one-speed Campbell result. So
``rotorred modes ROTOR --speed W`` and ``rotorred campbell ROTOR --speeds W`` number the modes alike, from 1.

Each mode's physical motion at a node is the pair of complex amplitudes (X, Y) of x and y:
``x(t) = Re(X e^{i w t})``, ``y(t) = Re(Y e^{i w t})``, an ellipse (the node's orbit) with forward and backward
radii |X + iY|/2 and |X - iY|/2 (:func:`rotorred.linear.campbell.whirl_direction`): semi-major axis their sum,
semi-minor axis their difference. A mode is scaled so that its largest orbit has a semi-major axis of 1 and is at
the end of that axis at t = 0 (the phase that makes the largest excursion real; of the two, the one with x >= 0).
Nodes a support fixes do not move (0); pedestal nodes are not listed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

import numpy as np

from rotorred import checks, writers
from rotorred.linear.campbell import ModeCount, campbell, modes_at
from rotorred.model.assembly import SystemMatrices, system_of
from rotorred.model.operating import Operating
from rotorred.model.operating import checked as checked_operating
from rotorred.results import Result, label_coordinate

#: most modes listed in a repr, a line each
_LISTED = 10


@dataclass(frozen=True, repr=False)
class ModeShapes(Result):
    """The modes of a rotor at one operating point: frequency, whirl, damping and the motion of every shaft node.

    Modes are numbered from 1 in frequency order (:attr:`numbers`), as :func:`rotorred.campbell` numbers them at
    the same speed; arrays are indexed from 0 (mode k is row k - 1).

    Attributes
    ----------
    speeds : dict of str to float
        Speed of every spool (rad/s).
    reference : str
        The reference spool (the operating point's).
    frequencies : ndarray, shape (n_modes,)
        Damped whirl frequency Im(lambda) of each mode (rad/s).
    log_dec : ndarray, shape (n_modes,)
        Logarithmic decrement -2 pi Re(lambda) / Im(lambda) (-).
    whirl : ndarray of str, shape (n_modes,)
        ``"forward"``, ``"backward"``, ``"mixed"`` or ``"planar"`` (:data:`rotorred.linear.campbell.WHIRL_LABELS`).
    nodes : ndarray of int, shape (n_nodes,)
        Shaft nodes, spool by spool, axially.
    node_spools : tuple of str, length n_nodes
        Spool of each node.
    z : ndarray, shape (n_nodes,)
        Axial position of each node (m).
    X, Y : ndarray, shape (n_modes, n_nodes), complex
        Complex amplitudes of x and y at each node (-, scaled: the largest orbit's semi-major axis is 1).
    rigid_modes : tuple of int
        Rows of rigid-body modes of a free or singly supported spool.
    rotor_name : str
    mode_count : ModeCount or None
        Why this many modes, when chosen by default (:func:`rotorred.default_mode_count`).
    operating : Operating or None
        The operating point.
    """

    speeds: Mapping[str, float]
    reference: str
    frequencies: np.ndarray
    log_dec: np.ndarray
    whirl: np.ndarray
    nodes: np.ndarray
    node_spools: tuple[str, ...]
    z: np.ndarray
    X: np.ndarray
    Y: np.ndarray
    rigid_modes: tuple[int, ...] = ()
    rotor_name: str = ""
    mode_count: ModeCount | None = None
    operating: Operating | None = field(default=None, compare=False)

    def __post_init__(self):
        for f in ("frequencies", "log_dec", "whirl", "nodes", "z", "X", "Y"):
            a = np.array(getattr(self, f))
            a.setflags(write=False)
            object.__setattr__(self, f, a)
        object.__setattr__(self, "speeds", dict(self.speeds))
        object.__setattr__(self, "node_spools", tuple(self.node_spools))

    @property
    def n_modes(self) -> int:
        """Number of modes."""
        return len(self.frequencies)

    @property
    def numbers(self) -> np.ndarray:
        """Mode numbers 1, 2, ..., n_modes (frequency order), shape (n_modes,)."""
        return np.arange(1, self.n_modes + 1)

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Damped whirl frequencies (Hz), shape (n_modes,)."""
        return self.frequencies / (2.0 * math.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        """Damping ratio delta / sqrt(delta^2 + 4 pi^2) of each mode (-), shape (n_modes,)."""
        return self.log_dec / np.sqrt(self.log_dec ** 2 + 4.0 * math.pi ** 2)

    @property
    def forward_radius(self) -> np.ndarray:
        """``|X + iY|`` / 2: radius of each node orbit's forward circle (-), shape (n_modes, n_nodes)."""
        return np.abs(self.X + 1j * self.Y) / 2.0

    @property
    def backward_radius(self) -> np.ndarray:
        """``|X - iY|`` / 2: radius of each node orbit's backward circle (-), shape (n_modes, n_nodes)."""
        return np.abs(self.X - 1j * self.Y) / 2.0

    @property
    def semi_major(self) -> np.ndarray:
        """Semi-major axis of each node orbit (-), shape (n_modes, n_nodes)."""
        return self.forward_radius + self.backward_radius

    @property
    def semi_minor(self) -> np.ndarray:
        """Semi-minor axis of each node orbit (-), shape (n_modes, n_nodes): 0 for a straight-line orbit."""
        return np.abs(self.forward_radius - self.backward_radius)

    def spool_nodes(self, spool: str) -> np.ndarray:
        """Columns of :attr:`nodes` on ``spool``, axially, shape (k,).

        Parameters
        ----------
        spool : str
            A spool of the rotor.
        """
        checks.choice("spool", spool, dict.fromkeys(self.node_spools))
        return np.array([i for i, s in enumerate(self.node_spools) if s == spool], dtype=int)

    def to_csv(self, path: str | Path) -> Path:
        """Write one row per (mode, node): ``mode`` (from 1), ``frequency_hz``, ``whirl``, ``log_dec``, ``node``,
        ``spool``, ``z_m``, and the amplitude (-, scaled) and phase (deg) of x and y.

        Parameters
        ----------
        path : str or Path
            The CSV file to write.

        Returns
        -------
        Path
            ``path``.
        """
        n_m, n_n = self.X.shape
        header = ["mode", "frequency_hz", "whirl", "log_dec", "node", "spool", "z_m", "x_amplitude", "x_phase_deg",
                  "y_amplitude", "y_phase_deg"]
        columns = [np.repeat(self.numbers, n_n), [f"{v:.9g}" for v in np.repeat(self.frequencies_hz, n_n)],
                   [str(w) for w in np.repeat(self.whirl, n_n)], [f"{v:.6g}" for v in np.repeat(self.log_dec, n_n)],
                   np.tile(self.nodes, n_m), list(self.node_spools) * n_m, [f"{v:.9g}" for v in np.tile(self.z, n_m)],
                   np.abs(self.X).ravel(), np.degrees(np.angle(self.X)).ravel(),
                   np.abs(self.Y).ravel(), np.degrees(np.angle(self.Y)).ravel()]
        return writers.write_csv(path, header, columns, digits=9)

    def summary(self) -> list[str]:
        """The operating point and one line per mode (the first :data:`_LISTED`)."""
        speeds = ", ".join(f"{s} {w * 30.0 / math.pi:.6g} rpm" for s, w in self.speeds.items())
        lines = [f"{self.rotor_name or 'rotor'}: {self.n_modes} modes at {speeds}; "
                 f"{len(self.nodes)} shaft nodes on {len(dict.fromkeys(self.node_spools))} spool(s)"]
        for k in range(min(self.n_modes, _LISTED)):
            rigid = " (rigid body)" if k in self.rigid_modes else ""
            lines.append(f"mode {k + 1}: {self.frequencies_hz[k]:.6g} Hz, {self.whirl[k]}, "
                         f"log dec {self.log_dec[k]:.4g}{rigid}")
        if self.n_modes > _LISTED:
            lines.append(f"... {self.n_modes - _LISTED} more modes")
        return lines

    def plot(self, ax=None, **options):
        """Draw the mode shapes (:func:`rotorred.plots.modes.draw_mode_shapes`): each mode's deflection along the
        axis for every spool, with node orbits and the whirl sense; return the Figure.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw one mode into (``mode``, default 1); default a new figure with every mode.
        **options
            ``mode`` (the one mode drawn into ``ax``), ``modes`` (the numbers drawn in a new figure), ``orbits``
            (number of orbits drawn along each spool), ``figsize`` (in).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.modes import draw_mode_shapes

        return draw_mode_shapes(self, ax, **options)

    def to_xarray(self):
        """The modes as an :class:`xarray.Dataset`: dimensions ``mode`` (numbers from 1) and ``node``; variables
        ``frequency`` (Hz), ``log_dec``, ``whirl`` (flags of :data:`rotorred.linear.campbell.WHIRL_LABELS`), and the amplitude (-) and phase
        (rad) of x and y; coordinates ``z`` (m) and ``spool`` of each node."""
        import xarray as xr

        from rotorred.linear.campbell import _WHIRL_ATTRS, _whirl_codes

        one, mn = {"units": "1"}, ("mode", "node")
        data = {
            "frequency": ("mode", self.frequencies_hz, {"units": "Hz", "long_name": "damped whirl frequency"}),
            "log_dec": ("mode", self.log_dec, {**one, "long_name": "logarithmic decrement"}),
            "whirl": ("mode", _whirl_codes(self.whirl), _WHIRL_ATTRS),
            "x_amplitude": (mn, np.abs(self.X), {**one, "long_name": "amplitude of x (largest orbit 1)"}),
            "x_phase": (mn, np.angle(self.X), {"units": "rad", "long_name": "phase of x"}),
            "y_amplitude": (mn, np.abs(self.Y), {**one, "long_name": "amplitude of y (largest orbit 1)"}),
            "y_phase": (mn, np.angle(self.Y), {"units": "rad", "long_name": "phase of y"}),
        }
        coords = {"mode": ("mode", self.numbers, {**one, "long_name": "mode number (frequency order)"}),
                  "node": ("node", self.nodes.astype(np.int64), {**one, "long_name": "shaft node"}),
                  "z": ("node", self.z, {"units": "m", "long_name": "axial position"}),
                  "spool": label_coordinate("node", self.node_spools, "spool of the node")}
        return xr.Dataset(data, coords, attrs={
            "title": "mode shapes", "rotor": self.rotor_name, "reference_spool": self.reference,
            **{f"speed_{s}_rad_s": float(w) for s, w in self.speeds.items()}})


def mode_shapes(model, operating: Operating, *, n_modes: int | None = None) -> ModeShapes:
    """The modes of ``model`` at the operating point ``operating``: frequencies, whirl, damping and shapes.

    Parameters
    ----------
    model : Rotor, SystemMatrices or ReducedSystem
        The rotor (assembled here), its assembled model, or a Craig-Bampton model (its shapes recovered on the
        full model's nodes); it must come from a :class:`rotorred.Rotor` (the nodes' positions).
    operating : Operating
        One operating point (:meth:`Operating.point`, or :meth:`Operating.line` of one speed): the speed of every
        spool (rad/s) by :meth:`Operating.lines`.
    n_modes : int, optional
        Number of modes, the lowest; default the rule of :func:`rotorred.campbell` (every mode below 1.25 x the
        highest 1x excitation frequency, at least 6; :func:`rotorred.default_mode_count`).

    Returns
    -------
    ModeShapes

    Raises
    ------
    InputError
        If ``operating`` is not one point, the model has no rotor, or ``n_modes`` is out of range (as
        :func:`rotorred.campbell`).
    """
    sm = system_of(model, sparse_ok=True)
    operating = checked_operating(operating)
    if operating.kind != "point":
        checks.fail("operating", operating.describe(), "must be one operating point (Operating.point, or "
                    f"Operating.line of one speed), not a {operating.kind}")
    if sm.rotor is None:
        checks.fail("model", type(sm).__name__, "must be built from a Rotor (assemble, reduce_rotor): mode shapes "
                    "need the nodes' axial positions")
    table = campbell(sm, operating, n_modes=n_modes)
    lines = operating.lines(sm)
    _, shapes = modes_at(sm, lines, float(operating.Omega[0]), table.n_modes)
    nodes, node_spools, z, X, Y = node_motion(sm, shapes)
    X, Y = _scaled(X, Y)
    return ModeShapes(speeds={s: float(line.at(operating.Omega[0])) for s, line in lines.items()},
                      reference=table.reference, frequencies=table.frequencies[0], log_dec=table.log_dec[0],
                      whirl=table.whirl[0], nodes=nodes, node_spools=node_spools, z=z, X=X, Y=Y,
                      rigid_modes=table.rigid_modes, rotor_name=sm.name, mode_count=table.mode_count,
                      operating=operating)


def node_motion(sm, shapes: np.ndarray):
    """The motion of every shaft node in the modes ``shapes``.

    Parameters
    ----------
    sm : SystemMatrices or ReducedSystem
        A model with its rotor.
    shapes : ndarray, shape (n, n_modes), complex
        Modes in the model's coordinates (columns).

    Returns
    -------
    nodes : ndarray of int, shape (n_nodes,)
        Shaft nodes, spool by spool, axially.
    spools : tuple of str
        Spool of each node.
    z : ndarray, shape (n_nodes,)
        Axial positions (m).
    X, Y : ndarray, shape (n_modes, n_nodes), complex
        x and y of each node (the rows of :meth:`output_rows`, a reduced model's rows of T); 0 where a support
        holds the node.
    """
    rotor, dofs = sm.rotor, sm.full_dofs
    positions = rotor.positions
    nodes = [n for s in rotor.spools for n in s.nodes]
    spools = tuple(s.name for s in rotor.spools for _ in s.nodes)
    X = np.zeros((shapes.shape[1], len(nodes)), complex)
    Y = np.zeros_like(X)
    free = [i for i, n in enumerate(nodes) if not dofs.is_fixed(n, "x")]
    if free:
        outputs = [(nodes[i], d) for i in free for d in ("x", "y")]
        # a full model's outputs are its coordinates: picked, not multiplied (a 9224-DOF model's rows are 340 MB)
        rows = shapes[sm.output_index(outputs)] if isinstance(sm, SystemMatrices) else sm.output_rows(outputs) @ shapes
        X[:, free], Y[:, free] = rows[0::2].T, rows[1::2].T
    return np.array(nodes, dtype=int), spools, np.array([positions[n] for n in nodes]), X, Y


def _scaled(X: np.ndarray, Y: np.ndarray):
    """Each mode (row) scaled so that its largest orbit has semi-major axis 1 and is at that axis's end at t = 0,
    with x >= 0 there (module docstring)."""
    F, B = (X + 1j * Y) / 2.0, np.conj(X - 1j * Y) / 2.0  # x + i y = F e^{iwt} + B e^{-iwt}
    major = np.abs(F) + np.abs(B)
    k = np.argmax(major, axis=1)
    rows = np.arange(X.shape[0])
    Fk, Bk = F[rows, k], B[rows, k]
    # X, Y times e^{i psi}: F -> F e^{i psi}, B -> B e^{-i psi}; |F + B| is largest where arg F + psi = arg B - psi
    psi = 0.5 * (np.angle(Bk) - np.angle(Fk))
    at_zero = Fk * np.exp(1j * psi) + Bk * np.exp(-1j * psi)  # x + i y of the largest orbit at t = 0
    psi = np.where((at_zero.real < 0) | ((at_zero.real == 0) & (at_zero.imag < 0)), psi + math.pi, psi)
    scale = np.exp(1j * psi) / major[rows, k]
    return X * scale[:, None], Y * scale[:, None]
