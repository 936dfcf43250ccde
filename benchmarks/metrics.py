"""Per-QP accuracy metrics and per-solver aggregates, with one percentile method.

Every solution is judged on the ORIGINAL problem, with exact friction cones, even when
the solver only saw a pyramid: a pyramid answer is feasible but restricted, which shows
as an objective gap and a torque error against the exact-cone reference.

Success follows qpbenchmark's convention (a solver succeeds on a QP when it reports
success AND its solution passes checks within a tolerance); the checks here are the
ones that exist for every variant, pyramid or not (see :func:`qp_metrics`), at the
relative tolerance :data:`TOLERANCE`.

Every percentile, median included, is the nearest rank over per-QP values
(:func:`percentile`, numpy's ``method="inverted_cdf"``): the value of an actual QP,
never an interpolation, so that a table's p95 and a target's p95 of the same QPs are
the same number. A QP the solver does not report solved counts as an infinite error
(:func:`solved_torque_errors`, :func:`solved_objective_gaps`) and, in time, as the
controller period, or its own time when that is longer (:func:`penalized_times`). The
shifted geometric mean follows qpbenchmark (shift 10 s, an unreported solve counting as
the time limit).
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
    "exact_share",
    "penalized_times",
    "percentile",
    "qp_metrics",
    "shifted_geometric_mean",
    "solved_objective_gaps",
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


def percentile(values: Sequence[float] | np.ndarray, q: float) -> float:
    """The ``q``-th percentile of ``values`` by nearest rank (the value of rank
    ``ceil(q / 100 * n)``; ``q = 50`` is the median, ``100`` the maximum).

    Infinite values (failures) are ranked like any other, so a p95 is infinite exactly
    when more than 5 % of the values are.
    """
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return float("nan")
    return float(np.percentile(v, q, method="inverted_cdf"))


def _reported(row: dict[str, object]) -> bool:
    return bool(row["reported"])


def penalized_times(rows: Sequence[dict[str, object]], period: float) -> np.ndarray:
    """Per-QP times, a solve not reported solved counting as ``max(time, period)``: an
    answer the controller cannot use is as late as a missed tick."""
    return np.array(
        [float(r["time"]) if _reported(r) else max(float(r["time"]), period) for r in rows],
        dtype=float,
    )


def solved_torque_errors(rows: Sequence[dict[str, object]]) -> np.ndarray:
    """``torque_error_rel`` of each row, infinite where the solver did not report success."""
    return _solved(rows, "torque_error_rel")


def solved_objective_gaps(rows: Sequence[dict[str, object]]) -> np.ndarray:
    """``objective_gap`` of each row, infinite where the solver did not report success."""
    return _solved(rows, "objective_gap")


def _solved(rows: Sequence[dict[str, object]], key: str) -> np.ndarray:
    return np.array([float(r[key]) if _reported(r) else np.inf for r in rows], dtype=float)


def exact_share(rows: Sequence[dict[str, object]]) -> float:
    """Share of ``rows`` answered exactly: reported solved, with every joint's torque
    within :data:`TORQUE_LIMIT_SHARE` of its limit of the exact-cone reference's."""
    ok = [_reported(r) and float(r["torque_error_rel"]) <= TORQUE_LIMIT_SHARE for r in rows]
    return float(np.mean(ok)) if ok else float("nan")


def deadline_share(rows: Sequence[dict[str, object]], budget: float) -> float:
    """Share of ``rows`` (one solver) answered within ``budget`` seconds, and usefully.

    A QP counts when the solve took at most ``budget``, the solver reports success, the
    point is feasible for the exact cones (:attr:`QPMetrics.feasible`) and its largest
    torque error is below :data:`TORQUE_LIMIT_SHARE` of the joint's limit.
    """
    ok = [
        float(r["time"]) <= budget
        and _reported(r)
        and bool(r["feasible"])
        and float(r["torque_error_rel"]) < TORQUE_LIMIT_SHARE
        for r in rows
    ]
    return float(np.mean(ok)) if ok else float("nan")


@dataclass(frozen=True)
class Summary:
    """Aggregates of one solver over some QPs (times in seconds).

    ``success_rate`` is qpbenchmark's: solver reports success and the solution is
    accurate; ``feasible_rate`` drops the objective check (a pyramid answer is feasible
    but restricted); ``reported_rate`` is how often the solver itself reports success;
    ``exact_rate`` is :func:`exact_share`. Times are :func:`penalized_times`; the
    torque errors and objective gaps count a QP not reported solved as infinite.
    ``shm_time`` counts unreported solves as the time limit; the ratios compare medians
    with the fastest variant of the same rows and with one ``dsytrf`` of the KKT matrix.
    """

    solver: str
    n: int
    success_rate: float
    feasible_rate: float
    reported_rate: float
    exact_rate: float
    median_time: float
    p95_time: float
    p99_time: float
    max_time: float
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


def summarize(rows: Sequence[dict[str, object]], period: float) -> list[Summary]:
    """Aggregate result rows (one view of one test set) per solver, in order of first
    appearance.

    Parameters
    ----------
    rows
        Rows as written to ``results.csv`` (keys ``solver``, ``time``, ``reported``,
        ``success``, ``feasible``, ``iterations``, the metric names and
        ``dsytrf_time``).
    period
        The controller period (s): the time a solve not reported solved counts as at
        least, and the time limit of the shifted geometric mean.
    """
    solvers = list(dict.fromkeys(str(r["solver"]) for r in rows))
    mine = {s: [r for r in rows if r["solver"] == s] for s in solvers}

    def column(solver: str, key: str) -> np.ndarray:
        return np.array([r[key] for r in mine[solver]], dtype=float)

    times = {s: penalized_times(mine[s], period) for s in solvers}
    medians = {s: percentile(times[s], 50) for s in solvers}
    fastest = min(medians.values())
    shms = {}
    for s in solvers:
        limited = np.where(column(s, "reported") > 0, column(s, "time"), period)
        shms[s] = shifted_geometric_mean(limited)
    best_shm = min(shms.values())
    out = []
    for s in solvers:
        t = times[s]
        it = column(s, "iterations")
        du = np.where(column(s, "reported") > 0, column(s, "torque_error"), np.inf)
        gaps = solved_objective_gaps(mine[s])
        out.append(
            Summary(
                solver=s,
                n=int(t.size),
                success_rate=float(np.mean(column(s, "success"))),
                feasible_rate=float(np.mean(column(s, "feasible"))),
                reported_rate=float(np.mean(column(s, "reported"))),
                exact_rate=exact_share(mine[s]),
                median_time=medians[s],
                p95_time=percentile(t, 95),
                p99_time=percentile(t, 99),
                max_time=float(np.max(t)),
                shm_time=shms[s],
                shm_ratio=shms[s] / best_shm,
                ratio_to_fastest=medians[s] / fastest,
                ratio_to_dsytrf=medians[s] / percentile(column(s, "dsytrf_time"), 50),
                median_iterations=percentile(it, 50) if np.all(it >= 0) else float("nan"),
                max_equality_residual=float(np.max(column(s, "equality_residual"))),
                max_cone_violation=float(np.max(column(s, "cone_violation"))),
                median_objective_gap=percentile(gaps, 50),
                max_objective_gap=float(np.max(gaps)),
                median_torque_error=percentile(du, 50),
                p95_torque_error=percentile(du, 95),
                max_torque_error=float(np.max(du)),
                p95_torque_error_rel=percentile(solved_torque_errors(mine[s]), 95),
            )
        )
    return out
