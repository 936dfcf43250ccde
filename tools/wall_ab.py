"""Wall time of two fccqp builds on the benchmark's ticks, measured in lockstep.

What: per tick of a robot's cached test set (the ``--full`` preset's: scenario ``mix``,
seed 0, 400 QPs in 4 sequences of 100 ticks; with ``--scenario contact_switch`` the set of
800 QPs in 4 sequences of 200 ticks whose every sequence makes and breaks contacts, seven
contact-change ticks a quadruped), the wall time of ``fccqp-realtime`` (or
``--variant``) and of ``daqp-pyr4`` through the benchmark's own adapters
(:mod:`benchmarks.solvers`), each timed as the harness times it, for two builds ``A``
and ``B`` of fccqp; the median and p95 over the ticks of each, the fccqp/DAQP ratios,
and ``B / A`` per tick.

Why: a shared machine's speed drifts by 1.5x over minutes, so two builds timed one
after the other differ by more than most changes do. Both builds run at once here,
each in its own worker process (a process imports one ``fccqp``), driven in lockstep:
one pass at a time, every round one pass of each (build, solver) in an order that
rotates from round to round, so that both builds see the same drifts. DAQP's ``B / A``
is the noise floor of a run (it should be 1).

How: each worker loads the set (``benchmarks/.cache`` of the build's own checkout,
generated there when missing), prepares every QP, warms each solver up with one pass,
freezes the garbage collector's objects and waits; a pass walks the QPs in order,
``cold`` resetting the solver before every QP (the benchmark's cold view), ``warm``
at each sequence start (its warm view), with the collector off; ``contact`` walks as
``warm`` and keeps the times of its contact-change ticks only (the benchmark's contact
change view: one tick per robot, whose wall time the rest of the walk's leaves cold
caches for); ``coarse`` walks every ``--stride``-th QP of each sequence, each warm from
the previous kept one and reset at each sequence start (the report's "every 10th" view,
``benchmarks.views.coarse_path``). Times are per tick the median over ``--rounds``. One
BLAS thread. Run::

    python tools/wall_ab.py /tmp/base /tmp/branch --robot go2 --mode cold --rounds 30

where each root is a built checkout (``python setup.py build_ext --inplace``); copy a
tree aside before building it if its sources are being edited.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

WORKER = r'''
import gc, json, sys
from threadpoolctl import threadpool_limits
from benchmarks.cache import DEFAULT_CACHE, cached_test_set
from benchmarks.solvers import make_adapter
from benchmarks.views import coarse_path, cold_path, contact_changes, warm_path

mode, robot, stride, scenario = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
names = sys.argv[5:]
n_qps, seq_len = (800, 200) if scenario == "contact_switch" else (400, 100)
test_set, _ = cached_test_set(DEFAULT_CACHE, robot, scenario, n_qps, 0, seq_len=seq_len,
                              dt=0.002, report=lambda line: print(line, file=sys.stderr))
path = (cold_path(test_set) if mode == "cold" else
        coarse_path(test_set, stride) if mode == "coarse" else warm_path(test_set))
shown = [True] * len(path) if mode != "contact" else list(contact_changes(path))
adapters = {name: make_adapter(name) for name in names}
prepared = {name: [a.prepare(test_set.qps[i]) for i in path.indices]
            for name, a in adapters.items()}


def one_pass(name):
    adapter, times = adapters[name], []
    for data, fresh in zip(prepared[name], path.fresh):
        if fresh:
            adapter.reset()
        times.append(adapter.solve(data).time)
    return times


with threadpool_limits(1):
    for name in names:
        one_pass(name)
    gc.collect()
    gc.freeze()
    print("ready", flush=True)
    for line in sys.stdin:
        gc.collect()
        gc.disable()
        times = one_pass(line.strip())
        gc.enable()
        print(json.dumps([t for t, s in zip(times, shown) if s]), flush=True)
'''
"""The worker: one build's solvers, a pass per line of stdin, its times on stdout."""
REFERENCE = "daqp-pyr4"
"""The peer timed beside fccqp in each worker."""
THREAD_ENV = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def start_worker(root: Path, mode: str, robot: str, stride: int, scenario: str,
                 names: list[str]) -> subprocess.Popen:
    """A worker on the build at ``root``, warmed up and waiting for passes."""
    env = dict(os.environ, PYTHONPATH=f"{root / 'src'}{os.pathsep}{root}",
               **dict.fromkeys(THREAD_ENV, "1"))
    worker = subprocess.Popen([sys.executable, "-c", WORKER, mode, robot, str(stride), scenario,
                               *names],
                              cwd=root, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                              text=True)
    if worker.stdout.readline().strip() != "ready":
        raise SystemExit(f"the worker on {root} failed (its errors are above)")
    return worker


def lockstep(workers: dict[str, subprocess.Popen], names: list[str],
             rounds: int) -> dict[tuple[str, str], np.ndarray]:
    """Per (build, solver) the times of each round and tick, one pass running at a time,
    the passes' order rotated by one from round to round."""
    keys = [(build, name) for build in workers for name in names]
    times: dict[tuple[str, str], list[list[float]]] = {key: [] for key in keys}
    for r in range(rounds):
        shift = r % len(keys)
        for build, name in keys[shift:] + keys[:shift]:
            worker = workers[build]
            worker.stdin.write(name + "\n")
            worker.stdin.flush()
            times[build, name].append(json.loads(worker.stdout.readline()))
    return {key: np.array(value) for key, value in times.items()}


def report(medians: dict[tuple[str, str], np.ndarray], roots: dict[str, Path],
           variant: str, per_tick: bool) -> None:
    """Median and p95 per build and solver, fccqp/DAQP, and B / A per tick (with
    ``per_tick``, each tick's medians and ratios too, in the walk's order)."""
    if per_tick:
        print(f"tick: {variant} A, B, B / A; {REFERENCE} A, B, B / A (us)")
        for k in range(len(medians["A", variant])):
            ours_a, ours_b = medians["A", variant][k], medians["B", variant][k]
            peer_a, peer_b = medians["A", REFERENCE][k], medians["B", REFERENCE][k]
            print(f"{k:4d}: {ours_a * 1e6:7.1f} {ours_b * 1e6:7.1f} {ours_b / ours_a:6.3f}; "
                  f"{peer_a * 1e6:7.1f} {peer_b * 1e6:7.1f} {peer_b / peer_a:6.3f}")
    for build, root in roots.items():
        ours, peer = medians[build, variant], medians[build, REFERENCE]
        print(f"{build} {root}: {variant} median {np.median(ours) * 1e6:.1f} us, p95 "
              f"{np.percentile(ours, 95) * 1e6:.1f} us; {REFERENCE} median "
              f"{np.median(peer) * 1e6:.1f} us, p95 {np.percentile(peer, 95) * 1e6:.1f} us; "
              f"ratio median {np.median(ours) / np.median(peer):.3f}, p95 "
              f"{np.percentile(ours, 95) / np.percentile(peer, 95):.3f}")
    for name in (variant, REFERENCE):
        ratio = medians["B", name] / medians["A", name]
        change = np.median(medians["B", name] - medians["A", name]) * 1e6
        print(f"{name} B / A per tick: median {np.median(ratio):.3f}, mean "
              f"{ratio.mean():.3f}; B - A median {change:+.2f} us")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a", type=Path, help="checkout of build A (the baseline), built")
    parser.add_argument("b", type=Path, help="checkout of build B, built")
    parser.add_argument("--robot", default="go2")
    parser.add_argument("--mode", choices=("cold", "warm", "contact", "coarse"), default="cold",
                        help="contact: the warm walk, timed at its contact-change ticks only; "
                             "coarse: every --stride-th QP, warm from the previous kept one")
    parser.add_argument("--scenario", choices=("mix", "contact_switch"), default="mix",
                        help="the test set: the --full preset's, or the contact_switch set")
    parser.add_argument("--stride", type=int, default=10, help="the coarse mode's step")
    parser.add_argument("--rounds", type=int, default=30)
    parser.add_argument("--variant", default="fccqp-realtime", help="the fccqp variant")
    parser.add_argument("--per-tick", action="store_true",
                        help="each timed tick's medians and ratios (for --mode contact)")
    args = parser.parse_args()
    roots = {"A": args.a.resolve(), "B": args.b.resolve()}
    names = [args.variant, REFERENCE]
    workers = {build: start_worker(root, args.mode, args.robot, args.stride,
                                         args.scenario, names)
               for build, root in roots.items()}
    try:
        times = lockstep(workers, names, args.rounds)
    finally:
        for worker in workers.values():
            worker.stdin.close()
            worker.wait()
    mode = f"every {args.stride}th" if args.mode == "coarse" else args.mode
    print(f"{args.robot}, {args.scenario}, {mode}, {args.rounds} rounds, per-tick medians")
    report({key: np.median(value, axis=0) for key, value in times.items()}, roots,
           args.variant, args.per_tick)


if __name__ == "__main__":
    main()
