"""Test configuration.

BLAS is pinned to one thread before numpy loads: rotorred's dense problems are small
(a few hundred DOFs), where one thread is as fast as several, and a busy 2-core CI machine
makes multi-threaded OpenBLAS 10-40x slower on them.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import pytest  # noqa: E402


def pytest_addoption(parser):
    parser.addoption("--sparse-from", type=int, default=None,
                     help="assemble and solve models of at least this many DOFs sparse (rotorred.model.sparse."
                          "SPARSE_FROM, SOLVE_SPARSE_FROM); 0 runs every test on the sparse path")
    parser.addoption("--solve-sparse-from", type=int, default=None,
                     help="solve models of at least this many DOFs sparse (rotorred.model.sparse.SOLVE_SPARSE_FROM): "
                          "an analysis with a sparse path assembles them sparse and solves them sparse, a test's own "
                          "matrices are assembled as their size says; 0 runs every such analysis on the sparse path")


@pytest.fixture(autouse=True)
def _sparse_from(request, monkeypatch):
    """``--sparse-from N``: the size from which models are assembled and solved sparse, for this run;
    ``--solve-sparse-from N``: the size from which the analyses assemble and solve them sparse
    (``system_of(..., sparse_ok=True)``: a rotor's or an assembled model's sparse assembly, docs/model.md §24)."""
    from rotorred.model import sparse

    value = request.config.getoption("--sparse-from")
    if value is not None:
        monkeypatch.setattr(sparse, "SPARSE_FROM", value)
        monkeypatch.setattr(sparse, "SOLVE_SPARSE_FROM", value)
    solve = request.config.getoption("--solve-sparse-from")
    if solve is not None:
        monkeypatch.setattr(sparse, "SOLVE_SPARSE_FROM", solve)
