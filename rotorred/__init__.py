"""rotorred: rotordynamics of dual-rotor (twin-spool) machines with rub-impact faults.

The user-level functions and result types, importable from ``rotorred`` directly::

    import rotorred as rr

    rotor = rr.load_rotor("seed-rig")
    cd = rr.campbell(rotor, rr.Operating.line(np.linspace(0, 1200, 61)))   # rad/s of the reference spool
    model = rr.reduce_rotor(rotor, extra_nodes=[18], n_modes=24)
    res = rr.simulate(model, rr.Operating.point(rotor.speeds), 0.5, 2e-5, loads=rr.Loads([rr.Unbalance(18, 2e-3)]),
                      contacts=[rr.RubPlate.for_rotor(rotor, 18)], recording=rr.Recording([(18, "y")]))

Every analysis takes ``(model, operating, ...)``: a Rotor, an assembled or a reduced model, and an
:class:`~rotorred.model.operating.Operating` (a point, a speed line or a profile; docs/model.md §17). Every result
shows itself: a short ``repr``, ``plot(ax=None)`` returning a Figure, ``to_xarray()`` with units
(:class:`rotorred.results.Result`). The command line imports rotorred only through these names.

Layers (imports point downwards only; ``tests/test_architecture.py`` checks it):
``checks``/``writers``/``progress``/``provenance``/``results`` and ``_generated`` at the bottom, then ``model``,
``linear`` and ``signals``, ``transient``, ``nonlinear``, ``plots`` (the only layer besides ``cli`` that imports
matplotlib; a result's ``plot`` method imports its drawing when called), ``scenes``, ``maps``, this package's
public names, and ``cli``. The names below are loaded on first use, so ``import rotorred`` costs little and never
loads matplotlib or numba.
"""

from __future__ import annotations

import importlib

from rotorred._version import __version__

#: the service modules of the bottom layer, public as modules: the one validation module (its InputError messages),
#: the one writer of each file format and the locked output folder, the feedback of long work, the provenance record
_MODULES = ("checks", "writers", "progress", "provenance")

#: public name -> module that defines it
_EXPORTS = {
    # errors
    "InputError": "rotorred.checks",
    # model
    "Material": "rotorred.model.elements",
    "ShaftElement": "rotorred.model.elements",
    "Disk": "rotorred.model.elements",
    "Bearing": "rotorred.model.elements",
    "IntershaftBearing": "rotorred.model.elements",
    "BearingTable": "rotorred.model.elements",
    "IntershaftBearingTable": "rotorred.model.elements",
    "Pedestal": "rotorred.model.elements",
    "Support": "rotorred.model.elements",
    "Spool": "rotorred.model.rotor",
    "Rotor": "rotorred.model.rotor",
    "load_rotor": "rotorred.model.rotor_file",
    "read_rotor": "rotorred.model.rotor_file",
    "parse_dof": "rotorred.model.dofs",
    "presets": "rotorred.model.rotor_file",
    "convert_ross": "rotorred.model.rotor_file",
    "assemble": "rotorred.model.assembly",
    "system_of": "rotorred.model.assembly",
    "SystemMatrices": "rotorred.model.assembly",
    "system_of": "rotorred.model.assembly",
    "Unbalance": "rotorred.model.loads",
    "SpeedProfile": "rotorred.model.speeds",
    "Operating": "rotorred.model.operating",
    # linear analyses
    "campbell": "rotorred.linear.campbell",
    "default_mode_count": "rotorred.linear.campbell",
    "MIN_DEFAULT_MODES": "rotorred.linear.campbell",
    "CampbellResult": "rotorred.linear.campbell",
    "CriticalSpeed": "rotorred.linear.campbell",
    "mode_shapes": "rotorred.linear.modes",
    "ModeShapes": "rotorred.linear.modes",
    "separation_margins": "rotorred.linear.margins",
    "required_margin": "rotorred.linear.margins",
    "OperatingRange": "rotorred.linear.margins",
    "SeparationMargin": "rotorred.linear.margins",
    "unbalance_response": "rotorred.linear.harmonic",
    "UnbalanceResponse": "rotorred.linear.harmonic",
    "frequency_response": "rotorred.linear.harmonic",
    "FrequencyResponse": "rotorred.linear.harmonic",
    "steady_state": "rotorred.linear.harmonic",
    "SteadyState": "rotorred.linear.harmonic",
    "reduce_rotor": "rotorred.linear.reduction",
    "default_boundary_nodes": "rotorred.linear.reduction",
    "ReducedSystem": "rotorred.linear.reduction",
    # transient
    "RubPlate": "rotorred.transient.contact",
    "NavierPlate": "rotorred.transient.plate",
    "ClampedFreePlate": "rotorred.transient.plate",
    "RigidPlate": "rotorred.transient.plate",
    "simulate": "rotorred.transient.newmark",
    "Loads": "rotorred.transient.options",
    "Scheme": "rotorred.transient.options",
    "Recording": "rotorred.transient.options",
    "StepControl": "rotorred.transient.options",
    "Initial": "rotorred.transient.options",
    "FinalState": "rotorred.transient.results",
    "TransientResult": "rotorred.transient.newmark",
    "SimulationDiverged": "rotorred.transient.newmark",
    "energy_balance": "rotorred.transient.energy",
    "EnergyBalance": "rotorred.transient.energy",
    # signals
    "amplitude_spectrum": "rotorred.signals.spectra",
    "settled_spectrum": "rotorred.signals.spectra",
    "Spectrum": "rotorred.signals.spectra",
    "fit_lines": "rotorred.signals.linefit",
    "FitOptions": "rotorred.signals.linefit",
    "settling_time": "rotorred.signals.settling",
    "Settling": "rotorred.signals.settling",
    "classify": "rotorred.signals.classify",
    "Classification": "rotorred.signals.classify",
    "poincare_samples": "rotorred.signals.classify",
    "PoincareSamples": "rotorred.signals.classify",
    "fit_peaks": "rotorred.signals.linefit",
    "LineFit": "rotorred.signals.linefit",
    "FittedLine": "rotorred.signals.linefit",
    "angle_blocks": "rotorred.signals.orders",
    "order_tracks": "rotorred.signals.orders",
    "OrderTrack": "rotorred.signals.orders",
    # nonlinear: harmonic balance (periodic and on a torus), continuation, Floquet stability
    "Harmonics": "rotorred.nonlinear.fourier",
    "PeriodicProblem": "rotorred.nonlinear.hb",
    "PeriodicSolution": "rotorred.nonlinear.hb",
    "solve_periodic": "rotorred.nonlinear.hb",
    "NotConverged": "rotorred.nonlinear.hb",
    "TorusHarmonics": "rotorred.nonlinear.torus",
    "TorusProblem": "rotorred.nonlinear.torus",
    "TorusSolution": "rotorred.nonlinear.torus",
    "solve_torus": "rotorred.nonlinear.torus",
    "TorusTruncation": "rotorred.nonlinear.torus_truncation",
    "torus_to_tolerance": "rotorred.nonlinear.torus_truncation",
    "ContinuationOptions": "rotorred.nonlinear.continuation",
    "continue_branch": "rotorred.nonlinear.continuation",
    "TorusFamily": "rotorred.nonlinear.torus_continuation",
    "Branch": "rotorred.nonlinear.continuation",
    "Fold": "rotorred.nonlinear.continuation",
    "CubicSpring": "rotorred.nonlinear.forces",
    "CircularClearance": "rotorred.nonlinear.forces",
    "PlateRub": "rotorred.nonlinear.forces",
    "floquet": "rotorred.nonlinear.stability",
    "floquet_by_monodromy": "rotorred.nonlinear.stability",
    "Floquet": "rotorred.nonlinear.stability",
    "torus_lyapunov": "rotorred.nonlinear.torus_stability",
    "torus_trajectory": "rotorred.nonlinear.torus_stability",
    "LyapunovOptions": "rotorred.nonlinear.torus_stability",
    "TorusStability": "rotorred.nonlinear.torus_stability",
    # scenes
    "load_scene": "rotorred.scenes.schema",
    "builtin_scenes": "rotorred.scenes.builtin",
    "Scene": "rotorred.scenes.schema",
    "parse_setting": "rotorred.scenes.schema",
    "scene_toml": "rotorred.scenes.resolved",
    "scene_estimate": "rotorred.scenes.budget",
    "model_estimate": "rotorred.scenes.budget",
    "Estimate": "rotorred.scenes.budget",
    "SceneDiverged": "rotorred.scenes.run",
    "build_model": "rotorred.scenes.run",
    "SceneModel": "rotorred.scenes.run",
    "run_to_tolerance": "rotorred.scenes.tolerance",
    "format_summary": "rotorred.scenes.summary",
    "submit_figures": "rotorred.scenes.outputs",
    "write_runup_outputs": "rotorred.scenes.runup_outputs",
    "format_runup_summary": "rotorred.scenes.runup_outputs",
    # figures drawn in worker processes
    "FigurePool": "rotorred.plots.pool",
    "save_figure": "rotorred.plots.axes",
    "scene_frames": "rotorred.plots.scene",
    # interactive views (plotly): report.html of every command, Result.view()
    "write_report": "rotorred.plots.interactive",
    "report_of": "rotorred.plots.interactive",
    "run_scene": "rotorred.scenes.run",
    "SceneResult": "rotorred.scenes.run",
    "write_outputs": "rotorred.scenes.outputs",
    "run_runup": "rotorred.scenes.runup",
    "runup": "rotorred.scenes.runup",
    "RunupOptions": "rotorred.scenes.runup",
    "harmonic_balance": "rotorred.scenes.balance",
    "continue_balance": "rotorred.scenes.balance",
    "BalanceOptions": "rotorred.scenes.balance",
    "RubBalance": "rotorred.scenes.balance",
    "torus_balance": "rotorred.scenes.quasi_periodic",
    "TorusOptions": "rotorred.scenes.quasi_periodic",
    "RubTorus": "rotorred.scenes.quasi_periodic",
    "continue_scene": "rotorred.scenes.branch",
    "BranchOptions": "rotorred.scenes.branch",
    "check_key": "rotorred.scenes.branch",
    "SceneBranch": "rotorred.scenes.branch",
    "continue_torus": "rotorred.scenes.torus_branch",
    "TorusBranchOptions": "rotorred.scenes.torus_branch",
    "TorusBranch": "rotorred.scenes.torus_branch",
    "check_torus_key": "rotorred.scenes.torus_branch",
    "write_branch": "rotorred.scenes.branch_outputs",
    "format_branch": "rotorred.scenes.branch_outputs",
    "compare_models": "rotorred.scenes.compare",
    "CompareOptions": "rotorred.scenes.compare",
    "ModelComparison": "rotorred.scenes.compare",
    "ModelRun": "rotorred.scenes.compare",
    "check_comparison": "rotorred.scenes.compare",
    "format_comparison": "rotorred.scenes.compare",
    "write_comparison": "rotorred.scenes.compare",
    # maps
    "MapSpec": "rotorred.maps.spec",
    "Axis": "rotorred.maps.spec",
    "run_map": "rotorred.maps.run",
    "envelope_map": "rotorred.maps.envelope",
    "MapOptions": "rotorred.maps.envelope",
    "MapRun": "rotorred.maps.run",
    "format_map": "rotorred.maps.run",
    "RunupResult": "rotorred.scenes.runup",
}

__all__ = sorted([*_EXPORTS, *_MODULES])


def __getattr__(name: str):
    if name in _MODULES:
        return importlib.import_module(f"rotorred.{name}")
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'rotorred' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later lookups skip __getattr__
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
