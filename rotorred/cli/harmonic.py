"""``rotorred harmonic ROTOR_OR_SCENE --speeds ... --out DIR``: steady-state unbalance response sweep.

ROTOR_OR_SCENE is a rotor (preset or rotor TOML file) or a scene (built-in name or scene TOML
file, :mod:`rotorred.scenes.schema`). A scene supplies the defaults: its unbalances, its spool speeds
(the ratio, and the sweep 0 to 1.5x its reference speed), its output DOFs, and its solver's
model ("full" or "reduced", with its mode count, cutoff, boundary nodes and rub nodes).

Writes ``response.csv`` (speeds in rpm, amplitudes in µm, phases in deg), ``bode.png`` and
``polar.png`` into ``--out``; with ``--frf`` also ``frf.csv`` and ``frf.png``; and ``harmonic.txt`` (what it prints,
under the rotorred version, command line and date) with the resolved input: ``rotor.toml`` (the rotor as read) or,
for a scene, ``scene.toml`` (:mod:`rotorred.scenes.resolved`); and ``report.html``, the Bode and polar plots with
hover (``--no-html`` leaves it out: :mod:`rotorred.cli.report`).

Defaults (documented in ``--help``):

* speeds: 0 to 1.5x the reference spool's nominal speed, 301 points;
* ratio: from the rotor's nominal speeds (seed rig: outer/inner = 5400/4200 rpm);
* unbalances, outputs and the reduced model's extra boundary nodes: the rotor file's
  ``[defaults]`` table (the seed rig's: 1e-5 kg m on disks 11 and 16; outputs 13:x,13:y,14:x,14:y;
  the rub node 18), else 1e-5 kg m on the first disk of each spool and x, y at each unbalance node.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from rotorred import checks, progress, writers
from rotorred.cli.feedback import report
from rotorred.cli.report import add_html_option, stage_report
from rotorred.cli.options import (dof_list, grid, node_list, options_named, out_dir, provenance,
                                  ratio_number, speed_line, spool_ratios, stage_summary)

#: unbalance magnitude (kg m) put on the first disk of each spool when neither the user nor the rotor
#: file's ``[defaults]`` gives one
DEFAULT_M_E = 1e-5
_RPM = 60.0 / (2.0 * math.pi)
#: the FRF frequencies (Hz) when --frf is given without --frequencies
FRF_FREQUENCIES = "0:500:1001"


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "harmonic", help="steady-state unbalance response over a speed sweep (Bode, polar, CSV)",
        description="Steady-state unbalance response of the linear rotor (full or Craig-Bampton reduced) over "
                    "a speed sweep at a fixed speed ratio. Each spool's unbalances excite that spool's own "
                    "frequency; the per-spool phasors are reported, and their 'peak bound' is the sum of "
                    "magnitudes (an upper bound of the two-frequency signal's peak).")
    p.add_argument("rotor", metavar="ROTOR_OR_SCENE",
                   help="rotor preset (e.g. seed-rig, ross-coaxial) or rotor TOML file, or a scene (built-in name "
                        "or scene TOML file), whose unbalances, speeds, outputs and model are then the defaults")
    p.add_argument("--speeds", default=None,
                   help="reference spool speeds in rpm: START:STOP:N or a comma list "
                        "(default 0 to 1.5x the nominal speed, 301 points)")
    p.add_argument("--reference-spool", default=None, help="spool whose speed --speeds gives (default: the first)")
    p.add_argument("--ratio", default=None,
                   help="speed ratio(s) to the reference spool: a number (two-spool rotors) or "
                        "SPOOL=R,SPOOL=R (default: from the nominal speeds)")
    p.add_argument("--unbalance", action="append", default=None, metavar="NODE:ME[:PHASE]",
                   help="unbalance at NODE, ME in kg m, PHASE in degrees (repeatable; default: the rotor file's "
                        "[defaults] unbalances, seed rig 11:1e-5 and 16:1e-5; otherwise 1e-5 kg m on the first disk "
                        "of each spool)")
    p.add_argument("--outputs", default=None,
                   help="response DOFs NODE:DIR,... with DIR x, y, tx, ty (default: the rotor file's [defaults] outputs, "
                        "seed rig 13:x,13:y,14:x,14:y)")
    p.add_argument("--model", choices=("full", "reduced"), default=None,
                   help="full FE model or Craig-Bampton reduced model (boundary: bearings, inter-shaft "
                        "bearings, the rub node 18 of the seed rig or a scene's rub nodes, --boundary-nodes); "
                        "default full, or the scene's")
    p.add_argument("--reduced", dest="model", action="store_const", const="reduced", help="same as --model reduced")
    p.add_argument("--modes", type=int, default=None, help="number of fixed-interface modes (with --reduced)")
    p.add_argument("--cutoff", type=float, default=None,
                   help="keep fixed-interface modes up to this frequency in Hz (with --reduced); it must not lie "
                        "below the highest excitation frequency of the sweep")
    p.add_argument("--boundary-nodes", default="", help="extra boundary nodes N,N,... (with --reduced)")
    p.add_argument("--frf", default=None,
                   help="FRF pairs IN>OUT,... e.g. 18:x>13:x, at the nominal speeds (writes frf.csv, frf.png)")
    p.add_argument("--frequencies", default=None,
                   help=f"FRF frequencies in Hz START:STOP:N (with --frf; default {FRF_FREQUENCIES})")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--force", action="store_true", help="go on with a model beyond the size limits")
    add_html_option(p)
    return p


def _unbalance(text: str, nodes):
    from rotorred import Unbalance

    parts = text.split(":")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        node, m_e = int(parts[0]), float(parts[1])
        phase = float(parts[2]) if len(parts) == 3 else 0.0
    except ValueError:
        checks.fail("--unbalance", text, "must be NODE:ME[:PHASE_DEG] (e.g. 11:1e-5:90)")
    checks.node("--unbalance", node, nodes)
    checks.non_negative("--unbalance", m_e, "kg m")
    checks.bounded("--unbalance", text, m_e, "unbalance")
    return Unbalance(node, m_e, math.radians(checks.number("--unbalance", phase, "deg")))


def _ratios(text: str | None, rotor, reference: str) -> dict[str, float] | None:
    """--ratio as {spool: speed ratio to the reference spool} (None: not given; :func:`speed_line` completes it): a
    bare number is the other spool's ratio, for a two-spool rotor."""
    names = [s.name for s in rotor.spools]
    if text is None:
        return None
    if "=" not in text:
        others = [s for s in names if s != reference]
        if len(others) != 1:
            checks.fail("--ratio", text, f"a bare number needs a two-spool rotor; spools are {names}: write SPOOL=R,...")
        ratio = checks.number("--ratio", ratio_number("--ratio", text), gt=0.0)
        return {others[0]: float(checks.bounded("--ratio", text, ratio, "ratio"))}
    return {spool: float(checks.bounded("--ratio", text, checks.number("--ratio", r, ge=0.0), "ratio"))
            for spool, r in spool_ratios("--ratio", [text]).items()}


def _load(spec: str):
    """(rotor, scene or None, resolved input: ("scene" or "rotor", its TOML text)) for a rotor or scene argument."""
    from rotorred import builtin_scenes, load_scene, read_rotor, scene_toml

    if spec in builtin_scenes() or _is_scene_file(spec):
        scene = load_scene(spec)
        return scene.rotor.with_speeds(scene.speeds), scene, ("scene", scene_toml(scene))
    rotor, document = read_rotor(spec)
    return rotor, None, ("rotor", writers.toml_text(document))


def _is_scene_file(spec: str) -> bool:
    """A TOML file with a [rotor] table is a scene (rotor files have [[spool]] instead)."""
    import tomllib
    path = Path(spec)
    if not (path.suffix == ".toml" and path.is_file()):
        return False
    try:
        return isinstance(tomllib.loads(path.read_text()).get("rotor"), dict)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError):
        return False


def _speeds(args, rotor, reference: str) -> np.ndarray:
    """Reference-spool speeds of the sweep (rad/s)."""
    if args.speeds is not None:
        return checks.bounded("--speeds", args.speeds, grid("--speeds", args.speeds, "rpm", ge=0.0), "speed") / _RPM
    nominal = rotor.speeds[reference]
    if nominal <= 0:
        checks.fail("--speeds", None, f"must be given: rotor {args.rotor!r} has no nominal speed for spool "
                                      f"{reference!r}", "rpm")
    return np.linspace(0.0, 1.5 * nominal, 301)


def _unbalances(args, rotor, scene) -> list:
    """--unbalance, else the scene's, else the rotor file's [defaults], else 1e-5 kg m on each spool's first disk;
    each within :data:`rotorred.checks.BOUNDS` ``["unbalance"]``."""
    from rotorred import Unbalance

    nodes = rotor.spool_of
    if args.unbalance:
        return [_unbalance(u, nodes) for u in args.unbalance]
    given, field, source = ((list(scene.unbalances), "unbalance", str(scene.source)) if scene is not None
                            else (list(rotor.defaults.unbalances), "defaults.unbalance", str(args.rotor)))
    for i, u in enumerate(given):
        try:
            checks.bounded(f"{field}[{i}].m_e", u.m_e, u.m_e, "unbalance")
        except checks.InputError as exc:
            raise exc.from_source(source) from None
    if scene is not None or given:
        return given
    out = []
    for s in rotor.spools:
        disks = [d for d in rotor.disks if d.node in set(s.nodes)]
        if disks:
            out.append(Unbalance(disks[0].node, DEFAULT_M_E))
    if not out:
        checks.fail("--unbalance", None, f"must be given: rotor {args.rotor!r} has no disk to put a default on")
    return out


def _outputs(args, rotor, scene, unbalances) -> list[tuple[int, str]]:
    """--outputs, else the scene's output DOFs, else the rotor file's [defaults], else x, y at each unbalance."""
    if args.outputs:
        return dof_list("--outputs", args.outputs, rotor.spool_of)
    if scene is not None and scene.output.nodes:
        return list(scene.output.dofs)
    if rotor.defaults.outputs:
        return list(rotor.defaults.outputs)
    return [(u.node, d) for u in unbalances for d in ("x", "y")]


def _model(args, rotor, scene, operating):
    """The full model, or the Craig-Bampton model with its description."""
    from rotorred import assemble, default_boundary_nodes, reduce_rotor

    system = assemble(rotor)
    kind = args.model or (scene.solver.model if scene is not None else "full")
    if kind != "reduced":
        return system, f"full model, {system.n_dof} DOFs", kind
    modes, cutoff_hz = args.modes, args.cutoff
    if scene is not None and modes is None and cutoff_hz is None:
        modes, cutoff_hz = scene.solver.modes, scene.solver.cutoff_hz
    if modes is not None:
        checks.integer("--modes", modes, ge=0)
    extra = (list(scene.solver.boundary_nodes) + [p.node for p in scene.plates] if scene is not None
             else list(rotor.defaults.boundary_nodes))
    if args.boundary_nodes.strip():
        extra += node_list("--boundary-nodes", args.boundary_nodes, rotor.spool_of)
    extra = list(dict.fromkeys(extra))
    cutoff = None if cutoff_hz is None else 2 * math.pi * checks.positive("--cutoff", cutoff_hz, "Hz")
    # the band a cutoff must cover: every excitation frequency of the sweep
    band = None if cutoff is None else (0.0, max(float(np.max(w)) for w in operating.speeds(rotor).values()))
    with options_named({"n_modes": "--modes" if args.modes is not None else "solver.modes"}):
        model = reduce_rotor(rotor, extra, n_modes=modes, cutoff=cutoff, band=band, system=system)
    label = (f"Craig-Bampton model, {model.n_dof} DOFs ({model.n_boundary_dofs} boundary DOFs at nodes "
             f"{list(default_boundary_nodes(rotor, extra))} + {model.n_modes} modes); {model.selection.describe()}")
    return model, label, kind


def _frf_pairs(text: str, nodes) -> list[tuple[tuple[int, str], tuple[int, str]]]:
    pairs = []
    for item in text.split(","):
        a, sep, b = item.partition(">")
        if not sep:
            checks.fail("--frf", text, "pairs must be IN>OUT (e.g. 18:x>13:x)")
        pairs.append((dof_list("--frf", a, nodes)[0], dof_list("--frf", b, nodes)[0]))
    return pairs


def run(args) -> int:
    """Check every option and ``--out``, then solve and write into a locked, staged ``--out``."""
    from rotorred.cli.campbell import check_model_size
    from rotorred import unbalance_response

    out = out_dir("--out", args.out)
    rotor, scene, resolved = _load(str(args.rotor))
    record = provenance(args, *resolved)
    check_model_size(rotor, args.force)
    reference = checks.choice("--reference-spool", args.reference_spool or rotor.spools[0].name,
                              [s.name for s in rotor.spools])
    speeds = _speeds(args, rotor, reference)
    unbalances = _unbalances(args, rotor, scene)
    outputs = _outputs(args, rotor, scene, unbalances)
    operating = speed_line(rotor, speeds, reference, _ratios(args.ratio, rotor, reference), "rad/s",
                           ("--reference-spool", "--ratio"))
    frf_pairs = _frf_pairs(args.frf, rotor.spool_of) if args.frf else []
    frf_freqs = 2 * math.pi * _frequencies(args.frequencies or FRF_FREQUENCIES) if args.frf else None
    _check_model_options(args, scene)

    with writers.OutputFolder(out) as folder:
        t0 = time.perf_counter()
        model, label, kind = _model(args, rotor, scene, operating)  # checks the model's options against the rotor
        progress.stage(f"unbalance response of {args.rotor} at {len(speeds)} speeds ({kind} model)")
        result = unbalance_response(model, operating, unbalances, outputs)
        _check_finite(result)
        elapsed = time.perf_counter() - t0
        title = f"{rotor.name or args.rotor}: unbalance response ({kind} model)"
        names = _write(folder, result, title, model, rotor, frf_pairs, frf_freqs)
        text = _report(args, rotor, scene, label, unbalances, elapsed, result)
        names += [f.name for f in stage_summary(folder, "harmonic.txt", text, record)]
        names += [f.name for f in stage_report(args, folder, result, title=title)]
        folder.commit()
    report(text)
    for name in names:
        report(f"wrote {out / name}")
    return 0


def _check_model_options(args, scene) -> None:
    """--modes and --cutoff, in the units the user typed, before any model is built; options that would be ignored
    (the reduced model's with the full model, --frequencies without --frf) refused as conflicting."""
    full = (args.model or (scene.solver.model if scene is not None else "full")) != "reduced"
    reduced_only = {"--modes": args.modes, "--cutoff": args.cutoff,
                    "--boundary-nodes": args.boundary_nodes.strip() or None}
    for option, value in reduced_only.items():
        if full and value is not None:
            checks.fail(option, value, "applies to the reduced model only: add --reduced (the model is the full one"
                                       + (f", as scene {scene.name!r} says" if scene is not None and not args.model
                                          else "") + ")")
    if args.frequencies is not None and not args.frf:
        checks.fail("--frequencies", args.frequencies, "applies with --frf only (the FRF's frequencies): add --frf "
                                                       "IN>OUT or leave --frequencies out")
    if args.modes is not None:
        checks.integer("--modes", args.modes, ge=0)
    if args.cutoff is not None:
        checks.bounded("--cutoff", args.cutoff, checks.positive("--cutoff", args.cutoff, "Hz"), "frequency")


def _frequencies(text: str) -> np.ndarray:
    """--frequencies (Hz), each within :data:`rotorred.checks.BOUNDS` ``["frequency"]``."""
    return checks.bounded("--frequencies", text, grid("--frequencies", text, "Hz", ge=0.0), "frequency")


def _check_finite(result) -> None:
    """Refuse a response holding NaN or inf before anything is written, naming the output, spool and speeds."""
    for spool, phasors in result.phasors.items():
        for output, values in phasors.items():
            checks.finite_result(f"the response at node {output[0]} {output[1]} to the {spool} unbalances", values,
                                 lambda k: "at " + ", ".join(f"{s} {w[k[0]] * _RPM:.6g} rpm"
                                                             for s, w in result.spool_speeds.items()))


def _write(folder, result, title, model, rotor, frf_pairs, frf_freqs) -> list[str]:
    """Stage response.csv, bode.png, polar.png (and frf.csv, frf.png); returns their names."""
    from rotorred import Operating, frequency_response, save_figure

    result.write_csv(folder.staged("response.csv"))
    save_figure(result.plot(kind="bode", title=title), folder.staged("bode.png"))
    save_figure(result.plot(kind="polar", title=title), folder.staged("polar.png"))
    names = ["response.csv", "bode.png", "polar.png"]
    if frf_pairs:
        inputs = list(dict.fromkeys(p[0] for p in frf_pairs))
        frf = frequency_response(model, Operating.point(rotor.speeds), inputs,
                                 list(dict.fromkeys(p[1] for p in frf_pairs)), frf_freqs)
        checks.finite_result("the receptance (FRF)", frf.H, lambda k: f"at {frf.frequencies[k[0]] / (2 * math.pi):.6g} "
                             f"Hz from {frf.inputs[k[2]]} to {frf.outputs[k[1]]}")
        frf.write_csv(folder.staged("frf.csv"))
        save_figure(frf.plot(), folder.staged("frf.png"))
        names += ["frf.csv", "frf.png"]
    return names


def _report(args, rotor, scene, label, unbalances, elapsed, result) -> str:
    """What the sweep solved and the peak of each output (printed, and ``harmonic.txt``)."""
    lines = [f"scene {scene.name} ({scene.source})"] if scene is not None else []
    lines.append(f"rotor {rotor.name or args.rotor}: {label}")
    lines.append("unbalances: " + ", ".join(f"node {u.node} ({rotor.spool_of[u.node]}) {u.m_e:g} kg m at "
                                            f"{math.degrees(u.phase):g} deg" for u in unbalances))
    speeds, reference = result.speeds, result.reference_spool
    ratios = {s: line.slope for s, line in result.operating.lines(rotor).items()}
    lines.append(f"sweep: {len(speeds)} speeds, {reference} {speeds[0] * _RPM:.0f}-{speeds[-1] * _RPM:.0f} rpm, "
                 f"ratios {ratios}; solved in {elapsed:.2f} s")
    for o in result.outputs:
        k = int(np.argmax(result.peak(o)))
        lines.append(f"  node {o[0]} {o[1]}: max peak bound {1e6 * result.peak(o)[k]:.4g} um at "
                     f"{speeds[k] * _RPM:.0f} rpm")
    return "\n".join(lines)
