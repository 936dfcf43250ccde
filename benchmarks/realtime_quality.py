"""What the real-time preset returns within its time budget, warm and cold.

Run ``python -m benchmarks.realtime_quality [--robots R ...] [--qps N] [--passes K]``.
For each robot it generates the default test set (``mix`` of the four scenarios,
seed 0) and solves every QP with ``fccqp.Settings.realtime()``, with and without
feasibility restoration, warm along the controller-loop sequences and cold (every QP
from scratch). It prints, per variant, the largest exact friction-cone violation
[N], torque-limit violation [Nm] and equality residual, the torque error against the
test set's Clarabel reference (median and p95 over QPs of the largest joint error,
[Nm]), the p95 of the cost excess over the reference (relative to ``max(1, |cost|)``;
negative when the answer is infeasible and cheaper), the share of QPs reported solved,
and the median solve time. Times are
medians over ``K`` passes that alternate the variants, so the restoration's cost is a
same-run ratio.
"""

from __future__ import annotations

import argparse
import statistics
from dataclasses import dataclass

import numpy as np

import fccqp
from benchmarks.exact_solvers import fccqp_arguments
from benchmarks.polish_effect import solve_sequence
from benchmarks.robots import ROBOTS
from benchmarks.testsets import TestSet, generate_test_set


@dataclass
class Quality:
    """Worst-case feasibility and typical accuracy of one variant over a test set."""

    cone: float
    torque_limit: float
    equality: float
    torque_error_median: float
    torque_error_p95: float
    cost_excess_p95: float
    solved: float


def _quality(test_set: TestSet, results: list) -> Quality:
    errors = [
        float(np.max(np.abs(r.x[qp.layout["u"]] - x_ref[qp.layout["u"]])))
        for qp, x_ref, r in zip(test_set.qps, test_set.x_ref, results, strict=True)
    ]
    excess = [
        (qp.objective(r.x) - qp.objective(x_ref)) / max(1.0, abs(qp.objective(x_ref)))
        for qp, x_ref, r in zip(test_set.qps, test_set.x_ref, results, strict=True)
    ]
    return Quality(
        cone=max(qp.cone_violation(r.x) for qp, r in zip(test_set.qps, results, strict=True)),
        torque_limit=max(
            qp.bound_violation(r.x) for qp, r in zip(test_set.qps, results, strict=True)
        ),
        equality=max(
            qp.equality_residual(r.x) for qp, r in zip(test_set.qps, results, strict=True)
        ),
        torque_error_median=float(np.median(errors)),
        torque_error_p95=float(np.percentile(errors, 95)),
        cost_excess_p95=float(np.percentile(excess, 95)),
        solved=sum(r.status.is_solved() for r in results) / len(results),
    )


def main() -> None:
    """Print one Markdown table row per robot, start and restoration setting."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=list(ROBOTS), choices=list(ROBOTS))
    parser.add_argument("--qps", type=int, default=200, help="QPs per robot (default 200)")
    parser.add_argument("--passes", type=int, default=5, help="timing passes (default 5)")
    options = parser.parse_args()
    if options.qps < 1 or options.passes < 1:
        parser.error("--qps and --passes must be >= 1")
    print("| robot | start | restoration | cone viol. [N] | torque-limit viol. [Nm] "
          "| equality res. | torque err. median / p95 [Nm] | cost excess p95 | solved "
          "| median time [us] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for robot in options.robots:
        test_set = generate_test_set(robot, "mix", options.qps, 0)
        arguments = [fccqp_arguments(qp) for qp in test_set.qps]
        for cold in (False, True):
            medians: dict[bool, list[float]] = {True: [], False: []}
            quality = {}
            for _ in range(options.passes):
                for restore in (True, False):
                    results, times = solve_sequence(
                        test_set, arguments,
                        fccqp.Settings.realtime(restore_feasibility=restore), cold)
                    medians[restore].append(statistics.median(times))
                    quality[restore] = _quality(test_set, results)
            for restore in (True, False):
                q = quality[restore]
                print(
                    f"| {robot} | {'cold' if cold else 'warm'} | {'on' if restore else 'off'} "
                    f"| {q.cone:.2g} | {q.torque_limit:.2g} | {q.equality:.1g} "
                    f"| {q.torque_error_median:.2g} / {q.torque_error_p95:.2g} "
                    f"| {q.cost_excess_p95:.2g} "
                    f"| {100 * q.solved:.0f} % "
                    f"| {1e6 * statistics.median(medians[restore]):.0f} |"
                )


if __name__ == "__main__":
    main()
