"""The sparse path (the compiled core on compressed columns, ``SPARSE_LDL``): forced on
small problems, and taken on its own by problems whose KKT matrix exceeds
``MAX_DENSE_KKT_ROWS``. Its equilibration is pinned to the dense one in
``tests/test_scaling_csc.py``.

Its answers are checked against Clarabel at tight tolerance and against the dense
path, its statuses with ``verify_solution`` (which recomputes everything from the
data), and its certificates likewise; above the limit, through ``fccqp.solve`` and
through qpsolvers with ``scipy.sparse`` matrices.
"""

import sys

import numpy as np
import pytest
import scipy.sparse as sp

import fccqp
from fccqp import FrictionCone, SecondOrderCone, Status
from fccqp.settings import MAX_DENSE_KKT_ROWS
from problems import large_problem, random_problem
from reference import clarabel_solve, clarabel_sparse_form
from verify import Tolerances, from_qpsolvers, verify_solution

SPARSE = dict(kkt_backend="sparse")
TIGHT = dict(eps_abs=1e-8, eps_rel=1e-8, max_iter=20000)
TIGHT_TOLERANCES = Tolerances.of(**TIGHT)


def sparse_args(problem):
    """The problem with ``P`` and ``A`` as CSC matrices."""
    P, q, A, b, lb, ub, cones = problem
    return sp.csc_matrix(P), q, sp.csc_matrix(A), b, lb, ub, cones


@pytest.mark.parametrize("seed", range(6))
def test_matches_clarabel_and_the_dense_path(seed):
    """Friction cones (tilted normals included), a second-order cone on odd seeds, a box
    and equalities, at tight tolerance."""
    problem = random_problem(seed, soc_dim=4 if seed % 2 else 0)
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*sparse_args(problem), **SPARSE, **TIGHT)
    assert result.status is Status.SOLVED and result.backend == "sparse"
    np.testing.assert_allclose(result.x, reference.x, atol=1e-4)
    assert result.obj - reference.obj <= 1e-7 * (1 + abs(reference.obj))
    verify_solution(problem, result, TIGHT_TOLERANCES)
    dense = fccqp.solve(*problem, **TIGHT)
    np.testing.assert_allclose(result.x, dense.x, atol=1e-6)


@pytest.mark.parametrize("seed", range(3))
def test_default_settings_reach_tolerance_and_report_true_residuals(seed):
    problem = random_problem(seed, psd_rank=10, n=40, m=10, n_cones=4, n_box=8)
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*problem, **SPARSE)
    assert result.status is Status.SOLVED
    verify_solution(problem, result, Tolerances(factor=1.0))
    assert abs(result.obj - reference.obj) <= 1e-3 * (1 + abs(reference.obj))


def test_polishing_gives_the_exact_optimum():
    """The README's example: the friction cone binds; the polished point is exact."""
    P = np.diag([1.0, 1.0, 1e-3, 1e-3, 1e-3])
    q = np.array([-8.0, 0.0, 0.0, 0.0, 0.0])
    A = np.array([[1.0, 0, -1, 0, 0], [0, 1, 0, -1, 0], [0, 0, 0, 0, 1]])
    b = np.array([0.0, 0.0, 10.0])
    lb, ub = np.array([-6, -6] + [-np.inf] * 3), np.array([6, 6] + [np.inf] * 3)
    cones = [FrictionCone(start=2, mu=0.5)]
    result = fccqp.solve(P, q, A, b, lb, ub, cones, **SPARSE)
    assert result.status is Status.SOLVED and result.polished
    np.testing.assert_allclose(result.x, [5.0, 0.0, 5.0, 0.0, 10.0], atol=1e-9)
    verify_solution((P, q, A, b, lb, ub, cones), result, Tolerances(factor=1.0))
    plain = fccqp.solve(P, q, A, b, lb, ub, cones, polish=False, **SPARSE)
    assert plain.status is Status.SOLVED and not plain.polished


def test_the_kkt_solve_meets_equalities_whose_curvature_lies_below_delta():
    """``A (P + sigma I)^-1 A'`` of 1e-11 beside the (2, 2) block's ``-delta`` of 1e-9:
    each refinement step recovers 1 % of its correction, which is no sign that ``A x =
    b`` has no solution; the solve refactors with a smaller ``delta`` and meets it."""
    from fccqp.sparse_kkt import DELTA, SparseKKT

    P, A = sp.csc_matrix(np.diag([10.0, 10.0])), sp.csc_matrix(np.diag([1e-5, 1e-5]))
    kkt = SparseKKT(P, A, np.zeros(0, dtype=np.intp), np.ones(2))
    kkt.factor(1e-6, np.zeros(0))
    assert kkt.delta == DELTA
    sol = kkt.solve(np.array([0.0, 0.0, 1e-5, 2e-5]))
    np.testing.assert_allclose(sol[:2], [1.0, 2.0], rtol=1e-9)
    assert kkt.delta < 1e-2 * DELTA


def _inconsistent_beside_huge_p():
    """``P`` of 1e11 on three entries and 0 on the first, which only ``sigma`` weighs,
    beside three rows of rank two whose right-hand sides miss each other by 0.01."""
    P = np.diag([0.0, 1e11, 1e11, 1e11])
    rows = np.array([[1.0, 1.0, -1.0, 2.0], [-1.0, 2.0, 1.0, -1.0]])
    A = np.vstack([rows, rows[0] + rows[1]])
    return P, A, np.array([1.0, 2.0, 3.01])


def test_the_kkt_solve_leaves_the_least_squares_residual_beside_an_entry_only_sigma_weighs():
    """Eliminated first in qdldl's order, the entry that only ``sigma`` (1e-6) weighs adds
    ``a a' / sigma`` (1e6) to the rows' block, whose rounding buries their curvature
    (6e-11) and ``delta``: the factorization solved neither its own matrix nor the
    system (residuals of 2.6 off the least-squares ones). The solve pivots and returns
    the least-squares residual, up to the bias of ``delta``."""
    from fccqp.sparse_kkt import SparseKKT

    P, A, b = _inconsistent_beside_huge_p()
    kkt = SparseKKT(sp.csc_matrix(P), sp.csc_matrix(A), np.zeros(0, dtype=np.intp),
                    np.ones(3))
    kkt.factor(1e-6, np.zeros(0))
    x = kkt.solve(np.concatenate([np.zeros(4), b]))[:4]
    least_squares = b - A @ np.linalg.lstsq(A, b, rcond=None)[0]
    np.testing.assert_allclose(b - A @ x, least_squares, atol=1e-2)


def test_inconsistent_rows_beside_an_entry_only_sigma_weighs_are_certified_at_the_start():
    """The same rows beside a boxed entry: the cold start's least-squares point carries
    the equality certificate, as on the dense path (0 iterations), where the sparse path
    needed its auxiliary tries (12063 iterations)."""
    P, A, b = _inconsistent_beside_huge_p()
    q = np.array([1.0, -1.0, 0.5, 0.2])
    lb, ub = np.full(4, -np.inf), np.array([3.0, np.inf, np.inf, np.inf])
    result = fccqp.solve(sp.csc_matrix(P), q, sp.csc_matrix(A), b, lb, ub, **SPARSE)
    assert result.status is Status.PRIMAL_INFEASIBLE and result.iterations == 0
    verify_solution((P, q, A, b, lb, ub, []), result)


def test_the_polish_pivots_where_delta_lies_below_the_rounding_of_p():
    """Unscaled, ``P`` of 1.4e14 on 15 of 19 entries and zero on the others, a dependent
    row in ``A`` (the fuzzer's "P huge" class): the polished QP's matrix spans 1e10
    (``P`` times the cost scale) to ``delta`` = 1e-8, where qdldl's pivots without
    pivoting are lost to rounding; the polish factors it with pivoting and lands on the
    dense backend's optimum."""
    from fuzzing import Case

    problem = Case.of("extreme_data", 2900221).scenario().problem.args()
    unscaled = dict(scaling=0, max_iter=100)
    result = fccqp.solve(*sparse_args(problem), **SPARSE, **unscaled)
    assert result.status is Status.SOLVED and result.polished
    verify_solution(problem, result, Tolerances(factor=1.0))
    dense = fccqp.solve(*problem, kkt_backend="ldl_full", **unscaled)
    np.testing.assert_allclose(result.x, dense.x, atol=1e-6)


def test_rank_deficient_equalities():
    problem = random_problem(3, duplicate_rows=3)
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*problem, **SPARSE, **TIGHT)
    assert result.status is Status.SOLVED
    np.testing.assert_allclose(result.x, reference.x, atol=1e-5)
    verify_solution(problem, result, TIGHT_TOLERANCES)


@pytest.mark.parametrize("budget", [1, 2, 5, 20])
def test_equalities_exact_at_every_budget(budget):
    problem = random_problem(5, psd_rank=10)
    result = fccqp.solve(*problem, max_iter=budget, eps_abs=1e-12, eps_rel=0.0, **SPARSE)
    assert result.status in (Status.MAX_ITER_REACHED, Status.SOLVED_INACCURATE, Status.SOLVED)
    verify_solution(problem, result)   # A x = b to factorization accuracy, whatever the status


def test_budget_statuses():
    """Without the polish (which, after the budget, solves this problem's active set to
    1e-14 on every backend) the budgets are what stops the run."""
    problem = random_problem(11, psd_rank=10)
    result = fccqp.solve(*problem, max_iter=2, eps_abs=1e-12, eps_rel=0.0, polish=False,
                         **SPARSE)
    assert result.status is Status.MAX_ITER_REACHED
    verify_solution(problem, result)
    result = fccqp.solve(*problem, time_limit=1e-9, eps_abs=1e-12, eps_rel=0.0, **SPARSE)
    assert result.status is Status.TIME_LIMIT_REACHED
    verify_solution(problem, result)


def test_box_infeasible():
    problem = (np.eye(3), np.zeros(3), np.ones((1, 3)), [10.0], -np.ones(3), np.ones(3), ())
    result = fccqp.solve(*problem, **SPARSE)
    assert result.status is Status.PRIMAL_INFEASIBLE and np.isnan(result.gap)
    assert clarabel_solve(*problem).status == "primal_infeasible"
    verify_solution(problem, result)


def test_box_infeasible_through_many_rows():
    """A chain of equalities that pushes the last entry out of its box."""
    n = 40
    A = sp.diags([np.ones(n - 1), -np.ones(n - 1)], [0, 1], shape=(n - 1, n)).tocsc()
    b = np.full(n - 1, 0.1)   # x_i = x_{i+1} + 0.1, so x_0 = x_{n-1} + 3.9
    lb, ub = -np.ones(n), np.ones(n)
    problem = (np.eye(n), np.zeros(n), A, b, lb, ub, ())
    result = fccqp.solve(sp.eye(n, format="csc"), np.zeros(n), A, b, lb, ub, **SPARSE)
    assert result.status is Status.PRIMAL_INFEASIBLE
    verify_solution(problem, result)


def test_cone_infeasible():
    """The normal force must be negative: impossible inside a friction cone."""
    cones = [FrictionCone(0, 0.5)]
    problem = (np.eye(3), np.zeros(3), np.array([[0.0, 0.0, 1.0]]), [-1.0], None, None, cones)
    result = fccqp.solve(*problem, **SPARSE)
    assert result.status is Status.PRIMAL_INFEASIBLE
    verify_solution(problem, result)



@pytest.mark.parametrize(("mu", "gap"), [(0.3, 1e-3), (0.7, 1e-4), (1.0, 1e-4)])
def test_the_run_cleans_its_certificate_on_compressed_columns(mu, gap):
    """Rows ``fz = 1``, ``fx = mu (1 + gap)`` beside one friction cone: the certificates
    form a thin wedge that the differences of ADMM's multipliers reach only like 1/k.
    The run cleans its candidate by least squares on ``A A'`` (a Cholesky factor on the
    dense path, a ``qdldl`` one on compressed columns) and certifies in the iterations
    the dense path takes; the stalled run's auxiliary QPs, which answered such a case
    after 4000 iterations, are switched off here."""
    A = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    problem = (np.eye(3), np.array([0.1, -0.2, 0.3]), A, [1.0, mu * (1 + gap)], None, None,
               [FrictionCone(0, mu)])
    results = []
    for backend in ("sparse", "ldl_full"):
        solver = fccqp.Solver(fccqp.Settings(kkt_backend=backend))
        solver._stalled_certificates = False
        results.append(solver.solve(*problem))
    sparse, dense = results
    assert sparse.status is Status.PRIMAL_INFEASIBLE and sparse.backend == "sparse"
    assert sparse.iterations == dense.iterations < 4000
    verify_solution(problem, sparse)

def test_inconsistent_equalities():
    problem = (np.eye(2), np.zeros(2), np.array([[1.0, 1.0], [2.0, 2.0]]), [1.0, 3.0],
               [-5, -5], [5, 5], ())
    result = fccqp.solve(*problem, **SPARSE)
    assert result.status is Status.PRIMAL_INFEASIBLE
    verify_solution(problem, result)


def test_unbounded_lp():
    problem = (np.zeros((3, 3)), np.array([-1.0, 0.0, 0.0]), np.array([[0.0, 1.0, 1.0]]),
               [1.0], [0, 0, 0], [np.inf, 1, 1], ())
    result = fccqp.solve(*problem, **SPARSE)
    assert result.status is Status.DUAL_INFEASIBLE
    verify_solution(problem, result)
    assert result.certificate[0] > 0


def test_unbounded_along_cone():
    cones = [SecondOrderCone(0, 3)]
    problem = (np.zeros((3, 3)), np.array([0.0, 0.0, -1.0]), None, None, None, None, cones)
    result = fccqp.solve(*problem, **SPARSE)
    assert result.status is Status.DUAL_INFEASIBLE
    verify_solution(problem, result)


def test_lp_matches_clarabel():
    rng = np.random.default_rng(3)
    n = 12
    A = rng.standard_normal((4, n))
    problem = (np.zeros((n, n)), rng.uniform(0.1, 1, n), A, A @ rng.uniform(0.1, 1, n),
               np.zeros(n), np.full(n, 2.0), ())
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*problem, **SPARSE, **TIGHT)
    assert result.status is Status.SOLVED
    verify_solution(problem, result, TIGHT_TOLERANCES)
    assert abs(result.obj - reference.obj) <= 1e-6 * (1 + abs(reference.obj))


def test_nonconvex_objective_is_rejected():
    with pytest.raises(ValueError, match="not convex"):
        fccqp.solve(np.diag([1.0, -2.0, 1.0]), np.zeros(3), lb=-np.ones(3), ub=np.ones(3),
                    **SPARSE)
    # negative curvature that the equality removes is convex (docs/formulation.md)
    result = fccqp.solve(np.diag([-1.0, 1.0]), np.zeros(2), np.array([[1.0, 0.0]]), [1.0],
                         [-5, -5], [5, 5], **SPARSE)
    assert result.status is Status.SOLVED


@pytest.mark.parametrize("seed", [1, 4, 5])
def test_dependent_rows_of_1e10_unequilibrated_are_not_called_non_convex(seed):
    """Two rows of 1e10, one a multiple of the other, in the user's units (no
    equilibration) over entries that only ``sigma`` weighs: without pivoting the second
    row's pivot is lost to the rounding of ``|A|^2 / sigma``, and only a regularization
    scaled with ``|A|^2`` factors the KKT matrix of this convex QP."""
    rng = np.random.default_rng(seed)
    row = rng.standard_normal(6)
    A = 1e10 * np.vstack([row, 0.9 * row])
    b = A @ rng.standard_normal(6)
    P = sp.diags([1.0, 1.0, 1.0, 0.0, 0.0, 0.0], format="csc")
    problem = (P, np.zeros(6), sp.csc_matrix(A), b, None, None, ())
    result = fccqp.solve(*problem, scaling=0, **SPARSE)
    assert result.status is Status.SOLVED
    verify_solution(problem, result)


@pytest.mark.parametrize("args, error, message", [
    ((sp.csc_matrix(np.array([[1.0, 1.0], [0.0, 1.0]])), np.zeros(2)), ValueError,
     "P must be symmetric"),
    ((sp.csc_matrix((2, 3)), np.zeros(2)), ValueError, "P must be square"),
    ((sp.eye(2, format="csc"), np.zeros(3)), ValueError, "q must have 2 entries"),
    ((sp.eye(2, format="csc") * 1j, np.zeros(2)), TypeError, "P must be real"),
    ((sp.eye(2, format="csc"), np.zeros(2), sp.csc_matrix(np.array([[np.nan, 1.0]])), [1.0]),
     ValueError, "A contains NaN or inf"),
    ((sp.eye(2, format="csc"), np.zeros(2), sp.csc_matrix(np.ones((1, 3))), [1.0]),
     ValueError, "A must have 2 columns"),
    ((sp.eye(2, format="csc"), np.zeros(2), sp.csc_matrix(np.ones((1, 2))), [1.0, 2.0]),
     ValueError, "b must have 1 entries"),
    ((sp.eye(2, format="csc"), np.zeros(2), None, None, [1.0, 0.0], [0.0, 1.0]), ValueError,
     "lb > ub at index 0"),
    ((sp.eye(2, format="csc"), [0.0, np.inf]), ValueError, "q contains NaN or inf"),
])
def test_bad_input_names_the_argument(args, error, message):
    with pytest.raises(error, match=message):
        fccqp.solve(*args, **SPARSE)


def test_cone_entry_with_a_bound_is_rejected():
    with pytest.raises(ValueError, match="cone block and has a finite bound"):
        fccqp.solve(sp.eye(3, format="csc"), np.zeros(3), lb=[0.0, -np.inf, -np.inf],
                    cones=[FrictionCone(0, 0.5)], **SPARSE)


def test_warm_solver_reuses_the_factorization_and_the_solution():
    problem = random_problem(1, n_box=6)
    solver = fccqp.Solver(adaptive_rho=False, **SPARSE)
    first = solver.solve(*problem)
    again = solver.solve(*problem)
    assert first.status is again.status is Status.SOLVED
    assert again.factorizations == 0 and again.backend == "sparse"
    assert again.iterations <= first.iterations
    P, q, A, b, lb, ub, cones = problem
    moved = solver.solve(P, q + 0.01, A, b, lb, ub, cones)
    assert moved.factorizations == 0 and moved.status is Status.SOLVED
    verify_solution((P, q + 0.01, A, b, lb, ub, cones), moved)
    changed = solver.solve(1.01 * P, q, A, b, lb, ub, cones)
    assert changed.factorizations >= 1 and changed.status is Status.SOLVED
    verify_solution((1.01 * P, q, A, b, lb, ub, cones), changed)
    solver.reset()
    assert solver.solve(*problem).iterations == first.iterations


def test_x0_initial_guess():
    problem = random_problem(10)
    reference = clarabel_solve(*problem)
    result = fccqp.Solver(**SPARSE).solve(*problem, x0=reference.x)
    assert result.status is Status.SOLVED
    verify_solution(problem, result)


def test_verbose_prints_log(capsys):
    fccqp.solve(*random_problem(14), verbose=True, **SPARSE)
    out = capsys.readouterr().out
    assert "prim_res" in out and "status: solved" in out and "sparse backend" in out


def test_settings_name_the_sparse_backend():
    assert fccqp.Settings(kkt_backend="sparse").kkt_backend == "sparse"
    with pytest.raises(ValueError, match="ldl_full, sparse"):
        fccqp.Settings(kkt_backend="qdldl")


def test_missing_qdldl_is_a_clear_import_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "qdldl", None)
    with pytest.raises(ImportError, match="pip install qdldl"):
        fccqp.solve(np.eye(2), np.zeros(2), lb=[0, 0], ub=[1, 1], **SPARSE)


def clarabel_sparse(P, q, A, b, lb, ub, cones):
    """Clarabel at tight tolerance on a sparse problem with friction cones about z."""
    clarabel = pytest.importorskip("clarabel")
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-10
    solution = clarabel.DefaultSolver(*clarabel_sparse_form(P, q, A, b, lb, ub, cones),
                                      settings).solve()
    assert str(solution.status) == "Solved"
    x = np.array(solution.x)
    return x, float(0.5 * x @ (P @ x) + q @ x)


def test_problem_above_the_limit_takes_the_sparse_path():
    n = MAX_DENSE_KKT_ROWS
    problem = P, q, A, b, lb, ub, cones = large_problem(n)
    result = fccqp.solve(*problem)
    assert result.status is Status.SOLVED and result.backend == "sparse"
    x, obj = clarabel_sparse(*problem)
    assert abs(result.obj - obj) <= 1e-8 * (1 + abs(obj))
    np.testing.assert_allclose(result.x, x, atol=1e-5)
    assert np.abs(A @ result.x - b).max() <= 1e-12 * n


def test_qpsolvers_sparse_problem_above_the_limit():
    """qpsolvers' sparse least-squares problem (as ``solve_ls`` poses it without
    conversion), whose slack form has 5101 KKT rows: solved with scipy.sparse input,
    meeting the KKT conditions (recomputed by ``verify_solution``) and qpsolvers' own
    checks, at Clarabel's objective (tight tolerance) or better."""
    qpsolvers = pytest.importorskip("qpsolvers")
    from qpsolvers.problems import get_sparse_least_squares

    R, s, G, h, A, b, _, _ = get_sparse_least_squares(1700)
    P, q = (R.T @ R).tocsc(), -(s @ R)
    problem = qpsolvers.Problem(P, q, G, h, A, b)
    assert P.shape[0] + A.shape[0] + 2 * G.shape[0] > MAX_DENSE_KKT_ROWS
    solution = qpsolvers.solve_problem(problem, solver="fccqp")
    assert solution.found and solution.extras["backend"] == "sparse"
    assert solution.is_optimal(1e-5 * max(1.0, np.abs(q).max()))
    verify_solution(*from_qpsolvers(problem, solution))
    reference = qpsolvers.solve_problem(problem, solver="clarabel", tol_gap_abs=1e-10,
                                        tol_gap_rel=1e-10, tol_feas=1e-10)
    assert solution.obj - reference.obj <= 1e-12 * abs(reference.obj)
    # P = I: the optimum is unique, but at an objective of 1e8 Clarabel's tolerance
    # leaves entries up to 3e-3 inside constraints that fccqp's polished point holds
    # exactly (x[915] + x[916] <= 1 with x[915] = 0, against 5.6e-4 for Clarabel)
    np.testing.assert_allclose(solution.x, reference.x, atol=1e-2)
    x = qpsolvers.solve_qp(P, q, G, h, A, b, solver="fccqp")
    np.testing.assert_array_equal(x, solution.x)
