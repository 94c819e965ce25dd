"""Sparse shift-invert whirl frequencies against the dense solvers and an extended-precision reference.

On the seed rig refined (``--refine``, default 16: 1160 DOFs) at one spool speed pair, the lowest 12 whirl
eigenvalues of M q'' + D q' + K q = 0 from

* the sparse path (:func:`rotorred.linear.modal.eigen` on the sparse model: shift-invert Arnoldi, docs/model.md §24),
* the dense M^-1 form (the same function on the dense model: LAPACK on [[0, I], [-M^-1 K, -M^-1 D]]),
* the dense generalised pencil (LAPACK ``eig(A, B)``, A = [[0, I], [-K, -D]], B = [[I, 0], [0, M]]),

are compared with an extended-precision reference: each eigenpair refined by Newton's method on the bordered
quadratic eigenproblem with its residual (lambda^2 M + lambda D + K) v evaluated in long double (64-bit mantissa,
eps 1.1e-19) and the double-precision LU of the bordered Jacobian (iterative refinement: the fixed point is the
long-double one). The same matrices (doubles) are solved by all four: the reference measures round-off only.

The mesh study gives the lowest 12 whirl frequencies at refined(8, 16, ..., 128) (sparse path) and the observed
order of convergence p = log2(|f_h - f_h/2| / |f_h/2 - f_h/4|).

The damping-ratio study (``--damping``) is tests/test_campbell.py's identity check on the unrefined rig at 3000 rpm
(the lowest 6 whirl modes): the damping ratios of the dense solve a Campbell of 6 modes makes (2 x 6 + 4 candidates,
more than a quarter of the 80-DOF rig's eigenvalues: dense even on a sparse model) and of the test's own
``eigen(..., n_modes=6)`` on the sparse matrices (shift-invert Arnoldi), each against the extended-precision one.

The damping scan (``--damping-scan``) lists, for each preset rotor and the built-in scenes' rotor (its Rayleigh
damping), unrefined and refined(8), the lowest whirl frequency with a damping ratio in [0.6, 0.99) at 0 to 1.5 times
the nominal speeds (every spool 0 to 12 000 rpm where the rotor has none; dense, every mode): the modes the sparse
path does not certify (docs/model.md §24).

``--hierarchical`` runs the mesh study of the rig with every shaft element ``hierarchical`` (h^4), refined(1 .. 32):
the rig's order 2 is its Nelson element's (docs/model.md §24, "Mesh convergence").

Run ``python validation/sparse_eigen.py [--refine N] [--mesh] [--hierarchical] [--damping] [--damping-scan]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time
from dataclasses import dataclass

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
import scipy.linalg as sla  # noqa: E402
import scipy.sparse as sp  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402

from rotorred.linear.modal import WHIRL_MAX_DAMPING_RATIO, eigen  # noqa: E402
from rotorred.model.assembly import assemble  # noqa: E402
from rotorred.model.rotor_file import load_rotor  # noqa: E402

N_MODES = 12
#: spool speeds of the comparison (rad/s): the rig's nominal ones (4200 and 5400 rpm)
SPEED_FACTOR = 1.0


@dataclass(frozen=True)
class Comparison:
    """Relative errors of the lowest ``N_MODES`` whirl frequencies Im(lambda) against the extended-precision
    reference, shape (N_MODES,) each, and the wall times (s) of one solve."""

    n_dof: int
    reference: np.ndarray
    sparse: np.ndarray
    dense_inverse: np.ndarray
    dense_pencil: np.ndarray
    sparse_vs_inverse: float
    sparse_vs_pencil: float
    sparse_time: float
    dense_time: float


def _matrices(refine: int, element: str = "nelson"):
    rotor = load_rotor("seed-rig")
    if element != "nelson":  # every shaft element of the rig in the given formulation
        spools = tuple(dataclasses.replace(s, elements=tuple(dataclasses.replace(e, element=element)
                                                             for e in s.elements)) for s in rotor.spools)
        rotor = dataclasses.replace(rotor, spools=spools)
    rotor = rotor.refined(refine)
    model = assemble(rotor, as_sparse=True)
    speeds = {s: SPEED_FACTOR * w for s, w in rotor.speeds.items()}
    return tuple(sp.csc_array(X) for X in (model.M, model.damping(speeds), model.stiffness(speeds)))


def _lowest(lam: np.ndarray, vec: np.ndarray | None = None):
    keep = np.flatnonzero((lam.imag > 1e-6) & (-lam.real < WHIRL_MAX_DAMPING_RATIO * np.abs(lam)))
    order = keep[np.argsort(lam.imag[keep])][:N_MODES]
    return lam[order] if vec is None else (lam[order], vec[:, order])


def dense_pencil(M, D, K):
    """The lowest whirl eigenpairs of the generalised pencil (A, B) by LAPACK, displacement part of the vectors."""
    n = M.shape[0]
    Md, Dd, Kd = M.toarray(), D.toarray(), K.toarray()
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Kd, -Dd]])
    B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), Md]])
    lam, vec = sla.eig(A, B)
    finite = np.isfinite(lam)
    return _lowest(lam[finite], vec[:n, finite])


def extended(M, D, K, lam0: complex, v0: np.ndarray, iterations: int = 12) -> complex:
    """The eigenvalue near (lam0, v0) with the residual in long double (iterative refinement of Newton's bordered
    system, its Jacobian factorised once in double)."""
    Ml, Dl, Kl = (X.astype(np.clongdouble).tocsr() for X in (M, D, K))
    v = (v0 / np.linalg.norm(v0)).astype(np.clongdouble)
    w = v.copy()
    lam = np.clongdouble(lam0)
    lam_d, v_d = complex(lam0), v.astype(complex)
    column = sp.csr_array(((2.0 * lam_d) * (M @ v_d) + D @ v_d)[:, None])
    J = sp.block_array([[(lam_d * lam_d) * M + lam_d * D + K, column], [sp.csr_array(v_d.conj()[None, :]), None]],
                       format="csc")
    lu = spla.splu(J)
    for _ in range(iterations):
        residual = (lam * lam) * (Ml @ v) + lam * (Dl @ v) + Kl @ v
        gauge = np.vdot(w, v) - np.vdot(w, w)
        step = lu.solve(-np.concatenate([residual, [gauge]]).astype(complex))
        v = v + step[:-1].astype(np.clongdouble)
        lam = lam + np.clongdouble(step[-1])
    return lam


def compare(refine: int = 16) -> Comparison:
    """The four solutions on the seed rig refined ``refine`` times (the dense ones cost O(n^3))."""
    M, D, K = _matrices(refine)
    t0 = time.perf_counter()
    sparse = eigen(M, D, K, n_modes=N_MODES, max_damping_ratio=WHIRL_MAX_DAMPING_RATIO)
    t_sparse = time.perf_counter() - t0
    t0 = time.perf_counter()
    inverse = eigen(M.toarray(), D.toarray(), K.toarray(), n_modes=N_MODES,
                    max_damping_ratio=WHIRL_MAX_DAMPING_RATIO).eigenvalues
    t_dense = time.perf_counter() - t0
    pencil, vectors = dense_pencil(M, D, K)
    reference = np.array([extended(M, D, K, sparse.eigenvalues[j], sparse.modes[:, j]) for j in range(N_MODES)])

    def error(lam):
        return np.abs(np.array(lam.imag, np.longdouble) / reference.imag - 1).astype(float)

    return Comparison(n_dof=M.shape[0], reference=reference, sparse=error(sparse.eigenvalues),
                      dense_inverse=error(inverse), dense_pencil=error(pencil),
                      sparse_vs_inverse=float(np.max(np.abs(sparse.eigenvalues.imag / inverse.imag - 1))),
                      sparse_vs_pencil=float(np.max(np.abs(sparse.eigenvalues.imag / pencil.imag - 1))),
                      sparse_time=t_sparse, dense_time=t_dense)


def mesh_study(refines=(8, 16, 32, 64, 128), element: str = "nelson") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lowest ``N_MODES`` whirl frequencies (rad/s) at each refinement (rows, each mesh halving the last), the
    largest relative change between consecutive meshes, and the observed order log2 of the ratio of consecutive
    changes; every shaft element of the rig ``element`` (the rig's own: ``"nelson"``)."""
    f = np.array([eigen(*_matrices(r, element), n_modes=N_MODES,
                        max_damping_ratio=WHIRL_MAX_DAMPING_RATIO).frequencies for r in refines])
    change = np.max(np.abs(f[1:] / f[:-1] - 1), axis=1)
    return f, change, np.log2(change[:-1] / change[1:])


def damping_ratios() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Relative errors of the lowest 6 whirl modes' damping ratios -Re(lambda)/|lambda| of the unrefined rig at
    3000 rpm (tests/test_campbell.py's identity check) against the extended-precision reference: the dense solve a
    Campbell makes, the sparse one the test's ``eigen(..., n_modes=6)`` makes, and the two against each other."""
    rig = load_rotor("seed-rig")
    model = assemble(rig, as_sparse=True)
    omega = 3000 * np.pi / 30
    ratios = {s: w / rig.speeds["inner"] for s, w in rig.speeds.items()}
    M, D, K = (sp.csc_array(X) for X in (model.M, model.C + omega * model.gyroscopic(ratios), model.K))
    sparse_solution = eigen(M, D, K, n_modes=6)
    dense = eigen(M.toarray(), D.toarray(), K.toarray(), n_modes=2 * 6 + 4).eigenvalues[:6]
    reference = np.array([complex(extended(M, D, K, lam, v)) for lam, v in zip(sparse_solution.eigenvalues,
                                                                                sparse_solution.modes.T)])

    def zeta(lam):
        return -lam.real / np.abs(lam)

    return (np.abs(zeta(dense) / zeta(reference) - 1), np.abs(zeta(sparse_solution.eigenvalues) / zeta(reference) - 1),
            np.abs(zeta(sparse_solution.eigenvalues) / zeta(dense) - 1))


def damping_scan() -> list[tuple[str, int, float, float]]:
    """(rotor, DOFs, lowest whirl frequency (Hz) with 0.6 <= zeta < 0.99 at 0, 0.25, ..., 1.5 x the nominal speeds (a
    rotor without them: every spool 0 to 12 000 rpm) or inf, the top of a Campbell band 1.25 x the fastest spool's
    highest speed (Hz)) of each shipped rotor."""
    from rotorred.linear.modal import SPARSE_COMPLETE_DAMPING_RATIO
    from rotorred.scenes.schema import load_scene

    scene_rotor = load_scene("paper-rub").rotor
    cases = [(name, load_rotor(name)) for name in ("seed-rig", "nelson-mcvaugh", "ross-coaxial")]
    cases += [("built-in scenes' rotor", scene_rotor), ("built-in scenes' rotor refined(8)", scene_rotor.refined(8))]
    out = []
    for name, rotor in cases:
        model = assemble(rotor, as_sparse=False)
        top = {s: 1.5 * w for s, w in rotor.speeds.items()}
        if not any(top.values()):  # no nominal speed: every spool to 12 000 rpm
            top = {s: 12000 * np.pi / 30 for s in top}
        lowest = np.inf
        for factor in np.linspace(0.0, 1.0, 7):
            speeds = {s: factor * w for s, w in top.items()}
            lam = eigen(model.M, model.damping(speeds), model.stiffness(speeds),
                        max_damping_ratio=WHIRL_MAX_DAMPING_RATIO).eigenvalues
            damped = -lam.real / np.abs(lam) >= SPARSE_COMPLETE_DAMPING_RATIO
            lowest = min(lowest, float(np.min(lam.imag[damped], initial=np.inf)))
        out.append((name, model.n_dof, lowest / (2 * np.pi), 1.25 * max(top.values()) / (2 * np.pi)))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--refine", type=int, default=16)
    parser.add_argument("--mesh", action="store_true", help="also the mesh study, refined(8 .. 128)")
    parser.add_argument("--hierarchical", action="store_true",
                        help="only the mesh study of the rig with hierarchical elements, refined(1 .. 32)")
    parser.add_argument("--damping", action="store_true", help="only the damping-ratio study of the unrefined rig")
    parser.add_argument("--damping-scan", action="store_true", help="only the shipped rotors' modes beyond zeta = 0.6")
    args = parser.parse_args(argv)
    if args.damping_scan:
        print("lowest whirl frequency with 0.6 <= damping ratio < 0.99 at 0 to 1.5 x the nominal speeds "
              "(none: 12000 rpm)")
        for name, n_dof, lowest, band in damping_scan():
            print(f"  {name:36s} {n_dof:5d} DOFs  {lowest:8.1f} Hz   (Campbell band top {band:.1f} Hz)")
        return
    if args.damping:
        dense, sparse, between = damping_ratios()
        print("unrefined rig at 3000 rpm, lowest 6 whirl modes: damping ratios against the extended-precision ones")
        print("  dense (a Campbell's solve)   " + " ".join(f"{e:.1e}" for e in dense))
        print("  sparse eigen(n_modes=6)      " + " ".join(f"{e:.1e}" for e in sparse))
        print(f"  sparse against dense: {between.max():.2e} (largest)")
        return
    if args.hierarchical:
        _print_mesh((1, 2, 4, 8, 16, 32), "hierarchical")
        return
    c = compare(args.refine)
    print(f"seed rig refined({args.refine}), {c.n_dof} DOFs, lowest {N_MODES} whirl frequencies at the nominal speeds")
    print("relative error against the extended-precision reference (max over the modes):")
    for name, err in (("sparse shift-invert", c.sparse), ("dense M^-1 form", c.dense_inverse),
                      ("dense pencil (A, B)", c.dense_pencil)):
        print(f"  {name:22s} {err.max():.2e}   per mode: " + " ".join(f"{e:.0e}" for e in err))
    print(f"sparse against dense M^-1 form {c.sparse_vs_inverse:.2e}, against the dense pencil {c.sparse_vs_pencil:.2e}")
    print(f"one solve: sparse {c.sparse_time:.3f} s, dense {c.dense_time:.2f} s ({c.dense_time / c.sparse_time:.0f}x)")
    if args.mesh:
        _print_mesh((8, 16, 32, 64, 128), "nelson")


def _print_mesh(refines: tuple[int, ...], element: str) -> None:
    f, change, order = mesh_study(refines, element)
    print(f"mesh study ({element} elements): lowest whirl frequencies (Hz) and the largest change from the "
          "previous mesh")
    for r, row, c in zip(refines, f, [None, *change]):
        text = "" if c is None else f"  max change {c:.2e}"
        print(f"  refined({r:3d}) " + " ".join(f"{x / (2 * np.pi):10.6f}" for x in row[:6]) + " ..." + text)
    print("observed order (log2 of consecutive changes): " + " ".join(f"{p:.2f}" for p in order))


if __name__ == "__main__":
    main()
