"""Every KKT backend of the x-update, forced through ``Settings.kkt_backend``.

The backends (see docs/algorithm.md) must give the same answers: each is checked
against Clarabel, and the fallbacks (Schur needs ``A`` of full row rank and ``P + R``
positive definite) are checked through ``Result.backend``.
"""

import numpy as np
import pytest
from fccqp.tuning import CHOLESKY_LOOP_ROWS, SYRK_LOOP_ORDER, TRSM_LOOP_ROWS

import fccqp
from fccqp import Status, schur
from fuzzing import Case
from problems import random_problem
from reference import clarabel_solve
from verify import verify_solution

pytestmark = pytest.mark.kkt_backends(
    "schur_reduced", "ldl_reduced", "ldl_full", "sparse",
    reason="each test forces its backend and checks Result.backend (tests/conftest.py)")


def test_ordering_puts_constrained_entries_last():
    order = schur.ordering(6, np.array([4, 0], dtype=np.intp))
    np.testing.assert_array_equal(order, [1, 2, 3, 5, 4, 0])


@pytest.mark.kkt_backends("schur_reduced", "ldl_reduced", "ldl_full",
                            reason="the dense workspaces' Schur order")
def test_a_workspace_without_an_order_orders_the_schur_entries_as_ordering_does(kkt_backend):
    """A dense workspace given no Schur order (``order=None``, as ``fccqp.Solver``
    builds them) takes the free entries ascending, then the constrained ones, the
    order of :func:`fccqp.schur.ordering`: its answers are those of a workspace given
    that order, bit for bit, on a problem with free, boxed and cone entries."""
    from fccqp import admm

    P, q, A, b, lb, ub, cones = random_problem(7, n=20, m=4, n_cones=2, n_box=5)
    settings = fccqp.Settings(kkt_backend=kkt_backend)
    solver = fccqp.Solver(settings)
    solver.solve(P, q, A, b, lb, ub, cones)
    structure = solver._structure
    constrained = structure.constrained[: structure.count].copy()
    flat = structure.cones
    arrays = (flat.kind, structure.relocated.copy(), flat.dim, flat.mu, flat.normal)
    fixed = structure.fixed[: structure.count].astype(bool)
    answers = []
    for order in (None, schur.ordering(20, constrained)):
        w = admm.Workspace(20, 4, constrained, arrays, fixed, order, settings, 0)
        out = w.solve(P, q, A, b, lb, ub, None, False, 0.0, np.empty(24), True)
        assert out.status is Status.SOLVED
        answers.append(out.x.tobytes())
    assert answers[0] == answers[1]


@pytest.mark.parametrize("seed", range(3))
def test_backend_matches_clarabel(kkt_backend, seed):
    problem = random_problem(seed, n_box=6, soc_dim=4 if seed == 2 else 0)
    result = fccqp.solve(*problem, kkt_backend=kkt_backend, eps_abs=1e-8, eps_rel=1e-8)
    assert result.status is Status.SOLVED
    assert result.backend == kkt_backend
    reference = clarabel_solve(*problem)
    np.testing.assert_allclose(result.x, reference.x, atol=1e-5 * (1 + np.abs(reference.x).max()))
    P, q, A, b = problem[:4]
    assert np.abs(A @ result.x - b).max() <= 1e-9 * (1 + np.abs(b).max())


def test_schur_cold_start_leaves_its_factorization_to_the_iterations():
    """The cold start's proximal steps run on the iteration's Schur factorization for
    rho (its table's coordinates), so a cold run that keeps its rho factors once."""
    problem = random_problem(0, n_box=6)
    result = fccqp.solve(*problem, kkt_backend="schur_reduced", adaptive_rho=False)
    assert result.status is Status.SOLVED and result.iterations > 0
    assert result.backend == "schur_reduced" and result.factorizations == 1
    reference = clarabel_solve(*problem)
    np.testing.assert_allclose(result.x, reference.x, atol=1e-3 * (1 + np.abs(reference.x).max()))


def test_schur_cold_start_keeps_a_huge_bounded_start():
    """A bounded QP whose equality-constrained start is huge (a curvature of 1e-5 along
    the direction ``q`` pulls, between two boxed entries) is no candidate ray: its
    proximal steps shrink (by ``sigma / (lambda + sigma)``), so the Schur start is kept
    and the run factors once, not once more for a start with ``sigma`` and again for
    rho."""
    a, b = 0.5 + 5e-6, 0.5 - 5e-6
    P = np.array([[1.0, 0.0, 0.0], [0.0, a, b], [0.0, b, a]])
    q = np.array([0.0, -1.0, 1.0])
    A, rhs = np.array([[1.0, 0.0, 0.0]]), np.array([1.0])
    lb, ub = np.array([-np.inf, -10.0, -10.0]), np.array([np.inf, 10.0, 10.0])
    result = fccqp.solve(P, q, A, rhs, lb, ub, (), kkt_backend="schur_reduced",
                         adaptive_rho=False)
    assert result.status is Status.SOLVED
    assert result.backend == "schur_reduced" and result.factorizations == 1
    np.testing.assert_allclose(result.x, [1.0, 10.0, -10.0], atol=1e-6)


def _block_diagonal(problem, coupled_constrained=False, flat_free=False):
    """``problem`` with the cost of whole-body control's shape: dense on the first
    free entries, diagonal on the other free ones and on every constrained entry (the
    Schur backend's diagonal tail); ``coupled_constrained`` couples a boxed entry to a
    free one, ``flat_free`` gives a diagonal free entry no curvature."""
    P, q, A, b, lb, ub, cones = problem
    n = P.shape[0]
    constrained = np.isfinite(lb) | np.isfinite(ub)
    for cone in cones:
        constrained[cone.start:cone.start + cone.dim] = True
    free = np.flatnonzero(~constrained)
    dense = free[:6]
    P2 = np.diag(np.linspace(0.5, 2.0, n))
    P2[np.ix_(dense, dense)] = P[np.ix_(dense, dense)] + np.eye(6)
    if coupled_constrained:
        boxed = np.flatnonzero(np.isfinite(lb) & ~np.isin(np.arange(n), dense))[0]
        P2[boxed, dense[0]] = P2[dense[0], boxed] = 0.3
    if flat_free:
        P2[free[-1], free[-1]] = 0.0
    return P2, q, A, b, lb, ub, cones


@pytest.mark.parametrize("n", [CHOLESKY_LOOP_ROWS, 2 * CHOLESKY_LOOP_ROWS])
def test_backend_matches_clarabel_on_either_side_of_the_cholesky_loop(kkt_backend, n):
    """The Schur backend factors ``P + R`` (order ``n``) by the loop up to
    ``CHOLESKY_LOOP_ROWS`` and by LAPACK's ``dpotrf`` above: both give Clarabel's answer."""
    problem = random_problem(7, n=n, m=12, n_box=10)
    result = fccqp.solve(*problem, kkt_backend=kkt_backend, eps_abs=1e-8, eps_rel=1e-8)
    assert result.status is Status.SOLVED
    assert result.backend == kkt_backend
    reference = clarabel_solve(*problem)
    np.testing.assert_allclose(result.x, reference.x, atol=1e-5 * (1 + np.abs(reference.x).max()))


@pytest.mark.parametrize("m", [SYRK_LOOP_ORDER - 1, SYRK_LOOP_ORDER + 1])
def test_backend_matches_clarabel_on_either_side_of_the_syrk_loop(kkt_backend, m):
    """``S = Y'Y`` (order ``m``), the Gram matrix ``A A'`` and the Schur polish's
    complements are summed by the AVX2 tiles of ``fccqp_syrk_lower`` up to order
    ``SYRK_LOOP_ORDER`` and by BLAS' ``dsyrk`` above (``m`` odd: a last tile with fewer
    than four rows): both give Clarabel's answer, with ``A x = b`` held."""
    problem = random_problem(9, n=m + 40, m=m, n_box=10)
    result = fccqp.solve(*problem, kkt_backend=kkt_backend, eps_abs=1e-8, eps_rel=1e-8)
    assert result.status is Status.SOLVED
    assert result.backend == kkt_backend
    reference = clarabel_solve(*problem)
    np.testing.assert_allclose(result.x, reference.x, atol=1e-5 * (1 + np.abs(reference.x).max()))
    A, b = problem[2:4]
    assert np.abs(A @ result.x - b).max() <= 1e-9 * (1 + np.abs(b).max())


@pytest.mark.parametrize("n", [TRSM_LOOP_ROWS, 2 * TRSM_LOOP_ROWS])
def test_backend_matches_clarabel_on_either_side_of_the_triangular_loops(kkt_backend, n):
    """The Schur backend's triangular solves (``Y = L^-1 A'`` over the ``n - 15`` free
    rows, ``S^-1`` on its ``n / 2 + 8`` rows) go through the loops up to
    ``TRSM_LOOP_ROWS`` and through ``dtrsm`` / ``dpotrs`` above: both give Clarabel's
    answer."""
    problem = random_problem(11, n=n, m=n // 2 + 8, n_box=6)
    result = fccqp.solve(*problem, kkt_backend=kkt_backend, eps_abs=1e-8, eps_rel=1e-8)
    assert result.status is Status.SOLVED
    assert result.backend == kkt_backend
    reference = clarabel_solve(*problem)
    np.testing.assert_allclose(result.x, reference.x, atol=1e-5 * (1 + np.abs(reference.x).max()))


@pytest.mark.parametrize("shape", ["diagonal tail", "coupled constrained", "flat free"])
def test_backend_matches_clarabel_on_block_diagonal_costs(kkt_backend, shape):
    problem = _block_diagonal(random_problem(4, n_box=6), shape == "coupled constrained",
                              shape == "flat free")
    result = fccqp.solve(*problem, kkt_backend=kkt_backend, eps_abs=1e-8, eps_rel=1e-8)
    assert result.status is Status.SOLVED
    if kkt_backend != "schur_reduced" or shape != "flat free":
        assert result.backend == kkt_backend
    else:   # H = P + R is singular on the flat entry: LDL' takes over
        assert result.backend in ("ldl_reduced", "ldl_full")
    reference = clarabel_solve(*problem)
    np.testing.assert_allclose(result.x, reference.x, atol=1e-5 * (1 + np.abs(reference.x).max()))
    A, b = problem[2:4]
    assert np.abs(A @ result.x - b).max() <= 1e-9 * (1 + np.abs(b).max())


def test_new_nonzeros_in_the_constrained_columns_of_a_reused_solver_are_used():
    """The Schur backend sums ``S`` over the nonzeros of ``A``'s constrained columns,
    found once for each ``P`` and ``A``: after a QP with zeros there, a QP without them
    is solved as a fresh solver would."""
    problem = _block_diagonal(random_problem(4, n_box=6))
    P, q, A, b, lb, ub, cones = problem
    constrained = np.isfinite(lb) | np.isfinite(ub)
    for cone in cones:
        constrained[cone.start:cone.start + cone.dim] = True
    feasible = fccqp.solve(*problem).x
    sparser = A.copy()
    sparser[:4, constrained] = 0.0
    solver = fccqp.Solver(kkt_backend="schur_reduced", eps_abs=1e-8, eps_rel=1e-8)
    assert solver.solve(P, q, sparser, sparser @ feasible, lb, ub, cones).backend == (
        "schur_reduced")
    solver.reset()
    result = solver.solve(*problem)
    assert result.status is Status.SOLVED and result.backend == "schur_reduced"
    reference = clarabel_solve(*problem)
    np.testing.assert_allclose(result.x, reference.x, atol=1e-5 * (1 + np.abs(reference.x).max()))


def test_schur_table_with_the_dense_block_in_two_runs_and_sparse_free_columns():
    """The Schur backend forms the table's rows on its diagonal tail from the nonzeros of
    ``A``'s columns there (found for each ``P`` and ``A``, the free tail's as the
    constrained entries'), and writes the dense block's rows in place only where they are
    one run of ``x``: with the dense block in two runs, and a reused solver whose QP before
    had zeros in the free tail's columns, the answers are Clarabel's."""
    _, q, A, b, lb, ub, cones = random_problem(4, n_box=6)
    n = A.shape[1]
    constrained = np.isfinite(lb) | np.isfinite(ub)
    for cone in cones:
        constrained[cone.start:cone.start + cone.dim] = True
    free = np.flatnonzero(~constrained)
    dense = free[[0, 1, 2, 6, 7, 8]]   # two runs, diagonal free entries between them
    P = np.diag(np.linspace(0.5, 2.0, n))
    rng = np.random.default_rng(0)
    M = rng.standard_normal((6, 6))
    P[np.ix_(dense, dense)] = M @ M.T / 6 + np.eye(6)
    tail = np.setdiff1d(free, dense)
    sparser = A.copy()
    sparser[:5, tail] = 0.0
    sparser[5:, tail[::2]] = 0.0
    feasible = clarabel_solve(P, q, A, b, lb, ub, cones).x
    solver = fccqp.Solver(kkt_backend="schur_reduced", eps_abs=1e-8, eps_rel=1e-8)
    for matrix, reset in ((sparser, False), (A, True)):
        if reset:
            solver.reset()
        rhs = matrix @ feasible
        result = solver.solve(P, q, matrix, rhs, lb, ub, cones)
        assert result.status is Status.SOLVED and result.backend == "schur_reduced"
        reference = clarabel_solve(P, q, matrix, rhs, lb, ub, cones)
        np.testing.assert_allclose(result.x, reference.x,
                                   atol=1e-5 * (1 + np.abs(reference.x).max()))
        assert np.abs(matrix @ result.x - rhs).max() <= 1e-9 * (1 + np.abs(rhs).max())


@pytest.mark.parametrize("entry", ["free", "boxed"])
def test_negative_curvature_on_the_diagonal_tail_is_rejected(entry):
    P, q, A, b, lb, ub, cones = _block_diagonal(random_problem(4, n_box=6))
    constrained = np.isfinite(lb) | np.isfinite(ub)
    for cone in cones:
        constrained[cone.start:cone.start + cone.dim] = True
    i = np.flatnonzero(np.isfinite(lb) if entry == "boxed" else ~constrained)[-1]
    null = np.linalg.svd(A)[2][A.shape[0]:].T
    P[i, i] = 0.0
    # the curvature that makes the cost concave on the null space of A, doubled
    curvature = np.linalg.eigvalsh(null.T @ P @ null)[0] / (null[i] @ null[i])
    P[i, i] = -2.0 * max(curvature, 1e-3)
    assert np.linalg.eigvalsh(null.T @ P @ null)[0] < 0
    with pytest.raises(ValueError, match="not convex"):
        fccqp.Solver(kkt_backend="schur_reduced").solve(P, q, A, b, lb, ub, cones)


def test_warm_solver_reuses_every_backend(kkt_backend):
    problem = random_problem(1, n_box=6)
    solver = fccqp.Solver(kkt_backend=kkt_backend)
    first = solver.solve(*problem)
    again = solver.solve(*problem)
    assert first.status is again.status is Status.SOLVED
    assert again.factorizations == 0 and again.backend == kkt_backend


@pytest.mark.kkt_backends("schur_reduced", "ldl_reduced", reason="the reduced forms' fallback")
def test_reduced_forms_fall_back_on_dependent_rows(kkt_backend):
    P, q, A, b, lb, ub, cones = random_problem(0, n_box=6)
    A, b = np.vstack([A, 2.0 * A[0]]), np.append(b, 2.0 * b[0])
    result = fccqp.solve(P, q, A, b, lb, ub, cones, kkt_backend=kkt_backend)
    assert result.status is Status.SOLVED
    assert result.backend in ("ldl_reduced", "ldl_full")  # Schur: S is singular
    assert np.abs(A @ result.x - b).max() <= 1e-9 * (1 + np.abs(b).max())


def test_a_cost_flat_to_rounding_on_entries_the_rows_tie_down_is_solved(kkt_backend):
    """``P`` of 1e-100 (a linear program to rounding) with ``A`` square and invertible on
    the free entries: the Schur route's ``H^-1`` multiplies the rounding of ``f - A' nu``
    by 1e100 (``S`` outgrows ``H`` and ``A`` by as much: ADMM stalled there, and only
    the retries answered), so the reduced form goes to LDL', whose pivoting ties the
    free entries to the boxed ones through ``A``."""
    P = 1e-100 * np.eye(4)
    q = np.array([0.3, -0.2, 1.0, -1.5])
    A = np.array([[1.0, 0.5, 0.4, -0.3], [0.2, 1.0, -0.6, 0.8]])
    b = np.array([1.0, -0.5])
    lb, ub = np.array([-np.inf, -np.inf, -1.0, -2.0]), np.array([np.inf, np.inf, 1.0, 2.0])
    result = fccqp.solve(P, q, A, b, lb, ub, kkt_backend=kkt_backend)
    assert result.status is Status.SOLVED
    assert result.iterations < fccqp.Settings().max_iter
    if kkt_backend == "schur_reduced":
        assert result.backend in ("ldl_reduced", "ldl_full")
    reference = clarabel_solve(P, q, A, b, lb, ub, [])
    np.testing.assert_allclose(result.x, reference.x, atol=1e-4 * (1 + np.abs(reference.x).max()))


@pytest.mark.kkt_backends("schur_reduced", "ldl_reduced", reason="the reduced forms' fallback")
@pytest.mark.parametrize("seed", [102753, 104299])
def test_an_lp_whose_rows_leave_free_entries_free_leaves_the_reduced_form(kkt_backend, seed):
    """``P = 0`` beside cones and fixed entries, with free entries that the rows do not
    all tie down (the fuzzer's degenerate structures): ``P + R`` is singular on the null
    space of ``A``, the reduced LDL' pivot of that direction came out positive by
    rounding, and the reduced iteration diverged to 1e48 (MAX_ITER_REACHED after every
    retry); the full form solves it."""
    problem = Case.of("degenerate", seed).scenario().problem
    result = fccqp.solve(*problem.args(), kkt_backend=kkt_backend)
    assert result.status is Status.SOLVED
    assert result.backend == "ldl_full"
    verify_solution(problem, result)

def test_nonconvex_cost_is_rejected_by_every_backend(kkt_backend):
    P, q, A, b, lb, ub, cones = random_problem(0, n_box=6)
    P = P - 10.0 * np.eye(P.shape[0])
    with pytest.raises(ValueError, match="not convex"):
        fccqp.Solver(kkt_backend=kkt_backend).solve(P, q, A, b, lb, ub, cones, x0=np.zeros(30))


def test_infeasibility_after_rho_changes_is_certified(kkt_backend):
    """The reduced forms carry their coordinates across a refactorization (a change of
    rho), so the step that the certificate tests right after it is a real one."""
    P, q, A, b, lb, ub, cones = random_problem(0, n_cones=0)
    lb[5:8], ub[5:8] = 1.0, 2.0
    A = np.vstack([A, np.eye(30)[5]])
    b = np.append(b, -1.0)  # x5 = -1 against lb 1
    result = fccqp.solve(P, q, A, b, lb, ub, cones, kkt_backend=kkt_backend,
                         adaptive_rho_interval=2, adaptive_rho_tolerance=1.01)
    assert result.status is Status.PRIMAL_INFEASIBLE
    y, z = result.certificate[: A.shape[0]], result.certificate[A.shape[0]:]
    support = np.sum(np.where(z > 0, np.where(np.isfinite(ub), ub, 0) * z,
                              np.where(np.isfinite(lb), lb, 0) * z))
    assert b @ y + support < 0
    assert np.abs(A.T @ y + z).max() <= 1e-5 * np.abs(result.certificate).max()
