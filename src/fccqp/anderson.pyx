# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Safeguarded type-II Anderson acceleration of the ADMM map ``g = (z, y/rho) -> T(g)``.

The step just taken went from ``g = (z_prev, y_prev/rho)`` to ``T(g) = (z, y/rho)``,
with fixed-point residual ``f = T(g) - g``. With the last differences ``dG, dF`` of
``g`` and ``f``, the next point is ``T(g) - (dG + dF) gamma``, ``gamma`` minimizing
``||f - dF gamma||`` (a ridge-regularized normal equation). Safeguard: when the step
from an accelerated point has a larger residual than the step before it, the plain
``T`` of the previous point is restored and the memory cleared, and plain ADMM runs
``capacity`` steps before the next try (for the rest of the run after
``MAX_REJECTIONS`` rejections). Weights ``gamma`` of norm ``MAX_WEIGHT_NORM`` or more
are not used, and the memory is cleared, as SCS does (its cap is 1e10): on an
infeasible problem ADMM's map becomes a translation, ``T(g) = g + v``, the residual
stops changing, ``gamma ~ ||f|| / ||dF||`` grows without bound and the safeguard
(which only asks that the residual not grow) lets each step multiply the iterate
(a random problem: ``|y|`` from 4e5 to 1.5e15 in four steps, then rho at its ceiling,
``A x = b`` lost to rounding and no certificate in 4000 iterations).
"""

import numpy as np

from libc.math cimport sqrt

from fccqp._types cimport Iterates
from fccqp.tuning cimport MAX_REJECTIONS, MAX_WEIGHT_NORM, REGULARIZATION

cdef extern from "fccqp_kernels.h" nogil:
    int fccqp_spd_solve(const double* A, int lda, double shift, double* M, double* b, int k)
    void fccqp_slot_products(const double* df, long two_s, int stored, const double* newest,
                             const double* f, double* to_new, double* to_f)
    void fccqp_slot_combination(const double* rows, long two_s, int stored,
                                const double* coefficient, double* out)
    double fccqp_sum_squares(const double* v, long k)
    void fccqp_fixed_point_residual(const double* z_prev, const double* y_prev,
                                    const double* z, const double* y, const double* rho,
                                    long s, double* g, double* f)
    void fccqp_point_differences(const double* g_new, const double* f_new, const double* g,
                                 const double* f, long two_s, double* df, double* dgf)
    void fccqp_extrapolate(double* z, double* y, const double* rho, const double* step,
                           long s, double* plain)


cdef void anderson_reset(Anderson* a, bint keep_rejections) noexcept nogil:
    """Forget the memory (after a change of rho, or at the start of a run)."""
    a.stored = 0
    a.have_previous = False
    a.accelerated = False
    if not keep_rejections:
        a.wait = 0
        a.rejections = 0


cdef bint solve_small_spd(double* M, double* b, int k) noexcept nogil:
    """Solve ``M x = b`` in place (``b`` becomes ``x``, ``M`` row-major its Cholesky
    factor) for the tiny positive definite Gram matrix; False if a pivot is not
    positive. ``fccqp_spd_solve`` (fccqp_kernels.h): loops unrolled for each ``k`` up to
    10, which beat LAPACK's call overhead (0.5 us against 1.2 us for ``dpotrf`` +
    ``dpotrs`` at size 10, measured through numba) and the rolled loops' mispredicted
    exits. :func:`anderson_step` calls the same kernel on the products in place, every
    iteration.
    """
    return fccqp_spd_solve(M, k, 0.0, M, b, k)


cdef inline void _new_products(Anderson* a, const double* f, Py_ssize_t slot, int stored,
                               Py_ssize_t two_s) noexcept nogil:
    """The new slot's row of ``products`` (``df_slot' df_l``) and ``gamma = dF' f`` in one
    pass over the stored slots (``fccqp_slot_products``: each sum in four lanes, two slots
    at a time); ``gram`` holds the row until it is copied into place (``gram`` is scratch
    until :func:`anderson_step` fills it)."""
    cdef Py_ssize_t l, cap = a.capacity
    fccqp_slot_products(a.df, two_s, stored, a.df + slot * two_s, f, a.gram, a.gamma)
    for l in range(stored):
        a.products[slot * cap + l] = a.gram[l]
        a.products[l * cap + slot] = a.gram[l]


cdef inline double _residual(Anderson* a, const Iterates* it, Py_ssize_t s) noexcept nogil:
    """``g_new = (z_prev, y_prev / rho)`` and its residual ``f_new = (z, y / rho) - g_new``;
    returns ``|f_new|``."""
    fccqp_fixed_point_residual(it.z_prev, it.y_prev, it.z, it.y, it.rho_vec, s, a.g_new,
                               a.f_new)
    return sqrt(fccqp_sum_squares(a.f_new, 2 * s))


cdef inline void _record(Anderson* a, Py_ssize_t two_s) noexcept nogil:
    """Store the differences from the previous point to the new one (``g``, ``f`` to
    ``g_new``, ``f_new``) in the next slot, and the new slot's products."""
    cdef Py_ssize_t slot = a.stored % a.capacity
    fccqp_point_differences(a.g_new, a.f_new, a.g, a.f, two_s, a.df + slot * two_s,
                            a.dgf + slot * two_s)
    a.stored += 1
    # only the new slot's products change: O(capacity s) instead of O(capacity^2 s)
    _new_products(a, a.f_new, slot, <int>min(a.stored, <long>a.capacity), two_s)


cdef inline void _keep_new_point(Anderson* a) noexcept nogil:
    """The new point becomes the previous one (``g``, ``f``), and the previous one's
    arrays the scratch ``g_new``, ``f_new``: pointers exchanged, nothing copied."""
    a.g, a.g_new = a.g_new, a.g
    a.f, a.f_new = a.f_new, a.f


cdef void anderson_step(Anderson* a, Iterates* it, Py_ssize_t s) noexcept nogil:
    """Record the step just taken and extrapolate ``(z, y)`` in ``it`` when possible."""
    cdef Py_ssize_t j, i, two_s = 2 * s
    cdef int stored, cap = a.capacity
    cdef double f_norm, ridge, acc
    if a.wait > 0:   # plain steps only (a rejection cleared ``accelerated``)
        a.wait -= 1
        return
    f_norm = _residual(a, it, s)
    if a.accelerated and f_norm > a.plain[two_s]:
        for j in range(s):
            it.z[j] = a.plain[j]
            it.y[j] = a.plain[s + j] * it.rho_vec[j]
        a.rejections += 1
        anderson_reset(a, True)
        # let plain ADMM run before trying again; after a few failures, for good
        a.wait = cap if a.rejections < MAX_REJECTIONS else (<long>1) << 62
        return
    if a.have_previous:
        _record(a, two_s)
    _keep_new_point(a)
    a.plain[two_s] = f_norm
    a.have_previous = True
    stored = <int>min(a.stored, <long>cap)
    a.accelerated = False
    if stored == 0:
        return
    ridge = 0.0
    for i in range(stored):
        ridge = max(ridge, a.products[i * cap + i])
    # the Gram matrix plus the ridge, factored where its products are kept
    if not fccqp_spd_solve(a.products, cap, REGULARIZATION * ridge + 1e-300, a.gram, a.gamma,
                           stored):
        return
    acc = 0.0
    for i in range(stored):
        acc += a.gamma[i] * a.gamma[i]
    if not acc < MAX_WEIGHT_NORM * MAX_WEIGHT_NORM:
        anderson_reset(a, True)   # nothing to extrapolate from: plain steps rebuild it
        return
    # the step (dG + dF) gamma into the scratch g_new (fccqp_slot_combination: each
    # entry's terms in slot order, four slots per pass)
    fccqp_slot_combination(a.dgf, two_s, stored, a.gamma, a.g_new)
    fccqp_extrapolate(it.z, it.y, it.rho_vec, a.g_new, s, a.plain)
    a.accelerated = True


def solve_small_spd_py(double[:, ::1] M, double[::1] b):
    """:func:`solve_small_spd` on numpy arrays (``M`` is overwritten by its factor)."""
    if M.shape[0] != M.shape[1] or M.shape[0] != b.shape[0] or b.shape[0] == 0:
        raise ValueError("M must be square and match b")
    return solve_small_spd(&M[0, 0], &b[0], <int>b.shape[0])
