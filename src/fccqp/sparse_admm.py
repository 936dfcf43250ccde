"""The sparse path: fccqp's ADMM on ``scipy.sparse`` data, for problems too large for
the dense core.

The dense core (:mod:`fccqp.admm`) factors an ``(n + m)``-square dense KKT matrix,
which stops paying (and then fitting in memory) beyond a few thousand rows.
:class:`fccqp.Solver` sends larger problems here, and any problem when
``Settings.kkt_backend == "sparse"``. The algorithm is the dense core's ``ldl_full``
form (docs/algorithm.md), step for step:

    (x~, nu) = argmin_{A x = b} 1/2 x'Px + q'x + sigma/2 ||x - x_k||^2
                                 + rho/2 ||x_S - z_k + y_k / rho||^2      (one KKT solve)
    x_S^r    = alpha x~_S + (1 - alpha) z_k
    z_{k+1}  = P_C(x_S^r + y_k / rho)
    y_{k+1}  = y_k + rho (x_S^r - z_{k+1})
    x_{k+1}  = alpha x~ + (1 - alpha) x_k     (the first step of a run unrelaxed)

with the equalities as hard rows of the KKT system (:mod:`fccqp.sparse_kkt`, ``qdldl``
with refinement), so every iterate satisfies ``A x = b`` to factorization accuracy.
The same Ruiz scaling, cold start (the equality-constrained QP, its inertia
certifying convexity), residuals and termination test, adaptive rho, safeguarded
Anderson acceleration, infeasibility certificates (:mod:`fccqp.sparse_checks`),
polishing with its acceptance test and retries (:mod:`fccqp.sparse_polish`), and the
status settled on the returned point in the user's units. Each iteration is a few
vectorized numpy operations and one sparse triangular solve pair; constants are the
dense core's (imported from :mod:`fccqp.admm`, :mod:`fccqp.tuning` and :mod:`fccqp.anderson`).

Not on this path: the reduced iteration, the Schur backend and the warm polish in the
table's coordinates (dense-only accelerations), and the feasibility restoration after
a budget stop (``restore_feasibility`` has no effect: a budget-stopped point keeps
``A x = b`` but may leave the box and the cones, and its status says so).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fccqp.admm import RhoTrial
from fccqp.settings import Settings
from fccqp.sparse_checks import (
    Residuals,
    dot,
    dual_infeasible,
    equality_inconsistent,
    iterate_residuals,
    primal_infeasible,
    user_residuals,
)
from fccqp.sparse_kkt import FactorizationError, SparseKKT
from fccqp.sparse_polish import multiplier_violation, polish
from fccqp.sparse_problem import Scaled, SparseData, equilibrate
from fccqp.status import Status
from fccqp.tuning import (
    EQUALITY_EXACT,
    EQUALITY_SLACK,
    EQUALITY_START_LIMIT,
    EQUALITY_START_STEPS,
    FIXED_RHO_SCALE,
    INACCURATE_FACTOR,
    LOG_INTERVAL,
    MAX_REJECTIONS,
    POLISH_EXACT,
    POLISH_GATE,
    POLISH_RETRIES,
    REGULARIZATION,
    RESERVE_DECAY,
    RHO_MAX,
    RHO_MIN,
    STALL_FACTOR,
    STALLS,
)

BACKEND = "sparse"
"""``Result.backend`` of a solve on this path (and the ``Settings.kkt_backend`` that
forces it)."""

_BUDGETS = (Status.SOLVED, Status.SOLVED_INACCURATE, Status.MAX_ITER_REACHED,
            Status.TIME_LIMIT_REACHED)
"""The statuses of a run that ended with a point (not a certificate or an error)."""


class NotConvexError(ValueError):
    """The inertia of the KKT matrix shows negative curvature on the null space of ``A``."""


@dataclass
class Outcome:
    """What a sparse solve returns to :class:`fccqp.Solver`, which builds the Result."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    status: Status
    residuals: Residuals
    iterations: int
    rho: float
    factorizations: int
    setup_time: float
    polished: bool
    certificate: np.ndarray | None
    log: list[tuple[float, ...]]


class Anderson:
    """Safeguarded type-II Anderson acceleration of ``g = (z, y/rho) -> T(g)``, as
    :mod:`fccqp.anderson` (its docstring gives the rule), on numpy vectors.

    The differences live in ring buffers and their Gram matrix is updated one row per
    step (``capacity`` products of ``2 s`` entries instead of ``capacity^2``); products
    go through :func:`fccqp.sparse_checks.dot`'s BLAS-free kernels."""

    def __init__(self, capacity: int, s: int) -> None:
        self.capacity = capacity
        self.dg = np.zeros((capacity, 2 * s))
        self.df = np.zeros((capacity, 2 * s))
        self.gram = np.zeros((capacity, capacity))
        self.reset(False)

    def reset(self, keep_rejections: bool) -> None:
        """Forget the memory (after a change of rho, or at the start of a run)."""
        self.stored = 0
        self.g = self.f = self.plain = None
        self.plain_norm = math.inf
        self.accelerated = False
        if not keep_rejections:
            self.wait = 0
            self.rejections = 0

    def step(self, z_prev: np.ndarray, y_prev: np.ndarray, z: np.ndarray, y: np.ndarray,
             rho_vec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Record the step ``(z_prev, y_prev) -> (z, y)`` and return the next point: the
        extrapolated one, the plain ``(z, y)``, or, when the step from an accelerated
        point made the residual grow, the plain point that acceleration replaced."""
        g = np.concatenate([z_prev, y_prev / rho_vec])
        f = np.concatenate([z, y / rho_vec]) - g
        f_norm = math.sqrt(dot(f, f))
        s, cap = z.shape[0], self.capacity
        if self.accelerated and f_norm > self.plain_norm:
            z, y = self.plain[:s].copy(), self.plain[s:] * rho_vec
            self.rejections += 1
            self.reset(True)
            self.wait = cap if self.rejections < MAX_REJECTIONS else 1 << 62
            return z, y
        if self.wait > 0:
            self.wait -= 1
            return z, y
        if self.g is not None:
            slot = self.stored % cap
            self.dg[slot] = g - self.g
            self.df[slot] = f - self.f
            self.stored += 1
            k = min(self.stored, cap)
            row = np.einsum("ij,j->i", self.df[:k], self.df[slot])
            self.gram[slot, :k] = row
            self.gram[:k, slot] = row
        self.g, self.f, self.plain_norm = g, f, f_norm
        self.accelerated = False
        k = min(self.stored, cap)
        if k == 0:
            return z, y
        gram = self.gram[:k, :k].copy()
        gram[np.diag_indices(k)] += REGULARIZATION * float(gram.diagonal().max()) + 1e-300
        try:
            factor = np.linalg.cholesky(gram)
        except np.linalg.LinAlgError:
            return z, y
        rhs = np.einsum("ij,j->i", self.df[:k], f)
        gamma = np.linalg.solve(factor.T, np.linalg.solve(factor, rhs))
        self.plain = np.concatenate([z, y / rho_vec])
        extrapolated = self.plain - np.einsum("ij,i->j", self.dg[:k] + self.df[:k], gamma)
        self.accelerated = True
        return extrapolated[:s], extrapolated[s:] * rho_vec


class SparseWorkspace:
    """What the sparse path keeps between the solves of one :class:`fccqp.Solver`: the
    previous solution (for a warm start), the scaling and the KKT factorization while
    ``P``, ``A`` and the structure stay the same, and the recent cost of the final
    polish (for a time budget)."""

    def __init__(self, settings: Settings) -> None:
        self.settings = settings
        self.key = None          # structure and matrices of the data scaled last
        self.scaled: Scaled | None = None
        self.kkt: SparseKKT | None = None
        self.factored_rho: float | None = None   # rho of kkt's factorization, None: none
        self.certified = False
        self.previous: tuple[np.ndarray, ...] | None = None   # (x, y, z) of the last solve
        self.previous_rho = settings.rho
        self.previous_polished = False
        self.final_reserve = 0.0

    def forget(self) -> None:
        """Drop the previous solution: the next solve starts cold."""
        self.previous = None

    @staticmethod
    def _key(data: SparseData) -> tuple:
        """Everything the scaling and the KKT matrix depend on, as bytes."""
        P, A, cones = data.P, data.A, data.cones
        return (P.shape, A.shape, P.indptr.tobytes(), P.indices.tobytes(), P.data.tobytes(),
                A.indptr.tobytes(), A.indices.tobytes(), A.data.tobytes(),
                data.constrained.tobytes(), data.fixed.tobytes(), cones.kind.tobytes(),
                cones.offset.tobytes(), cones.dim.tobytes())

    def solve(self, data: SparseData, x0: np.ndarray | None, start: float) -> Outcome:
        """Scale (or reuse the scaling), start, run ADMM and settle the status.

        Raises :class:`NotConvexError` when the KKT inertia shows that the QP is not
        convex (the workspace then forgets everything).
        """
        settings = self.settings
        key = self._key(data)
        structure_kept = self.key is not None and self.key[:2] == key[:2] and \
            self.key[8:] == key[8:]
        if key == self.key:
            scaled = equilibrate(data, settings.scaling, self.scaled)
        else:
            scaled = equilibrate(data, settings.scaling)
            self.kkt = SparseKKT(scaled.P, scaled.A, scaled.constrained, scaled.E)
            self.factored_rho, self.certified = None, False
        if not structure_kept:
            self.previous = None
        self.key, self.scaled = key, scaled
        warm = settings.warm_start and self.previous is not None and x0 is None
        run = _Run(self, data, scaled, self.previous_rho if warm else settings.rho,
                   warm and self.previous_polished)
        if x0 is not None:
            run.start_from_guess(x0)
        elif warm:
            run.start_from_previous(*self.previous, self.previous_rho)
        try:
            outcome = run.execute(cold=x0 is None and not warm, start=start)
        except NotConvexError:
            self.key = self.scaled = self.kkt = self.previous = None
            self.factored_rho, self.certified = None, False
            raise
        if run.iterated:   # learn what the final step after the iterations costs
            self.final_reserve = max(RESERVE_DECAY * self.final_reserve,
                                     time.perf_counter() - run.iterations_end)
        keep = outcome.residuals.finite and not outcome.status.is_infeasible()
        # copies: the Result hands the arrays to the caller, who may write into them
        self.previous = (outcome.x.copy(), outcome.y.copy(), outcome.z.copy()) if keep else None
        self.previous_rho = outcome.rho
        self.previous_polished = keep and outcome.polished
        return outcome


class _Run:
    """One solve on the sparse path: the scaled iterate and the loop over it."""

    def __init__(self, workspace: SparseWorkspace, data: SparseData, scaled: Scaled,
                 rho: float, from_polished: bool) -> None:
        self.w, self.data, self.p = workspace, data, scaled
        self.o = workspace.settings
        p = scaled
        self.rho = rho
        self.rho_scale = np.where(data.fixed, FIXED_RHO_SCALE, 1.0)
        self.rho_vec = rho * self.rho_scale
        self.x, self.nu = np.zeros(p.n), np.zeros(p.m)
        self.z, self.y = np.zeros(p.s), np.zeros(p.s)
        self.from_polished = from_polished   # warm polish first, as the dense core does
        self.factorizations = 0
        self.tighten = 1.0
        self.certificate: np.ndarray | None = None
        self.log: list[tuple[float, ...]] = []
        self.iterated = False
        self.iteration = 0   # iterations taken so far
        self.iterations_end = 0.0
        self.res = Residuals()

    # ------------------------------------------------------------ the start

    def _remember(self) -> None:
        """Make the current iterate the 'previous' one of the next step."""
        self.x_prev, self.nu_prev = self.x.copy(), self.nu.copy()
        self.z_prev, self.y_prev = self.z.copy(), self.y.copy()

    def start_from_guess(self, x0: np.ndarray) -> None:
        """Primal guess ``x0`` (user's units), duals zero, slack its projection."""
        p = self.p
        self.x = x0 / p.D
        self.z = p.project(self.x[p.constrained])
        self._remember()

    def start_from_previous(self, x: np.ndarray, y: np.ndarray, z: np.ndarray,
                            rho: float) -> None:
        """Warm start from an unscaled solution, as :func:`fccqp.scaling.scale_start`:
        the slack is ``P_C(x_S + y_S / rho)``, what ADMM's z-update would produce."""
        p, S = self.p, self.p.constrained
        self.x = x / p.D
        self.nu = y * p.c / p.E
        self.y = z[S] * p.c * p.D[S]
        self.z = p.project(self.x[S] + self.y / max(rho, 1e-12))
        self._remember()

    def _factor(self, sigma: float, rho_vec: np.ndarray) -> int:
        """Factor the x-update's matrix; NotConvexError when its inertia has more than
        ``m`` negative pivots."""
        negative = self.w.kkt.factor(sigma, rho_vec)
        self.factorizations += 1
        if negative > self.p.m:
            raise NotConvexError(
                "the QP is not convex: P has negative curvature on the null space of A "
                f"(P is not positive semidefinite: the KKT matrix has {negative} negative "
                f"pivots, more than the {self.p.m} rows of A)")
        return negative

    def _equality_start(self) -> bool:
        """The paper's cold start (see ``fccqp.factorization.equality_start``): ``x``
        solves the QP with the equalities only, from a penalty-free factorization whose
        inertia certifies convexity, with ``EQUALITY_START_STEPS`` proximal steps to
        remove sigma's bias; when that QP is unbounded, ``direction`` keeps the last step
        and ``x`` is the point of ``A x = b`` with the least ``x'(P + sigma I)x``.
        Returns whether it was unbounded."""
        p, sigma = self.p, self.o.sigma
        n = p.n
        self._factor(sigma, np.zeros(p.s))
        self.w.certified, self.w.factored_rho = True, None
        x = np.zeros(n)
        rhs = np.concatenate([np.zeros(n), p.b])
        for _ in range(EQUALITY_START_STEPS):
            rhs[:n] = sigma * x - p.q
            sol = self.w.kkt.solve(rhs)
            self.direction = sol[:n] - x
            x = sol[:n]
        self.x, self.nu = x, sol[n:]
        unbounded = sigma * float(np.max(np.abs(x), initial=0.0)) > EQUALITY_START_LIMIT * max(
            1.0, float(np.max(np.abs(p.q), initial=0.0)))
        if unbounded:
            rhs[:n] = 0.0
            sol = self.w.kkt.solve(rhs)
            self.x, self.nu = sol[:n], np.zeros(p.m)
        self.z = p.project(self.x[p.constrained])
        self.y = np.zeros(p.s)
        self._remember()
        return unbounded

    def _factor_rho(self) -> None:
        """Factor for the current rho, certifying convexity first when the matrices are
        new (the penalty-free factorization, as the dense ``fccqp.factorization.factor``)."""
        if not self.w.certified:
            self._factor(self.o.sigma, np.zeros(self.p.s))
            self.w.certified = True
        self._factor(self.o.sigma, self.rho_vec)
        self.w.factored_rho = self.rho

    # ---------------------------------------------------------- the iteration

    def _step(self, relax_x: bool) -> None:
        """One ADMM iteration: x-update (a refined KKT solve), z- and y-updates."""
        p, o, S = self.p, self.o, self.p.constrained
        n = p.n
        self._remember()
        alpha = o.alpha
        alpha_x = alpha if relax_x else 1.0
        rhs = np.concatenate([o.sigma * self.x - p.q, p.b])
        rhs[S] += self.rho_vec * self.z - self.y
        sol = self.w.kkt.solve(rhs)
        relaxed = alpha * sol[S] + (1.0 - alpha) * self.z_prev
        self.x = alpha_x * sol[:n] + (1.0 - alpha_x) * self.x_prev
        self.nu = sol[n:]
        self.z = p.project(relaxed + self.y / self.rho_vec)
        self.y = self.y + self.rho_vec * (relaxed - self.z)

    def _residuals(self) -> None:
        self.res = iterate_residuals(self.p, self.x, self.nu, self.z, self.y)

    def _classify(self, iteration: int, stopped: bool) -> Status:
        """Status of the point from its residuals alone (see ``fccqp.verdict.classify``)."""
        r, o = self.res, self.o
        if not r.finite:
            return Status.NUMERICAL_ERROR
        if r.within(o.eps_abs, o.eps_rel):
            return Status.SOLVED
        if r.within(o.eps_abs, o.eps_rel, INACCURATE_FACTOR):
            return Status.SOLVED_INACCURATE
        if iteration >= o.max_iter or not stopped:
            return Status.MAX_ITER_REACHED
        return Status.TIME_LIMIT_REACHED

    def _inconsistent(self) -> bool:
        self.certificate = equality_inconsistent(self.p, self.x, self.o.eps_prim_inf)
        return self.certificate is not None

    def _unbounded(self) -> bool:
        self.certificate = dual_infeasible(self.p, self.direction, self.o.eps_dual_inf)
        return self.certificate is not None

    def _check(self, iteration: int, last: bool) -> Status | None:
        """Termination and the infeasibility tests after the residuals of ``iteration``;
        None to go on."""
        r, o, p = self.res, self.o, self.p
        if not r.finite:
            return Status.NUMERICAL_ERROR
        if r.within(self.tighten * o.eps_abs, self.tighten * o.eps_rel):
            return Status.SOLVED
        self.certificate = primal_infeasible(p, self.x, self.nu - self.nu_prev,
                                             self.y - self.y_prev, o.eps_prim_inf)
        if self.certificate is not None:
            return Status.PRIMAL_INFEASIBLE
        if r.prim_eq > o.eps_abs + o.eps_rel * r.prim_eq_scale and self._inconsistent():
            return Status.PRIMAL_INFEASIBLE
        self.direction = self.x - self.x_prev
        if self._unbounded():
            return Status.DUAL_INFEASIBLE
        if last:
            return self._classify(iteration, True)
        return None

    def _new_rho(self, trial: RhoTrial) -> float:
        """OSQP's rule on the scaled residuals: ``rho sqrt(relative primal / relative
        dual)``, clipped, when it moves rho by more than the tolerance; a smaller move
        on trial as in the dense core (:class:`fccqp.rho_rule.RhoTrial`)."""
        r = self.res
        prim = r.prim_s / max(r.prim_scale_s, 1e-30)
        dual = r.dual_s / max(r.dual_scale_s, 1e-30)
        new_rho = min(max(self.rho * math.sqrt(prim / max(dual, 1e-30)), RHO_MIN), RHO_MAX)
        return trial.propose(self.rho, new_rho, max(prim, dual), self.o.adaptive_rho_tolerance)

    def _log(self, iteration: int) -> None:
        if self.o.verbose:
            r = self.res
            self.log.append((float(iteration), r.prim, r.dual, r.gap, self.rho))

    # ---------------------------------------------------------- polishing

    def _unscaled(self, x: np.ndarray, nu: np.ndarray,
                  y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(x, y, z)`` in the user's units (see :func:`fccqp.scaling.unscale`)."""
        p = self.p
        z = np.zeros(p.n)
        z[p.constrained] = y / (p.c * p.D[p.constrained])
        return x * p.D, nu * p.E / p.c, z

    def _keep_polished(self, status: Status, iteration: int,
                       solved_only: bool = False) -> tuple[bool, Status]:
        """Replace the iterate by its polished version when that passes the dense core's
        acceptance test (``fccqp.acceptance.keep_polished``): on the user's problem,
        primal feasible within the tolerance, multipliers in the normal cones of the
        guess, ``A x = b`` at factorization accuracy, and each residual and the gap no
        worse than the ADMM point's (or at the rounding of an exact solve); with
        ``solved_only``, solved. Returns (accepted, status)."""
        p, o = self.p, self.o
        polished = polish(p, self.x, self.nu, self.z, self.y, o.polish_refine_iter)
        if polished is None:
            return False, status
        plain = user_residuals(self.data, p, *self._unscaled(self.x, self.nu, self.y))
        point = self._unscaled(polished.x, polished.nu, polished.y)
        r = user_residuals(self.data, p, *point)
        tol_p = o.eps_abs + o.eps_rel * r.prim_scale
        tol_d = o.eps_abs + o.eps_rel * r.dual_scale
        tol_g = o.eps_abs + o.eps_rel * r.gap_scale
        accepted = (
            r.finite
            and r.prim_eq <= o.eps_abs + o.eps_rel * r.prim_eq_scale
            and r.prim_set <= o.eps_abs + o.eps_rel * r.prim_set_scale
            and multiplier_violation(p, polished.active, point[2]) <= POLISH_EXACT * tol_d
            and r.prim_eq <= max(EQUALITY_SLACK * plain.prim_eq,
                                 EQUALITY_EXACT * r.prim_eq_scale)
            and (r.prim <= plain.prim or r.prim <= POLISH_EXACT * tol_p)
            and (r.dual <= plain.dual or r.dual <= POLISH_EXACT * tol_d)
            and (r.gap <= plain.gap or r.gap <= POLISH_EXACT * tol_g)
            and not (solved_only and not r.within(o.eps_abs, o.eps_rel)))
        if not accepted:
            return False, status
        self.x, self.nu, self.y = polished.x, polished.nu, polished.y
        self.z = p.project(self.x[p.constrained])
        self.res = r
        new_status = self._classify(iteration, True)
        if new_status in (Status.SOLVED, Status.SOLVED_INACCURATE):
            status = new_status
        return True, status

    # ---------------------------------------------------------- the run

    def execute(self, cold: bool, start: float) -> Outcome:
        """Run from the start in place (or a cold start) and settle the outcome."""
        status, iterations, polished = self._iterate(cold, start)
        return self._finish(status, iterations, polished)

    def _iterate(self, cold: bool, start: float) -> tuple[Status, int, bool]:
        """The loop of ``fccqp.iteration.iterate`` for the full form; returns the
        run's status (before it is settled on the returned point), its iterations and
        whether the point is polished."""
        p, o = self.p, self.o
        self.setup_time = time.perf_counter() - start
        timed = math.isfinite(o.time_limit)
        deadline = o.time_limit - min(self.w.final_reserve, 0.5 * o.time_limit)
        unbounded = False
        self.direction = np.zeros(p.n)
        try:
            if cold or p.s == 0:
                unbounded = self._equality_start()
            self._residuals()
            self._log(0)
            r = self.res
            if unbounded and self._unbounded():
                return Status.DUAL_INFEASIBLE, 0, False
            if (cold or p.s == 0) and r.within(o.eps_abs, o.eps_rel) and not unbounded:
                if o.polish:   # the start carries sigma's bias where the cost is flat
                    polished, status = self._keep_polished(Status.SOLVED, 0)
                    return status, 0, polished
                return Status.SOLVED, 0, False
            if ((cold or p.s == 0) and r.prim_eq > o.eps_abs + o.eps_rel * r.prim_eq_scale
                    and self._inconsistent()):
                return Status.PRIMAL_INFEASIBLE, 0, False
            if p.s == 0:   # nothing to iterate: the equality-constrained QP was the answer
                status = self._classify(0, False)
                if o.polish and status in _BUDGETS:
                    polished, status = self._keep_polished(status, 0)
                    return status, 0, polished
                return status, 0, False
            if self.w.factored_rho != self.rho or cold:
                self._factor_rho()
            if self.from_polished and o.polish:
                polished, status = self._keep_polished(Status.SOLVED, 0, solved_only=True)
                if polished:
                    return Status.SOLVED, 0, True
            return self._loop(start, timed, deadline)
        except FactorizationError:   # a zero pivot: not quasi-definite (overflow, say)
            self.w.factored_rho = None
            return Status.NUMERICAL_ERROR, self.iteration, False

    def _loop(self, start: float, timed: bool, deadline: float) -> tuple[Status, int, bool]:
        """ADMM iterations until a status; then the final polish."""
        o = self.o
        anderson = Anderson(o.anderson_memory, self.p.s)
        accelerate = o.anderson_memory > 0
        periodic_prim, stalls, retries = math.inf, 0, 0
        iteration, polished_at, polished = 0, -1, False
        trial = RhoTrial()
        fresh = True   # the next step starts a run of KKT solutions: do not relax x
        status = None
        if timed and o.min_iter == 0 and time.perf_counter() - start >= deadline:
            status = self._classify(0, True)   # the setup spent the budget
        while status is None:
            iteration += 1
            self.iteration = iteration
            self._step(not fresh)
            fresh = False
            last = iteration >= o.max_iter or (
                timed and iteration >= o.min_iter and time.perf_counter() - start >= deadline)
            periodic = iteration % o.adaptive_rho_interval == 0
            adapt = o.adaptive_rho and periodic
            if iteration % o.check_termination == 0 or last or adapt:
                self._residuals()
                if iteration % LOG_INTERVAL == 0:
                    self._log(iteration)
                status = self._check(iteration, last)
                if (status is Status.SOLVED and o.polish and not last
                        and retries < POLISH_RETRIES):
                    polished_at = iteration
                    polished, status = self._keep_polished(status, iteration)
                    if not polished:   # go on, closer to the active set
                        retries += 1
                        self.tighten *= 0.1
                        status = None
                if status is None and periodic and accelerate:
                    # plain ADMM where the primal residual stalls far from tolerance:
                    # extrapolation hides the steady step that certifies infeasibility
                    r = self.res
                    if (r.prim > STALL_FACTOR * (o.eps_abs + o.eps_rel * r.prim_scale)
                            and r.prim > 0.5 * periodic_prim):
                        stalls += 1
                    else:
                        stalls = 0
                    accelerate = stalls < STALLS
                    periodic_prim = r.prim
                if status is None and adapt:
                    new_rho = self._new_rho(trial)
                    if new_rho != self.rho:
                        self.rho, self.rho_vec = new_rho, new_rho * self.rho_scale
                        self._factor_rho()
                        anderson.reset(True)
                        fresh = True
            if status is None and accelerate:
                self.z, self.y = anderson.step(self.z_prev, self.y_prev, self.z, self.y,
                                               self.rho_vec)
        self.iterated = True
        self.iterations_end = time.perf_counter()
        if (not polished and o.polish and status in _BUDGETS and polished_at != iteration
                and (not timed or self.res.within(o.eps_abs, o.eps_rel, POLISH_GATE))):
            polished, status = self._keep_polished(status, iteration)
        return status, iteration, polished

    def _finish(self, status: Status, iterations: int, polished: bool) -> Outcome:
        """Unscale, recompute the residuals of the returned point on the user's data and
        settle the status on them (as ``fccqp.scaled_run.unscaled_answer``)."""
        o = self.o
        x, y, z = self._unscaled(self.x, self.nu, self.y)
        r = user_residuals(self.data, self.p, x, y, z)
        if status in _BUDGETS:
            if r.within(o.eps_abs, o.eps_rel):
                status = Status.SOLVED
            elif r.within(o.eps_abs, o.eps_rel, INACCURATE_FACTOR):
                status = Status.SOLVED_INACCURATE
            elif status in (Status.SOLVED, Status.SOLVED_INACCURATE):
                status = Status.NUMERICAL_ERROR   # the scaled test passed, the point does not
        if not r.finite:
            status = Status.NUMERICAL_ERROR
        certificate = self.certificate if status.is_infeasible() else None
        return Outcome(x, y, z, status, r, iterations, self.rho, self.factorizations,
                       self.setup_time, polished, certificate, self.log)
