"""One timed solve of a suite problem by fccqp, Clarabel, OSQP or PIQP, all at eps 1e-6.

Each solver gets its own tolerance options set to :data:`EPS` and otherwise its
defaults: fccqp ``Settings(eps_abs, eps_rel)``; OSQP ``eps_abs``, ``eps_rel`` with
``polish`` on; Clarabel ``tol_gap_abs``, ``tol_gap_rel``, ``tol_feas``; PIQP
``eps_abs``, ``eps_rel``.

fccqp takes every problem natively. OSQP and PIQP see the cone-free problems only,
through ``qpsolvers.solve_problem``; so does Clarabel, except for two kinds of problems
that go to Clarabel's own API, in the form of ``tests/reference.py``'s
:func:`clarabel_form` (which is also how the references are computed): problems with
cones (friction cones as second-order cones of ``(mu n'f, T'f)``), and problems with no
constraint at all, which qpsolvers would answer itself (by LSQR, raising on unbounded
ones) without calling Clarabel.

The clock runs over the whole call (for qpsolvers including its conversion to the
solver's matrices, for Clarabel's API the solver's construction), as a user of each
interface would see it.

Every run reports its point in fccqp's sign convention, ``P x + q + A'y + z = 0`` with
``z`` the box (and cone) multipliers, so that one yardstick judges them all.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import clarabel
import numpy as np
import qpsolvers

import fccqp
from benchmarks.general_suite.families import DUAL_INFEASIBLE, PRIMAL_INFEASIBLE
from reference import clarabel_form
from verify import Problem

EPS = 1e-6
"""The tolerance every solver is asked for."""
SOLVERS = ("fccqp", "clarabel", "osqp", "piqp")
"""The benchmarked solvers, in table order."""
SOLVED = "solved"
OTHER = "other"

FCCQP_SETTINGS = fccqp.Settings(eps_abs=EPS, eps_rel=EPS)
QPSOLVERS_OPTIONS = {
    "clarabel": {"tol_gap_abs": EPS, "tol_gap_rel": EPS, "tol_feas": EPS},
    "osqp": {"eps_abs": EPS, "eps_rel": EPS, "polish": True},
    "piqp": {"eps_abs": EPS, "eps_rel": EPS},
}
"""Each peer's own names for "aim at 1e-6"."""

CLAIMS = {
    "fccqp": {fccqp.Status.SOLVED.value: SOLVED,
              fccqp.Status.PRIMAL_INFEASIBLE.value: PRIMAL_INFEASIBLE,
              fccqp.Status.DUAL_INFEASIBLE.value: DUAL_INFEASIBLE},
    "clarabel": {"Solved": SOLVED, "PrimalInfeasible": PRIMAL_INFEASIBLE,
                 "DualInfeasible": DUAL_INFEASIBLE},
    "osqp": {"solved": SOLVED, "primal infeasible": PRIMAL_INFEASIBLE,
             "dual infeasible": DUAL_INFEASIBLE},
    "piqp": {"PIQP_SOLVED": SOLVED, "PIQP_PRIMAL_INFEASIBLE": PRIMAL_INFEASIBLE,
             "PIQP_DUAL_INFEASIBLE": DUAL_INFEASIBLE},
}
"""Each solver's status strings that claim an outcome; any other status claims
nothing (:data:`OTHER`). Inaccurate and "almost" statuses claim nothing."""


@dataclass(frozen=True)
class Run:
    """One solve: the solver's own status, what it claims, the point and the time."""

    solver: str
    status: str
    """The solver's status string, or ``error: <exception>`` when it raised."""
    claim: str
    """:data:`SOLVED`, ``primal_infeasible``, ``dual_infeasible`` or :data:`OTHER`."""
    time: float
    """Seconds of the whole call."""
    x: np.ndarray | None = None
    y: np.ndarray | None = None
    z: np.ndarray | None = None
    result: fccqp.Result | None = None
    """fccqp's own result (fccqp runs only)."""


def applies(solver: str, problem: Problem) -> bool:
    """Whether ``solver`` is run on ``problem``: OSQP and PIQP only without cones."""
    return solver in ("fccqp", "clarabel") or not problem.cones


def _claim(solver: str, status: str) -> str:
    return CLAIMS[solver].get(status, OTHER)


def run_fccqp(problem: Problem, kkt_backend: str = "auto") -> Run:
    """fccqp at :data:`FCCQP_SETTINGS` on ``kkt_backend``. Only ``ValueError`` and
    ``TypeError`` (fccqp's documented input errors) become a failed run; anything else
    propagates."""
    start = time.perf_counter()
    try:
        result = fccqp.solve(*problem.args(), settings=FCCQP_SETTINGS,
                             kkt_backend=kkt_backend)
    except (ValueError, TypeError) as exn:
        return Run("fccqp", f"error: {type(exn).__name__}: {exn}", OTHER,
                   time.perf_counter() - start)
    elapsed = time.perf_counter() - start
    status = result.status.value
    return Run("fccqp", status, _claim("fccqp", status), elapsed,
               result.x, result.y, result.z, result)


def _qpsolvers_problem(problem: Problem) -> qpsolvers.Problem:
    A = problem.A if problem.A.shape[0] else None
    b = problem.b if problem.A.shape[0] else None
    lb = problem.lb if np.isfinite(problem.lb).any() else None
    ub = problem.ub if np.isfinite(problem.ub).any() else None
    return qpsolvers.Problem(problem.P, problem.q, None, None, A, b, lb, ub)


def _peer_status(solver: str, extras: dict) -> str:
    if solver == "clarabel":
        return str(extras["status"])
    status = extras["info"].status
    return status if solver == "osqp" else status.name


def run_qpsolvers(solver: str, problem: Problem) -> Run:
    """A peer through ``qpsolvers.solve_problem``; a peer's exception is its failure."""
    qp = _qpsolvers_problem(problem)
    start = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            solution = qpsolvers.solve_problem(qp, solver=solver, **QPSOLVERS_OPTIONS[solver])
    except Exception as exn:  # noqa: BLE001 -- whatever a peer raises, it did not solve
        return Run(solver, f"error: {type(exn).__name__}: {exn}", OTHER,
                   time.perf_counter() - start)
    elapsed = time.perf_counter() - start
    status = _peer_status(solver, solution.extras)
    n = problem.n
    z = solution.z_box if solution.z_box is not None and solution.z_box.size else np.zeros(n)
    y = solution.y if solution.y is not None else np.zeros(problem.b.shape[0])
    return Run(solver, status, _claim(solver, status), elapsed, solution.x, y, z)


def unconstrained(problem: Problem) -> bool:
    """No equality, no finite bound and no cone."""
    return not (problem.A.shape[0] or problem.cones or np.isfinite(problem.lb).any()
                or np.isfinite(problem.ub).any())


def run_clarabel_native(problem: Problem) -> Run:
    """Clarabel's own API on the problem in fccqp's form (see the module docstring)."""
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    for key, value in QPSOLVERS_OPTIONS["clarabel"].items():
        setattr(settings, key, value)
    form = clarabel_form(*problem.args())
    start = time.perf_counter()
    solver = clarabel.DefaultSolver(form.P, form.q, form.A, form.b, form.cones, settings)
    solution = solver.solve()
    elapsed = time.perf_counter() - start
    status = str(solution.status)
    y, z = form.duals(solution.z)
    return Run("clarabel", status, _claim("clarabel", status), elapsed,
               np.array(solution.x), y, z)


def run(solver: str, problem: Problem) -> Run:
    """``solver`` on ``problem`` (which it must apply to, see :func:`applies`)."""
    if solver == "fccqp":
        return run_fccqp(problem)
    if solver == "clarabel" and (problem.cones or unconstrained(problem)):
        return run_clarabel_native(problem)
    return run_qpsolvers(solver, problem)
