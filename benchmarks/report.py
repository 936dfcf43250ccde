"""Write the benchmark's outputs: ``results.csv``, ``report.md`` and the PNG figures.

The report opens with fccqp's real-time preset against DAQP in every view (warm, cold,
coarse, contact-change ticks; median and tails) and the targets, each MET or MISSED
with its numbers (:mod:`benchmarks.targets`); then how it was produced (the exact
command, the machine, BLAS threads, load average, library versions), the variants, the
method and definitions, and per test set its tables (:mod:`benchmarks.tables`) and
figures (:mod:`benchmarks.plots`).
"""

from __future__ import annotations

import csv
import os
import platform
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from benchmarks.machine import cpu_model, git_revision, version
from benchmarks.metrics import SHIFT, TOLERANCE, TORQUE_LIMIT_SHARE, summarize
from benchmarks.plots import (
    REFERENCE_NOTE,
    plot_distribution,
    plot_sequence,
    plot_work_precision,
)
from benchmarks.solvers import VARIANTS
from benchmarks.tables import (
    PEER,
    REALTIME,
    by_view,
    default_table,
    glance_table,
    sweep_table,
    us,
    views_table,
)
from benchmarks.targets import default_rows, earlier_rows, every_tick_rows, exact_rows
from benchmarks.testsets import TestSet, active_fraction
from benchmarks.views import COARSE_STEPS, view_rows

__all__ = ["RunInfo", "SetResult", "write_csv", "write_outputs"]

_CSV_SKIP = ("u",)
_LIBRARIES = (
    "numpy", "scipy", "fccqp", "clarabel", "qoco", "scs", "daqp", "quadprog", "piqp",
    "proxsuite", "osqp", "qpsolvers", "pin", "example-robot-data", "matplotlib",
    "threadpoolctl",
)
_TARGET_HEADER = ("| robot | target | numbers | verdict |", "|---|---|---|---|")


@dataclass(frozen=True)
class RunInfo:
    """How the results were produced, for the report's header.

    Attributes
    ----------
    command
        The command line.
    preset
        ``"quick"``, ``"full"`` or ``"custom"``.
    repeats
        Timing passes per QP (median reported).
    seed
        Seed of the test sets.
    skipped
        Variants requested but not installed.
    blas
        threadpoolctl's description of each thread pool, one line each.
    blas_threads
        Thread limit applied to those pools while timing (``None``: not limited).
    load_start, load_end
        1-minute load average when the run started and when the timing ended.
    seconds
        Wall time from the start of the run to the end of the timing, test-set
        generation (or loading) included.
    """

    command: str
    preset: str
    repeats: int
    seed: int
    skipped: tuple[str, ...] = ()
    blas: tuple[str, ...] = ()
    blas_threads: int | None = None
    load_start: float = float("nan")
    load_end: float = float("nan")
    seconds: float = float("nan")


@dataclass(frozen=True)
class SetResult:
    """One robot's results: its test set, the set the coarse views walked (the full
    preset's, or the same) and the rows of every view
    (:func:`benchmarks.harness.run_variants`)."""

    test_set: TestSet
    coarse_set: TestSet
    rows: list[dict[str, object]]


def write_csv(rows: Sequence[dict[str, object]], path: Path) -> None:
    """Write one CSV row per (view, solver, QP), floats to 4 digits; array columns are
    left out."""
    fields = [k for k in rows[0] if k not in _CSV_SKIP]
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow(
                {k: (f"{v:.4g}" if isinstance(v, float) else v) for k, v in row.items()}
            )


def _set_description(ts: TestSet) -> str:
    ns = sorted({qp.n for qp in ts.qps})
    ms = sorted({qp.A.shape[0] for qp in ts.qps})
    ks = sorted({qp.n_contacts for qp in ts.qps})
    mus = [float(m) for qp in ts.qps for m in qp.mus]
    return (
        f"robot `{ts.robot}`, scenario `{ts.scenario}`, seed {ts.seed}, {len(ts)} QPs in "
        f"{len(set(ts.sequence.tolist()))} sequences (dt {ts.dt * 1e3:g} ms); variables "
        f"{ns[0]}-{ns[-1]}, equality rows {ms[0]}-{ms[-1]}, contact points {ks[0]}-{ks[-1]}, "
        f"mu {min(mus, default=0):.2f}-{max(mus, default=0):.2f}; active fraction (friction "
        f"cone at its boundary or torque saturated in the reference) {active_fraction(ts):.2f}"
    )


def _coarse_description(result: SetResult) -> str:
    c = result.coarse_set
    where = ("this set's sequences" if c is result.test_set else
             f"the full preset's set of this robot ({len(c)} QPs in "
             f"{len(set(c.sequence.tolist()))} sequences, seed {c.seed})")
    n = sum(r["view"] == "warm" and r["contact_change"] for r in result.rows
            if r["solver"] == result.rows[0]["solver"])
    return (f"Cold: every QP of this set from a reset solver. Every 5th / 10th: those QPs of "
            f"{where}, warm from the previous kept QP. Contact change: the "
            f"{n} QP{'s' if n != 1 else ''} of this set whose stance (feet in contact) differs "
            "from the previous QP's.")


def _machine(info: RunInfo) -> list[str]:
    cores = os.cpu_count() or 1
    lines = [
        "## Machine and versions",
        "",
        "| item | value |",
        "|---|---|",
        f"| CPU | {cpu_model()} |",
        f"| cores | {cores} |",
        f"| load average (1 min) at start / end of timing | {info.load_start:.2f} / "
        f"{info.load_end:.2f} |",
        *[f"| BLAS / OpenMP pool | {pool} |" for pool in info.blas],
        f"| BLAS threads while timing | "
        f"{'not limited' if info.blas_threads is None else info.blas_threads} "
        "(threadpoolctl `threadpool_limits`) |",
        f"| fccqp revision | {git_revision()} |",
        f"| python | {platform.python_version()} ({platform.system()} {platform.release()}) |",
        *[f"| {lib} | {version(lib)} |" for lib in _LIBRARIES],
        "",
    ]
    if max(info.load_start, info.load_end) > cores:
        lines += [
            f"**Warning: the load average ({max(info.load_start, info.load_end):.1f}) exceeded "
            f"the {cores} cores during this run: other processes competed for the CPU, so "
            "absolute times are inflated and noisier than usual; compare ratios within the "
            "run.**",
            "",
        ]
    return lines


def _variants(info: RunInfo, variants: Sequence[str]) -> list[str]:
    lines = [
        "## Variants",
        "",
        "A variant is one solver at one setting. *exact* solvers see the exact friction "
        "cones; *pyramid* solvers see an inner (inscribed) pyramid of 4 or 8 facets, whose "
        "answers are cone-feasible but restricted. *loose* and *tight* variants run a "
        "peer at a looser and a tighter tolerance than its default; the fccqp sweep varies "
        "its tolerance and the real-time preset's time budget. The sweeps and the "
        "qpsolvers calls run the warm view only; the other variants run every view.",
        "",
        "| variant | solver | cones | setting | what |",
        "|---|---|---|---|---|",
        *[
            f"| {v} | {VARIANTS[v].family} | {'exact' if VARIANTS[v].exact_cones else 'pyramid'} "
            f"| {VARIANTS[v].setting} | {VARIANTS[v].description} |"
            for v in variants
        ],
        "| dsytrf (floor) | LAPACK | - | - | one `dsytrf` of `[[P + 1e-6 I, A'], [A, 0]]`, "
        "no solve |",
        "",
    ]
    if info.skipped:
        lines += [f"Skipped (not installed): {', '.join(info.skipped)}.", ""]
    return lines


def _method() -> list[str]:
    coarse = " and ".join(f"every {k}th" for k in COARSE_STEPS)
    return [
        "## Method and definitions",
        "",
        "- **Views.** *warm*: every QP in controller-loop order, each solver warm from the"
        " previous QP and reset at each sequence start (fccqp its state; DAQP the previous"
        " multipliers as `dual_start`; ProxQP `update` + `WARM_START_WITH_PREVIOUS_RESULT`;"
        " OSQP `warm_start(x, y)`; SCS the previous `x, y, s`; Clarabel, QOCO, PIQP and"
        " quadprog have no warm start and solve every QP cold). *cold*: every QP from a"
        " reset solver: fccqp `Solver.reset()` (the workspace of the problem's structure"
        " is kept, as a controller keeps it), DAQP without `dual_start`, ProxQP a new"
        " model, OSQP and SCS without a warm start. *every 5th / every 10th*: " + coarse +
        " QP of each sequence of the full preset's sets, warm from the previous kept QP (a"
        " controller at 100 or 50 Hz on the same motion). *contact change*: the warm"
        " view's QPs whose set of feet in contact differs from the previous QP's.",
        f"- **DAQP at its best**: one `daqp.solve` per QP with `dual_start` (the previous"
        f" QP's multipliers, which set the initial working set), which measured faster"
        f" than a persistent `daqp.Model` updated with each QP on these problems"
        f" (`notes/daqp_model.py`). It is the peer of the every-view comparison"
        f" ({REALTIME} against {PEER}).",
        "- **Timing.** Data conversion (sparse matrices, pyramid rows, cone lists) happens"
        " before timing; the timer (`time.perf_counter`) surrounds the solver's own Python"
        " call, including the setup of solvers that cannot update their matrices"
        " (Clarabel, QOCO, SCS, OSQP, PIQP). A pass is one variant walking one view once;"
        " passes never interleave per QP. Each variant first solves a few QPs and the"
        " first QP of each other problem size untimed (warm-up: loading extension modules"
        " and first-call costs, such as fccqp's workspace per problem structure, are"
        " excluded). Passes rotate through the variants round by round, so drifts of the"
        " shared machine's speed reach every variant alike. The garbage collector is off"
        " during timed passes. A QP's time is the median over the passes; its answer is"
        " the first pass's.",
        "- **Percentiles.** Every median, p95 and p99 is the nearest rank over per-QP"
        " values (numpy `percentile(..., method=\"inverted_cdf\")`): the value of an"
        " actual QP. A QP the solver does not report solved counts as the controller"
        " period in time (or its own time when longer) and as an infinite error"
        " (torque error, objective gap), so that a p95 is `failed`/`inf` when more than"
        " 5 % of the QPs are not solved.",
        f"- **Accuracy.** Every solution is judged on the exact-cone problem against the"
        f" reference ({REFERENCE_NOTE}), also for pyramid solvers. **exact %**: reported"
        f" solved with every joint's torque within {100 * TORQUE_LIMIT_SHARE:g} % of its"
        f" limit of the reference's. **success %** (qpbenchmark's convention): reported"
        f" solved and the equality residual, exact-cone violation and bound violation"
        f" within {TOLERANCE:g} relative to `1 + ||b||`, `1 + max ||f_ref||` and"
        f" `1 + max u_max`, and the objective gap `|f - f_ref| / max(1, |f_ref|)` within"
        f" {TOLERANCE:g}. **feasible %** drops the objective check (a pyramid answer is"
        " feasible but restricted). **reported %**: the solver's own status says solved"
        " (fccqp: `SOLVED` only).",
        f"- **shm ratio**: the shifted geometric mean (shm) of times, `exp(mean(log(t + s)))"
        f" - s` with shift `s` = {SHIFT:g} s as in qpbenchmark (at these sub-millisecond"
        " times it is close to the arithmetic mean), a solve not reported solved counting"
        " as the controller period (2 ms), divided by the smallest shm of the table."
        " **median / fastest**, **median / dsytrf**: the median divided by the smallest"
        " median of the table and by the median time of one `dsytrf` of the QP's KKT"
        " matrix (the floor). **median iter**: median of the iterations the solver reports"
        " (`-` when it reports none); fccqp's 0 is a QP that its warm polish answered"
        " before any ADMM iteration: the exact solution on the previous QP's active set,"
        " accepted by its KKT check.",
        "- **max eq. res.**: largest `||A x - b||_inf`; **max cone viol.**: largest"
        " exact-cone violation `max(0, ||f_t|| - mu f_n)` in newtons. **torque err.**: per"
        " QP the largest joint torque error `max_j |u_j - u_ref_j|` in Nm, and **/ limit**"
        " as a fraction of each joint's limit, `max_j |u_j - u_ref_j| / u_max_j`.",
        "- **Work-precision**: per variant, the median (or p99) time against the p95 over"
        " QPs of the torque error / limit. **Deadline view** (`<= B us %`): share of QPs"
        " answered within the budget `B`, reported solved, feasible on the exact cones and"
        f" with torque error under {100 * TORQUE_LIMIT_SHARE:g} % of the limit.",
        "",
    ]


def _targets(per_set: Sequence[tuple[SetResult, dict]]) -> list[str]:
    groups = (
        (f"### {REALTIME} against {PEER} in every view",
         lambda res, views: every_tick_rows(res.test_set.robot, views)),
        (f"### {REALTIME}: exact answers in every view (2 ms budget)",
         lambda res, views: exact_rows(res.test_set.robot, views)),
        ("### fccqp-default: accuracy in every view",
         lambda res, views: default_rows(res.test_set.robot, views)),
        ("### Earlier targets (warm view)", _earlier),
    )
    lines = ["## Targets", ""]
    met = missed = 0
    for title, make in groups:
        rows = [row for res, views in per_set for row in make(res, views)]
        if rows:
            lines += [title, "", *_TARGET_HEADER, *rows, ""]
            met += sum(row.endswith("| **MET** |") for row in rows)
            missed += sum(row.endswith("| **MISSED** |") for row in rows)
    lines[2:2] = [f"{met} targets met, {missed} missed. Ratios compare per-QP times of the"
                  " same run; peers run at their own defaults and are never tuned down.", ""]
    return lines


def _earlier(result: SetResult, views: dict) -> list[str]:
    warm = view_rows(result.rows, "warm")
    period = result.test_set.dt
    return earlier_rows(result.test_set.robot, warm, views.get("warm", []),
                        summarize(warm, period))


def _set_section(result: SetResult, views: dict, out: Path) -> list[str]:
    ts = result.test_set
    warm = view_rows(result.rows, "warm")
    every = summarize(warm, ts.dt)
    times_png, torque_png = plot_sequence(ts, warm, out)
    wp = [plot_work_precision(ts, warm, out, stat) for stat in (50, 99)]
    kkt = float(np.median([float(r["dsytrf_time"]) for r in warm]))
    return [
        f"### {ts.robot} / {ts.scenario}",
        "",
        _set_description(ts) + f". Median dsytrf of the KKT matrix: {us(kkt)} us.",
        "",
        "#### Warm, every tick: default settings",
        "",
        default_table(views["warm"]),
        "",
        f"![solve time along a sequence]({times_png})",
        "",
        f"![torque along a sequence]({torque_png})",
        "",
        "#### Every view: default settings",
        "",
        _coarse_description(result),
        "",
        views_table(views),
        "",
        "#### Every variant, warm: work precision and deadlines",
        "",
        sweep_table(warm, every),
        "",
        f"![work precision, median time]({wp[0]})",
        "",
        f"![work precision, p99 time]({wp[1]})",
        "",
    ]


def write_outputs(
    out: Path,
    results: Sequence[SetResult],
    variants: Sequence[str],
    info: RunInfo,
) -> Path:
    """Write ``results.csv``, the PNGs and ``report.md`` into ``out``; return the report path.

    Parameters
    ----------
    out
        Output folder (created if needed).
    results
        Each robot's test sets and result rows.
    variants
        Variants that ran, in table order.
    info
        How the run was made.
    """
    out.mkdir(parents=True, exist_ok=True)
    write_csv([r for res in results for r in res.rows], out / "results.csv")
    per_set = [(res, by_view(res.rows, res.test_set.dt)) for res in results]
    glance = glance_table([(res.test_set.robot, views) for res, views in per_set])
    lines = [
        "# fccqp benchmark report: whole-body-control QPs from real robots",
        "",
        f"Produced by `{info.command}` (preset `{info.preset}`, seed {info.seed}, "
        f"{info.repeats} timing passes per QP, median reported; {info.seconds:.0f} s from the "
        "start to the end of the timing, test sets included).",
        "",
    ]
    if glance is not None:
        lines += [
            f"## At a glance: {REALTIME} against {PEER} in every view",
            "",
            "Times over the QPs of each view (definitions in *Method*); ratios below 1 favour"
            " fccqp. *exact*: reported solved with every joint torque within"
            f" {100 * TORQUE_LIMIT_SHARE:g} % of its limit of the exact-cone reference's.",
            "",
            glance,
            "",
        ]
    lines += _targets(per_set)
    lines += [*_machine(info), *_variants(info, variants), *_method()]
    lines += ["## Results per test set", ""]
    for res, views in per_set:
        lines += _set_section(res, views, out)
    dist_png = plot_distribution([(res.test_set, view_rows(res.rows, "warm"))
                                  for res in results], out)
    lines += ["## Distribution of solve times", "", f"![solve time distribution]({dist_png})",
              ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path
