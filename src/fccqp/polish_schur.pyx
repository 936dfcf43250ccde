# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The polished QP's KKT system by Schur complement, without ADMM's factorization.

:mod:`fccqp.polish` solves, for a guess of the active set, the regularized system

    [ H   C'       ] [x_F]   [r_x]        H = P_FF + curvature + delta I
    [ C   -delta I ] [mu ] = [r_c]        C = [A_F; G]

(free entries ``F``, equality rows and one tangent plane per boundary block). Where
``P`` has nothing off its diagonal in the rows of the constrained entries (the torques
and forces of whole-body control), ``H`` is block diagonal whatever the guess: ``P`` on
the unconstrained entries, a dense block ``D`` that ``P`` couples and a diagonal rest,
then one entry per free box entry and one block per cone block off the apex, diagonal
or, on the boundary, ``diag(P) + curvature`` (``d x d``). So

    mu = S^-1 (C H^-1 r_x - r_c),   x_F = H^-1 (r_x - C' mu),   S = C H^-1 C' + delta I,

and ``S = Y'Y + delta I`` with ``Y = L^-1 C'`` by blocks of ``H = L L'``. The
unconstrained entries' rows of ``Y`` and their part of ``S`` depend on ``P`` and ``A``
only: :func:`polish_schur_setup` computes them once per solve (one Cholesky of the
``D x D`` block, one triangular solve, one ``dsyrk``), and each guess adds its free
constrained entries' rows (:func:`polish_schur_factor`: a ``dsyrk`` of about ``s``
rows and a Cholesky of ``m + nb`` rows). On go2 (``n, m, s`` = 54, 30, 24, ``D`` = 18)
that is a few tens of thousands of multiply-adds a guess, against the ``dsytrf`` of the
``nf + m + nb`` (about 75) rows of the assembled matrix; and it needs no ADMM
factorization and no reduced table, which the table polish (:mod:`fccqp.polish_table`)
is built on. So a warm polish that succeeds skips both (see ``Workspace._iterate``).

The cone blocks off their apex are bordered (:func:`polish_schur_factor`): a base
(:func:`_build_base`) factors ``S0``, the part of ``S`` of the unconstrained and free
box entries, once for every guess that holds the same box entries, and each guess
factors only its cone blocks against it (``K``, ``nb`` planes in ``T``), so that a
polish whose guesses move contacts between free, boundary and apex (a contact change's)
builds one base. ``S``'s first ``m`` columns take ``A``'s rows in the order
:func:`_order_rows` gives them (the rows that cone entries touch last), so that the
bases of one solve share the factor of ``S``'s leading block. A solve keeps ``Y``: ``w = L^-1 r_x``, ``mu = S^-1 (Y'w - r_c)``, ``x_F = L'^-1 (w -
Y mu)``, two products with ``Y`` and the triangular solves of ``H``'s blocks. The
caller refines against the unregularized system, as with ``dsytrf``. Where ``P``
couples a constrained entry, a block is not positive definite or ``S`` loses a pivot
(dependent rows: a squared pivot below ``POLISH_RANK_TOLERANCE`` times ``S``'s largest
diagonal entry), the functions return False; the warm polish before ADMM's
factorization then hands the guess to the table, and any other polish assembles the
matrix for ``dsytrf``. Rows that a guess's free entries span only barely are not
dependent: the guesses of warm polishes whose contacts leave the ground (talos, solo12)
reach squared pivots of 3e-12 to 1e-10 of the largest diagonal, which ``dsytrf`` and the
table solve the same regularized way; refused, the warm polish had run again after
ADMM's factorization, its earlier guesses repeated in the table's coordinates
(notes/tuning.md, ``POLISH_RANK_TOLERANCE``).

Measured with callgrind (realtime preset without a clock, one OpenBLAS thread,
instructions per tick): go2 1.12M -> 0.87M, solo12 1.06M -> 0.83M, talos 7.63M ->
6.96M, with the same answers (SOLVED 100 %, worst objective gap and torque error p95
unchanged on the four robots' sets).
"""

from libc.math cimport sqrt

from fccqp._blas cimport (backward_substitution, cholesky, cholesky_solve_vector,
                          forward_substitution, syrk_t, trsm)
from fccqp._dense cimport colmatvec, fill, matvec_ld
from fccqp._types cimport Problem
from fccqp.schur cimport mark_coupled
from fccqp.tuning cimport (CHOLESKY_LOOP_ROWS, PIVOT_TOLERANCE, POLISH_BORDER_TOLERANCE,
                           POLISH_RANK_TOLERANCE)


cdef extern from "fccqp_kernels.h" nogil:
    void fccqp_matvec_t(const double* M, int ld, const double* y, double* out, int rows,
                        int cols)
    void fccqp_sparse_rank_update(const double* Y, int ld, int rows, const int* index,
                                  const int* count, int m, double* T, double* values)
    int fccqp_cholesky_lead(double* M, int n, int ld, int stop)
    void fccqp_forward_vector(const double* L, int n, int ld, double* b)
    void fccqp_backward_vector(const double* L, int n, int ld, double* b)
    enum: FCCQP_LU_PANEL


cdef bint polish_schur_setup(PolishSchur* f, const Problem* p, double delta) noexcept nogil:
    """Check ``P``'s structure, factor its dense unconstrained block, and compute the
    unconstrained rows of ``Y`` and their part ``SU`` of ``S``; sets and returns
    ``ready``. When ready, ``convex`` says whether that proves ``P`` positive
    semidefinite: its dense block factored and no diagonal entry is negative (``P`` is
    block diagonal here), so that a polish without ADMM's factorization, which holds
    the convexity test, still answers only convex problems."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, i, j, r, c, lead = 0, rest
    cdef double largest = 0.0, pivot
    cdef int k
    f.ready = f.bordered = f.lead_valid = False
    f.base = BASE_NONE
    f.border_all = False
    f.convex = True
    mark_coupled(p.P.values, n, f.coupled)
    for i in range(n):
        largest = max(largest, p.P.values[i * n + i])
    if not largest > 0.0:
        return False
    for j in range(s):
        i = p.constrained[j]
        if f.coupled[i]:
            return False
        f.coupled[i] = 2   # constrained: not part of the unconstrained order
        f.entry_count[i] = -1   # its diagonal row not written in this solve
        if p.P.values[i * n + i] < 0.0:
            f.convex = False
        f.root[i] = sqrt(p.P.values[i * n + i] + delta) if p.P.values[i * n + i] > PIVOT_TOLERANCE * largest else 0.0
    for i in range(n):
        if f.coupled[i] == 1:
            f.order[lead] = i
            lead += 1
    rest = lead
    for i in range(n):
        if f.coupled[i] == 0:
            if not p.P.values[i * n + i] > PIVOT_TOLERANCE * largest:
                return False
            f.root[i] = sqrt(p.P.values[i * n + i] + delta)
            f.order[rest] = i
            rest += 1
    k = <int>lead
    f.dense, f.unconstrained, f.kept_rows = k, rest, <int>rest
    for r in range(rest):
        f.rowvar[r] = f.order[r]
        f.inv_root[r] = 1.0 / f.root[f.order[r]] if r >= k else 0.0
    for c in range(k):
        for r in range(c, k):
            f.L[r + c * n] = p.P.values[f.order[r] * n + f.order[c]]
        f.L[c + c * n] += delta
    if k > 0 and not cholesky(f.L, k, <int>n):
        return False
    for c in range(k):
        pivot = f.L[c + c * n]
        if not pivot * pivot > PIVOT_TOLERANCE * largest:
            return False
    _order_rows(f, p)
    for c in range(m):
        for r in range(k):
            f.Y[r + c * n] = p.A.values[f.arow[c] * n + f.order[r]]
    for r in range(k, rest):
        _write_row(f, p, f.order[r], r, f.inv_root[r])
    if m > 0:
        if k > 0:
            trsm(b"L", b"N", k, <int>m, f.L, <int>n, f.Y, <int>n)
            syrk_t(<int>m, k, f.Y, <int>n, 0.0, f.SU, <int>m)
        else:
            _zero_lower(f.SU, m)
        _add_sparse_rows(f, p, k, rest, 0, m, f.SU)   # the diagonal rows go on with dsyrk's sums
        for c in range(m):
            f.SU[c + c * m] += delta
    f.ready = True
    return True


cdef inline void _zero_lower(double* T, Py_ssize_t size) noexcept nogil:
    """Zero the lower triangle of the ``size x size`` column-major ``T``."""
    cdef Py_ssize_t r, c
    for c in range(size):
        for r in range(c, size):
            T[r + c * size] = 0.0


cdef void _order_rows(PolishSchur* f, const Problem* p) noexcept nogil:
    """``S``'s first ``m`` columns (``arow``): the rows of ``A`` that no cone entry
    touches, then those it does, each in ``A``'s order. A boundary block's rows of ``Y``
    are zero in the former, so ``S`` and ``S0`` agree on their leading ``lead`` columns
    (that count rounded down to the Cholesky's panel of ``FCCQP_LU_PANEL``), and every
    guess of a base shares their factor (:func:`_build_base`). ``lead`` is 0 where ``m``
    takes ``dpotrf`` (``CHOLESKY_LOOP_ROWS``)."""
    cdef Py_ssize_t n = p.n, m = p.m, c, k, a, d, untouched = 0, last
    cdef double* touched = f.u   # scratch: the count of cone entries' nonzeros in a row
    cdef const double* row
    for c in range(m):
        touched[c] = 0.0
    for k in range(p.cones.count):   # a cone's entries are consecutive entries of x
        d = p.cones.dim[k]
        row = p.A.values + p.constrained[p.cones.offset[k]]
        for c in range(m):
            for a in range(d):
                touched[c] += row[c * n + a] != 0.0
    for c in range(m):
        untouched += touched[c] == 0.0
    last = untouched
    untouched = 0
    for c in range(m):
        if touched[c] == 0.0:
            f.arow[untouched] = c
            untouched += 1
        else:
            f.arow[last] = c
            last += 1
    f.lead = <int>(untouched - untouched % FCCQP_LU_PANEL) if m <= CHOLESKY_LOOP_ROWS else 0


cdef inline void _write_row(PolishSchur* f, const Problem* p, Py_ssize_t i, Py_ssize_t row,
                            double inverse) noexcept nogil:
    """Row ``row`` of ``Y``'s first ``m`` columns: column ``i`` of ``A`` in ``arow``'s
    order times ``inverse``, and where it is nonzero (``row_nz``, ``row_count``;
    branch-free: every column is written, kept where nonzero)."""
    cdef Py_ssize_t c, n = p.n, m = p.m
    cdef double* y = f.Y + row
    cdef const double* a = p.A.values + i
    cdef int* nz = f.row_nz + row * (m + p.s)
    cdef int count = 0
    cdef double value
    for c in range(m):
        value = a[f.arow[c] * n] * inverse
        y[c * n] = value
        nz[count] = <int>c
        count += value != 0.0
    f.row_count[row] = count


cdef inline void _keep_row(PolishSchur* f, const Problem* p, Py_ssize_t i,
                           Py_ssize_t row) noexcept nogil:
    """Keep row ``row`` of ``Y``, entry ``i``'s diagonal row as :func:`_write_row` wrote
    it, by its nonzeros (``entry_nz``, ``entry_values``, ``entry_count``), so that a
    later base of the solve that puts the entry at another row copies it
    (:func:`_cached_row`)."""
    cdef Py_ssize_t k, n = p.n, m = p.m
    cdef const int* nz = f.row_nz + row * (m + p.s)
    cdef int count = f.row_count[row]
    for k in range(count):
        f.entry_nz[i * m + k] = nz[k]
        f.entry_values[i * m + k] = f.Y[row + nz[k] * n]
    f.entry_count[i] = count


cdef inline void _cached_row(PolishSchur* f, const Problem* p, Py_ssize_t i,
                             Py_ssize_t row) noexcept nogil:
    """Row ``row`` of ``Y``'s first ``m`` columns and its nonzeros for entry ``i`` from
    what :func:`_keep_row` kept: the same values as :func:`_write_row`'s, without its
    products and comparisons (on anymal_c's contact tick 360, where the bases' rows move
    as their boundary blocks change, those took ~27k instructions, 10 a column)."""
    cdef Py_ssize_t c, k, n = p.n, m = p.m
    cdef double* y = f.Y + row
    cdef int* nz = f.row_nz + row * (m + p.s)
    cdef const int* kept = f.entry_nz + i * m
    cdef const double* values = f.entry_values + i * m
    cdef int count = f.entry_count[i]
    for c in range(m):
        y[c * n] = 0.0
    for k in range(count):
        y[kept[k] * n] = values[k]
        nz[k] = kept[k]
    f.row_count[row] = count


cdef inline void _find_row(PolishSchur* f, const Problem* p, Py_ssize_t row,
                           Py_ssize_t first, Py_ssize_t size) noexcept nogil:
    """Where row ``row`` of ``Y``'s columns ``first .. size`` is nonzero (as
    :func:`_write_row` records it, counted from ``first``)."""
    cdef Py_ssize_t c, n = p.n
    cdef const double* y = f.Y + row
    cdef int* nz = f.row_nz + row * (p.m + p.s)
    cdef int count = 0
    for c in range(first, size):
        nz[count] = <int>(c - first)
        count += y[c * n] != 0.0
    f.row_count[row] = count


cdef void _add_sparse_rows(PolishSchur* f, const Problem* p, Py_ssize_t first,
                           Py_ssize_t last, Py_ssize_t column, Py_ssize_t size,
                           double* T) noexcept nogil:
    """``T += Y_R' Y_R`` (lower triangle, ``size x size``) over the rows ``R = first:last``
    of ``Y`` from its column ``column`` on, from the nonzeros that :func:`_write_row` and
    :func:`_find_row` recorded (counted from that column):
    a fused multiply-add per nonzero pair, row after row, which is how ``dsyrk`` sums
    each entry (a zero term adds exactly nothing), so ``T`` holds the bits ``dsyrk``
    would where its kernel sums that way (as :func:`fccqp.schur._add_row_products`:
    OpenBLAS' Haswell kernels do, its SkylakeX kernels do not; the sums here are then
    the same on every machine). These rows are a column of ``A`` over a pivot (a
    torque, a slack: one entry; a contact force: a few) or a boundary block's few
    columns: on talos' warm ticks ``dsyrk`` over them took 60-130k instructions a call
    (callgrind)."""
    cdef Py_ssize_t j, ld = p.m + p.s
    for j in range(first, last):
        if f.row_count[j] > 0:
            fccqp_sparse_rank_update(f.Y + j + column * p.n, <int>p.n, 1, f.row_nz + j * ld,
                                     f.row_count + j, <int>size, T, f.nz_values)


cdef inline bint _diagonal_row(PolishSchur* f, const Problem* p, Py_ssize_t i, Py_ssize_t row,
                               Py_ssize_t size) noexcept nogil:
    """Row ``row`` of ``Y`` for free entry ``i``, a diagonal entry of ``H``: ``C``'s
    column ``i`` (no plane) divided by ``sqrt(P_ii + delta)``; False when ``P_ii`` is
    too small for that."""
    cdef Py_ssize_t c, n = p.n, m = p.m
    cdef double inverse
    if f.root[i] == 0.0:
        return False
    inverse = 1.0 / f.root[i]
    if f.entry_count[i] < 0:
        _write_row(f, p, i, row, inverse)
        _keep_row(f, p, i, row)
    else:
        _cached_row(f, p, i, row)
    for c in range(m, size):
        f.Y[row + c * n] = 0.0
    f.rowvar[row] = i
    f.inv_root[row] = inverse
    return True


cdef inline bint _next_boundary(const Py_ssize_t* boundary, Py_ssize_t nb, Py_ssize_t k,
                                Py_ssize_t* kb) noexcept nogil:
    """Whether cone block ``k`` is ``boundary[kb]`` (the ascending ``boundary[:nb]``
    walked beside the cone blocks in order), ``kb`` then moved past it."""
    if kb[0] < nb and boundary[kb[0]] == k:
        kb[0] += 1
        return True
    return False


cdef bint _factor_whole(PolishSchur* f, const Problem* p, const Py_ssize_t* boundary,
                        Py_ssize_t nb, const double* g, const double* hess,
                        double delta) noexcept nogil:
    """Factor the whole ``S`` (``m + nb`` rows) of the guess (see
    :func:`polish_schur_factor`) and keep ``Y = L^-1 C'`` for the solves. ``Y``'s rows:
    the unconstrained entries (from the set-up), the free box entries and the base's
    diagonal cone blocks (a diagonal entry of ``H`` each; written by :func:`_build_base`),
    then the bordered blocks (:func:`_border`), each a Cholesky of ``d`` rows of
    ``diag(P)``, plus the curvature and a column for the plane where the block is on its
    boundary. These
    are zero in ``S``'s leading ``lead`` columns, where ``S`` is ``S0`` and the base holds
    its factor: only the rest, the base's Schur complement ``SC`` plus the bordered rows'
    sums, is factored (into ``S``, ``m + nb - lead`` rows). False where the Schur
    complement does not apply."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, size = m + nb, r, c, k, o, d, b, plane
    cdef Py_ssize_t start, row = f.diag_end, kb = 0, a, lead = f.lead, rest = m - lead
    cdef Py_ssize_t t = size - lead
    cdef double* S = f.S
    cdef double* Y = f.Y
    cdef double* B
    cdef double largest = f.lead_largest
    if f.base == BASE_NONE or f.base == BASE_SINGULAR:
        return False   # a free row could not be written, or S0's leading block failed
    for c in range(m, size):   # the rows above the bordered blocks have no plane
        for r in range(row):
            Y[r + c * n] = 0.0
    for b in range(f.nborder):   # diag(P) (+ curvature): a Cholesky of d rows each
        k = f.border[b]
        o, d = p.cones.offset[k], p.cones.dim[k]
        start = p.constrained[o]
        B = f.block + o * s
        plane = kb   # its plane's column, where it is on its boundary
        if not _next_boundary(boundary, nb, k, &kb):
            plane = -1
        if (not _curved_block(f, p, o, d, start, hess if plane >= 0 else NULL)
                or not cholesky(B, <int>d, <int>d)):
            return False
        for a in range(d):
            for c in range(lead):
                Y[row + a + c * n] = 0.0
            for c in range(lead, m):
                Y[row + a + c * n] = p.A.values[f.arow[c] * n + start + a]
            for c in range(m, size):
                Y[row + a + c * n] = 0.0
            if plane >= 0:
                Y[row + a + (m + plane) * n] = g[o + a]
        for c in range(lead, size):   # Y_block := B^-1 Y_block
            forward_substitution(B, <int>d, <int>d, Y + row + c * n)
        for a in range(d):
            _find_row(f, p, row + a, lead, size)
        row += d
    if kb != nb:   # a boundary block held at its apex: not the guess the polish keeps
        return False
    f.rows = <int>row
    for c in range(t):   # the base's Schur complement, the bordered rows' sums added
        for r in range(c, t):
            S[r + c * t] = f.SC[(lead + r) + (lead + c) * m] if r < rest else 0.0
    _add_sparse_rows(f, p, f.diag_end, row, lead, t, S)
    for c in range(t):   # S's diagonal: diag0 and the sums since
        if c < rest:
            largest = max(largest, f.diag0[lead + c] + S[c + c * t]
                          - f.LSC[(lead + c) * (m + 1)])
        else:
            S[c + c * t] += delta
            largest = max(largest, S[c + c * t])
    if t > 0 and not cholesky(S, <int>t, <int>t):
        return False
    if lead > 0 and f.lead_min <= POLISH_RANK_TOLERANCE * largest:
        return False
    for c in range(t):
        if S[c + c * t] * S[c + c * t] <= POLISH_RANK_TOLERANCE * largest:
            return False
    f.size = <int>size
    return True


cdef inline bint _take_row(PolishSchur* f, const Problem* p, Py_ssize_t i, Py_ssize_t row,
                           bint build) noexcept nogil:
    """Row ``row`` of ``Y`` for the free entry ``i``: written in ``S0``'s ``m`` columns
    where ``Y`` does not hold it yet (``build``: rows below ``kept_rows`` that an
    earlier base of the solve wrote for the same entry are kept), else whether ``Y``
    holds it there."""
    if build:
        if row < f.kept_rows and f.rowvar[row] == i:
            return True
        if not _diagonal_row(f, p, i, row, p.m):
            return False
        if row == f.kept_rows:
            f.kept_rows += 1
        return True
    return row < f.diag_end and f.rowvar[row] == i


cdef Py_ssize_t _walk_diagonal(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                               bint build) noexcept nogil:
    """The rows of ``Y`` after the unconstrained ones for the guess's free box entries and
    the base's diagonal cone blocks (``CONE_DIAGONAL``), in :func:`_build_base`'s order:
    written (``build``) or compared with those ``Y`` holds. Their end, or -1 where a row
    cannot be written or they differ."""
    cdef Py_ssize_t j, k, a, start, row = f.unconstrained
    for j in range(p.s):
        if not p.in_cone[j] and index[p.constrained[j]] >= 0:
            if not _take_row(f, p, p.constrained[j], row, build):
                return -1
            row += 1
    for k in range(p.cones.count):
        if f.cone_base[k] == CONE_DIAGONAL:
            start = p.constrained[p.cones.offset[k]]
            for a in range(p.cones.dim[k]):
                if not _take_row(f, p, start + a, row, build):
                    return -1
                row += 1
    if not (build or row == f.diag_end):
        return -1
    return row


cdef bint _same_base(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                     const Py_ssize_t* boundary, Py_ssize_t nb) noexcept nogil:
    """Whether the base (:func:`_build_base`) is the guess's: the same free box entries,
    its diagonal cone blocks free in the guess and its held ones at their apex (its
    bordered ones may be free, on their boundary or at their apex)."""
    cdef Py_ssize_t k, kb = 0
    cdef bint on_boundary, at_apex
    cdef char kept
    if f.base == BASE_NONE:
        return False
    for k in range(p.cones.count):
        on_boundary = _next_boundary(boundary, nb, k, &kb)
        at_apex = index[p.constrained[p.cones.offset[k]]] < 0
        kept = f.cone_base[k]
        if ((kept == CONE_DIAGONAL and (on_boundary or at_apex))
                or (kept == CONE_HELD and not at_apex)):
            return False
    return _walk_diagonal(f, p, index, False) >= 0


cdef void _border(PolishSchur* f, const Problem* p, const Py_ssize_t* index) noexcept nogil:
    """The guess's bordered blocks: the base's bordered cone blocks off their apex (their
    entries' ``index`` not -1), ascending in ``border``, with their rows of ``Y`` after
    the base's (``block_row``, ``rowvar``) and their entries' columns of ``W``
    (``border_col``)."""
    cdef Py_ssize_t k, a, d, start, row = f.diag_end, column = 0, count = 0
    for k in range(p.cones.count):
        if f.cone_base[k] != CONE_BORDERED:
            continue
        d = p.cones.dim[k]
        start = p.constrained[p.cones.offset[k]]
        if index[start] >= 0:
            f.border[count] = k
            f.block_row[count] = row
            count += 1
            for a in range(d):
                f.rowvar[row + a] = start + a
                f.border_col[row - f.diag_end + a] = column + a
            row += d
        column += d
    f.nborder, f.nbd = <int>count, <int>(row - f.diag_end)


cdef inline bint _reaches_lead(PolishSchur* f, const Problem* p, Py_ssize_t j) noexcept nogil:
    """Whether row ``j`` of ``Y`` (a diagonal row, as :func:`_write_row` records it) is
    nonzero in ``S``'s leading ``lead`` columns."""
    return f.row_count[j] > 0 and f.row_nz[j * (p.m + p.s)] < f.lead


cdef bint _same_lead(PolishSchur* f, const Problem* p, Py_ssize_t end) noexcept nogil:
    """Whether the free diagonal rows ``unconstrained .. end`` of ``Y`` that reach ``S``'s
    leading columns are those whose factor :func:`_build_lead` keeps."""
    cdef Py_ssize_t j, k = 0
    if not f.lead_valid:
        return False
    for j in range(f.unconstrained, end):
        if _reaches_lead(f, p, j):
            if k == f.lead_count or f.lead_rows[k] != f.rowvar[j]:
                return False
            k += 1
    return k == f.lead_count


cdef void _add_rows(PolishSchur* f, const Problem* p, Py_ssize_t end, bint reaching,
                    double* T) noexcept nogil:
    """``T += Y_R' Y_R`` (lower triangle, ``m x m``) over the free diagonal rows
    ``unconstrained .. end`` of ``Y`` that reach ``S``'s leading columns (``reaching``)
    or that do not, as :func:`_add_sparse_rows` sums."""
    cdef Py_ssize_t j, ld = p.m + p.s
    for j in range(f.unconstrained, end):
        if f.row_count[j] > 0 and _reaches_lead(f, p, j) == reaching:
            fccqp_sparse_rank_update(f.Y + j, <int>p.n, 1, f.row_nz + j * ld, f.row_count + j,
                                     <int>p.m, T, f.nz_values)


cdef bint _build_lead(PolishSchur* f, const Problem* p, Py_ssize_t end) noexcept nogil:
    """Factor the leading ``lead`` columns of ``SU`` plus the sums of the free diagonal
    rows ``unconstrained .. end`` that reach them, into ``S0``'s leading columns; keep
    the rest's Schur complement ``LSC``, the diagonal ``diag0``, the leading block's
    largest diagonal entry and smallest squared pivot, and those rows (``lead_rows``).
    The other rows add only to ``LSC``'s block, so every base with the same rows
    shares this (:func:`_build_base`): on talos the rows that reach it are the free
    torques of the joints without a contact force. False where the leading block is not
    positive definite."""
    cdef Py_ssize_t m = p.m, lead = f.lead, r, c, j
    cdef double smallest
    f.lead_valid = False
    for c in range(m):
        for r in range(c, m):
            f.S0[r + c * m] = f.SU[r + c * m]
    _add_rows(f, p, end, True, f.S0)
    f.lead_largest = 0.0
    for c in range(m):
        f.diag0[c] = f.S0[c * (m + 1)]
        if c < lead:
            f.lead_largest = max(f.lead_largest, f.diag0[c])
    if lead > 0 and not fccqp_cholesky_lead(f.S0, <int>m, <int>m, <int>lead):
        return False
    smallest = f.lead_largest
    for c in range(lead):
        smallest = min(smallest, f.S0[c * (m + 1)] * f.S0[c * (m + 1)])
    f.lead_min = smallest
    for c in range(lead, m):
        for r in range(c, m):
            f.LSC[r + c * m] = f.S0[r + c * m]
    f.lead_count = 0
    for j in range(f.unconstrained, end):
        if _reaches_lead(f, p, j):
            f.lead_rows[f.lead_count] = f.rowvar[j]
            f.lead_count += 1
    f.lead_valid = True
    return True


cdef void _build_base(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                      const Py_ssize_t* boundary, Py_ssize_t nb) noexcept nogil:
    """The guess's part of ``S`` that its bordered cone blocks leave alone: the rows of
    ``Y`` of its free box entries and of its diagonal cone blocks (``cone_base``), the
    Cholesky factor ``L0`` of ``S0 = SU + Y_D'Y_D`` (the regularized Schur complement of
    every free entry but the bordered blocks'), ``W = L0^-1 A_B'`` on the bordered
    blocks' entries and ``W'W``; ``BASE_NONE`` where a row cannot be written,
    ``BASE_REFUSED`` where ``S0`` is too near singular for the bordered solve
    (``POLISH_BORDER_TOLERANCE``: go2's rows that only boundary blocks span leave ``S0``
    ``delta`` there), so that the guesses of that base go straight to
    :func:`_factor_whole`. ``S0``'s leading ``lead`` columns come from
    :func:`_build_lead` (kept while the free diagonal rows that reach them stay), and
    their Schur complement ``SC`` is kept: they are the whole ``S``'s too, so that
    :func:`_factor_whole` factors only the rest for each guess of the base, a refused
    ``S0``'s included.

    The first base of a solve keeps its free cone blocks diagonal, borders its boundary
    blocks and holds its apex blocks, as the guess has them: a warm polish's guess
    usually settles on its first base. A later one, and the first of a polish from no
    multipliers (``border_all``), borders every cone block, so that it serves every
    guess that holds the same box entries, whichever of free, boundary or apex each
    cone block takes: a polish whose guesses move contacts between those (a contact
    change's, a block or two a pass) builds one base for them, where it had built one a
    guess (anymal_c's contact tick 360: 22k instructions each, six bases;
    notes/performance-history.md, "bordercones"). Bordering every block costs a warm
    tick's single base about 7 % of its instructions (go2), so a warm polish's first
    base does not."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, r, c, a, k, d, start, e = 0, row
    cdef Py_ssize_t lead = f.lead, rest = m - lead
    cdef double largest
    cdef double* trailing = f.S0 + lead * (m + 1)
    cdef Py_ssize_t kb = 0
    f.base = BASE_NONE
    for k in range(p.cones.count):
        if _next_boundary(boundary, nb, k, &kb) or f.border_all:
            f.cone_base[k] = CONE_BORDERED
        else:
            f.cone_base[k] = (CONE_HELD if index[p.constrained[p.cones.offset[k]]] < 0
                              else CONE_DIAGONAL)
    f.border_all = True
    row = _walk_diagonal(f, p, index, True)
    if row < 0:
        return
    f.diag_end = f.kept_rows = <int>row   # the rows past it take the bordered entries
    f.base = BASE_SINGULAR
    if not _same_lead(f, p, row) and not _build_lead(f, p, row):
        return
    for c in range(lead, m):   # SC: LSC and the other free diagonal rows' sums
        for r in range(c, m):
            f.SC[r + c * m] = f.LSC[r + c * m]
    _add_rows(f, p, row, False, f.SC)
    largest = f.lead_largest
    for c in range(lead, m):   # S0's diagonal: diag0 and the sums since
        largest = max(largest, f.diag0[c] + f.SC[c * (m + 1)] - f.LSC[c * (m + 1)])
        for r in range(c, m):
            f.S0[r + c * m] = f.SC[r + c * m]
    f.base = BASE_REFUSED
    if rest > 0 and not cholesky(trailing, <int>rest, <int>m):
        return
    for c in range(m):
        if f.S0[c + c * m] * f.S0[c + c * m] <= POLISH_BORDER_TOLERANCE * largest:
            return
    for k in range(p.cones.count):   # the bordered blocks' entries: columns of W
        if f.cone_base[k] != CONE_BORDERED:
            continue
        d = p.cones.dim[k]
        start = p.constrained[p.cones.offset[k]]
        for a in range(d):
            for c in range(rest):
                f.W[c + (e + a) * rest] = p.A.values[f.arow[lead + c] * n + start + a]
        e += d
    if e > 0 and rest > 0:   # W's leading rows are zero: A_B' is
        trsm(b"L", b"N", <int>rest, <int>e, trailing, <int>m, f.W, <int>rest)
        syrk_t(<int>e, <int>rest, f.W, <int>rest, 0.0, f.WW, <int>s)
    else:
        for c in range(e):
            for r in range(c, e):
                f.WW[r + c * s] = 0.0
    f.ncone, f.base_largest = <int>e, largest
    f.base = BASE_READY


cdef inline bint _curved_block(PolishSchur* f, const Problem* p, Py_ssize_t o, Py_ssize_t d,
                               Py_ssize_t start, const double* hess) noexcept nogil:
    """Lower triangle of a bordered block's ``H_b = diag(P)`` plus its curvature ``hess``
    (NULL for a free block) into its ``block`` (cone entries ``o .. o + d``, entries of
    ``x`` from ``start``); False where a diagonal entry of ``P`` is too small for the
    Schur complement."""
    cdef Py_ssize_t r, c, s = p.s
    cdef double* B = f.block + o * s
    for c in range(d):
        if f.root[start + c] == 0.0:
            return False
        for r in range(c, d):
            B[r + c * d] = hess[o * s + r * d + c] if hess != NULL else 0.0
        B[c + c * d] += f.root[start + c] * f.root[start + c]
    return True


cdef bint _factor_bordered(PolishSchur* f, const Problem* p, const Py_ssize_t* boundary,
                           Py_ssize_t nb, const double* g, const double* hess,
                           double delta) noexcept nogil:
    """Factor the guess's cone blocks against the base (:func:`_build_base`): ``K = H_B +
    W'W`` on the bordered entries (``H_B``: ``diag(P)``, plus the curvature on the
    boundary blocks), ``Z = L_K^-1 G'`` and ``T = Z'Z + delta I`` on the planes. False
    where a boundary block of ``H`` or ``K`` is not positive definite, or a pivot of
    ``T`` fails ``POLISH_RANK_TOLERANCE`` against the largest diagonal entry of ``S0``
    and of ``S``'s planes' part."""
    cdef Py_ssize_t s = p.s, nbd = f.nbd, r, c, a, b, k, kb = 0, o, d, start, e = 0
    cdef bint curved
    cdef double* B
    cdef double* column
    cdef double largest = f.base_largest, value
    for c in range(nbd):
        for r in range(c, nbd):
            f.K[r + c * s] = f.WW[f.border_col[r] + f.border_col[c] * s]
    for b in range(f.nborder):
        k = f.border[b]
        o, d = p.cones.offset[k], p.cones.dim[k]
        start = p.constrained[o]
        B = f.block + o * s
        curved = _next_boundary(boundary, nb, k, &kb)
        if not _curved_block(f, p, o, d, start, hess if curved else NULL):
            return False
        for c in range(d):
            for r in range(c, d):
                f.K[e + r + (e + c) * s] += B[r + c * d]
        if curved:
            if not cholesky(B, <int>d, <int>d):
                return False
            for a in range(d):   # S's diagonal entry of this plane: g' H_b^-1 g + delta
                f.t2[a] = g[o + a]
            forward_substitution(B, <int>d, <int>d, f.t2)
            value = delta
            for a in range(d):
                value += f.t2[a] * f.t2[a]
            largest = max(largest, value)
        e += d
    if kb != nb:   # a boundary block held at its apex: not the guess the polish keeps
        return False
    if nbd > 0 and not cholesky(f.K, <int>nbd, <int>s):
        return False
    e = kb = 0
    for b in range(f.nborder):
        k = f.border[b]
        o, d = p.cones.offset[k], p.cones.dim[k]
        if _next_boundary(boundary, nb, k, &kb):
            column = f.Z + (kb - 1) * s
            for r in range(nbd):
                column[r] = 0.0
            for a in range(d):
                column[e + a] = g[o + a]
            fccqp_forward_vector(f.K + e + e * s, <int>(nbd - e), <int>s, column + e)
        e += d
    for c in range(nb):
        for r in range(c, nb):
            f.T[r + c * s] = _dot(f.Z + r * s, f.Z + c * s, nbd)
        f.T[c + c * s] += delta
    if nb > 0 and not cholesky(f.T, <int>nb, <int>s):
        return False
    for c in range(nb):
        if f.T[c + c * s] * f.T[c + c * s] <= POLISH_RANK_TOLERANCE * largest:
            return False
    return True


cdef inline double _dot(const double* a, const double* b, Py_ssize_t count) noexcept nogil:
    cdef Py_ssize_t i
    cdef double total = 0.0
    for i in range(count):
        total += a[i] * b[i]
    return total


cdef bint polish_schur_factor(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                              const Py_ssize_t* boundary, Py_ssize_t nb, const double* g,
                              const double* hess, double delta) noexcept nogil:
    """Factor the polished KKT system of the guess whose held entries have ``index`` -1
    and whose boundary blocks are ``boundary[:nb]`` (ascending), with planes ``g`` and
    curvature ``hess`` as :mod:`fccqp.polish` keeps them. False where the Schur
    complement does not apply.

    Bordered where it can be: ``mu`` and the entries ``x_B`` of the cone blocks off their
    apex are eliminated after the other free entries, through ``S0`` (the Schur
    complement without the cone blocks, ``m`` rows), then ``x_B`` through ``K = H_B + A_B'
    S0^-1 A_B``, the planes last through ``T = G K^-1 G' + delta I``. A guess that keeps
    the free box entries (most factorizations of a polish: every Newton step, every
    ``renew`` that moves the planes or moves cone blocks between free, boundary and apex)
    then refactors only ``K`` and ``T`` (the bordered entries and ``nb`` rows) and keeps
    ``S0``, ``W`` and ``W'W`` (notes/polish.md, "schurup"). Otherwise, or where ``S0`` is
    too near singular for that order, the whole ``S`` (:func:`_factor_whole`, from the
    base's rows of ``Y`` and their sums, so the base stays the guess's); its columns
    are ``A``'s rows that no cone entry touches first (``arow``), so that a guess
    factors only the rows past the base's leading block (talos: 20 + nb of 68 + nb)."""
    f.bordered = False
    if not _same_base(f, p, index, boundary, nb):
        _build_base(f, p, index, boundary, nb)
    if f.base == BASE_NONE or f.base == BASE_SINGULAR:
        return False   # a free row could not be written, or S0's leading block failed
    _border(f, p, index)
    if f.base == BASE_READY and _factor_bordered(f, p, boundary, nb, g, hess, delta):
        f.bordered = True
        f.rows = f.diag_end + f.nbd
        f.size = <int>(p.m + nb)
        return True
    return _factor_whole(f, p, boundary, nb, g, hess, delta)


cdef void _forward(PolishSchur* f, const Problem* p, double* w) noexcept nogil:
    """``w := L^-1 w``, ``w`` in the order of ``Y``'s rows."""
    cdef Py_ssize_t r, b, k
    if f.dense > 0:
        fccqp_forward_vector(f.L, f.dense, <int>p.n, w)
    for r in range(f.dense, f.diag_end):
        w[r] *= f.inv_root[r]
    for b in range(f.nborder):
        k = f.border[b]
        forward_substitution(f.block + p.cones.offset[k] * p.s, <int>p.cones.dim[k],
                             <int>p.cones.dim[k], w + f.block_row[b])


cdef void _backward(PolishSchur* f, const Problem* p, double* w) noexcept nogil:
    """``w := L'^-1 w``, ``w`` in the order of ``Y``'s rows."""
    cdef Py_ssize_t r, b, k
    for b in range(f.nborder):
        k = f.border[b]
        backward_substitution(f.block + p.cones.offset[k] * p.s, <int>p.cones.dim[k],
                              <int>p.cones.dim[k], w + f.block_row[b])
    for r in range(f.dense, f.diag_end):
        w[r] *= f.inv_root[r]
    if f.dense > 0:
        fccqp_backward_vector(f.L, f.dense, <int>p.n, w)


cdef inline void _subtract_rows(PolishSchur* f, Py_ssize_t m, const double* r,
                                double* u) noexcept nogil:
    """``u[c] -= r[arow[c]]`` over ``S``'s first ``m`` columns: the right-hand side of
    ``A``'s rows in ``S``'s order."""
    cdef Py_ssize_t c
    for c in range(m):
        u[c] -= r[f.arow[c]]


cdef inline void _put_rows(PolishSchur* f, Py_ssize_t m, Py_ssize_t size, const double* u,
                           double* out) noexcept nogil:
    """``out`` := ``u`` (``size`` entries), the first ``m`` back in ``A``'s row order."""
    cdef Py_ssize_t c
    for c in range(m):
        out[f.arow[c]] = u[c]
    for c in range(m, size):
        out[c] = u[c]


cdef void _solve_whole(PolishSchur* f, Py_ssize_t m, Py_ssize_t size, double* u) noexcept nogil:
    """``u := S^-1 u`` for :func:`_factor_whole`'s ``S``: its leading ``lead`` columns'
    factor ``[L11; L21]`` is ``S0``'s (rows past ``m``: zero), the rest's ``S``'s."""
    cdef Py_ssize_t lead = f.lead, rest = m - lead, r, c
    cdef const double* column
    if lead > 0:
        fccqp_forward_vector(f.S0, <int>lead, <int>m, u)
        for c in range(lead):   # u_2 -= L21 u_1
            column = f.S0 + c * m
            for r in range(lead, m):
                u[r] -= column[r] * u[c]
    fccqp_forward_vector(f.S, <int>(size - lead), <int>(size - lead), u + lead)
    fccqp_backward_vector(f.S, <int>(size - lead), <int>(size - lead), u + lead)
    if lead > 0:
        for c in range(lead):   # u_1 -= L21' u_2
            u[c] -= _dot(f.S0 + lead + c * m, u + lead, rest)
        fccqp_backward_vector(f.S0, <int>lead, <int>m, u)


cdef void _solve_bordered(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                          Py_ssize_t nb, double* v) noexcept nogil:
    """:func:`polish_schur_solve` for a bordered factorization: ``w_E = L_E^-1 r_E`` on
    the free entries but the boundary blocks', ``rho = L0^-1 (Y_E'w_E - r_mu)``, then
    ``K x_B + G'lam = r_B - W'rho`` and ``G x_B - delta lam = r_lam`` through ``K`` and
    ``T``, ``mu = L0'^-1 (rho + W x_B)``, ``x_E = L_E'^-1 (w_E - Y_E mu)``."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, r, c, e, kb, nf = f.rows, nbd = f.nbd
    cdef Py_ssize_t lead = f.lead, rest = m - lead
    cdef int end = f.diag_end, mm = <int>m, ld = <int>p.n
    cdef double* w = f.t
    cdef double* xb = f.t + f.diag_end
    cdef double* u = f.u
    cdef double* lam = f.u + m
    for r in range(nf):
        w[r] = v[index[f.rowvar[r]]]
    if f.dense > 0:
        fccqp_forward_vector(f.L, f.dense, <int>n, w)
    for r in range(f.dense, end):
        w[r] *= f.inv_root[r]
    if m > 0:
        matvec_ld(f.Y, ld, w, u, mm, end)   # Y_E'w_E
        _subtract_rows(f, m, v + nf, u)
        fccqp_forward_vector(f.S0, mm, mm, u)
    matvec_ld(f.W, rest, u + lead, f.t2, f.ncone, rest)   # W'rho: W's columns are rows of W'
    for e in range(nbd):
        xb[e] -= f.t2[f.border_col[e]]
    fccqp_forward_vector(f.K, <int>nbd, <int>s, xb)
    for kb in range(nb):
        lam[kb] = _dot(f.Z + kb * s, xb, nbd) - v[nf + m + kb]
    cholesky_solve_vector(f.T, <int>nb, <int>s, lam)
    for kb in range(nb):
        for e in range(nbd):
            xb[e] -= f.Z[e + kb * s] * lam[kb]
    fccqp_backward_vector(f.K, <int>nbd, <int>s, xb)
    if m > 0:
        fill(f.t2, 0.0, f.ncone)   # x_B in W's columns, the apex blocks' zero
        for e in range(nbd):
            f.t2[f.border_col[e]] = xb[e]
        colmatvec(f.W, <int>rest, f.t2, u + lead, rest, f.ncone, 1.0)
        fccqp_backward_vector(f.S0, mm, mm, u)
        fccqp_matvec_t(f.Y, <int>n, u, f.t2, mm, end)   # Y_E mu
        for r in range(end):
            w[r] -= f.t2[r]
    for r in range(f.dense, end):
        w[r] *= f.inv_root[r]
    if f.dense > 0:
        fccqp_backward_vector(f.L, f.dense, <int>n, w)
    for r in range(nf):
        v[index[f.rowvar[r]]] = w[r]
    _put_rows(f, m, m + nb, u, v + nf)


cdef void polish_schur_solve(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                             Py_ssize_t nb, double* v) noexcept nogil:
    """``v := M^-1 v`` for the factored guess (its planes and curvature, also after
    they moved: a chord step), ``v = [x_F; nu; lam]`` as :mod:`fccqp.polish` lays out
    its unknowns (free entries by ``index``, the rows, the planes):
    ``w = L^-1 r_x``, ``u = S^-1 (Y'w - r_c)``, ``x_F = L'^-1 (w - Y u)``."""
    cdef Py_ssize_t n = p.n, r, c, nf = f.rows
    cdef int rows = f.rows, size = f.size, ld = <int>p.n
    cdef double* w = f.t
    cdef double* u = f.u
    if f.bordered:
        _solve_bordered(f, p, index, nb, v)
        return
    for r in range(rows):
        w[r] = v[index[f.rowvar[r]]]
    _forward(f, p, w)
    if size > 0:
        # Y'w in fccqp's kernel: go2's warm ticks 0.966x OpenBLAS dgemv's wall time (in
        # lockstep), and sums that do not follow the kernel OpenBLAS picks for the CPU
        # (notes/performance-history.md, "End of session 36")
        matvec_ld(f.Y, ld, w, u, size, rows)
        _subtract_rows(f, p.m, v + nf, u)
        for c in range(p.m, size):
            u[c] -= v[nf + c]
        _solve_whole(f, p.m, size, u)
        fccqp_matvec_t(f.Y, <int>n, u, f.t2, size, rows)   # Y u: columns of Y
        for r in range(rows):
            w[r] -= f.t2[r]
    _backward(f, p, w)
    for r in range(rows):
        v[index[f.rowvar[r]]] = w[r]
    _put_rows(f, p.m, size, u, v + nf)
