"""Mesh convergence on the sparse path (docs/model.md §24, "Mesh convergence"): the observed order is the shaft
element's, h^2 for the default Nelson element and h^4 for the hierarchical one, on a pinned-pinned Timoshenko shaft
against its closed form (tests/test_convergence.py) and on the seed rig against its own finer meshes; nothing in the
rig (disks, bearings, the inter-shaft bearing, Rayleigh damping, the spin) lowers the element's order."""

from __future__ import annotations

import dataclasses

import numpy as np
from test_convergence import D, L_SHAFT, STEEL, exact_frequencies

import rotorred as rr
from rotorred.linear.modal import WHIRL_MAX_DAMPING_RATIO, eigen
from rotorred.model.assembly import assemble


def _pinned_shaft_errors(n_el: int, element: str) -> np.ndarray:
    """Relative errors of the 4 lowest bending frequencies at rest of the pinned-pinned Ø50 mm x 1 m shaft of
    ``n_el`` elements, assembled and solved sparse (shift-invert: 2 x 8 + 12 Arnoldi vectors, at most a quarter of
    the 2n eigenvalues from 56 DOFs on, so every mesh here is solved sparse, not through the dense fallback)."""
    els = tuple(rr.ShaftElement(i, i + 1, L_SHAFT / n_el, D, 0.0, STEEL, element=element) for i in range(n_el))
    rotor = rr.Rotor((rr.Spool("shaft", els),), supports=(rr.Support(0, "pinned"), rr.Support(n_el, "pinned")))
    model = assemble(rotor, as_sparse=True)
    assert model.is_sparse and 2 * 8 + 12 <= 0.25 * 2 * model.n_dof
    f = eigen(model.M, model.C, model.K, n_modes=8).frequencies[::2]  # x, y pairs at rest: one of each
    return np.abs(f / exact_frequencies(4)[:, 0] - 1)


def test_sparse_path_converges_at_the_elements_order_against_the_closed_form():
    """Measured: Nelson from 32 to 64 elements, orders 2.034-2.037 (errors 4.5e-7 to 1.1e-4 at 64); hierarchical from
    16 to 32, orders 3.98-4.00 (6.4e-8 to 1.5e-5 at 32). Asserted: 1.9-2.2 and 3.8-4.2."""
    for element, meshes, (low, high) in (("nelson", (32, 64), (1.9, 2.2)), ("hierarchical", (16, 32), (3.8, 4.2))):
        coarse, fine = (_pinned_shaft_errors(n, element) for n in meshes)
        orders = np.log2(coarse / fine)
        assert np.all((low < orders) & (orders < high)), (element, orders, fine)


def _rig_changes(element: str, refines: tuple[int, ...]) -> np.ndarray:
    """Largest relative change of the seed rig's lowest 12 whirl frequencies at its nominal speeds from each mesh to
    the next (each halving the elements), every shaft element of the given formulation; sparse path."""
    rig = rr.load_rotor("seed-rig")
    spools = tuple(dataclasses.replace(s, elements=tuple(dataclasses.replace(e, element=element) for e in s.elements))
                   for s in rig.spools)
    rig = dataclasses.replace(rig, spools=spools)
    f = []
    for r in refines:
        model = assemble(rig.refined(r), as_sparse=True)
        solution = eigen(model.M, model.damping(rig.speeds), model.stiffness(rig.speeds), n_modes=12,
                         max_damping_ratio=WHIRL_MAX_DAMPING_RATIO)
        f.append(solution.frequencies[:12])
    f = np.array(f)
    return np.max(np.abs(f[1:] / f[:-1] - 1), axis=1)


def test_the_rig_converges_at_the_elements_order():
    """The rig's order 2 (refined(16) to (128): changes 7.4e-7 to 1.3e-8) is the Nelson element's: the same rig with
    hierarchical elements converges at 4. Measured: Nelson refined(4, 8, 16) changes 3.1e-6, 7.4e-7, order 2.08;
    hierarchical refined(1, 2, 4) 5.9e-5, 3.7e-6, order 3.99. Asserted: 1.9-2.3 and 3.8-4.2."""
    nelson = _rig_changes("nelson", (4, 8, 16))
    hierarchical = _rig_changes("hierarchical", (1, 2, 4))
    assert 1.9 < np.log2(nelson[0] / nelson[1]) < 2.3, nelson
    assert 3.8 < np.log2(hierarchical[0] / hierarchical[1]) < 4.2, hierarchical
