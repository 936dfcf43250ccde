# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Ruiz equilibration of compressed-column data (issue 28: the sparse backend).

:mod:`fccqp.scaling`'s three passes over the matrices, for ``P`` (its full symmetric
pattern) and ``A`` in compressed columns (:mod:`fccqp.matrices`): :func:`equilibrate_csc`,
:func:`scaled_norms_csc` and :func:`rescale_csc`. Rows' maxima gather entry by entry
into a vector; every product is formed in the dense kernels' order (``(P_ij D_i) D_j``)
and a maximum does not depend on the order it is taken in, so ``D``, ``E``, ``c`` and the scaled entries are the dense
functions' to the bit (``tests/test_scaling_csc.py`` holds them to it). ``scale_start`` and
``unscale`` do not read the matrices and serve both storages.
"""

import numpy as np

from libc.math cimport fabs, ilogb, ldexp, log

from fccqp.matrices cimport Matrix
from fccqp.matrix_ops cimport Held
from fccqp.scaling cimport (cost_scale, gauge_apply, gauge_shift, inverse_sqrt_norm,
                            ruiz_factors, start_tiny_columns, within_drift)
from fccqp.tuning cimport CAPPED_PASSES, MAX_NORM, MIN_NORM


cdef double equilibrate_csc(Matrix* P, double* q, Matrix* A, double* b,
                            const Py_ssize_t* block_start, const Py_ssize_t* block_dim,
                            Py_ssize_t blocks, Py_ssize_t iterations, double* D, double* E,
                            double* d, double* e) noexcept nogil:
    """:func:`fccqp.scaling.equilibrate` on compressed columns: scale ``P, q, A, b`` in
    place, fill ``D`` and ``E``, return the cost scale ``c``; ``d`` and ``e`` are
    scratch of sizes ``n`` and ``m``."""
    cdef Py_ssize_t n = P.cols, m = A.rows, it = 0, i, j, k, passes = iterations
    cdef double value, norm
    cdef bint capped
    for j in range(n):
        D[j] = 1.0
    _row_maxima(A, D, e)
    for i in range(m):
        # as the dense pass: a row below MIN_NORM starts at norm 1 exactly
        value = e[i]
        E[i] = ldexp(1.0, -ilogb(value)) if 0.0 < value < MIN_NORM else 1.0
    while it < passes:
        it += 1
        _maxima(P, A, D, E, d, e)
        if it == 1 and start_tiny_columns(D, d, q, n, block_start, block_dim, blocks):
            _maxima(P, A, D, E, d, e)   # as the dense pass: a tiny column is started first
        capped = ruiz_factors(D, E, d, e, n, m, block_start, block_dim, blocks)
        if capped and passes < iterations + CAPPED_PASSES:
            passes += 1
    if m > 0 and passes > 0:
        _gauge(P, D, E, n, m)
    for j in range(n):
        for k in range(P.colptr[j], P.colptr[j + 1]):
            P.values[k] = P.values[k] * D[P.rowind[k]] * D[j]
        q[j] *= D[j]
    for j in range(n):
        for k in range(A.colptr[j], A.colptr[j + 1]):
            A.values[k] *= E[A.rowind[k]] * D[j]
    for i in range(m):
        b[i] *= E[i]
    return _normalize_cost(P, q, n, d)


cdef void _maxima(const Matrix* P, const Matrix* A, const double* D, const double* E,
                  double* column, double* row) noexcept nogil:
    """The scaled columns' norms into ``column``, the rows' into ``row``, in the dense
    kernels' products."""
    cdef Py_ssize_t n = P.cols, m = A.rows, i, j, k
    cdef double value, norm
    for j in range(n):
        norm = 0.0
        for k in range(P.colptr[j], P.colptr[j + 1]):
            norm = max(norm, fabs(P.values[k]) * D[P.rowind[k]])
        column[j] = norm * D[j]
    for i in range(m):
        row[i] = 0.0
    for j in range(n):
        for k in range(A.colptr[j], A.colptr[j + 1]):
            i = A.rowind[k]
            value = fabs(A.values[k]) * D[j]
            column[j] = max(column[j], value * E[i])
            row[i] = max(row[i], value)
    for i in range(m):
        row[i] *= E[i]


cdef void _row_maxima(const Matrix* A, const double* weight, double* out) noexcept nogil:
    """``out_i = max_j |A_ij| weight_j``."""
    cdef Py_ssize_t i, j, k
    for i in range(A.rows):
        out[i] = 0.0
    for j in range(A.cols):
        for k in range(A.colptr[j], A.colptr[j + 1]):
            i = A.rowind[k]
            out[i] = max(out[i], fabs(A.values[k]) * weight[j])


cdef void _gauge(const Matrix* P, double* D, double* E, Py_ssize_t n,
                 Py_ssize_t m) noexcept nogil:
    """The gauge of ``D`` (:func:`fccqp.scaling.gauge_apply` says why) on compressed
    columns."""
    cdef Py_ssize_t j, k
    cdef double largest = 0.0, shift
    if not gauge_shift(D, n, &shift):
        return
    for j in range(n):
        for k in range(P.colptr[j], P.colptr[j + 1]):
            largest = max(largest, fabs(P.values[k]) * D[P.rowind[k]] * D[j])
    gauge_apply(D, E, n, m, shift, largest)


cdef void _row_norms(const Matrix* P, double* out) noexcept nogil:
    """``out_i = max_j |P_ij|``, row by row as the dense kernels take it: the scaled
    ``P`` is symmetric only to rounding (``(P_ij D_i) D_j`` beside ``(P_ji D_j) D_i``)."""
    cdef Py_ssize_t i, j, k
    for i in range(P.rows):
        out[i] = 0.0
    for j in range(P.cols):
        for k in range(P.colptr[j], P.colptr[j + 1]):
            i = P.rowind[k]
            out[i] = max(out[i], fabs(P.values[k]))


cdef double _normalize_cost(Matrix* P, double* q, Py_ssize_t n, double* rows) noexcept nogil:
    """Multiply the scaled cost by :func:`fccqp.scaling.cost_scale`'s ``c`` and return
    it; ``rows`` is scratch of size ``n``."""
    cdef Py_ssize_t i, k
    cdef double mean_col = 0.0, q_norm = 0.0, c
    _row_norms(P, rows)
    for i in range(n):
        mean_col += rows[i]
    mean_col /= n
    for i in range(n):
        q_norm = max(q_norm, fabs(q[i]))
    c = cost_scale(mean_col, q_norm)
    for k in range(P.colptr[n]):
        P.values[k] *= c
    for i in range(n):
        q[i] *= c
    return c


cdef void scaled_norms_csc(const Matrix* P_s, const Matrix* A_s, double c,
                           double* norms) noexcept nogil:
    """:func:`fccqp.scaling.scaled_norms` on compressed columns: the columns' infinity
    norms of ``[P_s / c; A_s]`` into ``norms[:n]``, the rows' of ``A_s`` after them."""
    cdef Py_ssize_t n = P_s.cols, m = A_s.rows, i, j, k
    cdef double size, norm
    for j in range(n):
        norm = 0.0
        for k in range(P_s.colptr[j], P_s.colptr[j + 1]):
            norm = max(norm, fabs(P_s.values[k]))
        norms[j] = norm / c
    for i in range(m):
        norms[n + i] = 0.0
    for j in range(n):
        for k in range(A_s.colptr[j], A_s.colptr[j + 1]):
            size = fabs(A_s.values[k])
            norms[j] = max(norms[j], size)
            norms[n + A_s.rowind[k]] = max(norms[n + A_s.rowind[k]], size)


cdef bint rescale_csc(const Matrix* P, const double* q, const Matrix* A, const double* b,
                      const double* D, const double* E, const double* reference,
                      double* norms, Matrix* P_s, double* q_s, Matrix* A_s, double* b_s,
                      double* c) noexcept nogil:
    """:func:`fccqp.scaling.rescale` (what and why: see there) on compressed columns;
    ``P_s`` and ``A_s`` have the patterns of ``P`` and ``A``."""
    cdef Py_ssize_t n = P.cols, m = A.rows, i, j, k
    cdef double mean_col = 0.0, q_norm = 0.0, value, size
    for j in range(n):
        for k in range(P.colptr[j], P.colptr[j + 1]):
            P_s.values[k] = P.values[k] * D[P.rowind[k]] * D[j]
    _row_norms(P_s, norms)
    for j in range(n):
        mean_col += norms[j]
        q_s[j] = q[j] * D[j]
        q_norm = max(q_norm, fabs(q_s[j]))
    c[0] = cost_scale(mean_col / n, q_norm)
    for k in range(P.colptr[n]):
        P_s.values[k] *= c[0]
    for j in range(n):
        q_s[j] *= c[0]
    for i in range(m):
        norms[n + i] = 0.0
    for j in range(n):
        for k in range(A.colptr[j], A.colptr[j + 1]):
            i = A.rowind[k]
            value = A.values[k] * E[i] * D[j]
            A_s.values[k] = value
            size = fabs(value)
            norms[n + i] = max(norms[n + i], size)
            norms[j] = max(norms[j], size)
    for i in range(m):
        b_s[i] = b[i] * E[i]
    return within_drift(norms, reference, n + m)


cdef inline double* _ptr(double[::1] v) noexcept:
    return &v[0] if v.shape[0] else NULL


def equilibrate_csc_py(P, double[::1] q, A, double[::1] b, Py_ssize_t[::1] block_start,
                       Py_ssize_t[::1] block_dim, Py_ssize_t iterations, double[::1] D,
                       double[::1] E):
    """:func:`equilibrate_csc` on ``scipy.sparse`` ``P, A`` (``q, b, D, E`` in place);
    returns ``(c, P_s, A_s)``."""
    cdef Held Ph = Held(P), Ah = Held(A)
    cdef Py_ssize_t n = Ph.M.cols, m = Ah.M.rows
    cdef double[::1] d = np.empty(n), e = np.empty(max(m, 1))
    c = equilibrate_csc(&Ph.M, &q[0], &Ah.M, _ptr(b),
                        &block_start[0] if block_start.shape[0] else NULL,
                        &block_dim[0] if block_dim.shape[0] else NULL, block_start.shape[0],
                        iterations, &D[0], _ptr(E), &d[0], &e[0])
    return c, Ph.matrix(), Ah.matrix()


def rescale_csc_py(P, double[::1] q, A, double[::1] b, double[::1] D, double[::1] E,
                   double[::1] reference):
    """:func:`rescale_csc` on ``scipy.sparse`` ``P, A``; returns ``(kept, P_s, q_s, A_s,
    b_s, c)``."""
    cdef Held Ph = Held(P), Ah = Held(A), Ps = Held(P), As = Held(A)
    cdef Py_ssize_t n = Ph.M.cols, m = Ah.M.rows
    q_s, b_s = np.empty(n), np.empty(m)
    cdef double[::1] qv = q_s, bv = b_s, norms = np.empty(n + m)
    cdef double c = 0.0
    cdef bint kept = rescale_csc(&Ph.M, &q[0], &Ah.M, _ptr(b), &D[0], _ptr(E), &reference[0],
                                 &norms[0], &Ps.M, &qv[0], &As.M, _ptr(bv), &c)
    return kept, Ps.matrix(), q_s, As.matrix(), b_s, c


def scaled_norms_csc_py(P_s, A_s, double c):
    """:func:`scaled_norms_csc` on ``scipy.sparse`` matrices; returns the ``n + m`` norms."""
    cdef Held Ph = Held(P_s), Ah = Held(A_s)
    norms = np.empty(Ph.M.cols + Ah.M.rows)
    cdef double[::1] out = norms
    scaled_norms_csc(&Ph.M, &Ah.M, c, &out[0])
    return norms
