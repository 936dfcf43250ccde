# cython: language_level=3
from fccqp._types cimport Cones, Problem
from fccqp.cone_dispatch cimport INSIDE, POLAR, cone_region
from fccqp.polish cimport APEX, BOUNDARY, FIXED, FREE, LOWER, UPPER, Polish


cdef inline char box_code(const Problem* p, Py_ssize_t j, double v) noexcept nogil:
    """The guess for box entry ``j`` from ``v = z_j + y_j``, the point before projection."""
    if p.lo[j] == p.hi[j]:
        return FIXED
    if v < p.lo[j]:
        return LOWER
    if v > p.hi[j]:
        return UPPER
    return FREE


cdef inline char cone_code(const Cones* c, Py_ssize_t k, const double* v) noexcept nogil:
    """The guess for cone block ``k`` from ``v = z_J + y_J``: FREE inside the cone, APEX
    in its polar, BOUNDARY otherwise (where the plane exists)."""
    cdef int region = cone_region(v, c.kind[k], c.dim[k], c.mu[k], c.normal + 3 * k)
    if region == INSIDE:
        return FREE
    if region == POLAR:
        return APEX
    return BOUNDARY


cdef void linearize(Polish* w, const Problem* p, Py_ssize_t k, const double* v) noexcept nogil
cdef void linearize_on_cone(Polish* w, const Problem* p, Py_ssize_t k,
                           const double* x) noexcept nogil
cdef Py_ssize_t guess(Polish* w, const Problem* p, const double* z, const double* y,
                      Py_ssize_t* changed) noexcept nogil
cdef void keep_bare_plane(Polish* w, const Problem* p, Py_ssize_t k) noexcept nogil
cdef Py_ssize_t wrong_signed(Polish* w, const Problem* p) noexcept nogil
cdef Py_ssize_t most_wrong(Polish* w, const Problem* p, double slack) noexcept nogil
cdef double step_length(Polish* w, const Problem* p, Py_ssize_t* blocking) noexcept nogil
cdef Py_ssize_t renew(Polish* w, const Problem* p, bint adding, bint stepped,
                      const double* ahead, Py_ssize_t* changed) noexcept nogil
cdef bint leaves_set(const Polish* w, const Problem* p) noexcept nogil
cdef Py_ssize_t boundary_entries(const Polish* w, const Problem* p, Py_ssize_t nb) noexcept nogil
cdef bint past_apex(const Polish* w, const Problem* p, Py_ssize_t nb) noexcept nogil
cdef Py_ssize_t drop_far_side(Polish* w, const Problem* p, Py_ssize_t nb,
                              Py_ssize_t* changed) noexcept nogil
cdef double multiplier_violation(Polish* w, const Problem* p, const double* z) noexcept nogil
