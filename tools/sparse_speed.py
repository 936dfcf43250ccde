"""Wall time of fccqp's sparse path against OSQP and Clarabel, in one process.

    python tools/sparse_speed.py [--rounds 7] [--problems mpc large_friction sparse_ls]

Problems (the sizes of issue 28's target "large sparse problems at least as fast as
today's sparse path"):

- ``mpc``: a linear MPC with 12 states, 4 inputs and horizon 100 (1612 variables, 1212
  equality rows: the initial state and the dynamics; 2824 KKT rows), inputs boxed to
  ``[-0.3, 0.3]`` (16 of them active at the optimum), states to ``[-5, 5]``;
  random stable dynamics (seed 0);
- ``large_friction``: ``tests/problems.large_problem`` above the dense limit
  (5000 variables, a tridiagonal ``P``, two rows, a box and a friction cone);
- ``sparse_ls``: qpsolvers' sparse least-squares problem as
  ``test_qpsolvers_sparse_problem_above_the_limit`` poses it (5101 KKT rows in
  fccqp's slack form), with its inequalities ``G x <= h`` turned into slack entries.

Each solver gets its default settings and a cold solve (set-up included); fccqp gets
``kkt_backend="sparse"``. The machine is shared and noisy: every round runs each
solver once on each problem, in an order that rotates from round to round, and the
report gives the median per solver and its ratio to fccqp's (the minimum beside it).
OSQP has no second-order cones: it is left out of ``large_friction``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import fccqp

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests")]

import problems  # noqa: E402 - tests/problems.py, found through the path set just above


def large_friction(n: int = 5000, seed: int = 0):
    """``tests/problems.large_problem``: a tridiagonal ``P``, two equalities, a box on
    most entries and one friction cone."""
    return problems.large_problem(n, seed)


def sparse_ls(size: int = 1700):
    """qpsolvers' sparse least squares with ``G x <= h`` as ``G x + t = h``, ``t >= 0``."""
    from qpsolvers.problems import get_sparse_least_squares

    R, s, G, h, A, b, _, _ = get_sparse_least_squares(size)
    n, k = R.shape[1], G.shape[0]
    P = sp.block_diag([(R.T @ R), sp.csc_matrix((k, k))], format="csc")
    q = np.concatenate([-(s @ R), np.zeros(k)])
    rows = sp.vstack([sp.hstack([A, sp.csr_matrix((A.shape[0], k))]),
                      sp.hstack([G, sp.eye(k)])], format="csc")
    lb = np.concatenate([np.full(n, -np.inf), np.zeros(k)])
    return P, q, rows, np.concatenate([b, h]), lb, np.full(n + k, np.inf), []


PROBLEMS = {"mpc": problems.mpc_problem, "large_friction": large_friction, "sparse_ls": sparse_ls}


def run_fccqp(problem):
    result = fccqp.solve(*problem, kkt_backend="sparse")
    return result.status.name, result.obj


def run_osqp(problem):
    import osqp

    P, q, A, b, lb, ub, cones = problem
    if cones:
        return None
    n = q.shape[0]
    boxed = np.flatnonzero(np.isfinite(lb) | np.isfinite(ub))
    rows = sp.vstack([A, sp.eye(n, format="csr")[boxed]], format="csc")
    solver = osqp.OSQP()
    solver.setup(sp.triu(P, format="csc"), q, rows, np.concatenate([b, lb[boxed]]),
                 np.concatenate([b, ub[boxed]]), verbose=False)
    result = solver.solve()
    return result.info.status, result.info.obj_val


def run_clarabel(problem):
    import clarabel

    from reference import clarabel_sparse_form  # tests/reference.py

    settings = clarabel.DefaultSettings()
    settings.verbose = False
    solution = clarabel.DefaultSolver(*clarabel_sparse_form(*problem), settings).solve()
    return str(solution.status), solution.obj_val


SOLVERS = {"fccqp": run_fccqp, "osqp": run_osqp, "clarabel": run_clarabel}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--problems", nargs="+", default=list(PROBLEMS), choices=PROBLEMS)
    args = parser.parse_args()
    problems = {name: PROBLEMS[name]() for name in args.problems}
    times = {(p, s): [] for p in problems for s in SOLVERS}
    outcome = {}
    jobs = [(p, s) for p in problems for s in SOLVERS]
    for round_ in range(args.rounds):
        shift = round_ % len(jobs)
        for p, s in jobs[shift:] + jobs[:shift]:
            start = time.perf_counter()
            answer = SOLVERS[s](problems[p])
            elapsed = time.perf_counter() - start
            if answer is not None:
                times[p, s].append(elapsed)
                outcome[p, s] = answer
    print(f"{args.rounds} rounds, median (min) ms of a cold solve, ratio of medians to fccqp")
    for p, problem in problems.items():
        n, m = problem[1].shape[0], problem[2].shape[0]
        print(f"{p}: n = {n}, m = {m}, KKT rows {n + m}")
        base = statistics.median(times[p, "fccqp"])
        for s in SOLVERS:
            if not times[p, s]:
                print(f"  {s:9s} (no cones)")
                continue
            median = statistics.median(times[p, s])
            status, obj = outcome[p, s]
            print(f"  {s:9s} {1e3 * median:9.2f} ({1e3 * min(times[p, s]):8.2f})"
                  f"  x{median / base:5.2f}  {status}  obj {obj:.10g}")


if __name__ == "__main__":
    main()
