"""Issue 19 on the rig: the rub scene off 70/90 Hz (outer 88.8 Hz), the classifier on rig runs, and
validation/any_ratio.py (--quick)."""

import functools
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from validation_scripts import load_validation

from rotorred.scenes.run import run_scene
from rotorred.scenes.schema import load_scene
from rotorred.signals.linefit import FitOptions, fit_lines

ROOT = Path(__file__).resolve().parents[1]
F_L, F_H = 70.0, 88.8


def _load_validation(name: str):
    return load_validation(name.removeprefix("validation_"))


@functools.lru_cache(maxsize=1)
def _any_ratio():
    return _load_validation("validation_any_ratio")


@functools.lru_cache(maxsize=1)
def _rig_88_8():
    """paper-rub at outer 88.8 Hz, node 14 Y, recorded 2.0-3.5 s (the scene's record start, 1.5 s long)."""
    scene = load_scene("paper-rub", {"speeds.outer": F_H, "solver.duration": 3.5, "output.nodes": [14],
                                     "output.directions": ["y"], "output.table": "14:y", "output.plots": [],
                                     "output.formats": [], "output.compare_normal": False,
                                     "output.plot_window": [2.0, 3.5]})
    res = run_scene(scene)
    return res.t, res.outputs[(14, "y")]


def test_rub_at_88_8_hz_finds_the_f_H_over_3_torus_and_60_lines_explain_90_percent():
    """The issue's "not commensurate" case, on a 1.5 s record from the scene's record start (2.0 s).

    Measured: torus (f_H/3, f_L) found among the four tried, 179 significant lines, the 60 strongest
    refitted alone explain 0.921. (On the scene's default 0.6 s record they cannot: see the next test.)
    """
    t, x = _rig_88_8()
    fit = fit_lines(t, x, F_L, F_H, options=FitOptions(max_kept=60))  # torus not given: found
    assert (fit.torus.k, fit.torus.j) == (3, 1)
    assert len(fit.lines) <= 60 and fit.n_significant > 60
    assert fit.explained_share >= 0.90  # the threshold (measured 0.921)
    assert any(ln.m == Fraction(1, 3) and ln.n == 0 for ln in fit.lines)  # f_H/3 itself is a line
    for ln in fit.lines:  # exact by construction: the frequency is the first label's combination
        assert ln.m.denominator in (1, 3) and ln.n.denominator == 1
        assert ln.frequency_hz == pytest.approx(float(ln.m) * F_H + float(ln.n) * F_L, rel=1e-13, abs=1e-12)
        for m, n in ln.orders:  # every merged label lies within the merge distance c/T
            assert abs(float(m) * F_H + float(n) * F_L - ln.frequency_hz) < fit.resolution_hz
    # the residual is listed: its strongest peaks, strongest first, between labelled lines
    peaks = fit.unlabelled
    assert len(peaks) >= 5 and all(p.amplitude > 0 for p in peaks)
    strongest = max(peaks, key=lambda p: p.amplitude)
    assert 300.0 < strongest.frequency_hz < 420.0  # the band the fit leaves (measured 341.3 Hz)
    assert all(abs(p.frequency_hz - f) > 0.5 / fit.duration for p in peaks for f in fit.frequencies_hz)
    # explained share as defined: 1 - RSS / energy on the time record
    energy = np.sum((x - x.mean()) ** 2)
    assert fit.explained_share == pytest.approx(1.0 - np.sum(fit.residual ** 2) / energy, rel=1e-12)


def test_rub_at_88_8_hz_default_record_is_too_short():
    """On the scene's default record, 2.0-2.6 s, no honest fit reaches 90 %: lines of the torus that
    carry the 300-420 Hz band (14 % of the energy) lie 0.4-2.8 Hz apart, below 2/T = 3.3 Hz.
    Measured: 11 significant lines explain 0.826."""
    t, x = _rig_88_8()
    part = t < 2.6 - 1e-9
    fit = fit_lines(t[part], x[part], F_L, F_H, options=FitOptions(max_kept=60))
    assert (fit.torus.k, fit.torus.j) == (3, 1)  # the torus is found all the same
    assert fit.explained_share < 0.90


@functools.lru_cache(maxsize=1)
def _quick(tmp: str):
    return _any_ratio().main(["--quick", "--plot", tmp])


def test_any_ratio_quick_classifies_the_rig_periodic_and_period_3(tmp_path_factory, capsys):
    """validation/any_ratio.py --quick: at 90 Hz the rig is periodic (period 1/gcd = 0.1 s); at 88 Hz the
    impacts lock to f_H/3 and the response is period-3 (measured: settled 0.40 s and 0.50 s, explained
    0.9999 and 0.956)."""
    path = tmp_path_factory.mktemp("any_ratio") / "any_ratio.png"
    points = {p.f_outer: p for p in _quick(str(path))}
    out = capsys.readouterr().out
    assert "total time" in out and path.stat().st_size > 0
    periodic, period_3 = points[90.0].classification, points[88.0].classification
    assert periodic.kind == "periodic" and periodic.period == pytest.approx(0.1, rel=1e-12)
    assert periodic.settling.settled and periodic.explained_share > 0.999
    assert (period_3.kind, period_3.subharmonic) == ("period-k", 3)
    assert period_3.period == pytest.approx(1.5, rel=1e-12)  # 3 / gcd(88, 70) = 3 / 2 Hz
    assert period_3.settling.settled and period_3.explained_share > 0.9


def test_a_rig_run_too_short_to_settle_is_reported_unsettled():
    """At 86 Hz the rig settles (period-2) only after about 3 s (validation/any_ratio.py); run to 2 s it
    has not settled, and it is said so, not labelled."""
    v = _any_ratio()
    point = v.run_point(86.0, durations=(2.0,))
    c = point.classification
    assert c.kind == "unsettled" and not c.settling.settled and c.subharmonic is None
    assert "not settled" in c.settling.reason or "too short" in c.settling.reason


def test_rig_at_96_5_hz_is_quasi_periodic_on_the_f_H_over_3_torus():
    """From the 80-100 Hz sweep (validation/any_ratio.py): at outer 96.5 Hz the impacts lock to f_H/3 and the
    response lies on the 2-torus (f_H/3, f_L), which is not commensurate (ratio 193/420). Measured: settled
    0.47 s, explained 0.998, Poincare samples once per 3 revolutions on one closed curve."""
    c = _any_ratio().run_point(96.5, durations=(4.0,)).classification
    assert c.kind == "quasi-periodic" and c.settling.settled
    assert (c.torus.k, c.torus.j) == (3, 1) and c.explained_share > 0.99
    assert c.poincare.frequency_hz == pytest.approx(96.5 / 3, rel=1e-12)
    assert c.curve_share is None or c.curve_share > 0.9


def test_scene_summary_at_88_8_hz_on_the_default_record_says_unsettled_and_what_record_would_do():
    """paper-rub at outer 88.8 Hz as a user runs it (record 2.0-2.6 s): the fit finds f_H/3 but explains
    less than 90 % (measured 0.826), the settling windows (10 periods of f_H/3 ... resolved: 0.589 s)
    do not fit twice in 0.6 s, so the class is "unsettled", and the summary names the record that would."""
    from rotorred.scenes.summary import format_summary
    res = run_scene(load_scene("paper-rub", {"speeds.outer": F_H, "output.nodes": [14], "output.directions": ["y"],
                                             "output.table": "14:y", "output.plots": [], "output.formats": [],
                                             "output.compare_normal": False}))
    a = res.analysis
    assert (a.fit.torus.k, a.fit.torus.j) == (3, 1) and a.fit.explained_share < 0.90
    assert a.classification.kind == "unsettled" and not a.settling.settled
    text = format_summary(res)
    assert f"a recorded window of at least {2 * a.settling.window:.3g} s" in text
    assert f"{2 * a.settling.window:.3g}" == "1.18"  # docs/scenes.md; the 1.5 s record of the test above holds it
    assert "class: unsettled" in text and "period" not in text[text.index("class:"):].split("\n")[0]
