# cython: language_level=3
from fccqp._types cimport Iterates, Problem

cdef enum:
    # Outcomes of a primal or equality certificate's tests.
    REJECTED = 0
    CERTIFIED = 1
    SEPARATED = 2   # it separates, but its residual is not small enough against that
    WEAK = 3        # it passes at the iterate, but its residual reaches the separation
                    # at the data's scale

cdef int primal_infeasible(const Problem* p, const Iterates* it, double eps, const double* Ax,
                           double* row_norm, double* d_nu, double* d_y, double* lhs,
                           double* terms) noexcept nogil

cdef int primal_candidate(const Problem* p, const double* x, bint at_iterate,
                          const double* d_nu, double* d_y, double eps, double* lhs,
                          double* terms) noexcept nogil
cdef int equality_inconsistent(const Problem* p, const Iterates* it, double eps, double* r,
                               double* ATr, double* terms, double* sizes) noexcept nogil
cdef int equality_direction(const Problem* p, const double* r, const double* x, double eps,
                            double* ATr, double* terms, double* sizes) noexcept nogil
cdef bint zero_rows_inconsistent(const Problem* p, double* r, double* ones,
                                 double* norms) noexcept nogil
cdef void row_sizes(const Problem* p, const double* x, double* t, double* sizes) noexcept nogil
cdef bint gram_factor(const Problem* p, void* sparse, double* gram) noexcept nogil
cdef bint regularized_cholesky(double* gram, Py_ssize_t m) noexcept nogil
cdef int clean_primal_certificate(const Problem* p, const double* x, const double* gram,
                                   void* sparse, double eps, double* d_nu, double* d_y,
                                   double* saved, double* w, double* lhs,
                                   double* terms) noexcept nogil
