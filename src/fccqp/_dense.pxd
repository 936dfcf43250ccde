# cython: language_level=3
"""Vector loops and matrix-vector products for the small dense matrices of a WBC QP.

``M x`` goes to ``fccqp_matvec`` (fccqp_kernels.h) where the CPU has AVX2 and FMA: a dot
product per row is a chain of dependent additions that the compiler may not reorder (no
fast-math), so the kernel keeps four rows in four explicit lanes each. Through scipy's
``dgemv`` each call paid OpenBLAS' interface and driver, about 1.5k instructions a call
beside the kernel's (ipc2, notes/performance-history.md), and the kernel took 125 ns
against ``dgemv``'s 164 on go2's ``A`` (natively, a loop of calls). Without AVX2 ``dgemv``
stays: the kernel in 16-byte halves was slower than it. ``M' y`` and the column-major
``M x`` add scaled rows (columns), which vectorize as written: ``fccqp_matvec_t`` and
``fccqp_colmatvec`` in both copies (2.1k against 2.8k instructions a call for ``M' y`` on
go2; 115 against 242 ns for the reduced table's ``84 x 24`` block). ``dgemv`` never goes
multithreaded below 460,800 entries (OpenBLAS's threshold). The vector loops stay loops:
a BLAS call costs more than the arithmetic at these lengths.
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
    int fccqp_matvec(const double* M, int ld, const double* x, double* out, int rows,
                     int cols)
    void fccqp_colmatvec(const double* M, int ld, const double* x, double* out, int rows,
                         int cols, double beta)


cdef inline void matvec(const double* M, const double* x, double* out,
                        Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """``out = M x`` for a row-major ``rows x cols`` matrix ``M`` (:func:`matvec_ld`)."""
    matvec_ld(M, cols, x, out, rows, cols)


cdef inline void matvec_ld(const double* M, Py_ssize_t ld, const double* x, double* out,
                           Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """``out = M x`` for a row-major ``rows x cols`` block ``M`` whose rows lie ``ld``
    apart (``fccqp_matvec``, else ``dgemv``)."""
    cdef int r = <int>rows, c = <int>cols, lda = <int>ld, one = 1
    cdef double alpha = 1.0, beta = 0.0
    cdef char trans = b"T"
    if rows == 0:
        return
    if cols == 0:
        fill(out, 0.0, rows)
        return
    if not fccqp_matvec(M, lda, x, out, r, c):
        dgemv(&trans, &c, &r, &alpha, <double*>M, &lda, <double*>x, &one, &beta, out, &one)


cdef inline void matvec_t(const double* M, const double* y, double* out,
                          Py_ssize_t rows, Py_ssize_t cols) noexcept nogil:
    """``out = M' y`` for a row-major ``rows x cols`` matrix ``M`` (``fccqp_kernels.h``)."""
    fccqp_matvec_t(M, <int>cols, y, out, <int>rows, <int>cols)


cdef inline void colmatvec(const double* M, int ld, const double* x, double* out,
                           Py_ssize_t rows, Py_ssize_t cols, double beta) noexcept nogil:
    """``out = M x + beta out`` for a column-major ``rows x cols`` block ``M`` with
    leading dimension ``ld`` (``fccqp_colmatvec``; beta 0: ``out`` is not read)."""
    fccqp_colmatvec(M, ld, x, out, <int>rows, <int>cols, beta)
