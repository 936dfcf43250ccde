# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The ADMM iteration of one run: :func:`iterate`, each of its steps a function below.

Splitting: the constrained entries ``x_S`` (finite bound or cone) are copied into a
slack ``z`` that must lie in ``C`` = box x cones; the equalities stay in the x-update.
With multipliers ``y`` of ``x_S = z`` and over-relaxation ``alpha``, one iteration is

    (x~, nu) = argmin_{A x = b} 1/2 x'Px + q'x + sigma/2 ||x - x_k||^2
                                 + rho/2 ||x_S - z_k + y_k / rho||^2     (update_x)
    x_S^r    = alpha x~_S + (1 - alpha) z_k
    z_{k+1}  = P_C(x_S^r + y_k / rho)                                    (update_z)
    y_{k+1}  = y_k + rho (x_S^r - z_{k+1})                               (update_y)
    x_{k+1}  = alpha x~ + (1 - alpha) x_k     (x_1 = x~)

Unlike the paper, rho touches the constrained entries only: a free variable gets no
penalty (sigma is a 1e-6 proximal regularization of the full form; the reduced form,
:mod:`fccqp.reduced`, needs none). The first x of a run is not relaxed, because the
start (a warm start after ``b`` changed, say) may violate the equalities; from then on
every ``x_k`` is a combination of KKT solutions for the same ``b``, so ``A x = b`` holds
at every iterate. After each step, safeguarded Anderson acceleration may extrapolate
``(z, y)`` (:mod:`fccqp.anderson`). Everything here works on the scaled problem
(:mod:`fccqp.scaling`); residuals and tolerances are in the user's units
(:mod:`fccqp.termination`).
"""

from libc.limits cimport LONG_MAX
from libc.math cimport INFINITY, isfinite, log

from fccqp._dense cimport copy, fill
from fccqp._types cimport Iterates, Problem
from fccqp.acceptance cimport keep_polished, keep_restored, restore_equalities, warm_polish
from fccqp.anderson cimport anderson_reset, anderson_step
from fccqp.engine cimport (DUAL_INFEASIBLE, INACCURATE, MAX_ITER, NOT_CONVEX_QP,
                           NUMERICAL_ERROR, PRIMAL_INFEASIBLE, RUNNING, SOLVED, TIME_LIMIT,
                           Engine, Options, Run, cold_start_rho, end_run, fccqp_now,
                           measure)
from fccqp.equalities cimport hold_equalities
from fccqp.factorization cimport budget, change_rho, equality_start, factor, reduced_base
from fccqp.kkt cimport FACTORED, NOT_CONVEX, is_reduced, kkt_solve
from fccqp.polish cimport guess_changes, polish_prepare
from fccqp.projections cimport proj_set
from fccqp.scaling cimport scale_start
from fccqp.reduced cimport materialize, near_convergence, reduced_start, reduced_step
from fccqp.rho_rule cimport TrialState, new_rho, trial_reset
from fccqp.termination cimport Residuals, converged, distance, nearly_converged
from fccqp.tuning cimport (AUXILIARY_TIME, CLEANING_START, CONVERGING, EARLY_POLISH_GATE,
                           EARLY_POLISH_TRIES, EQUALITY_MISSED, GATED_CHECK_WAIT, GUESS_LEAD,
                           LOG_INTERVAL, POLISH_GATE, POLISH_RETRIES, RESERVE_PASSES,
                           RESTART_MIN_ITER, RHO_TIME_SHARE, SETTLE_ITERATIONS, SETTLE_TRIES,
                           SOLVED_GUESS_PASSES, STALL_FACTOR, STALLED_GUESS_PASSES, STALLS,
                           TIMED_EARLY_POLISH)
from fccqp.verdict cimport (check, classify, inconsistent, missed, row_missed_by_data,
                            unbounded)


cdef struct Loop:
    # The state of one run's iterations.
    double start_time       # the solve's start (fccqp_now's clock)
    double deadline         # under a time limit the iterations stop this long after start_time
    long iteration
    int status
    bint cold               # the run starts from the equality-constrained QP
    bint timed              # a time limit holds
    bint unbounded_start    # that QP is unbounded: its last step is a candidate ray
    bint warm_polish        # polish the warm start (a polished solution) before iterating
    bint reduced            # the reduced form iterates (else the full KKT form)
    bint fresh              # the next step starts a run of KKT solutions: do not relax x
    bint last, periodic, adapt, check, gated   # what this iteration does (_schedule)
    double eps_p, eps_d     # the gate's tolerances on x_S - z and the dual residual
    long wait, next_gated   # the gated check backs off: its wait, and when it may run again
    long polished_at        # the iteration of the last polish tried; -1: none
    int retries             # polishes of SOLVED iterates that failed (POLISH_RETRIES)
    int early_tries         # early polishes tried (EARLY_POLISH_TRIES)
    bint guess_polished     # the settled active set was polished early already
    bint first_check        # no early-polish check has run yet
    long settled_from       # a timed run's active set counts as settled from this iteration
    bint settle_polished    # that active set was polished already
    int settle_tries        # settled active sets polished (SETTLE_TRIES)
    bint accelerate         # Anderson acceleration is on
    int stalls              # scheduled checks in a row whose primal residual stalled
    double periodic_prim    # the primal residual at the last scheduled check
    TrialState trial        # small rho moves on trial (fccqp.rho_rule)
    long cap                # the iteration cap: max_iter, extended under a time limit (_extend)
    bint cap_polish         # the cap was just extended: polish as an untimed run's end would
    long mark_at            # the first check from this iteration records mark
    double mark             # termination.distance at that check
    long trend_from         # the iteration of the first mark; LONG_MAX before it
    double trend_start      # termination.distance there
    double best             # the lowest termination.distance at a check since then
    double last_distance    # termination.distance at the last iteration's check
    long cut                # under a time limit the clock counts as run out at this iteration


cdef long _cut_iterations = LONG_MAX
cdef long _cut_polish_charge = 0
cdef double _rho_change_charge = 0.0


def cut_after(long iterations, long failed_polish_charge=0):
    """Test hook: a clock that counts iterations, not seconds (tools/callgrind_ticks.py).

    From now on, in this process, a run under a time limit stops as if its clock had
    passed the deadline after ``iterations`` iterations, ``failed_polish_charge`` fewer
    when its warm polish was tried and failed (that polish took the budget's time):
    the clock's own stop (``_schedule``) and everything after it (the final step's
    ``POLISH_GATE``) unchanged, so that a cut is deterministic under valgrind. The wall
    clock still stops a run first when it runs out. ``cut_after(-1)`` (or any negative
    count) removes the cut.
    """
    global _cut_iterations, _cut_polish_charge
    if iterations < 0:
        _cut_iterations, _cut_polish_charge = LONG_MAX, 0
    else:
        _cut_iterations, _cut_polish_charge = iterations, max(failed_polish_charge, 0)


def charge_rho_changes(double seconds):
    """Test hook: from now on, in this process, every change of rho counts as taking
    ``seconds`` longer than it did (``Clock.rho_time``), as one that a preemption or a
    first touch of its memory interrupted does; ``charge_rho_changes(0)`` removes the
    charge. The change itself and the answers are those of an uncharged run."""
    global _rho_change_charge
    _rho_change_charge = max(seconds, 0.0)


cdef void iterate(Engine* e, Run* run, bint cold, double start_time) noexcept nogil:
    """Run ADMM from the iterate in the engine (or a cold start) to a verdict."""
    cdef Loop loop
    _begin(e, &loop, run, cold, start_time)
    if not _start(e, &loop, run):                 # the start was the answer
        return
    if not _factor_or_polish(e, &loop, run):      # the warm polish was, or no factorization
        return
    if e.prev.guessed and e.prev.from_polished and e.opt.polish:   # its polish failed
        if not _nearer_start(e, &loop, run):
            return
    _prepare(e, &loop)
    while loop.status == RUNNING:
        loop.iteration += 1
        _step(e, &loop)                           # update_x, update_z, update_y
        _track_settling(e, &loop)                 # when the active set last changed
        _schedule(e, &loop)                       # check, adapt rho, or neither
        if loop.check:
            _check(e, &loop, run)                 # residuals, termination, certificates
            _polish_attempts(e, &loop, run)
            _stall_rule(e, &loop)
            if not _adapt_rho(e, &loop, run):     # no factorization for the new rho
                return
        if loop.status == RUNNING and loop.accelerate:
            anderson_step(&e.aa, &e.it, e.prob.s)
    _final_step(e, &loop, run)


cdef inline void _begin(Engine* e, Loop* L, Run* run, bint cold, double start_time) noexcept nogil:
    """Reset the run's state; the iterations stop early enough for the final step to fit
    in the time limit: its recent duration, or ``RESERVE_PASSES`` guesses of a polish
    and what follows one that fails (restoration, ``A x = b``, unscaling, the result)."""
    cdef Options* o = &e.opt
    L.start_time = start_time
    L.cold = cold
    L.iteration = 0
    L.polished_at = -1
    L.wait = L.next_gated = 0
    L.status = RUNNING
    L.retries = L.early_tries = 0
    L.guess_polished = False
    L.first_check = True
    L.settled_from = LONG_MAX   # until the first look (_track_settling)
    L.settle_polished = False
    L.settle_tries = 0
    L.unbounded_start = False
    L.timed = isfinite(o.time_limit)
    L.cap = o.max_iter
    L.cap_polish = False
    L.mark_at = o.max_iter - o.max_iter // 2
    L.mark = L.last_distance = L.trend_start = L.best = INFINITY
    L.trend_from = LONG_MAX
    L.cut = _cut_iterations
    L.deadline = o.time_limit - min(
        max(e.clock.final_reserve, RESERVE_PASSES * e.clock.pass_time + e.clock.tail_time),
        0.5 * o.time_limit)
    run.factorizations = 0
    run.backend = e.fact.form
    trial_reset(&L.trial)
    run.polished = run.converging = False
    e.tighten = 1.0
    e.certs.stalled_prim = INFINITY
    e.certs.stalled_at = e.certs.checked_at = 0
    e.certs.checked_prim = INFINITY
    e.certs.stalled_checks = 0
    e.certs.next_cleaning = CLEANING_START
    e.certs.cleaning_wait = o.adaptive_rho_interval
    e.certs.gram_state = 0
    e.certs.row_norm = -1.0
    e.certs.weak = False
    e.fact.table_ready = False   # base is for the previous q, b
    e.pol.schur.ready = False   # set up for the previous P, A
    e.fact.kkt.schur.free_ready = False   # likewise
    e.iterated = False
    e.clock.marks[3] = e.clock.marks[4] = fccqp_now()   # phases skipped show 0


cdef inline bint _start(Engine* e, Loop* L, Run* run) noexcept nogil:
    """The cold start (:func:`fccqp.factorization.equality_start`) and what it decides
    alone: an unbounded or inconsistent QP, a start that is solved already, a QP with
    no constrained entry whose start is solved. False when the run ended here.

    A QP with no constrained entry whose start is not solved is iterated: ADMM's steps
    are then proximal steps ``x_{k+1} = argmin f + sigma/2 ||x - x_k||^2`` subject to
    ``A x = b``, which converge to an optimum of a bounded QP and, along a ray, step by
    the same direction each time (the dual certificate). Ending at 0 iterations left
    MAX_ITER_REACHED on a bounded QP whose optimum the start mistook for a ray (fuzz
    extreme_data:1100361: ``q`` of 3.8e11 orthogonal to the two rays of ``[P; A]`` to
    rounding, the optimum at 1e11)."""
    cdef Options* o = &e.opt
    cdef Residuals* r = &e.res
    cdef bint at_start = L.cold or e.prob.s == 0
    cdef int status
    if at_start:
        status = equality_start(e, run, &L.unbounded_start)
        run.factorizations += 1
        if status == NOT_CONVEX:
            run.status = NOT_CONVEX_QP
            return False
    measure(e)
    _log(e, 0, run.rho)
    if L.unbounded_start and unbounded(e):
        end_run(e, run, DUAL_INFEASIBLE, 0)
        return False
    if at_start:   # not at factorization accuracy: inconsistent or dependent rows
        e.equalities_missed = r.prim_eq > EQUALITY_MISSED * max(r.prim_eq_scale, 1.0)
        if (row_missed_by_data(e, e.work.vec_m)   # the residuals' A x
                and (inconsistent(e, True) or _least_squares_inconsistent(e))):
            # tested on the penalty-free start: with rho in the KKT matrix (up to 1e9
            # on fixed entries) the regularization's trace in A'r can hide it
            end_run(e, run, PRIMAL_INFEASIBLE, 0)
            return False
    if at_start and converged(r, o.eps_abs, o.eps_rel) and not L.unbounded_start:
        status = SOLVED
        if o.polish:   # the start carries sigma's bias where the cost is flat
            run.polished = keep_polished(e, &status, 0, L.start_time, False)
        end_run(e, run, status, 0)
        return False
    if e.prob.s == 0:  # the equality-constrained QP: the start's steps are its answer
        status = classify(e, 0, False)
        if o.polish and SOLVED <= status <= TIME_LIMIT:
            run.polished = keep_polished(e, &status, 0, L.start_time, False)
        if status == SOLVED or status == INACCURATE or o.max_iter == 0:
            end_run(e, run, status, 0)
            return False
        # not there yet: the iterations go on as proximal steps on the same problem
        # (nothing to project), from the start's point (see _start's docstring)
    return True


cdef bint _least_squares_inconsistent(Engine* e) noexcept nogil:
    """The equality certificate (:func:`fccqp.verdict.inconsistent`) at the point of
    least ``A x = b`` residual, the start's regularized solve for ``(0, b)``, in place of
    the start's ``x``: that one solves for ``-q`` too, and with ``q`` huge it carries the
    regularization's pull (``delta`` times ``q``, through ``A``), so that its residual is
    not the least-squares one and ``A'r ~ 0`` fails (the fuzzer's extreme_data:1100150,
    ``q`` of 1e16 on six inconsistent rows of rank 2: ``|b - A x|`` 0.052 where least
    squares leaves 1.7e-3, MAX_ITER_REACHED at 0 iterations). ``x`` is kept only with
    the certificate."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t n = p.n
    cdef double* saved = e.work.vec_n3   # not among inconsistent's scratch
    copy(e.it.x, saved, n)
    fill(e.work.rhs, 0.0, n)
    copy(p.b, e.work.rhs + n, p.m)
    kkt_solve(&e.fact.kkt, p, e.it.rho_vec, e.work.rhs, e.work.sol)
    copy(e.work.sol, e.it.x, n)
    if inconsistent(e, True):
        return True
    copy(saved, e.it.x, n)
    return False


cdef inline void _charge_failed_polish(Loop* L) noexcept nogil:
    """Charge a failed warm polish to the iteration cut (the clock's cut, when set)."""
    if L.cut != LONG_MAX:
        L.cut = max(L.cut - _cut_polish_charge, 0)


cdef inline bint _start_factored(const Engine* e, const Run* run) noexcept nogil:
    """Whether the cold start left the factorization for the run's rho, its table and
    ``base`` (:func:`fccqp.factorization.equality_start`), and its equalities held."""
    return e.fact.table_ready and e.fact.factored_rho == run.rho and not e.equalities_missed


cdef inline bint _factor_or_polish(Engine* e, Loop* L, Run* run) noexcept nogil:
    """Factor for the run's rho unless the factorization holds it, and the reduced
    form's ``base``; first, where it can, polish a polished warm start
    (:func:`fccqp.acceptance.warm_polish`). False when the run ended here."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t j
    cdef int code
    cdef bint polished
    for j in range(p.s):
        e.it.rho_vec[j] = run.rho * e.fact.rho_scale[j]
    L.warm_polish = e.prev.from_polished and e.opt.polish
    if not _start_factored(e, run) and (e.fact.factored_rho != run.rho or L.cold):
        if (L.warm_polish and polish_prepare(&e.pol, p)
                and (e.fact.certified or e.pol.schur.convex)):
            # polish before ADMM's factorization, which it does not need; new
            # matrices must be proven convex first, which the set-up does for free
            # where P is positive semidefinite, else the factorization below does
            e.fact.certified = True
            e.pol.schur_only = True
            polished = warm_polish(e, run, L.start_time)
            e.pol.schur_only = False
            if polished:
                return False
            # a guess that failed the check would fail again; one that the Schur
            # complement could not solve goes to the table
            L.warm_polish = e.pol.schur_failed
            if e.prev.guessed and not L.warm_polish:   # _nearer_start factors once
                _charge_failed_polish(L)
                return True
        code = factor(e, run, budget(e, 0))
        if code != FACTORED:
            run.status = NOT_CONVEX_QP if code == NOT_CONVEX else NUMERICAL_ERROR
            return False
    L.reduced = is_reduced(e.fact.form)
    if L.reduced and not e.fact.table_ready:
        reduced_base(e)
    if L.warm_polish and warm_polish(e, run, L.start_time):
        return False
    if e.prev.from_polished and e.opt.polish:   # it failed
        _charge_failed_polish(L)
    return True


cdef bint _nearer_start(Engine* e, Loop* L, Run* run) noexcept nogil:
    """After a caller's guess failed its warm polish, ADMM starts from the cold start
    (the equality-constrained QP, at a cold start's rho) unless the guess is
    ``GUESS_LEAD`` times nearer the termination test
    (:func:`fccqp.termination.distance`); the guess is scaled in again and factored for
    its rho when it wins. A carried guess across a contact change is either a few
    iterations from the answer or far slower than the cold start, and neither start
    wins everywhere. Its distance understates its cost: it is mostly the dual residual
    and gap of multipliers carried from another problem, which ADMM corrects slowly,
    while the cold start's is its primal residual alone, with multipliers at zero
    (notes/performance-history.md, "contactfall", "contactstart"). False when the run
    ended here."""
    cdef Problem* p = &e.prob
    cdef double guess_rho = run.rho, guess_distance
    e.prev.from_polished = False   # not polished again below
    measure(e)
    guess_distance = distance(&e.res, e.opt.eps_abs, e.opt.eps_rel)
    L.cold = True
    run.rho = cold_start_rho(e)
    if not _start(e, L, run):
        return False
    if distance(&e.res, e.opt.eps_abs, e.opt.eps_rel) > GUESS_LEAD * guess_distance:
        L.cold = False
        run.rho = guess_rho
        scale_start(e.prev.x, e.prev.y, e.prev.z, e.prev.rho, p.D, p.E, p.c, p.n, p.m,
                    p.s, p.constrained, p.lo, p.hi, p.cones, e.it.x, e.it.nu, e.it.y,
                    e.it.z)
        measure(e)
    return _factor_or_polish(e, L, run)


cdef inline void _prepare(Engine* e, Loop* L) noexcept nogil:
    """The iterations' own start: the reduced coordinates, the gate's tolerances,
    Anderson's memory; a setup that spent the time limit leaves no iteration."""
    cdef Options* o = &e.opt
    cdef Residuals* r = &e.res
    e.clock.marks[3] = fccqp_now()
    if L.reduced:
        reduced_start(&e.red, &e.prob, &e.it)
    L.eps_p = o.eps_abs + o.eps_rel * r.prim_set_scale   # the gate tests x_S - z
    L.eps_d = o.eps_abs + o.eps_rel * r.dual_scale
    anderson_reset(&e.aa, False)
    L.accelerate = o.anderson_memory > 0
    L.periodic_prim = INFINITY
    L.stalls = 0
    L.fresh = True
    if L.timed and o.min_iter == 0 and fccqp_now() - L.start_time >= L.deadline:
        L.status = classify(e, 0, True)   # the setup spent the budget


cdef inline void _step(Engine* e, Loop* L) noexcept nogil:
    """One ADMM iteration, in the reduced form's coordinates or with a KKT solve."""
    if L.reduced:
        reduced_step(&e.red, &e.prob, &e.it, e.opt.alpha, not L.fresh)
    else:
        _full_step(e, not L.fresh)
    L.fresh = False


cdef inline void _schedule(Engine* e, Loop* L) noexcept nogil:
    """Whether this iteration is the last, adapts rho, and is checked: every
    ``check_termination`` iterations, or in the reduced form when the gate
    (:func:`fccqp.reduced.near_convergence`) says that the check may pass."""
    cdef Options* o = &e.opt
    if L.iteration == L.cap and L.timed:
        _extend(e, L)
    L.last = L.iteration >= L.cap or (L.timed and L.iteration >= o.min_iter
                                      and (L.iteration >= L.cut
                                           or fccqp_now() - L.start_time >= L.deadline))
    L.periodic = L.iteration % o.adaptive_rho_interval == 0
    L.adapt = o.adaptive_rho and L.periodic
    L.check = L.iteration % o.check_termination == 0 or L.last or L.adapt
    L.gated = L.check and L.reduced and not (L.last or L.periodic)
    if L.gated:
        # a scheduled full check (and with it infeasibility detection) still runs
        # every adaptive_rho_interval iterations
        L.check = L.iteration >= L.next_gated and near_convergence(&e.red, &e.prob, &e.it,
                                                                   L.eps_p, L.eps_d)


cdef inline void _check(Engine* e, Loop* L, Run* run) noexcept nogil:
    """The residuals and :func:`fccqp.verdict.check`; a gate that passed where the
    check did not backs off."""
    cdef Options* o = &e.opt
    cdef Residuals* r = &e.res
    if L.reduced:
        materialize(&e.red, &e.prob, &e.it)
    measure(e)
    L.eps_p = e.tighten * (o.eps_abs + o.eps_rel * r.prim_set_scale)
    L.eps_d = e.tighten * (o.eps_abs + o.eps_rel * r.dual_scale)
    if L.iteration % LOG_INTERVAL == 0:
        _log(e, L.iteration, run.rho)
    L.status = check(e, L.iteration, L.last)
    if L.iteration >= L.mark_at:
        L.mark = L.trend_start = distance(&e.res, e.opt.eps_abs, e.opt.eps_rel)
        L.mark_at = L.trend_from = LONG_MAX
        if L.timed:
            L.trend_from = L.iteration
    elif L.iteration > L.trend_from:
        L.best = min(L.best, distance(&e.res, e.opt.eps_abs, e.opt.eps_rel))
    if L.last:
        L.last_distance = distance(&e.res, e.opt.eps_abs, e.opt.eps_rel)
    if L.gated and L.status == RUNNING:   # the gate passed, the check did not
        L.wait = min(2 * L.wait + 1, GATED_CHECK_WAIT)
        L.next_gated = L.iteration + L.wait


cdef inline void _track_settling(Engine* e, Loop* L) noexcept nogil:
    """Under a time limit, before ``TIMED_EARLY_POLISH`` iterations, every
    ``SETTLE_ITERATIONS`` steps: whether the active set ADMM's iterate points to
    (:func:`fccqp.polish.guess_changes`) changed; a new one counts as settled once it
    has held for as many iterations as the run took to reach it (:func:`_settled`). A
    cold control tick's set settles 13-47 iterations (the robots' means) before the
    check that the tolerances pass, where it used to be polished first; an early polish
    of a set that changes again later fails, and costs up to ``GUESS_PASSES`` guesses
    (talos: a guess costs about 20 iterations), so the wait grows with the run. Sampled,
    not at every step: one look costs about a tenth of one of talos' iterations."""
    if not L.timed or L.iteration >= TIMED_EARLY_POLISH or L.iteration % SETTLE_ITERATIONS:
        return
    if (guess_changes(&e.prob, e.it.z, e.it.y, e.work.guess_point, e.work.guess_codes) != 0
            or L.iteration == SETTLE_ITERATIONS):   # the first look compares with another run
        L.settled_from = 2 * L.iteration
        L.settle_polished = False


cdef inline bint _settled(const Loop* L) noexcept nogil:
    """Whether a timed run's active set has settled (:func:`_track_settling`) and is
    not polished yet, with tries left (``SETTLE_TRIES``)."""
    return (L.timed and L.iteration < TIMED_EARLY_POLISH and L.iteration >= L.settled_from
            and not L.settle_polished and L.settle_tries < SETTLE_TRIES)


cdef inline void _polish_attempts(Engine* e, Loop* L, Run* run) noexcept nogil:
    """Polish a SOLVED iterate (a failure goes on at tighter tolerances, closer to the
    active set, ``POLISH_RETRIES`` times); also polish an active set that settled near
    convergence (``EARLY_POLISH_GATE``): between two scheduled checks (every
    ``adaptive_rho_interval`` iterations), under a time limit only from
    ``TIMED_EARLY_POLISH`` iterations on (a long run needs it: PRIMALC1 of
    Maros-Meszaros, whose gap stays at 1.6 without it); before that, at a check once it
    held as long as it took to form (:func:`_settled`): a control tick's budget has no
    room for polishes of a set that moves again."""
    cdef Options* o = &e.opt
    if L.status == SOLVED and o.polish and not L.last and L.retries < POLISH_RETRIES:
        L.polished_at = L.iteration
        run.polished = _solved_polish(e, L)
        if not run.polished:   # go on, closer to the active set
            L.retries += 1
            e.tighten *= 0.1
            L.status = RUNNING
    if (L.status == RUNNING and L.periodic and o.polish and not L.last
            and (not L.timed or L.iteration >= TIMED_EARLY_POLISH)
            and L.early_tries < EARLY_POLISH_TRIES):
        if (guess_changes(&e.prob, e.it.z, e.it.y, e.work.guess_point,
                          e.work.guess_codes) != 0 or L.first_check):
            L.guess_polished = L.first_check = False   # polish it once it settles
        elif not L.guess_polished and nearly_converged(&e.res, o.eps_abs, o.eps_rel,
                                                       EARLY_POLISH_GATE):
            L.guess_polished = True
            L.early_tries += 1
            L.polished_at = L.iteration
            run.polished = keep_polished(e, &L.status, L.iteration, L.start_time, True)
    if (L.status == RUNNING and o.polish and not L.last and _settled(L)
            and nearly_converged(&e.res, o.eps_abs, o.eps_rel, EARLY_POLISH_GATE)):
        L.settle_polished = True
        L.settle_tries += 1
        L.polished_at = L.iteration
        run.polished = keep_polished(e, &L.status, L.iteration, L.start_time, True)
    if L.cap_polish and L.status == RUNNING and o.polish and not L.last:
        # an extended cap (_extend): where an untimed run ends and polishes whatever its
        # distance, this one polishes too and goes on unless that solved it
        L.cap_polish = False
        L.polished_at = L.iteration
        run.polished = keep_polished(e, &L.status, L.iteration, L.start_time, True)


cdef bint _solved_polish(Engine* e, Loop* L) noexcept nogil:
    """Polish an iterate that earned SOLVED (:func:`fccqp.acceptance.keep_polished`);
    whether the polished point was kept. Under a time limit it may take up to
    ``SOLVED_GUESS_PASSES`` guesses (the polish still stops between guesses at the
    budget): from an iterate within the tolerances each guess after the first is a step
    of a primal active-set method, and talos' cold ticks walk up to 19 of them: with 8
    the polish failed, and the run iterated, failed its retries and ended at ADMM's
    tolerance unpolished, torques 10-30 % of a joint's limit off, or reached the
    deadline (notes/performance-history.md, "talosexact: a SOLVED iterate's polish")."""
    return _polish_within(e, L, SOLVED_GUESS_PASSES if L.timed else e.pol.guess_passes)


cdef bint _polish_within(Engine* e, Loop* L, long guesses) noexcept nogil:
    """:func:`fccqp.acceptance.keep_polished` of the iterate with at most ``guesses``
    guesses; the workspace's own cap is put back after it."""
    cdef long passes = e.pol.guess_passes
    cdef bint kept
    e.pol.guess_passes = guesses
    kept = keep_polished(e, &L.status, L.iteration, L.start_time, False)
    e.pol.guess_passes = passes
    return kept


cdef inline bint _near(Engine* e, double factor) noexcept nogil:
    """Whether the iterate of a run that the clock stopped is worth its final polish:
    its four tolerance tests pass at ``factor`` times the tolerances
    (:func:`fccqp.termination.distance`). The guards that
    :func:`fccqp.termination.nearly_converged` adds whatever the factor (``x_S`` within
    1 % of its size from C in the scaled units) keep a status from promising the
    tolerances; a polished point is judged on its own (:mod:`fccqp.acceptance`), and
    the polish solves the active set exactly. On talos an entry boxed to +-1 held at
    1.07 failed the guard for 150 iterations after the four tests passed (every 5th,
    QP 75: iterations 280 to 427), where a clock stop left the run unpolished."""
    return distance(&e.res, e.opt.eps_abs, e.opt.eps_rel) <= factor


cdef inline bint _converging(const Loop* L, double now) noexcept nogil:
    """Whether the run's distance to tolerance ``now`` (:func:`fccqp.termination.distance`)
    shrank by ``CONVERGING`` since the last mark (half a ``max_iter`` before the cap,
    or the cap's last extension)."""
    return isfinite(now) and now <= CONVERGING * L.mark


cdef inline bint _on_course(const Loop* L, double now) noexcept nogil:
    """Whether the run's lowest distance to tolerance so far, falling from the first
    mark at the geometric rate it has fallen since, reaches the tolerance (distance 1)
    within the iterations' time left at the run's own time per iteration; never with
    less than ``AUXILIARY_TIME`` left, so never on a control tick."""
    cdef double elapsed = fccqp_now() - L.start_time
    cdef double left = L.deadline - elapsed
    cdef double best = min(L.best, now)
    cdef double rate   # log of the distance's factor per iteration (negative)
    if left < AUXILIARY_TIME or not (best < L.trend_start) or L.iteration <= L.trend_from:
        return False
    if best <= 1.0:
        return True
    rate = log(best / L.trend_start) / (L.iteration - L.trend_from)
    return log(best) / -rate * (elapsed / L.iteration) <= left


cdef inline void _extend(Engine* e, Loop* L) noexcept nogil:
    """Under a time limit the clock is the budget: a run at its iteration cap whose
    distance to tolerance (:func:`fccqp.termination.distance`) shrank by ``CONVERGING``
    since the last mark (half a ``max_iter`` ago), or which is on course to reach the
    tolerance before the clock stops it (:func:`_on_course`), gets half a ``max_iter``
    more, until the clock or a stall stops it (PRIMALC2 of Maros-Meszaros at 1e-6:
    SOLVED at 11,250 iterations, stopped at 4,000 before; QSCAGR7 at 1e-3, whose
    residuals fall by 1e1-1e2 over 20,000 iterations without halving in every 2,000:
    SOLVED at 76,000 iterations in 13 s of its 1,000, stopped at 8,000 before). Each extension first asks for
    the polish that ends an untimed run at its cap (``cap_polish``,
    :func:`_polish_attempts`), kept only when it solves: PRIMALC8 was solved so at
    4,000 iterations untimed and ran on past 90 s under qpbenchmark's time limit.
    """
    cdef double now = distance(&e.res, e.opt.eps_abs, e.opt.eps_rel)
    if _converging(L, now) or _on_course(L, now):
        L.cap += max(e.opt.max_iter // 2, 1)
        L.mark = now
        L.cap_polish = True


cdef inline void _stall_rule(Engine* e, Loop* L) noexcept nogil:
    """Stop Anderson acceleration where the primal residual stalls far from tolerance.

    A primal residual that does not halve between two scheduled checks far from
    tolerance is how infeasibility looks; Anderson's extrapolated points there hide
    the steady step that certifies it (CVXPY's lp_4 ran 4000 iterations uncertified),
    so plain ADMM runs on."""
    cdef Options* o = &e.opt
    cdef Residuals* r = &e.res
    if L.status == RUNNING and L.periodic and L.accelerate:
        if (r.prim > STALL_FACTOR * (o.eps_abs + o.eps_rel * r.prim_scale)
                and r.prim > 0.5 * L.periodic_prim):
            L.stalls += 1
        else:
            L.stalls = 0
        L.accelerate = L.stalls < STALLS
        L.periodic_prim = r.prim


cdef inline bint _adapt_rho(Engine* e, Loop* L, Run* run) noexcept nogil:
    """Adapt rho on its schedule (:func:`fccqp.rho_rule.new_rho`) and refactor for a
    new one (:func:`_rho_change_fits`); False, the run ended, when that factorization
    fails."""
    cdef double rho, began
    cdef int code
    if L.status == RUNNING and L.adapt and _rho_change_fits(e, L):
        rho = new_rho(&e.res, run.rho, &L.trial, e.opt.adaptive_rho_tolerance)
        if rho != run.rho:
            began = fccqp_now()
            code = change_rho(e, run, rho, L.iteration, L.reduced)
            e.clock.rho_time = fccqp_now() - began + _rho_change_charge
            if code != FACTORED:
                run.status = NOT_CONVEX_QP if code == NOT_CONVEX else NUMERICAL_ERROR
                return False
            L.reduced = is_reduced(e.fact.form)
            L.fresh = True
            L.wait = L.next_gated = 0
    return True


cdef inline bint _rho_change_fits(Engine* e, const Loop* L) noexcept nogil:
    """Whether a change of rho, at what the last one took (its factorization), ends
    before a timed run's iterations stop: one that would not leaves no iteration at the
    new rho, and ran talos' last iteration 0.1 ms past their deadline.

    The last change counts at most ``RHO_TIME_SHARE`` of the iterations' time: only a
    change measures ``Clock.rho_time`` again, and one interrupted by a preemption or
    the first touch of a new workspace's memory (talos: 4-16 ms against 0.11-0.17)
    would bar every later change of the workspace, every solve left at the rho it
    started from (notes/performance-history.md, "talosedge")."""
    return (not L.timed
            or fccqp_now() - L.start_time + min(e.clock.rho_time, RHO_TIME_SHARE * L.deadline)
            < L.deadline)


cdef inline bint _polish_fits(Engine* e, const Loop* L) noexcept nogil:
    """Whether the final polish may start: not under a time limit once an earlier
    polish of the run ran to the end of the polishes' budget (``Clock.tail_time``, see
    :func:`fccqp.acceptance.keep_polished`), which the final step's restoration needs."""
    return (not L.timed or L.polished_at < 0
            or fccqp_now() - L.start_time < e.opt.time_limit - e.clock.tail_time)


cdef inline void _final_step(Engine* e, Loop* L, Run* run) noexcept nogil:
    """After the iterations: polish the final iterate (when the clock stopped them only
    near convergence, ``POLISH_GATE``; a run that stalled at its cap has no better use
    for the time left), else restore its feasibility when the settings ask,
    else remove the rounding in ``A x = b`` that the reduced form accumulates; a
    stalled point that still misses ``A x = b`` is projected onto it."""
    cdef Options* o = &e.opt
    e.clock.marks[4] = fccqp_now()
    e.iterated = True
    if L.status == MAX_ITER and L.iteration < L.cap:
        L.status = TIME_LIMIT   # past max_iter on an extended cap (_extend): the clock stopped it
    run.converging = (L.iteration >= L.cap and o.max_iter >= RESTART_MIN_ITER
                      and _converging(L, L.last_distance))   # halves worth judging
    if (not run.polished and o.polish and SOLVED <= L.status <= TIME_LIMIT
            and L.polished_at != L.iteration and _polish_fits(e, L)
            and (not L.timed or L.iteration >= L.cap
                 or _near(e, POLISH_GATE))):
        run.polished = _final_polish(e, L)
    e.clock.polish_end = fccqp_now()
    if not run.polished:   # a polished point is feasible already: nothing to restore
        if o.restore_feasibility and SOLVED <= L.status <= TIME_LIMIT:
            L.status = keep_restored(e, L.status, L.iteration, L.reduced)
        elif (L.reduced or missed(e)) and L.status != NUMERICAL_ERROR:
            restore_equalities(e)   # certificates are already in cert
    if L.status == MAX_ITER or L.status == TIME_LIMIT:
        hold_equalities(e)   # where the KKT solves could not (fccqp.equalities)
    end_run(e, run, L.status, L.iteration)


cdef bint _final_polish(Engine* e, Loop* L) noexcept nogil:
    """Polish the final iterate (:func:`fccqp.acceptance.keep_polished`); whether the
    polished point was kept. A run stopped at ``max_iter`` may take up to
    ``STALLED_GUESS_PASSES`` guesses: its iterate is feasible to its tolerance, and each
    guess after the first is a step of a primal active-set method from it, which ends
    only once it has made every change of the active set between the iterate's face and
    the optimum's, one a guess. Where ADMM stalls far from the optimum (the multipliers
    of two nearly antiparallel active rows, an implicit equality, grow by a fixed step
    an iteration toward 1e4 times that step, the primal iterate held on a face of other
    bounds meanwhile) that takes more than ``GUESS_PASSES``, and nothing after the cap
    would use the time better. Runs stopped earlier (converged, or by the clock) keep
    ``GUESS_PASSES``, and so do runs capped below ``RESTART_MIN_ITER`` iterations: a cap
    that small is a budget (2 iterations from a random start, the polish of 32 guesses
    reached the optimum), not room for a walk."""
    if L.status != MAX_ITER or L.iteration < RESTART_MIN_ITER:
        return _polish_within(e, L, e.pol.guess_passes)
    return _polish_within(e, L, STALLED_GUESS_PASSES)


cdef void _full_step(Engine* e, bint relax_x) noexcept nogil:
    """One ADMM iteration with a KKT solve (update_x, update_z, update_y)."""
    cdef Problem* p = &e.prob
    cdef Iterates* it = &e.it
    cdef double* rhs = e.work.rhs
    cdef double* sol = e.work.sol
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, i, j
    cdef double alpha = e.opt.alpha, alpha_x = alpha if relax_x else 1.0
    cdef double sigma = e.opt.sigma
    copy(it.x, it.x_prev, n)
    copy(it.nu, it.nu_prev, m)
    copy(it.z, it.z_prev, s)
    copy(it.y, it.y_prev, s)
    for i in range(n):
        rhs[i] = sigma * it.x[i] - p.q[i]
    for i in range(m):
        rhs[n + i] = p.b[i]
    for j in range(s):
        rhs[p.constrained[j]] += it.rho_vec[j] * it.z[j] - it.y[j]
    kkt_solve(&e.fact.kkt, p, it.rho_vec, rhs, sol)
    for j in range(s):
        it.relaxed[j] = alpha * sol[p.constrained[j]] + (1.0 - alpha) * it.z_prev[j]
    for i in range(n):
        it.x[i] = alpha_x * sol[i] + (1.0 - alpha_x) * it.x_prev[i]
    copy(sol + n, it.nu, m)
    for j in range(s):
        it.z[j] = it.relaxed[j] + it.y[j] / it.rho_vec[j]
    proj_set(it.z, p.lo, p.hi, p.cones, s, it.z)
    for j in range(s):
        it.y[j] += it.rho_vec[j] * (it.relaxed[j] - it.z[j])


cdef void _log(Engine* e, long iteration, double rho) noexcept nogil:
    """A row of the solve's log (:attr:`fccqp.admm.Workspace.log_lines`)."""
    cdef double* row
    if e.log.count < e.log.capacity:
        row = e.log.rows + 5 * e.log.count
        row[0], row[1], row[2], row[3], row[4] = (
            iteration, e.res.prim, e.res.dual, e.res.gap, rho)
        e.log.count += 1
