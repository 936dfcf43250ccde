# cython: language_level=3

cdef int sparse_factor(void* handle, Py_ssize_t s, double sigma,
                       const double* rho_vec) noexcept nogil
cdef void sparse_solve(void* handle, Py_ssize_t N, const double* rhs, double* sol) noexcept nogil
cdef void sparse_hold_equalities(void* handle, Py_ssize_t n, Py_ssize_t m, double* x,
                                 const double* b) noexcept nogil
cdef bint sparse_gram_factor(void* handle) noexcept nogil
cdef void sparse_gram_solve(void* handle, Py_ssize_t m, double* v) noexcept nogil
cdef bint sparse_column_gram_factor(void* handle, Py_ssize_t m, double* rows) noexcept nogil
cdef void sparse_column_gram_solve(void* handle, Py_ssize_t m, double* v) noexcept nogil
