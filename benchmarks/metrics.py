"""Per-QP accuracy metrics and per-solver aggregates.

Every solution is judged on the ORIGINAL problem, with exact friction cones, even when
the solver only saw a pyramid: a pyramid answer is feasible but restricted, which shows
as an objective gap and a torque error against the exact-cone reference.

Success follows qpbenchmark's convention (a solver succeeds on a QP when it reports
success AND its solution passes checks within a tolerance); the checks here are the
ones that exist for every variant, pyramid or not (see :func:`qp_metrics`), at the
relative tolerance :data:`TOLERANCE`. Times are aggregated as qpbenchmark does too:
shifted geometric mean with shift 10 (seconds), a solve the solver itself does not
report as solved counting as the time limit.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from benchmarks.wbc_qp import WbcQP

__all__ = [
    "DEADLINES",
    "SHIFT",
    "TOLERANCE",
    "TORQUE_LIMIT_SHARE",
    "QPMetrics",
    "Summary",
    "deadline_share",
    "qp_metrics",
    "shifted_geometric_mean",
    "solved_torque_errors",
    "summarize",
]

TOLERANCE = 1e-3
"""Relative tolerance of the success checks."""

SHIFT = 10.0
"""Shift of the shifted geometric mean of times, in seconds (qpbenchmark's value)."""

DEADLINES = (250e-6, 500e-6, 1e-3)
"""Time budgets (s) of the deadline view."""

TORQUE_LIMIT_SHARE = 0.05
"""Largest torque error, as a fraction of the joint's limit, of a usable answer."""


@dataclass(frozen=True)
class QPMetrics:
    """Accuracy of one solution ``x`` against the reference ``x_ref``.

    Attributes
    ----------
    equality_residual
        ``||A x - b||_inf`` (N, Nm and m/s^2 mixed: the rows are dynamics and contacts).
    cone_violation
        Largest violation of the EXACT friction cones, ``max(0, ||f_t|| - mu f_n)`` [N].
    bound_violation
        Largest violation of the torque limits [Nm].
    objective_gap
        ``|f(x) - f(x_ref)| / max(1, |f(x_ref)|)``.
    torque_error
        ``max_j |u_j - u_ref_j|`` [Nm]: what the robot would feel.
    torque_error_rel
        ``max_j |u_j - u_ref_j| / u_max_j``, as a fraction of each joint's limit.
    feasible
        Equality residual, cone and bound violations within :data:`TOLERANCE` relative
        to ``1 + ||b||_inf``, ``1 + max ||f_ref||`` and ``1 + max u_max``.
    accurate
        ``feasible`` and ``objective_gap <= TOLERANCE``.
    """

    equality_residual: float
    cone_violation: float
    bound_violation: float
    objective_gap: float
    torque_error: float
    torque_error_rel: float
    feasible: bool
    accurate: bool


def qp_metrics(qp: WbcQP, x: np.ndarray, x_ref: np.ndarray, tol: float = TOLERANCE) -> QPMetrics:
    """Judge ``x`` on ``qp`` against the reference ``x_ref`` (see :class:`QPMetrics`)."""
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        inf = float("inf")
        return QPMetrics(inf, inf, inf, inf, inf, inf, False, False)
    eq = qp.equality_residual(x)
    cone = qp.cone_violation(x)
    bound = qp.bound_violation(x)
    f_ref = qp.objective(x_ref)
    gap = abs(qp.objective(x) - f_ref) / max(1.0, abs(f_ref))
    u = qp.layout["u"]
    du = np.abs(x[u] - x_ref[u])
    u_max = qp.ub[u]
    force_scale = float(np.max(np.linalg.norm(qp.forces(x_ref), axis=1), initial=0.0))
    feasible = (
        eq <= tol * (1.0 + np.max(np.abs(qp.b), initial=0.0))
        and cone <= tol * (1.0 + force_scale)
        and bound <= tol * (1.0 + np.max(u_max, initial=0.0))
    )
    return QPMetrics(
        equality_residual=eq,
        cone_violation=cone,
        bound_violation=bound,
        objective_gap=float(gap),
        torque_error=float(np.max(du, initial=0.0)),
        torque_error_rel=float(np.max(du / u_max, initial=0.0)),
        feasible=bool(feasible),
        accurate=bool(feasible and gap <= tol),
    )


def shifted_geometric_mean(values: np.ndarray, shift: float = SHIFT) -> float:
    """``exp(mean(log(v + shift))) - shift`` (qpbenchmark's ``shgeom``).

    With shift 10 s and sub-millisecond times it is close to the arithmetic mean:
    the shift exists so that tiny times do not dominate, and failures (counted as
    the time limit) weigh in linearly.
    """
    v = np.asarray(values, dtype=float)
    if v.size == 0 or np.any(v < 0):
        raise ValueError("shifted geometric mean needs nonnegative values")
    return float(np.exp(np.mean(np.log(v + shift))) - shift)


@dataclass(frozen=True)
class Summary:
    """Aggregates of one solver on one test set (times in seconds).

    ``success_rate`` is qpbenchmark's: solver reports success and the solution is
    accurate; ``feasible_rate`` drops the objective check (a pyramid answer is feasible
    but suboptimal); ``reported_rate`` is how often the solver itself reports success.
    ``shm_time`` counts unreported solves as ``time_limit``; the ratios compare medians
    with the fastest variant of the set and with one ``dsytrf`` of the KKT matrix.
    ``p95_torque_error_rel`` judges every returned point; ``p95_solved_torque_error_rel``
    counts a QP the solver did not report solved as an infinite error.
    """

    solver: str
    n: int
    success_rate: float
    feasible_rate: float
    reported_rate: float
    median_time: float
    p95_time: float
    shm_time: float
    shm_ratio: float
    ratio_to_fastest: float
    ratio_to_dsytrf: float
    median_iterations: float
    max_equality_residual: float
    max_cone_violation: float
    median_objective_gap: float
    max_objective_gap: float
    median_torque_error: float
    p95_torque_error: float
    max_torque_error: float
    p95_torque_error_rel: float
    p95_solved_torque_error_rel: float


def solved_torque_errors(rows: Sequence[dict[str, object]]) -> np.ndarray:
    """``torque_error_rel`` of each row, infinite where the solver did not report success.

    The work-precision view counts an unsolved QP as a failure whatever point came back.
    """
    return np.array(
        [float(r["torque_error_rel"]) if r["reported"] else np.inf for r in rows], dtype=float
    )


def deadline_share(rows: Sequence[dict[str, object]], budget: float) -> float:
    """Share of ``rows`` (one solver) answered within ``budget`` seconds, and usefully.

    A QP counts when the solve took at most ``budget``, the solver reports success, the
    point is feasible for the exact cones (:attr:`QPMetrics.feasible`) and its largest
    torque error is below :data:`TORQUE_LIMIT_SHARE` of the joint's limit.
    """
    ok = [
        float(r["time"]) <= budget
        and bool(r["reported"])
        and bool(r["feasible"])
        and float(r["torque_error_rel"]) < TORQUE_LIMIT_SHARE
        for r in rows
    ]
    return float(np.mean(ok)) if ok else float("nan")


def summarize(
    rows: Sequence[dict[str, object]], time_limit: float
) -> list[Summary]:
    """Aggregate result rows of ONE test set per solver, in order of first appearance.

    Parameters
    ----------
    rows
        Rows as written to ``results.csv`` (keys ``solver``, ``time``, ``reported``,
        ``success``, ``feasible``, ``iterations``, the metric names and
        ``dsytrf_time``).
    time_limit
        Time (s) counted for a solve the solver does not report as solved, in the
        shifted geometric mean.
    """
    solvers = list(dict.fromkeys(str(r["solver"]) for r in rows))

    def column(solver: str, key: str) -> np.ndarray:
        return np.array([r[key] for r in rows if r["solver"] == solver], dtype=float)

    medians = {s: float(np.median(column(s, "time"))) for s in solvers}
    fastest = min(medians.values())
    shms = {}
    for s in solvers:
        penalized = np.where(column(s, "reported") > 0, column(s, "time"), time_limit)
        shms[s] = shifted_geometric_mean(penalized)
    best_shm = min(shms.values())
    out = []
    for s in solvers:
        t = column(s, "time")
        it = column(s, "iterations")
        du = column(s, "torque_error")
        out.append(
            Summary(
                solver=s,
                n=int(t.size),
                success_rate=float(np.mean(column(s, "success"))),
                feasible_rate=float(np.mean(column(s, "feasible"))),
                reported_rate=float(np.mean(column(s, "reported"))),
                median_time=medians[s],
                p95_time=float(np.percentile(t, 95)),
                shm_time=shms[s],
                shm_ratio=shms[s] / best_shm,
                ratio_to_fastest=medians[s] / fastest,
                ratio_to_dsytrf=medians[s] / float(np.median(column(s, "dsytrf_time"))),
                median_iterations=float(np.median(it)) if np.all(it >= 0) else float("nan"),
                max_equality_residual=float(np.max(column(s, "equality_residual"))),
                max_cone_violation=float(np.max(column(s, "cone_violation"))),
                median_objective_gap=float(np.median(column(s, "objective_gap"))),
                max_objective_gap=float(np.max(column(s, "objective_gap"))),
                median_torque_error=float(np.median(du)),
                p95_torque_error=float(np.percentile(du, 95)),
                max_torque_error=float(np.max(du)),
                p95_torque_error_rel=float(np.percentile(column(s, "torque_error_rel"), 95)),
                p95_solved_torque_error_rel=float(
                    np.percentile(
                        solved_torque_errors([r for r in rows if r["solver"] == s]), 95,
                        method="higher",  # no interpolation with an infinite neighbour
                    )
                ),
            )
        )
    return out
