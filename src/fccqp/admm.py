"""The ADMM iteration, compiled with numba.

Splitting: the constrained entries ``x_S`` (finite bound or cone) are copied into a
slack ``z`` that must lie in ``C`` = box x cones; the equalities stay in the x-update.
With multipliers ``y`` of ``x_S = z`` and over-relaxation ``alpha``, one iteration is

    (x~, nu) = argmin_{A x = b} 1/2 x'Px + q'x + sigma/2 ||x - x_k||^2
                                 + rho/2 ||x_S - z_k + y_k / rho||^2     (KKT solve)
    x_S^r    = alpha x~_S + (1 - alpha) z_k
    z_{k+1}  = P_C(x_S^r + y_k / rho)
    y_{k+1}  = y_k + rho (x_S^r - z_{k+1})
    x_{k+1}  = alpha x~ + (1 - alpha) x_k     (x_1 = x~)

Unlike the paper, rho touches the constrained entries only: a free variable gets no
penalty (sigma is a 1e-6 proximal regularization). The first x of a run is not
relaxed, because the start (a warm start after ``b`` changed, say) may violate the
equalities; from then on every ``x_k`` is a combination of KKT solutions for the same
``b``, so ``A x = b`` holds at every iterate. After each step, safeguarded Anderson
acceleration may extrapolate ``(z, y)`` (see :func:`_anderson`). Everything here works
on the scaled problem (see :mod:`fccqp.scaling`); residuals and tolerances are unscaled.
"""

import time
from typing import NamedTuple

import numpy as np
from numba import njit, objmode

from fccqp import kkt, restoration, schur
from fccqp.projections import project_cone_block, project_constraint_set

SOLVED, SOLVED_INACCURATE, MAX_ITER, TIME_LIMIT, PRIMAL_INFEASIBLE, DUAL_INFEASIBLE = range(1, 7)
FULL, REDUCED, SCHUR = range(3)
"""Forms of the x-update (``w.reduced``): full KKT solves; the reduced iteration with the
LDL' backend; the reduced iteration with the Schur-complement backend."""
NOT_CONVEX = -1
"""Kernel code: the KKT inertia shows that P is not positive semidefinite."""
INACCURATE_FACTOR = 10.0
"""A budget-stopped iterate within this multiple of the tolerances is 'inaccurate'."""
AA_MAX_REJECTIONS = 3
"""Anderson steps rejected by the safeguard before a run gives up accelerating."""
AA_REGULARIZATION = 1e-8
"""Tikhonov weight of Anderson's least-squares problem, relative to its largest diagonal."""
RHO_MIN, RHO_MAX = 1e-6, 1e6
"""Range of the adaptive rho."""
REDUCED_COST = 0.5
"""The reduced iteration is used when ``REDUCED_COST * s`` fits in the iteration budget:
tabulating ``s`` columns costs about ``s / 4`` single KKT solves (measured at KKT sizes
84 and 192), each iteration then saves about one; 0.5 leaves a factor 2 of margin."""
FIXED_RHO_SCALE = 1e3
"""rho multiplier on entries with lb == ub, which act as equalities (as in OSQP)."""
EQUALITY_START_STEPS = 3
"""Proximal steps of the cold start's equality-constrained QP (see _equality_qp_start)."""
RESTORED_EQUALITY = 1e-7
"""A restored point is kept only if its primal residual is below this times its scale:
otherwise the other entries could not absorb the pinning. Refinement aims at 1e-13, but
an ill-conditioned ``W_TT`` (condition 1e8 on solo12) costs digits."""
EQUALITY_START_LIMIT = 1e-3
"""Cold start falls back to the origin when sigma * ||x_eq|| exceeds this * max(1, ||q||):
the equality-constrained QP is then unbounded but for sigma, and its solution useless."""


class ScaledProblem(NamedTuple):
    """Problem data after equilibration; bounds and cones act on ``x[constrained]``."""

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    constrained: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    cones: tuple
    D: np.ndarray
    E: np.ndarray
    c: float


class Workspace(NamedTuple):
    """Iterates, factorization and scratch arrays, reused across solves."""

    K: np.ndarray
    ipiv: np.ndarray
    work: np.ndarray
    rhs: np.ndarray
    sol: np.ndarray
    residual: np.ndarray
    x: np.ndarray
    nu: np.ndarray
    z: np.ndarray
    y: np.ndarray
    x_prev: np.ndarray
    nu_prev: np.ndarray
    z_prev: np.ndarray
    y_prev: np.ndarray
    rho_vec: np.ndarray
    rho_scale: np.ndarray
    relaxed: np.ndarray
    log: np.ndarray
    aa_dg: np.ndarray
    aa_df: np.ndarray
    aa_g: np.ndarray
    aa_f: np.ndarray
    aa_plain: np.ndarray
    aa_counts: np.ndarray
    reduced: np.ndarray
    factored_rho: np.ndarray
    L: np.ndarray
    LS: np.ndarray
    Y: np.ndarray
    order: np.ndarray
    W: np.ndarray
    W_S: np.ndarray
    base: np.ndarray
    v: np.ndarray
    v_prev: np.ndarray
    u: np.ndarray
    u_prev: np.ndarray


class Params(NamedTuple):
    """Scalar settings of one run of :func:`run`."""

    rho: float
    sigma: float
    alpha: float
    eps_abs: float
    eps_rel: float
    eps_prim_inf: float
    eps_dual_inf: float
    max_iter: int
    check_termination: int
    adaptive_rho: bool
    adaptive_rho_interval: int
    adaptive_rho_tolerance: float
    anderson_memory: int
    time_limit: float
    start_time: float
    cold_start: bool
    factorize: bool
    restore_feasibility: bool


@njit(cache=True)
def _now():
    with objmode(now="float64"):
        now = time.perf_counter()
    return now


@njit(cache=True)
def _inf_norm(v):
    out = 0.0
    for i in range(v.shape[0]):
        out = max(out, abs(v[i]))
    return out


@njit(cache=True)
def _factor_kkt(p, w, sigma):
    kkt.assemble(p.P, p.A, sigma, p.constrained, w.rho_vec, w.K)
    return kkt.factor(w.K, w.ipiv, w.work) == p.A.shape[0]


@njit(cache=True)
def _solve_x(p, w, sigma):
    """Solve the KKT system for ``w.rhs`` into ``w.sol``, with the backend factored last."""
    if w.reduced[0] == SCHUR:
        schur.solve_refined(
            w.L, w.LS, p.P, p.A, p.E, w.order, p.constrained, w.rho_vec, w.rhs, w.sol
        )
    else:
        kkt.solve_refined(
            w.K, w.ipiv, p.P, p.A, p.E, sigma, p.constrained, w.rho_vec, w.rhs, w.sol,
            w.residual,
        )


@njit(cache=True)
def residuals(p, w):
    """Unscaled primal and dual residuals and tolerance scales, plus their scaled versions.

    Returns ``(prim, dual, prim_scale, dual_scale, prim_s, dual_s, prim_scale_s,
    dual_scale_s)``: a residual passes when ``res <= eps_abs + eps_rel * scale``.
    """
    n = p.P.shape[0]
    D, E, c = p.D, p.E, p.c
    prim = prim_scale = prim_s = prim_scale_s = 0.0
    if p.A.shape[0] > 0:
        Ax = p.A @ w.x
        for i in range(Ax.shape[0]):
            prim = max(prim, abs(Ax[i] - p.b[i]) / E[i])
            prim_scale = max(prim_scale, abs(Ax[i]) / E[i], abs(p.b[i]) / E[i])
            prim_s = max(prim_s, abs(Ax[i] - p.b[i]))
            prim_scale_s = max(prim_scale_s, abs(Ax[i]), abs(p.b[i]))
        ATnu = p.A.T @ w.nu
    else:
        ATnu = np.zeros(n)
    for j in range(p.constrained.shape[0]):
        i = p.constrained[j]
        xs, zs = w.x[i], w.z[j]
        prim = max(prim, abs(xs - zs) * D[i])
        prim_scale = max(prim_scale, abs(xs) * D[i], abs(zs) * D[i])
        prim_s = max(prim_s, abs(xs - zs))
        prim_scale_s = max(prim_scale_s, abs(xs), abs(zs))
    Px = p.P @ w.x
    grad = Px + p.q + ATnu
    dual_scale = dual_scale_s = 0.0
    for i in range(n):
        scale = 1.0 / (c * D[i])
        dual_scale = max(dual_scale, abs(Px[i]) * scale, abs(p.q[i]) * scale, abs(ATnu[i]) * scale)
        dual_scale_s = max(dual_scale_s, abs(Px[i]), abs(p.q[i]), abs(ATnu[i]))
    for j in range(p.constrained.shape[0]):
        i = p.constrained[j]
        grad[i] += w.y[j]
        dual_scale = max(dual_scale, abs(w.y[j]) / (c * D[i]))
        dual_scale_s = max(dual_scale_s, abs(w.y[j]))
    dual = dual_s = 0.0
    for i in range(n):
        dual = max(dual, abs(grad[i]) / (c * D[i]))
        dual_s = max(dual_s, abs(grad[i]))
    return prim, dual, prim_scale, dual_scale, prim_s, dual_s, prim_scale_s, dual_scale_s


@njit(cache=True)
def is_primal_infeasible(p, w, eps):
    """Test ``(d_nu, d_y)`` of the last step as a Farkas certificate.

    ``d_y`` is first projected onto the polar of the recession cone of C (so that the
    support function is finite); the certificate needs ``A'd_nu + d_y`` (on S) to be
    small and ``b'd_nu + sigma_C(d_y) < 0`` relative to ``||(d_nu, d_y)||``.
    """
    n = p.P.shape[0]
    s = p.constrained.shape[0]
    d_nu = w.nu - w.nu_prev
    d_y = w.y - w.y_prev
    kind, offset, dim, mu, normal = p.cones
    in_cone = np.zeros(s, dtype=np.bool_)
    for k in range(kind.shape[0]):
        a, e = offset[k], offset[k] + dim[k]
        in_cone[a:e] = True
        projected = np.empty(e - a)
        project_cone_block(d_y[a:e], kind[k], mu[k], normal[k], projected)
        d_y[a:e] -= projected
    support = 0.0
    for j in range(s):
        if in_cone[j]:
            continue
        if p.hi[j] == np.inf:
            d_y[j] = min(d_y[j], 0.0)
        if p.lo[j] == -np.inf:
            d_y[j] = max(d_y[j], 0.0)
        if d_y[j] > 0:
            support += p.hi[j] * d_y[j]
        elif d_y[j] < 0:
            support += p.lo[j] * d_y[j]
    norm = 0.0
    for i in range(d_nu.shape[0]):
        norm = max(norm, abs(d_nu[i] * p.E[i]))
    for j in range(s):
        norm = max(norm, abs(d_y[j] / p.D[p.constrained[j]]))
    if norm <= 1e-300 or p.b @ d_nu + support >= -eps * norm:
        return False
    lhs = p.A.T @ d_nu if p.A.shape[0] > 0 else np.zeros(n)
    for j in range(s):
        lhs[p.constrained[j]] += d_y[j]
    for i in range(n):
        if abs(lhs[i] / p.D[i]) > eps * norm:
            return False
    return True


@njit(cache=True)
def is_equality_inconsistent(p, w, eps):
    """Test the equality residual ``r = b - A x`` as a certificate that ``A x = b`` has no solution.

    ``x`` is a KKT solution of the regularized system, so when the equalities are
    inconsistent ``r`` is their least-squares residual: ``A'r = 0`` and ``b'r = ||r||^2 > 0``.
    """
    if p.A.shape[0] == 0:
        return False
    r = p.b - p.A @ w.x
    norm = 0.0
    for i in range(r.shape[0]):
        norm = max(norm, abs(r[i] * p.E[i]))
    ATr = p.A.T @ r
    for i in range(ATr.shape[0]):
        if abs(ATr[i] / p.D[i]) > eps * norm:
            return False
    return p.b @ r > eps * norm


@njit(cache=True)
def is_dual_infeasible(p, w, eps):
    """Test the last step ``dx`` as an unbounded direction.

    Needs ``P dx ~ 0``, ``q'dx < 0``, ``A dx ~ 0`` and ``dx_S`` in the recession cone
    of C, all relative to ``||dx||``.
    """
    dx = w.x - w.x_prev
    norm = 0.0
    for i in range(dx.shape[0]):
        norm = max(norm, abs(dx[i] * p.D[i]))
    if norm <= 1e-300:
        return False
    tol = eps * norm
    if p.q @ dx / p.c >= -tol:
        return False
    Pdx = p.P @ dx
    for i in range(dx.shape[0]):
        if abs(Pdx[i] / (p.c * p.D[i])) > tol:
            return False
    if p.A.shape[0] > 0:
        Adx = p.A @ dx
        for i in range(Adx.shape[0]):
            if abs(Adx[i] / p.E[i]) > tol:
                return False
    for j in range(p.constrained.shape[0]):
        i = p.constrained[j]
        step = dx[i] * p.D[i]
        if (p.hi[j] < np.inf and step > tol) or (p.lo[j] > -np.inf and step < -tol):
            return False
    kind, offset, dim, mu, normal = p.cones
    for k in range(kind.shape[0]):
        a, e = offset[k], offset[k] + dim[k]
        block = np.empty(e - a)
        for t in range(a, e):
            block[t - a] = dx[p.constrained[t]]
        projected = np.empty(e - a)
        project_cone_block(block, kind[k], mu[k], normal[k], projected)
        scale = p.D[p.constrained[a]]
        if _inf_norm(block - projected) * scale > tol:
            return False
    return True


@njit(cache=True)
def _equality_qp_start(p, w, sigma):
    """Paper's cold start: ``x`` solves the QP with equalities only, ``z = P_C(x_S)``, ``y = 0``.

    The factorization carries the regularization ``sigma I``; a few proximal steps
    (``x_{j+1} = argmin f + sigma/2 ||x - x_j||^2`` on the same factorization) remove
    its bias, so that an optimum with no active constraint is recognised at once.
    Returns False if the KKT inertia shows that P is not positive semidefinite.
    """
    n = p.P.shape[0]
    w.rho_vec[:] = 0.0
    w.factored_rho[0] = -1.0  # the KKT matrix now holds no rho factorization
    w.reduced[0] = FULL
    if not _factor_kkt(p, w, sigma):
        return False
    w.x[:] = 0.0
    w.rhs[n:] = p.b
    for _ in range(EQUALITY_START_STEPS):
        w.rhs[:n] = sigma * w.x - p.q
        _solve_x(p, w, sigma)
        w.x[:] = w.sol[:n]
    w.nu[:] = w.sol[n:]
    if sigma * _inf_norm(w.x) > EQUALITY_START_LIMIT * max(1.0, _inf_norm(p.q)):
        w.x[:] = 0.0
        w.nu[:] = 0.0
    for j in range(p.constrained.shape[0]):
        w.relaxed[j] = w.x[p.constrained[j]]
    project_constraint_set(w.relaxed, p.lo, p.hi, p.cones, w.z)
    w.y[:] = 0.0
    return True


@njit(cache=True)
def _update_rho(rho, prim_s, dual_s, prim_scale_s, dual_scale_s, tolerance):
    """OSQP's rule: rho *= sqrt(relative primal / relative dual residual), clipped."""
    ratio = (prim_s / max(prim_scale_s, 1e-30)) / max(dual_s / max(dual_scale_s, 1e-30), 1e-30)
    new_rho = min(max(rho * np.sqrt(ratio), RHO_MIN), RHO_MAX)
    if new_rho > rho * tolerance or new_rho < rho / tolerance:
        return new_rho
    return rho


@njit(cache=True)
def _admm_step(p, w, prm, relax_x):
    """One ADMM iteration from ``(x, z, y)`` in ``w``; the previous values go to ``*_prev``."""
    n = p.P.shape[0]
    s = p.constrained.shape[0]
    w.x_prev[:] = w.x
    w.nu_prev[:] = w.nu
    w.z_prev[:] = w.z
    w.y_prev[:] = w.y
    w.rhs[:n] = prm.sigma * w.x - p.q
    w.rhs[n:] = p.b
    for j in range(s):
        w.rhs[p.constrained[j]] += w.rho_vec[j] * w.z[j] - w.y[j]
    _solve_x(p, w, prm.sigma)
    for j in range(s):
        w.relaxed[j] = prm.alpha * w.sol[p.constrained[j]] + (1.0 - prm.alpha) * w.z_prev[j]
    alpha_x = prm.alpha if relax_x else 1.0
    for i in range(n):
        w.x[i] = alpha_x * w.sol[i] + (1.0 - alpha_x) * w.x_prev[i]
    w.nu[:] = w.sol[n:]
    for j in range(s):
        w.z[j] = w.relaxed[j] + w.y[j] / w.rho_vec[j]
    project_constraint_set(w.z, p.lo, p.hi, p.cones, w.z)
    for j in range(s):
        w.y[j] += w.rho_vec[j] * (w.relaxed[j] - w.z[j])


@njit(cache=True)
def _solve_small_spd(M, b):
    """Solve ``M x = b`` in place (``b`` becomes ``x``, ``M`` its Cholesky factor) for
    the tiny positive definite Gram matrix of Anderson acceleration; False if a pivot is
    not positive. At size 10 a loop beats LAPACK's call overhead: 0.5 us against 1.2 us
    (``dpotrf`` + ``dpotrs``) and 1.5 us (``np.linalg.solve``) through numba, and this
    runs at every iteration.
    """
    k = M.shape[0]
    for c in range(k):
        pivot = M[c, c]
        for t in range(c):
            pivot -= M[c, t] * M[c, t]
        if not pivot > 0.0:
            return False
        pivot = np.sqrt(pivot)
        M[c, c] = pivot
        for r in range(c + 1, k):
            value = M[r, c]
            for t in range(c):
                value -= M[r, t] * M[c, t]
            M[r, c] = value / pivot
    for r in range(k):
        value = b[r]
        for t in range(r):
            value -= M[r, t] * b[t]
        b[r] = value / M[r, r]
    for r in range(k - 1, -1, -1):
        value = b[r]
        for t in range(r + 1, k):
            value -= M[t, r] * b[t]
        b[r] = value / M[r, r]
    return True


@njit(cache=True)
def _anderson(w, capacity):
    """Type-II Anderson acceleration of the ADMM map ``g = (z, y/rho) -> T(g)``.

    The step just taken went from ``g = (z_prev, y_prev/rho)`` to ``T(g) = (z, y/rho)``,
    with fixed-point residual ``f = T(g) - g``. With the last differences ``dG, dF`` of
    ``g`` and ``f``, the next point is ``T(g) - (dG + dF) gamma``, ``gamma`` minimizing
    ``||f - dF gamma||``. Safeguard: when the step from an accelerated point has a larger
    residual than the step before it, the plain ``T`` of the previous point is restored
    and the memory cleared, and plain ADMM runs ``capacity`` steps before the next try
    (for the rest of the run after ``AA_MAX_REJECTIONS`` rejections). ``w.aa_counts``
    holds (pairs stored so far, previous point known, current point accelerated, steps
    left before accelerating again, rejections); zero it to reset.
    """
    s = w.z.shape[0]
    counts = w.aa_counts
    g = np.empty(2 * s)
    f = np.empty(2 * s)
    for j in range(s):
        g[j] = w.z_prev[j]
        g[s + j] = w.y_prev[j] / w.rho_vec[j]
        f[j] = w.z[j] - g[j]
        f[s + j] = w.y[j] / w.rho_vec[j] - g[s + j]
    f_norm = np.sqrt(f @ f)
    if counts[2] == 1 and f_norm > w.aa_plain[2 * s]:
        for j in range(s):
            w.z[j] = w.aa_plain[j]
            w.y[j] = w.aa_plain[s + j] * w.rho_vec[j]
        rejections = counts[4] + 1
        counts[:] = 0
        counts[4] = rejections
        # let plain ADMM run before trying again; after a few failures, for good
        counts[3] = capacity if rejections < AA_MAX_REJECTIONS else 1 << 62
        return
    if counts[3] > 0:
        counts[3] -= 1
        return
    if counts[1] == 1:
        slot = counts[0] % capacity
        w.aa_dg[slot] = g - w.aa_g
        w.aa_df[slot] = f - w.aa_f
        counts[0] += 1
    w.aa_g[:] = g
    w.aa_f[:] = f
    w.aa_plain[2 * s] = f_norm
    counts[1] = 1
    stored = min(counts[0], capacity)
    counts[2] = 0
    if stored == 0:
        return
    dF = w.aa_df[:stored]
    dG = w.aa_dg[:stored]
    gram = dF @ dF.T
    ridge = 0.0
    for i in range(stored):
        ridge = max(ridge, gram[i, i])
    for i in range(stored):
        gram[i, i] += AA_REGULARIZATION * ridge + 1e-300
    gamma = dF @ f
    if not _solve_small_spd(gram, gamma):
        return
    for j in range(s):
        w.aa_plain[j] = w.z[j]
        w.aa_plain[s + j] = w.y[j] / w.rho_vec[j]
        step_z = step_y = 0.0
        for i in range(stored):
            step_z += (dG[i, j] + dF[i, j]) * gamma[i]
            step_y += (dG[i, s + j] + dF[i, s + j]) * gamma[i]
        w.z[j] -= step_z
        w.y[j] -= step_y * w.rho_vec[j]
    counts[2] = 1


@njit(cache=True)
def _factor_reduced(p, w):
    """Factor the KKT matrix without sigma and tabulate its response on the constrained entries.

    When ``P + R`` is positive definite (the inertia says so), the x-update is
    ``(x~, nu) = base + W v`` with ``v = rho z - y`` and ``W`` the ``(n + m) x s`` block of
    the inverse on the constrained entries, so an iteration needs only ``x~_S = base_S
    + W_S v``, an ``s x s`` product, instead of an ``(n + m)``-sized KKT solve; ``x`` and
    ``nu`` are formed only when residuals are checked. The Schur-complement backend
    (:mod:`fccqp.schur`) is tried first, the LDL' one when ``A`` is rank-deficient.
    Returns False (no reduced form) when the inertia or the refinement of ``W`` fails.
    """
    if schur.factor(p.P, p.A, w.order, w.rho_vec, w.L, w.LS, w.Y):
        schur.unit_columns(w.L, w.LS, w.Y, w.order, w.W)
        w.reduced[0] = SCHUR
    else:
        w.reduced[0] = REDUCED
        if not _factor_kkt(p, w, 0.0):
            return False
        if not kkt.solve_unit_columns(
            w.K, w.ipiv, p.P, p.A, p.E, 0.0, p.constrained, w.rho_vec, p.constrained, w.W
        ):
            return False
    for j in range(p.constrained.shape[0]):
        w.W_S[j] = w.W[p.constrained[j]]
    return True


@njit(cache=True)
def _reduced_budget(p, prm, iteration):
    """Solves the reduced form's table can save: the iterations left, plus, when the
    result will be restored, the columns the restoration would otherwise compute."""
    restoring = p.constrained.shape[0] if prm.restore_feasibility else 0
    return prm.max_iter - iteration + restoring


@njit(cache=True)
def _factor(p, w, rho, sigma, budget):
    """Factor for the current rho, in reduced form when it pays and ``P + R`` allows it.

    The reduced form costs ``s`` extra right-hand sides up front and saves one solve
    per iteration, so it is tried when ``budget`` (see :func:`_reduced_budget`) covers
    that (``REDUCED_COST``) and the constrained entries are at most half the KKT size. Records
    the form in ``w.reduced`` and ``rho`` in ``w.factored_rho`` (what a later solve with
    the same matrices may reuse); returns the number of factorizations, negated when
    the inertia shows that P is not positive semidefinite.
    """
    s = p.constrained.shape[0]
    count = 0
    w.factored_rho[0] = rho
    if 2 * s <= p.P.shape[0] + p.A.shape[0] and REDUCED_COST * s <= budget:
        count += 1
        if _factor_reduced(p, w):
            return count
    w.reduced[0] = FULL
    count += 1
    return count if _factor_kkt(p, w, sigma) else -count


@njit(cache=True)
def _reduced_base(p, w):
    """``base``: the x-update's response to ``(-q, b)`` alone."""
    n = p.P.shape[0]
    w.rhs[:n] = -p.q
    w.rhs[n:] = p.b
    _solve_x(p, w, 0.0)
    w.base[:] = w.sol


@njit(cache=True)
def _reduced_step(p, w, prm, relax_x):
    """One ADMM iteration in reduced form: the update of :func:`_admm_step` with
    ``sigma = 0``, ``x = base + W u`` kept implicit through ``u``."""
    s = p.constrained.shape[0]
    w.z_prev[:] = w.z
    w.y_prev[:] = w.y
    w.v_prev[:] = w.v
    w.u_prev[:] = w.u
    for j in range(s):
        w.v[j] = w.rho_vec[j] * w.z[j] - w.y[j]
    x_S = w.W_S @ w.v
    alpha_x = prm.alpha if relax_x else 1.0
    for j in range(s):
        x_new = w.base[p.constrained[j]] + x_S[j]
        w.relaxed[j] = prm.alpha * x_new + (1.0 - prm.alpha) * w.z_prev[j]
        w.u[j] = alpha_x * w.v[j] + (1.0 - alpha_x) * w.u_prev[j]
        w.z[j] = w.relaxed[j] + w.y[j] / w.rho_vec[j]
    project_constraint_set(w.z, p.lo, p.hi, p.cones, w.z)
    for j in range(s):
        w.y[j] += w.rho_vec[j] * (w.relaxed[j] - w.z[j])


@njit(cache=True)
def _near_convergence(p, w, eps_p, eps_d):
    """Cheap gate before a residual check in the reduced form, in ``O(s^2)``.

    ``(x, nu) = base + W u`` satisfies ``P x + q + A'nu = E_S (u - R x_S)`` (the KKT
    identity of ``base`` and ``W``), so with that ``nu`` the dual residual is ``u - R x_S
    + y`` on the constrained entries and zero elsewhere; the primal residual is ``x_S -
    z`` (``A x = b`` holds by construction). The iterate's ``nu`` comes from ``v``, not
    ``u``, and ``eps_p``, ``eps_d`` are from the last full check, so this only decides
    whether the full check (:func:`_materialize` + :func:`residuals`) is worth running.
    """
    x_S = w.W_S @ w.u
    for j in range(p.constrained.shape[0]):
        i = p.constrained[j]
        x = w.base[i] + x_S[j]
        if abs(x - w.z[j]) * p.D[i] > eps_p:
            return False
        if abs(w.u[j] - w.rho_vec[j] * x + w.y[j]) > eps_d * p.c * p.D[i]:
            return False
    return True


@njit(cache=True)
def _materialize(p, w):
    """Form ``x, nu`` and their previous values from ``base + W (u, v)``."""
    n = p.P.shape[0]
    w.x[:] = (w.base + w.W @ w.u)[:n]
    w.x_prev[:] = (w.base + w.W @ w.u_prev)[:n]
    w.nu[:] = (w.base + w.W @ w.v)[n:]
    w.nu_prev[:] = (w.base + w.W @ w.v_prev)[n:]


@njit(cache=True)
def _restore_equalities(p, w, sigma):
    """Remove the rounding that a combination of KKT solutions (``x = base + W u`` in
    the reduced form, a restoration) accumulates in ``A x = b``.

    One refined KKT solve for ``(0, b - A x)`` with the current factorization (``sigma``
    as factored): the returned ``x`` then satisfies the equalities to factorization
    accuracy.
    """
    n = p.P.shape[0]
    if p.A.shape[0] == 0:
        return
    w.rhs[:n] = 0.0
    w.rhs[n:] = p.b - p.A @ w.x
    _solve_x(p, w, sigma)
    w.x[:] += w.sol[:n]
    w.nu[:] += w.sol[n:]


@njit(cache=True)
def _budget_status(prim, dual, eps_p, eps_d, out_of_iterations):
    """Status of an iterate that stopped on a budget without meeting the tolerances."""
    if prim <= INACCURATE_FACTOR * eps_p and dual <= INACCURATE_FACTOR * eps_d:
        return SOLVED_INACCURATE
    return MAX_ITER if out_of_iterations else TIME_LIMIT


@njit(cache=True)
def _keep_restored(p, w, prm, reduced, status, iteration, prim, dual):
    """Replace the final iterate by its feasibility restoration (see :mod:`fccqp.restoration`).

    The restored point has its violating constrained entries pinned at their projection
    onto the box and the cones; its status comes from its own residuals, with the slack
    ``z`` set to its (feasible) ``x_S``. It is kept when its primal residual shows that
    the other entries absorbed the pinning (``RESTORED_EQUALITY``) and, if the iterate
    was solved, when it is solved too. Returns ``(status, prim, dual)`` of the point left
    in ``w``, whose equalities hold to factorization accuracy in either case.
    """
    x, nu, z = w.x.copy(), w.nu.copy(), w.z.copy()
    if restoration.restore(p, w, prm.sigma, reduced):
        _restore_equalities(p, w, 0.0 if reduced else prm.sigma)
        for j in range(z.shape[0]):
            w.z[j] = w.x[p.constrained[j]]
        project_constraint_set(w.z, p.lo, p.hi, p.cones, w.z)
        new_prim, new_dual, prim_scale, dual_scale = residuals(p, w)[:4]
        eps_p = prm.eps_abs + prm.eps_rel * prim_scale
        eps_d = prm.eps_abs + prm.eps_rel * dual_scale
        if new_prim <= eps_p and new_dual <= eps_d:
            new_status = SOLVED
        else:
            new_status = _budget_status(
                new_prim, new_dual, eps_p, eps_d, iteration >= prm.max_iter
            )
        exact = new_prim <= RESTORED_EQUALITY * max(1.0, prim_scale)
        if exact and (status != SOLVED or new_status == SOLVED):
            return new_status, new_prim, new_dual
    w.x[:] = x
    w.nu[:] = nu
    w.z[:] = z
    if reduced:
        _restore_equalities(p, w, 0.0)
    return status, prim, dual


@njit(cache=True)
def run(p, w, prm):
    """Run ADMM from the iterate in ``w`` (or a cold start); return a summary tuple.

    Returns ``(status, iterations, rho, prim, dual, factorizations)``;
    status ``NOT_CONVEX`` means the KKT inertia rejected P. ``w.log`` rows receive
    ``(iteration, prim, dual, rho)`` at each residual check, as long as there is room.
    """
    s = p.constrained.shape[0]
    rho = prm.rho
    factorizations = 0
    iteration = 0
    if prm.cold_start:
        if not _equality_qp_start(p, w, prm.sigma):
            return NOT_CONVEX, 0, rho, 0.0, 0.0, 1
        factorizations += 1
    prim, dual, prim_scale, dual_scale, prim_s, dual_s, prim_scale_s, dual_scale_s = residuals(p, w)
    eps_p = prm.eps_abs + prm.eps_rel * prim_scale
    eps_d = prm.eps_abs + prm.eps_rel * dual_scale
    if w.log.shape[0] > 0:
        w.log[0, 0], w.log[0, 1], w.log[0, 2], w.log[0, 3] = 0, prim, dual, rho
    if prm.cold_start and prim <= eps_p and dual <= eps_d:
        return SOLVED, 0, rho, prim, dual, factorizations
    for j in range(s):
        w.rho_vec[j] = rho * w.rho_scale[j]
    if prm.factorize or prm.cold_start:
        count = _factor(p, w, rho, prm.sigma, _reduced_budget(p, prm, 0))
        if count < 0:
            return NOT_CONVEX, 0, rho, prim, dual, factorizations - count
        factorizations += count
    reduced = w.reduced[0] != FULL
    if reduced:
        _reduced_base(p, w)
        for j in range(s):
            w.v[j] = w.rho_vec[j] * w.z[j] - w.y[j]
        w.u[:] = w.v
    status = 0
    timed = prm.time_limit < np.inf
    w.aa_counts[:] = 0
    fresh = True  # the next step starts a run of KKT solutions: do not relax x
    while status == 0:
        iteration += 1
        if reduced:
            _reduced_step(p, w, prm, not fresh)
        else:
            _admm_step(p, w, prm, not fresh)
        fresh = False
        last = iteration >= prm.max_iter or (timed and _now() - prm.start_time >= prm.time_limit)
        periodic = iteration % prm.adaptive_rho_interval == 0
        adapt = prm.adaptive_rho and periodic
        check = iteration % prm.check_termination == 0 or last or adapt
        if check and reduced and not (last or periodic):
            # a scheduled full check (and with it infeasibility detection) still runs
            # every adaptive_rho_interval iterations
            check = _near_convergence(p, w, eps_p, eps_d)
        if check:
            if reduced:
                _materialize(p, w)
            prim, dual, prim_scale, dual_scale, prim_s, dual_s, prim_scale_s, dual_scale_s = (
                residuals(p, w)
            )
            eps_p = prm.eps_abs + prm.eps_rel * prim_scale
            eps_d = prm.eps_abs + prm.eps_rel * dual_scale
            if iteration < w.log.shape[0]:
                row = w.log[iteration]
                row[0], row[1], row[2], row[3] = iteration, prim, dual, rho
            if prim <= eps_p and dual <= eps_d:
                status = SOLVED
            elif is_primal_infeasible(p, w, prm.eps_prim_inf) or (
                prim > eps_p and is_equality_inconsistent(p, w, prm.eps_prim_inf)
            ):
                status = PRIMAL_INFEASIBLE
            elif is_dual_infeasible(p, w, prm.eps_dual_inf):
                status = DUAL_INFEASIBLE
            elif last:
                status = _budget_status(prim, dual, eps_p, eps_d, iteration >= prm.max_iter)
            elif adapt:
                new_rho = _update_rho(
                    rho, prim_s, dual_s, prim_scale_s, dual_scale_s, prm.adaptive_rho_tolerance
                )
                if new_rho != rho:
                    rho = new_rho
                    for j in range(s):
                        w.rho_vec[j] = rho * w.rho_scale[j]
                    count = _factor(p, w, rho, prm.sigma, _reduced_budget(p, prm, iteration))
                    if count < 0:
                        return NOT_CONVEX, iteration, rho, prim, dual, factorizations - count
                    factorizations += count
                    reduced = w.reduced[0] != FULL
                    if reduced:
                        _reduced_base(p, w)
                    fresh = True
                    w.aa_counts[:3] = 0
        if status == 0 and prm.anderson_memory > 0:
            _anderson(w, prm.anderson_memory)
    if prm.restore_feasibility and status <= TIME_LIMIT:
        status, prim, dual = _keep_restored(p, w, prm, reduced, status, iteration, prim, dual)
    elif reduced:
        _restore_equalities(p, w, 0.0)
    return status, iteration, rho, prim, dual, factorizations
