# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The verdict on an iterate: solved, infeasible (with a certificate), unbounded, or the
budget's status, from the residuals of :mod:`fccqp.termination` and the certificates
of :mod:`fccqp.certificates`.

:func:`check` is the test after each checked iteration; :func:`classify` the status of
a point from its residuals alone; :func:`settle` the status of the returned point.
The certificates found are left in ``Engine.certs.cert``, in the user's units.
"""

from libc.math cimport fabs, isfinite, isinf, log

from fccqp._blas cimport cholesky_solve
from fccqp._dense cimport copy, fill
from fccqp._types cimport Iterates, Problem
from fccqp.certificates cimport (CERTIFIED, REJECTED, SEPARATED, WEAK,
                                 clean_primal_certificate, equality_direction,
                                 equality_inconsistent, gram_factor, primal_infeasible,
                                 row_sizes, zero_rows_inconsistent)
from fccqp.dual_certificate cimport dual_infeasible
from fccqp.equalities cimport column_gram
from fccqp.engine cimport (DUAL_INFEASIBLE, INACCURATE, MAX_ITER, NUMERICAL_ERROR,
                           PRIMAL_INFEASIBLE, RUNNING, SOLVED, TIME_LIMIT, Engine, Run,
                           fccqp_now)
from fccqp.kkt cimport is_reduced, kkt_solve
from fccqp.kkt_sparse cimport sparse_column_gram_factor, sparse_column_gram_solve
from fccqp.matrices cimport DENSE, entry, zero_column
from fccqp.reduced cimport materialize_nu_prev, materialize_x_prev
from fccqp.termination cimport Residuals, converged, nearly_converged
from fccqp.tuning cimport (CLEANING_GATE, CLEANING_HORIZON, EQUALITY_MISSED, INACCURATE_FACTOR,
                           MAX_REFINE)


cdef int check(Engine* e, long iteration, bint last) noexcept nogil:
    """Termination and infeasibility tests after the residuals of ``iteration``; in the
    reduced form ``x_prev`` and ``nu_prev`` are formed here, by the tests that read
    them."""
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef Residuals* r = &e.res
    cdef Py_ssize_t i
    cdef int code
    cdef const double* Ax = e.work.vec_m   # the residuals' A x
    if not r.finite:
        return NUMERICAL_ERROR
    if missed_by_data(e):
        if inconsistent(e, iteration % e.opt.adaptive_rho_interval == 0):
            # A x = b has no solution: no point can be SOLVED (cleaned on the schedule
            # of rho adaptation, a KKT solve each time)
            return PRIMAL_INFEASIBLE
        Ax = NULL   # the test's b - A x took its place
    if converged(r, e.tighten * e.opt.eps_abs, e.tighten * e.opt.eps_rel):
        return SOLVED
    code = REJECTED
    if _may_separate(e, iteration):
        if is_reduced(e.fact.form):
            materialize_nu_prev(&e.red, p, it)
        code = primal_infeasible(p, it, e.opt.eps_prim_inf, Ax, &e.certs.row_norm,
                                 e.work.vec_m2, e.work.vec_s, e.work.vec_n, e.work.vec_n2)
    if code == WEAK:
        _keep_weak(e)
    if code == CERTIFIED or ((code == SEPARATED or code == WEAK)
                             and iteration >= e.certs.next_cleaning
                             and iteration % e.opt.adaptive_rho_interval == 0
                             and _cleaned_certificate(e, iteration)):
        _keep_certificate(e)
        return PRIMAL_INFEASIBLE
    if is_reduced(e.fact.form):
        materialize_x_prev(&e.red, p, it)
    for i in range(p.n):
        e.certs.direction[i] = it.x[i] - it.x_prev[i]
    if unbounded(e):
        return DUAL_INFEASIBLE
    if last:
        return _last_status(e, iteration)
    return RUNNING


cdef inline void _keep_certificate(Engine* e) noexcept nogil:
    """The primal candidate in ``vec_m2``, ``vec_s`` into ``certs.cert``, in the user's
    units (the common factor 1/c dropped)."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t i
    fill(e.certs.cert, 0.0, p.n + p.m)
    for i in range(p.m):
        e.certs.cert[i] = e.work.vec_m2[i] * p.E[i]
    for i in range(p.s):
        e.certs.cert[p.m + p.constrained[i]] = e.work.vec_s[i] / p.D[p.constrained[i]]


cdef inline void _keep_weak(Engine* e) noexcept nogil:
    """Keep a ``WEAK`` primal candidate (:func:`_keep_certificate`) unless the run kept
    one already."""
    if not e.certs.weak:
        _keep_certificate(e)
        e.certs.weak = True


cdef inline int _last_status(Engine* e, long iteration) noexcept nogil:
    """:func:`classify` at the last check, but ``PRIMAL_INFEASIBLE`` with the run's first
    ``WEAK`` candidate (kept in ``certs.cert``) where the budget ran out. A weak
    candidate's residual passes at the iterate but reaches its separation at the
    data's scale, so it certifies only when the run finds no point: a feasible
    problem's run goes on to its solution (a cone's columns 1e-7 of the largest, its
    entries 20 times the iterate's at the solution, was claimed infeasible at 520
    iterations), an infeasible one ends certified as before."""
    cdef int status = classify(e, iteration, True)
    if e.certs.weak and (status == MAX_ITER or status == TIME_LIMIT):
        return PRIMAL_INFEASIBLE
    return status


cdef inline bint _may_separate(Engine* e, long iteration) noexcept nogil:
    """Whether the primal certificate test is worth its ``A' d_nu`` at this check: not
    where the primal residual, at its rate since the last check, reaches its tolerance
    within ``CLEANING_HORIZON`` times the run's iterations (:func:`_stalled`): a
    feasible run converging, however slowly. The first check, a residual at its
    tolerance (weakly infeasible problems stall there) and a residual that levels off
    or rises are tested. On talos_reduced's slow feasible ticks every check's candidate
    separated and the test cost 2.2M of a 21M tick."""
    cdef Residuals* r = &e.res
    cdef double tolerance = e.opt.eps_abs + e.opt.eps_rel * r.prim_scale
    cdef double previous = e.certs.checked_prim
    cdef long span = iteration - e.certs.checked_at
    e.certs.checked_prim = r.prim
    e.certs.checked_at = iteration
    return (not isfinite(previous) or r.prim <= tolerance
            or _stalled(r.prim, previous, span, iteration, tolerance))


cdef bint _cleaned_certificate(Engine* e, long iteration) noexcept nogil:
    """Clean the primal certificate's candidate that the last test left in ``vec_m2``,
    ``vec_s`` (:func:`fccqp.certificates.clean_primal_certificate`), on the schedule
    of rho adaptation, when the primal residual is above ``CLEANING_GATE`` times
    its tolerance and stalled over the last two such checks (:func:`_stalled`), and
    the candidate separates: how infeasibility looks, and the only case worth an ``A
    A'`` factorization (m x m, once per solve). Not before ``CLEANING_START``
    iterations, and each failed try doubles the wait before the next: a try costs
    about a hundred of talos_reduced's iterations, and its slow feasible ticks
    stall and separate too (tried at every such check, cleaning took 20 % of the
    realtime preset's warm instructions). A cleaned candidate that comes out ``WEAK``
    is kept for the last check (:func:`_keep_weak`) and counts as a failed try."""
    cdef Problem* p = &e.prob
    cdef Residuals* r = &e.res
    cdef double tolerance = e.opt.eps_abs + e.opt.eps_rel * r.prim_scale
    cdef bint stalled = _stalled(r.prim, e.certs.stalled_prim, iteration - e.certs.stalled_at,
                                 iteration, tolerance)
    cdef int code
    e.certs.stalled_prim = r.prim
    e.certs.stalled_at = iteration
    e.certs.stalled_checks = e.certs.stalled_checks + 1 if stalled else 0
    if not (p.m > 0 and e.certs.stalled_checks >= 2 and r.prim > CLEANING_GATE * tolerance):
        return False
    if e.certs.gram_state == 0:   # once per solve: A A' of this solve's scaled rows
        e.certs.gram_state = 1 if gram_factor(p, e.fact.kkt.sparse, e.certs.gram) else -1
    if e.certs.gram_state == 1:
        code = clean_primal_certificate(
            p, e.it.x, e.certs.gram, e.fact.kkt.sparse, e.opt.eps_prim_inf, e.work.vec_m2,
            e.work.vec_s, e.work.saved, e.work.vec_n3, e.work.vec_n, e.work.vec_n2)
        if code == CERTIFIED:
            return True
        if code == WEAK:
            _keep_weak(e)
    e.certs.cleaning_wait *= 2   # the next try waits twice as long
    e.certs.next_cleaning = iteration + e.certs.cleaning_wait
    return False


cdef inline bint _stalled(double prim, double previous, long span, long iteration,
                          double tolerance) noexcept nogil:
    """Whether the primal residual, falling from ``previous`` to ``prim`` over the last
    ``span`` iterations, would at that rate still miss ``tolerance`` after
    ``CLEANING_HORIZON`` times the run's ``iteration`` more: an infeasible run's
    residual levels off, a feasible one's falls geometrically, however slowly. The
    former rule (did not halve between two checks ten iterations apart) let
    talos_reduced's slow feasible ticks clean five times (tick 80 of the coarse view:
    977 iterations, 43M of its 80M instructions in cleaning)."""
    if not isfinite(previous):   # the first check that could clean: no rate yet
        return False
    if not prim < previous or span <= 0:
        return True
    if prim <= tolerance:
        return False
    return log(prim / tolerance) * span > CLEANING_HORIZON * iteration * log(previous / prim)


cdef bint missed(const Engine* e) noexcept nogil:
    """The last residuals miss ``A x = b`` beyond factorization accuracy
    (``EQUALITY_MISSED`` of their scale). Not the tolerance: rows inconsistent by
    less than ``eps_rel`` of the largest row (a duplicated row of size 2 off by 0.65
    among rows of 3e6) are no more solvable, and were left uncertified for 4000
    iterations."""
    return e.res.prim_eq > EQUALITY_MISSED * e.res.prim_eq_scale


cdef bint missed_by_data(Engine* e) noexcept nogil:
    """:func:`missed`, and also beyond ``EQUALITY_MISSED`` of each row's terms at the
    magnitude of the iterate and the box (:func:`fccqp.certificates.row_sizes`): only
    then can the equality certificate hold. Where ``b`` and ``A x`` both cancel to
    rounding noise (consistent dependent rows asking 0 with right-hand sides of
    4e-16, at a start of 1e-13), ``max(|A x|, |b|)`` alone made that a miss, and a
    public QP (QSCORPIO) was claimed infeasible. Computed only when :func:`missed`
    holds."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t i
    cdef double largest = 0.0
    if not missed(e):
        return False
    row_sizes(p, e.it.x, e.work.vec_n, e.work.vec_m2)
    for i in range(p.m):
        largest = max(largest, e.work.vec_m2[i] / p.E[i])
    return e.res.prim_eq > EQUALITY_MISSED * largest


cdef bint row_missed_by_data(Engine* e, const double* Ax) noexcept nogil:
    """Some row misses ``A x = b`` beyond ``EQUALITY_MISSED`` of its own terms:
    ``|b_i - A_i x|`` against ``max(|b_i|, |A_i x|)`` and against ``sizes_i`` (the row's
    terms at the magnitude of the iterate and the box,
    :func:`fccqp.certificates.row_sizes`), each row in its own units; ``Ax`` is ``A x``
    at the iterate (scaled, as the residuals formed it). :func:`missed_by_data`
    measures the largest miss against the largest row: rows of 1e-36 to 1e-142
    inconsistent among themselves beside a row of 1e-17 missed by 1e-38, far below 1e-9
    of that row, and the equality certificate was never tried at the start. A row
    that :func:`missed_by_data` finds missed is missed here too. ``sizes`` (all of
    ``A``) only once a row misses its own ``max(|b_i|, |A_i x|)``."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t i
    cdef double* sizes = e.work.vec_m2
    for i in range(p.m):
        if fabs(p.b[i] - Ax[i]) > EQUALITY_MISSED * max(fabs(p.b[i]), fabs(Ax[i])):
            break
    else:
        return False
    row_sizes(p, e.it.x, e.work.vec_n, sizes)
    for i in range(p.m):
        if fabs(p.b[i] - Ax[i]) > EQUALITY_MISSED * max(max(fabs(p.b[i]), fabs(Ax[i])),
                                                        sizes[i]):
            return True
    return False


cdef bint inconsistent(Engine* e, bint clean) noexcept nogil:
    """The equality certificate; on success ``cert`` holds ``(-E r, 0)``: ``A'y ~ 0`` and
    ``b'y < 0`` in the user's units.

    ``r = b_s - A_s x_s`` of a regularized KKT solution is the least-squares residual
    when ``A x = b`` has no solution, but it carries the regularization's trace:
    ``A'r = -delta A'nu``, which is large against ``r`` itself when the rows are
    inconsistent by little (``rho = 2.6e-9`` against ``delta = 5.9e-8`` on a random
    problem), or when a row is so small that ``delta`` outweighs it (rows of norm
    1e-9, ``r`` all on such a row, ``rho = 1``). With ``clean``, an ``r`` that
    separates but is not certified is cleaned by one step of inverse iteration: the
    regularized solve for ``(0, r)`` returns ``nu`` with ``-delta nu`` equal to the
    part of ``r`` in the null space of ``A'`` and the rest shrunk by ``delta /
    lambda`` (``lambda`` the eigenvalues of ``A H^-1 A'`` off that null space): the
    first problem's ``rho`` fell to 1e-17, the second's to 7e-17. That step weighs the
    columns by ``H^-1``, though: next to a ``P`` of 1e18 (columns of ``A_s`` near 1e-9)
    the KKT solves leave ``r`` orthogonal to the other columns only, and ``b - A x``
    is no least-squares residual at any ``delta``, so ``clean`` also tries
    :func:`_column_gram_direction`. Failing those, rows of ``A`` with no nonzero entry
    that ask ``b_i != 0`` are the certificate
    (:func:`fccqp.certificates.zero_rows_inconsistent`)."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t n = p.n, m = p.m, i
    cdef double* r = e.work.vec_m
    cdef int code = equality_inconsistent(p, &e.it, e.opt.eps_prim_inf, r,
                                          e.work.vec_n, e.work.vec_n2, e.work.vec_m2)
    if code == SEPARATED and clean:
        fill(e.work.rhs, 0.0, n)
        copy(r, e.work.rhs + n, m)
        kkt_solve(&e.fact.kkt, p, e.it.rho_vec, e.work.rhs, e.work.sol)
        for i in range(m):
            r[i] = -e.work.sol[n + i]
        code = equality_direction(p, r, e.it.x, e.opt.eps_prim_inf, e.work.vec_n,
                                  e.work.vec_n2, e.work.vec_m2)
    if code != CERTIFIED and clean:
        code = _column_gram_direction(e, r)
    if code != CERTIFIED and not zero_rows_inconsistent(p, r, e.work.vec_n, e.work.vec_m2):
        return False
    fill(e.certs.cert, 0.0, n + m)
    for i in range(m):
        e.certs.cert[i] = -r[i] * p.E[i]
    return True


cdef int _column_gram_direction(Engine* e, double* r) noexcept nogil:
    """:func:`fccqp.certificates.equality_direction` for ``r`` (m, filled) from inverse
    iteration on the Gram matrix ``G G'`` of ``G = diag(1/rows) A_s diag(w)``
    (:func:`fccqp.equalities.column_gram`: each column of ``A_s`` divided by its
    largest entry, so that the equilibration's column scale, which follows ``P``,
    weighs nothing): ``v := (G G' + eps I)^-1 v`` from ``v = b / rows``, ``r = v / rows``,
    tested after each of at most ``MAX_REFINE`` steps. Each step shrinks the part of
    ``v`` off the null space of ``G'`` (``A_s'r = 0``) by ``eps / (lambda + eps)``;
    ``b'r = v_0'(eps (G G' + eps I)^-1)^k v_0 > 0`` whatever the rows. On dense rows
    ``e.certs.gram`` is the factor's scratch, left to be factored again for the primal
    certificates; over compressed columns the sparse handle holds the factor
    (:func:`fccqp.kkt_sparse.sparse_column_gram_factor`)."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t m = p.m, i, step
    cdef double* rows = e.work.rhs
    cdef double* v = e.work.sol
    cdef double size
    cdef int code = REJECTED
    cdef bint dense = p.A.kind == DENSE
    if m == 0 or not (dense or e.fact.kkt.sparse != NULL):
        return REJECTED
    if dense:
        e.certs.gram_state = 0   # the scratch below is not A A'
        if not column_gram(p, e.work.vec_n, rows, e.certs.gram):
            return REJECTED
    elif not sparse_column_gram_factor(e.fact.kkt.sparse, m, rows):
        return REJECTED
    for i in range(m):
        v[i] = p.b[i] / rows[i]
    for step in range(MAX_REFINE):
        if dense:
            cholesky_solve(e.certs.gram, <int>m, <int>m, v, 1, <int>m)
        else:
            sparse_column_gram_solve(e.fact.kkt.sparse, m, v)
        size = 0.0
        for i in range(m):
            size = max(size, fabs(v[i]))
        if not (size > 0.0 and isfinite(size)):
            return REJECTED
        for i in range(m):   # normalized: each step multiplies the null part by 1/eps
            v[i] /= size
            r[i] = v[i] / rows[i]
        code = equality_direction(p, r, e.it.x, e.opt.eps_prim_inf, e.work.vec_n,
                                  e.work.vec_n2, e.work.vec_m2)
        if code != SEPARATED:
            return code
    return code


cdef bint unbounded(Engine* e) noexcept nogil:
    """The dual certificate for ``direction``; on success ``cert`` holds it, unscaled."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t i
    if not dual_infeasible(p, e.certs.direction, e.opt.eps_dual_inf, e.work.vec_n,
                           e.work.vec_n2, e.work.vec_s2, e.work.vec_n3, e.work.vec_m2):
        return False
    for i in range(p.n):
        e.certs.cert[i] = e.certs.direction[i] * p.D[i]
    return True


cdef int classify(const Engine* e, long iteration, bint stopped) noexcept nogil:
    """Status of an iterate from its residuals alone: solved, inaccurate (within
    ``INACCURATE_FACTOR`` of the tolerances), or the budget that ran out."""
    cdef const Residuals* r = &e.res
    if not r.finite:
        return NUMERICAL_ERROR
    if converged(r, e.opt.eps_abs, e.opt.eps_rel):
        return SOLVED
    if nearly_converged(r, e.opt.eps_abs, e.opt.eps_rel, INACCURATE_FACTOR):
        return INACCURATE
    if iteration >= e.opt.max_iter or not stopped:
        return MAX_ITER
    return TIME_LIMIT


cdef bint settle(Engine* e, Run* run) noexcept nogil:
    """Settle the status of a run on the residuals of the point it returns (in
    ``Engine.res``): a budget's status or a solved one becomes solved or inaccurate
    when the point is, and one that no longer passes says why; a solved or inaccurate
    one becomes unbounded when a coordinate is a ray (:func:`coordinate_ray`). True
    when that put a certificate in ``Engine.certs.cert``."""
    if run.status in (SOLVED, INACCURATE, MAX_ITER, TIME_LIMIT):
        if converged(&e.res, e.opt.eps_abs, e.opt.eps_rel):
            run.status = SOLVED
        elif nearly_converged(&e.res, e.opt.eps_abs, e.opt.eps_rel, INACCURATE_FACTOR):
            run.status = INACCURATE
        elif run.status in (SOLVED, INACCURATE):
            # the iterate passed, the returned point does not: a budget that ran out
            # says so (finite residuals are no numerical error), else the point
            # carries no guarantee
            run.status = (MAX_ITER if run.iterations >= e.opt.max_iter
                          else TIME_LIMIT if fccqp_now() - e.clock.marks[0] >= e.opt.time_limit
                          else NUMERICAL_ERROR)
    if not e.res.finite:
        run.status = NUMERICAL_ERROR
    if run.status in (SOLVED, INACCURATE) and coordinate_ray(e):
        run.status = DUAL_INFEASIBLE
        return True
    return False


cdef bint coordinate_ray(Engine* e) noexcept nogil:
    """Whether a single entry ``x_i`` outside the cones is a ray: its columns of ``P``
    and ``A`` are zero, and the dual certificate test (:func:`unbounded`) passes for
    ``-sign(q_i) e_i`` where its box is open that way. Its descent is ``|q_i|`` per
    unit of ``x_i``, which the tolerances of a solved point can hide when ``x_i``'s
    units are small (``q_i`` of 4.5e-8 on a free entry with empty columns: SOLVED where
    the problem is unbounded, fuzz extreme_data:500064), and ADMM, moving that entry by
    ``q_i / sigma`` a step, certifies it only when the other entries have settled.
    Exactly zero columns, not small ones: the equilibration leaves a column below
    ``MIN_NORM`` unscaled, and a variable in units of 1e-8 (``A``'s column 4e-9, ``q_i``
    2.5e-9) then looked like a ray of a bounded problem (extreme_data:100082). Costs a
    pass over ``P``'s diagonal when no entry has ``P_ii = 0`` and ``q_i != 0``."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t n = p.n, i, j
    cdef double sign
    for i in range(n):
        if entry(&p.P, i, i) != 0.0 or p.q[i] == 0.0 or not _empty_column(p, i):
            continue
        sign = -1.0 if p.q[i] > 0.0 else 1.0
        for j in range(p.s):
            if p.constrained[j] == i:
                break
        else:
            j = -1
        if j >= 0 and (p.in_cone[j] or not isinf(p.hi[j] if sign > 0.0 else p.lo[j])):
            continue
        fill(e.certs.direction, 0.0, n)
        e.certs.direction[i] = sign
        if unbounded(e):
            return True
    return False


cdef bint _empty_column(const Problem* p, Py_ssize_t i) noexcept nogil:
    """Whether column ``i`` of ``P`` and of ``A`` is zero."""
    return zero_column(&p.P, i) and zero_column(&p.A, i)
