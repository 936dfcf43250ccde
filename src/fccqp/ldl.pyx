# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Dense LDL' backend of the x-update: Bunch-Kaufman through LAPACK.

The x-update solves, for a right-hand side ``(r, b)``,

    [ P + sigma I + R   A' ] [x ]   [r]
    [ A                 0  ] [nu] = [b],      R = diag(rho on constrained entries).

We factor the quasi-definite matrix with ``-delta I`` in place of the zero block
(``dsytrf``), which exists for any ``A``, rank-deficient included, and remove the
perturbation by iterative refinement against the true matrix (as OSQP does):
equalities hold to factorization accuracy and no rank-revealing decomposition is
needed. The inertia certifies convexity: with ``P + sigma I + R`` positive definite
the matrix has exactly ``m`` negative eigenvalues (fewer when rounding turns the
``-delta`` of a dependent row positive, never more); more than ``m`` means that ``P +
R`` has negative curvature on the null space of ``A``.

Contract: :func:`ldl_factor` for given (P, A, sigma, rho); :func:`ldl_solve` for one
right-hand side (refined); :func:`ldl_solve_many` for several, unrefined (level-3
``dsytrs2``); callers refine those.
"""

from libc.float cimport DBL_EPSILON
from libc.math cimport INFINITY, fabs

from scipy.linalg.cython_lapack cimport dsytrf, dsytrs, dsytrs2

from fccqp._blas cimport gemm
from fccqp._types cimport Problem
from fccqp.matrices cimport product, product_t
from fccqp.tuning cimport KKT_DELTA, KKT_REFINE_TOLERANCE, MAX_REFINE


cdef int ldl_factor(LDL* f, const Problem* p, double sigma, const double* rho_vec) noexcept nogil:
    """Assemble the lower triangle of the regularized KKT matrix and factor it.

    Returns the number of negative eigenvalues, or -1 if the factorization broke down,
    or if, without ``sigma`` (the reduced form's matrix), a pivot is zero to rounding
    (:func:`_singular_pivot`): ``P + R`` is then singular on the null space of ``A``,
    which the reduced form cannot iterate on.
    """
    cdef Py_ssize_t n = p.n, m = p.m, N = f.N, i, j, k
    cdef double* K = f.K
    for j in range(n):
        for i in range(j, n):
            K[i + j * N] = p.P.values[i * n + j]
        K[j + j * N] += sigma
        for i in range(m):
            K[n + i + j * N] = p.A.values[i * n + j]
    for k in range(p.s):
        j = p.constrained[k]
        K[j + j * N] += rho_vec[k]
    for i in range(m):
        for j in range(i, m):
            K[n + j + (n + i) * N] = 0.0
        K[n + i + (n + i) * N] = -KKT_DELTA
    cdef char uplo = b"L"
    cdef int size = f.N, info = 0
    dsytrf(&uplo, &size, K, &size, f.ipiv, f.work, &f.lwork, &info)
    if info != 0:
        return -1
    cdef int negative = 0
    cdef double a, c, d, det
    if sigma == 0.0 and _singular_pivot(f):
        return -1
    k = 0
    while k < N:
        if f.ipiv[k] > 0:
            if K[k + k * N] < 0:
                negative += 1
            k += 1
        else:  # 2x2 block: one negative eigenvalue if det < 0, two if det > 0 and trace < 0
            a, c, d = K[k + k * N], K[k + 1 + k * N], K[k + 1 + (k + 1) * N]
            det = a * d - c * c
            if det < 0:
                negative += 1
            elif a + d < 0:
                negative += 2
            k += 2
    return negative


cdef bint _singular_pivot(const LDL* f) noexcept nogil:
    """Whether a pivot of the factored ``D`` (a 1x1 one, or the smaller eigenvalue of a
    2x2 block, ``det / max entry``) is below ``N^2`` units of rounding of the largest
    pivot entry: the eigenvalue of a direction ``v`` with ``(P + R) v = 0`` and ``A v =
    0``, which the matrix maps to 0 whatever its ``-delta`` block, left to rounding's sign.
    An LP's free entries that the rows leave free (``P = 0``, no ``R`` on them) came out
    positive by rounding, the inertia passed, and the reduced form's solves, multiplied
    by the inverse of that pivot, diverged to 1e48 over 4000 iterations where the full
    form, with ``sigma`` on every entry, solves in 12."""
    cdef Py_ssize_t N = f.N, k = 0
    cdef double largest = 0.0, smallest = INFINITY, a, c, d, size
    cdef const double* K = f.K
    while k < N:
        if f.ipiv[k] > 0:
            largest = max(largest, fabs(K[k + k * N]))
            smallest = min(smallest, fabs(K[k + k * N]))
            k += 1
        else:
            a, c, d = K[k + k * N], K[k + 1 + k * N], K[k + 1 + (k + 1) * N]
            size = max(fabs(a), max(fabs(c), fabs(d)))
            largest = max(largest, size)
            smallest = min(smallest, fabs(a * d - c * c) / size if size > 0.0 else 0.0)
            k += 2
    return smallest <= N * N * DBL_EPSILON * largest


cdef void _solve_one(LDL* f, double* rhs) noexcept nogil:
    cdef char uplo = b"L"
    cdef int size = f.N, one = 1, info = 0
    dsytrs(&uplo, &size, &one, f.K, &size, f.ipiv, rhs, &size, &info)


cdef void ldl_solve_many(LDL* f, double* B, int columns, double* work) noexcept nogil:
    """Solve in place for the ``columns`` right-hand sides of the Fortran ``N x columns``
    matrix ``B`` with the unrefined factorization (``work``: ``N`` entries)."""
    cdef char uplo = b"L"
    cdef int size = f.N, info = 0
    dsytrs2(&uplo, &size, &columns, f.K, &size, f.ipiv, B, &size, work, &info)


cdef bint meets_equalities(const double* Ax, const double* b, const double* row_scale,
                           Py_ssize_t m) noexcept nogil:
    """Refinement's stopping test: ``||E^-1 (b - A x)|| <= REFINE_TOLERANCE`` times its
    scale, ``E`` being ``row_scale`` (so it measures the user's equality residual)."""
    cdef double error = 0.0, size = 0.0
    cdef Py_ssize_t i
    for i in range(m):
        error = max(error, fabs(b[i] - Ax[i]) / row_scale[i])
        size = max(size, max(fabs(b[i]), fabs(Ax[i])) / row_scale[i])
    return error <= KKT_REFINE_TOLERANCE * max(1.0, size)


cdef void _refine_step(LDL* f, const Problem* p, double sigma, const double* rho_vec,
                       const double* rhs, double* sol, double delta) noexcept nogil:
    """One refinement step against the KKT matrix with ``-delta I`` as its (2, 2) block:
    0 for the true system, ``KKT_DELTA`` for the factored one. Needs ``f.Ax = A x`` on entry;
    leaves the correction in ``f.residual``."""
    cdef Py_ssize_t n = p.n, m = p.m, i, k
    cdef double* res = f.residual
    product(&p.P, sol, res)
    product_t(&p.A, sol + n, f.ATnu)
    for i in range(n):
        res[i] = rhs[i] - res[i] - sigma * sol[i] - f.ATnu[i]
    for k in range(p.s):
        i = p.constrained[k]
        res[i] -= rho_vec[k] * sol[i]
    for i in range(m):
        res[n + i] = rhs[n + i] - f.Ax[i] + delta * sol[n + i]
    _solve_one(f, res)
    for i in range(n + m):
        sol[i] += res[i]


cdef void _refine_regularized(LDL* f, const Problem* p, double sigma, const double* rho_vec,
                             const double* rhs, double* sol) noexcept nogil:
    """Two refinement steps against the factored matrix itself (with ``-delta I``): the
    factorization of a matrix with entries 1 and 1e-13 loses digits that refinement
    recovers."""
    cdef int step
    for step in range(2):
        product(&p.A, sol, f.Ax)
        _refine_step(f, p, sigma, rho_vec, rhs, sol, KKT_DELTA)


cdef void ldl_solve(LDL* f, const Problem* p, double sigma, const double* rho_vec,
                    const double* rhs, double* sol) noexcept nogil:
    """Solve the unregularized KKT system for ``rhs`` into ``sol`` (they may not alias).

    Refinement stops when a step does not halve the equality error: then ``A x = b``
    has no solution, and the regularized solution (the least-squares ``x`` up to
    ``delta``) is returned rather than one drifting with the singular system.
    """
    cdef Py_ssize_t n = p.n, m = p.m, i, r
    for i in range(n + m):
        sol[i] = rhs[i]
    _solve_one(f, sol)
    if m == 0:
        return
    cdef double* res = f.residual
    cdef double error, last_error = INFINITY
    for r in range(MAX_REFINE + 1):
        product(&p.A, sol, f.Ax)
        if meets_equalities(f.Ax, rhs + n, p.E, m):
            return
        error = 0.0
        for i in range(m):
            error = max(error, fabs(rhs[n + i] - f.Ax[i]) / p.E[i])
        if error >= 0.5 * last_error:
            # no progress: A x = b has no solution (inconsistent rows), and refining
            # against the singular system would only inflate nu; undo the last step and
            # refine against the regularized matrix instead, whose least-squares x is
            # what the equality certificate reads
            if r > 0:
                for i in range(n + m):
                    sol[i] -= res[i]
            _refine_regularized(f, p, sigma, rho_vec, rhs, sol)
            return
        last_error = error
        if r == MAX_REFINE:
            return
        _refine_step(f, p, sigma, rho_vec, rhs, sol, 0.0)


cdef bint _in_null_space(const double* AW, const Problem* p, const double* W, int N,
                         int count) noexcept nogil:
    """:func:`meets_equalities` for columns ``W_x`` that should satisfy ``A W_x = 0``,
    given ``AW = A W_x`` (``m x count``, Fortran)."""
    cdef Py_ssize_t i, j, n = p.n, m = p.m
    cdef double error = 0.0, a_max = 0.0, w_max = 0.0, e_min = 1e300
    for j in range(count):
        for i in range(m):
            error = max(error, fabs(AW[i + j * m]) / p.E[i])
        for i in range(n):
            w_max = max(w_max, fabs(W[i + j * N]))
    for i in range(m * n):
        a_max = max(a_max, fabs(p.A.values[i]))
    for i in range(m):
        e_min = min(e_min, p.E[i])
    return error <= KKT_REFINE_TOLERANCE * max(1.0, a_max * w_max / e_min)


cdef bint ldl_unit_columns(LDL* f, const Problem* p, double sigma, const double* rho_vec,
                           const Py_ssize_t* entries, int count, double* W, double* R,
                           double* work) noexcept nogil:
    """Fill ``W`` (Fortran, ``N x count``) with the KKT solutions for ``[e_i; 0]``, ``i``
    in ``entries``, refined like :func:`ldl_solve`; ``R`` is scratch of ``W``'s size and
    ``work`` of ``N``. False when the equality part misses ``KKT_REFINE_TOLERANCE``."""
    cdef int n = <int>p.n, m = <int>p.m, N = f.N, i, j, k, r
    for j in range(count):
        for i in range(N):
            W[i + j * N] = 0.0
        W[entries[j] + j * N] = 1.0
    ldl_solve_many(f, W, count, work)
    if m == 0:
        return True
    for r in range(MAX_REFINE + 1):
        # R_nu = A W_x (m x count, stored in the first m rows of R's columns of length m)
        gemm(b"T", b"N", m, count, n, 1.0, p.A.values, n, W, N, 0.0, R, m)
        if _in_null_space(R, p, W, N, count):
            return True
        for j in range(count - 1, -1, -1):  # -A W_x to rows n.. (back to front: no overlap)
            for i in range(m - 1, -1, -1):
                R[n + i + j * N] = -R[i + j * m]
        # R_x = e - (P + sigma I) W_x - A' W_nu - R W_x
        gemm(b"N", b"N", n, count, n, -1.0, p.P.values, n, W, N, 0.0, R, N)
        gemm(b"N", b"N", n, count, m, -1.0, p.A.values, n, W + n, N, 1.0, R, N)
        for j in range(count):
            for i in range(n):
                R[i + j * N] -= sigma * W[i + j * N]
            for k in range(p.s):
                i = <int>p.constrained[k]
                R[i + j * N] -= rho_vec[k] * W[i + j * N]
            R[entries[j] + j * N] += 1.0
        ldl_solve_many(f, R, count, work)
        for i in range(N * count):
            W[i] += R[i]
    return False
