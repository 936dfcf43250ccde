# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Whether a replacement of ADMM's iterate is kept: the polished point
(:mod:`fccqp.polish`), checked on the user's problem in the user's units, and the
feasibility restoration (:mod:`fccqp.restoration`); and the residuals of a point in
the user's units that both checks (and the returned point) are measured by.
"""

from libc.math cimport INFINITY, fabs, isfinite

from fccqp._dense cimport copy, fill
from fccqp._types cimport Iterates, Problem
from fccqp.engine cimport (INACCURATE, RUNNING, SOLVED, Engine, Options, Run, end_run,
                           fccqp_now, measure)
from fccqp.kkt cimport kkt_solve
from fccqp.matrices cimport abs_product, product, product_t
from fccqp.polish cimport polish
from fccqp.polish_guess cimport multiplier_violation
from fccqp.projections cimport proj_block, proj_set
from fccqp.restoration cimport restore
from fccqp.scaling cimport unscale
from fccqp.termination cimport Residuals, box_entry_size, gap_scale
from fccqp.tuning cimport (CYCLED_GUESS_PASSES, EQUALITY_EXACT, EQUALITY_MISSED,
                           EQUALITY_SLACK, GUESS_PASSES, POLISH_EXACT, RESTORED_EQUALITY,
                           SCALED_VIOLATION, WARM_GUESS_PASSES)
from fccqp.verdict cimport classify, missed


cdef bint keep_polished(Engine* e, int* status, long iteration, double start_time,
                        bint solved_only) noexcept nogil:
    """:func:`_try_polished`, timed: learn what a guess of a polish of ADMM's iterate
    costs (see ``RESERVE_PASSES``). A warm polish's guesses cost twice as much (no
    reduced table yet): learned from one, the reserve cut talos' next run by 0.15 ms.

    Under a time limit the polish starts no guess later than the budget less what the
    final step took after its last failed polish (``Clock.tail_time``: the restoration,
    ``A x = b`` held, the unscaling), so that a failed polish leaves that step its time:
    a polish at a check just before the iterations' deadline ran guesses to the end of
    the budget, and talos' tick then returned 0.1-0.45 ms past it."""
    cdef double began = fccqp_now()
    cdef bint kept = _try_polished(e, status, iteration, start_time, solved_only)
    if iteration > 0:   # the final step polishes ADMM's iterate, not a warm start
        e.clock.pass_time = (fccqp_now() - began) / max(e.pol.passes, 1)
    return kept


cdef bint _try_polished(Engine* e, int* status, long iteration, double start_time,
                        bint solved_only) noexcept nogil:
    """Replace the final iterate by its polished version (see :mod:`fccqp.polish`)
    when that passes a KKT check on the user's problem; True if it did.

    The polished point is accepted only when, in the user's units, it is primal
    feasible within the tolerance (box and exact cones), its multipliers lie in the
    normal cones its active set needs (:func:`fccqp.polish_guess.multiplier_violation`,
    within ``POLISH_EXACT`` of the dual tolerance), it keeps ``A x = b`` at
    factorization accuracy (``EQUALITY_SLACK``, ``EQUALITY_EXACT``) and its primal
    and dual residuals and gap are each no worse than the ADMM point's (or below
    ``POLISH_EXACT`` times their tolerance: then the ADMM point is not measured at
    all, 12k of a go2 tick's 0.79M instructions); with ``solved_only`` (the warm
    polish) it must also be solved, and where the iterate earned a solved or
    inaccurate status, so must the polished point: the tests above are the residuals',
    and the status also asks each box entry and cone block to lie within its own size
    of C in the scaled units (:func:`fccqp.termination.nearly_converged`), which a
    polished point can miss where the iterate did not (fuzz extreme_data:1100169,
    ``P`` of 9e16: an entry bounded above by -2.5e-8 polished to 1.0e-4, within the
    set tolerance of entries of 71; the iterate, solved at 11 iterations, was then
    returned NUMERICAL_ERROR). Otherwise the iterate and its residuals are left as
    they were. On acceptance the status is the polished point's when that is
    solved or inaccurate, and then the point and its residuals in ``e.unscaled`` and
    ``e.res`` are the answer (``Unscaled.current``): measuring it again for the answer
    took 1 % of a cold go2 tick's instructions.
    """
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef Options* o = &e.opt
    cdef Residuals* r = &e.res
    cdef Residuals before = e.res, plain, polished
    cdef double* ux = e.unscaled.x
    cdef double* uy = e.unscaled.y
    cdef double* uz = e.unscaled.z
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s
    cdef double tol_p, tol_d, tol_g
    cdef int new_status, factorizations = 0   # of polishing's own matrix: not counted
    cdef bint iterated = iteration > 0   # ADMM's own iterate, within its tolerance of C
    # the slack on an unsettled last guess's multipliers only where no ADMM run follows
    # a rejection: a warm polish's near-miss kept there had torques 14 % of a limit off
    # the optimum along a flat direction (solo12), where ADMM then finds the exact one
    cdef double slack = POLISH_EXACT * (o.eps_abs + o.eps_rel * r.dual_scale) if iterated else 0.0
    if not polish(&e.pol, p, it, o.polish_refine_iter, &factorizations,
                  &e.red if e.fact.table_ready else NULL, &e.fact.kkt, it.rho_vec,
                  start_time + o.time_limit - e.clock.tail_time, slack, iterated):
        return False
    unscale(e.pol.x, e.pol.nu, e.pol.y, p.D, p.E, p.c, n, m, s, p.constrained, ux, uy, uz)
    user_residuals(e, ux, uy, uz)
    tol_p = o.eps_abs + o.eps_rel * r.prim_scale
    tol_d = o.eps_abs + o.eps_rel * r.dual_scale
    tol_g = o.eps_abs + o.eps_rel * r.gap_scale
    if (r.prim <= POLISH_EXACT * tol_p and r.dual <= POLISH_EXACT * tol_d
            and r.gap <= POLISH_EXACT * tol_g
            and r.prim_eq <= EQUALITY_EXACT * r.prim_eq_scale):
        plain = e.res   # the comparisons below do not need the ADMM point's
    else:   # measure the ADMM point, then the polished one again (into the user point)
        polished = e.res
        unscale(it.x, it.nu, it.y, p.D, p.E, p.c, n, m, s, p.constrained, ux, uy, uz)
        user_residuals(e, ux, uy, uz)
        plain = e.res
        unscale(e.pol.x, e.pol.nu, e.pol.y, p.D, p.E, p.c, n, m, s, p.constrained,
                ux, uy, uz)
        e.res = polished
    new_status = classify(e, iteration, True)
    if not (r.finite
            and r.prim_eq <= o.eps_abs + o.eps_rel * r.prim_eq_scale
            and r.prim_set <= o.eps_abs + o.eps_rel * r.prim_set_scale
            and multiplier_violation(&e.pol, p, uz) <= POLISH_EXACT * tol_d
            # at EQUALITY_EXACT of max(|A x|, |b|) it is below EQUALITY_MISSED of |A||x|
            and (r.prim_eq <= EQUALITY_EXACT * r.prim_eq_scale
                 or (r.prim_eq <= EQUALITY_SLACK * plain.prim_eq
                     and r.prim_eq <= EQUALITY_MISSED * _row_terms(e, ux)))
            and (r.prim <= plain.prim or r.prim <= POLISH_EXACT * tol_p)
            and (r.dual <= plain.dual or r.dual <= POLISH_EXACT * tol_d)
            and (r.gap <= plain.gap or r.gap <= POLISH_EXACT * tol_g)
            and not (solved_only and new_status != SOLVED)
            and not (_claimed(status[0]) and not _claimed(new_status))):
        e.res = before
        return False
    _take_polished_point(e)
    if _claimed(new_status):
        status[0] = new_status
    # a claimed status ends the run: the answer is this point, unscaled and measured
    # here (its A x = b within tolerance, so judge_rounding has nothing to add)
    e.unscaled.current = _claimed(status[0])
    return True


cdef inline bint _claimed(int status) noexcept nogil:
    """Whether ``status`` claims the tolerances (``SOLVED``, ``SOLVED_INACCURATE``)."""
    return status == SOLVED or status == INACCURATE


cdef bint warm_polish(Engine* e, Run* run, double start_time) noexcept nogil:
    """Polish the warm start (a polished solution of the previous data) before any
    iteration; True, and the run finished SOLVED, when the point passes
    :func:`keep_polished`'s check and is solved.

    In a control loop the active set mostly survives a tick, and then this is the
    whole solve: no iteration (go2: 91 % of the ticks). Where ``P`` is diagonal on the
    constrained entries (whole-body control) it runs before ADMM's factorization, its
    systems solved by Schur complement on ``P``'s blocks (:mod:`fccqp.polish_schur`),
    and a success skips that factorization and the reduced table; otherwise it runs
    after them in the table's coordinates (one small LU a guess). The polished QP's
    own KKT matrix by ``dsytrf`` instead was no cheaper than the table, and dearer when
    the guess fails; polishing from every previous solution, or from an unpolished one,
    did not pay either (notes/tuning.md, "The warm polish").

    It may solve ``WARM_GUESS_PASSES`` guesses, more than another polish: the previous
    tick's active set is a few corrections from this one's, and a warm polish that
    stopped unsettled at ``GUESS_PASSES`` sent its tick to ADMM, dozens of iterations
    dearer than the guesses it lacked (notes/performance-history.md, "warmp95").
    A warm polish that ended cycling is tried once more from its own last point, one
    guess (``CYCLED_GUESS_PASSES``, :func:`_polish_again`). One whose crawl cannot release
    its wrong-signed multipliers in the guesses left gives up (``e.pol.warm``,
    ``HOPELESS_RATE``). A caller's guess carried from another structure is polished
    without its multipliers (:func:`_polish_start`).
    """
    cdef int status = RUNNING
    cdef bint kept
    e.pol.guess_passes = WARM_GUESS_PASSES
    e.pol.warm = True
    kept = _polish_start(e, &status, start_time)
    e.pol.warm = False
    if not kept and e.pol.cycling:
        e.pol.guess_passes = CYCLED_GUESS_PASSES
        kept = _polish_again(e, &status, start_time)
    e.pol.guess_passes = GUESS_PASSES
    if not kept:
        return False
    run.polished = True
    e.clock.marks[3] = e.clock.marks[4] = fccqp_now()
    end_run(e, run, SOLVED, 0)
    return True


cdef bint _polish_start(Engine* e, int* status, double start_time) noexcept nogil:
    """:func:`keep_polished` on the warm start; on a caller's guess carried from another
    structure (``e.prev.carried``) with its constraint multipliers ``y`` set to zero and
    put back when the polish fails (ADMM may start from them,
    :func:`fccqp.iteration._nearer_start`).

    Such a guess then holds nothing its slack does not lie outside of (``z`` is in
    ``C``): the first solve is the equality-constrained QP and the corrections add the
    violated bounds and cone blocks together. With the multipliers, the guess held the
    previous answer's active set; a guess carried across a contact change holds torque
    bounds and loaded feet that the new stance releases, and the polish releases one
    wrong multiplier a pass. On 16 of the benchmark's 184 contact-change ticks (mix and
    generated ``contact_switch`` sets, every one a quadruped's) that polish failed and
    ADMM ran 5-80 iterations, where the polish from nothing is kept at 0 (go2's quick
    tick 54: 3.9M instructions -> 1.5M); it loses one talos tick whose carried active
    set settled at its eleventh guess (notes/performance-history.md, "contact6"). A guess
    for the same structure (a caller passing its previous answer, as OSQP's
    ``warm_start(x, y)`` is used) keeps its multipliers, as the solver's own warm start
    does: from nothing, the polish of the benchmark's warm walks failed often enough that
    such a caller ran 10x the warm start's ADMM iterations, and a problem's own polished
    answer given back took an iteration on 16-92 % of the ticks (notes/polish.md,
    "guessheld"). The polish from nothing is marked ``bare_start``: its planes start
    without curvature, and two of its rules differ (:func:`fccqp.polish_guess.renew`,
    ``fccqp.polish._planes_first``)."""
    cdef double* held = e.work.saved   # s of it: _polish_again's scratch, not yet in use
    cdef Py_ssize_t s = e.prob.s
    cdef bint kept
    if not (e.prev.guessed and e.prev.carried):
        return keep_polished(e, status, 0, start_time, True)
    copy(e.it.y, held, s)
    fill(e.it.y, 0.0, s)
    e.pol.bare_start = True
    kept = keep_polished(e, status, 0, start_time, True)
    e.pol.bare_start = False
    if not kept:
        copy(held, e.it.y, s)
    return kept


cdef void _take_polished_point(Engine* e) noexcept nogil:
    """The polished point as the iterate: ``x``, ``nu``, ``y``, and ``z`` the projection
    of ``x_S``."""
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef Py_ssize_t j
    copy(e.pol.x, it.x, p.n)
    copy(e.pol.nu, it.nu, p.m)
    copy(e.pol.y, it.y, p.s)
    for j in range(p.s):
        it.z[j] = it.x[p.constrained[j]]
    proj_set(it.z, p.lo, p.hi, p.cones, p.s, it.z)


cdef bint _polish_again(Engine* e, int* status, double start_time) noexcept nogil:
    """Polish from the polished point of a warm polish that ended cycling (a block
    thrown past its apex, held there, released and thrown again) as from an iterate:
    its guess comes from that point's slack and multipliers, and its planes are
    linearized there, no longer where the previous tick's answer put them. True when
    :func:`keep_polished` keeps the result; otherwise the iterate, ADMM's start, is put
    back as it was. Such ticks had run ADMM for a few iterations, after which a polish
    mostly settled at its first guess on the cycling guess's boundary blocks: ADMM's
    factorization and iterations were the price of new planes. From the cycling point
    itself the guesses that were kept settled at the first one too, and those that did
    not settle took 5-12 guesses at up to 0.5M each (go2) before the tick ran ADMM
    anyway, so ``CYCLED_GUESS_PASSES`` is 1 (notes/performance-history.md,
    "talosadmm")."""
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef double* saved = e.work.saved
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s
    copy(it.x, saved, n)
    copy(it.nu, saved + n, m)
    copy(it.y, saved + n + m, s)
    copy(it.z, it.z_prev, s)   # free until ADMM's first step writes it
    _take_polished_point(e)
    if keep_polished(e, status, 0, start_time, True):
        return True
    copy(saved, it.x, n)
    copy(saved + n, it.nu, m)
    copy(saved + n + m, it.y, s)
    copy(it.z_prev, it.z, s)
    return False


cdef void restore_equalities(Engine* e) noexcept nogil:
    """Remove the rounding that a combination of KKT solutions (``x = base + W u`` in
    the reduced form, a restoration) accumulates in ``A x = b``: one refined KKT
    solve for ``(0, b - A x)`` with the current factorization. The full form needs
    it only when its iterate misses ``A x = b`` beyond factorization accuracy
    (:func:`fccqp.verdict.missed`): diverging iterates of an infeasible problem
    (``|x| = 4e6``, rho 2.4e5) left a 3.5e-7 relative error in their KKT solves'
    ``A x = b``."""
    cdef Problem* p = &e.prob
    cdef double* rhs = e.work.rhs
    cdef Py_ssize_t n = p.n, m = p.m, i
    if m == 0:
        return
    fill(rhs, 0.0, n)
    product(&p.A, e.it.x, rhs + n)
    for i in range(m):
        rhs[n + i] = p.b[i] - rhs[n + i]
    kkt_solve(&e.fact.kkt, p, e.it.rho_vec, rhs, e.work.sol)
    for i in range(n):
        e.it.x[i] += e.work.sol[i]
    for i in range(m):
        e.it.nu[i] += e.work.sol[n + i]


cdef int keep_restored(Engine* e, int status, long iteration, bint reduced) noexcept nogil:
    """Replace the final iterate by its feasibility restoration (see
    :mod:`fccqp.restoration`) when that is better.

    The restored point has its violating constrained entries pinned at their
    projection; its status comes from its own residuals, with the slack set to its
    (feasible) ``x_S``. It is kept when its primal residual shows that the other
    entries absorbed the pinning (``RESTORED_EQUALITY``) and, if the iterate was
    solved, when it is solved too. Equalities hold to factorization accuracy in
    either case.
    """
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef double* saved = e.work.saved
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, j
    cdef int new_status
    cdef bint was_missed = missed(e)
    copy(it.x, saved, n)
    copy(it.nu, saved + n, m)
    copy(it.z, saved + n + m, s)
    if restore(&e.rest, &e.fact.kkt, &e.red, reduced, p, it):
        restore_equalities(e)
        for j in range(s):
            it.z[j] = it.x[p.constrained[j]]
        proj_set(it.z, p.lo, p.hi, p.cones, s, it.z)
        measure(e)
        new_status = classify(e, iteration, True)
        if (e.res.prim <= RESTORED_EQUALITY * max(1.0, e.res.prim_scale)
                and (status != SOLVED or new_status == SOLVED)):
            return new_status
    copy(saved, it.x, n)
    copy(saved + n, it.nu, m)
    copy(saved + n + m, it.z, s)
    if reduced or was_missed:
        restore_equalities(e)
    return status


cdef double _row_terms(Engine* e, const double* x) noexcept nogil:
    """``max_i sum_j |A_ij x_j|`` on the user's data: the size of the terms whose
    rounding ``A x = b`` carries at factorization accuracy (``|A_ij x_j|`` is
    ``|A_ij| |x_j|`` exactly; ``vec_n3`` and ``vec_m2`` are its scratch)."""
    cdef Py_ssize_t i
    cdef double largest = 0.0
    for i in range(e.prob.n):
        e.work.vec_n3[i] = fabs(x[i])
    abs_product(&e.user.A, e.work.vec_n3, e.work.vec_m2)
    for i in range(e.prob.m):
        largest = max(largest, e.work.vec_m2[i])
    return largest


cdef void judge_rounding(Engine* e, const double* x) noexcept nogil:
    """``Residuals.eq_rounding`` of the returned point ``x``, just after
    :func:`user_residuals` measured it (its ``A x`` still in ``vec_m``): whether each
    row of ``A x = b`` that misses its tolerance lies within ``EQUALITY_EXACT`` of its
    terms ``|A_i| |x| + |b_i|``, the rounding no double-precision point avoids. Only
    when a row misses: the ``|A| |x|`` product would cost a warm tick, whose previous
    point (measured beside the polished one) misses the new rows, 0.25 % (go2)."""
    cdef double tolerance = e.opt.eps_abs + e.opt.eps_rel * e.res.prim_eq_scale
    e.res.eq_rounding = (e.res.prim_eq > tolerance
                         and _at_rounding(e, x, e.work.vec_m, tolerance))


cdef bint _at_rounding(Engine* e, const double* x, const double* Ax,
                       double tolerance) noexcept nogil:
    """Whether each row of ``A x = b`` (user's data, ``Ax`` given) is within
    ``tolerance`` or within ``EQUALITY_EXACT`` of its terms (``vec_n3``, ``vec_m2``:
    scratch)."""
    cdef Py_ssize_t i
    cdef double miss
    for i in range(e.prob.n):
        e.work.vec_n3[i] = fabs(x[i])
    abs_product(&e.user.A, e.work.vec_n3, e.work.vec_m2)
    for i in range(e.prob.m):
        miss = fabs(Ax[i] - e.user.b[i])
        if miss > tolerance and miss > EQUALITY_EXACT * (e.work.vec_m2[i]
                                                         + fabs(e.user.b[i])):
            return False
    return True


cdef void user_residuals(Engine* e, const double* x, const double* y,
                         const double* z) noexcept nogil:
    """:mod:`fccqp.termination`'s residuals of the returned ``(x, y, z)`` on the user's
    data, with ``dist(x_S, C)`` as the primal part off the equalities; and whether the
    point passes only on tolerances its own units do not give it: ``set_lent`` (see
    :func:`_lent`), and ``dual_lent`` when the cost's terms (the dual scale) are below
    ``eps_abs`` and the dual residual above ``eps_rel`` of them: it passes through
    ``eps_abs`` alone, as any point would (``P = 0`` and ``q`` of 1e-9: an unbounded
    problem, a second-order-cone ray, was SOLVED, fuzz extreme_data 489). Not on every
    residual that needs ``eps_abs``: an unpolished solo12 tick passed with a dual
    residual of 1.4e-5 of a scale near 1. Also the largest complementarity of a box
    entry (``|z_i|`` times the distance of ``x_i`` to the bound on ``z_i``'s side) or
    cone block (``|x_block' z_block|``) and its scale (``Residuals.compl``), which the
    summed gap can hide (:func:`fccqp.termination.nearly_converged`)."""
    cdef Problem* p = &e.prob
    cdef Residuals* r = &e.res
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, i, j, k
    cdef double eps_abs = e.opt.eps_abs, eps_rel = e.opt.eps_rel, miss, block
    cdef const double* b = e.user.b
    cdef const double* lb = e.user.lb
    cdef const double* ub = e.user.ub
    cdef const double* q = e.user.q
    cdef double* Ax = e.work.vec_m
    cdef double* grad = e.work.vec_n
    cdef double* ATy = e.work.vec_n2
    cdef double* proj = e.work.vec_s
    cdef double xPx = 0.0, qx = 0.0, by = 0.0, support = 0.0, terms = 0.0, total = 0.0
    cdef double value, size
    # the maxima in locals, not in r's fields: a store through proj or a load of x may
    # alias a field, so each field was loaded and stored again every step
    cdef double prim_eq = 0.0, prim_eq_scale = 0.0, prim_set = 0.0, prim_set_scale = 0.0
    cdef double set_s = 0.0, set_scale_s = 0.0, compl = 0.0, box_excess = -INFINITY
    cdef double dual = 0.0, dual_scale = 0.0
    cdef bint set_lent = False
    product(&e.user.A, x, Ax)
    product_t(&e.user.A, y, ATy)
    product(&e.user.P, x, grad)
    for i in range(m):
        prim_eq = max(prim_eq, fabs(Ax[i] - b[i]))
        prim_eq_scale = max(prim_eq_scale, max(fabs(Ax[i]), fabs(b[i])))
        by += b[i] * y[i]
        terms += fabs(b[i] * y[i])
    r.eq_rounding = False   # judge_rounding's, for the returned point
    for j in range(s):
        i = p.constrained[j]
        value = x[i]
        if value < lb[i]:
            value = lb[i]
        if value > ub[i]:
            value = ub[i]
        proj[j] = value
    for j in range(p.cones.count):   # cone blocks are contiguous in x too
        i = p.cones.offset[j]
        proj_block(x + p.constrained[i], p.cones.kind[j], p.cones.dim[j], p.cones.mu[j],
                   p.cones.normal + 3 * j, proj + i)
        miss = block = value = 0.0
        for k in range(i, i + p.cones.dim[j]):
            miss = max(miss, fabs(x[p.constrained[k]] - proj[k]))
            block = max(block, max(fabs(x[p.constrained[k]]), fabs(proj[k])))
            value += x[p.constrained[k]] * z[p.constrained[k]]
        set_lent |= _lent(miss, block, p.D[p.constrained[i]], eps_abs, eps_rel)
        compl = max(compl, fabs(value))
    for j in range(s):
        i = p.constrained[j]
        prim_set = max(prim_set, fabs(x[i] - proj[j]))
        prim_set_scale = max(prim_set_scale, fabs(x[i]))
        set_s = max(set_s, fabs(x[i] - proj[j]) / p.D[i])
        set_scale_s = max(set_scale_s, max(fabs(x[i]), fabs(proj[j])) / p.D[i])
        if not p.in_cone[j]:
            size = box_entry_size(max(fabs(x[i]), fabs(proj[j])), ub[i] - lb[i])
            box_excess = max(box_excess,
                             (fabs(x[i] - proj[j]) - SCALED_VIOLATION * size) / p.D[i])
            set_lent |= _lent(fabs(x[i] - proj[j]), size, p.D[i], eps_abs, eps_rel)
        if z[i] > 0.0 and isfinite(ub[i]):
            support += ub[i] * z[i]
            terms += fabs(ub[i] * z[i])
            compl = max(compl, z[i] * fabs(ub[i] - x[i]))
        elif z[i] < 0.0 and isfinite(lb[i]):
            support += lb[i] * z[i]
            terms += fabs(lb[i] * z[i])
            compl = max(compl, -z[i] * fabs(x[i] - lb[i]))
    for i in range(n):
        xPx += x[i] * grad[i]
        qx += q[i] * x[i]
        dual_scale = max(dual_scale, max(fabs(grad[i]), fabs(q[i])))
        value = grad[i] + q[i] + ATy[i] + z[i]
        dual = max(dual, fabs(value))
        total += fabs(value) + fabs(x[i]) + fabs(z[i])
    for i in range(m):
        total += fabs(y[i])
    r.prim_eq, r.prim_eq_scale, r.prim_set, r.prim_set_scale = (prim_eq, prim_eq_scale,
                                                                prim_set, prim_set_scale)
    r.set_s, r.set_scale_s, r.compl, r.box_excess = set_s, set_scale_s, compl, box_excess
    r.set_lent, r.dual, r.dual_scale = set_lent, dual, dual_scale
    r.objective = 0.5 * xPx + qx
    r.gap = fabs(xPx + qx + by + support)
    r.gap_scale = gap_scale(xPx, qx, terms)
    r.compl_scale = max(fabs(xPx), fabs(qx))
    r.prim = max(prim_eq, prim_set)
    r.prim_scale = max(prim_eq_scale, prim_set_scale)
    r.finite = isfinite(total) and isfinite(r.gap) and isfinite(r.prim)
    r.dual_lent = dual_scale < eps_abs and dual > eps_rel * dual_scale


cdef inline bint _lent(double miss, double size, double D, double eps_abs,
                       double eps_rel) noexcept nogil:
    """Whether a cone block or box entry that misses C by ``miss`` (user's units) is
    farther than ``eps_abs + eps_rel * size`` (its own ``size``), in the user's units or
    in the scaled ones (``miss / D``, ``size / D``).

    The set test of ``SOLVED`` takes the largest constrained entry as every entry's
    scale, and ``eps_abs`` is absolute: in other units than the rest, a block may pass
    on either while it misses C by a whole fraction of its own size. Three friction or
    second-order cones pinned outside their sum passed beside a one-sided entry of
    1.2e14 (``q`` huge: the cones missed by their own size) or 6.3e6 (by 1.3e-3 of it);
    a fixed entry of 0.08 missed by 4.4e-4, and a friction cone of forces 7e-3 by 5e-6,
    beside an entry of 780 (variables rescaled by 1e-8..1e8); all infeasible
    (fuzz extreme_data 2244, 1182, 900343). :class:`fccqp.Solver` then asks the
    auxiliary least-distance QP for a certificate (``Workspace.doubt``)."""
    return miss > eps_rel * size + eps_abs * min(1.0, D)
