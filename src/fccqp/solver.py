"""The user-facing solver: validation, scaling, warm starts and results."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fccqp import admm, schur
from fccqp.cones import Cone
from fccqp.problem import ProblemData, same_entries, validate
from fccqp.projections import project_constraint_set
from fccqp.result import Result
from fccqp.scaling import equilibrate, scale_start, unscale_solution
from fccqp.settings import Settings
from fccqp.status import Status

_STATUS_BY_CODE = {
    admm.SOLVED: Status.SOLVED,
    admm.SOLVED_INACCURATE: Status.SOLVED_INACCURATE,
    admm.MAX_ITER: Status.MAX_ITER_REACHED,
    admm.TIME_LIMIT: Status.TIME_LIMIT_REACHED,
    admm.PRIMAL_INFEASIBLE: Status.PRIMAL_INFEASIBLE,
    admm.DUAL_INFEASIBLE: Status.DUAL_INFEASIBLE,
}
_LAPACK_BLOCK = 64
"""Work size per row given to dsytrf (its blocked algorithm's block size)."""


@dataclass
class _Previous:
    """What a solve leaves for the next one: data to compare, factorization, solution."""

    data: ProblemData
    scaled: admm.ScaledProblem
    rho: float
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray


def _scale(data: ProblemData, iterations: int) -> admm.ScaledProblem:
    """Equilibrate ``data`` with ``iterations`` Ruiz passes.

    Starting from the previous tick's scaling with a single pass was measured on the
    WBC sets: 50 us faster per solve, but the slowest QPs took 2-4x more iterations
    (ADMM is sensitive to the scaling), so every solve scales from scratch.
    """
    P, q, A, b = data.P.copy(), data.q.copy(), data.A.copy(), data.b.copy()
    D, E = np.ones(data.n), np.ones(data.m)
    cones = data.cones
    block_start = data.constrained[cones.offset] if cones.count else np.zeros(0, np.int64)
    c = equilibrate(P, q, A, b, block_start, cones.dim, iterations, D, E) if iterations else 1.0
    Ds = D[data.constrained]
    return admm.ScaledProblem(
        P=P, q=q, A=A, b=b, constrained=data.constrained,
        lo=data.lb[data.constrained] / Ds, hi=data.ub[data.constrained] / Ds,
        cones=(cones.kind, cones.offset, cones.dim, cones.mu, cones.normal),
        D=D, E=E, c=float(c),
    )


def _rho_scale(data: ProblemData) -> np.ndarray:
    """Per-entry rho multiplier: entries with lb == ub act as equalities and get more."""
    fixed = data.lb[data.constrained] == data.ub[data.constrained]
    return np.where(fixed, admm.FIXED_RHO_SCALE, 1.0)


def _workspace(data: ProblemData, log_rows: int, memory: int) -> admm.Workspace:
    n, m, s = data.n, data.m, data.constrained.shape[0]
    N = n + m
    return admm.Workspace(
        K=np.zeros((N, N), order="F"), ipiv=np.zeros(N, np.int32),
        work=np.zeros(N * _LAPACK_BLOCK), rhs=np.zeros(N), sol=np.zeros(N),
        residual=np.zeros(N), x=np.zeros(n), nu=np.zeros(m), z=np.zeros(s), y=np.zeros(s),
        x_prev=np.zeros(n), nu_prev=np.zeros(m), z_prev=np.zeros(s), y_prev=np.zeros(s),
        rho_vec=np.zeros(s), rho_scale=_rho_scale(data),
        relaxed=np.zeros(s), log=np.zeros((log_rows, 4)),
        aa_dg=np.zeros((memory, 2 * s)), aa_df=np.zeros((memory, 2 * s)),
        aa_g=np.zeros(2 * s), aa_f=np.zeros(2 * s), aa_plain=np.zeros(2 * s + 1),
        aa_counts=np.zeros(5, np.int64), reduced=np.zeros(1, np.int64),
        factored_rho=np.full(1, -1.0),
        L=np.zeros((n, n), order="F"), LS=np.zeros((m, m), order="F"),
        Y=np.zeros((n, m), order="F"), order=schur.ordering(n, data.constrained),
        W=np.zeros((N, s), order="F"), W_S=np.zeros((s, s)), base=np.zeros(N),
        v=np.zeros(s), v_prev=np.zeros(s), u=np.zeros(s), u_prev=np.zeros(s),
    )


def _same_structure(a: ProblemData, b: ProblemData) -> bool:
    """Same sizes, constrained entries, fixed entries and cone blocks.

    Compares raw bytes: five times faster than ``np.array_equal`` on these small
    integer and boolean arrays, which matters once per control tick.
    """
    return (
        a.P.shape == b.P.shape and a.A.shape == b.A.shape
        and a.constrained.tobytes() == b.constrained.tobytes()
        and (a.lb == a.ub).tobytes() == (b.lb == b.ub).tobytes()
        and a.cones.offset.tobytes() == b.cones.offset.tobytes()
        and a.cones.dim.tobytes() == b.cones.dim.tobytes()
    )


def _smallest_eigenvalue(P: np.ndarray) -> float:
    return float(np.linalg.eigvalsh(P)[0])


class Solver:
    """ADMM solver for QPs with equalities, a box and friction / second-order cones.

    A ``Solver`` keeps its workspace between :meth:`solve` calls. With
    ``settings.warm_start`` each solve starts from the previous primal and dual
    solution and rho; when ``P``, ``A``, the constrained entries and rho are
    unchanged the scaling and the KKT factorization are reused as well.

    Parameters
    ----------
    settings : Settings, optional
        Defaults to ``Settings()``.
    **overrides
        Fields of :class:`Settings` to change, e.g. ``Solver(max_iter=100)``.
    """

    def __init__(self, settings: Settings | None = None, **overrides: object) -> None:
        if settings is not None and not isinstance(settings, Settings):
            raise TypeError(f"settings must be a fccqp.Settings, got {type(settings).__name__}")
        self.settings = (settings or Settings()).replace(**overrides)
        self._previous: _Previous | None = None
        self._workspace: admm.Workspace | None = None

    def reset(self) -> None:
        """Forget the previous solve: the next one starts cold."""
        self._previous = None

    def solve(
        self,
        P: object,
        q: object,
        A: object = None,
        b: object = None,
        lb: object = None,
        ub: object = None,
        cones: Sequence[Cone] = (),
        *,
        x0: object = None,
    ) -> Result:
        """Solve ``min 1/2 x'Px + q'x  s.t.  A x = b, lb <= x <= ub, x[block] in cone``.

        Parameters
        ----------
        P : (n, n) array_like or scipy.sparse matrix
            Symmetric positive semidefinite cost matrix (densified if sparse).
        q : (n,) array_like
            Linear cost.
        A, b : (m, n) and (m,) array_like, optional
            Equality constraints, held to factorization accuracy at every iterate.
        lb, ub : (n,) array_like, optional
            Bounds, ``-inf``/``+inf`` where absent. Entries of cone blocks must be free.
        cones : sequence of FrictionCone or SecondOrderCone
            Disjoint cone blocks of ``x``.
        x0 : (n,) array_like, optional
            Primal initial guess; overrides the warm start from the previous solve.

        Returns
        -------
        Result
            Only ``Status.SOLVED`` means both residuals are within tolerance.

        Raises
        ------
        ValueError, TypeError
            On malformed input, naming the argument, and when ``P`` is not positive
            semidefinite (detected from the inertia of the KKT factorization).
        """
        start = time.perf_counter()
        settings = self.settings
        data = validate(P, q, A, b, lb, ub, cones)
        prev = self._previous
        same_structure = prev is not None and _same_structure(prev.data, data)
        reuse = (
            same_structure and same_entries(prev.data.P, data.P)
            and same_entries(prev.data.A, data.A)
        )
        if reuse:
            scaled = self._rescale_vectors(prev.scaled, data)
        else:
            scaled = _scale(data, settings.scaling)
        log_rows = settings.max_iter + 1 if settings.verbose else 0
        w = self._workspace
        if w is None or w.x.shape != data.q.shape or w.nu.shape != data.b.shape \
                or w.z.shape != data.constrained.shape or w.log.shape[0] != log_rows \
                or w.aa_dg.shape[0] != settings.anderson_memory:
            w = self._workspace = _workspace(data, log_rows, settings.anderson_memory)
        elif not same_structure:
            w.rho_scale[:] = _rho_scale(data)
            w.order[:] = schur.ordering(data.n, data.constrained)
        warm = settings.warm_start and prev is not None and prev.x.shape == data.q.shape
        warm = warm and prev.y.shape == data.b.shape
        rho = prev.rho if warm else settings.rho
        if x0 is not None:
            self._start_from_guess(scaled, data, x0, w)
        elif warm:
            scale_start(prev.x, prev.y, prev.z, prev.rho, scaled.D, scaled.E, scaled.c,
                        scaled.constrained, scaled.lo, scaled.hi, scaled.cones,
                        w.x, w.nu, w.y, w.z)
        cold = x0 is None and not warm
        params = admm.Params(
            rho=rho, sigma=settings.sigma, alpha=settings.alpha,
            eps_abs=settings.eps_abs, eps_rel=settings.eps_rel,
            eps_prim_inf=settings.eps_prim_inf, eps_dual_inf=settings.eps_dual_inf,
            max_iter=settings.max_iter, check_termination=settings.check_termination,
            adaptive_rho=settings.adaptive_rho,
            adaptive_rho_interval=settings.adaptive_rho_interval,
            adaptive_rho_tolerance=settings.adaptive_rho_tolerance,
            anderson_memory=settings.anderson_memory,
            time_limit=float(settings.time_limit), start_time=start,
            cold_start=cold, factorize=not (reuse and w.factored_rho[0] == rho),
            restore_feasibility=settings.restore_feasibility,
        )
        setup_time = time.perf_counter() - start
        code, iterations, rho, prim, dual, factorizations = admm.run(scaled, w, params)
        if code == admm.NOT_CONVEX:
            self._previous = None
            raise ValueError(
                "P is not positive semidefinite: its smallest eigenvalue is "
                f"{_smallest_eigenvalue(data.P):.3g}"
            )
        status = _STATUS_BY_CODE[code]
        x, y, z, obj = unscale_solution(w.x, w.nu, w.y, scaled.D, scaled.E, scaled.c,
                                        scaled.constrained, data.P, data.q)
        certificate = self._certificate(scaled, w, status)
        self._previous = _Previous(data, scaled, rho, x, y, z)
        if settings.verbose:
            self._print_log(w, status, iterations)
        return Result(
            x=x, y=y, z=z, status=status, obj=float(obj), iterations=int(iterations),
            prim_res=float(prim), dual_res=float(dual), setup_time=setup_time,
            solve_time=time.perf_counter() - start, rho=float(rho),
            factorizations=int(factorizations), certificate=certificate,
        )

    @staticmethod
    def _rescale_vectors(old: admm.ScaledProblem, data: ProblemData) -> admm.ScaledProblem:
        """Reuse the scaling of unchanged matrices for new q, b and bounds."""
        Ds = old.D[data.constrained]
        return old._replace(
            q=old.c * old.D * data.q, b=old.E * data.b,
            lo=data.lb[data.constrained] / Ds, hi=data.ub[data.constrained] / Ds,
        )

    @staticmethod
    def _start_from_guess(
        scaled: admm.ScaledProblem, data: ProblemData, x0: object, w: admm.Workspace
    ) -> None:
        guess = np.asarray(x0, dtype=np.float64).reshape(-1)
        if guess.shape != (data.n,) or not np.all(np.isfinite(guess)):
            raise ValueError(f"x0 must be a finite vector of {data.n} entries")
        w.x[:] = guess / scaled.D
        w.nu[:] = 0.0
        w.y[:] = 0.0
        project_constraint_set(w.x[scaled.constrained], scaled.lo, scaled.hi, scaled.cones, w.z)

    @staticmethod
    def _certificate(scaled: admm.ScaledProblem, w: admm.Workspace, status: Status):
        if status is Status.DUAL_INFEASIBLE:
            return (w.x - w.x_prev) * scaled.D
        if status is Status.PRIMAL_INFEASIBLE:
            s = scaled.constrained
            d_z = np.zeros(w.x.shape[0])
            d_z[s] = (w.y - w.y_prev) / scaled.D[s]
            return np.concatenate([(w.nu - w.nu_prev) * scaled.E, d_z])
        return None

    @staticmethod
    def _print_log(w: admm.Workspace, status: Status, iterations: int) -> None:
        print(f"{'iter':>6} {'prim_res':>10} {'dual_res':>10} {'rho':>9}")
        for it, prim, dual, rho in w.log[: iterations + 1]:
            if it > 0 or (prim, dual) != (0.0, 0.0):
                print(f"{int(it):6d} {prim:10.3e} {dual:10.3e} {rho:9.2e}")
        print(f"status: {status.value} after {iterations} iterations")


def solve(
    P: object,
    q: object,
    A: object = None,
    b: object = None,
    lb: object = None,
    ub: object = None,
    cones: Sequence[Cone] = (),
    settings: Settings | None = None,
    **overrides: object,
) -> Result:
    """Solve one QP from a cold start; see :meth:`Solver.solve` for the arguments.

    ``settings`` and keyword ``overrides`` (fields of :class:`Settings`) configure
    the solve; an unknown keyword raises ``ValueError``.
    """
    return Solver(settings, **overrides).solve(P, q, A, b, lb, ub, cones)
