# cython: language_level=3
"""Level-1 and level-2 loops for the small dense matrices of a whole-body-control QP.

BLAS is not called for these: at our sizes (n + m <= ~200) its call overhead and, for
OpenBLAS, its thread pool cost more than the arithmetic (a matrix-vector product of
124 x 124 is 15k flops, a few microseconds as a plain loop that the compiler
vectorizes), and a loop never spins a thread when the machine is loaded. Factorizations
and triangular solves with many right-hand sides go to LAPACK (see fccqp.ldl, fccqp.schur).
"""

from libc.math cimport fabs


cdef inline double inf_norm(const double* v, Py_ssize_t k) noexcept nogil:
    cdef double out = 0.0
    cdef Py_ssize_t i
    for i in range(k):
        if fabs(v[i]) > out:
            out = fabs(v[i])
    return out


cdef inline double dot(const double* a, const double* b, Py_ssize_t k) noexcept nogil:
    cdef double out = 0.0
    cdef Py_ssize_t i
    for i in range(k):
        out += a[i] * b[i]
    return out


cdef inline void copy(const double* src, double* dst, Py_ssize_t k) noexcept nogil:
    cdef Py_ssize_t i
    for i in range(k):
        dst[i] = src[i]


cdef inline void fill(double* dst, double value, Py_ssize_t k) noexcept nogil:
    cdef Py_ssize_t i
    for i in range(k):
        dst[i] = value


cdef inline void matvec(const double* M, const double* x, double* out,
                        Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """``out = M x`` for a row-major ``rows x cols`` matrix ``M``."""
    cdef Py_ssize_t i, j
    cdef double acc
    cdef const double* row
    for i in range(rows):
        row = M + i * cols
        acc = 0.0
        for j in range(cols):
            acc += row[j] * x[j]
        out[i] = acc


cdef inline void matvec_t(const double* M, const double* y, double* out,
                          Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """``out = M' y`` for a row-major ``rows x cols`` matrix ``M`` (row by row, so that
    the inner loop is contiguous)."""
    cdef Py_ssize_t i, j
    cdef double yi
    cdef const double* row
    for j in range(cols):
        out[j] = 0.0
    for i in range(rows):
        row = M + i * cols
        yi = y[i]
        for j in range(cols):
            out[j] += row[j] * yi
