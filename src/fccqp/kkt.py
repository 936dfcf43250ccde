"""Dense KKT backend of the x-update, compiled with numba; LAPACK does the algebra.

The x-update solves, for a right-hand side ``(r, b)``,

    [ P + sigma I + R   A' ] [x ]   [r]
    [ A                 0  ] [nu] = [b],      R = diag(rho on constrained entries).

We factor the quasi-definite matrix with ``-delta I`` in place of the zero block
(Bunch-Kaufman ``dsytrf``), which exists for any ``A``, rank-deficient included, and
remove the perturbation by iterative refinement against the true matrix (as OSQP
does): equalities hold to factorization accuracy and no rank-revealing
decomposition is needed. The inertia of the factorization certifies that
``P + sigma I + R`` is positive definite: it must have exactly ``m`` negative
eigenvalues.

Contract: :func:`assemble` + :func:`factor` build the factorization for given
(P, A, sigma, rho); :func:`solve_refined` solves with it for one right-hand side,
:func:`solve_unit_columns` for unit vectors on chosen entries of ``x``.
"""

import numpy as np
from numba import njit

from fccqp._lapack import dsytrf, dsytrs, dsytrs2

DELTA = 1e-13
"""Quasi-definite regularization of the (2, 2) block (scaled problem)."""
MAX_REFINE = 5
"""Most refinement steps per solve."""
REFINE_TOLERANCE = 1e-13
"""Refine while ``||A x - b||`` (unscaled) exceeds this times ``max(1, ||b||, ||A x||)``."""

_LOWER = 76  # ord("L")


@njit(cache=True)
def assemble(P, A, sigma, constrained, rho_vec, K):
    """Write the lower triangle of the regularized KKT matrix into ``K`` (Fortran order)."""
    n = P.shape[0]
    m = A.shape[0]
    for j in range(n):
        for i in range(j, n):
            K[i, j] = P[i, j]
        K[j, j] += sigma
        for i in range(m):
            K[n + i, j] = A[i, j]
    for k in range(constrained.shape[0]):
        j = constrained[k]
        K[j, j] += rho_vec[k]
    for i in range(m):
        for j in range(i, m):
            K[n + j, n + i] = 0.0
        K[n + i, n + i] = -DELTA


@njit(cache=True)
def factor(K, ipiv, work):
    """Factor ``K`` in place; return the number of negative eigenvalues (-1 if singular)."""
    N = K.shape[0]
    size = np.array([N], dtype=np.int32)
    lwork = np.array([work.shape[0]], dtype=np.int32)
    info = np.zeros(1, dtype=np.int32)
    dsytrf(np.array([_LOWER], dtype=np.uint8), size, K, size, ipiv, work, lwork, info)
    if info[0] != 0:
        return -1
    negative = 0
    k = 0
    while k < N:
        if ipiv[k] > 0:
            if K[k, k] < 0:
                negative += 1
            k += 1
        else:  # 2x2 block: one negative eigenvalue if det < 0, two if det > 0 and trace < 0
            a, c, d = K[k, k], K[k + 1, k], K[k + 1, k + 1]
            det = a * d - c * c
            if det < 0:
                negative += 1
            elif a + d < 0:
                negative += 2
            k += 2
    return negative


@njit(cache=True)
def _solve_factored(K, ipiv, rhs):
    """Solve in place for one right-hand side (a vector) or several (a Fortran matrix,
    with the level-3 ``dsytrs2``)."""
    size = np.array([K.shape[0]], dtype=np.int32)
    info = np.zeros(1, dtype=np.int32)
    uplo = np.array([_LOWER], dtype=np.uint8)
    if rhs.ndim == 1:
        dsytrs(uplo, size, np.ones(1, dtype=np.int32), K, size, ipiv, rhs, size, info)
    else:
        columns = np.array([rhs.shape[1]], dtype=np.int32)
        dsytrs2(uplo, size, columns, K, size, ipiv, rhs, size, np.empty(K.shape[0]), info)


@njit(cache=True)
def meets_equalities(Ax, b, row_scale):
    """Refinement's stopping test: ``||E^-1 (b - A x)|| <= REFINE_TOLERANCE`` times its
    scale, ``E`` being ``row_scale`` (the user's equality residual)."""
    error = size = 0.0
    for i in range(Ax.shape[0]):
        error = max(error, abs(b[i] - Ax[i]) / row_scale[i])
        size = max(size, abs(b[i]) / row_scale[i], abs(Ax[i]) / row_scale[i])
    return error <= REFINE_TOLERANCE * max(1.0, size)


@njit(cache=True)
def in_null_space(AW, A, Wx, row_scale):
    """:func:`meets_equalities` for columns ``W_x`` that should satisfy ``A W_x = 0``,
    given ``AW = A W_x``."""
    error = 0.0
    for i in range(AW.shape[0]):
        for j in range(AW.shape[1]):
            error = max(error, abs(AW[i, j]) / row_scale[i])
    size = np.max(np.abs(A)) * np.max(np.abs(Wx)) / np.min(row_scale)
    return error <= REFINE_TOLERANCE * max(1.0, size)


@njit(cache=True)
def solve_refined(K, ipiv, P, A, row_scale, sigma, constrained, rho_vec, rhs, sol, residual):
    """Solve the unregularized KKT system for ``rhs`` into ``sol``.

    ``A`` has equilibrated rows ``E A_user D``; ``row_scale`` is ``E``, so that the
    stopping test measures the user's equality residual ``E^-1 (b - A x)``.
    ``residual`` is scratch space of the same size as ``rhs``.
    """
    n = P.shape[0]
    sol[:] = rhs
    _solve_factored(K, ipiv, sol)
    if A.shape[0] == 0:
        return
    b = rhs[n:]
    for _ in range(MAX_REFINE):
        x = sol[:n]
        nu = sol[n:]
        Ax = A @ x
        if meets_equalities(Ax, b, row_scale):
            return
        eq = b - Ax
        residual[:n] = rhs[:n] - P @ x - sigma * x - A.T @ nu
        for k in range(constrained.shape[0]):
            residual[constrained[k]] -= rho_vec[k] * x[constrained[k]]
        residual[n:] = eq
        _solve_factored(K, ipiv, residual)
        sol += residual


@njit(cache=True)
def solve_unit_columns(K, ipiv, P, A, row_scale, sigma, constrained, rho_vec, entries, W):
    """Fill ``W`` (Fortran, ``(n + m) x len(entries)``) with the KKT solutions for ``[e_i; 0]``.

    Column ``j`` is the response of ``(x, nu)`` to a unit right-hand side on entry
    ``entries[j]`` of ``x``. Refined like :func:`solve_refined`, all columns at once;
    returns False when the equality part does not reach ``REFINE_TOLERANCE`` (then the
    caller falls back).
    """
    n = P.shape[0]
    s = entries.shape[0]
    W[:, :] = 0.0
    for j in range(s):
        W[entries[j], j] = 1.0
    _solve_factored(K, ipiv, W)
    if A.shape[0] == 0:
        return True
    for _ in range(MAX_REFINE + 1):
        Wx = np.ascontiguousarray(W[:n])
        AW = A @ Wx
        if in_null_space(AW, A, Wx, row_scale):
            return True
        residual = np.zeros((s, W.shape[0])).T  # Fortran order, as dsytrs wants
        residual[:n] = -(P @ Wx) - sigma * Wx - A.T @ np.ascontiguousarray(W[n:])
        for j in range(s):
            residual[entries[j], j] += 1.0
            for k in range(constrained.shape[0]):
                residual[constrained[k], j] -= rho_vec[k] * Wx[constrained[k], j]
        residual[n:] = -AW
        _solve_factored(K, ipiv, residual)
        W += residual
    return False
