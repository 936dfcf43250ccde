# cython: language_level=3
from fccqp.engine cimport Engine, Run

cdef Run scaled_run(Engine* e, bint same_matrices, const double* x0, bint warm,
                    bint keep_scaling, double start_time) noexcept nogil
cdef void unscaled_answer(Engine* e, Run* run, double* x, double* y, double* z,
                          double* cert) noexcept nogil
