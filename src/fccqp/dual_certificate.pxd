# cython: language_level=3
from fccqp._types cimport Problem

cdef bint dual_infeasible(const Problem* p, const double* dx, double eps, double* Pdx,
                          double* terms, double* block, double* weights,
                          double* rows) noexcept nogil
