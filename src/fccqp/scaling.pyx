# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Ruiz equilibration of the problem data.

With ``x = D x_s`` and the equality rows multiplied by ``E``, the solver works on

    P_s = c D P D,   q_s = c D q,   A_s = E A D,   b_s = E b,   bounds / D,

where each Ruiz pass divides every column of ``[[P, A'], [A, 0]]`` by the square
root of its infinity norm (as OSQP does) and ``c`` normalizes the cost. ``D`` is
kept constant over each cone block (geometric mean), so a scaled cone is the same
cone: friction cones keep their ``mu`` and normal.

:func:`scale_start` and :func:`unscale` carry iterates across the scaling:
``x = D x_s``, equality multipliers ``y = E nu_s / c`` and constraint multipliers
``z_S = y_s / (c D_S)``. The ``def`` functions at the end wrap them for tests.
"""

import numpy as np

from libc.math cimport fabs, ilogb, ldexp, log
from libc.stdint cimport uint64_t

from fccqp._types cimport Cones
from fccqp.projections cimport proj_set
from fccqp.tuning cimport CAPPED_PASSES, SPARSE_PASSES

cdef extern from "fccqp_kernels.h" nogil:
    void fccqp_rescale_rows(const double* M, int rows, int cols, const double* left,
                            const double* right, double* out, double* row_max,
                            double* column_max)
    void fccqp_rescale_multiply(double* v, long k, double factor)
    void fccqp_ruiz_maxima(const double* P, const double* A, int n, int m, const double* D,
                           const double* E, double* column, double* row)


cdef int find_pattern(const double* P, const double* A, Py_ssize_t n, Py_ssize_t m,
                      Pattern* pattern) noexcept nogil:
    """The nonzeros of ``P`` and ``A`` into ``pattern``; returns how many there are."""
    return (_nonzero_rows(P, n, n, pattern.P_start, pattern.P_index)
            + _nonzero_rows(A, m, n, pattern.A_start, pattern.A_index))


cdef inline int _nonzero_rows(const double* M, Py_ssize_t rows, Py_ssize_t cols, int* start,
                              int* index) noexcept nogil:
    """Compressed rows of the nonzeros of the row-major ``rows x cols`` ``M``; returns
    their count. An entry is nonzero where its bits without the sign are (``-0.0`` is
    zero, NaN is not: ``!= 0.0`` exactly), so four entries are tested at once by one
    OR and a group of zeros (most of them: ``P`` and ``A`` are 10-27 % nonzero on the
    benchmark's robots) is skipped; a group with a nonzero is compacted without a
    branch: every column is written, and kept (the count moves on) where nonzero."""
    cdef Py_ssize_t i, j, l, whole = cols - cols % 4
    cdef int k = 0
    cdef const uint64_t* row
    start[0] = 0
    for i in range(rows):
        row = <const uint64_t*>(M + i * cols)
        for j in range(0, whole, 4):
            if (row[j] | row[j + 1] | row[j + 2] | row[j + 3]) << 1:
                for l in range(j, j + 4):
                    index[k] = <int>l
                    k += (row[l] << 1) != 0
        for j in range(whole, cols):
            index[k] = <int>j
            k += (row[j] << 1) != 0
        start[i + 1] = k
    return k


cdef inline double _row_max(const double* row, const int* index, int first, int last,
                            const double* weight) noexcept nogil:
    """``max_j |row_j| weight_j`` over the nonzeros ``index[first:last]`` of ``row``."""
    cdef double largest = 0.0, size
    cdef int k
    for k in range(first, last):
        size = fabs(row[index[k]]) * weight[index[k]]
        if size > largest:
            largest = size
    return largest


cdef void _sparse_maxima(const double* P, const double* A, Py_ssize_t n, Py_ssize_t m,
                         const Pattern* pt, const double* D, const double* E,
                         double* column, double* row) noexcept nogil:
    """``fccqp_ruiz_maxima`` (the scaled columns' norms into ``column``, the rows' into
    ``row``) on the nonzeros alone: the same products and maxima, as a zero entry adds
    nothing to a maximum of absolute values."""
    cdef Py_ssize_t i, j
    cdef int k
    cdef double size, scaled, largest
    for j in range(n):
        column[j] = 0.0
    for i in range(n):
        for k in range(pt.P_start[i], pt.P_start[i + 1]):
            j = pt.P_index[k]
            size = fabs(P[i * n + j]) * D[i]
            if size > column[j]:
                column[j] = size
    for j in range(n):
        column[j] *= D[j]
    for i in range(m):
        largest = 0.0
        for k in range(pt.A_start[i], pt.A_start[i + 1]):
            j = pt.A_index[k]
            size = fabs(A[i * n + j]) * D[j]
            scaled = size * E[i]
            if size > largest:
                largest = size
            if scaled > column[j]:
                column[j] = scaled
        row[i] = largest * E[i]


cdef inline void _maxima(const double* P, const double* A, Py_ssize_t n, Py_ssize_t m,
                         const Pattern* pattern, bint sparse, const double* D,
                         const double* E, double* column, double* row) noexcept nogil:
    """The scaled columns' norms into ``column``, the rows' into ``row``: on the nonzeros
    where ``sparse``, else in four lanes (a running maximum does not vectorize by itself)."""
    if sparse:
        _sparse_maxima(P, A, n, m, pattern, D, E, column, row)
    else:
        fccqp_ruiz_maxima(P, A, <int>n, <int>m, D, E, column, row)


cdef double equilibrate(double* P, double* q, double* A, double* b, Py_ssize_t n,
                        Py_ssize_t m, const Py_ssize_t* block_start,
                        const Py_ssize_t* block_dim, Py_ssize_t blocks, Py_ssize_t iterations,
                        double* D, double* E, double* d, double* e,
                        Pattern* pattern) noexcept nogil:
    """Scale ``P, q, A, b`` in place; fill ``D`` and ``E``; return the cost scale ``c``.

    Each pass reads the norms of the currently scaled matrix off the original entries
    (row ``i`` of ``D P D`` has norm ``D_i max_j |P_ij| D_j``), so the data is touched
    once per pass and rescaled once at the end. ``block_start``/``block_dim`` give the
    cone blocks in ``x``; ``d`` and ``e`` are scratch of sizes ``n`` and ``m``;
    ``pattern`` receives the nonzeros of ``P`` and ``A`` (:func:`find_pattern`). Rows
    and columns below ``MIN_NORM``, which the passes leave alone, are started first:
    a row at norm 1, a column at the root of its norm (:func:`start_tiny_columns`).

    Everything after finding the nonzeros walks them alone: the scaling, the cost's
    normalization and, where at most ``SPARSE_PASSES`` of the entries are nonzero, the
    passes (dense data keep the four-lane kernel). Whole-body control is sparse (go2:
    12 % of ``P``, 25 % of ``A``; talos 10 %, 16 %), and the result is bit for bit the
    one of a walk over every entry.
    """
    cdef Py_ssize_t it = 0, i, j, passes = iterations
    cdef int k
    cdef double value
    cdef bint capped
    cdef bint sparse = find_pattern(P, A, n, m, pattern) <= SPARSE_PASSES * (n + m) * n
    cdef const int* P_start = pattern.P_start
    cdef const int* P_index = pattern.P_index
    cdef const int* A_start = pattern.A_start
    cdef const int* A_index = pattern.A_index
    for j in range(n):
        D[j] = 1.0
    for i in range(m):
        # a row below MIN_NORM, which the passes leave alone, starts at norm 1 exactly
        # (a power of two): rows of 1e-300 were lost to the KKT matrix's regularization
        # and A x = b to |b|, whatever the passes
        value = _row_max(A + i * n, A_index, A_start[i], A_start[i + 1], D)
        E[i] = ldexp(1.0, -ilogb(value)) if 0.0 < value < MIN_NORM else 1.0
    while it < passes:
        it += 1
        # the columns' norms into d, the rows' into e; a column the passes would leave
        # alone is started first
        _maxima(P, A, n, m, pattern, sparse, D, E, d, e)
        if it == 1 and start_tiny_columns(D, d, q, n, block_start, block_dim, blocks):
            _maxima(P, A, n, m, pattern, sparse, D, E, d, e)
        capped = ruiz_factors(D, E, d, e, n, m, block_start, block_dim, blocks)
        if capped and passes < iterations + CAPPED_PASSES:
            passes += 1
    if m > 0 and passes > 0:
        _gauge(P, D, E, n, m, pattern)
    for i in range(n):
        for k in range(P_start[i], P_start[i + 1]):
            j = P_index[k]
            P[i * n + j] = P[i * n + j] * D[i] * D[j]
        q[i] *= D[i]
    for i in range(m):
        for k in range(A_start[i], A_start[i + 1]):
            j = A_index[k]
            A[i * n + j] *= E[i] * D[j]
        b[i] *= E[i]
    return _normalize_cost(P, q, n, pattern, d)


cdef void _gauge(const double* P, double* D, double* E, Py_ssize_t n, Py_ssize_t m,
                 const Pattern* pattern) noexcept nogil:
    """The gauge of ``D`` (:func:`fccqp.scaling.gauge_apply` says why) on dense ``P``."""
    cdef Py_ssize_t i, j
    cdef int k
    cdef double largest = 0.0, shift
    if not gauge_shift(D, n, &shift):
        return
    for i in range(n):
        for k in range(pattern.P_start[i], pattern.P_start[i + 1]):
            j = pattern.P_index[k]
            largest = max(largest, fabs(P[i * n + j]) * D[i] * D[j])
    gauge_apply(D, E, n, m, shift, largest)


cdef double _normalize_cost(double* P, double* q, Py_ssize_t n, const Pattern* pattern,
                            double* ones) noexcept nogil:
    """Multiply the (scaled) cost by :func:`cost_scale`'s ``c`` and return it; ``ones``
    is scratch of size ``n``."""
    cdef Py_ssize_t i
    cdef int k
    cdef double mean_col = 0.0, q_norm = 0.0, c
    for i in range(n):
        ones[i] = 1.0
    for i in range(n):
        mean_col += _row_max(P + i * n, pattern.P_index, pattern.P_start[i],
                             pattern.P_start[i + 1], ones)
    mean_col /= n
    for i in range(n):
        q_norm = max(q_norm, fabs(q[i]))
    c = cost_scale(mean_col, q_norm)
    for i in range(n):
        for k in range(pattern.P_start[i], pattern.P_start[i + 1]):
            P[i * n + pattern.P_index[k]] *= c
    for i in range(n):
        q[i] *= c
    return c


cdef void scaled_norms(const double* P_s, const double* A_s, Py_ssize_t n, Py_ssize_t m,
                       double c, const Pattern* pattern, double* norms) noexcept nogil:
    """Infinity norms of the columns of ``[P_s / c; A_s]`` into ``norms[:n]`` and of the
    rows of ``A_s`` into ``norms[n:n + m]``: what :func:`rescale` compares. Without the
    cost's normalization ``c``, which follows ``q`` and is found anew every time. The
    entries are the nonzeros of ``pattern`` (those of the unscaled matrices)."""
    cdef Py_ssize_t i, j
    cdef int k
    cdef double row, size
    for j in range(n):
        norms[j] = 0.0
    for i in range(n):
        for k in range(pattern.P_start[i], pattern.P_start[i + 1]):
            j = pattern.P_index[k]
            norms[j] = max(norms[j], fabs(P_s[i * n + j]))
    for j in range(n):
        norms[j] /= c
    for i in range(m):
        row = 0.0
        for k in range(pattern.A_start[i], pattern.A_start[i + 1]):
            j = pattern.A_index[k]
            size = fabs(A_s[i * n + j])
            norms[j] = max(norms[j], size)
            row = max(row, size)
        norms[n + i] = row


cdef bint rescale(const double* P, const double* q, const double* A, const double* b,
                  Py_ssize_t n, Py_ssize_t m, Py_ssize_t diagonal_from, const double* D,
                  const double* E, const double* reference, double* norms, double* P_s,
                  double* q_s, double* A_s, double* b_s, double* c) noexcept nogil:
    """Scale new data with the ``D, E`` of an earlier equilibration and normalize its
    cost into ``c`` as :func:`equilibrate` does (two passes over ``P``'s rows before
    ``diagonal_from``, a product of the diagonal after them, one pass over ``A``, the
    norms found on the way); False when a column or row norm of the result (as
    :func:`scaled_norms` reads them, into ``norms``) left the factor ``RESCALE_DRIFT``
    around ``reference``, the norms that equilibration gave its own data: then the data
    moved too far for it and the caller equilibrates.

    In a control loop the matrices change a little every tick, and the ``D, E`` of an
    earlier tick scale this tick's data about as well (on the WBC sets the largest
    scaled norm moved from 1 to at most 1.014): any positive ``D, E, c`` give the same
    solution, the scaling only conditions the iteration. The cost's size follows ``q``
    (8x between two solo12 ticks), so ``c`` is found anew. On go2 the four Ruiz passes
    are 0.22M of a 1.76M-instruction tick (callgrind).
    """
    cdef Py_ssize_t i, k = diagonal_from
    cdef double mean_col = 0.0, q_norm = 0.0, cost
    # D P D and its rows' norms (its columns': it is symmetric), then the cost's size
    fccqp_rescale_rows(P, <int>k, <int>n, D, D, P_s, norms, NULL)
    _scale_diagonal_rows(P, n, k, D, P_s, norms)
    for i in range(n):
        mean_col += norms[i]
        q_s[i] = q[i] * D[i]
        q_norm = max(q_norm, fabs(q_s[i]))
    cost = c[0] = cost_scale(mean_col / n, q_norm)
    fccqp_rescale_multiply(P_s, k * n, cost)
    for i in range(k, n):
        P_s[i * n + i] *= cost
    fccqp_rescale_multiply(q_s, n, cost)
    if m:   # E A D, its rows' norms and its columns' beside D P D's
        fccqp_rescale_rows(A, <int>m, <int>n, E, D, A_s, norms + n, norms)
    for i in range(m):
        b_s[i] = b[i] * E[i]
    return within_drift(norms, reference, n + m)


cdef inline void _scale_diagonal_rows(const double* P, Py_ssize_t n, Py_ssize_t first,
                                      const double* D, double* P_s,
                                      double* norms) noexcept nogil:
    """Rows ``first:n`` of ``D P D`` and their norms, where ``P`` holds only its diagonal
    (``Matrix.diagonal_from``): the entry as ``fccqp_rescale_rows`` forms it, ``(P_ii D_i)
    D_i``, and zeros beside it (``+0.0``: the sign of a zero of ``P`` is not kept)."""
    cdef Py_ssize_t i, j
    cdef double* row
    for i in range(first, n):
        row = P_s + i * n
        for j in range(n):
            row[j] = 0.0
        row[i] = P[i * n + i] * D[i] * D[i]
        norms[i] = fabs(row[i])


cdef void scale_start(const double* x, const double* y, const double* z, double rho,
                      const double* D, const double* E, double c, Py_ssize_t n, Py_ssize_t m,
                      Py_ssize_t s, const Py_ssize_t* constrained, const double* lo,
                      const double* hi, Cones cones, double* x_s, double* nu_s, double* y_s,
                      double* z_s) noexcept nogil:
    """Warm start from an unscaled solution ``(x, y, z)`` of a previous solve.

    Fills the scaled iterate ``x_s, nu_s`` (x and equality multipliers), ``y_s``
    (constraint multipliers on the constrained entries) and the slack ``z_s = P_C(x_s
    + y_s / rho)``, the point ADMM's z-update would produce from them.
    """
    cdef Py_ssize_t i, j
    cdef double inverse_rho = 1.0 / max(rho, 1e-12)
    for i in range(n):
        x_s[i] = x[i] / D[i]
    for i in range(m):
        nu_s[i] = y[i] * c / E[i]
    for j in range(s):
        i = constrained[j]
        y_s[j] = z[i] * c * D[i]
        z_s[j] = x_s[i] + y_s[j] * inverse_rho
    proj_set(z_s, lo, hi, cones, s, z_s)


cdef void unscale(const double* x_s, const double* nu_s, const double* y_s, const double* D,
                  const double* E, double c, Py_ssize_t n, Py_ssize_t m, Py_ssize_t s,
                  const Py_ssize_t* constrained, double* x, double* y,
                  double* z) noexcept nogil:
    """``(x, y, z)`` of the user's problem from a scaled iterate; ``z`` is zero off the
    constrained entries."""
    cdef Py_ssize_t i, j
    for i in range(n):
        x[i] = x_s[i] * D[i]
        z[i] = 0.0
    for i in range(m):
        y[i] = nu_s[i] * E[i] / c
    for j in range(s):
        i = constrained[j]
        z[i] = y_s[j] / (c * D[i])


cdef inline double* _ptr(double[::1] v) noexcept:
    return &v[0] if v.shape[0] else NULL


cdef Pattern _pattern(list arrays, Py_ssize_t n, Py_ssize_t m):
    """A :c:type:`Pattern` over new numpy arrays (kept alive in ``arrays``)."""
    cdef Pattern pattern
    cdef int[::1] P_start = np.zeros(n + 1, dtype=np.intc)
    cdef int[::1] P_index = np.zeros(max(n * n, 1), dtype=np.intc)
    cdef int[::1] A_start = np.zeros(m + 1, dtype=np.intc)
    cdef int[::1] A_index = np.zeros(max(m * n, 1), dtype=np.intc)
    arrays.extend((P_start, P_index, A_start, A_index))
    pattern.P_start, pattern.P_index = &P_start[0], &P_index[0]
    pattern.A_start, pattern.A_index = &A_start[0], &A_index[0]
    return pattern


def equilibrate_py(double[:, ::1] P, double[::1] q, double[:, ::1] A, double[::1] b,
                   Py_ssize_t[::1] block_start, Py_ssize_t[::1] block_dim,
                   Py_ssize_t iterations, double[::1] D, double[::1] E):
    """:func:`equilibrate` on numpy arrays (``P, A`` C-ordered); returns ``c``."""
    cdef Py_ssize_t n = P.shape[0], m = A.shape[0]
    cdef double[::1] d = np.empty(n), e = np.empty(max(m, 1))
    cdef double* A_ptr = &A[0, 0] if m else NULL
    cdef list kept = []
    cdef Pattern pattern = _pattern(kept, n, m)
    return equilibrate(&P[0, 0], &q[0], A_ptr, _ptr(b), n, m,
                       &block_start[0] if block_start.shape[0] else NULL,
                       &block_dim[0] if block_dim.shape[0] else NULL, block_start.shape[0],
                       iterations, &D[0], _ptr(E), &d[0], &e[0], &pattern)


def rescale_py(double[:, ::1] P, double[::1] q, double[:, ::1] A, double[::1] b,
               double[::1] D, double[::1] E, double[::1] reference,
               Py_ssize_t diagonal_from=-1):
    """:func:`rescale` on numpy arrays (``P``'s rows from ``diagonal_from`` on hold their
    diagonal only; default none); returns ``(kept, P_s, q_s, A_s, b_s, c)``."""
    cdef Py_ssize_t n = P.shape[0], m = A.shape[0]
    if diagonal_from < 0:
        diagonal_from = n
    P_s, q_s, A_s, b_s = np.empty((n, n)), np.empty(n), np.empty((m, n)), np.empty(m)
    cdef double[:, ::1] Pv = P_s, Av = A_s
    cdef double[::1] qv = q_s, bv = b_s, norms = np.empty(n + m)
    cdef double c = 0.0
    cdef bint kept = rescale(&P[0, 0], &q[0], &A[0, 0] if m else NULL, _ptr(b), n, m,
                             diagonal_from, &D[0], _ptr(E), &reference[0], &norms[0],
                             &Pv[0, 0], &qv[0], &Av[0, 0] if m else NULL, _ptr(bv), &c)
    return kept, P_s, q_s, A_s, b_s, c


def scaled_norms_py(double[:, ::1] P_s, double[:, ::1] A_s, double c):
    """:func:`scaled_norms` on numpy arrays; returns the ``n + m`` norms."""
    cdef Py_ssize_t n = P_s.shape[0], m = A_s.shape[0]
    norms = np.empty(n + m)
    cdef double[::1] out = norms
    cdef const double* A_ptr = &A_s[0, 0] if m else NULL
    cdef list kept = []
    cdef Pattern pattern = _pattern(kept, n, m)
    find_pattern(&P_s[0, 0], A_ptr, n, m, &pattern)
    scaled_norms(&P_s[0, 0], A_ptr, n, m, c, &pattern, &out[0])
    return norms


def scale_start_py(double[::1] x, double[::1] y, double[::1] z, double rho, double[::1] D,
                   double[::1] E, double c, Py_ssize_t[::1] constrained, double[::1] lo,
                   double[::1] hi, cones, double[::1] x_s, double[::1] nu_s, double[::1] y_s,
                   double[::1] z_s):
    """:func:`scale_start` on numpy arrays; ``cones`` as in
    :func:`fccqp.projections.project_constraint_set`."""
    cdef Py_ssize_t[::1] kind, offset, dim
    cdef double[::1] mu
    cdef double[:, ::1] normal
    kind, offset, dim, mu, normal = cones
    cdef Cones c_
    c_.count = kind.shape[0]
    if c_.count:
        c_.kind, c_.offset, c_.dim = &kind[0], &offset[0], &dim[0]
        c_.mu, c_.normal = &mu[0], &normal[0, 0]
    cdef Py_ssize_t s = constrained.shape[0]
    scale_start(&x[0], _ptr(y), &z[0], rho, &D[0], _ptr(E), c, x.shape[0], y.shape[0], s,
                &constrained[0] if s else NULL, _ptr(lo), _ptr(hi), c_, &x_s[0], _ptr(nu_s),
                _ptr(y_s), _ptr(z_s))


def unscale_py(double[::1] x_s, double[::1] nu_s, double[::1] y_s, double[::1] D,
               double[::1] E, double c, Py_ssize_t[::1] constrained):
    """:func:`unscale` on numpy arrays; returns new arrays ``(x, y, z)``."""
    cdef Py_ssize_t n = x_s.shape[0], m = nu_s.shape[0], s = constrained.shape[0]
    x, y, z = np.empty(n), np.empty(m), np.empty(n)
    cdef double[::1] xv = x, yv = y, zv = z
    unscale(&x_s[0], _ptr(nu_s), _ptr(y_s), &D[0], _ptr(E), c, n, m, s,
            &constrained[0] if s else NULL, &xv[0], _ptr(yv), &zv[0])
    return x, y, z
