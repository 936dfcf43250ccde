"""Ruiz equilibration of the problem data, compiled with numba.

With ``x = D x_s`` and the equality rows multiplied by ``E``, the solver works on

    P_s = c D P D,   q_s = c D q,   A_s = E A D,   b_s = E b,   bounds / D,

where each Ruiz pass divides every column of ``[[P, A'], [A, 0]]`` by the square
root of its infinity norm (as OSQP does) and ``c`` normalizes the cost. ``D`` is
kept constant over each cone block (geometric mean), so a scaled cone is the same
cone: friction cones keep their ``mu`` and normal.
"""

import math

import numpy as np
from numba import njit

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
        # P is symmetric: its column norms are its row norms (contiguous rows).
        for i in range(n):
            norm = 0.0
            for j in range(n):
                norm = max(norm, abs(P[i, j]) * D[j])
            d[i] = norm * D[i]
        for i in range(m):
            norm = 0.0
            for j in range(n):
                a = abs(A[i, j]) * D[j]
                norm = max(norm, a)
                d[j] = max(d[j], a * E[i])
            e[i] = _inverse_sqrt_norm(norm * E[i])
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
    for i in range(n):
        norm = 0.0
        for j in range(n):
            norm = max(norm, abs(P[i, j]))
        mean_col += norm
    mean_col /= n
    q_norm = 0.0
    for i in range(n):
        q_norm = max(q_norm, abs(q[i]))
    size = max(mean_col if mean_col >= MIN_NORM else 1.0, q_norm if q_norm >= MIN_NORM else 1.0)
    c = 1.0 / min(size, MAX_NORM)
    P *= c
    q *= c
    return c
