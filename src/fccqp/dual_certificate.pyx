# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The dual infeasibility (unboundedness) certificate from ADMM's last step.

A direction ``dx`` (scaled) certifies that the QP is unbounded below when ``P dx ~ 0``,
``A dx ~ 0`` (each row against its norm times ``||dx||``, see :func:`_near_zero`),
``q'dx < -eps |q|'|dx|`` with that descent dominating the residuals, and ``dx_S`` in
the recession cone of the box and the cones. The primal and equality certificates, and
the principles all three share (relative tests, no fixed margin), are in
:mod:`fccqp.certificates`.
"""

from libc.math cimport fabs, isfinite, sqrt

from fccqp._types cimport Problem
from fccqp.matrices cimport DENSE, Matrix, product_row_norms
from fccqp.projections cimport proj_block
from fccqp.tuning cimport BALANCE_RANGE, DOMINANCE


cdef inline bint _near_zero(const Matrix* M, const double* dx, double dx_norm, double eps,
                            double* out, double* norms) noexcept nogil:
    """``M dx ~ 0`` (scaled) row by row: ``|M_i dx| <= eps ||M_i|| ||dx||`` with the row's
    1-norm and ``dx``'s max-norm (``dx_norm``), as OSQP and COSMO normalize by
    ``||dx||``; ``out`` and ``norms`` are scratch of ``M``'s rows.

    In the equilibrated problem, where columns are balanced: in the user's units a row
    whose norm comes from large-scale variables hid curvature on small-scale ones
    (variables rescaled by 1e-8..1e11: a bounded problem certified unbounded). Not
    relative to the terms ``|M_i||dx|``: along a ray in a coordinate-aligned null
    space (zero columns of ``P``) the ray contributes to neither side, and the
    unconverged remainder is compared with itself."""
    cdef Py_ssize_t i
    product_row_norms(M, dx, out, norms)
    for i in range(M.rows):
        if not fabs(out[i]) <= eps * norms[i] * dx_norm:
            return False
    return True


cdef bint dual_infeasible(const Problem* p, const double* dx, double eps, double* Pdx,
                          double* terms, double* block, double* weights,
                          double* rows) noexcept nogil:
    """Test the direction ``dx`` (scaled); ``Pdx`` and ``terms`` (``max(n, m)``),
    ``block`` (s), ``weights`` (n) and ``rows`` (m) are scratch (``terms`` holds the
    rows' norms of :func:`_near_zero`).

    Its descent ``-q'dx``, relative to its terms, must also dominate every residual
    (``DOMINANCE`` times, as for the primal certificate): with ``P = 0`` and ``|q| =
    1e14`` a bounded problem once passed with a descent of 2e-6 against residuals of
    5e-7 in the cone and 1e-7 in ``A dx``.

    The recession cone is tested in the user's units and in the scaled ones, where the
    columns are balanced: in the user's units alone a cone block of entries 1e-7 of the
    ray's largest (variables rescaled by 1e-8..1e8) was let out of its cone by a whole
    unit of its own size, and a bounded problem was certified unbounded at its start;
    in the scaled units alone a box entry of large ``D`` left its recession cone by
    1e-3 of the ray in the user's units. ``P dx ~ 0`` and ``A dx ~ 0`` hold in the
    equilibrated units and in a second balance (:func:`_balanced_near_zero`)."""
    cdef Py_ssize_t n = p.n, s = p.s, i, j, k, a, dim
    cdef double qdx = 0.0, size = 0.0, norm = 0.0, user = 0.0, step, tol, tol_user, miss
    for i in range(n):
        qdx += p.q[i] * dx[i]
        size += fabs(p.q[i] * dx[i])
        norm = max(norm, fabs(dx[i]))
        user = max(user, fabs(dx[i] * p.D[i]))
    if not (qdx < -eps * size) or not isfinite(qdx) or user <= 1e-300:
        return False
    eps = min(eps, -qdx / (size * DOMINANCE))
    tol, tol_user = eps * norm, eps * user
    for j in range(s):
        i = p.constrained[j]
        step = dx[i]
        if (isfinite(p.hi[j]) and (step > tol or step * p.D[i] > tol_user)) or (
                isfinite(p.lo[j]) and (step < -tol or step * p.D[i] < -tol_user)):
            return False
    for k in range(p.cones.count):
        a, dim = p.cones.offset[k], p.cones.dim[k]
        for j in range(dim):
            block[a + j] = dx[p.constrained[a + j]]
        proj_block(block + a, p.cones.kind[k], dim, p.cones.mu[k], p.cones.normal + 3 * k,
                   terms)
        for j in range(dim):
            miss = fabs(block[a + j] - terms[j])
            if miss > tol or miss * p.D[p.constrained[a]] > tol_user:
                return False
    if not _near_zero(&p.P, dx, norm, eps, Pdx, terms):
        return False
    if p.m > 0 and not _near_zero(&p.A, dx, norm, eps, Pdx, terms):
        return False
    return _balanced_near_zero(p, dx, eps, weights, rows, Pdx, terms)


cdef bint _balanced_near_zero(const Problem* p, const double* dx, double eps,
                              double* weights, double* rows, double* out,
                              double* norms) noexcept nogil:
    """:func:`_near_zero` of ``P dx`` and ``A dx`` in a second balance of the columns,
    found from the data alone: each of the user's columns divided by the square root of
    its largest entry, in ``P`` and in ``A`` with each row at unit size (bounded to
    ``1 / BALANCE_RANGE .. BALANCE_RANGE``), as ``tests/verify.py`` judges the
    certificate. ``weights`` (n) and ``rows`` (m) are scratch, ``out`` and ``norms``
    (``max(n, m)``) too.

    ``M dx ~ 0`` depends on the balance of the columns (it sets the weight of each
    entry of ``dx`` in ``||dx||`` and in each row's norm), and Ruiz's, which follows
    ``P``'s and ``A``'s norms together, may make a ray's one entry dominate the rest:
    with ``P`` of rank 2 and entries of 1e-12 (variables rescaled), ADMM's direction
    after 50 iterations passed at 9.6e-7 in the equilibrated units and had ``P dx`` at
    1.6e-4 of its rows in this balance, where the others' error counts (fuzz
    extreme_data 900360). Runs only for a direction that passed every other test."""
    cdef const Matrix* A = &p.A
    cdef const Matrix* P = &p.P
    cdef Py_ssize_t n = p.n, m = p.m, i, j, k
    cdef double size, norm = 0.0
    # in the scaled units: the user's |A_ij| / max_k |A_ik| is (|A_ij| / D_j) / rows_i
    # with rows_i = max_k |A_ik| / D_k, the user's |P_ij| is |P_ij| / (c D_i D_j)
    for i in range(m):
        rows[i] = 0.0
    for j in range(n):
        weights[j] = 0.0
    if A.kind == DENSE:
        for i in range(m):
            for j in range(n):
                rows[i] = max(rows[i], fabs(A.values[i * n + j]) / p.D[j])
        for i in range(m):
            for j in range(n):
                if rows[i] > 0.0:
                    weights[j] = max(weights[j], fabs(A.values[i * n + j]) / (p.D[j] * rows[i]))
    else:
        for j in range(n):
            for k in range(A.colptr[j], A.colptr[j + 1]):
                rows[A.rowind[k]] = max(rows[A.rowind[k]], fabs(A.values[k]) / p.D[j])
        for j in range(n):
            for k in range(A.colptr[j], A.colptr[j + 1]):
                if rows[A.rowind[k]] > 0.0:
                    weights[j] = max(weights[j],
                                     fabs(A.values[k]) / (p.D[j] * rows[A.rowind[k]]))
    for j in range(n):
        if P.kind == DENSE:
            for i in range(n):
                weights[j] = max(weights[j], fabs(P.values[i * n + j]) / (p.c * p.D[i] * p.D[j]))
        else:
            for k in range(P.colptr[j], P.colptr[j + 1]):
                weights[j] = max(weights[j],
                                 fabs(P.values[k]) / (p.c * p.D[P.rowind[k]] * p.D[j]))
    for j in range(n):   # the column's factor, in the scaled units
        size = weights[j] if weights[j] > 0.0 else 1.0
        size = min(max(size, 1.0 / BALANCE_RANGE), BALANCE_RANGE)
        weights[j] = 1.0 / (sqrt(size) * p.D[j])
        norm = max(norm, fabs(dx[j]) / weights[j])
    return (_weighted_near_zero(P, dx, weights, norm, eps, out, norms)
            and (m == 0 or _weighted_near_zero(A, dx, weights, norm, eps, out, norms)))


cdef bint _weighted_near_zero(const Matrix* M, const double* dx, const double* weights,
                              double norm, double eps, double* out,
                              double* norms) noexcept nogil:
    """``|M_i dx| <= eps (sum_j |M_ij| weights_j) norm`` for every row: :func:`_near_zero`
    with the columns scaled by ``weights`` (``norm = max_j |dx_j| / weights_j``)."""
    cdef Py_ssize_t n = M.cols, i, j, k
    if M.kind == DENSE:
        for i in range(M.rows):
            out[i] = norms[i] = 0.0
            for j in range(n):
                out[i] += M.values[i * n + j] * dx[j]
                norms[i] += fabs(M.values[i * n + j]) * weights[j]
    else:
        for i in range(M.rows):
            out[i] = norms[i] = 0.0
        for j in range(n):
            for k in range(M.colptr[j], M.colptr[j + 1]):
                out[M.rowind[k]] += M.values[k] * dx[j]
                norms[M.rowind[k]] += fabs(M.values[k]) * weights[j]
    for i in range(M.rows):
        if not fabs(out[i]) <= eps * norms[i] * norm:
            return False
    return True
