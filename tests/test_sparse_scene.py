"""A scene on a large rotor (docs/model.md §24, "Scenes on large rotors"): the way a user runs one, a rotor file
written by ``Rotor.to_toml`` from a refined rotor and referenced by the scene's ``[rotor] file``. Its size check
counts a sparse model's memory, and its reduced model is built without a dense full matrix. The run itself, through
``rotorred run``, and its cost per step against the rig's: validation/bench_sparse.py ``--checks``."""

from __future__ import annotations

import tracemalloc
from importlib import resources

import pytest

import rotorred as rr
from rotorred.checks import InputError
from rotorred.model import sparse

GiB = 1024 ** 3


def _large_scene(tmp_path, refine: int, settings=None):
    """The paper-rub scene on the seed rig refined ``refine`` times, its rotor in a file of its own."""
    rr.load_rotor("seed-rig").refined(refine).to_toml(tmp_path / "rig.toml")
    text = resources.files("rotorred.scenes.builtin").joinpath("paper-rub.toml").read_text(encoding="utf-8")
    assert 'preset = "seed-rig"' in text
    (tmp_path / "scene.toml").write_text(text.replace('preset = "seed-rig"', 'file = "rig.toml"'), encoding="utf-8")
    return rr.load_scene(tmp_path / "scene.toml", settings)


def test_a_scene_on_a_large_rotor_is_sized_and_reduced_sparse(tmp_path, request):
    """refined(64), 4616 DOFs, assembled sparse: the estimate counts 64 KiB a DOF (0.28 GiB) where dense matrices
    would count 3.8 GiB, so 4 GiB available pass; a full-model run (a dense copy for the transient) is refused. The
    Craig-Bampton model of the scene (48 DOFs) is built with a traced peak of 27 MB (measured) where one dense
    4616 x 4616 matrix alone is 170 MB: asserted below half of that, so no dense full matrix is made."""
    if request.config.getoption("--sparse-from") is not None:
        pytest.skip("--sparse-from replaces the size from which the rotor is assembled sparse")
    scene = _large_scene(tmp_path, 64)
    n = 4 * len(scene.rotor.nodes)
    assert n == 4616 and n >= sparse.SPARSE_FROM
    estimate = rr.scene_estimate(scene).check(memory=4 * GiB)
    assert estimate.n_dof == n and estimate.model_bytes < 0.3 * GiB
    full = _large_scene(tmp_path, 64, {"solver.model": "full"})
    with pytest.raises(InputError, match="beyond the limits"):
        rr.scene_estimate(full).check(memory=4 * GiB)
    tracemalloc.start()
    try:
        built = rr.build_model(scene)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert built.model.n_dof == 48 and "of the 4616-DOF FE model" in built.label
    assert peak < 0.5 * 8 * n * n, peak / 1e6
