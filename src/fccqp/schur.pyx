# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Schur-complement KKT backend of the reduced form.

When ``H = P + R`` is positive definite, the x-update's system

    [ H   A' ] [x ]   [f]
    [ A   0  ] [nu] = [g]

is solved through two Cholesky factorizations, ``H = L L'`` and ``S = A H^-1 A' =
LS LS'``: ``nu = S^-1 (A H^-1 f - g)``, ``x = H^-1 (f - A' nu)``. With ``Y = L^-1 A'``
(one ``dtrsm``), ``S = Y'Y`` is one ``dsyrk`` (the constrained rows' share, which
changes with rho, summed over their few nonzeros in ``dsyrk``'s bits). ``H`` is
factored with its rows and columns in ``order``: free entries first, the ``s``
constrained entries last. Then ``L^-1`` maps a unit vector on a constrained entry into
the trailing ``s`` rows only, and the reduced form's table (:func:`schur_unit_columns`)
skips the leading rows; and the leading block of ``L`` is the Cholesky factor of ``P``
on the free entries, which makes a convexity certificate cheap
(:func:`schur_certifies_convexity`).

Where ``P`` is diagonal on the constrained entries and on some free ones (no entry
off its diagonal in their rows: the torques and forces of whole-body control), those
free entries go after the other free ones in ``order`` and ``H`` is block diagonal, a
dense leading block of ``dense`` rows and a diagonal tail: Cholesky, the triangular
solves and the table's columns then work on the leading block only, and the tail is a
division. On talos (``n, m, s`` = 124, 68, 56, a dense block of 38) the factorization
and the table take half the multiply-adds of the dense way.

``S`` is positive definite exactly when ``A`` has full row rank; when either
factorization fails (or loses a pivot to cancellation, see ``RANK_TOLERANCE``), or ``S``
outgrows ``H`` and ``A`` by more than ``SCHUR_GROWTH`` (``P`` nearly singular on free
entries that ``A`` ties down: ``x = H^-1 (f - A' nu)`` then multiplies the rounding of
``f - A' nu`` by ``H^-1``, while a pivoting LDL' keeps its growth bounded), the
caller falls back to the quasi-definite LDL' backend of :mod:`fccqp.ldl`, which handles
rank-deficient ``A``. Solves are refined like :func:`fccqp.ldl.ldl_solve`.
"""

import numpy as np

from libc.math cimport fabs, sqrt

from fccqp._blas cimport cholesky, cholesky_solve, cholesky_solve_vector, gemm, syrk_t, trsm
from fccqp._types cimport Problem
from fccqp.ldl cimport meets_equalities
from fccqp.matrices cimport product, product_t
from fccqp.tuning cimport MAX_REFINE, RANK_TOLERANCE, SCHUR_GROWTH

cdef extern from "fccqp_kernels.h" nogil:
    void fccqp_sparse_rank_update(const double* Y, int ld, int rows, const int* index,
                                  const int* count, int m, double* T, double* values)
    void fccqp_sparse_rank_clear(int rows, const int* index, const int* count, int m,
                                 double* T)
    void fccqp_mark_coupled(const double* P, int n, char* coupled)
    void fccqp_transpose(const double* M, long ld, int m, int s, double* T)
    void fccqp_sparse_table_rows(const double* Y, int ldy, int first, int last,
                                 const int* index, const int* count, int m, const double* WT,
                                 int s, const double* L, int ldl, int unit,
                                 const Py_ssize_t* dest, double* W, long ldw, double* rows)


def ordering(n, constrained):
    """The order of ``H``'s rows: the free entries of ``x``, then ``constrained``."""
    free = np.ones(n, dtype=np.bool_)
    free[constrained] = False
    return np.concatenate((np.flatnonzero(free), constrained)).astype(np.intp)


cdef void mark_coupled(const double* P, Py_ssize_t n, char* coupled) noexcept nogil:
    """``coupled[i]`` = 1 where row ``i`` of ``P`` has an entry off its diagonal, else 0
    (``fccqp_mark_coupled``: the strict lower triangle, ``P`` being symmetric)."""
    fccqp_mark_coupled(P, <int>n, coupled)


cdef void _order(Schur* f, const Problem* p) noexcept nogil:
    """Put the free entries whose row of ``P`` is diagonal after the other free ones and
    set ``dense``: the rows before the diagonal tail, ``n`` when some constrained entry is
    coupled (then ``order`` keeps the base order's free entries and nothing is diagonal).
    ``order`` is rebuilt from ``base_order``, so it depends only on this ``P``."""
    cdef Py_ssize_t n = p.n, s = p.s, first = n - s, i, k, lead = 0
    cdef char* coupled = f.coupled
    mark_coupled(p.P.values, n, coupled)
    for k in range(s):
        if coupled[p.constrained[k]]:
            for i in range(n):
                f.order[i] = f.base_order[i]
            f.dense = <int>n
            return
    for k in range(first):
        if coupled[f.base_order[k]]:
            f.order[lead] = f.base_order[k]
            lead += 1
    f.dense = <int>lead
    for k in range(first):
        if not coupled[f.base_order[k]]:
            f.order[lead] = f.base_order[k]
            lead += 1
    for k in range(first, n):
        f.order[k] = f.base_order[k]


cdef bint schur_factor(Schur* f, const Problem* p, const double* rho_vec) noexcept nogil:
    """Factor ``H = P + R`` (rows in ``order``) into ``L`` and ``S`` into ``LS``;
    ``Y := L^-1 A'``. False when ``H`` or ``S`` is not (numerically) positive definite.

    Where the constrained entries are in the diagonal tail, ``R`` reaches only their
    rows: the free rows of ``L`` and ``Y`` and their share ``G`` of ``S`` are kept
    (``free_ready``, until the caller's next ``P`` and ``A``) and another ``R`` (a rho
    change, or the iteration after the cold start) refactors the constrained rows and
    ``S`` alone (:func:`_factor_constrained`; talos: the dense block's Cholesky and
    ``dtrsm`` and 68 of ``dsyrk``'s 124 rows skipped)."""
    cdef int first = <int>(p.n - p.s)
    if f.free_ready:
        return _factor_constrained(f, p, rho_vec)
    _order(f, p)
    if f.dense > first:
        return _factor_whole(f, p, rho_vec)
    if not _factor_free(f, p):
        return False
    f.free_ready = True
    return _factor_constrained(f, p, rho_vec)


cdef bint _factor_free(Schur* f, const Problem* p) noexcept nogil:
    """The free rows (the ``first = n - s`` leading ones in ``order``) of ``L`` and
    ``Y``, and ``G = Y_F' Y_F``; False when ``P`` is not positive definite on them.
    The diagonal tail's rows of ``Y`` are ``A``'s columns over their pivots, as sparse as
    those columns (:func:`_find_nonzeros`): ``G`` sums the dense block's rows by
    ``syrk_t`` and the free tail's from their nonzeros (``fccqp_sparse_rank_update``)."""
    cdef int n = <int>p.n, m = <int>p.m, first = n - <int>p.s, k = f.dense, i, j
    cdef Py_ssize_t column
    cdef double largest = 0.0
    for j in range(k):   # the dense block's lower triangle; below it L is never read
        column = f.order[j]
        for i in range(j, k):
            f.L[i + j * n] = p.P.values[f.order[i] * n + column]
            largest = max(largest, fabs(f.L[i + j * n]))
    if k > 0 and not cholesky(f.L, k, n):
        return False
    for j in range(k, first):   # the diagonal tail's free rows
        column = f.order[j]
        f.L[j + j * n] = p.P.values[column * n + column]
        if not f.L[j + j * n] > 0.0:
            return False
        largest = max(largest, f.L[j + j * n])
        f.L[j + j * n] = sqrt(f.L[j + j * n])
    if m == 0:
        return True
    for j in range(k):
        column = f.order[j]
        for i in range(m):
            f.Y[j + i * n] = p.A.values[i * n + column]
            largest = max(largest, fabs(f.Y[j + i * n]))
    _find_nonzeros(f, p, k, n)
    f.free_largest = _pivot_free_tail(f, k, first, m, largest)
    if k > 0:
        trsm(b"L", b"N", k, m, f.L, n, f.Y, n)
        syrk_t(m, k, f.Y, n, 0.0, f.G, m)
    else:
        for i in range(m * m):
            f.G[i] = 0.0
    fccqp_sparse_rank_update(f.Y + k, n, first - k, f.nonzeros + k * m,
                             f.nonzero_count + k, m, f.G, f.tail_values)
    return True


cdef double _pivot_free_tail(Schur* f, int k, int first, int m, double largest) noexcept nogil:
    """Divide the free tail's rows ``k:first`` of ``Y`` (``A``'s columns, from
    :func:`_find_nonzeros`) by their pivots at their nonzeros; returns ``largest`` raised
    to their largest ``|A|`` entry."""
    cdef int n = f.n, i, j, l
    cdef double a
    for j in range(k, first):
        for l in range(f.nonzero_count[j]):
            i = f.nonzeros[j * m + l]
            a = f.Y[j + i * n]
            largest = max(largest, fabs(a))
            f.Y[j + i * n] = a / f.L[j + j * n]
    return largest


cdef void _find_nonzeros(Schur* f, const Problem* p, int first, int last) noexcept nogil:
    """Where the rows ``first:last`` of the diagonal tail of ``Y`` can be nonzero: row
    ``j`` is column ``order[j]`` of ``A`` over a pivot, nonzero where that column is
    (into ``nonzeros`` and ``nonzero_count``; branch-free: every row index is written,
    kept where nonzero). The rows get ``A``'s column here (its zeros are the row's,
    signed as a division would leave them); their nonzeros are divided by the pivot by
    :func:`_pivot_free_tail` (free rows) and :func:`_factor_constrained`."""
    cdef int n = <int>p.n, m = <int>p.m, i, j, count
    cdef Py_ssize_t column
    cdef double a
    for j in range(first, last):
        column = f.order[j]
        count = 0
        for i in range(m):
            a = p.A.values[i * n + column]
            f.Y[j + i * n] = a
            f.nonzeros[j * m + count] = i
            count += a != 0.0
        f.nonzero_count[j] = count


cdef bint _factor_constrained(Schur* f, const Problem* p, const double* rho_vec) noexcept nogil:
    """The constrained rows of the diagonal tail of ``L`` and ``Y`` for ``rho_vec``, and
    ``S = G + Y_S' Y_S``, over the free rows that :func:`_factor_free` left. A
    constrained row of ``Y`` is a column of ``A`` over its pivot, as sparse as that
    column (whole-body control: one entry for a torque, a few for a contact force), so
    ``Y_S' Y_S`` is summed over the rows' nonzeros (:func:`_add_row_products`; their
    places are :func:`_find_nonzeros`', found once for ``P`` and ``A``)."""
    cdef int n = <int>p.n, m = <int>p.m, s = <int>p.s, first = n - s, i, j, k
    cdef Py_ssize_t column
    cdef const int* index
    cdef double d, a, largest = f.free_largest
    for j in range(first, n):
        column = f.order[j]
        d = p.P.values[column * n + column] + rho_vec[j - first]
        if not d > 0.0:
            return False
        largest = max(largest, d)
        f.L[j + j * n] = sqrt(d)
    if m == 0:
        return True
    for j in range(first, n):   # the zeros of Y's rows stay as _find_nonzeros wrote them
        column = f.order[j]
        index = f.nonzeros + j * m
        for k in range(f.nonzero_count[j]):
            i = index[k]
            a = p.A.values[i * n + column]
            largest = max(largest, fabs(a))
            f.Y[j + i * n] = a / f.L[j + j * n]
    _add_row_products(f, first, n, m)
    return _factor_complement(f, m, largest)


cdef void _add_row_products(Schur* f, int first, int last, int m) noexcept nogil:
    """``LS = G + Y_R' Y_R`` (lower triangle) over the rows ``R = first:last`` of ``Y``,
    from their nonzeros alone. Each entry's products are summed in ``dsyrk``'s way, a
    fused multiply-add per row in the rows' order from zero, into ``T`` (zero between
    calls), and the sum then added to ``G``: a zero term adds exactly nothing to a fused
    sum, so the entry is the one ``dsyrk`` with ``beta = 1`` gives, bit for bit, where
    that kernel sums each entry that way (OpenBLAS' Haswell kernels do; its SkylakeX
    kernels, natively on AVX-512 machines, round 5 % of such entries otherwise)."""
    cdef int k
    fccqp_sparse_rank_update(f.Y + first, f.n, last - first, f.nonzeros + first * m,
                             f.nonzero_count + first, m, f.T, f.tail_values)
    for k in range(m * m):
        f.LS[k] = f.G[k] + f.T[k]
    fccqp_sparse_rank_clear(last - first, f.nonzeros + first * m, f.nonzero_count + first,
                            m, f.T)


cdef bint _factor_whole(Schur* f, const Problem* p, const double* rho_vec) noexcept nogil:
    """:func:`schur_factor` where a constrained entry is coupled in ``P`` (``order``
    keeps the base order and ``L`` is dense): every row depends on rho."""
    cdef int n = <int>p.n, m = <int>p.m, s = <int>p.s, first = n - s, i, j
    cdef Py_ssize_t column
    cdef double largest = 0.0
    for j in range(n):
        column = f.order[j]
        for i in range(j, n):
            f.L[i + j * n] = p.P.values[f.order[i] * n + column]
            largest = max(largest, fabs(f.L[i + j * n]))
    for j in range(s):
        f.L[first + j + (first + j) * n] += rho_vec[j]
        largest = max(largest, fabs(f.L[first + j + (first + j) * n]))
    if not cholesky(f.L, n, n):
        return False
    if m == 0:
        return True
    for j in range(n):
        column = f.order[j]
        for i in range(m):
            f.Y[j + i * n] = p.A.values[i * n + column]
            largest = max(largest, fabs(f.Y[j + i * n]))
    trsm(b"L", b"N", n, m, f.L, n, f.Y, n)
    syrk_t(m, n, f.Y, n, 0.0, f.LS, m)
    return _factor_complement(f, m, largest)


cdef bint _factor_complement(Schur* f, int m, double kkt_largest) noexcept nogil:
    """Cholesky of ``S`` in ``LS`` (its lower triangle holds ``S``); False when ``S``
    outgrew ``kkt_largest``, the largest entry of ``H`` and ``A``, by ``SCHUR_GROWTH``
    (see the module docstring), or a pivot is not positive or was lost to cancellation
    (dependent rows: left to LDL')."""
    cdef int i
    cdef double largest = 0.0
    for i in range(m):
        largest = max(largest, f.LS[i + i * m])
    if not largest <= SCHUR_GROWTH * kkt_largest:
        return False
    if not cholesky(f.LS, m, m):
        return False
    for i in range(m):
        if f.LS[i + i * m] * f.LS[i + i * m] <= RANK_TOLERANCE * largest:
            return False
    return True


cdef void _triangular_solve(Schur* f, char trans, int n, int columns, double* B,
                            int ldb) noexcept nogil:
    """``B := L^-1 B`` (``trans`` ``N``) or ``L'^-1 B`` (``T``), ``B`` ``n x columns``
    column-major: ``dtrsm`` on the dense block, a division on the diagonal tail."""
    cdef int k = f.dense, i, j
    if k > 0:
        trsm(b"L", trans, k, columns, f.L, n, B, ldb)
    for j in range(columns):
        for i in range(k, n):
            B[i + j * ldb] /= f.L[i + i * n]


cdef bint schur_certifies_convexity(Schur* f, const Problem* p, const double* rho_vec,
                                    double sigma) noexcept nogil:
    """True when the factorization of :func:`schur_factor` proves ``P + sigma I`` positive
    semidefinite, so that the QP is convex whatever ``A``.

    In the permuted order ``L = [L11 0; L21 L22]`` with ``L11 L11' = P_FF`` (no penalty on
    the free entries) and ``L22 L22' = P_SS - P_SF P_FF^-1 P_FS + R``; ``P`` is positive
    semidefinite exactly when that Schur complement without ``R`` is, so one Cholesky
    of ``L22 L22' - R + sigma I`` (``s x s``, a few microseconds) decides. False means
    "not proven": the caller then asks the inertia of the penalty-free KKT matrix.
    """
    cdef int n = <int>p.n, s = <int>p.s, first = n - s, i, j, k
    cdef double acc
    cdef const double* L22 = f.L + first + first * n
    if f.dense <= first:   # L22 is diagonal
        for j in range(s):
            if not L22[j + j * n] * L22[j + j * n] + sigma - rho_vec[j] > 0.0:
                return False
        return True
    for j in range(s):
        for i in range(j, s):
            acc = 0.0
            for k in range(j + 1):
                acc += L22[i + k * n] * L22[j + k * n]
            f.M[i + j * s] = acc
        f.M[j + j * s] += sigma - rho_vec[j]
    return s == 0 or cholesky(f.M, s, s)


cdef void _h_solve(Schur* f, double* v, Py_ssize_t n) noexcept nogil:
    """``v := H^-1 v`` in place, ``v`` in the user's order of ``x``."""
    cdef Py_ssize_t i, k = f.dense
    cdef double d
    for i in range(n):
        f.perm[i] = v[f.order[i]]
    if k > 0:
        cholesky_solve_vector(f.L, <int>k, <int>n, f.perm)
    for i in range(k, n):
        d = f.L[i + i * n]
        f.perm[i] /= d * d
    for i in range(n):
        v[f.order[i]] = f.perm[i]


cdef void _solve(Schur* f, const Problem* p, const double* rhs_x, const double* rhs_nu,
                 double* x, double* nu) noexcept nogil:
    """One unrefined solve of the system for ``(f, g)`` into ``x, nu``."""
    cdef Py_ssize_t n = p.n, m = p.m, i
    for i in range(n):
        x[i] = rhs_x[i]
    _h_solve(f, x, n)
    if m == 0:
        return
    product(&p.A, x, nu)
    for i in range(m):
        nu[i] -= rhs_nu[i]
    cholesky_solve_vector(f.LS, <int>m, <int>m, nu)
    product_t(&p.A, nu, f.ATnu)
    _h_solve(f, f.ATnu, n)
    for i in range(n):
        x[i] -= f.ATnu[i]


cdef void schur_solve_once(Schur* f, const Problem* p, const double* rhs,
                           double* sol) noexcept nogil:
    """Solve for ``rhs = (f, g)`` into ``sol = (x, nu)`` without refinement: for callers
    that refine against their own residual (no aliasing)."""
    _solve(f, p, rhs, rhs + p.n, sol, sol + p.n)


cdef void schur_solve(Schur* f, const Problem* p, const double* rho_vec, const double* rhs,
                      double* sol) noexcept nogil:
    """Solve for ``rhs = (f, g)`` into ``sol = (x, nu)``, refined (no aliasing)."""
    cdef Py_ssize_t n = p.n, m = p.m, i, k, r
    cdef double* x = sol
    cdef double* nu = sol + n
    _solve(f, p, rhs, rhs + n, x, nu)
    if m == 0:
        return
    for r in range(MAX_REFINE):
        product(&p.A, x, f.Ax)
        if meets_equalities(f.Ax, rhs + n, p.E, m):
            return
        product(&p.P, x, f.r)
        product_t(&p.A, nu, f.ATnu)
        for i in range(n):
            f.r[i] = rhs[i] - f.r[i] - f.ATnu[i]
        for k in range(p.s):
            i = p.constrained[k]
            f.r[i] -= rho_vec[k] * x[i]
        for i in range(m):
            f.Ax[i] = rhs[n + i] - f.Ax[i]
        _solve(f, p, f.r, f.Ax, f.dx, f.dnu)
        for i in range(n):
            x[i] += f.dx[i]
        for i in range(m):
            nu[i] += f.dnu[i]


cdef void schur_unit_columns(Schur* f, const Problem* p, double* W, double* W_S) noexcept nogil:
    """Fill ``W`` (Fortran, ``(n + m) x s``) with the responses of ``(x, nu)`` to unit
    right-hand sides ``[e_i; 0]`` on the last ``s`` entries of ``order``, and, where
    ``W_S`` is not NULL, ``W``'s rows on them into ``W_S`` (row-major ``s x s``).

    In the permuted order ``Z = L^-1 E_S`` is ``[0; L22^-1]``, so ``W_nu = S^-1 Y'Z =
    LS^-T LS^-1 Y2' L22^-1`` and ``W_x = L^-T (Z - Y W_nu)``: about half the work of
    ``s`` general solves (``n, m, s`` = 124, 68, 56 on talos). Where ``H`` has a diagonal
    tail (:func:`_sparse_unit_columns`) the tail's rows of ``Y W_nu`` are summed from their
    nonzeros.
    """
    cdef Py_ssize_t s = p.s, N = p.n + p.m, first = p.n - p.s, i, j
    if f.dense <= first and p.m > 0:
        _sparse_unit_columns(f, p, W, W_S)
        return
    _dense_unit_columns(f, p, W)
    if W_S != NULL:
        for j in range(s):
            for i in range(s):
                W_S[j * s + i] = W[f.order[first + j] + i * N]


cdef void _sparse_unit_columns(Schur* f, const Problem* p, double* W, double* W_S) noexcept nogil:
    """:func:`schur_unit_columns` where ``L`` is its dense block and a diagonal tail
    (``m > 0``). ``W_nu`` is solved in place in ``W``; the dense block's rows are
    ``L11^-T (-Y1 W_nu)`` (``gemm``, ``trsm``), written in place where ``order`` keeps
    them in one run of ``x``; each tail row ``j`` is ``(Z_j - Y_j W_nu) / L_jj`` from
    ``Y_j``'s nonzeros (``fccqp_sparse_table_rows``; go2: 2.2k multiply-adds where the
    dense product took 26k on these rows)."""
    cdef int n = <int>p.n, m = <int>p.m, s = <int>p.s, first = n - s, N = n + m
    cdef int k = f.dense, i, j, l
    cdef bint in_place = _in_one_run(f.order, k)
    cdef double* Wnu = W + n
    cdef double* dense_rows = W + f.order[0] if in_place else f.X
    cdef int ld = N if in_place else n
    cdef const int* index
    cdef double d
    for j in range(s):
        for i in range(m):
            Wnu[i + j * N] = 0.0
        d = 1.0 / f.L[first + j + (first + j) * n]
        index = f.nonzeros + (first + j) * m
        for l in range(f.nonzero_count[first + j]):
            i = index[l]
            Wnu[i + j * N] = f.Y[first + j + i * n] * d
    cholesky_solve(f.LS, m, m, Wnu, s, N)
    if k > 0:
        gemm(b"N", b"N", k, s, m, -1.0, f.Y, n, Wnu, N, 0.0, dense_rows, ld)
        trsm(b"L", b"T", k, s, f.L, n, dense_rows, ld)
        if not in_place:
            for j in range(s):
                for i in range(k):
                    W[f.order[i] + j * N] = f.X[i + j * n]
    fccqp_transpose(Wnu, N, m, s, f.Wnu)
    fccqp_sparse_table_rows(f.Y, n, k, n, f.nonzeros, f.nonzero_count, m, f.Wnu, s, f.L,
                            n, first, f.order, W, N, W_S)


cdef inline bint _in_one_run(const Py_ssize_t* order, int k) noexcept nogil:
    """Whether ``order[:k]`` is one run of consecutive entries."""
    cdef int i
    for i in range(1, k):
        if order[i] != order[0] + i:
            return False
    return True


cdef void _dense_unit_columns(Schur* f, const Problem* p, double* W) noexcept nogil:
    """:func:`schur_unit_columns` by dense products: ``L`` dense (a coupled constrained
    entry), or no equality row."""
    cdef int n = <int>p.n, m = <int>p.m, s = <int>p.s, first = n - s, N = n + m, i, j
    cdef double* X = f.X
    for i in range(n * s):
        X[i] = 0.0
    if f.dense <= first:   # L22 is diagonal, and so is Z's block (here m = 0)
        for j in range(s):
            X[first + j + j * n] = 1.0 / f.L[first + j + (first + j) * n]
    else:
        for j in range(s):
            X[first + j + j * n] = 1.0
        trsm(b"L", b"N", s, s, f.L + first + first * n, n, X + first, n)
        if m > 0:
            gemm(b"T", b"N", m, s, s, 1.0, f.Y + first, n, X + first, n, 0.0, f.Wnu, m)
    if m > 0:
        cholesky_solve(f.LS, m, m, f.Wnu, s, m)
        gemm(b"N", b"N", n, s, m, -1.0, f.Y, n, f.Wnu, m, 1.0, X, n)
    _triangular_solve(f, b"T", n, s, X, n)
    for j in range(s):
        for i in range(n):
            W[f.order[i] + j * N] = X[i + j * n]
        for i in range(m):
            W[n + i + j * N] = f.Wnu[i + j * m]
