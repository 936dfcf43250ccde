# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Infeasibility certificates from ADMM's last step, judged relative to their own terms.

On an infeasible problem ADMM's iterates diverge along a certificate, so the last step
is tested (as in OSQP), but with every "approximately zero" of the primal certificates
judged against the size of the terms that must cancel, not in absolute terms (the dual
certificate's against the size of the direction: :mod:`fccqp.dual_certificate`): a
certificate is then invariant to the scale of the data, and the rounding noise of a sum
(``1e-16`` of its terms) never passes for one. Concretely, for terms ``t_k`` of a sum
``S``, "``S ~ 0``" is ``|S| <= eps max |t_k|``, relative residual ``rho = |S| / max
|t_k|``. All tests run on the scaled problem; norms are taken in the user's units.

The strict inequality of a certificate (``b'dy + sigma_C(dz) < 0``, ``q'dx < 0``) is
what proves; it is judged by ``delta``, the sum divided by the sum of the magnitudes
of its terms. For the primal and equality certificates (Farkas) it must hold by more
than rounding, ``delta < -SEPARATION_FLOOR``, and by more than the residual of the
"``~ 0``" part could explain, ``|delta| >= DOMINANCE * rho``, as Clarabel and SCS ask
(``||A'y|| <= eps_infeas |b'y|``, with ``eps_infeas`` 1e-8 and 1e-7 in their normalized
units; OSQP asks ``b'dy + sigma_C(dz) < 0`` alone). No fixed margin in ``eps`` is asked:
the separation of the best certificate is a property of the data (a duplicated row
whose right-hand side is off by ``1.5e-6`` of its terms allows no certificate with
more), and such a problem has no other honest status: fccqp keeps ``A x = b``, which
has no solution. The dual certificate keeps ``q'dx < -eps |q|'|dx|``.

- primal: ``(d_nu, d_y)`` with ``A'd_nu + E_S d_y ~ 0`` and ``b'd_nu + sigma_C(d_y) < 0``,
  ``d_y`` first projected onto the polar of C's recession cone (where ``sigma_C`` is
  finite);
- equality: the residual ``r = b - A x`` of a KKT solution, when ``A x = b`` has no
  solution, is the least-squares residual: ``A'r ~ 0`` and ``b'r > 0``;
- dual (in :mod:`fccqp.dual_certificate`): a direction ``dx`` with ``P dx ~ 0``, ``A dx
  ~ 0``, ``q'dx < 0`` dominating those residuals, and ``dx_S`` in the recession cone of C.
"""

from libc.math cimport INFINITY, fabs, isfinite

from fccqp._blas cimport cholesky, cholesky_solve_vector, syrk_t
from fccqp._dense cimport copy
from fccqp._types cimport Iterates, Problem
from fccqp.kkt_sparse cimport sparse_gram_factor, sparse_gram_solve
from fccqp.matrices cimport (CSC, DENSE, Matrix, abs_product, product, product_row_norms,
                             product_t_terms, row_spans, subtract_product)
from fccqp.projections cimport proj_block
from fccqp.tuning cimport (CLEANING_PASSES, CLEANING_SHRINK, DOMINANCE, GRAM_REGULARIZATION,
                           SEPARATION_FLOOR)


cdef void magnitudes(const Problem* p, const double* x, double* t) noexcept nogil:
    """``t_j = max(|x_j|, |lb_j|, |ub_j|)`` over the finite bounds (scaled, n entries):
    the magnitude of a point like ``x`` in the box."""
    cdef Py_ssize_t i, j
    for i in range(p.n):
        t[i] = fabs(x[i])
    for j in range(p.s):
        i = p.constrained[j]
        if isfinite(p.lo[j]):
            t[i] = max(t[i], fabs(p.lo[j]))
        if isfinite(p.hi[j]):
            t[i] = max(t[i], fabs(p.hi[j]))


cdef void row_sizes(const Problem* p, const double* x, double* t, double* sizes) noexcept nogil:
    """``sizes_i = sum_j |A_ij| t_j`` for the :func:`magnitudes` ``t`` of ``x`` (``t``: n,
    filled; ``sizes``: m): the size of each row's terms at a point of that magnitude,
    whose rounding (and ``A x = b`` at factorization accuracy) no certificate can tell
    from an inconsistency. At the iterate alone it was no floor where the iterate is 0
    (an equality-only start of 1e-13)."""
    magnitudes(p, x, t)
    abs_product(&p.A, t, sizes)


cdef int primal_infeasible(const Problem* p, const Iterates* it, double eps, const double* Ax,
                           double* row_norm, double* d_nu, double* d_y, double* lhs,
                           double* terms) noexcept nogil:
    """Test ``(nu - nu_prev, y - y_prev)``: ``CERTIFIED``, ``SEPARATED`` when it separates
    but its residual is too large (:func:`clean_primal_certificate` may pass it),
    ``WEAK`` when only the data's scale refutes it (:func:`_residual_tests`), else
    ``REJECTED``. ``Ax`` is ``A x`` at the iterate as the residuals formed it (NULL when
    not at hand) and ``row_norm`` the largest row 1-norm of ``A`` (negative until
    :func:`_explained_at_iterate` first needs it in a solve, which then sets it): with
    them a candidate that :func:`_explained_at_iterate` rules out is ``SEPARATED``
    without ``A'd_nu``, the outcome the full test gives it.
    ``d_nu`` (m), ``d_y`` (s), ``lhs`` and ``terms`` (n) are scratch, and hold the
    candidate (``d_y`` projected) afterwards."""
    cdef Py_ssize_t i, j
    cdef double support, size
    for i in range(p.m):
        d_nu[i] = it.nu[i] - it.nu_prev[i]
    for j in range(p.s):
        d_y[j] = it.y[j] - it.y_prev[j]
    _onto_polar(p, d_y, terms)
    support = _separation(p, d_nu, d_y, &size)
    if not (support < -SEPARATION_FLOOR * size) or not isfinite(support):
        return REJECTED
    if Ax != NULL and _explained_at_iterate(p, it.x, Ax, row_norm, d_nu, d_y, support,
                                            lhs, terms):
        return SEPARATED
    return _residual_tests(p, it.x, True, d_nu, d_y, eps, support, size, lhs, terms)


cdef int primal_candidate(const Problem* p, const double* x, bint at_iterate,
                          const double* d_nu, double* d_y, double eps, double* lhs,
                          double* terms) noexcept nogil:
    """:func:`primal_infeasible`'s tests on a candidate ``(d_nu, d_y)`` found otherwise
    (scaled; ``d_y`` is projected onto the polar first), at ``x``: the iterate, or
    (``at_iterate`` false) the solution of the problem that found the candidate."""
    _onto_polar(p, d_y, terms)
    return _farkas(p, x, at_iterate, d_nu, d_y, eps, lhs, terms)


cdef void _onto_polar(const Problem* p, double* d_y, double* scratch) noexcept nogil:
    """Project ``d_y`` (s) onto the set where ``sigma_C`` is finite: each cone block onto
    its polar (``d_y - P_K(d_y)``), and a box entry's sign onto its finite bounds
    (``scratch``: n). That is :func:`_shrink` with ``tau = 0``."""
    _shrink(p, d_y, 0.0, scratch)


cdef void _shrink(const Problem* p, double* d_y, double tau, double* scratch) noexcept nogil:
    """``d_y := d_y - P_{tau C}(d_y)``, the proximal step of ``tau sigma_C`` (Moreau): cone
    blocks onto their polars, box entries shrunk toward ``[tau lb, tau ub]``'s far side
    by what the support would charge (``scratch``: n)."""
    cdef Py_ssize_t j, k, a, dim
    cdef double low, high
    for k in range(p.cones.count):
        a, dim = p.cones.offset[k], p.cones.dim[k]
        proj_block(d_y + a, p.cones.kind[k], dim, p.cones.mu[k], p.cones.normal + 3 * k,
                   scratch)
        for j in range(dim):
            d_y[a + j] -= scratch[j]
    for j in range(p.s):
        if p.in_cone[j]:
            continue
        low = tau * p.lo[j] if isfinite(p.lo[j]) else -INFINITY
        high = tau * p.hi[j] if isfinite(p.hi[j]) else INFINITY
        d_y[j] -= min(max(d_y[j], low), high)


cdef int _farkas(const Problem* p, const double* x, bint at_iterate, const double* d_nu,
                 const double* d_y, double eps, double* lhs, double* terms) noexcept nogil:
    """The tests of a primal certificate ``(d_nu, d_y)`` with ``d_y`` on the polar (see
    the module docstring), at ``x`` (see :func:`_residual_tests`), as
    :func:`primal_infeasible` returns them (``lhs``, ``terms``: n scratch)."""
    cdef double size
    cdef double support = _separation(p, d_nu, d_y, &size)
    if not (support < -SEPARATION_FLOOR * size) or not isfinite(support):
        return REJECTED
    return _residual_tests(p, x, at_iterate, d_nu, d_y, eps, support, size, lhs, terms)


cdef double _separation(const Problem* p, const double* d_nu, const double* d_y,
                        double* size) noexcept nogil:
    """``b'd_nu + sigma_C(d_y)`` for ``d_y`` on the polar (cones contribute 0), and in
    ``size`` the sum of its terms' magnitudes."""
    cdef Py_ssize_t i, j
    cdef double support = 0.0
    size[0] = 0.0
    for j in range(p.s):
        if p.in_cone[j]:
            continue
        if d_y[j] > 0.0:
            support += p.hi[j] * d_y[j]
            size[0] += fabs(p.hi[j] * d_y[j])
        elif d_y[j] < 0.0:
            support += p.lo[j] * d_y[j]
            size[0] += fabs(p.lo[j] * d_y[j])
    for i in range(p.m):
        support += p.b[i] * d_nu[i]
        size[0] += fabs(p.b[i] * d_nu[i])
    return support


cdef int _residual_tests(const Problem* p, const double* x, bint at_iterate,
                         const double* d_nu, const double* d_y, double eps, double support,
                         double size, double* lhs, double* terms) noexcept nogil:
    """The tests of a candidate that separates by ``support`` (its terms' magnitudes
    ``size``) on its residual ``A'd_nu + E_S d_y``: ``CERTIFIED``, ``WEAK`` or
    ``SEPARATED`` (``lhs``, ``terms``: n scratch). What the residual explains is
    measured at ``x`` and over the box; at ADMM's iterate (``at_iterate``), which can lie
    far from every feasible point, also at the data's scale, and a candidate that only
    this last test rejects is ``WEAK`` (:func:`fccqp.verdict.check` certifies it only at
    the run's last check, where no point was found). A least distance's solution is the
    point of the box and cones nearest to meeting the rows, where the residual's
    products are those of its own identity."""
    cdef Py_ssize_t n = p.n, i, j
    cdef double lhs_max = 0.0, terms_max = 0.0, explained = 0.0
    product_t_terms(&p.A, d_nu, lhs, terms)
    for j in range(p.s):
        i = p.constrained[j]
        lhs[i] += d_y[j]
        terms[i] += fabs(d_y[j])
    for i in range(n):
        lhs_max = max(lhs_max, fabs(lhs[i]) / p.D[i])
        terms_max = max(terms_max, terms[i] / p.D[i])
        explained += fabs(lhs[i] * x[i])
    # For every x with A x = b and x_S in C, b'd_nu + sigma_C(d_y) >= (A'd_nu + d_y)'x: a
    # separation no larger than what the residual explains at the iterate's own x proves
    # nothing (dependent rows let d_nu drift along null(A') with b'd_nu ~ 0), nor one
    # that the residual's products with the box's bounds reach (:func:`_box_reach`), nor,
    # at an iterate, with the data's scale (:func:`_scale_reach`, last: it reads all of A;
    # ``terms`` is its scratch)
    if not (lhs_max <= eps * terms_max and support < -explained
            and support < -_box_reach(p, lhs)
            and DOMINANCE * lhs_max * size <= -support * terms_max):
        return SEPARATED
    if at_iterate and not support < -_box_reach(p, lhs) - _scale_reach(p, lhs, terms):
        return WEAK
    return CERTIFIED


cdef double ROUNDING = 4.5e-16
"""Four times the unit roundoff: with ``n + m + s + 4`` terms, twice the bound on the
rounding of the sums that :func:`_explained_at_iterate` compares (a rounding bound,
not a tuning constant)."""
cdef double SLACK = 1e-12
"""Relative room for the few roundings of that comparison itself."""


cdef bint _explained_at_iterate(const Problem* p, const double* x, const double* Ax,
                                double* row_norm, const double* d_nu, const double* d_y,
                                double support, double* ones, double* norms) noexcept nogil:
    """Whether the residual ``lhs = A'd_nu + E_S d_y`` surely explains the separation at
    ``x``, known in ``O(n + m + s)`` from ``A x`` without ``A'd_nu``: ``lhs'x = d_nu'(A
    x) + d_y'x_S``, and :func:`_residual_tests`' ``explained = sum_i |lhs_i x_i|`` is
    at least ``|lhs'x|``, so where ``|lhs'x|`` exceeds ``-support`` by more than the
    rounding of both sides (``A x`` as the residuals formed it, within ``n`` roundings
    of ``|A| |x| <= row_norm max|x|``; ``lhs`` within ``m + 1`` of its terms; the sums
    themselves), the test ``support < -explained`` fails however ``lhs`` is rounded,
    and the candidate is ``SEPARATED``. On whole-body-control QPs a feasible run's
    candidates separate at nearly every check and ``|lhs'x|`` exceeds ``-support`` at
    96 % of them, each of which would otherwise cost ``A'd_nu`` and ``|A|'|d_nu|``.
    ``row_norm`` is formed (once per solve, ``ones``: n, ``norms``: m scratch) only
    when the sums alone surely pass."""
    cdef Py_ssize_t i, j
    cdef double along = 0.0, terms = 0.0, nu_size = 0.0, x_max = 0.0, value, error
    for i in range(p.m):
        value = d_nu[i] * Ax[i]
        along += value
        terms += fabs(value)
        nu_size += fabs(d_nu[i])
    for j in range(p.s):
        value = d_y[j] * x[p.constrained[j]]
        along += value
        terms += fabs(value)
    for i in range(p.n):
        x_max = max(x_max, fabs(x[i]))
    error = (p.n + p.m + p.s + 4) * ROUNDING * (fabs(along) + terms)
    if not (isfinite(error) and (fabs(along) - error) * (1.0 - SLACK) >= -support):
        return False
    if row_norm[0] < 0.0:
        row_norm[0] = _largest_row_norm(p, ones, norms)
    error += (p.n + p.m + p.s + 4) * ROUNDING * row_norm[0] * x_max * nu_size
    return isfinite(error) and (fabs(along) - error) * (1.0 - SLACK) >= -support


cdef double _largest_row_norm(const Problem* p, double* ones, double* norms) noexcept nogil:
    """The largest 1-norm of a row of ``A``, summed in any order (``ones``: n, ``norms``:
    m scratch)."""
    cdef Py_ssize_t i
    cdef double largest = 0.0
    for i in range(p.n):
        ones[i] = 1.0
    row_spans(&p.A, ones, norms)
    for i in range(p.m):
        largest = max(largest, norms[i])
    return largest


cdef double _box_reach(const Problem* p, const double* lhs) noexcept nogil:
    """``sigma_box(-lhs)`` over the box entries' finite sides (scaled): the most that
    ``-lhs'x`` reaches with ``x`` in the box, which a primal certificate's separation
    must exceed, as ``tests/verify.py`` asks. At a point alone the residual's products
    proved too little: with columns scaled over 1e16 (bounds up to 4e7), feasible
    problems had certificates whose residual was 3e-9 of its terms (a least distance's)
    or 1e-13 (ADMM's own) and reached 23 and 45 times their separation in the box."""
    cdef Py_ssize_t i, j
    cdef double reach = 0.0
    for j in range(p.s):
        if p.in_cone[j]:
            continue
        i = p.constrained[j]
        if lhs[i] < 0.0 and isfinite(p.hi[j]):
            reach -= lhs[i] * p.hi[j]
        elif lhs[i] > 0.0 and isfinite(p.lo[j]):
            reach -= lhs[i] * p.lo[j]
    return reach


cdef double _scale_reach(const Problem* p, const double* lhs, double* scales) noexcept nogil:
    """``sum_i |lhs_i| scales_i`` over the entries whose products with ``lhs`` no finite
    bound limits (free, in a cone, or a box entry unbounded in the residual's direction;
    :func:`_box_reach` bounds the others), at :func:`_column_scales`' ``x_i``
    (``scales``: n scratch): what the residual explains at a point of the data's scale,
    whatever the iterate. At the iterate alone, a feasible problem's candidate whose
    residual on a cone's columns was their own size (1e-7 of the largest terms)
    explained 0.07 of its separation, where that cone's entries were 20 times smaller
    than at the optimum (3.8 times it at the data's scale, 1.16 at the optimum)."""
    cdef Py_ssize_t i, j
    cdef double reach = 0.0
    _column_scales(p, scales)
    for j in range(p.s):
        if p.in_cone[j]:
            continue
        i = p.constrained[j]
        if (lhs[i] < 0.0 and isfinite(p.hi[j])) or (lhs[i] > 0.0 and isfinite(p.lo[j])):
            scales[i] = 0.0
    for i in range(p.n):
        reach += fabs(lhs[i]) * scales[i]
    return reach


cdef void _column_scales(const Problem* p, double* scales) noexcept nogil:
    """``scales_i = max |b| / max_k |A_ki|`` (0 for an empty column): the size of ``x_i``
    that meets the largest right-hand side with column ``i`` alone, the scale of a
    feasible point's entry where no bound limits it (an iterate far from feasibility can
    be orders of magnitude off it)."""
    cdef const Matrix* A = &p.A
    cdef Py_ssize_t i, k
    cdef double b_max = 0.0
    for k in range(p.m):
        b_max = max(b_max, fabs(p.b[k]))
    for i in range(p.n):
        scales[i] = 0.0
    if A.kind == DENSE:
        for k in range(A.rows):
            for i in range(A.cols):
                scales[i] = max(scales[i], fabs(A.values[k * A.cols + i]))
    else:
        for i in range(A.cols):
            for k in range(A.colptr[i], A.colptr[i + 1]):
                scales[i] = max(scales[i], fabs(A.values[k]))
    for i in range(p.n):
        scales[i] = b_max / scales[i] if scales[i] > 0.0 else 0.0


cdef bint gram_factor(const Problem* p, void* sparse, double* gram) noexcept nogil:
    """Factor ``A A'`` plus ``GRAM_REGULARIZATION`` of its largest diagonal entry
    (dependent rows); False when that fails. On dense rows ``gram`` (m x m,
    column-major) := its Cholesky factor; on compressed columns, whose workspace has no
    ``m x m`` array, the ``SparseKKT`` ``sparse`` holds a sparse LDL' factor of it
    (:func:`fccqp.kkt_sparse.sparse_gram_factor`) and ``gram`` is not used."""
    cdef Py_ssize_t m = p.m
    if p.A.kind == CSC:
        return sparse_gram_factor(sparse)
    # the row-major m x n A is, column-major, A' (n x m): one dsyrk gives A A' (dense
    # storage)
    syrk_t(<int>m, <int>p.n, p.A.values, <int>p.n, 0.0, gram, <int>m)
    return regularized_cholesky(gram, m)


cdef inline void _gram_solve(const Problem* p, const double* gram, void* sparse,
                             double* v) noexcept nogil:
    """``v`` (m) := ``(A A')^-1 v`` on the factor of :func:`gram_factor`."""
    if p.A.kind == CSC:
        sparse_gram_solve(sparse, p.m, v)
    else:
        cholesky_solve_vector(gram, <int>p.m, <int>p.m, v)


cdef bint regularized_cholesky(double* gram, Py_ssize_t m) noexcept nogil:
    """Factor ``gram`` (m x m, column-major, lower triangle) in place after adding
    ``GRAM_REGULARIZATION`` of its largest diagonal entry (dependent rows); False when
    it is zero or Cholesky fails."""
    cdef Py_ssize_t i
    cdef double largest = 0.0
    for i in range(m):
        largest = max(largest, gram[i + i * m])
    if not largest > 0.0:
        return False
    for i in range(m):
        gram[i + i * m] += GRAM_REGULARIZATION * largest
    return cholesky(gram, <int>m, <int>m)


cdef int clean_primal_certificate(const Problem* p, const double* x, const double* gram,
                                  void* sparse, double eps, double* d_nu, double* d_y,
                                  double* saved, double* w, double* lhs,
                                  double* terms) noexcept nogil:
    """Clean the candidate ``(d_nu, d_y)`` that :func:`primal_infeasible` left by
    alternating steps between the subspace ``A'd_nu + E_S'd_y = 0`` (``d_nu`` by least
    squares on :func:`gram_factor`'s factor, in ``gram`` or ``sparse``) and the polar
    (``d_y := -(A'd_nu)_S`` projected): ``CLEANING_PASSES`` plain projections, then as
    many again from the candidate with each projection preceded by :func:`_shrink`'s
    proximal step on the box's support. ``CERTIFIED`` (or ``WEAK``, see
    :func:`_residual_tests`), with the certificate in ``(d_nu, d_y)``, as soon as a
    pass's pair passes the tests, else ``REJECTED`` (``saved``: m + s, ``w``, ``lhs``,
    ``terms``: n scratch).

    On a curved cone boundary the differences of ADMM's multipliers reach the set of
    certificates only like 1/k: rows ``fz = 1``, ``fx = mu (1 + 1e-3)`` with one friction
    cone left the candidate's ratio of the two multipliers at 0.6991 after 4000
    iterations, where certificates have 0.7 to 0.7007, and 64000 iterations reached
    0.69988. The certificates are the intersection of that subspace and the polar,
    and the nearest ones to the candidate lie on its boundary, inside the separating
    wedge: one pass gives the ratio 0.7 exactly. Projections do not weigh the box's
    support, though: beside two friction cones pinned outside their sum, a row through
    a boxed entry kept a multiplier that only costs, which the shrinking removes."""
    cdef Py_ssize_t m = p.m, s = p.s, j
    cdef double bounds = 0.0
    cdef int code
    for j in range(s):
        if not p.in_cone[j]:
            if isfinite(p.lo[j]):
                bounds = max(bounds, fabs(p.lo[j]))
            if isfinite(p.hi[j]):
                bounds = max(bounds, fabs(p.hi[j]))
    copy(d_nu, saved, m)
    copy(d_y, saved + m, s)
    code = _alternate(p, x, gram, sparse, eps, 0.0, d_nu, d_y, w, lhs, terms)
    if code != REJECTED or bounds == 0.0:
        return code
    copy(saved, d_nu, m)
    copy(saved + m, d_y, s)
    return _alternate(p, x, gram, sparse, eps, CLEANING_SHRINK / bounds, d_nu, d_y, w, lhs,
                      terms)


cdef int _alternate(const Problem* p, const double* x, const double* gram, void* sparse,
                    double eps, double shrink, double* d_nu, double* d_y, double* w,
                    double* lhs, double* terms) noexcept nogil:
    """At most ``CLEANING_PASSES`` passes of :func:`clean_primal_certificate`, each
    subspace step followed by :func:`_shrink` with ``tau = shrink ||d_y||`` (``tau = 0``:
    the plain projection onto the polar) and the tests: the first pass's ``CERTIFIED``
    or ``WEAK`` code, else ``REJECTED``; stops after two passes in a row that do not
    separate."""
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, i, j, pass_
    cdef double size
    cdef int code, rejected = 0
    for pass_ in range(CLEANING_PASSES):
        for i in range(n):   # w = -E_S'd_y, then d_nu := (A A')^-1 A w
            w[i] = 0.0
        for j in range(s):
            w[p.constrained[j]] = -d_y[j]
        product(&p.A, w, d_nu)
        _gram_solve(p, gram, sparse, d_nu)
        product_t_terms(&p.A, d_nu, w, terms)   # w = A'd_nu, then d_y := -(A'd_nu)_S
        size = 0.0
        for j in range(s):
            d_y[j] = -w[p.constrained[j]]
            size = max(size, fabs(d_y[j]))
        _shrink(p, d_y, shrink * size, terms)
        code = _farkas(p, x, True, d_nu, d_y, eps, lhs, terms)
        if code == CERTIFIED or code == WEAK:
            return code
        # two passes in a row that do not even separate: the candidate of a feasible
        # problem (on go2's controller ticks the full rounds cost 2.6 % of the warm
        # solves' instructions)
        rejected = rejected + 1 if code == REJECTED else 0
        if rejected == 2:
            return REJECTED
    return REJECTED


cdef int equality_inconsistent(const Problem* p, const Iterates* it, double eps, double* r,
                               double* ATr, double* terms, double* sizes) noexcept nogil:
    """:func:`equality_direction` for ``r = b - A x`` (``r``: m, filled; ``ATr``,
    ``terms``: n, ``sizes``: m scratch)."""
    copy(p.b, r, p.m)
    subtract_product(&p.A, it.x, r)
    return equality_direction(p, r, it.x, eps, ATr, terms, sizes)


cdef int equality_direction(const Problem* p, const double* r, const double* x, double eps,
                            double* ATr, double* terms, double* sizes) noexcept nogil:
    """Test ``r`` (m) for ``A'r ~ 0`` and ``b'r > 0``: ``CERTIFIED``, ``SEPARATED`` when
    ``b'r`` separates but ``A'r`` is not small enough against it (a cleaner ``r`` may
    pass, see :meth:`fccqp.admm.Workspace._inconsistent`), else ``REJECTED`` (``ATr``,
    ``terms``: n, ``sizes``: m scratch).

    Its separation is measured against the data's size, not only its own terms: ``b'r``
    must exceed ``SEPARATION_FLOOR`` of ``sum_i |r_i| max(|b_i|, row_size_i)`` (see
    :func:`row_sizes`: the rounding a right-hand side ``A x`` carries for a point of the
    iterate's and the box's magnitude), and what the residual explains at the iterate
    (every ``x`` with ``A x = b`` has ``b'r = (A'r)'x``, as for the primal certificate).
    Relative to its own terms alone, ``b'r`` of dependent rows whose right-hand sides
    are rounding noise (entries of 4e-16 where the rows ask 0, at a start ``x`` of
    1e-13) looked like a proof: a public QP (QSCORPIO) was claimed infeasible."""
    cdef Py_ssize_t n = p.n, i, j
    cdef double br = 0.0, size = 0.0, lhs_max = 0.0, terms_max = 0.0, explained = 0.0
    cdef double data = 0.0
    if p.m == 0:
        return REJECTED
    row_sizes(p, x, terms, sizes)
    for i in range(p.m):
        br += p.b[i] * r[i]
        size += fabs(p.b[i] * r[i])
        data += fabs(r[i]) * max(fabs(p.b[i]), sizes[i])
    if not (br > SEPARATION_FLOOR * data) or not isfinite(br):
        return REJECTED
    product_t_terms(&p.A, r, ATr, terms)
    for j in range(n):
        lhs_max = max(lhs_max, fabs(ATr[j]) / p.D[j])
        terms_max = max(terms_max, terms[j] / p.D[j])
        explained += fabs(ATr[j] * x[j])
    if (lhs_max <= eps * terms_max and DOMINANCE * lhs_max * size <= br * terms_max
            and br > explained):
        return CERTIFIED
    return SEPARATED


cdef bint zero_rows_inconsistent(const Problem* p, double* r, double* ones,
                                 double* norms) noexcept nogil:
    """Whether a row of ``A`` with no nonzero entry asks ``b_i != 0``; then ``r`` (m) holds
    ``b`` on those rows and 0 elsewhere, the equality certificate with ``A'r = 0`` exactly
    and ``b'r = sum b_i^2 > 0`` (``ones``: n, ``norms``: m scratch; ``r`` is left alone
    otherwise).

    :func:`equality_direction` judges ``A'r ~ 0`` against the terms ``|A|'|r|``, to
    which such a row adds nothing: the least-squares residual's rounding on the other
    rows (1e-16 of their terms) then meets itself as both residual and terms, and no
    cleaning shrinks the ratio (``A = [e_1; 0]``, ``b = (1, 1e-3)``: 4000 iterations at
    ``A x = b`` missed by 1e-3, on every backend)."""
    cdef Py_ssize_t i
    cdef bint found = False
    for i in range(p.n):
        ones[i] = 1.0
    row_spans(&p.A, ones, norms)
    for i in range(p.m):
        found = found or (norms[i] == 0.0 and p.b[i] != 0.0)
    if not found:
        return False
    for i in range(p.m):
        r[i] = p.b[i] if norms[i] == 0.0 else 0.0
    return True
