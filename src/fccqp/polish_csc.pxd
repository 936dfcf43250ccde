# cython: language_level=3
from cpython.ref cimport PyObject

from fccqp._types cimport Problem

cdef struct PolishCSC:
    # The polished QP's KKT matrix in compressed columns (upper triangle) and its qdldl
    # factor, for a problem whose P and A are CSC (see polish_csc.pyx). The arrays are
    # those of polish_csc.arrays, sized once per structure; N = n + m + cone count.
    Py_ssize_t* row_start   # m + 1: A's rows, the entries of row i at row_start[i] <= t < row_start[i + 1]
    Py_ssize_t* row_col     # nnz(A): the column of each, ascending in a row
    Py_ssize_t* row_entry   # nnz(A): its position in A.values
    Py_ssize_t* block_of    # n: the boundary block (of the guess) of each entry of x, else -1
    int* colptr             # N + 1: the assembled matrix (int32, as qdldl reads it)
    int* rowind             # capacity
    double* values          # capacity
    double* rhs             # N: the right-hand side handed to qdldl
    double* hess            # n x hess_stride (n >= s): the polish's curvature terms (Polish.hess on CSC)
    Py_ssize_t hess_stride  # the largest cone dimension (at least 1)
    PyObject* factor        # the polish_csc._Factor of these arrays (held by the workspace)

cdef bint polish_csc_factor(PolishCSC* f, const Problem* p, Py_ssize_t nf,
                            const Py_ssize_t* free, const Py_ssize_t* index,
                            const Py_ssize_t* boundary, Py_ssize_t nb,
                            const double* g, double delta) noexcept nogil
cdef void polish_csc_solve(PolishCSC* f, Py_ssize_t size, double* v) noexcept nogil
cdef void bind(PolishCSC* f, tuple arrays) except *
