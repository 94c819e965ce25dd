"""Order tracking of run-ups: the amplitude of each spool's orders against its speed.

Method: angle-domain resampling (computed order tracking). The record is interpolated with a
cubic spline at ``samples_per_rev`` equal steps of a spool's spin angle; the resampled signal is
cut into blocks of ``revs_per_block`` revolutions with 50 % overlap; each block, Hann-windowed,
gives an order's complex amplitude by a single-bin DFT at that order, read against the spool's
mean speed over the block. In the angle domain the spool's own orders are periodic whatever the
speed does, so they fall on bins; another spool's orders (at the speed ratio) fall between
bins and leak through the Hann window's sidelobes only (below 1 % once they are three bins away:
``revs_per_block`` >= 3 / |order distance|).

The overall amplitude against speed is the largest radius of the orbit, ``sqrt(x^2 + y^2)``, in each block.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from rotorred import checks
from rotorred.results import Result
from rotorred.signals.spectra import window_values

#: the method, as stated with every track
METHOD = ("angle-domain resampling (computed order tracking): cubic-spline resampling at {spr} samples per "
          "revolution, blocks of {rpb} revolutions with 50 % overlap, Hann window, single-bin DFT per order")


@dataclass(frozen=True, repr=False)
class OrderTrack(Result):
    """One order of one spool in one signal, block by block.

    Attributes
    ----------
    spool : str
    order : float
        Order (cycles per revolution of ``spool``).
    t : ndarray, shape (n_blocks,)
        Time at each block's centre (s).
    speed : ndarray, shape (n_blocks,)
        The spool's mean speed over the block (rad/s).
    amplitude : ndarray, shape (n_blocks,)
        Amplitude of the order (units of the signal: a cos(order phi) reads a).
    phase : ndarray, shape (n_blocks,)
        Its phase against the spool's spin angle (rad): ``x ~ a cos(order phi + phase)``.
    method : str
    """

    spool: str
    order: float
    t: np.ndarray
    speed: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray
    method: str

    def summary(self) -> list[str]:
        """The order and spool, the blocks and speeds, the largest amplitude and where, the method."""
        lines = [f"order {self.order:g} of the {self.spool} spool over {len(self.t)} blocks"]
        if len(self.t):
            hz = self.speed / (2 * np.pi)
            k = int(np.argmax(self.amplitude))
            lines[0] += f", t = {self.t[0]:.4g}-{self.t[-1]:.4g} s, {self.spool} at {hz.min():.4g}-{hz.max():.4g} Hz"
            lines.append(f"largest amplitude {self.amplitude[k]:.6g} (the signal's units) at {hz[k]:.6g} Hz "
                         f"({60 * hz[k]:.6g} rpm), t = {self.t[k]:.4g} s")
        return lines + textwrap.wrap(self.method, 110, max_lines=3, placeholder=" ...")

    def plot(self, ax=None, **options):
        """The amplitude against the spool's speed (Hz, rpm on top), as a run-up's order tracks are drawn
        (:func:`rotorred.plots.runup.draw_order_track`).

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Axes to draw into; default a new figure.
        **options
            ``scale`` and ``unit`` (default µm from m), ``title``.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from rotorred.plots.runup import draw_order_track

        return draw_order_track(self, ax, **options)

    def to_xarray(self, units: str = "m"):
        """The track as an :class:`xarray.Dataset`: dimension ``block``, variables ``time`` (s, the block's centre),
        ``speed`` (rad/s, the spool's mean), ``amplitude`` in ``units`` and ``phase`` (rad); spool, order and method as
        attributes.

        Parameters
        ----------
        units : str
            The signal's units, which a track does not know (UDUNITS text); default "m", as rotorred's
            displacements.

        Returns
        -------
        xarray.Dataset
        """
        import xarray as xr

        return xr.Dataset(
            {"time": ("block", self.t, {"units": "s", "long_name": "time at the block's centre"}),
             "speed": ("block", self.speed, {"units": "rad/s", "long_name": f"mean speed of the {self.spool} spool"}),
             "amplitude": ("block", self.amplitude, {"units": units, "long_name": f"amplitude of order {self.order:g}"}),
             "phase": ("block", self.phase, {"units": "rad", "long_name": "phase against the spool's spin angle"})},
            attrs={"title": "order track", "spool": self.spool, "order": self.order, "method": self.method})


@dataclass(frozen=True)
class AngleBlocks:
    """A record resampled in a spool's angle and cut into overlapping blocks.

    Attributes
    ----------
    theta : ndarray, shape (n_blocks, m)
        Spin angle of every sample (rad), m = revs_per_block * samples_per_rev.
    t : ndarray, shape (n_blocks, m)
        Time of every sample (s).
    values : ndarray, shape (n_signals, n_blocks, m)
        The signals at those times.
    speed : ndarray, shape (n_blocks,)
        Mean speed over each block (rad/s): the angle it spans over its duration.
    method : str
    """

    theta: np.ndarray
    t: np.ndarray
    values: np.ndarray
    speed: np.ndarray
    method: str


def angle_blocks(t, signals, angle, revs_per_block: int = 16, samples_per_rev: int = 64) -> AngleBlocks:
    """Resample ``signals`` at equal steps of ``angle`` and cut them into blocks of ``revs_per_block`` revolutions.

    Parameters
    ----------
    t : array_like, shape (n,)
        Record times (s), increasing, at least 4.
    signals : array_like, shape (n_signals, n) or (n,)
        The signals at ``t``, any units (m for displacements).
    angle : array_like, shape (n,)
        Spin angle of the spool at ``t`` (rad), non-decreasing (a spool at rest holds its angle).
    revs_per_block, samples_per_rev : int
        Revolutions a block, >= 1 (blocks overlap by half), and samples a revolution, >= 8.

    Returns
    -------
    AngleBlocks
        No block when the record turns the spool less than ``revs_per_block`` revolutions.

    Raises
    ------
    InputError
        If ``t`` is not increasing, ``signals`` or ``angle`` does not match it, ``angle`` decreases, or a count is
        below its bound.
    """
    t = checks.vector("t", t, "s", min_len=4, increasing=True)
    angle = checks.array("angle", angle, t.shape, "rad")
    signals = np.atleast_2d(checks.array("signals", signals))
    if signals.shape[1] != len(t):
        checks.fail("signals", f"shape {signals.shape}", f"must have {len(t)} samples per signal (as t)")
    if np.any(np.diff(angle) < 0):
        checks.fail("angle", "decreasing", "must not decrease (speeds are >= 0)", "rad")
    revs_per_block = checks.integer("revs_per_block", revs_per_block, ge=1)
    samples_per_rev = checks.integer("samples_per_rev", samples_per_rev, ge=8)
    method = METHOD.format(spr=samples_per_rev, rpb=revs_per_block)
    # the times at equal angle steps (angle is piecewise smooth and increasing once the spool turns)
    moving = np.concatenate([[True], np.diff(angle) > 0])
    step = 2 * np.pi / samples_per_rev
    theta = np.arange(angle[0], angle[-1], step)
    m, hop = revs_per_block * samples_per_rev, revs_per_block * samples_per_rev // 2
    n_blocks = 0 if len(theta) < m else (len(theta) - m) // hop + 1
    if n_blocks == 0:
        empty = np.zeros((0, m))
        return AngleBlocks(empty, empty, np.zeros((len(signals), 0, m)), np.zeros(0), method)
    t_theta = np.interp(theta, angle[moving], t[moving])
    values = CubicSpline(t, signals, axis=1)(t_theta)
    index = np.arange(n_blocks)[:, None] * hop + np.arange(m)[None, :]
    tb = t_theta[index]
    span = tb[:, -1] + (tb[:, -1] - tb[:, -2]) - tb[:, 0]  # the block's m steps of angle take this long
    return AngleBlocks(theta=theta[index], t=tb, values=values[:, index], speed=2 * np.pi * revs_per_block / span,
                       method=method)


def order_tracks(blocks: AngleBlocks, spool: str, orders) -> list[list[OrderTrack]]:
    """Every order of ``orders`` in every signal of ``blocks`` (resampled in the angle of ``spool``): a single-bin DFT
    of each Hann-windowed block at the order, its phase against the spin angle.

    Parameters
    ----------
    blocks : AngleBlocks
        The signals resampled in the spool's angle (:func:`angle_blocks`).
    spool : str
        The spool whose angle ``blocks`` follows (named in each track).
    orders : array_like, shape (k,)
        Orders (cycles per revolution of ``spool``, -), > 0.

    Returns
    -------
    list (per signal) of list (per order) of OrderTrack

    Raises
    ------
    InputError
        If an order is not > 0.
    """
    orders = checks.vector("orders", orders, gt=0.0)
    n_signals, n_blocks, m = blocks.values.shape
    w = window_values("hann", m) if m else np.zeros(0)
    tc = blocks.t.mean(axis=1) if n_blocks else np.zeros(0)
    if not (m and n_blocks):
        empty = np.zeros(0)
        return [[OrderTrack(spool, float(o), tc, blocks.speed, empty, empty, blocks.method) for o in orders]
                for _ in range(n_signals)]
    per_order = []
    for order in orders:
        # single-bin DFT of every block and signal at once, phase against the spin angle itself
        X = (2.0 / w.sum()) * np.einsum("kbm,bm->kb", blocks.values, w * np.exp(-1j * order * blocks.theta))
        per_order.append(X)
    return [[OrderTrack(spool=spool, order=float(order), t=tc, speed=blocks.speed, amplitude=np.abs(X[k]),
                        phase=np.angle(X[k]), method=blocks.method) for order, X in zip(orders, per_order)]
            for k in range(n_signals)]


def overall_amplitude(blocks: AngleBlocks, ix: int, iy: int) -> np.ndarray:
    """The orbit's largest radius ``max sqrt(x^2 + y^2)`` in each block, signals ``ix`` (x) and ``iy`` (y)."""
    return np.hypot(blocks.values[ix], blocks.values[iy]).max(axis=1) if blocks.values.shape[1] else np.zeros(0)
