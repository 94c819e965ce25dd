"""Parameter sweeps of a scene, e.g. the rub clearance study promised by Xu et al. (2016, abstract).

:func:`sweep` runs a scene once per value of one key (``rub.clearance`` by default), reusing
one structural model for every run when the key does not change it, and collects per value:
the amplitudes of f_L, f_H and every combination line at one DOF, the number of combination
lines, the peak displacement, the contact fraction and the number of impacts of the first
plate. :func:`rotorred.plots.sweep.plot_sweep` draws them against the swept value; for a
clearance sweep it marks the free (no-rub) orbit's reach towards the plate at the rub node,
beyond which no contact and so no combination line can occur.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Sequence

import numpy as np

from rotorred import checks
from rotorred.scenes.run import (SceneDiverged, SceneModel, build_model, model_key, run_scene, settled_response,
                                 spool_frequencies)
from rotorred.scenes.schema import Scene, load_scene
from rotorred.scenes.summary import table_dof
from rotorred.writers import render_table, write_csv, write_text

__all__ = ["SweepResult", "sweep", "free_reach", "write_sweep", "format_sweep", "axis_of", "key_unit"]


@dataclass(frozen=True)
class SweepResult:
    """Results of a one-key sweep.

    Attributes
    ----------
    scene_name : str
    key : str
        The swept key ("rub.clearance").
    values : ndarray, shape (n,)
        Swept values, in the scene file's units (SI).
    dof : (int, str)
        DOF whose spectral lines are collected.
    f_L, f_H : float
        Spool frequencies (Hz).
    amplitudes : dict of str to ndarray, shape (n,)
        Amplitude (m) of each labelled line (ASCII label, "f_L", "f_H", "2f_H-f_L", ...) per value;
        0 where the line is not a peak above the scene's threshold.
    n_combinations : ndarray of int, shape (n,)
        Labelled lines other than f_L and f_H per value.
    peak : ndarray, shape (n,)
        Largest |displacement| of ``dof`` in the window (m).
    contact_fraction : ndarray, shape (n,)
        Fraction of the window in contact (first plate; 0 without plates).
    n_impacts : ndarray of int, shape (n,)
        Contact onsets in the window (first plate).
    free_reach : float or None
        Largest displacement of the free (no-rub) orbit at the first plate's node towards the
        plate (m); a clearance above it cannot be touched. None without plates.
    wall_times : ndarray, shape (n,)
        Wall time per run (s).
    axis_scale : float
        Factor from the swept value (SI) to the unit of ``axis_label`` (1e6 for a clearance in µm).
    axis_label : str
        Name and unit of the swept key for plots and tables, e.g. "Rub clearance (µm)".
    failures : dict of int to str
        Index of each value whose run failed (a diverged transient) -> why; its amplitudes, peak,
        contact fraction are NaN and its impacts -1.
    """

    scene_name: str
    key: str
    values: np.ndarray
    dof: tuple
    f_L: float
    f_H: float
    amplitudes: dict
    n_combinations: np.ndarray
    peak: np.ndarray
    contact_fraction: np.ndarray
    n_impacts: np.ndarray
    free_reach: float | None
    wall_times: np.ndarray
    axis_scale: float = 1.0
    axis_label: str = ""
    failures: dict = field(default_factory=dict)

    def status(self, i: int) -> str:
        """``"ok"`` or ``"failed: <why>"`` for value ``i``."""
        return f"failed: {self.failures[i]}" if i in self.failures else "ok"

    def combinations(self) -> list[str]:
        """Combination-line labels, strongest (largest amplitude over the sweep) first."""
        combos = [k for k in self.amplitudes if k not in ("f_L", "f_H")]
        return sorted(combos, key=lambda k: -float(np.nanmax(self.amplitudes[k], initial=0.0)))

    def combination_total(self) -> np.ndarray:
        """Sum of the combination-line amplitudes per value (m), shape (n,)."""
        total = np.zeros(len(self.values))
        for k in self.combinations():
            total += self.amplitudes[k]
        return total


def free_reach(scene: Scene, model=None) -> float | None:
    """Reach of the settled no-rub orbit towards the first plate at its node (m), None without plates.

    ``max_t n . (x(t), y(t))`` over one common period of the spools (sampled at ``solver.dt``),
    from the harmonic (linear steady-state) solution, plus gravity's static deflection.
    """
    if not scene.plates:
        return None
    if model is None:
        model = build_model(scene)
    m = model.model if isinstance(model, SceneModel) else model
    plate = scene.plates[0]
    rows = m.output_rows([(plate.node, "x"), (plate.node, "y")])
    f = [w / (2 * math.pi) for w in scene.speeds.values() if w > 0]
    ratio = Fraction(max(f) / min(f)).limit_denominator(100)
    period = ratio.denominator / min(f)
    t = np.arange(0.0, period, min(scene.solver.dt, period / 2000))
    return float(np.max(plate.normal @ settled_response(scene, m, rows, t)))


def sweep(spec, key: str, values: Sequence, settings: dict | None = None, dof: tuple | None = None,
          progress: bool = False) -> SweepResult:
    """Run a scene for each value of ``key``.

    Parameters
    ----------
    spec : str or Path
        Built-in scene name or scene file.
    key : str
        Key to sweep, "section.key" (:func:`rotorred.scenes.schema.apply_settings`), e.g. "rub.clearance".
    values : sequence
        Values of ``key`` (scene units: SI).
    settings : dict, optional
        Further fixed overrides.
    dof : (int, str), optional
        DOF whose lines are collected (default the scene's table DOF).
    progress : bool
        Print one line per run.

    Returns
    -------
    SweepResult
    """
    values = list(values)
    if not values:
        raise ValueError(f"`values` of the sweep of {key!r} must not be empty")
    settings = dict(settings or {})
    # validate every scene, and the DOF, before computing anything
    scenes = [load_scene(spec, {**settings, key: v}) for v in values]
    d = check_dof(scenes[0], dof)
    points = _Points(len(scenes))
    model_cache, reach = {}, None
    for i, sc in enumerate(scenes):
        t0 = time.perf_counter()
        mk = model_key(sc)
        if mk not in model_cache:
            model_cache[mk] = build_model(sc)
        if i == 0:
            reach = free_reach(sc, model_cache[mk])
        try:
            points.add(i, run_scene(sc, model_cache[mk], compare_normal=False), d)
        except SceneDiverged as exc:
            points.fail(i, str(exc))
        points.wall[i] = time.perf_counter() - t0
        if progress:
            print(f"  {key} = {values[i]!r}: {points.describe(i)} ({points.wall[i]:.2f} s)", flush=True)
    vals = np.array([float(v) for v in values]) if all(isinstance(v, (int, float)) for v in values) \
        else np.arange(len(values), dtype=float)
    scale, label = axis_of(key)
    f_L, f_H = spool_frequencies(scenes[0])
    return SweepResult(scene_name=scenes[0].name, key=key, values=vals, dof=d, f_L=f_L, f_H=f_H,
                       amplitudes={k: np.array(v) for k, v in points.amps.items()}, n_combinations=points.n_comb,
                       peak=points.peak, contact_fraction=points.cf, n_impacts=points.imp, free_reach=reach,
                       wall_times=points.wall, axis_scale=scale, axis_label=label, failures=points.failures)


def check_dof(scene: Scene, dof: tuple | None, option: str = "--dof", text: str | None = None) -> tuple:
    """The DOF whose lines a sweep collects: ``dof`` if the scene records it, else its table DOF.

    ``option`` and ``text`` (the DOF as the user typed it) name it in the message of a refusal.
    """
    if dof is None:
        return table_dof(scene)
    d = tuple(dof)
    if d not in scene.output.dofs:
        checks.fail(option, text or f"{d[0]}:{d[1]}", "must be a DOF the scene records (output.nodes x output.directions: "
                                              + ", ".join(f"{n}:{x}" for n, x in scene.output.dofs) + ")")
    return d


class _Points:
    """The per-value quantities of a sweep, filled run by run (NaN for a failed run)."""

    def __init__(self, n: int):
        self.n = n
        self.amps: dict[str, list] = {}
        self.n_comb = np.zeros(n, dtype=int)
        self.peak, self.cf, self.wall = np.zeros(n), np.zeros(n), np.zeros(n)
        self.imp = np.zeros(n, dtype=int)
        self.failures: dict[int, str] = {}

    def add(self, i: int, res, d: tuple) -> None:
        for ln in res.lines[d]:
            if not ln.known:
                continue
            self.amps.setdefault(ln.label_ascii, [math.nan if j in self.failures else 0.0
                                                  for j in range(self.n)])[i] = ln.amplitude
            if ln.label_ascii not in ("f_L", "f_H"):
                self.n_comb[i] += 1
        self.peak[i] = res.peak(d)
        self.cf[i] = res.contact_fraction(0)
        self.imp[i] = res.n_impacts(0)

    def fail(self, i: int, why: str) -> None:
        self.failures[i] = why
        for v in self.amps.values():
            v[i] = math.nan
        self.peak[i] = self.cf[i] = math.nan
        self.imp[i] = self.n_comb[i] = -1

    def describe(self, i: int) -> str:
        if i in self.failures:
            return f"FAILED: {self.failures[i]}"
        return (f"contact {100 * self.cf[i]:.2f} %, {self.imp[i]} impacts, {self.n_comb[i]} combination lines, "
                f"peak {1e6 * self.peak[i]:.4g} um")


#: how a varied scene key is shown, by its last name: (scale from the scene's unit, unit shown)
_KEY_UNITS = {"clearance": (1e6, "µm"), "m_e": (1.0, "kg m"), "dt": (1.0, "s"), "mu_s": (1.0, "-"),
              "mu_d": (1.0, "-"), "k_n": (1.0, "N/m"), "K_nr": (1.0, "N/m^1.5"), "theta_deg": (1.0, "deg")}


def key_unit(key: str) -> tuple[float, str]:
    """(scale, unit) in which a varied scene key is shown: ``"rub.clearance"`` -> (1e6, "µm"), a speed in Hz."""
    if key.startswith("speeds."):
        return 1.0, "Hz"
    return _KEY_UNITS.get(key.split(".")[-1], (1.0, "scene units"))


def axis_of(key: str) -> tuple[float, str]:
    """Plot scale and axis label of a swept scene key: ``"rub.clearance"`` -> (1e6, "Rub clearance (µm)")."""
    scale, unit = key_unit(key)
    if key.split(".")[-1] == "clearance":
        return scale, "Rub clearance (µm)"
    return scale, f"{key} ({unit})"


def _reported_lines(result: SweepResult, n_lines: int | None) -> list[str]:
    """f_L, f_H, then the combination lines, strongest first (the first ``n_lines`` of them)."""
    combos = result.combinations()
    return [k for k in ("f_L", "f_H") if k in result.amplitudes] + (combos if n_lines is None else combos[:n_lines])


def format_sweep(result: SweepResult, n_lines: int = 4) -> str:
    """Table: value, contact fraction, impacts, number of combination lines, amplitudes (µm)."""
    labels = _reported_lines(result, n_lines)
    header = [result.axis_label, "contact (%)", "impacts", "comb. lines", "peak (um)"] + [f"{k} (um)" for k in labels]
    rows = [[f"{result.axis_scale * v:.4g}", f"{100 * result.contact_fraction[i]:.2f}", str(result.n_impacts[i]),
             str(result.n_combinations[i]), f"{1e6 * result.peak[i]:.4g}"]
            + [f"{1e6 * result.amplitudes[k][i]:.4g}" for k in labels] + [result.status(i)[:6]]
            for i, v in enumerate(result.values)]
    out = render_table(header + ["status"], rows)
    for i, why in sorted(result.failures.items()):
        out += f"\n{result.key} = {result.values[i]:.6g}: FAILED: {why}"
    if result.free_reach is not None:
        out += f"\nfree (no-rub) orbit reach towards the plate at the rub node: {1e6 * result.free_reach:.4g} um"
    return out


def write_sweep(result: SweepResult, out) -> list[Path]:
    """Write ``sweep.png``, ``sweep.csv`` (all lines, amplitudes in µm, a status per value) and ``sweep.txt``.

    A failed value has NaN amplitudes and its reason in the ``status`` column; no figure when every value failed.
    """
    from rotorred.plots.sweep import plot_sweep  # matplotlib only when figures are written

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    labels = _reported_lines(result, None)
    header = [f"{result.key} (SI)", "contact fraction", "impacts", "combination lines", "peak (um)"] + [
        f"{k} (um)" for k in labels]
    cols = [result.values, result.contact_fraction, result.n_impacts, result.n_combinations, 1e6 * result.peak]
    cols += [1e6 * result.amplitudes[k] for k in labels]
    header.append("status")
    cols.append([result.status(i) for i in range(len(result.values))])
    ok = len(result.failures) < len(result.values)
    return ([plot_sweep(result, out / "sweep.png")] if ok else []) + [
        write_csv(out / "sweep.csv", header, cols), write_text(out / "sweep.txt", format_sweep(result) + "\n")]
