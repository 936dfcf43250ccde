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

import numpy as np

from fccqp._dense cimport colmatvec, copy, matvec
from fccqp._types cimport Iterates, Problem
from fccqp.kkt cimport KKT, kkt_table
from fccqp.projections cimport proj_cones

cdef extern from "fccqp_kernels.h" nogil:
    void fccqp_step_start(const double* z, const double* y, const double* rho, long s,
                          double* z_prev, double* y_prev, double* v, double* v_prev,
                          double* u, double* u_prev)
    void fccqp_step_relax(const double* base, const Py_ssize_t* constrained,
                          const double* xs, const double* z_prev, const double* v,
                          const double* u_prev, const double* y, const double* rho,
                          const double* lo, const double* hi, double alpha, double alpha_x,
                          long s, double* relaxed, double* u, double* z)
    void fccqp_step_multipliers(const double* rho, const double* relaxed, const double* z,
                                long s, double* y)
    void fccqp_row_gate_sums(const double* row, const double* u, long s, double* out)


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
    """One ADMM iteration with ``x = base + W u`` kept implicit through ``u``: the loops
    around the product are ``fccqp_kernels.h``'s (``fccqp_step_*``), and the box's clip
    is fused into the z-update (:func:`fccqp.projections.proj_cones` projects the cones'
    blocks after it)."""
    cdef Py_ssize_t s = p.s
    cdef double alpha_x = alpha if relax_x else 1.0
    fccqp_step_start(it.z, it.y, it.rho_vec, s, it.z_prev, it.y_prev, r.v, r.v_prev, r.u,
                     r.u_prev)
    _table_product(r, r.v, r.xs, s)
    fccqp_step_relax(r.base, p.constrained, r.xs, it.z_prev, r.v, r.u_prev, it.y,
                     it.rho_vec, p.lo, p.hi, alpha, alpha_x, s, it.relaxed, r.u, it.z)
    proj_cones(it.z, p.cones)
    fccqp_step_multipliers(it.rho_vec, it.relaxed, it.z, s, it.y)


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
    (``fccqp_row_gate_sums``: the row's product and the sum of its terms' magnitudes, in
    four lanes): 1 when one of them surely fails whatever the order of
    :func:`_table_product`'s sums, 0 when both surely pass, -1 undecided."""
    cdef Py_ssize_t s = p.s, i = p.constrained[j]
    cdef double sums[2]
    cdef double x, error, w
    cdef int primal
    fccqp_row_gate_sums(r.W_S + j * s, r.u, s, sums)
    x = r.base[i] + sums[0]
    error = (s + 4) * ROUNDING * (sums[1] + abs(r.base[i]) + abs(x))
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


def step_kernels_py(double[::1] z, double[::1] y, const double[::1] rho, double[::1] v,
                    double[::1] u, const double[::1] base, const Py_ssize_t[::1] constrained,
                    const double[::1] xs, const double[::1] lo, const double[::1] hi,
                    double alpha, double alpha_x):
    """Test hook: :func:`reduced_step`'s kernels on numpy arrays with the product ``xs``
    given (no cones, at least one entry): ``z, y, v, u`` updated in place; returns
    ``(z_prev, y_prev, v_prev, u_prev, relaxed)``."""
    cdef long s = z.shape[0]
    cdef double[::1] z_prev = np.empty(s), y_prev = np.empty(s), v_prev = np.empty(s)
    cdef double[::1] u_prev = np.empty(s), relaxed = np.empty(s)
    fccqp_step_start(&z[0], &y[0], &rho[0], s, &z_prev[0], &y_prev[0], &v[0], &v_prev[0],
                     &u[0], &u_prev[0])
    fccqp_step_relax(&base[0], &constrained[0], &xs[0], &z_prev[0], &v[0], &u_prev[0],
                     &y[0], &rho[0], &lo[0], &hi[0], alpha, alpha_x, s, &relaxed[0], &u[0],
                     &z[0])
    fccqp_step_multipliers(&rho[0], &relaxed[0], &z[0], s, &y[0])
    return (np.asarray(z_prev), np.asarray(y_prev), np.asarray(v_prev), np.asarray(u_prev),
            np.asarray(relaxed))
