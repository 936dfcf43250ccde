"""Iterations and exactness of fccqp on the contact-change ticks of a cached test set.

What: each robot's test set walked as the benchmark's warm view walks it (one
``fccqp.Solver`` with the realtime preset, ``Solver.reset()`` at each sequence start,
``benchmarks.views.warm_path``), and for each contact-change tick
(``benchmarks.views.contact_changes``: the stance differs from the previous tick's, no
reset in between) the tick, the stance before and after, the sizes, the iterations, the
polished flag, the status and the largest torque error in shares of the joint's limit
against the set's exact reference (``benchmarks.metrics.qp_metrics``, the report's
``torque_error_rel``), and DAQP's iterations on the same tick along the same walk (its
adapter, ``benchmarks.pyramid_solvers.DaqpAdapter``); then the iterations over all ticks
of the walk. With ``--mapped``, fccqp starts each contact-change tick from the previous
answer carried by the contact points (``benchmarks.exact_solvers.carried_guess``, as the
benchmark's adapter does) and DAQP from its multipliers carried likewise; without it,
as both did before the map: fccqp from its own warm start, DAQP from its previous
multipliers where the sizes match.

Why: the report's contact-change view is a median over one tick per robot in the
``mix`` sets (tick 360 of ``--full``, 54 of ``--quick``); a ``contact_switch`` set
(``--scenario contact_switch --n-qps 800 --seq-len 200``, generated and cached in
``--cache`` on the first run, seconds per robot) has trot switches and feet put down
again, to judge a change of how the solver crosses a contact change. Run it on the
revision before and after (``PYTHONPATH=<build>/src:<build>``), same arguments::

    python tools/contact_ticks.py [--robots go2 ...] [--mapped]
                                  [--scenario mix --n-qps 400 --seq-len 100]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))   # this checkout's benchmarks
sys.path.insert(0, str(ROOT / "tools"))
from answer_census import imported_fccqp, tick_arguments  # noqa: E402
from benchmarks.cache import cached_test_set  # noqa: E402
from benchmarks.contact_map import ContactMaps  # noqa: E402
from benchmarks.exact_solvers import carried_guess, fccqp_arguments  # noqa: E402
from benchmarks.metrics import qp_metrics  # noqa: E402
from benchmarks.pyramid_solvers import DaqpAdapter  # noqa: E402
from benchmarks.views import contact_changes, warm_path  # noqa: E402


def contact_ticks(fccqp: object, test_set: object, budget: float,
                  mapped: bool) -> tuple[list[str], int]:
    """The lines of the contact-change ticks of ``test_set``'s warm walk, and the
    iterations of the whole walk; ``mapped``: fccqp starts a contact-change tick from
    the carried answer."""
    path = warm_path(test_set)
    changed = contact_changes(path)
    solver = fccqp.Solver(fccqp.Settings.realtime(budget))
    daqp, maps = DaqpAdapter("daqp", carry=mapped), ContactMaps()
    lines, iterations, previous, answer = [], 0, None, None
    for i, fresh, change in zip(path.indices, path.fresh, changed, strict=True):
        if fresh:
            solver.reset()
            daqp.reset()
            answer = None
        qp = test_set.qps[i]
        guess = carried_guess(maps, answer, qp) if mapped else {}
        result = solver.solve(*fccqp_arguments(qp), **guess)
        answer = (qp, result)
        pyramid = daqp.solve(daqp.prepare(qp))
        iterations += result.iterations
        if change:
            error = qp_metrics(qp, result.x, test_set.x_ref[i]).torque_error_rel
            lines.append(f"tick {i}: {'+'.join(test_set.stance[previous])} -> "
                         f"{'+'.join(test_set.stance[i])} (n {test_set.qps[previous].n} -> "
                         f"{qp.n}), iterations {result.iterations}, polished "
                         f"{int(result.polished)}, {result.status.name}, torque error "
                         f"{error:.2%}; daqp iterations {pyramid.iterations}")
        previous = i
    return lines, iterations


def main(argv: list[str] | None = None) -> None:
    """Print each robot's contact-change ticks (one BLAS thread)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    tick_arguments(parser)
    parser.add_argument("--scenario", default="mix")
    parser.add_argument("--n-qps", type=int, default=400)
    parser.add_argument("--seq-len", type=int, default=100)
    parser.add_argument("--mapped", action="store_true",
                        help="start fccqp's contact-change ticks from the carried answer")
    args = parser.parse_args(argv)
    fccqp = imported_fccqp()
    for robot in args.robots:
        test_set, _ = cached_test_set(args.cache, robot, args.scenario, args.n_qps, 0,
                                      seq_len=args.seq_len, report=lambda line: None)
        lines, iterations = contact_ticks(fccqp, test_set, args.budget, args.mapped)
        print(f"{robot}: {len(lines)} contact-change ticks, {iterations} iterations in all "
              f"{len(test_set)} ticks")
        for line in lines:
            print(f"  {line}", flush=True)


if __name__ == "__main__":
    main()
