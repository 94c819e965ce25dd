"""Element matrices of the rotating Timoshenko shaft and the rigid disk, from energy integrals.

Every matrix is the Hessian of an energy written with the shape functions of
:mod:`derivations.shape_functions`:

* translational kinetic energy  T_t = 1/2 int rho A (x'^2 + y'^2) dz           -> M_t
* rotary kinetic energy         T_r = 1/2 int rho I (theta_x'^2 + theta_y'^2) dz -> M_r
* gyroscopic kinetic energy     T_g = Omega int rho (2 I) theta_x' theta_y dz    -> G, K_G
* strain energy                 U   = 1/2 int [EI (psi_xz'^2 + psi_yz'^2)
                                        + kappa G A ((x' - psi_xz)^2 + (y' - psi_yz)^2)] dz -> K

with (.)' a time derivative in T and a z derivative in U. ``kappa G A`` is eliminated in
favour of the shear parameter ``phi = 12 EI / (kappa G A L^2)``.
For ``T_g = Omega qdot^T A q``, Lagrange's equations give
``d/dt (Omega A q) - Omega A^T qdot = Omega (A - A^T) qdot + Omega' A q``, so ``G = A - A^T``
and, when the spin speed varies, ``K_G = A`` multiplies the angular acceleration ``Omega'``:

    M q'' + (C + Omega G) q' + (K + Omega' K_G) q = F.

At constant speed the ``K_G`` term vanishes (Xu et al. 2016, Eq. 13); ``K_G`` is not skew: its
symmetric part depends on how the small rotations are defined (here theta_x, then theta_y, the
convention of the energy that gives G), so it is generated from the same ``T_g`` as ``G``.

References
----------
Nelson, H. D., J. Mech. Des. 102 (1980) 793-803, Eqs. (16)-(22) (element energies).
Xu et al., Shock and Vibration 2016, 6239281, Eq. (13) (M_T, M_R, G, K_B).
"""

from __future__ import annotations

import sympy as sp

from derivations.shape_functions import L, hierarchical_shape_functions, phi, spatial_shape_functions, z

rho, A, I, E = sp.symbols("rho A I E", positive=True)


def _integrate(expr: sp.Matrix) -> sp.Matrix:
    return expr.applyfunc(lambda e: sp.factor(sp.integrate(sp.expand(e), (z, 0, L))))


def shaft_matrices(formulation: str = "nelson") -> dict[str, sp.Matrix]:
    """Return the element matrices of a uniform Timoshenko shaft element.

    Parameters
    ----------
    formulation : {"nelson", "hierarchical"}
        ``"nelson"``: interdependent interpolation, 8x8 (nodal DOFs only).
        ``"hierarchical"``: cubic/quadratic interpolation with 6 internal bubble DOFs, 14x14.

    Returns
    -------
    dict
        ``"mass_translational"`` (rho, A, L, phi), ``"mass_rotary"`` (rho, I, L, phi),
        ``"stiffness"`` (E, I, L, phi), ``"gyroscopic"`` and ``"spin_acceleration"`` (rho, I, L, phi),
        each a sympy.Matrix, shape (8, 8), in the DOF order (x1, y1, theta_x1, theta_y1, x2, ...).
    """
    N = spatial_shape_functions() if formulation == "nelson" else hierarchical_shape_functions()
    Nx, Ny, Ntx, Nty = N["x"], N["y"], N["theta_x"], N["theta_y"]
    M_t = rho * A * _integrate(Nx.T * Nx + Ny.T * Ny)
    M_r = rho * I * _integrate(Ntx.T * Ntx + Nty.T * Nty)
    A_g = 2 * rho * I * _integrate(Ntx.T * Nty)
    G = A_g - A_g.T
    # Bending: psi_xz = theta_y, psi_yz = -theta_x.
    dpsi_xz, dpsi_yz = Nty.diff(z), -Ntx.diff(z)
    gamma_xz = Nx.diff(z) - Nty
    gamma_yz = Ny.diff(z) + Ntx
    kGA = 12 * E * I / (phi * L**2)
    K_b = E * I * _integrate(dpsi_xz.T * dpsi_xz + dpsi_yz.T * dpsi_yz)
    # The shear strain of the interdependent interpolation is proportional to phi, so the
    # shear energy stays finite as phi -> 0; cancel phi before integrating. (The hierarchical
    # element keeps kappa G A = 12 E I / (phi L^2): it needs phi > 0.)
    K_s = (kGA * (gamma_xz.T * gamma_xz + gamma_yz.T * gamma_yz)).applyfunc(sp.cancel)
    K = (K_b + _integrate(K_s)).applyfunc(sp.factor)
    return {
        "mass_translational": M_t.applyfunc(sp.factor),
        "mass_rotary": M_r.applyfunc(sp.factor),
        "stiffness": K,
        "gyroscopic": G.applyfunc(sp.factor),
        "spin_acceleration": A_g.applyfunc(sp.factor),
    }


def disk_matrices() -> dict[str, sp.Matrix]:
    """Return the 4x4 matrices of a rigid disk on one node.

    The disk's kinetic energy is T = 1/2 m (x'^2 + y'^2) + 1/2 I_d (theta_x'^2 + theta_y'^2)
    + I_p Omega theta_x' theta_y (+ const), whose Hessians give M, G and K_G.

    Returns
    -------
    dict
        ``"mass"`` (m, I_d), ``"gyroscopic"`` and ``"spin_acceleration"`` (I_p), sympy.Matrix, shape (4, 4).
    """
    m, I_d, I_p = sp.symbols("m I_d I_p", positive=True)
    qd = sp.Matrix(sp.symbols("xd yd txd tyd"))
    q = sp.Matrix(sp.symbols("x y tx ty"))
    T = sp.Rational(1, 2) * m * (qd[0] ** 2 + qd[1] ** 2)
    T += sp.Rational(1, 2) * I_d * (qd[2] ** 2 + qd[3] ** 2)
    T_g = I_p * qd[2] * q[3]  # per unit Omega
    M = sp.hessian(T, qd)
    A_g = sp.Matrix(4, 4, lambda i, j: sp.diff(T_g, qd[i], q[j]))
    return {"mass": M, "gyroscopic": A_g - A_g.T, "spin_acceleration": A_g}


def module_text() -> str:
    """Text of ``rotorred/_generated/timoshenko.py``."""
    from derivations.codegen import GeneratedFunction, render_module

    sh = shaft_matrices()
    dk = disk_matrices()
    m, I_d, I_p = sp.symbols("m I_d I_p", positive=True)
    order = "(x1, y1, theta_x1, theta_y1, x2, y2, theta_x2, theta_y2)"
    common = (
        "\n    Parameters\n    ----------\n    L : float\n        Element length (m).\n"
        "    phi : float\n        Shear parameter 12 E I / (kappa G A L^2) (-); 0 for Euler-Bernoulli.\n"
    )
    fns = [
        GeneratedFunction(
            "timoshenko_mass_translational", (L, rho, A, phi), sh["mass_translational"],
            f"Translational mass matrix of a Timoshenko shaft element.\n{common}"
            "    rho : float\n        Density (kg/m^3).\n    A : float\n        Cross-section area (m^2).\n\n"
            f"    Returns\n    -------\n    ndarray, shape (8, 8)\n        DOF order {order}.\n",
        ),
        GeneratedFunction(
            "timoshenko_mass_rotary", (L, rho, I, phi), sh["mass_rotary"],
            f"Rotary (section) inertia matrix of a Timoshenko shaft element.\n{common}"
            "    rho : float\n        Density (kg/m^3).\n    I : float\n        Diametral area moment (m^4).\n\n"
            f"    Returns\n    -------\n    ndarray, shape (8, 8)\n        DOF order {order}.\n",
        ),
        GeneratedFunction(
            "timoshenko_stiffness", (L, E, I, phi), sh["stiffness"],
            f"Bending-plus-shear stiffness matrix of a Timoshenko shaft element.\n{common}"
            "    E : float\n        Young's modulus (Pa).\n    I : float\n        Diametral area moment (m^4).\n\n"
            f"    Returns\n    -------\n    ndarray, shape (8, 8)\n        DOF order {order}.\n",
        ),
        GeneratedFunction(
            "timoshenko_gyroscopic", (L, rho, I, phi), sh["gyroscopic"],
            f"Gyroscopic matrix of a Timoshenko shaft element per unit spin speed (1 rad/s).\n{common}"
            "    rho : float\n        Density (kg/m^3).\n    I : float\n        Diametral area moment (m^4);"
            " the polar moment is 2 I.\n\n"
            f"    Returns\n    -------\n    ndarray, shape (8, 8)\n        Skew-symmetric, DOF order {order}.\n",
        ),
        GeneratedFunction(
            "timoshenko_spin_acceleration", (L, rho, I, phi), sh["spin_acceleration"],
            "Spin-acceleration matrix K_G of a Timoshenko shaft element per unit angular acceleration (1 rad/s^2).\n"
            f"{common}"
            "    rho : float\n        Density (kg/m^3).\n    I : float\n        Diametral area moment (m^4);"
            " the polar moment is 2 I.\n\n"
            f"    Returns\n    -------\n    ndarray, shape (8, 8)\n        ``A`` of ``G = A - A^T``, DOF order {order}.\n",
        ),
    ]
    hi = shaft_matrices("hierarchical")
    order_h = ("(x1, y1, theta_x1, theta_y1, x2, y2, theta_x2, theta_y2, a_x1, a_x2, a_y1, a_y2, c_x, c_y);"
               " a_*, c_* are internal bubble amplitudes (derivations/shape_functions.py)")
    for key, args, what, unit_doc in (
        ("mass_translational", (L, rho, A, phi), "Translational mass matrix",
         "    rho : float\n        Density (kg/m^3).\n    A : float\n        Cross-section area (m^2).\n"),
        ("mass_rotary", (L, rho, I, phi), "Rotary (section) inertia matrix",
         "    rho : float\n        Density (kg/m^3).\n    I : float\n        Diametral area moment (m^4).\n"),
        ("stiffness", (L, E, I, phi), "Bending-plus-shear stiffness matrix (phi > 0)",
         "    E : float\n        Young's modulus (Pa).\n    I : float\n        Diametral area moment (m^4).\n"),
        ("gyroscopic", (L, rho, I, phi), "Gyroscopic matrix per unit spin speed (1 rad/s)",
         "    rho : float\n        Density (kg/m^3).\n    I : float\n        Diametral area moment (m^4).\n"),
        ("spin_acceleration", (L, rho, I, phi),
         "Spin-acceleration matrix K_G per unit angular acceleration (1 rad/s^2)",
         "    rho : float\n        Density (kg/m^3).\n    I : float\n        Diametral area moment (m^4).\n"),
    ):
        fns.append(GeneratedFunction(
            f"hierarchical_{key}", args, hi[key],
            f"{what} of the hierarchical (cubic/quadratic) Timoshenko element.\n{common}{unit_doc}\n"
            f"    Returns\n    -------\n    ndarray, shape (14, 14)\n        DOF order {order_h}.\n"))
    fns += [
        GeneratedFunction(
            "disk_mass", (m, I_d), dk["mass"],
            "Mass matrix of a rigid disk.\n\n    Parameters\n    ----------\n"
            "    m : float\n        Mass (kg).\n    I_d : float\n        Diametral moment of inertia (kg m^2).\n\n"
            "    Returns\n    -------\n    ndarray, shape (4, 4)\n        DOF order (x, y, theta_x, theta_y).\n",
        ),
        GeneratedFunction(
            "disk_gyroscopic", (I_p,), dk["gyroscopic"],
            "Gyroscopic matrix of a rigid disk per unit spin speed (1 rad/s).\n\n"
            "    Parameters\n    ----------\n    I_p : float\n        Polar moment of inertia (kg m^2).\n\n"
            "    Returns\n    -------\n    ndarray, shape (4, 4)\n        DOF order (x, y, theta_x, theta_y).\n",
        ),
        GeneratedFunction(
            "disk_spin_acceleration", (I_p,), dk["spin_acceleration"],
            "Spin-acceleration matrix K_G of a rigid disk per unit angular acceleration (1 rad/s^2).\n\n"
            "    Parameters\n    ----------\n    I_p : float\n        Polar moment of inertia (kg m^2).\n\n"
            "    Returns\n    -------\n    ndarray, shape (4, 4)\n        ``A`` of ``G = A - A^T``,"
            " DOF order (x, y, theta_x, theta_y).\n",
        ),
    ]
    doc = (
        "Timoshenko shaft element and rigid disk matrices.\n\n"
        "Derived in derivations/timoshenko.py from the interdependent shape functions of\n"
        "derivations/shape_functions.py (Nelson 1980; Friedman & Kosmatka 1993).\n"
        "Equation of motion: M q'' + (C + Omega G) q' + (K + Omega' K_G) q = F  (Xu et al. 2016, Eq. 13,\n"
        "with the spin acceleration Omega'; docs/model.md, Eq. (R2))."
    )
    return render_module("derivations/timoshenko.py", fns, doc)
