"""The compressed-column equilibration (:mod:`fccqp.scaling_csc`) is the dense one's
to the bit: the same ``D``, ``E``, ``c``, scaled entries, norms and verdicts."""

import numpy as np
import pytest
import scipy.sparse as sp

from fccqp import scaling, scaling_csc


def _problem(seed, n, m, spread):
    """A sparse convex problem with a zero row and column of ``P``, an empty column of
    ``A`` whose column of ``P`` is tiny, and a row of tiny entries; rows and columns
    ``spread`` orders apart."""
    rng = np.random.default_rng(seed)
    G = sp.random(n, n, density=0.2, random_state=rng).toarray() * np.logspace(-spread, spread, n)
    P = G @ G.T + np.diag(rng.uniform(0.0, 1.0, n))
    P[:, 1] = P[1, :] = 0.0
    A = sp.random(m, n, density=0.3, random_state=rng).toarray()
    A *= np.logspace(spread, -spread, m)[:, None] * rng.choice([-1.0, 1.0], size=(m, n))
    A[:, 0] = 0.0
    P[0] *= 1e-12   # a column below MIN_NORM
    P[:, 0] *= 1e-12
    if m > 2:
        A[2] *= 1e-300
    return P, rng.standard_normal(n) * 100, A, rng.standard_normal(m)


CASES = [(0, 9, 4, 3), (1, 13, 6, 3), (2, 31, 12, 8), (3, 5, 0, 1), (4, 20, 15, 12)]


@pytest.mark.parametrize(("seed", "n", "m", "spread"), CASES)
@pytest.mark.parametrize("iterations", [0, 1, 4, 10])
def test_equilibrate_csc_is_the_dense_kernel_bitwise(seed, n, m, spread, iterations):
    P, q, A, b = _problem(seed, n, m, spread)
    start, dim = np.array([2], dtype=np.intp), np.array([3], dtype=np.intp)
    P_d, q_d, A_d, b_d = P.copy(), q.copy(), A.copy(), b.copy()
    D_d, E_d = np.empty(n), np.empty(m)
    c_d = scaling.equilibrate_py(P_d, q_d, A_d, b_d, start, dim, iterations, D_d, E_d)
    q_c, b_c, D_c, E_c = q.copy(), b.copy(), np.empty(n), np.empty(m)
    c_c, P_c, A_c = scaling_csc.equilibrate_csc_py(sp.csc_matrix(P), q_c, sp.csc_matrix(A),
                                                   b_c, start, dim, iterations, D_c, E_c)
    assert c_c == c_d
    for dense, compressed in [(D_d, D_c), (E_d, E_c), (q_d, q_c), (b_d, b_c),
                              (P_d, P_c.toarray()), (A_d, A_c.toarray())]:
        assert np.array_equal(dense, compressed)
    assert np.array_equal(scaling.scaled_norms_py(P_d, A_d, c_d),
                          scaling_csc.scaled_norms_csc_py(P_c, A_c, c_c))


@pytest.mark.parametrize(("seed", "n", "m", "spread"), CASES)
@pytest.mark.parametrize("drift", [1.0, 1e3])
def test_rescale_csc_is_the_dense_kernel_bitwise(seed, n, m, spread, drift):
    """New data under an earlier scaling: kept (a little drift) or refused (much)."""
    P, q, A, b = _problem(seed, n, m, spread)
    start = dim = np.zeros(0, dtype=np.intp)
    P_s, q_s, A_s, b_s = P.copy(), q.copy(), A.copy(), b.copy()
    D, E = np.empty(n), np.empty(m)
    c = scaling.equilibrate_py(P_s, q_s, A_s, b_s, start, dim, 4, D, E)
    reference = scaling.scaled_norms_py(P_s, A_s, c)
    P_new, A_new = P * 1.01, A.copy()
    if m:
        A_new[0] *= drift
    dense = scaling.rescale_py(P_new, q, A_new, b, D, E, reference)
    compressed = scaling_csc.rescale_csc_py(sp.csc_matrix(P_new), q, sp.csc_matrix(A_new), b,
                                            D, E, reference)
    assert dense[0] == compressed[0]
    assert dense[0] == (drift == 1.0 or m == 0 or not np.abs(A_new[0]).any())
    assert np.array_equal(dense[1], compressed[1].toarray())
    assert np.array_equal(dense[3], compressed[3].toarray())
    for k in (2, 4, 5):
        assert np.array_equal(dense[k], compressed[k])
