"""What polishing changes on the whole-body-control sets, at default and real-time settings.

Run ``python -m benchmarks.polish_effect [--robots R ...] [--qps N] [--passes K]``. For
each robot it generates the ``mix`` test set (seed 0) and solves it in controller-loop
order with a warm :class:`fccqp.Solver` (reset where a new sequence starts), with
``Settings()`` and ``Settings.realtime()``, polishing off and on. Per variant it prints
the median solve time, the share of QPs reported ``SOLVED`` and the share polished, the
p95 and largest torque error against the set's Clarabel reference (largest joint error
of a QP, [Nm]) and the worst relative objective gap ``|f(x) - f(x_ref)| / max(1,
|f(x_ref)|)``. Passes alternate off and on in one process, so the time ratio is a
same-run comparison; quality figures come from the last pass (the solves are
deterministic).
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import dataclass

import numpy as np

import fccqp
from benchmarks.exact_solvers import fccqp_arguments
from benchmarks.testsets import TestSet, generate_test_set

PRESETS = {"default": fccqp.Settings, "realtime": fccqp.Settings.realtime}
"""The settings compared, by name."""


@dataclass
class Effect:
    """One variant's figures over a test set."""

    median_time: float
    solved: float
    polished: float
    torque_error_p95: float
    torque_error_max: float
    objective_gap_max: float


def solve_sequence(test_set: TestSet, arguments: list, settings: fccqp.Settings,
                   cold: bool = False):
    """Solve the set in order with one solver, warm along each sequence (``cold``: reset
    before every QP); the results and each call's time."""
    solver = fccqp.Solver(settings)
    results, times = [], []
    previous = None
    for args, sequence in zip(arguments, test_set.sequence, strict=True):
        if cold or sequence != previous:
            solver.reset()
            previous = sequence
        start = time.perf_counter()
        results.append(solver.solve(*args))
        times.append(time.perf_counter() - start)
    return results, times


def effect(test_set: TestSet, results: list, times: list[float]) -> Effect:
    """The figures of one variant from its results and per-QP times."""
    pairs = list(zip(test_set.qps, test_set.x_ref, results, strict=True))
    errors = [float(np.max(np.abs(r.x[qp.layout["u"]] - x[qp.layout["u"]])))
              for qp, x, r in pairs]
    gaps = [abs(qp.objective(r.x) - qp.objective(x)) / max(1.0, abs(qp.objective(x)))
            for qp, x, r in pairs]
    return Effect(
        median_time=statistics.median(times),
        solved=float(np.mean([r.status is fccqp.Status.SOLVED for r in results])),
        polished=float(np.mean([r.polished for r in results])),
        torque_error_p95=float(np.percentile(errors, 95)),
        torque_error_max=max(errors),
        objective_gap_max=max(gaps),
    )


def measure(test_set: TestSet, passes: int) -> dict[tuple[str, bool], Effect]:
    """Every preset with polishing off and on, ``passes`` alternating passes each."""
    arguments = [fccqp_arguments(qp) for qp in test_set.qps]
    out = {}
    for name, preset in PRESETS.items():
        times: dict[bool, list[list[float]]] = {False: [], True: []}
        last = {}
        for _ in range(passes):
            for polish in (False, True):
                results, t = solve_sequence(test_set, arguments, preset(polish=polish))
                times[polish].append(t)
                last[polish] = results
        for polish in (False, True):
            per_qp = [statistics.median(column) for column in zip(*times[polish], strict=True)]
            out[name, polish] = effect(test_set, last[polish], per_qp)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=["go2", "talos_reduced"])
    parser.add_argument("--qps", type=int, default=200)
    parser.add_argument("--passes", type=int, default=3)
    args = parser.parse_args()
    print("| robot | settings | polish | median time [us] | SOLVED | polished "
          "| torque error p95 / max [Nm] | worst relative objective gap |")
    print("|---|---|---|---|---|---|---|---|")
    for robot in args.robots:
        test_set = generate_test_set(robot, "mix", args.qps, 0)
        for (name, polish), e in measure(test_set, args.passes).items():
            print(f"| {robot} | {name} | {'on' if polish else 'off'} | "
                  f"{e.median_time * 1e6:.0f} | {e.solved:.0%} | {e.polished:.0%} | "
                  f"{e.torque_error_p95:.3g} / {e.torque_error_max:.3g} | "
                  f"{e.objective_gap_max:.2g} |", flush=True)


if __name__ == "__main__":
    main()
