"""Success at eps 1e-6, judged the same way for every solver from the data and its point.

A run on a feasible problem succeeds when the solver claims "solved", its point meets
:data:`TOLERANCES` on the checks :data:`CHECKS` of ``tests/verify.py`` (equalities,
box and cones relative to ``max(1, |b|, |A||x|)`` and ``max(1, |x|)``; stationarity,
multiplier signs and dual cones relative to ``max(1, |q|, |Px|)``; the duality gap
relative to ``max(1, |x'Px|, |q'x|)``; each ``eps_abs + eps_rel * scale`` with both
at 1e-6 and no slack factor), and its objective ``1/2 x'Px + q'x`` is within
``1e-6 * max(1, |reference|)`` of the reference's. Complementarity is not a separate
check: with the point feasible and the multipliers of the right signs, the gap is the
sum of the complementarity terms. On an infeasible problem a run succeeds when the
solver claims the right kind of infeasibility.

Separately, :func:`verified` asks whether ``verify_solution`` (at the tolerances the
fccqp test suite uses for these settings) accepts fccqp's own result, whatever its
status: a ``SOLVED`` it rejects is a wrong claim.
"""

from __future__ import annotations

import numpy as np

import fccqp
from benchmarks.general_suite.families import FEASIBLE, SuiteProblem
from benchmarks.general_suite.runs import EPS, FCCQP_SETTINGS, SOLVED, Run
from reference import Reference
from verify import Tolerances, check_solution

TOLERANCES = Tolerances(eps_abs=EPS, eps_rel=EPS, factor=1.0, equality=EPS)
"""The yardstick's bounds: ``eps_abs + eps_rel * scale`` on every check."""
CHECKS = ("finite point", "equality", "box", "cone", "dual residual",
          "box multiplier sign", "dual cone", "duality gap")
"""The checks of ``verify.check_solution`` that make up the yardstick."""


def _as_result(problem_size: tuple[int, int], run: Run) -> fccqp.Result:
    """The run's point as a ``SOLVED`` result claiming nothing (infinite residuals)."""
    n, m = problem_size
    fill = lambda v, k: np.full(k, np.nan) if v is None else np.asarray(v, float)  # noqa: E731
    return fccqp.Result(x=fill(run.x, n), y=fill(run.y, m), z=fill(run.z, n),
                        status=fccqp.Status.SOLVED, obj=np.nan, iterations=0,
                        prim_res=np.inf, dual_res=np.inf, setup_time=0.0, solve_time=0.0,
                        rho=np.nan, factorizations=0)


def point_failures(item: SuiteProblem, run: Run) -> dict[str, tuple[float, float]]:
    """The yardstick checks the run's point fails, as ``name -> (value, bound)``."""
    problem = item.problem
    report = check_solution(problem, _as_result((problem.n, problem.b.shape[0]), run),
                            TOLERANCES)
    return {name: check for name, check in report.failures.items() if name in CHECKS}


def objective_error(item: SuiteProblem, run: Run, reference: Reference) -> float:
    """``|obj(x) - obj_ref| / max(1, |obj_ref|)``; NaN without both points."""
    if run.x is None or reference.obj is None:
        return float("nan")
    p, x = item.problem, np.asarray(run.x, float)
    obj = 0.5 * x @ p.P @ x + p.q @ x
    return float(abs(obj - reference.obj) / max(1.0, abs(reference.obj)))


def success(item: SuiteProblem, run: Run, reference: Reference) -> bool:
    """Success at eps 1e-6 (see the module docstring). A feasible problem whose
    reference failed counts the yardstick alone."""
    if item.expected != FEASIBLE:
        return run.claim == item.expected
    if run.claim != SOLVED or point_failures(item, run):
        return False
    return reference.obj is None or objective_error(item, run, reference) <= EPS


def verified(item: SuiteProblem, run: Run) -> bool:
    """Whether ``verify.check_solution`` accepts fccqp's result for its status."""
    tolerances = Tolerances.of(FCCQP_SETTINGS)
    return run.result is not None and check_solution(item.problem, run.result,
                                                     tolerances).passed
