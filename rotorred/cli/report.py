"""``report.html`` of a command and its ``--no-html``: one option, one way to stage the report.

The report's content comes from the public API (:func:`rotorred.write_report`, :func:`rotorred.report_of`): a
self-contained page of interactive figures that opens offline (:mod:`rotorred.plots.interactive.report`).
"""

from __future__ import annotations

from pathlib import Path

#: the report's file name in every output folder
REPORT = "report.html"


def add_html_option(parser) -> None:
    """``--no-html``: do not write ``report.html``."""
    parser.add_argument("--no-html", action="store_true",
                        help=f"do not write {REPORT} (the interactive figures: one self-contained page that opens "
                             "offline in a browser)")


def stage_report(args, folder, result, **options) -> list[Path]:
    """Stage ``report.html`` of ``result`` into the :class:`rotorred.writers.OutputFolder` ``folder`` (committed with
    the other files), unless ``--no-html``; the files staged (names in the folder).

    Parameters
    ----------
    args : argparse.Namespace
        The command's options (``no_html``).
    folder : OutputFolder
    result : Result
        A result with an interactive view (:func:`rotorred.report_of`).
    **options
        The report's options (a Campbell diagram's ``model`` and ``operating_speed``).
    """
    if args.no_html:
        return []
    from rotorred import write_report

    write_report(result, folder.staged(Path(REPORT)), **options)
    return [folder.folder / REPORT]


def write_report_to(args, out: Path, result, **options) -> list[Path]:
    """Write ``report.html`` of ``result`` into the folder ``out`` atomically (a command whose files another function
    committed, ``map``), unless ``--no-html``; the files written."""
    if args.no_html:
        return []
    from rotorred import write_report

    return [write_report(result, Path(out) / REPORT, **options)]
