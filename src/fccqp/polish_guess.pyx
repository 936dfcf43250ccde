# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The polish's active set: its first guess from ADMM's iterate and its corrections.

:mod:`fccqp.polish` solves the QP on a guessed active set; this module makes the guess
and corrects it from each polished point (the rules and why they are so are in
:func:`fccqp.polish.polish`'s docstring). One code per constrained entry
(:c:type:`Polish`'s ``active``): a box entry is free or held at a bound, a cone block is
free, at its apex or on its boundary, where it contributes its tangent plane and the
curvature term of Newton's step (:func:`linearize`); the acceptance asks
:func:`multiplier_violation` whether the polished point's multipliers fit its final
guess. The cone geometry comes from
:mod:`fccqp.cone_dispatch` (projection, axis and slope, tangent plane, curvature, step
to the boundary): nothing here names a cone kind.
"""

from libc.math cimport fabs, sqrt

from fccqp._dense cimport copy
from fccqp._types cimport Cones, Problem
from fccqp.cone_dispatch cimport (cone_curvature, cone_inside, cone_plane, cone_polar_distance,
                                  cone_project, cone_slope, cone_split, cone_step, cone_touch)
from fccqp.polish cimport APEX, BARE, BOUNDARY, FREE, KEPT, LOWER, UPPER, Polish
from fccqp.tuning cimport ACTIVE_TOLERANCE


cdef void linearize(Polish* w, const Problem* p, Py_ssize_t k, const double* v) noexcept nogil:
    """Plane ``g`` and curvature ``hess`` of boundary block ``k`` (of ``boundary``) at
    ``v``, with its current multiplier where that is positive; a block whose ``v`` is on
    the axis keeps its plane and gets no curvature. Without a positive multiplier the
    block is marked ``BARE`` (see :func:`renew`).

    A negative multiplier marks a wrong guess, which the next correction releases; its
    curvature would only make the block's Hessian indefinite, and the Schur complement
    (:mod:`fccqp.polish_schur`) then no longer applies (every pass after the first of
    go2's cold polishes, whose planes start with ``lam = 0``, had fallen to ``dsytrf``).
    """
    _place(w, p, k, v, 1.0)


cdef void linearize_on_cone(Polish* w, const Problem* p, Py_ssize_t k,
                            const double* x) noexcept nogil:
    """:func:`linearize` at ``x`` (block ``k``'s entries), its curvature that of the cone
    at ``x``'s axis part: the cone function's Hessian is ``1 / across`` times a
    projector that depends on the direction of ``x``'s part across the axis only, so it
    is scaled by ``across / (slope along)``, the point of the cone in that direction
    (unscaled where ``x`` is not outside the cone).

    A point of Newton's iterate lies on the last plane, outside the cone, its part
    across the axis longer than the cone's radius at its axis part; the curvature there
    is that much flatter than the constraint's, and where ``P`` is flat on the forces and
    ``lam`` small the next step swung that part round the axis (go2: a contact at a
    normal force of 0.006 circled for 20 steps, its relative miss 0.45-1.0). At the
    answer both points coincide, so Newton's quadratic convergence is kept
    (notes/polish.md, "newtonrate")."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t cone = w.boundary[k]
    cdef double across, radius
    cdef double along = cone_split(x, c.kind[cone], c.dim[cone], c.mu[cone],
                                   c.normal + 3 * cone, &across)
    radius = cone_slope(c.kind[cone], c.mu[cone]) * along
    _place(w, p, k, x, across / radius if radius > 0.0 and across > radius else 1.0)


cdef inline void _place(Polish* w, const Problem* p, Py_ssize_t k, const double* v,
                        double stiffen) noexcept nogil:
    """:func:`linearize`, its curvature times ``stiffen``."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t cone = w.boundary[k], o = c.offset[cone], d = c.dim[cone]
    cdef double phi
    cone_plane(v, c.kind[cone], d, c.mu[cone], c.normal + 3 * cone, w.g + o, &phi)
    cone_curvature(v, c.kind[cone], d, c.mu[cone], c.normal + 3 * cone,
                   stiffen * max(w.lam[k], 0.0), w.hess + o * w.hess_stride)
    if not w.lam[k] > 0.0:
        w.bare[cone] = BARE


cdef void keep_bare_plane(Polish* w, const Problem* p, Py_ssize_t k) noexcept nogil:
    """Put boundary block ``k``'s ``KEPT`` plane back and give it its curvature there, at
    the point of the plane's own touching ray with ``x_block``'s axis part (``x_block``
    itself where that part is not positive or the plane lies on the axis).

    A plane placed with ``lam = 0`` (a free block that left its cone) is solved without
    its curvature, and nothing held the block's tangential part on the cone: moving the
    plane to that ``x_block`` had turned it 20-50 degrees away from the answer's, and the
    next solve put the contact past its apex; the polish then cycled between apex and
    boundary and the tick ran ADMM (notes/performance-history.md, "warmtail2")."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t cone = w.boundary[k], o = c.offset[cone]
    copy(w.kept_plane + o, w.g + o, c.dim[cone])
    _own_point(w, c, cone, w.x + p.constrained[o], w.step)
    linearize(w, p, k, w.step)


cdef inline void _own_point(const Polish* w, const Cones* c, Py_ssize_t k, const double* x,
                            double* out) noexcept nogil:
    """Into ``out``: the point of cone ``k``'s current plane's touching ray with the axis
    part of ``x`` (its block); ``x`` itself where that part is not positive or the plane
    lies on the axis."""
    cdef Py_ssize_t o = c.offset[k], d = c.dim[k]
    cdef double across
    cdef double along = cone_split(x, c.kind[k], d, c.mu[k], c.normal + 3 * k, &across)
    if not (along > 0.0 and cone_touch(w.g + o, c.kind[k], d, c.mu[k], c.normal + 3 * k,
                                       along, out)):
        copy(x, out, d)


cdef Py_ssize_t guess(Polish* w, const Problem* p, const double* z, const double* y,
                      Py_ssize_t* changed) noexcept nogil:
    """Fill ``active`` from the slack ``z`` and multiplier ``y``, the list ``boundary``
    and each boundary block's multiplier ``lam`` (the component of ``y`` along the
    plane's normal), plane and curvature at the projection of ``z + y`` onto the cone;
    return the number of boundary blocks and count in ``changed`` the constrained
    entries whose code changed.

    A polish from no multipliers (``bare_start``: ``y`` is zero, ``z`` the carried
    point's projection onto ``C``) starts a block free where ``z`` lies in its cone to
    ``ACTIVE_TOLERANCE``: a foot on its cone in the previous answer is there to the
    rounding of that answer, one ulp outside or inside by the BLAS kernels' order of
    sums, and started on its plane or not accordingly (solo12's contact_switch tick
    320: 13 factorizations with SkylakeX's ``dgemv``, 5 with Haswell's; 5 with either
    now, notes/performance-history.md, "End of session 36")."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, d, nb = 0
    cdef double phi, lam
    cdef char code
    changed[0] = 0
    for j in range(p.s):
        if not p.in_cone[j]:
            code = box_code(p, j, z[j] + y[j])
            changed[0] += code != w.active[j]
            w.active[j] = code
    for k in range(c.count):
        o, d = c.offset[k], c.dim[k]
        for j in range(o, o + d):
            w.g[j] = z[j] + y[j]
        code = cone_code(c, k, w.g + o)
        if (code == BOUNDARY and w.bare_start
                and cone_inside(w.g + o, c.kind[k], d, c.mu[k], c.normal + 3 * k,
                                ACTIVE_TOLERANCE)):
            code = FREE   # on its cone to rounding: the previous answer's, carried
        if code == BOUNDARY:
            cone_project(w.g + o, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
            cone_plane(w.step, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.g + o, &phi)
            lam = 0.0
            for j in range(o, o + d):
                lam += y[j] * w.g[j]
            w.lam[nb] = lam
            w.boundary[nb] = k
            linearize(w, p, nb, w.step)
            nb += 1
        for j in range(o, o + d):
            changed[0] += code != w.active[j]
            w.active[j] = code
    return nb


cdef inline double _box_wrong(const Polish* w, const Problem* p, Py_ssize_t j) noexcept nogil:
    """How far box entry ``j``'s multiplier is from the normal cone its code needs (0
    when in it), in the user's units."""
    cdef char code = w.active[j]
    cdef double wrong = w.y[j] if code == LOWER else (-w.y[j] if code == UPPER else 0.0)
    return wrong / (p.c * p.D[p.constrained[j]])


cdef inline double _block_wrong(Polish* w, const Problem* p, Py_ssize_t k,
                                Py_ssize_t* plane) noexcept nogil:
    """The same for cone block ``k``: a boundary block's ``-lam`` (``plane`` counts the
    boundary blocks before it, the index of its ``lam``), an apex block's distance of
    ``y_block`` to the polar cone, a free block's 0."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t o = c.offset[k], d = c.dim[k]
    cdef double wrong = 0.0
    if w.active[o] == BOUNDARY:
        wrong = -w.lam[plane[0]]
        plane[0] += 1
    elif w.active[o] == APEX:
        wrong = cone_polar_distance(w.y + o, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
    return wrong / (p.c * p.D[p.constrained[o]])


cdef Py_ssize_t most_wrong(Polish* w, const Problem* p, double slack) noexcept nogil:
    """The held entry (its index ``j < s``) or held block (``s`` plus its cone's index)
    whose multiplier is farthest, in the user's units, from the normal cone its code
    needs; -1 when none is farther than ``slack``. The distance is a box entry's
    wrong-signed ``|y_j|``, a boundary block's ``-lam``, an apex block's distance of
    ``y_block`` to the polar cone (``||P_K(y_block)||``), each divided by ``c D_i`` as
    :func:`fccqp.scaling.unscale` does: what :func:`multiplier_violation` measures on the
    polished point."""
    cdef Py_ssize_t j, k, plane = 0, most = -1
    cdef double worst = slack, wrong
    for j in range(p.s):
        if p.in_cone[j]:
            continue
        wrong = _box_wrong(w, p, j)
        if wrong > worst:
            worst, most = wrong, j
    for k in range(p.cones.count):
        wrong = _block_wrong(w, p, k, &plane)
        if wrong > worst:
            worst, most = wrong, p.s + k
    return most


cdef Py_ssize_t wrong_signed(Polish* w, const Problem* p) noexcept nogil:
    """How many held box entries and held blocks (boundary or apex) have a multiplier
    outside the normal cone their code needs: those :func:`most_wrong` chooses from, one a
    pass."""
    cdef Py_ssize_t j, k, plane = 0, count = 0
    for j in range(p.s):
        if not p.in_cone[j] and _box_wrong(w, p, j) > 0.0:
            count += 1
    for k in range(p.cones.count):
        if _block_wrong(w, p, k, &plane) > 0.0:
            count += 1
    return count


cdef double step_length(Polish* w, const Problem* p, Py_ssize_t* blocking) noexcept nogil:
    """The largest ``t`` in ``[0, 1]`` such that ``x_prev + t (x - x_prev)`` keeps every
    free box entry within its bounds, every free cone block in its cone and every
    boundary block on the near side of its apex; ``blocking`` receives the constraint
    that stops it first (an entry ``j < s``, or ``s`` plus a cone's index), -1 when none
    does and ``t`` is 1. ``blocked`` (by entry, a cone block at its first entry) marks
    the constraints :func:`renew` is to hold after the step: the first one that stops
    it, and at ``t = 0`` every one that does. A step of length 0 does not move, so
    holding its blocking constraints one per pass paid a solve each for the same point:
    on talos' cold ticks, most of the passes of polishes that used all their guesses
    (notes/polish.md, "zerostep")."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, d, i, start
    cdef double t = 1.0, stop, x0, x1, along0, along1, across
    blocking[0] = -1
    for j in range(p.s):
        if p.in_cone[j] or w.active[j] != FREE:
            continue
        i = p.constrained[j]
        x0, x1 = w.x_prev[i], w.x[i]
        stop = 1.0
        if x1 < p.lo[j] and x1 < x0:
            stop = max(0.0, (p.lo[j] - x0) / (x1 - x0))
        elif x1 > p.hi[j] and x1 > x0:
            stop = max(0.0, (p.hi[j] - x0) / (x1 - x0))
        w.blocked[j] = stop == 0.0
        if stop < t:
            t, blocking[0] = stop, j
    for k in range(c.count):
        o, d = c.offset[k], c.dim[k]
        start = p.constrained[o]
        if w.active[o] == FREE:
            stop = cone_step(w.x_prev + start, w.x + start, c.kind[k], d, c.mu[k],
                             c.normal + 3 * k, ACTIVE_TOLERANCE, w.step)
        elif w.active[o] == BOUNDARY:   # its tangent plane also holds the far ray
            along0 = cone_split(w.x_prev + start, c.kind[k], d, c.mu[k], c.normal + 3 * k,
                                &across)
            along1 = cone_split(w.x + start, c.kind[k], d, c.mu[k], c.normal + 3 * k, &across)
            stop = 1.0
            if along1 <= 0.0:
                stop = max(0.0, along0 / (along0 - along1)) if along0 > along1 else 0.0
        else:
            continue
        w.blocked[o] = stop == 0.0
        if stop < t:
            t, blocking[0] = stop, p.s + k
    if t > 0.0 and blocking[0] >= 0:   # no constraint had stop 0: mark the first
        j = blocking[0]
        w.blocked[j if j < p.s else c.offset[j - p.s]] = True
    return t


cdef inline char _bound_passed(const Problem* p, Py_ssize_t j, double value) noexcept nogil:
    """The bound that box entry ``j`` at ``value`` passed by more than ``ACTIVE_TOLERANCE``
    (``LOWER``, ``UPPER``), else ``FREE``."""
    if value < p.lo[j] - ACTIVE_TOLERANCE * max(1.0, fabs(p.lo[j])):
        return LOWER
    if value > p.hi[j] + ACTIVE_TOLERANCE * max(1.0, fabs(p.hi[j])):
        return UPPER
    return FREE


cdef inline bint _left_cone(const Cones* c, Py_ssize_t k, const double* x, double* along,
                            double* across, double* size) noexcept nogil:
    """Whether block ``x`` of cone ``k`` lies outside it by more than ``ACTIVE_TOLERANCE``
    of its norm; ``along``, ``across`` its split (:func:`cone_split`), ``size`` its
    squared norm."""
    cdef Py_ssize_t j
    size[0] = 0.0
    for j in range(c.dim[k]):
        size[0] += x[j] * x[j]
    along[0] = cone_split(x, c.kind[k], c.dim[k], c.mu[k], c.normal + 3 * k, across)
    return (across[0] - cone_slope(c.kind[k], c.mu[k]) * along[0]
            > ACTIVE_TOLERANCE * sqrt(size[0]))


cdef bint leaves_set(const Polish* w, const Problem* p) noexcept nogil:
    """Whether the point ``x`` puts a free box entry past a bound or a free cone block
    outside its cone (as :func:`renew` would hold them), the guess left as it is."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k
    cdef double along, across, size
    for j in range(p.s):
        if (not p.in_cone[j] and w.active[j] == FREE
                and _bound_passed(p, j, w.x[p.constrained[j]]) != FREE):
            return True
    for k in range(c.count):
        if (w.active[c.offset[k]] == FREE
                and _left_cone(c, k, w.x + p.constrained[c.offset[k]], &along, &across, &size)):
            return True
    return False


cdef inline double _off_cone(const double* v, const double* projection,
                             Py_ssize_t d) noexcept nogil:
    """``||v - projection||``: with ``projection`` the projection of ``v`` onto its cone,
    the part of ``v`` in the polar cone, which is ``v``'s component along the unit normal
    of the cone's plane at ``projection`` (Moreau's decomposition)."""
    cdef double total = 0.0
    cdef Py_ssize_t j
    for j in range(d):
        total += (v[j] - projection[j]) * (v[j] - projection[j])
    return sqrt(total)


cdef Py_ssize_t renew(Polish* w, const Problem* p, bint adding, bint stepped,
                      const double* ahead, Py_ssize_t* changed) noexcept nogil:
    """Correct the guess from the polished point. With ``adding``, hold free entries
    that violate their bound and put free blocks that left their cone on the boundary
    (or at the apex, if ``x_block`` lies in the polar), and, after a step (``stepped``),
    hold the constraints :func:`step_length` marked in ``blocked`` where the step left
    them: a box entry at its nearer bound, a free block on the boundary, a boundary
    block at the apex. After a step of length 0 (``ahead``: the full step's point, else
    NULL) a free block it stopped is classified and given its plane from where the full
    step took it, not from the unmoved point: there it sits at the apex or on the plane
    it was just released from, and the next pass would release it again, stop at length
    0 and hold it back, all the polish's guesses long (go2, solo12 and anymal_c warm
    ticks; notes/performance-history.md, "warmtail2"). Otherwise release the one held
    entry or block whose multiplier is the most wrong (:func:`most_wrong`): a held entry
    or a boundary block becomes free, an apex block is reclassified from its multiplier
    as in :func:`guess`. Returns the number of boundary blocks (planes and curvature at
    ``x_block``, or at the projection for a new one) and counts the changed entries in
    ``changed``.

    An apex block released to its boundary starts, as in :func:`guess`, with its plane at
    the projection of ``y_block`` and ``lam`` the part of ``y_block`` off the cone
    (:func:`_off_cone`), so that its first solve has the curvature. Placed with ``lam =
    0`` instead, nothing held the block's part across the axis where ``P`` is flat on the
    forces: the solve that followed threw the contact past its apex, it was held there,
    released the same way, and the polish ended ``cycling`` (warm polishes of contacts
    being loaded: 7 of go2's 400 warm ticks, 16 of talos'; notes/polish.md, "apexplane").

    A ``BARE`` boundary block (its plane placed with ``lam = 0``) whose multiplier came
    out positive has that plane kept (``KEPT``) for :func:`keep_bare_plane`.

    In a polish from no multipliers (``bare_start``, a carried guess) a free block that
    a solve threw into its polar cone, off the axis, goes on its boundary with the plane
    through the cone's ray on its side of the axis (the plane of ``x_block`` itself),
    not to the apex: nothing held the block in that solve, so where its part across the
    axis points says more than the sign of its part along it. anymal_c's contact tick 360
    put a foot that carries 0.12 of the answer's multipliers at its apex so, gave up
    infeasible after three guesses and ran ADMM (notes/performance-history.md,
    "guesses")."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, d, start, nb = 0, old = 0
    cdef double value, size, along, across, slope, lam
    cdef const double* point
    cdef bint held
    cdef char code, before
    cdef Py_ssize_t released = -1 if adding else most_wrong(w, p, 0.0)
    changed[0] = 0
    for j in range(p.s):
        if p.in_cone[j]:
            continue
        code = before = w.active[j]
        value = w.x[p.constrained[j]]
        if j == released:
            code = FREE
        elif adding and code == FREE and stepped and w.blocked[j]:
            code = LOWER if fabs(value - p.lo[j]) <= fabs(value - p.hi[j]) else UPPER
        elif adding and code == FREE:
            code = _bound_passed(p, j, value)
        changed[0] += code != before
        w.active[j] = code
    copy(w.lam, w.rhs, c.count)   # the old boundary multipliers, by old position
    for k in range(c.count):
        o, d = c.offset[k], c.dim[k]
        start = p.constrained[o]
        code = before = w.active[o]
        lam = 0.0
        slope = cone_slope(c.kind[k], c.mu[k])
        if before == BOUNDARY:
            lam = w.rhs[old]
            old += 1
            if released == p.s + k:
                code = FREE
            elif stepped and w.blocked[o]:
                code = APEX
            if w.bare[k] == BARE and lam > 0.0:   # for Newton's first solve (see keep_bare_plane)
                copy(w.g + o, w.kept_plane + o, d)
                w.bare[k] = KEPT
            copy(w.x + start, w.step, d)
        elif before == FREE and adding:
            held = stepped and w.blocked[o]
            point = (ahead if held and ahead != NULL else w.x) + start
            if _left_cone(c, k, point, &along, &across, &size) or held:
                code = APEX if slope * across <= -along or size == 0.0 else BOUNDARY
                if code == APEX and w.bare_start and not stepped and across > 0.0:
                    code = BOUNDARY   # the plane through the ray on its side of the axis
                    copy(point, w.step, d)
                else:
                    cone_project(point, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
        elif released == p.s + k:   # an apex block whose y left the polar
            along = cone_split(w.y + o, c.kind[k], d, c.mu[k], c.normal + 3 * k, &across)
            code = FREE if across <= slope * along else BOUNDARY
            cone_project(w.y + o, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
            lam = _off_cone(w.y + o, w.step, d)
        for j in range(o, o + d):
            changed[0] += code != before
            w.active[j] = code
        if code == BOUNDARY:
            w.lam[nb] = lam
            w.boundary[nb] = k
            linearize(w, p, nb, w.step)
            nb += 1
    return nb


cdef Py_ssize_t boundary_entries(const Polish* w, const Problem* p, Py_ssize_t nb) noexcept nogil:
    """How many constrained entries the ``nb`` blocks of ``boundary`` have: a correction
    that only put free blocks on their boundary changes exactly as many more entries
    (:func:`fccqp.polish.polish`'s give-up does not count such passes)."""
    cdef Py_ssize_t k, entries = 0
    for k in range(nb):
        entries += p.cones.dim[w.boundary[k]]
    return entries


cdef inline bint _far_side(const Polish* w, const Problem* p, Py_ssize_t cone) noexcept nogil:
    """Whether block ``cone``'s ``x_block`` lies on the far side of its apex
    (``n'x_block <= 0``)."""
    cdef const Cones* c = &p.cones
    cdef double across
    return cone_split(w.x + p.constrained[c.offset[cone]], c.kind[cone], c.dim[cone],
                      c.mu[cone], c.normal + 3 * cone, &across) <= 0.0


cdef bint past_apex(const Polish* w, const Problem* p, Py_ssize_t nb) noexcept nogil:
    """Whether some block of the ``nb`` of ``boundary`` lies on the far side of its apex
    (the test of :func:`drop_far_side`, which would hold it there)."""
    cdef Py_ssize_t k
    for k in range(nb):
        if _far_side(w, p, w.boundary[k]):
            return True
    return False


cdef Py_ssize_t drop_far_side(Polish* w, const Problem* p, Py_ssize_t nb,
                              Py_ssize_t* changed) noexcept nogil:
    """Hold at the apex every boundary block whose ``x_block`` lies on the far side of it
    (``n'x_block <= 0``: the tangent plane through the origin also holds the opposite
    ray, and a polished QP that pulls a contact ends there); return the number of
    boundary blocks left, compacted in order with their multipliers, and count the
    changed entries in ``changed``.

    Newton's re-linearization cannot leave that side: each new plane is tangent along
    the projection of a point outside the cone, and the miss stays where it is (on
    talos' whole-body control, in one polish of five). The apex is the active set such a
    block asks for (no force); the next guess pass releases it again if its multiplier
    leaves the polar cone. A block that goes past its apex a second time in one polish
    sets ``cycling``: the guess flips it between apex and boundary, and the polish ends
    after the next solve, as after ``GUESS_PASSES`` guesses: failing polishes had run all
    their guesses releasing and dropping the same block (notes/polish.md)."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t k, j, cone, o, d, kept = 0
    changed[0] = 0
    for k in range(nb):
        cone = w.boundary[k]
        o, d = c.offset[cone], c.dim[cone]
        if _far_side(w, p, cone):
            for j in range(o, o + d):
                w.active[j] = APEX
            changed[0] += d
            w.cycling = w.cycling or w.dropped[cone]
            w.dropped[cone] = True
            continue
        w.boundary[kept] = cone
        w.lam[kept] = w.lam[k]
        kept += 1
    return kept


cdef double multiplier_violation(Polish* w, const Problem* p, const double* z) noexcept nogil:
    """How far the multipliers ``z`` (user's units, one per entry of ``x``) of the
    polished point are from the normal cone its guess needs: the wrong-signed part of a
    held box entry's (``z <= 0`` at a lower bound, ``>= 0`` at an upper one, either on
    ``lo == hi``) and, on held or boundary cone blocks, the distance of ``z_block`` to
    the polar cone (``-z_block`` must lie in the dual cone). The scaling is constant on a
    cone block, so the cones are those of the scaled problem."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, d, start
    cdef double worst = 0.0
    cdef char code
    for j in range(p.s):
        code = w.active[j]
        if code == LOWER:
            worst = max(worst, z[p.constrained[j]])
        elif code == UPPER:
            worst = max(worst, -z[p.constrained[j]])
    for k in range(c.count):
        o, d = c.offset[k], c.dim[k]
        if w.active[o] == FREE:
            continue
        start = p.constrained[o]
        worst = max(worst, cone_polar_distance(z + start, c.kind[k], d, c.mu[k],
                                               c.normal + 3 * k, w.step))
    return worst
