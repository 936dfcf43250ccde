# cython: language_level=3
"""The matrices contract: ``P`` and ``A`` as the algorithm reads them, and the products
it takes of them, in one place (OSQP's algebra layer, ``lin_alg``, is the model).

The iteration, the residuals, the certificates and the acceptance of a point reach the
matrices only through these operations, so that a second storage (compressed columns,
for the sparse backend of issue 28) needs a second implementation of them here and
in the storage-specific code, which reads ``values`` directly: the validation scan
(``validation.scan_and_copy``), the equilibration (``scaling``), the dense KKT backends
(``ldl``, ``schur``: their assembly and many-column products), the polish's dense
assembly (``polish._assemble``, ``polish_schur``) and the certificate cleaning's ``A A'``
(``certificates.gram_factor``).

Today's storage is dense: ``values`` row-major, ``M_ij = values[i * cols + j]`` (``P``
is symmetric, so its order does not matter). Each operation keeps the kernel and the
summation order that its caller had before the contract, so that answers stay bitwise
identical: ``M x`` by ``dgemv``, ``M' y`` and the row spans by ``fccqp_kernels.h``, the
certificates' row sums as plain loops in column order.
"""

from libc.math cimport fabs

from fccqp._dense cimport matvec, matvec_t

cdef extern from "fccqp_kernels.h" nogil:
    void fccqp_row_spans(const double* A, int rows, int cols, const double* width,
                         double* span)


cdef struct Matrix:
    Py_ssize_t rows, cols
    double* values              # rows x cols, row-major


cdef inline Matrix dense(double* values, Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """A dense ``rows x cols`` matrix over the row-major ``values``."""
    cdef Matrix M
    M.rows, M.cols, M.values = rows, cols, values
    return M


cdef inline double entry(const Matrix* M, Py_ssize_t i, Py_ssize_t j) noexcept nogil:
    """``M_ij``."""
    return M.values[i * M.cols + j]


cdef inline void product(const Matrix* M, const double* x, double* out) noexcept nogil:
    """``out = M x`` (``dgemv``)."""
    matvec(M.values, x, out, M.rows, M.cols)


cdef inline void product_t(const Matrix* M, const double* y, double* out) noexcept nogil:
    """``out = M' y`` (``fccqp_matvec_t``)."""
    matvec_t(M.values, y, out, M.rows, M.cols)


cdef inline void product_t_terms(const Matrix* M, const double* y, double* out,
                                 double* terms) noexcept nogil:
    """``out = M' y`` and ``terms = |M|' |y|``, the size of the products each entry of
    ``out`` sums (the certificates judge ``out`` against ``terms``)."""
    cdef Py_ssize_t n = M.cols, i, j
    cdef double value
    for j in range(n):
        out[j] = 0.0
        terms[j] = 0.0
    for i in range(M.rows):
        for j in range(n):
            value = M.values[i * n + j] * y[i]
            out[j] += value
            terms[j] += fabs(value)


cdef inline void subtract_product(const Matrix* M, const double* x, double* out) noexcept nogil:
    """``out -= M x``, each row's terms subtracted one by one in column order."""
    cdef Py_ssize_t n = M.cols, i, j
    cdef double value
    for i in range(M.rows):
        value = out[i]
        for j in range(n):
            value -= M.values[i * n + j] * x[j]
        out[i] = value


cdef inline void abs_product(const Matrix* M, const double* t, double* out) noexcept nogil:
    """``out = |M| t`` (``t >= 0`` finite), each row summed in column order."""
    cdef Py_ssize_t n = M.cols, i, j
    cdef double row
    for i in range(M.rows):
        row = 0.0
        for j in range(n):
            row += fabs(M.values[i * n + j]) * t[j]
        out[i] = row


cdef inline void row_spans(const Matrix* M, const double* width, double* span) noexcept nogil:
    """``span_i = sum_j |M_ij| width_j`` over the entries ``M_ij != 0`` (a zero entry adds
    nothing even where the width is infinite), by ``fccqp_row_spans``."""
    if M.rows:
        fccqp_row_spans(M.values, <int>M.rows, <int>M.cols, width, span)


cdef inline void product_row_norms(const Matrix* M, const double* x, double* out,
                                   double* norms) noexcept nogil:
    """``out = M x`` and ``norms_i = sum_j |M_ij|``, each row summed in column order (the
    dual certificate's test of ``M dx ~ 0`` row by row)."""
    cdef Py_ssize_t n = M.cols, i, j
    cdef double value, norm
    for i in range(M.rows):
        value = 0.0
        norm = 0.0
        for j in range(n):
            value += M.values[i * n + j] * x[j]
            norm += fabs(M.values[i * n + j])
        out[i] = value
        norms[i] = norm
