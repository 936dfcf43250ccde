"""The report's targets: each a goal, this run's numbers and MET or MISSED.

Every row reads ``| robot | target | numbers | verdict |``. Three groups come from the
views (:mod:`benchmarks.views`): fccqp's real-time preset against DAQP in every view
(:func:`every_tick_rows`), its exact answers in every view (:func:`exact_rows`) and the
default preset's accuracy (:func:`default_rows`). The older group
(:func:`earlier_rows`) compares warm medians with the fastest peers and holds the
realtime preset's quality goals. Every figure is one of the tables' figures for the same
rows (the same summaries, :func:`benchmarks.metrics.summarize`), so a target and a table
cannot disagree.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from benchmarks.metrics import TORQUE_LIMIT_SHARE, Summary
from benchmarks.solvers import VARIANTS
from benchmarks.tables import PEER, REALTIME, g, pct, ratio, us
from benchmarks.views import CONTACT_CHANGE, VIEWS

__all__ = [
    "DEFAULT",
    "EXACT_SHARE",
    "default_rows",
    "earlier_rows",
    "every_tick_rows",
    "exact_rows",
]

DEFAULT = "fccqp-default"
"""The default preset's variant."""

WARM_MEDIAN = 0.9
"""Smooth warm path: fccqp-realtime's median at most this times DAQP's."""
WARM_P95 = 1.25
"""Tail: fccqp-realtime's warm p95 at most this times DAQP's warm p95."""
COLD_MEDIAN = 1.0
"""Cold: fccqp-realtime's cold median at most this times DAQP's cold median."""
COARSE_MEDIAN = 1.0
"""Every 10th QP: fccqp-realtime's median at most this times DAQP's."""
CONTACT_MEDIAN = 1.0
"""Contact-change ticks: fccqp-realtime's median at most this times DAQP's."""
EXACT_SHARE = 0.99
"""Share of QPs fccqp-realtime answers exactly in every view (2 ms budget)."""
DEFAULT_TORQUE_P95 = 0.01
"""fccqp-default's warm torque error p95, as a share of the joint limit."""
DEFAULT_GAP = 1e-6
"""fccqp-default's worst relative objective gap on the warm path."""

REALTIME_TORQUE_P95 = TORQUE_LIMIT_SHARE
"""fccqp-realtime's warm torque error p95, as a share of the joint limit."""
REALTIME_SUCCESS = 0.95
"""fccqp-realtime's warm success rate."""
REALTIME_GAP = 1e-3
"""fccqp-realtime's worst relative objective gap on the warm path."""
REALTIME_POLISH_COST = 1.3
"""fccqp-realtime's warm median against the same preset without polishing."""
EQUALITY_FACTOR = 10.0
"""An equality residual is at factorization accuracy when within this factor of
(plus 1e-12) the residual of a direct ``dsytrf``/``dsytrs`` solve of the KKT system."""
PROJECT_SPEED = (("proxqp-pyr4", 4.0), ("osqp-pyr4", 10.0), ("clarabel", 10.0))
"""fccqp-realtime's warm median at most 1/factor of these peers' medians."""


def _verdict(ok: bool) -> str:
    return "**MET**" if ok else "**MISSED**"


def _pair(views: dict[str, list[Summary]], view: str) -> tuple[Summary, Summary] | None:
    by = {s.solver: s for s in views.get(view, ())}
    return (by[REALTIME], by[PEER]) if REALTIME in by and PEER in by else None


def _versus(a: Summary, b: Summary, stat: str) -> str:
    x, y = getattr(a, stat), getattr(b, stat)
    return f"{us(x)} vs {us(y)} us = {ratio(x, y)}"


def _ratio_row(robot: str, goal: str, pair: tuple[Summary, Summary], stat: str, limit: float,
               beside: str = "") -> str:
    a, b = pair
    ok = getattr(a, stat) <= limit * getattr(b, stat)
    return (f"| {robot} | {goal} <= {limit:g}x {PEER}'s | {_versus(a, b, stat)} "
            f"({a.n} QP{'s' if a.n != 1 else ''}){beside} | {_verdict(ok)} |")


def every_tick_rows(robot: str, views: dict[str, list[Summary]]) -> list[str]:
    """fccqp-realtime against DAQP: smooth warm median, warm tail, cold, every 10th QP
    and contact-change ticks (rows only for views where both ran)."""
    out = []
    warm = _pair(views, "warm")
    if warm:
        out.append(_ratio_row(robot, f"{REALTIME} warm median", warm, "median_time",
                              WARM_MEDIAN))
        a, b = warm
        beside = f"; p99 {_versus(a, b, 'p99_time')}; max {_versus(a, b, 'max_time')}"
        out.append(_ratio_row(robot, f"{REALTIME} warm p95", warm, "p95_time", WARM_P95,
                              beside))
    cold = _pair(views, "cold")
    if cold:
        out.append(_ratio_row(robot, f"{REALTIME} cold median", cold, "median_time",
                              COLD_MEDIAN))
    tenth, fifth = _pair(views, "every 10th"), _pair(views, "every 5th")
    if tenth:
        beside = f"; every 5th: {_versus(*fifth, 'median_time')}" if fifth else ""
        out.append(_ratio_row(robot, f"{REALTIME} median on every 10th QP", tenth,
                              "median_time", COARSE_MEDIAN, beside))
    change = _pair(views, CONTACT_CHANGE)
    if change:
        out.append(_ratio_row(robot, f"{REALTIME} median on contact-change ticks", change,
                              "median_time", CONTACT_MEDIAN))
    elif warm:
        out.append(f"| {robot} | {REALTIME} median on contact-change ticks <= "
                   f"{CONTACT_MEDIAN:g}x {PEER}'s | no contact change in this set | - |")
    return out


def exact_rows(robot: str, views: dict[str, list[Summary]]) -> list[str]:
    """fccqp-realtime answers exactly (reported solved, torque within 5 % of each
    joint's limit) on at least 99 % of the QPs of every view."""
    mine = {view: s for view in VIEWS for s in views.get(view, ()) if s.solver == REALTIME}
    if not mine:
        return []
    numbers = "; ".join(
        f"{view} {pct(s.exact_rate)} % ({round(s.exact_rate * s.n)}/{s.n})"
        for view, s in mine.items()
    )
    ok = all(s.exact_rate >= EXACT_SHARE for s in mine.values())
    return [f"| {robot} | {REALTIME} exact on >= {100 * EXACT_SHARE:g} % of the QPs of every "
            f"view | {numbers} | {_verdict(ok)} |"]


def default_rows(robot: str, views: dict[str, list[Summary]]) -> list[str]:
    """The default preset: warm every QP SOLVED, torque error p95 at most 1 % of the
    limit, worst objective gap at most 1e-6; cold and coarse every QP SOLVED."""
    mine = {view: s for view in VIEWS for s in views.get(view, ()) if s.solver == DEFAULT}
    if "warm" not in mine:
        return []
    w = mine["warm"]
    out = [
        f"| {robot} | {DEFAULT} warm: every QP SOLVED | {pct(w.reported_rate)} % "
        f"({round(w.reported_rate * w.n)}/{w.n}) | {_verdict(w.reported_rate == 1.0)} |",
        f"| {robot} | {DEFAULT} warm torque error p95 <= {100 * DEFAULT_TORQUE_P95:g} % of the "
        f"joint limit | {_limit_share(w.p95_torque_error_rel)} "
        f"| {_verdict(w.p95_torque_error_rel <= DEFAULT_TORQUE_P95)} |",
        f"| {robot} | {DEFAULT} warm worst relative objective gap <= {DEFAULT_GAP:g} "
        f"| {g(w.max_objective_gap)} | {_verdict(w.max_objective_gap <= DEFAULT_GAP)} |",
    ]
    others = {v: s for v, s in mine.items() if v in ("cold", "every 5th", "every 10th")}
    if others:
        numbers = "; ".join(f"{v} {pct(s.reported_rate)} % ({round(s.reported_rate * s.n)}/"
                            f"{s.n})" for v, s in others.items())
        ok = all(s.reported_rate == 1.0 for s in others.values())
        out.append(f"| {robot} | {DEFAULT} cold and coarse: every QP SOLVED | {numbers} "
                   f"| {_verdict(ok)} |")
    return out


def _limit_share(value: float) -> str:
    return f"p95 {100 * value:.2g} %" if np.isfinite(value) else "p95 inf (over 5 % not solved)"


def _fastest_peer(summaries: Sequence[Summary], exact: bool) -> Summary | None:
    """The fastest (median) peer of a cone class at its default setting, direct API."""
    peers = [
        x for x in summaries
        if VARIANTS[x.solver].family != "fccqp" and VARIANTS[x.solver].direct
        and not VARIANTS[x.solver].sweep and VARIANTS[x.solver].exact_cones == exact
    ]
    return min(peers, key=lambda x: x.median_time, default=None)


def _speed_row(robot: str, mine: Summary, peer: Summary, factor: float, what: str) -> str:
    r = mine.median_time / peer.median_time
    return (
        f"| {robot} | {mine.solver} warm median <= "
        f"{'' if factor == 1 else f'1/{factor:g} of '}{what} | {us(mine.median_time)} us vs "
        f"{peer.solver} {us(peer.median_time)} us (reported solved {pct(peer.reported_rate)} "
        f"%): ratio {r:.2f} (target <= {1 / factor:.2f}) | {_verdict(r <= 1 / factor)} |"
    )


def earlier_rows(robot: str, rows: Sequence[dict[str, object]], defaults: Sequence[Summary],
                 every: Sequence[Summary]) -> list[str]:
    """The warm path's older targets: fccqp against the fastest peer of each cone class
    and the project's speed goals, equalities at factorization accuracy, and the
    realtime preset's success, worst gap, polish cost and torque error.

    ``rows`` are the warm path's, ``defaults`` their summaries at default settings,
    ``every`` those of every variant (for the preset without polishing, a sweep point).
    """
    by = {s.solver: s for s in defaults}
    out = []
    for name in (REALTIME, DEFAULT):
        for exact, what in ((True, "the fastest exact-cone peer"),
                            (False, "the fastest pyramid peer")):
            peer = _fastest_peer(defaults, exact)
            if name in by and peer is not None:
                out.append(_speed_row(robot, by[name], peer, 1.0, what))
    rt = by.get(REALTIME)
    for peer, factor in PROJECT_SPEED:
        if rt is not None and peer in by:
            out.append(_speed_row(robot, rt, by[peer], factor, peer))
    if DEFAULT in by:
        d = by[DEFAULT]
        out.append(
            f"| {robot} | {DEFAULT} solves every QP to tolerance "
            f"| success {pct(d.success_rate)} % ({round(d.success_rate * d.n)}/{d.n}); "
            f"reported solved {pct(d.reported_rate)} % | {_verdict(d.success_rate == 1.0)} |"
        )
    for name in (REALTIME, DEFAULT):
        mine = [r for r in rows if r["solver"] == name]
        if mine:
            out.append(_equality_row(robot, name, mine))
    if rt is not None:
        out += _realtime_quality_rows(robot, rt, {s.solver: s for s in every}.get(
            "fccqp-realtime-nopolish"))
    return out


def _equality_row(robot: str, name: str, rows: Sequence[dict[str, object]]) -> str:
    eq = np.array([float(r["equality_residual"]) for r in rows])
    ref = np.array([float(r["dsytrf_equality_residual"]) for r in rows])
    ok = eq <= EQUALITY_FACTOR * ref + 1e-12
    return (
        f"| {robot} | {name} equality residual at factorization accuracy "
        f"| max {g(eq.max())} (direct KKT solve: max {g(ref.max())}); "
        f"{ok.sum()}/{ok.size} QPs within {EQUALITY_FACTOR:g}x + 1e-12 | {_verdict(ok.all())} |"
    )


def _realtime_quality_rows(robot: str, rt: Summary, plain: Summary | None) -> list[str]:
    """The realtime preset's warm success, worst objective gap, torque error and, when
    that variant ran, its time against the same preset without polishing."""
    rows = [
        f"| {robot} | {REALTIME} success >= {100 * REALTIME_SUCCESS:g} % "
        f"| {pct(rt.success_rate)} % (reported solved {pct(rt.reported_rate)} %) "
        f"| {_verdict(rt.success_rate >= REALTIME_SUCCESS)} |",
        f"| {robot} | {REALTIME} worst relative objective gap <= {REALTIME_GAP:g} "
        f"| {g(rt.max_objective_gap)} | {_verdict(rt.max_objective_gap <= REALTIME_GAP)} |",
    ]
    if plain is not None:
        r = rt.median_time / plain.median_time
        rows.append(
            f"| {robot} | {REALTIME} median <= {REALTIME_POLISH_COST:g}x without polishing "
            f"| {us(rt.median_time)} us / {us(plain.median_time)} us = {r:.2f} "
            f"| {_verdict(r <= REALTIME_POLISH_COST)} |"
        )
    met = rt.p95_torque_error_rel <= REALTIME_TORQUE_P95
    rows.append(
        f"| {robot} | {REALTIME} torque error p95 <= {100 * REALTIME_TORQUE_P95:g} % of the "
        f"joint limit | {_limit_share(rt.p95_torque_error_rel)} (median / p95 / max "
        f"{g(rt.median_torque_error)} / {g(rt.p95_torque_error)} / "
        f"{g(rt.max_torque_error)} Nm) | {_verdict(met)} |"
    )
    return rows
