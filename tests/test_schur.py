"""The Schur-complement KKT backend against a dense solve of the same system."""

import numpy as np

from fccqp import schur


def _system(seed, n=12, m=5, rank_deficient=False):
    rng = np.random.default_rng(seed)
    M = rng.standard_normal((n, n))
    P = M @ M.T / n + 0.1 * np.eye(n)
    A = rng.standard_normal((m, n))
    if rank_deficient:
        A[-1] = 2.0 * A[0]
    constrained = np.array([7, 1, 10, 4], dtype=np.int64)  # scattered, not sorted
    rho_vec = np.array([0.7, 0.3, 2.0, 0.7])
    H = P.copy()
    H[constrained, constrained] += rho_vec
    K = np.block([[H, A.T], [A, np.zeros((m, m))]])
    work = (np.zeros((n, n), order="F"), np.zeros((m, m), order="F"),
            np.zeros((n, m), order="F"))
    return P, A, constrained, rho_vec, K, work


def test_ordering_puts_constrained_entries_last():
    order = schur.ordering(6, np.array([4, 0], dtype=np.int64))
    np.testing.assert_array_equal(order, [1, 2, 3, 5, 4, 0])


def test_solve_matches_dense_solution():
    P, A, constrained, rho_vec, K, (L, LS, Y) = _system(0)
    order = schur.ordering(P.shape[0], constrained)
    assert schur.factor(P, A, order, rho_vec, L, LS, Y)
    rhs = np.random.default_rng(1).standard_normal(K.shape[0])
    sol = np.empty_like(rhs)
    schur.solve_refined(L, LS, P, A, np.ones(A.shape[0]), order, constrained, rho_vec, rhs, sol)
    np.testing.assert_allclose(sol, np.linalg.solve(K, rhs), rtol=1e-10, atol=1e-12)


def test_unit_columns_are_columns_of_the_inverse():
    P, A, constrained, rho_vec, K, (L, LS, Y) = _system(2)
    order = schur.ordering(P.shape[0], constrained)
    assert schur.factor(P, A, order, rho_vec, L, LS, Y)
    W = np.zeros((K.shape[0], constrained.shape[0]), order="F")
    schur.unit_columns(L, LS, Y, order, W)
    np.testing.assert_allclose(W, np.linalg.inv(K)[:, constrained], rtol=1e-9, atol=1e-12)


def test_unit_columns_without_equalities_are_columns_of_the_inverse_of_H():
    P, _, constrained, rho_vec, _, (L, _, _) = _system(5)
    n, s = P.shape[0], constrained.shape[0]
    order = schur.ordering(n, constrained)
    LS, Y = np.zeros((0, 0), order="F"), np.zeros((n, 0), order="F")
    assert schur.factor(P, np.zeros((0, n)), order, rho_vec, L, LS, Y)
    W = np.zeros((n, s), order="F")
    schur.unit_columns(L, LS, Y, order, W)
    H = P.copy()
    H[constrained, constrained] += rho_vec
    np.testing.assert_allclose(W, np.linalg.inv(H)[:, constrained], rtol=1e-9, atol=1e-12)


def test_rank_deficient_equalities_are_refused():
    P, A, constrained, rho_vec, K, (L, LS, Y) = _system(3, rank_deficient=True)
    order = schur.ordering(P.shape[0], constrained)
    assert not schur.factor(P, A, order, rho_vec, L, LS, Y)


def test_indefinite_cost_is_refused():
    P, A, constrained, rho_vec, K, (L, LS, Y) = _system(4)
    P = P - 10.0 * np.eye(P.shape[0])
    order = schur.ordering(P.shape[0], constrained)
    assert not schur.factor(P, A, order, rho_vec, L, LS, Y)
