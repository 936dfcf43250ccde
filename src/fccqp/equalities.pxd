# cython: language_level=3
from fccqp._types cimport Problem
from fccqp.engine cimport Engine

cdef bint column_gram(const Problem* p, double* w, double* rows, double* gram) noexcept nogil

cdef void hold_equalities(Engine* e) noexcept nogil
