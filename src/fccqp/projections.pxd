# cython: language_level=3
from fccqp._types cimport Cones
from fccqp.cone_dispatch cimport cone_project


cdef inline void proj_block(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                            const double* normal, double* out) noexcept nogil:
    """Project one cone block onto its cone (:func:`fccqp.cone_dispatch.cone_project`)."""
    cone_project(v, kind, dim, mu, normal, out)


cdef void proj_set(const double* v, const double* lo, const double* hi, Cones cones,
                   Py_ssize_t s, double* out) noexcept nogil
cdef void proj_cones(double* v, Cones cones) noexcept nogil
