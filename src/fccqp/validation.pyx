# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The numeric half of input validation, fused with the copy into the workspace.

One pass over the user's arrays checks that they are finite (bounds: not NaN, ``lb <=
ub``, no ``lb = +inf`` or ``ub = -inf``), that ``P`` is symmetric up to rounding, and
that no entry exceeds ``MAX_ENTRY``; it writes ``(P + P') / 2`` and the other arrays
into the workspace's private copies (a caller may refill its arrays in place before
the next solve) and reports whether ``P`` and ``A`` equal the previous copies, which
decides whether the scaling and the factorization can be reused. Bounds of magnitude
``INFINITE_BOUND`` or more are stored as infinite, as Clarabel's presolve does.
The shape and type half lives in :mod:`fccqp.problem`. :func:`scan_and_copy_csc` is
the scan of compressed-column ``P`` and ``A`` (the sparse backend, issue 28; not yet on
a solve's path).
"""

from libc.math cimport INFINITY, fabs, isfinite, isnan

from fccqp.matrices cimport Matrix
from fccqp.matrix_ops cimport Held
from fccqp.tuning cimport INFINITE_BOUND, MAX_ENTRY, SYMMETRY_TOLERANCE

cdef extern from "fccqp_kernels.h" nogil:
    int FCCQP_NOT_FINITE, FCCQP_CHANGED
    int fccqp_scan_symmetric(const double* P, int n, double* out, double* sizes)
    int fccqp_scan_copy(const double* v, long k, double limit, double* out)
    int fccqp_bounds_copy(const double* lb, const double* ub, long n, double big,
                          double* lb_out, double* ub_out)


cdef inline Finding _found(int code, int argument, Py_ssize_t index, double value) noexcept nogil:
    cdef Finding f
    f.code, f.argument, f.index, f.value = code, argument, index, value
    return f


cdef inline Finding _check_vector(const double* v, double* out, Py_ssize_t k,
                                  int argument) noexcept nogil:
    """Check and copy the vector ``v`` (``fccqp_scan_copy``); its first entry that is not
    finite or exceeds ``MAX_ENTRY`` is looked up only when there is one."""
    cdef Py_ssize_t i
    if fccqp_scan_copy(v, k, MAX_ENTRY, out) & FCCQP_NOT_FINITE:
        for i in range(k):
            if not isfinite(v[i]):
                return _found(NOT_FINITE, argument, i, v[i])
            if fabs(v[i]) > MAX_ENTRY:
                return _found(TOO_LARGE, argument, i, v[i])
    return _found(SCAN_OK, -1, -1, 0.0)


cdef Finding _first_bad_entry(const double* P, Py_ssize_t n) noexcept nogil:
    """The first non-finite entry of ``P``, or the first of its largest ones, with its
    row (the slow path of a scan that found something wrong)."""
    cdef Py_ssize_t i, j, largest_row = 0
    cdef double largest = 0.0
    for i in range(n):
        for j in range(n):
            if not isfinite(P[i * n + j]):
                return _found(P_NOT_FINITE, -1, i, P[i * n + j])
            if fabs(P[i * n + j]) > largest:
                largest, largest_row = fabs(P[i * n + j]), i
    return _found(TOO_LARGE, -1, largest_row, largest)


cdef Finding scan_and_copy(const double* P, const double* q, const double* A, const double* b,
                           const double* lb, const double* ub, Py_ssize_t n, Py_ssize_t m,
                           double* P_out, double* q_out, double* A_out, double* b_out,
                           double* lb_out, double* ub_out, bint* same_matrices) noexcept nogil:
    """Check and copy; ``same_matrices`` becomes False as soon as ``P`` or ``A`` differs
    from what ``P_out``, ``A_out`` held.

    ``P`` goes through ``fccqp_scan_symmetric`` (four pairs ``(i, j), (j, i)`` of the
    upper triangle a step) and ``A`` through ``fccqp_scan_copy`` (fccqp_kernels.h: one
    32-byte vector a step where the CPU has AVX2, two halves else), passes that do not
    branch on the data; what went wrong is looked up only when something did.
    """
    cdef Py_ssize_t i
    cdef double sizes[2]   # the largest entry and asymmetry of P
    cdef bint same = same_matrices[0], differs
    cdef int found = fccqp_scan_symmetric(P, <int>n, P_out, sizes)
    cdef Finding f
    if found & FCCQP_NOT_FINITE or sizes[0] > MAX_ENTRY:
        return _first_bad_entry(P, n)
    if sizes[1] > SYMMETRY_TOLERANCE * sizes[0]:
        return _found(P_ASYMMETRIC, -1, -1, sizes[1])
    differs = found & FCCQP_CHANGED
    found = fccqp_scan_copy(A, m * n, MAX_ENTRY, A_out)
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
    return _check_bounds(lb, ub, n, lb_out, ub_out)


cdef inline Finding _check_bounds(const double* lb, const double* ub, Py_ssize_t n,
                                  double* lb_out, double* ub_out) noexcept nogil:
    """Check and copy the bounds (both storages' last step), magnitudes of
    ``INFINITE_BOUND`` or more stored as infinite (``fccqp_bounds_copy``); the first bad
    entry is looked up only when there is one."""
    cdef Py_ssize_t i
    if fccqp_bounds_copy(lb, ub, n, INFINITE_BOUND, lb_out, ub_out):
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
    return _found(SCAN_OK, -1, -1, 0.0)


cdef Finding scan_and_copy_csc(const Matrix* P, const double* q, const Matrix* A,
                               const double* b, const double* lb, const double* ub,
                               Matrix* P_out, double* q_out, Matrix* A_out, double* b_out,
                               double* lb_out, double* ub_out,
                               bint* same_matrices) noexcept nogil:
    """:func:`scan_and_copy` for ``P`` and ``A`` in compressed columns (issue 28): the
    finding ``NEW_PATTERN`` when their patterns are not ``P_out``'s and ``A_out``'s (the
    workspace's, fixed at allocation), else the same checks, copies, findings and
    ``same_matrices`` as the dense scan, but for the symmetry of ``P``, which the
    conversion to compressed columns checks and makes exact (``(P + P') / 2``)."""
    cdef bint differs = False
    cdef Finding f
    if not (_same_pattern(P, P_out) and _same_pattern(A, A_out)):
        return _found(NEW_PATTERN, -1, -1, 0.0)
    if not _copy_entries(P, P_out, &differs):
        return _first_bad_csc(P, -1)
    if not _copy_entries(A, A_out, &differs):
        return _first_bad_csc(A, 1)
    same_matrices[0] = same_matrices[0] and not differs
    f = _check_vector(q, q_out, P.cols, 0)
    if f.code != SCAN_OK:
        return f
    f = _check_vector(b, b_out, A.rows, 2)
    if f.code != SCAN_OK:
        return f
    return _check_bounds(lb, ub, P.cols, lb_out, ub_out)


cdef bint _same_pattern(const Matrix* M, const Matrix* pattern) noexcept nogil:
    cdef Py_ssize_t j, k
    if M.rows != pattern.rows or M.cols != pattern.cols:
        return False
    for j in range(M.cols + 1):
        if M.colptr[j] != pattern.colptr[j]:
            return False
    for k in range(M.colptr[M.cols]):
        if M.rowind[k] != pattern.rowind[k]:
            return False
    return True


cdef bint _copy_entries(const Matrix* M, Matrix* out, bint* differs) noexcept nogil:
    """Copy ``M``'s entries into ``out`` (the same pattern); False when one is not
    finite or exceeds ``MAX_ENTRY``. ``differs`` becomes True where an entry changed."""
    cdef Py_ssize_t k
    cdef double value
    cdef bint good = True
    for k in range(M.colptr[M.cols]):
        value = M.values[k]
        good = good and fabs(value) <= MAX_ENTRY   # False on NaN too
        differs[0] = differs[0] or out.values[k] != value
        out.values[k] = value
    return good


cdef Finding _first_bad_csc(const Matrix* M, int argument) noexcept nogil:
    """The dense scan's finding for the bad entries of ``M`` (``argument`` -1 for ``P``,
    1 for ``A``): the first in row order that is not finite (``P``) or bad at all
    (``A``), else (``P``) the first in row order of its largest entries."""
    cdef Py_ssize_t j, k, row = M.rows, col = M.cols, largest_row = 0, largest_col = 0
    cdef double value, largest = 0.0, bad = 0.0
    for j in range(M.cols):
        for k in range(M.colptr[j], M.colptr[j + 1]):
            value = M.values[k]
            if fabs(value) > largest or (fabs(value) == largest and (
                    M.rowind[k] < largest_row
                    or (M.rowind[k] == largest_row and j < largest_col))):
                largest, largest_row, largest_col = fabs(value), M.rowind[k], j
            if (not isfinite(value) or (argument >= 0 and fabs(value) > MAX_ENTRY)) and (
                    M.rowind[k] < row or (M.rowind[k] == row and j < col)):
                row, col, bad = M.rowind[k], j, value
    if row < M.rows:
        if argument < 0:
            return _found(P_NOT_FINITE, -1, row, bad)
        return _found(NOT_FINITE if not isfinite(bad) else TOO_LARGE, argument, row, bad)
    return _found(TOO_LARGE, argument, largest_row, largest)


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


def scan_and_copy_csc_py(P, q, A, b, lb, ub, P_previous, A_previous):
    """:func:`scan_and_copy_csc` on ``scipy.sparse`` ``P, A`` against the workspace's
    copies ``P_previous, A_previous`` (whose patterns are the workspace's); returns
    ``(finding, same_matrices, P_copy, q, A_copy, b, lb, ub)``, the copies as written."""
    import numpy as np
    cdef Held Pi = Held(P), Ai = Held(A), Po = Held(P_previous), Ao = Held(A_previous)
    cdef Py_ssize_t n = Pi.M.cols, m = Ai.M.rows
    cdef double[::1] qi = np.append(np.asarray(q, dtype=np.float64), 0.0)
    cdef double[::1] bi = np.append(np.asarray(b, dtype=np.float64), 0.0)
    cdef double[::1] lbi = np.append(np.asarray(lb, dtype=np.float64), 0.0)
    cdef double[::1] ubi = np.append(np.asarray(ub, dtype=np.float64), 0.0)
    cdef double[::1] qo = np.zeros(n + 1), bo = np.zeros(m + 1)
    cdef double[::1] lbo = np.zeros(n + 1), ubo = np.zeros(n + 1)
    cdef bint same = True
    cdef Finding f = scan_and_copy_csc(&Pi.M, &qi[0], &Ai.M, &bi[0], &lbi[0], &ubi[0], &Po.M,
                                       &qo[0], &Ao.M, &bo[0], &lbo[0], &ubo[0], &same)
    return ((f.code, f.argument, f.index, f.value), same, Po.matrix(), np.asarray(qo)[:n],
            Ao.matrix(), np.asarray(bo)[:m], np.asarray(lbo)[:n], np.asarray(ubo)[:n])
