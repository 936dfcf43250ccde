# cython: language_level=3
from fccqp.matrices cimport Matrix
from fccqp.tuning cimport INFINITE_BOUND

cdef enum:
    # Codes of scan_and_copy's findings, turned into messages by fccqp.problem.
    SCAN_OK = 0
    P_NOT_FINITE = 1
    P_ASYMMETRIC = 2
    NOT_FINITE = 3      # q, A, b (argument 0-2)
    NAN_BOUND = 4       # lb, ub (argument 3-4)
    CROSSED = 5
    INFINITE_SIDE = 6
    TOO_LARGE = 7       # an entry beyond MAX_ENTRY
    NEW_PATTERN = 8     # scan_and_copy_csc: P or A has another pattern than the workspace's

cdef enum:
    # Codes of bound_kind.
    UNBOUNDED = 0
    BOUNDED = 1
    FIXED_BOUND = 2

cdef struct Finding:
    int code
    int argument        # q, A, b, lb, ub numbered 0-4; -1 for P
    Py_ssize_t index
    double value

cdef Finding scan_and_copy(const double* P, const double* q, const double* A, const double* b,
                           const double* lb, const double* ub, Py_ssize_t n, Py_ssize_t m,
                           double* P_out, double* q_out, double* A_out, double* b_out,
                           double* lb_out, double* ub_out, bint* same_matrices) noexcept nogil
cdef Finding scan_and_copy_csc(const Matrix* P, const double* q, const Matrix* A,
                               const double* b, const double* lb, const double* ub,
                               Matrix* P_out, double* q_out, Matrix* A_out, double* b_out,
                               double* lb_out, double* ub_out,
                               bint* same_matrices) noexcept nogil
cdef inline int bound_kind(double lb, double ub) noexcept nogil:
    """How the bounds ``lb, ub`` of one entry constrain it: ``UNBOUNDED`` (both beyond
    ``INFINITE_BOUND``), ``FIXED_BOUND`` (``lb == ub``) or ``BOUNDED``. The one rule for
    :func:`structure_scan` and the workspace's check of each solve's bounds."""
    if lb > -INFINITE_BOUND or ub < INFINITE_BOUND:
        return FIXED_BOUND if lb == ub else BOUNDED
    return UNBOUNDED
