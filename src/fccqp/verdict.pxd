# cython: language_level=3
from fccqp.engine cimport Engine, Run

cdef int check(Engine* e, long iteration, bint last) noexcept nogil
cdef bint missed(const Engine* e) noexcept nogil
cdef bint missed_by_data(Engine* e) noexcept nogil
cdef bint row_missed_by_data(Engine* e, const double* Ax) noexcept nogil
cdef bint inconsistent(Engine* e, bint clean) noexcept nogil
cdef bint unbounded(Engine* e) noexcept nogil
cdef int classify(const Engine* e, long iteration, bint stopped) noexcept nogil
cdef bint settle(Engine* e, Run* run) noexcept nogil
