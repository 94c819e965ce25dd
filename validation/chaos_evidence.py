"""Chaotic rub in 80-100 Hz: the evidence at outer 81.5, 82.0 and 83.5 Hz (inner 70 Hz), with regular controls.

Issue "any speed ratio", Must show: "if the rig shows chaotic rub anywhere in 80-100 Hz, show that
case too, with the evidence". At outer 81.5, 82.0 and 83.5 Hz the rig's response does not repeat;
this script shows that it is chaotic there, and that the same tests say "regular" for the period-3
point of the same rig at outer 88.0 Hz and for a synthetic 3-frequency torus.

What is run
    Per outer speed f_H, ``paper-rub`` (rub at node 18, node 14 Y read) is stepped from the
    scene's start (the linear settled state, then the rub) by the scene pipeline's own call of
    :func:`rotorred.transient.newmark.simulate` to ``--duration`` (default 40 s, ``--quick`` 12 s;
    rounded up to a whole common forcing period ``1/gcd(f_L, f_H)``: 2 s at 81.5 and 83.5 Hz,
    0.5 s at 82 and 88 Hz); the first ``DISCARD`` = 8 s (``--quick``: 4 s) are discarded, the
    rest is analysed. Then ``RESTARTS`` = 3 restarts (``--quick``: 1) of ``T_DIV`` = 10 s
    (``--quick``: 6 s) from states on the attractor (the state at the end of the run, then at the
    end of each reference restart: whole common forcing periods, so the forcing phase at a restart
    equals that at t = 0 and the restart is the same forced system): a reference, and two runs
    with ``q -> q (1 + eps)``, eps = 1e-9 and 1e-6 (plates at rest in all three: ``simulate``
    takes no plate state). The synthetic 3-torus is f_H, f_L, f_H/3 and an incommensurate
    ``TORUS_F3`` = 131.957 Hz with combinations, over the rig's analysed span at the rig's dt.
    Everything stays in memory; no file is written except the ``--plot`` figure.

The tests, their thresholds and why
    1. **0-1 test for chaos** (Gottwald and Melbourne 2009,
       :func:`rotorred.signals.classify.zero_one_test`) on Poincare samples
       (:func:`rotorred.signals.classify.poincare_samples`), once per outer revolution (f_H) and
       once per three (f_H/3, the impacts' lock elsewhere in 80-100 Hz), on the last N = 100,
       200, 400, 800 samples and on all. K tends to 1 for chaos and to 0 for regular motion
       (periodic or quasi-periodic) as N grows; chaotic means ``K >= 0.8``
       (:data:`rotorred.signals.classify.CHAOS_K`). N matters: regular motion reads K near 1
       until the record holds many of its slowest periods. The 3-torus reads K = 0.96 at N = 400
       and 0.1 at N = 800 (f_H section); the 88 Hz period-3 orbit, 132 samples per period at f_H,
       reads 0.97, 0.96, 0.88, 0.84 at N = 100-800 and 0.41 on all 2815. So K near 1 is evidence
       of chaos only where it stays near 1 at N >= 800 and on all samples while the controls fall.
    2. **Broadband band**: of the Hann spectrum's energy in ``BAND`` = 100-160 Hz (where the rub
       puts its non-forced response, near the 122.6 Hz backward and 128.7 Hz forward whirl modes
       of the rotor without rub), the share its ten strongest peaks hold, each with +-1 bin. A
       stationary line holds at least 98 % of its energy within +-1 bin (100 % on a bin), so a band
       of a few lines gives close to 1 (the 88 Hz control 0.94, the 3-torus 0.99); a broadband
       hump far less, and the less the longer the record (its energy spreads over more bins): at
       81.5 Hz 0.54, 0.45, 0.30, 0.24 on 8, 12, 24, 40 s, 0.11-0.14 on 60 s. The project's bound
       for a broadband residual is < 0.9 (:data:`rotorred.signals.classify.BROADBAND_MAX`).
    3. **Explained share** of :func:`rotorred.signals.linefit.fit_lines` (torus found by the
       tool) on the analysed record: below 0.9 (:data:`rotorred.signals.classify.EXPLAINED_MIN`)
       the combination lines of f_H, f_L and their sub-harmonics do not describe the response.
       On its own this does not tell chaos from a torus with a third frequency (the synthetic
       3-torus: 0.77 on 32 s; on 8 s a sub-harmonic torus comes within the resolution of its third
       frequency, 0.95); with 1 and 2 it does.
    4. **Divergence of nearby states**: the largest Lyapunov exponent lambda (Wolf et al. 1985;
       Parker and Chua 1989) is positive for chaos, negative on a stable periodic orbit. While
       the separations are small the flow is linear in them, so the eps = 1e-9 run's separation
       is a 1e-3 copy of the eps = 1e-6 run's, and the delay between the two reaching
       ``THRESHOLD`` = 1e-8 m at node 14 Y is the time a small separation takes to grow 1000-fold:
       ``lambda = ln(1000) / delay``, with no fitting window to choose. Printed per restart (the
       finite-time rate varies along the attractor: 2.3-26 1/s over 18 restarts at 81.5 Hz) and
       pooled, ln(1000) / mean delay; the e-folding time 1/lambda (also in outer revolutions);
       the growth of the eps = 1e-9 separation within ``GROWTH_SPAN`` = 4 s (largest |dx| up to
       4 s over the largest in the first ``INITIAL_SPAN`` = 0.5 s): exponential divergence gives
       1e3-1e7, up to the attractor's size (~1e-5 m), a stable orbit about 1; and the eps = 1e-6
       separation in the last second over the first 0.5 s ("end"): about 1e5 at the attractor's
       size, well below 1 when it decays.

What the results mean
    Default run (40 s, 8 s discarded, 2600-2700 samples at f_H): at 81.5, 82.0 and 83.5 Hz K =
    0.98-1.00 at every N and on all samples, both sections, while the 3-torus falls to 0.12 at
    N = 800 and the 88 Hz orbit to 0.41 on all samples (0.29 at f_H/3); the ten strongest
    100-160 Hz peaks hold 0.28-0.44 of the band (0.94 and 0.99 for the controls); the lines
    explain 0.31-0.50 (88 Hz: 0.955); states 1e-9 apart diverge exponentially, pooled lambda
    4.1-6.3 1/s (e-folding 0.16-0.25 s, 13-21 outer revolutions), up to the attractor's size,
    while at 88 Hz the separation decays (2.6e-4 of its start after 10 s). The earlier study, on
    120 s records, found K = 0.98-1.00 up to about 10 000 samples, and halving dt (1e-5 s,
    ``--dt``) left K at 0.985-0.998. The rub there is chaotic: deterministic, bounded, aperiodic,
    with sensitive dependence on the state; no line fit can explain it.

Run: ``python validation/chaos_evidence.py [--quick] [--duration S] [--dt S] [--plot PATH]``
(default about 1 min on one core; ``--quick``, 81.5 Hz and the 88 Hz control, about 10 s). BLAS is
set to one thread unless set otherwise in the environment.

References
----------
.. [1] G. A. Gottwald, I. Melbourne, "On the implementation of the 0-1 test for chaos", SIAM J.
   Appl. Dyn. Syst. 8(1), 129-145, 2009; "On the validity of the 0-1 test for chaos",
   Nonlinearity 22, 1367-1382, 2009.
.. [2] A. Wolf, J. B. Swift, H. L. Swinney, J. A. Vastano, "Determining Lyapunov exponents from
   a time series", Physica D 16, 285-317, 1985.
.. [3] T. S. Parker, L. O. Chua, "Practical Numerical Algorithms for Chaotic Systems", Springer,
   1989 (Lyapunov exponents).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402
from fractions import Fraction  # noqa: E402

import numpy as np  # noqa: E402

from rotorred.scenes.run import build_model, settled_state  # noqa: E402
from rotorred.scenes.schema import load_scene  # noqa: E402
from rotorred.signals.classify import poincare_samples, zero_one_test  # noqa: E402
from rotorred.signals.linefit import fit_lines  # noqa: E402
from rotorred.signals.spectra import amplitude_spectrum  # noqa: E402

F_INNER = 70.0  #: inner spool (Hz), as paper-rub
SPEEDS = (81.5, 82.0, 83.5)  #: outer spool (Hz): the chaotic points
CONTROL = 88.0  #: outer spool (Hz): period-3 at this rig (validation/any_ratio.py)
QUICK = (81.5, CONTROL)
CHANNEL = (14, "y")  #: the paper's outer-rotor Y response
DURATION, DISCARD = 40.0, 8.0  #: s: run length, and the part discarded before the analysis
QUICK_DURATION, QUICK_DISCARD = 12.0, 4.0
SIZES = (100, 200, 400, 800)  #: 0-1 test on the last N Poincare samples (and on all)
BAND = (100.0, 160.0)  #: Hz: the broadband test's band
N_PEAKS = 10  #: strongest peaks (+-1 bin) of the band
EPS = (1e-9, 1e-6)  #: relative perturbations q -> q (1 + eps)
THRESHOLD = 1e-8  #: m: separation at node 14 Y whose crossing times give lambda
T_DIV, QUICK_T_DIV = 10.0, 6.0  #: s: length of each restart (whole common forcing periods at every speed)
RESTARTS, QUICK_RESTARTS = 3, 1
GROWTH_SPAN, INITIAL_SPAN = 4.0, 0.5  #: s: growth = max |dx| up to 4 s / max |dx| in the first 0.5 s
WINDOW = 0.05  #: s: the plotted separation is its maximum per 50 ms
TORUS_F3 = 131.957  #: Hz: the synthetic torus's third frequency (incommensurate with f_H and f_L)


# --------------------------------------------------------------------------- simulation
@dataclass(frozen=True)
class Run:
    """Node 14 Y from ``t[0]`` on, and the state (model coordinates) at the end of the run."""

    t: np.ndarray
    x: np.ndarray
    q: np.ndarray
    v: np.ndarray


def scene(f_outer: float, duration: float = DURATION, dt: float | None = None):
    """paper-rub at outer ``f_outer`` Hz, node 14 Y recorded."""
    over = {"speeds.outer": f_outer, "solver.duration": duration, "solver.record_start": 0.0,
            "output.nodes": [CHANNEL[0]], "output.directions": [CHANNEL[1]],
            "output.table": f"{CHANNEL[0]}:{CHANNEL[1]}", "output.plots": [], "output.formats": [],
            "output.compare_normal": False, "output.plot_window": [0.0, min(duration, 0.1)]}
    if dt is not None:
        over["solver.dt"] = dt
    return load_scene("paper-rub", over)


def common_period(f_outer: float) -> float:
    """1 / gcd(f_L, f_H) (s), the speeds taken as fractions of denominator <= 1000: both spools back at phase 0."""
    a, b = (Fraction(f).limit_denominator(1000) for f in (F_INNER, f_outer))
    if abs(float(b) - f_outer) > 1e-9 * f_outer or abs(float(a) - F_INNER) > 1e-9 * F_INNER:
        raise ValueError(f"outer {f_outer} Hz: no common forcing period with {F_INNER} Hz")
    g = Fraction(math.gcd(a.numerator * b.denominator, b.numerator * a.denominator), a.denominator * b.denominator)
    return float(1 / g)


def whole_periods(f_outer: float, duration: float) -> float:
    """``duration`` rounded up to a whole number of common forcing periods (s)."""
    T = common_period(f_outer)
    return T * math.ceil(duration / T - 1e-9)


def simulate_from(sc, model, q0, v0, t_end: float, record_start: float = 0.0) -> Run:
    """The scene pipeline's call (rotorred.scenes.run._transient_response) from a given state."""
    from rotorred.model.operating import Operating
    from rotorred.transient.newmark import Initial, Loads, Recording, Scheme, StepControl, simulate

    s = sc.solver
    res = simulate(model.model, Operating.point(sc.speeds), t_end, s.dt,
                   loads=Loads(sc.unbalances, gravity=s.gravity or None), contacts=sc.plates,
                   scheme=Scheme(s.method), recording=Recording(sc.output.dofs, start=record_start),
                   start=Initial(q0=q0, v0=v0), control=StepControl(progress=False))
    return Run(res.t, res.outputs[CHANNEL], res.final.q, res.final.v)


def settled_run(f_outer: float, duration: float, discard: float, model, dt: float | None = None) -> Run:
    """Scene start (linear settled state) to ``duration`` (whole common periods), recorded from ``discard``."""
    duration = whole_periods(f_outer, duration)
    sc = scene(f_outer, duration, dt)
    q0, v0 = settled_state(sc, model.model)
    return simulate_from(sc, model, q0, v0, duration, discard)


# --------------------------------------------------------------------------- record tests
def zero_one_table(t, x, f_section: float, sizes=SIZES) -> tuple[int, dict]:
    """0-1 test K of the last N Poincare samples at ``f_section`` for each N in sizes (that fits) and all."""
    x_s = poincare_samples(t, x, f_section).x
    Ks = {n: zero_one_test(x_s[-n:]) for n in sizes if n <= x_s.size}
    Ks["all"] = zero_one_test(x_s)
    return x_s.size, Ks


def band_peak_share(t, x, band=BAND, n_peaks: int = N_PEAKS) -> float:
    """Share of the Hann spectral energy in ``band`` that its ``n_peaks`` strongest peaks (+-1 bin) hold."""
    spec = amplitude_spectrum(x - x.mean(), t[1] - t[0], window="hann")
    E = spec.amplitudes ** 2
    inside = np.flatnonzero((spec.frequencies >= band[0]) & (spec.frequencies <= band[1]))
    peaks = [i for i in inside if E[i] >= E[i - 1] and E[i] >= E[i + 1]]
    top = sorted(peaks, key=lambda i: E[i], reverse=True)[:n_peaks]
    return float(sum(E[i - 1:i + 2].sum() for i in top) / E[inside].sum())


def torus_record(f_outer: float, t0: float, t1: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Synthetic 3-torus: f_H, f_L, f_H/3 and their combinations, plus 131.957 Hz and its combinations."""
    t = t0 + dt * np.arange(int(round((t1 - t0) / dt)) + 1)
    w, f3 = 2.0 * np.pi, TORUS_F3
    x = (1.0 * np.cos(w * f_outer * t) + 0.8 * np.cos(w * F_INNER * t + 0.3)
         + 0.4 * np.cos(w * f_outer / 3 * t + 1.0) + 0.3 * np.cos(w * (f_outer - F_INNER) * t + 2.0)
         + 0.2 * np.cos(w * 2 * F_INNER * t) + 0.5 * np.cos(w * f3 * t + 0.7)
         + 0.25 * np.cos(w * (f3 - f_outer) * t) + 0.2 * np.cos(w * (f3 - F_INNER) * t + 1.3)
         + 0.15 * np.cos(w * (f3 + f_outer / 3) * t))
    return t, 1e-6 * x


# --------------------------------------------------------------------------- divergence
@dataclass(frozen=True)
class Divergence:
    """One restart, per eps: crossing time of ``THRESHOLD`` (NaN: not reached), growth, end ratio, curve."""

    t_hit: dict
    growth: dict  #: max |dx| up to GROWTH_SPAN / max |dx| in the first INITIAL_SPAN
    end: dict  #: max |dx| in the last second / max |dx| in the first INITIAL_SPAN
    curves: dict  #: (window centres (s), max |dx| per WINDOW (m))

    @property
    def delay(self) -> float:
        """t_hit(smaller eps) - t_hit(larger eps) (s); NaN when either did not reach THRESHOLD."""
        (_, t1), (_, t2) = sorted(self.t_hit.items())
        return t1 - t2 if t1 > t2 else math.nan

    @property
    def rate(self) -> float:
        """lambda = ln(eps_2 / eps_1) / delay (1/s)."""
        (e1, _), (e2, _) = sorted(self.t_hit.items())
        return math.log(e2 / e1) / self.delay


def crossing_time(t, d, threshold: float = THRESHOLD) -> float:
    """First time (s) at which ``d >= threshold``; NaN when never."""
    hit = np.flatnonzero(d >= threshold)
    return float(t[hit[0]]) if hit.size else math.nan


def window_max(t, d, width: float = WINDOW) -> tuple[np.ndarray, np.ndarray]:
    """Max of ``d`` per window of ``width`` s, and the window centres."""
    n = max(1, int(round(width / (t[1] - t[0]))))
    m = d.size // n
    return t[0] + (np.arange(m) + 0.5) * n * (t[1] - t[0]), d[:m * n].reshape(m, n).max(axis=1)


def separation(t, d) -> tuple[float, float, float]:
    """Crossing time of THRESHOLD, growth up to GROWTH_SPAN and end ratio of one separation record."""
    initial = d[t <= INITIAL_SPAN].max()
    growth = d[t <= GROWTH_SPAN].max() / initial
    return crossing_time(t, d), float(growth), float(d[t >= t[-1] - 1.0].max() / initial)


def diverge(sc, model, q, v, t_div: float = T_DIV, eps=EPS) -> tuple[Divergence, Run]:
    """Reference and perturbed restarts from (q, v); returns the divergence and the reference run."""
    ref = simulate_from(sc, model, q, v, t_div)
    t_hit, growth, end, curves = {}, {}, {}, {}
    for e in eps:
        d = np.abs(simulate_from(sc, model, q * (1.0 + e), v, t_div).x - ref.x)
        t_hit[e], growth[e], end[e] = separation(ref.t, d)
        curves[e] = window_max(ref.t, d)
    return Divergence(t_hit, growth, end, curves), ref


def restarts(f_outer: float, model, run: Run, n: int, t_div: float = T_DIV, dt=None) -> list[Divergence]:
    """``n`` restarts, the first from the end of ``run``, each next from the end of the previous reference."""
    t_div = whole_periods(f_outer, t_div)
    sc = scene(f_outer, t_div, dt)
    out, q, v = [], run.q, run.v
    for _ in range(n):
        div, ref = diverge(sc, model, q, v, t_div)
        out.append(div)
        q, v = ref.q, ref.v
    return out


# --------------------------------------------------------------------------- one case
@dataclass
class Case:
    """Everything printed and plotted for one outer speed (or the synthetic torus)."""

    name: str
    f_outer: float
    span: tuple
    K: dict  #: section name -> (number of samples, {N or "all": K})
    band_share: float
    explained: float
    torus: str
    divergences: list = field(default_factory=list)
    sections: dict = field(default_factory=dict)  #: section name -> PoincareSamples (for the plot)
    wall: float = 0.0

    @property
    def rate(self) -> float:
        """Pooled lambda = ln(eps_2 / eps_1) / mean delay over the restarts where both runs reached (1/s)."""
        delays = [d.delay for d in self.divergences if np.isfinite(d.delay)]
        return math.log(EPS[1] / EPS[0]) / float(np.mean(delays)) if delays else math.nan


def analyse_record(name: str, f_outer: float, t, x) -> Case:
    """Tests 1-3 on a record (rig or synthetic)."""
    sections = {"f_H": f_outer, "f_H/3": f_outer / 3.0}
    K = {s: zero_one_table(t, x, f) for s, f in sections.items()}
    fit = fit_lines(t, x, F_INNER, f_outer)
    case = Case(name, f_outer, (float(t[0]), float(t[-1])), K, band_peak_share(t, x), fit.explained_share,
                fit.torus.label)
    case.sections = {s: poincare_samples(t, x, f) for s, f in sections.items()}
    return case


def rig_case(f_outer: float, model, duration: float, discard: float, n_restarts: int, t_div: float = T_DIV,
             dt=None) -> Case:
    """Run, analyse, restart: the rig at outer ``f_outer`` Hz."""
    t0 = time.perf_counter()
    run = settled_run(f_outer, duration, discard, model, dt)
    case = analyse_record(f"rig {f_outer:g} Hz", f_outer, run.t, run.x)
    case.divergences = restarts(f_outer, model, run, n_restarts, t_div, dt)
    case.wall = time.perf_counter() - t0
    return case


def torus_case(f_outer: float, span: tuple, dt: float) -> Case:
    """The synthetic 3-torus over the rig's analysed span, sampled at the rig's dt."""
    t0 = time.perf_counter()
    t, x = torus_record(f_outer, span[0], span[1], dt)
    case = analyse_record(f"3-torus {f_outer:g}", f_outer, t, x)
    case.wall = time.perf_counter() - t0
    return case


# --------------------------------------------------------------------------- output
def print_zero_one(cases: list[Case]) -> None:
    """Table 1: K per case and section, for N = 100 ... 800 and all."""
    cols = [str(n) for n in SIZES] + ["all"]
    print("\n0-1 test K (last N Poincare samples; chaos: K >= 0.8, regular: K -> 0)")
    print(f"{'case':<14} {'section':<7} {'N all':>6}  " + "  ".join(f"{'N=' + c:>6}" for c in cols))
    for c in cases:
        for sec, (n_all, Ks) in c.K.items():
            row = [f"{Ks[n]:6.3f}" if n in Ks else f"{'-':>6}" for n in SIZES] + [f"{Ks['all']:6.3f}"]
            print(f"{c.name:<14} {sec:<7} {n_all:6d}  " + "  ".join(row))


def fmt(v: float, spec: str) -> str:
    return format(v, spec) if np.isfinite(v) else "-"


def print_summary(cases: list[Case]) -> None:
    """Table 2: broadband share, explained share, lambda per restart and pooled, e-folding, growth."""
    e1, e2 = EPS
    print(f"\nband {BAND[0]:g}-{BAND[1]:g} Hz: share of its Hann energy in its {N_PEAKS} strongest peaks (+-1 bin; "
          f"a line: >= 0.98); explained: fit_lines, torus found; lambda = ln({e2 / e1:g}) / delay of eps {e1:g} "
          f"behind {e2:g} reaching {THRESHOLD:g} m, per restart and pooled (mean delay); growth: eps {e1:g}, "
          f"max |dx| to {GROWTH_SPAN:g} s / first {INITIAL_SPAN:g} s (min over restarts); end: eps {e2:g}, "
          f"last 1 s / first {INITIAL_SPAN:g} s (max over restarts)")
    print(f"{'case':<14} {'record (s)':>11} {'band 10pk':>9} {'explained':>9}  {'torus':<13} "
          f"{'lambda per restart':<19} {'lambda':>6} {'1/lambda':>8} {'revs':>5} {'growth':>7} {'end':>7} {'wall':>5}")
    for c in cases:
        lam = c.rate
        per = " ".join(fmt(d.rate, ".2f") for d in c.divergences) or "-"
        growth = min((d.growth[e1] for d in c.divergences), default=math.nan)
        end = max((d.end[e2] for d in c.divergences), default=math.nan)
        print(f"{c.name:<14} {c.span[0]:5.1f}-{c.span[1]:<5.1f} {c.band_share:9.3f} {c.explained:9.4f}  "
              f"{c.torus.split(' (')[0]:<13.13} {per:<19} {fmt(lam, '6.2f'):>6} {fmt(1 / lam, '8.3f'):>8} "
              f"{fmt(c.f_outer / lam, '5.1f'):>5} {fmt(growth, '7.1e'):>7} {fmt(end, '7.1e'):>7} {c.wall:5.1f}")


def plot_separations(ax, case: Case) -> None:
    """The restarts' separation curves (log), with the threshold."""
    if not case.divergences:
        ax.axis("off")
        return
    for k, d in enumerate(case.divergences):
        for e, (tw, dm) in d.curves.items():
            ax.semilogy(tw, dm, lw=0.8, label=f"restart {k + 1}, eps {e:g}")
    ax.axhline(THRESHOLD, color="0.5", ls="--", lw=0.8)
    ax.set_title(f"{case.name}: separation, max |dx| per {1e3 * WINDOW:g} ms (m)", fontsize=9)
    ax.set_xlabel("t after restart (s)")
    ax.legend(fontsize=6)


def plot(cases: list[Case], path: str) -> None:
    """Per case: separation curves of the restarts, and the Poincare clouds at f_H and f_H/3."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(14, 3.2 * len(cases)))
    axes = fig.subplots(len(cases), 3, squeeze=False)
    for row, c in zip(axes, cases):
        plot_separations(row[0], c)
        for ax, (sec, ps) in zip(row[1:], c.sections.items()):
            ax.scatter(1e6 * ps.x, 1e3 * ps.velocity, s=1.5, c=ps.times, cmap="viridis")
            ax.set_title(f"{c.name}: Poincare at {sec}, {ps.x.size} samples", fontsize=9)
            ax.set_xlabel("x (um)")
            ax.set_ylabel("dx/dt (mm/s)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


# --------------------------------------------------------------------------- main
@dataclass(frozen=True)
class Settings:
    """What one invocation runs."""

    speeds: tuple
    duration: float
    discard: float
    restarts: int
    t_div: float
    dt: float | None


def settings(argv=None) -> tuple[Settings, str | None]:
    """Parse the command line: (settings, plot path)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help=f"{QUICK[0]:g} Hz and the {CONTROL:g} Hz control, "
                        f"{QUICK_DURATION:g} s, {QUICK_RESTARTS} restart of {QUICK_T_DIV:g} s")
    parser.add_argument("--duration", type=float,
                        help=f"run length (s), default {DURATION:g} ({QUICK_DURATION:g} quick)")
    parser.add_argument("--dt", type=float, help="time step (s); default the scene's (2e-5)")
    parser.add_argument("--plot", metavar="PATH", help="draw the separation curves and the Poincare clouds")
    a = parser.parse_args(argv)
    discard = QUICK_DISCARD if a.quick else DISCARD
    duration = a.duration or (QUICK_DURATION if a.quick else DURATION)
    if duration <= discard + 1.0:
        parser.error(f"--duration must exceed the discarded {discard:g} s by more than 1 s")
    if a.quick:
        return Settings(QUICK, duration, discard, QUICK_RESTARTS, QUICK_T_DIV, a.dt), a.plot
    return Settings(SPEEDS + (CONTROL,), duration, discard, RESTARTS, T_DIV, a.dt), a.plot


def main(argv=None) -> list[Case]:
    s, plot_path = settings(argv)
    t0 = time.perf_counter()
    print(f"paper-rub, inner {F_INNER:g} Hz, node {CHANNEL[0]} {CHANNEL[1].upper()}: outer "
          f"{', '.join(f'{f:g}' for f in s.speeds)} Hz; runs of {s.duration:g} s (whole common forcing periods), "
          f"first {s.discard:g} s discarded; {s.restarts} restart(s) of {s.t_div:g} s, eps {EPS[0]:g} and "
          f"{EPS[1]:g}; synthetic 3-torus (f_H, f_L, {TORUS_F3:g} Hz) over the same span")
    model = build_model(scene(s.speeds[0], 1.0, s.dt))
    cases = [rig_case(f, model, s.duration, s.discard, s.restarts, s.t_div, s.dt) for f in s.speeds]
    cases.append(torus_case(s.speeds[0], cases[0].span, s.dt or scene(s.speeds[0], 1.0).solver.dt))
    print_zero_one(cases)
    print_summary(cases)
    if plot_path:
        plot(cases, plot_path)
        print(f"plot: {plot_path}")
    print(f"total time {time.perf_counter() - t0:.1f} s")
    return cases

if __name__ == "__main__":
    main()
