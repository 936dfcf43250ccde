# cython: language_level=3
from fccqp._types cimport Cones

cdef void proj_friction(const double* v, double mu, const double* normal,
                                double* out) noexcept nogil
cdef void proj_soc(const double* v, Py_ssize_t dim, double* out) noexcept nogil
cdef void proj_block(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                        const double* normal, double* out) noexcept nogil
cdef void proj_set(const double* v, const double* lo, const double* hi, Cones cones,
                      Py_ssize_t s, double* out) noexcept nogil
