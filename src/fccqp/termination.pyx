# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Residuals, duality gap and the termination test of an ADMM iterate.

For the user's problem and an iterate ``(x, y, z)`` with slack ``w`` in ``C``:

    ||A x - b||                                      <= eps_abs + eps_rel * max(||A x||, ||b||)
    ||x_S - w||                                      <= eps_abs + eps_rel * max(||x_S||, ||w||)
    dual = ||P x + q + A'y + z||                     <= eps_abs + eps_rel * dual_scale
    gap  = |x'Px + q'x + b'y + sigma_C(z)|           <= eps_abs + eps_rel * gap_scale

(infinity norms); the primal residual reported is the larger of the first two, each
judged in its own units (rows of ``A``, entries of ``x``). The scales come from the
data and the primal point; the multipliers, which diverge on an infeasible problem,
can widen them by a bounded factor at most. ``dual_scale = max(||q||, ||P x||)`` leaves
them out (a dual scale that included them let a dual residual of 486 pass against
multipliers of 3.6e8). The gap's scale (:func:`gap_scale`) is the primal objective's
terms, ``max(|x'Px|, |q'x|)``, as in Clarabel's relative gap (which divides by the
smaller of the primal and dual objectives), widened by the size of the multiplier
terms of ``b'y + sigma_C(z)`` (the sum of the magnitudes of its products; PIQP counts
each dot product of the gap) to at most ``GAP_TERMS_CAP`` times: the multiplier terms
alone can make any gap look small, and did on a random problem with dependent,
slightly inconsistent rows (``|x| = 3e8``, ``x'Px = -q'x = 1e14``, multipliers
diverging along the inconsistency: a gap of 1.4e10 was accepted against terms of
1.7e16; Clarabel stops there with ``InsufficientProgress``). Up to the cap they let the
test follow the accuracy of large legitimate multipliers: on talos_reduced's WBC
problems they are 2-18 times ``|x'Px|`` at the optimum, and with the cap at 10 one QP
of the 200 needs 48 more iterations (1392 -> 1440 at default settings, 505 -> 556 in
the realtime preset) before its polish, no other changes. Ten is also the factor by
which the independent checker (``tests/verify.py``) loosens the same test, whose scale
has no multiplier terms at all, so a ``SOLVED`` here passes it there. ``sigma_C`` is the support function of the box
and the cones; ADMM's multiplier lies in the normal cone of ``C`` at its slack, so it is
finite (``sum hi_i z_i`` over upper, ``lo_i z_i`` over lower entries, 0 on cones).

The set residual's relative tolerance takes the largest constrained entry as its scale,
in the user's units: with variables in units 1e-8 to 1e8 of each other, an entry of
3.7e7 lent ``eps_rel`` x 3.7e7 = 371 to a friction cone of forces near 1 that its rows
pinned outside itself by 78, and an infeasible problem was claimed SOLVED at its
start. So a point is also judged in the scaled units, where the equilibration has
brought the variables to comparable sizes: no status that promises the tolerances
while ``x_S`` misses C there by more than ``eps_abs`` plus ``SCALED_VIOLATION`` (1 %) of
``x_S``'s size (the absolute part for points at rounding level: a solution at 0 with
entries of 4e-17 off their bounds of 0).
The guard is gross on purpose for the cones: judging each cone block against its own
size instead (in either units) is the exact fix, but it tightens the test on friction
cones with near-zero forces and doubled the iterations of the whole-body-control QPs.
A box entry is judged against its own size (``box_excess``), its value or the width of
a two-sided box (whichever is larger, so that a torque near its limit is held to 1 % of
its range, not of its value): a one-sided bound of 2.77 missed by 0.05 beside a cone
block of entries near 5e8 was claimed SOLVED on an infeasible problem otherwise.

Rho adaptation (:mod:`fccqp.rho_rule`) balances the scaled primal and dual residuals, each
relative to its own scale. There the primal scale of a box entry is capped by the
width of its box, and that of a row by the range its ``A x`` can take over the box
(:func:`row_spans`): a residual as large as that range says the iterate does not know
yet where in the box it lies, however small it is against the distance of the box to
the origin. Without the cap the balance depended on where the box lies: entries boxed
to widths 1e-4..1e-2 about points of size 1 (the general suite's
``large_multipliers``) looked 1e3 times closer to convergence than they were, rho
stayed 1e3 times too small and ADMM crawled for 4000 iterations, while the same
problems moved to the origin solved (8 of 9 in 140-1800 iterations). A range of 0
(an entry with ``lo == hi``, a row on such entries only) sets no cap: that is an
equality, judged against its size as the rows are (capped at 0, the suite's problem
with every entry fixed took 4000 iterations instead of 20). Whole-body control leaves
the cap idle (torque boxes hold the origin, so ``|x|`` stays within their width, and
the rows pass through free accelerations): the WBC sets' solves are unchanged.

Everything is computed from the scaled iterate (see :mod:`fccqp.scaling`) and mapped
back: ``x = D x_s``, ``y = E nu_s / c``, ``z_S = y_s / (c D_S)``, so that the residual of
row ``i`` is the scaled one divided by ``E_i``, of entry ``i`` of ``x`` by ``c D_i``.
"""

from libc.math cimport INFINITY, fabs, isfinite

from fccqp._types cimport Iterates, Problem
from fccqp.matrices cimport product, product_t
from fccqp.matrices cimport row_spans as matrix_row_spans
from fccqp.tuning cimport COMPLEMENTARITY_FACTOR, GAP_TERMS_CAP, SCALED_VIOLATION

cdef extern from "fccqp_kernels.h" nogil:
    void fccqp_row_residuals(const double* Ax, const double* b, const double* E,
                             const double* span, long m, double* out)
    void fccqp_set_residuals(const double* x, const double* D, const Py_ssize_t* constrained,
                             const double* z, const double* y, const double* lo,
                             const double* hi, const char* in_cone, double violation, long s,
                             double* out)
    void fccqp_dual_scales(double* Px, const double* q, const double* ATnu, const double* x,
                           const double* D, double c, long n, double* out)
    void fccqp_dual_residual(const double* grad, const double* x, const double* D, double c,
                             long n, double* out)


cdef void row_spans(Problem* p, double* width) noexcept nogil:
    """``span``: for each row ``i``, ``sum_j |A_ij| (hi_j - lo_j)``, the range of ``(A x)_i``
    over the box (infinite where the row meets an entry without two finite bounds);
    ``width`` (n) is scratch."""
    cdef Py_ssize_t n = p.n, j
    for j in range(n):
        width[j] = INFINITY
    for j in range(p.s):
        width[p.constrained[j]] = p.hi[j] - p.lo[j]
    matrix_row_spans(&p.A, width, p.span)


cdef double box_support(const Problem* p, const double* y, double* terms) noexcept nogil:
    """``sigma_C(y)`` over the box entries (cones contribute 0 to a multiplier in their
    polar), on the scaled problem, adding the magnitudes of its terms to ``terms``;
    infinite sides are skipped (ADMM's y is exactly 0 there)."""
    cdef double out = 0.0, value
    cdef Py_ssize_t j
    for j in range(p.s):
        value = 0.0
        if y[j] > 0.0 and isfinite(p.hi[j]):
            value = p.hi[j] * y[j]
        elif y[j] < 0.0 and isfinite(p.lo[j]):
            value = p.lo[j] * y[j]
        out += value
        terms[0] += fabs(value)
    return out


cdef double gap_scale(double xPx, double qx, double terms) noexcept nogil:
    """Scale of the gap's relative tolerance: ``max(|x'Px|, |q'x|)``, widened to the
    multiplier ``terms`` (sum of the magnitudes of the products in ``b'y + sigma_C(z)``)
    up to ``GAP_TERMS_CAP`` times, so that diverging multipliers cannot hide a gap."""
    cdef double primal = max(fabs(xPx), fabs(qx))
    return max(primal, min(terms, GAP_TERMS_CAP * primal))


cdef void residuals(const Problem* p, const Iterates* it, double* Ax, double* ATnu,
                    double* Px, Residuals* r) noexcept nogil:
    """Fill ``r`` for the iterate ``it`` (``Ax``, ``ATnu``, ``Px``: scratch of sizes m, n, n).
    The passes over the rows, the constrained entries and the variables are
    ``fccqp_kernels.h``'s (``fccqp_row_residuals`` and the three after it)."""
    cdef Py_ssize_t n = p.n, m = p.m, i, j
    cdef double c = p.c, xPx, qx, bnu, support, terms, total
    cdef double rows[5]
    cdef double entries[7]
    cdef double variables[4]
    cdef double dual[3]
    r.compl = r.compl_scale = 0.0   # measured on the returned point only
    r.eq_rounding = False
    product(&p.A, it.x, Ax)
    product_t(&p.A, it.nu, ATnu)
    product(&p.P, it.x, Px)
    fccqp_row_residuals(Ax, p.b, p.E, p.span, m, rows)
    fccqp_set_residuals(it.x, p.D, p.constrained, it.z, it.y, p.lo, p.hi, p.in_cone,
                        SCALED_VIOLATION, p.s, entries)
    r.prim_eq, r.prim_eq_scale = rows[0], rows[1]
    r.prim_set, r.prim_set_scale = entries[0], entries[1]
    r.prim_s = max(rows[2], entries[2])
    r.prim_scale_s = max(rows[3], entries[3])
    r.set_s, r.set_scale_s = entries[2], entries[4]
    r.box_excess = entries[5]
    total = rows[4] + entries[6]
    r.prim = max(r.prim_eq, r.prim_set)
    r.prim_scale = max(r.prim_eq_scale, r.prim_set_scale)
    fccqp_dual_scales(Px, p.q, ATnu, it.x, p.D, c, n, variables)
    xPx, qx = variables[0], variables[1]
    r.dual_scale, r.dual_scale_s = variables[2], variables[3]
    for j in range(p.s):   # Px now holds the gradient of the Lagrangian
        i = p.constrained[j]
        Px[i] += it.y[j]
        r.dual_scale_s = max(r.dual_scale_s, fabs(it.y[j]))
    fccqp_dual_residual(Px, it.x, p.D, c, n, dual)
    r.dual, r.dual_s = dual[0], dual[1]
    total += dual[2]
    bnu = terms = 0.0
    for i in range(m):
        bnu += p.b[i] * it.nu[i]
        terms += fabs(p.b[i] * it.nu[i])
    support = box_support(p, it.y, &terms)
    r.gap = fabs(xPx + qx + bnu + support) / c
    r.gap_scale = gap_scale(xPx, qx, terms) / c
    r.finite = isfinite(total) and isfinite(r.gap)


cdef bint converged(const Residuals* r, double eps_abs, double eps_rel) noexcept nogil:
    """The termination test: all three within tolerance (and finite)."""
    return nearly_converged(r, eps_abs, eps_rel, 1.0)


cdef bint nearly_converged(const Residuals* r, double eps_abs, double eps_rel,
                           double factor) noexcept nogil:
    """:func:`converged` with tolerances multiplied by ``factor``; and in the scaled
    units, whatever the factor, ``x_S`` within ``eps_abs`` plus ``SCALED_VIOLATION`` of
    its size from C (see the module docstring); and each box entry's and cone block's
    complementarity (``Residuals.compl``, measured on a returned point) within
    ``COMPLEMENTARITY_FACTOR`` times the gap's tolerance on the primal objective's
    scale, which is what ``tests/verify.py`` asks of the status. The gap sums these
    products, and its test alone passed a sum that cancelled: a linear program with
    ``q`` of 2.4e17 and entries of 1e11 (fuzz extreme_data:1900288) had a cone block's
    ``x'z`` of 1.8e14 (1e-14 of the products' terms) against a gap of 2.7e12, and was
    returned SOLVED at 3999 iterations and SOLVED_INACCURATE at 4000.

    On a returned point ``A x = b`` also passes at the rounding of its terms
    (``Residuals.eq_rounding``): no double-precision point does better, and where ``x``
    is large against ``A x`` (an optimum at 2e13 beside ``|A x|`` of 1.2, fuzz
    extreme_data:2500055; 1183 of the deep run) ``eps_rel max(|A x|, |b|)`` lies
    below it."""
    return (r.finite
            and r.compl <= COMPLEMENTARITY_FACTOR * factor * (eps_abs + eps_rel
                                                               * r.compl_scale)
            and (r.prim_eq <= factor * (eps_abs + eps_rel * r.prim_eq_scale)
                 or r.eq_rounding)
            and r.prim_set <= factor * (eps_abs + eps_rel * r.prim_set_scale)
            and r.set_s <= eps_abs + SCALED_VIOLATION * r.set_scale_s
            and r.box_excess <= eps_abs
            and r.dual <= factor * (eps_abs + eps_rel * r.dual_scale)
            and r.gap <= factor * (eps_abs + eps_rel * r.gap_scale))


cdef double distance(const Residuals* r, double eps_abs, double eps_rel) noexcept nogil:
    """How far the residuals are from the termination test: the smallest ``factor`` of
    :func:`nearly_converged`'s four tolerance tests (the equalities, the set, the dual
    residual, the gap), ``INFINITY`` when a residual is not finite. A run's progress
    measure under a time limit (:func:`fccqp.iteration._extend`)."""
    if not r.finite:
        return INFINITY
    return max(max(r.prim_eq / (eps_abs + eps_rel * r.prim_eq_scale),
                   r.prim_set / (eps_abs + eps_rel * r.prim_set_scale)),
               max(r.dual / (eps_abs + eps_rel * r.dual_scale),
                   r.gap / (eps_abs + eps_rel * r.gap_scale)))


def residual_passes_py(const double[::1] Ax, const double[::1] b, const double[::1] E,
                       const double[::1] span, const double[::1] x, const double[::1] D,
                       const Py_ssize_t[::1] constrained, const double[::1] z,
                       const double[::1] y, const double[::1] lo, const double[::1] hi,
                       const signed char[::1] in_cone, double[::1] Px, const double[::1] q,
                       const double[::1] ATnu, double c):
    """Test hook: :func:`residuals`' four kernels on numpy arrays (at least one row, one
    constrained entry, one variable), ``Px`` overwritten by ``Px + (q + A'nu)``; returns
    their outputs (the rows', the constrained entries', the variables' and the gradient's)
    as four lists."""
    cdef double rows[5]
    cdef double entries[7]
    cdef double variables[4]
    cdef double dual[3]
    cdef long m = Ax.shape[0], s = z.shape[0], n = x.shape[0]
    fccqp_row_residuals(&Ax[0], &b[0], &E[0], &span[0], m, rows)
    fccqp_set_residuals(&x[0], &D[0], &constrained[0], &z[0], &y[0], &lo[0], &hi[0],
                        <const char*>&in_cone[0], SCALED_VIOLATION, s, entries)
    fccqp_dual_scales(&Px[0], &q[0], &ATnu[0], &x[0], &D[0], c, n, variables)
    fccqp_dual_residual(&Px[0], &x[0], &D[0], c, n, dual)
    return list(rows), list(entries), list(variables), list(dual)
