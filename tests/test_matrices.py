"""The matrices contract's compressed-column arm against its dense arm (issue 28).

Every operation of :mod:`fccqp.matrices` runs, through :func:`fccqp.matrix_ops.apply`,
on the same matrix stored densely and in compressed columns: the certificates' row
sums must agree to the bit (both add each row's terms in column order), the BLAS and
four-lane products to rounding, and both to numpy.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from fccqp.matrix_ops import OPERATIONS, apply, diagonal_from

BITWISE = ("product_t_terms", "subtract_product", "abs_product", "product_row_norms")


def _matrix(rows, cols, seed):
    """A random sparse matrix with an empty row and an empty column when it has some."""
    rng = np.random.default_rng(seed)
    M = sp.random(rows, cols, density=0.3, random_state=rng).toarray()
    M *= rng.choice([-1.0, 1.0], size=(rows, cols)) * 10.0 ** rng.integers(-3, 3, size=(rows, cols))
    if rows > 2 and cols > 2:
        M[1, :] = 0.0
        M[:, 2] = 0.0
    return M


def _reference(operation, M, v, start):
    if operation == "product":
        return M @ v
    if operation == "product_t":
        return M.T @ v
    if operation == "product_t_terms":
        return M.T @ v, np.abs(M).T @ np.abs(v)
    if operation == "subtract_product":
        return start - M @ v
    if operation in ("abs_product", "row_spans"):
        return np.abs(M) @ v
    return M @ v, np.abs(M).sum(axis=1)


@pytest.mark.parametrize("operation", OPERATIONS)
@pytest.mark.parametrize("shape", [(7, 5), (5, 9), (1, 1), (0, 4), (13, 13)])
@pytest.mark.parametrize("seed", [0, 1])
def test_csc_arm_matches_dense_arm(operation, shape, seed):
    rows, cols = shape
    M = _matrix(rows, cols, seed)
    rng = np.random.default_rng(seed + 10)
    transposed = operation in ("product_t", "product_t_terms")
    v = rng.standard_normal(rows if transposed else cols)
    if operation in ("abs_product", "row_spans"):
        v = np.abs(v)
    start = rng.standard_normal(rows)
    on_dense = apply(operation, M, v, out=start)
    on_csc = apply(operation, sp.csc_matrix(M), v, out=start)
    expected = _reference(operation, M, v, start)
    pairs = zip(on_dense, on_csc, expected, strict=True) if isinstance(expected, tuple) else [
        (on_dense, on_csc, expected)]
    for dense_result, csc_result, reference in pairs:
        np.testing.assert_allclose(dense_result, reference, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(csc_result, reference, rtol=1e-12, atol=1e-12)
        if operation in BITWISE:
            assert np.array_equal(dense_result, csc_result)


def test_row_spans_skip_zero_entries_under_infinite_width():
    """A stored zero adds nothing where the width is infinite, in both arms."""
    M = np.array([[0.0, 2.0], [1.0, 0.0]])
    stored_zero = sp.csc_matrix((np.array([0.0, 1.0, 2.0]), np.array([0, 1, 0]),
                                 np.array([0, 2, 3])), shape=(2, 2))
    width = np.array([np.inf, 3.0])
    expected = np.array([6.0, np.inf])
    assert np.array_equal(apply("row_spans", M, width), expected)
    assert np.array_equal(apply("row_spans", stored_zero, width), expected)


def test_apply_rejects_bad_arguments():
    with pytest.raises(ValueError, match="operation"):
        apply("inverse", np.eye(2), np.ones(2))
    with pytest.raises(ValueError, match="vector must have 3 entries"):
        apply("product", np.ones((2, 3)), np.ones(2))


def _block_and_diagonal(n, block, seed):
    """A symmetric ``n x n`` matrix as whole-body control's ``P``: a dense leading
    ``block``, a diagonal after it with some zeros and negative entries."""
    rng = np.random.default_rng(seed)
    P = np.diag(rng.standard_normal(n) * (rng.random(n) > 0.2))
    B = rng.standard_normal((block, block))
    P[:block, :block] = B + B.T
    return P


@pytest.mark.parametrize(("n", "block", "expected"),
                         [(54, 18, 20), (124, 38, 40), (48, 16, 16), (54, 52, 52),
                          (54, 53, 54), (9, 9, 9), (7, 0, 0), (1, 1, 0)])
def test_diagonal_tail_starts_after_the_last_coupled_row_rounded_up_to_four(n, block,
                                                                             expected):
    P = _block_and_diagonal(n, block, seed=n + block)
    assert diagonal_from(P) == expected


@pytest.mark.parametrize(("n", "block"), [(54, 18), (48, 18), (124, 38), (100, 38), (13, 5)])
@pytest.mark.parametrize("seed", range(5))
def test_product_over_a_diagonal_tail_has_the_whole_products_bits(n, block, seed):
    P = _block_and_diagonal(n, block, seed)
    rng = np.random.default_rng(seed + 100)
    x = rng.standard_normal(n) * 10.0 ** rng.integers(-8, 8, size=n)
    x[rng.random(n) < 0.3] = 0.0
    x[rng.random(n) < 0.1] = -0.0
    whole = apply("product", P, x)
    assert apply("product", P, x, diagonal_tail=True).tobytes() == whole.tobytes()


def _wide_vectors():
    """Whether this x86-64 CPU has AVX2 and FMA (``fccqp_matvec`` runs; else ``dgemv``)."""
    try:
        with open("/proc/cpuinfo") as info:
            flags = next((line.split() for line in info if line.startswith("flags")), [])
    except OSError:
        return False
    return "avx2" in flags and "fma" in flags


@pytest.mark.skipif(not _wide_vectors(), reason="the dense M x is dgemv's without AVX2 + FMA")
@pytest.mark.parametrize(("rows", "cols"), [(30, 54), (20, 54), (24, 24), (68, 124), (7, 13),
                                            (5, 3), (3, 1)])
@pytest.mark.parametrize("seed", range(3))
def test_each_row_of_the_dense_product_is_summed_on_its_own(rows, cols, seed):
    """A row of ``M x`` has the same bits as that row alone times ``x``, wherever it sits
    among the rows (four at a time or in the remainder): dgemv's kernels sum rows in
    fours and the remainder apart, in other orders."""
    rng = np.random.default_rng(seed)
    M = rng.standard_normal((rows, cols)) * 10.0 ** rng.integers(-4, 4, size=(rows, cols))
    x = rng.standard_normal(cols)
    whole = apply("product", M, x)
    alone = np.array([apply("product", M[i:i + 1], x)[0] for i in range(rows)])
    assert whole.tobytes() == alone.tobytes()
    assert np.all(np.abs(whole - M @ x) <= 1e-13 * (np.abs(M) @ np.abs(x)))
