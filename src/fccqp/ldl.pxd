# cython: language_level=3
from fccqp._types cimport Problem

cdef struct LDL:
    # Bunch-Kaufman factorization of the quasi-definite KKT matrix and its scratch.
    int N              # n + m
    double* K          # N x N, Fortran order; the factor after ldl_factor
    int* ipiv
    double* work       # lwork entries, for dsytrf
    int lwork
    double* residual   # N entries
    double* Ax         # m entries
    double* ATnu       # n entries

cdef int ldl_factor(LDL* f, const Problem* p, double sigma, const double* rho_vec) noexcept nogil
cdef void ldl_solve(LDL* f, const Problem* p, double sigma, const double* rho_vec,
                    const double* rhs, double* sol) noexcept nogil
cdef void ldl_solve_many(LDL* f, double* B, int columns, double* work) noexcept nogil
cdef bint meets_equalities(const double* Ax, const double* b, const double* row_scale,
                           Py_ssize_t m) noexcept nogil
cdef bint ldl_unit_columns(LDL* f, const Problem* p, double sigma, const double* rho_vec,
                           const Py_ssize_t* entries, int count, double* W, double* R,
                           double* work) noexcept nogil
