"""``rotorred continue SCENE --param KEY=START:STOP --out DIR``: a branch of the rub response by harmonic balance.

Follows the periodic response of the scene (commensurate speeds, rub plates) by pseudo-arclength continuation in
``rub.clearance`` (m), a spool speed ``speeds.<spool>`` (Hz, the speed ratio kept) or a number of the plate (``rub.k_n``
its supports' stiffness in N/m, ``rub.K_nr``, ``rub.mu_d`` ...: ``scenes.branch.PLATE_KEYS``), through its folds, with
each point's stability (Floquet multipliers of the monodromy matrix). Writes ``branch.csv`` (a row a point: the key, the
peak of each output DOF in µm, the largest multiplier, stable or not), ``branch_lines.csv`` (the amplitude of each
harmonic of f_0 at the first output DOF), ``branch.nc`` (the same, labelled, xarray/NetCDF), ``branch.png`` (peak
against the key: stable solid, unstable dashed, folds and corners marked), ``branch.txt`` and ``report.html`` (the
same, interactive; ``--no-html``: none).

With ``--torus [J,K]`` the scene's speeds are incommensurate and the response quasi-periodic: its torus of the bases
``(f_L / J, f_H / K)`` (default: the torus the start's line fit finds) is followed instead (``--orders H1,H2`` its box,
band 900 Hz; ``--lines-tol TOL`` grows the box along the branch where its largest lines change by more than TOL), in ``rub.clearance``, a plate's number or a spool's speed (``speeds.<spool>``, the other spool held), its
folds located, no stability; a speed branch that stalls near an order's 0 Hz goes on past that order, the speeds between
not traced and named in ``branch.txt`` (``--stop-at-stalls``: it ends there); ``branch.csv`` then has a row a point (the key, the bases, the 10 largest lines of the
table DOF in µm, the corrections and the point's time), ``branch_lines.csv`` every order's line at each point, and no
``report.html`` (no interactive view of a torus branch yet).

SIGINT or SIGTERM while the branch is traced or its stability computed ends it there and keeps every point traced:
the files are written with them all (those without their stability marked "unknown", the folder INCOMPLETE, the
summary saying which signal, where, how many points traced and with their stability), exit 130 or 143. The files
(of an interrupted or a complete branch) are written with the signals held back: a signal then does not cut them, and
is answered with exit 130 or 143 once they are written. Before the first point (the cold start), a signal leaves the
earlier result, as in every command.
"""

from __future__ import annotations

from rotorred import checks, progress
from rotorred.cli.feedback import error, report
from rotorred.cli.options import SCENE_UNITS, add_settings, out_dir, provenance
from rotorred.cli.report import add_html_option, stage_report


def add_parser(subparsers):
    p = subparsers.add_parser(
        "continue",
        help="follow the rub response by harmonic balance in a key (clearance, speed, plate): folds, stability",
        description="Follow a rub scene's periodic response by harmonic balance with pseudo-arclength continuation in "
                    "rub.clearance (m), speeds.<spool> (Hz, the speed ratio kept) or a plate number (rub.k_n N/m, "
                    "rub.K_nr, rub.mu_d, ...), through its folds, with each "
                    "point's stability; write the branch as CSV and NetCDF and plot it.")
    p.add_argument("scene", metavar="SCENE", help="built-in scene or scene TOML file (with rub plates)")
    p.add_argument("--param", required=True, metavar="KEY=START:STOP",
                   help=f"the key and its first and last value ({SCENE_UNITS})")
    add_settings(p, "fix")
    p.add_argument("--harmonics", type=int, default=50, help="harmonics of the base frequency f_0 (default 50)")
    p.add_argument("--samples", type=int, default=1024, help="AFT samples a period, even (default 1024)")
    p.add_argument("--tol", type=float, default=None,
                   help="relative residual of every point (default 1e-9; 1e-6 on a torus)")
    p.add_argument("--torus", nargs="?", const="found", default=None, metavar="J,K",
                   help="follow the quasi-periodic response on the torus of the bases f_L/J, f_H/K (Hz, the spools' "
                        "frequencies over integers; incommensurate speeds; without J,K: the torus the start's line "
                        "fit finds)")
    p.add_argument("--orders", default="32,80", metavar="H1,H2",
                   help="with --torus: the box of orders |k1| <= H1, |k2| <= H2 (default 32,80), lines up to 900 Hz")
    p.add_argument("--refine-folds", action="store_true",
                   help="with --torus: locate each fold by Brent's method on corrected points (default: interpolated "
                        "between the points either side of it, without a solve)")
    p.add_argument("--stop-at-stalls", action="store_true",
                   help="with --torus: a speed branch that stalls near an order's 0 Hz ends there (default: it goes on "
                        "past that order, the speeds between not traced and named in branch.txt)")
    p.add_argument("--lines-tol", type=float, default=None, metavar="TOL",
                   help="with --torus: grow the box along the branch (bounds x1.5) where its 10 largest lines change by "
                        "more than TOL (a relative change of amplitudes in m, e.g. 0.01) against the next box "
                        "(default: the --orders box throughout)")
    p.add_argument("--no-stability", action="store_true", help="skip the Floquet multipliers (the slow part)")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--force", action="store_true",
                   help="go on with a branch beyond the size limits (steps, memory, model size; see the message)")
    add_html_option(p)
    return p


def _param(text: str) -> tuple[str, float, float]:
    """KEY, START, STOP of ``--param KEY=START:STOP``."""
    key, sep, values = text.partition("=")
    parts = values.split(":")
    if not sep or len(parts) != 2:
        checks.fail("--param", text, "must be KEY=START:STOP, e.g. rub.clearance=20e-6:5e-6, speeds.outer=90:95 or "
                    "rub.k_n=1e8:1e9")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        checks.fail("--param", text, "must have numbers START and STOP")
    if not (start > 0 and stop > 0) or start == stop:
        checks.fail("--param", text, "must have START and STOP > 0 and different")
    key = key.strip()
    if key.startswith("speeds.") or key == "rub.clearance":  # the keys with a physical bound (checks.BOUNDS)
        checks.bounded("--param", text, (start, stop), "speed" if key.startswith("speeds.") else "clearance",
                       "Hz" if key.startswith("speeds.") else "m")
    return key, start, stop


def run(args) -> int:
    """Check everything, then follow the branch into ``--out`` (exit 130 or 143 when interrupted, its points kept)."""
    from rotorred.cli import interrupts as signals
    from rotorred.cli.run import _settings
    from rotorred import BranchOptions, build_model, check_key, continue_scene, load_scene, scene_toml

    out = out_dir("--out", args.out)
    key, start, stop = _param(args.param)
    if args.torus is not None:
        return _run_torus(args, out, key, start, stop)
    H = checks.integer("--harmonics", args.harmonics, ge=1)
    N = checks.integer("--samples", args.samples, ge=2 * H + 2)
    if N % 2:
        checks.fail("--samples", N, "must be even")
    tol = _tol(args, 1e-9)
    scene = load_scene(args.scene, _settings(args.set))
    check_key(scene, key, start, stop)
    options = BranchOptions(H, N, tol, not args.no_stability)
    options.estimate(scene).check(force=args.force)
    record = provenance(args, "scene", scene_toml(scene))  # with the base scene; --param in the command line
    model = build_model(scene).model
    report(f"branch of {scene.name} in {key} from {start:g} to {stop:g}: {H} harmonics, {N} samples a period")
    interrupts = signals()
    progress.stage("tracing the branch of %s in %s from %g to %g", scene.name, key, start, stop)
    with _Progress(key) as tracing:
        branch = continue_scene(scene, model, key, start, stop, options,
                                progress=tracing, interrupts=interrupts)
    return _finish(branch, out, interrupts, record, args)


def _tol(args, default: float) -> float:
    """``--tol`` checked, or ``default``."""
    value = default if args.tol is None else args.tol
    return float(checks.bounded("--tol", value, checks.positive("--tol", value), "tolerance"))


def _pair(field: str, text: str) -> tuple[int, int]:
    """Two positive integers ``A,B`` of an option."""
    parts = text.split(",")
    try:
        values = tuple(int(v) for v in parts)
    except ValueError:
        values = ()
    if len(values) != 2 or min(values) < 1:
        checks.fail(field, text, "must be two integers >= 1, A,B (e.g. 1,3)")
    return values


def _run_torus(args, out, key: str, start: float, stop: float) -> int:
    """``--torus``: check everything, then follow the torus into ``--out``."""
    from rotorred.cli import interrupts as signals
    from rotorred.cli.run import _settings
    from rotorred import TorusBranchOptions, build_model, check_torus_key, continue_torus, load_scene, scene_toml

    divisors = None if args.torus == "found" else _pair("--torus", args.torus)
    orders = _pair("--orders", args.orders)
    lines_tol = None if args.lines_tol is None else checks.number("--lines-tol", args.lines_tol, gt=0.0, lt=1.0)
    options = TorusBranchOptions(orders=orders, divisors=divisors, tol=_tol(args, TorusBranchOptions.tol),
                                 lines_tol=lines_tol, fold_refine=args.refine_folds,
                                 past_stalls=not args.stop_at_stalls)
    scene = load_scene(args.scene, _settings(args.set))
    check_torus_key(scene, key, start, stop)
    record = provenance(args, "scene", scene_toml(scene))
    model = build_model(scene).model
    report(f"torus branch of {scene.name} in {key} from {start:g} to {stop:g}: orders |k1| <= {orders[0]}, |k2| <= "
           f"{orders[1]}")
    interrupts = signals()
    progress.stage("tracing the torus branch of %s in %s from %g to %g", scene.name, key, start, stop)
    with _Progress(key) as tracing:
        branch = continue_torus(scene, model, key, start, stop, options, progress=tracing, interrupts=interrupts)
    return _finish(branch, out, interrupts, record, args)


def _finish(branch, out, interrupts, record, args) -> int:
    """Report the branch, write its files and the exit status (130 or 143 when interrupted, its points kept)."""
    from rotorred.cli import interrupted_status
    from rotorred import format_branch

    report(format_branch(branch))
    files, late = _write(branch, out, interrupts, record, args)
    for f in files:
        report(f"wrote {f}")
    if branch.interrupted:
        error(f"{branch.stopped}; every point traced is written, the folder marked INCOMPLETE")
        return interrupted_status(branch.interrupt)
    if late:  # the signal came as the complete branch was written: it was written whole first
        error(f"interrupted ({late}) as the complete branch was written; it is written whole")
        return interrupted_status(late)
    return 0


def _write(branch, out, interrupts: dict, record=None, args=None) -> tuple[list, str]:
    """Stage and commit the branch's files into ``out`` with SIGINT and SIGTERM held back (``writers.signals_held``,
    as a commit is), so that a signal does not cut them (nor leave a file half made): the points an interrupt kept,
    or a complete branch, are written whole. A signal that came meanwhile is dropped once they are committed. The
    files written, and that signal ("SIGINT", "SIGTERM"; "" if none)."""
    from rotorred import TorusBranch, write_branch, writers

    folder, files, late = writers.OutputFolder(out), [], ""
    try:
        with writers.signals_held(), folder:
            write_branch(branch, folder, record)
            if args is not None and not isinstance(branch, TorusBranch):  # no interactive view of a torus branch
                stage_report(args, folder, branch)
            files = folder.commit(incomplete=branch.stopped if branch.interrupted else None)
    except tuple(interrupts) as exc:
        if not folder.committed:
            raise
        late = next(name for kind, name in interrupts.items() if isinstance(exc, kind))
    return files, late


class _Progress:
    """The progress of :func:`rotorred.scenes.branch.continue_scene` (its ``progress(points, value)``): a bar of the
    points traced with the key's value, then a stage line and a bar of the points whose stability is computed."""

    def __init__(self, key: str):
        self.key, self.points, self.bar, self.stability = key, 0, progress.bar(None, "tracing", "point"), False

    def __call__(self, points: int, value) -> None:
        if value is not None:
            self.points = points
            self.bar.set_postfix_str(f"{self.key} = {value:.6g}", refresh=False)
            self.bar.update(points - self.bar.n)
            return
        if not self.stability:
            self.stability = True
            self.bar.close()
            progress.stage("stability of %d points: Floquet multipliers", self.points)
            self.bar = progress.bar(self.points, "stability", "point")
        self.bar.update(points - self.bar.n)

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.bar.close()
