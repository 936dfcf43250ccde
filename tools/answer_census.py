"""Iterations, polished and solved ticks of fccqp over the benchmark's whole test sets.

What: for each robot of the benchmark (solo12, anymal_c, go2, talos_reduced) and each
mode (warm along the sequences, cold with ``Solver.reset()`` before every QP), the sum of
``Result.iterations`` and the counts of polished and SOLVED answers of the realtime
preset (with a budget that never stops a solve, as ``tools/callgrind_ticks.py`` uses)
over all 400 QPs of the ``--full`` test set, plus a digest of the answers.

Why: ``tools/callgrind_ticks.py`` counts instructions on the first 100 QPs of go2 and
talos_reduced, under valgrind; a change of the polish or the iteration can keep those
cells' answers and still change the others (the polish's give-up after two infeasible
guesses kept go2's first 100 answers and left 24 more of its 400 cold ticks unpolished).
This census runs natively in seconds: run it on the revision before and after a change
(same command) and compare the lines; equal digests, equal answers.

    PYTHONPATH=<build>/src:<build> python tools/answer_census.py [--robots go2 ...]
"""

from __future__ import annotations

import argparse
import hashlib
import sys
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
from callgrind_ticks import load_qps, set_path  # noqa: E402  (this checkout's driver)

ROBOTS = ("solo12", "anymal_c", "go2", "talos_reduced")
FLAT = np.array([0.0, 0.0, 1.0])


def arguments(raw: tuple[np.ndarray, ...], fccqp: object) -> tuple:
    """``Solver.solve``'s arguments of one cached QP, as the benchmark's adapter makes them."""
    P, q, A, b, lb, ub, starts, mus, normals = raw
    cones = tuple(fccqp.FrictionCone(int(s), float(mu),
                                     None if np.allclose(n, FLAT) else tuple(map(float, n)))
                  for s, mu, n in zip(starts, mus, normals, strict=True))
    return P, q, A, b, lb, ub, cones


def census(fccqp: object, qps: list[tuple], sequence: np.ndarray, mode: str,
           budget: float) -> str:
    """One line: iterations, polished, solved and the answers' digest of a pass."""
    solver = fccqp.Solver(fccqp.Settings.realtime(budget))
    digest = hashlib.sha256()
    iterations = polished = solved = 0
    for i, qp in enumerate(qps):
        if mode == "cold" or (i > 0 and sequence[i] != sequence[i - 1]):
            solver.reset()
        result = solver.solve(*qp)
        iterations += result.iterations
        polished += result.polished
        solved += result.status is fccqp.Status.SOLVED
        digest.update(np.ascontiguousarray(result.x).tobytes())
        digest.update(result.status.value.encode())
    return (f"iterations {iterations}, polished {polished}, solved {solved} of {len(qps)}, "
            f"x `{digest.hexdigest()[:12]}`")


def tick_arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments every per-tick tool here takes: robots, the test sets' cache, the
    realtime preset's time limit."""
    parser.add_argument("--robots", nargs="+", choices=ROBOTS, default=list(ROBOTS))
    parser.add_argument("--cache", type=Path, default=ROOT / "benchmarks" / ".cache")
    parser.add_argument("--budget", type=float, default=100.0,
                        help="the realtime preset's time limit (s); large: never stops a solve")


def imported_fccqp() -> object:
    """fccqp from ``PYTHONPATH`` (the build under test, whose folder is printed), with one
    BLAS thread."""
    import fccqp

    threadpool_limits(1)
    print(f"fccqp: {Path(fccqp.__file__).parent}")
    return fccqp


def main(argv: list[str] | None = None) -> None:
    """Print the census of each robot and mode asked for (one BLAS thread)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    tick_arguments(parser)
    parser.add_argument("--modes", nargs="+", choices=("warm", "cold"),
                        default=["warm", "cold"])
    args = parser.parse_args(argv)
    fccqp = imported_fccqp()
    for robot in args.robots:
        raw, sequence = load_qps(set_path(robot, args.cache), 400)
        qps = [arguments(r, fccqp) for r in raw]
        for mode in args.modes:
            print(f"{robot} {mode}: {census(fccqp, qps, sequence, mode, args.budget)}",
                  flush=True)


if __name__ == "__main__":
    main()
