"""A rub scene's harmonic balance at incommensurate spool speeds: the quasi-periodic response on a torus.

``solver.method = "harmonic-balance"`` at speeds that share no period of at most 10 s (the one rule,
:func:`rotorred.scenes.harmonic_balance.common_frequency`) has no periodic response; the scene's run solves the torus
by :func:`rotorred.scenes.quasi_periodic.torus_balance` (docs/model.md §15, §25) with the scene's settings
(:func:`torus_options`):

* ``solver.harmonics = [H1, H2]``: the box of orders ``|k1| <= H1``, ``|k2| <= H2`` of the two base frequencies
  (default :class:`~rotorred.scenes.quasi_periodic.TorusOptions`' (16, 70));
* ``solver.samples = [N1, N2]``: the AFT grid (default :func:`~rotorred.scenes.quasi_periodic.default_grid` of the
  orders);
* ``solver.tolerance``: the orders chosen by the convergence of the output DOFs' response, from ``solver.harmonics``
  (or the default box) doubled, each box with its default grid (``TorusOptions.tolerance``);
* ``solver.dt``: the step of the short transient the bases are found in and the solution started from.

The bases are those the line fit finds in that transient (``f_L`` and ``f_H / 3`` on ``paper-rub`` near 91 Hz). The
record is the torus series at the scene's record times (:func:`torus_record`), so spectra, line fit, files and
summary are those of any run.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from rotorred import checks
from rotorred.checks import InputError
from rotorred.nonlinear.torus import TorusSeries
from rotorred.scenes.harmonic_balance import contact_history
from rotorred.signals.lines import line_label

__all__ = ["torus_options", "solve_scene_torus", "torus_record", "spool_bases", "base_labels", "order_label",
           "describe_torus"]


def torus_options(scene):
    """The :class:`rotorred.scenes.quasi_periodic.TorusOptions` of a scene's settings (module docstring)."""
    from rotorred.scenes.quasi_periodic import TorusOptions

    s = scene.solver
    given = {"orders": s.harmonics, "grid": s.samples}
    return TorusOptions(dt=s.dt, tolerance=s.tolerance, outputs=scene.output.dofs,
                        **{key: value for key, value in given.items() if value is not None})


def solve_scene_torus(scene, model):
    """The torus of ``scene`` on its (reduced) ``model`` (:func:`rotorred.scenes.quasi_periodic.torus_balance`), a
    refusal in the scene's key names: no torus found in the start's transient (``speeds``), a box too small for the
    spools' orders on the bases found (``solver.harmonics``), a torus whose lines the start's record cannot resolve
    (``speeds``, nearly commensurate).

    Parameters
    ----------
    scene : rotorred.scenes.schema.Scene
        A rub scene at incommensurate speeds with ``solver.method = "harmonic-balance"``.
    model : SystemMatrices or ReducedSystem
        The scene's model (:func:`rotorred.scenes.run.build_model`).

    Returns
    -------
    rotorred.scenes.quasi_periodic.RubTorus
    """
    from rotorred.scenes.quasi_periodic import torus_balance
    from rotorred.transient.options import Loads

    options = torus_options(scene)
    try:
        return torus_balance(model, scene.operating, Loads(scene.unbalances), scene.plates, options)
    except InputError as exc:
        frequencies = {name: round(f, 9) for name, f in scene.frequencies_hz.items()}
        if exc.field == "options.bases" and "truncated set" in exc.requirement:  # the spools' orders outside the box
            checks.fail("solver.harmonics", list(options.orders), f"must hold each spool's order on the torus found "
                        f"(bases {_hz(exc.value)} Hz): {exc.requirement.removeprefix('must hold ')}")
        if exc.field == "options.bases":  # the start's line fit found no torus of two incommensurate bases
            checks.fail("speeds", frequencies, "must have a quasi-periodic rub response for a harmonic balance on a "
                        "torus (the speeds share no period of at most 10 s), but "
                        f"{exc.requirement.removeprefix('must be given: ')}; {ADVICE}", "Hz")
        if exc.field == "options.start_orders":  # the torus's lines closer than the start's record resolves
            window = options.start_window[1] - options.start_window[0]
            checks.fail("speeds", frequencies, f"must give a torus whose lines a {window:g} s record resolves (the "
                        f"start's transient; {exc.requirement.split(': ', 1)[-1]}): nearly commensurate speeds; "
                        f"{ADVICE}", "Hz")
        raise


#: what a scene whose speeds have no torus the start finds can do instead
ADVICE = ('make the speeds share a period of at most 10 s (a periodic harmonic balance) or run a transient '
          '(solver.method = "newmark")')


def _hz(bases) -> str:
    return ", ".join(f"{f:.6g}" for f in np.ravel(bases)) if bases is not None else "none"


def torus_record(torus, t: np.ndarray, dofs) -> tuple[dict, tuple]:
    """The torus as a transient's record at the times ``t`` (s): each model DOF of ``dofs`` (m or rad), and a
    :class:`rotorred.transient.results.ContactHistory` per plate from the law at those instants
    (:func:`rotorred.scenes.harmonic_balance.contact_history`).

    The series ``Re sum_k Q_k exp(i (k_1 w_1 + k_2 w_2) t)`` (phase origin t = 0, as the unbalance's) is
    :class:`rotorred.nonlinear.torus.TorusSeries`'s.

    Parameters
    ----------
    torus : rotorred.scenes.quasi_periodic.RubTorus
    t : ndarray, shape (n,)
        Times (s).
    dofs : sequence of (int, str)
        Model DOFs (node, direction).

    Returns
    -------
    outputs : dict of (int, str) to ndarray, shape (n,)
    contacts : tuple of ContactHistory
    """
    rp = torus.problem
    h, w = rp.problem.harmonics, rp.problem.w
    Q = rp.problem.recover(torus.solution.z)  # (K, n_all) complex: every DOF of the model and the plates
    rubs = rp.problem.forces
    columns = [Q @ rp.output_rows(dofs).T]
    for rub in rubs:  # each plate's unknowns and their rates, d/dt -> i (k . w)
        columns += [Q[:, list(rub.dofs)], 1j * h.frequencies(w)[:, None] * Q[:, list(rub.dofs)]]
    x = TorusSeries(h.orders, np.hstack(columns), w)(t)
    outputs = {d: x[:, j] for j, d in enumerate(dofs)}
    at = len(dofs)
    contacts = tuple(contact_history(rub, x[:, at + 8 * i:at + 8 * i + 4], x[:, at + 8 * i + 4:at + 8 * i + 8])
                     for i, rub in enumerate(rubs))
    return outputs, contacts


def spool_bases(torus, f_L: float, f_H: float) -> tuple:
    """Each base of the torus as a spool's frequency over a whole number, ``(m, n)`` with the base
    ``m f_H + n f_L`` (Fractions: ``(0, 1)`` is f_L, ``(1/3, 0)`` f_H/3), or None where no spool's order lies along
    that base alone."""
    out = []
    for i, f in enumerate(torus.bases_hz):
        found = None
        for order in torus.problem.spool_orders.values():
            k = abs(order[i])
            if k and not order[1 - i]:
                if abs(k * f - f_H) <= 1e-9 * f_H:
                    found = (Fraction(1, k), Fraction(0))
                elif abs(k * f - f_L) <= 1e-9 * f_L:
                    found = (Fraction(0), Fraction(1, k))
        out.append(found)
    return tuple(out)


def base_labels(torus, f_L: float, f_H: float) -> tuple[str, str]:
    """The names of the torus's bases: ``"f_L"``, ``"f_H/3"`` (:func:`spool_bases`), else ``"f_1"``, ``"f_2"``."""
    return tuple(line_label(*b) if b is not None else f"f_{i + 1}"
                 for i, b in enumerate(spool_bases(torus, f_L, f_H)))


def order_label(order, bases: tuple) -> str:
    """The label of the order ``(k1, k2)``'s line, ``bases`` those of :func:`spool_bases`: the one form of a line's
    label (:func:`rotorred.signals.lines.line_label`, ``"2f_H/3+f_L"``), or ``"k1 f_1 + k2 f_2"`` where a base is no
    spool's."""
    k1, k2 = (int(k) for k in order)
    if None in bases:
        return f"{k1} f_1 {'-' if k2 < 0 else '+'} {abs(k2)} f_2"
    return line_label(k1 * bases[0][0] + k2 * bases[1][0], k1 * bases[0][1] + k2 * bases[1][1])


def describe_torus(torus, f_L: float, f_H: float) -> tuple[str, str]:
    """Two phrases: the torus (its bases named in the spools' frequencies and the spools' orders) and its truncation
    (orders, band, grid, unknowns)."""
    h, z = torus.problem.problem.harmonics, torus.solution.z
    bases = ", ".join(f"{name} = {f:.6g} Hz" for name, f in zip(base_labels(torus, f_L, f_H), torus.bases_hz))
    band = f" in the band <= {h.w_max / (2 * np.pi):g} Hz" if h.w_max is not None else ""
    return (f"torus ({bases}; spool orders "
            + ", ".join(f"{sp} {tuple(k)}" for sp, k in torus.problem.spool_orders.items()) + ")",
            f"orders |k1| <= {h.H1} x |k2| <= {h.H2} ({h.n_orders} orders{band}), grid {h.N1} x {h.N2}, {z.size} "
            f"unknowns (the Fourier coefficients of {len(torus.solution.dofs)} rub DOFs)")
