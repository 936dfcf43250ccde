# cython: language_level=3
"""The registry of cone kinds in the compiled core, and the operations on one cone block.

A cone kind is a module ``fccqp/cone_<kind>.pxd`` of ``cdef inline ... noexcept nogil``
functions with one signature for every kind, acting on one block ``v`` of ``dim``
entries with the block's parameters ``mu`` and ``normal`` (the fields of
:c:type:`Cones`; a kind ignores those it does not use):

- ``fits(dim)``: whether a block of ``dim`` entries can be of this kind;
- ``project(v, dim, mu, normal, out)``: the Euclidean projection onto the cone;
- ``split(v, dim, mu, normal, &across)``: the axis geometry, the part of ``v`` along
  the cone's axis (returned) and the norm of the rest, so that the cone reads
  ``across <= slope * along``: its apex is the origin and ``along <= 0`` is the far side
  of it;
- ``slope(mu)``: that slope;
- ``plane(v, dim, mu, normal, g, &phi)``: the tangent plane at ``v``, the unit gradient
  ``g`` of the (positively homogeneous) cone function ``phi = across - slope * along``
  and its value; False where the gradient does not exist;
- ``curvature(v, dim, mu, normal, weight, H)``: ``weight`` times the Hessian of ``phi``
  at ``v`` over the normalization of ``g`` (``dim x dim``), for the polish's Newton steps.
- ``touch(g, dim, mu, normal, along, out)``: the point with axis part ``along`` of the
  ray where the plane through the apex with unit normal ``g`` touches the cone (False
  where ``g`` lies on the axis), for a plane that keeps its place while it gains its
  curvature.

This file is the only place in the compiled core that lists the kinds: each ``cone_*``
function below switches on the kind code to the module's operation, and the algorithm
(:mod:`fccqp.projections`, the polish, the certificates through ``proj_block``) calls
these. The rest of the contract follows from those operations and is written once here
or where it is used:

- the active-set region of a point (:func:`cone_region`: in the cone, in its polar, or
  neither), membership to a tolerance (:func:`cone_inside`), the step to the boundary
  along a segment (:func:`cone_step`) and the distance to the polar cone
  (:func:`cone_polar_distance`), from ``split``, ``slope`` and ``project``;
- the projection onto the polar cone ``K° = -K*`` is ``v - P_K(v)`` (Moreau), which
  the certificates take; the dual of the friction cone with coefficient ``mu`` is the
  friction cone with ``1/mu`` about the same normal, second-order cones are self-dual;
- the support function of a cone is 0 on its polar and infinite elsewhere, so the
  duality gap and the certificates count no cone term once a multiplier lies in the
  polar (:mod:`fccqp.termination`, :mod:`fccqp.certificates`);
- a cone is its own recession cone: the dual certificate tests ``dx_block`` against
  ``project``.

Adding a kind: its module ``cone_<kind>.pxd`` with the seven operations, its code in the
enum below and a branch in each ``cone_*`` switch; on the Python side its spec in
:mod:`fccqp.cones` (the registry ``KINDS`` there, with the same code).
"""

from libc.math cimport sqrt

cimport fccqp.cone_friction as friction
cimport fccqp.cone_soc as soc


cdef enum:
    # Kind codes of Cones.kind; the same numbers as fccqp.cones.KINDS.
    FRICTION = 0        # fccqp.cone_friction
    SECOND_ORDER = 1    # fccqp.cone_soc


cdef enum:
    # Regions of a point for the active set (cone_region).
    INSIDE = 0      # in the cone
    POLAR = 1       # in the polar cone (and not in the cone)
    BETWEEN = 2     # in neither: its projection lies on the boundary, away from the apex


cdef inline bint cone_fits(Py_ssize_t kind, Py_ssize_t dim) noexcept nogil:
    """Whether ``kind`` is a known code and a block of ``dim`` entries can be of it."""
    if kind == FRICTION:
        return friction.fits(dim)
    if kind == SECOND_ORDER:
        return soc.fits(dim)
    return False


cdef inline void cone_project(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                              const double* normal, double* out) noexcept nogil:
    """Project the block ``v`` onto its cone into ``out`` (may be ``v``)."""
    if kind == FRICTION:
        friction.project(v, dim, mu, normal, out)
    else:
        soc.project(v, dim, mu, normal, out)


cdef inline double cone_slope(Py_ssize_t kind, double mu) noexcept nogil:
    """The cone's slope: it reads ``across <= slope * along`` (:func:`cone_split`)."""
    if kind == FRICTION:
        return friction.slope(mu)
    return soc.slope(mu)


cdef inline double cone_split(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                              const double* normal, double* across) noexcept nogil:
    """The part of ``v`` along the cone's axis (returned) and the norm of the rest
    (``across``)."""
    if kind == FRICTION:
        return friction.split(v, dim, mu, normal, across)
    return soc.split(v, dim, mu, normal, across)


cdef inline bint cone_plane(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                            const double* normal, double* g, double* phi) noexcept nogil:
    """Unit gradient ``g`` of the cone function at ``v`` and its value ``phi``; False
    (``g`` untouched) where the gradient does not exist (``v`` on the axis)."""
    if kind == FRICTION:
        return friction.plane(v, dim, mu, normal, g, phi)
    return soc.plane(v, dim, mu, normal, g, phi)


cdef inline void cone_curvature(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                                const double* normal, double weight,
                                double* H) noexcept nogil:
    """``H`` (``dim x dim``, symmetric) = ``weight`` times the Hessian of the cone
    function at ``v`` divided by the normalization of its gradient; 0 on the axis."""
    if kind == FRICTION:
        friction.curvature(v, dim, mu, normal, weight, H)
    else:
        soc.curvature(v, dim, mu, normal, weight, H)


cdef inline bint cone_touch(const double* g, Py_ssize_t kind, Py_ssize_t dim, double mu,
                            const double* normal, double along, double* out) noexcept nogil:
    """The point with axis part ``along`` where the plane through the apex with unit
    normal ``g`` touches the cone; False (``out`` untouched) where ``g`` is on the axis."""
    if kind == FRICTION:
        return friction.touch(g, dim, mu, normal, along, out)
    return soc.touch(g, dim, mu, normal, along, out)


cdef inline double cone_phi(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                            const double* normal) noexcept nogil:
    """The cone function ``across - slope * along`` at ``v``: <= 0 in the cone, 0 on its
    boundary, positively homogeneous."""
    cdef double across
    cdef double along = cone_split(v, kind, dim, mu, normal, &across)
    return across - cone_slope(kind, mu) * along


cdef inline int cone_region(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                            const double* normal) noexcept nogil:
    """``INSIDE`` the cone, in its ``POLAR`` (the projection is the apex) or
    ``BETWEEN`` (the projection is on the boundary, where the plane exists)."""
    cdef double across, slope = cone_slope(kind, mu)
    cdef double along = cone_split(v, kind, dim, mu, normal, &across)
    if across <= slope * along:
        return INSIDE
    if slope * across <= -along:
        return POLAR
    return BETWEEN


cdef inline bint cone_inside(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                             const double* normal, double tolerance) noexcept nogil:
    """Whether ``v`` lies in its cone to ``tolerance ||v||`` (``phi <= tolerance ||v||``)."""
    cdef double across, size = 0.0
    cdef Py_ssize_t j
    cdef double along = cone_split(v, kind, dim, mu, normal, &across)
    for j in range(dim):
        size += v[j] * v[j]
    return across - cone_slope(kind, mu) * along <= tolerance * sqrt(size)


cdef inline double cone_step(const double* x0, const double* x1, Py_ssize_t kind,
                             Py_ssize_t dim, double mu, const double* normal, double tolerance,
                             double* point) noexcept nogil:
    """The largest ``t`` in ``[0, 1]`` with ``x0 + t (x1 - x0)`` in the cone (to
    ``tolerance``, :func:`cone_inside`), to ``2^-40`` by bisection (``point``: ``dim``
    scratch): 1 when ``x1`` is inside (the cone is convex), 0 when ``x0`` is not."""
    cdef double low = 0.0, high = 1.0, middle
    cdef Py_ssize_t halving, j
    if cone_inside(x1, kind, dim, mu, normal, tolerance):
        return 1.0
    if not cone_inside(x0, kind, dim, mu, normal, tolerance):
        return 0.0
    for halving in range(40):
        middle = 0.5 * (low + high)
        for j in range(dim):
            point[j] = x0[j] + middle * (x1[j] - x0[j])
        if cone_inside(point, kind, dim, mu, normal, tolerance):
            low = middle
        else:
            high = middle
    return low


cdef inline double cone_polar_distance(const double* v, Py_ssize_t kind, Py_ssize_t dim,
                                       double mu, const double* normal,
                                       double* scratch) noexcept nogil:
    """The distance of ``v`` to the polar cone, ``||P_K(v)||`` (Moreau; ``scratch``:
    ``dim`` entries, left holding ``P_K(v)``)."""
    cdef double total = 0.0
    cdef Py_ssize_t j
    cone_project(v, kind, dim, mu, normal, scratch)
    for j in range(dim):
        total += scratch[j] * scratch[j]
    return sqrt(total)
