# cython: language_level=3
from fccqp._types cimport Iterates, Problem
from fccqp.kkt cimport KKT
from fccqp.polish_csc cimport PolishCSC
from fccqp.polish_schur cimport PolishSchur
from fccqp.reduced cimport Reduced

cdef enum:
    # Active-set codes of a constrained entry (Polish.active).
    FREE = 0        # no constraint imposed
    LOWER = 1       # box entry held at its lower bound
    UPPER = 2       # box entry held at its upper bound
    FIXED = 3       # box entry with lo == hi: held there, its multiplier of either sign
    APEX = 4        # entry of a cone block held at the apex (the block is 0)
    BOUNDARY = 5    # entry of a cone block on the cone's tangent plane

cdef enum:
    # Whether a boundary block's plane lacks its curvature (Polish.bare).
    CURVED = 0      # its plane was placed with its curvature
    BARE = 1        # its plane was placed without (its multiplier was not positive)
    KEPT = 2        # bare, its multiplier now positive: the plane is in kept_plane

cdef struct Polish:
    # Scratch of the polishing step; N = n + m + s bounds the size of its KKT system.
    char* active            # s: the guess, one code per constrained entry
    Py_ssize_t* index       # n: position of x_i among the unknowns, -1 when held fixed
    Py_ssize_t* free        # n: the entries that are unknowns, ascending
    Py_ssize_t* boundary    # s: the cone blocks on their boundary
    double* g               # s: unit normal of each boundary block's tangent plane
    double* hess            # a boundary block's curvature term (d x d) at hess + offset * hess_stride
    Py_ssize_t hess_stride  # s (hess is s x s) on dense storage; on CSC, polish points hess at PolishCSC's
    double* K               # N x N, Fortran order; the factor after dsytrf (dense P and A)
    int* ipiv               # N
    PolishSchur schur       # the Schur-complement solve where P's structure allows it
    PolishCSC csc           # the assembled matrix and its qdldl factor where P and A are CSC
    bint structured         # the current guess is factored in schur, not in K
    double delta            # the regularization of the current factorization
    bint retry_spent        # a refactorization with a smaller delta failed: no other on this one
    bint schur_only         # fail rather than assemble for dsytrf where schur does not apply
    bint schur_failed       # the last polish failed so
    long passes             # the guesses the last polish solved
    long guess_passes       # the most guesses a polish solves (GUESS_PASSES; a warm polish WARM_GUESS_PASSES)
    bint warm               # a warm polish (the previous answer's active set): it gives up a hopeless crawl
    bint bare_start         # a polish from no multipliers (a carried guess): its planes start without curvature
    char* dropped           # cone count: the block went past its apex in this polish
    char* bare              # cone count: BARE, the block's plane was placed without its curvature (lam <= 0); KEPT, and that plane is in kept_plane
    double* kept_plane      # s: a KEPT block's curvature-less plane, where Newton's first solve puts it back
    char* blocked           # s: the constraints a step holds (polish_guess.step_length)
    bint cycling            # a block went past its apex twice: the guess cycles
    double* work            # lwork entries, for dsytrf
    int lwork
    double* rhs             # N: residual of the current solution
    double* step            # N: correction solved from rhs
    double* lam             # s: multiplier of each boundary block's tangent plane
    double* x               # n: the polished point (scaled problem)
    double* nu              # m: its equality multipliers
    double* y               # s: its constraint multipliers
    double* x_prev          # n: the point a step starts from (see polish)
    double* nu_prev         # m: its equality multipliers
    double* chord_start     # n + m + 2 s: (x, nu, y, lam) before a chord step, to undo it
    double* grad            # n: scratch, the gradient of the Lagrangian
    bint grad_current       # grad and Ax are those of the current (x, nu): reused until they move
    double* ATnu            # n: scratch
    double* Ax              # m: scratch
    # the solve in the reduced form's coordinates (fccqp.polish_table)
    double* T               # (2 s)^2, Fortran order: its matrix, the LU factor after dgetrf
    int* tpiv               # 2 s
    double* tr              # 2 s: residual of the constraints' conditions, then solution
    double* du              # 2 s: the last correction (du, dlam)
    double* full            # n + m: residual of the KKT conditions
    double* dfull           # n + m: the last correction (dx, dnu)
    double kkt_norm         # infinity norm of full

cdef bint polish(Polish* w, const Problem* p, const Iterates* it, long newton_steps,
                 int* factorizations, const Reduced* table, KKT* kkt,
                 const double* rho_vec, double deadline,
                 double multiplier_slack, bint from_iterate) noexcept nogil
cdef bint polish_prepare(Polish* w, const Problem* p) noexcept nogil
cdef Py_ssize_t guess_changes(const Problem* p, const double* z, const double* y,
                              double* point, char* codes) noexcept nogil
