"""Sparse models (docs/model.md §24): the sparse assembly equals the dense one, and each sparse analysis (Campbell,
unbalance response, Craig-Bampton) equals the dense one on small models, with the independent references of
validation/sparse_eigen.py (an extended-precision eigenvalue) where round-off decides. Large models belong in
validation/bench_sparse.py; ``pytest --sparse-from 0`` runs any test file on the sparse path."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp
from validation_scripts import load_validation

import rotorred as rr
from rotorred.checks import InputError
from rotorred.linear.harmonic import response_error, unbalance_response
from rotorred.linear.modal import eigen
from rotorred.linear.reduction import reduce, reduce_rotor
from rotorred.model import sparse
from rotorred.model.assembly import assemble
from rotorred.model.elements import IntershaftBearingTable, Material, ShaftElement
from rotorred.model.loads import Unbalance
from rotorred.model.rigid import null_space
from rotorred.model.rotor import Rotor, Spool

TABLE = IntershaftBearingTable(24, 6, (0.0, 400.0, 800.0, 1200.0), k_xx=(2e6, 5e6, 7e6, 8e6), k_yy=(2e6, 4e6, 6e6, 7e6),
                               k_xy=(0.0, 1e5, 3e5, 4e5), c_xx=(400.0, 300.0, 250.0, 240.0), c_yy=300.0,
                               speed_of="outer")


def _tabulated_and_damped() -> Rotor:
    """Two spools joined by a tabulated inter-shaft bearing, internal damping (viscous and hysteretic) on the inner."""
    steel = Material("steel", 2.1e11, 7850.0)
    inner = Spool("inner", tuple(ShaftElement(i, i + 1, 0.1, 0.03, 0.0, steel) for i in range(8)), speed=300.0,
                  internal_damping_beta=2e-4, internal_loss_factor=0.01)
    outer = Spool("outer", tuple(ShaftElement(i, i + 1, 0.1, 0.07, 0.05, steel) for i in range(20, 24)), speed=500.0,
                  z0=0.2)
    return Rotor((inner, outer), disks=(rr.Disk(4, 3.0, 0.01, 0.02), rr.Disk(22, 5.0, 0.03, 0.05)),
                 bearings=(rr.Bearing(node=0, k_xx=1e7, k_yy=1e7, c_xx=200.0, c_yy=200.0),
                           rr.Bearing(node=8, k_xx=1e7, k_yy=1e7, c_xx=200.0, c_yy=200.0),
                           rr.Bearing(node=20, k_xx=2e7, k_yy=2e7, c_xx=300.0, c_yy=300.0)),
                 intershaft_bearings=(TABLE,))


ROTORS = {"seed-rig": lambda: rr.load_rotor("seed-rig"), "nelson-mcvaugh": lambda: rr.load_rotor("nelson-mcvaugh"),
          "ross-coaxial": lambda: rr.load_rotor("ross-coaxial"), "tabulated-damped": _tabulated_and_damped}


@pytest.mark.parametrize("name", ROTORS)
def test_sparse_assembly_is_the_dense_one(name):
    """Every assembled matrix equal to the bit (each entry's terms summed in the same order: a round-off difference
    split a free spool's zero eigenvalues otherwise, tests/test_supports.py failed with --sparse-from 0), the loss
    frequency (first natural frequency, sparse Lanczos against dense LAPACK) within 1e-9 (measured 5e-12), so the
    speed-dependent matrices, whose hysteretic damping is taken at it, within 1e-11 (measured 6e-13); the rigid-body
    test agrees."""
    rotor = ROTORS[name]()
    d, s = assemble(rotor, as_sparse=False), assemble(rotor, as_sparse=True)
    assert s.is_sparse and not d.is_sparse and sp.issparse(s.K) and s.dense().M.shape == d.M.shape

    def close(a, b, rtol=1e-14):
        return np.max(np.abs(sparse.dense(a) - b)) <= rtol * max(np.max(np.abs(b)), 1e-300)

    assert all(np.array_equal(sparse.dense(a), b) for a, b in ((s.M, d.M), (s.K, d.K), (s.C, d.C)))
    assert all(np.array_equal(sparse.dense(s.G[k]), d.G[k]) and np.array_equal(sparse.dense(s.K_G[k]), d.K_G[k])
               for k in d.G)
    for factor in (0.3, 1.7):
        speeds = {k: factor * w for k, w in rotor.speeds.items()}
        assert close(s.stiffness(speeds), d.stiffness(speeds), 1e-11) and close(s.damping(speeds), d.damping(speeds),
                                                                                1e-11)
    assert s.loss_frequency == pytest.approx(d.loss_frequency, rel=1e-9)
    assert np.array_equal(null_space(s)[2][:4], null_space(d)[2][:4])


def test_the_sparse_twin_of_an_assembled_model_is_its_sparse_assembly():
    """``assemble(rotor).sparse()`` is the rotor's sparse assembly, not its dense matrices converted (so an analysis
    on the sparse path runs the sparse assembly, ``pytest --solve-sparse-from 0``), equal to them to the bit, its loss
    frequency the model's; a model changed after assembly gets its own matrices converted; ``system_of`` assembles a
    rotor solved sparse sparse at once."""
    from rotorred.model.assembly import system_of

    model = assemble(_tabulated_and_damped(), as_sparse=False)
    twin = model.sparse()
    assert twin is model.sparse() and twin.is_sparse and twin.loss_frequency == model.loss_frequency
    assert twin._as_assembled and "_twin" not in vars(twin)
    d = twin.dense()
    assert all(np.array_equal(getattr(d, k), getattr(model, k)) for k in ("M", "K", "C"))
    assert all(np.array_equal(d.G[k], model.G[k]) and np.array_equal(d.rotating[k].N_h, model.rotating[k].N_h)
               for k in model.rotating)
    speeds = {k: 0.7 * w for k, w in model.nominal_speeds.items()}
    assert np.array_equal(sparse.dense(twin.stiffness(speeds)), model.stiffness(speeds))
    changed = dataclasses.replace(model, K=2.0 * model.K)
    assert not hasattr(changed, "_as_assembled") and np.array_equal(changed.sparse().K.toarray(), 2.0 * model.K)
    rig = rr.load_rotor("seed-rig")
    assert system_of(rig, sparse_ok=True).is_sparse is (assemble(rig).n_dof >= sparse.SOLVE_SPARSE_FROM)


def test_size_decides_the_form_and_the_path(request):
    """The unrefined rig is assembled and solved dense; refined(16), 1160 DOFs, is assembled dense and solved through
    its sparse twin (system_of); refined(32), 2312 DOFs, dense too; refined(64) sparse."""
    from rotorred.model.assembly import system_of

    if any(request.config.getoption(o) is not None for o in ("--sparse-from", "--solve-sparse-from")):
        pytest.skip("--sparse-from or --solve-sparse-from replaces the sizes this test checks")

    rig = rr.load_rotor("seed-rig")
    small, mid = assemble(rig), assemble(rig.refined(16))
    assert not small.is_sparse and not system_of(small, sparse_ok=True).is_sparse
    assert not mid.is_sparse and system_of(mid, sparse_ok=True).is_sparse and not system_of(mid).is_sparse
    assert not assemble(rig.refined(32)).is_sparse and assemble(rig.refined(64)).is_sparse


def test_sparse_whirl_frequencies_against_extended_precision():
    """validation/sparse_eigen.py on the rig refined(4), 296 DOFs: the lowest 12 whirl frequencies of the sparse
    path against an extended-precision (long double) Newton refinement: measured 3.5e-11, the dense M^-1 form
    7.7e-10, the dense pencil 3.2e-9."""
    c = load_validation("sparse_eigen").compare(4)
    assert c.sparse.max() < 3e-10
    assert c.sparse_vs_inverse < 1e-8


def test_sparse_campbell_is_the_dense_one():
    """Seed rig refined(2) with sparse matrices against dense: whirl frequencies within 1e-8 (measured ~1e-10), the
    same whirl labels and critical speeds within 1e-8."""
    rotor = rr.load_rotor("seed-rig").refined(2)
    operating = rr.Operating.line(np.linspace(0.0, 12000.0, 13), unit="rpm")
    a = rr.campbell(assemble(rotor, as_sparse=True), operating)
    b = rr.campbell(assemble(rotor, as_sparse=False), operating)
    assert a.n_modes == b.n_modes and np.array_equal(a.whirl, b.whirl)
    assert np.max(np.abs(a.frequencies / b.frequencies - 1)) < 1e-8
    assert len(a.critical_speeds) == len(b.critical_speeds) > 4
    assert all(abs(x.speed / y.speed - 1) < 1e-8 and x.mode == y.mode and x.whirl == y.whirl
               for x, y in zip(a.critical_speeds, b.critical_speeds))


def test_sparse_campbell_with_tables_and_internal_damping():
    """A tabulated inter-shaft bearing and internal damping (viscous and hysteretic) on the sparse path: the same
    diagram as the dense one (frequencies within 1e-8, log decs within 1e-6 absolute)."""
    rotor = _tabulated_and_damped()
    operating = rr.Operating.line(np.linspace(0.0, 1200.0, 9), ratios={"outer": 1.5})
    a = rr.campbell(assemble(rotor, as_sparse=True), operating, n_modes=6)
    b = rr.campbell(assemble(rotor, as_sparse=False), operating, n_modes=6)
    assert np.max(np.abs(a.frequencies / b.frequencies - 1)) < 1e-8
    assert np.max(np.abs(a.log_dec - b.log_dec)) < 1e-6


def test_sparse_unbalance_response_is_the_dense_one():
    rotor = rr.load_rotor("seed-rig").refined(2)
    operating = rr.Operating.line(np.linspace(0.0, 12000.0, 41), unit="rpm")
    unbalances, outputs = [Unbalance(11, 1e-5), Unbalance(16, 1e-5, 1.5)], [(13, "x"), (18, "y")]
    a = unbalance_response(assemble(rotor, as_sparse=True), operating, unbalances, outputs)
    b = unbalance_response(assemble(rotor, as_sparse=False), operating, unbalances, outputs)
    assert response_error(b, a) < 1e-9


def test_sparse_craig_bampton_is_the_dense_one():
    """The reduced models of a sparse and a dense full model: the same automatic count, fixed-interface frequencies
    within 1e-9 and whirl frequencies within 1e-9 (the mode shapes may differ in sign or, for a double frequency,
    by a rotation in its plane: the reduced matrices are equivalent, not equal)."""
    rotor = rr.load_rotor("seed-rig").refined(2)
    a = reduce_rotor(rotor, (18,), system=assemble(rotor, as_sparse=True))
    b = reduce_rotor(rotor, (18,), system=assemble(rotor, as_sparse=False))
    assert a.n_modes == b.n_modes and a.selection.history[-1][0] == b.selection.history[-1][0]
    assert np.max(np.abs(a.interior_frequencies / b.interior_frequencies - 1)) < 1e-9
    speeds = dict(rotor.speeds)
    fa = eigen(a.M, a.damping(speeds), a.stiffness(speeds)).frequencies
    fb = eigen(b.M, b.damping(speeds), b.stiffness(speeds)).frequencies
    assert np.max(np.abs(fa[:12] / fb[:12] - 1)) < 1e-9


def test_harmonic_balance_takes_a_small_sparse_model_dense_and_refuses_a_large_one():
    """PeriodicProblem handed sparse matrices: up to DENSE_UP_TO DOFs their dense copies (the same linear response to
    the bit), beyond refused by name before any work (its operators are dense in the (2H + 1) n unknowns)."""
    from rotorred.nonlinear.hb import DENSE_UP_TO

    model = assemble(rr.load_rotor("seed-rig"), as_sparse=False)
    h = rr.Harmonics(1, 8)
    n = model.n_dof

    def forcing(omega):
        F = np.zeros((h.size, n))
        F[1, 4] = 1.0
        return F.reshape(-1), np.zeros(h.size * n)

    args = dict(harmonics=h, forcing=forcing)
    dense = rr.PeriodicProblem(M=model.M, D=model.C, K=model.K, **args)
    twin = model.sparse()
    as_sparse = rr.PeriodicProblem(M=twin.M, D=twin.C, K=twin.K, **args)
    assert not sp.issparse(as_sparse.M)
    assert np.array_equal(as_sparse.linear_response(300.0), dense.linear_response(300.0))
    big = sp.identity(DENSE_UP_TO + 1, format="csr")
    with pytest.raises(InputError, match="M = 'a sparse matrix of 2501 DOFs'.*reduce_rotor"):
        rr.PeriodicProblem(M=big, D=big, K=big, **args)


def test_gravity_and_node_motion_of_a_full_model_pick_its_coordinates():
    """A full model's gravity load and mode-shape node motion read its coordinates by index (no n x n rows, no
    least squares: 680 MB and O(n^3) at 9224 DOFs): equal to the least-squares and row-product formulas they
    replace, on the dense and the sparse form."""
    from rotorred.linear.modes import node_motion
    from rotorred.model.loads import gravity_force

    d = assemble(rr.load_rotor("seed-rig"), as_sparse=False)
    pairs = list(d.full_dofs.pairs)
    R = d.output_rows(pairs)
    e = np.linalg.lstsq(R, np.array([1.0 if k == "y" else 0.0 for _, k in pairs]), rcond=None)[0]
    expected = -9.81 * (d.M @ e)
    for model in (d, d.sparse()):
        assert np.max(np.abs(gravity_force(model, 9.81) - expected)) <= 1e-14 * np.max(np.abs(expected))
    shapes = np.random.default_rng(1).standard_normal((d.n_dof, 3)) + 0j
    nodes, _, _, X, Y = node_motion(d, shapes)
    rows = d.output_rows([(n, k) for n in nodes for k in ("x", "y")]) @ shapes
    assert np.array_equal(X, rows[0::2].T) and np.array_equal(Y, rows[1::2].T)


def test_sparse_reduction_refuses_a_free_interior():
    rig = rr.load_rotor("seed-rig")
    loose = assemble(dataclasses.replace(rig, intershaft_bearings=()), as_sparse=True)
    with pytest.raises(InputError, match=r"^boundary_nodes = \[1\]: must restrain the interior part"):
        reduce(loose, (1,), n_modes=2)


class _BranchSolver:
    """A stand-in for campbell's solver along one tracked curve: ``curve(W)`` its eigenvalue at speed W (rad/s),
    one fixed shape."""

    def __init__(self, curve):
        self.curve = curve
        self.x_rows = self.y_rows = np.eye(2)

    def local(self, W, lam0, v0):
        return self.curve(W), np.array([1.0, 1j]) / np.sqrt(2)

    def solve(self, W):
        return np.array([self.curve(W)]), (np.array([1.0, 1j]) / np.sqrt(2))[:, None]


def test_a_jump_of_the_tracked_curve_is_no_critical_speed():
    """A Campbell crossing is refined by Brent's method on a sign change of Im(lambda) - line; where the tracked curve
    jumps between two modes (as it did under --sparse-from 0 in tests/test_supports.py, before the two assemblies were
    equal to the bit: round-off split a free spool's zero eigenvalues into three tiny whirl frequencies instead of two),
    Brent's method converges on the jump, and the 'crossing' was reported at a speed whose line is 14 Hz off its
    frequency. Now it is none; a true crossing is found to round-off."""
    from rotorred.linear.campbell import _refine

    Omega = np.array([60.0, 80.0])
    shapes = [np.array([[1.0], [1j]]) / np.sqrt(2)] * 2
    whirl = np.array([["forward"], ["forward"]])
    line = ("s", 1.0, 1.0, 0.0)  # frequency = W
    for curve, crossing in ((lambda W: -1.0 + (100.0 if W < 70.0 else 50.0) * 1j, False),
                            (lambda W: -1.0 + (0.5 * W + 35.0) * 1j, True)):
        lam_grid = np.array([[curve(60.0)], [curve(80.0)]])
        found = _refine(_BranchSolver(curve), Omega, lam_grid, shapes, whirl, (0, 0), line)
        assert (found is not None) == crossing
        if crossing:
            assert found.speed == pytest.approx(70.0, rel=1e-10) and found.frequency == pytest.approx(70.0, rel=1e-10)


def test_every_mode_below_a_frequency_alone_is_certified():
    """``eigen(..., below=w)`` with no mode count (the band of a scene's automatic mode count, linear/accuracy.py): on
    a sparse model every whirl mode below w, as the dense solve gives them (within 1e-7). Before, with no count the
    sparse solve never certified its eigenvalues, doubled its Arnoldi vectors to a quarter of the model's and fell back
    to a dense solve (for the rig refined(128) hours and 10 GB)."""
    rotor = rr.load_rotor("seed-rig").refined(4)
    d, s = assemble(rotor, as_sparse=False), assemble(rotor, as_sparse=True)
    w = 2 * np.pi * 650.0
    dense = eigen(d.M, d.damping(rotor.speeds), d.K, below=w).eigenvalues
    found = eigen(s.M, s.damping(rotor.speeds), s.K, below=w).eigenvalues
    assert found.shape[0] < 0.25 * 2 * s.n_dof  # the sparse solve, not its dense fallback
    lower = np.sort(found.imag[found.imag < w])
    assert len(lower) == np.sum(dense.imag < w) > 10
    np.testing.assert_allclose(lower, np.sort(dense.imag[dense.imag < w]), rtol=1e-7)
