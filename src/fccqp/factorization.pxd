# cython: language_level=3
from fccqp.engine cimport Engine, Run

cdef long budget(const Engine* e, long iteration) noexcept nogil
cdef int factor(Engine* e, Run* run, long solves) noexcept nogil
cdef void reduced_base(Engine* e) noexcept nogil
cdef int change_rho(Engine* e, Run* run, double new_rho, long iteration,
                    bint reduced) noexcept nogil
cdef int equality_start(Engine* e, Run* run, bint* unbounded) noexcept nogil
