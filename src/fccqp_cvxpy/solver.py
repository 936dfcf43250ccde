"""The CVXPY conic-solver interface of fccqp.

``problem.solve(solver=FCCQP)`` (or ``solver="FCCQP"`` after ``import fccqp_cvxpy``)
runs CVXPY's reduction chain down to zero, nonnegative and second-order cones with a
quadratic objective, translates that form with :mod:`fccqp_cvxpy.translation` and
solves it with :class:`fccqp.Solver`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import cvxpy.settings as s
import numpy as np
from cvxpy.constraints import SOC
from cvxpy.reductions.solution import Solution, failure_solution
from cvxpy.reductions.solvers import utilities
from cvxpy.reductions.solvers.conic_solvers.conic_solver import ConicSolver

import fccqp
from fccqp_cvxpy.translation import (
    ConeDims,
    Translation,
    recover_duals,
    recover_primal,
    translate,
)

STATUS_MAP = {
    fccqp.Status.SOLVED: s.OPTIMAL,
    fccqp.Status.SOLVED_INACCURATE: s.OPTIMAL_INACCURATE,
    fccqp.Status.MAX_ITER_REACHED: s.USER_LIMIT,
    fccqp.Status.TIME_LIMIT_REACHED: s.USER_LIMIT,
    fccqp.Status.PRIMAL_INFEASIBLE: s.INFEASIBLE,
    fccqp.Status.DUAL_INFEASIBLE: s.UNBOUNDED,
    fccqp.Status.NUMERICAL_ERROR: s.SOLVER_ERROR,
}
"""fccqp status -> CVXPY status; a non-finite point with a solved status is SOLVER_ERROR."""

CITATION = """@misc{acosta2024fccqp,
  title = {{FCCQP}: A Whole Body Control {QP} Solver with Full Friction Cones},
  author = {Acosta, Brian},
  year = {2024},
  note = {\\url{https://github.com/Brian-Acosta/fcc_qp}}
}"""

_CVXPY_OPTIONS = ("use_quad_obj",)
"""Keys CVXPY leaves in the solver options for its own canonicalization."""


@dataclass
class _Cached:
    """The fccqp solver kept in a problem's ``solver_cache`` for warm starts."""

    structure: tuple
    settings: fccqp.Settings
    solver: fccqp.Solver


@dataclass(frozen=True)
class RawSolution:
    """What :meth:`FCCQPSolver.solve_via_data` returns and :meth:`FCCQPSolver.invert` reads."""

    result: fccqp.Result
    translation: Translation
    translate_time: float
    warm_started: bool


class FCCQPSolver(ConicSolver):
    """CVXPY interface to the fccqp ADMM solver (zero, nonnegative and SOC cones).

    CVXPY takes a solver *instance*; :data:`FCCQP` is the default one, and calling
    an instance returns a new one with other default settings
    (``FCCQP(eps_abs=1e-7)``), so ``solver=FCCQP`` and ``solver=FCCQP()`` both work.

    Parameters
    ----------
    settings : fccqp.Settings, optional
        Default settings of this instance; ``fccqp.Settings()`` if omitted.
    **overrides
        Fields of :class:`fccqp.Settings` to change in the defaults. Options given to
        ``problem.solve(solver=..., **options)`` override these per solve; an unknown
        name raises ``ValueError`` naming it.

    Notes
    -----
    Two instances with the same default settings compare (and hash) equal, so
    CVXPY keeps its compiled solve chain when a new ``FCCQP()`` is passed. For
    warm starts a :class:`fccqp.Solver` is kept in the problem's solver cache
    (``problem._solver_cache``, which CVXPY clears whenever it rebuilds the chain);
    re-solving after a parameter change starts from the previous primal and dual
    and reuses the KKT factorization when ``P`` and ``A`` did not change.
    ``problem.solve(warm_start=False)`` solves from scratch.
    """

    MIP_CAPABLE = False
    REQUIRES_CONSTR = False
    BOUNDED_VARIABLES = True
    """CVXPY passes variable bounds as arrays, which become fccqp's box directly."""
    SUPPORTED_CONSTRAINTS = [*ConicSolver.SUPPORTED_CONSTRAINTS, SOC]

    def __init__(self, settings: fccqp.Settings | None = None, **overrides: Any) -> None:
        if settings is not None and not isinstance(settings, fccqp.Settings):
            raise TypeError(f"settings must be a fccqp.Settings, got {type(settings).__name__}")
        self.settings = (settings or fccqp.Settings()).replace(**overrides)

    def __call__(
        self, settings: fccqp.Settings | None = None, **overrides: Any
    ) -> FCCQPSolver:
        """A new instance whose defaults are ``settings`` (or this one's) with ``overrides``."""
        return type(self)(settings or self.settings, **overrides)

    def __eq__(self, other: object) -> bool:
        return type(other) is type(self) and other.settings == self.settings

    def __hash__(self) -> int:
        return hash((type(self).__name__, self.settings))

    def __repr__(self) -> str:
        return f"FCCQPSolver({self.settings!r})"

    def name(self) -> str:
        """The name CVXPY reports and looks the solver up by."""
        return "FCCQP"

    def import_solver(self) -> None:
        """Import fccqp (CVXPY calls this to check the solver is installed)."""
        import fccqp  # noqa: F401

    def apply(self, problem):
        """CVXPY's conic data, with ``n_eq`` and ``n_ineq`` (the zero and nonnegative
        cone rows) as CVXPY's QP solvers report them: its conformance test of
        ``BOUNDED_VARIABLES`` reads ``n_ineq`` to check that bounds did not become rows."""
        data, inverse_data = super().apply(problem)
        dims = data[s.DIMS]
        data["n_eq"], data["n_ineq"] = dims.zero, dims.nonneg
        return data, inverse_data

    def supports_quad_obj(self) -> bool:
        """fccqp takes the quadratic objective directly, so CVXPY keeps ``P``."""
        return True

    def cite(self, data: dict) -> str:
        """BibTeX entry of the FCCQP paper the algorithm builds on."""
        return CITATION

    def solve_settings(self, verbose: bool, solver_opts: dict) -> fccqp.Settings:
        """This instance's settings with ``verbose`` and the per-solve options applied.

        Raises
        ------
        ValueError
            If an option is not a field of :class:`fccqp.Settings` (the message names it
            and lists the valid ones), or a value is out of range.
        """
        options = {k: v for k, v in solver_opts.items() if k not in _CVXPY_OPTIONS}
        try:
            return self.settings.replace(verbose=bool(verbose), **options)
        except ValueError as exn:
            raise ValueError(f"FCCQP: {exn}") from exn

    def solve_via_data(
        self,
        data: dict,
        warm_start: bool,
        verbose: bool,
        solver_opts: dict,
        solver_cache: dict | None = None,
    ) -> RawSolution:
        """Translate CVXPY's conic data and solve it with fccqp.

        Parameters
        ----------
        data : dict
            Output of :meth:`apply`: ``P`` (absent for a linear objective), ``c``,
            ``A``, ``b`` and the cone dimensions.
        warm_start : bool
            Start from the previous solve of the same problem, if its layout matches.
        verbose : bool
            Print fccqp's iteration log.
        solver_opts : dict
            Fields of :class:`fccqp.Settings`.
        solver_cache : dict, optional
            The problem's cache, where the :class:`fccqp.Solver` is kept between solves.

        Returns
        -------
        RawSolution
        """
        settings = self.solve_settings(verbose, solver_opts)
        dims = data[self.DIMS]
        start = time.perf_counter()
        translation = translate(
            data.get(s.P), data[s.C], data[s.A], data[s.B],
            ConeDims(dims.zero, dims.nonneg, tuple(dims.soc)),
            data.get(s.LOWER_BOUNDS), data.get(s.UPPER_BOUNDS),
        )
        translate_time = time.perf_counter() - start
        cached = solver_cache.get(self.name()) if solver_cache is not None else None
        warm = (
            warm_start and cached is not None
            and cached.structure == translation.structure and cached.settings == settings
        )
        solver = cached.solver if warm else fccqp.Solver(settings)
        t = translation
        result = solver.solve(t.P, t.q, t.A, t.b, t.lb, t.ub, t.cones)
        if solver_cache is not None:
            solver_cache[self.name()] = _Cached(translation.structure, settings, solver)
        return RawSolution(result, translation, translate_time, warm)

    def invert(self, solution: RawSolution, inverse_data: Any) -> Solution:
        """Map fccqp's result back to CVXPY's variables, duals, status and stats."""
        result = solution.result
        status = STATUS_MAP[result.status]
        finite = np.isfinite(result.x).all() and np.isfinite(result.y).all()
        if status in s.SOLUTION_PRESENT and not (finite and np.isfinite(result.z).all()):
            status = s.SOLVER_ERROR
        attr = {
            s.SOLVE_TIME: result.solve_time,
            s.SETUP_TIME: result.setup_time,
            s.NUM_ITERS: result.iterations,
            s.EXTRA_STATS: {
                "result": result,
                "translation": solution.translation,
                "translate_time": solution.translate_time,
                "warm_started": solution.warm_started,
            },
        }
        if status not in s.SOLUTION_PRESENT:
            return failure_solution(status, attr)
        t = solution.translation
        duals = recover_duals(t, result.y, result.z)
        zero = inverse_data[self.DIMS].zero
        dual_vars = utilities.get_dual_values(
            duals[:zero], utilities.extract_dual_value, inverse_data[self.EQ_CONSTR]
        )
        dual_vars.update(utilities.get_dual_values(
            duals[zero:], utilities.extract_dual_value, inverse_data[self.NEQ_CONSTR]
        ))
        primal_vars = {inverse_data[self.VAR_ID]: recover_primal(t, result.x)}
        opt_val = result.obj + inverse_data[s.OFFSET]
        return Solution(status, opt_val, primal_vars, dual_vars, attr)


FCCQP = FCCQPSolver()
"""The default instance: ``problem.solve(solver=FCCQP, max_iter=200)``."""
