# cython: language_level=3
from fccqp._types cimport Problem
from fccqp.polish cimport Polish

cdef Py_ssize_t number_unknowns(Polish* w, const Problem* p) noexcept nogil
cdef void point_products(Polish* w, const Problem* p) noexcept nogil
cdef double kkt_residual(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil
cdef void refine(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb,
                 double tolerance, int* factorizations) noexcept nogil
cdef bint refactor(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb, double delta,
                   int* factorizations) noexcept nogil
cdef void correct_once(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil
