"""The report's Markdown tables and the number formats they share.

- :func:`default_table`: the warm path of one test set, the solvers at their defaults:
  accuracy and time, median and tails;
- :func:`views_table`: every view of one test set, the solvers at their defaults: time
  (median and tails) and exact answers, with the ratios to DAQP;
- :func:`sweep_table`: every variant on the warm path: time, the torque error of the
  work-precision figure and the deadline shares;
- :func:`glance_table`: fccqp's real-time preset against DAQP in every view, every set.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from benchmarks.metrics import DEADLINES, Summary, deadline_share, summarize
from benchmarks.solvers import VARIANTS
from benchmarks.views import VIEWS, runs_every_view, view_rows

__all__ = [
    "PEER",
    "REALTIME",
    "by_view",
    "default_table",
    "g",
    "glance_table",
    "pct",
    "ratio",
    "sweep_table",
    "us",
    "views_table",
]

REALTIME = "fccqp-realtime"
"""The variant the every-view comparison and its targets are about."""

PEER = "daqp-pyr4"
"""The peer of that comparison: the fastest peer of these QPs at its best (``daqp.solve``
warm from the previous QP's multipliers through ``dual_start``)."""


def us(seconds: float) -> str:
    """Microseconds: no decimals from 10 us, one below, ``inf`` for a failure."""
    if not np.isfinite(seconds):
        return "inf" if seconds > 0 else "-"
    return f"{seconds * 1e6:.0f}" if seconds >= 1e-5 else f"{seconds * 1e6:.1f}"


def pct(rate: float) -> str:
    """A share in whole percent (``-`` when there is none)."""
    return "-" if np.isnan(rate) else f"{100 * rate:.0f}"


def g(value: float) -> str:
    """Two significant digits."""
    return f"{value:.2g}"


def ratio(a: float, b: float) -> str:
    """``a / b`` to two decimals (``-`` when undefined)."""
    if not (np.isfinite(b) and b > 0) or np.isnan(a):
        return "-"
    return f"{a / b:.2f}"


def _tails(s: Summary) -> str:
    return f"| {us(s.median_time)} | {us(s.p95_time)} | {us(s.p99_time)} | {us(s.max_time)} "


def default_table(summaries: Sequence[Summary]) -> str:
    """Accuracy and time of the solvers at their defaults on the warm path."""
    lines = [
        "| solver | success % | feasible % | reported % | exact % | median us | p95 us "
        "| p99 us | max us | shm ratio | median / fastest | median / dsytrf | median iter "
        "| max eq. res. | max cone viol. [N] | median obj. gap "
        "| torque err. median / p95 / max [Nm] | p95 torque err. / limit |",
        "|---|" + "---|" * 17,
    ]
    for s in summaries:
        iters = "-" if np.isnan(s.median_iterations) else f"{s.median_iterations:.0f}"
        lines.append(
            f"| {s.solver} | {pct(s.success_rate)} | {pct(s.feasible_rate)} "
            f"| {pct(s.reported_rate)} | {pct(s.exact_rate)} {_tails(s)}"
            f"| {s.shm_ratio:.2f} | {s.ratio_to_fastest:.1f} | {s.ratio_to_dsytrf:.1f} "
            f"| {iters} | {g(s.max_equality_residual)} | {g(s.max_cone_violation)} "
            f"| {g(s.median_objective_gap)} | {g(s.median_torque_error)} / "
            f"{g(s.p95_torque_error)} / {g(s.max_torque_error)} "
            f"| {_share_of_limit(s.p95_torque_error_rel)} |"
        )
    return "\n".join(lines)


def _share_of_limit(value: float) -> str:
    return f"{100 * value:.2g} %" if np.isfinite(value) else "failed"


def by_view(rows: Sequence[dict[str, object]], period: float,
            defaults_only: bool = True) -> dict[str, list[Summary]]:
    """Summaries of each view that has rows (the solvers at their defaults only, unless
    ``defaults_only`` is false)."""
    out = {}
    for view in VIEWS:
        mine = [r for r in view_rows(rows, view)
                if not (defaults_only and VARIANTS[str(r["solver"])].sweep)]
        if mine:
            out[view] = summarize(mine, period)
    return out


def views_table(views: dict[str, list[Summary]]) -> str:
    """Every view of one set for the variants that run them all: QPs, reported and
    exact shares, time median and tails, and the median and p99 against DAQP's in the
    same view."""
    lines = [
        f"| view | variant | QPs | reported % | exact % | median us | p95 us | p99 us "
        f"| max us | median / {PEER} | p99 / {PEER} |",
        "|---|---|" + "---|" * 9,
    ]
    for view, summaries in views.items():
        peer = next((s for s in summaries if s.solver == PEER), None)
        for s in (s for s in summaries if runs_every_view(s.solver)):
            lines.append(
                f"| {view} | {s.solver} | {s.n} | {pct(s.reported_rate)} "
                f"| {pct(s.exact_rate)} {_tails(s)}"
                f"| {ratio(s.median_time, peer.median_time) if peer else '-'} "
                f"| {ratio(s.p99_time, peer.p99_time) if peer else '-'} |"
            )
    return "\n".join(lines)


def sweep_table(rows: Sequence[dict[str, object]], summaries: Sequence[Summary]) -> str:
    """Every variant on the warm path: time median and tails, the work-precision torque
    error and the deadline shares."""
    budgets = " | ".join(f"<= {us(b)} us %" for b in DEADLINES)
    lines = [
        f"| variant | cones | setting | median us | p95 us | p99 us | max us "
        f"| p95 torque err. / limit | reported % | {budgets} |",
        "|---|---|---|---|---|---|---|---|---|" + "---|" * len(DEADLINES),
    ]
    for s in summaries:
        v = VARIANTS[s.solver]
        mine = [r for r in rows if r["solver"] == s.solver]
        shares = " | ".join(pct(deadline_share(mine, b)) for b in DEADLINES)
        lines.append(
            f"| {s.solver} | {'exact' if v.exact_cones else 'pyramid'} | {v.setting} "
            f"{_tails(s)}| {_share_of_limit(s.p95_torque_error_rel)} "
            f"| {pct(s.reported_rate)} | {shares} |"
        )
    return "\n".join(lines)


def glance_table(per_set: Sequence[tuple[str, dict[str, list[Summary]]]]) -> str | None:
    """fccqp-realtime against DAQP in every view of every set, or ``None`` when either
    did not run."""
    lines = [
        f"| robot | view | QPs | {REALTIME} median / p95 / p99 / max [us] "
        f"| {PEER} median / p95 / p99 / max [us] | ratio median / p95 / p99 / max "
        f"| exact % {REALTIME} / {PEER} |",
        "|---|---|---|---|---|---|---|",
    ]
    for robot, views in per_set:
        for view, summaries in views.items():
            by = {s.solver: s for s in summaries}
            if REALTIME not in by or PEER not in by:
                continue
            a, b = by[REALTIME], by[PEER]
            stats = ("median_time", "p95_time", "p99_time", "max_time")
            lines.append(
                f"| {robot} | {view} | {a.n} "
                f"| {' / '.join(us(getattr(a, k)) for k in stats)} "
                f"| {' / '.join(us(getattr(b, k)) for k in stats)} "
                f"| {' / '.join(ratio(getattr(a, k), getattr(b, k)) for k in stats)} "
                f"| {pct(a.exact_rate)} / {pct(b.exact_rate)} |"
            )
    return "\n".join(lines) if len(lines) > 2 else None
