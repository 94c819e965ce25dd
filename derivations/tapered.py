"""Element matrices of a tapered (conical) Timoshenko shaft element, from the energy integrals of
:mod:`derivations.timoshenko` with the section varying along the element.

Between its nodes the outer and inner diameters vary linearly, ``d(xi) = d_l + (d_r - d_l) xi``,
``xi = z / L``, so the area is a quadratic and the diametral area moment a quartic in ``xi``:

    A(xi) = A0 + A1 xi + A2 xi^2,        I(xi) = I0 + I1 xi + I2 xi^2 + I3 xi^3 + I4 xi^4

(:func:`rotorred.model.elements.taper_coefficients`). The energies are integrated exactly with these
sections; the interpolation is the interdependent one of the uniform element, with the shear parameter
``phi`` of the mean section (the shape functions are the uniform beam's static solution), and the shear
energy ``1/2 int kappa G A(xi) gamma^2 dz`` uses the local area. With A1 = A2 = I1 = ... = I4 = 0 and
``kappa G = 12 E I0 / (phi A0 L^2)`` every matrix is the uniform element's (tested). The same
construction (mean-section phi, exact section integrals) is Genta's conical element as ROSS uses it.

References
----------
Nelson, H. D., J. Mech. Des. 102 (1980) 793-803 (the uniform element's energies).
Genta, G., Gugliotta, A., "A conical element for finite element rotor dynamics", J. Sound Vib. 120 (1988)
175-182 (the conical element).
"""

from __future__ import annotations

import sympy as sp

from derivations.shape_functions import L, phi, spatial_shape_functions, z

rho, E, kG = sp.symbols("rho E kG", positive=True)
A = sp.symbols("A0:3")
I = sp.symbols("I0:5")  # noqa: E741 - the textbook name of the area moment


def _integrate(weight, M: sp.Matrix) -> sp.Matrix:
    """``int_0^L weight N_i N_j dz`` of a symmetric integrand matrix, each entry collected in the section
    coefficients with factored coefficients (deterministic)."""
    out = sp.zeros(*M.shape)
    for i in range(M.shape[0]):
        for j in range(i, M.shape[1]):
            e = sp.integrate(sp.expand(weight * M[i, j]), (z, 0, L))
            out[i, j] = out[j, i] = sp.collect(sp.expand(e), list(A) + list(I), sp.factor)
    return out


def _integrate_full(weight, M: sp.Matrix) -> sp.Matrix:
    """The same for a matrix that is not symmetric."""
    return M.applyfunc(lambda e: sp.collect(sp.expand(sp.integrate(sp.expand(weight * e), (z, 0, L))),
                                            list(A) + list(I), sp.factor))


def tapered_matrices() -> dict[str, sp.Matrix]:
    """The 8x8 matrices of the tapered element, in the DOF order of the uniform one.

    Returns
    -------
    dict
        ``"mass_translational"`` (L, rho, A0..A2, phi), ``"mass_rotary"`` (L, rho, I0..I4, phi),
        ``"stiffness"`` (L, E, I0..I4, kG, A0..A2, phi), ``"spin_acceleration"`` (L, rho, I0..I4, phi);
        the gyroscopic matrix is ``A - A^T`` of the last.
    """
    xi = z / L
    A_z = sum(A[k] * xi**k for k in range(3))
    I_z = sum(I[k] * xi**k for k in range(5))
    N = spatial_shape_functions()
    Nx, Ny, Ntx, Nty = N["x"], N["y"], N["theta_x"], N["theta_y"]
    dpsi_xz, dpsi_yz = Nty.diff(z), -Ntx.diff(z)
    gamma_xz, gamma_yz = Nx.diff(z) - Nty, Ny.diff(z) + Ntx
    K = E * _integrate(I_z, dpsi_xz.T * dpsi_xz + dpsi_yz.T * dpsi_yz)
    K += kG * _integrate(A_z, gamma_xz.T * gamma_xz + gamma_yz.T * gamma_yz)
    return {
        "mass_translational": rho * _integrate(A_z, Nx.T * Nx + Ny.T * Ny),
        "mass_rotary": rho * _integrate(I_z, Ntx.T * Ntx + Nty.T * Nty),
        "stiffness": K.applyfunc(lambda e: sp.collect(sp.expand(e), list(A) + list(I) + [kG, E], sp.factor)),
        "spin_acceleration": 2 * rho * _integrate_full(I_z, Ntx.T * Nty),
    }


def module_text() -> str:
    """Text of ``rotorred/_generated/tapered.py``."""
    from derivations.codegen import GeneratedFunction, render_module

    m = tapered_matrices()
    order = "(x1, y1, theta_x1, theta_y1, x2, y2, theta_x2, theta_y2)"
    common = ("\n    Parameters\n    ----------\n    L : float\n        Element length (m).\n")
    area = "    A0, A1, A2 : float\n        A(xi) = A0 + A1 xi + A2 xi^2, xi = z / L (m^2).\n"
    moment = "    I0, I1, I2, I3, I4 : float\n        I(xi) = I0 + I1 xi + ... + I4 xi^4, diametral area moment (m^4).\n"
    phi_doc = "    phi : float\n        Shear parameter of the mean section, 12 E I / (kappa G A L^2) (-); 0: Euler-Bernoulli.\n"
    returns = f"\n    Returns\n    -------\n    ndarray, shape (8, 8)\n        DOF order {order}.\n"
    fns = [
        GeneratedFunction("tapered_mass_translational", (L, rho, *A, phi), m["mass_translational"],
                          f"Translational mass matrix of a tapered Timoshenko shaft element.\n{common}"
                          f"    rho : float\n        Density (kg/m^3).\n{area}{phi_doc}{returns}"),
        GeneratedFunction("tapered_mass_rotary", (L, rho, *I, phi), m["mass_rotary"],
                          f"Rotary (section) inertia matrix of a tapered Timoshenko shaft element.\n{common}"
                          f"    rho : float\n        Density (kg/m^3).\n{moment}{phi_doc}{returns}"),
        GeneratedFunction("tapered_stiffness", (L, E, *I, kG, *A, phi), m["stiffness"],
                          f"Bending-plus-shear stiffness matrix of a tapered Timoshenko shaft element.\n{common}"
                          f"    E : float\n        Young's modulus (Pa).\n{moment}"
                          f"    kG : float\n        kappa G, shear coefficient times shear modulus (Pa).\n{area}"
                          f"{phi_doc}{returns}"),
        GeneratedFunction("tapered_spin_acceleration", (L, rho, *I, phi), m["spin_acceleration"],
                          "Spin-acceleration matrix K_G of a tapered Timoshenko shaft element per unit angular "
                          f"acceleration (1 rad/s^2); the gyroscopic matrix per unit spin speed is K_G - K_G^T.\n"
                          f"{common}    rho : float\n        Density (kg/m^3).\n{moment}{phi_doc}{returns}"),
    ]
    doc = ("Tapered (conical) Timoshenko shaft element matrices.\n\n"
           "Derived in derivations/tapered.py: the energies of derivations/timoshenko.py integrated with the\n"
           "section of linearly varying diameters, the interdependent shape functions at the mean section's phi.")
    return render_module("derivations/tapered.py", fns, doc)
