# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Euclidean projections onto the constraint set C = box x cones.

The set is a box on every constrained entry times cones on disjoint blocks (see
:mod:`fccqp.cones`). Cone entries carry infinite box bounds, so one kernel clips the
whole vector and then projects each cone block.

The polar of a closed convex cone ``K`` is ``K° = -K*``; by Moreau's decomposition
``v = P_K(v) + P_K°(v)``, so a distance to ``K°`` is the norm of ``P_K(v)`` and a
projection onto ``K°`` is ``v - P_K(v)``: the same kernel serves both. The dual of the
friction cone with coefficient ``mu`` is the friction cone with coefficient ``1/mu``
about the same normal; second-order cones are self-dual.

The ``def`` functions at the end wrap the kernels for tests and for Python callers.
"""

import numpy as np

from libc.math cimport sqrt

from fccqp._types cimport FRICTION, Cones


cdef void proj_friction(const double* v, double mu, const double* normal,
                                double* out) noexcept nogil:
    """Project the 3-vector ``v`` onto ``{f : ||f - (n'f)n|| <= mu n'f}`` into ``out``.

    With ``f_n = n'v`` and tangential part ``t = v - f_n n`` of norm ``a``: inside the
    cone (``a <= mu f_n``) ``v`` is kept; inside the polar (``mu a <= -f_n``) the answer
    is 0; otherwise ``v`` lands on the ray through ``(mu t/a, 1)``: normal part
    ``(mu a + f_n)/(1 + mu^2)`` and tangential part ``mu`` times that. For ``mu > 1``
    the formula is rewritten in ``1/mu`` so that huge coefficients neither overflow nor
    lose the tangential part. ``f_n == 0`` with ``t != 0`` falls in the third case,
    which the original C++ got wrong. ``out`` may be ``v``.
    """
    cdef double fn = normal[0] * v[0] + normal[1] * v[1] + normal[2] * v[2]
    cdef double t0 = v[0] - fn * normal[0]
    cdef double t1 = v[1] - fn * normal[1]
    cdef double t2 = v[2] - fn * normal[2]
    cdef double a = sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    cdef double normal_part, tangential_part, inv, scale
    if a <= mu * fn:
        out[0] = v[0]
        out[1] = v[1]
        out[2] = v[2]
    elif mu * a <= -fn:
        out[0] = 0.0
        out[1] = 0.0
        out[2] = 0.0
    else:
        if mu <= 1.0:
            normal_part = (mu * a + fn) / (1.0 + mu * mu)
            tangential_part = mu * normal_part
        else:
            inv = 1.0 / mu
            tangential_part = (a + fn * inv) / (1.0 + inv * inv)
            normal_part = tangential_part * inv
        scale = tangential_part / a
        out[0] = normal_part * normal[0] + scale * t0
        out[1] = normal_part * normal[1] + scale * t1
        out[2] = normal_part * normal[2] + scale * t2


cdef void proj_soc(const double* v, Py_ssize_t dim,
                                    double* out) noexcept nogil:
    """Project ``v = (t, w)`` onto ``{(t, w) : ||w|| <= t}`` into ``out`` (may be ``v``)."""
    cdef double t = v[0]
    cdef double norm_w = 0.0
    cdef double half, scale
    cdef Py_ssize_t i
    for i in range(1, dim):
        norm_w += v[i] * v[i]
    norm_w = sqrt(norm_w)
    if norm_w <= t:
        for i in range(dim):
            out[i] = v[i]
    elif norm_w <= -t:
        for i in range(dim):
            out[i] = 0.0
    else:
        half = 0.5 * (t + norm_w)
        scale = half / norm_w
        out[0] = half
        for i in range(1, dim):
            out[i] = scale * v[i]


cdef void proj_block(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                        const double* normal, double* out) noexcept nogil:
    """Project one cone block, dispatching on its kind code."""
    if kind == FRICTION:
        proj_friction(v, mu, normal, out)
    else:
        proj_soc(v, dim, out)


cdef void proj_set(const double* v, const double* lo, const double* hi, Cones cones,
                      Py_ssize_t s, double* out) noexcept nogil:
    """Project ``v`` (``s`` entries) onto the box ``[lo, hi]`` times the cones into ``out``,
    which may be ``v``."""
    cdef Py_ssize_t i, k, o
    cdef double value
    for i in range(s):
        value = v[i]
        if value < lo[i]:
            value = lo[i]
        if value > hi[i]:
            value = hi[i]
        out[i] = value
    for k in range(cones.count):
        o = cones.offset[k]
        proj_block(v + o, cones.kind[k], cones.dim[k], cones.mu[k], cones.normal + 3 * k,
                      out + o)


def project_friction_cone(v, double mu, normal, double[::1] out):
    """Project the 3-vector ``v`` onto the friction cone (``mu``, unit ``normal``) into
    ``out``."""
    cdef const double[::1] v_ = np.ascontiguousarray(v, dtype=np.float64)
    cdef const double[::1] normal_ = np.ascontiguousarray(normal, dtype=np.float64)
    if v_.shape[0] != 3 or normal_.shape[0] != 3 or out.shape[0] != 3:
        raise ValueError("v, normal and out must have 3 entries")
    proj_friction(&v_[0], mu, &normal_[0], &out[0])


def project_second_order_cone(const double[::1] v, double[::1] out):
    """Projection of ``v`` onto the second-order cone, into ``out``."""
    if v.shape[0] < 2 or out.shape[0] != v.shape[0]:
        raise ValueError("v needs at least 2 entries and out as many")
    proj_soc(&v[0], v.shape[0], &out[0])


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
    if kind == FRICTION and v.shape[0] != 3:
        raise ValueError("a friction cone block has 3 entries")
    proj_block(&v[0], kind, v.shape[0], mu, &normal[0], &out[0])
