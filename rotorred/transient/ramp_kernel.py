"""Compiled step loop of the Newmark transient at spool speeds that vary in time (run-ups, coast-downs).

The equation of motion with speeds ``Omega_s(t)`` (docs/model.md, Eqs. R1-R3) is

    M q'' + (C + sum_s Omega_s G_s) q' + (K + sum_s Omega_s' K_G,s - sum_s Omega_s N_s) q = F_u(t) + F_g + B f,

(``N_s`` the circulatory matrix of spool s's internal damping, docs/model.md §19), with the unbalance forces of
:mod:`rotorred.transient.matrices` at the spin angle ``phi_s(t)``.
Average-acceleration Newmark (gamma = 1/2, beta = 1/4) with the equation at both ends of a step
(``a`` eliminated through the equation at ``ta``) gives, with ``D_i, K_i`` at ``t_i``,

    A_1 dq = F_0 + F_1 + B (f_0 + f_1) + (4/h) M v_0 - (K_0 + K_1) q_0 + (D_1 - D_0) v_0,
    A_1 = (4/h^2) M + (2/h) D_1 + K_1.

``A_1`` changes every step. It is split as ``A_1 = A_r + E_1`` with ``A_r`` the matrix at the reference
speeds ``Omega_r`` and accelerations ``Omega_r'`` of the current speed interval (factorised once per
interval by :mod:`rotorred.transient.ramp`), so that

    dq = dq_r + sum_s P_s [(Omega_s1 - Omega_s0) v_0 - (2/h) delta_s dq]
              - sum_s Q_s [(Omega_s0' + Omega_s1' - 2 Omega_sr') q_0 + epsilon_s dq]
              - sum_s S_s [(Omega_s0 + Omega_s1 - 2 Omega_sr) q_0 + delta_s dq],

with ``dq_r`` the constant-speed step at the reference (the kernel's own predictor and contact
condensation, :mod:`rotorred.transient.kernel`), ``P_s = A_r^-1 G_s``, ``Q_s = A_r^-1 K_G,s``,
``S_s = -A_r^-1 N_s`` (only where a spool has internal damping: then every spool has the third block),
``delta_s = Omega_s1 - Omega_sr`` and ``epsilon_s = Omega_s1' - Omega_sr'``. The ``dq`` on the right is the
step's own: the step is solved by fixed-point passes, each a linear predictor plus the exact
implicit contact solve, until ``dq`` is converged (:func:`_ramp_substep`). The map contracts
by ``rho <= sum_s (2/h) |delta_s| ||P_s|| + |epsilon_s| ||Q_s|| + |delta_s| ||S_s||`` (``Varying.rho``, kept small
by the interval length), so a converged pass is the exact implicit step with ``A_1``; a step that does not
converge within ``Varying.max_passes`` is halved like a failed contact solve.

One matrix-vector product with ``R = [P_0, Q_0, P_1, Q_1, ..., (S_0, S_1, ...)]`` per pass; without contact a pass is
accepted on the a-posteriori bound ``rho / (1 - rho) |dq_k - dq_k-1| <= tol |dq_k|`` (the error of ``dq_k``),
with contact after two passes that agree to ``tol``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rotorred.transient import numba_cache
from rotorred.transient.contact_solve import C_MAXPASSES, C_PASSES
from rotorred.transient.kernel import (C_STEPS, C_SUBSTEPS, E_STATUS, E_TIME, LOOP,
                                       P_V, Condensed, _beyond_limit,
                                       _condense_contact, _disk_forces, _add_columns, _failed_plate, _matvec,
                                       _newmark_update, _record, _record_step, _solve_contact_forces,
                                       _stick_reset, _stop_at_limit, _update_contact, _write_state,
                                       solve_contact)
from rotorred.transient.status import PASSES_FAILED, RUNNING

numba_cache.register()


class ProfileTable(NamedTuple):
    """The breakpoints of a :class:`~rotorred.model.speeds.SpeedProfile` (``kernel_table``), n_s spools, k breakpoints.

    Attributes
    ----------
    tk : ndarray, shape (k,)
        Breakpoint times (s).
    W, Wd, Phi : ndarray, shape (n_s, k)
        Speeds (rad/s), accelerations of the segment that starts there (rad/s^2) and spin angles (rad).
    force_spool : ndarray of int64, shape (nf,)
        Spool of each force column, -1 for a constant one (gravity).
    force_kind : ndarray of int64, shape (nf,)
        0 constant, 1 the cos column, 2 the sin column of an unbalance (per unit Omega^2).
    """

    tk: np.ndarray
    W: np.ndarray
    Wd: np.ndarray
    Phi: np.ndarray
    force_spool: np.ndarray
    force_kind: np.ndarray


class Varying(NamedTuple):
    """The speed profile and the speed-dependent step operators of one speed interval.

    Attributes
    ----------
    R : ndarray, shape (L, n, b n_s n)
        ``[A_r^-1 G_0, A_r^-1 K_G,0, A_r^-1 G_1, ...]`` per step size level (s/kg... per rad/s, per rad/s^2), b = 2
        blocks a spool; b = 3 with internal damping: ``-A_r^-1 N_0, -A_r^-1 N_1, ...`` after all those (per rad/s).
    rho : ndarray, shape (L,)
        Bound of the passes' contraction over the interval, per level (-).
    ref : ndarray, shape (n_s, 2)
        Reference speed (rad/s) and acceleration (rad/s^2) of each spool.
    profile : ProfileTable
    plate_spool : ndarray of int64, shape (n_p,)
        Spool of each plate's disk.
    plate_radius : ndarray, shape (n_p,)
        Disk radius under each plate (m): ``P_V = Omega r``.
    tol : float
        Relative tolerance of the passes on ``dq`` (-).
    max_passes : int
    """

    R: np.ndarray
    rho: np.ndarray
    ref: np.ndarray
    profile: ProfileTable
    plate_spool: np.ndarray
    plate_radius: np.ndarray
    tol: float
    max_passes: int


class RampWork(NamedTuple):
    """Work arrays of :func:`run_ramp_steps` (n DOFs, n_s spools, nf force columns)."""

    s0: np.ndarray     # (n_s, 3) Omega, Omega', phi at the start of the step
    s1: np.ndarray     # (n_s, 3) and at its end
    fw: np.ndarray     # (nf,) mean of the force weights at both ends
    qbase: np.ndarray  # (n,) constant-speed predictor at the reference
    yfix: np.ndarray   # (b n_s n,) the pass input's part fixed in the step
    y: np.ndarray      # (b n_s n,) the pass input
    e: np.ndarray      # (n,) R y
    dq: np.ndarray     # (n,) the step's dq, last pass


def ramp_work(n: int, n_s: int, nf: int, blocks: int = 2) -> RampWork:
    """Empty :class:`RampWork` (Python side); ``blocks`` a spool in ``Varying.R`` (3 with internal damping)."""
    return RampWork(s0=np.empty((n_s, 3)), s1=np.empty((n_s, 3)), fw=np.empty(nf), qbase=np.empty(n),
                    yfix=np.empty(blocks * n_s * n), y=np.empty(blocks * n_s * n), e=np.empty(n), dq=np.empty(n))


@njit(cache=True, inline="always")
def _profile_at(t, pt, out):
    """``out[s] = (Omega, Omega', phi)`` of each spool at ``t`` (s) (``pt``: :class:`ProfileTable`); the
    acceleration is the left limit."""
    tk = pt.tk
    lo, hi = 0, tk.shape[0] - 1
    if t <= tk[0]:
        k = 0
    elif t > tk[hi]:
        k = hi
    else:  # the k with tk[k] < t <= tk[k + 1]
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if tk[mid] < t:
                lo = mid
            else:
                hi = mid
        k = lo
    tau = t - tk[k]
    for s in range(pt.W.shape[0]):
        wd = pt.Wd[s, k]
        out[s, 0] = pt.W[s, k] + wd * tau
        out[s, 1] = wd
        out[s, 2] = pt.Phi[s, k] + pt.W[s, k] * tau + 0.5 * wd * tau * tau


@njit(cache=True, inline="always")
def _force_weight(kind, st):
    """Time function of a force column at the state ``st = (Omega, Omega', phi)`` of its spool (Eq. R3)."""
    if kind == 0:
        return 1.0
    c, s = math.cos(st[2]), math.sin(st[2])
    if kind == 1:
        return st[0] * st[0] * c + st[1] * s
    return st[0] * st[0] * s - st[1] * c


@njit(cache=True)
def force_weights(t, pt, out):
    """``out[i, j]``: the time function of force column ``j`` at times ``t[i]`` (s) (the step's own rule, for
    the Python side: initial state, energy balance); ``out`` has shape (len(t), nf)."""
    st = np.empty((pt.W.shape[0], 3))
    for i in range(t.shape[0]):
        _profile_at(t[i], pt, st)
        for j in range(pt.force_kind.shape[0]):
            s = pt.force_spool[j]
            out[i, j] = 1.0 if s < 0 else _force_weight(pt.force_kind[j], st[s])


@njit(cache=True, inline="always")
def _ramp_predictor(level, ta, tb, cur, levels, var, plates, w, rw):
    """Speeds at both ends, the force weights, the plates' surface speeds, ``rw.qbase`` and ``rw.yfix``."""
    pt = var.profile
    _profile_at(ta, pt, rw.s0)
    _profile_at(tb, pt, rw.s1)
    for j in range(pt.force_kind.shape[0]):
        s = pt.force_spool[j]
        if s < 0:
            rw.fw[j] = 1.0
        else:
            rw.fw[j] = 0.5 * (_force_weight(pt.force_kind[j], rw.s0[s]) + _force_weight(pt.force_kind[j], rw.s1[s]))
    for k in range(var.plate_spool.shape[0]):
        plates.par[k, P_V] = rw.s1[var.plate_spool[k], 0] * var.plate_radius[k]
    _matvec(levels.H[level], cur.x, rw.qbase)
    for j in range(rw.fw.shape[0]):
        for ii in range(rw.qbase.shape[0]):
            rw.qbase[ii] += rw.fw[j] * levels.UF[level, j, ii]
    if plates.par.shape[0] > 0:
        _disk_forces(cur.z, plates.par, w.frot)
        _add_columns(rw.qbase, w.frot, levels.S0T[level], 1.0)
    n = rw.qbase.shape[0]
    n_s = rw.s0.shape[0]
    for s in range(n_s):
        dW = rw.s1[s, 0] - rw.s0[s, 0]
        sig = rw.s0[s, 1] + rw.s1[s, 1] - 2.0 * var.ref[s, 1]
        off = 2 * s * n
        for ii in range(n):
            rw.yfix[off + ii] = dW * cur.x[n + ii]
            rw.yfix[off + n + ii] = -sig * cur.x[ii]
    if rw.yfix.shape[0] > 2 * n_s * n:  # internal damping: the S_s blocks after all the others
        for s in range(n_s):
            sw = rw.s0[s, 0] + rw.s1[s, 0] - 2.0 * var.ref[s, 0]
            off = (2 * n_s + s) * n
            for ii in range(n):
                rw.yfix[off + ii] = -sw * cur.x[ii]
    # first guess of dq: h v0 + h^2/2 a0
    h = levels.coef[level, 7]
    for ii in range(n):
        rw.dq[ii] = h * cur.x[n + ii] + 0.5 * h * h * cur.x[2 * n + ii]


@njit(cache=True, inline="always")
def _ramp_substep(level, ta, tb, first_try, cur, new, levels, var, plates, settings, diag, w, rw):
    """One (sub)step at ``level`` from ``ta`` to ``tb`` (s), by fixed-point passes; RUNNING or a failure code."""
    _ramp_predictor(level, ta, tb, cur, levels, var, plates, w, rw)
    n = rw.dq.shape[0]
    c3 = levels.coef[level, 3]
    rho = var.rho[level]
    has_plates = plates.par.shape[0] > 0
    circulatory = rw.y.shape[0] > 2 * rw.s1.shape[0] * n
    for p in range(var.max_passes):
        # the pass input y(dq) and the correction e = R y
        for s in range(rw.s1.shape[0]):
            delta = rw.s1[s, 0] - var.ref[s, 0]
            eps = rw.s1[s, 1] - var.ref[s, 1]
            off = 2 * s * n
            for ii in range(n):
                rw.y[off + ii] = rw.yfix[off + ii] - c3 * delta * rw.dq[ii]
                rw.y[off + n + ii] = rw.yfix[off + n + ii] - eps * rw.dq[ii]
        if circulatory:  # internal damping's S_s blocks
            for s in range(rw.s1.shape[0]):
                delta = rw.s1[s, 0] - var.ref[s, 0]
                off = (2 * rw.s1.shape[0] + s) * n
                for ii in range(n):
                    rw.y[off + ii] = rw.yfix[off + ii] - delta * rw.dq[ii]
        _matvec(var.R[level], rw.y, rw.e)
        for ii in range(n):
            w.qn[ii] = rw.qbase[ii] + rw.e[ii]
        touching = False
        if has_plates:
            touching = _condense_contact(level, cur, levels, plates, w)
            cond = Condensed(w.p_lin, w.pd_lin, w.v_lin, levels.Jp[level], levels.Jv[level], c3)
            if p == 0 or not touching:
                ok = _solve_contact_forces(touching, first_try, cond, cur, new, plates, settings, diag, w)
            else:  # a later pass starts Newton from the last pass's forces
                ok = solve_contact(new.z, cond, plates.par, new.mode, new.sgn, settings.newton_tol, plates.atol,
                                   settings.max_newton, diag.counters, w.wv, w.wm)
            if not ok:
                return _failed_plate(w, diag)
            _update_contact(level, touching, cond, cur, new, levels, plates, w)
        change = 0.0
        size = 0.0
        for ii in range(n):
            d = w.qn[ii] - cur.x[ii]
            change = max(change, abs(d - rw.dq[ii]))
            size = max(size, abs(d))
            rw.dq[ii] = d
        diag.counters[C_PASSES] += 1
        if p + 1 > diag.counters[C_MAXPASSES]:
            diag.counters[C_MAXPASSES] = p + 1
        if touching:
            done = p > 0 and change <= var.tol * size
        else:
            done = rho < 1.0 and rho / (1.0 - rho) * change <= var.tol * size
        if done:
            status = _newmark_update(level, cur, new, levels, diag, w)
            if status == RUNNING:
                _stick_reset(new, plates, w)
            return status
    return PASSES_FAILED


@njit(**LOOP)
def run_ramp_steps(i_begin, i_end, levels, var, plates, state, spare, work, rwork, record, settings, diag):
    """Advance main steps ``i_begin .. i_end - 1`` at the profile's speeds (as :func:`kernel.run_steps`).

    Parameters are those of :func:`rotorred.transient.kernel.run_steps`, with ``var`` (:class:`Varying`) in
    place of the forcing and ``rwork`` (:class:`RampWork`). Returns RUNNING or the failure code.
    """
    cur, new, w, rw = state, spare, work, rwork
    t0, dt, n_halvings = settings.t0, settings.dt, settings.n_halvings
    if i_begin == 0 and record.start == 0 and record.count[0] == 0:
        _record(0, t0, cur, record)
        record.count[0] = 1
    units_total = 1 << n_halvings
    extrapolate = False
    for i in range(i_begin, i_end):
        t_main = t0 + i * dt
        level = 0
        progress = 0
        while progress < units_total:
            h_units = 1 << (n_halvings - level)
            ta = t_main + progress * (dt / units_total)
            tb = ta + h_units * (dt / units_total)
            if progress + h_units == units_total:
                tb = t0 + (i + 1) * dt
            status = _ramp_substep(level, ta, tb, extrapolate, cur, new, levels, var, plates, settings, diag, w, rw)
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
        diag.counters[C_STEPS] += 1
        _record_step(i + 1, t0 + (i + 1) * dt, cur, record)
    _write_state(cur, state)
    return RUNNING
