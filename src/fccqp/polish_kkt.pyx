# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The KKT system of one polish guess: its unknowns, its matrix, its residual, and the
solve refined against the unregularized matrix.

:mod:`fccqp.polish` drives the guesses and the Newton steps; each solve it asks for is
here. The unknowns are the free entries of ``x``, the equality multipliers and one
multiplier per boundary block (:func:`number_unknowns`); the matrix (its lower triangle,
regularized by ``delta``) is factored by Bunch-Kaufman ``dsytrf``, by qdldl where ``P``
and ``A`` are CSC (:mod:`fccqp.polish_csc`), or was factored by
:mod:`fccqp.polish_schur`'s Schur complement (``Polish.structured``), and every solve
is refined by residual corrections against the unregularized matrix, curvature terms
included (:func:`refine`), where a stalled refinement factors again with a smaller
``delta``.
"""

from libc.math cimport INFINITY

from scipy.linalg.cython_lapack cimport dsytrf, dsytrs

from fccqp._dense cimport copy
from fccqp._types cimport Problem
from fccqp.matrices cimport CSC, product, product_t
from fccqp.polish cimport APEX, FIXED, LOWER, UPPER, Polish
from fccqp.polish_csc cimport polish_csc_factor, polish_csc_solve
from fccqp.polish_schur cimport polish_schur_solve
from fccqp.tuning cimport MAX_REFINE, POLISH_DELTA_CUT, POLISH_STALL_RESIDUAL

cdef extern from "fccqp_kernels.h" nogil:
    double fccqp_abs_max(const double* v, long n)


cdef inline bint _same_bits(double a, double b) noexcept nogil:
    """Whether ``a`` and ``b`` are the same double bit for bit (``0.0`` and ``-0.0``
    differ)."""
    return (<unsigned long long*>&a)[0] == (<unsigned long long*>&b)[0]


cdef Py_ssize_t number_unknowns(Polish* w, const Problem* p) noexcept nogil:
    """Put the held entries of ``x`` at their values; number the free entries
    (``index``, ``free``) and return how many there are.

    ``grad`` and ``Ax`` stay current (``grad_current``) where no held entry moved: a new
    guess that only puts blocks on their boundary or releases a bound keeps ``x``, and
    its first residual then reuses the last one's products with ``P`` and ``A``
    (anymal_c's contact tick 360: 3 of its 10 guesses' point products)."""
    cdef Py_ssize_t n = p.n, i, j, nf = 0
    cdef char code
    cdef double value
    for i in range(n):
        w.index[i] = 0
    for j in range(p.s):
        code = w.active[j]
        i = p.constrained[j]
        if code == LOWER or code == FIXED:
            value = p.lo[j]
        elif code == UPPER:
            value = p.hi[j]
        elif code == APEX:
            value = 0.0
        else:
            continue
        if not _same_bits(w.x[i], value):
            w.x[i] = value
            w.grad_current = False
        w.index[i] = -1
    for i in range(n):
        if w.index[i] == 0:
            w.index[i] = nf
            w.free[nf] = i
            nf += 1
    return nf


cdef void _assemble(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb,
                    double delta) noexcept nogil:
    """Lower triangle of the KKT matrix of the polished QP, regularized by ``delta``,
    into ``K``."""
    cdef Py_ssize_t n = p.n, m = p.m, N = nf + m + nb, r, col, i, j, k, o, d, start, jc
    cdef double* K = w.K
    for col in range(N):
        for r in range(col, N):
            K[r + col * N] = 0.0
    for col in range(nf):
        jc = w.free[col]
        for r in range(col, nf):
            K[r + col * N] = p.P.values[w.free[r] * n + jc]
        K[col + col * N] += delta
        for i in range(m):
            K[nf + i + col * N] = p.A.values[i * n + jc]
    for k in range(nb):
        o, d = p.cones.offset[w.boundary[k]], p.cones.dim[w.boundary[k]]
        start = p.constrained[o]
        for j in range(d):
            K[nf + m + k + w.index[start + j] * N] = w.g[o + j]
            for i in range(j, d):   # entries of a block are consecutive unknowns
                K[w.index[start + i] + w.index[start + j] * N] += w.hess[o * w.hess_stride + i * d + j]
    for r in range(nf, N):
        K[r + r * N] = -delta


cdef double kkt_residual(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """Residual of the current ``(x, nu, lam)`` in the unregularized system (with the
    curvature terms) into ``rhs``; returns its infinity norm. Leaves the gradient of the
    Lagrangian without the boundary blocks' terms in ``grad`` (there it is minus the
    multipliers of the held entries) and ``A x`` in ``Ax``.

    Where ``grad_current`` says ``x`` and ``nu`` have not moved since the last residual,
    its ``grad`` and ``Ax`` are taken as they are and only the rows of the guess and its
    planes are formed again: a Newton step or a chord step re-linearizes the planes at
    the point the last refinement left, whose products with ``P`` and ``A`` (most of a
    residual's instructions) are then already known."""
    cdef Py_ssize_t n = p.n, m = p.m, i, j, k, o, d, start, cone
    cdef double value, curved
    if not w.grad_current:
        point_products(w, p)
    for i in range(nf):
        w.rhs[i] = -w.grad[w.free[i]]
    for k in range(nb):
        cone = w.boundary[k]
        o = p.cones.offset[cone]
        start = p.constrained[o]
        d = p.cones.dim[cone]
        value = 0.0
        for j in range(d):
            curved = 0.0
            for i in range(d):
                curved += w.hess[o * w.hess_stride + j * d + i] * w.x[start + i]
            w.rhs[w.index[start + j]] -= w.lam[k] * w.g[o + j] + curved
            value += w.g[o + j] * w.x[start + j]
        w.rhs[nf + m + k] = -value
    for i in range(m):
        w.rhs[nf + i] = p.b[i] - w.Ax[i]
    return fccqp_abs_max(w.rhs, nf + m + nb)   # inf_norm's value in vectors


cdef void point_products(Polish* w, const Problem* p) noexcept nogil:
    """``grad := P x + q + A'nu`` and ``Ax := A x`` at the current point; sets
    ``grad_current``."""
    cdef Py_ssize_t i
    product(&p.P, w.x, w.grad)
    product_t(&p.A, w.nu, w.ATnu)
    for i in range(p.n):
        w.grad[i] += p.q[i] + w.ATnu[i]
    product(&p.A, w.x, w.Ax)
    w.grad_current = True


cdef void _apply(Polish* w, Py_ssize_t nf, Py_ssize_t m, Py_ssize_t nb,
                 double sign) noexcept nogil:
    """Add ``sign`` times ``step`` to the unknowns."""
    cdef Py_ssize_t i
    w.grad_current = False
    for i in range(nf):
        w.x[w.free[i]] += sign * w.step[i]
    for i in range(m):
        w.nu[i] += sign * w.step[nf + i]
    for i in range(nb):
        w.lam[i] += sign * w.step[nf + m + i]


cdef void refine(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb,
                 double tolerance, int* factorizations) noexcept nogil:
    """Correct ``(x, nu, lam)`` to the solution of the factored system: residual
    corrections against the unregularized matrix until the residual is below
    ``tolerance``, stops halving, or ``MAX_REFINE`` corrections after the first; a
    correction that makes it grow is undone.

    A refinement can stop halving because of the regularization: a free block whose
    curvature ``c`` lies below ``delta`` recovers ``c / (c + delta)`` of its step a
    correction, so the residual contracts by ``rate = delta / (c + delta)`` and stays
    far above ``tolerance`` with the step mostly unmade (a friction cone of curvature
    1e-14 against the dense 1e-12, the sparse 1e-8). Where it stops more than
    ``POLISH_STALL_RESIDUAL`` times above ``tolerance`` and still contracting, the system
    is factored again with ``delta`` cut to ``POLISH_DELTA_CUT`` times the curvature that
    rate shows, ``delta (1 - rate) / rate``, and the corrections go on from the current
    point. A correction of that factorization that does not halve the residual is undone
    and the previous factorization restored (a singular block, an LP's free entry, has
    no curvature for any ``delta`` to uncover: its steps would only grow), and no other
    retry is made on it (``retry_spent``). A refinement that halves as it should is
    untouched, and so is one that stops within ``POLISH_STALL_RESIDUAL`` of
    ``tolerance`` (where rounding usually stops it) or in a polish held to the Schur
    complement (``schur_only``: it assembles nothing)."""
    cdef double norm, last = INFINITY, previous = 0.0
    cdef bint retrying = False, was_structured = False
    cdef int r
    for r in range(MAX_REFINE + 2):
        norm = kkt_residual(w, p, nf, nb)
        if retrying and not norm <= 0.5 * last:   # NaN included
            _apply(w, nf, p.m, nb, -1.0)
            _restore(w, p, nf, nb, previous, was_structured, factorizations)
            return
        retrying = False
        if norm > last:
            _apply(w, nf, p.m, nb, -1.0)
            return
        if norm <= tolerance or r == MAX_REFINE + 1:
            return
        if norm > 0.5 * last:
            if (norm >= last or norm <= POLISH_STALL_RESIDUAL * tolerance or w.retry_spent
                    or w.schur_only):
                return
            previous, was_structured = w.delta, w.structured
            if not refactor(w, p, nf, nb, POLISH_DELTA_CUT * w.delta * (last - norm) / norm,
                            factorizations):
                _restore(w, p, nf, nb, previous, was_structured, factorizations)
                return
            retrying = True
        last = norm
        _factored_solve(w, p, nf, nb)
        _apply(w, nf, p.m, nb, 1.0)


cdef bint refactor(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb, double delta,
                   int* factorizations) noexcept nogil:
    """Factor the current guess's KKT matrix regularized by ``delta``, assembled for
    ``dsytrf`` (or for qdldl where ``P`` and ``A`` are CSC); False when the
    factorization breaks down."""
    cdef char uplo = b"L"
    cdef int size = <int>(nf + p.m + nb), info = 0
    factorizations[0] += 1
    w.structured = False
    w.delta = delta
    if p.P.kind == CSC:
        return polish_csc_factor(&w.csc, p, nf, w.free, w.index, w.boundary, nb, w.g, delta)
    _assemble(w, p, nf, nb, delta)
    dsytrf(&uplo, &size, w.K, &size, w.ipiv, w.work, &w.lwork, &info)
    return info == 0


cdef void _restore(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb, double delta,
                   bint structured, int* factorizations) noexcept nogil:
    """Return to the factorization with regularization ``delta`` after a retry with a
    smaller one failed (the Schur complement's is intact: the retry assembled ``K``)."""
    w.retry_spent = True
    if structured:
        w.structured, w.delta = True, delta
    else:
        refactor(w, p, nf, nb, delta, factorizations)   # it factored before: it does again


cdef void _factored_solve(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """``step`` := the current factorization's solution for ``rhs``."""
    cdef char uplo = b"L"
    cdef int size = <int>(nf + p.m + nb), one = 1, info = 0
    copy(w.rhs, w.step, size)
    if w.structured:
        polish_schur_solve(&w.schur, p, w.index, nb, w.step)
    elif p.P.kind == CSC:
        polish_csc_solve(&w.csc, size, w.step)
    else:
        dsytrs(&uplo, &size, &one, w.K, &size, w.ipiv, w.step, &size, &info)


cdef void correct_once(Polish* w, const Problem* p, Py_ssize_t nf, Py_ssize_t nb) noexcept nogil:
    """One correction of the current point with the last factorization (a chord step)."""
    if nf + p.m + nb == 0:
        return
    kkt_residual(w, p, nf, nb)
    _factored_solve(w, p, nf, nb)
    _apply(w, nf, p.m, nb, 1.0)


def abs_max_py(const double[::1] v):
    """Test hook: the norm :func:`kkt_residual` returns for the entries ``v``
    (``fccqp_abs_max``)."""
    if v.shape[0] == 0:
        return 0.0
    return fccqp_abs_max(&v[0], v.shape[0])
