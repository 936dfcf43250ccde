# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The operations of the matrices contract (:mod:`fccqp.matrices`) called from Python.

The compiled core reaches ``P`` and ``A`` only through these inline operations;
:func:`apply` runs one of them on a matrix in either storage, so that the tests hold
the compressed-column arm to the dense arm on the same matrix (issue 28, stage 2).
Not on any solve's path.
"""

import numpy as np
import scipy.sparse as sp

from fccqp.matrices cimport (Matrix, abs_product, csc, dense, product, product_row_norms,
                             product_t, product_t_terms, row_spans, subtract_product)

OPERATIONS = ("product", "product_t", "product_t_terms", "subtract_product", "abs_product",
              "row_spans", "product_row_norms")
"""The names :func:`apply` takes, one per operation of the contract."""


def apply(str operation, matrix, vector, out=None):
    """Run ``operation`` on ``matrix`` (a 2-d array: dense storage; ``scipy.sparse``:
    compressed columns) and ``vector`` (the operand: ``x``, ``y``, ``t`` or the width).

    Returns the result array, and for ``product_t_terms`` and ``product_row_norms``
    the pair (result, terms or norms); ``out`` is the starting ``out`` of
    ``subtract_product``. Raises ``ValueError`` for an unknown operation or a vector
    of the wrong size.
    """
    if operation not in OPERATIONS:
        raise ValueError(f"operation must be one of {OPERATIONS}, got {operation!r}")
    cdef Matrix M
    cdef double[::1] values
    cdef Py_ssize_t[::1] colptr, rowind
    if sp.issparse(matrix):
        stored = sp.csc_matrix(matrix, dtype=np.float64)
        stored.sort_indices()
        rows, cols = stored.shape
        # one spare entry each: a pointer even for an empty pattern
        values = np.concatenate([stored.data, [0.0]]).astype(np.float64)
        colptr = stored.indptr.astype(np.intp)
        rowind = np.concatenate([stored.indices, [0]]).astype(np.intp)
        M = csc(&values[0], &colptr[0], &rowind[0], rows, cols)
    else:
        held = np.ascontiguousarray(matrix, dtype=np.float64)
        rows, cols = held.shape
        values = np.concatenate([held.reshape(-1), [0.0]])
        M = dense(&values[0], rows, cols)
    transposed = operation in ("product_t", "product_t_terms")
    operand = np.array(vector, dtype=np.float64)
    if operand.shape != ((rows,) if transposed else (cols,)):
        raise ValueError(f"vector must have {rows if transposed else cols} entries, "
                         f"got shape {operand.shape}")
    result = np.zeros(cols if transposed else rows)
    second = np.zeros(cols if transposed else rows)
    if operation == "subtract_product" and out is not None:
        result[:] = out
    cdef double[::1] v = np.concatenate([operand, [0.0]])
    cdef double[::1] r = np.concatenate([result, [0.0]])
    cdef double[::1] t = np.concatenate([second, [0.0]])
    if operation == "product":
        product(&M, &v[0], &r[0])
    elif operation == "product_t":
        product_t(&M, &v[0], &r[0])
    elif operation == "product_t_terms":
        product_t_terms(&M, &v[0], &r[0], &t[0])
    elif operation == "subtract_product":
        subtract_product(&M, &v[0], &r[0])
    elif operation == "abs_product":
        abs_product(&M, &v[0], &r[0])
    elif operation == "row_spans":
        row_spans(&M, &v[0], &r[0])
    else:
        product_row_norms(&M, &v[0], &r[0], &t[0])
    size = len(result)
    result = np.asarray(r)[:size].copy()
    if operation in ("product_t_terms", "product_row_norms"):
        return result, np.asarray(t)[:size].copy()
    return result
