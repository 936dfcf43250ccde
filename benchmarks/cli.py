"""Command line: ``python -m benchmarks [--quick | --full] [options]``, ``... export`` and
``... closedloop``.

The benchmark loads (or generates and caches, :mod:`benchmarks.cache`) one test set per
robot (scenario ``mix`` by default) and, for the coarse views of the quick preset, the
full preset's set of the robot; runs every installed solver variant along the views'
paths (:mod:`benchmarks.views`, :mod:`benchmarks.harness`) with the BLAS thread pools
limited; and writes the report (:mod:`benchmarks.report`) into the output folder, by
default one that git ignores. Progress lines go to stdout, warnings and progress bars to
stderr. ``python -m benchmarks export ...`` writes a test set for qpbenchmark instead
(:mod:`benchmarks.export`); ``python -m benchmarks closedloop ...`` runs the closed-loop
MuJoCo benchmark (:mod:`benchmarks.closedloop.cli`).
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
from benchmarks.cache import DEFAULT_CACHE, cached_test_set
from benchmarks.harness import run_variants
from benchmarks.machine import blas_info, load_average
from benchmarks.presets import PRESETS, Preset
from benchmarks.report import RunInfo, SetResult, write_outputs
from benchmarks.robots import ROBOTS
from benchmarks.scenarios import SCENARIOS
from benchmarks.solvers import VARIANTS, available_variants, make_adapter
from benchmarks.testsets import CLOSEDLOOP, MIX
from benchmarks.views import timed_paths

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


def _sizes(preset: Preset) -> str:
    sequences = -(-preset.n_qps // preset.seq_len)
    return (f"{preset.n_qps} QPs per robot in {sequences} sequences of {preset.seq_len} ticks, "
            f"{preset.repeats} timing passes")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its errors name the valid choices)."""
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks",
        description="Benchmark fccqp against exact-cone and pyramid QP solvers on "
        "whole-body-control QPs of real robots, and write a Markdown report with plots and a "
        "CSV. `python -m benchmarks export --help`: write a test set for qpbenchmark.",
    )
    size = parser.add_mutually_exclusive_group()
    quick, full = PRESETS["quick"], PRESETS["full"]
    size.add_argument("--quick", action="store_true",
                      help=f"{_sizes(quick)}; the coarse views walk the full preset's "
                      "sequences (default; under 5 minutes on 2 cores, test sets included)")
    size.add_argument("--full", action="store_true", help=_sizes(full))
    parser.add_argument("--out", type=Path, help="output folder (default benchmarks/out/"
                        "<preset>, ignored by git)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE,
                        help="folder of cached test sets (default benchmarks/.cache)")
    parser.add_argument("--robots", nargs="+", type=_choice_list("robot", list(ROBOTS)),
                        default=list(ROBOTS), metavar="ROBOT",
                        help=f"robots (default all: {', '.join(ROBOTS)})")
    parser.add_argument("--scenario",
                        type=_choice_list("scenario", [*SCENARIOS, MIX, CLOSEDLOOP]),
                        default=MIX, help="scenario of the test sets (default mix; "
                        "closedloop: QPs logged from the MuJoCo closed loop)")
    parser.add_argument("--solvers", nargs="+", type=_choice_list("solver", list(VARIANTS)),
                        default=list(VARIANTS), metavar="SOLVER",
                        help=f"variants (default all installed: {', '.join(VARIANTS)})")
    parser.add_argument("--no-sweep", action="store_true",
                        help="leave out the loose/tight and fccqp sweep variants")
    parser.add_argument("--blas-threads", type=_positive_int, default=1,
                        help="BLAS/OpenMP threads while timing (default 1)")
    parser.add_argument("--seed", type=int, default=0, help="test-set seed (default 0)")
    parser.add_argument("--repeats", type=_positive_int,
                        help=f"timing passes per QP (preset: quick {quick.repeats}, "
                        f"full {full.repeats})")
    parser.add_argument("--n-qps", type=_positive_int,
                        help="QPs per robot (overrides the preset; the coarse views then walk "
                        "this set)")
    parser.add_argument("--seq-len", type=_positive_int,
                        help="ticks per sequence (overrides the preset, as --n-qps)")
    parser.add_argument("--no-progress", action="store_true", help="hide progress bars")
    return parser


def _say(message: str) -> None:
    print(message, flush=True)


def _warn(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def main(argv: Sequence[str] | None = None) -> Path:
    """Run the benchmark (or ``export``, ``closedloop``); return the path of the written
    report."""
    argv_list = sys.argv[1:] if argv is None else list(argv)
    if argv_list[:1] == ["export"]:
        return export.main(argv_list[1:])
    if argv_list[:1] == ["closedloop"]:  # imported here: only it needs mujoco
        from benchmarks.closedloop.cli import main as closedloop

        return closedloop(argv_list[1:])
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
        _warn(f"skipping {missing}: {VARIANTS[missing].module} is not installed")
    if not variants:
        raise SystemExit("none of the requested solvers is installed")
    start = time.perf_counter()
    full = PRESETS["full"]
    results = []
    with threadpool_limits(limits=args.blas_threads):
        blas = tuple(blas_info())
        for robot in args.robots:
            ts, _ = cached_test_set(args.cache, robot, args.scenario, n_qps, args.seed,
                                    seq_len=seq_len, verbose=progress, report=_say)
            coarse = ts
            if not custom and (n_qps, seq_len) != (full.n_qps, full.seq_len):
                coarse, _ = cached_test_set(args.cache, robot, args.scenario, full.n_qps,
                                            args.seed, seq_len=full.seq_len, verbose=progress,
                                            report=_say)
            adapters = [make_adapter(variant) for variant in variants]
            rows = run_variants(adapters, timed_paths(ts, coarse), repeats, progress=progress)
            results.append(SetResult(ts, coarse, rows))
            _say(f"{robot}: {len(variants)} variants timed "
                 f"({time.perf_counter() - start:.0f} s so far)")
    info = RunInfo(
        command=shlex.join(["python", "-m", "benchmarks", *argv_list]),
        preset="custom" if custom else name, repeats=repeats, seed=args.seed,
        skipped=tuple(skipped), blas=blas, blas_threads=args.blas_threads,
        load_start=load_start, load_end=load_average(),
        seconds=time.perf_counter() - start,
    )
    _say(f"writing the report and figures into {out}")
    report = write_outputs(out, results, variants, info)
    _say(f"wrote {report} in {time.perf_counter() - start:.0f} s")
    return report
