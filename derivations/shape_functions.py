"""Shape functions of the two-node Timoshenko beam element, derived from its statics.

The interpolation is the "interdependent" one (Friedman & Kosmatka 1993; Nelson 1980):
the displacement ``w`` and the section rotation ``psi`` are the exact solution of the
homogeneous static Timoshenko equations of a uniform beam,

    EI psi'' + kappa G A (w' - psi) = 0,        (moment balance)
    (kappa G A (w' - psi))' = 0,                (shear balance)

so ``w`` is a cubic, ``psi`` a quadratic, and both depend on the shear parameter
``phi = 12 EI / (kappa G A L^2)``. With ``phi = 0`` they reduce to the Hermite cubics of the
Euler-Bernoulli beam (``psi = w'``).

References
----------
Nelson, H. D., "A finite rotating shaft element using Timoshenko beam theory",
J. Mech. Des. 102 (1980) 793-803, Eqs. (10)-(14).
Friedman, Z., Kosmatka, J. B., "An improved two-node Timoshenko beam finite element",
Computers & Structures 47 (1993) 473-481, Eqs. (9)-(12).
"""

from __future__ import annotations

import sympy as sp

z, L, phi = sp.symbols("z L phi", positive=True)


def planar_shape_functions() -> tuple[sp.Matrix, sp.Matrix]:
    """Shape functions of one bending plane.

    Returns
    -------
    N_w, N_psi : sympy.Matrix, shape (1, 4)
        ``w(z) = N_w q`` and ``psi(z) = N_psi q`` for the planar nodal vector
        ``q = (w_1, psi_1, w_2, psi_2)``, ``0 <= z <= L``.
    """
    a = sp.symbols("a0:4")
    b = sp.symbols("b0:3")
    w = sum(a[i] * z**i for i in range(4))
    psi = sum(b[i] * z**i for i in range(3))
    # EI/(kappa G A) written through phi: EI/(kappa G A) = phi L^2 / 12.
    s = phi * L**2 / 12
    moment_balance = sp.expand(s * sp.diff(psi, z, 2) + (sp.diff(w, z) - psi))
    # The shear balance (w' - psi)' = 0 follows once the moment balance holds with psi
    # quadratic; require every power of z of the moment balance to vanish.
    conditions = sp.Poly(moment_balance, z).all_coeffs()
    solved_b = sp.solve(conditions, b, dict=True)[0]
    w_sub, psi_sub = w, psi.subs(solved_b)
    q = sp.symbols("q0:4")
    nodal = [
        sp.Eq(w_sub.subs(z, 0), q[0]),
        sp.Eq(psi_sub.subs(z, 0), q[1]),
        sp.Eq(w_sub.subs(z, L), q[2]),
        sp.Eq(psi_sub.subs(z, L), q[3]),
    ]
    solved_a = sp.solve(nodal, a, dict=True)[0]
    w_q = sp.expand(w_sub.subs(solved_a))
    psi_q = sp.expand(psi_sub.subs(solved_a))
    N_w = sp.Matrix([[sp.simplify(sp.diff(w_q, qi)) for qi in q]])
    N_psi = sp.Matrix([[sp.simplify(sp.diff(psi_q, qi)) for qi in q]])
    return N_w, N_psi


def spatial_shape_functions() -> dict[str, sp.Matrix]:
    """Shape functions in the element's 4-DOF-per-node frame.

    Nodal vector ``q = (x_1, y_1, theta_x1, theta_y1, x_2, y_2, theta_x2, theta_y2)``.
    In the x-z plane the section rotation is ``psi = theta_y`` (a positive rotation about
    y turns z towards x); in the y-z plane it is ``psi = -theta_x`` (a positive rotation
    about x turns z towards -y).

    Returns
    -------
    dict
        ``"x"``, ``"y"``, ``"theta_x"``, ``"theta_y"``: sympy.Matrix, shape (1, 8).
    """
    N_w, N_psi = planar_shape_functions()
    zero = sp.zeros(1, 8)
    Nx, Ny, Ntx, Nty = zero.copy(), zero.copy(), zero.copy(), zero.copy()
    # planar index -> (element DOF of the xz plane, sign), (element DOF of the yz plane, sign)
    xz = [(0, 1), (3, 1), (4, 1), (7, 1)]
    yz = [(1, 1), (2, -1), (5, 1), (6, -1)]
    for j in range(4):
        dof, sign = xz[j]
        Nx[0, dof] += sign * N_w[0, j]
        Nty[0, dof] += sign * N_psi[0, j]
        dof, sign = yz[j]
        Ny[0, dof] += sign * N_w[0, j]
        # theta_x = -psi_yz
        Ntx[0, dof] += -sign * N_psi[0, j]
    return {"x": Nx, "y": Ny, "theta_x": Ntx, "theta_y": Nty}


def hierarchical_shape_functions() -> dict[str, sp.Matrix]:
    """Shape functions of the hierarchical (p = 3 / 2) Timoshenko element.

    Displacements are cubic and section rotations quadratic, interpolated independently:
    linear nodal interpolation plus bubbles vanishing at both nodes,

        x = x1 (1 - s) + x2 s + a_x1 s (1 - s) + a_x2 s (1 - s)(1 - 2 s),   s = z / L,
        theta_y = theta_y1 (1 - s) + theta_y2 s + c_y s (1 - s),

    and likewise for y and theta_x. With w' and psi in the same (quadratic) space the element
    does not lock, and the shear strain w' - psi varies along the element, so the eigenvalue
    error of a smooth mode falls as h^4 (the interdependent element's constant shear strain
    gives h^2).

    Returns
    -------
    dict
        ``"x"``, ``"y"``, ``"theta_x"``, ``"theta_y"``: sympy.Matrix, shape (1, 14), for the
        element vector (x1, y1, theta_x1, theta_y1, x2, y2, theta_x2, theta_y2,
        a_x1, a_x2, a_y1, a_y2, c_x, c_y).
    """
    s = z / L
    lin0, lin1 = 1 - s, s
    b2, b3 = s * (1 - s), s * (1 - s) * (1 - 2 * s)
    out = {}
    for name, (n1, n2, bubbles) in {
        "x": (0, 4, {8: b2, 9: b3}),
        "y": (1, 5, {10: b2, 11: b3}),
        "theta_x": (2, 6, {12: b2}),
        "theta_y": (3, 7, {13: b2}),
    }.items():
        N = sp.zeros(1, 14)
        N[0, n1], N[0, n2] = lin0, lin1
        for j, f in bubbles.items():
            N[0, j] = f
        out[name] = N
    return out
