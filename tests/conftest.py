"""Test configuration.

BLAS is pinned to one thread before numpy loads: rotorred's dense problems are small
(a few hundred DOFs), where one thread is as fast as several, and a busy 2-core CI machine
makes multi-threaded OpenBLAS 10-40x slower on them.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


def pytest_addoption(parser):
    parser.addoption("--sparse-from", type=int, default=None,
                     help="assemble and solve models of at least this many DOFs sparse (rotorred.model.sparse."
                          "SPARSE_FROM, SOLVE_SPARSE_FROM); 0 runs every test on the sparse path")
    parser.addoption("--solve-sparse-from", type=int, default=None,
                     help="solve models of at least this many DOFs sparse (rotorred.model.sparse.SOLVE_SPARSE_FROM): "
                          "an analysis with a sparse path assembles them sparse and solves them sparse, a test's own "
                          "matrices are assembled as their size says; 0 runs every such analysis on the sparse path")


def pytest_configure(config):
    """``--sparse-from N``: the size from which models are assembled and solved sparse, for this run;
    ``--solve-sparse-from N``: the size from which the analyses assemble and solve them sparse
    (``system_of(..., sparse_ok=True)``: a rotor's or an assembled model's sparse assembly, docs/model.md §24). Set
    once for the session, before any fixture: a module-scoped fixture's reference is computed on the same path as
    the test that compares with it (a function-scoped setting left test_bench's reference on the dense path and its
    comparison on the sparse one, 1.2e-11 apart where the test asks for identity)."""
    from rotorred.model import sparse

    value = config.getoption("--sparse-from")
    if value is not None:
        sparse.SPARSE_FROM = sparse.SOLVE_SPARSE_FROM = value
    solve = config.getoption("--solve-sparse-from")
    if solve is not None:
        sparse.SOLVE_SPARSE_FROM = solve
