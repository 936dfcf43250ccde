# cython: language_level=3
"""The C state of a solve, one struct per role, shared by the modules of the dense core.

:class:`fccqp.admm.Workspace` allocates every array once per problem structure and holds
one :c:type:`Engine`; the compiled steps (``scaled_run``, ``iteration``, ``factorization``,
``verdict``, ``acceptance``) take a pointer to it. Nothing here allocates: the structs
hold pointers into the workspace's numpy arrays.
"""

from libc.math cimport isfinite

from fccqp._types cimport Iterates, Problem
from fccqp.anderson cimport Anderson
from fccqp.kkt cimport KKT
from fccqp.matrices cimport Matrix
from fccqp.polish cimport Polish
from fccqp.reduced cimport Reduced
from fccqp.restoration cimport Restoration
from fccqp.scaling cimport Pattern
from fccqp.termination cimport Residuals, residuals

cdef extern from "fccqp_clock.h" nogil:
    double fccqp_now()


cdef enum:
    # How a run ends; fccqp.admm.STATUS_BY_CODE maps the positive codes to fccqp.Status.
    RUNNING = 0
    SOLVED = 1
    INACCURATE = 2
    MAX_ITER = 3
    TIME_LIMIT = 4
    PRIMAL_INFEASIBLE = 5
    DUAL_INFEASIBLE = 6
    NUMERICAL_ERROR = 7
    NOT_CONVEX_QP = -1      # the KKT inertia shows that the QP is not convex
    BAD_NUMBERS = -2        # the validation scan found bad numbers
    NEW_STRUCTURE = -3      # the bounds no longer have the workspace's structure

cdef enum:
    CONE_ENTRY = 3   # UserData.entry_kind of a cone entry, beside fccqp.validation's bound_kind codes


cdef struct Options:
    # Settings of fccqp.Settings the kernels read.
    double rho, sigma, alpha, eps_abs, eps_rel, eps_prim_inf, eps_dual_inf
    double time_limit, adaptive_rho_tolerance
    long max_iter, min_iter, check_termination, adaptive_rho_interval, scaling, polish_refine_iter
    bint adaptive_rho, restore_feasibility, polish
    int backend, anderson_memory


cdef struct Run:
    # What one run reports back.
    int status
    long iterations
    double rho
    int factorizations
    double setup_time
    int backend
    bint polished
    bint converging     # stopped at its cap, its distance shrunk by CONVERGING over the last half


cdef struct UserData:
    # Private copies of the user's last data (validation.scan_and_copy writes them).
    Matrix P
    double* q
    Matrix A
    double* b
    double* lb
    double* ub
    char* entry_kind            # n: bound_kind of the bounds at allocation, or CONE_ENTRY
    Py_ssize_t* block_start     # cone count: first entry of x of each cone block
    bint has_matrices           # P and A hold a validated problem's (to detect reuse)


cdef struct Scaling:
    # The equilibration's memory between solves (fccqp.scaling).
    double* reference           # n + m: norms of the scaled matrices at the last equilibration
    double* norms               # n + m scratch
    double* d                   # n scratch
    double* e                   # m scratch
    Pattern pattern             # the nonzeros of the dense P and A at the last equilibration
    bint done                   # an equilibration ran for this workspace
    bint kept                   # the last run's scaling is an earlier equilibration's
    # The equilibration in use before the current one (its D, E and reference), tried
    # when new data drift from the current one: a trot's two stances share a structure
    # and drift 30-40x from each other's scaling (fccqp.scaled_run._scale).
    double* other_D             # n
    double* other_E             # m
    double* other_reference     # n + m
    bint other_done             # the three above hold an equilibration


cdef struct Factorization:
    # The KKT factorization and what it holds.
    KKT kkt
    int form                    # the backend factored last (full_form after the cold start)
    double factored_rho         # the rho it factored; -1 when it holds none
    double* rho_scale           # s: rho multiplier per constrained entry (FIXED_RHO_SCALE on lb == ub)
    bint certified              # the current matrices are proven convex
    bint table_ready            # the reduced table and base hold for this solve's data and rho


cdef struct Certificates:
    # Infeasibility certificates and the schedule of cleaning them.
    double* direction           # n: the step tested as a ray (dual certificate)
    double* cert                # n + m: the certificate found, in the user's units
    double* gram                # m x m: Cholesky factor of A A' for cleaning certificates
    int gram_state              # gram: 0 not factored in this solve, 1 factored, -1 failed
    double stalled_prim         # primal residual at the last check that could clean
    long stalled_at             # and that check's iteration
    double checked_prim         # primal residual at the last check
    long checked_at             # and that check's iteration
    int stalled_checks          # checks in a row that could clean whose residual stalled
    long next_cleaning          # when the next cleaning may run
    long cleaning_wait          # and the wait after a failed one
    double row_norm             # A's largest row 1-norm (primal test), < 0 until needed
    bint weak                   # cert holds this run's first WEAK primal candidate


cdef struct Previous:
    # The last solution, in the user's units, for a warm start.
    double* x
    double* y
    double* z
    double rho
    bint exists                 # x, y, z hold a finite, not infeasible, solution
    bint polished               # and it was polished
    bint from_polished          # this solve starts from it
    bint has_rho                # rho is one some solve adapted (a cold start keeps it too)
    bint guessed                # x, y, z are a caller's guess, not an answer
    bint carried                # and carried from another structure (a contact change)


cdef struct UserPoint:
    # A point unscaled to the user's units (the polish's check, the returned point).
    double* x
    double* y
    double* z
    bint current                # x, y, z and the residuals are the returned point's


cdef struct Clock:
    double marks[6]             # phase boundaries of the last solve (Workspace.phase_times)
    double final_reserve        # seconds the final polish or restoration took lately
    double pass_time            # seconds per guess of the last polish of an iterate, its check included
    double polish_end           # when the final step's polish ended (or was skipped)
    double tail_time            # seconds unpolished final steps took after their polish lately
    double rho_time             # seconds the last change of rho took (its factorization)


cdef struct Log:
    double* rows                # log_rows x 5: (iteration, prim, dual, gap, rho)
    Py_ssize_t capacity, count


cdef struct Scratch:
    double* rhs                 # n + m: a KKT right-hand side
    double* sol                 # n + m: its solution
    double* vec_n
    double* vec_n2
    double* vec_n3
    double* vec_s
    double* vec_s2
    double* mat_s               # s x s: the equality start's small system (column-major)
    double* vec_m
    double* vec_m2
    double* saved               # n + m + s: an iterate kept while a replacement is tried
    double* guess_point         # s scratch of guess_changes
    char* guess_codes           # s: the active set ADMM's iterate pointed to at the last check


cdef struct Engine:
    Problem prob                # the scaled problem
    UserData user
    Scaling scaling
    Iterates it
    Factorization fact
    Reduced red
    Anderson aa
    Restoration rest
    Polish pol
    Options opt
    Residuals res
    Certificates certs
    Previous prev
    UserPoint unscaled
    Clock clock
    Log log
    Scratch work
    double tighten              # factor on the tolerances of the run (see POLISH_RETRIES)
    bint iterated               # the last solve ran the iterations (and then its final step)
    bint equalities_missed      # the last cold start did not meet A x = b


cdef inline void measure(Engine* e) noexcept nogil:
    """The residuals of the scaled iterate (:func:`fccqp.termination.residuals`)."""
    residuals(&e.prob, &e.it, e.work.vec_m, e.work.vec_n, e.work.vec_n2, &e.res)


cdef inline double cold_start_rho(const Engine* e) noexcept nogil:
    """The rho of a cold start: under a time limit the one the last solve adapted (as
    OSQP keeps its rho between solves: fewer iterations and factorizations on
    talos_reduced's cold starts), else ``settings.rho`` (without a time limit keeping it
    helped solo12 but cost talos_reduced and anymal_c iterations; notes/tuning.md, "The
    rho of a cold start")."""
    return e.prev.rho if e.prev.has_rho and isfinite(e.opt.time_limit) else e.opt.rho


cdef inline void end_run(Engine* e, Run* run, int status, long iteration) noexcept nogil:
    run.status = status
    run.iterations = iteration
    run.backend = e.fact.form
