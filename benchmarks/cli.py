"""Command line: ``python -m benchmarks [--quick | --full] [options]``.

Generates one test set per robot (scenario ``mix`` by default), runs every installed
solver variant on it (:mod:`benchmarks.harness`) and writes the report
(:mod:`benchmarks.report`) into the output folder.
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from benchmarks.baseline import baseline
from benchmarks.harness import run_variants
from benchmarks.report import RunInfo, write_outputs
from benchmarks.robots import ROBOTS
from benchmarks.scenarios import SCENARIOS
from benchmarks.solvers import VARIANTS, available_variants, make_adapter
from benchmarks.testsets import MIX, generate_test_set

__all__ = ["PRESETS", "Preset", "build_parser", "main"]

RESULTS = Path(__file__).resolve().parent / "results"
"""Default parent folder of the outputs."""


@dataclass(frozen=True)
class Preset:
    """Sizes of a run: QPs per robot, ticks per sequence, timing passes."""

    n_qps: int
    seq_len: int
    repeats: int


PRESETS: dict[str, Preset] = {
    # 4 sequences of 40 ticks: one of each scenario of the mix.
    "quick": Preset(n_qps=160, seq_len=40, repeats=5),
    # 4 sequences of 100 ticks (the generator's default length).
    "full": Preset(n_qps=400, seq_len=100, repeats=10),
}


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
        description="Benchmark fccqp against Clarabel, ProxQP and OSQP on whole-body-control "
        "QPs of real robots, and write a Markdown report with plots and a CSV.",
    )
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true", help="a few minutes on 2 cores (default)")
    size.add_argument("--full", action="store_true", help="more QPs and timing passes")
    parser.add_argument("--out", type=Path, help="output folder (default benchmarks/results/"
                        "<preset>)")
    parser.add_argument("--robots", nargs="+", type=_choice_list("robot", list(ROBOTS)),
                        default=list(ROBOTS), metavar="ROBOT",
                        help=f"robots (default all: {', '.join(ROBOTS)})")
    parser.add_argument("--scenario", type=_choice_list("scenario", [*SCENARIOS, MIX]),
                        default=MIX, help="scenario of the test sets (default mix)")
    parser.add_argument("--solvers", nargs="+", type=_choice_list("solver", list(VARIANTS)),
                        default=list(VARIANTS), metavar="SOLVER",
                        help=f"variants (default all installed: {', '.join(VARIANTS)})")
    parser.add_argument("--seed", type=int, default=0, help="test-set seed (default 0)")
    parser.add_argument("--repeats", type=_positive_int,
                        help="timing passes per QP (preset: quick 5, full 10)")
    parser.add_argument("--n-qps", type=_positive_int, help="QPs per robot (overrides preset)")
    parser.add_argument("--seq-len", type=_positive_int,
                        help="ticks per sequence (overrides preset)")
    parser.add_argument("--no-progress", action="store_true", help="hide progress bars")
    return parser


def main(argv: Sequence[str] | None = None) -> Path:
    """Run the benchmark; return the path of the written report."""
    args = build_parser().parse_args(argv)
    name = "full" if args.full else "quick"
    preset = PRESETS[name]
    custom = args.n_qps is not None or args.seq_len is not None
    n_qps = args.n_qps or preset.n_qps
    seq_len = args.seq_len or preset.seq_len
    repeats = args.repeats or preset.repeats
    out = args.out or RESULTS / name
    progress = not args.no_progress
    variants, skipped = available_variants(list(dict.fromkeys(args.solvers)))
    for missing in skipped:
        print(f"skipping {missing}: not installed", file=sys.stderr)
    if not variants:
        raise SystemExit("none of the requested solvers is installed")
    argv_list = sys.argv[1:] if argv is None else list(argv)
    info = RunInfo(
        command=shlex.join(["python", "-m", "benchmarks", *argv_list]),
        preset="custom" if custom else name, repeats=repeats, seed=args.seed,
        skipped=tuple(skipped),
    )
    start = time.perf_counter()
    sets = []
    for robot in args.robots:
        ts = generate_test_set(robot, args.scenario, n_qps, args.seed, seq_len=seq_len,
                               verbose=progress)
        kkt = baseline(ts, repeats)
        adapters = [make_adapter(variant) for variant in variants]
        sets.append((ts, run_variants(adapters, ts, repeats, kkt, progress=progress)))
    report = write_outputs(out, sets, variants, info)
    print(f"wrote {report} in {time.perf_counter() - start:.0f} s")
    return report
