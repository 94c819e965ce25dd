"""Every command's report.html in a real browser (Debian's Chromium, the network refused: tests/e2e/conftest.py).

The commands run once, small (module fixture ``reports``, about a minute on a loaded 2-core machine):
``campbell seed-rig --speeds 0:12000:61`` (the size the issue measures), ``harmonic seed-rig`` at 31 speeds, ``run
paper-rub`` over 0.6 s (0.2 s recorded), ``run runup-rub`` to 0.6 x its speeds in 3 s, ``map paper-rub`` over 3
outer speeds (1 s each, serial), ``continue paper-rub`` from 45 to 30 µm at 10 harmonics without stability.
Screenshots go to e2e-screenshots/.
"""

from __future__ import annotations

import csv
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from rotorred.plots.interactive.report import external_sources

SHORT_SCENE = ["--set", "solver.duration=0.6", "--set", "solver.record_start=0.4", "--set",
               "output.plot_window=[0.4, 0.5]"]
COMMANDS = {
    "campbell": ["campbell", "seed-rig", "--speeds", "0:12000:61"],
    "harmonic": ["harmonic", "seed-rig", "--speeds", "0:12000:31"],
    "run": ["run", "paper-rub", *SHORT_SCENE],
    "runup": ["run", "runup-rub", "--set", "runup.duration=3.0", "--set", "runup.to=0.6", "--set",
              "runup.orbits_hz=[]"],
    "map": ["map", "paper-rub", "--vary", "speeds.outer=80:100:3", "--limit", "1", "--workers", "0",
            "--set", "solver.duration=1.0", "--set", "solver.record_start=0.6", "--set", "output.plot_window=[0.6, 0.7]"],
    "continue": ["continue", "paper-rub", "--param", "rub.clearance=45e-6:30e-6", "--harmonics", "10",
                 "--samples", "128", "--no-stability"],
}
#: the issue's cap on the Campbell report of seed-rig over 61 speeds (bytes)
CAMPBELL_CAP = 5e6


def rotorred(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    return subprocess.run([sys.executable, "-c", "import sys; from rotorred.cli import main; sys.exit(main())", *args],
                          capture_output=True, text=True, env=env, timeout=600)


@pytest.fixture(scope="module")
def reports(tmp_path_factory) -> dict[str, Path]:
    """Each command of :data:`COMMANDS` run into its own folder: name -> folder."""
    root = tmp_path_factory.mktemp("reports")
    out = {}
    for name, args in COMMANDS.items():
        done = rotorred(*args, "--out", str(root / name))
        assert done.returncode == 0, f"{name}: {done.stderr[-3000:]}"
        out[name] = root / name
    return out


def test_every_command_writes_a_self_contained_report_and_no_html_writes_none(reports, tmp_path):
    for name, folder in reports.items():
        page = (folder / "report.html").read_text(encoding="utf-8")
        assert external_sources(page) == [], name
        assert not re.search(r"""<(script|link)[^>]+(src|href)\s*=\s*["']?\s*(https?:)?//""", page.split(
            "<script>", 1)[0] + page.rsplit("</script>", 1)[-1], re.I), name
    size = (reports["campbell"] / "report.html").stat().st_size
    print(f"Campbell report of seed-rig over 61 speeds: {size / 1e6:.2f} MB")
    assert size <= CAMPBELL_CAP
    done = rotorred("campbell", "seed-rig", "--speeds", "0:12000:5", "--no-html", "--out", str(tmp_path / "c"))
    assert done.returncode == 0 and not (tmp_path / "c" / "report.html").exists()
    assert (tmp_path / "c" / "campbell.csv").exists()


def _open(tab, folder: Path):
    """Open ``folder``'s report and wait until every figure is drawn."""
    tab.page.goto((folder / "report.html").as_uri())
    tab.page.wait_for_function("document.querySelectorAll('.fig').length > 0 && document.querySelectorAll('.fig')"
                               ".length === document.querySelectorAll('.fig.js-plotly-plot').length", timeout=60000)
    tab.page.wait_for_timeout(300)


def test_each_report_loads_without_console_errors_or_requests(reports, tab):
    for name, folder in reports.items():
        _open(tab, folder)
        tab.screenshot(f"report-{name}")
        assert tab.errors == [] and tab.refused == [], name
        drawn = tab.page.evaluate("[...document.querySelectorAll('.fig')].map((d) => d.data.length)")
        assert drawn[0] > 0, (name, drawn)


#: the centre (viewport px) of the rendered marker ``point`` of trace ``trace`` of the figure ``name``
_MARKER = """([name, trace, point]) => {
  const gd = RR.div(name);
  gd.scrollIntoView({block: 'center'});
  const p = gd.querySelectorAll('.scatterlayer .trace')[trace].querySelectorAll('path.point')[point];
  const r = p.getBoundingClientRect();
  return [r.left + r.width / 2, r.top + r.height / 2];
}"""


def _campbell_rows(folder: Path) -> list[dict]:
    with open(folder / "campbell.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_the_campbell_view_shows_a_point_a_row_and_its_hover_and_click(reports, tab):
    """Points drawn = rows of campbell.csv; a mouse hover on mode 10 at a speed near 6000 rpm whose shape the report
    embeds shows that row's frequency and whirl; a click draws that mode's shape at that speed."""
    folder = reports["campbell"]
    rows = _campbell_rows(folder)
    _open(tab, folder)
    counts = tab.page.evaluate("""() => { const gd = RR.div('campbell');
        const traces = gd.querySelectorAll('.scatterlayer .trace');
        return gd.data.map((t, i) => t.meta === 'mode' ? traces[i].querySelectorAll('path.point').length : 0); }""")
    assert sum(counts) == len(rows) == 61 * len([c for c in counts if c])
    at = tab.page.evaluate("RR.data.shapes.at")
    i = min(at, key=lambda k: abs(k - 30))
    rpm = f"{200 * i}"  # 0:12000:61
    row = next(r for r in rows if float(r["speed_rpm"]) == float(rpm) and r["mode"] == "10")
    x, y = tab.page.evaluate(_MARKER, ["campbell", 9, i])
    tab.page.mouse.move(x, y)
    tab.page.wait_for_selector("#rr-campbell .hoverlayer .hovertext", timeout=10000)
    text = tab.page.evaluate("""() => { const t = document.querySelector('#rr-campbell .hoverlayer .hovertext text');
        const lines = [...t.querySelectorAll('tspan.line')].map((s) => s.textContent);
        return lines.length ? lines.join('\\n') : t.textContent; }""")
    shown = float(re.search(r"([\d.]+) Hz", text).group(1))
    assert shown == pytest.approx(float(row["frequency_hz"]), rel=5e-5), text
    assert f"mode 10: {row['whirl']} whirl" in text and f"\n{rpm} rpm\n" in text, text
    tab.screenshot("report-campbell-hover")
    tab.page.mouse.click(x, y)
    tab.page.wait_for_function(f"RR.div('shape').layout.title.text.startsWith('mode 10 at {rpm} rpm: ')",
                               timeout=10000)
    tab.screenshot("report-campbell-click")
    assert tab.errors == [] and tab.refused == []


def test_clicking_a_map_point_shows_its_orbit_and_spectrum(reports, tab):
    _open(tab, reports["map"])
    trace, point, index, title = tab.page.evaluate("""() => { const gd = RR.div('classes');
        for (let t = 0; t < gd.data.length; t++) for (let p = 0; p < gd.data[t].customdata.length; p++)
          if (gd.data[t].customdata[p][0] === RR.data.points.length - 1) return [t, p, RR.data.points.length - 1,
                                                                             RR.data.points[RR.data.points.length - 1].title];
        }""")
    assert index > 0
    x, y = tab.page.evaluate(_MARKER, ["classes", trace, point])
    tab.page.mouse.click(x, y)
    tab.page.wait_for_function(f"RR.div('orbit').layout.title.text.endsWith({title!r})", timeout=10000)
    orbit = tab.page.evaluate("[RR.div('orbit').data.map((t) => t.x.length), RR.data.samples, "
                              "RR.data.points[%d].px.length, RR.div('spectrum').data[0].x.length, "
                              "RR.data.points[%d].f.length]" % (index, index))
    lengths, samples, n_poincare, bars, lines = orbit
    assert lengths[0] >= samples + 1 and lengths[1] == n_poincare and bars == lines > 0
    tab.screenshot("report-map-click")
    assert tab.errors == [] and tab.refused == []
