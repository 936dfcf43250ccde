"""The closed-loop report: ``report.md``, ``results.csv`` (one row per run) and the figures.

The report says how it was produced (command, revision, machine, BLAS threads, load,
versions), how a run works, then per robot and control rate one table with a row per
scenario and solver -- kept up or fell (when), tick-time median, p99 and max, overruns,
failures, tracking, slip, torque smoothness -- and a summary naming, per scenario, the
solvers that kept the robot up with fccqp's p99 and max next to each peer's; then the
friction-margin sweep and the figures.
"""

from __future__ import annotations

import csv
import os
import platform
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from benchmarks.closedloop.metrics import SETTLE, SLIDING, RunSummary
from benchmarks.closedloop.plots import TORQUED, TRACED, plot_cdf, plot_torques, plot_trace
from benchmarks.closedloop.simulate import Trace
from benchmarks.closedloop.variants import lookup
from benchmarks.machine import cpu_model, git_revision, version
from benchmarks.tables import us

__all__ = ["RunInfo", "write_report"]

_LIBRARIES = ("numpy", "fccqp", "mujoco", "pin", "example-robot-data", "clarabel", "qoco",
              "daqp", "proxsuite", "osqp", "threadpoolctl")
_FIGURE_SCENARIO = ("lift", "push")
"""Scenario of the trace and torque figures: the first of these that ran."""


@dataclass(frozen=True)
class RunInfo:
    """How the results were produced (the report's header).

    Attributes
    ----------
    command
        The command line.
    physics_rate
        MuJoCo steps per second.
    floor_mu
        Floor friction of the main runs; ``sweep_mu`` that of the margin sweep.
    blas, blas_threads
        threadpoolctl's pools, one line each, and the thread limit while running.
    load_start, load_end
        1-minute load average at the start and the end.
    seconds
        Wall time of the runs.
    """

    command: str
    physics_rate: int
    floor_mu: float
    sweep_mu: float
    blas: tuple[str, ...]
    blas_threads: int
    load_start: float
    load_end: float
    seconds: float


def _header(info: RunInfo, variants: Sequence[str]) -> list[str]:
    cores = os.cpu_count() or 1
    lines = [
        "# Closed-loop benchmark: each solver drives a simulated robot in MuJoCo",
        "",
        f"Command: `{info.command}` (fccqp revision {git_revision()}, "
        f"{info.seconds / 60:.1f} min of wall time).",
        "",
        "## Machine and versions",
        "",
        "| item | value |",
        "|---|---|",
        f"| CPU | {cpu_model()} ({cores} cores) |",
        f"| load average (1 min) at start / end | {info.load_start:.2f} / {info.load_end:.2f} |",
        *[f"| BLAS / OpenMP pool | {pool} |" for pool in info.blas],
        f"| BLAS threads while running | {info.blas_threads} (threadpoolctl) |",
        f"| python | {platform.python_version()} |",
        *[f"| {lib} | {version(lib)} |" for lib in _LIBRARIES],
        "",
    ]
    if max(info.load_start, info.load_end) > cores - 0.5:
        lines += [f"**The load average reached {max(info.load_start, info.load_end):.1f} on "
                  f"{cores} cores: other processes shared the CPU, so the tails (p99, max) "
                  "include preemptions by them.**", ""]
    lines += [
        "## How a run works",
        "",
        "MuJoCo simulates the robot at "
        f"{info.physics_rate} Hz from a model generated from the controller's Pinocchio "
        "model (same bodies, inertias and joints; spheres at the contact points; elliptic "
        "friction cones). At every control tick the controller reads MuJoCo's state, builds "
        "the whole-body-control QP (task PD on CoM, base orientation, posture and swing "
        "feet; contact stabilization; the benchmark's cost and constraints) and one solver "
        "answers it; the torques are held until the next tick. The tick time is the solver "
        "call alone (`time.perf_counter` around it, as in the open-loop benchmark), one "
        "BLAS thread. Every answer reported solved is applied, however long it took (the "
        "run is offline); ticks longer than the control period are counted as overruns. "
        "An answer not reported solved is not applied: the controller holds the previous "
        "torques and the tick counts as failed. A robot has fallen when its base drops "
        "below half its starting height or tilts by more than 60 degrees; the run stops "
        f"there. Tracking and slip leave out the first {SETTLE:g} s (settling onto the "
        f"soft floor). Main runs: floor mu {info.floor_mu:g}, controller mu = floor mu.",
        "",
        "Columns: *kept up* (or the time of the fall); solver-call time median, p99 and "
        "max in us (wall time); *CPU p99 / max*: the same call's CPU time (this thread's, "
        "`time.thread_time`), the tail without preemptions by other processes; *over*: "
        "ticks longer than the control period; *failed*: answers not "
        "applied; CoM error RMS / max and largest swing-foot error in mm; *slip*: largest "
        "tangential contact-point speed (mm/s) and its mean over ticks with a contact; "
        "*slid*: distance the contact points slid, summed over them (mm); "
        f"*sliding*: % of ticks with a contact at the simulated cone's boundary "
        f"(|f_t| >= {SLIDING:g} mu f_n; MuJoCo never exceeds the cone); *QP cone*: largest "
        "|f_t| / (floor mu f_n) the applied answers asked for; *torque rate*: RMS torque "
        "change (Nm/s), smoothness. In a run that fell, tracking and slip include the "
        "fall itself.",
        "",
        "Solvers (variants of the open-loop benchmark, `benchmarks/solvers.py`, and "
        "`osqp-paper`, `benchmarks/closedloop/variants.py`):",
        "",
        *[f"- `{v}`: {lookup(v).description}" for v in variants],
        "",
    ]
    return lines


def _kept(s: RunSummary) -> str:
    return "yes" if s.completed else f"**fell at {s.fell_at:.2f} s**"


def _row(s: RunSummary) -> str:
    return (f"| {s.scenario} | {s.variant} | {_kept(s)} | {us(s.median)} | {us(s.p99)} | "
            f"{us(s.max)} | {us(s.cpu_p99)} / {us(s.cpu_max)} | {s.overruns} | "
            f"{s.failed} / {s.ticks} | "
            f"{s.com_rms * 1e3:.1f} / {s.com_max * 1e3:.1f} | {s.foot_max * 1e3:.1f} | "
            f"{s.slip_max * 1e3:.0f} / {s.slip_mean * 1e3:.1f} | {s.slide * 1e3:.1f} | "
            f"{100 * s.sliding:.0f} | "
            f"{s.qp_cone_max:.2f} | {s.torque_rate:.0f} |")


_TABLE = ("| scenario | solver | kept up | median | p99 | max | CPU p99 / max | over | failed "
          "| CoM mm | foot mm | slip mm/s | slid mm | sliding % | QP cone | torque rate |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")


def _tails(s: RunSummary) -> str:
    return f"{us(s.p99)} / {us(s.max)} ({us(s.cpu_p99)} / {us(s.cpu_max)})"


def _summary(runs: Sequence[RunSummary]) -> list[str]:
    lines = ["| robot | rate | scenario | kept up | fell | fccqp-realtime p99 / max "
             "(CPU p99 / max) | peers' p99 / max (CPU p99 / max) |",
             "|---|---|---|---|---|---|---|"]
    keys = dict.fromkeys((s.robot, s.rate, s.scenario) for s in runs)
    for robot, rate, scenario in keys:
        group = [s for s in runs if (s.robot, s.rate, s.scenario) == (robot, rate, scenario)]
        up = ", ".join(s.variant for s in group if s.completed) or "none"
        down = ", ".join(s.variant for s in group if not s.completed) or "none"
        fccqp = [s for s in group if s.variant == "fccqp-realtime"]
        mine = _tails(fccqp[0]) if fccqp else "-"
        peers = "; ".join(f"{s.variant} {_tails(s)}" for s in group
                          if s.variant != "fccqp-realtime")
        lines.append(f"| {robot} | {rate:.0f} Hz | {scenario} | {up} | {down} | {mine} | "
                     f"{peers} |")
    return lines


def _sweep(sweep: Sequence[RunSummary]) -> list[str]:
    fractions = sorted({s.mu_fraction for s in sweep}, reverse=True)
    lines = [
        "| robot | scenario | solver | " + " | ".join(f"mu x {f:g}" for f in fractions) + " |",
        "|---|---|---|" + "---|" * len(fractions),
    ]
    for robot, scenario, variant in dict.fromkeys((s.robot, s.scenario, s.variant)
                                                   for s in sweep):
        cells = []
        for f in fractions:
            match = [s for s in sweep if (s.robot, s.scenario, s.variant, s.mu_fraction)
                     == (robot, scenario, variant, f)]
            s = match[0] if match else None
            cells.append("-" if s is None else
                         f"{s.slip_max * 1e3:.0f} mm/s, {s.slide * 1e3:.1f} mm"
                         f"{'' if s.completed else ', **fell**'}")
        lines.append(f"| {robot} | {scenario} | {variant} | " + " | ".join(cells) + " |")
    return lines


def _figures(traces: Sequence[Trace], out: Path) -> list[str]:
    lines = ["## Figures", ""]
    for robot, period in dict.fromkeys((t.scenario.robot, t.period) for t in traces):
        group = [t for t in traces if (t.scenario.robot, t.period) == (robot, period)]
        rate = round(1 / period)
        lines += [f"![tick-time CDF, {robot} {rate} Hz]({plot_cdf(group, robot, rate, out)})",
                  ""]
        names = {t.scenario.name for t in group}
        scenario = next((s for s in _FIGURE_SCENARIO if s in names), None)
        if scenario is None:
            continue
        runs = [t for t in group if t.scenario.name == scenario]
        traced = [t for v in TRACED for t in runs if t.variant == v]
        torqued = [t for v in TORQUED for t in runs if t.variant == v]
        if traced:
            lines += [f"![solve-time trace]({plot_trace(traced, out)})", ""]
        if torqued:
            lines += [f"![knee torque]({plot_torques(torqued, out)})", ""]
    return lines


def write_report(out: Path, info: RunInfo, variants: Sequence[str], traces: Sequence[Trace],
                 runs: Sequence[RunSummary], sweep: Sequence[RunSummary]) -> Path:
    """Write ``report.md``, ``results.csv`` and the figures into ``out``; return the report.

    ``traces`` and ``runs`` are the main runs (controller mu = floor mu), ``sweep`` the
    margin sweep's summaries (empty without a sweep).
    """
    out.mkdir(parents=True, exist_ok=True)
    rows = [s.row() for s in (*runs, *sweep)]
    with open(out / "results.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.4g}" if isinstance(v, float) else v)
                             for k, v in row.items()})
    lines = _header(info, variants)
    lines += ["## Which solvers kept the robot up", "", *_summary(runs), ""]
    for robot, rate in dict.fromkeys((s.robot, s.rate) for s in runs):
        lines += [f"## {robot}, control at {rate:.0f} Hz", "", *_TABLE,
                  *[_row(s) for s in runs if (s.robot, s.rate) == (robot, rate)], ""]
    if sweep:
        first = sweep[0]
        lines += [
            "## Friction margin",
            "",
            f"Floor mu {info.sweep_mu:g}; the controller's mu is the floor's times the "
            f"fraction of each column ({first.rate:.0f} Hz). Each cell: largest slip speed, "
            "distance slid (summed over contact points), and whether the robot fell. The "
            "exact cones let the controller ask for all the friction it is given; the inner "
            "pyramid keeps an implicit margin (1/sqrt 2 along the tangent axes, none on its "
            "diagonals).",
            "",
            *_sweep(sweep),
            "",
        ]
    lines += _figures(traces, out)
    report = out / "report.md"
    report.write_text("\n".join(lines))
    return report
