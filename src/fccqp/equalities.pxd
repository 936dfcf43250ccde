# cython: language_level=3
from fccqp.engine cimport Engine

cdef void hold_equalities(Engine* e) noexcept nogil
