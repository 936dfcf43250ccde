"""Ruiz equilibration against a plain numpy restatement of its definition."""

import numpy as np
import pytest
from fccqp.projections import project_constraint_set
from fccqp.scaling import equilibrate_py as equilibrate
from fccqp.scaling import rescale_py as rescale
from fccqp.scaling import scale_start_py as scale_start
from fccqp.scaling import scaled_norms_py as scaled_norms
from fccqp.scaling import unscale_py as unscale
from fccqp.tuning import (
    CAPPED_PASSES,
    GAUGE_LIMIT,
    MAX_NORM,
    MIN_NORM,
    RESCALE_DRIFT,
    SPARSE_PASSES,
)


def _inverse_sqrt(norm):
    return np.where(norm < MIN_NORM, 1.0, 1.0 / np.sqrt(np.clip(norm, MIN_NORM, MAX_NORM)))


def _power_of_two(x):
    """``2 ** ilogb(x)``: ``x`` rounded down to a power of two."""
    return np.ldexp(1.0, np.frexp(x)[1] - 1)


def _tiny_column_start(columns, q, blocks):
    """``D`` of the first pass's start: ``1 / sqrt(norm)`` (a power of two) on the
    columns below ``MIN_NORM``, ``D_j |q_j|`` at most ``max |q|``, a cone block at its
    smallest."""
    tiny = (columns > 0.0) & (columns < MIN_NORM)
    D = np.where(tiny, 1.0 / _power_of_two(np.sqrt(columns)), 1.0)
    costly = tiny & (q != 0.0)
    D[costly] = np.minimum(D[costly], np.maximum(
        _power_of_two(np.abs(q).max() / np.abs(q[costly])), 1.0))
    for start, dim in blocks:
        D[start : start + dim] = D[start : start + dim].min()
    return D


def _norms(P, A, D, E):
    """The columns' and rows' norms of the scaled KKT matrix."""
    P_s = D[:, None] * P * D[None, :]
    A_s = E[:, None] * A * D[None, :]
    columns = np.maximum(np.abs(P_s).max(axis=0), np.abs(A_s).max(axis=0, initial=0.0))
    return columns, np.abs(A_s).max(axis=1, initial=0.0)


def _ruiz(P, q, A, blocks, iterations):
    n, m = P.shape[0], A.shape[0]
    D, E = np.ones(n), np.ones(m)
    done, passes = 0, iterations
    while done < passes:
        done += 1
        columns, rows = _norms(P, A, D, E)
        if done == 1 and ((columns > 0.0) & (columns < MIN_NORM)).any():
            D = _tiny_column_start(columns, q, blocks)
            columns, rows = _norms(P, A, D, E)
        if max(columns.max(), rows.max(initial=0.0)) > MAX_NORM and (
                passes < iterations + CAPPED_PASSES):
            passes += 1   # a pass whose correction was capped does not count
        d = _inverse_sqrt(columns)
        e = _inverse_sqrt(rows)
        for start, dim in blocks:
            d[start : start + dim] = np.exp(np.log(d[start : start + dim]).mean())
        D, E = D * d, E * e
    return D, E, _cost_normalization(D, P, q)


def _cost_normalization(D, P, q):
    """``c`` of the cost of ``P, q`` under the column scaling ``D``."""
    P_s = D[:, None] * P * D[None, :]
    mean_col = np.abs(P_s).max(axis=1).mean()
    q_norm = np.abs(D * q).max()
    size = max(mean_col if mean_col >= MIN_NORM else 1.0, q_norm if q_norm >= MIN_NORM else 1.0)
    return 1.0 / min(size, MAX_NORM)


@pytest.mark.parametrize(("seed", "n", "m"), [(0, 9, 4), (1, 13, 6), (2, 31, 12), (3, 5, 0)])
@pytest.mark.parametrize("iterations", [0, 1, 4, 10])
@pytest.mark.parametrize("density", [1.0, 0.2])
def test_equilibrate_matches_its_definition(seed, n, m, iterations, density):
    """Dense data (the four-lane passes) and sparse data (the passes over the nonzeros,
    ``SPARSE_PASSES``) alike."""
    rng = np.random.default_rng(seed)
    # badly scaled rows and columns, a zero column, one cone block of 3 entries
    G = rng.standard_normal((n, n)) * np.logspace(-3, 3, n)
    P = G @ G.T
    P[:, 1] = P[1, :] = 0.0
    A = rng.standard_normal((m, n)) * np.logspace(2, -2, m)[:, None]
    if density < 1.0:   # a symmetric pattern with the diagonal, at most density of the rest
        keep = np.triu(rng.random((n, n)) < density)
        P *= keep | keep.T | np.eye(n, dtype=bool)
        A *= rng.random((m, n)) < density
        assert np.count_nonzero(P) + np.count_nonzero(A) <= SPARSE_PASSES * (n + m) * n
    q, b = rng.standard_normal(n) * 100, rng.standard_normal(m)
    blocks = [(2, 3)]
    D_ref, E_ref, c_ref = _ruiz(P, q, A, blocks, iterations)
    P_s, q_s, A_s, b_s = P.copy(), q.copy(), A.copy(), b.copy()
    D, E = np.empty(n), np.empty(m)
    start = np.array([b[0] for b in blocks], dtype=np.intp)
    dim = np.array([b[1] for b in blocks], dtype=np.intp)
    c = equilibrate(P_s, q_s, A_s, b_s, start, dim, iterations, D, E)
    np.testing.assert_allclose(D, D_ref, rtol=1e-12)
    np.testing.assert_allclose(E, E_ref, rtol=1e-12)
    assert c == pytest.approx(c_ref, rel=1e-12)
    np.testing.assert_allclose(P_s, c * D[:, None] * P * D[None, :], rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(q_s, c * D * q, rtol=1e-12)
    np.testing.assert_allclose(A_s, E[:, None] * A * D[None, :], rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(b_s, E * b, rtol=1e-12)
    assert np.ptp(D[2:5]) <= 1e-12 * D[2]  # a cone block keeps one scale


@pytest.mark.parametrize("seed", range(4))
def test_variables_scaled_by_1e_8_to_1e8_are_equilibrated(seed):
    """Each pass corrects a norm by at most ``sqrt(MAX_NORM)`` = 100x, so four passes
    left variables rescaled by 1e-8 to 1e8 with column norms of 1e-4 (and ADMM ran 4000
    iterations on such feasible problems of the fuzzer's ``extreme_data``). Passes whose
    correction was capped no longer count toward ``scaling``."""
    rng = np.random.default_rng(seed)
    n, m = 8, 3
    M = rng.standard_normal((n, n))
    s = 10.0 ** np.linspace(-8, 8, n)
    P_s, A_s = (M @ M.T / n) * np.outer(s, s), rng.standard_normal((m, n)) * s
    q, b = rng.standard_normal(n) * s, rng.standard_normal(m)
    D, E = np.empty(n), np.empty(m)
    start = dim = np.zeros(0, dtype=np.intp)
    c = equilibrate(P_s, q, A_s, b, start, dim, 4, D, E)
    norms = scaled_norms(P_s, A_s, c)
    assert 0.25 <= norms.min() and norms.max() <= 4.0


def _variables_in_units(s, m, seed=0):
    """``P, q, A, b`` of a convex QP with ``len(s)`` entries, entry ``j`` in units of
    ``s_j`` (its columns of ``P`` and ``A`` and its ``q_j`` multiplied by ``s_j``)."""
    rng = np.random.default_rng(seed)
    n = len(s)
    M = rng.standard_normal((n, n))
    P, A = (M @ M.T / n) * np.outer(s, s), rng.standard_normal((m, n)) * s
    return P, rng.standard_normal(n) * s, A, rng.standard_normal(m)


UNITS_BELOW_MIN_NORM = np.array([1.0, 1.0, 1e-14, 1e-14, 1e-14, 1.0, 1e-12, 1e3])
"""Entry units whose columns lie below ``MIN_NORM``: a cone block (entries 2-4) and a
single entry."""


def test_variables_in_units_below_min_norm_are_equilibrated():
    """A column below ``MIN_NORM`` was left unscaled by every pass: an entry in units
    of 1e-8 (columns of 1e-14 in ``P``, 3.5e-9 in ``A``) kept a scaled curvature of
    2.5e-18, and ADMM and the polish's refinement both stalled 3e6 short of its
    optimum. Such a column starts at the square root of its norm, and the passes go
    on from there."""
    P_s, q, A_s, b = _variables_in_units(UNITS_BELOW_MIN_NORM, 3)
    D, E = np.empty(len(q)), np.empty(3)
    blocks = np.array([2], dtype=np.intp), np.array([3], dtype=np.intp)
    c = equilibrate(P_s, q, A_s, b, *blocks, 4, D, E)
    norms = scaled_norms(P_s, A_s, c)
    assert norms.min() >= 0.25 and norms.max() <= 4.0
    assert np.ptp(D[2:5]) == 0.0


@pytest.mark.parametrize("iterations", [1, 4, 10])
@pytest.mark.parametrize("m", [0, 3])
def test_columns_below_min_norm_match_the_definition(iterations, m):
    """Columns below ``MIN_NORM``: a cone block, a single entry, and a column tiny
    because the cost is (a ``P`` of 1e-200 on an entry with ``q_j`` of 1, no row when
    ``m`` is 0), which stays at most ``max |q|`` in ``D_j |q_j|``."""
    P, q, A, b = _variables_in_units(UNITS_BELOW_MIN_NORM, m)
    P[-1], P[:, -1], A[:, -1], q[-1] = 0.0, 0.0, 0.0, 1.0
    P[-1, -1] = 1e-200
    blocks = [(2, 3)]
    D_ref, E_ref, c_ref = _ruiz(P, q, A, blocks, iterations)
    D, E = np.empty(len(q)), np.empty(m)
    start, dim = np.array([2], dtype=np.intp), np.array([3], dtype=np.intp)
    c = equilibrate(P.copy(), q.copy(), A.copy(), b.copy(), start, dim, iterations, D, E)
    np.testing.assert_allclose(D, D_ref, rtol=1e-12)
    np.testing.assert_allclose(E, E_ref, rtol=1e-12)
    assert c == pytest.approx(c_ref, rel=1e-12)
    assert D[-1] * abs(q[-1]) <= np.abs(q).max()


@pytest.mark.parametrize("factor", [1e10, 1e12, 1e15])
def test_rows_scaled_by_1e10_and_more_leave_the_variables_their_scale(factor):
    """Ruiz split rows of ``A`` scaled by ``factor`` between ``E`` and ``D``: the scaled
    variables grew by ``sqrt(factor)`` and the cost shrank by as much, and rho hit its
    floor on such feasible fuzz problems (``A huge``). ``D`` keeps its scale now
    (``GAUGE_LIMIT``), with ``A_s`` as balanced and ``D P D`` at most 1."""
    rng = np.random.default_rng(0)
    n, m = 8, 3
    M = rng.standard_normal((n, n))
    P_s, A_s = M @ M.T / n, factor * rng.standard_normal((m, n))
    q, b = rng.standard_normal(n), factor * rng.standard_normal(m)
    D, E = np.empty(n), np.empty(m)
    start = dim = np.zeros(0, dtype=np.intp)
    c = equilibrate(P_s, q, A_s, b, start, dim, 4, D, E)
    assert 1 / GAUGE_LIMIT <= np.exp(np.log(D).mean()) <= GAUGE_LIMIT
    assert np.abs(A_s).max(axis=1).max() <= 4.0 and np.abs(P_s).max() / c <= 1.0


def test_warm_start_and_unscaling_are_inverse():
    rng = np.random.default_rng(0)
    n, m = 8, 3
    constrained = np.array([1, 2, 3, 4, 6], dtype=np.intp)  # a friction cone on 2-4, a box on 1, 6
    D, E, c = rng.uniform(0.1, 10, n), rng.uniform(0.1, 10, m), 0.37
    lo = np.array([-1.0, -np.inf, -np.inf, -np.inf, 0.0]) / D[constrained]
    hi = np.array([1.0, np.inf, np.inf, np.inf, 2.0]) / D[constrained]
    intp = np.intp
    cones = (np.array([0], intp), np.array([1], intp), np.array([3], intp), np.array([0.5]),
             np.zeros((1, 3)))
    cones[4][0, 2] = 1.0
    x, y, z = rng.standard_normal(n), rng.standard_normal(m), np.zeros(n)
    z[constrained] = rng.standard_normal(constrained.shape[0])
    rho = 0.3
    x_s, nu_s, y_s, z_s = np.empty(n), np.empty(m), np.empty(5), np.empty(5)
    scale_start(x, y, z, rho, D, E, c, constrained, lo, hi, cones, x_s, nu_s, y_s, z_s)
    np.testing.assert_allclose(x_s, x / D)
    expected_z = np.empty(5)
    project_constraint_set(x_s[constrained] + y_s / rho, lo, hi, cones, expected_z)
    np.testing.assert_array_equal(z_s, expected_z)
    x2, y2, z2 = unscale(x_s, nu_s, y_s, D, E, c, constrained)
    np.testing.assert_allclose(x2, x, rtol=1e-14)
    np.testing.assert_allclose(y2, y, rtol=1e-14)
    np.testing.assert_allclose(z2, z, rtol=1e-14)


def _equilibrated(P, q, A, b, iterations=4):
    n, m = P.shape[0], A.shape[0]
    P_s, q_s, A_s, b_s = P.copy(), q.copy(), A.copy(), b.copy()
    D, E = np.empty(n), np.empty(m)
    none = np.array([], dtype=np.intp)
    c = equilibrate(P_s, q_s, A_s, b_s, none, none, iterations, D, E)
    return D, E, c, scaled_norms(P_s, A_s, c)


def test_rescale_applies_an_earlier_scaling_and_normalizes_the_cost_anew():
    rng = np.random.default_rng(4)
    n, m = 12, 5
    G = rng.standard_normal((n, n)) * np.logspace(-2, 2, n)
    P, A = G @ G.T, rng.standard_normal((m, n)) * np.logspace(1, -1, m)[:, None]
    q, b = rng.standard_normal(n), rng.standard_normal(m)
    D, E, c, reference = _equilibrated(P, q, A, b)
    # the next tick: matrices 2 % off, a cost 8x larger
    P2 = P * (1 + 0.02 * rng.standard_normal((n, n)))
    P2 = (P2 + P2.T) / 2
    A2, q2 = A * (1 + 0.02 * rng.standard_normal((m, n))), 8 * q
    kept, P_s, q_s, A_s, b_s, c2 = rescale(P2, q2, A2, b, D, E, reference)
    assert kept
    assert c2 == pytest.approx(_cost_normalization(D, P2, q2), rel=1e-12)
    np.testing.assert_allclose(P_s, c2 * D[:, None] * P2 * D[None, :], rtol=1e-12)
    np.testing.assert_allclose(q_s, c2 * D * q2, rtol=1e-12)
    np.testing.assert_allclose(A_s, E[:, None] * A2 * D[None, :], rtol=1e-12)
    np.testing.assert_allclose(b_s, E * b, rtol=1e-12)
    # kept: every column norm of [P_s / c; A_s] and row norm of A_s within the drift
    norms = np.concatenate((np.maximum(np.abs(P_s).max(axis=0) / c2, np.abs(A_s).max(axis=0)),
                            np.abs(A_s).max(axis=1)))
    np.testing.assert_allclose(scaled_norms(P_s, A_s, c2), norms, rtol=1e-14)
    assert np.all(norms <= RESCALE_DRIFT * reference) and np.all(reference <= RESCALE_DRIFT * norms)


@pytest.mark.parametrize("block", [0, 4, 7, 12])
def test_rescale_over_a_diagonal_tail_gives_the_whole_scalings_bits(block):
    # P a dense leading block and a diagonal after it (whole-body control's shape):
    # the rows after the block are scaled on their diagonal alone, with the same bits
    rng = np.random.default_rng(6)
    n, m = 12, 5
    G = rng.standard_normal((block, block)) * np.logspace(-2, 2, block)
    P = np.diag(rng.uniform(0.1, 10.0, n))
    P[:block, :block] = G @ G.T + np.eye(block)
    A = rng.standard_normal((m, n))
    q, b = rng.standard_normal(n), rng.standard_normal(m)
    D, E, _, reference = _equilibrated(P, q, A, b)
    P2, q2 = P * (1 + 0.02 * rng.standard_normal((n, n))), 8 * q
    P2 = (P2 + P2.T) / 2
    whole = rescale(P2, q2, A, b, D, E, reference)
    tail = rescale(P2, q2, A, b, D, E, reference, diagonal_from=block)
    assert whole[0] and tail[0] and whole[5] == tail[5]
    for full, part in zip(whole[1:5], tail[1:5], strict=True):
        np.testing.assert_array_equal(part.view(np.int64), full.view(np.int64))


@pytest.mark.parametrize("where", ["P column", "A row"])
def test_rescale_refuses_data_that_moved_beyond_the_drift(where):
    rng = np.random.default_rng(5)
    n, m = 10, 4
    G = rng.standard_normal((n, n))
    P, A = G @ G.T + np.eye(n), rng.standard_normal((m, n))
    q, b = rng.standard_normal(n), rng.standard_normal(m)
    D, E, _, reference = _equilibrated(P, q, A, b)
    factor = 1.5 * RESCALE_DRIFT   # beyond the drift even after the cost's normalization
    P2, A2 = P.copy(), A.copy()
    if where == "P column":
        P2[:, 3] *= factor
        P2[3, :] *= factor
        A2[:, 3] *= factor
    else:
        A2[2] *= factor
    assert not rescale(P2, q, A2, b, D, E, reference)[0]
    assert rescale(P, q, A, b, D, E, reference)[0]


@pytest.mark.parametrize("column", range(11))
def test_the_nonzero_pattern_finds_an_entry_at_every_place_of_a_group_of_four(column):
    """The pattern tests four entries at once and skips groups of zeros: a lone
    nonzero in each column of ``A`` (two groups of four and a tail of three) and
    negative zeros elsewhere give the scaling of the definition."""
    n, m = 11, 2
    rng = np.random.default_rng(column)
    P = np.diag(rng.uniform(1e-2, 1e2, n))
    P[P == 0.0] = -0.0
    A = np.full((m, n), -0.0)
    A[0, column] = 50.0
    A[1, (column + 5) % n] = -0.02
    assert np.count_nonzero(P) + np.count_nonzero(A) <= SPARSE_PASSES * (n + m) * n
    q, b = rng.standard_normal(n), rng.standard_normal(m)
    D_ref, E_ref, c_ref = _ruiz(P, q, A, [], 4)
    D, E = np.empty(n), np.empty(m)
    none = np.zeros(0, dtype=np.intp)
    c = equilibrate(P.copy(), q.copy(), A.copy(), b.copy(), none, none, 4, D, E)
    np.testing.assert_allclose(D, D_ref, rtol=1e-12)
    np.testing.assert_allclose(E, E_ref, rtol=1e-12)
    assert c == pytest.approx(c_ref, rel=1e-12)
