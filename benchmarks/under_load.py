"""Solve times unloaded and under CPU load: does a busy machine slow the solver down?

A controller shares its computer with other processes. This script times every solver
over one robot's test set (``generate_test_set(robot, "mix", n, seed)``, warm along
sequences where the solver supports it, as in the main benchmark). Rounds alternate
between unloaded and loaded. A loaded round has ``--load`` CPU-bound background
processes (three by default, on what is meant to be a 2-core machine). The script prints
the median solve time of each solver unloaded and loaded, and their ratio. The issue #12
target is a ratio of at most 3 for fccqp, with the library defaults a user has: this
script does not limit any thread pool, and it prints what threadpoolctl sees so that the
run says which BLAS and how many threads were in play.

Solvers come from :mod:`benchmarks.solvers` (``fccqp-realtime``, ``fccqp-default``,
``daqp-pyr4`` on the 4-facet inner pyramid, ``clarabel``). While the registry has no
``daqp-pyr4``, a small local adapter with the same conventions stands in for it. A name
that is unknown, or whose module is missing, is listed as skipped.

Run ``python -m benchmarks.under_load [--robot solo12] [--n-qps 200] [--rounds 4]``.
The background processes exit by themselves after ``--max-seconds``. They are also
killed as each loaded round ends, and on any error. Nothing is written to disk.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np

from benchmarks import solvers
from benchmarks.testsets import MIX, TestSet, generate_test_set

__all__ = [
    "DEFAULT_SOLVERS",
    "LoadResult",
    "blas_info",
    "busy_cpus",
    "cpu_load",
    "main",
    "measure",
]

DEFAULT_SOLVERS = ("fccqp-realtime", "fccqp-default", "daqp-pyr4", "clarabel")
"""Solvers timed by default (those the registry knows and that are installed)."""

_SPIN = "import time\nt = time.monotonic() + {seconds}\nwhile time.monotonic() < t: pass\n"


@contextlib.contextmanager
def cpu_load(count: int, max_seconds: float = 600.0) -> Iterator[list[subprocess.Popen]]:
    """Run ``count`` CPU-bound Python processes for the duration of the block.

    Each process also exits by itself after ``max_seconds``. On leaving the block, the
    processes this function started are killed by their own handles and reaped.
    """
    code = _SPIN.format(seconds=float(max_seconds))
    procs: list[subprocess.Popen] = []
    try:
        for _ in range(count):
            procs.append(subprocess.Popen([sys.executable, "-c", code]))
        if procs:
            time.sleep(0.3)  # let the scheduler see them before timing starts
        yield procs
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
        for p in procs:
            p.wait()


def busy_cpus(interval: float = 0.5) -> float | None:
    """How many CPUs other processes kept busy over ``interval`` s (None without /proc/stat).

    This process sleeps meanwhile, so the figure is the load of the rest of the machine:
    an "unloaded" round is only unloaded if this is close to 0.
    """

    def read() -> tuple[int, int] | None:
        try:
            with open("/proc/stat") as fh:
                fields = [int(v) for v in fh.readline().split()[1:]]
        except (OSError, ValueError):
            return None
        idle = fields[3] + (fields[4] if len(fields) > 4 else 0)
        return sum(fields), idle

    a = read()
    time.sleep(interval)
    b = read()
    if a is None or b is None or b[0] == a[0]:
        return None
    total, idle = b[0] - a[0], b[1] - a[1]
    return (total - idle) / total * (os.cpu_count() or 1)


def blas_info() -> list[dict]:
    """What threadpoolctl reports about the loaded BLAS/OpenMP libraries (may be empty)."""
    try:
        import threadpoolctl
    except ImportError:
        return []
    return threadpoolctl.threadpool_info()


@dataclass
class LoadResult:
    """Per-solver solve times (seconds), unloaded and loaded, pooled over rounds."""

    unloaded: dict[str, list[float]] = field(default_factory=dict)
    loaded: dict[str, list[float]] = field(default_factory=dict)
    solved: dict[str, list[bool]] = field(default_factory=dict)
    skipped: dict[str, str] = field(default_factory=dict)
    busy: list[float] = field(default_factory=list)
    """CPUs busy with other processes just before each unloaded round (Linux only)."""

    def median(self, name: str, loaded: bool) -> float:
        """Median solve time of ``name`` (s)."""
        return statistics.median((self.loaded if loaded else self.unloaded)[name])

    def ratio(self, name: str) -> float:
        """Loaded median over unloaded median."""
        return self.median(name, True) / self.median(name, False)


def _pass(adapter, data: Sequence[object], sequence: np.ndarray):
    """One pass over the set in controller order, resetting at sequence boundaries."""
    adapter.reset()
    times, solved = [], []
    previous = None
    for item, seq in zip(data, sequence, strict=True):
        if previous is not None and seq != previous:
            adapter.reset()
        previous = seq
        outcome = adapter.solve(item)
        times.append(outcome.time)
        solved.append(bool(outcome.success))
    return times, solved


@dataclass(frozen=True)
class _Outcome:
    time: float
    success: bool


class _DaqpPyramid:
    """DAQP on the 4-facet inner pyramid, warm from the previous multipliers.

    Used only while :data:`benchmarks.solvers.VARIANTS` has no ``daqp-pyr4`` entry. It
    follows the same conventions: DAQP defaults, equalities as ``sense`` 5 rows, torque
    bounds as simple bounds, only the ``daqp.solve`` call timed.
    """

    name = "daqp-pyr4"

    def __init__(self) -> None:
        import daqp

        self._daqp = daqp
        self._lam: np.ndarray | None = None

    def prepare(self, qp) -> tuple:
        G, h = qp.pyramid(facets=4, inner=True)
        m = qp.A.shape[0]
        rows = np.ascontiguousarray(np.vstack([qp.A, G]))
        upper = np.concatenate([qp.ub, qp.b, h])
        lower = np.concatenate([qp.lb, qp.b, np.full(h.shape, -np.inf)])
        sense = np.zeros(upper.shape, dtype=np.int32)
        sense[qp.n : qp.n + m] = 5
        return (np.array(qp.P), np.array(qp.q), rows, upper, lower, sense)

    def solve(self, data: tuple) -> _Outcome:
        lam = self._lam
        warm = {"dual_start": lam} if lam is not None and lam.shape == data[3].shape else {}
        start = time.perf_counter()
        _, _, exitflag, info = self._daqp.solve(*data, **warm)
        elapsed = time.perf_counter() - start
        self._lam = np.array(info["lam"]) if exitflag == 1 else None
        return _Outcome(elapsed, exitflag == 1)

    def reset(self) -> None:
        self._lam = None


_FALLBACKS = {"daqp-pyr4": ("daqp", _DaqpPyramid)}
"""Adapters used when the registry lacks the name: name -> (module, factory)."""


def _select(names: Sequence[str]) -> tuple[dict[str, object], dict[str, str]]:
    """Adapters for the installed solvers among ``names``, and why the others are skipped."""
    known = [n for n in names if n in solvers.VARIANTS]
    found, missing = solvers.available_variants(known)
    skipped = {n: "not installed" for n in missing}
    adapters: dict[str, object] = {n: solvers.make_adapter(n) for n in found}
    for n in names:
        if n in known:
            continue
        if n in _FALLBACKS and importlib.util.find_spec(_FALLBACKS[n][0]) is not None:
            adapters[n] = _FALLBACKS[n][1]()
        else:
            skipped[n] = "not in benchmarks.solvers.VARIANTS or not installed"
    return {n: adapters[n] for n in names if n in adapters}, skipped


def measure(
    test_set: TestSet,
    names: Sequence[str] = DEFAULT_SOLVERS,
    *,
    rounds: int = 4,
    load: int = 3,
    max_seconds: float = 600.0,
    warmup: int = 5,
) -> LoadResult:
    """Time each solver over ``test_set`` in ``rounds`` alternating unloaded/loaded rounds.

    Round ``r`` is unloaded when ``r`` is even and loaded otherwise, so with an even
    number of rounds both states get the same number of passes and any drift of the
    machine hits both states alike. The solvers' order rotates from round to round.
    Every solver first solves ``warmup`` QPs untimed (for JIT compilation and caches).
    """
    if rounds < 2:
        raise ValueError("rounds must be >= 2 (one unloaded and one loaded)")
    adapters, skipped = _select(names)
    found = list(adapters)
    result = LoadResult(skipped=skipped)
    prepared = {n: [a.prepare(qp) for qp in test_set.qps] for n, a in adapters.items()}
    for n, a in adapters.items():
        k = min(warmup, len(test_set))
        _pass(a, prepared[n][:k], test_set.sequence[:k])
        result.unloaded[n], result.loaded[n], result.solved[n] = [], [], []
    for r in range(rounds):
        loaded = r % 2 == 1
        order = found[r % len(found) :] + found[: r % len(found)] if found else []
        if not loaded:
            busy = busy_cpus()
            if busy is not None:
                result.busy.append(busy)
        with cpu_load(load if loaded else 0, max_seconds):
            for n in order:
                times, solved = _pass(adapters[n], prepared[n], test_set.sequence)
                (result.loaded if loaded else result.unloaded)[n].extend(times)
                result.solved[n].extend(solved)
    return result


def format_table(result: LoadResult, load: int) -> str:
    """The medians, the loaded p90 and the ratio as a small text table."""
    lines = [
        f"{'solver':16s} {'unloaded us':>12s} {'loaded us':>10s} {'loaded p90':>11s} "
        f"{'ratio':>6s} {'solved':>7s}"
    ]
    for n in result.unloaded:
        loaded = result.loaded[n]
        p90 = statistics.quantiles(loaded, n=10)[-1] if len(loaded) > 1 else loaded[0]
        solved = float(np.mean(result.solved[n])) if result.solved[n] else float("nan")
        lines.append(
            f"{n:16s} {result.median(n, False) * 1e6:12.0f} {result.median(n, True) * 1e6:10.0f} "
            f"{p90 * 1e6:11.0f} {result.ratio(n):6.2f} {solved:7.1%}"
        )
    if result.busy:
        worst = max(result.busy)
        note = "" if worst < 0.3 else "  WARNING: other processes were running"
        lines.append(
            f"CPUs busy with other processes before unloaded rounds: max {worst:.2f}{note}"
        )
    for n, why in result.skipped.items():
        lines.append(f"{n:16s} skipped: {why}")
    lines.append(
        f"load: {load} CPU-bound processes on {os.cpu_count()} CPUs; ratio = loaded/unloaded"
    )
    return "\n".join(lines)


def format_blas(info: list[dict]) -> str:
    """One line per library threadpoolctl found."""
    if not info:
        return "threadpoolctl: not installed or no BLAS found"
    return "\n".join(
        f"threadpoolctl: {i.get('internal_api')} {i.get('version')} "
        f"({i.get('threading_layer', '?')}), num_threads={i.get('num_threads')}, "
        f"{os.path.basename(i.get('filepath', ''))}"
        for i in info
    )


def main(argv: Sequence[str] | None = None) -> None:
    """Parse arguments, generate the test set, measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="solo12", help="a key of benchmarks.robots.ROBOTS")
    parser.add_argument("--n-qps", type=int, default=200, help="QPs in the test set")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--rounds", type=int, default=4, help="alternating rounds (even)")
    parser.add_argument("--load", type=int, default=3, help="background processes")
    parser.add_argument(
        "--max-seconds", type=float, default=600.0, help="lifetime cap of each background process"
    )
    parser.add_argument("--solvers", nargs="+", default=list(DEFAULT_SOLVERS))
    args = parser.parse_args(argv)
    if args.rounds < 2 or args.load < 1 or args.n_qps < 1:
        parser.error("need --rounds >= 2, --load >= 1 and --n-qps >= 1")
    test_set = generate_test_set(args.robot, MIX, args.n_qps, args.seed)
    result = measure(
        test_set, args.solvers, rounds=args.rounds, load=args.load, max_seconds=args.max_seconds
    )
    env = {k: v for k, v in os.environ.items() if k.endswith("_NUM_THREADS")}
    threads = f"thread variables set: {env}" if env else "library thread defaults"
    head = f"{args.robot}, {len(test_set)} QPs ({MIX}, seed {args.seed}), {args.rounds} rounds"
    print(f"{head}, {threads}")
    print(format_table(result, args.load))
    print(format_blas(blas_info()))


if __name__ == "__main__":
    main()
