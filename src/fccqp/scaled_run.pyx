# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""One run on the scaled problem: scale the user's data (or reuse the scaling), place the
start, iterate (:mod:`fccqp.iteration`); then unscale the answer into the user's arrays,
settle its status on its own residuals and keep it for the next warm start.
"""

from fccqp._dense cimport copy, fill
from fccqp._types cimport Problem
from fccqp.acceptance cimport judge_rounding, user_residuals
from fccqp.engine cimport (DUAL_INFEASIBLE, PRIMAL_INFEASIBLE, Engine, Run, cold_start_rho,
                           fccqp_now)
from fccqp.iteration cimport iterate
from fccqp.matrices cimport DENSE
from fccqp.projections cimport proj_set
from fccqp.scaling cimport equilibrate, rescale, scale_start, scaled_norms, unscale
from fccqp.scaling_csc cimport equilibrate_csc, rescale_csc, scaled_norms_csc
from fccqp.termination cimport row_spans
from fccqp.verdict cimport settle


cdef Run scaled_run(Engine* e, bint same_matrices, const double* x0, bint warm,
                    bint keep_scaling, double start_time) noexcept nogil:
    """Scale (or reuse the scaling), start, run; with ``keep_scaling`` new matrices may
    be scaled with the workspace's last equilibration (:func:`_scale`)."""
    cdef Problem* p = &e.prob
    cdef Run run
    cdef bint reuse = same_matrices and e.scaling.done
    if not same_matrices:
        e.fact.certified = False
    e.user.has_matrices = True
    e.prev.from_polished = x0 == NULL and warm and e.prev.polished
    e.unscaled.current = False
    e.clock.marks[1] = fccqp_now()
    _scale(e, reuse, keep_scaling)
    e.clock.marks[2] = fccqp_now()
    e.log.count = 0
    run.rho = e.prev.rho if warm else cold_start_rho(e)
    if x0 != NULL:
        _start_from_guess(e, x0)
    elif warm:
        scale_start(e.prev.x, e.prev.y, e.prev.z, e.prev.rho, p.D, p.E, p.c,
                    p.n, p.m, p.s, p.constrained, p.lo, p.hi, p.cones, e.it.x,
                    e.it.nu, e.it.y, e.it.z)
    if not reuse:
        e.fact.factored_rho = -1.0
    run.setup_time = fccqp_now() - start_time
    iterate(e, &run, x0 == NULL and not warm, start_time)
    return run


cdef void _scale(Engine* e, bint reuse, bint keep_scaling) noexcept nogil:
    """Equilibrate the user's data into the scaled problem; with ``reuse`` (unchanged
    matrices) apply the scaling to the new vectors only, and with ``keep_scaling``
    scale new matrices with the workspace's last equilibration
    (:func:`fccqp.scaling.rescale`) unless they drifted from it, then with the one
    before it (which becomes the current one) unless they drifted from that one too,
    else equilibrate them (the current one becoming the one before); then the rows'
    spans over the (new) box. The matrices' storage picks the passes
    (:mod:`fccqp.scaling` or :mod:`fccqp.scaling_csc`), one test per solve.

    The workspace of a structure serves every stance of its size: a trot's two
    diagonal pairs of feet, a walk's stances on three feet. Their matrices drift 30-40x
    from each other's scaling (a leg joint's column with its contact rows or without)
    and within 1.2-1.35 of the scaling their own stance gave a step earlier (solo12's
    contact_switch set), so a stance coming back rescales instead of running the Ruiz
    passes: 17k instructions instead of 90k of a 386k-instruction trot tick (callgrind).

    The scaling is the structure's, not the last answer's: a cold start (after
    ``Solver.reset()``) keeps it as a warm one does, and saves the Ruiz passes, a
    cold tick's largest fixed cost after its factorizations. Any positive ``D, E``
    give the same solution, and the drift test bounds how far this tick's norms stray
    from those the equilibration gave its own data."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t n = p.n, m = p.m, i, j
    cdef bint other
    p.P.diagonal_from = e.user.P.diagonal_from   # the scaling keeps every zero
    e.scaling.kept = True
    if reuse:
        for i in range(n):
            p.q[i] = p.c * p.D[i] * e.user.q[i]
        for i in range(m):
            p.b[i] = p.E[i] * e.user.b[i]
    elif not (keep_scaling and e.scaling.done and _rescale(e)):
        other = keep_scaling and e.scaling.other_done
        if e.scaling.done:   # the current equilibration becomes the other one
            _swap_scalings(e)
            e.scaling.other_done = True
        if not (other and _rescale(e)):
            _equilibrate(e)
            e.scaling.done = True
            e.scaling.kept = False
    for j in range(p.s):
        i = p.constrained[j]
        p.lo[j] = e.user.lb[i] / p.D[i]
        p.hi[j] = e.user.ub[i] / p.D[i]
    row_spans(p, e.scaling.d)


cdef inline bint _rescale(Engine* e) noexcept nogil:
    """The new data scaled with the previous equilibration, unless it drifted (see
    :func:`fccqp.scaling.rescale`)."""
    cdef Problem* p = &e.prob
    if p.P.kind == DENSE:
        return rescale(e.user.P.values, e.user.q, e.user.A.values, e.user.b, p.n, p.m,
                       e.user.P.diagonal_from, p.D, p.E, e.scaling.reference,
                       e.scaling.norms, p.P.values, p.q, p.A.values, p.b, &p.c)
    return rescale_csc(&e.user.P, e.user.q, &e.user.A, e.user.b, p.D, p.E,
                       e.scaling.reference, e.scaling.norms, &p.P, p.q, &p.A, p.b, &p.c)


cdef void _swap_scalings(Engine* e) noexcept nogil:
    """Exchange the current equilibration (``D, E`` and the reference norms) with the
    other kept one, entry by entry: other code holds the pointers."""
    cdef Problem* p = &e.prob
    _swap(p.D, e.scaling.other_D, p.n)
    _swap(p.E, e.scaling.other_E, p.m)
    _swap(e.scaling.reference, e.scaling.other_reference, p.n + p.m)


cdef inline void _swap(double* u, double* v, Py_ssize_t size) noexcept nogil:
    cdef Py_ssize_t i
    cdef double t
    for i in range(size):
        t = u[i]
        u[i] = v[i]
        v[i] = t


cdef inline void _equilibrate(Engine* e) noexcept nogil:
    """Copy the user's data into the scaled problem and equilibrate it; the scaled
    matrices' norms become the reference of later rescalings."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t n = p.n, m = p.m
    copy(e.user.q, p.q, n)
    copy(e.user.b, p.b, m)
    if p.P.kind == DENSE:
        copy(e.user.P.values, p.P.values, n * n)
        copy(e.user.A.values, p.A.values, m * n)
        p.c = equilibrate(p.P.values, p.q, p.A.values, p.b, n, m, e.user.block_start,
                          p.cones.dim, p.cones.count, e.opt.scaling, p.D, p.E, e.scaling.d,
                          e.scaling.e, &e.scaling.pattern)
        scaled_norms(p.P.values, p.A.values, n, m, p.c, &e.scaling.pattern,
                     e.scaling.reference)
        return
    copy(e.user.P.values, p.P.values, p.P.colptr[n])
    copy(e.user.A.values, p.A.values, p.A.colptr[n])
    p.c = equilibrate_csc(&p.P, p.q, &p.A, p.b, e.user.block_start, p.cones.dim,
                          p.cones.count, e.opt.scaling, p.D, p.E, e.scaling.d, e.scaling.e)
    scaled_norms_csc(&p.P, &p.A, p.c, e.scaling.reference)


cdef void _start_from_guess(Engine* e, const double* x0) noexcept nogil:
    """Primal guess ``x0`` (user's units), duals zero, slack its projection."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t i, j
    for i in range(p.n):
        e.it.x[i] = x0[i] / p.D[i]
    fill(e.it.nu, 0.0, p.m)
    fill(e.it.y, 0.0, p.s)
    for j in range(p.s):
        e.it.z[j] = e.it.x[p.constrained[j]]
    proj_set(e.it.z, p.lo, p.hi, p.cones, p.s, e.it.z)


cdef void unscaled_answer(Engine* e, Run* run, double* x, double* y, double* z,
                          double* cert) noexcept nogil:
    """Unscale the iterate into the result arrays, recompute its residuals in the
    user's units from the returned point alone (the primal one as the distance of
    ``x_S`` to C), settle the status on them (:func:`fccqp.verdict.settle`) and keep
    the point for a warm start."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s
    if e.unscaled.current:   # a kept polish's point: unscaled and measured already
        copy(e.unscaled.x, x, n)
        if m:
            copy(e.unscaled.y, y, m)
        copy(e.unscaled.z, z, n)
    else:
        unscale(e.it.x, e.it.nu, e.it.y, p.D, p.E, p.c, n, m, s, p.constrained, x, y, z)
        if run.status == PRIMAL_INFEASIBLE or run.status == DUAL_INFEASIBLE:
            copy(e.certs.cert, cert, n + m)
        user_residuals(e, x, y, z)
        judge_rounding(e, x)   # A x = b at the rounding of its terms, for settle
    if settle(e, run):   # a coordinate ray: its certificate replaces the point's status
        copy(e.certs.cert, cert, n)
    e.prev.exists = e.res.finite and run.status not in (PRIMAL_INFEASIBLE, DUAL_INFEASIBLE)
    if e.prev.exists:
        copy(x, e.prev.x, n)
        copy(y, e.prev.y, m)
        copy(z, e.prev.z, n)
        e.prev.rho = run.rho
        e.prev.has_rho = True
    e.prev.polished = e.prev.exists and run.polished
    e.prev.guessed = False
