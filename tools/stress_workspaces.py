"""Many solvers created and dropped in one process: a crash or a history-dependent answer
shows memory that a workspace uses after it was released.

What: ``--iterations`` rounds over the four robots' ``--full`` sets (cached in
``benchmarks/.cache``). Each round makes a fresh :class:`fccqp.Solver` (the default and the
realtime preset in turn) and solves one QP cold, whose answer must be the same bit for bit
every time that QP is solved so; then it walks 30 ticks across the set's contact change
(tick 360) with the benchmark's ``fccqp-realtime`` adapter (a new workspace per contact
set, the carried guess); a few of those solvers are kept alive for a while and dropped out
of order, so that workspaces are released while others are made.

Why: session 35 found with this loop that the workspaces' shared 2 MB pools
(``fccqp.workspace_arrays``) were freed while a workspace's arrays were in them: a
segmentation fault in a new talos workspace's first solve after 600-2750 rounds, or,
with released pools reused, a convex QP answered "not convex". The cause was
``owner.kept[-1]`` under the module's ``wraparound=False``: it read the word before the
list's items, and where that word happened to be the current pool the pool was not kept.
A run takes about 30 s per 1000 rounds. Run::

    python tools/stress_workspaces.py --iterations 3000

(``python -X faulthandler`` prints the Python stack of a crash.) Exit status 1 when an
answer changed.
"""

from __future__ import annotations

import argparse
import hashlib
from pathlib import Path

from benchmarks.cache import DEFAULT_CACHE, cached_test_set
from benchmarks.exact_solvers import fccqp_arguments
from benchmarks.solvers import make_adapter

import fccqp

ROBOTS = ("solo12", "anymal_c", "go2", "talos_reduced")
KEPT = 5   # solvers kept alive at once, dropped out of order


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--iterations", type=int, default=3000)
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE)
    args = parser.parse_args()
    sets = {robot: cached_test_set(args.cache, robot, "mix", 400, 0, seq_len=100, dt=0.002,
                                   report=lambda line: None)[0] for robot in ROBOTS}
    first: dict[tuple[str, int, bool], str] = {}
    kept: list[object] = []
    changed = 0
    for k in range(args.iterations):
        robot = ROBOTS[k % len(ROBOTS)]
        test_set = sets[robot]
        qp, realtime = (k * 37) % len(test_set.qps), bool(k % 2)
        solver = fccqp.Solver(fccqp.Settings.realtime(100.0) if realtime else fccqp.Settings())
        x = solver.solve(*fccqp_arguments(test_set.qps[qp])).x
        digest = hashlib.sha1(x.tobytes()).hexdigest()
        if first.setdefault((robot, qp, realtime), digest) != digest:
            changed += 1
            print(f"round {k}: {robot} QP {qp} answered differently", flush=True)
        adapter = make_adapter("fccqp-realtime")
        start = 340 + k % 15
        for i in range(start, start + 30):
            adapter.solve(adapter.prepare(test_set.qps[i]))
        if k % 3 == 0:
            kept.append((adapter, solver))
        if len(kept) > KEPT:
            kept.pop(k % KEPT)
        if k % 500 == 0:
            print(f"round {k}: {changed} changed answers", flush=True)
    print(f"{args.iterations} rounds: {changed} changed answers")
    raise SystemExit(1 if changed else 0)


if __name__ == "__main__":
    main()
