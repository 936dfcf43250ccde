"""What Ruiz equilibration leaves on Maros-Meszaros problems, and what accuracy they ask.

Usage::

    python tools/maros_meszaros_scaling.py --data DIR [--passes 4] [--eps 1e-3] NAME ...

For each problem, in the slack form the qpsolvers backend builds
(:func:`fccqp.qpsolvers_backend.slack_form`): the infinity norms of the columns of
``[P; A]`` and of the rows of ``A`` before and after :func:`fccqp.scaling.equilibrate_py`
(range and geometric mean), ``D`` and ``E``, the cost scale ``c``, the columns where
``P`` acts, and the scaled ``P``'s and ``q``'s sizes. Then Clarabel's solution of the
user's problem: the sizes of ``x`` and of the multipliers, and the relative accuracy
``eps / size`` that qpbenchmark's absolute tolerance (``eps_rel`` 0) asks of the
primal (``eps / |x|``) and of the dual residual (``eps / |multipliers|``): what no
scaling changes, since the criterion is judged in the user's units.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import maros_meszaros as mm  # noqa: E402


def slack_form(problem):
    """``(P, q, A, b)`` dense over ``[x; s]``, as the qpsolvers backend poses it."""
    from fccqp import qpsolvers_backend
    from fccqp.problem import validate

    P, q, G, h, A, b, lb, ub = problem.unpack()
    return qpsolvers_backend.slack_form(validate(P, q, A, b, lb, ub), G, h)[0][:4]


def norms(P: np.ndarray, A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Infinity norms of the columns of ``[P; A]`` and of the rows of ``A``."""
    columns = np.abs(P).max(axis=0)
    if A.shape[0] == 0:
        return columns, np.zeros(0)
    return np.maximum(columns, np.abs(A).max(axis=0)), np.abs(A).max(axis=1)


def spread(values: np.ndarray) -> str:
    """Range and geometric mean of the positive entries."""
    values = values[values > 0]
    if values.size == 0:
        return "-"
    return (f"[{values.min():.2e}, {values.max():.2e}] "
            f"gmean {np.exp(np.log(values).mean()):.2e}")


def largest(*arrays: object) -> float:
    """Largest absolute entry over the given arrays (None and empty ones skipped)."""
    sizes = [np.abs(np.asarray(a, dtype=float)).max() for a in arrays
             if a is not None and np.size(a)]
    return max(sizes, default=0.0)


def report(name: str, path: Path, passes: int, eps: float) -> None:
    import qpsolvers
    from fccqp.scaling import equilibrate_py

    problem = mm._convert(mm.load_problem(path)[0], dense=True)
    P, q, A, b = slack_form(problem)
    n, m = P.shape[0], A.shape[0]
    columns, rows = norms(P, A)
    acting = int(np.count_nonzero(np.abs(P).max(axis=0)))
    print(f"{name}: n {n}, m {m} (slack form), P acts on {acting} columns")
    print(f"  before: columns {spread(columns)}, rows {spread(rows)}, |q| {largest(q):.2e}")
    P_s, q_s, A_s, b_s = P.copy(), q.copy(), np.ascontiguousarray(A), b.copy()
    D, E = np.ones(n), np.ones(m)
    none = np.zeros(0, dtype=np.intp)
    c = equilibrate_py(P_s, q_s, A_s, b_s, none, none, passes, D, E)
    columns, rows = norms(P_s / c, A_s)
    print(f"  after {passes} passes: columns {spread(columns)}, rows {spread(rows)}")
    print(f"  D {spread(D)}, E {spread(E)}, c {c:.2e}, c D P D columns "
          f"{spread(np.abs(P_s).max(axis=0))}, |c D q| {largest(q_s):.2e}")
    sol = qpsolvers.solve_problem(problem, solver="clarabel")
    x_size = largest(sol.x)
    multipliers = largest(sol.y, sol.z, sol.z_box)
    print(f"  Clarabel: |x| {x_size:.1e}, |multipliers| {multipliers:.1e}; "
          f"eps {eps:g} asks relative {eps / max(x_size, 1.0):.0e} of the primal, "
          f"{eps / max(multipliers, 1.0):.0e} of the dual")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, required=True, help="folder of the .mat files")
    parser.add_argument("--passes", type=int, default=4, help="Ruiz passes (Settings.scaling)")
    parser.add_argument("--eps", type=float, default=1e-3, help="qpbenchmark's eps_abs")
    parser.add_argument("problems", nargs="+")
    args = parser.parse_args(argv)
    files = mm.mat_files(args.data)
    for name in args.problems:
        report(name, files[name], args.passes, args.eps)
    return 0


if __name__ == "__main__":
    sys.exit(main())
