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
Bunch-Kaufman ``dsytrf`` (or by :mod:`fccqp.polish_schur`'s Schur complement where
``P``'s structure allows it; by qdldl in compressed columns, :mod:`fccqp.polish_csc`, where
``P`` and ``A`` are CSC) and refined against the unregularized matrix, as :mod:`fccqp.ldl`
does; where a free block's curvature lies below ``delta`` and the refinement crawls, it is
factored again with a smaller ``delta``. That system of one guess (its unknowns, its
matrix, its residual and the refined solve) is :mod:`fccqp.polish_kkt`; this module
chooses the guesses and drives the steps. Each boundary block's plane is then
re-linearized at the new ``x_block`` and the system re-solved, ``newton_steps`` times at
most or until ``|phi| <= NEWTON_TOLERANCE ||x_block||``: Newton's method (SQP) on the
KKT conditions of the QP on the active manifold, quadratically convergent when the
guess is right.

Newton needs the curvature of the constraint: the Hessian of the Lagrangian adds
``lam H`` on each boundary block, ``H`` the Hessian of the cone function times the
normalization of ``g`` (for friction ``(I - nn' - ee') / ||t||``, ``e`` the unit
tangential direction; for second order ``(I - ee') / ||w||`` on ``w``). Homogeneity
makes ``H x_k = 0`` at the linearization point, so the Newton step is the same
equality-constrained QP with ``P + lam H`` on the block. Without that term the
iteration is a fixed point that diverges where ``P`` is flat on the forces and the
multipliers are large, as in whole-body control (measured on random problems: the
cone violation grew from 1e-7 to 2e-5 in one re-linearization). ``H`` is taken on the
cone at ``x_k``'s axis part (the same ``e``, ``||t||`` the cone's radius there, so
``H x_k = 0`` still): ``x_k`` lies on the last plane, outside the cone, where the
curvature is flatter than the constraint's
(:func:`~fccqp.polish_guess.linearize_on_cone`).

Multipliers, in the sign convention of docs/formulation.md (``P x + q + A'nu + y = 0``,
``y`` in the normal cone of the set): a held entry's is minus the gradient of the
Lagrangian there, a boundary block's is ``lam g`` with ``g`` the normal at the final
``x_block`` (in the polar cone when ``lam >= 0``; to first order ``lam g(x) = lam g_k +
lam H x``, so the curvature term of the last step is accounted for and stationarity
holds to second order), a free entry's is 0. Whether the guess was right is decided by
the caller, on the user's problem (:func:`fccqp.polish_guess.multiplier_violation` and the residuals of
:mod:`fccqp.admm`); nothing here tells a wrong guess from a right one.
"""

from libc.math cimport INFINITY, fabs, isfinite, pow, sqrt

from fccqp._dense cimport copy, inf_norm
from fccqp._types cimport Cones, Iterates, Problem
from fccqp.cone_dispatch cimport cone_phi, cone_plane
from fccqp.kkt cimport KKT
from fccqp.matrices cimport CSC, DENSE
from fccqp.polish_guess cimport (boundary_entries, box_code, cone_code, drop_far_side, guess,
                                 keep_bare_plane, leaves_set, linearize_on_cone, most_wrong,
                                 past_apex, renew, step_length, wrong_signed)
from fccqp.polish_kkt cimport correct_once, kkt_residual, number_unknowns, refactor, refine
from fccqp.polish_schur cimport polish_schur_factor, polish_schur_setup
from fccqp.polish_table cimport table_correct, table_factor, table_solve
from fccqp.reduced cimport Reduced
from fccqp.tuning cimport (CHORD_RATE, CHORD_STEPS, FEASIBLE_PASSES, GUESS_TOLERANCE,
                           HOPELESS_RATE, MISS_FLOOR, NEWTON_TOLERANCE, POLISH_CSC_DELTA,
                           POLISH_DELTA, POLISH_REFINE_TOLERANCE)

cdef extern from "fccqp_clock.h" nogil:
    double fccqp_now()


cdef Py_ssize_t guess_changes(const Problem* p, const double* z, const double* y,
                              double* point, char* codes) noexcept nogil:
    """Classify every constrained entry as :func:`fccqp.polish_guess.guess` would from
    ``z, y`` into ``codes`` (``point``: ``s`` scratch) and return how many codes changed:
    the iteration asks it whether ADMM's active set has settled before it polishes early."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t j, k, o, changed = 0
    cdef char code
    for j in range(p.s):
        point[j] = z[j] + y[j]
        if not p.in_cone[j]:
            code = box_code(p, j, point[j])
            changed += code != codes[j]
            codes[j] = code
    for k in range(c.count):
        o = c.offset[k]
        code = cone_code(c, k, point + o)
        for j in range(o, o + c.dim[k]):
            changed += code != codes[j]
            codes[j] = code
    return changed


cdef void _keep_point(Polish* w, const Problem* p, Py_ssize_t nb, bint undo) noexcept nogil:
    """Copy ``(x, nu, y, lam)`` into ``chord_start``, or back from it with ``undo``."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s
    cdef double* kept = w.chord_start
    if undo:
        copy(kept, w.x, n)
        copy(kept + n, w.nu, m)
        copy(kept + n + m, w.y, s)
        copy(kept + n + m + s, w.lam, nb)
        w.grad_current = False
    else:
        copy(w.x, kept, n)
        copy(w.nu, kept + n, m)
        copy(w.y, kept + n + m, s)
        copy(w.lam, kept + n + m + s, nb)


cdef bint _chord_step(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb, double scale,
                      const Reduced* table, KKT* kkt, const double* rho_vec,
                      bint tabled) noexcept nogil:
    """One chord step of Newton's method (the last factorization, the current planes);
    False, with the step undone, when it puts a boundary block past its apex: the
    caller then refactors (a Newton step) from the same point.

    The last factorization lacks the curvature of a plane that entered the guess with
    ``lam = 0`` (:func:`~fccqp.polish_guess.linearize`), and where ``P`` is flat on the
    forces its step along that plane is all but unbounded: contacts whose plane entered
    so were thrown past the apex by that first chord step, held at the apex by
    :func:`~fccqp.polish_guess.drop_far_side`, released again, and the polish ended
    cycling; the tick then ran ADMM. The Newton step's factorization has the curvature;
    where it too crosses, ``drop_far_side`` holds the block as before (notes/polish.md,
    "warmtail")."""
    _keep_point(w, p, nb, False)
    if tabled:
        table_correct(w, p, table, kkt, rho_vec, nb, scale)
    else:
        correct_once(w, p, nf, nb)
    if past_apex(w, p, nb):
        _keep_point(w, p, nb, True)
        return False
    return True


cdef double _plane_miss(const Polish* w, const Problem* p, Py_ssize_t nb) noexcept nogil:
    """The largest ``|phi| / ||x_block||`` of the ``nb`` boundary blocks that miss
    their cone by more than ``NEWTON_TOLERANCE`` of their size; 0 when none does."""
    cdef const Cones* c = &p.cones
    cdef Py_ssize_t k, j, cone, start, d
    cdef double size, miss, worst = 0.0
    for k in range(nb):
        cone = w.boundary[k]
        d = c.dim[cone]
        start = p.constrained[c.offset[cone]]
        size = 0.0
        for j in range(d):
            size += w.x[start + j] * w.x[start + j]
        miss = fabs(cone_phi(w.x + start, c.kind[cone], d, c.mu[cone], c.normal + 3 * cone))
        if miss > NEWTON_TOLERANCE * sqrt(size):
            worst = max(worst, miss / sqrt(size))
    return worst


cdef bint _relinearize(Polish* w, const Problem* p, Py_ssize_t nb,
                       double* worst) noexcept nogil:
    """Move each boundary block's plane to the current ``x_block`` and its curvature to
    the cone there (:func:`~fccqp.polish_guess.linearize_on_cone`), unless every block
    already meets ``NEWTON_TOLERANCE``: then return False and keep the planes, with
    which ``(x, lam)`` were solved. ``worst`` receives the largest ``|phi| /
    ||x_block||`` (:func:`_plane_miss`)."""
    cdef Py_ssize_t k
    worst[0] = _plane_miss(w, p, nb)
    if worst[0] == 0.0:
        return False
    for k in range(nb):
        linearize_on_cone(w, p, k, w.x + p.constrained[p.cones.offset[w.boundary[k]]])
    return True


cdef bint _planes_first(Polish* w, const Problem* p, Py_ssize_t nb) noexcept nogil:
    """Whether a feasible pass of a polish from no multipliers (``bare_start``) runs
    Newton's steps on its guess before releasing its most wrong multiplier: it is a
    boundary block's ``lam`` while some boundary block still misses its cone
    (:func:`_plane_miss`). Such a polish places every plane where a free block left its
    cone, with no curvature (``lam = 0``), and a ``lam`` solved on those planes says
    little about its sign at the answer; Newton's steps settle the planes first and the
    block is released after them if its ``lam`` is still wrong (see :func:`polish`).
    Not in other polishes, whose planes come with the multipliers of ADMM's iterate or
    of the previous answer: there this rule and ``renew``'s polar one together cost
    solo12's every-10th ticks 5.5 % more instructions (notes/performance-history.md,
    "guesses")."""
    cdef Py_ssize_t most
    if not w.bare_start:
        return False
    most = most_wrong(w, p, 0.0)
    return (most >= p.s and w.active[p.cones.offset[most - p.s]] == BOUNDARY
            and _plane_miss(w, p, nb) > 0.0)


cdef bint _factor_solve(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb,
                       double tolerance, int* factorizations) noexcept nogil:
    """Factor the KKT matrix of the current active set and planes (by Schur complement
    where :mod:`fccqp.polish_schur` was set up for this problem and applies, else
    assembled for ``dsytrf``, or for qdldl where ``P`` and ``A`` are CSC) and solve it
    from the current point to ``tolerance``; False when the factorization breaks down.

    A polish after ADMM's factorization (the table's fallback where its system is
    singular, or a run without a table) sets the Schur solve up here when no warm polish
    of this solve did: on talos' cold ticks the table's fallback had been ``dsytrf`` of
    the whole polished KKT matrix, 1.5M instructions a guess, where the set-up costs
    0.4M once and a guess 0.15M (notes/polish.md, "polishcost"). Where ``P`` does not
    allow it the set-up is tried again at the next fallback, at most its own cost
    against the ``dsytrf`` that follows anyway. Not without the workspace's storage
    (``schur.L`` NULL: :mod:`fccqp.polish_ops`' dense arm, which the tests hold to the
    CSC arm)."""
    if nf + p.m + nb == 0:   # every entry held, no rows: nothing to solve
        return True
    if not w.schur.ready and not w.schur_only and w.schur.L != NULL:
        polish_prepare(w, p)   # first fallback of this solve from the table (see polish)
    w.retry_spent = False
    w.delta = POLISH_DELTA
    w.structured = w.schur.ready and polish_schur_factor(&w.schur, p, w.index, w.boundary, nb,
                                                         w.g, w.hess, POLISH_DELTA)
    if w.structured:
        factorizations[0] += 1
        refine(w, p, nf, nb, tolerance, factorizations)
        return True
    if w.schur_only:
        factorizations[0] += 1
        w.schur_failed = True
        return False
    if not refactor(w, p, nf, nb, POLISH_CSC_DELTA if p.P.kind == CSC else POLISH_DELTA,
                    factorizations):
        return False
    refine(w, p, nf, nb, tolerance, factorizations)
    return True


cdef bint _solve_guess(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb,
                      double scale, int* factorizations, const Reduced* table, KKT* kkt,
                      const double* rho_vec, bint* tabled) noexcept nogil:
    """Solve the polished QP of the current guess in the reduced form's coordinates
    while ``tabled`` (:mod:`fccqp.polish_table`), else with its own KKT matrix, refined
    only to ``GUESS_TOLERANCE``: the point moves on from there (the guess's
    corrections, Newton's next step), and the point a polish returns is refined to
    ``POLISH_REFINE_TOLERANCE`` by :func:`_newton` or at the end of :func:`polish`. A
    singular system in the table's coordinates ends ``tabled`` for this polish. ``KEPT``
    planes are dropped: they serve only the first solve of :func:`_newton`."""
    cdef Py_ssize_t k
    for k in range(nb):   # a kept plane serves only the Newton step that follows it
        if w.bare[w.boundary[k]] == KEPT:
            w.bare[w.boundary[k]] = CURVED
    if tabled[0]:
        if table_factor(w, p, table, rho_vec, nb):
            table_solve(w, p, table, kkt, rho_vec, nb, scale)
            return True
        tabled[0] = False
    return _factor_solve(w, p, nf, nb, GUESS_TOLERANCE * scale, factorizations)


cdef void _multipliers(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """``y`` of the current point: minus the Lagrangian's gradient on held entries,
    ``lam g(x)`` on boundary blocks (stationary to second order in the last Newton
    step), 0 elsewhere."""
    cdef Py_ssize_t j, k, o, cone
    cdef char code
    cdef double phi
    if not w.grad_current:   # a solve's last residual is often the point's
        kkt_residual(w, p, nf, nb)   # grad: the held entries' multipliers, negated
    for j in range(p.s):
        code = w.active[j]
        w.y[j] = 0.0 if code == FREE or code == BOUNDARY else -w.grad[p.constrained[j]]
    for k in range(nb):
        cone = w.boundary[k]
        o = p.cones.offset[cone]
        cone_plane(w.x + p.constrained[o], p.cones.kind[cone], p.cones.dim[cone],
                   p.cones.mu[cone], p.cones.normal + 3 * cone, w.g + o, &phi)
        for j in range(o, o + p.cones.dim[cone]):
            w.y[j] = w.lam[k] * w.g[j]


cdef bint _restore_kept_planes(Polish* w, const Problem* p, Py_ssize_t nb) noexcept nogil:
    """Put every ``KEPT`` plane of the ``nb`` boundary blocks back, with its curvature
    (:func:`~fccqp.polish_guess.keep_bare_plane`); whether there was one."""
    cdef Py_ssize_t k
    cdef bint any = False
    for k in range(nb):
        if w.bare[w.boundary[k]] == KEPT:
            keep_bare_plane(w, p, k)
            any = True
    return any


cdef inline bint _stalled(double miss, double last_miss) noexcept nogil:
    """Whether a fresh factorization's step left the planes' miss where :func:`_newton`
    stops: not below ``last_miss`` and at the floor rounding leaves (``MISS_FLOOR``), or
    exactly ``last_miss``, the point unmoved. A step solves from the current point and
    corrects it only where the residual on the moved planes exceeds ``GUESS_TOLERANCE``;
    a point whose planes miss by less than that (in ``x_block``'s units) but more than
    ``NEWTON_TOLERANCE`` is left as it is, the same planes are placed again and every
    later step repeats the same factorization: solo12's polish of a carried guess at a
    contact switch refactored 16 times at a miss of 3.2e-10 and ended with the point it
    had (notes/performance-history.md, "contactray")."""
    return miss >= last_miss and (miss <= MISS_FLOOR or miss == last_miss)


cdef int _newton(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t* nb, long newton_steps,
                 double scale, int* factorizations, const Reduced* table, KKT* kkt,
                 const double* rho_vec, bint* tabled) noexcept nogil:
    """Newton's method on the current guess's ``nb`` boundary planes (see :func:`polish`):
    re-linearize them at the current point up to ``newton_steps`` times (chord steps while
    they converge fast), then refine the point and set its multipliers: 0. 1 when a block
    went past its apex (held there now, ``nb`` the blocks left, the point not re-solved);
    -1 when a factorization broke down. Where planes were ``KEPT``
    (:func:`~fccqp.polish_guess.keep_bare_plane`), the first step solves them there.

    A refactored step is refined only to ``GUESS_TOLERANCE`` (:func:`_solve_guess`) and
    the point to ``POLISH_REFINE_TOLERANCE`` once, after the last step: the next step's
    residual, against the moved planes, repeats a refactored step's last corrections.
    Refining every step to ``POLISH_REFINE_TOLERANCE`` takes a KKT residual and a solve
    more wherever a step's first correction leaves more than that (on whole-body control
    about 1e-9 of the scale, from a step far off), for the same passes and steps
    (notes/performance-history.md, "tail10")."""
    cdef double miss, rate, last_miss = INFINITY
    cdef bint refactored = False
    cdef bint loose = False   # the point is a refactored step's, refined to GUESS_TOLERANCE
    cdef Py_ssize_t changed
    cdef long step
    if _restore_kept_planes(w, p, nb[0]):
        if not _solve_guess(w, p, nf, nb[0], scale, factorizations, table, kkt, rho_vec,
                            tabled):
            return -1
        refactored = True
        loose = not tabled[0]
        nb[0] = drop_far_side(w, p, nb[0], &changed)
        if changed != 0:
            return 1
    for step in range(newton_steps):
        if not _relinearize(w, p, nb[0], &miss) or (refactored and _stalled(miss, last_miss)):
            break   # converged, at the floor that rounding leaves, or unmoved
        rate = miss / last_miss   # 0 at the first step: a chord step
        refactored = rate > CHORD_RATE or pow(rate, CHORD_STEPS) * miss > NEWTON_TOLERANCE
        if not refactored and not _chord_step(w, p, nf, nb[0], scale, table, kkt, rho_vec,
                                              tabled[0]):
            refactored = True   # the chord step crossed an apex: a Newton step instead
        if refactored and not _solve_guess(w, p, nf, nb[0], scale, factorizations, table,
                                           kkt, rho_vec, tabled):
            return -1
        loose = refactored and not tabled[0]
        last_miss = miss
        nb[0] = drop_far_side(w, p, nb[0], &changed)
        if changed != 0:
            return 1
    if loose or not refactored:   # refine the last step's (or the first solve's) point
        if tabled[0]:
            table_solve(w, p, table, kkt, rho_vec, nb[0], scale)
        else:
            refine(w, p, nf, nb[0], POLISH_REFINE_TOLERANCE * scale, factorizations)
    _multipliers(w, p, nf, nb[0])
    return 0


cdef inline bint _hopeless(Polish* w, const Problem* p, long passes) noexcept nogil:
    """Whether a warm polish's guess, stepped to from a feasible point, has more
    wrong-signed multipliers (:func:`~fccqp.polish_guess.wrong_signed`) than
    ``HOPELESS_RATE`` times the guesses left: releasing one a guess, it would run out of
    guesses unsettled and be rejected."""
    return w.warm and wrong_signed(w, p) > HOPELESS_RATE * (w.guess_passes - passes)


cdef inline bint _bare_crawl(Polish* w, const Problem* p, long passes) noexcept nogil:
    """Whether a polish from no multipliers (``bare_start``), at its first point that
    violates nothing, has more wrong-signed multipliers
    (:func:`~fccqp.polish_guess.wrong_signed`) than guesses left: releasing one a guess,
    it cannot settle. Such a polish holds every bound and block its curvature-less
    planes' points passed. At that first feasible guess 0 or 1 multipliers were wrong on
    the 18 quadruped contact-change ticks of the benchmark's sets that it settled, and
    11-18 on the three talos ticks that reached one, whose crawl (steps of length
    0-0.1, one release a guess) then ran to the warm polish's hopeless test and failed
    (talos' quick tick 54: 6 more guesses, 0.3 ms; notes/performance-history.md,
    "contactguess")."""
    return w.bare_start and wrong_signed(w, p) > w.guess_passes - passes


cdef bint polish_prepare(Polish* w, const Problem* p) noexcept nogil:
    """Set up the Schur-complement solve of :mod:`fccqp.polish_schur` for this solve's
    ``P`` and ``A``; True when it applies, and then polishing needs no table. Never on
    CSC ``P`` and ``A`` (the Schur solve reads dense storage): each guess is assembled."""
    if p.P.kind == CSC:
        w.schur.ready = False
        return False
    return polish_schur_setup(&w.schur, p, POLISH_DELTA)


cdef bint polish(Polish* w, const Problem* p, const Iterates* it, long newton_steps,
                 int* factorizations, const Reduced* table, KKT* kkt,
                 const double* rho_vec, double deadline,
                 double multiplier_slack, bint from_iterate) noexcept nogil:
    """Polish the iterate ``it`` into ``w.x``, ``w.nu``, ``w.y`` (scaled problem) and
    leave the final guess in ``w.active``; ``factorizations`` counts the ``dsytrf``
    calls. With ``table`` (the reduced form's, current for ``rho_vec`` and ``kkt``'s
    factorization) each guess is solved in its coordinates (:mod:`fccqp.polish_table`),
    else, or where that system is singular, with the guess's own KKT matrix.

    Each guess is solved once (one Newton step, curvature included) and corrected from the
    polished point (:func:`~fccqp.polish_guess.renew`), until the guess stops changing or
    ``w.guess_passes`` guesses were solved (``GUESS_PASSES``; ``WARM_GUESS_PASSES`` for a
    warm polish, see :func:`fccqp.acceptance.warm_polish`). A correction first only adds
    the violated constraints; a wrong-signed multiplier is released only from a point that violates
    nothing, and only one per pass, the most wrong (:func:`~fccqp.polish_guess.most_wrong`),
    as a primal active-set method drops one constraint at a time: changing both at once (a
    plain primal-dual active-set step) diverged on whole-body control, where the cost is
    flat on the torques and forces, and releasing every wrong-signed multiplier of a pass
    together cycled on contact switches. Once a pass's point violates nothing, and with
    ``from_iterate`` (an iterate ADMM leaves within its tolerance of ``C``) from the first
    pass on, each pass is a step of a primal active-set method: from the previous point
    toward the new guess's solution only as far as the first free constraint allows
    (:func:`~fccqp.polish_guess.step_length`), which is
    then held, and a release only from a full step: the polished QP of a wrong guess lies
    far out where the cost is flat on the forces, and jumping there swung contact forces by
    hundreds of newtons from pass to pass. Stepping from ADMM's iterate is what ends its
    slide along a face of ``C``: on talos' slowest cold ticks the iterate, solved at the
    tolerance after about 100 iterations, moves contact forces from one foot to another
    along a straight line for 500-1500 more iterations until cone blocks reach their apex;
    the first guess's solution lies past those apexes, and the step stops at the first one
    and holds it. (The measurements behind these rules are in notes/polish.md and
    notes/performance-history.md, "talosslow".) On a settled guess
    the boundary planes are then re-linearized up to ``newton_steps`` times (chord steps
    while they converge fast, see ``CHORD_RATE``), stopping early at the floor rounding
    leaves (:func:`_newton`); so are those of the last guess of a polish that did not
    settle (all its guesses, or ``cycling``) where its multipliers fit it to within
    ``multiplier_slack`` (the caller's tolerance on them, in the user's units) and its
    first solve's point violates no free constraint, and the caller then judges the
    point: go2's and solo12's polishes had ended so on the right active set, its blocks
    off their cones by up to 3e-2 N at the first solve's planes, and been rejected
    (otherwise the guess is wrong: on talos' warm ticks those steps had cost 5 % of the
    instructions, on go2's cold ones 2 %, for nothing). The slack serves a contact whose
    optimal force is all but 0: the guess flips its block between the apex, where its
    multiplier lies outside the polar cone by a thousandth of the dual tolerance, and
    the boundary, where Newton's steps throw it past the apex, and the polish ends
    ``cycling`` at the apex, the other blocks off their cones by 3e-5 at the first
    solve's planes (go2; notes/polish.md, "polishfail"). A boundary block that a solve
    puts past the apex (:func:`~fccqp.polish_guess.drop_far_side`) is held at the apex
    instead and the corrected guess solved, within the same guesses; so is a settled
    guess whose Newton steps left a multiplier wrong-signed (a plane's ``lam`` past 0: the release
    was judged on the guess's first solve), with that constraint released: polishes of
    go2's equality-constrained starts, whose planes begin with ``lam = 0``, had ended so
    in 25 of 100 and failed the caller's check (notes/performance-history.md, "The cold
    polish"). Likewise a settled guess whose Newton steps moved a free entry or block out of
    its set (the first solve's planes, at the projections of points outside their cones,
    kept it inside) holds it and solves the corrected guess: solo12's cold polishes had
    been rejected so, a free friction cone missed by 0.3 N. A polish whose points violated
    a constraint through its first ``FEASIBLE_PASSES`` guesses gives up: on talos' cold
    ticks such polishes had run all their guesses and been rejected (notes/polish.md,
    "zerostep"); not while each of its corrections only put free blocks on their boundary
    (at most one pass per block): where the cone multipliers are too small for ADMM to
    resolve (solo12, 1e-5), its guess has every block free and the polish finds the
    boundary blocks one or two a pass, kept at its fourth or fifth (notes/polish.md,
    "polishmiss"). A warm polish (``w.warm``: the previous answer's active set, which a
    tick 10 or 20 ms on changes in a dozen box entries and blocks) gives up too once a
    guess it stepped to from a feasible point has more wrong-signed multipliers than
    ``HOPELESS_RATE`` times its guesses left (:func:`_hopeless`): releasing one a guess,
    it would end unsettled and be rejected, and ADMM, which follows a rejection anyway,
    would start its guesses later (talos' every-10th ticks: 12 such polishes crawled
    through all 12 guesses at 0.4-0.5M instructions each; notes/polish.md,
    "talosexact"). False then, when a
    factorization breaks down or the result is not finite, or when the clock (:func:`fccqp_now`) has
    passed ``deadline`` before a guess after the first (``INFINITY``: never); otherwise
    the caller judges the point. A polish from no multipliers (``bare_start``) settles
    its planes by Newton's steps before it releases a boundary block's wrong ``lam``
    (:func:`_planes_first`), and gives up at its first point that violates nothing when
    that point has more wrong-signed multipliers than guesses left (:func:`_bare_crawl`).
    """
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, nb, nf = 0, j, changed
    cdef long passes = 0
    cdef int settled
    cdef double total = 0.0
    cdef double scale = max(1.0, max(inf_norm(p.q, n), inf_norm(p.b, m)))
    cdef bint tabled = table != NULL and p.P.kind == DENSE   # the table reads dense storage
    cdef bint feasible = from_iterate   # a pass's point violated nothing: from then on, steps
    cdef bint planes_only = True   # every infeasible pass only put free blocks on their boundary
    cdef Py_ssize_t held
    cdef Py_ssize_t blocking
    cdef const double* ahead
    cdef double t
    if p.P.kind == CSC:   # the curvature terms in PolishCSC's storage (n x the largest cone)
        w.hess, w.hess_stride = w.csc.hess, w.csc.hess_stride
    else:
        w.hess_stride = s
    copy(it.x, w.x, n)
    copy(it.nu, w.nu, m)
    copy(it.y, w.y, s)
    w.grad_current = False
    w.schur_failed = False
    for j in range(s):
        w.active[j] = FREE
    for j in range(p.cones.count):
        w.dropped[j] = False
        w.bare[j] = CURVED
    w.cycling = False
    if w.bare_start:   # its guesses move cone blocks pass by pass (see polish_schur._build_base)
        w.schur.border_all = True
    nb = guess(w, p, it.z, it.y, &changed)
    while True:
        w.passes = passes
        if passes > 0 and fccqp_now() > deadline:
            return False   # a time limit: the caller keeps its point
        nf = number_unknowns(w, p)
        if feasible:
            copy(w.x, w.x_prev, n)
            copy(w.nu, w.nu_prev, m)
        if not _solve_guess(w, p, nf, nb, scale, factorizations, table, kkt, rho_vec, &tabled):
            return False
        _multipliers(w, p, nf, nb)
        passes += 1
        if passes == w.guess_passes or w.cycling:   # not settled: the caller judges this point
            if most_wrong(w, p, multiplier_slack) >= 0 or leaves_set(w, p):
                # not its point: as it is
                if not tabled:
                    refine(w, p, nf, nb, POLISH_REFINE_TOLERANCE * scale, factorizations)
                    _multipliers(w, p, nf, nb)
                break
            settled = _newton(w, p, nf, &nb, newton_steps, scale, factorizations, table, kkt,
                              rho_vec, &tabled)   # else on its cones
            if settled < 0:
                return False
            if settled > 0:   # the multipliers of the block now held at its apex
                _multipliers(w, p, nf, nb)
            break
        if feasible and _hopeless(w, p, passes):
            return False
        if feasible:
            t = step_length(w, p, &blocking)
            if blocking >= 0:   # stop where the first constraint does, and hold it (all at t = 0)
                ahead = NULL
                if t == 0.0:   # renew places the blocks held from where the step pointed
                    ahead = w.grad   # scratch here: the full step's point
                    copy(w.x, w.grad, n)
                for j in range(n):
                    w.x[j] = w.x_prev[j] + t * (w.x[j] - w.x_prev[j])
                for j in range(m):
                    w.nu[j] = w.nu_prev[j] + t * (w.nu[j] - w.nu_prev[j])
                w.grad_current = False
                nb = renew(w, p, True, True, ahead, &changed)
                continue
        held = boundary_entries(w, p, nb)
        nb = renew(w, p, True, False, NULL, &changed)
        if changed == 0:
            if not feasible and _bare_crawl(w, p, passes):
                return False
            feasible = True
            if not _planes_first(w, p, nb):
                nb = renew(w, p, False, False, NULL, &changed)
        elif not feasible:
            planes_only = planes_only and changed == boundary_entries(w, p, nb) - held
            if passes >= FEASIBLE_PASSES and not planes_only:
                return False   # no guess's point was feasible yet: none of those settled in time
        if changed == 0:
            nb = drop_far_side(w, p, nb, &changed)
        if changed != 0:
            continue
        settled = _newton(w, p, nf, &nb, newton_steps, scale, factorizations, table, kkt,
                          rho_vec, &tabled)
        if settled < 0:
            return False
        if settled > 0:
            continue   # a block went past its apex: solve the corrected guess
        nb = renew(w, p, True, False, NULL, &changed)
        if changed != 0:   # Newton's planes moved a free constraint out of its set: hold it
            feasible = False   # and solve the corrected guess from this point, without a step
            continue
        if most_wrong(w, p, 0.0) >= 0:   # Newton moved a plane's multiplier past 0: release it
            nb = renew(w, p, False, False, NULL, &changed)
            continue
        break
    w.passes = passes
    for j in range(n):
        total += w.x[j]
    for j in range(m):
        total += w.nu[j]
    for j in range(s):
        total += w.y[j]
    return isfinite(total)
