# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The reduced iteration: an ADMM step in ``O(s^2)`` instead of a KKT solve.

When ``P + R`` is positive definite (no ``sigma`` needed), the x-update is ``(x~, nu)
= base + W v`` with ``v = rho z - y`` and ``W`` the ``(n + m) x s`` block of the KKT
inverse on the constrained entries, so an iteration needs only ``x~_S = base_S + W_S
v``, an ``s x s`` product; ``x`` and ``nu`` are formed (:func:`materialize`) only when
residuals are checked. Works on top of either backend of :mod:`fccqp.kkt`.

Coordinates: ``x = base + W u`` means that ``x`` solves the x-update's KKT system for
the right-hand side ``(-q + E_S u, b)``. After a change of ``R`` the same ``x`` has the
coordinate ``u + (R' - R) x_S`` in the new table (:func:`reduced_rebase`).
"""

from fccqp._dense cimport colmatvec, copy, matvec
from fccqp._types cimport Iterates, Problem
from fccqp.kkt cimport KKT, kkt_table
from fccqp.projections cimport proj_set


cdef bint reduced_table(Reduced* r, KKT* k, const Problem* p, const double* rho_vec) noexcept nogil:
    """Tabulate ``W`` and ``W_S`` with the factorization in ``k``; False when the columns
    missed the refinement tolerance. ``base``, which follows ``q`` and ``b``, is the
    caller's (:func:`fccqp.factorization.reduced_base`, after every factorization)."""
    return kkt_table(k, p, rho_vec, r.W, r.W_S)


cdef void reduced_start(Reduced* r, const Problem* p, Iterates* it) noexcept nogil:
    """Coordinates of the start: ``u = v = rho z - y`` (the first step is not relaxed)."""
    cdef Py_ssize_t j
    r.hint = 0
    for j in range(p.s):
        r.v[j] = it.rho_vec[j] * it.z[j] - it.y[j]
        r.u[j] = r.v[j]
        r.v_prev[j] = r.v[j]
        r.u_prev[j] = r.u[j]


cdef inline void _table_product(const Reduced* r, const double* c, double* out,
                                Py_ssize_t s) noexcept nogil:
    """``out = W_S c`` (row-major ``s x s``)."""
    matvec(r.W_S, c, out, s, s)


cdef void reduced_step(Reduced* r, const Problem* p, Iterates* it, double alpha,
                       bint relax_x) noexcept nogil:
    """One ADMM iteration with ``x = base + W u`` kept implicit through ``u``."""
    cdef Py_ssize_t s = p.s, j
    cdef double alpha_x = alpha if relax_x else 1.0
    for j in range(s):
        it.z_prev[j] = it.z[j]
        it.y_prev[j] = it.y[j]
        r.v_prev[j] = r.v[j]
        r.u_prev[j] = r.u[j]
        r.v[j] = it.rho_vec[j] * it.z[j] - it.y[j]
    _table_product(r, r.v, r.xs, s)
    for j in range(s):
        it.relaxed[j] = alpha * (r.base[p.constrained[j]] + r.xs[j]) + (1.0 - alpha) * it.z_prev[j]
        r.u[j] = alpha_x * r.v[j] + (1.0 - alpha_x) * r.u_prev[j]
        it.z[j] = it.relaxed[j] + it.y[j] / it.rho_vec[j]
    proj_set(it.z, p.lo, p.hi, p.cones, s, it.z)
    for j in range(s):
        it.y[j] += it.rho_vec[j] * (it.relaxed[j] - it.z[j])


cdef double ROUNDING = 4.5e-16
"""Four times the unit roundoff: twice the bound ``s u |W||u|`` by which two summation
orders of one row product can differ, so that a decision made on one order's value
stands for the other's (a rounding bound, not a tuning constant)."""
cdef double SLACK = 1e-12
"""Relative room for the few roundings of the gate's comparisons themselves."""


cdef inline int _surely(double value, double error, double tolerance) noexcept nogil:
    """Whether ``|t| > tolerance`` for every ``t`` within ``error`` of ``value``: 1 for
    all of them, 0 for none, -1 undecided (NaN included)."""
    value = abs(value)
    if (value - error) * (1.0 - SLACK) > tolerance:
        return 1
    if (value + error) * (1.0 + SLACK) <= tolerance:
        return 0
    return -1


cdef inline int _row_gate(Reduced* r, const Problem* p, Iterates* it, Py_ssize_t j,
                          double eps_p, double eps_d) noexcept nogil:
    """The gate's two tests on constrained entry ``j`` alone, from one row of ``W_S``
    summed in this loop's order: 1 when one of them surely fails whatever the order
    of :func:`_table_product`'s sums, 0 when both surely pass, -1 undecided."""
    cdef Py_ssize_t s = p.s, i = p.constrained[j], l
    cdef const double* row = r.W_S + j * s
    cdef double d0 = 0.0, d1 = 0.0, a0 = 0.0, a1 = 0.0, x, error, w
    cdef int primal
    for l in range(0, s - 1, 2):   # two sums each: the compiler pairs them in vectors
        d0 += row[l] * r.u[l]
        d1 += row[l + 1] * r.u[l + 1]
        a0 += abs(row[l] * r.u[l])
        a1 += abs(row[l + 1] * r.u[l + 1])
    if s % 2:
        d0 += row[s - 1] * r.u[s - 1]
        a0 += abs(row[s - 1] * r.u[s - 1])
    x = r.base[i] + (d0 + d1)
    error = (s + 4) * ROUNDING * ((a0 + a1) + abs(r.base[i]) + abs(x))
    primal = _surely((x - it.z[j]) * p.D[i], error * p.D[i], eps_p)
    if primal != 0:
        return primal
    w = r.u[j] - it.rho_vec[j] * x + it.y[j]
    error = it.rho_vec[j] * error + ROUNDING * (abs(r.u[j]) + abs(it.rho_vec[j] * x)
                                                + abs(it.y[j]))
    return _surely(w, error, eps_d * p.c * p.D[i])


cdef bint near_convergence(Reduced* r, const Problem* p, Iterates* it, double eps_p,
                           double eps_d) noexcept nogil:
    """Cheap gate before a residual check, in ``O(s^2)``.

    ``(x, nu) = base + W u`` satisfies ``P x + q + A'nu = E_S (u - R x_S)`` (the KKT
    identity of ``base`` and ``W``), so with that ``nu`` the dual residual is ``u - R x_S
    + y`` on the constrained entries and zero elsewhere; the primal residual is ``x_S -
    z`` (``A x = b`` holds by construction). The iterate's ``nu`` comes from ``v``, not
    ``u``, and ``eps_p``, ``eps_d`` are from the last full check, so this only decides
    whether the full check is worth running.

    The gate mostly fails, and mostly at the entry where it failed the iteration before
    (``hint``): that entry is tested first from its row of ``W_S`` alone
    (:func:`_row_gate`, in ``O(s)``), and where it surely fails the gate ends there;
    otherwise ``x_S`` is formed by one product as before. Either way the decision is
    that product's. (Testing every row in turn until one fails cost talos' cold ticks
    more than the product: there the gate often fails late or passes.)
    """
    cdef Py_ssize_t j, i
    cdef double x
    if r.hint < p.s and _row_gate(r, p, it, r.hint, eps_p, eps_d) == 1:
        return False
    _table_product(r, r.u, r.xs, p.s)
    for j in range(p.s):
        i = p.constrained[j]
        x = r.base[i] + r.xs[j]
        if (abs(x - it.z[j]) * p.D[i] > eps_p
                or abs(r.u[j] - it.rho_vec[j] * x + it.y[j]) > eps_d * p.c * p.D[i]):
            r.hint = j
            return False
    return True


cdef inline void _combine(const Reduced* r, const double* c, double* out, Py_ssize_t first,
                          Py_ssize_t count, Py_ssize_t N, Py_ssize_t s) noexcept nogil:
    """``out = (base + W c)[first:first + count]``."""
    copy(r.base + first, out, count)
    colmatvec(r.W + first, <int>N, c, out, count, s, 1.0)


cdef void materialize(Reduced* r, const Problem* p, Iterates* it) noexcept nogil:
    """Form ``x, nu`` from ``base + W (u, v)``; their previous values are due
    (:func:`materialize_x_prev`, :func:`materialize_nu_prev`)."""
    cdef Py_ssize_t n = p.n, m = p.m, N = n + m, s = p.s
    _combine(r, r.u, it.x, 0, n, N, s)
    _combine(r, r.v, it.nu, n, m, N, s)
    r.x_prev_due = r.nu_prev_due = True


cdef void materialize_x_prev(Reduced* r, const Problem* p, Iterates* it) noexcept nogil:
    """Form ``x_prev`` from ``base + W u_prev`` where the last :func:`materialize` left it
    due: only the dual certificate's test reads it, and a check that passes or
    certifies first never does."""
    if r.x_prev_due:
        _combine(r, r.u_prev, it.x_prev, 0, p.n, p.n + p.m, p.s)
        r.x_prev_due = False


cdef void materialize_nu_prev(Reduced* r, const Problem* p, Iterates* it) noexcept nogil:
    """Form ``nu_prev`` from ``base + W v_prev`` where the last :func:`materialize` left
    it due: only the primal certificate's test reads it, and it does not run at every
    check (:func:`fccqp.verdict._may_separate`)."""
    if r.nu_prev_due:
        _combine(r, r.v_prev, it.nu_prev, p.n, p.m, p.n + p.m, p.s)
        r.nu_prev_due = False


cdef inline void _shift(Reduced* r, const Problem* p, double* c, const double* old_rho,
                        const double* new_rho) noexcept nogil:
    """``c += (R' - R) x_S(c)`` with ``x_S(c) = base_S + W_S c`` in the old table."""
    cdef Py_ssize_t j
    _table_product(r, c, r.xs, p.s)
    for j in range(p.s):
        c[j] += (new_rho[j] - old_rho[j]) * (r.base[p.constrained[j]] + r.xs[j])


cdef void reduced_rebase(Reduced* r, const Problem* p, const double* old_rho,
                         const double* new_rho) noexcept nogil:
    """Carry ``u, u_prev, v, v_prev`` into the coordinates of the table for ``new_rho``,
    so that the iterates they stand for (and the steps between them, which the
    infeasibility tests read) are unchanged. Call before refactoring."""
    _shift(r, p, r.u, old_rho, new_rho)
    _shift(r, p, r.u_prev, old_rho, new_rho)
    _shift(r, p, r.v, old_rho, new_rho)
    _shift(r, p, r.v_prev, old_rho, new_rho)
