"""``rotorred harmonic ROTOR_OR_SCENE --speeds ... --out DIR``: steady-state unbalance response sweep.

ROTOR_OR_SCENE is a rotor (preset or rotor TOML file) or a scene (built-in name or scene TOML
file, :mod:`rotorred.scenes.schema`). A scene supplies the defaults: its unbalances, its spool speeds
(the ratio, and the sweep 0 to 1.5x its reference speed), its output DOFs, and its solver's
model ("full" or "reduced", with its mode count, cutoff, boundary nodes and rub nodes).

Writes ``response.csv`` (speeds in rpm, amplitudes in µm, phases in deg), ``bode.png`` and
``polar.png`` into ``--out``; with ``--frf`` also ``frf.csv`` and ``frf.png``.

Defaults (documented in ``--help``):

* speeds: 0 to 1.5x the reference spool's nominal speed, 301 points;
* ratio: from the rotor's nominal speeds (seed rig: outer/inner = 5400/4200 rpm);
* unbalances: seed rig: 1e-5 kg m on disk 11 (inner, LP turbine) and on disk 16 (outer,
  HP compressor), phase 0; any other rotor: 1e-5 kg m on the first disk of each spool;
* outputs: seed rig: 13:x,13:y,14:x,14:y; otherwise x and y at each unbalance node.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

#: default unbalance magnitude (kg m) when none is given
DEFAULT_M_E = 1e-5
#: per-preset defaults: unbalance nodes, output DOFs, extra boundary nodes (the rub node)
PRESET_DEFAULTS = {
    "seed-rig": {"unbalance_nodes": (11, 16), "outputs": "13:x,13:y,14:x,14:y", "boundary": (18,)},
}
_RPM = 60.0 / (2.0 * math.pi)


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "harmonic", help="steady-state unbalance response over a speed sweep (Bode, polar, CSV)",
        description="Steady-state unbalance response of the linear rotor (full or Craig-Bampton reduced) over "
                    "a speed sweep at a fixed speed ratio. Each spool's unbalances excite that spool's own "
                    "frequency; the per-spool phasors are reported, and their 'peak bound' is the sum of "
                    "magnitudes (an upper bound of the two-frequency signal's peak).")
    p.add_argument("rotor", metavar="ROTOR_OR_SCENE",
                   help="rotor preset (seed-rig, nelson-mcvaugh) or rotor TOML file, or a scene (built-in name "
                        "or scene TOML file), whose unbalances, speeds, outputs and model are then the defaults")
    p.add_argument("--speeds", default=None,
                   help="reference spool speeds in rpm: START:STOP:N or a comma list "
                        "(default 0 to 1.5x the nominal speed, 301 points)")
    p.add_argument("--reference-spool", default=None, help="spool whose speed --speeds gives (default: the first)")
    p.add_argument("--ratio", default=None,
                   help="speed ratio(s) to the reference spool: a number (two-spool rotors) or "
                        "SPOOL=R,SPOOL=R (default: from the nominal speeds)")
    p.add_argument("--unbalance", action="append", default=None, metavar="NODE:ME[:PHASE]",
                   help="unbalance at NODE, ME in kg m, PHASE in degrees (repeatable; default seed rig: "
                        "11:1e-5 and 16:1e-5; otherwise 1e-5 kg m on the first disk of each spool)")
    p.add_argument("--outputs", default=None,
                   help="response DOFs NODE:DIR,... with DIR x, y, tx, ty (default seed rig 13:x,13:y,14:x,14:y)")
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
    p.add_argument("--frequencies", default="0:500:1001", help="FRF frequencies in Hz START:STOP:N (default 0:500:1001)")
    p.add_argument("--out", required=True, help="output directory")
    return p


def _grid(text: str, name: str, unit: str) -> np.ndarray:
    try:
        if ":" in text:
            a, b, n = text.split(":")
            n = int(n)
            if n < 1:
                raise ValueError
            return np.linspace(float(a), float(b), n)
        return np.array([float(v) for v in text.split(",") if v.strip()])
    except ValueError:
        raise ValueError(f"`--{name}` must be START:STOP:N (N >= 1) or a comma list of numbers in {unit}, "
                         f"got {text!r}") from None


def _unbalance(text: str):
    from rotorred.model.loads import Unbalance
    parts = text.split(":")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        node, m_e = int(parts[0]), float(parts[1])
        phase = math.radians(float(parts[2])) if len(parts) == 3 else 0.0
    except ValueError:
        raise ValueError(f"`--unbalance` must be NODE:ME[:PHASE_DEG] (e.g. 11:1e-5:90), got {text!r}") from None
    return Unbalance(node, m_e, phase)


def _ratios(text: str | None, rotor, reference: str) -> dict[str, float]:
    names = [s.name for s in rotor.spools]
    if text is None:
        nominal = rotor.speeds
        if nominal[reference] <= 0:
            return {s: 1.0 for s in names}
        return {s: nominal[s] / nominal[reference] for s in names}
    out = {reference: 1.0}
    try:
        if "=" not in text:
            others = [s for s in names if s != reference]
            if len(others) != 1:
                raise ValueError(f"`--ratio` as a bare number needs a two-spool rotor; spools are {names}: "
                                 f"write SPOOL=R,...")
            out[others[0]] = float(text)
        else:
            for item in text.split(","):
                s, r = item.split("=")
                out[s.strip()] = float(r)
    except ValueError as exc:
        if "bare number" in str(exc):
            raise
        raise ValueError(f"`--ratio` must be a number or SPOOL=R,..., got {text!r}") from None
    return out


def _load(spec: str):
    """(rotor, scene or None) for a rotor or scene argument."""
    from rotorred.model.rotor_file import load_rotor
    try:
        from rotorred.scenes.schema import builtin_scenes, load_scene
    except ImportError:  # pragma: no cover - scenes not available
        return load_rotor(spec), None
    if spec in builtin_scenes() or _is_scene_file(spec):
        scene = load_scene(spec)
        return scene.rotor, scene
    return load_rotor(spec), None


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


def run(args) -> int:
    from rotorred.model.assembly import assemble
    from rotorred.linear.harmonic import frequency_response, parse_dof, unbalance_response
    from rotorred.plots.harmonic import plot_bode, plot_frf, plot_polar
    from rotorred.model.loads import Unbalance
    from rotorred.linear.reduction import default_boundary_nodes, reduce_rotor

    rotor, scene = _load(str(args.rotor))
    preset = PRESET_DEFAULTS.get(str(args.rotor), {})
    if scene is not None:
        rotor = rotor.with_speeds(scene.speeds)
        preset = {"unbalance": scene.unbalances,
                  "boundary": tuple(scene.solver.boundary_nodes) + tuple(p.node for p in scene.plates)}
        if scene.output.nodes:
            preset["outputs"] = ",".join(f"{n}:{d}" for n, d in scene.output.dofs)
    model_kind = args.model or (scene.solver.model if scene is not None else "full")
    modes, cutoff_hz = args.modes, args.cutoff
    if scene is not None and modes is None and cutoff_hz is None:
        modes, cutoff_hz = scene.solver.modes, scene.solver.cutoff_hz
    reference = args.reference_spool or rotor.spools[0].name
    rotor.spool(reference)  # ValueError naming the spools if unknown
    if args.speeds is None:
        nominal = rotor.speeds[reference]
        if nominal <= 0:
            raise ValueError(f"rotor {args.rotor!r} has no nominal speed for spool {reference!r}; give `--speeds`")
        speeds = np.linspace(0.0, 1.5 * nominal, 301)
    else:
        speeds = _grid(args.speeds, "speeds", "rpm") / _RPM
    if args.unbalance:
        unbalances = [_unbalance(u) for u in args.unbalance]
    elif "unbalance" in preset:
        unbalances = list(preset["unbalance"])
    elif "unbalance_nodes" in preset:
        unbalances = [Unbalance(n, DEFAULT_M_E) for n in preset["unbalance_nodes"]]
    else:
        unbalances = []
        for s in rotor.spools:
            disks = [d for d in rotor.disks if d.node in set(s.nodes)]
            if disks:
                unbalances.append(Unbalance(disks[0].node, DEFAULT_M_E))
        if not unbalances:
            raise ValueError(f"rotor {args.rotor!r} has no disk to put a default unbalance on; give `--unbalance`")
    if args.outputs:
        outputs = [parse_dof(o) for o in args.outputs.split(",") if o.strip()]
    elif "outputs" in preset:
        outputs = [parse_dof(o) for o in preset["outputs"].split(",")]
    else:
        outputs = [(u.node, d) for u in unbalances for d in ("x", "y")]
    ratios = _ratios(args.ratio, rotor, reference)
    unknown = set(ratios) - {s.name for s in rotor.spools}
    if unknown:
        raise ValueError(f"`--ratio` names unknown spool(s) {sorted(unknown)}; spools are "
                         f"{[s.name for s in rotor.spools]}")

    t0 = time.perf_counter()
    system = assemble(rotor)
    model, label = system, f"full model, {system.n_dof} DOFs"
    if model_kind == "reduced":
        extra = list(dict.fromkeys(preset.get("boundary", ())))
        if args.boundary_nodes.strip():
            try:
                extra += [int(n) for n in args.boundary_nodes.split(",") if n.strip()]
            except ValueError:
                raise ValueError(f"`--boundary-nodes` must be a comma list of node numbers, got "
                                 f"{args.boundary_nodes!r}") from None
        if modes is not None and modes < 0:
            raise ValueError(f"`--modes` must be an integer >= 0, got {modes}")
        cutoff = None if cutoff_hz is None else 2 * math.pi * cutoff_hz
        # the band a cutoff must cover: every excitation frequency of the sweep
        band = None if cutoff is None else (0.0, max(float(np.max(speeds)) * r for r in ratios.values()))
        model = reduce_rotor(rotor, extra, n_modes=modes, cutoff=cutoff, band=band, system=system)
        label = (f"Craig-Bampton model, {model.n_dof} DOFs ({model.n_boundary_dofs} boundary DOFs at nodes "
                 f"{list(default_boundary_nodes(rotor, extra))} + {model.n_modes} modes); "
                 f"{model.selection.describe()}")
    result = unbalance_response(model, unbalances, speeds, ratios=ratios, outputs=outputs,
                                spool_of=rotor.spool_of, reference_spool=reference)
    elapsed = time.perf_counter() - t0

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    title = f"{rotor.name or args.rotor}: unbalance response ({model_kind} model)"
    files = [result.write_csv(out / "response.csv"), plot_bode(result, out / "bode.png", title),
             plot_polar(result, out / "polar.png", title)]
    if args.frf:
        pairs = []
        for item in args.frf.split(","):
            try:
                a, b = item.split(">")
            except ValueError:
                raise ValueError(f"`--frf` pairs must be IN>OUT (e.g. 18:x>13:x), got {item!r}") from None
            pairs.append((parse_dof(a), parse_dof(b)))
        inputs = list(dict.fromkeys(p[0] for p in pairs))
        frf_outputs = list(dict.fromkeys(p[1] for p in pairs))
        freqs = 2 * math.pi * _grid(args.frequencies, "frequencies", "Hz")
        frf = frequency_response(model, inputs, frf_outputs, freqs, speeds=rotor.speeds)
        files += [frf.write_csv(out / "frf.csv"), plot_frf(frf, out / "frf.png")]

    if scene is not None:
        print(f"scene {scene.name} ({scene.source})")
    print(f"rotor {rotor.name or args.rotor}: {label}")
    print("unbalances: " + ", ".join(f"node {u.node} ({rotor.spool_of[u.node]}) {u.m_e:g} kg m at "
                                     f"{math.degrees(u.phase):g} deg" for u in unbalances))
    print(f"sweep: {len(speeds)} speeds, {reference} {speeds[0] * _RPM:.0f}-{speeds[-1] * _RPM:.0f} rpm, "
          f"ratios {ratios}; solved in {elapsed:.2f} s")
    for o in result.outputs:
        k = int(np.argmax(result.peak(o)))
        print(f"  node {o[0]} {o[1]}: max peak bound {1e6 * result.peak(o)[k]:.4g} um at "
              f"{speeds[k] * _RPM:.0f} rpm")
    for f in files:
        print(f"wrote {f}")
    return 0
