"""The small positive definite solve behind Anderson acceleration."""

import numpy as np
import pytest
from fccqp.anderson import solve_small_spd_py as _solve_small_spd


@pytest.mark.parametrize("size", [1, 2, 5, 10])
def test_small_spd_solve_matches_numpy(size):
    rng = np.random.default_rng(size)
    G = rng.standard_normal((size, 3 * size))
    M = G @ G.T + 1e-3 * np.eye(size)
    b = rng.standard_normal(size)
    x = b.copy()
    assert _solve_small_spd(M.copy(), x)
    np.testing.assert_allclose(M @ x, b, atol=1e-10 * np.abs(b).max() * np.linalg.cond(M))


def test_small_spd_solve_refuses_an_indefinite_matrix():
    M = np.array([[1.0, 2.0], [2.0, 1.0]])
    assert not _solve_small_spd(M, np.ones(2))


def _rolled_spd_solve(M, b):
    """The Gram solve's operations in their order, as plain loops (row-major M)."""
    k = len(b)
    for c in range(k):
        pivot = M[c, c]
        for t in range(c):
            pivot -= M[c, t] * M[c, t]
        if not pivot > 0.0:
            return False
        pivot = float(np.sqrt(pivot))
        M[c, c] = pivot
        for r in range(c + 1, k):
            value = M[r, c]
            for t in range(c):
                value -= M[r, t] * M[c, t]
            M[r, c] = value / pivot
    for r in range(k):
        value = b[r]
        for t in range(r):
            value -= M[r, t] * b[t]
        b[r] = value / M[r, r]
    for r in range(k - 1, -1, -1):
        value = b[r]
        for t in range(r + 1, k):
            value -= M[t, r] * b[t]
        b[r] = value / M[r, r]
    return True


@pytest.mark.parametrize("size", range(1, 13))
def test_small_spd_solve_has_the_bits_of_plain_loops_at_every_size(size):
    """The compiled solve has a copy per size up to 10 and a general one beyond: each
    must round as the plain loops do, so that acceleration does not depend on the copy."""
    rng = np.random.default_rng(100 + size)
    for _ in range(20):
        G = rng.standard_normal((size + 2, size)) * 10.0 ** rng.uniform(-4, 4, size)
        M = G.T @ G
        b = rng.standard_normal(size)
        M_compiled, b_compiled = M.copy(), b.copy()
        M_loops, b_loops = M.copy(), b.copy()
        assert _solve_small_spd(M_compiled, b_compiled) == _rolled_spd_solve(M_loops, b_loops)
        assert b_compiled.tobytes() == b_loops.tobytes()
        assert np.tril(M_compiled).tobytes() == np.tril(M_loops).tobytes()


@pytest.mark.parametrize("size", range(2, 13))
def test_small_spd_solve_refuses_a_late_pivot_that_is_not_positive(size):
    M = np.eye(size)
    M[size - 1, size - 2] = M[size - 2, size - 1] = 1.0
    assert not _solve_small_spd(M, np.ones(size))
