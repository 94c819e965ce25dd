"""The interactive views (rotorred.plots.interactive): figure contents, hover data, report.html, Result.view and
_repr_html_. The browser checks (hover, click, console errors) are in tests/e2e/test_reports.py."""

from __future__ import annotations

import base64
import json
import math
import re

import numpy as np
import pytest

import rotorred as rr
from rotorred.plots.interactive import campbell as campbell_view
from rotorred.plots.interactive import figures, report_of, view
from rotorred.plots.interactive.report import DIGITS, external_sources, to_json
from rotorred.results import Result


@pytest.fixture(scope="module")
def rotor():
    return rr.load_rotor("seed-rig")


@pytest.fixture(scope="module")
def diagram(rotor):
    """Seed rig from 3000 to 12000 rpm (7 speeds): distinct modes at the first speed."""
    return rr.campbell(rotor, rr.Operating.line(np.linspace(3000, 12000, 7), unit="rpm"))


def _mode_traces(fig: dict) -> list[dict]:
    return [t for t in fig["data"] if t.get("meta") == "mode"]


def test_the_campbell_view_has_a_trace_a_mode_and_a_point_a_row_of_campbell_csv(diagram, tmp_path):
    fig = dict(figures(diagram))["campbell"]
    modes = _mode_traces(fig)
    rows = len(diagram.to_csv(tmp_path / "c.csv").read_text().splitlines()) - 1
    assert len(modes) == diagram.n_modes and sum(len(t["x"]) for t in modes) == rows == 7 * diagram.n_modes
    critical = [t for t in fig["data"] if t.get("meta") == "critical"]
    assert len(critical) == 1 and len(critical[0]["x"]) == len(diagram.critical_speeds) > 0
    assert len([t for t in fig["data"] if t.get("meta") == "excitation"]) == len(diagram.excitation_lines)


def test_a_campbell_points_hover_carries_its_speed_frequency_mode_whirl_log_dec_and_damping(diagram):
    modes = _mode_traces(campbell_view.campbell_figure(diagram))
    j, i = 2, 4
    t = modes[j]
    mode, whirl, log_dec, zeta, unstable = t["customdata"][i]
    assert (t["x"][i], t["y"][i]) == (diagram.speeds_rpm[i], diagram.frequencies_hz[i, j])
    assert (mode, whirl, unstable) == (j + 1, diagram.whirl[i, j], "")
    assert (log_dec, zeta) == (diagram.log_dec[i, j], diagram.damping_ratio[i, j])
    for field in ("%{x", "%{y", "customdata[0]", "customdata[1]", "customdata[2]", "customdata[3]"):
        assert field in t["hovertemplate"]


def test_unstable_points_are_marked_and_the_operating_point_drawn(diagram):
    unstable = np.zeros_like(diagram.unstable)
    unstable[2, 0] = True
    marked = campbell_view._mode_trace(type("D", (), {**{k: getattr(diagram, k) for k in (
        "whirl", "log_dec", "damping_ratio", "rigid_modes", "speeds_rpm", "frequencies_hz")}, "unstable": unstable})(), 0)
    assert marked["marker"]["symbol"][2] == "x" and marked["customdata"][2][4] == "UNSTABLE"
    assert marked["marker"]["symbol"].count("x") == 1
    fig = campbell_view.campbell_figure(diagram, operating_speed=500.0)
    assert fig["layout"]["shapes"][0]["x0"] == pytest.approx(500.0 * 30 / math.pi)


def test_the_embedded_mode_shapes_are_those_of_rr_mode_shapes(diagram, rotor):
    """At the first speed (3000 rpm, modes distinct) each Campbell column's embedded shape is mode_shapes' mode of
    the same number: the forward and backward radii |X +- iY| of every node (invariant to the phase, which a circular
    orbit leaves free) to the int8 quantum (each part within 1/254 of the largest orbit)."""
    data = campbell_view.mode_shape_data(diagram, rotor)
    q = np.frombuffer(base64.b64decode(data["q"]), np.int8).reshape(data["shape"]) / data["quantum"]
    assert data["at"][0] == 0 and data["at"][-1] == 6 and q.shape[:2] == (len(data["at"]), diagram.n_modes)
    point = rr.Operating.point({"inner": 3000.0, "outer": 3000.0 * diagram.speed_ratios["outer"]}, unit="rpm")
    ms = rr.mode_shapes(rotor, point, n_modes=diagram.n_modes)
    np.testing.assert_allclose(ms.frequencies, diagram.frequencies[0], rtol=1e-9)
    X, Y = q[0, ..., 0] + 1j * q[0, ..., 1], q[0, ..., 2] + 1j * q[0, ..., 3]
    for sign in (1j, -1j):
        error = np.abs(np.abs(X + sign * Y) - np.abs(ms.X + sign * ms.Y))
        assert np.max(error) <= 2 * math.sqrt(2) * 0.5 / data["quantum"]
    assert list(data["nodes"]) == list(ms.nodes)


def test_a_report_embeds_plotly_once_fetches_nothing_and_parses(diagram, rotor, tmp_path):
    path = report_of(diagram, model=rotor).write(tmp_path / "report.html")
    page = path.read_text(encoding="utf-8")
    assert external_sources(page) == [] and "https://" in page  # (plotly.js's text: a link, not a source)
    assert page.count("<script") == 3 and page.count("Plotly.newPlot = ") <= 1
    doc = json.loads(re.search(r'<script type="application/json" id="rr-data">(.*?)</script>', page, re.S)
                     .group(1).replace("<\\/", "</"))
    assert [f["name"] for f in doc["figures"]] == ["campbell", "shape"] and doc["data"]["shapes"]["q"]
    assert "&lt;" not in page[:200] and "<title>Campbell diagram - seed-rig</title>" in page


def test_external_sources_finds_what_a_browser_would_fetch():
    page = ('<script src="https://cdn.plot.ly/p.js"></script><script>var a = "<script src=http://x>";</script>'
            '<link rel="stylesheet" href="//fonts.x/css"><style>@import "http://y.css"; b {background: url(a.png)}'
            '</style><img src="data:image/png;base64,AA">')
    assert external_sources(page) == ["https://cdn.plot.ly/p.js", "//fonts.x/css", "http://y.css", "a.png"]


def test_to_json_is_compact_and_writes_nan_as_null():
    text = to_json({"a": np.array([1 / 3, np.nan, np.inf]), "b": (1, True, None, "µ</")})
    assert json.loads(text) == {"a": [float(f"{1 / 3:.{DIGITS}g}"), None, None], "b": [1, True, None, "µ</"]}


def test_view_returns_a_plotly_figure_and_refuses_an_unknown_kind(diagram):
    import plotly.graph_objects as go

    fig = diagram.view(operating_speed=600.0)
    assert isinstance(fig, go.Figure) and len(fig.data) == len(campbell_view.campbell_figure(diagram)["data"])
    with pytest.raises(rr.InputError, match="kind"):
        view(diagram, kind="nothing")


class _Plain(Result):
    def summary(self):
        return ["a < b & c", "second"]


def test_repr_html_is_the_escaped_summary_and_a_type_without_a_view_is_refused():
    text = _Plain()._repr_html_()
    assert "a &lt; b &amp; c" in text and "<strong>_Plain</strong>" in text and "second" in text
    with pytest.raises(rr.InputError, match="has no interactive view.*CampbellResult"):
        _Plain().view()


def test_the_response_view_has_bode_and_polar_traces_of_every_output_and_spool(rotor):
    res = rr.unbalance_response(rotor, rr.Operating.line(np.linspace(1000, 9000, 9), unit="rpm"),
                                [rr.Unbalance(13, 1e-5), rr.Unbalance(14, 2e-5)], [(13, "x"), (14, "y")])
    named = dict(figures(res))
    assert len(res.excited_spools) == 2
    assert len(named["bode"]["data"]) == 2 * 2 * 2 and len(named["polar"]["data"]) == 2 * 2
    amp = named["bode"]["data"][0]
    np.testing.assert_allclose(amp["y"], 1e6 * res.amplitude((13, "x"), res.excited_spools[0]))
    assert amp["customdata"][3][1] == pytest.approx(amp["y"][3]) and "phase" in amp["hovertemplate"]


def _branch(critical) -> rr.SceneBranch:
    p = len(critical)
    values = np.linspace(40e-6, 20e-6, p)
    return rr.SceneBranch("paper-rub", "rub.clearance", "m", values, np.full(p, 10.0), ((14, "y"), (18, "x")),
                          np.column_stack([np.linspace(1, 2, p), np.linspace(3, 4, p)]) * 1e-6, np.zeros((p, 3)),
                          np.zeros((p, 2)), np.asarray(critical, complex), ((30e-6, True),), "reached the end",
                          np.ones(p, int), 0.0, 0.0, 0.0, end="reached")


def test_the_branch_view_draws_stable_solid_unstable_dashed_and_marks_folds_and_bifurcations():
    branch = _branch([0.5, 0.6, 1.5, 1.4, 0.5, np.nan])
    fig = dict(figures(branch))["branch"]
    lines = [t for t in fig["data"] if t["mode"] == "lines"]
    assert [(t["line"]["dash"], len(t["x"])) for t in lines[:4]] == [("solid", 3), ("dash", 3), ("solid", 2),
                                                                     ("dot", 1)]
    assert len(lines) == 2 * 4
    folds, bifs = (next(t for t in fig["data"] if t.get("name") == n) for n in ("folds", "bifurcations"))
    assert folds["x"] == [30.0] and "fold at rub.clearance = 30 µm" in folds["text"][0]
    assert len(bifs["x"]) == len(branch.bifurcations) == 2 and "fold between" in bifs["text"][0]


@pytest.fixture(scope="module")
def small_map():
    """A synthetic 3-point map (up sweep of speeds.outer) through the map store's own dataset builder."""
    from rotorred.maps.point import PointResult
    from rotorred.maps.store import to_dataset

    spec = rr.MapSpec("paper-rub", (rr.Axis("speeds.outer", (80.0, 90.0, 100.0)),))
    points = {}
    for i, kind in enumerate(("periodic", "chaotic", "period-k")):
        points[("up", (i,))] = PointResult(
            status="ok", kind=kind, subharmonic=2 if kind == "period-k" else 1, settling_time=0.5 + i,
            explained_share=0.99 - 0.1 * i, line_frequency=np.array([70.0, 90.0]),
            line_amplitude=np.array([2e-6, 1e-6]), line_phase=np.array([0.1, 0.2]), line_label=("f_L", "f_H"),
            poincare_x=np.linspace(-1e-6, 1e-6, 150 + i), poincare_velocity=np.linspace(0, 1e-3, 150 + i),
            peak_orbit=np.ones(3) * 1e-6, contact_fraction=0.1 * i, n_impacts=3 * i)
    dataset = to_dataset(spec, points, (13, 14, 18), {"scene": "paper-rub", "table_dof": "14:y"})
    return rr.MapRun(spec, dataset, (), 3, 0, 0, None, 1.0)


def test_the_map_view_has_a_marker_a_point_with_its_class_settling_share_and_contact(small_map):
    named = dict(figures(small_map))
    classes = named["classes"]["data"]
    assert [t["name"] for t in classes] == ["periodic", "chaotic", "period-2"]
    row = classes[1]["customdata"][0]
    assert row[:6] == [1, "chaotic", "settled after 1.5 s", "0.890", "0.1", 3] and "90" in row[6]
    assert "class %{customdata[1]}" in classes[0]["hovertemplate"] and "contact" in classes[0]["hovertemplate"]
    bif = named["bifurcation"]["data"]
    assert len(bif) == 3 and all(len(t["y"]) == 100 for t in bif) and [t["meta"] for t in bif] == [0, 1, 2]


def test_the_map_report_embeds_each_points_lines_and_poincare_samples(small_map):
    rep = report_of(small_map)
    pts = rep.data["points"]
    assert len(pts) == 3 and list(pts[2]["l"]) == ["f_L", "f_H"]
    np.testing.assert_allclose(pts[1]["a"], [2e-6, 1e-6])
    assert len(pts[2]["px"]) == 152 and [p.name for p in rep.panels] == ["classes", "bifurcation", "orbit",
                                                                         "spectrum"]


def test_the_report_of_a_202_point_map_at_the_stores_limits_is_at_most_15_mb(tmp_path):
    """The README's map (speeds.outer 60:110:101, up and down: 202 points), every point at the most the map store
    keeps (N_LINES lines, N_SAMPLES Poincare samples): the report is at most 15 MB."""
    from rotorred.maps.point import N_LINES, N_SAMPLES, PointResult
    from rotorred.maps.store import to_dataset

    rng = np.random.default_rng(0)
    spec = rr.MapSpec("paper-rub", (rr.Axis("speeds.outer", tuple(np.linspace(60.0, 110.0, 101))),), direction="both")
    points = {(d, (i,)): PointResult(
        status="ok", kind="chaotic", settling_time=rng.random(), explained_share=rng.random(),
        line_frequency=rng.random(N_LINES) * 900, line_amplitude=rng.random(N_LINES) * 1e-5,
        line_phase=rng.random(N_LINES) * 6, line_label=tuple(f"{k}f_H-{k + 1}f_L" for k in range(N_LINES)),
        poincare_x=rng.random(N_SAMPLES) * 1e-5, poincare_velocity=rng.random(N_SAMPLES) * 1e-2,
        peak_orbit=rng.random(3) * 1e-5, contact_fraction=rng.random(), n_impacts=int(rng.integers(100)))
        for d in ("up", "down") for i in range(101)}
    run = rr.MapRun(spec, to_dataset(spec, points, (13, 14, 18), {"scene": "paper-rub", "table_dof": "14:y"}),
                    (), 202, 0, 0, None, 1.0)
    size = report_of(run).write(tmp_path / "report.html").stat().st_size
    print(f"report of a 202-point map at the store's limits: {size / 1e6:.2f} MB")
    assert size <= 15e6


def test_a_full_disk_while_writing_a_report_is_exit_4_naming_report_html(tmp_path):
    """Under a file-size limit of 1 MB (below plotly.js, above every other file of the command), ``rotorred campbell``
    exits 4 with one line naming --out's report.html and the limit; nothing of the result is kept (the folder, new,
    is removed)."""
    import subprocess
    import sys

    pytest.importorskip("resource", reason="RLIMIT_FSIZE needs POSIX")
    out = tmp_path / "out"
    code = ("import resource, sys\nfrom rotorred.cli import main\n"
            "resource.setrlimit(resource.RLIMIT_FSIZE, (1_000_000, resource.RLIM_INFINITY))\n"
            f"sys.exit(main(['campbell', 'seed-rig', '--speeds', '0:6000:5', '--out', {str(out)!r}]))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    errors = [line for line in done.stderr.splitlines() if ": error: " in line]
    assert done.returncode == 4 and len(errors) == 1, done.stderr[-2000:]
    assert f"could not write {str(out / 'report.html')!r}: the file would exceed the file-size limit" in errors[0]
    assert not out.exists() and "Traceback" not in done.stderr
