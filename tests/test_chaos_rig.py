"""Chaotic rub on the rig at outer 81.5 Hz (inner 70 Hz), against the period-3 point at outer 88.0 Hz.

The functions are those of validation/chaos_evidence.py (loaded as tests/test_any_ratio.py loads
validation/any_ratio.py), on short runs: paper-rub from the scene's start to 10 s (five common
forcing periods of 2 s at 81.5 Hz, twenty of 0.5 s at 88 Hz), node 14 Y recorded from 2 s (the
transients of the lightly damped modes, log dec >= 0.07, decay by e^-5 in about 1 s), then one
restart of 6 s from the state at 10 s (same forcing phase as t = 0), reference and q -> q (1 + eps)
for eps = 1e-9 and 1e-6.

Why the tolerances are wide: at 81.5 Hz a different BLAS or compiler changes the last bits, and
after 10 s of chaos the run is on another point of the same attractor. So each bound covers the
spread of the quantity over the attractor (measured on consecutive windows and restarts of longer
runs), not only the value measured on this machine, which is stated next to it.
"""

import functools
import math
from pathlib import Path

from validation_scripts import load_validation

ROOT = Path(__file__).resolve().parents[1]
F_CHAOS, F_PERIOD_3 = 81.5, 88.0
RUN, DISCARD, T_RESTART = 10.0, 2.0, 6.0  # s


def _load_validation(name: str):
    return load_validation(name.removeprefix("validation_"))


@functools.lru_cache(maxsize=1)
def _evidence():
    return _load_validation("validation_chaos_evidence")


@functools.lru_cache(maxsize=1)
def _model():
    ce = _evidence()
    return ce.build_model(ce.scene(F_CHAOS, 1.0))


@functools.lru_cache(maxsize=None)
def _run(f_outer: float):
    """paper-rub at outer ``f_outer`` Hz, 0-10 s, node 14 Y recorded 2-10 s, and the state at 10 s."""
    return _evidence().settled_run(f_outer, RUN, DISCARD, _model())


@functools.lru_cache(maxsize=None)
def _restart(f_outer: float):
    """One restart of 6 s from the state at 10 s: reference and eps = 1e-9, 1e-6."""
    return _evidence().restarts(f_outer, _model(), _run(f_outer), 1, T_RESTART)[0]


def test_rub_at_81_5_hz_is_aperiodic_by_the_0_1_test_and_broadband_in_100_160_hz():
    """(a) Record 2-10 s, 651 Poincare samples once per outer revolution.

    0-1 test: K >= 0.9 (measured 0.991 on all 651 samples; 0.988-0.997 on five consecutive 8 s
    windows of a 42 s run; chaos threshold of rotorred.signals.classify 0.8). Not enough alone on
    this length: the 88 Hz period-3 orbit has a period of 132 samples at this section and reads
    K = 0.84 on 703 samples (K falls with N: 0.41 on 2815, validation/chaos_evidence.py).

    Broadband: the ten strongest peaks (+-1 bin) of the Hann spectrum in 100-160 Hz hold < 0.75 of
    the band's energy (measured 0.536; 0.46-0.61 on the five windows); the 88 Hz period-3 record
    of the same length, a line spectrum, holds > 0.9 (measured 0.944; a line alone >= 0.98). The
    share of a broadband band falls as the record lengthens (more bins; a line keeps its +-1 bin):
    at 81.5 Hz 0.54, 0.45, 0.30, 0.24 on 8, 12, 24, 40 s, and 0.11-0.14 on 60 s records, where
    the bound of 0.3 holds; 8 s is what this test can afford.
    """
    ce = _evidence()
    run = _run(F_CHAOS)
    n, K = ce.zero_one_table(run.t, run.x, F_CHAOS, sizes=())
    assert n >= 600 and K["all"] >= 0.9
    assert ce.band_peak_share(run.t, run.x) < 0.75
    regular = _run(F_PERIOD_3)
    assert ce.band_peak_share(regular.t, regular.x) > 0.9


def test_states_1e_9_apart_on_the_81_5_hz_attractor_diverge_exponentially():
    """(b) Restart from the state at 10 s (on the attractor; forcing phase as at t = 0).

    While small, the separation is linear in eps, so the eps = 1e-9 run follows the eps = 1e-6 run
    1000 times lower, and its delay in reaching 1e-8 m at node 14 Y gives the largest Lyapunov
    exponent: lambda = ln(1000) / delay. Measured: 1e-6 at 1.235 s, 1e-9 at 3.089 s, lambda = 3.73
    1/s. Asserted 1.5 <= lambda <= 30 1/s: the finite-time rate varies along the attractor, 2.3-26
    1/s over 18 restarts (pooled over restarts 4.5-5.2 1/s, e-folding 0.2 s).
    Growth of the eps = 1e-9 separation within 4 s over its size in the first 0.5 s: >= 1e4
    (measured 1.1e5; >= 5.6e4 over 10 restarts), up to the attractor's size: it reaches > 1e-6 m
    (measured 1.1e-5 m; the response's std is 2e-6 m) from below 1e-12 m.
    """
    d = _restart(F_CHAOS)
    t_small, t_large = d.t_hit[1e-9], d.t_hit[1e-6]
    assert math.isfinite(t_small) and math.isfinite(t_large) and t_large < t_small
    assert 1.5 <= d.rate <= 30.0
    assert d.rate == math.log(1000.0) / (t_small - t_large)
    assert d.growth[1e-9] >= 1e4
    first, peak = d.curves[1e-9][1][0], d.curves[1e-9][1].max()
    assert first < 1e-12 and peak > 1e-6


def test_period_3_control_at_88_hz_does_not_diverge():
    """(c) The same restart at outer 88.0 Hz (period-3 at this rig, validation/any_ratio.py).

    The eps = 1e-9 separation stays within 10 times its size in the first 0.5 s (measured: 2.3 up
    to 4 s; it then falls to a round-off floor near 1e-15 m), the eps = 1e-6 separation decays:
    its last second is below 0.1 of its first 0.5 s (measured 1.3e-3; 2.6e-4 after 10 s), and
    neither reaches 1e-8 m (measured largest 1.1e-10 m for eps = 1e-6).
    """
    d = _restart(F_PERIOD_3)
    assert d.growth[1e-9] <= 10.0
    assert d.end[1e-6] <= 0.1
    assert all(math.isnan(t) for t in d.t_hit.values())
    assert max(c[1].max() for c in d.curves.values()) < 1e-9
