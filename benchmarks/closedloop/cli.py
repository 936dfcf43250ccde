"""``python -m benchmarks closedloop [--quick | --full] [options]``: run and report.

For every robot, control rate, scenario and solver one closed-loop run
(:func:`benchmarks.closedloop.simulate.run`) at the floor friction ``--floor-mu`` with the
controller using the floor's coefficient; then the friction-margin sweep: the ``push``
scenario on a floor of ``--sweep-mu`` with the controller's coefficient at each fraction
of ``--fractions`` (at the first rate). One process, BLAS pools limited to one thread.
The report (:mod:`benchmarks.closedloop.report`) goes to ``benchmarks/out/closedloop/
<preset>`` unless ``--out`` says otherwise, so a committed report is only rewritten on
purpose.
"""

from __future__ import annotations

import argparse
import shlex
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from threadpoolctl import threadpool_limits

from benchmarks.closedloop.metrics import RunSummary, summarize
from benchmarks.closedloop.model import FOOT_RADIUS, build_sim_model
from benchmarks.closedloop.report import RunInfo, write_report
from benchmarks.closedloop.scenarios import SCENARIOS, make_scenario
from benchmarks.closedloop.simulate import Trace, run
from benchmarks.closedloop.variants import CLOSEDLOOP_VARIANTS, available, lookup
from benchmarks.machine import blas_info, load_average
from benchmarks.robots import load_robot
from benchmarks.solvers import VARIANTS

__all__ = ["PRESETS", "ClosedLoopPreset", "build_parser", "main"]

DEFAULT_OUT = Path(__file__).resolve().parent.parent / "out" / "closedloop"
"""Parent folder of the default outputs (ignored by git)."""


@dataclass(frozen=True)
class ClosedLoopPreset:
    """What a preset runs: robots, control rates (Hz), scenarios (``None``: all of the
    robot's kind), solver variants, the margin sweep's fractions, solvers and robots."""

    robots: tuple[str, ...]
    rates: tuple[int, ...]
    scenarios: tuple[str, ...] | None
    solvers: tuple[str, ...]
    fractions: tuple[float, ...]
    sweep_solvers: tuple[str, ...]
    sweep_robots: tuple[str, ...]


_CORE = ("fccqp-realtime", "fccqp-default", "daqp-pyr4", "osqp-pyr4", "clarabel")
_FULL = (*_CORE[:3], "proxqp-pyr4", "osqp-pyr4", "osqp-paper", "clarabel", "qoco")
_NAMES = [*VARIANTS, *CLOSEDLOOP_VARIANTS]

PRESETS: dict[str, ClosedLoopPreset] = {
    # go2 only, 500 Hz, three scenarios, five solvers and a two-point sweep of two: 19 runs.
    "quick": ClosedLoopPreset(("go2",), (500,), ("stand", "push", "lift"), _CORE, (1.0, 0.7),
                              ("fccqp-realtime", "daqp-pyr4"), ("go2",)),
    # The sweep with the five of the quick preset, on go2: with all eight solvers on both
    # robots the run would take over an hour on a loaded 2-core machine.
    "full": ClosedLoopPreset(("go2", "talos_reduced"), (500, 100), None, _FULL,
                             (1.0, 0.9, 0.8, 0.7), _CORE, ("go2",)),
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser."""
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks closedloop",
        description="Each solver drives a robot simulated in MuJoCo through scripted "
        "scenarios with the whole-body-control QP in the loop; writes a Markdown report.")
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true",
                      help="go2, 500 Hz, stand/push/lift, 5 solvers, sweep 1.0 and 0.7 "
                      "with 2 (default; within 5 minutes on 2 cores)")
    size.add_argument("--full", action="store_true",
                      help="go2 and talos_reduced, 500 and 100 Hz, every scenario, 8 "
                      "solvers, sweep 1.0 0.9 0.8 0.7 with 5 on go2")
    parser.add_argument("--out", type=Path,
                        help="output folder (default benchmarks/out/closedloop/<preset>)")
    parser.add_argument("--robots", nargs="+", choices=sorted(FOOT_RADIUS), metavar="ROBOT",
                        help=f"robots (preset's by default; known: {', '.join(FOOT_RADIUS)})")
    parser.add_argument("--rates", nargs="+", type=int, metavar="HZ",
                        help="control rates in Hz, each dividing the physics rate")
    parser.add_argument("--scenarios", nargs="+", metavar="NAME",
                        help="scenarios (quadruped: " + ", ".join(SCENARIOS["quadruped"])
                        + "; humanoid: " + ", ".join(SCENARIOS["humanoid"]) + ")")
    parser.add_argument("--solvers", nargs="+", choices=_NAMES, metavar="SOLVER",
                        help="solver variants of benchmarks/solvers.py, or osqp-paper")
    parser.add_argument("--fractions", nargs="*", type=float, metavar="F",
                        help="controller mu as fractions of the floor's for the sweep "
                        "(none: no sweep)")
    parser.add_argument("--sweep-solvers", nargs="+", choices=_NAMES, metavar="SOLVER",
                        help="solver variants of the sweep (default: the preset's, or "
                        "--solvers when given)")
    parser.add_argument("--sweep-robots", nargs="+", choices=sorted(FOOT_RADIUS),
                        metavar="ROBOT", help="robots of the sweep (default: the preset's, or "
                        "--robots when given)")
    parser.add_argument("--floor-mu", type=float, default=0.7,
                        help="floor friction of the main runs (default 0.7)")
    parser.add_argument("--sweep-mu", type=float, default=0.4,
                        help="floor friction of the margin sweep (default 0.4)")
    parser.add_argument("--physics-hz", type=int, default=1000,
                        help="MuJoCo steps per second (default 1000)")
    parser.add_argument("--blas-threads", type=int, default=1,
                        help="BLAS/OpenMP threads (default 1)")
    return parser


def _say(message: str) -> None:
    print(message, flush=True)


def _runs(robot: str, scenarios: Sequence[str], rate: int, variants: Sequence[str],
          floor_mu: float, fraction: float, physics_hz: int) -> list[Trace]:
    loaded = load_robot(robot)
    sim = build_sim_model(loaded, floor_mu, 1.0 / physics_hz)
    traces = []
    for name in scenarios:
        scenario = make_scenario(loaded, name, floor_mu)
        for variant in variants:
            start = time.perf_counter()
            trace = run(sim, scenario, variant, 1.0 / rate, fraction)
            fell = "" if trace.fell_at is None else f", fell at {trace.fell_at:.2f} s"
            _say(f"{robot} {rate} Hz {name} mu {floor_mu:g} x {fraction:g} {variant}: "
                 f"{len(trace.time)} ticks{fell} ({time.perf_counter() - start:.1f} s)")
            traces.append(trace)
    return traces


def main(argv: Sequence[str] | None = None) -> Path:
    """Run the closed-loop benchmark; return the path of the written report."""
    argv_list = list(argv or [])
    args = build_parser().parse_args(argv_list)
    name = "full" if args.full else "quick"
    preset = PRESETS[name]
    robots = args.robots or preset.robots
    rates = args.rates or preset.rates
    fractions = preset.fractions if args.fractions is None else tuple(args.fractions)
    sweep_robots = args.sweep_robots or (preset.sweep_robots if not args.robots else robots)
    requested = list(args.solvers or preset.solvers)
    variants, skipped = available(requested)
    swept, missing_swept = available(
        list(args.sweep_solvers or args.solvers or preset.sweep_solvers))
    for missing in dict.fromkeys([*skipped, *missing_swept]):
        _say(f"skipping {missing}: {lookup(missing).module} is not installed")
    for rate in rates:
        if rate < 1 or args.physics_hz % rate:
            raise SystemExit(f"control rate {rate} Hz does not divide {args.physics_hz} Hz")
    load_start, start = load_average(), time.perf_counter()
    traces: list[Trace] = []
    sweep: list[RunSummary] = []
    with threadpool_limits(limits=args.blas_threads):
        blas = tuple(blas_info())
        for robot in robots:
            kind = load_robot(robot).config.kind
            scenarios = args.scenarios or preset.scenarios or SCENARIOS[kind]
            unknown = [s for s in scenarios if s not in SCENARIOS[kind]]
            if unknown:
                raise SystemExit(f"{robot}: unknown scenarios {unknown}; known: "
                                 f"{SCENARIOS[kind]}")
            for rate in rates:
                traces += _runs(robot, scenarios, rate, variants, args.floor_mu, 1.0,
                                args.physics_hz)
            for fraction in fractions if robot in sweep_robots else ():
                sweep += [summarize(t) for t in _runs(robot, ("push",), rates[0], swept,
                                                      args.sweep_mu, fraction, args.physics_hz)]
    info = RunInfo(
        command=shlex.join(["python", "-m", "benchmarks", "closedloop", *argv_list]),
        physics_rate=args.physics_hz, floor_mu=args.floor_mu, sweep_mu=args.sweep_mu,
        blas=blas, blas_threads=args.blas_threads, load_start=load_start,
        load_end=load_average(), seconds=time.perf_counter() - start,
    )
    out = args.out or DEFAULT_OUT / name
    report = write_report(out, info, variants, traces, [summarize(t) for t in traces], sweep)
    _say(f"wrote {report} in {time.perf_counter() - start:.0f} s")
    return report
