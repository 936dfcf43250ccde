# cython: language_level=3
"""The friction cone ``{f in R^3 : ||f - (n'f) n|| <= mu n'f}`` about the unit normal ``n``.

One cone kind of the compiled core (see :mod:`fccqp.cone_dispatch` for the contract and
the registry). Every operation acts on one block ``v`` of ``dim`` (here always 3)
entries with the block's ``mu`` and ``normal`` (3 entries); ``dim`` is taken so that
all kinds share one signature. Inline: the C compiler copies them into their callers,
as it did when they were static functions of one module; a call through a module's
function table per block per iteration would cost.

Axis geometry: the part of ``v`` along the axis is ``n'v`` and the rest is the
tangential part ``t = v - (n'v) n``; the cone reads ``||t|| <= slope n'v`` with slope
``mu``. Its cone function ``phi(f) = ||t|| - mu n'f`` is positively homogeneous.
"""

from libc.math cimport sqrt


cdef inline bint fits(Py_ssize_t dim) noexcept nogil:
    """Whether a block of ``dim`` entries can be a friction cone."""
    return dim == 3


cdef inline double slope(double mu) noexcept nogil:
    """The cone's slope: it reads ``across <= slope * along``."""
    return mu


cdef inline double split(const double* v, Py_ssize_t dim, double mu, const double* normal,
                         double* across) noexcept nogil:
    """The part of ``v`` along the normal (returned) and the norm of its tangential part
    (``across``)."""
    cdef double along, t, total = 0.0
    cdef Py_ssize_t i
    along = normal[0] * v[0] + normal[1] * v[1] + normal[2] * v[2]
    for i in range(3):
        t = v[i] - along * normal[i]
        total += t * t
    across[0] = sqrt(total)
    return along


cdef inline void project(const double* v, Py_ssize_t dim, double mu, const double* normal,
                         double* out) noexcept nogil:
    """Project the 3-vector ``v`` onto the cone into ``out`` (may be ``v``).

    With ``f_n = n'v`` and tangential part ``t = v - f_n n`` of norm ``a``: inside the
    cone (``a <= mu f_n``) ``v`` is kept; inside the polar (``mu a <= -f_n``) the answer
    is 0; otherwise ``v`` lands on the ray through ``(mu t/a, 1)``: normal part
    ``(mu a + f_n)/(1 + mu^2)`` and tangential part ``mu`` times that. For ``mu > 1``
    the formula is rewritten in ``1/mu`` so that huge coefficients neither overflow nor
    lose the tangential part. ``f_n == 0`` with ``t != 0`` falls in the third case,
    which the original C++ got wrong.
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


cdef inline bint plane(const double* v, Py_ssize_t dim, double mu, const double* normal,
                       double* g, double* phi) noexcept nogil:
    """Unit gradient ``g`` of the cone function at ``v``, ``(t/||t|| - mu n) / sqrt(1 +
    mu^2)``, and its value ``phi``; False (``g`` untouched) on the axis (``t = 0``),
    where the gradient does not exist."""
    cdef double across, slope_ = mu
    cdef double along = split(v, dim, mu, normal, &across)
    cdef double unit = 1.0 / sqrt(1.0 + slope_ * slope_)
    cdef Py_ssize_t i
    phi[0] = across - slope_ * along
    if not across > 0.0:
        return False
    for i in range(3):
        g[i] = ((v[i] - along * normal[i]) / across - slope_ * normal[i]) * unit
    return True


cdef inline bint touch(const double* g, Py_ssize_t dim, double mu, const double* normal,
                       double along, double* out) noexcept nogil:
    """The point with normal part ``along`` of the ray where the plane through the apex
    with unit normal ``g`` (:func:`plane`'s) touches the cone, ``along (n + mu e)`` with
    ``e`` the unit tangential part of ``g``; False (``out`` untouched) where ``g`` has
    none."""
    cdef double across
    cdef double g_along = split(g, dim, mu, normal, &across)
    cdef Py_ssize_t i
    if not across > 0.0:
        return False
    for i in range(3):
        out[i] = along * (normal[i] + mu * (g[i] - g_along * normal[i]) / across)
    return True


cdef inline void curvature(const double* v, Py_ssize_t dim, double mu, const double* normal,
                           double weight, double* H) noexcept nogil:
    """``H`` (3 x 3, symmetric) = ``weight`` times the Hessian of the cone function at
    ``v``, ``(I - nn' - ee') / ||t||`` with ``e = t / ||t||``, divided by ``sqrt(1 +
    mu^2)`` (the normalization of :func:`plane`); 0 on the axis."""
    cdef double across, along = split(v, dim, mu, normal, &across)
    cdef double slope_ = mu, scale, ea, eb
    cdef Py_ssize_t a, b
    for a in range(dim * dim):
        H[a] = 0.0
    if not across > 0.0:
        return
    scale = weight / (sqrt(1.0 + slope_ * slope_) * across)
    for a in range(3):
        ea = (v[a] - along * normal[a]) / across
        for b in range(3):
            eb = (v[b] - along * normal[b]) / across
            H[a * 3 + b] = scale * ((1.0 if a == b else 0.0) - normal[a] * normal[b]
                                    - ea * eb)
