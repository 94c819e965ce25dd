"""``rotorred run [SCENE] --out DIR``: run a scene and write its figures, data and summary.

With no scene it runs the built-in ``paper-rub`` (Xu et al. 2016: rub at node 18, 70/90 Hz).
Writes ``waveforms.png``, ``spectra_node<N>.png``, ``orbits.png``, ``result.npz``,
``result.mat``, ``timeseries.csv``, ``spectra.csv``, ``lines.csv`` and ``summary.txt``
(as the scene's ``[output]`` asks), and ``scene.toml``, the resolved scene, which ``rotorred run DIR/scene.toml``
runs again to the same bits (:mod:`rotorred.scenes.resolved`; version, command line and date on top of the summary
and in the NPZ and .mat: :mod:`rotorred.provenance`), and prints the summary. A scene with ``[runup]`` (the
built-in ``runup``, ``runup-rub``, ``coastdown-rub``) writes ``runup_amplitude.png``,
``order_tracks.png``, ``waterfall.png``, ``runup_orbits.png``, their CSV files
(``runup_amplitude.csv``, ``order_tracks.csv``, ``rub_intervals.csv``, ``critical_speeds.csv``),
the record and ``summary.txt``. ``--set solver.method=harmonic-balance`` writes the steady rub response by harmonic
balance as the record, periodic or, at incommensurate speeds, on a torus (:mod:`rotorred.scenes.torus_response`). Both
write ``report.html``, the interactive figures (``--no-html`` leaves it out:
:mod:`rotorred.cli.report`).

Everything is checked before computing (the scene, ``--out``, the size estimate of
:mod:`rotorred.scenes.budget`); the files are staged and moved into ``--out`` when complete
(:class:`rotorred.writers.OutputFolder`). A diverged transient writes its partial record marked
``INCOMPLETE`` and exits with status 3.
"""

from __future__ import annotations

import contextlib
import time

from rotorred import checks, progress, writers
from rotorred.cli.feedback import error, report
from rotorred.cli.options import add_settings, out_dir, provenance
from rotorred.cli.report import REPORT, add_html_option, stage_report

DEFAULT_SCENE = "paper-rub"


def warn(texts) -> None:
    """Say each warning (an estimate's, :attr:`rotorred.Estimate.warnings`) before computing."""
    import logging

    for text in texts:
        logging.getLogger(__name__).warning(text)


def add_parser(subparsers):
    from rotorred import builtin_scenes  # light: the scene schema is imported when a scene is read
    p = subparsers.add_parser(
        "run", help="run a scene (default paper-rub): figures, data (NPZ, CSV, .mat) and a summary",
        description="Run a scene file or built-in scene and write the paper's figures (time waveforms, spectra, "
                    "orbits; rub against normal), the data as NPZ, CSV and MATLAB .mat, and a summary (peak "
                    "amplitudes, contact fraction, impacts, labelled spectral lines in the form of the paper's "
                    "Table 1). With --set solver.method=harmonic-balance a rub scene's steady response is solved by "
                    "harmonic balance: periodic at commensurate speeds, on a torus at incommensurate ones (its bases, "
                    "truncation and lines in the summary). Scene keys: docs/scenes.md.")
    p.add_argument("scene", nargs="?", default=DEFAULT_SCENE, metavar="SCENE",
                   help=f"built-in scene ({', '.join(builtin_scenes())}) or scene TOML file (default {DEFAULT_SCENE})")
    p.add_argument("--out", default=None, help="output directory (default ./rotorred-<scene name>); locked while "
                                               "a run writes it, its files replaced as a whole when the run ends")
    add_settings(p, "override (before validation)")
    p.add_argument("--no-normal", action="store_true", help="do not compute the scene without rub for comparison")
    p.add_argument("--force", action="store_true",
                   help="go on with a run beyond the size limits (steps, memory, model size; see the message)")
    add_html_option(p)
    return p


def run(args) -> int:
    """Check everything, then compute into a locked, staged ``--out`` (exit statuses: :mod:`rotorred.cli`)."""
    from rotorred import load_scene, scene_estimate, scene_toml

    t0 = time.perf_counter()
    out = out_dir("--out", args.out) if args.out is not None else None  # refused before the scene is read
    settings = _settings(args.set)
    if args.no_normal:  # a key of the scene, so that its scene.toml runs without the normal comparison too
        settings["output.compare_normal"] = False
    scene = load_scene(args.scene, settings)
    if out is None:
        out = out_dir("--out", f"rotorred-{scene.name}")
    warn(scene_estimate(scene).check(force=args.force).warnings)
    record = provenance(args, "scene", scene_toml(scene))
    with writers.OutputFolder(out) as folder, _figure_pool(scene) as pool:  # the pool stops before the folder cleans up
        progress.stage("running %s into %s", scene.name, out)  # the first line, once the input is checked and --out locked
        status = _compute_and_write(scene, args, folder, out, pool, record)
    report(f"wall time {time.perf_counter() - t0:.2f} s")
    return status


def _figure_pool(scene):
    """The :class:`rotorred.plots.pool.FigurePool` of ``scene``: its workers draw the figures while the data files are
    written, their fork server importing matplotlib and preparing the figures' frames while the scene is solved; for
    a scene without figures or a run-up (drawn here), an empty pool."""
    from rotorred import FigurePool  # here, not at the top: every command imports this module (its parser)

    if scene.output.plots and scene.runup is None:
        from rotorred import scene_frames  # light: matplotlib is imported when a figure is drawn

        return FigurePool(frames=scene_frames(scene))
    return FigurePool(workers=0)


def _settings(items: list[str]) -> dict:
    """The ``--set KEY=VALUE`` overrides (one value each)."""
    from rotorred import parse_setting

    settings = {}
    for item in items:
        key, values = parse_setting(item)
        if len(values) != 1:
            checks.fail("--set", item, "must have one value in `rotorred run` (use `rotorred sweep --vary KEY=v1,v2,...` for several)")
        settings[key] = values[0]
    return settings


def _compute_and_write(scene, args, folder, out, pool, record) -> int:
    """Run the scene, stage its files and commit them, with the provenance ``record``; a diverged run commits its
    partial record (exit 3)."""
    from rotorred.cli import EXIT_DIVERGED

    if scene.runup is not None:
        return _runup_and_write(scene, args, folder, out, record)
    from rotorred import SceneDiverged, format_summary, run_to_tolerance, submit_figures, write_outputs

    drawing = []  # the record's figures: drawn while the line fit, settling and class are computed

    def on_record(partial):
        drawing.extend(submit_figures(partial, folder.staging, pool, "record"))
    try:
        result = run_to_tolerance(scene, progress=None, on_record=on_record)
    except SceneDiverged as exc:
        write_outputs(exc.partial, folder.staging, shown=out, pool=pool, provenance=record)
        stage_report(args, folder, exc.partial)
        files = folder.commit(incomplete=str(exc))
        report(format_summary(exc.partial, files))
        error(f"{exc}; partial results written to {out} (marked {writers.INCOMPLETE})")
        return EXIT_DIVERGED
    files = write_outputs(result, folder.staging, shown=out, pool=pool, drawing=drawing, provenance=record)
    files += [out / REPORT for _ in stage_report(args, folder, result)]
    folder.commit()
    report(format_summary(result, files))
    return 0


def _runup_and_write(scene, args, folder, out, record) -> int:
    """A run-up scene: the transient through its speed profile, its figures, data and summary; a diverged run
    writes what it computed up to then, analysed, marked INCOMPLETE (exit 3), and so does one that SIGINT or SIGTERM
    ended as it stepped (exit 130 or 143; its files written with the signals held back)."""
    from rotorred.cli import EXIT_DIVERGED, interrupted_status, interrupts
    from rotorred import format_runup_summary, run_runup, write_runup_outputs

    result = run_runup(scene, progress=None, interrupts=interrupts())
    with writers.signals_held() if result.interrupt else contextlib.nullcontext():
        write_runup_outputs(result, folder.staging, shown=out, provenance=record)
        stage_report(args, folder, result)
        committed = folder.commit(incomplete=result.incomplete)
    report(format_runup_summary(result, committed))
    if result.incomplete:
        error(f"{result.incomplete}; partial results written to {out} (marked {writers.INCOMPLETE})")
        return interrupted_status(result.interrupt) if result.interrupt else EXIT_DIVERGED
    return 0
