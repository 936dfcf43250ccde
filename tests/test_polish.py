"""Polishing: the exact solution on ADMM's active set, returned only when it is better."""

import numpy as np
import pytest
from fccqp.polish_ops import polish_point
from fccqp.polish_table import factor_solve
from fccqp.tuning import FEASIBLE_PASSES, GUESS_PASSES, WARM_GUESS_PASSES

import fccqp
from fccqp import Status
from fccqp.cones import flatten_cones
from problems import random_problem
from reference import clarabel_solve
from verify import Problem, Tolerances, check_solution, verify_solution

EXACT = Tolerances(eps_abs=1e-10, eps_rel=1e-10, factor=1.0)
"""The KKT conditions to 1e-10: what a polished answer meets and ADMM at 1e-5 does not."""


def _cone_problem(seed):
    """Friction cones (and a second-order cone on odd seeds) on their boundary and at
    the apex, and torque-like boxes at their bounds."""
    return random_problem(seed, n=40, m=6, n_cones=5, n_box=8, soc_dim=4 if seed % 2 else 0)


def _block_kinds(problem, x):
    """How many cone blocks of ``x`` are at the apex and on the boundary."""
    apex = boundary = 0
    for block, mu, normal in Problem.of(*problem).blocks():
        f = x[block]
        along = normal @ f
        across = np.linalg.norm(f - along * normal)
        if np.linalg.norm(f) < 1e-9:
            apex += 1
        elif abs(across - mu * along) < 1e-9 * np.linalg.norm(f):
            boundary += 1
    return apex, boundary


@pytest.mark.parametrize("seed", range(4))
def test_polished_answer_is_exact(seed, kkt_backend):
    problem = P, q, A, b, lb, ub, cones = _cone_problem(seed)
    plain = fccqp.solve(*problem, kkt_backend=kkt_backend, polish=False)
    result = fccqp.solve(*problem, kkt_backend=kkt_backend, polish=True)
    assert result.polished and not plain.polished
    assert result.status is plain.status is Status.SOLVED
    verify_solution(problem, result)
    verify_solution(problem, plain)
    # the active set the test is about: boxes at a bound, cones at the apex and boundary
    box = np.isfinite(lb)
    assert np.count_nonzero(np.abs(result.z[box]) > 1e-6) >= 5
    apex, boundary = _block_kinds(problem, result.x)
    assert boundary >= 2 and apex + boundary >= 4
    # KKT to 1e-10 on the user's problem; ADMM alone stops at its 1e-5 tolerance
    assert check_solution(Problem.of(*problem), result, EXACT).passed
    assert not check_solution(Problem.of(*problem), plain, EXACT).passed
    assert max(result.prim_res, result.dual_res, result.gap) <= 1e-10
    # Clarabel at 1e-12 agrees on the objective to its own accuracy; its x is itself
    # only good to about 1e-6 here (it moves towards ours as its tolerance tightens)
    reference = clarabel_solve(*problem, tol=1e-12)
    assert abs(result.obj - reference.obj) <= 1e-10 * abs(reference.obj)
    assert abs(plain.obj - reference.obj) > 1e-7 * abs(reference.obj)
    assert np.abs(result.x - reference.x).max() <= 1e-5
    assert np.abs(plain.x - reference.x).max() > 2e-5


@pytest.mark.parametrize("seed", [5, 20])
def test_wrong_guess_keeps_the_admm_point(seed, kkt_backend):
    # two iterations of ADMM do not know the active set: the polished point fails the
    # check and the (restored) ADMM point is returned unchanged
    problem = _cone_problem(seed)
    settings = dict(max_iter=2, kkt_backend=kkt_backend)
    kept = fccqp.solve(*problem, polish=True, **settings)
    plain = fccqp.solve(*problem, polish=False, **settings)
    assert not kept.polished
    assert kept.status is plain.status is Status.MAX_ITER_REACHED
    for name in ("x", "y", "z"):
        np.testing.assert_array_equal(getattr(kept, name), getattr(plain, name))
    assert kept.solve_time > 0
    verify_solution(problem, kept)


def test_budget_stopped_solve_is_polished_to_solved(kkt_backend):
    problem = _cone_problem(1)
    plain = fccqp.solve(*problem, max_iter=15, kkt_backend=kkt_backend, polish=False)
    result = fccqp.solve(*problem, max_iter=15, kkt_backend=kkt_backend, polish=True)
    assert plain.status is Status.MAX_ITER_REACHED
    assert result.polished and result.status is Status.SOLVED
    verify_solution(problem, result)
    assert check_solution(Problem.of(*problem), result, EXACT).passed


def test_a_free_cone_flatter_than_the_regularization_is_polished_to_its_minimum(kkt_backend):
    """A separable QP without rows whose friction cone has curvature 1e-12 (about 1e-14
    once scaled, below the polish's regularization on every backend) and its unconstrained
    minimum inside the cone: the polish guesses the cone free and must reach that minimum,
    where ADMM only crawls toward it (rho at its floor against that curvature)."""
    curvature = np.array([6e-9, 0.0, 1.7, 2e-12, 2.3e-12, 1.4e-12])
    q = np.array([5e-4, -90.0, -4.0, 6.6e-7, -9.2e-8, -3.92e-6])
    ub = np.array([-5e4, 5e-3, 4.0, np.inf, np.inf, np.inf])
    minimum = np.array([-q[0] / curvature[0], ub[1], -q[2] / curvature[2],
                        *(-q[3:] / curvature[3:])])   # x[1] at its bound, the rest free
    result = fccqp.solve(np.diag(curvature), q, None, None, None, ub,
                         [fccqp.FrictionCone(3, 0.7)], kkt_backend=kkt_backend)
    assert result.status is Status.SOLVED and result.polished
    np.testing.assert_allclose(result.x, minimum, rtol=1e-6)


def test_warm_solver_polishes_a_sequence():
    P, q, A, b, lb, ub, cones = _cone_problem(2)
    solver = fccqp.Solver(polish=True)
    rng = np.random.default_rng(0)
    for _ in range(5):
        q_k = q + 0.05 * rng.standard_normal(q.shape)
        result = solver.solve(P, q_k, A, b, lb, ub, cones)
        problem = (P, q_k, A, b, lb, ub, cones)
        assert result.polished and result.status is Status.SOLVED
        verify_solution(problem, result)
        assert check_solution(Problem.of(*problem), result, EXACT).passed


@pytest.mark.parametrize("shape", [dict(duplicate_rows=3), dict(psd_rank=5), dict(n_cones=0),
                                   dict(soc_dim=5)])
def test_degenerate_problems_stay_correct(shape):
    problem = random_problem(1, **shape)
    for refine in (0, 3):
        result = fccqp.solve(*problem, polish=True, polish_refine_iter=refine)
        assert result.status is Status.SOLVED
        verify_solution(problem, result)


def test_every_entry_held_leaves_nothing_to_solve():
    result = fccqp.solve(np.eye(2), np.array([10.0, -10.0]), lb=-np.ones(2), ub=np.ones(2))
    assert result.polished and result.status is Status.SOLVED
    np.testing.assert_array_equal(result.x, [-1.0, 1.0])
    np.testing.assert_allclose(result.z, [-9.0, 9.0], rtol=1e-14)


def test_solves_ended_at_the_start_are_polished_and_infeasible_ones_not():
    # the cold start's equality-constrained QP carries sigma's bias; polishing removes it
    P, q = np.diag([1.0, 1e-6, 1e-6]), np.ones(3)
    plain = fccqp.solve(P, q, polish=False)
    result = fccqp.solve(P, q, polish=True)
    assert result.iterations == 0 and result.polished
    np.testing.assert_allclose(result.x, -q / np.diag(P), rtol=1e-12)
    # unpolished, the start is not solved and (no constrained entry) the run goes on
    # with proximal steps; it ended MAX_ITER_REACHED at 0 iterations, 1e6 off, before
    assert plain.status is Status.SOLVED and plain.iterations > 0 and not plain.polished
    problem = random_problem(0, n_box=0, n_cones=1)   # cone inactive at the start's point
    result = fccqp.solve(*problem)
    verify_solution(problem, result)
    P, q, A, b, lb, ub, cones = random_problem(0, n_cones=0)
    lb[5:8], ub[5:8] = 1.0, 2.0
    A = np.vstack([A, np.eye(30)[5]])
    b = np.append(b, -1.0)  # x5 = -1 against lb 1
    result = fccqp.solve(P, q, A, b, lb, ub, cones, polish=True)
    assert result.status is Status.PRIMAL_INFEASIBLE and not result.polished
    verify_solution((P, q, A, b, lb, ub, cones), result)


def test_polish_is_on_in_both_presets():
    assert fccqp.Settings().polish is True
    assert fccqp.Settings.realtime().polish is True
    assert fccqp.solve(*_cone_problem(0)).polished is True
    assert fccqp.solve(*_cone_problem(0), polish=False).polished is False


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 7, 8, 26, 27, 28, 63, 64, 65, 66, 90])
def test_the_table_polish_lu_solves_pivoted_systems_on_both_sides_of_the_loop_bound(n):
    """fccqp.polish_table's LU (the loop up to LU_LOOP_ROWS = 64 rows, dgetrf above) and
    its hand-written solve: every size of the last panel of four, rows swapped."""
    rng = np.random.default_rng(n)
    matrix = rng.standard_normal((n, n))
    matrix[0, 0] = 0.0 if n > 1 else 2.0   # a zero leading entry: the first pivot swaps rows
    matrix[:, n // 2] *= 1e-3   # a small column: pivots further down
    rhs = rng.standard_normal(n)
    x = factor_solve(matrix, rhs)
    assert np.abs(matrix @ x - rhs).max() <= 1e-10 * max(1.0, np.abs(rhs).max())
    assert np.allclose(x, np.linalg.solve(matrix, rhs), rtol=1e-8, atol=1e-10)


@pytest.mark.parametrize("n", [10, 11])
def test_the_table_polish_lu_pairs_trailing_columns_with_nothing_to_subtract(n):
    """fccqp_lu updates the trailing columns two at a time and skips a column whose
    panel rows are 0: a pair whose first, second or both columns are skipped, and an odd
    last column."""
    rng = np.random.default_rng(n)
    matrix = np.zeros((n, n))
    matrix[:4, :4] = rng.standard_normal((4, 4))   # the first panel's pivots come from its rows
    matrix[4:, 4:] = rng.standard_normal((n - 4, n - 4))
    for column in (4, 7, n - 1):   # nonzero in the first panel's rows: 5, 6, 8 and 9 are not
        matrix[:4, column] = rng.standard_normal(4)
    rhs = rng.standard_normal(n)
    x = factor_solve(matrix, rhs)
    assert np.allclose(x, np.linalg.solve(matrix, rhs), rtol=1e-8, atol=1e-10)


def test_the_table_polish_lu_reports_a_zero_pivot():
    matrix = np.ones((6, 6))
    assert factor_solve(matrix, np.ones(6)) is None


@pytest.mark.parametrize("seed", range(4))
def test_table_and_full_polish_agree(seed):
    """The reduced backends polish in the table's coordinates (fccqp.polish_table),
    the full one with its own KKT matrix: the same active set gives the same point."""
    problem = _cone_problem(seed)
    table = fccqp.solve(*problem, kkt_backend="schur_reduced")
    full = fccqp.solve(*problem, kkt_backend="ldl_full")
    assert table.backend == "schur_reduced" and full.backend == "ldl_full"
    assert table.polished and full.polished
    for result in (table, full):
        assert check_solution(Problem.of(*problem), result, EXACT).passed
    assert np.abs(table.x - full.x).max() <= 1e-8 * max(1.0, np.abs(full.x).max())


def test_warm_solve_polishes_the_previous_active_set_without_iterating(kkt_backend):
    """A control loop's next tick: the data moves a little, the active set stays, so
    the warm solve's first polish is the answer (0 iterations), as exact as a cold
    solve's."""
    P, q, A, b, lb, ub, cones = _cone_problem(1)
    solver = fccqp.Solver(fccqp.Settings(kkt_backend=kkt_backend))
    assert solver.solve(P, q, A, b, lb, ub, cones).polished
    rng = np.random.default_rng(0)
    moved = (P, q + 1e-4 * rng.standard_normal(q.size), A, b, lb, ub, cones)
    warm = solver.solve(*moved)
    cold = fccqp.solve(*moved, kkt_backend=kkt_backend)
    assert warm.status is Status.SOLVED and warm.polished and warm.iterations == 0
    assert check_solution(Problem.of(*moved), warm, EXACT).passed
    assert abs(warm.obj - cold.obj) <= 1e-10 * abs(cold.obj)


def test_warm_solve_iterates_when_the_active_set_changed():
    """A warm start whose active set no longer holds is rejected by the KKT check:
    ADMM runs and the answer is still verified."""
    P, q, A, b, lb, ub, cones = _cone_problem(2)
    solver = fccqp.Solver()
    assert solver.solve(P, q, A, b, lb, ub, cones).polished
    moved = (P, -q, A, b, lb, ub, cones)
    result = solver.solve(*moved)
    assert result.iterations > 0
    verify_solution(moved, result)
    reference = clarabel_solve(*moved, tol=1e-12)
    assert abs(result.obj - reference.obj) <= 1e-6 * abs(reference.obj)


@pytest.mark.parametrize(("name", "value", "error"), [
    ("polish", 1, TypeError), ("polish", None, TypeError),
    ("polish_refine_iter", -1, ValueError), ("polish_refine_iter", 101, ValueError),
    ("polish_refine_iter", 1.5, TypeError), ("polish_refine_iter", True, TypeError),
])
def test_polish_settings_are_validated(name, value, error):
    with pytest.raises(error, match=name):
        fccqp.Settings(**{name: value})


@pytest.mark.parametrize("seed", range(40))
def test_polished_answers_pass_the_independent_check(seed):
    # random shapes: boxes, friction and second-order cones, dependent rows, flat costs
    rng = np.random.default_rng(seed)
    n_cones, n_box, soc_dim = int(rng.integers(0, 4)), int(rng.integers(0, 8)), 0
    if rng.random() < 0.3:
        soc_dim = int(rng.integers(2, 5))
    m = int(rng.integers(0, 6))
    problem = random_problem(
        seed, n=3 * n_cones + soc_dim + n_box + int(rng.integers(5, 30)), m=m,
        n_cones=n_cones, n_box=n_box, soc_dim=soc_dim,
        duplicate_rows=min(2, m) if rng.random() < 0.3 else 0,
        psd_rank=int(rng.integers(1, 5)) if rng.random() < 0.3 else None)
    for settings in (dict(), dict(max_iter=int(rng.integers(1, 40)))):
        result = fccqp.solve(*problem, **settings)
        verify_solution(problem, result)
        if result.polished and not settings:   # a budget-stopped one may stay inaccurate
            assert result.status is Status.SOLVED


def _block_structured(problem, couple=False):
    """``problem`` with ``P`` as whole-body control has it: dense on the unconstrained
    entries, diagonal (weights from 1e-6 to 1) on the boxed and cone entries; with
    ``couple``, one constrained entry keeps a coupling."""
    P, q, A, b, lb, ub, cones = problem
    constrained = np.isfinite(lb) | np.isfinite(ub)
    for cone in cones:
        constrained[cone.start:cone.start + getattr(cone, "dim", 3)] = True
    P = P.copy()
    weights = np.geomspace(1e-6, 1.0, constrained.sum())
    P[constrained, :] = 0.0
    P[:, constrained] = 0.0
    P[np.flatnonzero(constrained), np.flatnonzero(constrained)] = weights
    if couple:
        first, free = np.flatnonzero(constrained)[0], np.flatnonzero(~constrained)[0]
        P[first, free] = P[free, first] = 0.5 * np.sqrt(weights[0] * P[free, free])
    assert np.linalg.eigvalsh(P).min() > 0.0
    return P, q, A, b, lb, ub, cones


@pytest.mark.parametrize("seed", range(4))
def test_warm_polish_with_new_matrices_skips_admm_factorization(seed):
    """Where ``P`` is diagonal on the constrained entries (whole-body control's torques
    and forces), the warm polish of a tick whose matrices moved solves its KKT system by
    Schur complement (fccqp.polish_schur) before any ADMM factorization: none is made,
    and the answer is as exact as a cold solve's."""
    _assert_warm_polish_is_exact_without_factorization(_block_structured(_cone_problem(seed)),
                                                       seed)


def _assert_warm_polish_is_exact_without_factorization(problem, seed):
    """The warm solve of ``problem`` with ``P`` and ``q`` moved a little is polished by
    Schur complement (no iteration, no factorization) and exact."""
    P, q, A, b, lb, ub, cones = problem
    solver = fccqp.Solver(fccqp.Settings.realtime(float("inf")))
    assert solver.solve(*problem).polished
    rng = np.random.default_rng(seed)
    moved = (P * (1.0 + 1e-3 * np.eye(q.size)), q + 1e-4 * rng.standard_normal(q.size),
             A, b, lb, ub, cones)
    warm = solver.solve(*moved)
    assert warm.status is Status.SOLVED and warm.polished
    assert warm.iterations == 0 and warm.factorizations == 0
    assert check_solution(Problem.of(*moved), warm, EXACT).passed
    reference = clarabel_solve(*moved, tol=1e-12)
    assert abs(warm.obj - reference.obj) <= 1e-8 * max(1.0, abs(reference.obj))


def _boxes_among_free_entries(problem):
    """``problem`` with its entries reordered so that the boxed ones sit between two
    halves of the entries without a bound or a cone (the cone blocks stay first)."""
    P, q, A, b, lb, ub, cones = problem
    coned = np.zeros(q.size, bool)
    for cone in cones:
        coned[cone.start:cone.start + getattr(cone, "dim", 3)] = True
    boxed = ~coned & (np.isfinite(lb) | np.isfinite(ub))
    free = np.flatnonzero(~coned & ~boxed)
    half = free.size // 2
    order = np.concatenate([np.flatnonzero(coned), free[:half], np.flatnonzero(boxed),
                            free[half:]])
    return (P[np.ix_(order, order)], q[order], A[:, order], b, lb[order], ub[order], cones)


@pytest.mark.parametrize("seed", range(4))
def test_warm_polish_is_exact_where_constrained_entries_split_the_coupled_ones(seed):
    """The polish's residual takes ``P x`` on the rows that ``P`` couples from one
    product over their span (fccqp.polish_kkt), the rest of the rows diagonal: with
    boxed entries between the coupled ones the warm polish is as exact as with the
    coupled entries together."""
    problem = _boxes_among_free_entries(_block_structured(_cone_problem(seed)))
    _assert_warm_polish_is_exact_without_factorization(problem, seed)


def test_warm_polish_factors_where_p_couples_a_constrained_entry():
    """A coupled constrained entry leaves the Schur complement out: the tick factors as
    before, and its answer is still exact."""
    problem = _block_structured(_cone_problem(1), couple=True)
    P, q, A, b, lb, ub, cones = problem
    solver = fccqp.Solver(fccqp.Settings.realtime(float("inf")))
    assert solver.solve(*problem).polished
    moved = (P * (1.0 + 1e-3 * np.eye(q.size)), q, A, b, lb, ub, cones)
    warm = solver.solve(*moved)
    assert warm.status is Status.SOLVED and warm.polished and warm.factorizations >= 1
    assert check_solution(Problem.of(*moved), warm, EXACT).passed


def _chain(target, upper, from_iterate=False):
    """``min 1/2 ||x - target||^2`` s.t. ``sum x = 3``, ``-10 <= x <= upper``, polished
    from an iterate inside the box with no multiplier."""
    n = len(target)
    inside = np.zeros(n)
    return polish_point(np.eye(n), -np.asarray(target, float), np.ones((1, n)),
                        np.array([3.0]), np.full(n, -10.0), np.asarray(upper, float),
                        flatten_cones((), n), inside, np.zeros(1), np.zeros(n), inside,
                        from_iterate=from_iterate)


def test_polish_gives_up_when_its_first_guesses_violate_a_bound():
    """Each guess holds the bound its predecessor's point crossed and puts the next entry
    past its own: with three entries the third guess is feasible and solves the QP
    (``(1, 1.5, 0.5)``); with four, the first ``FEASIBLE_PASSES`` (3) guesses are all
    infeasible and the polish gives up rather than search on (such searches ended
    rejected on the whole-body-control ticks; giving up after two lost polishes that
    solo12's and go2's cold ticks had kept)."""
    three = _chain([3.0, 1.4, 0.0], [1.0, 1.5, 10.0])
    assert three["ok"] and three["factorizations"] == 3
    np.testing.assert_allclose(three["x"], [1.0, 1.5, 0.5], atol=1e-12)
    four = _chain([10.0, 0.0, -0.3, -5.0], [1.0, 0.5, 2.3, 10.0])
    assert not four["ok"] and four["factorizations"] == FEASIBLE_PASSES


def test_a_warm_polish_gives_up_when_more_multipliers_are_wrong_than_its_guesses_can_release():
    """``min 1/2 ||x - 1||^2`` over 20 entries in ``[0, 10]`` with ``sum x = 3``, from a
    point that holds 19 of them at 0: the first guess's point violates nothing, and each
    later guess releases one held entry, the others still pulling up. As a warm polish
    (the previous tick's answer) it gives up at the guess where more multipliers are
    wrong-signed than ``HOPELESS_RATE`` (2) times the guesses left, the fifth; another
    polish crawls on and settles at its ``GUESS_PASSES``-th. The rule gives such a crawl up
    (ADMM then answers the tick) for the warm crawls that never settle."""
    n = 20
    z = np.zeros(n)
    z[0] = 1.0
    y = np.full(n, -1.0)
    y[0] = 0.0

    def polished(warm):
        return polish_point(np.eye(n), -np.ones(n), np.ones((1, n)), np.array([3.0]),
                            np.zeros(n), np.full(n, 10.0), flatten_cones((), n), z,
                            np.zeros(1), y, z, warm=warm)

    warm = polished(True)
    assert not warm["ok"] and warm["factorizations"] == 5 < WARM_GUESS_PASSES
    cold = polished(False)
    assert cold["ok"] and cold["factorizations"] == GUESS_PASSES


def test_a_polish_of_admms_iterate_steps_and_holds_each_bound_its_step_reaches():
    """The four-entry chain above, polished as ADMM's iterate is (``from_iterate``): each
    pass steps from the previous point (the first from the iterate, inside the box) only
    as far as the first bound it meets, which the next guess holds, and the polish solves
    the QP, ``(1, 0.5, 2.3, -0.8)``, where jumping to each guess's solution gave up. ADMM's
    slides along a face of the cones, which this step cuts short, are in
    notes/performance-history.md, "talosslow"."""
    four = _chain([10.0, 0.0, -0.3, -5.0], [1.0, 0.5, 2.3, 10.0], from_iterate=True)
    assert four["ok"] and four["factorizations"] > FEASIBLE_PASSES
    np.testing.assert_allclose(four["x"], [1.0, 0.5, 2.3, -0.8], atol=1e-12)


def _contacts(targets, total, mu=0.5):
    """``min 1/2 ||f - targets||^2`` over friction cones (``mu``, flat normal), one per row
    of ``targets``, with the normal forces summing to ``total``; polished from an
    iterate strictly inside every cone with no multiplier (every block guessed free)."""
    k = len(targets)
    n = 3 * k
    cones = tuple(fccqp.FrictionCone(3 * i, mu) for i in range(k))
    A = np.zeros((1, n))
    A[0, 2::3] = 1.0
    q = -np.ravel(targets)
    inside = np.tile([0.0, 0.0, 1.0], k)
    polished = polish_point(np.eye(n), q, A, np.array([total]), np.full(n, -np.inf),
                            np.full(n, np.inf), flatten_cones(cones, n), inside, np.zeros(1),
                            np.zeros(n), inside, newton_steps=20)
    return polished, clarabel_solve(np.eye(n), q, A, np.array([total]), cones=cones)


def test_polish_goes_on_while_its_guesses_only_put_blocks_on_their_boundary():
    """Every block guessed free, each of the first three guesses' points leaves one more
    cone than the last: the fourth guess, with those blocks on their boundary, violates
    nothing and solves the QP. A guess that had only put free blocks on their boundary
    is no sign of a hopeless search (the polish gives up on those after
    ``FEASIBLE_PASSES`` infeasible guesses otherwise)."""
    polished, reference = _contacts([[0.7, 0.2, -0.2], [-0.4, -1.5, 1.7], [-2.5, -2.5, -2.2],
                                     [0.1, 0.4, 0.2]], 6.7)
    assert polished["ok"] and polished["factorizations"] > FEASIBLE_PASSES
    np.testing.assert_allclose(polished["x"], reference.x, atol=1e-7)


def test_polish_holds_a_free_block_that_newton_moved_out_of_its_cone():
    """The settled guess (three blocks on their boundary) leaves the fourth inside its
    cone at its first solve, whose planes lie at the projections of points far outside;
    the Newton steps that put the three on their cones push the fourth out. The polish
    puts it on its boundary and solves again, instead of returning a point that misses
    its cone by 2e-2."""
    k, total = 4, 8.3
    targets = np.array([[-2.9, -3.0, -2.5], [0.7, -0.8, -1.8], [2.2, -2.9, 1.9],
                        [0.2, -0.7, -0.8]])
    z = np.array([-0.5, -0.8, 1.1, 0.1, -0.5, 3.5, 0.0, -0.5, 2.0, 0.2, -0.1, 2.9])
    y = np.array([0.0, 0.6, -0.6, 0.0, 0.0, -0.6, -0.9, 0.7, -0.9, -0.5, -0.9, 0.2])
    n = 3 * k
    cones = tuple(fccqp.FrictionCone(3 * i, 0.5) for i in range(k))
    A = np.zeros((1, n))
    A[0, 2::3] = 1.0
    args = (np.eye(n), -np.ravel(targets), A, np.array([total]))
    polished = polish_point(*args, np.full(n, -np.inf), np.full(n, np.inf),
                            flatten_cones(cones, n), z, np.zeros(1), y, z, newton_steps=20)
    reference = clarabel_solve(*args, cones=cones)
    assert polished["ok"]
    np.testing.assert_allclose(polished["x"], reference.x, atol=1e-7)



def test_newton_stops_where_a_fresh_factorization_left_the_point_unmoved():
    """Seven contacts pulled every way against a flat cost (``P = w I``, ``w`` 1.3e-4),
    beside an equality of size 6.7e4 that sets the solve's tolerance (``GUESS_TOLERANCE``
    times the scale), polished from no multipliers: Newton's steps on a guess with a
    wrong-signed plane (no curvature there) refactor where the planes still miss their
    cones by 2.9e-8 of ``x_block``, within that tolerance, so the solve leaves the point
    where it was and every later step would repeat it. Newton stops there with the same
    answer (25 factorizations without the stop, 9 with it; 627 of 6000 random polishes
    of this family stalled so)."""
    rng = np.random.default_rng(3)
    k = int(rng.integers(2, 9))
    targets = rng.normal(size=(k, 3)) * 3 + rng.normal(size=3) * rng.uniform(0, 5)
    total, mu = rng.uniform(1, 20), rng.uniform(0.3, 0.8)
    w, big = 10.0 ** rng.uniform(-4, 0), 10.0 ** rng.uniform(2, 6)
    n = 3 * k + 1
    cones = tuple(fccqp.FrictionCone(3 * i, mu) for i in range(k))
    A = np.zeros((2, n))
    A[0, 2:n - 1:3] = 1.0
    A[1, n - 1] = 1.0
    P = w * np.eye(n)
    P[-1, -1] = 1.0
    q = np.append(-w * np.ravel(targets), 0.0)
    start = np.append(np.tile([0.0, 0.0, 1.0], k) * rng.uniform(0, 10)
                      + rng.normal(size=3 * k) * rng.uniform(0, 3), 0.0)
    b, free = np.array([total, big]), np.full(n, np.inf)
    polished = polish_point(P, q, A, b, -free, free, flatten_cones(cones, n), start,
                            np.zeros(2), np.zeros(n), start, newton_steps=20, warm=True,
                            bare=True, schur=True)
    reference = clarabel_solve(P, q, A, b, cones=cones)
    assert polished["ok"] and polished["factorizations"] <= 12
    np.testing.assert_allclose(polished["x"], reference.x, atol=1e-6 * big)

def test_polish_puts_its_last_guess_on_the_cones():
    """This polish uses all ``GUESS_PASSES`` guesses, and its last one is the optimal
    active set; its first solve, at the planes of the previous point, is 0.12 off the
    reference (``newton_steps=0``). The last guess also gets Newton's steps, and the
    polished point is the reference's."""
    targets = np.array([[-1.64, -3.14, 1.1], [-0.33, -0.99, -1.56], [-1.48, 0.5, 0.22],
                        [0.45, -0.43, 2.33]])
    z = np.array([0.8, 0.1, 3.7, 0.6, 0.0, 1.7, 0.5, 0.3, 2.1, 0.6, -0.3, 1.7])
    y = np.zeros(12)
    y[6:8] = [0.9, -0.2]
    cones = tuple(fccqp.FrictionCone(3 * i, 0.2) for i in range(4))
    A = np.zeros((1, 12))
    A[0, 2::3] = 1.0
    args = (np.eye(12), -np.ravel(targets), A, np.array([9.3]))
    polished = polish_point(*args, np.full(12, -np.inf), np.full(12, np.inf),
                            flatten_cones(cones, 12), z, np.zeros(1), y, z, newton_steps=20)
    reference = clarabel_solve(*args, cones=cones)
    assert polished["ok"] and polished["passes"] == GUESS_PASSES
    np.testing.assert_allclose(polished["x"], reference.x, atol=1e-7)


def _warm_ticks(robot, first, last):
    """The realtime preset's answers, warm along ticks ``first..last`` of ``robot``'s
    benchmark set (``mix``, seed 0; ``first`` starts a sequence or follows one cold)."""
    pytest.importorskip("pinocchio")
    from benchmarks.testsets import generate_test_set

    qps = generate_test_set(robot, "mix", 400, seed=0).qps[first:last + 1]
    solver = fccqp.Solver(fccqp.Settings.realtime(100.0))
    results = [solver.solve(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub,
                            [fccqp.FrictionCone(int(start), float(mu), tuple(map(float, normal)))
                             for start, mu, normal in zip(qp.cone_starts, qp.mus, qp.normals,
                                                          strict=True)])
               for qp in qps]
    assert all(r.status is Status.SOLVED for r in results)
    return results


def test_a_cold_tick_whose_admm_slides_along_the_cones_is_polished_at_its_first_solved_check():
    """talos_reduced's benchmark tick 265 from a fresh solver: ADMM meets the realtime
    tolerance after about 100 iterations while its contact forces still slide from one foot
    to another along a straight line (370 N off the answer), toward the apexes of four
    blocks the answer has at 0. The polish of that iterate steps from it, holds each block
    at the apex its step reaches, and settles there. Jumping to the first guess's solution,
    past those apexes, it had failed, and the tick took the 1610 iterations of the slide."""
    pytest.importorskip("pinocchio")
    from benchmarks.testsets import generate_test_set

    qp = generate_test_set("talos_reduced", "mix", 400, seed=0).qps[265]
    cones = [fccqp.FrictionCone(int(start), float(mu), tuple(map(float, normal)))
             for start, mu, normal in zip(qp.cone_starts, qp.mus, qp.normals, strict=True)]
    result = fccqp.Solver(fccqp.Settings.realtime(100.0)).solve(qp.P, qp.q, qp.A, qp.b,
                                                                qp.lb, qp.ub, cones)
    assert result.status is Status.SOLVED and result.polished
    assert result.iterations < 200


def test_warm_polish_keeps_a_contact_a_chord_step_threw_past_its_apex():
    """solo12's third benchmark sequence, ticks 200-208: on ticks 205-208 the previous
    tick's active set holds, but the first Newton step of the warm polish, a chord step
    with a factorization that lacks a plane's curvature, threw a boundary block past its
    apex; held at the apex, the block was released and thrown again until the polish
    ended, and ticks ran ADMM (16-20 iterations on 207 and 208). The chord step is now
    undone and refactored: the warm polish answers each of them."""
    results = _warm_ticks("solo12", 200, 208)
    assert all(r.polished and r.iterations == 0 for r in results[5:])


def test_warm_polish_solves_a_released_contact_on_its_own_plane_first():
    """go2's first benchmark sequence, tick 38: the warm polish releases an apex block
    (a contact being loaded) onto a plane with ``lam = 0``; moved to the solved point,
    where nothing had held the block's tangential part, the plane turned away from the
    answer's and every next solve put the contact past its apex, and the tick ran 46
    ADMM iterations. Newton's first solve now keeps that plane, with its curvature."""
    assert _warm_ticks("go2", 0, 38)[-1].iterations == 0


def test_warm_polish_releases_a_contact_from_its_apex_with_its_curvature():
    """go2's third benchmark sequence, tick 212, and solo12's, ticks 201-202: the warm
    polish releases an apex block (a contact being loaded) to its boundary; placed with
    ``lam = 0``, its first solve lacked the plane's curvature and threw the contact past
    its apex, where it was held, released the same way and thrown again, and the ticks
    ran ADMM. Released with the part of its multiplier off the cone as
    ``lam``, the block is solved with its curvature and the warm polish answers them."""
    assert _warm_ticks("go2", 200, 212)[-1].iterations == 0
    assert all(r.polished and r.iterations == 0 for r in _warm_ticks("solo12", 200, 202)[1:])


def test_warm_polish_solves_a_lifting_foot_by_schur_complement_without_admm_factorization():
    """talos' first benchmark sequence, ticks 75 and 76 (warm from a cold tick 70): a
    guess of the warm polish leaves rows that its free entries span only barely (a
    squared pivot of the Schur complement ~1e-10 of its largest diagonal); refused as
    singular, the polish failed, ADMM's factorization and reduced table were built and
    the polish ran again in the table's coordinates, repeating its guesses, to the same
    answer. The Schur complement now solves those guesses: no ADMM factorization."""
    results = _warm_ticks("talos_reduced", 70, 76)
    assert all(r.polished and r.iterations == 0 and r.factorizations == 0
               for r in results[-2:])


def test_warm_polish_places_a_block_a_zero_length_step_held_where_the_step_pointed():
    """go2's third benchmark sequence, tick 215: each released block was stopped by a
    step of length 0 and held back where it had been, then released again, for all the
    polish's guesses, and the tick ran 17 ADMM iterations. Held from where the step
    pointed, the warm polish answers it."""
    assert _warm_ticks("go2", 200, 215)[-1].iterations == 0


def test_warm_polish_may_take_more_guesses_than_a_cold_one():
    """solo12's second benchmark sequence, tick 192: the warm polish holds and releases a
    torque limit and two contacts' planes one correction a pass, stopped by steps of
    length 0 and 0.02-0.04, and settles at its tenth guess; at its eighth
    (``GUESS_PASSES``) a contact's multiplier was still wrong-signed, and a polish ending
    there sent its tick to ADMM. A warm polish may solve
    ``WARM_GUESS_PASSES`` guesses: it answers the tick."""
    assert _warm_ticks("solo12", 100, 192)[-1].iterations == 0


def test_warm_polish_puts_a_lightly_loaded_contact_on_its_cone():
    """go2's second benchmark sequence, tick 158: a contact at a normal force of 0.006
    with a multiplier of 1e-5. Newton's iterate lay on the last plane far outside the
    cone, where the cone function's curvature is flatter than at the cone, and circled
    round the axis for all its steps; the tick's answer had that contact 19 % of its
    force off the cone (another by 1.6e-7). With the curvature taken on the cone both
    lie on it."""
    pytest.importorskip("pinocchio")
    from benchmarks.testsets import generate_test_set

    qp = generate_test_set("go2", "mix", 400, seed=0).qps[158]
    x = _warm_ticks("go2", 100, 158)[-1].x
    for start, mu, normal in zip(qp.cone_starts, qp.mus, qp.normals, strict=True):
        force = x[start:start + 3]
        along = np.dot(normal, force)
        assert np.linalg.norm(force - along * normal) - mu * along <= 1e-9 * np.linalg.norm(force)


def test_a_warm_polish_that_cycles_is_tried_again_from_its_own_point():
    """go2's second benchmark sequence, tick 125: the warm polish from tick 124's answer
    throws a contact block past its apex, holds it there, releases it and throws it
    again, and ends cycling; its tick ran ADMM. One guess from the cycling polish's own
    point, with its planes linearized there, settles: the tick runs no iteration."""
    result = _warm_ticks("go2", 100, 125)[-1]
    assert result.polished and result.iterations == 0


def test_polish_that_cycles_on_a_barely_loaded_contact_puts_its_last_guess_on_the_cones():
    """go2's quick benchmark set (``mix``, seed 0, sequences of 15), QP 21, started at the
    rho a previous cold solve handed over: one contact's optimal normal force is 0.17 N.
    Every polish flips that block between its apex (its multiplier outside the polar
    cone by a thousandth of the dual tolerance) and its boundary (Newton's steps throw it
    past the apex) and ends cycling at the apex; that first solve left the loaded blocks
    3e-5 off their cones, more than ADMM's point, and the tick ended unpolished, a torque
    8 % of its limit off the reference. The multipliers fit the last guess within the
    tolerance the acceptance allows them: Newton's steps put it on the cones, and the
    answer is the reference's."""
    pytest.importorskip("pinocchio")
    from benchmarks.testsets import generate_test_set

    tests = generate_test_set("go2", "mix", 22, seed=0, seq_len=15)
    qp, x_ref = tests.qps[21], tests.x_ref[21]
    cones = [fccqp.FrictionCone(int(start), float(mu), tuple(map(float, normal)))
             for start, mu, normal in zip(qp.cone_starts, qp.mus, qp.normals, strict=True)]
    settings = fccqp.Settings.realtime(100.0, rho=0.01809)
    result = fccqp.Solver(settings).solve(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones)
    assert result.status is Status.SOLVED and result.polished
    verify_solution(Problem.of(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones), result,
                    Tolerances.of(settings))
    u = qp.layout["u"]
    assert np.max(np.abs(result.x[u] - x_ref[u]) / qp.ub[u]) <= 0.01


def test_a_warm_polish_ten_ticks_on_is_not_taken_on_a_near_miss_of_its_multipliers():
    """solo12's benchmark tick 140 warm from tick 130's answer (a 50 Hz controller on the
    2 ms sequence): the warm polish ends unsettled with its last guess's multipliers
    wrong by less than the acceptance's tolerance on them. Newton's steps on that guess
    would give a point the acceptance takes, 1e-8 from the optimal objective but with a
    torque 14 % of its limit off the optimum, along a direction the cost barely weighs.
    Without that slack the warm polish fails and ADMM, then its own polish, answers
    exactly."""
    pytest.importorskip("pinocchio")
    from benchmarks.testsets import generate_test_set

    tests = generate_test_set("solo12", "mix", 400, seed=0)
    qp, x_ref = tests.qps[140], tests.x_ref[140]
    solver = fccqp.Solver(fccqp.Settings.realtime(100.0))
    for tick in (tests.qps[130], qp):
        result = solver.solve(tick.P, tick.q, tick.A, tick.b, tick.lb, tick.ub,
                              [fccqp.FrictionCone(int(start), float(mu),
                                                  tuple(map(float, normal)))
                               for start, mu, normal in zip(tick.cone_starts, tick.mus,
                                                            tick.normals, strict=True)])
    assert result.status is Status.SOLVED and result.polished
    u = qp.layout["u"]
    assert np.max(np.abs(result.x[u] - x_ref[u]) / qp.ub[u]) <= 0.01


@pytest.mark.parametrize("iterations", [1, 2, 4])
@pytest.mark.parametrize("seed", range(8))
def test_schur_polish_over_guesses_and_newton_steps_is_the_assembled_polish(seed, iterations):
    """Where ``P`` is diagonal, each guess and Newton step of a polish is solved by Schur
    complement (fccqp.polish_schur), bordered: the part of ``S`` its planes and
    curvature leave alone is kept from one factorization to the next. From a rough
    iterate (several guesses and Newton steps) it takes the guesses and steps the
    polish of the assembled matrix (``dsytrf``) takes, to the same point."""
    P, q, A, b, lb, ub, cones = random_problem(seed, n=40, m=6, n_cones=8, n_box=8)
    schur = _schur_polish_matching_the_assembled(np.diag(np.diag(P)), q, A, b, lb, ub, cones,
                                                 iterations)
    assert schur["bordered"]


def _schur_polish_matching_the_assembled(P, q, A, b, lb, ub, cones, iterations):
    """The Schur polish of ``iterations`` unpolished ADMM iterations' iterate, checked to
    take the assembled polish's guesses and steps to the same point; returned."""
    it = fccqp.solve(P, q, A, b, lb, ub, cones, polish=False, kkt_backend="ldl_full",
                     max_iter=iterations)
    start = (it.x, it.y, it.z, it.x)
    flat = flatten_cones(cones, P.shape[0])
    assembled = polish_point(P, q, A, b, lb, ub, flat, *start)
    schur = polish_point(P, q, A, b, lb, ub, flat, *start, schur=True)
    assert assembled["ok"] and schur["ok"] and schur["schur"]
    assert np.array_equal(assembled["active"], schur["active"])
    assert (assembled["passes"], assembled["factorizations"]) == (schur["passes"],
                                                                   schur["factorizations"])
    for name in ("x", "nu", "y"):
        gap = np.abs(assembled[name] - schur[name]).max()
        assert gap <= 1e-12 * max(1.0, np.abs(assembled[name]).max()), name
    assert np.abs(A @ schur["x"] - b).max() <= 1e-12 * max(1.0, np.abs(b).max())
    return schur


@pytest.mark.parametrize("seed", range(8))
def test_schur_polish_from_no_multipliers_is_the_assembled_polish(seed):
    """A polish from no multipliers (a contact change's carried guess) borders every cone
    block in its Schur complement's bases (fccqp.polish_schur): its guesses move blocks
    between free, boundary and apex and share a base while they hold the same box
    entries. From another problem's answer, as a carried guess, it takes the assembled
    polish's guesses and steps, to the same point, which is the reference's."""
    P, q, A, b, lb, ub, cones = random_problem(seed, n=40, m=6, n_cones=8, n_box=8)
    P = np.diag(np.diag(P))
    rng = np.random.default_rng(seed)
    carried = fccqp.solve(P, q + rng.normal(size=q.size) * np.abs(q).max(), A, b, lb, ub,
                          cones).x
    flat = flatten_cones(cones, P.shape[0])
    start = (carried, np.zeros(A.shape[0]), np.zeros(P.shape[0]), carried)
    assembled = polish_point(P, q, A, b, lb, ub, flat, *start, newton_steps=20, bare=True)
    schur = polish_point(P, q, A, b, lb, ub, flat, *start, newton_steps=20, bare=True,
                         schur=True)
    assert schur["schur"] and schur["bordered"]
    assert np.array_equal(assembled["active"], schur["active"])
    assert (assembled["ok"], assembled["passes"], assembled["factorizations"]) == (
        schur["ok"], schur["passes"], schur["factorizations"])
    for name in ("x", "nu", "y"):
        gap = np.abs(assembled[name] - schur[name]).max()
        assert gap <= 1e-10 * max(1.0, np.abs(assembled[name]).max()), name


@pytest.mark.parametrize("iterations", [1, 4])
@pytest.mark.parametrize("seed", range(8))
def test_schur_polish_with_rows_no_cone_touches_is_the_assembled_polish(seed, iterations):
    """Rows of ``A`` that no cone entry touches come first in ``S`` (fccqp.polish_schur):
    their block is factored once for every base whose free rows that reach it are the
    same (here the free box entries: the guesses hold and release them), and a guess
    factors only the rows past it. From a rough iterate the Schur polish takes the
    guesses and steps of the assembled matrix's polish, to the same point."""
    P, q, A, b, lb, ub, cones = random_problem(seed, n=40, m=8, n_cones=8, n_box=8)
    P = np.diag(np.diag(P))
    A[3:, :24] = 0.0   # rows 3-7: no cone entry, the first four of them S's leading block
    b = A @ fccqp.solve(P, q, A, b, lb, ub, cones).x
    _schur_polish_matching_the_assembled(P, q, A, b, lb, ub, cones, iterations)


@pytest.mark.parametrize("iterations", [1, 2])
@pytest.mark.parametrize("seed", range(8))
def test_schur_polish_with_rows_moved_between_bases_is_the_assembled_polish(seed, iterations):
    """A base of the Schur polish (fccqp.polish_schur) keeps the rows of ``Y`` that an
    earlier base of the solve wrote for the same free entries at the same rows, and
    copies an entry's row, kept from its first writing, where it moved (a box entry
    before it held or released, a cone block before it on or off its boundary). From a
    rough iterate with many box entries and cones, whose guesses move their rows, the
    Schur polish takes the assembled polish's guesses and steps to the same point."""
    P, q, A, b, lb, ub, cones = random_problem(seed, n=50, m=6, n_cones=10, n_box=14)
    _schur_polish_matching_the_assembled(np.diag(np.diag(P)), q, A, b, lb, ub, cones,
                                         iterations)


def test_a_contact_change_polished_from_nothing_settles_its_planes_before_a_release():
    """anymal_c's benchmark tick 360 (``mix``, seed 0: a fourth foot put down), warm along
    its sequence from tick 300, started from tick 359's answer carried onto the new
    contacts: the polish starts from nothing held. Its first solve throws one loaded
    foot's force into the polar cone; held at the apex there, the polish gave up
    infeasible after three guesses and ADMM ran. On the plane on its side of the axis
    instead, and with Newton's steps settling the planes (placed with no curvature)
    before a plane's wrong-signed multiplier is released, the polish settles: no
    iteration, and the reference's answer."""
    pytest.importorskip("pinocchio")
    from benchmarks.contact_map import ContactMaps
    from benchmarks.exact_solvers import carried_guess, fccqp_arguments
    from benchmarks.testsets import generate_test_set

    tests = generate_test_set("anymal_c", "mix", 400, seed=0)
    solver = fccqp.Solver(fccqp.Settings.realtime(100.0))
    for tick in range(300, 360):
        before = solver.solve(*fccqp_arguments(tests.qps[tick]))
    qp, x_ref = tests.qps[360], tests.x_ref[360]
    assert len(tests.stance[360]) == len(tests.stance[359]) + 1
    result = solver.solve(*fccqp_arguments(qp),
                          **carried_guess(ContactMaps(), (tests.qps[359], before), qp))
    assert result.status is Status.SOLVED and result.polished and result.iterations == 0
    cones = [fccqp.FrictionCone(int(start), float(mu), tuple(map(float, normal)))
             for start, mu, normal in zip(qp.cone_starts, qp.mus, qp.normals, strict=True)]
    verify_solution(Problem.of(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones), result,
                    Tolerances.of(fccqp.Settings.realtime(100.0)))
    u = qp.layout["u"]
    assert np.max(np.abs(result.x[u] - x_ref[u]) / qp.ub[u]) <= 0.01


def test_a_polish_from_nothing_gives_up_where_its_first_feasible_guess_cannot_settle():
    """talos' quick benchmark tick 54 (``mix``, 60 QPs in sequences of 15: the right foot
    put down), polished as a carried guess is (no multipliers, the warm polish's
    guesses): its curvature-less planes' points pass a dozen torque bounds, and at its
    first point that violates nothing more of their multipliers are wrong-signed than
    guesses are left. Releasing one a guess it cannot settle, so it gives up there, within
    ``FEASIBLE_PASSES`` guesses, rather than crawl by steps of length 0-0.05 to the
    hopeless test (8 guesses without the rule; ADMM follows either way)."""
    pytest.importorskip("pinocchio")
    from benchmarks.contact_map import ContactMaps
    from benchmarks.exact_solvers import carried_guess, fccqp_arguments
    from benchmarks.testsets import generate_test_set

    tests = generate_test_set("talos_reduced", "mix", 60, seed=0, seq_len=15)
    solver = fccqp.Solver(fccqp.Settings.realtime(100.0))
    for tick in range(45, 54):
        before = solver.solve(*fccqp_arguments(tests.qps[tick]))
    qp = tests.qps[54]
    guess = carried_guess(ContactMaps(), (tests.qps[53], before), qp)
    P, q, A, b, lb, ub, cones = fccqp_arguments(qp)[:7]
    flat = flatten_cones(cones, P.shape[0])
    x = guess["x0"]
    z = np.clip(x, lb, ub)
    for k in range(flat.count):   # z: the projection of x onto C, as the solver's guess has it
        o, normal, mu = flat.offset[k], np.asarray(flat.normal[k]), flat.mu[k]
        along = z[o:o + 3] @ normal
        tangent = z[o:o + 3] - along * normal
        across = np.linalg.norm(tangent)
        if across > mu * along:
            on = max(0.0, (along + mu * across) / (1 + mu * mu))
            z[o:o + 3] = on * normal + mu * on / across * tangent
    polished = polish_point(P, q, A, b, lb, ub, flat, x, guess["y0"], np.zeros_like(x), z,
                            schur=True, warm=True, bare=True)
    assert not polished["ok"]
    assert polished["passes"] <= FEASIBLE_PASSES


def test_a_carried_point_on_its_cone_to_rounding_starts_free():
    """A polish from no multipliers (a carried guess) starts from the equality-
    constrained solve: blocks whose carried point lies on its cone's surface, one ulp
    outside or inside of it by the rounding of the previous answer, start free alike.
    On solo12's contact_switch tick 320 two feet on their cones with multipliers of
    1e-7 had started on their planes or not with the BLAS kernel's rounding, 13
    factorizations against 5; here both contacts' optimum lies inside their cones and
    the first solve is the answer."""
    mu, n = 0.75, 6
    cones = (fccqp.FrictionCone(0, mu), fccqp.FrictionCone(3, mu))
    target = np.array([0.5, 0.0, 4.0, 0.0, -0.5, 4.0])   # inside both cones
    A, b = np.array([[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]]), np.array([8.0])
    free = np.full(n, np.inf)
    for side in (np.inf, -np.inf):   # just outside, just inside: |f_t| = mu f_n = 3
        z = np.array([np.nextafter(3.0, side), 0.0, 4.0, 0.0, -np.nextafter(3.0, side), 4.0])
        polished = polish_point(np.eye(n), -target, A, b, -free, free,
                                flatten_cones(cones, n), z, np.zeros(1), np.zeros(n), z,
                                warm=True, bare=True, schur=True)
        assert polished["ok"]
        assert polished["factorizations"] == 1 and polished["passes"] == 1
        np.testing.assert_allclose(polished["x"], target, atol=1e-12)
