"""``rotorred campbell ROTOR --speeds START:STOP:COUNT --out DIR``: Campbell diagram and critical speeds.

Writes ``campbell.csv``, ``campbell.png``, ``critical_speeds.csv`` (with the API 684 / 617 amplification factors and
separation margins, :mod:`rotorred.linear.margins`), ``campbell.txt`` (what it prints, under the
rotorred version, command line and date), ``rotor.toml`` (the rotor as read, a rotor file that gives it again) and
``report.html`` (the interactive diagram: hover a point for its mode, whirl and damping, click it for its mode shape;
``--no-html`` leaves it out: :mod:`rotorred.cli.report`).
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from rotorred import checks, writers
from rotorred.cli.feedback import report
from rotorred.cli.report import add_html_option, stage_report
from rotorred.cli.options import (grid, number_list, options_named, out_dir, provenance, ratio_number,
                                  speed_line, spool_ratios, stage_summary)


def parse_speeds(text: str) -> np.ndarray:
    """``"0:12000:61"``, ``"0,1000,2500"`` or ``"3000"`` (rpm, >= 0, increasing) -> speeds (rpm)."""
    single = ":" not in text and "," not in text  # one speed; a range or a list holds at least two
    speeds = grid("--speeds", text, "rpm", min_count=1 if single else 2, ge=0.0, increasing=True)
    return checks.bounded("--speeds", text, speeds, "speed")


def parse_ratio(items: list[str]):
    """``["1.2857"]`` (two spools) -> 1.2857; ``["outer=1.2857", "mid=0.9"]`` -> {spool: ratio}; [] -> None."""
    if not items:
        return None
    if len(items) == 1 and "=" not in items[0]:
        ratio = checks.number("--ratio", ratio_number("--ratio", items[0]), ge=0.0)
        return float(checks.bounded("--ratio", items[0], ratio, "ratio"))
    return {spool: float(checks.bounded(f"--ratio {spool}", r, checks.number(f"--ratio {spool}", r, ge=0.0), "ratio"))
            for spool, r in spool_ratios("--ratio", items).items()}


def ratios_to_reference(ratio, rotor, reference: str | None) -> dict[str, float] | None:
    """``--ratio`` as {spool: speed ratio to the reference spool}: a bare number R (two spools) is the speed of
    the second spool over that of the first (``rotor.spools`` order), whichever is the reference."""
    if ratio is None or isinstance(ratio, dict):
        return ratio
    names = [s.name for s in rotor.spools]
    if len(names) != 2:
        checks.fail("--ratio", ratio, f"must be SPOOL=R for rotor {rotor.name!r} with {len(names)} spool(s) {names}: a "
                    "bare number is the speed of the second spool over that of the first, for two spools")
    first, second = names
    if reference in (None, first):
        return {second: ratio}
    if ratio <= 0:
        checks.fail("--ratio", ratio, f"must be > 0 with --reference {second}: {first} then turns at 1/R times "
                    f"{second}")
    return {first: 1.0 / ratio}


def parse_harmonics(text: str) -> tuple[float, ...]:
    """``"1,2"`` -> (1.0, 2.0); each > 0 and within :data:`rotorred.checks.BOUNDS` ``["harmonic"]``."""
    harmonics = number_list("--harmonics", text, gt=0.0)
    checks.bounded("--harmonics", text, harmonics, "harmonic")
    return harmonics


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "campbell", help="Campbell diagram and critical speeds",
        description="Whirl frequencies against the speed of a reference spool (other spools at a fixed speed "
                    "ratio), forward/backward whirl, modes tracked by MAC, and the critical speeds where a "
                    "whirl curve crosses an excitation line h x (spool speed). Writes campbell.csv and "
                    "campbell.png and critical_speeds.csv (excitation, mode, whirl, damping, margin to the "
                    "operating point, and the API 684 amplification factor and API 617 separation margin from "
                    "--operating-range) to --out and prints the critical speeds. Modes are numbered from 1.")
    p.add_argument("rotor", metavar="ROTOR", help="preset name (e.g. seed-rig) or rotor TOML file")
    p.add_argument("--speeds", required=True, metavar="START:STOP:COUNT",
                   help="reference-spool speeds in rpm, e.g. 0:12000:61, a comma list (increasing, >= 0), or one "
                        "speed (prints the whirl frequencies, directions and damping there)")
    p.add_argument("--ratio", action="append", default=[], metavar="SPOOL=R",
                   help="SPOOL turns at R times the reference spool (repeat for more spools); or, for two spools, "
                        "one number R: speed of the second spool / speed of the first (Omega_H/Omega_L for the seed "
                        "rig); default: the ratios of the nominal speeds")
    p.add_argument("--reference", default=None, metavar="SPOOL", help="spool on the x-axis (default: the first)")
    p.add_argument("--modes", type=int, default=None, metavar="N",
                   help="number of tracked modes (default: every mode below 1.25 x the highest excitation frequency, "
                        "the top speed x the highest harmonic on the fastest spool, at least 6; the printout says "
                        "how many and why)")
    p.add_argument("--harmonics", default="1", metavar="H1,H2",
                   help="multiples of each spool's speed used as excitation lines (default 1)")
    p.add_argument("--reduce", type=int, default=None, metavar="MODES",
                   help="solve the Craig-Bampton model with MODES fixed-interface modes (0: chosen to the default "
                        "target) and print its largest difference against the full model")
    p.add_argument("--operating-range", default=None, metavar="MIN:MAX",
                   help="minimum and maximum continuous speed of the reference spool (rpm) for the API 617 "
                        "separation margins of critical_speeds.csv (default: the rotor file's [defaults] "
                        "operating_range_rpm of that spool; without either, amplification factors only)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if missing)")
    p.add_argument("--force", action="store_true", help="go on with a model beyond the size limits")
    add_html_option(p)
    return p


def parse_operating_range(text: str | None) -> tuple[float, float] | None:
    """``"3000:4500"`` (rpm, 0 <= MIN <= MAX) -> (3000.0, 4500.0); None -> None."""
    if text is None:
        return None
    values = number_list("--operating-range", text.replace(":", ","), "rpm")
    if len(values) != 2 or not 0.0 <= values[0] <= values[1]:
        checks.fail("--operating-range", text, "must be MIN:MAX, the minimum and maximum continuous speed with "
                    "0 <= MIN <= MAX", "rpm")
    checks.bounded("--operating-range", text, values, "speed")
    return values


def operating_range(given: tuple[float, float] | None, rotor, reference: str):
    """The :class:`rotorred.OperatingRange` of the reference spool: ``--operating-range`` (rpm), else the rotor's
    ``[defaults]``, else None."""
    from rotorred import OperatingRange

    if given is not None:
        return OperatingRange(*(w * math.pi / 30.0 for w in given))
    default = rotor.defaults.operating_range(reference)
    return None if default is None else OperatingRange(*default)


def run(args) -> int:
    import matplotlib  # noqa: F401 - a missing matplotlib fails before any work

    from rotorred import campbell, read_rotor, save_figure, separation_margins

    out = out_dir("--out", args.out)
    speeds = parse_speeds(args.speeds)
    harmonics = parse_harmonics(args.harmonics)
    if args.modes is not None:
        checks.integer("--modes", args.modes, ge=1)
    ratio = parse_ratio(args.ratio)
    if args.reduce is not None:
        checks.integer("--reduce", args.reduce, ge=0)
    given_range = parse_operating_range(args.operating_range)
    rotor, document = read_rotor(args.rotor)
    record = provenance(args, "rotor", writers.toml_text(document))
    check_model_size(rotor, args.force)
    operating = speed_line(rotor, speeds, args.reference, ratios_to_reference(ratio, rotor, args.reference), "rpm")
    with writers.OutputFolder(out) as folder:
        with options_named({"n_modes": "--reduce"}):
            model = rotor if args.reduce is None else _reduced(rotor, args.reduce)
        with options_named({"n_modes": "--modes"}):
            result = campbell(model, operating, n_modes=args.modes, harmonics=harmonics)
        check_finite(result)
        # the full model tracks as many modes as the reduced one, whose frequencies it is compared with
        comparison = None if args.reduce is None else format_reduction_error(
            result, campbell(rotor, operating, n_modes=result.n_modes, harmonics=harmonics))
        files = [result.to_csv(folder.staged("campbell.csv"))]
        ref_nominal = rotor.speeds[result.reference]
        api = []
        operating_speed = ref_nominal if ref_nominal > 0 else None
        if len(result.speeds) > 1:  # one speed is a table, not a diagram
            files.append(save_figure(result.plot(operating_speed=operating_speed), folder.staged("campbell.png")))
            rng = operating_range(given_range, rotor, result.reference)
            margins = separation_margins(model, result, rng)
            files.append(result.critical_speeds_to_csv(folder.staged("critical_speeds.csv"), operating_speed, margins))
            api = [format_margins(result, margins, rng)]
        text = "\n".join([format_critical_speeds(result) if len(result.speeds) > 1 else format_whirl_table(result),
                          format_mode_count(result)] + api + ([comparison] if comparison else []))
        files += stage_summary(folder, "campbell.txt", text, record)
        files += stage_report(args, folder, result, model=model, operating_speed=operating_speed)
        folder.commit()
    report(text)
    report("wrote " + " and ".join(str(out / f.name) for f in files))
    return 0


def check_finite(result) -> None:
    """Refuse whirl frequencies or log decrements holding NaN or inf (a rigid-body mode's log decrement, over a zero
    frequency, excepted) before anything is written, naming the mode and speed."""
    def where(k):
        return f"for mode {k[1] + 1} at {result.speeds_rpm[k[0]]:.6g} rpm of {result.reference}"

    checks.finite_result("the whirl frequency (Hz)", result.frequencies_hz, where)
    elastic = [j for j in range(result.n_modes) if j not in set(result.rigid_modes)]
    checks.finite_result("the log decrement", result.log_dec[:, elastic],
                         lambda k: where((k[0], elastic[k[1]])))


def format_margins(result, margins, rng) -> str:
    """The API 617 amplification factor and separation margin of each critical speed (docs/model.md §21)."""
    rpm = 30.0 / math.pi
    head = (f"API 617 separation margins from the operating range {rng.minimum * rpm:.6g}-{rng.maximum * rpm:.6g} rpm "
            f"of {result.reference}" if rng is not None else
            f"amplification factors (no operating range of {result.reference}: give --operating-range MIN:MAX or "
            "[defaults] operating_range_rpm for the separation margins)")
    lines = [head, f"{result.reference + ' rpm':>14} {'mode':>5} {'AF':>8} {'required %':>11} {'actual %':>9}  verdict"]
    for m in margins:
        c = m.critical
        verdict = "" if m.meets is None else "meets API" if m.meets else "FAILS API"
        af = "-" if math.isnan(m.amplification_factor) else f"{m.amplification_factor:.3g}"
        req = "-" if math.isnan(m.required) else f"{100 * m.required:.3g}"
        act = "-" if math.isnan(m.actual) else f"{100 * m.actual:.3g}"
        lines.append(f"{c.speed_rpm:14.1f} {c.mode + 1:5d} {af:>8} {req:>11} {act:>9}  {verdict}"
                     + (f" ({m.note})" if m.note else ""))
    return "\n".join(lines)


def format_mode_count(result) -> str:
    """How many modes were tracked and why: ``--modes``, or the default rule
    (:func:`rotorred.linear.campbell.default_mode_count`)."""
    from rotorred import MIN_DEFAULT_MODES

    mc = result.mode_count
    if mc is None:
        return f"tracked {result.n_modes} modes (--modes)"
    rpm = 30.0 / math.pi
    if mc.limit <= 0:
        return (f"tracked {result.n_modes} modes: the default's minimum ({MIN_DEFAULT_MODES}), as no spool turns at "
                f"{mc.top_speed * rpm:.6g} rpm (no excitation line). --modes N sets the number")
    spool_speed = result.speed_ratios[mc.spool] * mc.top_speed + result.fixed_speeds.get(mc.spool, 0.0)
    line = (f"{mc.harmonic:g}× {mc.spool} at {mc.top_speed * rpm:.6g} rpm of {result.reference}"
            + (f", {mc.spool} at {spool_speed * rpm:.6g} rpm" if mc.spool != result.reference else ""))
    at = " and ".join(f"{w * rpm:.6g} rpm ({n})" for n, w in zip(mc.below, mc.speeds))
    text = (f"tracked {result.n_modes} modes: every mode below {mc.margin:g} × {mc.limit_hz:.4g} Hz, the highest "
            f"excitation frequency ({line}); modes below that at {at}")
    if mc.grown_at is not None:
        text += (f"; more, as a mode below {mc.limit_hz:.4g} Hz at {mc.grown_at * rpm:.6g} rpm was not among the "
                 "lowest at the first speed")
    elif result.n_modes > max(mc.below):
        text += f"; at least {MIN_DEFAULT_MODES}"
    elif result.n_modes < max(mc.below):
        text += "; all the oscillating modes"
    if mc.born:
        speed, w, zeta = mc.born[0]
        text += (f"; {len(mc.born)} mode{'s' * (len(mc.born) > 1)} below {mc.limit_hz:.4g} Hz become oscillating "
                 f"along the sweep (overdamped before), not tracked: the first at {speed * rpm:.6g} rpm, "
                 f"{w / (2 * math.pi):.4g} Hz, damping ratio {zeta:.3g}")
    return text + ". --modes N sets the number"


def _reduced(rotor, modes: int):
    """The Craig-Bampton model of ``rotor`` with ``modes`` fixed-interface modes (0: the default choice)."""
    from rotorred import reduce_rotor

    return reduce_rotor(rotor, n_modes=modes or None)


def format_reduction_error(reduced, full) -> str:
    """The reduced model's largest whirl-frequency and critical-speed differences against the full model."""
    rel = np.abs(reduced.frequencies / full.frequencies - 1.0)
    i, j = np.unravel_index(int(np.argmax(rel)), rel.shape)
    text = (f"reduced model against the full one: whirl frequencies within {100 * rel[i, j]:.3g} % (largest: mode {j + 1} "
            f"at {full.speeds_rpm[i]:.6g} rpm)")
    pairs = list(zip(reduced.critical_speeds, full.critical_speeds))
    if pairs and len(reduced.critical_speeds) == len(full.critical_speeds):
        text += f"; critical speeds within {100 * max(abs(a.speed / b.speed - 1) for a, b in pairs):.3g} %"
    elif full.critical_speeds or reduced.critical_speeds:
        text += (f"; {len(reduced.critical_speeds)} critical speeds against the full model's "
                 f"{len(full.critical_speeds)}: keep more modes")
    return text


def check_model_size(rotor, force: bool) -> None:
    """Refuse a rotor whose model is beyond the size limits of :mod:`rotorred.scenes.budget` (unless ``force``)."""
    from rotorred import Estimate, model_estimate

    n_dof, model_bytes = model_estimate(rotor)
    name = rotor.name or "the rotor"
    Estimate(0, 0, 0, n_dof, model_bytes, {"dofs": ("ROTOR", name), "memory": ("ROTOR", name)}).check(force)


def format_whirl_table(result, i: int = 0) -> str:
    """The whirl frequencies, directions, damping ratios and log decrements at speed ``i``, as a text table."""
    others = ", ".join(f"{s} at {result.fixed_speeds[s] * 30 / math.pi:.6g} rpm" if s in result.fixed_speeds
                       else f"{s} at {r:.4g}x" for s, r in result.speed_ratios.items() if s != result.reference)
    lines = [f"whirl frequencies of {result.rotor_name or 'rotor'} at {result.speeds_rpm[i]:.6g} rpm of "
             f"{result.reference}" + (f" ({others})" if others else ""),
             f"{'mode':>5} {'freq Hz':>12} {'whirl':>9} {'damping ratio':>14} {'log dec':>10}"]
    for j in range(result.n_modes):
        lines.append(f"{j + 1:5d} {result.frequencies_hz[i, j]:12.4f} {result.whirl[i, j]:>9} "
                     f"{result.damping_ratio[i, j]:14.6f} {result.log_dec[i, j]:10.5f}")
    return "\n".join(lines + _beyond_tables(result))


def format_critical_speeds(result) -> str:
    """The critical speeds as a text table."""
    ratios = ", ".join(f"{s}: {r:.4g}" for s, r in result.speed_ratios.items() if s not in result.fixed_speeds)
    fixed = "".join(f"; {s} fixed at {w * 30 / math.pi:.6g} rpm" for s, w in result.fixed_speeds.items())
    w = max([12] + [len(c.line) for c in result.critical_speeds])
    lines = [f"critical speeds of {result.rotor_name or 'rotor'} (speed ratios to {result.reference}: {ratios}{fixed})",
             f"{result.reference + ' rpm':>14} {'line':>{w}} {'mode':>5} {'freq Hz':>10} {'whirl':>9} {'log dec':>9}"]
    if not result.critical_speeds:
        lines.append("  (none in the speed range)")
    for c in result.stability_changes:
        lines.append(f"UNSTABLE: mode {c.mode + 1} ({c.whirl}, {c.frequency_hz:.2f} Hz) "
                     + (f"becomes unstable above {c.speed_rpm:.1f} rpm (log dec < 0)" if c.onset
                        else f"is unstable below {c.speed_rpm:.1f} rpm (log dec < 0), stable above"))
    if result.rigid_modes:
        f0 = ", ".join(f"{result.frequencies_hz[0, j]:.3g}" for j in result.rigid_modes)
        lines.append(f"rigid-body modes (a free or singly supported spool; not critical speeds): modes "
                     f"{', '.join(str(j + 1) for j in result.rigid_modes)}, {f0} Hz at {result.speeds_rpm[0]:.6g} rpm")
    for c in result.critical_speeds:
        lines.append(f"{c.speed_rpm:14.1f} {c.line:>{w}} {c.mode + 1:5d} {c.frequency_hz:10.2f} {c.whirl:>9} "
                     f"{c.log_dec:9.4f}")
    return "\n".join(lines + _beyond_tables(result))


def _beyond_tables(result) -> list[str]:
    """A line for each bearing table the speeds leave, with the rule that applies there."""
    lines = []
    for node, lo, hi, rule in result.beyond_tables:
        beyond = "the end values are held" if rule == "hold" else "the coefficients follow their end tangents (linear)"
        lines.append(f"bearing at node {node}: coefficients tabulated for {lo * 30 / math.pi:.6g}-{hi * 30 / math.pi:.6g} "
                     f"rpm of its spool; the speeds leave that range, where {beyond}")
    return lines
