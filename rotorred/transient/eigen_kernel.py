"""Compiled step loop of the average-acceleration Newmark transient in the eigenbasis of its amplification matrix.

At constant speeds, a full step of average-acceleration Newmark (gamma = 1/2, beta = 1/4) maps the
state x = (q, v) linearly, plus the forces:

    q' = H x + sum_j w_j(tb) UF_j + S (f_old + f_new),    v' = (2/h)(q' - q) - v,

so ``x' = A x + b`` with ``A = [[Hq, Hv], [(2/h)(Hq - I), (2/h) Hv - I]]`` and every input entering as
``[u; (2/h) u]``. With ``A = P D P^-1``, D real block-diagonal (a 1x1 block per real eigenvalue, a
rotation-scaling 2x2 block ``[[a, b], [-b, a]]`` per complex pair), the state ``y = P^-1 x`` obeys
``y' = D y + sum_j w_j(t') gF_j + sum_k f_k gS_k`` with the inputs mapped once, ``gF_j = P^-1 [UF_j; (2/h) UF_j]``
and ``gS_k = P^-1 [S_k; (2/h) S_k]``. The external forces are constants and (cos, sin) pairs at fixed
frequencies, so the recurrence has an exact periodic particular solution
``y_p(t) = Y_0 + sum_pairs Re(Y_j e^(i omega_j t))`` with ``(I - e^(-i omega h) D) Y_j = gF_cos - i gF_sin``
(:func:`rotorred.transient.eigenstep.eigen_form`). The kernel steps ``y_h = y - y_p`` in O(2n):
``y_h' = D y_h + sum_k f_k gS_k``, and adds ``y_p`` only where q is read: at the contact DOFs
(``C_r y``, 2 rows per plate) every step and at the recorded outputs when a record is due (both
precomputed row by pair). The contact stays implicit: the condensed Newton solve, the plates' update and
the stick reset are those of :mod:`rotorred.transient.kernel`.

This is the same discrete recurrence as the dense step, evaluated in another basis: the histories
agree to rounding (``cond(P)`` times the machine epsilon). A step whose contact solve fails is redone
by the dense step's halvings from the physical state ``x = P y`` (with no halving allowed, by the dense
step itself, which then reports the failure), and the state is mapped back.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rotorred.transient import numba_cache
from rotorred.transient.kernel import (C_STEPS, E_DOF, LOOP, Condensed, State, _add_columns, _beyond_limit,
                                       _condense_rlin, _cos_sin, _disk_forces, _failed_plate, _forcing_at_step_end,
                                       _matvec, _record, _solve_contact_forces, _start_forcing, _stick_reset,
                                       _stop_at_limit, _update_contact_dofs, _write_state)
from rotorred.transient.status import LIMIT, NEED_DENSE, RUNNING

numba_cache.register()


class Eigen(NamedTuple):
    """The real block-diagonal form of level 0's amplification matrix and the inputs in its basis (n DOFs).

    Attributes
    ----------
    a, b : ndarray, shape (n_c,)
        The complex pairs' blocks: y is ordered ``[Re-parts (n_c), Im-parts (n_c), real eigenvalues' parts]``,
        ``yr' = a yr + b yi``, ``yi' = -b yr + a yi`` (contiguous, vectorised).
    lam : ndarray, shape (2 n - 2 n_c,)
        The real eigenvalues: ``y' = lam y``.
    pair_col : ndarray of int64, shape (n_f,)
        Forcing column of the cos member of each (cos, sin) pair (its time functions ``w.fcos``, ``w.fsin``).
    omega : ndarray, shape (n_f,)
        Each pair's angular frequency (rad/s).
    Yr, Yi : ndarray, shape (n_f, 2 n)
        The particular solution of each pair: ``Re(Y e^(i omega t)) = cos Yr - sin Yi``.
    Y0 : ndarray, shape (2 n,)
        That of the constant forces.
    CYr, CYi : ndarray, shape (n_f, m)
        ``C_r Yr``, ``C_r Yi``; ``CY0``, shape (m,): ``C_r Y0``.
    RYr, RYi : ndarray, shape (n_f, n_out)
        The same for the record rows; ``RY0``, shape (n_out,).
    gS : ndarray, shape (m, 2 n)
        Contact-DOF force columns in the eigenbasis (m = 2 n_p).
    Cr : ndarray, shape (m, 2 n)
        Contact-DOF displacement rows on y.
    P, Pinv : ndarray, shape (2 n, 2 n)
        ``x = P y`` and back.
    """

    a: np.ndarray
    b: np.ndarray
    lam: np.ndarray
    pair_col: np.ndarray
    omega: np.ndarray
    Yr: np.ndarray
    Yi: np.ndarray
    Y0: np.ndarray
    CYr: np.ndarray
    CYi: np.ndarray
    CY0: np.ndarray
    RYr: np.ndarray
    RYi: np.ndarray
    RY0: np.ndarray
    gS: np.ndarray
    Cr: np.ndarray
    P: np.ndarray
    Pinv: np.ndarray


class EigenWork(NamedTuple):
    """The eigenbasis state y_h (two buffers), a full y for conversions, and cos, sin of each pair at a time."""

    y: np.ndarray      # (2 n,) current y_h
    y_new: np.ndarray  # (2 n,) next
    yfull: np.ndarray  # (2 n,) y_h + y_p
    c: np.ndarray      # (n_f,) cos(omega t)
    s: np.ndarray      # (n_f,) sin(omega t)


def eigen_work(n: int, n_pairs: int) -> EigenWork:
    return EigenWork(y=np.zeros(2 * n), y_new=np.zeros(2 * n), yfull=np.zeros(2 * n), c=np.zeros(n_pairs),
                     s=np.zeros(n_pairs))


@njit(cache=True, fastmath={"reassoc", "contract"})
def _sum(x):
    """The sum of ``x`` (reassociated: vectorised; a NaN or an infinity still shows)."""
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i]
    return s


@njit(cache=True, inline="always")
def _phases_at(t, eig, ew):
    """``ew.c``, ``ew.s``: cos and sin of each pair's omega t."""
    _cos_sin(eig.omega, t, ew.c, ew.s)


@njit(cache=True, inline="always")
def _phases_from_forcing(eig, w, ew):
    """``ew.c``, ``ew.s`` from the forcing's time functions at the end of the main step (``w.fcos``, ``w.fsin``)."""
    for j in range(eig.omega.shape[0]):
        ew.c[j] = w.fcos[eig.pair_col[j]]
        ew.s[j] = w.fsin[eig.pair_col[j]]


@njit(cache=True, inline="always")
def _with_particular(y, eig, ew, out, sign):
    """``out = y + sign * y_p`` at the phases in ``ew``."""
    for i in range(y.shape[0]):
        out[i] = y[i] + sign * eig.Y0[i]
    for j in range(eig.omega.shape[0]):
        c = sign * ew.c[j]
        sn = sign * ew.s[j]
        for i in range(y.shape[0]):
            out[i] += c * eig.Yr[j, i] - sn * eig.Yi[j, i]


@njit(cache=True, inline="always")
def _to_physical(y, eig, ew, x):
    """``x[:2n] = P (y_h + y_p)``: q and v of the state at the phases in ``ew`` (the acceleration is left alone)."""
    _with_particular(y, eig, ew, ew.yfull, 1.0)
    _matvec(eig.P, ew.yfull, x)


@njit(cache=True, inline="always")
def _from_physical(x, eig, ew, y):
    """``y = P^-1 x - y_p`` at the phases in ``ew``."""
    _matvec(eig.Pinv, x, ew.yfull)
    _with_particular(ew.yfull, eig, ew, y, -1.0)


@njit(cache=True, inline="always")
def _record_eigen(idx, t, y, cur, eig, ew, record):
    """Record row ``idx``: the rows on y_h plus the particular solution's rows at the phases in ``ew``."""
    _record(idx, t, State(y, cur.xc, cur.ps, cur.z, cur.mode, cur.sgn, cur.pinfo), record)
    for r in range(record.y.shape[1]):
        v = eig.RY0[r]
        for j in range(eig.omega.shape[0]):
            v += ew.c[j] * eig.RYr[j, r] - ew.s[j] * eig.RYi[j, r]
        record.y[idx, r] += v


@njit(cache=True, inline="always")
def _eigen_predictor(y, y_new, eig, cur, plates, w):
    """``y_new = D y + sum_k f_old,k gS_k``: the homogeneous part at zero new contact force."""
    nc = eig.a.shape[0]
    for k in range(nc):
        yr = y[k]
        yi = y[nc + k]
        y_new[k] = eig.a[k] * yr + eig.b[k] * yi
        y_new[nc + k] = eig.a[k] * yi - eig.b[k] * yr
    for k in range(eig.lam.shape[0]):
        y_new[2 * nc + k] = eig.lam[k] * y[2 * nc + k]
    if plates.par.shape[0] > 0:
        _disk_forces(cur.z, plates.par, w.frot)
        _add_columns(y_new, w.frot, eig.gS, 1.0)


@njit(cache=True, inline="always")
def _contact_rlin(y_new, eig, ew, w):
    """``w.rlin``: the contact DOFs' displacement at zero new contact force, ``C_r y_new`` plus the particular
    solution's rows at the phases in ``ew``."""
    _matvec(eig.Cr, y_new, w.rlin)
    for k in range(w.rlin.shape[0]):
        r = eig.CY0[k]
        for j in range(eig.omega.shape[0]):
            r += ew.c[j] * eig.CYr[j, k] - ew.s[j] * eig.CYi[j, k]
        w.rlin[k] += r


@njit(**LOOP)
def run_eigen_steps(i_begin, i_end, levels, eig, forcing, plates, state, spare, work, ework, record, settings, diag):
    """Advance main steps ``i_begin .. i_end - 1`` as :func:`rotorred.transient.kernel.run_steps` does, level 0 in
    the eigenbasis (``record.rows`` act on y: the output rows times ``P``). ``state.x`` holds q, v on entry
    and on return.

    A step whose contact solve fails returns NEED_DENSE with that step's start in ``state`` (step index
    ``diag.counters[C_STEPS]``): the caller redoes it with the dense loop, which halves it (or reports the
    failure), and calls again from the next step. Inlining the dense step's halvings here took 20 of the
    kernel's 53 s of compilation, for a path paper-rub never takes.
    """
    cur, new, w, ew = state, spare, work, ework
    t0, dt = settings.t0, settings.dt
    y, y_new = ew.y, ew.y_new
    _phases_at(t0 + i_begin * dt, eig, ew)
    _from_physical(cur.x, eig, ew, y)
    extrapolate = False
    _start_forcing(forcing, dt, w)
    status = RUNNING
    limit_dof = -1
    i = i_begin
    while True:
        if ((i > i_begin or (i == 0 and record.count[0] == 0)) and i >= record.start
                and (i - record.start) % record.every == 0 and record.count[0] < record.t.shape[0]):
            _record_eigen(record.count[0], t0 + i * dt, y, cur, eig, ew, record)
            record.count[0] += 1
        if i == i_end:
            break
        # one main step at level 0 in the eigenbasis, into y_new and new (written out here, not an inlined function:
        # numba copies an inlined function's IR block by block with its whole scope, 2.6 s for this step's)
        _forcing_at_step_end(i - i_begin, t0 + (i + 1) * dt, forcing, w)
        _phases_from_forcing(eig, w, ew)
        _eigen_predictor(y, y_new, eig, cur, plates, w)
        if plates.par.shape[0] > 0:
            _contact_rlin(y_new, eig, ew, w)
            touching = _condense_rlin(0, cur, levels, plates, w)
            cond = Condensed(w.p_lin, w.pd_lin, w.v_lin, levels.Jp[0], levels.Jv[0], levels.coef[0, 3])
            if not _solve_contact_forces(touching, extrapolate, cond, cur, new, plates, settings, diag, w):
                _failed_plate(w, diag)
                status = NEED_DENSE  # the dense step redoes this main step (its halvings, or its failure report)
                break
            _disk_forces(new.z, plates.par, w.frot)
            _add_columns(y_new, w.frot, eig.gS, 1.0)
            _update_contact_dofs(0, touching, cond, cur, new, levels, plates, w)
        if not math.isfinite(_sum(y_new)):
            diag.err[E_DOF] = -1
            status = NEED_DENSE  # as a failed contact solve
            break
        _stick_reset(new, plates, w)
        limit_dof = _beyond_limit(new.xc, settings.limit)
        if limit_dof >= 0:
            status = LIMIT
            break
        cur, new = new, cur
        y, y_new = y_new, y
        extrapolate = True
        diag.counters[C_STEPS] += 1
        i += 1
    _phases_at(t0 + i * dt, eig, ew)
    _to_physical(y, eig, ew, cur.x)
    if status == LIMIT:
        return _stop_at_limit(t0 + (i + 1) * dt, limit_dof, cur, state, diag)
    _write_state(cur, state)
    return status
