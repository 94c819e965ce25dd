"""The normal rub-impact law and its tangent (Xu et al. 2016, Eq. 8 with Eqs. 10-11).

Hertz contact with Hunt–Crossley damping on the local contact deformation ``delta`` (m)
(Eq. 8, the "nonlinear spring damping model"):

    F = K_nr delta^(3/2) (1 + c rate),

with ``rate`` the penetration rate (m/s) and ``c`` (s/m) the Hunt–Crossley coefficient.

The series coupling with the plate's bending (Eqs. 4, 10-11): the penetration ``p`` is shared
between the bending deflection ``W = lam F + w0`` and ``delta``, so the normal force solves
``R(F) = F - K_nr (p - w0 - lam F)^(3/2) (1 + c rate) = 0``. The integrator's Newton method
needs the tangent: dR/dF = 1 + lam dF/d(delta), dR/dp = -dF/d(delta), dR/d(rate) = -dF/d(rate)
(``normal_residual`` below, the one implementation of the law: the step kernel and
:func:`rotorred.transient.contact.normal_force` evaluate it, and the Hertz force alone is its
value at F = 0, lam = 0). The 3/2 power is written with the argument
``s = sqrt(p - w0 - lam F)`` so the generated code is polynomial (no ``sqrt``, safe at
``delta = 0`` where dF/d(delta) = 0); ``s = 0`` gives the open law R = F, dR/dF = 1 (the clamp of
:func:`rotorred.transient.contact.normal_law`).

The elastic energy stored in the contact, ``U = int_0^delta K_nr d^(3/2) dd = 2/5 K_nr delta^(5/2)``,
enters the energy balance of the tests. ``rate`` is the total approach rate p' (not the rate
``delta' = p' - lam F'`` of Eq. 8, which would make the law differential in F): the law then
dissipates ``F p' - d/dt(U + lam F^2 / 2) = c K_nr delta^(3/2) p' delta'`` (docs/model.md §4).
"""

from __future__ import annotations

import sympy as sp

s, rate, K_nr, c, lam, F, p, w0 = sp.symbols("s rate K_nr c lam F p w0", real=True)
delta = sp.Symbol("delta", positive=True)


def hertz_energy() -> sp.Matrix:
    """[U] = [int_0^delta K_nr d^(3/2) dd] as a function of (s, K_nr), shape (1, 1)."""
    d = sp.Symbol("d", positive=True)
    U = sp.integrate(K_nr * d ** sp.Rational(3, 2), (d, 0, delta))
    sq = sp.Symbol("sq", positive=True)
    return sp.Matrix([sp.expand(U.subs(delta, sq**2)).subs(sq, s)])


def normal_residual() -> sp.Matrix:
    """[R, dR/dF, dR/dp, dR/d(rate)] of R = F - K_nr (p - w0 - lam F)^(3/2) (1 + c rate), shape (4, 1).

    Arguments (F, s, rate, K_nr, c, lam) with ``s = sqrt(p - w0 - lam F)`` (the deformation
    left to Hertz contact); ``s = 0`` gives the law without contact force (R = F, dR/dF = 1).
    """
    dd = sp.Symbol("dd", positive=True)
    R = F - K_nr * dd ** sp.Rational(3, 2) * (1 + c * rate)
    # dd = p - w0 - lam F
    dR_dF = sp.diff(R, F) + sp.diff(R, dd) * (-lam)
    dR_dp = sp.diff(R, dd)
    dR_drate = sp.diff(R, rate)
    sq = sp.Symbol("sq", positive=True)
    return sp.Matrix([sp.expand(e.subs(dd, sq**2)).subs(sq, s) for e in (R, dR_dF, dR_dp, dR_drate)])


def module_text() -> str:
    """Text of ``rotorred/_generated/contact.py``."""
    from derivations.codegen import GeneratedFunction, render_module

    common = (
        "    s : float\n        Square root of the local contact deformation, sqrt(delta) (m^0.5), >= 0.\n"
    )
    fns = [
        GeneratedFunction(
            "hertz_energy", (s, K_nr), hertz_energy(),
            "Elastic energy of the Hertz contact, 2/5 K_nr delta^2.5.\n\n"
            "    Parameters\n    ----------\n" + common +
            "    K_nr : float\n        Hertz stiffness (N/m^1.5).\n\n"
            "    Returns\n    -------\n    ndarray, shape (1,)\n        [U] (J).\n",
        ),
        GeneratedFunction(
            "normal_residual", (F, s, rate, K_nr, c, lam), normal_residual(),
            "Residual of the normal force in series with plate bending and its tangent (Eqs. 8, 10-11).\n\n"
            "    R(F) = F - K_nr (p - w0 - lam F)^1.5 (1 + c rate), with s = sqrt(p - w0 - lam F).\n\n"
            "    Parameters\n    ----------\n    F : float\n        Normal force (N).\n" + common +
            "    rate : float\n        Penetration rate (m/s).\n"
            "    K_nr : float\n        Hertz stiffness (N/m^1.5).\n    c : float\n        Hunt–Crossley damping (s/m).\n"
            "    lam : float\n        Plate bending compliance (m/N).\n\n"
            "    Returns\n    -------\n    tuple of 4 floats\n        (R (N), dR/dF (-), dR/dp (N/m), dR/d(rate) (N s/m)).\n",
            returns="tuple",
        ),
    ]
    return render_module(
        "derivations/contact.py", fns,
        "Rub-impact contact law: Hertz force with Hunt–Crossley damping in series with plate bending,\n"
        "its tangent, and the Hertz energy.\n\n"
        "Derived in derivations/contact.py (Xu et al. 2016, Eqs. 8, 10-11). The 3/2 power is\n"
        "written with s = sqrt(delta) so every expression is a polynomial; rotorred.transient.contact\n"
        "applies the clamp (s = 0 without contact); the step kernel compiles normal_residual.")
