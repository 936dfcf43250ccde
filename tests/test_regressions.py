"""One test per reproducer of issue 11, with the issue's own numbers.

Each docstring names the item. Every answer is judged by :func:`verify.verify_solution`
(recomputed from the returned point and the data) and, where a problem has an optimum,
against Clarabel. Some of these wait for the compiled core's fixes (items 1-8, 10,
12-15); they fail until then, by design.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import tomllib

import fccqp
from fccqp import FrictionCone, SecondOrderCone, Status
from problems import random_problem
from reference import clarabel_solve
from verify import Problem, Tolerances, check_solution, verify_solution

pytestmark = pytest.mark.usefixtures("every_kkt_backend")
"""Every test on every KKT backend (tests/conftest.py)."""

ROOT = Path(__file__).resolve().parents[1]
INF = np.inf


def solve_and_verify(problem: Problem, tolerances: Tolerances | None = None, **settings):
    """Solve with fccqp and assert the result keeps its status's promises."""
    result = fccqp.solve(*problem.args(), **settings)
    verify_solution(problem, result, tolerances or Tolerances.of(**settings))
    return result


def assert_optimum(problem: Problem, result: fccqp.Result, rtol: float = 1e-4) -> None:
    """SOLVED, verified, at Clarabel's objective."""
    assert result.status is Status.SOLVED, result.status
    reference = clarabel_solve(*problem.args())
    assert reference.status == "solved"
    assert abs(result.obj - reference.obj) <= rtol * (1 + abs(reference.obj))


# item 1 ---------------------------------------------------------------------------

INFEASIBLE_WITH_SOC = Problem.of(
    np.diag([0, 0, 0, 1e4, 1e4, 1e4, 1e4]),
    [10, 6e-5, -600, -50, 50, 200, 100],
    [[-1, -9e-4, -2e3, 0, 0, 0, 0], [0, 0, 0, 500, 0, 0, 0]],
    [-4, -0.01],
    [-0.01, -INF, -INF, -INF, -INF, -INF, -INF],
    [INF, INF, 0.002, INF, INF, INF, INF],
    [SecondOrderCone(3, 4)],
)
UNBOUNDED_ALONG_SOC = Problem.of(np.zeros((4, 4)), [-5e-6, 0, 0, 0],
                                 cones=[SecondOrderCone(0, 4)])


def test_item1_infeasible_soc_problem_is_not_solved():
    """Item 1: Clarabel certifies this primal infeasible; fccqp said SOLVED (dual_res 486)."""
    assert clarabel_solve(*INFEASIBLE_WITH_SOC.args()).status == "primal_infeasible"
    result = solve_and_verify(INFEASIBLE_WITH_SOC)
    assert result.status is Status.PRIMAL_INFEASIBLE


def test_item1_unbounded_soc_problem_is_not_solved_at_iteration_zero():
    """Item 1: q'x -> -inf along the cone's axis; fccqp said SOLVED at iteration 0."""
    assert clarabel_solve(*UNBOUNDED_ALONG_SOC.args()).status == "dual_infeasible"
    result = solve_and_verify(UNBOUNDED_ALONG_SOC)
    assert result.status is Status.DUAL_INFEASIBLE


def _rows_of_size_1e3_and_1e_7() -> Problem:
    P, q, A, b, lb, ub, cones = random_problem(21, n=5, m=2, n_cones=1, n_box=2)
    rows = np.array([1e3, 1e-7])
    return Problem.of(P, q, rows[:, None] * A, rows * b, lb, ub, cones)


@pytest.mark.parametrize("settings", [{}, {"eps_abs": 1e-8, "eps_rel": 1e-8}],
                         ids=["default", "tight"])
def test_item1_claimed_residuals_are_those_of_the_returned_point(settings):
    """Item 1: with equality rows of size 1e3 and 1e-7 the claimed dual_res (3.8e-5) was
    10x below the returned point's (3.7e-4); verify_solution checks the claims."""
    problem = _rows_of_size_1e3_and_1e_7()
    result = solve_and_verify(problem, **settings)
    assert_optimum(problem, result, rtol=1e-3)


@pytest.mark.parametrize("seed", range(4))
def test_item1_claimed_gap_is_that_of_the_returned_point(seed):
    """Item 1 (and Result.gap): a SOLVED result reports the gap of its own point."""
    problem = Problem.of(*random_problem(seed, n=12, m=3, n_cones=2, n_box=3))
    result = fccqp.solve(*problem.args())
    report = verify_solution(problem, result)
    assert np.isfinite(result.gap)
    value, _ = report.checks["duality gap"]
    assert result.gap == pytest.approx(value, rel=1e-6, abs=1e-12)


# item 2 ---------------------------------------------------------------------------

BASE = Problem.of(*random_problem(22, n=10, m=3, n_cones=1, n_box=3))


def _extreme(change: str) -> tuple[Problem, dict, dict]:
    """The base problem with one of item 2's or item 6's extreme changes."""
    names = "P q A b lb ub cones".split()
    data, settings, guess = dict(zip(names, BASE.args(), strict=True)), {}, {}
    if change in ("q", "b"):
        data[change] = data[change] * 1e300
    elif change == "P":
        data["P"] = data["P"] * 1e100
    elif change in ("rho", "sigma"):
        settings[change] = 1e300
    else:
        guess["x0"] = np.full(BASE.n, 1e300)
    return Problem.of(**data), settings, guess


@pytest.mark.parametrize("change", ["q", "b", "rho", "x0", "P", "sigma"])
def test_items2_6_extreme_data_is_rejected_or_never_a_wrong_answer(change):
    """Items 2 and 6: q, b * 1e300, rho = 1e300, x0 = 1e300 gave NaN as SOLVED; P * 1e100
    and sigma = 1e300 broke A x = b. Acceptable: an error naming the argument, or a
    status whose promises verify_solution confirms (NaN only with NUMERICAL_ERROR)."""
    problem, settings, guess = _extreme(change)
    try:
        result = fccqp.Solver(**settings).solve(*problem.args(), **guess)
    except (ValueError, TypeError) as exn:
        assert change in str(exn)
        return
    finite = all(np.isfinite(v).all() for v in (result.x, result.y, result.z))
    assert finite or result.status is Status.NUMERICAL_ERROR, result.status
    verify_solution(problem, result, Tolerances.of(**settings))


# item 3 ---------------------------------------------------------------------------

P_BAD = np.diag([-0.01, 1, -0.01])
BOX3 = dict(lb=-np.ones(3), ub=np.ones(3))


@pytest.mark.parametrize("start", ["warm", "x0", "cold"])
def test_item3_convexity_checked_on_every_new_P_and_no_poisoned_state(start):
    """Item 3: after one valid solve, a warm Solver accepted P_bad (NaN, SOLVED) and the
    next valid solve returned NaN too."""
    q = np.array([0.3, -0.2, 0.1])
    good = Problem.of(np.eye(3), q, **BOX3)
    solver = fccqp.Solver(warm_start=start != "cold")
    guess = {"x0": np.zeros(3)} if start == "x0" else {}
    with pytest.raises(ValueError, match="P"):
        fccqp.solve(P_BAD, q, **BOX3)
    verify_solution(good, solver.solve(*good.args(), **guess))
    with pytest.raises(ValueError, match="P"):
        solver.solve(P_BAD, q, **BOX3, **guess)
    after = solver.solve(*good.args(), **guess)
    verify_solution(good, after)
    np.testing.assert_allclose(after.x, -q, atol=1e-4)


# item 4 ---------------------------------------------------------------------------

DEPENDENT_ROWS = Problem.of(
    np.eye(3), [-0.2, -0.2, 0.4], [[-0.4, -1.2, 1.7], [-0.8, -2.4, 3.4]], [2.55, 5.1],
    [-0.9, 0.3, 0.8], None,
)


@pytest.mark.parametrize("rows", [1, 2], ids=["one row", "row 2 = 2 x row 1"])
def test_item4_dependent_rows_are_not_infeasible(rows):
    """Item 4: with the duplicated row fccqp said PRIMAL_INFEASIBLE (Clarabel: 2.093)."""
    P, q, A, b, lb, ub, cones = DEPENDENT_ROWS.args()
    problem = Problem.of(P, q, A[:rows], b[:rows], lb, ub, cones)
    result = solve_and_verify(problem)
    assert_optimum(problem, result)
    assert result.obj == pytest.approx(2.093, abs=1e-3)


@pytest.mark.parametrize("scale", [1.0, 1e6])
def test_item4_small_curvature_is_not_unbounded(scale):
    """Item 4: diag(0, 1e-6), q = (0, -5e-5) in SOC(0, 2) has the optimal value -1.25e-3
    at x_1 = 50 and any x_0 >= 50 (the cost does not see x_0); fccqp said DUAL_INFEASIBLE
    unless the problem was multiplied by 1e6."""
    problem = Problem.of(scale * np.diag([0, 1e-6]), scale * np.array([0, -5e-5]),
                         cones=[SecondOrderCone(0, 2)])
    result = solve_and_verify(problem)
    assert result.status is Status.SOLVED
    assert result.x[1] == pytest.approx(50, rel=1e-3) and result.x[0] >= 50 * (1 - 1e-6)
    assert result.obj == pytest.approx(-1.25e-3 * scale, rel=1e-6)


# item 5 ---------------------------------------------------------------------------

def test_item5_positive_definite_P_with_dependent_rows_is_accepted():
    """Item 5: rejected as "not positive semidefinite: smallest eigenvalue is 3e+07"."""
    problem = Problem.of([[3e7]], [2e4], [[2e5], [4e5]], [400, 800], [0.002], [0.002])
    result = solve_and_verify(problem, scaling=0)
    assert result.status is Status.SOLVED
    assert result.x == pytest.approx([0.002], rel=1e-9)


# item 7 ---------------------------------------------------------------------------

ITERATIONS_TO_CERTIFY = 500
"""Item 7: "certified within a few hundred iterations"."""


def test_item7_inconsistent_rows_with_a_fixed_entry_are_certified():
    """Item 7: 2.6 x = 0.076 and 2.6 x = 0.1 with x fixed ran 4000 iterations."""
    problem = Problem.of([[100]], [-46], [[2.6], [2.6]], [0.076, 0.1], [0.029], [0.029])
    result = solve_and_verify(problem)
    assert result.status is Status.PRIMAL_INFEASIBLE
    assert result.iterations <= ITERATIONS_TO_CERTIFY


def test_item7_cvxpy_lp_4_is_certified():
    """Item 7: CVXPY's standard lp_4 (sum(x), x <= 0, x >= 1) returned user_limit."""
    cp = pytest.importorskip("cvxpy")
    from cvxpy.tests.solver_test_helpers import StandardTestLPs

    from fccqp_cvxpy import FCCQP

    sth = StandardTestLPs.test_lp_4(FCCQP)
    assert sth.prob.status == cp.INFEASIBLE
    assert sth.prob.solver_stats.num_iters <= ITERATIONS_TO_CERTIFY


# item 8 ---------------------------------------------------------------------------

def test_item8_inconsistent_rows_without_constrained_entries():
    """Item 8: no bounds, no cones, inconsistent rows: numba's zero-size reduction error."""
    problem = Problem.of(np.eye(1), np.zeros(1), [[1], [1]], [0, 1])
    result = solve_and_verify(problem)
    assert result.status is Status.PRIMAL_INFEASIBLE


@pytest.mark.parametrize("start", ["x0", "warm"])
def test_item8_duplicated_rows_without_constrained_entries(start):
    """Item 8: consistent duplicated rows with x0 or a warm start crashed the same way."""
    problem = Problem.of(np.eye(1), np.zeros(1), [[1], [1]], [1, 1])
    solver = fccqp.Solver()
    if start == "warm":
        solver.solve(*problem.args())
    result = solver.solve(*problem.args(), **({"x0": np.zeros(1)} if start == "x0" else {}))
    verify_solution(problem, result)
    assert result.status is Status.SOLVED and result.x == pytest.approx([1.0])


def test_item8_initial_guess_without_constraints(capfd):
    """Item 8: Solver().solve(eye(2), ones(2), x0=zeros(2)) made LAPACK print DTRSM errors."""
    problem = Problem.of(np.eye(2), np.ones(2))
    result = fccqp.Solver().solve(*problem.args()[:2], x0=np.zeros(2))
    verify_solution(problem, result)
    assert result.x == pytest.approx([-1.0, -1.0])
    captured = capfd.readouterr()
    assert "illegal value" not in captured.out + captured.err


# item 9 ---------------------------------------------------------------------------

@pytest.mark.parametrize(
    "arguments, name",
    [
        (dict(cones=None), "cones"),
        (dict(cones=5), "cones"),
        (dict(cones=[FrictionCone(0, 0.5, "abc")]), r"cones\[0\]\.normal"),
        (dict(cones=[FrictionCone(0, 0.5, (0, 0, 1j))]), r"cones\[0\]\.normal"),
        (dict(cones=[SecondOrderCone(0, 10**20)]), r"cones\[0\]"),
        (dict(cones=[FrictionCone(10**20, 0.5)]), r"cones\[0\]"),
        (dict(alpha=None), "alpha"),
        (dict(alpha="1.6"), "alpha"),
        (dict(adaptive_rho_tolerance=None), "adaptive_rho_tolerance"),
        (dict(max_iter=10**30), "max_iter"),
        (dict(scaling=10**30), "scaling"),
        (dict(scaling=10**7), "scaling"),
        (dict(x0="abc"), "x0"),
        (dict(x0=object()), "x0"),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_item9_errors_name_the_argument(arguments, name):
    """Item 9 (and 14's scaling=10**7, now out of range): wrong types and sizes raise
    ValueError or TypeError naming the argument, not OverflowError or numba's errors."""
    args = dict(P=np.eye(6), q=np.ones(6), cones=())
    arguments = dict(arguments)   # the parameter itself is shared by every backend's run
    guess = {"x0": arguments.pop("x0")} if "x0" in arguments else {}
    cones = arguments.pop("cones", ())
    with pytest.raises((ValueError, TypeError), match=name):
        fccqp.Solver(**arguments).solve(args["P"], args["q"], cones=cones, **guess)


def test_item9_cvxpy_huge_max_iter_names_the_setting():
    """Item 9: max_iter=10**30 through CVXPY raised numba's TypingError."""
    cp = pytest.importorskip("cvxpy")
    from fccqp_cvxpy import FCCQP

    x = cp.Variable(2)
    problem = cp.Problem(cp.Minimize(cp.sum_squares(x - 1)), [x >= 0])
    with pytest.raises((ValueError, TypeError), match="max_iter"):
        problem.solve(solver=FCCQP, max_iter=10**30)


# item 10 --------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["P", "q", "A", "b", "lb", "ub"])
def test_item10_complex_input_is_rejected(name):
    """Item 10: solve(eye(2), [1, 1] + 5j) was SOLVED on the real part."""
    data = dict(P=np.eye(2), q=np.ones(2), A=np.ones((1, 2)), b=np.ones(1),
                lb=-np.ones(2), ub=np.full(2, 2.0))
    data[name] = data[name] + 5j
    with pytest.raises((ValueError, TypeError), match=rf"\b{name}\b"):
        fccqp.solve(**data)


@pytest.mark.parametrize("name", ["G", "h"])
def test_item10_complex_inequalities_are_rejected_by_qpsolvers_backend(name):
    """Item 10: qpsolvers' G and h likewise."""
    qpsolvers = pytest.importorskip("qpsolvers")
    data = dict(P=np.eye(2), q=np.ones(2), G=np.ones((1, 2)), h=np.ones(1))
    data[name] = data[name] + 5j
    with pytest.raises((ValueError, TypeError), match=rf"\b{name}\b"):
        qpsolvers.solve_qp(**data, solver="fccqp")


# item 11 --------------------------------------------------------------------------

@pytest.mark.parametrize(
    "valid, invalid",
    [
        (FrictionCone(0, 0.5), FrictionCone(0, 0.5 + 0j)),
        (FrictionCone(0, 0.5, (0.0, 0.0, 1.0)), FrictionCone(0, 0.5, (0, 0, 1 + 0j))),
        (SecondOrderCone(0, 2), SecondOrderCone(0.0, 2)),
        (SecondOrderCone(0, 2), SecondOrderCone(0, 2.0)),
    ],
    ids=["complex mu", "complex normal", "float start", "float dim"],
)
def test_item11_memo_does_not_admit_equal_hashing_invalid_cones(valid, invalid):
    """Item 11: after a valid cone was solved, an invalid one that hashes equal passed."""
    assert valid == invalid and hash(valid) == hash(invalid)
    P, q = np.eye(3), np.ones(3)
    assert fccqp.solve(P, q, cones=[valid]).status is Status.SOLVED
    with pytest.raises(TypeError, match=r"cones\[0\]"):
        fccqp.solve(P, q, cones=[invalid])


# item 12 --------------------------------------------------------------------------

def test_item12_bounds_edited_in_place_are_seen():
    """Item 12: validate kept the caller's lb/ub, so in-place edits were compared with
    themselves and the reused structure kept a stale rho scaling. A Solver given the
    edited arrays must behave exactly as one given fresh copies."""
    P, q, A, b, lb, ub, cones = random_problem(23, n=12, m=3, n_cones=1, n_box=4)
    box = np.flatnonzero(np.isfinite(lb))
    in_place, copied = fccqp.Solver(), fccqp.Solver()
    in_place.solve(P, q, A, b, lb, ub, cones)
    copied.solve(P, q, A, b, lb.copy(), ub.copy(), cones)
    lb[box[0]] = ub[box[0]] = 0.5 * (lb[box[0]] + ub[box[0]])  # fix an entry in place
    edited = in_place.solve(P, q, A, b, lb, ub, cones)
    fresh = copied.solve(P, q, A, b, lb.copy(), ub.copy(), cones)
    verify_solution(Problem.of(P, q, A, b, lb, ub, cones), edited)
    assert edited.iterations == fresh.iterations
    np.testing.assert_array_equal(edited.x, fresh.x)


# item 13 --------------------------------------------------------------------------

FREQUENT_RHO_CHANGES = dict(adaptive_rho_interval=1, adaptive_rho_tolerance=1.01)
"""Refactor at nearly every iteration, so infeasibility tests run right after rho changes."""


@pytest.mark.parametrize(
    "problem",
    [
        Problem.of(np.eye(3), np.zeros(3), [[1, 1, 1]], [10], -np.ones(3), np.ones(3)),
        Problem.of(np.eye(3), np.zeros(3), [[0, 0, 1]], [-1], cones=[FrictionCone(0, 0.5)]),
        Problem.of(*random_problem(24, n=12, m=3, n_cones=2, n_box=3)),
    ],
    ids=["box infeasible", "cone infeasible", "feasible"],
)
def test_item13_infeasibility_tests_after_rho_changes(problem):
    """Item 13: after a refactorization the reduced iteration's u_prev / v_prev were
    coordinates in the old table, so the infeasibility tests saw a point that never
    existed. With rho changing at every check, certificates must still verify and a
    feasible problem must still solve (P = I keeps the reduced form)."""
    result = solve_and_verify(problem, **FREQUENT_RHO_CHANGES)
    expected = clarabel_solve(*problem.args()).status
    assert result.status.value == expected or (
        expected == "solved" and result.status is Status.SOLVED
    )


# item 14 --------------------------------------------------------------------------

def test_item14_a_budget_smaller_than_the_setup_leaves_no_iterations():
    """Item 14: time_limit did not bound setup. A budget of 1 microsecond is spent by
    the validation and factorization of a 200-variable problem, so no iteration may run."""
    problem = random_problem(25, n=200, m=60, n_cones=10, n_box=40)
    result = fccqp.solve(*problem, time_limit=1e-6)
    assert result.status is Status.TIME_LIMIT_REACHED
    assert result.iterations == 0
    verify_solution(Problem.of(*problem), result)


# item 15 --------------------------------------------------------------------------

LOG_ROW = re.compile(r"^\s*(\d+)\s+([-+.\deE]+)\s+([-+.\deE]+)", re.MULTILINE)


@pytest.mark.kkt_backends("auto", "schur_reduced", "ldl_reduced", "ldl_full", reason=(
    "the log is the compiled loop's, the same on both storages; the run to 1e-12 on the "
    "sparse path took 37 s of CPU (120 s of wall time at load 25)"))
def test_item15_verbose_log_is_sparse_and_ends_with_the_returned_residual(capsys):
    """Item 15: verbose=True printed every iteration, and the qpsolvers doc example logged
    5.4e-05 while returning prim_res = 0.0. Print like OSQP (every 25-50 iterations and
    the last) and return the last logged residual."""
    problem = random_problem(5, n=40, m=10, n_cones=4, n_box=8)
    result = fccqp.solve(*problem, verbose=True, eps_abs=1e-12, eps_rel=1e-12, max_iter=20000,
                         anderson_memory=0, alpha=1.0, polish=False)
    rows = LOG_ROW.findall(capsys.readouterr().out)
    assert result.iterations >= 100, "the test needs a long enough run"
    assert len(rows) <= result.iterations / 25 + 3
    last_iteration, last_prim, last_dual = rows[-1]
    assert int(last_iteration) == result.iterations
    assert float(last_prim) == pytest.approx(result.prim_res, rel=1e-3)
    assert float(last_dual) == pytest.approx(result.dual_res, rel=1e-3)


# item 16 --------------------------------------------------------------------------

def test_item16_cvxpy_lp_bound_attr():
    """Item 16: CVXPY's own test_lp_bound_attr, which needs BOUNDED_VARIABLES."""
    pytest.importorskip("cvxpy")
    from cvxpy.tests.solver_test_helpers import StandardTestLPs

    from fccqp_cvxpy import FCCQP

    StandardTestLPs.test_lp_bound_attr(FCCQP, eps_abs=1e-8, eps_rel=1e-8)


def test_item16_cvxpy_qp_bound_attr():
    """Item 16: CVXPY's qp_bound_attr problem; its test_qp_bound_attr reads QP-solver data
    (``n_ineq``), so the conic equivalent is checked: bounds arrive as arrays, no rows."""
    pytest.importorskip("cvxpy")
    import cvxpy.settings as s
    from cvxpy.tests.solver_test_helpers import qp_bound_attr

    from fccqp_cvxpy import FCCQP

    sth = qp_bound_attr()
    data, _, _ = sth.prob.get_problem_data(FCCQP)
    assert data[s.LOWER_BOUNDS] is not None and data[s.UPPER_BOUNDS] is not None
    assert data[s.DIMS].nonneg == 0
    sth.solve(FCCQP, eps_abs=1e-8, eps_rel=1e-8)
    sth.verify_objective(4)
    sth.verify_primal_values(4)


def test_numerical_error_maps_to_failure_in_both_integrations():
    """Items 2 and 16: NUMERICAL_ERROR is CVXPY's solver_error and qpsolvers' found=False."""
    pytest.importorskip("cvxpy")
    import cvxpy.settings as s

    from fccqp_cvxpy.solver import STATUS_MAP

    assert STATUS_MAP[Status.NUMERICAL_ERROR] == s.SOLVER_ERROR
    assert set(STATUS_MAP) == set(Status)
    assert not Status.NUMERICAL_ERROR.is_solved()


# item 17 --------------------------------------------------------------------------

def test_item17_inequality_multipliers_are_exactly_nonnegative():
    """Item 17: z came back as -4.8e-18 where the docs say "exactly >= 0"."""
    qpsolvers = pytest.importorskip("qpsolvers")
    from qpsolvers import problems

    getters = [problems.get_qpsut01, problems.get_qpsut03, problems.get_qptest,
               problems.get_qpgurdu, problems.get_qpgurabs]
    for getter in getters:
        problem, _ = getter()
        if problem.G is None:
            continue
        solution = qpsolvers.solve_problem(problem, solver="fccqp")
        assert (solution.z >= 0).all(), getter.__name__


def test_item17_listed_as_sparse_and_large_sparse_input_is_solved():
    """Item 17: fccqp takes scipy.sparse input, so it is a sparse solver too; a problem
    beyond the dense core's limit (it used to raise a ValueError naming its size) now
    takes the sparse path, without being densified."""
    qpsolvers = pytest.importorskip("qpsolvers")
    import scipy.sparse as sp

    from fccqp.settings import MAX_DENSE_KKT_ROWS

    assert "fccqp" in qpsolvers.sparse_solvers and "fccqp" in qpsolvers.dense_solvers
    n = MAX_DENSE_KKT_ROWS
    G = sp.eye(n, format="csc")
    solution = qpsolvers.solve_problem(
        qpsolvers.Problem(sp.eye(n, format="csc"), np.ones(n), G, np.ones(n)), solver="fccqp")
    assert solution.found and solution.extras["backend"] == "sparse"
    np.testing.assert_allclose(solution.x, -np.ones(n), atol=1e-9)


# item 18 --------------------------------------------------------------------------

def test_item18_negative_curvature_fixed_by_the_equalities_is_convex():
    """Item 18 (correct behaviour, now documented): diag(-1, 1) with x_0 = 1 fixed is
    convex on the feasible set, so it is solved, at x = (1, 0)."""
    problem = Problem.of(np.diag([-1.0, 1.0]), np.zeros(2), [[1.0, 0.0]], [1.0])
    result = solve_and_verify(problem)
    assert result.status is Status.SOLVED
    np.testing.assert_allclose(result.x, [1.0, 0.0], atol=1e-9)


def test_item18_negative_curvature_on_the_null_space_is_rejected():
    """Item 18, the other side: diag(1, -1) with x_0 = 1 is unbounded below along x_1, a
    non-convex QP: rejected with a ValueError naming P."""
    with pytest.raises(ValueError, match="P"):
        fccqp.solve(np.diag([1.0, -1.0]), np.zeros(2), [[1.0, 0.0]], [1.0])


def test_item18_formulation_documents_the_null_space_criterion():
    """Item 18: the docs state the criterion the solver applies."""
    text = (ROOT / "docs" / "formulation.md").read_text()
    assert "null space of `A`" in text and "inertia" in text


# item 19 --------------------------------------------------------------------------

def test_item19_cvxpy_extra_matches_the_docs_and_the_tested_version():
    """Item 19: cvxpy.md said CVXPY >= 1.9, the extra said >= 1.5."""
    cvxpy = pytest.importorskip("cvxpy")
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    (requirement,) = extras["cvxpy"]
    required = re.fullmatch(r"cvxpy>=([\d.]+)", requirement).group(1)
    documented = re.search(r"cvxpy >= ([\d.]+)", (ROOT / "docs" / "cvxpy.md").read_text())
    assert documented.group(1) == required
    installed = tuple(int(p) for p in cvxpy.__version__.split(".")[:2])
    assert installed >= tuple(int(p) for p in required.split("."))


# the certificate checks themselves ------------------------------------------------

def test_verify_rejects_a_fake_certificate():
    """verify_solution is not vacuous: a PRIMAL_INFEASIBLE claim on a feasible problem
    with a made-up certificate fails its conditions."""
    problem = Problem.of(np.eye(2), np.ones(2), [[1.0, 1.0]], [1.0], -np.ones(2), np.ones(2))
    honest = fccqp.solve(*problem.args())
    fake = fccqp.Result(**{**honest.__dict__, "status": Status.PRIMAL_INFEASIBLE,
                           "certificate": np.array([1.0, -1.0, -1.0])})
    assert not check_solution(problem, fake).passed
