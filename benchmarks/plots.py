"""The report's figures, written as PNG files with fixed names (see docs/benchmarks.md).

- ``times_<robot>.png``: solve time along one sequence per default variant, with one
  ``dsytrf`` of the KKT matrix as the floor (the paper's Figure 1, top);
- ``torque_<robot>.png``: one joint's torque along that sequence from the reference,
  fccqp and pyramid solvers (Figure 1, bottom);
- ``work_precision_<robot>.png`` and ``work_precision_p99_<robot>.png``: median and p99
  solve time against the p95 torque error, one point per variant (solver and setting);
- ``time_distribution.png``: box plots of per-QP times of the default variants.

All of them plot the warm view. Every solver keeps one colour and marker in every
figure (:data:`STYLE`); markers of solvers that see a pyramid are hollow (white inside,
drawn large enough to tell). A solve the solver does not report as solved is drawn as a
cross, never as a value it did not stand behind (a torque at the bottom edge, a time at
its own value); legends sit outside the axes and every title names the robot and the
scenario. Percentiles are nearest ranks (:func:`benchmarks.metrics.percentile`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402
from matplotlib.transforms import blended_transform_factory  # noqa: E402

from benchmarks.metrics import (  # noqa: E402
    TORQUE_LIMIT_SHARE,
    penalized_times,
    percentile,
    solved_torque_errors,
)
from benchmarks.plot_labels import Point, place_labels  # noqa: E402
from benchmarks.robots import actuated_joint_names, load_robot  # noqa: E402
from benchmarks.solvers import VARIANTS  # noqa: E402
from benchmarks.testsets import TestSet, active_flags  # noqa: E402

__all__ = [
    "REFERENCE_NOTE",
    "STYLE",
    "plot_distribution",
    "plot_sequence",
    "plot_work_precision",
    "plotted_joint",
    "plotted_sequence",
]

STYLE: dict[str, tuple[str, str]] = {
    "fccqp": ("tab:red", "o"),
    "clarabel": ("tab:blue", "s"),
    "qoco": ("tab:cyan", "D"),
    "scs": ("tab:olive", "P"),
    "daqp": ("tab:green", "^"),
    "quadprog": ("tab:brown", "v"),
    "piqp": ("tab:purple", "<"),
    "proxqp": ("tab:orange", ">"),
    "osqp": ("tab:pink", "h"),
}
"""Solver (variant family) -> (colour, marker), the same in every figure."""

REFERENCE_NOTE = "reference = Clarabel at the tightest of 1e-12 to 1e-9 it reaches"
"""Said in every figure that shows a torque or a torque error."""

_TORQUE_PLOTTED = ("fccqp-realtime", "fccqp-default", "daqp-pyr4", "osqp-pyr4", "proxqp-pyr8")
_WP_FLOOR = 1e-4
"""Lowest torque error drawn in the work-precision plot (% of limit); smaller ones sit on it."""
_LINES = {"realtime": "-.", "8 facets": "--"}
"""Line style of the settings that share a solver's colour in the sequence figures
(solid for the default; qpsolvers variants dotted)."""
_DPI = 110
_LEGEND = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "fontsize": 7, "frameon": False}
_TOLERANCE_ORDER = ("loose", "eps 1e-03", "eps 1e-04", "default", "eps 1e-06", "eps 1e-07",
                    "tight")
_BUDGET_ORDER = ("realtime, 0.5 ms", "realtime, 1 ms", "realtime", "realtime, 3 ms")


def _style(variant: str, size: float) -> dict[str, object]:
    """Colour, marker, line style and fill of a variant (hollow when it sees a pyramid)."""
    v = VARIANTS[variant]
    colour, marker = STYLE[v.family]
    line = ":" if not v.direct else _LINES.get(v.setting, "-")
    return {"color": colour, "marker": marker, "ls": line, "ms": size, "mew": 1.2,
            "mfc": colour if v.exact_cones else "white"}


def _plain_log_axis(axis) -> None:
    """Log ticks at 1, 2 and 5 per decade labelled as plain numbers, no minor labels
    (the default minor labels of a narrow log range collide)."""
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def _curve(variant: str) -> tuple[str, int] | None:
    """Which line of the work-precision plot a variant lies on, and its place on it.

    A solver's tolerance sweep (loose, default, tight; fccqp's eps values) is one line
    from loose to tight, fccqp's time budgets another; other points stand alone.
    """
    v = VARIANTS[variant]
    if not v.direct:
        return None
    for name, order in (("tolerance", _TOLERANCE_ORDER), ("budget", _BUDGET_ORDER)):
        if v.setting in order:
            return name, order.index(v.setting)
    return None


def _label(variant: str) -> str:
    v = VARIANTS[variant]
    return variant if v.exact_cones else f"{variant} (pyramid)"


def plotted_sequence(ts: TestSet) -> int:
    """The sequence with the largest share of active QPs (then the longest)."""
    best, key = int(ts.sequence[0]), (-1.0, 0)
    for seq in dict.fromkeys(ts.sequence.tolist()):
        idx = np.flatnonzero(ts.sequence == seq)
        share = np.mean([any(active_flags(ts.qps[i], ts.x_ref[i])) for i in idx])
        if (share, idx.size) > key:
            best, key = int(seq), (float(share), idx.size)
    return best


def plotted_joint(ts: TestSet, idx: np.ndarray) -> int:
    """The joint whose reference torque comes closest to its limit along ``idx``."""
    u = ts.qps[0].layout["u"]
    usage = np.max([np.abs(ts.x_ref[i][u]) / ts.qps[i].ub[u] for i in idx], axis=0)
    return int(np.argmax(usage))


def _edge_crosses(ax: plt.Axes, t: np.ndarray, failed: np.ndarray, colour: str) -> None:
    """Crosses on the bottom edge at the failed points."""
    if failed.any():
        edge = blended_transform_factory(ax.transData, ax.transAxes)
        ax.plot(t[failed], np.zeros(failed.sum()), "x", color=colour, ms=7, mew=1.8,
                ls="none", transform=edge, clip_on=False)


def _save(fig: plt.Figure, out: Path, name: str, layout: bool = True) -> str:
    if layout:
        fig.tight_layout()
    fig.savefig(out / name, dpi=_DPI)
    plt.close(fig)
    return name


def plot_sequence(ts: TestSet, rows: Sequence[dict[str, object]], out: Path) -> tuple[str, str]:
    """Figure 1 of the paper for one robot: times (top figure) and a torque (bottom).

    The time plot shows the default settings of the direct-API variants and the
    dsytrf floor (a failed solve is a cross at its time); the torque plot breaks a
    solver's line at a failed solve and puts a cross on the bottom edge, since the point
    it returned is not an answer. Returns the two file names.
    """
    seq = plotted_sequence(ts)
    idx = np.flatnonzero(ts.sequence == seq)
    t_ms = (idx - idx[0]) * ts.dt * 1e3
    solvers = list(dict.fromkeys(str(r["solver"]) for r in rows))
    by = {(str(r["solver"]), int(r["qp"])): r for r in rows}
    title = f"{ts.robot} / {ts.scenario} set, sequence {seq}"

    fig, ax = plt.subplots(figsize=(9, 4))
    for s in solvers:
        if VARIANTS[s].sweep or not VARIANTS[s].direct:
            continue
        style = _style(s, 4.5)
        times = np.array([1e6 * float(by[s, i]["time"]) for i in idx])
        failed = np.array([not by[s, i]["reported"] for i in idx])
        ax.plot(t_ms, times, lw=1, label=_label(s), **style)
        ax.plot(t_ms[failed], times[failed], "x", color=style["color"], ms=7, mew=1.8)
    kkt = [1e6 * float(by[solvers[0], i]["dsytrf_time"]) for i in idx]
    ax.plot(t_ms, kkt, "k--", lw=1, label="one dsytrf (floor)")
    ax.plot([], [], "kx", ls="none", label="not reported solved")
    ax.set_yscale("log")
    _plain_log_axis(ax.yaxis)
    ax.set_xlabel("time along the sequence [ms]")
    ax.set_ylabel("solve time [us]")
    ax.set_title(f"Solve time, warm: {title}", fontsize=10)
    ax.legend(**_LEGEND)
    times_png = _save(fig, out, f"times_{ts.robot}.png")

    joint = plotted_joint(ts, idx)
    name = actuated_joint_names(load_robot(ts.robot))[joint]
    u = ts.qps[0].layout["u"]
    fig, ax = plt.subplots(figsize=(9, 3.8))
    ax.plot(t_ms, [ts.x_ref[i][u][joint] for i in idx], "k-", lw=2.5, label="reference")
    for s in _TORQUE_PLOTTED:
        if (s, int(idx[0])) not in by:
            continue
        style = _style(s, 4.5)
        failed = np.array([not by[s, i]["reported"] for i in idx])
        torque = np.array([float(by[s, i]["u"][joint]) for i in idx])
        ax.plot(t_ms, np.where(failed, np.nan, torque), lw=1.2, label=_label(s), **style)
        _edge_crosses(ax, t_ms, failed, str(style["color"]))
    limit = ts.qps[idx[0]].ub[u][joint]
    for sign in (-1, 1):
        ax.axhline(sign * limit, color="gray", ls=":", lw=1)
    ax.plot([], [], color="gray", ls=":", label="torque limit")
    ax.plot([], [], "kx", ls="none", label="not reported solved\n(bottom edge)")
    ax.set_xlabel("time along the sequence [ms]")
    ax.set_ylabel(f"{name} torque [Nm]")
    ax.set_title(f"Torque of {name}, warm: {title} ({REFERENCE_NOTE})", fontsize=10)
    ax.legend(**_LEGEND)
    torque_png = _save(fig, out, f"torque_{ts.robot}.png")
    return times_png, torque_png


def plot_work_precision(ts: TestSet, rows: Sequence[dict[str, object]], out: Path,
                        time_percentile: float = 50) -> str:
    """Solve time (x: the median, or another percentile over QPs) against the p95 torque
    error in % of the joint limit (y).

    One point per variant; points of one solver at one spot share a label listing their
    settings, and a solver's tolerance sweep is joined from loose to tight (see
    :func:`_curve`). A QP the solver does not report solved counts as an infinite error
    and as the controller period in time, so a variant with more than 5 % of such QPs
    has an infinite p95 and is drawn as a cross on the top edge. Returns the file name.
    """
    solvers = list(dict.fromkeys(str(r["solver"]) for r in rows))
    what = "median" if time_percentile == 50 else f"p{time_percentile:g}"
    points: dict[str, tuple[float, float]] = {}
    for s in solvers:
        mine = [r for r in rows if r["solver"] == s]
        t = percentile(penalized_times(mine, ts.dt), time_percentile) * 1e6
        points[s] = (t, 100 * percentile(solved_torque_errors(mine), 95))

    fig, ax = plt.subplots(figsize=(10, 6))
    ax.set_xscale("log")
    ax.set_yscale("log")
    edge = blended_transform_factory(ax.transData, ax.transAxes)
    curves: dict[tuple[str, str], list[tuple[int, float, float]]] = {}
    finite, failed = [], []
    for s, (x, y) in points.items():
        v = VARIANTS[s]
        style = _style(s, 8)
        colour = str(style["color"])
        if np.isfinite(y):
            y_drawn = max(y, _WP_FLOOR)
            ax.plot(x, y_drawn, ls="none", color=colour, marker=style["marker"],
                    ms=style["ms"], mew=style["mew"], mfc=style["mfc"])
            finite.append(Point(x, y_drawn, v.family, v.setting, colour))
            curve = _curve(s)
            if curve is not None:
                curves.setdefault((v.family, curve[0]), []).append((curve[1], x, y_drawn))
        else:
            ax.plot(x, 1.0, "x", color=colour, ms=9, mew=2, transform=edge, clip_on=False)
            failed.append(Point(x, 1.0, v.family, v.setting, colour))
    for (family, _), pts in curves.items():
        pts.sort()
        ax.plot([p[1] for p in pts], [p[2] for p in pts], color=STYLE[family][0], lw=0.8)
    for family, (colour, marker) in STYLE.items():
        if any(VARIANTS[s].family == family for s in solvers):
            exact = any(VARIANTS[s].exact_cones for s in solvers if VARIANTS[s].family == family)
            label = family if exact else f"{family} (pyramid)"
            ax.plot([], [], ls="none", marker=marker, color=colour, ms=8, mew=1.2,
                    mfc=colour if exact else "white", label=label)
    ax.plot([], [], ls="none", marker="o", color="gray", ms=8, mfc="white",
            label="hollow: pyramid")
    ax.plot([], [], "x", color="gray", ls="none", label="> 5 % of QPs not solved")
    ax.axhline(100 * TORQUE_LIMIT_SHARE, color="gray", ls=":", lw=1)
    ax.plot([], [], color="gray", ls=":", label=f"{100 * TORQUE_LIMIT_SHARE:g} % of limit")
    _plain_log_axis(ax.xaxis)
    _plain_log_axis(ax.yaxis)
    ax.set_xlabel(f"{what} solve time over the QPs [us] (a QP not solved counts as "
                  f"{ts.dt * 1e3:g} ms)")
    ax.set_ylabel(f"p95 torque error [% of joint limit]\n({REFERENCE_NOTE}; "
                  f"values < {_WP_FLOOR:g} % drawn at {_WP_FLOOR:g} %)", fontsize=8)
    ax.set_title(f"Work-precision, {what} time, warm: {ts.robot} / {ts.scenario} set, "
                 f"{len(ts)} QPs", fontsize=10)
    ax.legend(**_LEGEND)
    fig.tight_layout()
    place_labels(ax, finite)
    place_labels(ax, failed, transform=edge)
    suffix = "" if time_percentile == 50 else f"_p{time_percentile:g}"
    return _save(fig, out, f"work_precision{suffix}_{ts.robot}.png", layout=False)


def _box_stats(times: np.ndarray, label: str) -> dict[str, object]:
    """Box statistics by nearest rank: box 25-75 %, whiskers 5-99 %, points beyond."""
    q = {p: percentile(times, p) for p in (5, 25, 50, 75, 99)}
    return {"label": label, "med": q[50], "q1": q[25], "q3": q[75], "whislo": q[5],
            "whishi": q[99], "fliers": times[(times < q[5]) | (times > q[99])]}


def plot_distribution(sets: Sequence[tuple[TestSet, list[dict[str, object]]]], out: Path) -> str:
    """Box plots of per-QP solve times of the default variants, one panel per test set.

    Failed solves (not reported solved) are crosses at their own time, counted on the
    right; the boxes hold every QP's time."""
    fig, axes = plt.subplots(len(sets), 1, figsize=(10, 3.6 * len(sets)), squeeze=False)
    for ax, (ts, rows) in zip(axes[:, 0], sets, strict=True):
        solvers = [
            s for s in dict.fromkeys(str(r["solver"]) for r in rows) if not VARIANTS[s].sweep
        ]
        mine = [[r for r in rows if r["solver"] == s] for s in solvers]
        data = [1e6 * np.array([float(r["time"]) for r in m]) for m in mine]
        boxes = ax.bxp([_box_stats(t, _label(s)) for t, s in zip(data, solvers, strict=True)],
                       orientation="horizontal", patch_artist=True,
                       flierprops={"ms": 2}, medianprops={"color": "black"})
        right = blended_transform_factory(ax.transAxes, ax.transData)
        for k, (box, s, m, t) in enumerate(zip(boxes["boxes"], solvers, mine, data,
                                               strict=True)):
            style = _style(s, 6)
            box.set_facecolor(style["color"] if VARIANTS[s].exact_cones else "white")
            box.set_edgecolor(style["color"])
            failed = np.array([not r["reported"] for r in m])
            if failed.any():
                ax.plot(t[failed], np.full(failed.sum(), k + 1), "x", color="black", ms=5,
                        mew=1.2)
                ax.text(1.01, k + 1, f"{failed.sum()}/{failed.size} not solved", fontsize=6,
                        va="center", transform=right)
        ax.set_xscale("log")
        _plain_log_axis(ax.xaxis)
        ax.tick_params(axis="y", labelsize=7)
        ax.set_title(f"{ts.robot} / {ts.scenario} set, warm: solve time [us] (box 25-75 %, "
                     "whiskers 5-99 %, nearest rank; white boxes: pyramid; x: not solved)",
                     fontsize=9)
    return _save(fig, out, "time_distribution.png")
