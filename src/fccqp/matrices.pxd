# cython: language_level=3
"""The matrices contract: ``P`` and ``A`` as the algorithm reads them, and the products
it takes of them, in one place (OSQP's algebra layer, ``lin_alg``, is the model).

The iteration, the residuals, the certificates and the acceptance of a point reach the
matrices only through these operations, so that a second storage (compressed columns,
for the sparse backend of issue 28) needs a second implementation of them here and
in the storage-specific code, which reads ``values`` directly: the validation scan
(``validation.scan_and_copy``), the equilibration (``scaling``), the dense KKT backends
(``ldl``, ``schur``: their assembly and many-column products), the polish's dense
assembly (``polish_kkt._assemble``, ``polish_schur``) and the certificate cleaning's ``A A'``
(``certificates.gram_factor``, which on compressed columns asks the sparse backend's
``SparseKKT.factor_gram``).

Two storages (``Matrix.kind``):

- ``DENSE``: ``values`` row-major, ``M_ij = values[i * cols + j]`` (``P`` is symmetric,
  so its order does not matter). Each operation keeps the kernel and the summation
  order that its caller had before the contract, so that answers stay bitwise
  identical: ``M x`` by ``_dense.matvec`` (a symmetric matrix's diagonal tail apart, in
  the same bits: :func:`mark_diagonal_tail`), ``M' y`` and the row spans by
  ``fccqp_kernels.h``,
  the certificates' row sums as plain loops in column order.
- ``CSC``: compressed columns, the entries of column ``j`` at ``colptr[j] <= k <
  colptr[j + 1]``, ``M_{rowind[k], j} = values[k]``, rows ascending in each column.
  ``P`` is stored with its full symmetric pattern, so that every operation is one pass
  over one array and column ``j`` of ``P`` is its row ``j``. The row sums run as
  column sweeps, which add each row's terms in column order: the certificates' sums
  (``subtract_product``, ``abs_product``, ``product_t_terms``, ``product_row_norms``)
  are then the dense arm's to the bit, ``product``, ``product_t`` and ``row_spans``
  (BLAS and four-lane kernels in the dense arm) agree to rounding.

Each operation tests ``kind`` once (the dense arm first, the branch always taken the
same way in a solve).
"""

from libc.math cimport fabs

from fccqp._dense cimport matvec_ld, matvec_t

cdef extern from "fccqp_kernels.h" nogil:
    void fccqp_row_spans(const double* A, int rows, int cols, const double* width,
                         double* span)
    int fccqp_last_coupled_row(const double* M, int n)


cdef enum:
    # Matrix.kind
    DENSE = 0
    CSC = 1


cdef struct Matrix:
    Py_ssize_t rows, cols
    int kind                    # DENSE or CSC
    double* values              # DENSE: rows x cols, row-major; CSC: the stored entries
    Py_ssize_t* colptr          # CSC: cols + 1 offsets into values and rowind; else NULL
    Py_ssize_t* rowind          # CSC: the row of each stored entry; else NULL
    Py_ssize_t diagonal_from    # DENSE: rows from here on hold their diagonal entry only


cdef inline Matrix dense(double* values, Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """A dense ``rows x cols`` matrix over the row-major ``values``."""
    cdef Matrix M
    M.rows, M.cols, M.values = rows, cols, values
    M.kind, M.colptr, M.rowind = DENSE, NULL, NULL
    M.diagonal_from = rows
    return M


cdef inline Matrix csc(double* values, Py_ssize_t* colptr, Py_ssize_t* rowind,
                       Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """A ``rows x cols`` matrix in compressed columns (``colptr`` has ``cols + 1``
    entries, rows ascending in each column)."""
    cdef Matrix M
    M.rows, M.cols, M.values = rows, cols, values
    M.kind, M.colptr, M.rowind = CSC, colptr, rowind
    M.diagonal_from = rows
    return M


cdef inline double entry(const Matrix* M, Py_ssize_t i, Py_ssize_t j) noexcept nogil:
    """``M_ij`` (CSC: a search of column ``j``'s stored rows)."""
    cdef Py_ssize_t k
    if M.kind == DENSE:
        return M.values[i * M.cols + j]
    for k in range(M.colptr[j], M.colptr[j + 1]):
        if M.rowind[k] == i:
            return M.values[k]
    return 0.0


cdef inline bint zero_column(const Matrix* M, Py_ssize_t j) noexcept nogil:
    """Whether every entry of column ``j`` is zero (CSC: its stored ones)."""
    cdef Py_ssize_t i, k
    if M.kind == DENSE:
        for i in range(M.rows):
            if M.values[i * M.cols + j] != 0.0:
                return False
        return True
    for k in range(M.colptr[j], M.colptr[j + 1]):
        if M.values[k] != 0.0:
            return False
    return True


cdef inline void mark_diagonal_tail(Matrix* M) noexcept nogil:
    """Set ``M.diagonal_from`` of a dense symmetric ``M``: the first row, rounded up to a
    multiple of 4 (or ``rows``), from which every row holds its diagonal entry only.

    Whole-body control's ``P`` is a dense block on the accelerations and a diagonal on
    the torques and forces (go2: 18 of 54 rows, talos_reduced 38 of 124): :func:`product`
    then sweeps the block's rows only, a third of the matrix, and multiplies the
    diagonal. ``fccqp_matvec`` sums each row on its own and ``dgemv`` forms its output
    rows in fours, so that a multiple of 4 leaves each leading row summed as the whole
    product sums it, bit for bit (``dgemv`` checked on OpenBLAS' Haswell and SkylakeX
    kernels). The rows are read from the last up, each
    below its diagonal (``M`` is symmetric), until one has an entry off it
    (``fccqp_last_coupled_row``)."""
    cdef Py_ssize_t n = M.rows, i = fccqp_last_coupled_row(M.values, <int>n)
    M.diagonal_from = min((i + 4) // 4 * 4, n) if i > 0 else 0


cdef inline void product(const Matrix* M, const double* x, double* out) noexcept nogil:
    """``out = M x`` (``_dense.matvec_ld`` over the rows before ``M.diagonal_from``, a
    product of the diagonal after them; CSC: a column sweep). Where a symmetric ``M``
    has a diagonal tail (:func:`mark_diagonal_tail`) its leading rows are zero past
    their first ``diagonal_from`` columns, which the product leaves out: their lanes
    only ever added zeros, so the sums keep their bits (anymal_c's ``P``: 20 of 54
    columns)."""
    cdef Py_ssize_t i, j, k
    cdef double xj
    if M.kind == DENSE:
        matvec_ld(M.values, M.cols, x, out, M.diagonal_from,
                  M.diagonal_from if M.diagonal_from < M.rows else M.cols)
        for i in range(M.diagonal_from, M.rows):
            out[i] = 0.0 + M.values[i * M.cols + i] * x[i]   # matvec's +0 for a zero sum
        return
    for i in range(M.rows):
        out[i] = 0.0
    for j in range(M.cols):
        xj = x[j]
        for k in range(M.colptr[j], M.colptr[j + 1]):
            out[M.rowind[k]] += M.values[k] * xj


cdef inline void product_t(const Matrix* M, const double* y, double* out) noexcept nogil:
    """``out = M' y`` (``fccqp_matvec_t``; CSC: a column gather)."""
    cdef Py_ssize_t j, k
    cdef double value
    if M.kind == DENSE:
        matvec_t(M.values, y, out, M.rows, M.cols)
        return
    for j in range(M.cols):
        value = 0.0
        for k in range(M.colptr[j], M.colptr[j + 1]):
            value += M.values[k] * y[M.rowind[k]]
        out[j] = value


cdef inline void product_t_terms(const Matrix* M, const double* y, double* out,
                                 double* terms) noexcept nogil:
    """``out = M' y`` and ``terms = |M|' |y|``, the size of the products each entry of
    ``out`` sums (the certificates judge ``out`` against ``terms``)."""
    cdef Py_ssize_t n = M.cols, i, j, k
    cdef double value, total, size
    if M.kind == DENSE:
        for j in range(n):
            out[j] = 0.0
            terms[j] = 0.0
        for i in range(M.rows):
            for j in range(n):
                value = M.values[i * n + j] * y[i]
                out[j] += value
                terms[j] += fabs(value)
        return
    for j in range(n):
        total = 0.0
        size = 0.0
        for k in range(M.colptr[j], M.colptr[j + 1]):
            value = M.values[k] * y[M.rowind[k]]
            total += value
            size += fabs(value)
        out[j] = total
        terms[j] = size


cdef inline void subtract_product(const Matrix* M, const double* x, double* out) noexcept nogil:
    """``out -= M x``, each row's terms subtracted one by one in column order."""
    cdef Py_ssize_t n = M.cols, i, j, k
    cdef double value
    if M.kind == DENSE:
        for i in range(M.rows):
            value = out[i]
            for j in range(n):
                value -= M.values[i * n + j] * x[j]
            out[i] = value
        return
    for j in range(n):
        value = x[j]
        for k in range(M.colptr[j], M.colptr[j + 1]):
            out[M.rowind[k]] -= M.values[k] * value


cdef inline void abs_product(const Matrix* M, const double* t, double* out) noexcept nogil:
    """``out = |M| t`` (``t >= 0`` finite), each row summed in column order."""
    cdef Py_ssize_t n = M.cols, i, j, k
    cdef double row
    if M.kind == DENSE:
        for i in range(M.rows):
            row = 0.0
            for j in range(n):
                row += fabs(M.values[i * n + j]) * t[j]
            out[i] = row
        return
    for i in range(M.rows):
        out[i] = 0.0
    for j in range(n):
        row = t[j]
        for k in range(M.colptr[j], M.colptr[j + 1]):
            out[M.rowind[k]] += fabs(M.values[k]) * row


cdef inline void row_spans(const Matrix* M, const double* width, double* span) noexcept nogil:
    """``span_i = sum_j |M_ij| width_j`` over the entries ``M_ij != 0`` (a zero entry adds
    nothing even where the width is infinite), by ``fccqp_row_spans``."""
    cdef Py_ssize_t i, j, k
    cdef double w
    if M.kind == DENSE:
        if M.rows:
            fccqp_row_spans(M.values, <int>M.rows, <int>M.cols, width, span)
        return
    for i in range(M.rows):
        span[i] = 0.0
    for j in range(M.cols):
        w = width[j]
        for k in range(M.colptr[j], M.colptr[j + 1]):
            if M.values[k] != 0.0:
                span[M.rowind[k]] += fabs(M.values[k]) * w


cdef inline void product_row_norms(const Matrix* M, const double* x, double* out,
                                   double* norms) noexcept nogil:
    """``out = M x`` and ``norms_i = sum_j |M_ij|``, each row summed in column order (the
    dual certificate's test of ``M dx ~ 0`` row by row)."""
    cdef Py_ssize_t n = M.cols, i, j, k
    cdef double value, norm
    if M.kind == DENSE:
        for i in range(M.rows):
            value = 0.0
            norm = 0.0
            for j in range(n):
                value += M.values[i * n + j] * x[j]
                norm += fabs(M.values[i * n + j])
            out[i] = value
            norms[i] = norm
        return
    for i in range(M.rows):
        out[i] = 0.0
        norms[i] = 0.0
    for j in range(n):
        value = x[j]
        for k in range(M.colptr[j], M.colptr[j + 1]):
            out[M.rowind[k]] += M.values[k] * value
            norms[M.rowind[k]] += fabs(M.values[k])
