# cython: language_level=3
from fccqp._types cimport Iterates, Problem

cdef bint primal_infeasible(const Problem* p, const Iterates* it, double eps, double* d_nu,
                            double* d_y, double* lhs, double* terms) noexcept nogil
cdef bint equality_inconsistent(const Problem* p, const Iterates* it, double eps, double* r,
                                double* ATr, double* terms) noexcept nogil
cdef bint dual_infeasible(const Problem* p, const double* dx, double eps, double* Pdx,
                          double* terms, double* block) noexcept nogil
