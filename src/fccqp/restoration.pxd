# cython: language_level=3
from fccqp._types cimport Iterates, Problem
from fccqp.kkt cimport KKT
from fccqp.reduced cimport Reduced

cdef struct Restoration:
    # Scratch of the feasibility restoration (sizes: s, s, s, s, s, N x s, s x s, s, N, N).
    char* pinned
    double* target
    double* projected
    Py_ssize_t* positions
    Py_ssize_t* entries
    double* W_T
    double* gram
    double* step
    double* start
    double* point

cdef bint restore(Restoration* r, KKT* k, Reduced* red, bint reduced, const Problem* p,
                  Iterates* it) noexcept nogil
