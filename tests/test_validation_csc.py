"""The compressed-column scan (:func:`fccqp.validation.scan_and_copy_csc`): the dense
scan's copies and findings (the same error message), and ``NEW_PATTERN`` for another
pattern."""

import numpy as np
import pytest
import scipy.sparse as sp
from fccqp.validation import scan_and_copy_csc_py as scan

import fccqp
from fccqp.problem import raise_finding

NEW_PATTERN = 8


def _data(seed=0, n=7, m=4):
    rng = np.random.default_rng(seed)
    G = sp.random(n, n, density=0.3, random_state=rng).toarray()
    P = G + G.T + np.eye(n)
    A = sp.random(m, n, density=0.4, random_state=rng).toarray()
    A[:, 0] = 1.0
    return P, rng.standard_normal(n), A, rng.standard_normal(m), -np.ones(n), np.ones(n)


def _scan(P, q, A, b, lb, ub, previous=None):
    """Scan ``P, A`` whose pattern is ``previous``'s (default: their own, zeroed)."""
    P_pattern, A_pattern = previous if previous is not None else (P, A)
    P_prev, A_prev = sp.csc_matrix(P_pattern, copy=True), sp.csc_matrix(A_pattern, copy=True)
    if previous is None:
        P_prev.data[:], A_prev.data[:] = 0.0, 0.0
    return scan(_with_pattern(P, P_prev), q, _with_pattern(A, A_prev), b, lb, ub, P_prev, A_prev)


def _with_pattern(M, pattern):
    """``M`` stored on ``pattern``'s entries (NaN and inf kept, unlike scipy's
    conversion, which would drop nothing but might reorder)."""
    pattern = sp.csc_matrix(pattern)
    pattern.sort_indices()
    rows = pattern.indices
    cols = np.repeat(np.arange(pattern.shape[1]), np.diff(pattern.indptr))
    return sp.csc_matrix((np.asarray(M)[rows, cols], rows, pattern.indptr), shape=pattern.shape)


def test_clean_data_is_copied_and_reuse_detected():
    P, q, A, b, lb, ub = _data()
    lb[2], ub[3] = -2e20, 3e20   # beyond INFINITE_BOUND: stored infinite
    finding, same, P_c, q_c, A_c, b_c, lb_c, ub_c = _scan(P, q, A, b, lb, ub)
    assert finding[0] == 0 and not same
    assert np.array_equal(P_c.toarray(), P) and np.array_equal(A_c.toarray(), A)
    assert np.array_equal(q_c, q) and np.array_equal(b_c, b)
    assert lb_c[2] == -np.inf and ub_c[3] == np.inf and lb_c[0] == -1.0
    previous = (sp.csc_matrix(P), sp.csc_matrix(A))
    assert scan(sp.csc_matrix(P), q, sp.csc_matrix(A), b, lb, ub, *previous)[1]
    P2 = P.copy()
    P2[0, 0] += 1.0
    assert not scan(sp.csc_matrix(P2), q, sp.csc_matrix(A), b, lb, ub, *previous)[1]


def test_another_pattern_is_a_new_structure():
    P, q, A, b, lb, ub = _data()
    A2 = A.copy()
    A2[A2 == 0.0] = 0.5   # a fuller pattern
    previous = (sp.csc_matrix(P), sp.csc_matrix(A))
    assert scan(sp.csc_matrix(P), q, sp.csc_matrix(A2), b, lb, ub, *previous)[0][0] == NEW_PATTERN
    P2 = P + np.ones_like(P)
    assert scan(sp.csc_matrix(P2), q, sp.csc_matrix(A), b, lb, ub, *previous)[0][0] == NEW_PATTERN


BAD = [
    ("P", [(3, 5, np.nan), (5, 3, np.nan), (2, 6, np.inf), (6, 2, np.inf)]),
    ("P", [(4, 4, 1e300)]),
    ("A", [(3, 1, np.nan), (2, 4, np.inf)]),
    ("A", [(2, 6, 1e300), (1, 0, -np.inf)]),
    ("A", [(3, 0, -1e300)]),
    ("q", [(4, None, np.nan)]),
    ("b", [(1, None, 1e300)]),
    ("lb", [(2, None, 5.0)]),        # crossed: lb > ub
    ("ub", [(5, None, np.nan)]),
    ("lb", [(0, None, np.inf)]),
]


@pytest.mark.parametrize(("argument", "entries"), BAD)
def test_bad_numbers_give_the_dense_scans_message(argument, entries):
    data = dict(zip(("P", "q", "A", "b", "lb", "ub"), _data(), strict=True))
    pattern = (data["P"] + 1.0, data["A"] + 1.0)   # every entry stored
    for i, j, value in entries:
        if j is None:
            data[argument][i] = value
        else:
            data[argument][i, j] = value
    finding = _scan(*data.values(), previous=pattern)[0]
    with pytest.raises(ValueError) as on_dense:
        fccqp.solve(**data)
    with pytest.raises(ValueError) as on_csc:
        raise_finding(finding, data["lb"], data["ub"])
    assert str(on_csc.value) == str(on_dense.value)


@pytest.mark.parametrize(("argument", "entries"), BAD)
def test_the_sparse_path_names_the_entry_the_dense_path_names(argument, entries):
    """The sparse path's first conversion (:func:`fccqp.sparse_problem.convert`) reports
    the first bad entry by row, its row and value, as the dense scan does."""
    data = dict(zip(("P", "q", "A", "b", "lb", "ub"), _data(), strict=True))
    for i, j, value in entries:
        if j is None:
            data[argument][i] = value
        else:
            data[argument][i, j] = value
    with pytest.raises(ValueError) as on_dense:
        fccqp.solve(**data)
    with pytest.raises(ValueError) as on_sparse:
        fccqp.solve(**data, kkt_backend="sparse")
    assert str(on_sparse.value) == str(on_dense.value)
