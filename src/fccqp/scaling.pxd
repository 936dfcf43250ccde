# cython: language_level=3
"""Ruiz equilibration (:mod:`fccqp.scaling`, dense storage; :mod:`fccqp.scaling_csc`,
compressed columns) and the two rules both storages share, inline here."""

from libc.math cimport exp, fabs, ilogb, ldexp, log, sqrt

from fccqp._types cimport Cones
from fccqp.tuning cimport GAUGE_LIMIT, MAX_NORM, MIN_COST_NORM, MIN_NORM, RESCALE_DRIFT


cdef struct Pattern:
    # The nonzeros of the dense P and A, row by row (compressed rows), found once per
    # equilibration: the Ruiz passes and the scaling walk them instead of every entry.
    int* P_start    # n + 1: row i of P has its columns at P_index[P_start[i]:P_start[i + 1]]
    int* P_index    # n * n
    int* A_start    # m + 1
    int* A_index    # m * n


cdef inline double inverse_sqrt_norm(double norm) noexcept nogil:
    """A Ruiz pass's factor for a column or row of infinity norm ``norm``: ``1 /
    sqrt(norm)``, with the norm capped at ``MAX_NORM`` and 1 below ``MIN_NORM``."""
    if norm < MIN_NORM:
        return 1.0
    return 1.0 / sqrt(norm if norm < MAX_NORM else MAX_NORM)


cdef inline bint start_tiny_columns(double* D, const double* d, const double* q,
                                    Py_ssize_t n, const Py_ssize_t* block_start,
                                    const Py_ssize_t* block_dim,
                                    Py_ssize_t blocks) noexcept nogil:
    """Start every column whose norm ``d_j`` (the first pass's, ``D = 1``) lies below
    ``MIN_NORM``, which the passes leave alone, at ``D_j = 1 / sqrt(d_j)`` (a power of
    two, exact); whether there was one (``D`` otherwise untouched).

    A variable in units of 1e-8 (its columns of ``P`` and ``A`` 1e-14 and 3.5e-9) was
    otherwise never scaled: its scaled curvature (2.5e-18) was too flat for ADMM to
    move it, and for the polish's regularization to see. The square root keeps ``P``'s
    entries, which ``D`` scales twice, below 1 (``|P_ij| <= d_j``, and for ``P``
    positive semidefinite ``|P_ij| <= sqrt(d_i d_j)``), and the passes go on from there.
    ``D_j |q_j|`` is held to the largest ``|q_i|``: a column that is tiny because the
    cost is (``P`` of 1e-300) must not become the largest linear cost. A cone block
    takes its columns' smallest factor (one that is 1 where a column is not tiny), so
    a scaled cone is the same cone."""
    cdef Py_ssize_t j, k, a, t
    cdef double q_max = 0.0, factor, smallest
    for j in range(n):
        if 0.0 < d[j] < MIN_NORM:
            break
    else:
        return False
    for j in range(n):
        q_max = max(q_max, fabs(q[j]))
    for j in range(n):
        if not 0.0 < d[j] < MIN_NORM:
            continue
        factor = ldexp(1.0, -ilogb(sqrt(d[j])))
        if q[j] != 0.0:
            factor = min(factor, max(1.0, ldexp(1.0, ilogb(q_max / fabs(q[j])))))
        D[j] = factor
    for k in range(blocks):
        a, t = block_start[k], block_start[k] + block_dim[k]
        smallest = D[a]
        for j in range(a, t):
            smallest = min(smallest, D[j])
        for j in range(a, t):
            D[j] = smallest
    return True


cdef inline bint ruiz_factors(double* D, double* E, double* d, double* e, Py_ssize_t n,
                              Py_ssize_t m, const Py_ssize_t* block_start,
                              const Py_ssize_t* block_dim, Py_ssize_t blocks) noexcept nogil:
    """The end of a Ruiz pass, from the scaled columns' norms ``d`` and rows' norms
    ``e``: each becomes its factor (:func:`inverse_sqrt_norm`), a cone block's columns
    share the geometric mean of theirs (a cone stays a cone), and ``D``, ``E`` take
    them. Returns whether a norm was capped at ``MAX_NORM``."""
    cdef Py_ssize_t i, j, k, a, t
    cdef double log_mean, value
    cdef bint capped = False
    for i in range(m):
        capped = capped or e[i] > MAX_NORM
        e[i] = inverse_sqrt_norm(e[i])
    for j in range(n):
        capped = capped or d[j] > MAX_NORM
        d[j] = inverse_sqrt_norm(d[j])
    for k in range(blocks):
        a, t = block_start[k], block_start[k] + block_dim[k]
        log_mean = 0.0
        for j in range(a, t):
            log_mean += log(d[j])
        value = exp(log_mean / (t - a))
        for j in range(a, t):
            d[j] = value
    for j in range(n):
        D[j] *= d[j]
    for i in range(m):
        E[i] *= e[i]
    return capped


cdef inline bint gauge_shift(const double* D, Py_ssize_t n, double* shift) noexcept nogil:
    """Whether the gauge applies (see :func:`gauge_apply`): ``D``'s geometric mean is
    below ``1 / GAUGE_LIMIT``; ``shift`` receives minus its logarithm."""
    cdef Py_ssize_t j
    cdef double log_mean = 0.0
    for j in range(n):
        log_mean += log(D[j])
    log_mean /= n
    shift[0] = -log_mean
    return log_mean < -log(GAUGE_LIMIT)


cdef inline void gauge_apply(double* D, double* E, Py_ssize_t n, Py_ssize_t m, double shift,
                             double largest) noexcept nogil:
    """Ruiz leaves ``(D t, E / t)`` free: ``E A D`` is the same for every ``t``. Rows of
    ``A`` 1e15 times the rest split that size between ``E`` and ``D`` (about 1e-7.5
    each): the scaled variables were then 1e7 and the cost 1e-7 (``D q``, ``D P D`` of
    1e-15), and OSQP's rule drove rho to ``RHO_MIN`` and the run stalled (six feasible
    fuzz problems). Where :func:`gauge_shift` says so, ``t`` (a power of two, exact)
    moves ``D`` toward 1 by ``shift`` as far as ``D P D``, whose largest entry is
    ``largest``, stays at most 1."""
    cdef Py_ssize_t i, j
    cdef int exponent
    if largest > 0.0:
        shift = min(shift, -0.5 * log(largest))
    exponent = <int>(shift / log(2.0))
    if exponent <= 0:
        return
    for j in range(n):
        D[j] = ldexp(D[j], exponent)
    for i in range(m):
        E[i] = ldexp(E[i], -exponent)


cdef inline bint within_drift(const double* norms, const double* reference,
                              Py_ssize_t count) noexcept nogil:
    """Whether every norm of a rescaled problem is within ``RESCALE_DRIFT`` of the
    equilibrated one's (``reference``), either way: :func:`rescale`'s verdict."""
    cdef Py_ssize_t i
    for i in range(count):
        if not (norms[i] <= RESCALE_DRIFT * reference[i]
                and reference[i] <= RESCALE_DRIFT * norms[i]):
            return False
    return True


cdef inline double cost_scale(double mean_col, double q_norm) noexcept nogil:
    """``c = 1 / size`` of a cost whose ``P`` has mean column norm ``mean_col`` and whose
    ``q`` has norm ``q_norm``: the larger of the two, each counted only above
    ``MIN_COST_NORM``, at most ``MAX_NORM``."""
    cdef double size = max(mean_col if mean_col >= MIN_COST_NORM else 1.0,
                           q_norm if q_norm >= MIN_COST_NORM else 1.0)
    return 1.0 / min(size, MAX_NORM)


cdef double equilibrate(double* P, double* q, double* A, double* b, Py_ssize_t n,
                        Py_ssize_t m, const Py_ssize_t* block_start,
                        const Py_ssize_t* block_dim, Py_ssize_t blocks, Py_ssize_t iterations,
                        double* D, double* E, double* d, double* e,
                        Pattern* pattern) noexcept nogil
cdef void scaled_norms(const double* P_s, const double* A_s, Py_ssize_t n, Py_ssize_t m,
                       double c, const Pattern* pattern, double* norms) noexcept nogil
cdef bint rescale(const double* P, const double* q, const double* A, const double* b,
                  Py_ssize_t n, Py_ssize_t m, Py_ssize_t diagonal_from, const double* D,
                  const double* E, const double* reference, double* norms, double* P_s,
                  double* q_s, double* A_s, double* b_s, double* c) noexcept nogil
cdef void scale_start(const double* x, const double* y, const double* z, double rho,
                      const double* D, const double* E, double c, Py_ssize_t n, Py_ssize_t m,
                      Py_ssize_t s, const Py_ssize_t* constrained, const double* lo,
                      const double* hi, Cones cones, double* x_s, double* nu_s, double* y_s,
                      double* z_s) noexcept nogil
cdef void unscale(const double* x_s, const double* nu_s, const double* y_s, const double* D,
                  const double* E, double c, Py_ssize_t n, Py_ssize_t m, Py_ssize_t s,
                  const Py_ssize_t* constrained, double* x, double* y,
                  double* z) noexcept nogil
