"""Command line: ``python -m benchmarks [--quick | --full] [options]`` and ``... export``.

The benchmark loads (or generates and caches, :mod:`benchmarks.cache`) one test set per
robot (scenario ``mix`` by default), runs every installed solver variant on it
(:mod:`benchmarks.harness`) with the BLAS thread pools limited, and writes the report
(:mod:`benchmarks.report`) into the output folder, by default one that git ignores.
``python -m benchmarks export ...`` writes a test set for qpbenchmark instead
(:mod:`benchmarks.export`).
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from threadpoolctl import threadpool_limits

from benchmarks import export
from benchmarks.baseline import KktFloor
from benchmarks.cache import DEFAULT_CACHE, cached_test_set
from benchmarks.harness import run_variants
from benchmarks.machine import blas_info, load_average
from benchmarks.presets import PRESETS
from benchmarks.report import RunInfo, write_outputs
from benchmarks.robots import ROBOTS
from benchmarks.scenarios import SCENARIOS
from benchmarks.solvers import VARIANTS, available_variants, make_adapter
from benchmarks.testsets import MIX

__all__ = ["DEFAULT_OUT", "build_parser", "main"]

DEFAULT_OUT = Path(__file__).resolve().parent / "out"
"""Default parent folder of the outputs (ignored by git; the committed reports under
``benchmarks/results/`` are only written when ``--out`` names them)."""


def _choice_list(kind: str, known: Sequence[str]):
    """An argparse type that accepts one of ``known`` and names them all otherwise."""

    def check(value: str) -> str:
        if value not in known:
            raise argparse.ArgumentTypeError(
                f"unknown {kind} {value!r}; known: {', '.join(known)}"
            )
        return value

    return check


def _positive_int(value: str) -> int:
    try:
        number = int(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {value!r}") from None
    if number < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {value!r}")
    return number


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its errors name the valid choices)."""
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks",
        description="Benchmark fccqp against exact-cone and pyramid QP solvers on "
        "whole-body-control QPs of real robots, and write a Markdown report with plots and a "
        "CSV. `python -m benchmarks export --help`: write a test set for qpbenchmark.",
    )
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true", help="a few minutes on 2 cores (default)")
    size.add_argument("--full", action="store_true", help="more QPs and timing passes")
    parser.add_argument("--out", type=Path, help="output folder (default benchmarks/out/"
                        "<preset>, ignored by git)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE,
                        help="folder of cached test sets (default benchmarks/.cache)")
    parser.add_argument("--robots", nargs="+", type=_choice_list("robot", list(ROBOTS)),
                        default=list(ROBOTS), metavar="ROBOT",
                        help=f"robots (default all: {', '.join(ROBOTS)})")
    parser.add_argument("--scenario", type=_choice_list("scenario", [*SCENARIOS, MIX]),
                        default=MIX, help="scenario of the test sets (default mix)")
    parser.add_argument("--solvers", nargs="+", type=_choice_list("solver", list(VARIANTS)),
                        default=list(VARIANTS), metavar="SOLVER",
                        help=f"variants (default all installed: {', '.join(VARIANTS)})")
    parser.add_argument("--no-sweep", action="store_true",
                        help="leave out the loose/tight and fccqp sweep variants")
    parser.add_argument("--blas-threads", type=_positive_int, default=1,
                        help="BLAS/OpenMP threads while timing (default 1)")
    parser.add_argument("--seed", type=int, default=0, help="test-set seed (default 0)")
    parser.add_argument("--repeats", type=_positive_int,
                        help="timing passes per QP (preset: quick 5, full 10)")
    parser.add_argument("--n-qps", type=_positive_int, help="QPs per robot (overrides preset)")
    parser.add_argument("--seq-len", type=_positive_int,
                        help="ticks per sequence (overrides preset)")
    parser.add_argument("--no-progress", action="store_true", help="hide progress bars")
    return parser


def _say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def main(argv: Sequence[str] | None = None) -> Path:
    """Run the benchmark (or ``export``); return the path of the written report."""
    argv_list = sys.argv[1:] if argv is None else list(argv)
    if argv_list[:1] == ["export"]:
        return export.main(argv_list[1:])
    args = build_parser().parse_args(argv_list)
    load_start = load_average()
    name = "full" if args.full else "quick"
    preset = PRESETS[name]
    custom = args.n_qps is not None or args.seq_len is not None
    n_qps = args.n_qps or preset.n_qps
    seq_len = args.seq_len or preset.seq_len
    repeats = args.repeats or preset.repeats
    out = args.out or DEFAULT_OUT / name
    progress = not args.no_progress
    requested = [v for v in dict.fromkeys(args.solvers)
                 if not (args.no_sweep and VARIANTS[v].sweep)]
    variants, skipped = available_variants(requested)
    for missing in skipped:
        _say(f"skipping {missing}: {VARIANTS[missing].module} is not installed")
    if not variants:
        raise SystemExit("none of the requested solvers is installed")
    start = time.perf_counter()
    sets = []
    with threadpool_limits(limits=args.blas_threads):
        blas = tuple(blas_info())
        for robot in args.robots:
            ts, _ = cached_test_set(args.cache, robot, args.scenario, n_qps, args.seed,
                                    seq_len=seq_len, verbose=progress, report=_say)
            floor = KktFloor(ts)   # timed in the rounds, beside the variants
            adapters = [make_adapter(variant) for variant in variants]
            sets.append((ts, run_variants(adapters, ts, repeats, floor, progress=progress)))
            _say(f"{robot}: {len(variants)} variants timed "
                 f"({time.perf_counter() - start:.0f} s so far)")
    info = RunInfo(
        command=shlex.join(["python", "-m", "benchmarks", *argv_list]),
        preset="custom" if custom else name, repeats=repeats, seed=args.seed,
        skipped=tuple(skipped), blas=blas, blas_threads=args.blas_threads,
        load_start=load_start, load_end=load_average(),
    )
    _say(f"writing the report and figures into {out}")
    report = write_outputs(out, sets, variants, info)
    _say(f"wrote {report} in {time.perf_counter() - start:.0f} s")
    return report
