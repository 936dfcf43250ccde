# cython: language_level=3
"""The second-order (Lorentz) cone ``{(t, w) : ||w|| <= t}`` of any dimension ``>= 2``.

One cone kind of the compiled core (see :mod:`fccqp.cone_dispatch` for the contract and
the registry). Every operation acts on one block ``v = (t, w)`` of ``dim`` entries;
``mu`` and ``normal`` are unused, taken so that all kinds share one signature. Inline,
as :mod:`fccqp.cone_friction` explains.

Axis geometry: the part along the axis is ``t = v[0]`` and the rest is ``w``; the cone
reads ``||w|| <= slope t`` with slope 1. Its cone function ``phi(t, w) = ||w|| - t`` is
positively homogeneous.
"""

from libc.math cimport sqrt


cdef inline bint fits(Py_ssize_t dim) noexcept nogil:
    """Whether a block of ``dim`` entries can be a second-order cone."""
    return dim >= 2


cdef inline double slope(double mu) noexcept nogil:
    """The cone's slope: it reads ``across <= slope * along``."""
    return 1.0


cdef inline double split(const double* v, Py_ssize_t dim, double mu, const double* normal,
                         double* across) noexcept nogil:
    """``t = v[0]`` (returned) and ``||w||`` (``across``)."""
    cdef double along, total = 0.0
    cdef Py_ssize_t i
    along = v[0]
    for i in range(1, dim):
        total += v[i] * v[i]
    across[0] = sqrt(total)
    return along


cdef inline void project(const double* v, Py_ssize_t dim, double mu, const double* normal,
                         double* out) noexcept nogil:
    """Project ``v = (t, w)`` onto the cone into ``out`` (may be ``v``)."""
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


cdef inline bint plane(const double* v, Py_ssize_t dim, double mu, const double* normal,
                       double* g, double* phi) noexcept nogil:
    """Unit gradient ``g = (-1, w/||w||) / sqrt(2)`` of the cone function at ``v`` and
    its value ``phi``; False (``g`` untouched) on the axis (``w = 0``), where the
    gradient does not exist."""
    cdef double across, slope_ = 1.0
    cdef double along = split(v, dim, mu, normal, &across)
    cdef double unit = 1.0 / sqrt(1.0 + slope_ * slope_)
    cdef Py_ssize_t i
    phi[0] = across - slope_ * along
    if not across > 0.0:
        return False
    g[0] = -unit
    for i in range(1, dim):
        g[i] = v[i] / across * unit
    return True


cdef inline bint touch(const double* g, Py_ssize_t dim, double mu, const double* normal,
                       double along, double* out) noexcept nogil:
    """The point with ``t = along`` of the ray where the plane through the apex with unit
    normal ``g`` (:func:`plane`'s) touches the cone, ``along (1, e)`` with ``e`` the unit
    direction of ``g``'s ``w`` part; False (``out`` untouched) where that part is 0."""
    cdef double across
    cdef Py_ssize_t i
    split(g, dim, mu, normal, &across)
    if not across > 0.0:
        return False
    out[0] = along
    for i in range(1, dim):
        out[i] = along * g[i] / across
    return True


cdef inline void curvature(const double* v, Py_ssize_t dim, double mu, const double* normal,
                           double weight, double* H) noexcept nogil:
    """``H`` (``dim x dim``, symmetric) = ``weight`` times the Hessian of the cone
    function at ``v``, ``(I - ee') / ||w||`` on ``w`` with ``e = w / ||w||``, divided by
    ``sqrt(2)`` (the normalization of :func:`plane`); 0 on the axis."""
    cdef double across, along = split(v, dim, mu, normal, &across)
    cdef double slope_ = 1.0, scale
    cdef Py_ssize_t a, b
    for a in range(dim * dim):
        H[a] = 0.0
    if not across > 0.0:
        return
    scale = weight / (sqrt(1.0 + slope_ * slope_) * across)
    for a in range(1, dim):
        for b in range(1, dim):
            H[a * dim + b] = scale * ((1.0 if a == b else 0.0)
                                      - v[a] * v[b] / (across * across))
