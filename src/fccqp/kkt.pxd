# cython: language_level=3
from fccqp._types cimport Problem
from fccqp.ldl cimport LDL
from fccqp.matrices cimport CSC
from fccqp.schur cimport Schur

cdef enum:
    # Backends of the x-update (Settings.kkt_backend), in the order "auto" tries them.
    SCHUR_REDUCED = 0   # Cholesky of P + R and of A H^-1 A', reduced iteration
    LDL_REDUCED = 1     # quasi-definite LDL', reduced iteration
    LDL_FULL = 2        # quasi-definite LDL', one refined KKT solve per iteration
    AUTO = 3
    SPARSE_LDL = 4      # qdldl's LDL' of the full form, the only backend of compressed columns

cdef enum:
    # Outcomes of kkt_factor.
    FACTORED = 0
    NOT_CONVEX = 1      # the inertia shows negative curvature of P on the null space of A
    UNAVAILABLE = 2     # this backend cannot factor this matrix (caller falls back)

cdef struct KKT:
    int backend         # the backend factored last
    double sigma        # the proximal term it was factored with
    LDL ldl
    Schur schur
    double* R           # (n + m) x s scratch, for refining columns
    double* work        # n + m scratch
    void* sparse        # SPARSE_LDL: the fccqp.sparse_kkt.SparseKKT (a PyObject* the workspace owns)

cdef int kkt_factor(KKT* k, const Problem* p, int backend, double sigma,
                    const double* rho_vec) noexcept nogil
cdef void kkt_solve(KKT* k, const Problem* p, const double* rho_vec, const double* rhs,
                    double* sol) noexcept nogil
cdef void kkt_solve_once(KKT* k, const Problem* p, const double* rho_vec, const double* rhs,
                         double* sol) noexcept nogil
cdef bint kkt_unit_columns(KKT* k, const Problem* p, const double* rho_vec,
                           const Py_ssize_t* entries, int count, double* W) noexcept nogil
cdef bint kkt_table(KKT* k, const Problem* p, const double* rho_vec, double* W,
                    double* W_S) noexcept nogil
cdef int kkt_convexity(KKT* k, const Problem* p, double sigma, const double* rho_vec,
                       bint schur_factored) noexcept nogil


cdef inline int full_form(const Problem* p) noexcept nogil:
    """The backend of one refined KKT solve per iteration for ``p``'s storage:
    ``LDL_FULL`` (dense) or ``SPARSE_LDL`` (compressed columns)."""
    return SPARSE_LDL if p.P.kind == CSC else LDL_FULL


cdef inline bint is_reduced(int form) noexcept nogil:
    """Whether the backend ``form`` iterates in the reduced form (with its table)."""
    return form == SCHUR_REDUCED or form == LDL_REDUCED
