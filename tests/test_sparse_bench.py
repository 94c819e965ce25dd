"""validation/bench_sparse.py's CSV (docs/data/bench_sparse.csv): written and read back, drawn, and the tables of
docs/performance.md equal to the ones it prints from the committed CSV (every number of the page's sparse-models
table is the script's)."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure
from validation_scripts import load_validation

ROOT = Path(__file__).resolve().parents[1]
CSV = ROOT / "docs" / "data" / "bench_sparse.csv"


def test_csv_round_trip_and_figure(tmp_path):
    """The unrefined rig, both forms (no rub run): the CSV read back gives the table's numbers to its 4 digits, and
    the figure draws a curve per task and form."""
    bs = load_validation("bench_sparse")
    rows = [bs.worker(1, as_sparse, False) for as_sparse in (True, False)]
    checks = [{"check": "campbell61", "n_modes": 10, "n_critical": 16, "critical_rpm": [714.9], "seconds": 1.5,
               "cpu_s": 1.2, "rss_mb": 400.0}]
    paths = bs.write_csv(rows, checks, tmp_path / "b.csv", "--test")
    back, header = bs.read_csv(paths[0])
    assert header[0] == "python validation/bench_sparse.py --test" and "commit" in header[2]
    assert [(r["refine"], r["sparse"], r["n_dof"]) for r in back] == [(1, True, 80), (1, False, 80)]
    for r, b in zip(rows, back):
        assert all(abs(b[t] - r[t]) <= 5e-4 * r[t] for t in bs.TASKS[:4]) and b["rub_us_step"] is None
    assert bs.read_checks(paths[1])["campbell61"]["n_critical"] == "16"
    fig = Figure()
    bs.draw(back, fig.add_subplot())
    assert len(fig.axes[0].lines) == 8


def test_performance_page_quotes_the_committed_csv():
    """docs/performance.md's sparse table, growth exponents and checks are the Markdown bench_sparse.py makes from
    docs/data/bench_sparse.csv and its _checks.csv, verbatim."""
    bs = load_validation("bench_sparse")
    page = (ROOT / "docs" / "performance.md").read_text(encoding="utf-8")
    rows, header = bs.read_csv(CSV)
    assert len(rows) >= 8 and {r["n_dof"] for r in rows} >= {80, 1160, 9224}
    assert bs.markdown_table(rows) in page
    assert bs.markdown_checks(bs.read_checks(CSV.with_name("bench_sparse_checks.csv"))) in page
    assert f"commit `{header[2].split(',')[0].split()[-1]}`" in page  # the commit measured
