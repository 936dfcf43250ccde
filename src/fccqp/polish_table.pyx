# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Solve the polished QP of one active set in the reduced form's coordinates.

The reduced iteration keeps a table of the x-update's KKT inverse on the constrained
entries (:mod:`fccqp.reduced`): ``(x, nu) = base + W u`` solves

    [ P + R   A' ] [x ]   [-q + E_S u]
    [ A       0  ] [nu] = [ b        ]

so every such point satisfies ``A x = b`` and stationarity ``P x + q + A'nu + E_S y =
0`` with ``y = R x_S - u``. The polished QP (:mod:`fccqp.polish`) only adds conditions
on the constrained entries, one per entry plus one per boundary cone block:

- a held entry sits at its value: ``x_j = h_j``;
- a free entry has no multiplier: ``y_j = 0``;
- a boundary block ``J`` has ``y_J = lam g + H x_J`` (its plane's normal ``g``, the
  curvature ``H`` of the Newton step) and lies on the plane: ``g'x_J = 0``.

In the coordinates ``(u, lam)`` that is a square system of ``s + nb`` equations, built
from the ``s x s`` table ``W_S`` in ``O(s^2)`` and factored with LU in ``O(s^3)``
(a vectorized loop up to ``LU_LOOP_ROWS``, LAPACK's ``dgetrf`` above): no new
factorization of the ``(n + m)``-sized KKT matrix, which is what the polishing of
:mod:`fccqp.polish` pays for every active set and every Newton step
(on go2, 84 rows and ``s = 24``: a warm polish cost 220 us there, mostly ``dsytrf``).
The system is solved as corrections of the current point against the residual of the
polished QP's full, unregularized KKT conditions (each correction one KKT solve with
the factorization ADMM already has, unrefined with the Schur backend since this loop
refines, one combination with ``W`` and one solve with the LU factor), so the table's
rounding errors are refined away.

The system is singular exactly when the polished QP's solution or its multipliers are
not unique (a cost flat on the free entries, active constraints that depend on each
other); then :func:`table_factor_solve` reports a breakdown and the caller polishes
with the regularized KKT matrix instead.
"""

from libc.math cimport INFINITY, fabs

import numpy as np

from scipy.linalg.cython_lapack cimport dgetrf

from fccqp._dense cimport colmatvec, fill, inf_norm
from fccqp._types cimport Problem
from fccqp.kkt cimport KKT, kkt_solve_once
from fccqp.polish cimport APEX, FIXED, LOWER, UPPER, Polish
from fccqp.polish_kkt cimport point_products
from fccqp.reduced cimport Reduced
from fccqp.tuning cimport LU_LOOP_ROWS, MAX_REFINE, MINOR_PART, PIVOT_RATIO, POLISH_REFINE_TOLERANCE

# LU with partial pivoting in place, LAPACK's pivots, and the solve with its factor: the
# loop LU_LOOP_ROWS speaks of and dgetrs' replacement, in C so that they can be built
# for AVX2 beside the baseline (see fccqp_kernels.h)
cdef extern from "fccqp_kernels.h" nogil:
    int fccqp_lu(double* T, int n, int* piv)
    void fccqp_lu_solve(const double* T, int n, const int* piv, double* b)


cdef inline double _held_value(const Problem* p, Py_ssize_t j, char code) noexcept nogil:
    if code == UPPER:
        return p.hi[j]
    if code == APEX:
        return 0.0
    return p.lo[j]   # LOWER and FIXED


cdef inline bint _held(char code) noexcept nogil:
    return code == LOWER or code == UPPER or code == FIXED or code == APEX


cdef void _assemble(Polish* w, const Problem* p, const Reduced* t, const double* rho,
                    Py_ssize_t nb) noexcept nogil:
    """The system's matrix ``T`` (column-major, ``s + nb`` square) in the unknowns
    ``(du, dlam)``; ``dx_S = d0_S + W_S du`` and ``dy = R dx_S - du``. Only the entries
    that the loops below do not set are zeroed first (zeroing all of ``T`` took 4.9k
    instructions a call in ``memset`` on go2's 24-28 rows, callgrind)."""
    cdef Py_ssize_t s = p.s, S2 = s + nb, j, l, k, o, d, a, b, cone
    cdef double* T = w.T
    cdef const double* WS = t.W_S
    cdef const double* H
    cdef const double* row
    cdef double* acc = w.tr   # scratch: _residual sets tr before a correction reads it
    cdef double h
    cdef char code
    for l in range(s):   # the planes' rows, which accumulate from 0
        for j in range(s, S2):
            T[j + l * S2] = 0.0
    for j in range(s * S2, S2 * S2):   # the planes' columns
        T[j] = 0.0
    for j in range(s):
        code = w.active[j]
        if _held(code):
            for l in range(s):
                T[j + l * S2] = WS[j * s + l]
            continue
        for l in range(s):
            T[j + l * S2] = rho[j] * WS[j * s + l]
        T[j + j * S2] -= 1.0
    for k in range(nb):
        cone = w.boundary[k]
        o, d = p.cones.offset[cone], p.cones.dim[cone]
        H = w.hess + o * s
        for a in range(d):   # row a of H W_S summed along W_S's rows, which vectorizes: go2's
            j = o + a        # table_factor 7.5k -> 6.2k instructions a call without the LU (callgrind)
            for l in range(s):
                acc[l] = 0.0
            for b in range(d):
                h = H[a * d + b]
                row = WS + (o + b) * s
                for l in range(s):
                    acc[l] += h * row[l]
            h = w.g[j]
            row = WS + j * s
            for l in range(s):
                T[j + l * S2] -= acc[l]
                T[s + k + l * S2] += h * row[l]
            T[j + (s + k) * S2] = -h


cdef double _residual(Polish* w, const Problem* p, Py_ssize_t nb) noexcept nogil:
    """Residual of ``(x, nu, y, lam)`` in the polished QP's conditions: the KKT part
    ``(-(P x + q + A'nu + E_S y), b - A x)`` into ``full``, the constraints' part into
    ``tr``; returns the infinity norm of both. The products with ``P`` and ``A`` (most
    of its instructions) are taken from ``grad`` and ``Ax`` where ``grad_current`` says
    the point has not moved since they were formed: a Newton step, a chord step or a
    guess that only releases a constraint or places a plane starts from the point the
    last solve left."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, i, j, k, o, d, a, b, start, cone
    cdef double value, curved
    cdef const double* H
    cdef char code
    if not w.grad_current:
        point_products(w, p)   # summed as polish_kkt's residual sums them
    for i in range(n):
        w.full[i] = -w.grad[i]
    for j in range(s):
        w.full[p.constrained[j]] -= w.y[j]
    for i in range(m):
        w.full[n + i] = p.b[i] - w.Ax[i]
    for j in range(s):
        code = w.active[j]
        if _held(code):
            w.tr[j] = _held_value(p, j, code) - w.x[p.constrained[j]]
        else:
            w.tr[j] = -w.y[j]
    for k in range(nb):
        cone = w.boundary[k]
        o, d = p.cones.offset[cone], p.cones.dim[cone]
        start = p.constrained[o]
        H = w.hess + o * s
        value = 0.0
        for a in range(d):
            curved = 0.0
            for b in range(d):
                curved += H[a * d + b] * w.x[start + b]
            w.tr[o + a] += w.lam[k] * w.g[o + a] + curved
            value += w.g[o + a] * w.x[start + a]
        w.tr[s + k] = -value
    w.kkt_norm = inf_norm(w.full, n + m)
    return max(w.kkt_norm, inf_norm(w.tr, s + nb))


cdef double _off_table_norm(Polish* w, const Problem* p) noexcept nogil:
    """The infinity norm of ``full`` outside the constrained entries' rows (``full``
    unchanged: their entries are set aside, zeroed for the norm and put back)."""
    cdef Py_ssize_t j, s = p.s
    cdef double norm
    for j in range(s):   # du is free until the correction's solve writes it
        w.du[j] = w.full[p.constrained[j]]
        w.full[p.constrained[j]] = 0.0
    norm = inf_norm(w.full, p.n + p.m)
    for j in range(s):
        w.full[p.constrained[j]] = w.du[j]
    return norm


cdef void _kkt_part(Polish* w, const Problem* p, const Reduced* t, KKT* kkt,
                    const double* rho, Py_ssize_t nb, double tiny) noexcept nogil:
    """``dfull := K_R^-1 full``, the correction of the residual's KKT part. Below
    ``tiny`` or ``MINOR_PART`` times the constraints' part it counts as 0, which saves
    the KKT solve. Where only its rows of the constrained entries ``S`` are more than
    that (``MINOR_PART`` of the KKT part: a point a solve left, whose multipliers
    ``y`` or planes were set anew, or a step between two such points), ``K_R^-1 E_S
    v = W v`` with the table's columns: one combination of them for the KKT solve
    (go2: 1.7k against 13.7k instructions; 65 of the 177 KKT solves of 100 cold ticks,
    solo12 118 of 234, anymal_c 100 of 231). One that an earlier KKT solve left is
    corrected: the Schur backend's unrefined solve leaves a relative error, not a
    rounding floor. Skipping KKT parts within 2x of that (tried until c6c2454) left
    talos' ``A x = b`` at 4.7e-10 in one polished tick against 2.7e-12 for a direct KKT
    solve; correcting them, at most 1.1e-11, and the 400 ticks took 3 % fewer
    instructions (go2 +0.1 %, solo12 +0.4 %, ``Settings.realtime(1.0)``, callgrind)."""
    cdef Py_ssize_t N = p.n + p.m
    if w.kkt_norm <= max(tiny, MINOR_PART * inf_norm(w.tr, p.s + nb)):
        fill(w.dfull, 0.0, N)
    elif _off_table_norm(w, p) <= max(tiny, MINOR_PART * w.kkt_norm):
        colmatvec(t.W, <int>N, w.du, w.dfull, N, p.s, 0.0)   # v = full_S, left in du
    else:
        kkt_solve_once(kkt, p, rho, w.full, w.dfull)


cdef void _correct(Polish* w, const Problem* p, const Reduced* t, KKT* kkt,
                   const double* rho, Py_ssize_t nb, double sign, double tiny) noexcept nogil:
    """Solve for the correction of the residual in ``full``/``tr`` into ``dfull``
    (``dx, dnu``) and ``du`` (``du, dlam``) and add ``sign`` times it; with ``sign ==
    -1`` undo the last one, which ``dfull`` and ``du`` still hold. The KKT part's
    correction (``d0``) is :func:`_kkt_part`'s."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, N = n + m, i, j, k, o, d, a, b, start, cone
    cdef int size = <int>(s + nb)
    cdef const double* H
    cdef double value
    cdef char code
    w.grad_current = False
    if sign > 0.0:
        _kkt_part(w, p, t, kkt, rho, nb, tiny)   # d0 = K_R^-1 (r1, r2)
        for j in range(s):
            code = w.active[j]
            value = w.dfull[p.constrained[j]]
            w.tr[j] -= value if _held(code) else rho[j] * value
        for k in range(nb):
            cone = w.boundary[k]
            o, d = p.cones.offset[cone], p.cones.dim[cone]
            start = p.constrained[o]
            H = w.hess + o * s
            for a in range(d):
                for b in range(d):
                    w.tr[o + a] += H[a * d + b] * w.dfull[start + b]
                w.tr[s + k] -= w.g[o + a] * w.dfull[start + a]
        fccqp_lu_solve(w.T, size, w.tpiv, w.tr)
        for j in range(s + nb):
            w.du[j] = w.tr[j]
        colmatvec(t.W, <int>N, w.du, w.dfull, N, s, 1.0)   # dx = d0 + W du
    for i in range(n):
        w.x[i] += sign * w.dfull[i]
    for i in range(m):
        w.nu[i] += sign * w.dfull[n + i]
    for j in range(s):   # dy = R dx_S - du
        w.y[j] += sign * (rho[j] * w.dfull[p.constrained[j]] - w.du[j])
    for k in range(nb):
        w.lam[k] += sign * w.du[s + k]


cdef bint _lu_factor(double* T, int size, int* piv) noexcept nogil:
    """LU-factor the column-major ``size`` square ``T`` in place with partial pivoting
    (LAPACK's pivots in ``piv``): the loop up to ``LU_LOOP_ROWS`` rows, ``dgetrf``
    above; False at a zero pivot."""
    cdef int info = 0
    if size <= LU_LOOP_ROWS:
        return fccqp_lu(T, size, piv) != 0
    dgetrf(&size, &size, T, &size, piv, &info)
    return info == 0


cdef bint table_factor(Polish* w, const Problem* p, const Reduced* t, const double* rho,
                       Py_ssize_t nb) noexcept nogil:
    """Assemble and LU-factor the system of the current active set and planes; False
    when it is singular (see the module's docstring)."""
    cdef int size = <int>(p.s + nb)
    cdef Py_ssize_t i
    cdef double big = 0.0, small = INFINITY, pivot
    _assemble(w, p, t, rho, nb)
    if not _lu_factor(w.T, size, w.tpiv):
        return False
    for i in range(size):
        pivot = fabs(w.T[i + i * size])
        big = max(big, pivot)
        small = min(small, pivot)
    return small > PIVOT_RATIO * big


cdef void table_solve(Polish* w, const Problem* p, const Reduced* t, KKT* kkt,
                      const double* rho, Py_ssize_t nb, double scale) noexcept nogil:
    """Correct the current point with the last factor until the residual is below
    ``REFINE_TOLERANCE * scale`` or stops halving (a correction that makes it grow is
    undone). With the factor of the current planes this solves the polished QP; after
    the planes moved (:func:`fccqp.polish._relinearize`) it is a chord step of Newton's
    method, the Jacobian of the earlier planes standing in for the current one. Where the
    last residual is the returned point's, its products leave that point's ``grad`` and
    ``Ax`` (``grad_current``) for :func:`fccqp.polish._multipliers` and the next
    residual."""
    cdef double norm, last = INFINITY
    cdef int r
    for r in range(MAX_REFINE + 2):
        norm = _residual(w, p, nb)
        if norm > last:
            _correct(w, p, t, kkt, rho, nb, -1.0, 0.0)
            return
        if norm <= POLISH_REFINE_TOLERANCE * scale or norm > 0.5 * last or r == MAX_REFINE + 1:
            return
        last = norm
        _correct(w, p, t, kkt, rho, nb, 1.0, POLISH_REFINE_TOLERANCE * scale)


cdef void table_correct(Polish* w, const Problem* p, const Reduced* t, KKT* kkt,
                        const double* rho, Py_ssize_t nb, double scale) noexcept nogil:
    """One correction of the current point with the last factor (a chord step)."""
    _residual(w, p, nb)
    _correct(w, p, t, kkt, rho, nb, 1.0, POLISH_REFINE_TOLERANCE * scale)


def factor_solve(matrix, rhs):
    """``matrix^-1 rhs`` through :func:`table_factor`'s LU (:func:`_lu_factor`) and the
    correction's solve with its factor, for the tests; None at a zero pivot."""
    cdef double[::1, :] T = np.array(matrix, dtype=np.float64, order="F", copy=True)
    cdef double[::1] b = np.array(rhs, dtype=np.float64, copy=True)
    cdef int[::1] piv = np.zeros(max(b.shape[0], 1), dtype=np.intc)
    cdef int size = <int>b.shape[0]
    if size == 0:
        return np.asarray(b)
    if not _lu_factor(&T[0, 0], size, &piv[0]):
        return None
    fccqp_lu_solve(&T[0, 0], size, &piv[0], &b[0])
    return np.asarray(b)
