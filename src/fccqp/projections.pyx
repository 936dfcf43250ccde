# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Euclidean projections onto the constraint set C = box x cones.

The set is a box on every constrained entry times cones on disjoint blocks (see
:mod:`fccqp.cones`). Cone entries carry infinite box bounds, so one kernel clips the
whole vector and then projects each cone block.

One module per cone kind holds its geometry (:mod:`fccqp.cone_dispatch` lists them and
switches on the kind code): ``proj_block`` (inline, in projections.pxd) projects one
block through it.

The polar of a closed convex cone ``K`` is ``K° = -K*``; by Moreau's decomposition
``v = P_K(v) + P_K°(v)``, so a distance to ``K°`` is the norm of ``P_K(v)`` and a
projection onto ``K°`` is ``v - P_K(v)``: the same kernel serves both. The dual of the
friction cone with coefficient ``mu`` is the friction cone with coefficient ``1/mu``
about the same normal; second-order cones are self-dual.

The ``def`` functions at the end wrap the kernels for tests and for Python callers.
"""

import numpy as np

cimport fccqp.cone_friction as friction
cimport fccqp.cone_soc as soc
from fccqp._types cimport Cones
from fccqp.cone_dispatch cimport cone_fits, cone_plane, cone_split, cone_touch


cdef void proj_set(const double* v, const double* lo, const double* hi, Cones cones,
                   Py_ssize_t s, double* out) noexcept nogil:
    """Project ``v`` (``s`` entries) onto the box ``[lo, hi]`` times the cones into ``out``,
    which may be ``v``."""
    cdef Py_ssize_t i
    cdef double value
    for i in range(s):
        value = v[i]
        if value < lo[i]:
            value = lo[i]
        if value > hi[i]:
            value = hi[i]
        out[i] = value
    _cone_blocks(v, cones, out)


cdef inline void _cone_blocks(const double* v, Cones cones, double* out) noexcept nogil:
    """Project each cone block of ``v`` onto its cone into ``out`` (which may be ``v``)."""
    cdef Py_ssize_t k, o
    for k in range(cones.count):
        o = cones.offset[k]
        proj_block(v + o, cones.kind[k], cones.dim[k], cones.mu[k], cones.normal + 3 * k,
                   out + o)


cdef void proj_cones(double* v, Cones cones) noexcept nogil:
    """Project each cone block of ``v`` onto its cone in place, the box entries left: the
    second half of :func:`proj_set`, where its caller clipped the box already (the
    reduced step's fused z-update, :func:`fccqp.reduced.reduced_step`)."""
    _cone_blocks(v, cones, v)


def project_friction_cone(v, double mu, normal, double[::1] out):
    """Project the 3-vector ``v`` onto the friction cone (``mu``, unit ``normal``) into
    ``out``."""
    cdef const double[::1] v_ = np.ascontiguousarray(v, dtype=np.float64)
    cdef const double[::1] normal_ = np.ascontiguousarray(normal, dtype=np.float64)
    if v_.shape[0] != 3 or normal_.shape[0] != 3 or out.shape[0] != 3:
        raise ValueError("v, normal and out must have 3 entries")
    friction.project(&v_[0], 3, mu, &normal_[0], &out[0])


def project_second_order_cone(const double[::1] v, double[::1] out):
    """Projection of ``v`` onto the second-order cone, into ``out``."""
    if v.shape[0] < 2 or out.shape[0] != v.shape[0]:
        raise ValueError("v needs at least 2 entries and out as many")
    soc.project(&v[0], v.shape[0], 0.0, NULL, &out[0])


def project_constraint_set(const double[::1] v, const double[::1] lo, const double[::1] hi, cones,
                           double[::1] out):
    """Project ``v`` onto ``[lo, hi]`` times the cones into ``out`` (may be ``v``).

    ``cones`` is the tuple ``(kind, offset, dim, mu, normal)`` of
    :class:`fccqp.cones.ConeArrays`, offsets indexing ``v``.
    """
    cdef const Py_ssize_t[::1] kind, offset, dim
    cdef const double[::1] mu
    cdef const double[:, ::1] normal
    kind, offset, dim, mu, normal = cones
    cdef Py_ssize_t s = v.shape[0]
    if lo.shape[0] != s or hi.shape[0] != s or out.shape[0] != s:
        raise ValueError("v, lo, hi and out must have the same size")
    cdef Py_ssize_t k
    for k in range(kind.shape[0]):
        if offset[k] < 0 or offset[k] + dim[k] > s:
            raise ValueError(f"cone {k} leaves the vector")
    if s == 0:
        return
    cdef Cones c
    c.count = kind.shape[0]
    if c.count:
        c.kind, c.offset, c.dim = &kind[0], &offset[0], &dim[0]
        c.mu, c.normal = &mu[0], &normal[0, 0]
    proj_set(&v[0], &lo[0], &hi[0], c, s, &out[0])


def project_cone_block(const double[::1] v, Py_ssize_t kind, double mu, const double[::1] normal,
                       double[::1] out):
    """Project one cone block (kind code of :mod:`fccqp.cones`) into ``out``."""
    if out.shape[0] != v.shape[0] or v.shape[0] < 2 or normal.shape[0] != 3:
        raise ValueError("v and out need the same size (>= 2) and normal 3 entries")
    if not cone_fits(kind, v.shape[0]):
        raise ValueError(f"a cone block of kind {kind} cannot have {v.shape[0]} entries")
    proj_block(&v[0], kind, v.shape[0], mu, &normal[0], &out[0])


def touching_point(const double[::1] v, Py_ssize_t kind, double mu, const double[::1] normal,
                   double[::1] out):
    """Into ``out``: the point with ``v``'s axis part where the tangent plane of the cone
    at ``v`` (through the apex, :func:`fccqp.cone_dispatch.cone_plane`) touches the cone
    (:func:`fccqp.cone_dispatch.cone_touch`); False, ``out`` untouched, where ``v`` is on
    the axis."""
    cdef double across, phi
    cdef double along
    cdef double[::1] g = np.empty(v.shape[0])
    if out.shape[0] != v.shape[0] or v.shape[0] < 2 or normal.shape[0] != 3:
        raise ValueError("v and out need the same size (>= 2) and normal 3 entries")
    if not cone_fits(kind, v.shape[0]):
        raise ValueError(f"a cone block of kind {kind} cannot have {v.shape[0]} entries")
    if not cone_plane(&v[0], kind, v.shape[0], mu, &normal[0], &g[0], &phi):
        return False
    along = cone_split(&v[0], kind, v.shape[0], mu, &normal[0], &across)
    return cone_touch(&g[0], kind, v.shape[0], mu, &normal[0], along, &out[0])
