"""Compiled step loop of the Newmark-β / HHT-α transient with implicit rub-impact contact.

Everything here is ``numba.njit(cache=True)``; no Python runs per step. The Python side
(:mod:`rotorred.transient.newmark`) builds the constant step matrices once per step size ("level":
``dt / 2**level``, used when a step must be halved) and calls :func:`run_steps` in chunks with a
few typed containers (namedtuples of arrays; the loop compiles without reference counting, :data:`LOOP`):

* :class:`Levels` -- the step matrices of every level;
* :class:`Forcing` -- the time functions of the external forces;
* :class:`Plates` -- the plates' parameters and the contact DOFs' selection;
* :class:`State` -- the state (rotor, contact DOFs, plates, contact forces), updated in place,
  with a spare set of the same buffers and the :class:`Work` arrays;
* :class:`Record` -- the record buffers and their plan;
* :class:`Settings` and :class:`Diagnostics` -- the solver's settings, its counters and the failure report.

One (sub)step from ``ta`` to ``tb = ta + h`` (HHT-α form, alpha = 0 is plain Newmark), in :func:`run_steps`:

1. Linear predictor ``q_lin`` (:func:`_linear_predictor`): the step with the new contact force
   set to zero. ``q_new = q_lin + (1+alpha) S f_new`` with ``A = c0 M + (1+alpha)(c3 D + K)`` and
   ``S = A^-1 B`` (B: the columns of the contact DOFs) is then the exact implicit step for any
   contact force ``f_new``. For Newmark (alpha = 0) the equation of motion holds at every step,
   ``M a = F + B f - D v - K q``, so ``a`` is eliminated from the predictor and
   ``q_lin = P_q q + P_v v + A^-1 F(tb) + Ha M^-1 (F(ta) + B f_old)`` costs two n x n products
   (``H = [P_q, P_v]``; for average acceleration ``Ha M^-1 = A^-1`` and ``H = [I - 2 A^-1 K, (4/h) A^-1 M]``,
   formed without ``M^-1``: :func:`rotorred.transient.matrices.level_matrices`); for HHT-α ``H = [Hq, Hv, Ha]`` acts on (q, v, a) and the old forces enter
   with ``-alpha A^-1``. The external forces are constants or sinusoids, so their values at ``ta``
   are a rotation of those at ``tb`` by the fixed step: both terms are folded into one set of
   vectors ``UF`` (per step size), evaluated with cos and sin at ``tb`` only.
2. Contact condensation (:func:`_condense_contact`): the disk displacements at the contact nodes,
   the plates' rigid DOFs and their velocities are affine in the unknown forces
   ``z = (P_0, T_0, P_1, T_1, ...)``: ``p = p_lin + Jp z`` (penetration), ``p' = p'_lin + c3 Jp z``,
   ``v_rel = v_lin + c3 Jv z`` (:class:`Condensed`).
3. Contact solve (:func:`_solve_contact_forces`): Newton on the contact residual
   (:func:`contact_residual`) with the analytic tangent of the law (the generated
   ``normal_residual`` through :func:`rotorred.transient.contact.normal_law`), with an active set
   for Coulomb friction: slip rows ``T + mu_d s P = 0``, stick rows ``v_rel = 0``; a slip whose
   ``v_rel`` reverses within the step becomes stick, a stick needing ``|T| > mu_s P`` becomes
   slip. The first guess extrapolates the forces of the last two steps. Every plate open at
   ``z = 0`` (the common case) skips Newton.
4. Newmark update (:func:`_update_contact`, :func:`_newmark_update`) of the contact DOFs, the
   plates and q, v, a; finiteness check.
5. Stick reset (:func:`_stick_reset`): for alpha = 0 the stick forces are corrected to zero
   relative acceleration.

After each main step the state is recorded (:func:`_record_step`). If the contact solve fails or
a value is not finite, the step is retried as two half steps, recursively (up to ``L - 1``
halvings), and then the main step size is resumed.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rotorred.transient import numba_cache
from rotorred.transient.contact_solve import (  # noqa: F401 - also read as kernel.<name> by newmark, matrices, tests
    C_CONTACT, C_MAXNEWTON, C_NEWTON, C_STEPS, C_SUBSTEPS, N_COUNTERS, N_PLATE_PAR, P_CLEAR, P_COS, P_MP, P_SIN, P_V,
    P_W0, Condensed, _kinematics, _normal_law, _open_plates, _solve_small, contact_residual, solve_contact)
from rotorred.transient.contact_solve import compiled_disk_force as _disk_force
from rotorred.transient.status import LIMIT, NEED_LEVELS, NEWTON_FAILED, NONFINITE, RUNNING

numba_cache.register()


#: numba options of the step loops (:func:`run_steps`, :func:`rotorred.transient.eigen_kernel.run_eigen_steps`,
#: :func:`rotorred.transient.ramp_kernel.run_ramp_steps`): cached on disk, and compiled without numba's reference
#: counting. Every array a loop touches is owned by its Python caller for the whole call and nothing in a loop
#: allocates, so the atomic count updates numba would emit for every array bound in the inlined steps (it cannot
#: prove most of them redundant, and they cost more than a step's arithmetic) are left out: they were two thirds of
#: the eigenbasis loop's unoptimised code. ``_nrt`` is the option behind numba's ``nrt`` flag; a loop that
#: allocated would fail to compile (numba finds no allocation without it), not run wrongly.
LOOP = {"cache": True, "_nrt": False}
#: numba options of a loop's cold path called from several sites (the state copy at a loop's exits): called, not
#: inlined, so that it compiles once rather than at every call site (numba types and lowers an inlined function
#: anew at each site: inlining ``_write_state`` at the dense loop's five exits took 5 s of its 19 s compilation);
#: no CPython wrapper, only compiled callers call it
COLD = {"cache": True, "no_cpython_wrapper": True}


# steps between exact re-evaluations of the forcing's cos/sin in the rotation recurrence
RESYNC = 1024

# columns of Record.plate
R_P, R_T, R_UN, R_UT, R_VREL, R_GAP = range(6)
N_PLATE_REC = 6
# Diagnostics.err: time of the failing step (s), DOF (or -1 - contact DOF), plate, status
E_TIME, E_DOF, E_PLATE, E_STATUS = range(4)


class Levels(NamedTuple):
    """Constant step matrices, one per step size ``h = dt / 2**level`` (leading axis: level, L of them).

    Attributes
    ----------
    H : ndarray, shape (L, n, n_hist)
        History map of the linear predictor: ``[P_q, P_v]`` on (q, v) for Newmark (n_hist = 2 n),
        ``[Hq, Hv, Ha]`` on (q, v, a) for HHT-α (n_hist = 3 n).
    UF : ndarray, shape (L, nf, n)
        Forcing vectors folded onto the end of the step: ``q_lin += sum_j w_j(tb) UF[j]`` (m per N).
    ST : ndarray, shape (L, m, n)
        ``(A^-1 B)^T``: displacement per unit new contact force (m/N), m = 2 n_p.
    S0T : ndarray, shape (L, m, n)
        The same for the previous step's contact force (``(Ha M^-1 B)^T``, which is ``(A^-1 B)^T`` for average
        acceleration, or ``-alpha (A^-1 B)^T``) (m/N).
    W : ndarray, shape (L, m, m)
        ``(1 + alpha) B^T A^-1 B``: contact-DOF displacement per unit contact force (m/N).
    Jp, Jv : ndarray, shape (L, n_p, m)
        The condensed contact operator: d(penetration)/dz and d(v_rel)/dz / c3 (m/N).
    plate : ndarray, shape (L, n_p, 2, 4)
        Per plate, (normal, tangential) x (hq, hv, ha, 1/A) of its scalar Newmark step.
    coef : ndarray, shape (L, 8)
        Newmark constants c0 ... c5, alpha, h.
    """

    H: np.ndarray
    UF: np.ndarray
    ST: np.ndarray
    S0T: np.ndarray
    W: np.ndarray
    Jp: np.ndarray
    Jv: np.ndarray
    plate: np.ndarray
    coef: np.ndarray


class Forcing(NamedTuple):
    """Time functions of the external force columns.

    Attributes
    ----------
    kind : ndarray of int64, shape (nf,)
        0 constant, 1 cos(omega t), 2 sin(omega t).
    omega : ndarray, shape (nf,)
        Angular frequency (rad/s).
    """

    kind: np.ndarray
    omega: np.ndarray


class Plates(NamedTuple):
    """The plates' parameters and the contact DOFs (x, y of each plate's node).

    Attributes
    ----------
    par : ndarray, shape (n_p, N_PLATE_PAR)
        Columns P_COS, P_SIN (normal n, -), P_CLEAR (m), P_W0 (m), P_LAM (m/N), P_K (N/m^1.5),
        P_C (s/m), P_MUS, P_MUD (-), P_V (disk surface speed Omega r, m/s), P_MP (kg).
    atol : ndarray, shape (n_p,)
        Absolute force tolerance of the contact Newton iteration (N).
    BT : ndarray, shape (m, n)
        ``B^T``: the contact DOFs as rows on q.
    MBT : ndarray, shape (m, n)
        ``(M^-1 B)^T`` (1/kg).
    G : ndarray, shape (m, m)
        ``B^T M^-1 B`` (1/kg).
    """

    par: np.ndarray
    atol: np.ndarray
    BT: np.ndarray
    MBT: np.ndarray
    G: np.ndarray


class State(NamedTuple):
    """The state after a step.

    Attributes
    ----------
    x : ndarray, shape (3 n,)
        q, v, a (model coordinates).
    xc : ndarray, shape (m, 3)
        Contact DOFs (x, y of each plate's node): displacement (m), velocity, acceleration.
    ps : ndarray, shape (n_p, 2, 3)
        Plates' rigid DOFs (normal, tangential) x (u (m), u' (m/s), u'' (m/s^2)).
    z : ndarray, shape (m,)
        Contact forces (P_0, T_0, P_1, ...) (N).
    mode : ndarray of int64, shape (n_p,)
        1 slip, 2 stick.
    sgn : ndarray, shape (n_p,)
        Slip direction, sign(v_rel).
    pinfo : ndarray, shape (n_p, 3)
        v_rel (m/s), gap (m), contact state (0 open, 1 slip, 2 stick).
    """

    x: np.ndarray
    xc: np.ndarray
    ps: np.ndarray
    z: np.ndarray
    mode: np.ndarray
    sgn: np.ndarray
    pinfo: np.ndarray


class Record(NamedTuple):
    """Record buffers: the state at step indices ``j >= start`` with ``(j - start) % every == 0``.

    Attributes
    ----------
    rows : ndarray, shape (n_out, n)
        Output rows on q.
    start, every : int
        First recorded step index and decimation.
    t : ndarray, shape (n_rec,)
        Times (s).
    y : ndarray, shape (n_rec, n_out)
        Outputs (m or rad).
    plate : ndarray, shape (n_rec, n_p, N_PLATE_REC)
        Columns R_P, R_T (N), R_UN, R_UT (m), R_VREL (m/s), R_GAP (m).
    state : ndarray of int8, shape (n_rec, n_p)
        Contact state (0 open, 1 slip, 2 stick).
    count : ndarray of int64, shape (1,)
        Records written.
    """

    rows: np.ndarray
    start: int
    every: int
    t: np.ndarray
    y: np.ndarray
    plate: np.ndarray
    state: np.ndarray
    count: np.ndarray


class Settings(NamedTuple):
    """Solver settings: start time t0 (s), main step dt (s), allowed halvings, Newton's relative tolerance
    and iteration budget, contact-DOF displacement limit (m)."""

    t0: float
    dt: float
    n_halvings: int
    newton_tol: float
    max_newton: int
    limit: float


class Diagnostics(NamedTuple):
    """Counters (int64, shape (N_COUNTERS,), C_*) and the failure report (shape (4,), E_*)."""

    counters: np.ndarray
    err: np.ndarray


class Work(NamedTuple):
    """Work arrays of :func:`run_steps` (n DOFs, n_p plates, m = 2 n_p, nf force columns)."""

    qn: np.ndarray      # (n,) the step's displacement
    frot: np.ndarray    # (m,) contact forces on the disks (F_x, F_y per plate)
    rlin: np.ndarray    # (m,) contact-DOF displacement at z = 0
    rdlin: np.ndarray   # (m,) and velocity
    p_lin: np.ndarray   # (n_p,) Condensed.p
    pd_lin: np.ndarray  # (n_p,) Condensed.pd
    v_lin: np.ndarray   # (n_p,) Condensed.v
    ulin: np.ndarray    # (n_p, 2) plate displacement at z = 0
    udlin: np.ndarray   # (n_p, 2) and velocity
    wv: np.ndarray      # (4, m) Newton vectors
    wm: np.ndarray      # (3, m, m) Newton matrices
    stuck: np.ndarray   # (n_p,) int64, sticking plates
    Hs: np.ndarray      # (n_p, n_p) stick reset matrix
    rs: np.ndarray      # (n_p,) its right-hand side
    dT: np.ndarray      # (n_p,) its solution
    Ws: np.ndarray      # (n_p, n_p) its work array
    fcos: np.ndarray    # (nf,) cos(omega t) at the end of the main step
    fsin: np.ndarray    # (nf,) sin(omega t)
    rot_c: np.ndarray   # (nf,) cos(omega dt)
    rot_s: np.ndarray   # (nf,) sin(omega dt)
    fval: np.ndarray    # (nf,) time functions at the end of the main step


# ----------------------------------------------------------------------------------- linear algebra
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


@njit(cache=True, inline="always")
def _add_columns(qn, f, cols, scale):
    """qn += scale f_j cols[j] for every non-zero f_j (cols: (m, n))."""
    for j in range(f.shape[0]):
        fj = scale * f[j]
        if fj != 0.0:
            for ii in range(qn.shape[0]):
                qn[ii] += fj * cols[j, ii]


@njit(cache=True, inline="always")
def _disk_forces(z, par, out):
    """out[2k], out[2k+1] = (F_x, F_y) on the disk of plate k (Eq. 12) for the forces z = (P_k, T_k)."""
    for k in range(par.shape[0]):
        fx, fy = _disk_force(z[2 * k], z[2 * k + 1], par[k, P_COS], par[k, P_SIN])
        out[2 * k] = fx
        out[2 * k + 1] = fy


# ----------------------------------------------------------------------------------- forcing
@njit(cache=True)
def _forcing_value(kind, omega, t):
    if kind == 0:
        return 1.0
    if kind == 1:
        return math.cos(omega * t)
    return math.sin(omega * t)


# The step functions below are inlined into run_steps (numba inline="always"): a call would pass
# every array of its containers (a few hundred machine words) per step.
@njit(cache=True, inline="always")
def _cos_sin(omega, t, c, s):
    """``c``, ``s``: cos and sin of each ``omega * t``."""
    for j in range(omega.shape[0]):
        c[j] = math.cos(omega[j] * t)
        s[j] = math.sin(omega[j] * t)


@njit(cache=True, inline="always")
def _start_forcing(forcing, dt, w):
    """The rotation of each sinusoid over one main step: cos and sin of omega dt."""
    _cos_sin(forcing.omega, dt, w.rot_c, w.rot_s)


@njit(cache=True, inline="always")
def _forcing_at_step_end(k, t_end, forcing, w):
    """``w.fval``: the time functions at the end ``t_end`` (s) of the chunk's ``k``-th main step.

    By an exact rotation recurrence (cos and sin of omega dt), re-synchronised with cos/sin every
    RESYNC steps (the recurrence's round-off grows like the number of steps, ~1e-13 over RESYNC).
    """
    if k % RESYNC == 0:
        for j in range(forcing.kind.shape[0]):
            w.fcos[j] = math.cos(forcing.omega[j] * t_end)
            w.fsin[j] = math.sin(forcing.omega[j] * t_end)
    else:
        for j in range(forcing.kind.shape[0]):
            c_old = w.fcos[j]
            w.fcos[j] = c_old * w.rot_c[j] - w.fsin[j] * w.rot_s[j]
            w.fsin[j] = w.fsin[j] * w.rot_c[j] + c_old * w.rot_s[j]
    for j in range(forcing.kind.shape[0]):
        kind = forcing.kind[j]
        w.fval[j] = 1.0 if kind == 0 else (w.fcos[j] if kind == 1 else w.fsin[j])


# ----------------------------------------------------------------------------------- the step
@njit(cache=True, inline="always")
def _linear_predictor(level, tb, cur, levels, forcing, plates, w):
    """``w.qn = H x + sum_j w_j(tb) UF_j + S0^T f_old``: the step's q at zero new contact force.

    A full main step (level 0) takes the time functions of ``w.fval``; a halved one evaluates them at ``tb``.
    """
    _matvec(levels.H[level], cur.x, w.qn)
    for j in range(forcing.kind.shape[0]):
        w1 = w.fval[j] if level == 0 else _forcing_value(forcing.kind[j], forcing.omega[j], tb)
        for ii in range(w.qn.shape[0]):
            w.qn[ii] += w1 * levels.UF[level, j, ii]
    if plates.par.shape[0] > 0:
        _disk_forces(cur.z, plates.par, w.frot)
        _add_columns(w.qn, w.frot, levels.S0T[level], 1.0)


@njit(cache=True, inline="always")
def _condense_contact(l, cur, levels, plates, w):
    """Contact kinematics at zero new contact force (:class:`Condensed` p, pd, v in ``w``); True if any plate touches.

    Fills ``w.rlin`` (contact-DOF displacement, ``B^T w.qn``), then :func:`_condense_rlin`.
    """
    for j in range(cur.xc.shape[0]):
        s = 0.0
        for ii in range(w.qn.shape[0]):
            s += plates.BT[j, ii] * w.qn[ii]
        w.rlin[j] = s
    return _condense_rlin(l, cur, levels, plates, w)


@njit(cache=True, inline="always")
def _condense_rlin(l, cur, levels, plates, w):
    """From the contact-DOF displacement ``w.rlin`` at zero new contact force: ``w.rdlin`` (its velocity),
    ``w.ulin``/``w.udlin`` (plate displacement and velocity), then the penetration, its rate and v_rel of each
    plate; True if any plate touches."""
    c3, c4, c5, alpha = levels.coef[l, 3], levels.coef[l, 4], levels.coef[l, 5], levels.coef[l, 6]
    for j in range(cur.xc.shape[0]):
        w.rdlin[j] = c3 * (w.rlin[j] - cur.xc[j, 0]) + c4 * cur.xc[j, 1] + c5 * cur.xc[j, 2]
    touching = False
    for k in range(plates.par.shape[0]):
        cs = plates.par[k, P_COS]
        sn = plates.par[k, P_SIN]
        for d in range(2):
            f0 = cur.z[2 * k] if d == 0 else -cur.z[2 * k + 1]
            u0 = cur.ps[k, d, 0]
            v0 = cur.ps[k, d, 1]
            a0 = cur.ps[k, d, 2]
            ul = (levels.plate[l, k, d, 0] * u0 + levels.plate[l, k, d, 1] * v0 + levels.plate[l, k, d, 2] * a0
                  - alpha * levels.plate[l, k, d, 3] * f0)
            w.ulin[k, d] = ul
            w.udlin[k, d] = c3 * (ul - u0) + c4 * v0 + c5 * a0
        dl = w.rlin[2 * k] * cs + w.rlin[2 * k + 1] * sn
        ddl = w.rdlin[2 * k] * cs + w.rdlin[2 * k + 1] * sn
        edl = -w.rdlin[2 * k] * sn + w.rdlin[2 * k + 1] * cs
        w.p_lin[k] = dl - plates.par[k, P_CLEAR] - w.ulin[k, 0] - plates.par[k, P_W0]
        w.pd_lin[k] = ddl - w.udlin[k, 0]
        w.v_lin[k] = plates.par[k, P_V] + edl - w.udlin[k, 1]
        if w.p_lin[k] > 0.0:
            touching = True
    return touching


@njit(cache=True, inline="always")
def _first_guess(extrapolate, cur, new):
    """Newton's start in ``new.z``: the linear extrapolation of the last two steps' forces (``new.z``
    holds the older one after the buffer swap) where both were in contact, else the last forces."""
    for k in range(cur.z.shape[0] // 2):
        for d in range(2):
            j = 2 * k + d
            g = 2.0 * cur.z[j] - new.z[j]
            if cur.z[2 * k] > 0.0 and new.z[2 * k] > 0.0 and extrapolate and math.isfinite(g):
                new.z[j] = g
            else:
                new.z[j] = cur.z[j]
        if new.z[2 * k] < 0.0:
            new.z[2 * k] = 0.0


@njit(cache=True, inline="always")
def _solve_contact_forces(touching, extrapolate, cond, cur, new, plates, settings, diag, w):
    """The step's contact forces and states into ``new.z``, ``new.mode``, ``new.sgn``; False if Newton failed."""
    if not touching:  # every plate open: no contact force, no Newton
        _open_plates(cond, new.z, new.mode, new.sgn)
        return True
    _first_guess(extrapolate, cur, new)
    for k in range(cur.mode.shape[0]):
        new.mode[k] = cur.mode[k]
        new.sgn[k] = cur.sgn[k]
    return solve_contact(new.z, cond, plates.par, new.mode, new.sgn, settings.newton_tol, plates.atol,
                         settings.max_newton, diag.counters, w.wv, w.wm)


@njit(cache=True, inline="always")
def _update_contact(l, touching, cond, cur, new, levels, plates, w):
    """The new contact forces' share of the step, and the Newmark update of the contact DOFs and plates.

    ``w.qn += (1 + alpha) S f``; ``new.xc`` (contact DOFs), ``new.ps`` (plates), ``new.pinfo``
    (v_rel, gap, state); the friction force of an open plate is set to zero.
    """
    _disk_forces(new.z, plates.par, w.frot)
    _add_columns(w.qn, w.frot, levels.ST[l], 1.0 + levels.coef[l, 6])
    _update_contact_dofs(l, touching, cond, cur, new, levels, plates, w)


@njit(cache=True, inline="always")
def _update_contact_dofs(l, touching, cond, cur, new, levels, plates, w):
    """The Newmark update of the contact DOFs (``r = w.rlin + W f``, f in ``w.frot``) and of the plates, and
    ``new.pinfo``; the friction force of an open plate is set to zero."""
    c0, c1, c2 = levels.coef[l, 0], levels.coef[l, 1], levels.coef[l, 2]
    c3, c4, c5, alpha = levels.coef[l, 3], levels.coef[l, 4], levels.coef[l, 5], levels.coef[l, 6]
    for j in range(cur.xc.shape[0]):
        r = w.rlin[j]
        if touching:
            for jj in range(cur.xc.shape[0]):
                r += levels.W[l, j, jj] * w.frot[jj]
        dr = r - cur.xc[j, 0]
        new.xc[j, 0] = r
        new.xc[j, 1] = c3 * dr + c4 * cur.xc[j, 1] + c5 * cur.xc[j, 2]
        new.xc[j, 2] = c0 * dr - c1 * cur.xc[j, 1] - c2 * cur.xc[j, 2]
    for k in range(plates.par.shape[0]):
        for d in range(2):
            f1 = new.z[2 * k] if d == 0 else -new.z[2 * k + 1]
            u = w.ulin[k, d] + (1.0 + alpha) * levels.plate[l, k, d, 3] * f1
            du = u - cur.ps[k, d, 0]
            new.ps[k, d, 0] = u
            new.ps[k, d, 1] = c3 * du + c4 * cur.ps[k, d, 1] + c5 * cur.ps[k, d, 2]
            new.ps[k, d, 2] = c0 * du - c1 * cur.ps[k, d, 1] - c2 * cur.ps[k, d, 2]
        if touching:
            p, pd, vr = _kinematics(new.z, cond, k)
        else:
            p = w.p_lin[k]
            vr = w.v_lin[k]
        new.pinfo[k, 0] = vr
        new.pinfo[k, 1] = -(p + plates.par[k, P_W0])  # gap
        if new.z[2 * k] == 0.0:
            new.z[2 * k + 1] = 0.0
            new.pinfo[k, 2] = 0.0
        else:
            new.pinfo[k, 2] = 2.0 if new.mode[k] == 2 else 1.0


@njit(cache=True, inline="always")
def _newmark_update(l, cur, new, levels, diag, w):
    """``new.x`` = (q, v, a) from ``q = w.qn``; NONFINITE (with the DOF in ``diag.err``) if not finite."""
    c0, c1, c2 = levels.coef[l, 0], levels.coef[l, 1], levels.coef[l, 2]
    c3, c4, c5 = levels.coef[l, 3], levels.coef[l, 4], levels.coef[l, 5]
    n = w.qn.shape[0]
    total = 0.0
    for ii in range(n):
        dq = w.qn[ii] - cur.x[ii]
        vi = c3 * dq + c4 * cur.x[n + ii] + c5 * cur.x[2 * n + ii]
        ai = c0 * dq - c1 * cur.x[n + ii] - c2 * cur.x[2 * n + ii]
        new.x[ii] = w.qn[ii]
        new.x[n + ii] = vi
        new.x[2 * n + ii] = ai
        total += w.qn[ii] + vi
    if math.isfinite(total):
        return RUNNING
    for ii in range(3 * n):
        if not math.isfinite(new.x[ii]):
            diag.err[E_DOF] = ii % n
            break
    return NONFINITE


@njit(cache=True, inline="always")
def _stick_reset(new, plates, w):
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
    ns = 0
    for k in range(plates.par.shape[0]):
        if new.mode[k] == 2 and new.z[2 * k] > 0.0:
            w.stuck[ns] = k
            ns += 1
    if ns == 0:
        return
    for a in range(ns):
        k = w.stuck[a]
        tx = -plates.par[k, P_SIN]
        ty = plates.par[k, P_COS]
        w.rs[a] = new.xc[2 * k, 2] * tx + new.xc[2 * k + 1, 2] * ty - new.ps[k, 1, 2]
        for b in range(ns):
            j = w.stuck[b]
            sx = -plates.par[j, P_SIN]
            sy = plates.par[j, P_COS]
            w.Hs[a, b] = (tx * (plates.G[2 * k, 2 * j] * sx + plates.G[2 * k, 2 * j + 1] * sy)
                          + ty * (plates.G[2 * k + 1, 2 * j] * sx + plates.G[2 * k + 1, 2 * j + 1] * sy))
        w.Hs[a, a] += 1.0 / plates.par[k, P_MP]
    if not _solve_small(w.Hs[:ns, :ns], w.rs[:ns], w.dT[:ns], w.Ws[:ns, :ns]):
        return
    n = plates.MBT.shape[1]
    for b in range(ns):
        j = w.stuck[b]
        d = w.dT[b]
        new.z[2 * j + 1] += d
        fx, fy = _disk_force(0.0, d, plates.par[j, P_COS], plates.par[j, P_SIN])  # friction increment on the disk
        for i in range(n):
            new.x[2 * n + i] += plates.MBT[2 * j, i] * fx + plates.MBT[2 * j + 1, i] * fy
        for i in range(new.xc.shape[0]):
            new.xc[i, 2] += plates.G[i, 2 * j] * fx + plates.G[i, 2 * j + 1] * fy
        new.ps[j, 1, 2] -= d / plates.par[j, P_MP]


@njit(cache=True, inline="always")
def _failed_plate(w, diag):
    """NEWTON_FAILED, with the first touching plate in ``diag.err``."""
    for k in range(w.p_lin.shape[0]):
        if w.p_lin[k] > 0.0:
            diag.err[E_PLATE] = k
            break
    return NEWTON_FAILED


@njit(cache=True, inline="always")
def _beyond_limit(xc, limit):
    """Index of the first contact DOF displaced beyond ``limit`` (m), or -1."""
    for j in range(xc.shape[0]):
        if abs(xc[j, 0]) > limit:
            return j
    return -1


# ----------------------------------------------------------------------------------- records, buffers
@njit(cache=True, inline="always")
def _record(idx, t, s, record):
    """Write the state ``s`` at time ``t`` (s) into record row ``idx``."""
    record.t[idx] = t
    _matvec(record.rows, s.x, record.y[idx])  # vectorised sums (a sequential one per row is latency-bound)
    for k in range(s.ps.shape[0]):
        record.plate[idx, k, R_P] = s.z[2 * k]
        record.plate[idx, k, R_T] = s.z[2 * k + 1]
        record.plate[idx, k, R_UN] = s.ps[k, 0, 0]
        record.plate[idx, k, R_UT] = s.ps[k, 1, 0]
        record.plate[idx, k, R_VREL] = s.pinfo[k, 0]
        record.plate[idx, k, R_GAP] = s.pinfo[k, 1]
        record.state[idx, k] = np.int8(s.pinfo[k, 2])


@njit(cache=True, inline="always")
def _record_step(j, t, s, record):
    """Record the state after step index ``j`` (time ``t``) if the plan asks for it and there is room."""
    if j >= record.start and (j - record.start) % record.every == 0:
        idx = record.count[0]
        if idx < record.t.shape[0]:
            _record(idx, t, s, record)
            record.count[0] = idx + 1


@njit(cache=True, inline="always")
def _stop_at_limit(t, j, cur, state, diag):
    """LIMIT, with the time ``t`` (s) and contact DOF ``j`` in ``diag.err`` and ``cur`` written to ``state``."""
    diag.err[E_TIME] = t
    diag.err[E_DOF] = -1 - j
    diag.err[E_STATUS] = LIMIT
    _write_state(cur, state)
    return LIMIT


@njit(cache=True, inline="always")
def _copy1(src, dst):
    """``dst[:] = src`` element by element (1-D): numba's slice assignment compiles its broadcast error messages
    (string formatting, 6 s of the kernel's compilation once), a flat ``reshape`` its shape checks."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@njit(cache=True, inline="always")
def _copy2(src, dst):
    """``dst[:, :] = src`` element by element (2-D)."""
    for i in range(src.shape[0]):
        _copy1(src[i], dst[i])


@njit(**COLD)
def _write_state(src, dst):
    """Copy the state ``src`` into ``dst``."""
    _copy1(src.x, dst.x)
    _copy2(src.xc, dst.xc)
    for k in range(src.ps.shape[0]):
        _copy2(src.ps[k], dst.ps[k])
    _copy1(src.z, dst.z)
    _copy1(src.mode, dst.mode)
    _copy1(src.sgn, dst.sgn)
    _copy2(src.pinfo, dst.pinfo)


def work_arrays(n: int, n_p: int, nf: int) -> Work:
    """Empty work arrays of :func:`run_steps` for n DOFs, n_p plates and nf force columns (Python side)."""
    m = 2 * n_p
    return Work(qn=np.empty(n), frot=np.empty(m), rlin=np.empty(m), rdlin=np.empty(m), p_lin=np.empty(n_p),
                pd_lin=np.empty(n_p), v_lin=np.empty(n_p), ulin=np.empty((n_p, 2)), udlin=np.empty((n_p, 2)),
                wv=np.empty((4, m)), wm=np.empty((3, m, m)), stuck=np.empty(n_p, dtype=np.int64),
                Hs=np.empty((n_p, n_p)), rs=np.empty(n_p), dT=np.empty(n_p), Ws=np.empty((n_p, n_p)),
                fcos=np.empty(nf), fsin=np.empty(nf), rot_c=np.empty(nf), rot_s=np.empty(nf), fval=np.empty(nf))


def spare_state(state: State) -> State:
    """A second set of state buffers (a copy of ``state``): :func:`run_steps` writes each step into one from the other."""
    return State(*(a.copy() for a in state))


# ----------------------------------------------------------------------------------- the loop
@njit(**LOOP)
def run_steps(i_begin, i_end, levels, forcing, plates, state, spare, work, record, settings, diag):
    """Advance main steps ``i_begin .. i_end - 1`` (time ``t0 + i dt`` to ``t0 + (i+1) dt``).

    Parameters
    ----------
    i_begin, i_end : int
        Main step indices of this chunk.
    levels : Levels
    forcing : Forcing
    plates : Plates
    state : State
        Updated in place to the state after the last completed step.
    spare : State
        Second state buffers (:func:`spare_state`): each step is written from one set into the other.
    work : Work
        Work arrays (:func:`work_arrays`).
    record : Record
        Records are written for step indices ``j >= record.start`` with
        ``(j - record.start) % record.every == 0`` (index j = state at time t0 + j dt).
    settings : Settings
    diag : Diagnostics
        Counters are incremented; ``diag.err`` receives (time, dof, plate, status) on failure.

    Returns
    -------
    int
        RUNNING when the chunk completed, else the failure code.
    """
    cur, new, w = state, spare, work  # the current and new state swap buffers each step
    t0, dt, n_halvings = settings.t0, settings.dt, settings.n_halvings
    if i_begin == 0 and record.start == 0 and record.count[0] == 0:
        _record(0, t0, cur, record)
        record.count[0] = 1
    units_total = 1 << n_halvings
    extrapolate = False  # new.z holds the previous step's forces only after a committed step
    _start_forcing(forcing, dt, w)
    for i in range(i_begin, i_end):
        t_main = t0 + i * dt
        _forcing_at_step_end(i - i_begin, t0 + (i + 1) * dt, forcing, w)
        level = 0
        progress = 0
        while progress < units_total:
            h_units = 1 << (n_halvings - level)
            ta = t_main + progress * (dt / units_total)
            tb = ta + h_units * (dt / units_total)
            if progress + h_units == units_total:
                tb = t0 + (i + 1) * dt
            # one (sub)step at `level` ending at tb, from cur into new (written out, not an inlined function: numba
            # copies an inlined function's IR block by block with its whole scope, 4 s of this loop's compilation)
            _linear_predictor(level, tb, cur, levels, forcing, plates, w)
            status = RUNNING
            if plates.par.shape[0] > 0:
                touching = _condense_contact(level, cur, levels, plates, w)
                cond = Condensed(w.p_lin, w.pd_lin, w.v_lin, levels.Jp[level], levels.Jv[level], levels.coef[level, 3])
                if _solve_contact_forces(touching, extrapolate, cond, cur, new, plates, settings, diag, w):
                    _update_contact(level, touching, cond, cur, new, levels, plates, w)
                else:
                    status = _failed_plate(w, diag)
            if status == RUNNING:
                status = _newmark_update(level, cur, new, levels, diag, w)
                if status == RUNNING and levels.coef[level, 6] == 0.0:
                    _stick_reset(new, plates, w)
            if status == RUNNING:
                j = _beyond_limit(new.xc, settings.limit)
                if j >= 0:
                    return _stop_at_limit(tb, j, cur, state, diag)
                cur, new = new, cur
                extrapolate = True
                progress += h_units
                if level > 0:
                    diag.counters[C_SUBSTEPS] += 1
            else:
                extrapolate = False
                level += 1
                if level > n_halvings:
                    diag.err[E_TIME] = tb
                    diag.err[E_STATUS] = status
                    _write_state(cur, state)
                    return status
                if level >= levels.H.shape[0]:  # level 0 failed (progress 0): cur is the main step's start
                    _write_state(cur, state)
                    return NEED_LEVELS
        diag.counters[C_STEPS] += 1
        _record_step(i + 1, t0 + (i + 1) * dt, cur, record)
    _write_state(cur, state)
    return RUNNING
