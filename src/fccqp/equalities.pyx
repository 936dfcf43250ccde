# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""``A x = b`` at a returned point the KKT solves could not hold it at: a projection.

The x-update's KKT matrix carries ``-delta I`` in its (2, 2) block, and refinement
against the true matrix converges like ``delta / (lambda + delta)`` per step, ``lambda``
the eigenvalues of the Schur complement ``A_s (P_s + sigma I + R)^-1 A_s'``. Where the
equilibration gives the columns of a huge ``P`` entries of ``D`` near 1e-9 (fuzz cases
with ``P`` of 1e16..1e19 beside ``A`` of 1..10), ``A_s = E A D`` has singular values
of 1e-9 and ``lambda`` drops to 1e-18, far below ``delta = 1e-13``: the refinement
stalls, reads that as inconsistent rows, and the iterate misses ``A x = b`` by units
(4.9 on a square, well-conditioned ``A`` whose only point is ``A^-1 b``).

:func:`hold_equalities` projects ``x`` onto ``A x = b`` with a Gram matrix of its own,
``G G'`` for ``G = diag(1/r) A_s diag(w)``, ``w`` the reciprocal column norms of
``A_s`` and ``r`` the row norms after them: the columns' scale, which made ``A_s``
ill-conditioned, is taken out (the condition number is about that of the user's
``A`` up to a diagonal scaling), and the step is the smallest in the metric
``diag(w)^-2``. It runs only when a stalled run's point still misses ``A x = b``
after the refined KKT solve for it, so it costs a tick nothing.
"""

from libc.math cimport fabs

from fccqp._blas cimport cholesky_solve
from fccqp.certificates cimport regularized_cholesky
from fccqp._dense cimport copy
from fccqp._types cimport Problem
from fccqp.engine cimport Engine
from fccqp.kkt_sparse cimport sparse_hold_equalities
from fccqp.matrices cimport DENSE, product
from fccqp.tuning cimport EQUALITY_MISSED, KKT_REFINE_TOLERANCE, MAX_REFINE


cdef double _equality_error(const Problem* p, const double* x, double* r,
                            double* scale) noexcept nogil:
    """``r := b - A x`` (scaled rows) and its largest entry in the user's units; ``scale``
    := the largest of 1 and ``|b_i|`` and the terms ``|A_i| |x|`` in the user's units (the
    size ``tests/verify.py`` judges ``A x = b`` against)."""
    cdef Py_ssize_t n = p.n, m = p.m, i, j
    cdef double error = 0.0, terms
    cdef const double* row
    product(&p.A, x, r)
    scale[0] = 1.0
    for i in range(m):
        row = p.A.values + i * n
        terms = fabs(p.b[i])
        for j in range(n):
            terms += fabs(row[j] * x[j])
        scale[0] = max(scale[0], terms / p.E[i])
        r[i] = p.b[i] - r[i]
        error = max(error, fabs(r[i]) / p.E[i])
    return error


cdef bint column_gram(const Problem* p, double* w, double* rows, double* gram) noexcept nogil:
    """``w`` := reciprocal column norms of ``A_s`` (1 on empty columns), ``rows`` := the
    row norms of ``A_s diag(w)`` (1 on empty rows), ``gram`` := the Cholesky factor of
    ``G G'`` (``G = diag(1/rows) A_s diag(w)``, column-major) plus
    ``GRAM_REGULARIZATION`` of its largest diagonal entry (dependent rows). False when
    Cholesky fails."""
    cdef Py_ssize_t n = p.n, m = p.m, i, k, j
    cdef double value
    cdef const double* A = p.A.values
    for j in range(n):
        w[j] = 0.0
    for i in range(m):
        for j in range(n):
            w[j] = max(w[j], fabs(A[i * n + j]))
    for j in range(n):
        w[j] = 1.0 / w[j] if w[j] > 0.0 else 1.0
    for i in range(m):
        rows[i] = 0.0
        for j in range(n):
            rows[i] = max(rows[i], fabs(A[i * n + j]) * w[j])
        if not rows[i] > 0.0:
            rows[i] = 1.0
    # a plain loop, not dsyrk on a weighted copy: the workspace holds no m x n scratch,
    # and this runs only on a stalled run's returned point
    for k in range(m):
        for i in range(k, m):
            value = 0.0
            for j in range(n):
                value += A[i * n + j] * A[k * n + j] * w[j] * w[j]
            gram[i + k * m] = value / (rows[i] * rows[k])
    return regularized_cholesky(gram, m)


cdef void hold_equalities(Engine* e) noexcept nogil:
    """Project the iterate's ``x`` onto ``A x = b`` (see the module docstring) when it
    misses it beyond ``EQUALITY_MISSED`` of its terms; up to ``MAX_REFINE`` projections,
    until ``KKT_REFINE_TOLERANCE`` of them, each kept only while it reduces the error (inconsistent rows keep the least-squares
    point the KKT solves left). Uses ``e.certs.gram`` as scratch and leaves it to be
    factored again for the certificates; over compressed columns, the sparse backend's
    projection (:mod:`fccqp.sparse_equalities`)."""
    cdef Problem* p = &e.prob
    cdef Py_ssize_t n = p.n, m = p.m, i, j, step
    cdef double* x = e.it.x
    cdef double* r = e.work.vec_m
    cdef double* rows = e.work.vec_m2
    cdef double* w = e.work.vec_n
    cdef double* saved = e.work.vec_n2
    cdef double* v = e.work.sol
    cdef double error, scale, new_error
    if m == 0:
        return
    if p.A.kind != DENSE:
        if e.fact.kkt.sparse != NULL:
            sparse_hold_equalities(e.fact.kkt.sparse, n, m, x, p.b)
        return
    error = _equality_error(p, x, r, &scale)
    if error <= EQUALITY_MISSED * scale:
        return
    e.certs.gram_state = 0   # the scratch below is not A A'
    if not column_gram(p, w, rows, e.certs.gram):
        return
    for step in range(MAX_REFINE):
        copy(x, saved, n)
        for i in range(m):   # v := (G G')^-1 diag(1/rows) r
            v[i] = r[i] / rows[i]
        cholesky_solve(e.certs.gram, <int>m, <int>m, v, 1, <int>m)
        for i in range(m):
            v[i] /= rows[i]
        for i in range(m):   # x += diag(w)^2 A_s' v
            for j in range(n):
                x[j] += w[j] * w[j] * p.A.values[i * n + j] * v[i]
        new_error = _equality_error(p, x, r, &scale)
        if not new_error < error:
            copy(saved, x, n)
            return
        error = new_error
        if error <= KKT_REFINE_TOLERANCE * scale:
            return
