"""Internal (rotating) damping: the rotating-frame damping of a shaft element in the fixed frame.

A shaft's material damping acts on the deformation rate seen in the frame that turns with the shaft.
With the element's DOFs in the fixed frame ``q`` and in the rotating frame ``q_r``, ``q = R(phi) q_r``,
``phi = Omega t``. The rotation ``R`` follows from rotating the deflection fields by ``phi`` about +z:
(x, y) turn as a plane vector, and so do the slopes (dx/dz, dy/dz); with theta_y = dx/dz and
theta_x = -dy/dz (docs/model.md §1) the rotations (theta_x, theta_y) turn alike. Each element's
``R(phi) = exp(phi J)`` with the *rotation generator* ``J`` (``J^2 = -I``: every DOF has its partner a
quarter turn on), derived here from the shape functions: ``N J = J_field N`` for all z.

The rotating-frame force ``f_r = -C_r q_r'`` with ``C_r = beta K`` (viscous, proportional to the element's
stiffness) becomes in the fixed frame, because ``K`` commutes with ``J`` (an axisymmetric element, checked
here) and so ``R C_r R^T = C_r``, and ``R' = Omega J R``:

    f = -R C_r d/dt (R^T q) = -C_r q' + Omega C_r J q,

i.e. the damping ``C_r`` and the circulatory (skew) stiffness ``-Omega C_r J`` on the left of the equation of
motion. For the Jeffcott rotor (one node, x + i y = z) this is m z'' + (c_e + c_i) z' + (k - i Omega c_i) z = 0,
unstable above Omega = omega_n (1 + c_e / c_i) (Genta 2005, Dynamics of Rotating Systems, §4.4, Eq. 4.47).

``python -m derivations`` writes :mod:`rotorred._generated.internal_damping` with ``J`` of the Nelson element
(8 DOFs: also the tapered element's, which has the same DOFs) and of the hierarchical element (14 DOFs).

References
----------
Zorzi, E. S., Nelson, H. D., "Finite element simulation of rotor-bearing systems with internal damping",
J. Eng. Power 99 (1977) 71-76 (C_r = beta K in the rotating frame, the circulatory term in the fixed one).
Genta, G., Dynamics of Rotating Systems, Springer 2005, §4.4.
"""

from __future__ import annotations

import sympy as sp

from derivations.shape_functions import hierarchical_shape_functions, spatial_shape_functions, z

phi_r, Omega, t = sp.symbols("phi Omega t", real=True)


def field_rotation() -> sp.Matrix:
    """``R_field(phi)`` of the fields (x, y, theta_x, theta_y) at a section: the fixed-frame fields of the
    rotating-frame ones, the deflection turned by ``phi`` about +z, shape (4, 4)."""
    rot = sp.Matrix([[sp.cos(phi_r), -sp.sin(phi_r)], [sp.sin(phi_r), sp.cos(phi_r)]])
    slope_of_theta = sp.Matrix([[0, 1], [-1, 0]])  # (dx/dz, dy/dz) = (theta_y, -theta_x)
    theta_rot = slope_of_theta.inv() * rot * slope_of_theta
    out = sp.zeros(4, 4)
    out[:2, :2] = rot
    out[2:, 2:] = theta_rot.applyfunc(sp.simplify)
    return out


def field_generator() -> sp.Matrix:
    """``J_field = dR_field/dphi`` at phi = 0, shape (4, 4)."""
    return field_rotation().diff(phi_r).subs(phi_r, 0)


def element_generator(formulation: str = "nelson") -> sp.Matrix:
    """The rotation generator ``J`` of an element's DOFs: ``N(z) J = J_field N(z)`` for every z, with ``N`` the
    (4, n) shape functions of (x, y, theta_x, theta_y); solved column by column (a polynomial identity in z)."""
    shapes = spatial_shape_functions() if formulation == "nelson" else hierarchical_shape_functions()
    N = sp.Matrix.vstack(*(shapes[k] for k in ("x", "y", "theta_x", "theta_y")))
    n = N.shape[1]
    target = field_generator() * N
    unknowns = sp.symbols(f"j0:{n}")
    columns = []
    for col in range(n):
        residual = N * sp.Matrix(unknowns) - target[:, col]
        equations = [c for e in residual for c in sp.Poly(sp.expand(e), z).all_coeffs()]
        solution = sp.solve(equations, unknowns, dict=True)
        if len(solution) != 1 or len(solution[0]) != n:
            raise ValueError(f"{formulation}: the rotation of DOF {col} is not a combination of the element's DOFs")
        columns.append([solution[0][u] for u in unknowns])
    J = sp.Matrix(columns).T
    if J * J != -sp.eye(n):
        raise ValueError(f"{formulation}: J^2 must be -I (every DOF paired a quarter turn on)")
    return J


def fixed_frame_force(K: sp.Matrix, J: sp.Matrix) -> sp.Matrix:
    """The fixed-frame force of the rotating-frame damping ``-beta K q_r'`` less ``-beta K q' + Omega beta K J q``:
    zero when ``K`` commutes with ``J`` (raises otherwise). Symbolic in the DOFs q(t) and Omega."""
    n = K.shape[0]
    if (K * J - J * K).applyfunc(sp.simplify) != sp.zeros(n, n):
        raise ValueError("K must commute with J (an axisymmetric element) for the rotating damping to be beta K")
    beta = sp.Symbol("beta", positive=True)
    q = sp.Matrix([sp.Function(f"q{i}")(t) for i in range(n)])
    angle = Omega * t
    R = sp.eye(n) + sp.sin(angle) * J + (1 - sp.cos(angle)) * J * J  # exp(angle J) with J^2 = -I
    q_r = R.T * q
    f = -R * (beta * K) * q_r.diff(t)
    expected = -beta * K * q.diff(t) + Omega * beta * K * J * q
    return (f - expected).applyfunc(lambda e: sp.simplify(sp.expand(e)))


def module_text() -> str:
    """Text of ``rotorred/_generated/internal_damping.py``."""
    from derivations.codegen import GeneratedFunction, render_module
    from derivations.timoshenko import shaft_matrices

    fns = []
    for formulation, name, order in (
            ("nelson", "timoshenko_spin_rotation", "(x1, y1, theta_x1, theta_y1, x2, y2, theta_x2, theta_y2)"),
            ("hierarchical", "hierarchical_spin_rotation",
             "(x1, y1, theta_x1, theta_y1, x2, y2, theta_x2, theta_y2, a_x1, a_x2, a_y1, a_y2, c_x, c_y)")):
        J = element_generator(formulation)
        K = shaft_matrices(formulation)["stiffness"]
        if fixed_frame_force(K, J) != sp.zeros(K.shape[0], 1):
            raise ValueError(f"{formulation}: the fixed-frame force is not -beta K q' + Omega beta K J q")
        n = J.shape[0]
        fns.append(GeneratedFunction(
            name, (), J,
            f"Rotation generator J of the {formulation} element's DOFs: q = exp(Omega t J) q_r.\n\n"
            "    The rotating-frame damping beta K acts in the fixed frame as the damping beta K and the\n"
            "    circulatory stiffness -Omega beta K J (derivations/internal_damping.py).\n\n"
            f"    Returns\n    -------\n    ndarray, shape ({n}, {n})\n        J^2 = -I, DOF order {order}.\n"))
    doc = ("Rotation generators of the shaft elements' DOFs (internal, rotating damping).\n\n"
           "Derived in derivations/internal_damping.py: q = exp(Omega t J) q_r between the fixed and the\n"
           "rotating frame; the rotating damping beta K gives beta K q' + (-Omega beta K J) q in the fixed frame.")
    return render_module("derivations/internal_damping.py", fns, doc)
