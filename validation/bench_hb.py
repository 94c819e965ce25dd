"""Side by side with pyHarm (Safran's pyHarm-os): harmonic-balance continuation of the two reference cases.

Run (pyHarm installs only on Python >= 3.11, in its own virtual environment; see below)::

    .venv-pyharm/bin/python validation/bench_hb.py [--repeats 3] [--plot PATH] [--profile]

The cases are pyHarm's published examples (and of tests/test_nonlinear_hb.py, whose
``duffing(H, N)`` and ``jeffcott(H, N)`` both take from :mod:`rotorred.nonlinear.examples`):

* Duffing ``x'' + 0.02 x' + x + 0.1 x^3 = 0.1 cos(w t)``, w from 0.5 to 2.5, ds0 = ds_max = 0.05,
  N = 128 time samples a period, H = 1 ... 7.
* Jeffcott rotor m = k = 1, c = 0.02, unbalance e = 0.05 (force e m w^2 rotating: the a_1 of x and the b_1
  of y), circular clearance g = 1 with penalty k_c = 100, no friction; w from 0.5 to 12, ds0 = 0.1,
  ds_max = 0.5, H = 5 and 10, N = 128 and 1024.

Both tools: ds_min = 1e-6, at most 5000 points, start from the linear response at w = 0.5, stop at the first
point past the end frequency. pyHarm's input is its own Duffing example's (a ``substructure`` with M, C, K,
``CosinusForcing``, ``CubicSpring``) and, for the rotor, a 2-DOF substructure, the unbalance as two
``GOForcing`` with ``dto = 2`` (``amp = -e``: pyHarm's force is ``amp w^dto nabla^dto``, and nabla^2 = -1 on the
first harmonic) and phase 0 / pi/2, and ``PenaltyBilateralGap`` on ``dirs [0, 1]`` (it closes when the
displacement *norm* reaches g: the circular clearance). Its defaults otherwise: ``scipyroot`` (MINPACK hybrj)
corrector solver, tangent predictor, ``arc_length`` corrector, ``acceptance`` step rule, no preconditioner.

Measured, for each case x H x N:

* rotorred: :func:`rotorred.nonlinear.continuation.continue_branch`, with and without stability (Hill, every
  point); pyHarm: ``FRF_NonLinear.Solve`` (no stability: pyHarm has none). Only the continuation is timed
  (problem and input built beforehand, no import, no plot), best of ``--repeats`` (3); pyHarm first runs each
  case once untimed (numba compiles its kernels on first call). BLAS, OpenMP and numba pinned to one thread.
* points (pyHarm: accepted solutions; its rejected solver calls are counted apart) and ms per point.
* accuracy against closed forms, with the same code on both tools' points: for Duffing H = 1 the single-term
  balance ``((1 - w^2 + 0.75 k3 A^2)^2 + (c w)^2) A^2 = F^2``, max |residual| / F^2 over the points; for the rotor
  the full-annular-rub radius ``((k - m w^2) r + k_c (r - g))^2 + (c w r)^2 = (e m w^2)^2`` (brentq), max relative
  radius error over the points whose sampled orbit is beyond the gap all round (min radius > g (1 + 1e-6)).
  Duffing with H > 1 has no closed form: "-".
* "HB res": the largest relative residual ``||R|| / ||F_ex||`` of the harmonic balance over the points, both
  tools' points evaluated by rotorred's :class:`~rotorred.nonlinear.hb.PeriodicProblem` (same H, same N: the
  same DFT, and pyHarm orders its unknowns harmonic-major, cos before sin, like rotorred).

What cannot be matched exactly:

* Tolerance semantics. rotorred accepts a point when ``||R|| / ||F_ex|| <= tol = 1e-10``. pyHarm's default
  ``scipyroot`` accepts what MINPACK's hybrj accepts: the relative change of the iterate below ``xtol``
  (default 1.49e-8); its ``residual_tolerance`` is consulted only for other exit statuses, and its
  ``NewtonRaphson`` solver takes an *absolute* residual (the rotor's forcing grows 576-fold over the sweep) and
  has no line search. Here pyHarm runs hybrj with ``xtol = --pyharm-xtol`` (1e-10); the "HB res" column shows
  what each tool actually reached (with the default xtol pyHarm's rotor points reach only ~1e-8). Other pyHarm
  settings, tried once on the rotor (H = 5, N = 128) and not run here: ``pseudo_arc_length`` with hybrj goes
  round the hysteresis loop (fold, corner, fold, ...) until the point cap, accepting a few points at the corner
  with a relative residual of 1e-4 (hybrj's status 1 is a small step, not a small residual); ``NewtonRaphson``
  (absolute residual 1e-10) with ``pseudo_arc_length`` stops at the corner; with ``arc_length`` it reaches 12.
* Continuation. rotorred: pseudo-arclength (plane normal to the tangent), ds x 1.5 after a correction of at most
  4 iterations, halved on failure, folds located by Brent on d omega/ds. pyHarm: arc-length (sphere of radius
  ds about the last point), ds x 2 after 5 accepted points in a row, halved on a rejected one; it flips its
  prediction direction where det(J) changes sign (a fold flagged at the first point past it, not refined).
* Stopping. pyHarm stops at the first accepted point outside [w_start, w_end] (within 1e-5 relative), after two
  solves at ds_min, at 5000 solutions (accepted or not: ``solnumber``) or after ``--pyharm-timeout`` s.
* Step norm. Both measure ds in the unscaled (z, omega) Euclidean norm.

pyHarm is optional: ``pip install pyHarm-os`` in a separate virtual environment (Python >= 3.11; it pulls in
jax and Jupyter), then ``pip install -e .`` there; numpy 2.4 and scipy 1.17 satisfy both. Without pyHarm the
script prints "pyHarm not installed: rotorred only" and the rotorred half of the table, and exits 0.
"""

from __future__ import annotations

import os

for _var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import contextlib  # noqa: E402
import cProfile  # noqa: E402
import io  # noqa: E402
import logging  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import pstats  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402

import numpy as np  # noqa: E402
import scipy  # noqa: E402
from scipy.optimize import brentq  # noqa: E402

from rotorred.nonlinear.continuation import ContinuationOptions, continue_branch  # noqa: E402
from rotorred.nonlinear.examples import C, E_UNB, GAP, K3, K_C, F, duffing, jeffcott  # noqa: E402
from rotorred.nonlinear.hb import PeriodicProblem  # noqa: E402

TOL = 1e-10  # rotorred's relative residual
DS_MIN = 1e-6
MAX_POINTS = 5000
FULL_RUB_MARGIN = 1e-6  # an orbit "beyond the gap all round": every sample's radius > g (1 + margin)


@dataclass(frozen=True)
class Case:
    """One row: the system, its harmonics and samples, the sweep and the step limits."""

    kind: str  # "duffing" or "jeffcott"
    H: int
    N: int
    omega: tuple[float, float]
    ds0: float
    ds_max: float

    @property
    def label(self) -> str:
        return f"{self.kind:8s} H={self.H:<2d} N={self.N}"

    def problem(self) -> PeriodicProblem:
        return duffing(self.H, self.N) if self.kind == "duffing" else jeffcott(self.H, self.N)

    def start(self, problem: PeriodicProblem) -> np.ndarray:
        """The linear response at omega_start (undamped): rotorred's first guess."""
        w = self.omega[0]
        z0 = np.zeros(problem.size)
        if self.kind == "duffing":
            z0[1] = F / (1 - w**2)
        else:
            z0[2] = z0[5] = E_UNB * w**2 / (1 - w**2)
        return z0


def cases() -> list[Case]:
    duff = [Case("duffing", H, 128, (0.5, 2.5), 0.05, 0.05) for H in range(1, 8)]
    jeff = [Case("jeffcott", H, N, (0.5, 12.0), 0.1, 0.5) for H in (5, 10) for N in (128, 1024)]
    return duff + jeff


# --- accuracy, the same code for both tools ------------------------------------------------------------------
def duffing_closed_form_error(z: np.ndarray, omega: np.ndarray) -> float:
    """max |((1 - w^2 + 3/4 k3 A^2)^2 + (c w)^2) A^2 - F^2| / F^2 over the points (H = 1)."""
    A2 = z[:, 1] ** 2 + z[:, 2] ** 2
    G = ((1 - omega**2 + 0.75 * K3 * A2) ** 2 + (C * omega) ** 2) * A2 - F**2
    return float(np.max(np.abs(G)) / F**2)


def _rub_radius(r: float, w: float) -> float:
    """The full-annular-rub radius nearest ``r`` at ``w``: a root of the closed form, by brentq."""
    g = lambda x: ((1 - w**2) * x + K_C * (x - GAP)) ** 2 + (C * w * x) ** 2 - (E_UNB * w**2) ** 2  # noqa: E731
    lo, hi = r * (1 - 1e-4), r * (1 + 1e-4)
    if g(lo) * g(hi) > 0:  # farther than 1e-4 off: bracket the nearest root of the quadratic in r
        kappa = 1 - w**2 + K_C
        a, b, c = kappa**2 + (C * w) ** 2, -2 * kappa * K_C * GAP, (K_C * GAP) ** 2 - (E_UNB * w**2) ** 2
        disc = b * b - 4 * a * c
        if disc <= 0:
            return -b / (2 * a)
        roots = (-b + np.array([-1.0, 1.0]) * math.sqrt(disc)) / (2 * a)
        nearest = roots[np.argmin(np.abs(roots - r))]
        half = 0.5 * (roots[1] - roots[0])
        lo, hi = nearest - 0.5 * half, nearest + 0.5 * half
    return brentq(g, lo, hi, xtol=1e-15)


def jeffcott_closed_form_error(problem: PeriodicProblem, z: np.ndarray, omega: np.ndarray) -> tuple[float, int]:
    """(max relative radius error, number of points) over the points in full annular rub."""
    errors = []
    for zi, wi in zip(z, omega):
        if np.hypot(*problem.samples(zi, wi)[0].T).min() > GAP * (1 + FULL_RUB_MARGIN):
            r = float(np.hypot(zi[2], zi[4]))  # first-harmonic amplitude of x: the circular orbit's radius
            errors.append(abs(r / _rub_radius(r, wi) - 1))
    return (max(errors) if errors else math.nan), len(errors)


def accuracy(case: Case, problem: PeriodicProblem, z: np.ndarray, omega: np.ndarray) -> dict:
    """The closed-form error (NaN where there is none), its point count, and the largest relative HB residual."""
    if len(omega) == 0:
        return dict(closed=math.nan, n_closed=0, hb=math.nan)
    if case.kind == "duffing":
        closed, n = (duffing_closed_form_error(z, omega), len(omega)) if case.H == 1 else (math.nan, 0)
    else:
        closed, n = jeffcott_closed_form_error(problem, z, omega)
    hb = max(problem.evaluate(zi, wi).relative for zi, wi in zip(z, omega))
    return dict(closed=closed, n_closed=n, hb=float(hb))


# --- rotorred -------------------------------------------------------------------------------------------------
@dataclass
class Run:
    """One tool's result on one case: best time (s), points, accuracy, how it ended, and what else to say."""

    time: float = math.nan
    points: int = 0
    closed: float = math.nan
    n_closed: int = 0
    hb: float = math.nan
    stopped: str = ""
    complete: bool = False
    folds: list = field(default_factory=list)
    rejected: int = 0
    error: str = ""

    @property
    def ms_per_point(self) -> float:
        return 1e3 * self.time / self.points if self.points else math.nan


def _best(fn, repeats: int):
    """(best wall time, last result) of ``repeats`` calls of ``fn()``."""
    best, out = math.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def run_rotorred(case: Case, repeats: int, stability: bool) -> Run:
    problem = case.problem()
    z0 = case.start(problem)
    w0, w1 = case.omega

    def go():
        return continue_branch(problem, z0, w0, w1,
                               ContinuationOptions(ds=case.ds0, ds_min=DS_MIN, ds_max=case.ds_max,
                                                   max_points=MAX_POINTS, tol=TOL, stability=stability))
    try:
        t, branch = _best(go, repeats)
    except Exception as exc:  # a failure of the continuation is a result to report, not a crash
        return Run(error=f"{type(exc).__name__}: {str(exc).splitlines()[0][:160] if str(exc) else ''}")
    run = Run(time=t, points=len(branch.omega), stopped=branch.stopped,
              complete=branch.stopped.startswith("reached the end"),
              folds=[(f.omega, getattr(f, "smooth", True)) for f in branch.folds])
    if not stability:
        run.__dict__.update(accuracy(case, problem, branch.z, branch.omega))
    return run


def profile_rotorred(case: Case, top: int = 15) -> str:
    """cProfile of one rotorred continuation (no stability) on ``case``: where the time goes (residual
    evaluations per point, ms per evaluation) and the top functions by own time."""
    problem = case.problem()
    z0 = case.start(problem)
    prof = cProfile.Profile()
    points, note = 0, ""
    prof.enable()
    try:
        points = len(
                     continue_branch(problem, z0, *case.omega,
                                     ContinuationOptions(ds=case.ds0, ds_min=DS_MIN, ds_max=case.ds_max,
                                                         max_points=MAX_POINTS, tol=TOL, stability=False)).omega)
    except Exception as exc:  # profile what ran
        note = f" (the continuation raised {type(exc).__name__})"
    prof.disable()
    stats = pstats.Stats(prof)
    total = sum(tt for _, _, tt, _, _ in stats.stats.values())
    calls = {f: (nc, ct) for (path, _, f), (_, nc, _, ct, _) in stats.stats.items()
             if path.replace(os.sep, "/").endswith("rotorred/nonlinear/hb.py") and f in ("evaluate", "solve")}
    n_eval, t_eval = calls.get("evaluate", (0, 0.0))
    out = io.StringIO()
    print(f"{points} points{note}, {total:.3f} s profiled; PeriodicProblem.evaluate (residual + Jacobian): {n_eval} "
          f"calls = {n_eval / max(points, 1):.1f} a point, {1e3 * t_eval / max(n_eval, 1):.3f} ms each, "
          f"{100 * t_eval / total:.0f} % of the time; hb.solve (Newton at fixed omega): {calls.get('solve', (0,))[0]} "
          f"calls", file=out)
    stats.stream = out
    stats.strip_dirs().sort_stats("tottime").print_stats(top)
    return out.getvalue()


# --- pyHarm ---------------------------------------------------------------------------------------------------
def import_pyharm():
    """The ``pyHarm`` module, or (None, why) when it is not installed or does not import."""
    try:
        with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            warnings.simplefilter("ignore")
            import pyHarm.Maestro  # binds pyHarm; the entry point must import too
    except Exception as exc:
        return None, f"{type(exc).__name__}: {str(exc).splitlines()[0][:200] if str(exc) else ''}"
    return pyHarm, ""


def pyharm_input(case: Case, xtol: float, timeout_s: int) -> dict:
    """pyHarm's input dictionary for ``case`` (its Duffing example's layout; the rotor as described above)."""
    n = 1 if case.kind == "duffing" else 2
    matrix = {"M": np.eye(n), "C": C * np.eye(n), "K": np.eye(n)}
    if case.kind == "duffing":
        connectors = {
            "loading": {"type": "CosinusForcing", "connect": {"sub": [0]}, "dirs": [0], "amp": F},
            "cubic": {"type": "CubicSpring", "connect": {"sub": [0]}, "dirs": [0], "k": K3}}
    else:  # e m w^2 rotating: amp w^2 nabla^2 with nabla^2 = -1 on harmonic 1, phase 0 on x, pi/2 on y
        connectors = {
            "unbalance_x": {"type": "GOForcing", "connect": {"sub": [0]}, "dirs": [0], "amp": -E_UNB, "dto": 2,
                            "ho": 1, "phi": 0.0},
            "unbalance_y": {"type": "GOForcing", "connect": {"sub": [0]}, "dirs": [1], "amp": -E_UNB, "dto": 2,
                            "ho": 1, "phi": math.pi / 2},
            "clearance": {"type": "PenaltyBilateralGap", "connect": {"sub": [0]}, "dirs": [0, 1], "g": GAP,
                          "k": K_C}}
    hh, mm, ss = timeout_s // 3600, timeout_s % 3600 // 60, timeout_s % 60
    frf = {"study": "frf", "puls_inf": case.omega[0], "puls_sup": case.omega[1], "ds0": case.ds0,
           "ds_min": DS_MIN, "ds_max": case.ds_max, "sign_ds": 1, "verbose": False,
           "stepsizer": "acceptance", "predictor": "tangent", "predictor_options": {"verbose": False},
           "corrector": "arc_length", "stopper": "solnumber",
           "stopper_options": {"max_solutions": MAX_POINTS,
                               "timeout": {"status": True, "timeout": f"00:{hh:02d}:{mm:02d}:{ss:02d}"}},
           "solver": "scipyroot", "solver_options": {"root": {"method": "hybr", "options": {"xtol": xtol}}}}
    return {"analysis": {"FRF": frf},
            "system": {"type": "Base", "nh": case.H, "nti": case.N, "adim": {"status": False, "lc": 1.0, "wc": 1.0}},
            "substructures": {"sub": {"matrix": matrix, "ndofs": n}},
            "connectors": connectors}


@contextlib.contextmanager
def _quiet():
    """pyHarm's banner, log lines and numba's performance warnings off."""
    logging.disable(logging.CRITICAL)
    try:
        with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            warnings.simplefilter("ignore")
            yield
    finally:
        logging.disable(logging.NOTSET)


def _pyharm_once(pyHarm, case: Case, xtol: float, timeout_s: int):
    """(seconds, solution list) of one pyHarm FRF analysis; the Maestro (system, elements) built untimed."""
    from pyHarm.Maestro import Maestro

    with _quiet():
        analysis = Maestro(pyharm_input(case, xtol, timeout_s)).nls["FRF"]
        t0 = time.perf_counter()
        analysis.Solve(None)
        t = time.perf_counter() - t0
    return t, analysis.SolList


def run_pyharm(pyHarm, case: Case, repeats: int, xtol: float, timeout_s: int) -> Run:
    try:
        _pyharm_once(pyHarm, case, xtol, timeout_s)  # untimed: numba compiles (or loads) its kernels
        best, sols = math.inf, None
        for _ in range(repeats):
            t, sols = _pyharm_once(pyHarm, case, xtol, timeout_s)
            best = min(best, t)
    except Exception as exc:
        return Run(error=f"{type(exc).__name__}: {str(exc).splitlines()[0][:160] if str(exc) else ''}")
    accepted = [s for s in sols if s.flag_accepted]
    y = np.array([s.x for s in accepted]) if accepted else np.zeros((0, 2))
    z, omega = y[:, :-1], y[:, -1]
    w0, w1 = case.omega
    eps = 0.5 * (w0 + w1) * 1e-5  # pyHarm's bound tolerance
    complete = bool(len(omega)) and omega[-1] >= w1 + eps
    if complete:
        stopped = f"reached the end (last point at {omega[-1]:.6g})"
    elif len(sols) >= MAX_POINTS:
        stopped = f"hit the cap of {MAX_POINTS} solutions at omega = {omega[-1]:.6g}"
    else:
        stopped = f"stopped at omega = {omega[-1]:.6g} (ds_min or timeout)" if len(omega) else "no point"
    run = Run(time=best, points=len(accepted), stopped=stopped, complete=complete, rejected=len(sols) - len(accepted),
              folds=[(float(s.x[-1]), True) for s in accepted if s.flag_bifurcation])
    run.__dict__.update(accuracy(case, case.problem(), z, omega))
    return run


# --- the table, the notes, the plot ---------------------------------------------------------------------------
def _f(x: float, fmt: str) -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, fmt)


def _closed(case: Case, run: Run) -> str:
    text = _f(run.closed, ".2e")
    return f"{text} ({run.n_closed})" if case.kind == "jeffcott" and not run.error else text


def _pts(run: Run) -> str:
    if run.error:
        return "FAIL"
    return f"{run.points}{'' if run.complete else '*'}"


def table(rows, have_pyharm: bool) -> str:
    head = (f"{'case':22s} | {'rr pts':>7s} {'ms/pt':>7s} {'+stab':>7s} {'closed-form':>11s} {'HB res':>8s}"
            + (f" | {'pH pts':>7s} {'ms/pt':>7s} {'closed-form':>15s} {'HB res':>8s} | {'pH/rr':>6s}"
               if have_pyharm else ""))
    lines = [head, "-" * len(head)]
    for case, rr, rs, ph in rows:
        line = (f"{case.label:22s} | {_pts(rr):>7s} {_f(rr.ms_per_point, '.3f'):>7s} {_f(rs.ms_per_point, '.3f'):>7s}"
                f" {_closed(case, rr):>15s} {_f(rr.hb, '.1e'):>8s}")
        if have_pyharm:
            ratio = ph.ms_per_point / rr.ms_per_point if rr.points and ph.points else math.nan
            line += (f" | {_pts(ph):>7s} {_f(ph.ms_per_point, '.3f'):>7s} {_closed(case, ph):>15s}"
                     f" {_f(ph.hb, '.1e'):>8s} | {_f(ratio, '.2f'):>6s}")
        lines.append(line)
    return "\n".join(lines)


def duffing_folds_closed_form() -> list[float]:
    """The one-harmonic Duffing folds: double roots of the cubic in A^2 (its discriminant's zeros)."""
    beta = 0.75 * K3

    def discriminant(omega):
        a3, a2, a1, a0 = beta**2, 2 * (1 - omega**2) * beta, (1 - omega**2) ** 2 + (C * omega) ** 2, -F**2
        return 18 * a3 * a2 * a1 * a0 - 4 * a2**3 * a0 + a2**2 * a1**2 - 4 * a3 * a1**3 - 27 * a3**2 * a0**2
    return sorted(brentq(discriminant, lo, hi, xtol=1e-15) for lo, hi in ((1.0, 1.2), (1.3, 1.5)))


def notes(rows, have_pyharm: bool) -> str:
    """How each run ended, the folds, and the closed-form point counts."""
    out = ["* = the branch did not reach omega_end; closed-form: Duffing H = 1 max |G| / F^2, rotor max relative "
           "radius error over the full-rub points (their count in brackets); HB res: max ||R|| / ||F_ex||; "
           "pH/rr: pyHarm's ms/pt over rotorred's (without stability).",
           f"closed-form Duffing H = 1 folds: {', '.join(f'{w:.9f}' for w in duffing_folds_closed_form())} rad/s"]
    for case, rr, _, ph in rows:
        out.append(f"{case.label}:")
        for name, run in (("rotorred", rr),) + ((("pyHarm", ph),) if have_pyharm else ()):
            if run.error:
                out.append(f"  {name:8s} FAILED: {run.error}")
                continue
            extra = f", {run.rejected} rejected solves" if name == "pyHarm" else ""
            kind = "located" if name == "rotorred" else "flagged at"
            folds = ", ".join(f"{w:.6f}{'' if smooth else ' (corner)'}" for w, smooth in sorted(run.folds)) or "none"
            out.append(f"  {name:8s} {run.stopped}{extra}; folds {kind}: {folds}")
    return "\n".join(out)


def plot(rows, have_pyharm: bool, path: str) -> str:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 4.8))
    ax = fig.subplots()
    x = np.arange(len(rows))
    series = [("rotorred", [r[1] for r in rows]), ("rotorred + Hill stability", [r[2] for r in rows])]
    if have_pyharm:
        series.append(("pyHarm-os (no stability)", [r[3] for r in rows]))
    width = 0.8 / len(series)
    for i, (name, runs) in enumerate(series):
        bars = ax.bar(x + (i - (len(series) - 1) / 2) * width, [r.ms_per_point for r in runs], width, label=name,
                      color=f"C{i}")
        for bar, run in zip(bars, runs):
            if not run.complete:
                bar.set_hatch("//")
    ax.set_xticks(x, [f"{c.kind[:4]}\nH={c.H} N={c.N}" for c, *_ in rows], fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("ms per continuation point (log)")
    ax.set_title("Harmonic-balance continuation: time per point (best of repeats, one thread; "
                 "hatched: branch stopped short)", fontsize=10)
    ax.legend()
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3, help="timed runs of each (best kept; default 3)")
    parser.add_argument("--plot", metavar="PATH", help="save a bar chart of ms per point (PNG)")
    parser.add_argument("--profile", action="store_true",
                        help="cProfile rotorred on every case where it is slower than pyHarm")
    parser.add_argument("--pyharm-xtol", type=float, default=1e-10, help="hybrj's xtol for pyHarm (default 1e-10)")
    parser.add_argument("--pyharm-timeout", type=int, default=300, help="pyHarm's time limit a run, s (default 300)")
    parser.add_argument("--only", choices=("duffing", "jeffcott"), help="one system only")
    args = parser.parse_args(argv)

    pyHarm, why = import_pyharm()
    have = pyHarm is not None
    print(f"python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
          f"threads {os.environ['OPENBLAS_NUM_THREADS']}; rotorred tol {TOL:g} (relative residual)")
    if have:
        print(f"pyHarm {getattr(pyHarm, '__version__', '?')}: scipyroot/hybr xtol {args.pyharm_xtol:g}, "
              f"tangent predictor, arc_length corrector, acceptance step rule")
    else:
        print(f"pyHarm not installed: rotorred only ({why})")
    rows = []
    for case in cases():
        if args.only and case.kind != args.only:
            continue
        rr = run_rotorred(case, args.repeats, stability=False)
        rs = run_rotorred(case, args.repeats, stability=True)
        ph = run_pyharm(pyHarm, case, args.repeats, args.pyharm_xtol, args.pyharm_timeout) if have else Run()
        rows.append((case, rr, rs, ph))
        print(f"  done {case.label}", file=sys.stderr, flush=True)
    print()
    print(table(rows, have))
    print()
    print(notes(rows, have))
    if args.plot:
        try:
            print(f"plot: {plot(rows, have, args.plot)}")
        except ImportError as exc:
            print(f"plot: not written ({exc})")
    if args.profile and have:
        for case, rr, _, ph in rows:
            if rr.points and ph.points and ph.ms_per_point < rr.ms_per_point:
                print(f"\n--- cProfile of rotorred, {case.label} (pyHarm faster per point) ---")
                print(profile_rotorred(case))
    return 0


if __name__ == "__main__":
    sys.exit(main())
