# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Polishing: the exact solution of the QP on the active set that ADMM's iterate suggests.

ADMM reaches high accuracy only slowly where the cost is flat; but its iterate usually
knows which constraints bind long before it has converged. Polishing (after OSQP's
``polish.c``, extended to the cones) guesses the active set from the slack ``z`` and
the multiplier ``y`` of the scaled problem and solves the equality-constrained QP on
it. The guess is Moreau's decomposition of ``v = z + y`` (OSQP's rule ``z_j - lo_j <
-y_j`` for a box entry reads ``v_j < lo_j``):

- a box entry is held at ``lo`` when ``v_j < lo_j``, at ``hi`` when ``v_j > hi_j``
  (always when ``lo == hi``), free otherwise;
- a cone block is held at the apex (all its entries 0) when ``v`` lies in the polar
  cone: ``z ~ 0`` and ``y`` inside the polar; it is on the boundary when ``v`` is in
  neither the cone nor its polar (``z`` on the boundary away from the apex, ``y`` a
  positive multiple of the outward normal there); it is free when ``v`` lies in the cone.

A boundary block contributes one linear equality, its tangent plane ``g'x_block = 0``,
which passes through the origin because the cone functions ``phi(f) = ||f - (n'f)n|| -
mu n'f`` (friction) and ``phi(t, w) = ||w|| - t`` (second order) are positively
homogeneous: ``g'f = phi(f)`` for ``g`` their gradient at ``f``. Held entries are
eliminated, so the KKT system of the polished QP

    [ P_FF + delta I   A_F'        G'        ] [x_F]   [-q_F - P_F,H x_H]
    [ A_F              -delta I              ] [nu ] = [ b - A_H x_H    ]
    [ G                            -delta I  ] [lam]   [ 0              ]

has the free entries ``F`` of ``x``, the equality multipliers and one multiplier per
boundary block as unknowns (``G`` holds the unit normals ``g``). It is factored with
Bunch-Kaufman ``dsytrf`` and refined against the unregularized matrix, as
:mod:`fccqp.ldl` does. Each boundary block's plane is then re-linearized at the new
``x_block`` and the system re-solved, ``newton_steps`` times at most or until ``|phi|
<= NEWTON_TOLERANCE ||x_block||``: Newton's method (SQP) on the KKT conditions of the
QP on the active manifold, quadratically convergent when the guess is right.

Newton needs the curvature of the constraint: the Hessian of the Lagrangian adds
``lam H`` on each boundary block, ``H`` the Hessian of the cone function times the
normalization of ``g`` (for friction ``(I - nn' - ee') / ||t||``, ``e`` the unit
tangential direction; for second order ``(I - ee') / ||w||`` on ``w``). Homogeneity
makes ``H x_k = 0`` at the linearization point, so the Newton step is the same
equality-constrained QP with ``P + lam H`` on the block. Without that term the
iteration is a fixed point that diverges where ``P`` is flat on the forces and the
multipliers are large, as in whole-body control (measured on random problems: the
cone violation grew from 1e-7 to 2e-5 in one re-linearization).

Multipliers, in the sign convention of docs/formulation.md (``P x + q + A'nu + y = 0``,
``y`` in the normal cone of the set): a held entry's is minus the gradient of the
Lagrangian there, a boundary block's is ``lam g`` with ``g`` the normal at the final
``x_block`` (in the polar cone when ``lam >= 0``; to first order ``lam g(x) = lam g_k +
lam H x``, so the curvature term of the last step is accounted for and stationarity
holds to second order), a free entry's is 0. Whether the guess was right is decided by
the caller, on the user's problem (:func:`multiplier_violation` and the residuals of
:mod:`fccqp.admm`); nothing here tells a wrong guess from a right one.
"""

from libc.math cimport INFINITY, fabs, isfinite, pow, sqrt

from scipy.linalg.cython_lapack cimport dsytrf, dsytrs

from fccqp._dense cimport copy, inf_norm, matvec, matvec_t
from fccqp._types cimport FRICTION, Cones, Iterates, Problem
from fccqp.kkt cimport KKT
from fccqp.polish_schur cimport polish_schur_factor, polish_schur_setup, polish_schur_solve
from fccqp.polish_table cimport table_correct, table_factor, table_solve
from fccqp.projections cimport proj_block
from fccqp.reduced cimport Reduced
from fccqp.tuning cimport (ACTIVE_TOLERANCE, CHORD_RATE, CHORD_STEPS, GUESS_PASSES, GUESS_TOLERANCE,
                           MAX_REFINE, MISS_FLOOR, NEWTON_TOLERANCE, POLISH_DELTA,
                           POLISH_REFINE_TOLERANCE)

cdef extern from "fccqp_clock.h" nogil:
    double fccqp_now()


cdef inline double _axis(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                         const double* normal, double* across) noexcept nogil:
    """Split a cone block ``v`` into its part along the cone's axis (returned) and the
    norm of the rest (``across``), with the axis scaled so that the cone reads
    ``across <= slope * axis`` (slope ``mu`` for friction, 1 for second order)."""
    cdef double along, t, total = 0.0
    cdef Py_ssize_t i
    if kind == FRICTION:
        along = normal[0] * v[0] + normal[1] * v[1] + normal[2] * v[2]
        for i in range(3):
            t = v[i] - along * normal[i]
            total += t * t
    else:
        along = v[0]
        for i in range(1, dim):
            total += v[i] * v[i]
    across[0] = sqrt(total)
    return along


cdef inline double _slope(Py_ssize_t kind, double mu) noexcept nogil:
    return mu if kind == FRICTION else 1.0


cdef bint _plane(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                 const double* normal, double* g, double* phi) noexcept nogil:
    """Unit gradient ``g`` of the cone function at ``v`` and its value ``phi``; False
    (``g`` untouched) where the gradient does not exist (``v`` on the axis)."""
    cdef double across, slope = _slope(kind, mu)
    cdef double along = _axis(v, kind, dim, mu, normal, &across)
    cdef double unit = 1.0 / sqrt(1.0 + slope * slope)
    cdef Py_ssize_t i
    phi[0] = across - slope * along
    if not across > 0.0:
        return False
    if kind == FRICTION:
        for i in range(3):
            g[i] = ((v[i] - along * normal[i]) / across - slope * normal[i]) * unit
    else:
        g[0] = -unit
        for i in range(1, dim):
            g[i] = v[i] / across * unit
    return True


cdef void _curvature(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                     const double* normal, double weight, double* H) noexcept nogil:
    """``H`` (``dim x dim``, symmetric) = ``weight`` times the Hessian of the cone
    function at ``v`` divided by ``sqrt(1 + slope^2)`` (the normalization of ``g``);
    0 on the axis, where the Hessian does not exist."""
    cdef double across, along = _axis(v, kind, dim, mu, normal, &across)
    cdef double slope = _slope(kind, mu), scale, ea, eb
    cdef Py_ssize_t a, b
    for a in range(dim * dim):
        H[a] = 0.0
    if not across > 0.0:
        return
    scale = weight / (sqrt(1.0 + slope * slope) * across)
    if kind == FRICTION:
        for a in range(3):
            ea = (v[a] - along * normal[a]) / across
            for b in range(3):
                eb = (v[b] - along * normal[b]) / across
                H[a * 3 + b] = scale * ((1.0 if a == b else 0.0) - normal[a] * normal[b]
                                        - ea * eb)
    else:
        for a in range(1, dim):
            for b in range(1, dim):
                H[a * dim + b] = scale * ((1.0 if a == b else 0.0)
                                          - v[a] * v[b] / (across * across))


cdef void _linearize(Polish* w, const Problem* p, Py_ssize_t k, const double* v) noexcept nogil:
    """Plane ``g`` and curvature ``hess`` of boundary block ``k`` (of ``boundary``) at
    ``v``, with its current multiplier; a block whose ``v`` is on the axis keeps its plane
    and gets no curvature."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t cone = w.boundary[k], o = c.offset[cone], d = c.dim[cone]
    cdef double phi
    _plane(v, c.kind[cone], d, c.mu[cone], c.normal + 3 * cone, w.g + o, &phi)
    _curvature(v, c.kind[cone], d, c.mu[cone], c.normal + 3 * cone, w.lam[k],
               w.hess + o * p.s)


cdef inline char _box_code(const Problem* p, Py_ssize_t j, double v) noexcept nogil:
    """The guess for box entry ``j`` from ``v = z_j + y_j``, the point before projection."""
    if p.lo[j] == p.hi[j]:
        return FIXED
    if v < p.lo[j]:
        return LOWER
    if v > p.hi[j]:
        return UPPER
    return FREE


cdef inline char _cone_code(const Cones* c, Py_ssize_t k, const double* v) noexcept nogil:
    """The guess for cone block ``k`` from ``v = z_J + y_J``: FREE inside the cone, APEX
    in its polar, BOUNDARY otherwise."""
    cdef double across, slope = _slope(c.kind[k], c.mu[k])
    cdef double along = _axis(v, c.kind[k], c.dim[k], c.mu[k], c.normal + 3 * k, &across)
    if across <= slope * along:
        return FREE
    if slope * across <= -along:
        return APEX
    return BOUNDARY   # across > 0 here, so the plane exists


cdef Py_ssize_t guess_changes(const Problem* p, const double* z, const double* y,
                              double* point, char* codes) noexcept nogil:
    """Classify every constrained entry as :func:`_guess` would from ``z, y`` into
    ``codes`` (``point``: ``s`` scratch) and return how many codes changed: the iteration
    asks it whether ADMM's active set has settled before it polishes early."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, changed = 0
    cdef char code
    for j in range(p.s):
        point[j] = z[j] + y[j]
        if not p.in_cone[j]:
            code = _box_code(p, j, point[j])
            changed += code != codes[j]
            codes[j] = code
    for k in range(c.count):
        o = c.offset[k]
        code = _cone_code(c, k, point + o)
        for j in range(o, o + c.dim[k]):
            changed += code != codes[j]
            codes[j] = code
    return changed


cdef Py_ssize_t _guess(Polish* w, const Problem* p, const double* z, const double* y,
                       Py_ssize_t* changed) noexcept nogil:
    """Fill ``active`` from the slack ``z`` and multiplier ``y``, the list ``boundary``
    and each boundary block's multiplier ``lam`` (the component of ``y`` along the
    plane's normal), plane and curvature at the projection of ``z + y`` onto the cone;
    return the number of boundary blocks and count in ``changed`` the constrained
    entries whose code changed."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, d, nb = 0
    cdef double phi, lam
    cdef char code
    changed[0] = 0
    for j in range(p.s):
        if not p.in_cone[j]:
            code = _box_code(p, j, z[j] + y[j])
            changed[0] += code != w.active[j]
            w.active[j] = code
    for k in range(c.count):
        o, d = c.offset[k], c.dim[k]
        for j in range(o, o + d):
            w.g[j] = z[j] + y[j]
        code = _cone_code(c, k, w.g + o)
        if code == BOUNDARY:
            proj_block(w.g + o, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
            _plane(w.step, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.g + o, &phi)
            lam = 0.0
            for j in range(o, o + d):
                lam += y[j] * w.g[j]
            w.lam[nb] = lam
            w.boundary[nb] = k
            _linearize(w, p, nb, w.step)
            nb += 1
        for j in range(o, o + d):
            changed[0] += code != w.active[j]
            w.active[j] = code
    return nb


cdef Py_ssize_t _most_wrong(Polish* w, const Problem* p) noexcept nogil:
    """The held entry (its index ``j < s``) or held block (``s`` plus its cone's index)
    whose multiplier is farthest, in the user's units, from the normal cone its code
    needs; -1 when none is. The distance is a box entry's wrong-signed ``|y_j|``, a
    boundary block's ``-lam``, an apex block's distance of ``y_block`` to the polar cone
    (``||P_K(y_block)||``), each divided by ``c D_i`` as :func:`fccqp.scaling.unscale`
    does: what :func:`multiplier_violation` measures on the polished point."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, d, old = 0, most = -1
    cdef double worst = 0.0, wrong
    cdef char code
    for j in range(p.s):
        if p.in_cone[j]:
            continue
        code = w.active[j]
        wrong = w.y[j] if code == LOWER else (-w.y[j] if code == UPPER else 0.0)
        wrong /= p.c * p.D[p.constrained[j]]
        if wrong > worst:
            worst, most = wrong, j
    for k in range(c.count):
        o, d = c.offset[k], c.dim[k]
        wrong = 0.0
        if w.active[o] == BOUNDARY:
            wrong = -w.lam[old]
            old += 1
        elif w.active[o] == APEX:
            proj_block(w.y + o, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
            for j in range(d):
                wrong += w.step[j] * w.step[j]
            wrong = sqrt(wrong)
        wrong /= p.c * p.D[p.constrained[o]]
        if wrong > worst:
            worst, most = wrong, p.s + k
    return most


cdef bint _inside(const double* v, Py_ssize_t kind, Py_ssize_t dim, double mu,
                  const double* normal) noexcept nogil:
    """Whether the block ``v`` lies in its cone to ``ACTIVE_TOLERANCE`` (the rule by
    which :func:`_renew` adds a free block that left it)."""
    cdef double across, size = 0.0
    cdef Py_ssize_t j
    cdef double along = _axis(v, kind, dim, mu, normal, &across)
    for j in range(dim):
        size += v[j] * v[j]
    return across - _slope(kind, mu) * along <= ACTIVE_TOLERANCE * sqrt(size)


cdef double _cone_step(const double* x0, const double* x1, Py_ssize_t kind, Py_ssize_t dim,
                       double mu, const double* normal, double* point) noexcept nogil:
    """The largest ``t`` in ``[0, 1]`` with ``x0 + t (x1 - x0)`` in the cone, to
    ``2^-40`` by bisection (``point``: ``dim`` scratch): 1 when ``x1`` is inside (the
    cone is convex), 0 when ``x0`` is not."""
    cdef double low = 0.0, high = 1.0, middle
    cdef Py_ssize_t halving, j
    if _inside(x1, kind, dim, mu, normal):
        return 1.0
    if not _inside(x0, kind, dim, mu, normal):
        return 0.0
    for halving in range(40):
        middle = 0.5 * (low + high)
        for j in range(dim):
            point[j] = x0[j] + middle * (x1[j] - x0[j])
        if _inside(point, kind, dim, mu, normal):
            low = middle
        else:
            high = middle
    return low


cdef double _step(Polish* w, const Problem* p, Py_ssize_t* blocking) noexcept nogil:
    """The largest ``t`` in ``[0, 1]`` such that ``x_prev + t (x - x_prev)`` keeps every
    free box entry within its bounds, every free cone block in its cone and every
    boundary block on the near side of its apex; ``blocking`` receives the constraint
    that stops it first (an entry ``j < s``, or ``s`` plus a cone's index), -1 when none
    does and ``t`` is 1."""
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
        if stop < t:
            t, blocking[0] = stop, j
    for k in range(c.count):
        o, d = c.offset[k], c.dim[k]
        start = p.constrained[o]
        if w.active[o] == FREE:
            stop = _cone_step(w.x_prev + start, w.x + start, c.kind[k], d, c.mu[k],
                              c.normal + 3 * k, w.step)
        elif w.active[o] == BOUNDARY:   # its tangent plane also holds the far ray
            along0 = _axis(w.x_prev + start, c.kind[k], d, c.mu[k], c.normal + 3 * k, &across)
            along1 = _axis(w.x + start, c.kind[k], d, c.mu[k], c.normal + 3 * k, &across)
            stop = 1.0
            if along1 <= 0.0:
                stop = max(0.0, along0 / (along0 - along1)) if along0 > along1 else 0.0
        else:
            continue
        if stop < t:
            t, blocking[0] = stop, p.s + k
    return t


cdef Py_ssize_t _renew(Polish* w, const Problem* p, bint adding, Py_ssize_t blocking,
                       Py_ssize_t* changed) noexcept nogil:
    """Correct the guess from the polished point. With ``adding``, hold free entries
    that violate their bound and put free blocks that left their cone on the boundary
    (or at the apex, if ``x_block`` lies in the polar), and hold the ``blocking``
    constraint of a step (:func:`_step`; -1 for none) where the step left it: a box
    entry at its nearer bound, a free block on the boundary, a boundary block at the
    apex. Otherwise release the one held entry or block whose multiplier is the most
    wrong (:func:`_most_wrong`): a held entry or a boundary block becomes free, an apex
    block is reclassified from its multiplier as in :func:`_guess`. Returns the number of boundary blocks (planes and curvature at ``x_block``, or at
    the projection for a new one) and counts the changed entries in ``changed``."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, d, start, nb = 0, old = 0
    cdef double value, size, along, across, slope, lam
    cdef char code, before
    cdef Py_ssize_t released = -1 if adding else _most_wrong(w, p)
    changed[0] = 0
    for j in range(p.s):
        if p.in_cone[j]:
            continue
        code = before = w.active[j]
        value = w.x[p.constrained[j]]
        if j == released:
            code = FREE
        elif adding and code == FREE and j == blocking:
            code = LOWER if fabs(value - p.lo[j]) <= fabs(value - p.hi[j]) else UPPER
        elif adding and code == FREE:
            if value < p.lo[j] - ACTIVE_TOLERANCE * max(1.0, fabs(p.lo[j])):
                code = LOWER
            elif value > p.hi[j] + ACTIVE_TOLERANCE * max(1.0, fabs(p.hi[j])):
                code = UPPER
        changed[0] += code != before
        w.active[j] = code
    copy(w.lam, w.rhs, c.count)   # the old boundary multipliers, by old position
    for k in range(c.count):
        o, d = c.offset[k], c.dim[k]
        start = p.constrained[o]
        code = before = w.active[o]
        lam = 0.0
        slope = _slope(c.kind[k], c.mu[k])
        if before == BOUNDARY:
            lam = w.rhs[old]
            old += 1
            if released == p.s + k:
                code = FREE
            elif blocking == p.s + k:
                code = APEX
            copy(w.x + start, w.step, d)
        elif before == FREE and adding:
            size = 0.0
            for j in range(d):
                size += w.x[start + j] * w.x[start + j]
            along = _axis(w.x + start, c.kind[k], d, c.mu[k], c.normal + 3 * k, &across)
            if across - slope * along > ACTIVE_TOLERANCE * sqrt(size) or blocking == p.s + k:
                code = APEX if slope * across <= -along or size == 0.0 else BOUNDARY
                proj_block(w.x + start, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
        elif released == p.s + k:   # an apex block whose y left the polar
            along = _axis(w.y + o, c.kind[k], d, c.mu[k], c.normal + 3 * k, &across)
            code = FREE if across <= slope * along else BOUNDARY
            proj_block(w.y + o, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
        for j in range(o, o + d):
            changed[0] += code != before
            w.active[j] = code
        if code == BOUNDARY:
            w.lam[nb] = lam
            w.boundary[nb] = k
            _linearize(w, p, nb, w.step)
            nb += 1
    return nb


cdef Py_ssize_t _unknowns(Polish* w, const Problem* p) noexcept nogil:
    """Put the held entries of ``x`` at their values; number the free entries
    (``index``, ``free``) and return how many there are."""
    cdef Py_ssize_t n = p.n, i, j, nf = 0
    cdef char code
    w.grad_current = False
    for i in range(n):
        w.index[i] = 0
    for j in range(p.s):
        code = w.active[j]
        i = p.constrained[j]
        if code == LOWER or code == FIXED:
            w.x[i] = p.lo[j]
        elif code == UPPER:
            w.x[i] = p.hi[j]
        elif code == APEX:
            w.x[i] = 0.0
        else:
            continue
        w.index[i] = -1
    for i in range(n):
        if w.index[i] == 0:
            w.index[i] = nf
            w.free[nf] = i
            nf += 1
    return nf


cdef void _assemble(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """Lower triangle of the regularized KKT matrix of the polished QP into ``K``."""
    cdef Py_ssize_t n = p.n, m = p.m, N = nf + m + nb, r, col, i, j, k, o, d, start, jc
    cdef double* K = w.K
    for col in range(N):
        for r in range(col, N):
            K[r + col * N] = 0.0
    for col in range(nf):
        jc = w.free[col]
        for r in range(col, nf):
            K[r + col * N] = p.P[w.free[r] * n + jc]
        K[col + col * N] += POLISH_DELTA
        for i in range(m):
            K[nf + i + col * N] = p.A[i * n + jc]
    for k in range(nb):
        o, d = p.cones.offset[w.boundary[k]], p.cones.dim[w.boundary[k]]
        start = p.constrained[o]
        for j in range(d):
            K[nf + m + k + w.index[start + j] * N] = w.g[o + j]
            for i in range(j, d):   # entries of a block are consecutive unknowns
                K[w.index[start + i] + w.index[start + j] * N] += w.hess[o * p.s + i * d + j]
    for r in range(nf, N):
        K[r + r * N] = -POLISH_DELTA


cdef double _residual(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """Residual of the current ``(x, nu, lam)`` in the unregularized system (with the
    curvature terms) into ``rhs``; returns its infinity norm. Leaves the gradient of the
    Lagrangian without the boundary blocks' terms in ``grad`` (there it is minus the
    multipliers of the held entries)."""
    cdef Py_ssize_t n = p.n, m = p.m, i, j, k, o, d, start, cone
    cdef double value, curved
    matvec(p.P, w.x, w.grad, n, n)
    matvec_t(p.A, w.nu, w.ATnu, m, n)
    for i in range(n):
        w.grad[i] += p.q[i] + w.ATnu[i]
    for i in range(nf):
        w.rhs[i] = -w.grad[w.free[i]]
    for k in range(nb):
        cone = w.boundary[k]
        o = p.cones.offset[cone]
        start = p.constrained[o]
        d = p.cones.dim[cone]
        value = 0.0
        for j in range(d):
            curved = 0.0
            for i in range(d):
                curved += w.hess[o * p.s + j * d + i] * w.x[start + i]
            w.rhs[w.index[start + j]] -= w.lam[k] * w.g[o + j] + curved
            value += w.g[o + j] * w.x[start + j]
        w.rhs[nf + m + k] = -value
    matvec(p.A, w.x, w.Ax, m, n)
    for i in range(m):
        w.rhs[nf + i] = p.b[i] - w.Ax[i]
    w.grad_current = True
    return inf_norm(w.rhs, nf + m + nb)


cdef void _apply(Polish* w, Py_ssize_t nf, Py_ssize_t m, Py_ssize_t nb,
                 double sign) noexcept nogil:
    """Add ``sign`` times ``step`` to the unknowns."""
    cdef Py_ssize_t i
    w.grad_current = False
    for i in range(nf):
        w.x[w.free[i]] += sign * w.step[i]
    for i in range(m):
        w.nu[i] += sign * w.step[nf + i]
    for i in range(nb):
        w.lam[i] += sign * w.step[nf + m + i]


cdef void _solve(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb,
                 double tolerance) noexcept nogil:
    """Correct ``(x, nu, lam)`` to the solution of the factored system: residual
    corrections against the unregularized matrix until the residual is below
    ``tolerance``, stops halving (a singular system), or ``MAX_REFINE`` corrections
    after the first; a correction that makes it grow is undone."""
    cdef double norm, last = INFINITY
    cdef int r
    for r in range(MAX_REFINE + 2):
        norm = _residual(w, p, nf, nb)
        if norm > last:
            _apply(w, nf, p.m, nb, -1.0)
            return
        if norm <= tolerance or norm > 0.5 * last or r == MAX_REFINE + 1:
            return
        last = norm
        _factored_solve(w, p, nf, nb)
        _apply(w, nf, p.m, nb, 1.0)


cdef void _factored_solve(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """``step`` := the current factorization's solution for ``rhs``."""
    cdef char uplo = b"L"
    cdef int size = <int>(nf + p.m + nb), one = 1, info = 0
    copy(w.rhs, w.step, size)
    if w.structured:
        polish_schur_solve(&w.schur, p, w.index, w.boundary, nb, w.step)
    else:
        dsytrs(&uplo, &size, &one, w.K, &size, w.ipiv, w.step, &size, &info)


cdef void _correct_once(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """One correction of the current point with the last factorization (a chord step)."""
    if nf + p.m + nb == 0:
        return
    _residual(w, p, nf, nb)
    _factored_solve(w, p, nf, nb)
    _apply(w, nf, p.m, nb, 1.0)


cdef bint _relinearize(Polish* w, const Problem* p, Py_ssize_t nb,
                       double* worst) noexcept nogil:
    """Move each boundary block's plane and curvature to the current ``x_block``,
    unless every block already meets ``NEWTON_TOLERANCE``: then return False and keep
    the planes, with which ``(x, lam)`` were solved. ``worst`` receives the largest
    ``|phi| / ||x_block||``."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t k, j, cone, start, d
    cdef double across, along, size, miss
    cdef bint converged = True
    worst[0] = 0.0
    for k in range(nb):
        cone = w.boundary[k]
        d = c.dim[cone]
        start = p.constrained[c.offset[cone]]
        size = 0.0
        for j in range(d):
            size += w.x[start + j] * w.x[start + j]
        along = _axis(w.x + start, c.kind[cone], d, c.mu[cone], c.normal + 3 * cone, &across)
        miss = fabs(across - _slope(c.kind[cone], c.mu[cone]) * along)
        if miss > NEWTON_TOLERANCE * sqrt(size):
            converged = False
            worst[0] = max(worst[0], miss / sqrt(size))
    if converged:
        return False
    for k in range(nb):
        _linearize(w, p, k, w.x + p.constrained[c.offset[w.boundary[k]]])
    return True


cdef Py_ssize_t _drop_far_side(Polish* w, const Problem* p, Py_ssize_t nb,
                               Py_ssize_t* changed) noexcept nogil:
    """Hold at the apex every boundary block whose ``x_block`` lies on the far side of it
    (``n'x_block <= 0``: the tangent plane through the origin also holds the opposite
    ray, and a polished QP that pulls a contact ends there); return the number of
    boundary blocks left, compacted in order with their multipliers, and count the
    changed entries in ``changed``.

    Newton's re-linearization cannot leave that side: each new plane is tangent along
    the projection of a point outside the cone, and on talos' whole-body control the
    miss stayed at 1.1-1.2 for all ten steps (a fresh factorization each) in one of five
    polishes. The apex is the active set such a block asks for (no force); the next
    guess pass releases it again if its multiplier leaves the polar cone. A block that
    goes past its apex a second time in one polish sets ``cycling``: the guess flips it
    between apex and boundary, and the polish ends after the next solve, as after
    ``GUESS_PASSES`` guesses. Many of talos' failing polishes had run all 8 guesses
    releasing and dropping the same block; ending them so changed no result on the four
    robots' 400 ticks (the same iterations at both presets); instructions per 400 ticks
    (``Settings.realtime(1.0)``, callgrind) talos 1.350G -> 1.317G, go2 255.4M ->
    253.7M, solo12 289.1M -> 285.8M."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t k, j, cone, o, d, kept = 0
    cdef double across, along
    changed[0] = 0
    for k in range(nb):
        cone = w.boundary[k]
        o, d = c.offset[cone], c.dim[cone]
        along = _axis(w.x + p.constrained[o], c.kind[cone], d, c.mu[cone], c.normal + 3 * cone,
                      &across)
        if along <= 0.0:
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


cdef bint _factor_solve(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb,
                       double tolerance, int* factorizations) noexcept nogil:
    """Factor the KKT matrix of the current active set and planes (by Schur complement
    where :mod:`fccqp.polish_schur` was set up for this problem and applies, else
    assembled for ``dsytrf``) and solve it from the current point to ``tolerance``;
    False when the factorization breaks down."""
    cdef char uplo = b"L"
    cdef int size = <int>(nf + p.m + nb), info = 0
    if size == 0:   # every entry held, no rows: nothing to solve
        return True
    w.structured = w.schur.ready and polish_schur_factor(&w.schur, p, w.index, w.boundary, nb,
                                                         w.g, w.hess, POLISH_DELTA)
    factorizations[0] += 1
    if w.structured:
        _solve(w, p, nf, nb, tolerance)
        return True
    if w.schur_only:
        w.schur_failed = True
        return False
    _assemble(w, p, nf, nb)
    dsytrf(&uplo, &size, w.K, &size, w.ipiv, w.work, &w.lwork, &info)
    if info != 0:
        return False
    _solve(w, p, nf, nb, tolerance)
    return True


cdef bint _solve_guess(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb,
                      double scale, int* factorizations, const Reduced* table, KKT* kkt,
                      const double* rho_vec, bint* tabled, bint first) noexcept nogil:
    """Solve the polished QP of the current guess in the reduced form's coordinates
    while ``tabled`` (:mod:`fccqp.polish_table`), else with its own KKT matrix (refined
    to ``GUESS_TOLERANCE`` on a guess's ``first`` solve); a singular system in the
    table's coordinates ends ``tabled`` for this polish."""
    w.grad_current = False
    if tabled[0]:
        if table_factor(w, p, table, rho_vec, nb):
            table_solve(w, p, table, kkt, rho_vec, nb, scale)
            return True
        tabled[0] = False
    return _factor_solve(w, p, nf, nb,
                         (GUESS_TOLERANCE if first else POLISH_REFINE_TOLERANCE) * scale,
                         factorizations)


cdef void _multipliers(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """``y`` of the current point: minus the Lagrangian's gradient on held entries,
    ``lam g(x)`` on boundary blocks (stationary to second order in the last Newton
    step), 0 elsewhere."""
    cdef Py_ssize_t j, k, o, cone
    cdef char code
    cdef double phi
    if not w.grad_current:   # a solve's last residual is often the point's
        _residual(w, p, nf, nb)   # grad: the held entries' multipliers, negated
    for j in range(p.s):
        code = w.active[j]
        w.y[j] = 0.0 if code == FREE or code == BOUNDARY else -w.grad[p.constrained[j]]
    for k in range(nb):
        cone = w.boundary[k]
        o = p.cones.offset[cone]
        _plane(w.x + p.constrained[o], p.cones.kind[cone], p.cones.dim[cone], p.cones.mu[cone],
               p.cones.normal + 3 * cone, w.g + o, &phi)
        for j in range(o, o + p.cones.dim[cone]):
            w.y[j] = w.lam[k] * w.g[j]


cdef bint polish_prepare(Polish* w, const Problem* p) noexcept nogil:
    """Set up the Schur-complement solve of :mod:`fccqp.polish_schur` for this solve's
    ``P`` and ``A``; True when it applies, and then polishing needs no table."""
    return polish_schur_setup(&w.schur, p, POLISH_DELTA)


cdef bint polish(Polish* w, const Problem* p, const Iterates* it, long newton_steps,
                 int* factorizations, const Reduced* table, KKT* kkt,
                 const double* rho_vec, double deadline) noexcept nogil:
    """Polish the iterate ``it`` into ``w.x``, ``w.nu``, ``w.y`` (scaled problem) and
    leave the final guess in ``w.active``; ``factorizations`` counts the ``dsytrf``
    calls. With ``table`` (the reduced form's, current for ``rho_vec`` and ``kkt``'s
    factorization) each guess is solved in its coordinates (:mod:`fccqp.polish_table`),
    else, or where that system is singular, with the guess's own KKT matrix.

    Each guess is solved once (one Newton step, curvature included) and corrected from
    the polished point (:func:`_renew`), until the guess stops changing or
    ``GUESS_PASSES`` guesses were solved. A correction first only adds the violated
    constraints; a wrong-signed multiplier is released only from a point that violates
    nothing, and only one per pass, the most wrong (:func:`_most_wrong`), as a primal
    active-set method drops one constraint at a time. Changing both at once (a plain
    primal-dual active-set step) was measured to diverge on whole-body control, where the
    cost is flat on the torques and forces: releasing a bound and a cone together sent
    free torques to 1e3. Releasing every wrong-signed multiplier of a pass together
    cycled on talos' contact switches (32 entries released, 17 held again the next
    pass); one at a time, 83.5 % of talos' ticks ended in the warm polish, without an
    iteration, instead of 80.5 %, and 93 % of go2's instead of 91.5 %
    (``Settings.realtime(math.inf)``, 200 ticks each). Once a pass's point violates
    nothing, each next pass is a step of a primal active-set method: from that point
    toward the new guess's solution only as far as the first free constraint allows
    (:func:`_step`), which is then held, and a release only from a full step. The
    polished QP of a wrong guess lies far out where the cost is flat on the forces, and
    jumping there swung talos' contact forces by hundreds of newtons from pass to pass
    (a block flipping between apex and boundary); with the steps, 88 instead of 83.5 %
    of talos' ticks ended in the warm polish and a tick took 4.72M instead of 5.96M
    instructions (six passes each). On a settled guess the boundary
    planes are then re-linearized up to ``newton_steps`` times (chord steps while they
    converge fast, see ``CHORD_RATE``), stopping early at the floor rounding leaves. A boundary block that a solve puts past the apex (:func:`_drop_far_side`)
    is held at the apex instead and the corrected guess solved, within the same
    ``GUESS_PASSES``. False when a factorization breaks down or the result is not
    finite, or when the clock (:func:`fccqp_now`) has passed ``deadline`` before a
    guess after the first (``INFINITY``: never); otherwise the caller judges the point.
    """
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, nb, nf = 0, j, changed
    cdef long passes = 0, step
    cdef double total = 0.0
    cdef double scale = max(1.0, max(inf_norm(p.q, n), inf_norm(p.b, m)))
    cdef bint tabled = table != NULL
    cdef double miss, rate, last_miss = INFINITY
    cdef bint refactored = False
    cdef bint feasible = False   # a pass's point violated nothing: from then on, steps
    cdef Py_ssize_t blocking
    cdef double t
    copy(it.x, w.x, n)
    copy(it.nu, w.nu, m)
    copy(it.y, w.y, s)
    w.grad_current = False
    w.schur_failed = False
    for j in range(s):
        w.active[j] = FREE
    for j in range(p.cones.count):
        w.dropped[j] = False
    w.cycling = False
    nb = _guess(w, p, it.z, it.y, &changed)
    while True:
        w.passes = passes
        if passes > 0 and fccqp_now() > deadline:
            return False   # a time limit: the caller keeps its point
        nf = _unknowns(w, p)
        if feasible:
            copy(w.x, w.x_prev, n)
            copy(w.nu, w.nu_prev, m)
        if not _solve_guess(w, p, nf, nb, scale, factorizations, table, kkt, rho_vec, &tabled,
                            True):
            return False
        _multipliers(w, p, nf, nb)
        passes += 1
        if passes == GUESS_PASSES or w.cycling:   # not settled: the caller judges this point
            if not tabled:
                _solve(w, p, nf, nb, POLISH_REFINE_TOLERANCE * scale)
                _multipliers(w, p, nf, nb)
            break
        if feasible:
            t = _step(w, p, &blocking)
            if blocking >= 0:   # stop where the first constraint does, and hold it
                for j in range(n):
                    w.x[j] = w.x_prev[j] + t * (w.x[j] - w.x_prev[j])
                for j in range(m):
                    w.nu[j] = w.nu_prev[j] + t * (w.nu[j] - w.nu_prev[j])
                w.grad_current = False
                nb = _renew(w, p, True, blocking, &changed)
                continue
        nb = _renew(w, p, True, -1, &changed)
        if changed == 0:
            feasible = True
            nb = _renew(w, p, False, -1, &changed)
        if changed == 0:
            nb = _drop_far_side(w, p, nb, &changed)
        if changed != 0:
            continue
        last_miss = INFINITY
        refactored = False
        for step in range(newton_steps):
            if not _relinearize(w, p, nb, &miss) or (
                    refactored and miss >= last_miss and miss <= MISS_FLOOR):
                break   # converged, or at the floor that rounding leaves
            rate = miss / last_miss   # 0 at the first step: a chord step
            refactored = rate > CHORD_RATE or pow(rate, CHORD_STEPS) * miss > NEWTON_TOLERANCE
            if not refactored:   # a chord step: one correction, the last factor, the current planes
                if tabled:
                    table_correct(w, p, table, kkt, rho_vec, nb, scale)
                    w.grad_current = False
                else:
                    _correct_once(w, p, nf, nb)
            elif not _solve_guess(w, p, nf, nb, scale, factorizations, table, kkt, rho_vec,
                                  &tabled, False):
                return False
            last_miss = miss
            nb = _drop_far_side(w, p, nb, &changed)
            if changed != 0:
                break
        if changed != 0:
            continue   # a block went past its apex: solve the corrected guess
        if not refactored:   # refine the last chord step's (or the first solve's) point
            if tabled:
                table_solve(w, p, table, kkt, rho_vec, nb, scale)
                w.grad_current = False
            else:
                _solve(w, p, nf, nb, POLISH_REFINE_TOLERANCE * scale)
        _multipliers(w, p, nf, nb)
        break
    w.passes = passes
    for j in range(n):
        total += w.x[j]
    for j in range(m):
        total += w.nu[j]
    for j in range(s):
        total += w.y[j]
    return isfinite(total)


cdef double multiplier_violation(Polish* w, const Problem* p, const double* z) noexcept nogil:
    """How far the multipliers ``z`` (user's units, one per entry of ``x``) of the
    polished point are from the normal cone its guess needs: the wrong-signed part of a
    held box entry's (``z <= 0`` at a lower bound, ``>= 0`` at an upper one, either on
    ``lo == hi``) and, on held or boundary cone blocks, the distance of ``z_block`` to
    the polar cone (``-z_block`` must lie in the dual cone). The scaling is constant on a
    cone block, so the cones are those of the scaled problem."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, d, start
    cdef double worst = 0.0, distance
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
        proj_block(z + start, c.kind[k], d, c.mu[k], c.normal + 3 * k, w.step)
        distance = 0.0   # ||P_K(z)||: the distance of z to the polar (Moreau)
        for j in range(d):
            distance += w.step[j] * w.step[j]
        worst = max(worst, sqrt(distance))
    return worst
