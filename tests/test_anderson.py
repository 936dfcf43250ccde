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
