# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The numeric half of input validation, fused with the copy into the workspace.

One pass over the user's arrays checks that they are finite (bounds: not NaN, ``lb <=
ub``, no ``lb = +inf`` or ``ub = -inf``), that ``P`` is symmetric up to rounding, and
that no entry exceeds ``MAX_ENTRY``; it writes ``(P + P') / 2`` and the other arrays
into the workspace's private copies (a caller may refill its arrays in place before
the next solve) and reports whether ``P`` and ``A`` equal the previous copies, which
decides whether the scaling and the factorization can be reused. Bounds of magnitude
``INFINITE_BOUND`` or more are stored as infinite, as Clarabel's presolve does.
The shape and type half lives in :mod:`fccqp.problem`.
"""

from libc.math cimport INFINITY, fabs, isfinite, isnan

from fccqp.tuning cimport INFINITE_BOUND, MAX_ENTRY, SYMMETRY_TOLERANCE

cdef extern from "fccqp_kernels.h" nogil:
    int FCCQP_NOT_FINITE, FCCQP_CHANGED
    int fccqp_symmetric_copy(const double* P, int n, double* out, double* sizes)
    int fccqp_checked_copy(const double* v, long k, double limit, double* out)


cdef inline Finding _found(int code, int argument, Py_ssize_t index, double value) noexcept nogil:
    cdef Finding f
    f.code, f.argument, f.index, f.value = code, argument, index, value
    return f


cdef inline Finding _check_vector(const double* v, double* out, Py_ssize_t k,
                                  int argument) noexcept nogil:
    cdef Py_ssize_t i
    for i in range(k):
        if not isfinite(v[i]):
            return _found(NOT_FINITE, argument, i, v[i])
        if fabs(v[i]) > MAX_ENTRY:
            return _found(TOO_LARGE, argument, i, v[i])
        out[i] = v[i]
    return _found(SCAN_OK, -1, -1, 0.0)


cdef Finding _first_bad_entry(const double* P, Py_ssize_t n) noexcept nogil:
    """The first non-finite entry of ``P``, or the largest one (the slow path of a
    scan that found something wrong)."""
    cdef Py_ssize_t i, j
    cdef double largest = 0.0
    for i in range(n):
        for j in range(n):
            if not isfinite(P[i * n + j]):
                return _found(P_NOT_FINITE, -1, i, P[i * n + j])
            largest = max(largest, fabs(P[i * n + j]))
    return _found(TOO_LARGE, -1, 0, largest)


cdef Finding scan_and_copy(const double* P, const double* q, const double* A, const double* b,
                           const double* lb, const double* ub, Py_ssize_t n, Py_ssize_t m,
                           double* P_out, double* q_out, double* A_out, double* b_out,
                           double* lb_out, double* ub_out, bint* same_matrices) noexcept nogil:
    """Check and copy; ``same_matrices`` becomes False as soon as ``P`` or ``A`` differs
    from what ``P_out``, ``A_out`` held.

    ``P`` goes through ``fccqp_symmetric_copy`` (four pairs ``(i, j), (j, i)`` of the
    upper triangle a step) and ``A`` through ``fccqp_checked_copy`` (fccqp_kernels.h),
    passes that do not branch on the data; what went wrong is looked up only when
    something did.
    """
    cdef Py_ssize_t i
    cdef double sizes[2]   # the largest entry and asymmetry of P
    cdef bint same = same_matrices[0], differs
    cdef int found = fccqp_symmetric_copy(P, <int>n, P_out, sizes)
    cdef Finding f
    if found & FCCQP_NOT_FINITE or sizes[0] > MAX_ENTRY:
        return _first_bad_entry(P, n)
    if sizes[1] > SYMMETRY_TOLERANCE * sizes[0]:
        return _found(P_ASYMMETRIC, -1, -1, sizes[1])
    differs = found & FCCQP_CHANGED
    found = fccqp_checked_copy(A, m * n, MAX_ENTRY, A_out)
    differs |= found & FCCQP_CHANGED
    if found & FCCQP_NOT_FINITE:   # NaN, infinite or too large
        for i in range(m * n):
            if not isfinite(A[i]):
                return _found(NOT_FINITE, 1, i // n, A[i])
            if fabs(A[i]) > MAX_ENTRY:
                return _found(TOO_LARGE, 1, i // n, A[i])
    same_matrices[0] = same and not differs
    f = _check_vector(q, q_out, n, 0)
    if f.code != SCAN_OK:
        return f
    f = _check_vector(b, b_out, m, 2)
    if f.code != SCAN_OK:
        return f
    for i in range(n):
        if isnan(lb[i]):
            return _found(NAN_BOUND, 3, i, lb[i])
        if isnan(ub[i]):
            return _found(NAN_BOUND, 4, i, ub[i])
        if lb[i] > ub[i]:
            return _found(CROSSED, 3, i, lb[i])
        if lb[i] == INFINITY:
            return _found(INFINITE_SIDE, 3, i, lb[i])
        if ub[i] == -INFINITY:
            return _found(INFINITE_SIDE, 4, i, ub[i])
        lb_out[i] = lb[i] if lb[i] > -INFINITE_BOUND else -INFINITY
        ub_out[i] = ub[i] if ub[i] < INFINITE_BOUND else INFINITY
    return _found(SCAN_OK, -1, -1, 0.0)


cdef int bound_kind(double lb, double ub) noexcept nogil:
    """How the bounds ``lb, ub`` of one entry constrain it: ``UNBOUNDED`` (both beyond
    ``INFINITE_BOUND``), ``FIXED_BOUND`` (``lb == ub``) or ``BOUNDED``. The one rule for
    :func:`structure_scan` and the workspace's check of each solve's bounds."""
    if lb > -INFINITE_BOUND or ub < INFINITE_BOUND:
        return FIXED_BOUND if lb == ub else BOUNDED
    return UNBOUNDED


def structure_scan(const double[::1] lb, const double[::1] ub, const Py_ssize_t[::1] offset,
                   const Py_ssize_t[::1] dim, Py_ssize_t[::1] constrained,
                   unsigned char[::1] fixed, Py_ssize_t[::1] relocated, Py_ssize_t count):
    """Update the splitting's structure in place and say whether it changed.

    ``constrained`` receives the entries with a finite bound (magnitude below
    ``INFINITE_BOUND``) or in a cone block (blocks ``x[offset:offset + dim]``, sorted by
    offset or not), ascending; ``fixed`` which of them have ``lb == ub``; ``relocated``
    each block's offset in ``constrained``. ``count`` is the previous number of
    constrained entries. Returns ``(count, changed, bounded_member)``, the last the first
    cone entry with a finite bound or -1. One pass, no allocation: the control-loop
    case, where the structure rarely changes, costs a microsecond.
    """
    cdef Py_ssize_t n = lb.shape[0], blocks = offset.shape[0], i, k, j = 0, member = -1
    cdef bint changed = False, in_cone
    cdef unsigned char is_fixed
    cdef int kind
    for i in range(n):
        in_cone = False
        for k in range(blocks):
            if offset[k] <= i < offset[k] + dim[k]:
                in_cone = True
                if i == offset[k]:
                    if relocated[k] != j:
                        changed = True
                        relocated[k] = j
                break
        kind = bound_kind(lb[i], ub[i])
        if in_cone and kind != UNBOUNDED and member < 0:
            member = i
        if in_cone or kind != UNBOUNDED:
            is_fixed = kind == FIXED_BOUND
            if j >= count or constrained[j] != i or fixed[j] != is_fixed:
                changed = True
                constrained[j] = i
                fixed[j] = is_fixed
            j += 1
    return j, changed or j != count, member
