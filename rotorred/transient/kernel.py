"""Compiled step loop of the Newmark-β / HHT-α transient with implicit rub-impact contact.

Everything here is ``numba.njit(cache=True)``; no Python runs per step. The Python side
(:mod:`rotorred.transient.newmark`) builds the constant step matrices once per step size ("level":
``dt / 2**level``, used when a step must be halved) and calls :func:`run_steps` in chunks.

One (sub)step from ``ta`` to ``tb = ta + h`` (HHT-α form, alpha = 0 is plain Newmark):

1. Linear predictor ``q_lin``: the step with the new contact force set to zero,
   ``q_new = q_lin + (1+alpha) S f_new`` with ``A = c0 M + (1+alpha)(c3 D + K)`` and
   ``S = A^-1 B`` (B: the columns of the contact DOFs) is then the exact implicit step for any
   contact force ``f_new``. For Newmark (alpha = 0) the equation of motion holds at every step,
   ``M a = F + B f - D v - K q``, so ``a`` is eliminated from the predictor and
   ``q_lin = P_q q + P_v v + A^-1 F(tb) + Ha M^-1 (F(ta) + B f_old)`` costs two n x n products
   (``H = [P_q, P_v]``); for HHT-α ``H = [Hq, Hv, Ha]`` acts on (q, v, a) and the old forces enter
   with ``-alpha A^-1``. The external forces are constants or sinusoids, so their values at ``ta``
   are a rotation of those at ``tb`` by the fixed step: both terms are folded into one set of
   vectors ``UF`` (per step size), evaluated with cos and sin at ``tb`` only.
2. Condensation: the disk displacements at the contact nodes, the plates' rigid DOFs and their
   velocities are affine in the unknown forces ``z = (P_0, T_0, P_1, T_1, ...)``:
   ``p = p_lin + Jp z`` (penetration), ``p' = p'_lin + c3 Jp z``, ``v_rel = v_lin + c3 Jv z``.
3. Newton on the contact residual (:func:`contact_residual`) with the analytic tangent of the
   law (generated from ``derivations/contact.py``), with an active set for Coulomb friction:
   slip rows ``T + mu_d s P = 0``, stick rows ``v_rel = 0``; a slip whose ``v_rel`` reverses
   within the step becomes stick, a stick needing ``|T| > mu_s P`` becomes slip. The first guess
   extrapolates the forces of the last two steps. Every plate open at ``z = 0`` (the common
   case) skips Newton.
4. Newmark update of q, v, a and of the plates; finiteness check. For alpha = 0 the stick forces
   are then corrected to zero relative acceleration (:func:`_stick_acceleration_reset`).

If Newton fails or a value is not finite, the step is retried as two half steps, recursively
(up to ``L - 1`` halvings), and then the main step size is resumed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rotorred._generated import contact as _gen

_hunt_crossley = njit(cache=True)(_gen.hunt_crossley)

# status codes
RUNNING, DONE, NONFINITE, NEWTON_FAILED, LIMIT = 0, 1, 2, 3, 4
# steps between exact re-evaluations of the forcing's cos/sin in the rotation recurrence
RESYNC = 1024

# columns of the per-plate parameter array
P_COS, P_SIN, P_CLEAR, P_W0, P_LAM, P_K, P_C, P_MUS, P_MUD, P_V, P_MP = range(11)
N_PLATE_PAR = 11
# columns of the per-plate record
R_P, R_T, R_UN, R_UT, R_VREL, R_GAP = range(6)
N_PLATE_REC = 6
# counters
C_STEPS, C_NEWTON, C_SUBSTEPS, C_CONTACT, C_MAXNEWTON, C_ACTIVESET = range(6)


@njit(cache=True)
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


@njit(cache=True)
def contact_residual(z, p_lin, pd_lin, v_lin, Jp, Jv, c3, pp, mode, sgn, R, J):
    """Residual and Jacobian of the condensed contact equations of one step.

    Parameters
    ----------
    z : ndarray, shape (2 n_p,)
        Unknown forces (P_0, T_0, P_1, T_1, ...) (N): P the normal force pressing the disk
        away from plate k, T the friction force on the disk along plate k's tangent.
    p_lin, pd_lin, v_lin : ndarray, shape (n_p,)
        Effective penetration p - w0 (m), its rate (m/s) and the sliding velocity (m/s) at z = 0.
    Jp, Jv : ndarray, shape (n_p, 2 n_p)
        d(penetration)/dz and d(v_rel)/dz / c3 (m/N).
    c3 : float
        Newmark velocity factor gamma / (beta h) (1/s).
    pp : ndarray, shape (n_p, 10)
        Plate parameters (cos, sin, clearance, w0, lam, K_nr, c, mu_s, mu_d, Omega r).
    mode : ndarray of int, shape (n_p,)
        1 = slip, 2 = stick.
    sgn : ndarray, shape (n_p,)
        Slip direction sign(v_rel) of slipping plates.
    R : ndarray, shape (2 n_p,)
        Output residual (N).
    J : ndarray, shape (2 n_p, 2 n_p)
        Output Jacobian dR/dz.
    """
    n_p = pp.shape[0]
    m = 2 * n_p
    for k in range(n_p):
        p = p_lin[k]
        pd = pd_lin[k]
        vr = v_lin[k]
        for j in range(m):
            p += Jp[k, j] * z[j]
            pd += c3 * Jp[k, j] * z[j]
            vr += c3 * Jv[k, j] * z[j]
        P = z[2 * k]
        T = z[2 * k + 1]
        lam = pp[k, P_LAM]
        delta = p - lam * P
        F = 0.0
        Fd = 0.0
        Fr = 0.0
        if delta > 0.0 and 1.0 + pp[k, P_C] * pd > 0.0:
            out = _hunt_crossley(math.sqrt(delta), pd, pp[k, P_K], pp[k, P_C])
            F = out[0]
            Fd = out[1]
            Fr = out[2]
        R[2 * k] = P - F
        g = Fd + c3 * Fr
        for j in range(m):
            J[2 * k, j] = -g * Jp[k, j]
        J[2 * k, 2 * k] += 1.0 + Fd * lam
        if mode[k] == 2:
            zeta = 1.0 / (c3 * Jv[k, 2 * k + 1])
            R[2 * k + 1] = zeta * vr
            for j in range(m):
                J[2 * k + 1, j] = Jv[k, j] / Jv[k, 2 * k + 1]
        else:
            mu = pp[k, P_MUD]
            R[2 * k + 1] = T + mu * sgn[k] * P
            for j in range(m):
                J[2 * k + 1, j] = 0.0
            J[2 * k + 1, 2 * k + 1] = 1.0
            J[2 * k + 1, 2 * k] = mu * sgn[k]


@njit(cache=True)
def _kinematics(z, p_lin, pd_lin, v_lin, Jp, Jv, c3, k):
    p = p_lin[k]
    pd = pd_lin[k]
    vr = v_lin[k]
    for j in range(z.shape[0]):
        p += Jp[k, j] * z[j]
        pd += c3 * Jp[k, j] * z[j]
        vr += c3 * Jv[k, j] * z[j]
    return p, pd, vr


@njit(cache=True)
def _newton(z, p_lin, pd_lin, v_lin, Jp, Jv, c3, pp, mode, sgn, tol, atol, maxiter, counters, wv, wm):
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
    contact_residual(z, p_lin, pd_lin, v_lin, Jp, Jv, c3, pp, mode, sgn, R, J)
    merit = 0.0
    for i in range(m):
        merit += R[i] * R[i]
    for it in range(maxiter):
        counters[C_NEWTON] += 1
        if not _solve_small(J, R, dz, wm[2]):
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
            contact_residual(zt, p_lin, pd_lin, v_lin, Jp, Jv, c3, pp, mode, sgn, Rt, Jt)
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


@njit(cache=True)
def solve_contact(z, p_lin, pd_lin, v_lin, Jp, Jv, c3, pp, mode, sgn, tol, atol, maxiter, counters, wv, wm):
    """Solve the condensed contact problem of one step with the Coulomb active set.

    ``z``, ``mode`` and ``sgn`` hold the previous step's forces and states on entry (warm
    start) and the solution on exit. Returns True on success.
    """
    n_p = pp.shape[0]
    # fast path: no plate touches when every force is zero
    any_contact = False
    for k in range(n_p):
        if p_lin[k] > 0.0:
            any_contact = True
    if not any_contact:
        for k in range(n_p):
            z[2 * k] = 0.0
            z[2 * k + 1] = 0.0
            mode[k] = 1
            sgn[k] = 1.0 if v_lin[k] >= 0.0 else -1.0
        return True
    counters[C_CONTACT] += 1
    for k in range(n_p):
        if z[2 * k] == 0.0:  # was open: start sliding in the predicted direction
            if v_lin[k] > 0.0:
                mode[k] = 1
                sgn[k] = 1.0
            elif v_lin[k] < 0.0:
                mode[k] = 1
                sgn[k] = -1.0
            else:
                mode[k] = 2
    for sweep in range(8):
        counters[C_ACTIVESET] += 1
        if not _newton(z, p_lin, pd_lin, v_lin, Jp, Jv, c3, pp, mode, sgn, tol, atol, maxiter, counters, wv, wm):
            return False
        consistent = True
        for k in range(n_p):
            P = z[2 * k]
            T = z[2 * k + 1]
            p, pd, vr = _kinematics(z, p_lin, pd_lin, v_lin, Jp, Jv, c3, k)
            if mode[k] == 2:
                if abs(T) > pp[k, P_MUS] * P * (1.0 + 1e-12) + atol[k]:
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


@njit(cache=True, fastmath={"reassoc", "contract"})
def _matvec(H, x, out):
    """out = H x for H (n, k) C-contiguous; four rows at a time (the step's only O(n^2) work)."""
    n, k = H.shape
    i = 0
    while i + 4 <= n:
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        s3 = 0.0
        for j in range(k):
            xj = x[j]
            s0 += H[i, j] * xj
            s1 += H[i + 1, j] * xj
            s2 += H[i + 2, j] * xj
            s3 += H[i + 3, j] * xj
        out[i] = s0
        out[i + 1] = s1
        out[i + 2] = s2
        out[i + 3] = s3
        i += 4
    while i < n:
        s = 0.0
        for j in range(k):
            s += H[i, j] * x[j]
        out[i] = s
        i += 1


@njit(cache=True)
def _forcing_value(kind, omega, t):
    if kind == 0:
        return 1.0
    if kind == 1:
        return math.cos(omega * t)
    return math.sin(omega * t)


@njit(cache=True)
def _stick_acceleration_reset(x_new, xc_new, ps_new, z_new, mode_new, pp, MBT, Gm, n, stuck, Hs, rs, dT, Ws):
    """Make the relative tangential acceleration of sticking plates zero (Newmark, alpha = 0).

    The average-acceleration rule with the velocity constraint v_rel = 0 gives
    ``a_rel(n+1) = -a_rel(n)``: the velocity jump at the onset of stick leaves a relative
    acceleration that alternates in sign forever, and with it the stick force T (an undamped
    oscillation at the Nyquist frequency around the true stick force). After each step the
    stick forces are therefore corrected, with q and v fixed, to the values for which the
    relative acceleration is zero, and the accelerations are updated consistently
    (``a += M^-1 B dF``; equilibrium at t_{n+1} still holds). Once a_rel = 0 the constraint
    keeps it zero, so this changes only the step where stick begins (and round-off).
    """
    n_p = pp.shape[0]
    ns = 0
    for k in range(n_p):
        if mode_new[k] == 2 and z_new[2 * k] > 0.0:
            stuck[ns] = k
            ns += 1
    if ns == 0:
        return
    for a in range(ns):
        k = stuck[a]
        tx = -pp[k, P_SIN]
        ty = pp[k, P_COS]
        rs[a] = xc_new[2 * k, 2] * tx + xc_new[2 * k + 1, 2] * ty - ps_new[k, 1, 2]
        for b in range(ns):
            j = stuck[b]
            sx = -pp[j, P_SIN]
            sy = pp[j, P_COS]
            Hs[a, b] = (tx * (Gm[2 * k, 2 * j] * sx + Gm[2 * k, 2 * j + 1] * sy)
                        + ty * (Gm[2 * k + 1, 2 * j] * sx + Gm[2 * k + 1, 2 * j + 1] * sy))
        Hs[a, a] += 1.0 / pp[k, P_MP]
    if not _solve_small(Hs[:ns, :ns], rs[:ns], dT[:ns], Ws[:ns, :ns]):
        return
    for b in range(ns):
        j = stuck[b]
        d = dT[b]
        z_new[2 * j + 1] += d
        fx = -pp[j, P_SIN] * d
        fy = pp[j, P_COS] * d
        for i in range(n):
            x_new[2 * n + i] += MBT[2 * j, i] * fx + MBT[2 * j + 1, i] * fy
        for i in range(xc_new.shape[0]):
            xc_new[i, 2] += Gm[i, 2 * j] * fx + Gm[i, 2 * j + 1] * fy
        ps_new[j, 1, 2] -= d / pp[j, P_MP]


@njit(cache=True)
def _record(idx, t, x, rows, ps, z, pinfo, out_t, out_y, out_plate, out_state):
    n = rows.shape[1]
    out_t[idx] = t
    for r in range(rows.shape[0]):
        s = 0.0
        for i in range(n):
            s += rows[r, i] * x[i]
        out_y[idx, r] = s
    for k in range(ps.shape[0]):
        out_plate[idx, k, R_P] = z[2 * k]
        out_plate[idx, k, R_T] = z[2 * k + 1]
        out_plate[idx, k, R_UN] = ps[k, 0, 0]
        out_plate[idx, k, R_UT] = ps[k, 1, 0]
        out_plate[idx, k, R_VREL] = pinfo[k, 0]
        out_plate[idx, k, R_GAP] = pinfo[k, 1]
        out_state[idx, k] = np.int8(pinfo[k, 2])


@njit(cache=True)
def _write_back(x, xc, ps, z, mode, sgn, pinfo, x_io, xc_io, ps_io, z_io, mode_io, sgn_io, pinfo_io):
    x_io[:] = x
    xc_io[:] = xc
    ps_io[:] = ps
    z_io[:] = z
    mode_io[:] = mode
    sgn_io[:] = sgn
    pinfo_io[:] = pinfo


@njit(cache=True)
def run_steps(i_begin, i_end, t0, dt, n_levels_max,
              H, UF, f_kind, f_omega, ST, S0T, BT, Wm, Jp, Jv, pp, plvl, coef, MBT, Gm,
              x_io, xc_io, ps_io, z_io, mode_io, sgn_io, pinfo_io,
              rows, rec_start, rec_every, out_t, out_y, out_plate, out_state, rec_count,
              newton_tol, atol, maxiter, limit, counters, err):
    """Advance main steps ``i_begin .. i_end - 1`` (time ``t0 + i dt`` to ``t0 + (i+1) dt``).

    The state arrays (x = [q, v, a], xc, ps, z, mode, sgn, pinfo) are updated in place.
    Records are written for step indices ``j >= rec_start`` with ``(j - rec_start) % rec_every == 0``
    (index j = state at time t0 + j dt). ``err`` receives (time, dof, plate, status) on failure.

    Returns a status code: RUNNING when the chunk completed, else the failure code.
    """
    # work on local copies and swap current/new buffers each step; written back on return
    x = x_io.copy()
    xc = xc_io.copy()
    ps = ps_io.copy()
    z = z_io.copy()
    mode = mode_io.copy()
    sgn = sgn_io.copy()
    pinfo = pinfo_io.copy()
    n3 = x.shape[0]
    n = n3 // 3
    n_p = pp.shape[0]
    m = 2 * n_p
    nf = f_kind.shape[0]
    qn = np.empty(n)
    x_new = np.empty_like(x)
    xc_new = np.empty_like(xc)
    ps_new = np.empty_like(ps)
    z_new = np.empty_like(z)
    mode_new = np.empty_like(mode)
    sgn_new = np.empty_like(sgn)
    pinfo_new = np.empty_like(pinfo)
    frot = np.empty(m)
    rlin = np.empty(m)
    rdlin = np.empty(m)
    p_lin = np.empty(n_p)
    pd_lin = np.empty(n_p)
    v_lin = np.empty(n_p)
    ulin = np.empty((n_p, 2))
    udlin = np.empty((n_p, 2))
    wv = np.empty((4, m))
    wm = np.empty((3, m, m))
    stuck = np.empty(n_p, dtype=np.int64)
    Hs = np.empty((n_p, n_p))
    rs = np.empty(n_p)
    dT = np.empty(n_p)
    Ws = np.empty((n_p, n_p))
    if i_begin == 0 and rec_start == 0 and rec_count[0] == 0:
        _record(0, t0, x, rows, ps, z, pinfo, out_t, out_y, out_plate, out_state)
        rec_count[0] = 1
    units_total = 1 << n_levels_max
    extrapolate = False  # z_new holds the previous step's forces only after a committed step
    # Sinusoidal forcing at the end of each full main step, t = t0 + (i+1) dt, by an exact rotation
    # recurrence (cos and sin of omega dt), re-synchronised with cos/sin every RESYNC steps (the
    # recurrence's round-off grows like the number of steps, ~1e-13 over RESYNC); halved substeps
    # evaluate cos/sin directly.
    fcos = np.empty(nf)
    fsin = np.empty(nf)
    rot_c = np.empty(nf)
    rot_s = np.empty(nf)
    fval = np.empty(nf)
    for j in range(nf):
        rot_c[j] = math.cos(f_omega[j] * dt)
        rot_s[j] = math.sin(f_omega[j] * dt)
    for i in range(i_begin, i_end):
        t_main = t0 + i * dt
        if (i - i_begin) % RESYNC == 0:
            t_end_main = t0 + (i + 1) * dt
            for j in range(nf):
                fcos[j] = math.cos(f_omega[j] * t_end_main)
                fsin[j] = math.sin(f_omega[j] * t_end_main)
        else:
            for j in range(nf):
                c_old = fcos[j]
                fcos[j] = c_old * rot_c[j] - fsin[j] * rot_s[j]
                fsin[j] = fsin[j] * rot_c[j] + c_old * rot_s[j]
        for j in range(nf):
            kind = f_kind[j]
            fval[j] = 1.0 if kind == 0 else (fcos[j] if kind == 1 else fsin[j])
        level = 0
        progress = 0
        while progress < units_total:
            h_units = 1 << (n_levels_max - level)
            ta = t_main + progress * (dt / units_total)
            tb = ta + h_units * (dt / units_total)
            if progress + h_units == units_total:
                tb = t0 + (i + 1) * dt
            # ---------------- one (sub)step at level `level` from ta to tb ----------------
            l = level
            status = RUNNING
            c0 = coef[l, 0]
            c1 = coef[l, 1]
            c2 = coef[l, 2]
            c3 = coef[l, 3]
            c4 = coef[l, 4]
            c5 = coef[l, 5]
            alpha = coef[l, 6]
            _matvec(H[l], x, qn)
            for j in range(nf):
                w1 = fval[j] if level == 0 else _forcing_value(f_kind[j], f_omega[j], tb)
                for ii in range(n):
                    qn[ii] += w1 * UF[l, j, ii]
            if n_p > 0:
                for k in range(n_p):
                    P = z[2 * k]
                    T = z[2 * k + 1]
                    frot[2 * k] = -P * pp[k, P_COS] - T * pp[k, P_SIN]
                    frot[2 * k + 1] = -P * pp[k, P_SIN] + T * pp[k, P_COS]
                for j in range(m):
                    f = frot[j]
                    if f != 0.0:
                        for ii in range(n):
                            qn[ii] += f * S0T[l, j, ii]
                for j in range(m):
                    s = 0.0
                    for ii in range(n):
                        s += BT[j, ii] * qn[ii]
                    rlin[j] = s
                    rdlin[j] = c3 * (s - xc[j, 0]) + c4 * xc[j, 1] + c5 * xc[j, 2]
                for k in range(n_p):
                    cs = pp[k, P_COS]
                    sn = pp[k, P_SIN]
                    for d in range(2):
                        f0 = z[2 * k] if d == 0 else -z[2 * k + 1]
                        u0 = ps[k, d, 0]
                        v0 = ps[k, d, 1]
                        a0 = ps[k, d, 2]
                        ul = plvl[l, k, d, 0] * u0 + plvl[l, k, d, 1] * v0 + plvl[l, k, d, 2] * a0 \
                            - alpha * plvl[l, k, d, 3] * f0
                        ulin[k, d] = ul
                        udlin[k, d] = c3 * (ul - u0) + c4 * v0 + c5 * a0
                    dl = rlin[2 * k] * cs + rlin[2 * k + 1] * sn
                    ddl = rdlin[2 * k] * cs + rdlin[2 * k + 1] * sn
                    edl = -rdlin[2 * k] * sn + rdlin[2 * k + 1] * cs
                    p_lin[k] = dl - pp[k, P_CLEAR] - ulin[k, 0] - pp[k, P_W0]
                    pd_lin[k] = ddl - udlin[k, 0]
                    v_lin[k] = pp[k, P_V] + edl - udlin[k, 1]
                touching = False
                for k in range(n_p):
                    if p_lin[k] > 0.0:
                        touching = True
                ok = True
                if touching:
                    # initial guess: linear extrapolation of the last two forces (z_new still holds the
                    # previous step's forces after the buffer swap) where both were in contact
                    for k in range(n_p):
                        for d in range(2):
                            j = 2 * k + d
                            g = 2.0 * z[j] - z_new[j]
                            if z[2 * k] > 0.0 and z_new[2 * k] > 0.0 and extrapolate and math.isfinite(g):
                                z_new[j] = g
                            else:
                                z_new[j] = z[j]
                        if z_new[2 * k] < 0.0:
                            z_new[2 * k] = 0.0
                    for k in range(n_p):
                        mode_new[k] = mode[k]
                        sgn_new[k] = sgn[k]
                    ok = solve_contact(z_new, p_lin, pd_lin, v_lin, Jp[l], Jv[l], c3, pp, mode_new, sgn_new,
                                       newton_tol, atol, maxiter, counters, wv, wm)
                else:  # every plate open: no contact force, no Newton
                    for k in range(n_p):
                        z_new[2 * k] = 0.0
                        z_new[2 * k + 1] = 0.0
                        mode_new[k] = 1
                        sgn_new[k] = 1.0 if v_lin[k] >= 0.0 else -1.0
                if not ok:
                    for k in range(n_p):
                        if p_lin[k] > 0.0:
                            err[2] = k
                            break
                    status = NEWTON_FAILED
                else:
                    for k in range(n_p):
                        P = z_new[2 * k]
                        T = z_new[2 * k + 1]
                        frot[2 * k] = -P * pp[k, P_COS] - T * pp[k, P_SIN]
                        frot[2 * k + 1] = -P * pp[k, P_SIN] + T * pp[k, P_COS]
                    for j in range(m):
                        f = (1.0 + alpha) * frot[j]
                        if f != 0.0:
                            for ii in range(n):
                                qn[ii] += f * ST[l, j, ii]
                    for j in range(m):
                        r = rlin[j]
                        if touching:
                            for jj in range(m):
                                r += Wm[l, j, jj] * frot[jj]
                        dr = r - xc[j, 0]
                        xc_new[j, 0] = r
                        xc_new[j, 1] = c3 * dr + c4 * xc[j, 1] + c5 * xc[j, 2]
                        xc_new[j, 2] = c0 * dr - c1 * xc[j, 1] - c2 * xc[j, 2]
                    for k in range(n_p):
                        for d in range(2):
                            f1 = z_new[2 * k] if d == 0 else -z_new[2 * k + 1]
                            u = ulin[k, d] + (1.0 + alpha) * plvl[l, k, d, 3] * f1
                            du = u - ps[k, d, 0]
                            ps_new[k, d, 0] = u
                            ps_new[k, d, 1] = c3 * du + c4 * ps[k, d, 1] + c5 * ps[k, d, 2]
                            ps_new[k, d, 2] = c0 * du - c1 * ps[k, d, 1] - c2 * ps[k, d, 2]
                        if touching:
                            p, pd, vr = _kinematics(z_new, p_lin, pd_lin, v_lin, Jp[l], Jv[l], c3, k)
                        else:
                            p = p_lin[k]
                            vr = v_lin[k]
                        pinfo_new[k, 0] = vr
                        pinfo_new[k, 1] = -(p + pp[k, P_W0])  # gap
                        if z_new[2 * k] == 0.0:
                            z_new[2 * k + 1] = 0.0
                            pinfo_new[k, 2] = 0.0
                        else:
                            pinfo_new[k, 2] = 2.0 if mode_new[k] == 2 else 1.0
            if status == RUNNING:
                total = 0.0
                for ii in range(n):
                    dq = qn[ii] - x[ii]
                    vi = c3 * dq + c4 * x[n + ii] + c5 * x[2 * n + ii]
                    ai = c0 * dq - c1 * x[n + ii] - c2 * x[2 * n + ii]
                    x_new[ii] = qn[ii]
                    x_new[n + ii] = vi
                    x_new[2 * n + ii] = ai
                    total += qn[ii] + vi
                if not math.isfinite(total):
                    for ii in range(n3):
                        if not math.isfinite(x_new[ii]):
                            err[1] = ii % n
                            break
                    status = NONFINITE
            any_stick = False
            for k in range(n_p):
                if mode_new[k] == 2 and z_new[2 * k] > 0.0:
                    any_stick = True
            if status == RUNNING and alpha == 0.0 and any_stick:
                _stick_acceleration_reset(x_new, xc_new, ps_new, z_new, mode_new, pp, MBT, Gm, n,
                                          stuck, Hs, rs, dT, Ws)
            # ------------------------------------------------------------------------------
            if status == RUNNING:
                for j in range(m):
                    if abs(xc_new[j, 0]) > limit:
                        err[0] = tb
                        err[1] = -1 - j
                        err[3] = LIMIT
                        _write_back(x, xc, ps, z, mode, sgn, pinfo, x_io, xc_io, ps_io, z_io, mode_io, sgn_io, pinfo_io)
                        return LIMIT
                x, x_new = x_new, x
                extrapolate = True
                if n_p > 0:
                    xc, xc_new = xc_new, xc
                    ps, ps_new = ps_new, ps
                    z, z_new = z_new, z
                    mode, mode_new = mode_new, mode
                    sgn, sgn_new = sgn_new, sgn
                    pinfo, pinfo_new = pinfo_new, pinfo
                progress += h_units
                if level > 0:
                    counters[C_SUBSTEPS] += 1
            else:
                extrapolate = False
                level += 1
                if level > n_levels_max:
                    err[0] = tb
                    err[3] = status
                    _write_back(x, xc, ps, z, mode, sgn, pinfo, x_io, xc_io, ps_io, z_io, mode_io, sgn_io, pinfo_io)
                    return status
        counters[C_STEPS] += 1
        j = i + 1
        if j >= rec_start and (j - rec_start) % rec_every == 0:
            idx = rec_count[0]
            if idx < out_t.shape[0]:
                _record(idx, t0 + j * dt, x, rows, ps, z, pinfo, out_t, out_y, out_plate, out_state)
                rec_count[0] = idx + 1
    _write_back(x, xc, ps, z, mode, sgn, pinfo, x_io, xc_io, ps_io, z_io, mode_io, sgn_io, pinfo_io)
    return RUNNING
