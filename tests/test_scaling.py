"""Ruiz equilibration against a plain numpy restatement of its definition."""

import numpy as np
import pytest

from fccqp.scaling import MAX_NORM, MIN_NORM, equilibrate


def _inverse_sqrt(norm):
    return np.where(norm < MIN_NORM, 1.0, 1.0 / np.sqrt(np.clip(norm, MIN_NORM, MAX_NORM)))


def _ruiz(P, q, A, blocks, iterations):
    n, m = P.shape[0], A.shape[0]
    D, E = np.ones(n), np.ones(m)
    for _ in range(iterations):
        P_s = D[:, None] * P * D[None, :]
        A_s = E[:, None] * A * D[None, :]
        d = _inverse_sqrt(np.maximum(np.abs(P_s).max(axis=0), np.abs(A_s).max(axis=0, initial=0.0)))
        e = _inverse_sqrt(np.abs(A_s).max(axis=1, initial=0.0))
        for start, dim in blocks:
            d[start : start + dim] = np.exp(np.log(d[start : start + dim]).mean())
        D, E = D * d, E * e
    P_s = D[:, None] * P * D[None, :]
    mean_col = np.abs(P_s).max(axis=1).mean()
    q_norm = np.abs(D * q).max()
    size = max(mean_col if mean_col >= MIN_NORM else 1.0, q_norm if q_norm >= MIN_NORM else 1.0)
    return D, E, 1.0 / min(size, MAX_NORM)


@pytest.mark.parametrize(("seed", "n", "m"), [(0, 9, 4), (1, 13, 6), (2, 31, 12), (3, 5, 0)])
@pytest.mark.parametrize("iterations", [0, 1, 4, 10])
def test_equilibrate_matches_its_definition(seed, n, m, iterations):
    rng = np.random.default_rng(seed)
    # badly scaled rows and columns, a zero column, one cone block of 3 entries
    G = rng.standard_normal((n, n)) * np.logspace(-3, 3, n)
    P = G @ G.T
    P[:, 1] = P[1, :] = 0.0
    A = rng.standard_normal((m, n)) * np.logspace(2, -2, m)[:, None]
    q, b = rng.standard_normal(n) * 100, rng.standard_normal(m)
    blocks = [(2, 3)]
    D_ref, E_ref, c_ref = _ruiz(P, q, A, blocks, iterations)
    P_s, q_s, A_s, b_s = P.copy(), q.copy(), A.copy(), b.copy()
    D, E = np.empty(n), np.empty(m)
    start, dim = np.array([b[0] for b in blocks]), np.array([b[1] for b in blocks])
    c = equilibrate(P_s, q_s, A_s, b_s, start, dim, iterations, D, E)
    np.testing.assert_allclose(D, D_ref, rtol=1e-12)
    np.testing.assert_allclose(E, E_ref, rtol=1e-12)
    assert c == pytest.approx(c_ref, rel=1e-12)
    np.testing.assert_allclose(P_s, c * D[:, None] * P * D[None, :], rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(q_s, c * D * q, rtol=1e-12)
    np.testing.assert_allclose(A_s, E[:, None] * A * D[None, :], rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(b_s, E * b, rtol=1e-12)
    assert np.ptp(D[2:5]) <= 1e-12 * D[2]  # a cone block keeps one scale
