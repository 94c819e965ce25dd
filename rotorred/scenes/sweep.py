"""Parameter sweeps of a scene, e.g. the rub clearance study promised by Xu et al. (2016, abstract).

:func:`sweep` runs a scene once per value of one key (``rub.clearance`` by default), reusing
one structural model for every run when the key does not change it, and collects per value:
the amplitudes of f_L, f_H and every combination line at one DOF, the number of combination
lines, the peak displacement, the contact fraction and the number of impacts of the first
plate. :func:`plot_sweep` draws them against the swept value; for a clearance sweep it marks
the free (no-rub) orbit's reach towards the plate at the rub node, beyond which no contact
and so no combination line can occur.
"""

from __future__ import annotations

import csv
import math
import time
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Sequence

import numpy as np

from rotorred.model.loads import gravity_force
from rotorred.scenes.run import _model_key, _steady, build_model, run_scene, table_dof
from rotorred.scenes.schema import Scene, load_scene

__all__ = ["SweepResult", "sweep", "free_reach", "plot_sweep", "write_sweep", "format_sweep"]


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

    def combinations(self) -> list[str]:
        """Combination-line labels, strongest (largest amplitude over the sweep) first."""
        combos = [k for k in self.amplitudes if k not in ("f_L", "f_H")]
        return sorted(combos, key=lambda k: -float(np.max(self.amplitudes[k])))

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
    from rotorred.scenes.run import SceneModel
    if model is None:
        model = build_model(scene)
    m = model.model if isinstance(model, SceneModel) else model
    plate = scene.plates[0]
    rows = m.output_rows([(plate.node, "x"), (plate.node, "y")])
    f = [w / (2 * math.pi) for w in scene.speeds.values() if w > 0]
    ratio = Fraction(max(f) / min(f)).limit_denominator(100)
    period = ratio.denominator / min(f)
    t = np.arange(0.0, period, min(scene.solver.dt, period / 2000))
    xy = np.zeros((2, len(t)))
    steady = _steady(scene, m)
    for s, P in (steady.phasors.items() if steady is not None else ()):
        xy += np.real((rows @ P)[:, None] * np.exp(1j * steady.speeds[s] * t)[None, :])
    if scene.solver.gravity:
        xy += (rows @ np.linalg.solve(m.K, gravity_force(m, scene.solver.gravity)))[:, None]
    return float(np.max(plate.normal @ xy))


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
    # validate every scene before computing anything
    scenes = [load_scene(spec, {**settings, key: v}) for v in values]
    model_cache = {}
    amps: dict[str, list] = {}
    n = len(scenes)
    n_comb = np.zeros(n, dtype=int)
    peak, cf, imp, wall = np.zeros(n), np.zeros(n), np.zeros(n, dtype=int), np.zeros(n)
    reach = None
    for i, sc in enumerate(scenes):
        t0 = time.perf_counter()
        mk = _model_key(sc)
        if mk not in model_cache:
            model_cache[mk] = build_model(sc)
        model = model_cache[mk]
        res = run_scene(sc, model, compare_normal=False)
        d = tuple(dof) if dof is not None else table_dof(res)
        if d not in res.outputs:
            raise ValueError(f"`dof` {d} is not recorded by the scene (outputs {list(res.outputs)})")
        for ln in res.lines[d]:
            if not ln.known:
                continue
            amps.setdefault(ln.label_ascii, [0.0] * n)[i] = ln.amplitude
            if ln.label_ascii not in ("f_L", "f_H"):
                n_comb[i] += 1
        peak[i] = res.peak(d)
        cf[i] = res.contact_fraction(0)
        imp[i] = res.n_impacts(0)
        if i == 0:
            reach = free_reach(sc, model)
            f_L, f_H, dof0 = res.f_L, res.f_H, d
        wall[i] = time.perf_counter() - t0
        if progress:
            print(f"  {key} = {values[i]!r}: contact {100 * cf[i]:.2f} %, {imp[i]} impacts, {n_comb[i]} combination "
                  f"lines, peak {1e6 * peak[i]:.4g} um ({wall[i]:.2f} s)", flush=True)
    vals = np.array([float(v) for v in values]) if all(isinstance(v, (int, float)) for v in values) \
        else np.arange(n, dtype=float)
    return SweepResult(scene_name=scenes[0].name, key=key, values=vals, dof=dof0, f_L=f_L, f_H=f_H,
                       amplitudes={k: np.array(v) for k, v in amps.items()}, n_combinations=n_comb, peak=peak,
                       contact_fraction=cf, n_impacts=imp, free_reach=reach, wall_times=wall)


def _axis(key: str) -> tuple[float, str]:
    """Plot scale and axis label of a swept key."""
    name = key.split(".")[-1]
    if name == "clearance":
        return 1e6, "Rub clearance (µm)"
    units = {"m_e": (1.0, "kg m"), "dt": (1.0, "s"), "mu_s": (1.0, "-"), "mu_d": (1.0, "-"),
             "k_n": (1.0, "N/m"), "K_nr": (1.0, "N/m^1.5"), "theta_deg": (1.0, "deg")}
    scale, unit = units.get(name, (1.0, "scene units"))
    return scale, f"{key} ({unit})"


def plot_sweep(result: SweepResult, path, n_lines: int = 4) -> Path:
    """Line amplitudes (f_L, f_H, the ``n_lines`` strongest combinations) and contact fraction against the value."""
    from matplotlib.figure import Figure

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    scale, xlabel = _axis(result.key)
    x = scale * result.values
    fig = Figure(figsize=(9, 7.5), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    node, d = result.dof
    labels = [k for k in ("f_L", "f_H") if k in result.amplitudes] + result.combinations()[:n_lines]
    for k in labels:
        style = "-o" if k in ("f_L", "f_H") else "--s"
        mathlabel = "$" + k.replace("f_L", "f_L").replace("f_H", "f_H") + "$"
        ax1.plot(x, 1e6 * result.amplitudes[k], style, ms=4, label=f"{mathlabel} ({_line_hz(k, result):.0f} Hz)")
    ax1.plot(x, 1e6 * result.combination_total(), ":", color="k", label="sum of all combination lines")
    ax1.set_ylabel(f"Line amplitude at node {node} {d.upper()} (µm)")
    ax1.set_title(f"Spectral lines at node {node} {d.upper()}")
    ax1.grid(True, alpha=0.3)
    ax2.plot(x, 100 * result.contact_fraction, "-o", ms=4, color="C3", label="contact fraction")
    ax2.set_ylabel("Contact fraction of the window (%)")
    ax2.set_xlabel(xlabel)
    ax2.set_title("Rub contact")
    ax2.grid(True, alpha=0.3)
    ax3 = ax2.twinx()
    ax3.plot(x, result.n_combinations, "-^", ms=4, color="C4", label="number of combination lines")
    ax3.set_ylabel("Combination lines above threshold")
    if result.free_reach is not None and result.key.endswith("clearance"):
        for ax in (ax1, ax2):
            ax.axvline(scale * result.free_reach, color="0.4", ls="--", lw=1.0,
                       label=f"free orbit reach {scale * result.free_reach:.3g} µm")
    h2, l2 = ax2.get_legend_handles_labels()
    h3, l3 = ax3.get_legend_handles_labels()
    ax2.legend(h2 + h3, l2 + l3, loc="upper right", fontsize=8)
    ax1.legend(loc="upper right", fontsize=8)
    fig.suptitle(f"{result.scene_name}: sweep of {result.key} (f_L = {result.f_L:.4g} Hz, f_H = {result.f_H:.4g} Hz)")
    fig.savefig(path, dpi=120)
    return path


def _line_hz(label: str, result: SweepResult) -> float:
    from rotorred.signals.lines import parse_label
    m, n = parse_label(label)
    return m * result.f_H + float(n) * result.f_L


def format_sweep(result: SweepResult, n_lines: int = 4) -> str:
    """Table: value, contact fraction, impacts, number of combination lines, amplitudes (µm)."""
    scale, xlabel = _axis(result.key)
    labels = [k for k in ("f_L", "f_H") if k in result.amplitudes] + result.combinations()[:n_lines]
    header = [xlabel, "contact (%)", "impacts", "comb. lines", "peak (um)"] + [f"{k} (um)" for k in labels]
    rows = []
    for i, v in enumerate(result.values):
        rows.append([f"{scale * v:.4g}", f"{100 * result.contact_fraction[i]:.2f}", str(result.n_impacts[i]),
                     str(result.n_combinations[i]), f"{1e6 * result.peak[i]:.4g}"]
                    + [f"{1e6 * result.amplitudes[k][i]:.4g}" for k in labels])
    widths = [max(len(h), *(len(r[j]) for r in rows)) for j, h in enumerate(header)]
    out = [" | ".join(h.ljust(w) for h, w in zip(header, widths)), "-|-".join("-" * w for w in widths)]
    out += [" | ".join(c.ljust(w) for c, w in zip(r, widths)) for r in rows]
    if result.free_reach is not None:
        out.append(f"free (no-rub) orbit reach towards the plate at the rub node: {1e6 * result.free_reach:.4g} um")
    return "\n".join(out)


def write_sweep(result: SweepResult, out) -> list[Path]:
    """Write ``sweep.png``, ``sweep.csv`` (all lines, amplitudes in µm) and ``sweep.txt``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    files = [plot_sweep(result, out / "sweep.png")]
    labels = [k for k in ("f_L", "f_H") if k in result.amplitudes] + result.combinations()
    with open(out / "sweep.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([f"{result.key} (SI)", "contact fraction", "impacts", "combination lines", "peak (um)"]
                   + [f"{k} (um)" for k in labels])
        for i, v in enumerate(result.values):
            w.writerow([f"{v:.9g}", f"{result.contact_fraction[i]:.6g}", result.n_impacts[i],
                        result.n_combinations[i], f"{1e6 * result.peak[i]:.6g}"]
                       + [f"{1e6 * result.amplitudes[k][i]:.6g}" for k in labels])
    files.append(out / "sweep.csv")
    (out / "sweep.txt").write_text(format_sweep(result) + "\n")
    files.append(out / "sweep.txt")
    return files
