# cython: language_level=3
from fccqp.engine cimport Engine, Run

cdef void iterate(Engine* e, Run* run, bint cold, double start_time) noexcept nogil
