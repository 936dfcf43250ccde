"""Feasibility restoration of the returned iterate, compiled with numba.

ADMM's ``x`` meets the equalities at every iterate but the box and the cones only in
the limit: after a 15-iteration budget a torque can exceed its limit or a contact
force leave its friction cone. The slack ``z`` is in ``C`` exactly (it is a
projection), so the restored point takes ``x_S = z`` and re-solves the free entries
from the equality-constrained QP

    min_{x_F}  1/2 x'Px + q'x   s.t.  A x = b,  x_S = z,

with one factorization of the KKT matrix restricted to the free entries, regularized by
``sigma`` like the full form and followed by a few proximal steps that remove that
bias (:func:`restore`).
The reduced iteration has tabulated the KKT response ``W`` on the constrained entries
(see :func:`fccqp.admm._factor_reduced`); there the same point is
``base + W u`` with ``W_S u = z - base_S``, an ``s x s`` Cholesky solve
(:func:`restore_reduced`), ``W_S`` being positive definite exactly when the free
entries can absorb any ``x_S``. The result is
in the box and the cones exactly, meets ``A x = b`` to factorization accuracy when
``A`` restricted to the free columns can absorb any ``x_S`` (true of whole-body
control: accelerations and contact slacks are free), and its ``x_F`` is optimal
for the given ``x_S``. The caller decides from its residuals whether to keep it.
"""

import numpy as np
from numba import njit

from fccqp import kkt
from fccqp._lapack import dpotrf, dpotrs

PROXIMAL_STEPS = 3
"""Solves of the full form's restoration: each one shrinks the bias of ``sigma`` by
about ``sigma / (sigma + curvature)``, as in the cold start."""
_LOWER = 76  # ord("L")
_LAPACK_BLOCK = 64
"""Work size per row given to dsytrf (its blocked algorithm's block size)."""


@njit(cache=True)
def _free_entries(n, constrained):
    """Indices of the entries of ``x`` that have neither a finite bound nor a cone."""
    is_free = np.ones(n, dtype=np.bool_)
    for j in range(constrained.shape[0]):
        is_free[constrained[j]] = False
    return np.flatnonzero(is_free)


@njit(cache=True)
def restore(p, w, sigma):
    """Overwrite ``w.x`` and ``w.nu`` with the restored point for the slack ``w.z``.

    ``p`` is the scaled problem and ``w`` the workspace of :mod:`fccqp.admm`.
    Returns False, leaving ``w`` untouched, when the restricted KKT matrix shows
    that ``P`` is not positive semidefinite on the free entries (a bias of
    ``sigma`` aside).
    """
    n, m = p.P.shape[0], p.A.shape[0]
    free = _free_entries(n, p.constrained)
    nf = free.shape[0]
    P_FF = np.empty((nf, nf))
    for a in range(nf):
        for c in range(nf):
            P_FF[a, c] = p.P[free[a], free[c]]
    A_F = np.empty((m, nf))
    for i in range(m):
        for c in range(nf):
            A_F[i, c] = p.A[i, free[c]]
    x_S_fixed = np.zeros(n)
    for j in range(p.constrained.shape[0]):
        x_S_fixed[p.constrained[j]] = w.z[j]
    gradient = p.P @ x_S_fixed + p.q
    size = nf + m
    rhs = np.empty(size)
    rhs[nf:] = p.b - p.A @ x_S_fixed
    K = np.zeros((size, size)).T  # Fortran order, as LAPACK wants
    no_rho = np.zeros(0, dtype=np.int64)
    kkt.assemble(P_FF, A_F, sigma, no_rho, np.zeros(0), K)
    ipiv = np.zeros(size, dtype=np.int32)
    if kkt.factor(K, ipiv, np.empty(size * _LAPACK_BLOCK)) != m:
        return False
    sol = np.empty(size)
    for a in range(nf):
        sol[a] = w.x[free[a]]
    for _ in range(PROXIMAL_STEPS):
        for a in range(nf):
            rhs[a] = sigma * sol[a] - gradient[free[a]]
        kkt.solve_refined(K, ipiv, P_FF, A_F, p.E, sigma, no_rho, np.zeros(0), rhs, sol,
                          np.empty(size))
    w.x[:] = x_S_fixed
    for a in range(nf):
        w.x[free[a]] = sol[a]
    w.nu[:] = sol[nf:]
    return True


@njit(cache=True)
def restore_reduced(p, w):
    """:func:`restore` for the reduced form, from ``w.W``, ``w.W_S`` and ``w.base``.

    Returns False, leaving ``w`` untouched, when ``W_S`` is not positive definite.
    ``A x = b`` then holds up to the rounding of ``base + W u``, which the caller
    removes as for any reduced iterate.
    """
    n, s = p.P.shape[0], p.constrained.shape[0]
    factor = np.asfortranarray(w.W_S)
    u = np.empty(s)
    for j in range(s):
        u[j] = w.z[j] - w.base[p.constrained[j]]
    uplo = np.array([_LOWER], dtype=np.uint8)
    size = np.array([s], dtype=np.int32)
    info = np.zeros(1, dtype=np.int32)
    dpotrf(uplo, size, factor, size, info)
    if info[0] != 0:
        return False
    dpotrs(uplo, size, np.ones(1, dtype=np.int32), factor, size, u, size, info)
    point = w.base + w.W @ u
    w.x[:] = point[:n]
    w.nu[:] = point[n:]
    return True
