# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The ADMM iteration and the one compiled call per solve.

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

:class:`Workspace` holds every array a solve touches, allocated once per problem
structure; :meth:`Workspace.solve` validates the numbers, scales, runs and unscales
without allocating and without the GIL.
"""

import numpy as np

from fccqp.result import Result
from fccqp.status import Status

from cpython.buffer cimport PyBuffer_Release
from libc.math cimport INFINITY, fabs, isfinite, sqrt

from fccqp._dense cimport copy, fill, inf_norm, matvec, matvec_t
from fccqp._types cimport Cones, Iterates, Problem
from fccqp.blas_threads cimport enter, leave
from fccqp.anderson cimport Anderson, anderson_reset, anderson_step
from fccqp.certificates cimport (CERTIFIED, SEPARATED, clean_primal_certificate,
                                 dual_infeasible, equality_direction, equality_inconsistent,
                                 gram_factor, magnitudes, primal_candidate,
                                 primal_infeasible, row_size)
from fccqp.fast_checks cimport hold_dense, hold_float64
from fccqp.kkt cimport (AUTO, FACTORED, KKT, LDL_FULL, LDL_REDUCED, NOT_CONVEX, SCHUR_REDUCED,
                        UNAVAILABLE, kkt_convexity, kkt_factor, kkt_solve)
from fccqp.polish cimport Polish, guess_changes, multiplier_violation, polish, polish_prepare
from fccqp.projections cimport proj_block, proj_set
from fccqp.reduced cimport (Reduced, materialize, near_convergence, reduced_rebase,
                            reduced_start, reduced_step, reduced_table)
from fccqp.restoration cimport Restoration, restore
from fccqp.scaling cimport equilibrate, rescale, scale_start, scaled_norms, unscale
from fccqp.termination cimport (Residuals, converged, gap_scale, nearly_converged, residuals,
                               row_spans)
from fccqp.validation cimport (BOUNDED, FIXED_BOUND, SCAN_OK, UNBOUNDED, Finding, bound_kind,
                               scan_and_copy)

cdef extern from "fccqp_clock.h" nogil:
    double fccqp_now()

# Run codes, mapped to fccqp.Status in fccqp.solver (one table).
SOLVED, SOLVED_INACCURATE, MAX_ITER, TIME_LIMIT = 1, 2, 3, 4
PRIMAL_INFEASIBLE, DUAL_INFEASIBLE, NUMERICAL_ERROR = 5, 6, 7
NOT_CONVEX_CODE = -1
"""The KKT inertia shows that the QP is not convex."""
BAD_DATA = -2
"""The validation scan found bad numbers (see ``Workspace.finding``)."""
STRUCTURE_CHANGED = -3
"""The bounds no longer have the structure the workspace was made for (another set of
constrained or fixed entries, or a bound on a cone entry): the caller rescans them
(:func:`fccqp.validation.structure_scan`) and makes a new workspace."""
NOT_DENSE = -4
"""An input array is not a C-contiguous float64 numpy array of the workspace's shape
(:meth:`Workspace.solve` with ``checked=False``): the caller converts the arguments."""
STATUS_BY_CODE = {
    SOLVED: Status.SOLVED,
    SOLVED_INACCURATE: Status.SOLVED_INACCURATE,
    MAX_ITER: Status.MAX_ITER_REACHED,
    TIME_LIMIT: Status.TIME_LIMIT_REACHED,
    PRIMAL_INFEASIBLE: Status.PRIMAL_INFEASIBLE,
    DUAL_INFEASIBLE: Status.DUAL_INFEASIBLE,
    NUMERICAL_ERROR: Status.NUMERICAL_ERROR,
}
"""The run codes as statuses: the only place they meet."""
cdef enum:
    _CONE_ENTRY = 3   # beside fccqp.validation's bound_kind codes
cdef enum:
    _RUNNING = 0
    _SOLVED = 1
    _INACCURATE = 2
    _MAX_ITER = 3
    _TIME_LIMIT = 4
    _PRIMAL_INFEASIBLE = 5
    _DUAL_INFEASIBLE = 6
    _NUMERICAL_ERROR = 7
    _NOT_CONVEX = -1
    _BAD_DATA = -2
    _STRUCTURE_CHANGED = -3

BACKENDS = {"schur_reduced": SCHUR_REDUCED, "ldl_reduced": LDL_REDUCED, "ldl_full": LDL_FULL,
            "auto": AUTO}
"""``Settings.kkt_backend`` names and their codes (see :mod:`fccqp.kkt`)."""
BACKEND_NAMES = {code: name for name, code in BACKENDS.items()}

INACCURATE_FACTOR = 10.0
"""A budget-stopped iterate within this multiple of the tolerances is 'inaccurate'."""
RHO_MIN, RHO_MAX = 1e-6, 1e6
"""Range of the adaptive rho."""
REDUCED_COST = 0.5
"""The reduced iteration is used when ``REDUCED_COST * s`` fits in the iteration budget:
tabulating ``s`` columns costs about ``s / 4`` single KKT solves (measured at KKT sizes
84 and 192), each iteration then saves about one; 0.5 leaves a factor 2 of margin."""
FIXED_RHO_SCALE = 1e3
"""rho multiplier on entries with lb == ub, which act as equalities (as in OSQP)."""
EQUALITY_START_STEPS = 3
"""Proximal steps of the cold start's equality-constrained QP (see _equality_start)."""
EQUALITY_START_LIMIT = 1e-3
"""The cold start's equality-constrained QP counts as unbounded when sigma * ||x_eq||
exceeds this * max(1, ||q||): its last proximal step is then an (unbounded) direction,
tested as a dual infeasibility certificate, and the start falls back onto A x = b."""
RESTORED_EQUALITY = 1e-7
"""A restored point is kept only if its primal residual is below this times its scale:
otherwise the other entries could not absorb the pinning. Refinement aims at 1e-13, but
an ill-conditioned ``W_TT`` (condition 1e8 on solo12) costs digits."""
STALL_FACTOR, STALLS = 1e3, 2
"""Anderson acceleration stops for the rest of a run when, at ``STALLS`` scheduled checks
in a row, the primal residual is above ``STALL_FACTOR`` times its tolerance and not half
of what it was at the previous scheduled check (see _iterate)."""
CLEANING_START = 500
"""No primal certificate is cleaned before this many iterations of a run (see
``Workspace._cleaned_certificate``)."""
RESTART_MIN_ITER = 200
"""A start from a previous solution or ``x0`` that fails within half of ``max_iter``
restarts cold for the rest only when ``max_iter`` is at least this (``Workspace._run``)."""
CLEANING_GATE = 1.0
"""A primal certificate's candidate is cleaned only while the primal residual is above
this many times its tolerance (see ``Workspace._cleaned_certificate``): weakly
infeasible problems stall near it (rows off two friction cones by 1e-4 at 10 times)."""
GATED_CHECK_WAIT = 8
"""In the reduced form a full residual check runs between the scheduled ones only when
``near_convergence`` says that it may pass; after a gated check that did not end the run
(a gap still open where the residuals already pass, say) the next one waits 1, 3, 7
iterations, then this many, until a scheduled check or a new rho. A full check (residuals,
gap, infeasibility tests) costs about 60k instructions on talos_reduced, an iteration
about 25k, and its cold solves ran one every other iteration: 80 in 218 iterations,
a fifth of the solve."""
POLISH_RETRIES = 2
"""When ADMM converges but its polished point is rejected, ADMM goes on with 10x tighter
tolerances and polishes again, at most this many times (the budgets still apply): on
talos' hardest controller sequence, 13 of 22 cold solves polished at eps 1e-5, 17 at
1e-6, 21 at 1e-7."""
POLISH_EXACT = 1e-3
"""A polished residual counts as no worse than ADMM's when it is below this times its
tolerance (rounding of an exact solve), and its multipliers may miss their cones by
this times the dual tolerance."""
LOG_INTERVAL = 25
"""With ``verbose``, the log keeps one line every this many iterations (as OSQP)."""
EQUALITY_SLACK = 10.0
EQUALITY_EXACT = 1e-13
"""A polished point keeps ``A x = b`` as ADMM's iterates do, at factorization accuracy:
within ``EQUALITY_SLACK`` times the ADMM point's residual, or below ``EQUALITY_EXACT``
times ``max(||A x||, ||b||)``, and never beyond ``EQUALITY_MISSED`` times the largest
row of ``|A| |x|``. (The tolerance alone let a polished point with ``A x - b`` at 2e-9
of its terms pass as SOLVED in a random test; the slack alone one at 8e-9 where the
ADMM point, a reduced form's combination ``base + W u`` with a wild ``u`` before its
final correction, missed by 1e-9.)"""
cdef double _EQUALITY_SLACK = EQUALITY_SLACK
cdef double _EQUALITY_EXACT = EQUALITY_EXACT
EQUALITY_MISSED = 1e-9
"""The equality-constrained cold start meets ``A x = b`` to factorization accuracy
(1e-14 of ``max(||A x||, ||b||)`` or better) unless the rows are inconsistent or
numerically dependent; beyond this the "auto" backend takes the full form."""
cdef double _EQUALITY_MISSED = EQUALITY_MISSED
POLISH_GATE = 1e3
"""A run under a time limit is polished at its end only when its residuals are within
this factor of the tolerances: farther out the iterate's active set is mostly wrong
(talos' realtime sequences, stopped after 0-30 iterations: 6 guesses changing 14-33
entries each, 1 ms, never accepted), and the time is better spent iterating. Without a
time limit the polish is tried whatever the residuals: after 4000 iterations on a
degenerate LP it is what finds the answer (2 of the general suite's 60)."""
cdef double _POLISH_GATE = POLISH_GATE
EARLY_POLISH_GATE = 1e2
EARLY_POLISH_TRIES = 3
"""ADMM converges slowly along the weakly determined directions of whole-body control's
costs (torque and force weights of 1e-4 to 1e-6) long after its active set has settled.
So at a scheduled check (every ``adaptive_rho_interval`` iterations) whose residuals are
within ``EARLY_POLISH_GATE`` of the tolerances, the run polishes early when the active
set ADMM's iterate points to (:func:`fccqp.polish.guess_changes`) is the one of the
previous scheduled check and was not polished yet; it ends there when the polished
point passes the KKT check and is solved. At most ``EARLY_POLISH_TRIES`` such attempts
per solve, and none under a time limit: on talos at the realtime preset's 2 ms a failed
polish of its 64-row systems takes the time the next iterations need (success 87-89 %
against 96 % when every settled guess was tried; with a rule that tried only while
twice the final step's reserve fit, 94.5 % against 95.2 % over nine alternating runs).
Measured on talos' first 100 ticks at default settings (callgrind): 9.07M instructions
per tick without, 6.99M with a gate of 1e2, 7.41M with 1e3, 7.96M with 1e4; mean
iterations 63 -> 25 over all 200 ticks, the worst gap unchanged."""
cdef double _EARLY_POLISH_GATE = EARLY_POLISH_GATE
cdef int _EARLY_POLISH_TRIES = EARLY_POLISH_TRIES
RESERVE_DECAY = 0.5
"""Under a time limit the iterations stop when the time left is what the final step
(polish or restoration, and unscaling) took lately: the largest of its last durations,
each weighted by this factor once per solve since (those that end without an iteration
too: on talos a slow final step was otherwise remembered through a run of warm-polished
ticks and cut the next run's iterations to half the budget). At most half the budget is
reserved; the polish itself stops between guesses once the budget is spent."""
cdef double _RESERVE_DECAY = RESERVE_DECAY
RESERVE_PASSES = 2
"""The final step's reserve is at least this many guesses of the polish, at what a guess
of the last polish cost: a run that a time limit stops polishes an iterate short of
convergence, whose guess needs correcting. On talos_reduced's tick 73 (a contact
switch) the polish of ADMM's iterate after 250 to 400 iterations took 2 guesses and
was exact; with a reserve learned from the cheap one-guess polishes of the ticks
before, the clock cut it after the first and the tick returned a gap of 0.05-0.1 at
1.5 ms (and up to 0.04 at 2 ms)."""
cdef double _RESERVE_PASSES = RESERVE_PASSES
RHO_PERSISTENCE = 5
"""Updates in a row (each ``adaptive_rho_interval`` iterations) after which a rho move
that OSQP's rule keeps asking for, by more than the square root of
``adaptive_rho_tolerance`` but less than the tolerance, is tried (see _rho_trial): the
tolerance keeps rho from chasing noise, but an imbalance that persists while the
residuals do not even halve is no noise. On talos_reduced's tick 73 (a contact switch)
the rule asked for 3.5x for 550 iterations and the warm run took 660; with the move,
355. A move whose residuals then fall more slowly than before is undone (talos' tick
288 went 181 -> 1214 iterations, rho 100x down in moves that were not undone).
Measured over each robot's 400 ticks, total iterations without / with: default preset
solo12 19391 / 5026, talos 8811 / 8806, go2 and anymal_c unchanged;
``Settings.realtime(1.0)`` talos 5513 / 5017, the quadrupeds unchanged. At the
realtime preset's 2 ms, talos missed the objective-gap target (1e-3) in 2 of 12 and 1
of 12 alternating passes, at 1.5 ms in 7 of 8 and 4 of 8; with 3 updates instead of 5
it lost more ticks (talos 7113 iterations). On the general-QP suite 7 of 543 problems
changed, 6 to fewer iterations (1510 -> 580 at most), one 267 -> 369."""
cdef int _RHO_PERSISTENCE = RHO_PERSISTENCE
cdef double _INACCURATE_FACTOR = INACCURATE_FACTOR
cdef double _REDUCED_COST = REDUCED_COST
cdef double _RHO_MIN = RHO_MIN, _RHO_MAX = RHO_MAX
cdef double _EQUALITY_START_LIMIT = EQUALITY_START_LIMIT
cdef double _RESTORED_EQUALITY = RESTORED_EQUALITY
cdef double _POLISH_EXACT = POLISH_EXACT
cdef int _POLISH_RETRIES = POLISH_RETRIES
cdef long _GATED_CHECK_WAIT = GATED_CHECK_WAIT
cdef long _EQUALITY_START_STEPS = EQUALITY_START_STEPS
cdef long _LOG_INTERVAL = LOG_INTERVAL
cdef double _STALL_FACTOR = STALL_FACTOR
cdef double _CLEANING_GATE = CLEANING_GATE
cdef long _RESTART_MIN_ITER = RESTART_MIN_ITER
cdef long _CLEANING_START = CLEANING_START
cdef int _STALLS = STALLS


cdef struct Options:
    # Settings of fccqp.Settings the kernels read.
    double rho, sigma, alpha, eps_abs, eps_rel, eps_prim_inf, eps_dual_inf
    double time_limit, adaptive_rho_tolerance
    long max_iter, min_iter, check_termination, adaptive_rho_interval, scaling, polish_refine_iter
    bint adaptive_rho, restore_feasibility, polish
    int backend, anderson_memory


cdef struct TrialState:
    # A rho move smaller than adaptive_rho_tolerance, asked for again and again (_rho_trial).
    int side          # +1 (up) or -1 (down): the way the current streak asks; 0: none
    int count         # updates in the streak, or since the move on trial
    double start      # larger relative residual at the streak's (or the trial's) first
    double progress   # its fall over the streak that made the move (a factor below 1)
    double old_rho    # the rho before the move on trial; 0 when none is
    bint locked       # a move was undone: none is tried again in this run


cdef struct Run:
    # What one run reports back.
    int status
    long iterations
    double rho
    int factorizations
    double setup_time
    int backend
    bint polished


cdef double _rho_trial(TrialState* trial, double rho, double new_rho, double worst,
                       double tolerance) noexcept nogil:
    """The rho to take, given OSQP's proposal ``new_rho`` and the larger relative
    residual ``worst`` at this update: ``new_rho`` when it moves rho by more than
    ``tolerance``. A smaller move, by more than the tolerance's square root, is made when
    the rule asked for it, the same way, at ``RHO_PERSISTENCE`` updates in a row while
    ``worst`` did not halve; it is undone (and none made again in the run) when over the
    next ``RHO_PERSISTENCE`` updates ``worst`` falls by less than it did over the streak."""
    cdef double half = sqrt(tolerance), old
    cdef int side = 1 if new_rho > rho * half else (-1 if new_rho < rho / half else 0)
    if new_rho > rho * tolerance or new_rho < rho / tolerance:
        trial.side = trial.count = 0
        trial.old_rho = 0.0
        return new_rho
    if trial.old_rho > 0.0:   # a move on trial
        trial.count += 1
        if trial.count == 1:
            trial.start = worst
        elif trial.count == _RHO_PERSISTENCE:
            old, trial.old_rho = trial.old_rho, 0.0
            trial.side = trial.count = 0
            if worst / trial.start > trial.progress:
                trial.locked = True
                return old
        return rho
    if trial.locked or side == 0 or side != trial.side:
        trial.side, trial.count, trial.start = side, 1, worst
        return rho
    trial.count += 1
    if trial.count < _RHO_PERSISTENCE:
        return rho
    trial.side = trial.count = 0
    if worst <= 0.5 * trial.start:
        return rho
    trial.progress = worst / trial.start
    trial.old_rho = rho
    return new_rho


cdef inline void _trial_reset(TrialState* trial) noexcept nogil:
    trial.side = trial.count = 0
    trial.old_rho = trial.start = trial.progress = 0.0
    trial.locked = False


cdef class RhoTrial:
    """:func:`_rho_trial` for the sparse path (:mod:`fccqp.sparse_admm`), which runs
    the dense core's rho rule: one per run."""

    cdef TrialState state

    def __cinit__(self):
        _trial_reset(&self.state)

    def propose(self, double rho, double new_rho, double worst, double tolerance):
        """The rho to take at this update (see :func:`_rho_trial`)."""
        return _rho_trial(&self.state, rho, new_rho, worst, tolerance)


cdef class Workspace:
    """Every array of a solve, allocated once for a problem structure.

    The structure is the sizes, the constrained entries, the entries with ``lb == ub``
    and the cone blocks; :class:`fccqp.Solver` builds a new workspace when it changes.
    Between solves the workspace keeps the user's last ``P`` and ``A`` (to detect
    reuse), their scaling and factorization, and the last solution (for a warm start).
    """

    cdef list _arrays
    cdef Problem prob
    cdef Iterates it
    cdef KKT kkt
    cdef Reduced red
    cdef Anderson aa
    cdef Restoration rest
    cdef Polish pol
    cdef Options opt
    cdef Residuals res
    cdef Finding found
    # user data (private copies) and scratch
    cdef double* P_user
    cdef double* q_user
    cdef double* A_user
    cdef double* b_user
    cdef double* lb_user
    cdef double* ub_user
    cdef double* rho_scale
    cdef double* d_scratch
    cdef double* e_scratch
    cdef double* scale_reference   # norms of the scaled matrices at the last equilibration
    cdef double* scale_norms
    cdef double* rhs
    cdef double* sol
    cdef double* vec_n
    cdef double* vec_n2
    cdef double* vec_n3
    cdef double* vec_s
    cdef double* vec_s2
    cdef double* guess_point   # s scratch of guess_changes
    cdef char* guess_codes     # s: the active set ADMM's iterate pointed to at the last check
    cdef double* vec_m
    cdef double* direction
    cdef double* cert
    cdef double* gram   # m x m: Cholesky factor of A A' for cleaning certificates
    cdef double* saved
    cdef double* log
    cdef double* prev_x
    cdef double* prev_y
    cdef double* prev_z
    cdef double* user_x
    cdef double* user_y
    cdef double* user_z
    cdef Py_ssize_t* block_start
    cdef char* entry_kind   # n: bound_kind of the bounds at allocation, or _CONE_ENTRY
    cdef Py_ssize_t log_rows, log_count
    cdef double prev_rho, factored_rho, setup_time
    cdef double final_reserve   # seconds the final polish or restoration took lately
    cdef double pass_time   # seconds per guess of the last polish, its check included
    cdef double tighten   # factor on the tolerances of the run (see POLISH_RETRIES)
    cdef double stalled_prim   # primal residual at the last check that could clean
    cdef int gram_state   # gram: 0 not factored in this solve, 1 factored, -1 failed
    cdef int stalled_checks   # checks in a row that could clean whose residual did not halve
    cdef long next_cleaning, cleaning_wait   # when the next cleaning may run, and the wait after
    cdef double clock[6]
    cdef bint has_previous, has_matrices, certified, scaled_once
    cdef bint has_rho   # prev_rho is a rho some solve adapted (a cold start keeps it too)
    cdef bint table_ready   # the reduced table and base hold for this solve's data and rho
    cdef bint iterated      # the last solve ran the iterations (and then its final step)
    cdef bint prev_polished, from_polished   # the previous solution was polished; this solve starts from it
    cdef bint user_current   # user_x, user_y, user_z and res are the returned point's
    cdef bint equalities_missed   # the last cold start did not meet A x = b
    cdef int form
    cdef object _keep

    def __init__(self, Py_ssize_t n, Py_ssize_t m, constrained, cones, fixed, order,
                 settings, Py_ssize_t log_rows):
        """Allocate for ``n`` variables, ``m`` rows, the ``constrained`` entries (intp,
        ascending), ``cones`` (the tuple of :class:`fccqp.cones.ConeArrays` with offsets
        into ``constrained``), the boolean mask ``fixed`` of constrained entries with
        ``lb == ub``, the Schur ``order`` and a :class:`fccqp.Settings`."""
        cdef Py_ssize_t s = len(constrained), N = n + m, memory = settings.anderson_memory
        cdef Py_ssize_t k, j
        self._arrays = []
        kind, offset, dim, mu, normal = cones
        # private copies: update_cones writes into them, and the caller's arrays may be
        # shared (fccqp.cones memoizes one ConeArrays per distinct set of cones)
        self._keep = (np.array(constrained, dtype=np.intp),
                      np.array(kind, dtype=np.intp),
                      np.array(offset, dtype=np.intp),
                      np.array(dim, dtype=np.intp),
                      np.array(mu, dtype=np.float64),
                      np.array(normal, dtype=np.float64).reshape(-1),
                      np.array(order, dtype=np.intp),
                      np.zeros(max(len(kind), 1), dtype=np.intp))
        cdef Py_ssize_t[::1] c_view = self._keep[0], kind_v = self._keep[1]
        cdef Py_ssize_t[::1] offset_v = self._keep[2], dim_v = self._keep[3]
        cdef Py_ssize_t[::1] order_v = self._keep[6], start_v = self._keep[7]
        cdef double[::1] mu_v = self._keep[4], normal_v = self._keep[5]
        p = &self.prob
        p.n, p.m, p.s = n, m, s
        p.constrained = &c_view[0] if s else NULL
        p.cones.count = len(kind)
        if p.cones.count:
            p.cones.kind, p.cones.offset, p.cones.dim = &kind_v[0], &offset_v[0], &dim_v[0]
            p.cones.mu, p.cones.normal = &mu_v[0], &normal_v[0]
            for k in range(p.cones.count):
                start_v[k] = c_view[offset_v[k]]
        self.block_start = &start_v[0]
        cdef char* in_cone = <char*>self._new(s)
        for k in range(p.cones.count):
            for j in range(offset_v[k], offset_v[k] + dim_v[k]):
                in_cone[j] = 1
        p.in_cone = in_cone
        p.P, p.q, p.A, p.b = self._new(n * n), self._new(n), self._new(m * n), self._new(m)
        p.lo, p.hi, p.D, p.E = self._new(s), self._new(s), self._new(n), self._new(m)
        p.span = self._new(m)
        p.c = 1.0
        self.P_user, self.q_user = self._new(n * n), self._new(n)
        self.A_user, self.b_user = self._new(m * n), self._new(m)
        self.lb_user, self.ub_user = self._new(n), self._new(n)
        self.rho_scale = self._new(s)
        for k in range(s):
            self.rho_scale[k] = FIXED_RHO_SCALE if fixed[k] else 1.0
        self.entry_kind = <char*>self._new(n)
        for k in range(s):
            self.entry_kind[c_view[k]] = (_CONE_ENTRY if in_cone[k] else
                                          FIXED_BOUND if fixed[k] else BOUNDED)
        self.d_scratch, self.e_scratch = self._new(n), self._new(m)
        self.scale_reference, self.scale_norms = self._new(N), self._new(N)
        it = &self.it
        it.x, it.nu, it.z, it.y = self._new(n), self._new(m), self._new(s), self._new(s)
        it.x_prev, it.nu_prev = self._new(n), self._new(m)
        it.z_prev, it.y_prev = self._new(s), self._new(s)
        it.relaxed, it.rho_vec = self._new(s), self._new(s)
        self.rhs, self.sol = self._new(N), self._new(N)
        cdef Py_ssize_t wide = max(n, m)
        self.vec_n, self.vec_n2, self.vec_n3 = self._new(wide), self._new(wide), self._new(wide)
        self.vec_s, self.vec_s2, self.vec_m = self._new(s), self._new(s), self._new(m)
        self.gram = self._new(m * m)
        self.guess_point, self.guess_codes = self._new(s), <char*>self._new(s)
        self.direction, self.saved, self.cert = self._new(n), self._new(N + s), self._new(N)
        self.prev_x, self.prev_y, self.prev_z = self._new(n), self._new(m), self._new(n)
        kk = &self.kkt
        kk.ldl.N = <int>N
        kk.ldl.K = self._new(N * N)
        kk.ldl.ipiv = <int*>self._new_int(N)
        kk.ldl.lwork = <int>(64 * N)
        kk.ldl.work, kk.ldl.residual = self._new(64 * N), self._new(N)
        kk.ldl.Ax, kk.ldl.ATnu = self._new(m), self._new(n)
        kk.schur.n, kk.schur.m = <int>n, <int>m
        kk.schur.L, kk.schur.LS, kk.schur.Y = self._new(n * n), self._new(m * m), self._new(n * m)
        kk.schur.base_order = &order_v[0]
        kk.schur.order = <Py_ssize_t*>self._new_int(n)
        kk.schur.coupled = <char*>self._new(n)
        kk.schur.dense = <int>n
        kk.schur.perm, kk.schur.dx, kk.schur.r = self._new(n), self._new(n), self._new(n)
        kk.schur.ATnu, kk.schur.dnu, kk.schur.Ax = self._new(n), self._new(m), self._new(m)
        kk.schur.X, kk.schur.Wnu, kk.schur.M = self._new(n * s), self._new(m * s), self._new(s * s)
        kk.R, kk.work = self._new(N * s), self._new(N)
        red = &self.red
        red.W, red.W_S, red.base = self._new(N * s), self._new(s * s), self._new(N)
        red.u, red.u_prev, red.v, red.v_prev = self._new(s), self._new(s), self._new(s), self._new(s)
        red.xs, red.rhs = self._new(s), self._new(N)
        aa = &self.aa
        aa.capacity = <int>memory
        aa.dg, aa.df = self._new(memory * 2 * s), self._new(memory * 2 * s)
        aa.g, aa.f, aa.g_new, aa.f_new = self._new(2 * s), self._new(2 * s), self._new(2 * s), self._new(2 * s)
        aa.plain, aa.gram, aa.gamma = self._new(2 * s + 1), self._new(memory * memory), self._new(memory)
        aa.products = self._new(memory * memory)
        anderson_reset(aa, False)
        rs = &self.rest
        rs.pinned = <char*>self._new(s)
        rs.target, rs.projected = self._new(s), self._new(s)
        rs.positions, rs.entries = <Py_ssize_t*>self._new_int(s), <Py_ssize_t*>self._new_int(s)
        rs.W_T, rs.gram, rs.step = self._new(N * s), self._new(s * s), self._new(s)
        rs.start, rs.point = self._new(N), self._new(N)
        pol = &self.pol
        pol.active = <char*>self._new(s)
        pol.dropped = <char*>self._new(s)
        pol.index, pol.free = <Py_ssize_t*>self._new_int(n), <Py_ssize_t*>self._new_int(n)
        pol.boundary = <Py_ssize_t*>self._new_int(s)
        pol.g, pol.lam, pol.hess = self._new(s), self._new(s), self._new(s * s)
        pol.K, pol.ipiv = self._new((N + s) * (N + s)), <int*>self._new_int(N + s)
        pol.lwork = <int>(64 * (N + s))
        pol.work = self._new(64 * (N + s))
        pol.rhs, pol.step = self._new(N + s), self._new(N + s)
        pol.x, pol.nu, pol.y = self._new(n), self._new(m), self._new(s)
        pol.x_prev, pol.nu_prev = self._new(n), self._new(m)
        pol.grad, pol.ATnu, pol.Ax = self._new(n), self._new(n), self._new(m)
        pol.T, pol.tpiv = self._new(4 * s * s), <int*>self._new_int(2 * s)
        pol.tr, pol.du = self._new(2 * s), self._new(2 * s)
        pol.full, pol.dfull = self._new(N), self._new(N)
        pol.schur_only = pol.schur_failed = False
        ps = &pol.schur
        ps.ready = False
        ps.order, ps.coupled = <Py_ssize_t*>self._new_int(n), <char*>self._new(n)
        ps.L, ps.root, ps.Y = self._new(n * n), self._new(n), self._new(n * (m + s))
        ps.SU, ps.S = self._new(m * m), self._new((m + s) * (m + s))
        ps.block = self._new(s * s)
        ps.rowvar, ps.block_row = <Py_ssize_t*>self._new_int(n), <Py_ssize_t*>self._new_int(s)
        ps.inv_root = self._new(n)
        ps.t, ps.t2, ps.u = self._new(n), self._new(n), self._new(m + s)
        self.user_x, self.user_y, self.user_z = self._new(n), self._new(m), self._new(n)
        self.log_rows = log_rows
        self.log = self._new(5 * log_rows)
        o = &self.opt
        o.rho, o.sigma, o.alpha = settings.rho, settings.sigma, settings.alpha
        o.eps_abs, o.eps_rel = settings.eps_abs, settings.eps_rel
        o.eps_prim_inf, o.eps_dual_inf = settings.eps_prim_inf, settings.eps_dual_inf
        o.time_limit = settings.time_limit
        o.adaptive_rho_tolerance = settings.adaptive_rho_tolerance
        o.max_iter, o.check_termination = settings.max_iter, settings.check_termination
        o.min_iter = settings.min_iter
        o.adaptive_rho_interval, o.scaling = settings.adaptive_rho_interval, settings.scaling
        o.adaptive_rho, o.restore_feasibility = settings.adaptive_rho, settings.restore_feasibility
        o.polish, o.polish_refine_iter = settings.polish, settings.polish_refine_iter
        o.backend, o.anderson_memory = BACKENDS[settings.kkt_backend], settings.anderson_memory
        self.has_previous = self.has_matrices = self.certified = self.scaled_once = False
        self.has_rho = False
        self.prev_polished = self.from_polished = self.equalities_missed = False
        self.user_current = False
        self.factored_rho = -1.0
        self.final_reserve = self.pass_time = 0.0

    cdef double* _new(self, Py_ssize_t size):
        """A zeroed array of ``size`` doubles (at least one) that lives with ``self``."""
        array = np.zeros(max(size, 1))
        self._arrays.append(array)
        cdef double[::1] view = array
        return &view[0]

    cdef void* _new_int(self, Py_ssize_t size):
        """An array of ``size`` pointer-sized integers that lives with ``self``."""
        array = np.zeros(max(size, 1), dtype=np.intp)
        self._arrays.append(array)
        cdef Py_ssize_t[::1] view = array
        return &view[0]

    def update_cones(self, mu, normal):
        """New friction coefficients and normals for the same cone blocks."""
        self._keep[4][:] = mu
        self._keep[5][:] = np.asarray(normal, dtype=np.float64).reshape(-1)

    def forget(self):
        """Drop the previous solution, so that the next solve starts cold."""
        self.has_previous = False

    def judge_certificate(self, const double[::1] candidate, bint primal,
                          const double[::1] point=None):
        """The certificate ``candidate`` (user's units, ``Result.certificate``'s layout:
        ``(dy, dz)`` for ``primal``, else ``dx``), found outside the run (see
        :mod:`fccqp.auxiliary`), judged by the tests of the run's own candidates on the
        last solve's scaled problem; the certificate as it passed (the primal one's
        ``dz`` projected onto the polar), or None. A primal certificate's separation
        must exceed what its residual explains at ``point`` (user's units, with ``A x =
        b``; default the run's iterate, which on a run that diverges along a ray, ``q``
        of 4.5e14 beside a cone pinned outside itself, explained away an exact one)."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t n = p.n, m = p.m, i, j
        cdef const double* x = self.it.x
        if candidate.shape[0] != (n + m if primal else n):
            raise ValueError("a certificate of the wrong size")
        if primal:
            if m == 0:
                return None
            if point is not None:
                if point.shape[0] != n:
                    raise ValueError("a point of the wrong size")
                for i in range(n):
                    self.vec_n3[i] = point[i] / p.D[i]
                x = self.vec_n3
            for i in range(m):
                self.vec_m[i] = candidate[i] / p.E[i]
            for j in range(p.s):
                i = p.constrained[j]
                self.vec_s[j] = candidate[m + i] * p.D[i]
            if primal_candidate(p, x, self.vec_m, self.vec_s, self.opt.eps_prim_inf,
                                self.vec_n, self.vec_n2) != CERTIFIED:
                return None
            fill(self.cert, 0.0, n + m)
            for i in range(m):
                self.cert[i] = self.vec_m[i] * p.E[i]
            for j in range(p.s):
                i = p.constrained[j]
                self.cert[m + i] = self.vec_s[j] / p.D[i]
            return np.asarray(<double[:n + m]>self.cert).copy()
        for i in range(n):
            self.direction[i] = candidate[i] / p.D[i]
        if not self._unbounded():
            return None
        return np.asarray(<double[:n]>self.cert).copy()

    @property
    def finding(self):
        """``(code, argument, index, value)`` of the last scan (see fccqp.validation)."""
        return self.found.code, self.found.argument, self.found.index, self.found.value

    @property
    def phase_times(self):
        """Seconds of the last solve's phases inside the compiled call: validation scan,
        scaling, start and factorization, iterations (with the polishing tried where
        ADMM converges before its budget), the final polishing or restoration and the
        unscaling (a phase the solve skipped shows 0)."""
        cdef int i
        return tuple(max(self.clock[i + 1] - self.clock[i], 0.0) for i in range(5))

    @property
    def log_lines(self):
        """Rows ``(iteration, prim, dual, gap, rho)`` of the last solve's log."""
        cdef Py_ssize_t i, j
        return [tuple(self.log[5 * i + j] for j in range(5)) for i in range(self.log_count)]

    def solve(self, P, q, A, b, lb, ub, x0, bint warm, double start_time, cert_out,
              bint checked=True):
        """Validate, scale, run ADMM and unscale; return the :class:`fccqp.Result`, or
        the code of what the caller must do instead.

        ``P, q, A, b, lb, ub`` are C-contiguous float64 arrays of the workspace's shapes
        (as :func:`fccqp.problem.convert` or :func:`fccqp.fast_checks.dense_arguments`
        leave them); with ``checked=False`` they are the caller's arguments as they came,
        and the code is ``NOT_DENSE`` when one is not such an array. ``x0`` (None or a
        float64 vector) overrides the warm start; ``warm`` asks for a start from the
        previous solution (when there is one); ``start_time`` is the call's start on the
        clock of ``time.perf_counter``. ``cert_out`` (``m + n`` entries) receives an
        infeasibility certificate, which the result copies. The other codes are
        ``STRUCTURE_CHANGED``, ``BAD_DATA`` (see :attr:`finding`) and
        ``NOT_CONVEX_CODE``; the last two leave the previous solution untouched.

        The arrays are read through their buffers, held for the call: typed memoryview
        arguments made a memoryview object for each of the eleven, and holding the
        buffers instead saved 9k of a go2 tick's 1.13M instructions (callgrind). The
        result is built here, not in Python from a tuple of the run's figures: the
        interpreter runs from cold caches after the compiled solve, and there that took
        7-10 us of a 100 us go2 or solo12 tick (in flow); built here, a go2 tick
        counts 7k fewer instructions of 706k (callgrind).
        """
        cdef Py_ssize_t n = self.prob.n, m = self.prob.m
        cdef Py_buffer views[11]
        cdef Py_ssize_t rows[11]
        cdef Py_ssize_t columns[11]
        cdef int held = 0, count = 10 if x0 is None else 11, i, code
        cdef Run run
        x_out, y_out, z_out = np.empty(n), np.empty(m), np.empty(n)
        cdef tuple arrays = (P, q, A, b, lb, ub, x_out, y_out, z_out, cert_out, x0)
        rows[:] = [n, n, m, m, n, n, n, m, n, n + m, n]
        columns[:] = [n, -1, n, -1, -1, -1, -1, -1, -1, -1, -1]   # -1: a vector
        try:
            for i in range(count):   # the outputs, 6 to 9, are written
                if i < 6 and not checked:
                    if not hold_dense(arrays[i], &views[i], rows[i], columns[i]):
                        return NOT_DENSE
                elif not hold_float64(arrays[i], &views[i], rows[i], columns[i], 6 <= i <= 9):
                    raise ValueError(f"expected a C-contiguous float64 array of {rows[i]} rows")
                held += 1
            code = self._run(<const double*>views[0].buf, <const double*>views[1].buf,
                             <const double*>views[2].buf, <const double*>views[3].buf,
                             <const double*>views[4].buf, <const double*>views[5].buf,
                             <const double*>views[10].buf if x0 is not None else NULL, warm,
                             start_time, <double*>views[6].buf, <double*>views[7].buf,
                             <double*>views[8].buf, <double*>views[9].buf, &run)
        finally:
            for i in range(held):
                PyBuffer_Release(&views[i])
        if code < _SOLVED:
            return code
        return self._result(&run, x_out, y_out, z_out, cert_out, start_time)

    cdef object _result(self, const Run* run, x, y, z, cert_out, double start_time):
        """The :class:`fccqp.Result` of a finished run (see ``Result.gap`` and
        ``Result.certificate`` for the infeasible statuses)."""
        cdef Residuals* r = &self.res
        certificate = None
        if run.status == _PRIMAL_INFEASIBLE:
            certificate = cert_out.copy()
        elif run.status == _DUAL_INFEASIBLE:
            certificate = cert_out[:self.prob.n].copy()
        return Result._of({
            "x": x, "y": y, "z": z, "status": STATUS_BY_CODE[run.status],
            "obj": r.objective, "iterations": run.iterations, "prim_res": r.prim,
            "dual_res": r.dual, "setup_time": run.setup_time,
            "solve_time": fccqp_now() - start_time, "rho": run.rho,
            "factorizations": run.factorizations, "certificate": certificate,
            "backend": BACKEND_NAMES[run.backend],
            "gap": r.gap if certificate is None else float("nan"), "polished": run.polished,
        })

    cdef int _run(self, const double* P, const double* q, const double* A, const double* b,
                  const double* lb, const double* ub, const double* x0, bint warm,
                  double start_time, double* x_out, double* y_out, double* z_out,
                  double* cert_out, Run* out) except -9:
        """:meth:`solve` on the held buffers: the run's status, with ``out`` filled, or
        one of the codes below ``SOLVED``."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t n = p.n, m = p.m
        cdef bint same = self.has_matrices
        cdef Run run
        cdef long spent
        cdef int factored
        self.clock[0] = fccqp_now()
        with nogil:
            self.found = scan_and_copy(
                P, q, A if m else NULL, b if m else NULL, lb, ub, n, m, self.P_user,
                self.q_user, self.A_user, self.b_user, self.lb_user, self.ub_user, &same)
        if self.found.code != SCAN_OK:
            self.has_matrices = False
            return _BAD_DATA
        if not self._same_structure(lb, ub):
            self.has_matrices = False
            return _STRUCTURE_CHANGED
        cdef long max_iter = self.opt.max_iter
        # a start from the previous solution (or x0), with the previous scaling, that
        # has not succeeded in half the iterations gets a cold start with a new scaling
        # for the other half, as a fresh solve would have (a changed A once ran 4000
        # iterations warm, where a fresh solve needed none); not under a time limit,
        # which leaves no time for it, nor for budgets too small to split
        cdef bint restartable = ((x0 != NULL or (warm and self.has_previous))
                                 and not isfinite(self.opt.time_limit)
                                 and max_iter >= _RESTART_MIN_ITER)
        enter()   # single-threaded BLAS for this solve (see fccqp.blas_threads)
        try:
            with nogil:
                if restartable:
                    self.opt.max_iter = max_iter // 2
                run = self._solve(same, x0, warm and self.has_previous, start_time)
                if run.status != _NOT_CONVEX:
                    self._finish(&run, x_out, y_out if m else NULL, z_out, cert_out)
                self.opt.max_iter = max_iter
                if restartable and (run.status == _MAX_ITER or run.status == _NUMERICAL_ERROR):
                    self.opt.max_iter = max_iter - run.iterations
                    spent, factored = run.iterations, run.factorizations
                    run = self._solve(False, NULL, False, start_time)
                    self.opt.max_iter = max_iter
                    run.iterations += spent
                    run.factorizations += factored
                    if run.status != _NOT_CONVEX:
                        self._finish(&run, x_out, y_out if m else NULL, z_out, cert_out)
                self.clock[5] = fccqp_now()
                self.final_reserve *= _RESERVE_DECAY
                if self.iterated:   # learn what the final step after the iterations costs
                    self.final_reserve = max(self.final_reserve, self.clock[5] - self.clock[4])
        finally:
            leave()
        if run.status == _NOT_CONVEX:
            self.has_matrices = self.has_previous = self.certified = False
            return _NOT_CONVEX
        out[0] = run
        return run.status

    cdef bint _same_structure(self, const double* lb, const double* ub) noexcept nogil:
        """Whether the user's new bounds bound, fix and leave free the entries they did at
        allocation, with no bound on a cone entry (:func:`fccqp.validation.bound_kind`,
        the rule of ``structure_scan``): one pass here instead of a separate call per
        solve (the control-loop case)."""
        cdef Py_ssize_t i
        cdef int kind
        for i in range(self.prob.n):
            kind = bound_kind(lb[i], ub[i])
            if kind == UNBOUNDED and self.entry_kind[i] == _CONE_ENTRY:
                continue
            if kind != self.entry_kind[i]:
                return False
        return True

    # ----------------------------------------------------------------- one solve

    cdef Run _solve(self, bint same_matrices, const double* x0, bint warm,
                    double start_time) noexcept nogil:
        """Scale (or reuse the scaling), start, run."""
        cdef Problem* p = &self.prob
        cdef Run run
        cdef bint reuse = same_matrices and self.scaled_once
        if not same_matrices:
            self.certified = False
        self.has_matrices = True
        self.from_polished = x0 == NULL and warm and self.prev_polished
        self.user_current = False
        self.clock[1] = fccqp_now()
        self._scale(reuse, warm)
        self.clock[2] = fccqp_now()
        self.log_count = 0
        # under a time limit a cold start too keeps the rho the last solve adapted (as
        # OSQP keeps its rho between solves): on talos_reduced's cold starts (a new
        # controller sequence) 42 to 173 iterations and 2-3 factorizations instead of 58
        # to 242 and 3-5 from Settings.rho, the quadrupeds' about the same. Without one
        # the default preset's iterations went 48.5 -> 9.3 on solo12 but 15.9 -> 22.7 on
        # talos and 1.8 -> 6.3 on anymal_c, and solo12's worst gap 7.3e-7 -> 1.0e-6
        run.rho = (self.prev_rho if warm or (self.has_rho and isfinite(self.opt.time_limit))
                   else self.opt.rho)
        if x0 != NULL:
            self._start_from_guess(x0)
        elif warm:
            scale_start(self.prev_x, self.prev_y, self.prev_z, self.prev_rho, p.D, p.E, p.c,
                        p.n, p.m, p.s, p.constrained, p.lo, p.hi, p.cones, self.it.x,
                        self.it.nu, self.it.y, self.it.z)
        if not reuse:
            self.factored_rho = -1.0
        run.setup_time = fccqp_now() - start_time
        self._iterate(&run, x0 == NULL and not warm, start_time)
        return run

    cdef void _scale(self, bint reuse, bint warm) noexcept nogil:
        """Equilibrate the user's data into the scaled problem; with ``reuse`` (unchanged
        matrices) apply the scaling to the new vectors only, and with ``warm`` (a start
        from the previous solution) scale the new data with the previous equilibration
        (:func:`fccqp.scaling.rescale`); then the rows' spans over the (new) box."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t n = p.n, m = p.m, i, j
        if reuse:
            for i in range(n):
                p.q[i] = p.c * p.D[i] * self.q_user[i]
            for i in range(m):
                p.b[i] = p.E[i] * self.b_user[i]
        elif not (warm and self.scaled_once and rescale(
                self.P_user, self.q_user, self.A_user, self.b_user, n, m, p.D, p.E,
                self.scale_reference, self.scale_norms, p.P, p.q, p.A, p.b, &p.c)):
            copy(self.P_user, p.P, n * n)
            copy(self.A_user, p.A, m * n)
            copy(self.q_user, p.q, n)
            copy(self.b_user, p.b, m)
            p.c = equilibrate(p.P, p.q, p.A, p.b, n, m, self.block_start, p.cones.dim,
                              p.cones.count, self.opt.scaling, p.D, p.E, self.d_scratch,
                              self.e_scratch)
            scaled_norms(p.P, p.A, n, m, p.c, self.scale_reference)
            self.scaled_once = True
        for j in range(p.s):
            i = p.constrained[j]
            p.lo[j] = self.lb_user[i] / p.D[i]
            p.hi[j] = self.ub_user[i] / p.D[i]
        row_spans(p, self.d_scratch)

    cdef void _start_from_guess(self, const double* x0) noexcept nogil:
        """Primal guess ``x0`` (user's units), duals zero, slack its projection."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t i, j
        for i in range(p.n):
            self.it.x[i] = x0[i] / p.D[i]
        fill(self.it.nu, 0.0, p.m)
        fill(self.it.y, 0.0, p.s)
        for j in range(p.s):
            self.it.z[j] = self.it.x[p.constrained[j]]
        proj_set(self.it.z, p.lo, p.hi, p.cones, p.s, self.it.z)

    # ------------------------------------------------------------ the iteration

    cdef void _iterate(self, Run* run, bint cold, double start_time) noexcept nogil:
        """Run ADMM from the iterate in the workspace (or a cold start)."""
        cdef Problem* p = &self.prob
        cdef Iterates* it = &self.it
        cdef Options* o = &self.opt
        cdef Residuals* r = &self.res
        cdef Py_ssize_t s = p.s, j
        cdef long iteration = 0, polished_at = -1, wait = 0, next_gated = 0
        cdef int status = _RUNNING, code, retries = 0, early_tries = 0
        cdef bint guess_polished = False, first_check = True
        cdef bint unbounded_start = False, timed = isfinite(o.time_limit)
        # the iterations stop early enough for the final polish or restoration to fit
        cdef double deadline = o.time_limit - min(
            max(self.final_reserve, _RESERVE_PASSES * self.pass_time), 0.5 * o.time_limit)
        cdef bint reduced, fresh, last, periodic, adapt, check, gated, accelerate, warm_polish
        cdef bint polished
        cdef double eps_p, eps_d, new_rho, periodic_prim
        cdef TrialState trial
        cdef int stalls
        run.factorizations = 0
        run.backend = self.form
        _trial_reset(&trial)
        run.polished = False
        self.tighten = 1.0
        self.stalled_prim = INFINITY
        self.stalled_checks = 0
        self.next_cleaning = _CLEANING_START
        self.cleaning_wait = self.opt.adaptive_rho_interval
        self.gram_state = 0
        self.table_ready = False   # base is for the previous q, b
        self.pol.schur.ready = False   # set up for the previous P, A
        self.iterated = False
        self.clock[3] = self.clock[4] = fccqp_now()   # phases skipped show 0
        if cold or s == 0:
            code = self._equality_start(&unbounded_start)
            run.factorizations += 1
            if code == NOT_CONVEX:
                run.status = _NOT_CONVEX
                return
        self._residuals()
        self._log(0, run.rho)
        if unbounded_start and self._unbounded():
            self._finish_run(run, _DUAL_INFEASIBLE, 0)
            return
        if cold or s == 0:   # not at factorization accuracy: inconsistent or dependent rows
            self.equalities_missed = r.prim_eq > _EQUALITY_MISSED * max(r.prim_eq_scale, 1.0)
            if self._missed_by_data() and self._inconsistent(True):
                # tested on the penalty-free start: with rho in the KKT matrix (up to 1e9
                # on fixed entries) the regularization's trace in A'r can hide it
                self._finish_run(run, _PRIMAL_INFEASIBLE, 0)
                return
        if (cold or s == 0) and converged(r, o.eps_abs, o.eps_rel) and not unbounded_start:
            status = _SOLVED
            if o.polish:   # the start carries sigma's bias where the cost is flat
                run.polished = self._keep_polished(&status, 0, start_time)
            self._finish_run(run, status, 0)
            return
        if s == 0:  # nothing to iterate: the equality-constrained QP was the answer
            status = self._classify(0, False, start_time)
            if o.polish and _SOLVED <= status <= _TIME_LIMIT:
                run.polished = self._keep_polished(&status, 0, start_time)
            self._finish_run(run, status, 0)
            return
        for j in range(s):
            it.rho_vec[j] = run.rho * self.rho_scale[j]
        warm_polish = self.from_polished and o.polish
        if self.factored_rho != run.rho or cold:
            if (warm_polish and polish_prepare(&self.pol, p)
                    and (self.certified or self.pol.schur.convex)):
                # polish before ADMM's factorization, which it does not need; new
                # matrices must be proven convex first, which the set-up does for free
                # where P is positive semidefinite, else the factorization below does
                self.certified = True
                self.pol.schur_only = True
                polished = self._warm_polish(run, start_time)
                self.pol.schur_only = False
                if polished:
                    return
                # a guess that failed the check would fail again; one that the Schur
                # complement could not solve goes to the table
                warm_polish = self.pol.schur_failed
            code = self._factor(run, self._budget(0))
            if code != FACTORED:
                run.status = _NOT_CONVEX if code == NOT_CONVEX else _NUMERICAL_ERROR
                return
        reduced = self.form != LDL_FULL
        if reduced:
            self._reduced_base()
        if warm_polish and self._warm_polish(run, start_time):
            return
        self.clock[3] = fccqp_now()
        if reduced:
            reduced_start(&self.red, p, it)
        eps_p = o.eps_abs + o.eps_rel * r.prim_set_scale   # the gate tests x_S - z
        eps_d = o.eps_abs + o.eps_rel * r.dual_scale
        anderson_reset(&self.aa, False)
        accelerate = o.anderson_memory > 0
        periodic_prim = INFINITY
        stalls = 0
        fresh = True  # the next step starts a run of KKT solutions: do not relax x
        if timed and o.min_iter == 0 and fccqp_now() - start_time >= deadline:
            status = self._classify(0, True, start_time)   # the setup spent the budget
        while status == _RUNNING:
            iteration += 1
            if reduced:
                reduced_step(&self.red, p, it, o.alpha, not fresh)
            else:
                self._full_step(not fresh)
            fresh = False
            last = iteration >= o.max_iter or (timed and iteration >= o.min_iter
                                               and fccqp_now() - start_time >= deadline)
            periodic = iteration % o.adaptive_rho_interval == 0
            adapt = o.adaptive_rho and periodic
            check = iteration % o.check_termination == 0 or last or adapt
            gated = check and reduced and not (last or periodic)
            if gated:
                # a scheduled full check (and with it infeasibility detection) still runs
                # every adaptive_rho_interval iterations
                check = iteration >= next_gated and near_convergence(&self.red, p, it, eps_p,
                                                                     eps_d)
            if check:
                if reduced:
                    materialize(&self.red, p, it)
                self._residuals()
                eps_p = self.tighten * (o.eps_abs + o.eps_rel * r.prim_set_scale)
                eps_d = self.tighten * (o.eps_abs + o.eps_rel * r.dual_scale)
                if iteration % _LOG_INTERVAL == 0:
                    self._log(iteration, run.rho)
                status = self._check(iteration, last, start_time)
                if gated and status == _RUNNING:   # the gate passed, the check did not
                    wait = min(2 * wait + 1, _GATED_CHECK_WAIT)
                    next_gated = iteration + wait
                if status == _SOLVED and o.polish and not last and retries < _POLISH_RETRIES:
                    polished_at = iteration
                    run.polished = self._keep_polished(&status, iteration, start_time)
                    if not run.polished:   # go on, closer to the active set
                        retries += 1
                        self.tighten *= 0.1
                        status = _RUNNING
                if (status == _RUNNING and periodic and o.polish and not timed and not last
                        and early_tries < _EARLY_POLISH_TRIES):
                    if (guess_changes(p, it.z, it.y, self.guess_point, self.guess_codes) != 0
                            or first_check):
                        guess_polished = first_check = False   # polish it once it settles
                    elif not guess_polished and nearly_converged(r, o.eps_abs, o.eps_rel,
                                                                 _EARLY_POLISH_GATE):
                        guess_polished = True
                        early_tries += 1
                        polished_at = iteration
                        run.polished = self._keep_polished(&status, iteration, start_time, True)
                if status == _RUNNING and periodic and accelerate:
                    # a primal residual that does not halve between two scheduled checks
                    # far from tolerance is how infeasibility looks; Anderson's
                    # extrapolated points there hide the steady step that certifies it
                    # (CVXPY's lp_4 ran 4000 iterations uncertified), so plain ADMM runs on
                    if (r.prim > _STALL_FACTOR * (o.eps_abs + o.eps_rel * r.prim_scale)
                            and r.prim > 0.5 * periodic_prim):
                        stalls += 1
                    else:
                        stalls = 0
                    accelerate = stalls < _STALLS
                    periodic_prim = r.prim
                if status == _RUNNING and adapt:
                    new_rho = self._new_rho(run.rho, &trial)
                    if new_rho != run.rho:
                        code = self._change_rho(run, new_rho, iteration, reduced)
                        if code != FACTORED:
                            run.status = _NOT_CONVEX if code == NOT_CONVEX else _NUMERICAL_ERROR
                            return
                        reduced = self.form != LDL_FULL
                        fresh = True
                        wait = next_gated = 0
            if status == _RUNNING and accelerate:
                anderson_step(&self.aa, it, s)
        self.clock[4] = fccqp_now()
        self.iterated = True
        if (not run.polished and o.polish and _SOLVED <= status <= _TIME_LIMIT
                and polished_at != iteration
                and (not timed or nearly_converged(r, o.eps_abs, o.eps_rel, _POLISH_GATE))):
            run.polished = self._keep_polished(&status, iteration, start_time)
        if not run.polished:   # a polished point is feasible already: nothing to restore
            if o.restore_feasibility and _SOLVED <= status <= _TIME_LIMIT:
                status = self._keep_restored(status, iteration, reduced, start_time)
            elif (reduced or self._missed()) and status != _NUMERICAL_ERROR:
                self._restore_equalities()   # certificates are already in cert
        self._finish_run(run, status, iteration)

    cdef bint _warm_polish(self, Run* run, double start_time) noexcept nogil:
        """Polish the warm start (a polished solution of the previous data) before any
        iteration; True, and the run finished SOLVED, when the point passes
        :func:`_keep_polished`'s check and is solved.

        In a control loop the active set mostly survives a tick, and then this is the
        whole solve: no iteration (go2: 91 % of the ticks). Where ``P`` is diagonal on the
        constrained entries (whole-body control) it runs before ADMM's factorization, its
        systems solved by Schur complement on ``P``'s blocks (:mod:`fccqp.polish_schur`),
        and a success skips that factorization and the reduced table; otherwise it runs
        after them in the table's coordinates (one small LU a guess). The polished QP's
        own KKT matrix by ``dsytrf`` instead was no cheaper than the table (1.9M against
        1.78M instructions per go2 tick, callgrind) and dearer when the guess fails. Tried
        and not kept: polishing from every previous solution, or with 1 or 2 guesses from
        an unpolished one. Capped at 15 / 30 iterations talos' ticks polish more often
        (32 -> 36 %, 61 -> 66 % end here), but under the realtime preset's 2 ms budget a
        failed polish after a budget-stopped tick takes the time the next ADMM run needs:
        talos solved 37 % of the ticks (every solution) against 82 %, and 58-87 % (one
        guess) against 77-93 % (polished only) in four alternating runs.
        """
        cdef int status = _RUNNING
        if not self._keep_polished(&status, 0, start_time, True):
            return False
        run.polished = True
        self.user_current = True   # _keep_polished left them so
        self.clock[3] = self.clock[4] = fccqp_now()
        self._finish_run(run, _SOLVED, 0)
        return True

    cdef int _change_rho(self, Run* run, double new_rho, long iteration,
                         bint reduced) noexcept nogil:
        """Refactor for ``new_rho``: carry the reduced form's coordinates into the new
        table (before the old one is gone), factor, recompute ``base``, forget
        Anderson's memory. Returns :func:`_factor`'s code."""
        cdef Problem* p = &self.prob
        cdef Iterates* it = &self.it
        cdef Py_ssize_t j
        cdef int code
        if reduced:
            for j in range(p.s):
                self.vec_s[j] = new_rho * self.rho_scale[j]
            reduced_rebase(&self.red, p, it.rho_vec, self.vec_s)
        run.rho = new_rho
        for j in range(p.s):
            it.rho_vec[j] = new_rho * self.rho_scale[j]
        code = self._factor(run, self._budget(iteration))
        if code == FACTORED:
            if self.form != LDL_FULL:
                self._reduced_base()
            anderson_reset(&self.aa, True)
        return code

    cdef int _check(self, long iteration, bint last, double start_time) noexcept nogil:
        """Termination and infeasibility tests after the residuals of ``iteration``."""
        cdef Problem* p = &self.prob
        cdef Iterates* it = &self.it
        cdef Options* o = &self.opt
        cdef Residuals* r = &self.res
        cdef Py_ssize_t i
        cdef int code
        if not r.finite:
            return _NUMERICAL_ERROR
        if (self._missed_by_data()
                and self._inconsistent(iteration % o.adaptive_rho_interval == 0)):
            # A x = b has no solution: no point can be SOLVED (cleaned on the schedule
            # of rho adaptation, a KKT solve each time)
            return _PRIMAL_INFEASIBLE
        if converged(r, self.tighten * o.eps_abs, self.tighten * o.eps_rel):
            return _SOLVED
        code = primal_infeasible(p, it, o.eps_prim_inf, self.vec_m, self.vec_s, self.vec_n,
                                 self.vec_n2)
        if code == CERTIFIED or (code == SEPARATED and iteration >= self.next_cleaning
                                 and iteration % o.adaptive_rho_interval == 0
                                 and self._cleaned_certificate(iteration)):
            fill(self.cert, 0.0, p.n + p.m)
            for i in range(p.m):   # in the user's units (the common factor 1/c dropped)
                self.cert[i] = self.vec_m[i] * p.E[i]
            for i in range(p.s):
                self.cert[p.m + p.constrained[i]] = self.vec_s[i] / p.D[p.constrained[i]]
            return _PRIMAL_INFEASIBLE
        for i in range(p.n):
            self.direction[i] = it.x[i] - it.x_prev[i]
        if self._unbounded():
            return _DUAL_INFEASIBLE
        if last:
            return self._classify(iteration, True, start_time)
        return _RUNNING

    cdef bint _cleaned_certificate(self, long iteration) noexcept nogil:
        """Clean the primal certificate's candidate that the last test left in ``vec_m``,
        ``vec_s`` (:func:`fccqp.certificates.clean_primal_certificate`), on the schedule
        of rho adaptation, when the primal residual is above ``CLEANING_GATE`` times
        its tolerance and did not halve over the last two such checks, and the
        candidate separates: how infeasibility looks, and the only case worth an ``A
        A'`` factorization (m x m, once per solve). Not before ``CLEANING_START``
        iterations, and each failed try doubles the wait before the next: a try costs
        about a hundred of talos_reduced's iterations, and its slow feasible ticks
        stall and separate too (tried at every such check, cleaning took 20 % of the
        realtime preset's warm instructions)."""
        cdef Problem* p = &self.prob
        cdef Residuals* r = &self.res
        cdef double previous = self.stalled_prim
        self.stalled_prim = r.prim
        self.stalled_checks = self.stalled_checks + 1 if r.prim > 0.5 * previous else 0
        if not (p.m > 0 and self.stalled_checks >= 2
                and r.prim > _CLEANING_GATE * (self.opt.eps_abs + self.opt.eps_rel * r.prim_scale)):
            return False
        if self.gram_state == 0:   # once per solve: A A' of this solve's scaled rows
            self.gram_state = 1 if gram_factor(p, self.gram) else -1
        if self.gram_state == 1 and clean_primal_certificate(
                p, self.it.x, self.gram, self.opt.eps_prim_inf, self.vec_m, self.vec_s,
                self.saved, self.vec_n3, self.vec_n, self.vec_n2):
            return True
        self.cleaning_wait *= 2   # the next try waits twice as long
        self.next_cleaning = iteration + self.cleaning_wait
        return False

    cdef bint _missed(self) noexcept nogil:
        """The last residuals miss ``A x = b`` beyond factorization accuracy
        (``EQUALITY_MISSED`` of their scale). Not the tolerance: rows inconsistent by
        less than ``eps_rel`` of the largest row (a duplicated row of size 2 off by 0.65
        among rows of 3e6) are no more solvable, and were left uncertified for 4000
        iterations."""
        return self.res.prim_eq > _EQUALITY_MISSED * self.res.prim_eq_scale

    cdef bint _missed_by_data(self) noexcept nogil:
        """:meth:`_missed`, and also beyond ``EQUALITY_MISSED`` of each row's terms at the
        magnitude of the iterate and the box (:func:`fccqp.certificates.row_size`): only
        then can the equality certificate hold. Where ``b`` and ``A x`` both cancel to
        rounding noise (consistent dependent rows asking 0 with right-hand sides of
        4e-16, at a start of 1e-13), ``max(|A x|, |b|)`` alone made that a miss, and a
        public QP (QSCORPIO) was claimed infeasible. Computed only when :meth:`_missed`
        holds."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t i
        cdef double largest = 0.0
        if not self._missed():
            return False
        magnitudes(p, self.it.x, self.vec_n)
        for i in range(p.m):
            largest = max(largest, row_size(p, i, self.vec_n) / p.E[i])
        return self.res.prim_eq > _EQUALITY_MISSED * largest

    cdef bint _inconsistent(self, bint clean) noexcept nogil:
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
        first problem's ``rho`` fell to 1e-17, the second's to 7e-17."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t n = p.n, m = p.m, i
        cdef double* r = self.vec_m
        cdef int code = equality_inconsistent(p, &self.it, self.opt.eps_prim_inf, r,
                                              self.vec_n, self.vec_n2)
        if code == SEPARATED and clean:
            fill(self.rhs, 0.0, n)
            copy(r, self.rhs + n, m)
            kkt_solve(&self.kkt, p, self.it.rho_vec, self.rhs, self.sol)
            for i in range(m):
                r[i] = -self.sol[n + i]
            code = equality_direction(p, r, self.it.x, self.opt.eps_prim_inf, self.vec_n,
                                      self.vec_n2)
        if code != CERTIFIED:
            return False
        fill(self.cert, 0.0, n + m)
        for i in range(m):
            self.cert[i] = -r[i] * p.E[i]
        return True

    cdef bint _unbounded(self) noexcept nogil:
        """The dual certificate for ``direction``; on success ``cert`` holds it, unscaled."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t i
        if not dual_infeasible(p, self.direction, self.opt.eps_dual_inf, self.vec_n,
                               self.vec_n2, self.vec_s2):
            return False
        for i in range(p.n):
            self.cert[i] = self.direction[i] * p.D[i]
        return True

    cdef int _classify(self, long iteration, bint stopped, double start_time) noexcept nogil:
        """Status of an iterate from its residuals alone: solved, inaccurate (within
        ``INACCURATE_FACTOR`` of the tolerances), or the budget that ran out."""
        cdef Residuals* r = &self.res
        if not r.finite:
            return _NUMERICAL_ERROR
        if converged(r, self.opt.eps_abs, self.opt.eps_rel):
            return _SOLVED
        if nearly_converged(r, self.opt.eps_abs, self.opt.eps_rel, _INACCURATE_FACTOR):
            return _INACCURATE
        if iteration >= self.opt.max_iter or not stopped:
            return _MAX_ITER
        return _TIME_LIMIT

    cdef void _full_step(self, bint relax_x) noexcept nogil:
        """One ADMM iteration with a KKT solve (update_x, update_z, update_y)."""
        cdef Problem* p = &self.prob
        cdef Iterates* it = &self.it
        cdef Py_ssize_t n = p.n, m = p.m, s = p.s, i, j
        cdef double alpha = self.opt.alpha, alpha_x = alpha if relax_x else 1.0
        cdef double sigma = self.opt.sigma
        copy(it.x, it.x_prev, n)
        copy(it.nu, it.nu_prev, m)
        copy(it.z, it.z_prev, s)
        copy(it.y, it.y_prev, s)
        for i in range(n):
            self.rhs[i] = sigma * it.x[i] - p.q[i]
        for i in range(m):
            self.rhs[n + i] = p.b[i]
        for j in range(s):
            self.rhs[p.constrained[j]] += it.rho_vec[j] * it.z[j] - it.y[j]
        kkt_solve(&self.kkt, p, it.rho_vec, self.rhs, self.sol)
        for j in range(s):
            it.relaxed[j] = alpha * self.sol[p.constrained[j]] + (1.0 - alpha) * it.z_prev[j]
        for i in range(n):
            it.x[i] = alpha_x * self.sol[i] + (1.0 - alpha_x) * it.x_prev[i]
        copy(self.sol + n, it.nu, m)
        for j in range(s):
            it.z[j] = it.relaxed[j] + it.y[j] / it.rho_vec[j]
        proj_set(it.z, p.lo, p.hi, p.cones, s, it.z)
        for j in range(s):
            it.y[j] += it.rho_vec[j] * (it.relaxed[j] - it.z[j])

    cdef double _new_rho(self, double rho, TrialState* trial) noexcept nogil:
        """OSQP's rule: rho *= sqrt(relative primal / relative dual residual), clipped,
        when that moves it by more than ``adaptive_rho_tolerance``; a smaller move that
        the rule keeps asking for is tried (:func:`_rho_trial`)."""
        cdef Residuals* r = &self.res
        cdef double prim = r.prim_s / max(r.prim_scale_s, 1e-30)
        cdef double dual = r.dual_s / max(r.dual_scale_s, 1e-30)
        cdef double new_rho = min(max(rho * sqrt(prim / max(dual, 1e-30)), _RHO_MIN), _RHO_MAX)
        return _rho_trial(trial, rho, new_rho, max(prim, dual), self.opt.adaptive_rho_tolerance)

    # -------------------------------------------------------- factorizations

    cdef long _budget(self, long iteration) noexcept nogil:
        """Solves the reduced form's table can save: the iterations left, plus, when the
        result will be restored, the columns the restoration would otherwise compute."""
        cdef long restoring = self.prob.s if self.opt.restore_feasibility else 0
        return self.opt.max_iter - iteration + restoring

    cdef int _certify(self, bint schur_factored) noexcept nogil:
        """Establish convexity for the current matrices (see :func:`fccqp.kkt.kkt_convexity`);
        ``schur_factored`` says that the Schur backend has just factored them."""
        cdef int code = kkt_convexity(&self.kkt, &self.prob, self.opt.sigma, self.it.rho_vec,
                                      schur_factored)
        if code == FACTORED:
            self.certified = True
        return code

    cdef int _factor(self, Run* run, long budget) noexcept nogil:
        """Factor for the current rho with the backend the settings ask for, falling back
        in the order Schur, LDL' reduced, LDL' full ("auto" starts with Schur when the
        reduced table pays for itself within ``budget`` and the constrained entries are
        at most half the KKT size, else with LDL' full). Certifies convexity when the
        matrices are new. Returns FACTORED, NOT_CONVEX, or UNAVAILABLE (numerical
        breakdown); records the form and the rho it factored."""
        cdef Problem* p = &self.prob
        cdef int backend, code, first = self.opt.backend
        cdef bint reduced_pays
        self.table_ready = False
        if first == AUTO:
            # rows the equality-constrained start could not meet (inconsistent, or
            # numerically dependent) go to the full form: its regularized solves give
            # least-squares iterates, on which the equality certificate is tested
            # (a random test: the reduced form ran 4000 iterations uncertified)
            reduced_pays = (2 * p.s <= p.n + p.m and _REDUCED_COST * p.s <= budget
                            and not self.equalities_missed)
            first = SCHUR_REDUCED if reduced_pays else LDL_FULL
        for backend in range(first, LDL_FULL + 1):
            if not self.certified and backend != SCHUR_REDUCED:
                # certify first: the certificate overwrites an LDL' factorization
                code = self._certify(False)
                run.factorizations += 1
                if code == NOT_CONVEX:
                    return NOT_CONVEX
            code = kkt_factor(&self.kkt, p, backend,
                              self.opt.sigma if backend == LDL_FULL else 0.0, self.it.rho_vec)
            run.factorizations += 1
            if code != FACTORED:
                if backend == LDL_FULL:
                    return UNAVAILABLE
                continue
            if not self.certified and self._certify(True) == NOT_CONVEX:
                return NOT_CONVEX
            if backend != LDL_FULL and not reduced_table(&self.red, &self.kkt, p,
                                                         self.it.rho_vec):
                continue
            self.form = backend
            run.backend = backend
            self.factored_rho = run.rho
            return FACTORED
        return UNAVAILABLE

    cdef void _reduced_base(self) noexcept nogil:
        """``base``: the x-update's response to ``(-q, b)`` alone (q and b change every
        solve; the table only with the factorization)."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t i
        for i in range(p.n):
            self.rhs[i] = -p.q[i]
        for i in range(p.m):
            self.rhs[p.n + i] = p.b[i]
        kkt_solve(&self.kkt, p, self.it.rho_vec, self.rhs, self.red.base)
        self.table_ready = True

    cdef int _equality_start(self, bint* unbounded) noexcept nogil:
        """Paper's cold start: ``x`` solves the QP with equalities only, ``z = P_C(x_S)``,
        ``y = 0``.

        The factorization carries the regularization ``sigma I`` and no rho, so its
        inertia certifies convexity; a few proximal steps (``x_{j+1} = argmin f +
        sigma/2 ||x - x_j||^2`` on the same factorization) remove sigma's bias, so that
        an optimum with no active constraint is recognised at once. When the solution
        is huge the equality-constrained QP is unbounded: ``direction`` keeps the last
        proximal step (a candidate certificate) and the start falls back to the point
        of ``A x = b`` with the least ``x'(P + sigma I) x``.

        The step, not the solution, is the direction: along a ray ``d`` (``P d = 0``,
        ``A d = 0``) each step adds the same multiple of ``d``, while the solution also
        carries its bounded part and ``A x = b``, so that ``P x`` and ``A x`` are up to
        ``1e-6`` of their terms (the suite's unbounded problems: 2e-7 to 9e-7 after
        three steps), the certificate test's own tolerance; in the step they are
        rounding (1e-16), the bounded part shrinking by ``sigma / (lambda + sigma)``
        per step.
        """
        cdef Problem* p = &self.prob
        cdef Iterates* it = &self.it
        cdef Py_ssize_t n = p.n, m = p.m, i, step
        cdef double sigma = self.opt.sigma
        fill(it.rho_vec, 0.0, p.s)
        self.factored_rho = -1.0  # the KKT matrix now holds no rho factorization
        self.form = LDL_FULL
        self.table_ready = False
        cdef int code = kkt_factor(&self.kkt, p, LDL_FULL, sigma, it.rho_vec)
        if code != FACTORED:
            return NOT_CONVEX
        self.certified = True
        fill(it.x, 0.0, n)
        for i in range(m):
            self.rhs[n + i] = p.b[i]
        for step in range(_EQUALITY_START_STEPS):
            for i in range(n):
                self.rhs[i] = sigma * it.x[i] - p.q[i]
            kkt_solve(&self.kkt, p, it.rho_vec, self.rhs, self.sol)
            for i in range(n):
                self.direction[i] = self.sol[i] - it.x[i]
            copy(self.sol, it.x, n)
        copy(self.sol + n, it.nu, m)
        unbounded[0] = sigma * inf_norm(it.x, n) > _EQUALITY_START_LIMIT * max(
            1.0, inf_norm(p.q, n))
        if unbounded[0]:
            # min 1/2 x'(P + sigma I) x subject to A x = b: bounded, and A x = b holds
            # for whatever status the run ends with
            fill(self.rhs, 0.0, n)
            kkt_solve(&self.kkt, p, it.rho_vec, self.rhs, self.sol)
            copy(self.sol, it.x, n)
            fill(it.nu, 0.0, m)
        for i in range(p.s):
            it.z[i] = it.x[p.constrained[i]]
        proj_set(it.z, p.lo, p.hi, p.cones, p.s, it.z)
        fill(it.y, 0.0, p.s)
        copy(it.x, it.x_prev, n)
        copy(it.nu, it.nu_prev, m)
        copy(it.y, it.y_prev, p.s)
        return FACTORED

    cdef void _restore_equalities(self) noexcept nogil:
        """Remove the rounding that a combination of KKT solutions (``x = base + W u`` in
        the reduced form, a restoration) accumulates in ``A x = b``: one refined KKT
        solve for ``(0, b - A x)`` with the current factorization. The full form needs
        it only when its iterate misses ``A x = b`` beyond factorization accuracy
        (:meth:`_missed`): diverging iterates of an infeasible problem (``|x| = 4e6``,
        rho 2.4e5) left a 3.5e-7 relative error in their KKT solves' ``A x = b``."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t n = p.n, m = p.m, i
        if m == 0:
            return
        fill(self.rhs, 0.0, n)
        matvec(p.A, self.it.x, self.rhs + n, m, n)
        for i in range(m):
            self.rhs[n + i] = p.b[i] - self.rhs[n + i]
        kkt_solve(&self.kkt, p, self.it.rho_vec, self.rhs, self.sol)
        for i in range(n):
            self.it.x[i] += self.sol[i]
        for i in range(m):
            self.it.nu[i] += self.sol[n + i]

    cdef int _keep_restored(self, int status, long iteration, bint reduced,
                            double start_time) noexcept nogil:
        """Replace the final iterate by its feasibility restoration (see
        :mod:`fccqp.restoration`) when that is better.

        The restored point has its violating constrained entries pinned at their
        projection; its status comes from its own residuals, with the slack set to its
        (feasible) ``x_S``. It is kept when its primal residual shows that the other
        entries absorbed the pinning (``RESTORED_EQUALITY``) and, if the iterate was
        solved, when it is solved too. Equalities hold to factorization accuracy in
        either case.
        """
        cdef Problem* p = &self.prob
        cdef Iterates* it = &self.it
        cdef Py_ssize_t n = p.n, m = p.m, s = p.s, j
        cdef int new_status
        cdef bint missed = self._missed()
        copy(it.x, self.saved, n)
        copy(it.nu, self.saved + n, m)
        copy(it.z, self.saved + n + m, s)
        if restore(&self.rest, &self.kkt, &self.red, reduced, p, it):
            self._restore_equalities()
            for j in range(s):
                it.z[j] = it.x[p.constrained[j]]
            proj_set(it.z, p.lo, p.hi, p.cones, s, it.z)
            self._residuals()
            new_status = self._classify(iteration, True, start_time)
            if (self.res.prim <= _RESTORED_EQUALITY * max(1.0, self.res.prim_scale)
                    and (status != _SOLVED or new_status == _SOLVED)):
                return new_status
        copy(self.saved, it.x, n)
        copy(self.saved + n, it.nu, m)
        copy(self.saved + n + m, it.z, s)
        if reduced or missed:
            self._restore_equalities()
        return status

    cdef bint _keep_polished(self, int* status, long iteration, double start_time,
                            bint solved_only=False) noexcept nogil:
        """:func:`_try_polished`, timed: learn what a guess of the polish costs (see
        ``RESERVE_PASSES``)."""
        cdef double began = fccqp_now()
        cdef bint kept = self._try_polished(status, iteration, start_time, solved_only)
        self.pass_time = (fccqp_now() - began) / max(self.pol.passes, 1)
        return kept

    cdef bint _try_polished(self, int* status, long iteration, double start_time,
                            bint solved_only) noexcept nogil:
        """Replace the final iterate by its polished version (see :mod:`fccqp.polish`)
        when that passes a KKT check on the user's problem; True if it did.

        The polished point is accepted only when, in the user's units, it is primal
        feasible within the tolerance (box and exact cones), its multipliers lie in the
        normal cones its active set needs (:func:`fccqp.polish.multiplier_violation`,
        within ``POLISH_EXACT`` of the dual tolerance), it keeps ``A x = b`` at
        factorization accuracy (``EQUALITY_SLACK``, ``EQUALITY_EXACT``) and its primal
        and dual residuals and gap are each no worse than the ADMM point's (or below
        ``POLISH_EXACT`` times their tolerance: then the ADMM point is not measured at
        all, 12k of a go2 tick's 0.79M instructions); with ``solved_only`` (the warm
        polish) it must also be solved. Otherwise the iterate and its residuals are left as
        they were. On acceptance the status is the polished point's when that is
        solved or inaccurate.
        """
        cdef Problem* p = &self.prob
        cdef Iterates* it = &self.it
        cdef Options* o = &self.opt
        cdef Residuals* r = &self.res
        cdef Residuals before = self.res, plain, polished
        cdef Py_ssize_t n = p.n, m = p.m, s = p.s, j
        cdef double tol_p, tol_d, tol_g
        cdef int new_status, factorizations = 0   # of polishing's own matrix: not counted
        if not polish(&self.pol, p, it, o.polish_refine_iter, &factorizations,
                      &self.red if self.table_ready else NULL, &self.kkt, it.rho_vec,
                      start_time + o.time_limit):
            return False
        unscale(self.pol.x, self.pol.nu, self.pol.y, p.D, p.E, p.c, n, m, s, p.constrained,
                self.user_x, self.user_y, self.user_z)
        self._user_residuals(self.user_x, self.user_y, self.user_z)
        tol_p = o.eps_abs + o.eps_rel * r.prim_scale
        tol_d = o.eps_abs + o.eps_rel * r.dual_scale
        tol_g = o.eps_abs + o.eps_rel * r.gap_scale
        if (r.prim <= _POLISH_EXACT * tol_p and r.dual <= _POLISH_EXACT * tol_d
                and r.gap <= _POLISH_EXACT * tol_g
                and r.prim_eq <= _EQUALITY_EXACT * r.prim_eq_scale):
            plain = self.res   # the comparisons below do not need the ADMM point's
        else:   # measure the ADMM point, then the polished one again (into user_x, ...)
            polished = self.res
            unscale(it.x, it.nu, it.y, p.D, p.E, p.c, n, m, s, p.constrained, self.user_x,
                    self.user_y, self.user_z)
            self._user_residuals(self.user_x, self.user_y, self.user_z)
            plain = self.res
            unscale(self.pol.x, self.pol.nu, self.pol.y, p.D, p.E, p.c, n, m, s,
                    p.constrained, self.user_x, self.user_y, self.user_z)
            self.res = polished
        if not (r.finite
                and r.prim_eq <= o.eps_abs + o.eps_rel * r.prim_eq_scale
                and r.prim_set <= o.eps_abs + o.eps_rel * r.prim_set_scale
                and multiplier_violation(&self.pol, p, self.user_z) <= _POLISH_EXACT * tol_d
                # at EQUALITY_EXACT of max(|A x|, |b|) it is below EQUALITY_MISSED of |A||x|
                and (r.prim_eq <= _EQUALITY_EXACT * r.prim_eq_scale
                     or (r.prim_eq <= _EQUALITY_SLACK * plain.prim_eq
                         and r.prim_eq <= _EQUALITY_MISSED * self._row_terms(self.user_x)))
                and (r.prim <= plain.prim or r.prim <= _POLISH_EXACT * tol_p)
                and (r.dual <= plain.dual or r.dual <= _POLISH_EXACT * tol_d)
                and (r.gap <= plain.gap or r.gap <= _POLISH_EXACT * tol_g)
                and not (solved_only and self._classify(iteration, True, start_time) != _SOLVED)):
            self.res = before
            return False
        copy(self.pol.x, it.x, n)
        copy(self.pol.nu, it.nu, m)
        copy(self.pol.y, it.y, s)
        for j in range(s):
            it.z[j] = it.x[p.constrained[j]]
        proj_set(it.z, p.lo, p.hi, p.cones, s, it.z)
        new_status = self._classify(iteration, True, start_time)
        if new_status == _SOLVED or new_status == _INACCURATE:
            status[0] = new_status
        return True

    cdef double _row_terms(self, const double* x) noexcept nogil:
        """``max_i sum_j |A_ij x_j|`` on the user's data: the size of the terms whose
        rounding ``A x = b`` carries at factorization accuracy."""
        cdef Problem* p = &self.prob
        cdef Py_ssize_t n = p.n, i, j
        cdef double largest = 0.0, row
        for i in range(p.m):
            row = 0.0
            for j in range(n):
                row += fabs(self.A_user[i * n + j] * x[j])
            largest = max(largest, row)
        return largest

    # ------------------------------------------------------------- bookkeeping

    cdef void _residuals(self) noexcept nogil:
        residuals(&self.prob, &self.it, self.vec_m, self.vec_n, self.vec_n2, &self.res)

    cdef void _log(self, long iteration, double rho) noexcept nogil:
        cdef double* row
        if self.log_count < self.log_rows:
            row = self.log + 5 * self.log_count
            row[0], row[1], row[2], row[3], row[4] = (
                iteration, self.res.prim, self.res.dual, self.res.gap, rho)
            self.log_count += 1

    cdef void _finish_run(self, Run* run, int status, long iteration) noexcept nogil:
        run.status = status
        run.iterations = iteration
        run.backend = self.form

    cdef void _finish(self, Run* run, double* x, double* y, double* z,
                      double* cert) noexcept nogil:
        """Unscale the iterate into the result arrays, recompute its residuals in the
        user's units from the returned point alone (the primal one as the distance of
        ``x_S`` to C), settle the status on them and keep the point for a warm start."""
        cdef Problem* p = &self.prob
        cdef Iterates* it = &self.it
        cdef Py_ssize_t n = p.n, m = p.m, s = p.s
        if self.user_current:   # a warm polish's point: unscaled and measured already
            copy(self.user_x, x, n)
            if m:
                copy(self.user_y, y, m)
            copy(self.user_z, z, n)
        else:
            unscale(it.x, it.nu, it.y, p.D, p.E, p.c, n, m, s, p.constrained, x, y, z)
            if run.status == _PRIMAL_INFEASIBLE or run.status == _DUAL_INFEASIBLE:
                copy(self.cert, cert, n + m)
            self._user_residuals(x, y, z)
        if run.status in (_SOLVED, _INACCURATE, _MAX_ITER, _TIME_LIMIT):
            if converged(&self.res, self.opt.eps_abs, self.opt.eps_rel):
                run.status = _SOLVED
            elif nearly_converged(&self.res, self.opt.eps_abs, self.opt.eps_rel, _INACCURATE_FACTOR):
                run.status = _INACCURATE
            elif run.status in (_SOLVED, _INACCURATE):
                # the iterate passed, the returned point does not: a budget that ran out
                # says so (finite residuals are no numerical error), else the point
                # carries no guarantee
                run.status = (_MAX_ITER if run.iterations >= self.opt.max_iter
                              else _TIME_LIMIT if fccqp_now() - self.clock[0] >= self.opt.time_limit
                              else _NUMERICAL_ERROR)
        if not self.res.finite:
            run.status = _NUMERICAL_ERROR
        self.has_previous = self.res.finite and run.status not in (
            _PRIMAL_INFEASIBLE, _DUAL_INFEASIBLE)
        if self.has_previous:
            copy(x, self.prev_x, n)
            copy(y, self.prev_y, m)
            copy(z, self.prev_z, n)
            self.prev_rho = run.rho
            self.has_rho = True
        self.prev_polished = self.has_previous and run.polished

    cdef void _user_residuals(self, const double* x, const double* y,
                              const double* z) noexcept nogil:
        """:mod:`fccqp.termination`'s residuals of the returned ``(x, y, z)`` on the user's
        data, with ``dist(x_S, C)`` as the primal part off the equalities."""
        cdef Problem* p = &self.prob
        cdef Residuals* r = &self.res
        cdef Py_ssize_t n = p.n, m = p.m, s = p.s, i, j
        cdef double* Ax = self.vec_m
        cdef double* grad = self.vec_n
        cdef double* ATy = self.vec_n2
        cdef double* proj = self.vec_s
        cdef double xPx = 0.0, qx = 0.0, by = 0.0, support = 0.0, terms = 0.0, total = 0.0
        cdef double value
        matvec(self.A_user, x, Ax, m, n)
        matvec_t(self.A_user, y, ATy, m, n)
        matvec(self.P_user, x, grad, n, n)
        r.prim_eq = r.prim_eq_scale = r.prim_set = r.prim_set_scale = 0.0
        for i in range(m):
            r.prim_eq = max(r.prim_eq, fabs(Ax[i] - self.b_user[i]))
            r.prim_eq_scale = max(r.prim_eq_scale, max(fabs(Ax[i]), fabs(self.b_user[i])))
            by += self.b_user[i] * y[i]
            terms += fabs(self.b_user[i] * y[i])
        for j in range(s):
            i = p.constrained[j]
            value = x[i]
            if value < self.lb_user[i]:
                value = self.lb_user[i]
            if value > self.ub_user[i]:
                value = self.ub_user[i]
            proj[j] = value
        for j in range(p.cones.count):   # cone blocks are contiguous in x too
            i = p.cones.offset[j]
            proj_block(x + p.constrained[i], p.cones.kind[j], p.cones.dim[j], p.cones.mu[j],
                       p.cones.normal + 3 * j, proj + i)
        r.dual_scale = 0.0
        for j in range(s):
            i = p.constrained[j]
            r.prim_set = max(r.prim_set, fabs(x[i] - proj[j]))
            r.prim_set_scale = max(r.prim_set_scale, fabs(x[i]))
            if z[i] > 0.0 and isfinite(self.ub_user[i]):
                support += self.ub_user[i] * z[i]
                terms += fabs(self.ub_user[i] * z[i])
            elif z[i] < 0.0 and isfinite(self.lb_user[i]):
                support += self.lb_user[i] * z[i]
                terms += fabs(self.lb_user[i] * z[i])
        r.dual = 0.0
        for i in range(n):
            xPx += x[i] * grad[i]
            qx += self.q_user[i] * x[i]
            r.dual_scale = max(r.dual_scale, max(fabs(grad[i]), fabs(self.q_user[i])))
            value = grad[i] + self.q_user[i] + ATy[i] + z[i]
            r.dual = max(r.dual, fabs(value))
            total += fabs(value) + fabs(x[i]) + fabs(z[i])
        for i in range(m):
            total += fabs(y[i])
        r.objective = 0.5 * xPx + qx
        r.gap = fabs(xPx + qx + by + support)
        r.gap_scale = gap_scale(xPx, qx, terms)
        r.prim = max(r.prim_eq, r.prim_set)
        r.prim_scale = max(r.prim_eq_scale, r.prim_set_scale)
        r.finite = isfinite(total) and isfinite(r.gap) and isfinite(r.prim)

