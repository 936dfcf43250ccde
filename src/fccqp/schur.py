"""Schur-complement KKT backend for the reduced form, compiled with numba.

When ``H = P + R`` is positive definite, the x-update's system

    [ H   A' ] [x ]   [f]
    [ A   0  ] [nu] = [g]

is solved through two Cholesky factorizations, ``H = L L'`` and ``S = A H^-1 A' =
LS LS'``: ``nu = S^-1 (A H^-1 f - g)``, ``x = H^-1 (f - A' nu)``. With ``Y = L^-1 A'``
(one ``dtrsm``), ``S = Y'Y`` is one ``dsyrk``. All level-3 BLAS, no pivoting: on the
WBC problems it factors and tabulates the reduced form's ``W`` 1.4x (quadrupeds) to
2.5x (talos) faster than ``dsytrf`` + ``dsytrs`` on the full KKT matrix (measured
through scipy's wrappers, ``n, m, s`` = 54, 30, 24 and 124, 68, 56). ``S`` is positive
definite exactly when ``A`` has full row rank; when either factorization fails (or
loses a pivot to cancellation, see ``RANK_TOLERANCE``), or ``W`` misses the accuracy
target (``W`` is not refined here), the caller falls back to the quasi-definite LDL'
backend of :mod:`fccqp.kkt`, which handles rank-deficient ``A``. Solves are refined
against the exact system like :func:`fccqp.kkt.solve_refined`.
"""

import numpy as np
from numba import njit

from fccqp._lapack import dpotrf, dpotrs, dsyrk, dtrsm
from fccqp.kkt import MAX_REFINE, in_null_space, meets_equalities

RANK_TOLERANCE = 1e-10
"""``S`` counts as singular when a Cholesky pivot falls below this times its largest
diagonal entry: (nearly) dependent rows of ``A`` go to the LDL' backend."""
_LOWER = np.array([76], dtype=np.uint8)  # "L"
_LEFT = np.array([76], dtype=np.uint8)  # "L"
_NO_TRANSPOSE = np.array([78], dtype=np.uint8)  # "N"
_TRANSPOSE = np.array([84], dtype=np.uint8)  # "T"
_NON_UNIT = np.array([78], dtype=np.uint8)  # "N"


@njit(cache=True)
def cholesky(M):
    """Factor ``M`` (Fortran, lower triangle) in place; False if not positive definite."""
    size = np.array([M.shape[0]], dtype=np.int32)
    info = np.zeros(1, dtype=np.int32)
    dpotrf(_LOWER.copy(), size, M, size, info)
    return info[0] == 0


@njit(cache=True)
def _triangular_solve(L, B, transpose):
    """``B := L^-1 B`` or ``L^-T B`` in place (``L`` lower, Fortran; ``B`` Fortran)."""
    m = np.array([B.shape[0]], dtype=np.int32)
    n = np.array([B.shape[1]], dtype=np.int32)
    lda = np.array([L.shape[0]], dtype=np.int32)
    trans = _TRANSPOSE.copy() if transpose else _NO_TRANSPOSE.copy()
    dtrsm(_LEFT.copy(), _LOWER.copy(), trans, _NON_UNIT.copy(), m, n, np.ones(1), L, lda, B, m)


@njit(cache=True)
def cholesky_solve(L, b):
    """``b := (L L')^-1 b`` in place for a vector ``b``, ``L`` from :func:`cholesky`."""
    size = np.array([L.shape[0]], dtype=np.int32)
    info = np.zeros(1, dtype=np.int32)
    dpotrs(_LOWER.copy(), size, np.ones(1, dtype=np.int32), L, size, b, size, info)


@njit(cache=True)
def factor(P, A, constrained, rho_vec, L, LS, Y):
    """Factor ``H = P + R`` into ``L`` and ``S`` into ``LS``; ``Y := L^-1 A'``.

    All three are Fortran arrays of shapes ``(n, n)``, ``(m, m)``, ``(n, m)``. Returns
    False when ``H`` or ``S`` is not (numerically) positive definite.
    """
    n, m = P.shape[0], A.shape[0]
    for j in range(n):
        for i in range(j, n):
            L[i, j] = P[i, j]
    for k in range(constrained.shape[0]):
        L[constrained[k], constrained[k]] += rho_vec[k]
    if not cholesky(L):
        return False
    if m == 0:
        return True
    for i in range(m):
        for j in range(n):
            Y[j, i] = A[i, j]
    _triangular_solve(L, Y, False)
    size_m = np.array([m], dtype=np.int32)
    size_n = np.array([n], dtype=np.int32)
    dsyrk(_LOWER.copy(), _TRANSPOSE.copy(), size_m, size_n, np.ones(1), Y, size_n,
          np.zeros(1), LS, size_m)
    largest = 0.0
    for i in range(m):
        largest = max(largest, LS[i, i])
    if not cholesky(LS):
        return False
    for i in range(m):  # a pivot lost to cancellation: dependent rows, leave them to LDL'
        if LS[i, i] * LS[i, i] <= RANK_TOLERANCE * largest:
            return False
    return True


@njit(cache=True)
def _solve(L, LS, A, f, g, x, nu):
    """One unrefined solve of the system for ``(f, g)`` into ``x, nu``."""
    x[:] = f
    cholesky_solve(L, x)
    if A.shape[0] == 0:
        return
    nu[:] = A @ x - g
    cholesky_solve(LS, nu)
    correction = A.T @ nu
    cholesky_solve(L, correction)
    x -= correction


@njit(cache=True)
def solve_refined(L, LS, P, A, row_scale, constrained, rho_vec, rhs, sol):
    """Solve for ``rhs = (f, g)`` into ``sol = (x, nu)``, refining as the LDL' backend does."""
    n = P.shape[0]
    f, g = rhs[:n], rhs[n:]
    x, nu = sol[:n], sol[n:]
    _solve(L, LS, A, f, g, x, nu)
    if A.shape[0] == 0:
        return
    dx, dnu = np.empty(n), np.empty(A.shape[0])
    for _ in range(MAX_REFINE):
        Ax = A @ x
        if meets_equalities(Ax, g, row_scale):
            return
        r_f = f - P @ x - A.T @ nu
        for k in range(constrained.shape[0]):
            r_f[constrained[k]] -= rho_vec[k] * x[constrained[k]]
        _solve(L, LS, A, r_f, g - Ax, dx, dnu)
        x += dx
        nu += dnu


@njit(cache=True)
def unit_columns(L, LS, Y, A, row_scale, constrained, W):
    """Fill ``W`` (Fortran, ``(n + m) x s``) with the responses to ``[e_S(j); 0]``.

    ``nu = S^-1 Y'Z``, ``x = L^-T (Z - Y nu)`` with ``Z = L^-1 E_S``. Returns False when
    ``A W_x`` is not zero to ``REFINE_TOLERANCE`` (then the caller falls back).
    """
    n, m, s = L.shape[0], A.shape[0], constrained.shape[0]
    Z = np.zeros((s, n)).T  # Fortran order
    for j in range(s):
        Z[constrained[j], j] = 1.0
    _triangular_solve(L, Z, False)
    if m > 0:
        nu = np.ascontiguousarray(Y.T) @ Z
        size = np.array([m], dtype=np.int32)
        info = np.zeros(1, dtype=np.int32)
        nu_f = np.asfortranarray(nu)
        dpotrs(_LOWER.copy(), size, np.array([s], dtype=np.int32), LS, size, nu_f, size, info)
        Z -= Y @ nu_f
        W[n:] = nu_f
    _triangular_solve(L, Z, True)
    W[:n] = Z
    if m == 0:
        return True
    Wx = np.ascontiguousarray(Z)
    return in_null_space(A @ Wx, A, Wx, row_scale)
