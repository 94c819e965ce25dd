"""Compiled solve of the condensed contact problem of one step: Newton with the law's tangent, Coulomb active set.

Called by the step loop of :mod:`rotorred.transient.kernel` (step 3 there). The unknowns are the
plates' forces ``z = (P_0, T_0, P_1, T_1, ...)`` (N); the kinematics are affine in them
(:class:`Condensed`). The normal law is the one of :mod:`rotorred.transient.contact`
(:func:`~rotorred.transient.contact.normal_law` over the generated ``normal_residual`` of
``derivations/contact.py``), compiled here. Everything is ``numba.njit(cache=True)``.
"""

from __future__ import annotations

import math
import types
from typing import NamedTuple

import numpy as np
from numba import njit

from rotorred._generated import contact as _gen
from rotorred.transient import contact, numba_cache

numba_cache.register()

# columns of Plates.par
P_COS, P_SIN, P_CLEAR, P_W0, P_LAM, P_K, P_C, P_MUS, P_MUD, P_V, P_MP = range(11)
N_PLATE_PAR = 11
# Diagnostics.counters
# (C_PASSES, C_MAXPASSES: fixed-point passes of the varying-speed step, rotorred.transient.ramp_kernel)
C_STEPS, C_NEWTON, C_SUBSTEPS, C_CONTACT, C_MAXNEWTON, C_ACTIVESET, C_PASSES, C_MAXPASSES = range(8)
N_COUNTERS = 8


def _compiled(fn, **callees):
    """``njit(cache=True)`` of the plain function ``fn``, its global names ``callees`` bound to compiled functions.

    ``fn`` itself stays plain Python for its Python callers; numba compiles the same code (numba
    freezes a function's globals when it compiles it, so this only chooses what they are).
    """
    scope = dict(fn.__globals__, **callees)
    clone = types.FunctionType(fn.__code__, scope, fn.__name__, fn.__defaults__, fn.__closure__)
    clone.__qualname__ = fn.__qualname__
    return njit(cache=True)(clone)


#: the contact law of rotorred.transient.contact, compiled: the generated residual (derivations/contact.py)
#: under the clamp of contact.normal_law, and the Eq. 12 force on the disk
_normal_residual = njit(cache=True)(_gen.normal_residual)
_normal_law = _compiled(contact.normal_law, _normal_residual=_normal_residual)
#: the normal force and its tangents (:func:`rotorred.transient.contact.normal_root`), compiled: harmonic balance calls
#: it at every AFT sample (:class:`rotorred.nonlinear.forces.PlateRub`)
compiled_normal_root = _compiled(contact.normal_root, normal_law=_normal_law)
#: the Eq. 12 force on the disk (:func:`rotorred.transient.contact.disk_force`), compiled: the step kernel's and harmonic
#: balance's
compiled_disk_force = njit(cache=True)(contact.disk_force)


class Condensed(NamedTuple):
    """The contact kinematics of one step, affine in the forces z (m = 2 n_p).

    Attributes
    ----------
    p, pd, v : ndarray, shape (n_p,)
        At z = 0: effective penetration p - w0 (m), its rate (m/s), sliding velocity (m/s).
    Jp, Jv : ndarray, shape (n_p, m)
        d(penetration)/dz and d(v_rel)/dz / c3 (m/N).
    c3 : float
        Newmark velocity factor gamma / (beta h) (1/s).
    """

    p: np.ndarray
    pd: np.ndarray
    v: np.ndarray
    Jp: np.ndarray
    Jv: np.ndarray
    c3: float


# ----------------------------------------------------------------------------------- contact solve
@njit(cache=True, no_cpython_wrapper=True)
def _solve_small(J, R, out, A):
    """Solve J out = -R (Gaussian elimination with partial pivoting, A a work array); False if singular."""
    m = R.shape[0]
    for i in range(m):
        for j in range(m):
            A[i, j] = J[i, j]
    b = out
    for i in range(m):
        b[i] = -R[i]
    for col in range(m):
        piv = col
        big = abs(A[col, col])
        for r in range(col + 1, m):
            if abs(A[r, col]) > big:
                big = abs(A[r, col])
                piv = r
        if big == 0.0 or not math.isfinite(big):
            return False
        if piv != col:
            for c in range(m):
                tmp = A[col, c]
                A[col, c] = A[piv, c]
                A[piv, c] = tmp
            tmp = b[col]
            b[col] = b[piv]
            b[piv] = tmp
        for r in range(col + 1, m):
            f = A[r, col] / A[col, col]
            if f != 0.0:
                for c in range(col, m):
                    A[r, c] -= f * A[col, c]
                b[r] -= f * b[col]
    for r in range(m - 1, -1, -1):
        s = b[r]
        for c in range(r + 1, m):
            s -= A[r, c] * b[c]
        b[r] = s / A[r, r]
    return True


@njit(cache=True, no_cpython_wrapper=True)
def _kinematics(z, cond, k):
    """Penetration - w0 (m), its rate (m/s) and v_rel (m/s) of plate ``k`` at the forces ``z``."""
    p = cond.p[k]
    pd = cond.pd[k]
    vr = cond.v[k]
    for j in range(z.shape[0]):
        p += cond.Jp[k, j] * z[j]
        pd += cond.c3 * cond.Jp[k, j] * z[j]
        vr += cond.c3 * cond.Jv[k, j] * z[j]
    return p, pd, vr


@njit(cache=True)
def contact_residual(z, cond, par, mode, sgn, R, J):
    """Residual and Jacobian of the condensed contact equations of one step.

    Parameters
    ----------
    z : ndarray, shape (2 n_p,)
        Unknown forces (P_0, T_0, P_1, T_1, ...) (N): P the normal force pressing the disk
        away from plate k, T the friction force on the disk along plate k's tangent.
    cond : Condensed
        The step's kinematics at z = 0 and their derivatives.
    par : ndarray, shape (n_p, N_PLATE_PAR)
        Plate parameters (:class:`Plates`).
    mode : ndarray of int, shape (n_p,)
        1 = slip, 2 = stick.
    sgn : ndarray, shape (n_p,)
        Slip direction sign(v_rel) of slipping plates.
    R : ndarray, shape (2 n_p,)
        Output residual (N): the normal law's residual, then the slip or stick row.
    J : ndarray, shape (2 n_p, 2 n_p)
        Output Jacobian dR/dz.
    """
    n_p = par.shape[0]
    m = 2 * n_p
    c3 = cond.c3
    for k in range(n_p):
        p, pd, vr = _kinematics(z, cond, k)
        P = z[2 * k]
        T = z[2 * k + 1]
        lam = par[k, P_LAM]
        law = _normal_law(P, p - lam * P, pd, par[k, P_K], par[k, P_C], lam)  # R, dR/dF, dR/dp, dR/drate
        R[2 * k] = law[0]
        g = law[2] + c3 * law[3]
        for j in range(m):
            J[2 * k, j] = g * cond.Jp[k, j]
        J[2 * k, 2 * k] += law[1]
        if mode[k] == 2:
            zeta = 1.0 / (c3 * cond.Jv[k, 2 * k + 1])
            R[2 * k + 1] = zeta * vr
            for j in range(m):
                J[2 * k + 1, j] = cond.Jv[k, j] / cond.Jv[k, 2 * k + 1]
        else:
            mu = par[k, P_MUD]
            R[2 * k + 1] = T + mu * sgn[k] * P
            for j in range(m):
                J[2 * k + 1, j] = 0.0
            J[2 * k + 1, 2 * k + 1] = 1.0
            J[2 * k + 1, 2 * k] = mu * sgn[k]


@njit(cache=True, inline="always")
def _newton(z, cond, par, mode, sgn, tol, atol, maxiter, counters, wv, wm):
    """Newton with backtracking on the contact residual; returns True on convergence.

    ``wv`` (4, m) and ``wm`` (3, m, m) are work arrays.
    """
    m = z.shape[0]
    R = wv[0]
    dz = wv[1]
    zt = wv[2]
    Rt = wv[3]
    J = wm[0]
    Jt = wm[1]
    contact_residual(z, cond, par, mode, sgn, R, J)
    merit = 0.0
    for i in range(m):
        merit += R[i] * R[i]
    for it in range(maxiter):
        counters[C_NEWTON] += 1
        if not _solve_small(J[:m, :m], R, dz, wm[2][:m, :m]):  # the stick reset's types ('A' slices): one compile
            return False
        small = True
        for k in range(m // 2):
            scale = tol * (abs(z[2 * k]) + abs(z[2 * k + 1])) + atol[k]
            if abs(dz[2 * k]) > scale or abs(dz[2 * k + 1]) > scale:
                small = False
        if small:  # quadratic convergence: the update is below tolerance, accept it as is
            for i in range(m):
                z[i] += dz[i]
            for k in range(m // 2):
                if z[2 * k] < 0.0:
                    z[2 * k] = 0.0
            if it + 1 > counters[C_MAXNEWTON]:
                counters[C_MAXNEWTON] = it + 1
            return True
        lam = 1.0
        for ls in range(12):
            for i in range(m):
                zt[i] = z[i] + lam * dz[i]
            for k in range(m // 2):
                if zt[2 * k] < 0.0:
                    zt[2 * k] = 0.0
            contact_residual(zt, cond, par, mode, sgn, Rt, Jt)
            mt = 0.0
            for i in range(m):
                mt += Rt[i] * Rt[i]
            if mt <= merit or small or not math.isfinite(merit):
                break
            lam *= 0.5
        if not math.isfinite(mt):
            return False
        for i in range(m):
            z[i] = zt[i]
            R[i] = Rt[i]
            for j in range(m):
                J[i, j] = Jt[i, j]
        merit = mt
        if small:
            if it + 1 > counters[C_MAXNEWTON]:
                counters[C_MAXNEWTON] = it + 1
            return True
    return False


@njit(cache=True, no_cpython_wrapper=True)
def solve_contact(z, cond, par, mode, sgn, tol, atol, maxiter, counters, wv, wm):
    """Solve the condensed contact problem of one step with the Coulomb active set.

    ``z``, ``mode`` and ``sgn`` hold the previous step's forces and states on entry (warm
    start) and the solution on exit. Returns True on success.
    """
    n_p = par.shape[0]
    # fast path: no plate touches when every force is zero
    any_contact = False
    for k in range(n_p):
        if cond.p[k] > 0.0:
            any_contact = True
    if not any_contact:
        _open_plates(cond, z, mode, sgn)
        return True
    counters[C_CONTACT] += 1
    for k in range(n_p):
        if z[2 * k] == 0.0:  # was open: start sliding in the predicted direction
            if cond.v[k] > 0.0:
                mode[k] = 1
                sgn[k] = 1.0
            elif cond.v[k] < 0.0:
                mode[k] = 1
                sgn[k] = -1.0
            else:
                mode[k] = 2
    for sweep in range(8):
        counters[C_ACTIVESET] += 1
        if not _newton(z, cond, par, mode, sgn, tol, atol, maxiter, counters, wv, wm):
            return False
        consistent = True
        for k in range(n_p):
            P = z[2 * k]
            T = z[2 * k + 1]
            p, pd, vr = _kinematics(z, cond, k)
            if mode[k] == 2:
                if abs(T) > par[k, P_MUS] * P * (1.0 + 1e-12) + atol[k]:
                    mode[k] = 1
                    sgn[k] = -1.0 if T > 0.0 else 1.0
                    consistent = False
            else:
                if P > 0.0 and sgn[k] * vr < 0.0:
                    mode[k] = 2
                    consistent = False
        if consistent:
            return True
    return False


@njit(cache=True, inline="always")
def _open_plates(cond, z, mode, sgn):
    """No contact force: z = 0, every plate slipping in the direction of its predicted v_rel."""
    for k in range(cond.v.shape[0]):
        z[2 * k] = 0.0
        z[2 * k + 1] = 0.0
        mode[k] = 1
        sgn[k] = 1.0 if cond.v[k] >= 0.0 else -1.0
