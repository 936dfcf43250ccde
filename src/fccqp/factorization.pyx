# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The factorizations of a run: the backend choice and its fallback, the convexity
certificate, rho changes, and the cold start on the equality-constrained QP.

:mod:`fccqp.kkt` factors and solves one backend; this module decides which backend
serves the run (and falls back when one breaks down), keeps the reduced form's table
and ``base`` in step with the factorization, and records what it holds
(:c:type:`fccqp.engine.Factorization`).
"""

from libc.math cimport fabs

from fccqp._blas cimport cholesky, cholesky_solve_vector
from fccqp._dense cimport colmatvec, copy, fill, inf_norm, matvec
from fccqp._types cimport Iterates, Problem
from fccqp.anderson cimport anderson_reset
from fccqp.engine cimport Engine, Run
from fccqp.kkt cimport (AUTO, FACTORED, LDL_FULL, NOT_CONVEX, SCHUR_REDUCED, SPARSE_LDL,
                        UNAVAILABLE, full_form, is_reduced, kkt_convexity, kkt_factor,
                        kkt_solve)
from fccqp.matrices cimport CSC, DENSE
from fccqp.projections cimport proj_set
from fccqp.reduced cimport reduced_rebase, reduced_table
from fccqp.tuning cimport (EQUALITY_START_LIMIT, EQUALITY_START_RAY_STEP, EQUALITY_START_STEPS,
                           REDUCED_COST)


cdef long budget(const Engine* e, long iteration) noexcept nogil:
    """Solves the reduced form's table can save: the iterations left, plus, when the
    result will be restored, the columns the restoration would otherwise compute."""
    cdef long restoring = e.prob.s if e.opt.restore_feasibility else 0
    return e.opt.max_iter - iteration + restoring


cdef int _certify(Engine* e, bint schur_factored) noexcept nogil:
    """Establish convexity for the current matrices (see :func:`fccqp.kkt.kkt_convexity`);
    ``schur_factored`` says that the Schur backend has just factored them."""
    cdef int code = kkt_convexity(&e.fact.kkt, &e.prob, e.opt.sigma, e.it.rho_vec,
                                  schur_factored)
    if code == FACTORED:
        e.fact.certified = True
    return code


cdef inline bint _reduced_pays(const Engine* e, long solves) noexcept nogil:
    """Whether "auto" iterates in the reduced form: its table pays for itself within
    ``solves`` and the constrained entries are at most half the KKT size."""
    cdef const Problem* p = &e.prob
    return 2 * p.s <= p.n + p.m and REDUCED_COST * p.s <= solves


cdef int factor(Engine* e, Run* run, long solves) noexcept nogil:
    """Factor for the current rho with the backend the settings ask for, falling back
    in the order Schur, LDL' reduced, LDL' full ("auto" starts with Schur when the
    reduced table pays for itself within ``solves`` and the constrained entries are
    at most half the KKT size, else with LDL' full; every backend starts with LDL'
    full after a cold start that missed ``A x = b``). Certifies convexity when the
    matrices are new. Returns FACTORED, NOT_CONVEX, or UNAVAILABLE (numerical
    breakdown); records the form and the rho it factored. Compressed columns have one
    backend, ``SPARSE_LDL`` (:func:`_factor_sparse`)."""
    cdef Problem* p = &e.prob
    cdef int backend, code, first = e.opt.backend
    e.fact.table_ready = False
    if p.P.kind == CSC:
        return _factor_sparse(e, run)
    if e.equalities_missed:
        # rows the equality-constrained start could not meet (inconsistent, or
        # numerically dependent) go to the full form: its regularized solves give
        # least-squares iterates, on which the equality certificate is tested
        # (a random test: the reduced form ran 4000 iterations uncertified); a forced
        # reduced form too: its S is then nearly singular, and its final A x = b
        # correction moves x along the rows' near-dependence
        first = LDL_FULL
    elif first == AUTO:
        first = SCHUR_REDUCED if _reduced_pays(e, solves) else LDL_FULL
    for backend in range(first, LDL_FULL + 1):
        if not e.fact.certified and backend != SCHUR_REDUCED:
            # certify first: the certificate overwrites an LDL' factorization
            code = _certify(e, False)
            run.factorizations += 1
            if code == NOT_CONVEX:
                return NOT_CONVEX
        code = kkt_factor(&e.fact.kkt, p, backend,
                          e.opt.sigma if backend == LDL_FULL else 0.0, e.it.rho_vec)
        run.factorizations += 1
        if code != FACTORED:
            if backend == LDL_FULL:
                return UNAVAILABLE
            continue
        if not e.fact.certified and _certify(e, True) == NOT_CONVEX:
            return NOT_CONVEX
        if backend != LDL_FULL and not reduced_table(&e.red, &e.fact.kkt, p, e.it.rho_vec):
            continue
        e.fact.form = backend
        run.backend = backend
        e.fact.factored_rho = run.rho
        return FACTORED
    return UNAVAILABLE


cdef int _factor_sparse(Engine* e, Run* run) noexcept nogil:
    """:func:`factor` on compressed columns: certify convexity when the matrices are new,
    then factor the full form with ``SPARSE_LDL`` (the reduced form's table, ``(n + m)
    x s``, is too large at these sizes, so there is nothing to fall back to)."""
    cdef int code
    if not e.fact.certified:
        code = _certify(e, False)
        run.factorizations += 1
        if code == NOT_CONVEX:
            return NOT_CONVEX
    code = kkt_factor(&e.fact.kkt, &e.prob, SPARSE_LDL, e.opt.sigma, e.it.rho_vec)
    run.factorizations += 1
    if code != FACTORED:
        return UNAVAILABLE
    e.fact.form = SPARSE_LDL
    run.backend = SPARSE_LDL
    e.fact.factored_rho = run.rho
    return FACTORED


cdef void reduced_base(Engine* e) noexcept nogil:
    """``base``: the x-update's response to ``(-q, b)`` alone (q and b change every
    solve; the table only with the factorization)."""
    cdef Problem* p = &e.prob
    cdef double* rhs = e.work.rhs
    cdef Py_ssize_t i
    for i in range(p.n):
        rhs[i] = -p.q[i]
    for i in range(p.m):
        rhs[p.n + i] = p.b[i]
    kkt_solve(&e.fact.kkt, p, e.it.rho_vec, rhs, e.red.base)
    e.fact.table_ready = True


cdef int change_rho(Engine* e, Run* run, double new_rho, long iteration,
                    bint reduced) noexcept nogil:
    """Refactor for ``new_rho``: carry the reduced form's coordinates into the new
    table (before the old one is gone), factor, recompute ``base``, forget
    Anderson's memory. Returns :func:`factor`'s code."""
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef Py_ssize_t j
    cdef int code
    if reduced:
        for j in range(p.s):
            e.work.vec_s[j] = new_rho * e.fact.rho_scale[j]
        reduced_rebase(&e.red, p, it.rho_vec, e.work.vec_s)
    run.rho = new_rho
    for j in range(p.s):
        it.rho_vec[j] = new_rho * e.fact.rho_scale[j]
    code = factor(e, run, budget(e, iteration))
    if code == FACTORED:
        if is_reduced(e.fact.form):
            reduced_base(e)
        anderson_reset(&e.aa, True)
    return code


cdef int _start_factor(Engine* e) noexcept nogil:
    """Factor the cold start's KKT matrix, penalty-free but for the proximal term:
    ``P + sigma I`` with LDL', or, where the iteration will use the Schur backend,
    ``P + sigma`` on the constrained entries alone (``rho_vec = sigma``). Returns
    FACTORED or NOT_CONVEX.

    The Schur start is the iteration's own factorization with ``sigma`` for rho: its
    two Choleskys cost a fraction of the LDL' of the whole KKT matrix (go2, callgrind:
    135k against 335k instructions, a refined solve 20k against 80k), and the free
    rows it leaves serve the iteration's first factorization
    (:func:`fccqp.schur.schur_factor`). Its success proves ``P + sigma I`` positive
    definite: the QP is convex. Dependent or inconsistent rows, or a ``P`` that
    Cholesky cannot factor on the free entries, fall back to LDL', whose inertia
    decides convexity and whose regularized solves the inconsistency test reads.
    Compressed columns start with ``SPARSE_LDL``, their only backend."""
    if _schur_start(e):
        fill(e.it.rho_vec, e.opt.sigma, e.prob.s)
        if kkt_factor(&e.fact.kkt, &e.prob, SCHUR_REDUCED, 0.0, e.it.rho_vec) == FACTORED:
            return FACTORED
    fill(e.it.rho_vec, 0.0, e.prob.s)
    return FACTORED if kkt_factor(&e.fact.kkt, &e.prob, full_form(&e.prob), e.opt.sigma,
                                  e.it.rho_vec) == FACTORED else NOT_CONVEX


cdef inline bint _schur_start(const Engine* e) noexcept nogil:
    """Whether the cold start factors with the Schur backend: where the iteration will."""
    cdef int backend = e.opt.backend
    return e.prob.P.kind == DENSE and (backend == SCHUR_REDUCED or (
        backend == AUTO and _reduced_pays(e, budget(e, 0))))


cdef int _table_start(Engine* e, Run* run) noexcept nogil:
    """:func:`equality_start`'s proximal steps on the iteration's own factorization:
    Schur with ``rho`` on the constrained entries, its table ``W`` and ``base``, which
    the iteration needs anyway. Returns FACTORED (``x``, ``nu`` set, the factorization
    left for the iteration, ``table_ready``), NOT_CONVEX, or UNAVAILABLE (the caller's
    start serves: no Schur form or constrained entry, a factorization or small system
    that failed, or a candidate ray, whose direction test needs the accuracy the small
    system lacks near a ray).

    A candidate ray is a huge ``x`` (``sigma ||x|| > EQUALITY_START_LIMIT max(1,
    ||q||)``) whose last step on ``x_S`` keeps at least ``EQUALITY_START_RAY_STEP`` of
    the one before: along a ray each step adds the same multiple of it (a ray has
    entries in ``S``: ``P`` is definite on the free ones), while the steps of a bounded
    QP shrink, each of its modes by ``sigma / (lambda + sigma)``. Measured (steps 3
    over 2, infinity norms): the suite's rays 1.000, talos' huge bounded starts
    0.47-0.70 (31 of its cold cell's 101), the suite's bounded ones 0.002-0.19.

    With ``R`` the rho entries and ``D = R - sigma``, a step ``(P + sigma_S) x + A'nu =
    -q + sigma x_prev`` is ``(P + R_S) x + A'nu = -q + u``, ``u = sigma x_prev_S + D x_S``,
    so ``x = base + W u`` and ``(D^-1 - W_SS) u = D^-1 sigma x_prev_S + base_S``:
    ``W_SS`` is below ``R^-1`` where ``P`` is positive semidefinite (the constrained
    block of ``(C + R)^-1``, ``C`` the Schur complement of ``P`` on them), so the ``s x s``
    matrix is positive definite, factored once; ``A x = b`` holds as for ``base``
    (``A W_x = 0``). Only ``x_S`` is carried between steps; ``x`` and ``nu`` are formed
    once."""
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef Py_ssize_t n = p.n, s = p.s, i, j, step
    cdef double sigma = e.opt.sigma
    cdef double* M = e.work.mat_s
    cdef double* gap = e.work.vec_s      # D
    cdef double* xs = e.work.vec_s2      # x_S
    cdef double* u = e.work.rhs
    cdef double* sol = e.work.sol
    cdef double step_before = 0.0, step_last = 0.0
    if s == 0 or e.equalities_missed or not _schur_start(e):
        return UNAVAILABLE
    for j in range(s):
        it.rho_vec[j] = run.rho * e.fact.rho_scale[j]
        gap[j] = it.rho_vec[j] - sigma
        if not gap[j] > 0.0:
            return UNAVAILABLE
    if kkt_factor(&e.fact.kkt, p, SCHUR_REDUCED, 0.0, it.rho_vec) != FACTORED:
        return UNAVAILABLE
    if not e.fact.certified and _certify(e, True) == NOT_CONVEX:
        return NOT_CONVEX
    if not reduced_table(&e.red, &e.fact.kkt, p, it.rho_vec):
        return UNAVAILABLE
    for j in range(s):
        for i in range(s):
            M[i + j * s] = -e.red.W_S[j * s + i]
        M[j + j * s] += 1.0 / gap[j]
    if not cholesky(M, <int>s, <int>s):
        return UNAVAILABLE
    reduced_base(e)
    fill(xs, 0.0, s)
    for step in range(EQUALITY_START_STEPS):
        for j in range(s):
            u[j] = sigma * xs[j] / gap[j] + e.red.base[p.constrained[j]]
            sol[j] = xs[j]   # the previous x_S (sol is free until x is formed)
        cholesky_solve_vector(M, <int>s, <int>s, u)
        matvec(e.red.W_S, u, xs, s, s)
        step_before = step_last
        step_last = 0.0
        for j in range(s):
            xs[j] += e.red.base[p.constrained[j]]
            step_last = max(step_last, fabs(xs[j] - sol[j]))
    colmatvec(e.red.W, <int>(n + p.m), u, sol, n + p.m, s, 0.0)
    for i in range(n + p.m):
        sol[i] += e.red.base[i]
    if (sigma * inf_norm(sol, n) > EQUALITY_START_LIMIT * max(1.0, inf_norm(p.q, n))
            and step_last >= EQUALITY_START_RAY_STEP * step_before):
        return UNAVAILABLE
    copy(sol, it.x, n)
    copy(sol + n, it.nu, p.m)
    e.fact.form = SCHUR_REDUCED
    run.backend = SCHUR_REDUCED
    e.fact.factored_rho = run.rho
    return FACTORED


cdef int equality_start(Engine* e, Run* run, bint* unbounded) noexcept nogil:
    """Paper's cold start: ``x`` solves the QP with equalities only, ``z = P_C(x_S)``,
    ``y = 0``.

    Where the iteration uses the Schur backend the steps run on its own factorization
    for ``run.rho`` (:func:`_table_start`), which stays for the iteration; elsewhere,
    and for a candidate ray, as follows.

    The factorization (:func:`_start_factor`) carries the proximal term ``sigma`` (on
    every entry, or on the constrained ones where ``P`` is definite on the others) and
    no rho, so it certifies convexity; a few proximal steps (``x_{j+1} = argmin f +
    sigma/2 ||x - x_j||^2`` in that term's norm, on the same factorization) remove
    sigma's bias, so that an optimum with no active constraint is recognised at once.
    When the solution is huge the equality-constrained QP is unbounded:
    ``direction`` keeps the last proximal step (a candidate certificate) and the start
    falls back to the point of ``A x = b`` with the least ``x'(P + sigma) x``.

    The step, not the solution, is the direction: along a ray ``d`` (``P d = 0``,
    ``A d = 0``) each step adds the same multiple of ``d``, while the solution also
    carries its bounded part and ``A x = b``, so that ``P x`` and ``A x`` are up to
    ``1e-6`` of their terms (the suite's unbounded problems: 2e-7 to 9e-7 after
    three steps), the certificate test's own tolerance; in the step they are
    rounding (1e-16), the bounded part shrinking by ``sigma / (lambda + sigma)``
    per step. (With ``sigma`` on the constrained entries alone a ray has some: ``P``
    is definite on the free ones.)
    """
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef double* rhs = e.work.rhs
    cdef double* sol = e.work.sol
    cdef Py_ssize_t n = p.n, m = p.m, i, step
    cdef double sigma = e.opt.sigma, free_sigma
    cdef bint schur_start
    cdef int code = _table_start(e, run)
    unbounded[0] = False
    if code == NOT_CONVEX:
        return NOT_CONVEX
    if code == FACTORED:
        _iterates_from_x(e)
        return FACTORED
    e.fact.factored_rho = -1.0  # the KKT matrix now holds no rho factorization
    e.fact.form = full_form(p)
    e.fact.table_ready = False
    if _start_factor(e) != FACTORED:
        return NOT_CONVEX
    e.fact.certified = True
    schur_start = e.fact.kkt.backend == SCHUR_REDUCED   # sigma is rho_vec, on S alone
    free_sigma = 0.0 if schur_start else sigma
    fill(it.x, 0.0, n)
    for i in range(m):
        rhs[n + i] = p.b[i]
    for step in range(EQUALITY_START_STEPS):
        for i in range(n):
            rhs[i] = free_sigma * it.x[i] - p.q[i]
        if schur_start:
            for i in range(p.s):
                rhs[p.constrained[i]] += it.rho_vec[i] * it.x[p.constrained[i]]
        kkt_solve(&e.fact.kkt, p, it.rho_vec, rhs, sol)
        for i in range(n):
            e.certs.direction[i] = sol[i] - it.x[i]
        copy(sol, it.x, n)
    copy(sol + n, it.nu, m)
    unbounded[0] = sigma * inf_norm(it.x, n) > EQUALITY_START_LIMIT * max(
        1.0, inf_norm(p.q, n))
    if unbounded[0]:
        # min 1/2 x'(P + sigma) x subject to A x = b: bounded, and A x = b holds
        # for whatever status the run ends with
        fill(rhs, 0.0, n)
        kkt_solve(&e.fact.kkt, p, it.rho_vec, rhs, sol)
        copy(sol, it.x, n)
        fill(it.nu, 0.0, m)
    _iterates_from_x(e)
    return FACTORED


cdef void _iterates_from_x(Engine* e) noexcept nogil:
    """The start's ``z = P_C(x_S)``, ``y = 0``, and the previous iterates."""
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef Py_ssize_t i
    for i in range(p.s):
        it.z[i] = it.x[p.constrained[i]]
    proj_set(it.z, p.lo, p.hi, p.cones, p.s, it.z)
    fill(it.y, 0.0, p.s)
    copy(it.x, it.x_prev, p.n)
    copy(it.nu, it.nu_prev, p.m)
    copy(it.y, it.y_prev, p.s)
