# cython: language_level=3
from fccqp.matrices cimport Matrix

cdef double equilibrate_csc(Matrix* P, double* q, Matrix* A, double* b,
                            const Py_ssize_t* block_start, const Py_ssize_t* block_dim,
                            Py_ssize_t blocks, Py_ssize_t iterations, double* D, double* E,
                            double* d, double* e) noexcept nogil
cdef void scaled_norms_csc(const Matrix* P_s, const Matrix* A_s, double c,
                           double* norms) noexcept nogil
cdef bint rescale_csc(const Matrix* P, const double* q, const Matrix* A, const double* b,
                      const double* D, const double* E, const double* reference,
                      double* norms, Matrix* P_s, double* q_s, Matrix* A_s, double* b_s,
                      double* c) noexcept nogil
