"""The polish over compressed-column matrices (fccqp.polish_csc) against the dense polish.

Both polish the same iterate of the same problem (:func:`fccqp.polish_ops.polish_point`):
the dense arm assembles each guess for ``dsytrf``, the CSC arm assembles its upper
triangle in compressed columns for qdldl. The guesses, and so the final active set, the
passes and the factorizations, must be the same, and the points the same to rounding
(both are refined against the unregularized system). Then whole solves on the sparse
path (``kkt_backend="sparse"``), judged by ``tests/verify.py`` and Clarabel.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from fccqp.polish_csc import arrays
from fccqp.polish_ops import polish_point

import fccqp
from fccqp.cones import flatten_cones
from problems import mpc_problem, random_problem
from reference import clarabel_solve
from verify import Problem, Tolerances, check_solution, verify_solution

EXACT = Tolerances(eps_abs=1e-10, eps_rel=1e-10, factor=1.0)
"""The KKT conditions to 1e-10: what a polished answer meets (as in test_polish.py)."""


def _sparse_cost(P, seed):
    """``P`` with 85 % of its couplings dropped, diagonally dominant again (a convex
    cost with a scattered pattern)."""
    rng = np.random.default_rng(seed)
    mask = rng.random(P.shape) < 0.15
    S = np.where(mask | mask.T, P, 0.0)
    np.fill_diagonal(S, 0.0)
    return S + np.diag(np.abs(S).sum(axis=1) + rng.uniform(0.0, 1.0, P.shape[0]))


def _flat_boxes(P, lb, seed):
    """A diagonal cost without curvature on half the boxed entries (no diagonal entry
    in the pattern: only their bounds hold them) plus a coupling of the free ones."""
    rng = np.random.default_rng(seed)
    n = P.shape[0]
    d = rng.uniform(0.5, 2.0, n)
    boxed = np.flatnonzero(np.isfinite(lb))
    d[boxed[: boxed.size // 2]] = 0.0
    free = np.arange(boxed[-1] + 1, n)
    M = np.zeros((n, 4))
    M[free] = rng.standard_normal((free.size, 4))
    return np.diag(d) + M @ M.T


def _problem(kind, seed):
    soc = 4 if seed % 2 else 0
    if kind == "wide":
        return random_problem(seed, n=60, m=20, n_cones=10, n_box=10, psd_rank=10, soc_dim=soc)
    P, q, A, b, lb, ub, cones = random_problem(seed, n=40, m=6, n_cones=5, n_box=8, soc_dim=soc)
    if kind == "sparse":
        P = _sparse_cost(P, seed)
    elif kind == "flat":
        P = _flat_boxes(P, lb, seed)
    return P, q, A, b, lb, ub, cones


def _both(problem, iterations):
    """The dense and the CSC polish of fccqp's iterate after ``iterations``."""
    P, q, A, b, lb, ub, cones = problem
    it = fccqp.solve(*problem, polish=False, kkt_backend="ldl_full", max_iter=iterations)
    flat = flatten_cones(cones, P.shape[0])
    start = (it.x, it.y, it.z, it.x)
    dense = polish_point(P, q, A, b, lb, ub, flat, *start)
    csc = polish_point(sp.csc_matrix(P), q, sp.csc_matrix(A), b, lb, ub, flat, *start)
    return dense, csc


def _close(a, b, tolerance=1e-12):
    return np.abs(a - b).max(initial=0.0) <= tolerance * max(1.0, np.abs(a).max(initial=0.0))


@pytest.mark.parametrize("kind", ["dense", "sparse", "flat", "wide"])
@pytest.mark.parametrize("iterations", [10, 40, 4000])
@pytest.mark.parametrize("seed", range(4))
def test_csc_polish_is_the_dense_polish(kind, iterations, seed):
    problem = _problem(kind, seed)
    dense, csc = _both(problem, iterations)
    assert dense["ok"] and csc["ok"]
    assert np.array_equal(dense["active"], csc["active"])
    assert (dense["passes"], dense["factorizations"]) == (csc["passes"], csc["factorizations"])
    for name in ("x", "nu", "y"):
        assert _close(dense[name], csc[name]), name


@pytest.mark.parametrize("seed", range(4))
def test_csc_polish_on_dependent_rows(seed):
    """``A`` with repeated rows: ``nu`` is not unique, ``A' nu`` and the point are."""
    problem = P, q, A, b, lb, ub, cones = random_problem(seed, n=40, m=6, n_cones=5, n_box=8,
                                                         duplicate_rows=2)
    dense, csc = _both(problem, 4000)
    assert dense["ok"] and csc["ok"]
    assert np.array_equal(dense["active"], csc["active"])
    assert _close(dense["x"], csc["x"]) and _close(dense["y"], csc["y"])
    assert _close(A.T @ dense["nu"], A.T @ csc["nu"], 1e-11)


@pytest.mark.parametrize("seed", range(3))
def test_csc_polish_reaches_the_optimum(seed):
    """The CSC polish of a settled iterate has Clarabel's objective at 1e-12."""
    problem = P, q, A, b, lb, ub, cones = _problem("sparse", seed)
    _, csc = _both(problem, 4000)
    x = csc["x"]
    reference = clarabel_solve(*problem, tol=1e-12)
    assert abs(0.5 * x @ P @ x + q @ x - reference.obj) <= 1e-10 * abs(reference.obj)
    assert np.abs(A @ x - b).max() <= 1e-12 * max(1.0, np.abs(b).max())


def test_arrays_reject_patterns_that_do_not_fit():
    P = sp.csc_matrix(np.eye(3))
    A = sp.csc_matrix(np.ones((2, 3)))
    args = (P.indptr, P.indices, A.indptr, A.indices, [3])
    with pytest.raises(ValueError, match="P_colptr must have n \\+ 1 = 5"):
        arrays(4, 2, *args)
    with pytest.raises(ValueError, match="A_rowind must hold rows in \\[0, 1\\)"):
        arrays(3, 1, *args)
    with pytest.raises(ValueError, match="A_rowind must have 6 entries"):
        arrays(3, 2, P.indptr, P.indices, A.indptr, A.indices[:4], [3])
    held = arrays(3, 2, *args)
    # capacity: nnz(P) + n + nnz(A) + m + a block's curvature (6), plane (3) and row (1)
    assert held[5].shape == (3 + 3 + 6 + 2 + 10,) and held[4].shape == (3 + 2 + 1 + 1,)
    assert held[8].shape == (3 * 3,)   # the curvature terms: n x the largest cone


@pytest.mark.parametrize("seed", range(4))
def test_sparse_solves_are_polished_as_dense_ones(seed):
    """The sparse path polishes the cone problems of test_polish.py as ``ldl_full``
    does: the same iterations, an exact answer, the same point to rounding."""
    problem = _problem("dense", seed)
    sparse = fccqp.solve(*problem, kkt_backend="sparse")
    dense = fccqp.solve(*problem, kkt_backend="ldl_full")
    assert sparse.backend == "sparse" and sparse.polished and dense.polished
    assert sparse.status is dense.status is fccqp.Status.SOLVED
    assert sparse.iterations == dense.iterations
    verify_solution(problem, sparse)
    assert check_solution(Problem.of(*problem), sparse, EXACT).passed
    assert _close(sparse.x, dense.x, 1e-10)


def test_sparse_solve_of_an_mpc_is_polished_to_the_optimum():
    problem = P, q, A, b, lb, ub, cones = mpc_problem(horizon=40)
    result = fccqp.solve(*problem, kkt_backend="sparse")
    assert result.status is fccqp.Status.SOLVED and result.polished
    dense = (P.toarray(), q, A.toarray(), b, lb, ub, cones)
    verify_solution(dense, result)
    assert check_solution(Problem.of(*dense), result, EXACT).passed
    reference = clarabel_solve(*dense, tol=1e-12)
    assert abs(result.obj - reference.obj) <= 1e-10 * abs(reference.obj)
