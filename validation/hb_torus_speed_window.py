"""What the rig's response does where the outer-speed torus branch stopped (issue 40, item 3; docs/model.md §26).

paper-rub, inner spool 70 Hz, rub torus (f_L, f_H/3) = (70, f_out/3) Hz, the default box of ``continue --torus``
(|k1| <= 32, |k2| <= 80, band 900 Hz, grid 128 x 256). The branch in the outer speed stopped near 93.33 Hz (3:4: the
order (4, -9) at 0 Hz) and at 96.162 Hz (near 8:11, 96.25 Hz: the order (11, -24)). In one run:

1. Settled 2-22 s transients (``validation/hb_torus.py``'s) at outer speeds across 92.8-94 Hz: the torus the line
   fit finds, its explained share, and the rms of node 18 Y (the rub disk) over 7-22 s.
2. The (70, f_out/3) torus at fixed speeds from 93.0 Hz (started from its transient's record through the coarse
   torus) up to 93.25 Hz, each speed from the last; at 93.25 Hz a transient started on the torus (its state at t = 0,
   :func:`rotorred.torus_trajectory`): the rms of node 18 Y each second and its largest distance from the torus.
3. At the other stop: the torus at fixed speeds from 96.0 Hz (its record) through 96.25 Hz to 96.3 Hz in 0.05 Hz
   steps, and at 96.3 Hz its 10 largest node-14 Y lines against a settled transient there.

Run::

    OPENBLAS_NUM_THREADS=1 python validation/hb_torus_speed_window.py
"""

from __future__ import annotations

import numpy as np

import rotorred as rr
from hb_torus import transient
from hb_torus_branch import scene_for
from rotorred.nonlinear.hb import NotConverged
from rotorred.nonlinear.torus import solve_torus
from rotorred.scenes.run import build_model
from rotorred.scenes.torus_balance import torus_rub_problem

INNER = 70.0  #: Hz
BOX = (32, 80, 128, 256, 900.0)  #: H1, H2, N1, N2, band (Hz): continue --torus's default
COARSE = (10, 40, 32, 256, 1500.0)  #: the start's coarse torus (validation/hb_torus.py's)
OUTPUT = (14, "y")
RUB = (18, "y")  #: the rub disk's node: its rms shows the change of torus
SCAN = (92.8, 93.0, 93.05, 93.1, 93.25, 93.3, 93.45, 93.5, 93.55, 93.7, 94.0)  #: Hz, part 1
UP = (93.0, 93.05, 93.1, 93.15, 93.2, 93.25)  #: Hz, part 2 (the first from its record)
THROUGH = (96.0, 96.05, 96.1, 96.15, 96.2, 96.25, 96.3)  #: Hz, part 3 (the first from its record; at 96.25 Hz itself
#: several orders share a line: the lines are compared past it)
SECONDS = 6  #: the transient started on the torus
LEAST_STEP = 0.01  #: Hz, the smallest speed step of part 2 and 3


def scene(outer: float):
    """paper-rub at ``outer`` (Hz) with the 2-22 s record of ``validation/hb_torus.py``."""
    return scene_for("speeds.outer", outer, record=True)


def rms_after(result, start: float = 7.0) -> float:
    """The rms of node 18 Y (the rub disk) from ``start`` (s) on (m)."""
    y = result.outputs[RUB][result.t >= start]
    return float(np.std(y))


def torus_problem(outer: float, model, box=BOX):
    return torus_rub_problem(scene(outer), model, (INNER, outer / 3), *box)


def from_record(outer: float, sm):
    """The torus at ``outer`` from its settled transient's last 5 s (least squares, the coarse torus where it
    converges), and that transient's 10 largest lines."""
    model = sm.model
    result, _, largest, records = transient(scene(outer), sm)
    window = result.t >= result.t[-1] - 5.0
    coarse = torus_problem(outer, model, COARSE)
    z0 = coarse.start_from_record(result.t[window][::8], {j: x[window][::8] for j, x in records.items()},
                                  within=(4, 30))
    try:
        zc = solve_torus(coarse.problem, z0, tol=1e-6).z
    except NotConverged:  # (96 Hz) the box from the least squares itself
        zc = z0
    rp = torus_problem(outer, model)
    z = solve_torus(rp.problem, coarse.problem.harmonics.transfer(zc, coarse.problem.n, rp.problem.harmonics)).z
    return rp, z, largest


def stepped(speeds, sm):
    """The torus at each of ``speeds`` (Hz), the first from its record, each next from the last (a step that does not
    converge halved, down to :data:`LEAST_STEP`): (rp, z) of each."""
    model = sm.model
    rp, z, _ = from_record(speeds[0], sm)
    out, at = {speeds[0]: (rp, z)}, speeds[0]
    for v in speeds[1:]:
        while at != v:
            h = v - at
            while True:
                new = torus_problem(at + h, model)
                try:
                    z = solve_torus(new.problem, rp.problem.harmonics.transfer(z, rp.problem.n,
                                                                               new.problem.harmonics)).z
                    break
                except NotConverged:
                    h /= 2
                    if abs(h) < LEAST_STEP:
                        raise
            rp, at = new, at + h if abs(v - at - h) > 1e-9 else v
        out[v] = rp, z
    return out


def torus_rms(rp, z) -> float:
    """The rms of node 18 Y on the torus (Parseval over its lines, the mean left out) (m)."""
    orders, _, a = rp.lines(z, RUB)
    moving = ~((orders[:, 0] == 0) & (orders[:, 1] == 0))
    return float(np.sqrt(np.sum(a[moving] ** 2) / 2))


def started_on(rp, z, outer: float, model):
    """A transient started on the torus's state at t = 0: node 18 Y each second (rms, and the largest distance from
    the torus's own series over its largest amplitude)."""
    sc, n = scene(outer), rp.n_model
    q, v = rr.torus_trajectory(rp.problem, z, [0.0], dofs="all")
    run = rr.simulate(model, rr.Operating.point(dict(sc.speeds)), float(SECONDS), sc.solver.dt,
                      loads=rr.Loads(sc.unbalances), contacts=sc.plates, recording=rr.Recording([RUB]),
                      start=rr.Initial(q[0, :n], v[0, :n]), control=rr.StepControl(progress=False))
    t, y = run.t[::10], run.outputs[RUB][::10]
    series = rr.torus_trajectory(rp.problem, z, t, dofs="all")[0][:, :n] @ model.output_rows([RUB])[0]
    size = np.max(np.abs(series))
    return [(float(np.std(y[(t >= s) & (t < s + 1)])), float(np.max(np.abs(y - series)[(t >= s) & (t < s + 1)]))
             / size) for s in range(SECONDS)]


def main() -> None:
    sm = build_model(scene(SCAN[0]))
    model = sm.model
    print("1. settled transients (2-22 s; the line fit at node 14 Y):")
    print("| outer (Hz) | torus found | explained | rms node 18 Y, 7-22 s (µm) |\n|---|---|---|---|")
    for v in SCAN:
        result, analysis, _, _ = transient(scene(v), sm)
        print(f"| {v:g} | {analysis.fit.torus.label} | {analysis.fit.explained_share:.4f} | "
              f"{1e6 * rms_after(result):.2f} |", flush=True)

    print(f"\n2. the (70, f_out/3) torus stepped from {UP[0]:g} Hz (its record):")
    tori = stepped(UP, sm)
    for v, (rp, z) in tori.items():
        print(f"  {v:g} Hz: converged, rms node 18 Y on the torus {1e6 * torus_rms(rp, z):.2f} µm")
    rp, z = tori[UP[-1]]
    rows = started_on(rp, z, UP[-1], model)
    print(f"  a transient started on the {UP[-1]:g} Hz torus, each second: rms (µm) / largest distance from the torus "
          "(of its largest): " + "  ".join(f"{1e6 * r:.2f} / {d:.2g}" for r, d in rows))

    print(f"\n3. the torus stepped from {THROUGH[0]:g} Hz (its record) through {THROUGH[-1]:g} Hz:")
    tori = stepped(THROUGH, sm)
    for v, (rp, z) in tori.items():
        print(f"  {v:g} Hz: converged, rms node 18 Y on the torus {1e6 * torus_rms(rp, z):.2f} µm")
    rp, z = tori[THROUGH[-1]]
    _, _, largest, _ = transient(scene(THROUGH[-1]), sm)
    f = np.array([ln.frequency_hz for ln in largest])
    relative = rp.amplitudes_at(z, OUTPUT, f) / np.array([ln.amplitude for ln in largest]) - 1
    print(f"  at {THROUGH[-1]:g} Hz its 10 largest lines against the settled transient's: worst "
          f"{np.max(np.abs(relative)):.2%}: " + " ".join(f"{x:.1f}:{d:+.2%}" for x, d in zip(f, relative)))


if __name__ == "__main__":
    main()
