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
``D x D`` block, one ``dtrsm``, one ``dsyrk``), and each guess adds its free
constrained entries' rows (:func:`polish_schur_factor`: a ``dsyrk`` of about ``s``
rows and a Cholesky of ``m + nb`` rows). On go2 (``n, m, s`` = 54, 30, 24, ``D`` = 18)
that is a few tens of thousands of multiply-adds a guess, against the ``dsytrf`` of the
``nf + m + nb`` (about 75) rows of the assembled matrix; and it needs no ADMM
factorization and no reduced table, which the table polish (:mod:`fccqp.polish_table`)
is built on. So a warm polish that succeeds skips both (see ``Workspace._iterate``).

The caller refines against the unregularized system, as with ``dsytrf``. Where ``P``
couples a constrained entry, a block is not positive definite (a negative plane
multiplier's curvature) or ``S`` loses a pivot (dependent rows), the functions return
False and the caller assembles the matrix for ``dsytrf``.
"""

from libc.math cimport sqrt

from fccqp._blas cimport cholesky_solve_vector, syrk_t, trsm
from fccqp._dense cimport matvec, matvec_t
from fccqp._types cimport Problem

PIVOT_TOLERANCE = 1e-12
"""A diagonal entry of ``P`` (or pivot of its dense block) below this times ``P``'s
largest diagonal entry makes ``H`` too close to singular for the Schur complement:
``dsytrf`` of the assembled matrix takes such problems (flat costs, LPs)."""
RANK_TOLERANCE = 1e-10
"""``S`` counts as singular when a Cholesky pivot falls below this times its largest
diagonal entry, as in :mod:`fccqp.schur`."""
cdef double _PIVOT_TOLERANCE = PIVOT_TOLERANCE
cdef double _RANK_TOLERANCE = RANK_TOLERANCE


cdef extern from "fccqp_kernels.h" nogil:
    int fccqp_cholesky(double* M, int n, int ld)


cdef bint polish_schur_setup(PolishSchur* f, const Problem* p, double delta) noexcept nogil:
    """Check ``P``'s structure, factor its dense unconstrained block, and compute the
    unconstrained rows of ``Y`` and their part ``SU`` of ``S``; sets and returns
    ``ready``."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, i, j, r, c, lead = 0, rest
    cdef double largest = 0.0, pivot
    cdef int k
    f.ready = False
    for i in range(n):
        largest = max(largest, p.P[i * n + i])
        f.coupled[i] = 0
        for j in range(n):
            if j != i and p.P[i * n + j] != 0.0:
                f.coupled[i] = 1
                break
    if not largest > 0.0:
        return False
    for j in range(s):
        i = p.constrained[j]
        if f.coupled[i]:
            return False
        f.coupled[i] = 2   # constrained: not part of the unconstrained order
        f.root[i] = sqrt(p.P[i * n + i] + delta) if p.P[i * n + i] > _PIVOT_TOLERANCE * largest else 0.0
    for i in range(n):
        if f.coupled[i] == 1:
            f.order[lead] = i
            lead += 1
    rest = lead
    for i in range(n):
        if f.coupled[i] == 0:
            if not p.P[i * n + i] > _PIVOT_TOLERANCE * largest:
                return False
            f.root[i] = sqrt(p.P[i * n + i] + delta)
            f.order[rest] = i
            rest += 1
    for j in range(s):   # restore the flag of the constrained entries (uncoupled)
        f.coupled[p.constrained[j]] = 0
    k = <int>lead
    f.dense, f.unconstrained = k, rest
    for c in range(k):
        for r in range(c, k):
            f.L[r + c * n] = p.P[f.order[r] * n + f.order[c]]
        f.L[c + c * n] += delta
    if k > 0 and not fccqp_cholesky(f.L, k, <int>n):
        return False
    for c in range(k):
        pivot = f.L[c + c * n]
        if not pivot * pivot > _PIVOT_TOLERANCE * largest:
            return False
    for c in range(m):
        for r in range(rest):
            f.Y[r + c * n] = p.A[c * n + f.order[r]]
        for r in range(k, rest):
            f.Y[r + c * n] /= f.root[f.order[r]]
    if m > 0:
        if k > 0:
            trsm(b"L", b"N", k, <int>m, f.L, <int>n, f.Y, <int>n)
        syrk_t(<int>m, <int>rest, f.Y, <int>n, 0.0, f.SU, <int>m)
        for c in range(m):
            f.SU[c + c * m] += delta
    f.ready = True
    return True


cdef bint _small_cholesky(double* B, Py_ssize_t d) noexcept nogil:
    """Cholesky factor of the ``d x d`` lower triangle of ``B`` in place; False if not
    positive definite. A loop, not ``dpotrf``, which took about 830 instructions a call
    for a friction cone's 3 rows (callgrind, go2), several times the loop's work."""
    cdef Py_ssize_t i, j, k
    cdef double value, pivot
    for j in range(d):
        value = B[j + j * d]
        for k in range(j):
            value -= B[j + k * d] * B[j + k * d]
        if not value > 0.0:
            return False
        pivot = sqrt(value)
        B[j + j * d] = pivot
        for i in range(j + 1, d):
            value = B[i + j * d]
            for k in range(j):
                value -= B[i + k * d] * B[j + k * d]
            B[i + j * d] = value / pivot
    return True


cdef bint polish_schur_factor(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                              const Py_ssize_t* boundary, Py_ssize_t nb, const double* g,
                              const double* hess, double delta) noexcept nogil:
    """Factor ``S`` of the guess whose held entries have ``index`` -1 and whose boundary
    blocks are ``boundary[:nb]`` (ascending), with planes ``g`` and curvature ``hess`` as
    :mod:`fccqp.polish` keeps them. False where the Schur complement does not apply."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, size = m + nb, i, j, r, c, k, o, d
    cdef Py_ssize_t start, rows = 0, kb = 0, a
    cdef double* S = f.S
    cdef double* Z = f.Y + f.unconstrained
    cdef double* B
    cdef double largest = 0.0, value
    for c in range(size):
        for r in range(c, size):
            S[r + c * size] = f.SU[r + c * m] if r < m else 0.0
        if c >= m:
            S[c + c * size] = delta
    for j in range(s):   # free box entries: a diagonal entry of H each
        if p.in_cone[j]:
            continue
        i = p.constrained[j]
        if index[i] < 0:
            continue
        if f.root[i] == 0.0:
            return False
        for c in range(m):
            Z[rows + c * n] = p.A[c * n + i] / f.root[i]
        for c in range(m, size):
            Z[rows + c * n] = 0.0
        rows += 1
    for k in range(p.cones.count):
        o, d = p.cones.offset[k], p.cones.dim[k]
        start = p.constrained[o]
        if index[start] < 0:
            continue   # at the apex: held
        for a in range(d):
            if f.root[start + a] == 0.0:
                return False
            for c in range(m):
                Z[rows + a + c * n] = p.A[c * n + start + a]
            for c in range(m, size):
                Z[rows + a + c * n] = 0.0
        if kb < nb and boundary[kb] == k:   # diag(P) + curvature: a Cholesky of d rows
            B = f.block + o * s
            for c in range(d):
                for r in range(c, d):
                    B[r + c * d] = hess[o * s + r * d + c]
                B[c + c * d] += f.root[start + c] * f.root[start + c]
            if not _small_cholesky(B, d):
                return False
            for a in range(d):
                f.g[o + a] = g[o + a]
                Z[rows + a + (m + kb) * n] = g[o + a]
            for c in range(size):   # Z_block := B^-1 Z_block (forward substitution)
                for a in range(d):
                    value = Z[rows + a + c * n]
                    for r in range(a):
                        value -= B[a + r * d] * Z[rows + r + c * n]
                    Z[rows + a + c * n] = value / B[a + a * d]
            kb += 1
        else:
            for a in range(d):
                for c in range(m):
                    Z[rows + a + c * n] /= f.root[start + a]
        rows += d
    if kb != nb:
        return False   # a boundary block that is held: not a guess this solves
    if rows > 0:
        syrk_t(<int>size, <int>rows, Z, <int>n, 1.0, S, <int>size)
    for c in range(size):
        largest = max(largest, S[c + c * size])
    if size > 0 and not fccqp_cholesky(S, <int>size, <int>size):
        return False
    for c in range(size):
        if S[c + c * size] * S[c + c * size] <= _RANK_TOLERANCE * largest:
            return False
    f.size = <int>size
    return True


cdef void _h_solve(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                   const Py_ssize_t* boundary, Py_ssize_t nb, double* t) noexcept nogil:
    """``t := H^-1 t`` on the free entries (``t`` in the order of ``x``; held entries
    are left alone)."""
    cdef Py_ssize_t n = p.n, s = p.s, r, j, i, k, o, d, start, a, kb = 0
    cdef int dense = f.dense
    cdef double* B
    cdef double value
    for r in range(dense):
        f.t2[r] = t[f.order[r]]
    if dense > 0:
        cholesky_solve_vector(f.L, dense, <int>n, f.t2)
    for r in range(dense):
        t[f.order[r]] = f.t2[r]
    for r in range(dense, f.unconstrained):
        i = f.order[r]
        t[i] /= f.root[i] * f.root[i]
    for j in range(s):
        if p.in_cone[j]:
            continue
        i = p.constrained[j]
        if index[i] >= 0:
            t[i] /= f.root[i] * f.root[i]
    for k in range(p.cones.count):
        o, d = p.cones.offset[k], p.cones.dim[k]
        start = p.constrained[o]
        if index[start] < 0:
            continue
        if kb < nb and boundary[kb] == k:
            B = f.block + o * s
            for a in range(d):   # B B' t = rhs: forward, then backward substitution
                value = t[start + a]
                for r in range(a):
                    value -= B[a + r * d] * t[start + r]
                t[start + a] = value / B[a + a * d]
            for a in range(d - 1, -1, -1):
                value = t[start + a]
                for r in range(a + 1, d):
                    value -= B[r + a * d] * t[start + r]
                t[start + a] = value / B[a + a * d]
            kb += 1
        else:
            for a in range(d):
                t[start + a] /= f.root[start + a] * f.root[start + a]


cdef void polish_schur_solve(PolishSchur* f, const Problem* p, const Py_ssize_t* free,
                             Py_ssize_t nf, const Py_ssize_t* index, const Py_ssize_t* boundary,
                             Py_ssize_t nb, double* v) noexcept nogil:
    """``v := M^-1 v`` for the factored guess (its planes and curvature, also after
    they moved: a chord step), ``v = [x_F; nu; lam]`` as :mod:`fccqp.polish` lays out
    its unknowns (``free[:nf]``, the rows, the planes)."""
    cdef const double* g = f.g
    cdef Py_ssize_t n = p.n, m = p.m, i, kb, a, o, start
    cdef int size = f.size
    cdef double* t = f.t
    cdef double* u = f.u
    cdef double value
    for i in range(n):
        t[i] = 0.0
    for i in range(nf):
        t[free[i]] = v[i]
    _h_solve(f, p, index, boundary, nb, t)
    matvec(p.A, t, u, m, n)
    for i in range(m):
        u[i] -= v[nf + i]
    for kb in range(nb):
        o = p.cones.offset[boundary[kb]]
        start = p.constrained[o]
        value = 0.0
        for a in range(p.cones.dim[boundary[kb]]):
            value += g[o + a] * t[start + a]
        u[m + kb] = value - v[nf + m + kb]
    if size > 0:
        cholesky_solve_vector(f.S, size, size, u)
    matvec_t(p.A, u, f.t2, m, n)
    for i in range(n):
        t[i] = 0.0
    for i in range(nf):
        t[free[i]] = v[i] - f.t2[free[i]]
    for kb in range(nb):
        o = p.cones.offset[boundary[kb]]
        start = p.constrained[o]
        for a in range(p.cones.dim[boundary[kb]]):
            t[start + a] -= g[o + a] * u[m + kb]
    _h_solve(f, p, index, boundary, nb, t)
    for i in range(nf):
        v[i] = t[free[i]]
    for i in range(m + nb):
        v[nf + i] = u[i]
