"""Size estimates checked before computing: steps, record and model size against the machine and stated limits.

A run whose estimate exceeds a limit is refused with an :class:`rotorred.checks.InputError`
that states the estimate; the commands' ``--force`` lets the user go on. The limits:

* :data:`MAX_STEPS` time steps (about 100 s at 1 µs per step, the built-in scenes' reduced model);
* :data:`MAX_DOFS` degrees of freedom of the finite-element model (dense eigen-solves and solves);
* the memory the run needs (record, its copies for the files, the CSV text, the dense model
  matrices) at most :data:`MEMORY_FRACTION` of the memory the machine has available, as the operating system
  reports it through psutil (:func:`available_memory`).
"""

from __future__ import annotations

from dataclasses import dataclass

from rotorred import checks

__all__ = ["Estimate", "available_memory", "scene_estimate", "model_estimate", "branch_estimate",
           "step_warnings", "MIN_STEPS_PER_REVOLUTION", "MAX_STEPS", "MAX_DOFS",
           "MEMORY_FRACTION", "format_bytes"]

MAX_STEPS = 100_000_000
#: fewest time steps a revolution of the fastest spool before a run is warned about: at 20 a period the average-
#: acceleration Newmark step lengthens the period by (2 pi / 20)^2 / 12 = 0.8 %, and the
#: unbalance forcing is sampled 20 times a turn; fewer resolve neither the 1x response nor the contact
MIN_STEPS_PER_REVOLUTION = 20
MAX_DOFS = 20_000
MEMORY_FRACTION = 0.5
#: bytes of one CSV value as written (9 significant digits, sign, exponent, separator)
_CSV_BYTES = 17
#: dense n x n float matrices held at once by the linear analyses (M, K, C, G per spool, factors, state space)
_DENSE_MATRICES = 24
#: bytes a DOF of a model solved sparse (docs/model.md §24): its sparse matrices, LU factors and Arnoldi bases
#: (measured: a 61-speed Campbell of the rig refined(128), 9224 DOFs, peaks at 460 MB traced, 50 KB a DOF;
#: validation/bench_sparse.py --checks)
_SPARSE_BYTES_PER_DOF = 64 * 1024


def format_bytes(n: float) -> str:
    """``1.5 GiB``-style size."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:.3g} {unit}"
        n /= 1024.0
    return f"{n:.3g} TiB"


def available_memory() -> int:
    """Memory available to a new computation without swapping (bytes), as the operating system reports it.

    ``psutil.virtual_memory().available``: ``MemAvailable`` on Linux, free and inactive pages on macOS and the
    BSDs, the available physical memory on Windows. An error of psutil's is raised, not taken for "unlimited".
    """
    import psutil

    return int(psutil.virtual_memory().available)


@dataclass(frozen=True)
class Estimate:
    """What a run will need.

    Attributes
    ----------
    steps : int
        Time steps.
    samples : int
        Recorded samples.
    record_bytes : int
        Memory of the record and its copies for the files, and the CSV text (bytes).
    n_dof : int
        Degrees of freedom of the finite-element model.
    model_bytes : int
        Memory of the dense model matrices (bytes).
    fields : dict of str to (str, object)
        The key or option (and its value) a message names for each limit: ``"steps"``,
        ``"memory"``, ``"dofs"`` (e.g. ``("solver.duration", 1e6)``).
    held : str
        What :attr:`record_bytes` holds, as the message names it (default "recorded samples").
    warnings : tuple of str
        What makes the run's result doubtful though within the limits (:func:`step_warnings`), said before computing.
    """

    steps: int
    samples: int
    record_bytes: int
    n_dof: int
    model_bytes: int
    fields: dict
    held: str = "recorded samples"
    warnings: tuple = ()

    def describe(self) -> str:
        """One line: the steps, the recorded samples and their memory, the model's DOFs and its matrices' memory."""
        parts = [f"{self.steps:.3g} steps" if self.steps else "",
                 f"{self.samples:.3g} {self.held} ({format_bytes(self.record_bytes)})" if self.samples else "",
                 f"a {self.n_dof}-DOF model ({format_bytes(self.model_bytes)} of model matrices)"]
        return "estimate: " + ", ".join(p for p in parts if p)

    def check(self, force: bool = False, memory: int | None = None) -> Estimate:
        """Refuse a run beyond :data:`MAX_STEPS`, :data:`MAX_DOFS` or the available memory (unless ``force``).

        Parameters
        ----------
        force : bool
            Go on beyond the limits.
        memory : int, optional
            Memory available (bytes); default :func:`available_memory`.

        Returns
        -------
        Estimate
            This estimate, within the limits (or forced).

        Raises
        ------
        rotorred.checks.InputError
            Naming the key or option behind the limit passed (:attr:`fields`) and ``--force``.
        """
        if force:
            return self
        memory = available_memory() if memory is None else memory
        need = self.record_bytes + self.model_bytes
        reasons = {}
        if need > MEMORY_FRACTION * memory:
            reasons["memory"] = (f"{format_bytes(need)} of memory, more than {MEMORY_FRACTION:g} x the "
                                 f"{format_bytes(memory)} available")
        if self.n_dof > MAX_DOFS:
            reasons["dofs"] = f"more than {MAX_DOFS} DOFs"
        if self.steps > MAX_STEPS:
            reasons["steps"] = f"more than {MAX_STEPS:.3g} steps"
        if reasons:
            field, value = self.fields[list(reasons)[-1]]
            checks.fail(field, value,
                        f"gives a run beyond the limits ({self.describe()}: {'; '.join(reasons.values())}); "
                        f"use --force to go on")
        return self


def model_estimate(rotor, dense: bool = False) -> tuple[int, int]:
    """(DOFs, bytes of the matrices) of ``rotor``'s finite-element model (4 DOFs per node).

    Parameters
    ----------
    rotor : Rotor
        The rotor; a hierarchical element adds 6 internal DOFs.
    dense : bool
        Whether the run reads the full model dense (a full-model transient); else a model of at least
        :data:`rotorred.model.sparse.SOLVE_SPARSE_FROM` DOFs is solved sparse (docs/model.md §24).

    Returns
    -------
    n_dof : int
        Degrees of freedom of the full model.
    bytes : int
        Memory of the matrices the linear analyses hold at once (bytes): dense n x n ones, or a sparse model's
        matrices, factors and bases, linear in n.
    """
    from rotorred.model import sparse

    n = 4 * len(rotor.nodes) + 6 * sum(1 for e in _elements(rotor) if getattr(e, "element", "") == "hierarchical")
    if not dense and n >= sparse.SOLVE_SPARSE_FROM:
        return n, _SPARSE_BYTES_PER_DOF * n
    return n, _DENSE_MATRICES * 8 * n * n


def _elements(rotor):
    for spool in getattr(rotor, "spools", ()):
        yield from getattr(spool, "elements", ())


def scene_estimate(scene) -> Estimate:
    """Steps, record and model size of a scene's run (the run and its no-rub comparison).

    Parameters
    ----------
    scene : Scene
        A validated scene (:func:`rotorred.scenes.schema.load_scene`).

    Returns
    -------
    Estimate
        Check it with :meth:`Estimate.check`.
    """
    s = scene.solver
    runup = getattr(scene, "runup", None)
    transient = runup is not None or not (scene.is_linear and s.start == "settled")
    steps = int(round(s.duration / s.dt)) if transient else 0
    record_dt = runup.record_dt if runup is not None else s.dt
    samples = int(round((s.duration - s.record_start) / record_dt)) + 1
    cases = 2 if scene.plates and scene.output.compare_normal and runup is None else 1
    columns = 1 + cases * len(scene.output.dofs) + 8 * len(scene.plates)
    record = samples * columns * (8 * 4 + _CSV_BYTES)  # record, result, NPZ/.mat copies; CSV text
    n_dof, model_bytes = model_estimate(scene.rotor, dense=s.model == "full")
    model = ("rotor", scene.rotor_source)
    fields = {"steps": ("solver.duration", s.duration), "dofs": model,
              "memory": ("solver.record_start", s.record_start) if record >= model_bytes else model}
    return Estimate(steps, samples, record, n_dof, model_bytes, fields, warnings=tuple(step_warnings(scene)))


def branch_estimate(scene, harmonics: int, samples: int, max_points: int, stability: bool) -> Estimate:
    """Work and memory of a branch by harmonic balance (``rotorred continue``), at most ``max_points`` points.

    Each point solves for the plates' unknowns (4 a plate: its disk's x, y and the plate's u_n, u_t) in
    ``2 harmonics + 1`` coefficients each, with dense Jacobians of that size and ``samples`` AFT samples of every
    unknown; its stability integrates the monodromy matrix of the whole linearised system (at most the full model's
    DOFs and the plates', a dense state matrix of twice that) over ``samples`` x 4 substeps, counted as steps.

    Parameters
    ----------
    scene : Scene
        A validated scene with rub plates.
    harmonics, samples, max_points : int
        Harmonics H, AFT samples N a period and the most points of the branch.
    stability : bool
        Whether each point's multipliers are computed.

    Returns
    -------
    Estimate
        Its fields name ``--samples`` (steps), ``--harmonics`` (memory) and the rotor (DOFs).
    """
    n_dof, model_bytes = model_estimate(scene.rotor)
    unknowns = 4 * len(scene.plates) * (2 * harmonics + 1)
    state = 2 * (n_dof + 2 * len(scene.plates))
    steps = max_points * samples * 4 if stability else 0
    held = 8 * (4 * unknowns ** 2 + 4 * samples * 4 * len(scene.plates) + max_points * unknowns
                + (4 * state ** 2 if stability else 0))
    fields = {"steps": ("--samples", samples), "memory": ("--harmonics", harmonics), "dofs": ("rotor", scene.rotor_source)}
    return Estimate(steps, max_points * unknowns, held, n_dof, model_bytes, fields, "unknowns of the branch")


def step_warnings(scene) -> list[str]:
    """A warning when ``solver.dt`` gives fewer than :data:`MIN_STEPS_PER_REVOLUTION` steps a revolution of the
    fastest spool at its highest speed (a run-up: over its profile; a steady run: at its speeds); else none.

    Parameters
    ----------
    scene : Scene
        A validated scene (steady or with ``[runup]``).

    Returns
    -------
    list of str
        At most one warning, naming ``solver.dt``, the spool, its speed (Hz) and the steps a revolution.
    """
    import math

    import numpy as np

    runup = getattr(scene, "runup", None)
    if runup is not None:
        times = np.linspace(0.0, scene.solver.duration, 2001)
        speeds = {}
        for t in times:
            for spool, w in runup.profile.speeds_at(float(t)).items():
                speeds[spool] = max(speeds.get(spool, 0.0), abs(w))
    else:
        speeds = {spool: abs(w) for spool, w in scene.speeds.items()}
    if not speeds or max(speeds.values()) <= 0:
        return []
    spool = max(speeds, key=speeds.get)
    f = speeds[spool] / (2 * math.pi)
    steps = 1.0 / (f * scene.solver.dt)
    if steps >= MIN_STEPS_PER_REVOLUTION:
        return []
    return [f"solver.dt = {scene.solver.dt:g} s gives {steps:.3g} steps a revolution of the {spool} spool at "
            f"{f:.6g} Hz{' (its highest in the run-up)' if runup is not None else ''}, fewer than "
            f"{MIN_STEPS_PER_REVOLUTION}: the response is not resolved (give solver.dt <= "
            f"{1.0 / (MIN_STEPS_PER_REVOLUTION * f):.3g} s)"]
