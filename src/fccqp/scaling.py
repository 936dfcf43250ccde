"""Ruiz equilibration of the problem data, compiled with numba.

With ``x = D x_s`` and the equality rows multiplied by ``E``, the solver works on

    P_s = c D P D,   q_s = c D q,   A_s = E A D,   b_s = E b,   bounds / D,

where each Ruiz pass divides every column of ``[[P, A'], [A, 0]]`` by the square
root of its infinity norm (as OSQP does) and ``c`` normalizes the cost. ``D`` is
kept constant over each cone block (geometric mean), so a scaled cone is the same
cone: friction cones keep their ``mu`` and normal.

:func:`scale_start` and :func:`unscale_solution` carry iterates across the scaling:
``x = D x_s``, equality multipliers ``y = E nu_s / c`` and constraint multipliers
``z_S = y_s / (c D_S)``.
"""

import math

import numpy as np
from numba import njit

from fccqp.projections import project_constraint_set

MIN_NORM = 1e-4
"""Column norms below this are treated as 1 (a column of zeros is left alone)."""
MAX_NORM = 1e4
"""Column norms are capped here, bounding one pass's scale change to 100x."""


@njit(cache=True)
def _inverse_sqrt_norm(norm):
    if norm < MIN_NORM:
        return 1.0
    return 1.0 / math.sqrt(min(norm, MAX_NORM))


@njit(cache=True)
def _row_max(row, weight):
    """``max_j |row_j| weight_j`` with four running maxima.

    One running maximum is a chain of dependent ``max`` operations that the compiler
    may not reorder; four independent ones run about twice as fast on these rows.
    """
    n = row.shape[0]
    m0 = m1 = m2 = m3 = 0.0
    j = 0
    while j + 4 <= n:
        m0 = max(m0, abs(row[j]) * weight[j])
        m1 = max(m1, abs(row[j + 1]) * weight[j + 1])
        m2 = max(m2, abs(row[j + 2]) * weight[j + 2])
        m3 = max(m3, abs(row[j + 3]) * weight[j + 3])
        j += 4
    while j < n:
        m0 = max(m0, abs(row[j]) * weight[j])
        j += 1
    return max(max(m0, m1), max(m2, m3))


@njit(cache=True)
def equilibrate(P, q, A, b, block_start, block_dim, iterations, D, E):
    """Scale ``P, q, A, b`` in place; fill ``D`` and ``E``; return the cost scale ``c``.

    Each pass reads the norms of the currently scaled matrix off the original entries
    (row ``i`` of ``D P D`` has norm ``D_i max_j |P_ij| D_j``), so the data is touched
    once per pass and rescaled once at the end. ``block_start``/``block_dim`` give the
    cone blocks in ``x``.
    """
    n = P.shape[0]
    m = A.shape[0]
    D[:] = 1.0
    E[:] = 1.0
    d = np.empty(n)
    e = np.empty(m)
    for _ in range(iterations):
        # Column maxima accumulate row by row (independent per column, so the inner
        # loops vectorize); the row maxima of A go through _row_max.
        d[:] = 0.0
        for i in range(n):
            for j in range(n):
                d[j] = max(d[j], abs(P[i, j]) * D[i])
        for j in range(n):
            d[j] *= D[j]
        for i in range(m):
            for j in range(n):
                d[j] = max(d[j], abs(A[i, j]) * D[j] * E[i])
            e[i] = _inverse_sqrt_norm(_row_max(A[i], D) * E[i])
        for j in range(n):
            d[j] = _inverse_sqrt_norm(d[j])
        for k in range(block_start.shape[0]):
            s, t = block_start[k], block_start[k] + block_dim[k]
            log_mean = 0.0
            for j in range(s, t):
                log_mean += math.log(d[j])
            d[s:t] = math.exp(log_mean / (t - s))
        D *= d
        E *= e
    for i in range(n):
        for j in range(n):
            P[i, j] *= D[i] * D[j]
        q[i] *= D[i]
    for i in range(m):
        for j in range(n):
            A[i, j] *= E[i] * D[j]
        b[i] *= E[i]
    mean_col = 0.0
    ones = np.ones(n)
    for i in range(n):
        mean_col += _row_max(P[i], ones)
    mean_col /= n
    q_norm = 0.0
    for i in range(n):
        q_norm = max(q_norm, abs(q[i]))
    size = max(mean_col if mean_col >= MIN_NORM else 1.0, q_norm if q_norm >= MIN_NORM else 1.0)
    c = 1.0 / min(size, MAX_NORM)
    P *= c
    q *= c
    return c


@njit(cache=True)
def scale_start(x, y, z, rho, D, E, c, constrained, lo, hi, cones, x_s, nu_s, y_s, z_s):
    """Warm start from an unscaled solution ``(x, y, z)`` of a previous solve.

    Fills the scaled iterate ``x_s, nu_s`` (x and equality multipliers), ``y_s``
    (constraint multipliers on the constrained entries) and the slack ``z_s = P_C(x_s
    + y_s / rho)``, the point ADMM's z-update would produce from them.
    """
    for i in range(x.shape[0]):
        x_s[i] = x[i] / D[i]
    for i in range(y.shape[0]):
        nu_s[i] = y[i] * c / E[i]
    inverse_rho = 1.0 / max(rho, 1e-12)
    shifted = np.empty(constrained.shape[0])
    for j in range(constrained.shape[0]):
        i = constrained[j]
        y_s[j] = z[i] * c * D[i]
        shifted[j] = x_s[i] + y_s[j] * inverse_rho
    project_constraint_set(shifted, lo, hi, cones, z_s)


@njit(cache=True)
def unscale_solution(x_s, nu_s, y_s, D, E, c, constrained, P, q):
    """``(x, y, z, objective)`` of the unscaled problem ``(P, q)`` from a scaled iterate;
    ``z`` is zero off the constrained entries."""
    x = x_s * D
    y = nu_s * E / c
    z = np.zeros(x.shape[0])
    for j in range(constrained.shape[0]):
        i = constrained[j]
        z[i] = y_s[j] / (c * D[i])
    objective = x @ (0.5 * (P @ x) + q)
    return x, y, z, objective
