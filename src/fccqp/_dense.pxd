# cython: language_level=3
"""Vector loops and matrix-vector products for the small dense matrices of a WBC QP.

``M x`` goes to BLAS ``dgemv``: a dot product per row is a chain of dependent
additions that the compiler may not reorder (no fast-math), and plain loops measured
slower than ``dgemv`` on these sizes (go2 realtime 329 us with loops against the numba
kernels' 290 us, which called BLAS); ``dgemv`` never goes multithreaded below 460,800
entries (OpenBLAS's threshold). ``M' y`` adds scaled rows, which vectorizes as written:
``fccqp_matvec_t`` (fccqp_kernels.h) beats ``dgemv`` there (2.1k against 2.8k
instructions a call on go2). The vector loops stay loops: a BLAS call costs more than
the arithmetic at these lengths.
"""

from libc.math cimport fabs
from scipy.linalg.cython_blas cimport dgemv


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


cdef extern from "fccqp_kernels.h" nogil:
    void fccqp_matvec_t(const double* M, int ld, const double* y, double* out, int rows,
                        int cols)


cdef inline void matvec(const double* M, const double* x, double* out,
                        Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """``out = M x`` for a row-major ``rows x cols`` matrix ``M`` (``dgemv``)."""
    cdef int r = <int>rows, c = <int>cols, one = 1
    cdef double alpha = 1.0, beta = 0.0
    cdef char trans = b"T"
    if rows == 0:
        return
    if cols == 0:
        fill(out, 0.0, rows)
        return
    dgemv(&trans, &c, &r, &alpha, <double*>M, &c, <double*>x, &one, &beta, out, &one)


cdef inline void matvec_t(const double* M, const double* y, double* out,
                          Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """``out = M' y`` for a row-major ``rows x cols`` matrix ``M`` (``fccqp_kernels.h``)."""
    fccqp_matvec_t(M, <int>cols, y, out, <int>rows, <int>cols)


cdef inline void colmatvec(const double* M, int ld, const double* x, double* out,
                           Py_ssize_t rows, Py_ssize_t cols, double beta) noexcept nogil:
    """``out = M x + beta out`` for a column-major ``rows x cols`` block ``M`` with
    leading dimension ``ld`` (``dgemv``)."""
    cdef int r = <int>rows, c = <int>cols, one = 1
    cdef double alpha = 1.0
    cdef char trans = b"N"
    if rows == 0:
        return
    if cols == 0:
        if beta == 0.0:
            fill(out, 0.0, rows)
        return
    dgemv(&trans, &r, &c, &alpha, <double*>M, &ld, <double*>x, &one, &beta, out, &one)
