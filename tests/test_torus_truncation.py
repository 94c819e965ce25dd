"""The orders of a torus chosen by the convergence of its response (rotorred.nonlinear.torus_truncation), on the cubic
oscillator forced at two incommensurate frequencies: the estimate bounds the error against a much finer truncation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotorred.checks import InputError
from rotorred.nonlinear.forces import CubicSpring
from rotorred.nonlinear.torus import TorusHarmonics, TorusProblem, alias_free_grid, solve_torus
from rotorred.nonlinear.torus_truncation import TorusOrdersNotConverged, torus_change, torus_to_tolerance
from results_checks import assert_shows_itself

C, K3, F1, F2 = 0.2, 0.5, 0.15, 0.1
W = (0.8, 0.8 * math.sqrt(2.0))


def cubic(H1: int, H2: int) -> TorusProblem:
    h = TorusHarmonics(H1, H2, *alias_free_grid(H1, H2, 3))
    Q = np.zeros((h.n_orders, 1), complex)
    Q[h.index(1, 0)], Q[h.index(0, 1)] = F1, F2
    return TorusProblem(np.eye(1), C * np.eye(1), np.eye(1), h, W, (0,), h.from_phasors(Q), (CubicSpring(0, K3),))


def amplitudes(problem, z):
    return problem.recover(z)


def test_orders_chosen_by_the_change_bound_the_error_against_a_finer_torus():
    """Ladder (1, 1), (2, 2), (4, 4), (8, 8) at tolerance 1e-4: measured changes 4.1e-2 (to 2 x 2), 2.2e-3 (to 4 x 4)
    and 3.0e-5 (to 8 x 8), so 8 x 8 is returned, and its error against 12 x 12 (5.6e-9) is far below its estimate, as
    the rule says (the finer of the pair); 1e-9 is not met along that ladder and says so."""
    build, ladder = cubic, ((1, 1), (2, 2), (4, 4), (8, 8))
    first = build(1, 1)
    problem, solution, choice = torus_to_tolerance(build, ladder, first.linear_response(), 1e-4, amplitudes)
    assert choice.orders == (8, 8) and choice.grid == alias_free_grid(8, 8, 3)
    assert [H for H, _ in choice.steps] == [(2, 2), (4, 4), (8, 8)]
    assert choice.steps[0][1] == pytest.approx(4.1e-2, rel=0.05) and choice.steps[1][1] == pytest.approx(2.2e-3, rel=0.05)
    assert choice.estimate == choice.steps[-1][1] < 1e-4
    fine = cubic(12, 12)
    Q_fine = fine.recover(solve_torus(fine, fine.linear_response()).z)
    error = torus_change(problem.harmonics, problem.recover(solution.z), fine.harmonics, Q_fine)
    assert error < 1e-3 * choice.estimate  # 5.6e-9 against 3.0e-5
    assert "orders |k1| <= 8, |k2| <= 8" in choice.describe()
    with pytest.raises(TorusOrdersNotConverged, match="still changes by"):
        torus_to_tolerance(build, ladder, first.linear_response(), 1e-9, amplitudes)
    with pytest.raises(InputError, match="ladder"):
        torus_to_tolerance(build, ladder[:1], first.linear_response(), 1e-4, amplitudes)


def test_torus_balance_with_a_tolerance_names_the_orders_it_chose(tmp_path):
    """torus_balance with options.tolerance on paper-rub out of contact (clearance 1 mm, the response linear): the
    ladder doubles (2, 4) to (4, 8), the change is round-off (the forced lines are in both), so (4, 8) is returned
    and the summary says so; a grid given with a tolerance is refused."""
    import rotorred as rr
    from rotorred.scenes.run import build_model
    from rotorred.scenes.schema import load_scene

    scene = load_scene("paper-rub", {"speeds.outer": 91.37, "rub.clearance": 1e-3})
    sm = build_model(scene)
    op = rr.Operating.point({s: w for s, w in scene.speeds.items()})
    options = rr.TorusOptions(bases=(70.0, 91.37 / 3), orders=(2, 4), f_max=None, start_window=None, tolerance=1e-6)
    result = rr.torus_balance(sm.model, op, rr.Loads(scene.unbalances), scene.plates, options)
    assert result.truncation.orders == (4, 8) and result.truncation.estimate < 1e-12
    assert result.problem.problem.harmonics.H1 == 4
    assert any("orders |k1| <= 4, |k2| <= 8" in line for line in result.summary())
    assert_shows_itself(result, tmp_path, of=rr.RubTorus)
    with pytest.raises(InputError, match="options.grid"):
        rr.TorusOptions(grid=(64, 1024), tolerance=1e-3)
