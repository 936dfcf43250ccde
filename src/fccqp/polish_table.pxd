# cython: language_level=3
from fccqp._types cimport Problem
from fccqp.kkt cimport KKT
from fccqp.polish cimport Polish
from fccqp.reduced cimport Reduced

cdef bint table_factor(Polish* w, const Problem* p, const Reduced* t, const double* rho,
                       Py_ssize_t nb) noexcept nogil
cdef void table_solve(Polish* w, const Problem* p, const Reduced* t, KKT* kkt,
                      const double* rho, Py_ssize_t nb, double scale) noexcept nogil
cdef void table_correct(Polish* w, const Problem* p, const Reduced* t, KKT* kkt,
                        const double* rho, Py_ssize_t nb, double scale) noexcept nogil
