# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The matrices contract (:mod:`fccqp.matrices`) from Python, for the tests.

The compiled core reaches ``P`` and ``A`` only through the contract's inline
operations; :func:`apply` runs one of them on a matrix in either storage, so that the
tests hold the compressed-column arm to the dense arm on the same matrix (issue 28,
stage 2), and :class:`Held` gives the ``def`` wrappers of the compressed-column kernels
(``scaling_csc``, ``validation``) a :c:type:`Matrix` over a ``scipy.sparse`` matrix.
Not on any solve's path; ``scipy.sparse`` is imported when first needed.
"""

import numpy as np

from fccqp.matrices cimport (DENSE, Matrix, abs_product, csc, dense, mark_diagonal_tail,
                             product, product_row_norms, product_t, product_t_terms,
                             row_spans, subtract_product)

OPERATIONS = ("product", "product_t", "product_t_terms", "subtract_product", "abs_product",
              "row_spans", "product_row_norms")
"""The names :func:`apply` takes, one per operation of the contract."""


cdef class Held:
    """A matrix as a :c:type:`Matrix` over arrays this object keeps: a ``scipy.sparse``
    matrix in compressed columns (rows sorted in each column), anything else dense.
    One spare entry each, so that an empty matrix has pointers."""

    def __init__(self, matrix):
        import scipy.sparse as sp
        if sp.issparse(matrix):
            held = sp.csc_matrix(matrix, dtype=np.float64)
            held.sort_indices()
            self.values = np.concatenate([held.data, [0.0]])
            self.colptr = held.indptr.astype(np.intp)
            self.rowind = np.concatenate([held.indices, [0]]).astype(np.intp)
            self.M = csc(&self.values[0], &self.colptr[0], &self.rowind[0], held.shape[0],
                         held.shape[1])
        else:
            held = np.asarray(matrix, dtype=np.float64)
            self.values = np.concatenate([held.reshape(-1), [0.0]])
            self.M = dense(&self.values[0], held.shape[0], held.shape[1])

    def matrix(self):
        """The held entries (written in place, perhaps) as a ``scipy.sparse`` CSC
        matrix, or a dense array."""
        import scipy.sparse as sp
        if self.M.kind == DENSE:
            return np.asarray(self.values)[:self.M.rows * self.M.cols].reshape(
                self.M.rows, self.M.cols).copy()
        count = self.colptr[self.M.cols]
        return sp.csc_matrix((np.asarray(self.values)[:count].copy(),
                              np.asarray(self.rowind)[:count].copy(),
                              np.asarray(self.colptr).copy()), shape=(self.M.rows, self.M.cols))


def diagonal_from(matrix):
    """:c:func:`mark_diagonal_tail`'s row of a dense symmetric ``matrix``: the first
    row, a multiple of 4 or the size, from which the rows hold their diagonal only."""
    cdef Held held = Held(np.asarray(matrix, dtype=np.float64))
    mark_diagonal_tail(&held.M)
    return held.M.diagonal_from


def apply(str operation, matrix, vector, out=None, bint diagonal_tail=False):
    """Run ``operation`` on ``matrix`` (a 2-d array: dense storage; ``scipy.sparse``:
    compressed columns) and ``vector`` (the operand: ``x``, ``y``, ``t`` or the width);
    with ``diagonal_tail`` a dense symmetric ``matrix`` is marked first as the solver
    marks ``P`` (:func:`diagonal_from`).

    Returns the result array, and for ``product_t_terms`` and ``product_row_norms``
    the pair (result, terms or norms); ``out`` is the starting ``out`` of
    ``subtract_product``. Raises ``ValueError`` for an unknown operation or a vector
    of the wrong size.
    """
    if operation not in OPERATIONS:
        raise ValueError(f"operation must be one of {OPERATIONS}, got {operation!r}")
    cdef Held held = Held(matrix)
    cdef Matrix* M = &held.M
    cdef Py_ssize_t rows = M.rows, cols = M.cols
    if diagonal_tail and M.kind == DENSE:
        mark_diagonal_tail(M)
    transposed = operation in ("product_t", "product_t_terms")
    operand = np.array(vector, dtype=np.float64)
    if operand.shape != ((rows,) if transposed else (cols,)):
        raise ValueError(f"vector must have {rows if transposed else cols} entries, "
                         f"got shape {operand.shape}")
    size = cols if transposed else rows
    start = np.zeros(size) if out is None or operation != "subtract_product" else out
    cdef double[::1] v = np.concatenate([operand, [0.0]])
    cdef double[::1] r = np.concatenate([start, [0.0]])
    cdef double[::1] t = np.zeros(size + 1)
    if operation == "product":
        product(M, &v[0], &r[0])
    elif operation == "product_t":
        product_t(M, &v[0], &r[0])
    elif operation == "product_t_terms":
        product_t_terms(M, &v[0], &r[0], &t[0])
    elif operation == "subtract_product":
        subtract_product(M, &v[0], &r[0])
    elif operation == "abs_product":
        abs_product(M, &v[0], &r[0])
    elif operation == "row_spans":
        row_spans(M, &v[0], &r[0])
    else:
        product_row_norms(M, &v[0], &r[0], &t[0])
    result = np.asarray(r)[:size].copy()
    if operation in ("product_t_terms", "product_row_norms"):
        return result, np.asarray(t)[:size].copy()
    return result
