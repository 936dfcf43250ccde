# cython: language_level=3
from fccqp.engine cimport Engine, Run

cdef bint keep_polished(Engine* e, int* status, long iteration, double start_time,
                        bint solved_only) noexcept nogil
cdef bint warm_polish(Engine* e, Run* run, double start_time) noexcept nogil
cdef int keep_restored(Engine* e, int status, long iteration, bint reduced) noexcept nogil
cdef void restore_equalities(Engine* e) noexcept nogil
cdef void user_residuals(Engine* e, const double* x, const double* y,
                         const double* z) noexcept nogil
cdef void judge_rounding(Engine* e, const double* x) noexcept nogil
