"""Determinism and per-solve allocations of fccqp over a warm-started sequence.

1. **Bit-identical outputs.** The script solves one robot's test set in controller order,
   warm across each sequence and reset at sequence boundaries. It does this twice in this
   process, each time with a fresh :class:`fccqp.Solver`, and once in each of two fresh
   processes. It checks that ``x``, ``y``, ``z`` (their bytes), ``iterations`` and
   ``status`` are bit-identical across the four runs. Processes are compared through a
   SHA-256 digest of those fields. The QPs go to the child processes through
   :func:`benchmarks.testsets.save` in a temporary directory, so every run sees the same
   bytes.
2. **Python-level allocations per solve in steady state**, measured with
   :mod:`tracemalloc`. After one untimed pass over the set (the workspace and any cache
   are allocated), each measured solve runs between ``tracemalloc.clear_traces()`` and a
   snapshot, with the peak reset before it. The script reports three figures. *Retained*
   counts the blocks allocated during the solve that are still alive when it returns:
   their number and bytes, minus the ``Result`` arrays ``x``, ``y``, ``z`` and
   ``certificate`` (their data buffers, traced by numpy in its own tracemalloc domain).
   *Peak* is the largest traced size during the solve, minus those arrays, and it bounds
   the temporaries the solve allocates and frees. *Sites* lists the source lines that
   allocate the most. The issue #12 target is no allocation beyond the ``Result`` arrays,
   so retained blocks beyond the ``Result`` itself, and peak bytes beyond its arrays,
   should both be near zero.

Only the public API is used (``fccqp.Solver``, ``fccqp.Settings``, ``Settings.realtime``,
``fccqp.Result``, ``fccqp.FrictionCone``). Run
``python -m benchmarks.determinism [--robot solo12] [--n-qps 100]``. The exit status is 1
when some outputs differ. Nothing is written outside a temporary directory.
"""

from __future__ import annotations

import argparse
import hashlib
import math
import os
import statistics
import subprocess
import sys
import tempfile
import tracemalloc
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from benchmarks import testsets
from benchmarks.exact_solvers import fccqp_arguments
from benchmarks.testsets import MIX, TestSet

__all__ = [
    "Allocations",
    "allocations",
    "child_digests",
    "digest",
    "first_difference",
    "main",
    "run_sequence",
]

SETTINGS = ("realtime", "default")
"""Settings presets checked: ``Settings.realtime(math.inf)`` (no time budget) and
``Settings()``."""

_NUMPY_DOMAIN = 389047
"""tracemalloc domain numpy traces its data buffers in (``NPY_TRACE_DOMAIN``)."""

_ROOT = Path(__file__).resolve().parent.parent


def _settings(name: str):
    import fccqp

    # the realtime preset's budget is the one decision that depends on the clock: off
    # here, so that the comparison is of the arithmetic
    return fccqp.Settings.realtime(math.inf) if name == "realtime" else fccqp.Settings()


Record = tuple[bytes, bytes, bytes, int, str]
"""What must be bit-identical: bytes of x, y, z, then iterations and status value."""


def _record(result) -> Record:
    return (
        np.ascontiguousarray(result.x, dtype=float).tobytes(),
        np.ascontiguousarray(result.y, dtype=float).tobytes(),
        np.ascontiguousarray(result.z, dtype=float).tobytes(),
        int(result.iterations),
        str(result.status.value),
    )


def run_sequence(test_set: TestSet, settings: str) -> list[Record]:
    """Solve the set in order with one fresh Solver, resetting at sequence boundaries."""
    import fccqp

    solver = fccqp.Solver(_settings(settings))
    args = [fccqp_arguments(qp) for qp in test_set.qps]
    records, previous = [], None
    for a, seq in zip(args, test_set.sequence, strict=True):
        if previous is not None and seq != previous:
            solver.reset()
        previous = seq
        records.append(_record(solver.solve(*a)))
    return records


def digest(records: Sequence[Record]) -> str:
    """SHA-256 over every record's fields, in order."""
    h = hashlib.sha256()
    for x, y, z, iterations, status in records:
        for part in (x, y, z, str(iterations).encode(), status.encode()):
            h.update(len(part).to_bytes(8, "little"))
            h.update(part)
    return h.hexdigest()


def first_difference(a: Sequence[Record], b: Sequence[Record]) -> str | None:
    """Where two runs first differ (QP index and field), or None when bit-identical."""
    if len(a) != len(b):
        return f"lengths {len(a)} != {len(b)}"
    names = ("x", "y", "z", "iterations", "status")
    for i, (ra, rb) in enumerate(zip(a, b, strict=True)):
        for name, fa, fb in zip(names, ra, rb, strict=True):
            if fa != fb:
                return f"QP {i}: {name} differs"
    return None


def child_digests(path: Path, settings: Sequence[str]) -> dict[str, str]:
    """Digests computed by a fresh interpreter from the test set saved at ``path``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(_ROOT), env.get("PYTHONPATH", "")) if p)
    cmd = [
        sys.executable,
        "-m",
        "benchmarks.determinism",
        "--child",
        str(path),
        "--settings",
        *settings,
    ]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=_ROOT, env=env)
    if out.returncode != 0:
        raise RuntimeError(f"child process failed:\n{out.stderr}")
    pairs = (line.split() for line in out.stdout.splitlines() if line.strip())
    return {name: value for name, value in pairs}


@dataclass(frozen=True)
class Allocations:
    """Steady-state tracemalloc figures per solve (medians over the measured solves)."""

    solves: int
    retained_blocks: float
    retained_bytes: float
    result_array_bytes: float
    retained_beyond_arrays_bytes: float
    retained_python_blocks: float
    peak_bytes: float
    peak_beyond_arrays_bytes: float
    sites: list[tuple[str, int, int]]
    """(file:line, blocks, bytes) of the top allocation sites over all measured solves."""


def _array_bytes(result) -> int:
    arrays = [result.x, result.y, result.z, result.certificate]
    return sum(int(a.nbytes) for a in arrays if isinstance(a, np.ndarray))


def allocations(test_set: TestSet, settings: str, top: int = 5) -> Allocations:
    """Trace each solve of a second pass over the set (the first pass warms up)."""
    import fccqp

    solver = fccqp.Solver(_settings(settings))
    args = [fccqp_arguments(qp) for qp in test_set.qps]
    previous = None

    def solve(i: int):
        nonlocal previous
        if previous is not None and test_set.sequence[i] != previous:
            solver.reset()
        previous = test_set.sequence[i]
        return solver.solve(*args[i])

    for i in range(len(args)):
        solve(i)
    previous = None
    rows = []
    site_blocks: dict[str, list[int]] = {}
    was_tracing = tracemalloc.is_tracing()
    if not was_tracing:
        tracemalloc.start(1)
    try:
        result = None
        for i in range(len(args)):
            del result  # the previous Result is freed before the measured solve starts
            tracemalloc.clear_traces()
            tracemalloc.reset_peak()
            result = solve(i)
            _, peak = tracemalloc.get_traced_memory()
            snap = tracemalloc.take_snapshot()
            traces = [t for t in snap.traces if t.domain in (0, _NUMPY_DOMAIN)]
            blocks = len(traces)
            size = sum(t.size for t in traces)
            python_blocks = sum(1 for t in traces if t.domain == 0)
            arrays = _array_bytes(result)
            rows.append((blocks, size, arrays, size - arrays, python_blocks, peak, peak - arrays))
            for stat in snap.statistics("lineno"):
                frame = stat.traceback[0]
                key = f"{os.path.basename(frame.filename)}:{frame.lineno}"
                acc = site_blocks.setdefault(key, [0, 0])
                acc[0] += stat.count
                acc[1] += stat.size
    finally:
        if not was_tracing:
            tracemalloc.stop()
    med = [statistics.median(col) for col in zip(*rows, strict=True)]
    n = len(rows)
    sites = sorted(site_blocks.items(), key=lambda kv: -kv[1][1])[:top]
    return Allocations(n, *med, sites=[(k, round(v[0] / n), round(v[1] / n)) for k, v in sites])


def _child(path: str, settings: Sequence[str]) -> None:
    test_set = testsets.load(path)
    for name in settings:
        print(name, digest(run_sequence(test_set, name)))


def main(argv: Sequence[str] | None = None) -> int:
    """Parse arguments, check determinism, trace allocations, print; 1 if outputs differ."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="solo12", help="a key of benchmarks.robots.ROBOTS")
    parser.add_argument("--n-qps", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--seq-len", type=int, default=50, help="QPs per warm sequence")
    parser.add_argument("--settings", nargs="+", choices=SETTINGS, default=list(SETTINGS))
    parser.add_argument("--child", metavar="NPZ", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        _child(args.child, args.settings)
        return 0
    test_set = testsets.generate_test_set(
        args.robot, MIX, args.n_qps, args.seed, seq_len=args.seq_len
    )
    same = True
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "set.npz"
        testsets.save(test_set, path)
        children = [child_digests(path, args.settings) for _ in range(2)]
    print(
        f"{args.robot}, {len(test_set)} QPs ({MIX}, seed {args.seed}), "
        f"{len(set(test_set.sequence.tolist()))} warm sequences"
    )
    print(f"{'settings':9s} {'in-process':>11s} {'2 processes':>12s}  digest")
    for name in args.settings:
        a, b = run_sequence(test_set, name), run_sequence(test_set, name)
        diff = first_difference(a, b)
        mine = digest(a)
        across = all(c[name] == mine for c in children)
        same = same and diff is None and across
        print(
            f"{name:9s} {'identical' if diff is None else diff:>11s} "
            f"{'identical' if across else 'DIFFERENT':>12s}  {mine[:16]}"
        )
    print("\nallocations per solve in steady state (medians; tracemalloc):")
    print(
        f"{'settings':9s} {'blocks':>7s} {'py blocks':>9s} {'bytes':>8s} {'Result arr':>10s} "
        f"{'beyond':>8s} {'peak':>8s} {'peak beyond':>11s}"
    )
    for name in args.settings:
        al = allocations(test_set, name)
        print(
            f"{name:9s} {al.retained_blocks:7.0f} {al.retained_python_blocks:9.0f} "
            f"{al.retained_bytes:8.0f} {al.result_array_bytes:10.0f} "
            f"{al.retained_beyond_arrays_bytes:8.0f} {al.peak_bytes:8.0f} "
            f"{al.peak_beyond_arrays_bytes:11.0f}"
        )
        for site, blocks, size in al.sites:
            print(f"    {site:40s} {blocks:5d} blocks {size:8d} B retained")
    print(
        "blocks/bytes: alive at return and allocated during the solve; 'beyond' subtracts "
        "the Result arrays' data; peak: largest traced size during the solve"
    )
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
