"""Mesh convergence of the Timoshenko element against exact solutions of a uniform shaft.

Simply supported uniform Timoshenko shaft, mode n (k = n pi / L), whirl r = x + i y = R sin(kz) e^{i w t},
complex slope theta = theta_y - i theta_x = Theta cos(kz) e^{i w t}. The field equations
    rho A r'' = kappa G A (r' - theta)',
    rho I theta'' - 2 i rho I Omega theta' = E I theta'' + kappa G A (r' - theta)
give the frequency equation
    (kappa G A k^2 - rho A w^2)(E I k^2 + kappa G A - rho I w^2 + 2 rho I Omega w) - (kappa G A k)^2 = 0,
w > 0 forward, w < 0 backward whirl (Omega = 0: the classical Timoshenko equation). Roots by brentq.
"""

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import brentq

from rotorred.model.assembly import assemble
from rotorred.model.elements import Material, ShaftElement
from rotorred.linear.modal import eigen
from rotorred.model.rotor import Rotor, Spool

STEEL = Material("steel", E=2.1e11, rho=7850.0, nu=0.3)
L_SHAFT, D = 1.0, 0.05


def exact_frequencies(n_modes, Omega=0.0):
    """Forward and backward natural frequencies (rad/s) of the first modes, from the closed form."""
    e = ShaftElement(0, 1, L_SHAFT, D, 0.0, STEEL)
    rho, A, I, E = STEEL.rho, e.A, e.I, STEEL.E
    kGA = e.kappa * STEEL.G_s * A

    def det(w, k):
        return (kGA * k**2 - rho * A * w**2) * (E * I * k**2 + kGA - rho * I * w**2 + 2 * rho * I * Omega * w) - (kGA * k) ** 2

    out = []
    for n in range(1, n_modes + 1):
        k = n * np.pi / L_SHAFT
        w_eb = k**2 * np.sqrt(E * I / (rho * A))  # Euler-Bernoulli estimate brackets the lower branch
        fwd = brentq(det, 0.5 * w_eb, 1.5 * w_eb, args=(k,), xtol=1e-14, rtol=1e-15)
        bwd = -brentq(det, -1.5 * w_eb, -0.5 * w_eb, args=(k,), xtol=1e-14, rtol=1e-15)
        # each bracket holds one root: the shear branch lies above sqrt(kGA/(rho I)) >> 1.5 w_eb here
        out.append((fwd, bwd))
    return np.array(out)


def simply_supported(n_el, formulation="hierarchical"):
    els = tuple(ShaftElement(i, i + 1, L_SHAFT / n_el, D, 0.0, STEEL, element=formulation) for i in range(n_el))
    return Rotor((Spool("shaft", els),), name=f"ss{n_el}")


def fe_frequencies(n_el, n_modes, Omega=0.0, formulation="hierarchical"):
    """Lowest FE whirl frequencies (rad/s) with x, y pinned at both ends."""
    rotor = simply_supported(n_el, formulation)
    S = assemble(rotor)
    fixed = [S.dofs.index(n, d) for n in (0, n_el) for d in ("x", "y")]
    free = np.setdiff1d(np.arange(S.n_dof), fixed)
    sub = np.ix_(free, free)
    return eigen(S.M[sub], S.gyroscopic({"shaft": Omega})[sub], S.K[sub], n_modes=2 * n_modes)


def fe_frequencies_at_rest(n_el, n_modes, formulation="hierarchical"):
    """Lowest FE bending frequencies (rad/s) at rest, one per x/y pair (symmetric eigenproblem)."""
    S = assemble(simply_supported(n_el, formulation))
    fixed = [S.dofs.index(n, d) for n in (0, n_el) for d in ("x", "y")]
    free = np.setdiff1d(np.arange(S.n_dof), fixed)
    sub = np.ix_(free, free)
    w2 = sla.eigh(S.K[sub], S.M[sub], eigvals_only=True, subset_by_index=(0, 2 * n_modes - 1))
    return np.sqrt(w2[::2])


def test_simply_supported_first_four_frequencies():
    """Issue 2: within 0.05 % with 40 elements and 0.005 % with 80 (hierarchical element)."""
    exact = exact_frequencies(4)[:, 0]
    for n_el, tol in ((40, 5e-4), (80, 5e-5)):
        f = fe_frequencies_at_rest(n_el, 4)
        rel = np.abs(f / exact - 1)
        assert rel.max() < tol, (n_el, rel)


def _observed_orders(formulation, meshes):
    exact = exact_frequencies(4)[:, 0]
    errs = np.array([np.abs(fe_frequencies_at_rest(n, 4, formulation) / exact - 1)
                     for n in meshes])
    return [np.polyfit(np.log(1.0 / meshes), np.log(errs[:, m]), 1)[0] for m in range(4)], errs


def test_observed_convergence_order_hierarchical():
    """Cubic w, quadratic psi, independent: energy error O(h^2), eigenvalue error O(h^4); require >= 3.5."""
    orders, errs = _observed_orders("hierarchical", np.array([8, 12, 16, 24, 32]))
    assert min(orders) >= 3.5, (orders, errs)


def test_observed_convergence_order_nelson_is_two():
    """The interdependent (Nelson) element has a constant shear strain per element, so the
    eigenvalue error falls as h^2 (with a small constant proportional to E I k^2 / (kappa G A)).
    Documented, not hidden: docs/model.md, "Shaft element"."""
    orders, errs = _observed_orders("nelson", np.array([16, 24, 32, 48]))
    assert all(1.8 < p < 2.3 for p in orders), (orders, errs)
    # it still meets the 40-element accuracy of issue 2 (0.05 %)
    exact = exact_frequencies(4)[:, 0]
    f = fe_frequencies_at_rest(40, 4, "nelson")
    assert np.abs(f / exact - 1).max() < 5e-4


def _is_forward(S, free, mode):
    full = np.zeros(S.n_dof, complex)
    full[free] = mode
    X, Y = full[S.dofs.nodal[:, 0]], full[S.dofs.nodal[:, 1]]
    return np.sum(np.abs(X + 1j * Y) ** 2) > np.sum(np.abs(X - 1j * Y) ** 2)


def test_spinning_shaft_forward_backward_split():
    """Forward/backward frequencies and their split against the closed form, and the whirl
    direction of each FE mode from its orbit (x + i y ~ e^{+i w t}: forward if |X + iY| > |X - iY|)."""
    Omega = 5000.0  # rad/s: splits the first mode by about 2 %
    n_el = 40
    exact = exact_frequencies(2, Omega)
    sol = fe_frequencies(n_el, 2, Omega)
    S = assemble(simply_supported(n_el))
    fixed = [S.dofs.index(n, d) for n in (0, n_el) for d in ("x", "y")]
    free = np.setdiff1d(np.arange(S.n_dof), fixed)
    f = sol.frequencies
    for mode in range(2):
        bwd, fwd = f[2 * mode], f[2 * mode + 1]
        # 40 hierarchical elements: measured errors 4.2e-7 (frequencies) and 2.9e-8 (split, relative);
        # the tolerances are about 10x those, so a wrong gyroscopic term (an O(1) change of the split)
        # or a lost h^4 (errors of 1e-5 and more at this mesh) fails.
        assert fwd == pytest.approx(exact[mode, 0], rel=5e-6)
        assert bwd == pytest.approx(exact[mode, 1], rel=5e-6)
        split_exact = exact[mode, 0] - exact[mode, 1]
        assert split_exact > 0.01 * exact[mode, 0]
        assert (fwd - bwd) == pytest.approx(split_exact, rel=5e-7)
        assert _is_forward(S, free, sol.modes[:, 2 * mode + 1])
        assert not _is_forward(S, free, sol.modes[:, 2 * mode])
