"""Feasibility restoration: a budget-stopped solve returns a point in the box and cones."""

import numpy as np
import pytest

import fccqp
from fccqp import Status
from problems import random_problem
from verify import Problem, primal_violations, verify_solution

pytestmark = pytest.mark.usefixtures("every_kkt_backend")
"""Every test on every KKT backend (tests/conftest.py)."""


def _infeasibility(problem, x):
    violations = primal_violations(Problem.of(*problem), x)
    return max(violations["box"], violations["cone"])


# Auto's reduced form needs at most half the KKT size constrained (n + m = 38 here): 15
# constrained entries use it, 21 take the full form. A forced backend keeps its form.
@pytest.mark.kkt_backends("auto", "schur_reduced", "ldl_reduced", "ldl_full", reason=(
    "restore_feasibility has no effect on the sparse path"))
@pytest.mark.parametrize(("n_box", "reduced"), [(6, 1), (12, 0)])
def test_budget_stopped_solve_is_exactly_feasible(n_box, reduced, kkt_backend):
    settings = dict(max_iter=3, eps_abs=1e-10, eps_rel=0.0, polish=False)
    unrestored = []
    for seed in range(4):
        problem = P, q, A, b, lb, ub, cones = random_problem(seed, n_box=n_box)
        solver = fccqp.Solver(**settings)
        result = solver.solve(*problem)
        if kkt_backend == "auto":
            assert (result.backend != "ldl_full") == reduced
        else:
            assert result.backend == kkt_backend
        assert result.status is Status.MAX_ITER_REACHED
        assert _infeasibility(problem, result.x) <= 1e-12
        verify_solution(problem, result)  # A x = b at factorization accuracy
        # entries that violated in the plain iterate are pinned at their projection
        plain = fccqp.solve(*problem, restore_feasibility=False, **settings)
        unrestored.append(_infeasibility(problem, plain.x))
        box = np.isfinite(lb) | np.isfinite(ub)
        clipped = np.clip(plain.x, lb, ub)
        moved = box & (clipped != plain.x)
        np.testing.assert_allclose(result.x[moved], clipped[moved], rtol=1e-9, atol=1e-12)
    assert max(unrestored) > 1e-3  # without restoration the same iterates are infeasible


def test_restoration_that_cannot_meet_the_equalities_is_dropped():
    # every entry is bounded and sum(x) = 1 ties them: x_S = z breaks the equality
    P, q = np.eye(3), np.array([1.0, -2.0, 0.5])
    A, b = np.ones((1, 3)), np.array([1.0])
    lb, ub = np.zeros(3), np.full(3, 0.8)
    problem = (P, q, A, b, lb, ub)
    kept = fccqp.solve(*problem, max_iter=2, eps_abs=1e-12, eps_rel=0.0, polish=False)
    plain = fccqp.solve(*problem, max_iter=2, eps_abs=1e-12, eps_rel=0.0,
                        restore_feasibility=False, polish=False)
    np.testing.assert_array_equal(kept.x, plain.x)
    assert kept.status is plain.status is Status.MAX_ITER_REACHED
    assert abs(A @ kept.x - b).max() <= 1e-12


def test_solved_answers_stay_solved_with_true_residuals():
    for seed in range(4):
        problem = random_problem(seed, soc_dim=4 if seed % 2 else 0)
        result = fccqp.solve(*problem)
        assert result.status is Status.SOLVED
        verify_solution(problem, result)  # includes the claimed residuals


def test_infeasible_problem_is_not_restored():
    P, q, A, b, lb, ub, cones = random_problem(0, n_cones=0)
    lb[5:8], ub[5:8] = 1.0, 2.0
    A = np.vstack([A, np.eye(30)[5]])
    b = np.append(b, -1.0)  # x5 = -1 against lb 1
    result = fccqp.solve(P, q, A, b, lb, ub, cones)
    assert result.status is Status.PRIMAL_INFEASIBLE
    verify_solution((P, q, A, b, lb, ub, cones), result)
