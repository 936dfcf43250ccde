"""The Schur-complement KKT backend against a dense solve of the same system."""

import numpy as np

from fccqp import schur


def _system(seed, n=12, m=5, s=4, rank_deficient=False):
    rng = np.random.default_rng(seed)
    M = rng.standard_normal((n, n))
    P = M @ M.T / n + 0.1 * np.eye(n)
    A = rng.standard_normal((m, n))
    if rank_deficient:
        A[-1] = 2.0 * A[0]
    constrained = np.arange(s, dtype=np.int64)
    rho_vec = np.full(s, 0.7)
    H = P.copy()
    H[constrained, constrained] += rho_vec
    K = np.block([[H, A.T], [A, np.zeros((m, m))]])
    work = (np.zeros((n, n), order="F"), np.zeros((m, m), order="F"),
            np.zeros((n, m), order="F"))
    return P, A, constrained, rho_vec, K, work


def test_solve_matches_dense_solution():
    P, A, constrained, rho_vec, K, (L, LS, Y) = _system(0)
    assert schur.factor(P, A, constrained, rho_vec, L, LS, Y)
    rhs = np.random.default_rng(1).standard_normal(K.shape[0])
    sol = np.empty_like(rhs)
    schur.solve_refined(L, LS, P, A, np.ones(A.shape[0]), constrained, rho_vec, rhs, sol)
    np.testing.assert_allclose(sol, np.linalg.solve(K, rhs), rtol=1e-10, atol=1e-12)


def test_unit_columns_are_columns_of_the_inverse():
    P, A, constrained, rho_vec, K, (L, LS, Y) = _system(2)
    assert schur.factor(P, A, constrained, rho_vec, L, LS, Y)
    W = np.zeros((K.shape[0], constrained.shape[0]), order="F")
    assert schur.unit_columns(L, LS, Y, A, np.ones(A.shape[0]), constrained, W)
    np.testing.assert_allclose(W, np.linalg.inv(K)[:, constrained], rtol=1e-9, atol=1e-12)


def test_rank_deficient_equalities_are_refused():
    P, A, constrained, rho_vec, K, (L, LS, Y) = _system(3, rank_deficient=True)
    assert not schur.factor(P, A, constrained, rho_vec, L, LS, Y)


def test_indefinite_cost_is_refused():
    P, A, constrained, rho_vec, K, (L, LS, Y) = _system(4)
    P = P - 10.0 * np.eye(P.shape[0])
    assert not schur.factor(P, A, constrained, rho_vec, L, LS, Y)
