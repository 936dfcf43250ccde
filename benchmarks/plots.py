"""The report's figures, written as PNG files with fixed names (see docs/benchmarks.md).

- ``times_<robot>.png``: solve time along one sequence per default variant, with one
  ``dsytrf`` of the KKT matrix as the floor (the paper's Figure 1, top);
- ``torque_<robot>.png``: one joint's torque along that sequence from the reference,
  fccqp and pyramid solvers (Figure 1, bottom);
- ``work_precision_<robot>.png``: median solve time against the p95 torque error, one
  point per variant (solver and setting);
- ``time_distribution.png``: box plots of per-QP times of the default variants.

Every solver keeps one colour and marker in every figure (:data:`STYLE`); markers of
solvers that see a pyramid are hollow. A solve the solver does not report as solved is
drawn as a cross, never as a zero; legends sit outside the axes and every title names
the robot and the scenario.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.transforms import blended_transform_factory  # noqa: E402

from benchmarks.metrics import TORQUE_LIMIT_SHARE, solved_torque_errors  # noqa: E402
from benchmarks.robots import actuated_joint_names, load_robot  # noqa: E402
from benchmarks.solvers import VARIANTS  # noqa: E402
from benchmarks.testsets import TestSet, active_flags  # noqa: E402

__all__ = [
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

REFERENCE_NOTE = "reference = Clarabel at 1e-9"
"""Said in every figure that shows a torque or a torque error."""

_TORQUE_PLOTTED = ("fccqp-realtime", "fccqp-default", "daqp-pyr4", "osqp-pyr4", "proxqp-pyr8")
_WP_FLOOR = 1e-4
"""Lowest torque error drawn in the work-precision plot (% of limit); smaller ones sit on it."""
_LINES = {"realtime": "-.", "8 facets": "--"}
"""Line style of the settings that share a solver's colour in the sequence figures
(solid for the default; qpsolvers variants dotted)."""
_DPI = 80
_LEGEND = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "fontsize": 7, "frameon": False}


def _style(variant: str) -> dict[str, object]:
    """Colour, marker, line style and fill of a variant (hollow when it sees a pyramid)."""
    v = VARIANTS[variant]
    colour, marker = STYLE[v.family]
    line = ":" if not v.direct else _LINES.get(v.setting, "-")
    return {"color": colour, "marker": marker, "ls": line,
            "mfc": colour if v.exact_cones else "none"}


_TOLERANCE_ORDER = ("loose", "eps 1e-03", "eps 1e-04", "default", "eps 1e-06", "eps 1e-07",
                    "tight")
_BUDGET_ORDER = ("realtime", "realtime, 30 it", "realtime, 60 it")


def _curve(variant: str) -> tuple[str, int] | None:
    """Which line of the work-precision plot a variant lies on, and its place on it.

    A solver's tolerance sweep (loose, default, tight; fccqp's eps values) is one line
    from loose to tight, fccqp's iteration budgets another; other points stand alone.
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


def _crosses(ax: plt.Axes, t: np.ndarray, y: np.ndarray, failed: np.ndarray, colour: str) -> None:
    """Crosses at the failed points; points with no finite value sit on the bottom edge."""
    finite = failed & np.isfinite(y)
    ax.plot(t[finite], y[finite], "x", color=colour, ms=6, mew=1.5, ls="none")
    missing = failed & ~np.isfinite(y)
    if missing.any():
        edge = blended_transform_factory(ax.transData, ax.transAxes)
        ax.plot(t[missing], np.zeros(missing.sum()), "x", color=colour, ms=6, mew=1.5,
                ls="none", transform=edge, clip_on=False)


def plot_sequence(ts: TestSet, rows: Sequence[dict[str, object]], out: Path) -> tuple[str, str]:
    """Figure 1 of the paper for one robot: times (top figure) and a torque (bottom).

    The time plot shows the default settings of the direct-API variants and the
    dsytrf floor (sweep points and qpsolvers variants are in the other figures).
    Returns the two file names.
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
        style = _style(s)
        times = np.array([1e6 * float(by[s, i]["time"]) for i in idx])
        failed = np.array([not by[s, i]["reported"] for i in idx])
        ax.plot(t_ms, times, lw=1, ms=3, label=_label(s), **style)
        _crosses(ax, t_ms, times, failed, str(style["color"]))
    kkt = [1e6 * float(by[solvers[0], i]["dsytrf_time"]) for i in idx]
    ax.plot(t_ms, kkt, "k--", lw=1, label="one dsytrf (floor)")
    ax.plot([], [], "kx", ls="none", label="not reported solved")
    ax.set_yscale("log")
    ax.set_xlabel("time along the sequence [ms]")
    ax.set_ylabel("solve time [us]")
    ax.set_title(f"Solve time: {title}", fontsize=10)
    ax.legend(**_LEGEND)
    fig.tight_layout()
    times_png = f"times_{ts.robot}.png"
    fig.savefig(out / times_png, dpi=_DPI)
    plt.close(fig)

    joint = plotted_joint(ts, idx)
    name = actuated_joint_names(load_robot(ts.robot))[joint]
    u = ts.qps[0].layout["u"]
    fig, ax = plt.subplots(figsize=(9, 3.8))
    ax.plot(t_ms, [ts.x_ref[i][u][joint] for i in idx], "k-", lw=2.5, label="reference")
    for s in _TORQUE_PLOTTED:
        if (s, int(idx[0])) not in by:
            continue
        style = _style(s)
        torque = np.array([float(by[s, i]["u"][joint]) for i in idx])
        failed = np.array([not by[s, i]["reported"] for i in idx])
        ax.plot(t_ms, torque, lw=1.2, ms=3, label=_label(s), **style)
        _crosses(ax, t_ms, torque, failed, str(style["color"]))
    limit = ts.qps[idx[0]].ub[u][joint]
    for sign in (-1, 1):
        ax.axhline(sign * limit, color="gray", ls=":", lw=1)
    ax.plot([], [], color="gray", ls=":", label="torque limit")
    ax.plot([], [], "kx", ls="none", label="not reported solved")
    ax.set_xlabel("time along the sequence [ms]")
    ax.set_ylabel(f"{name} torque [Nm]")
    ax.set_title(f"Torque of {name}: {title} ({REFERENCE_NOTE})", fontsize=10)
    ax.legend(**_LEGEND)
    fig.tight_layout()
    torque_png = f"torque_{ts.robot}.png"
    fig.savefig(out / torque_png, dpi=_DPI)
    plt.close(fig)
    return times_png, torque_png


def plot_work_precision(ts: TestSet, rows: Sequence[dict[str, object]], out: Path) -> str:
    """Median solve time (x) against p95 torque error in % of the joint limit (y).

    One point per variant, labelled with its setting; a solver's tolerance sweep is
    joined from loose to tight (see :func:`_curve`). A QP the solver does not report
    solved counts as an infinite error, so a variant with more than 5 % of such QPs has
    an infinite p95 and is drawn as a cross on the top edge. Returns the file name.
    """
    solvers = list(dict.fromkeys(str(r["solver"]) for r in rows))
    points: dict[str, tuple[float, float]] = {}
    for s in solvers:
        mine = [r for r in rows if r["solver"] == s]
        median = float(np.median([float(r["time"]) for r in mine])) * 1e6
        errors = solved_torque_errors(mine)
        points[s] = (median, 100 * float(np.percentile(errors, 95, method="higher")))

    fig, ax = plt.subplots(figsize=(9.5, 5.5))
    edge = blended_transform_factory(ax.transData, ax.transAxes)
    curves: dict[tuple[str, str], list[tuple[int, float, float]]] = {}
    for s, (x, y) in points.items():
        v = VARIANTS[s]
        setting = v.setting
        style = _style(s)
        colour = str(style["color"])
        if np.isfinite(y):
            y_drawn = max(y, _WP_FLOOR)
            ax.plot(x, y_drawn, ls="none", ms=7, color=colour, marker=style["marker"],
                    mfc=style["mfc"])
            ax.annotate(setting, (x, y_drawn), xytext=(4, 3), textcoords="offset points",
                        fontsize=6, color=colour)
            curve = _curve(s)
            if curve is not None:
                curves.setdefault((v.family, curve[0]), []).append((curve[1], x, y_drawn))
        else:
            ax.plot(x, 1.0, "x", color=colour, ms=8, mew=2, transform=edge, clip_on=False)
            ax.annotate(setting, (x, 1.0), xycoords=edge, xytext=(4, -9),
                        textcoords="offset points", fontsize=6, color=colour)
    for (family, _), pts in curves.items():
        pts.sort()
        ax.plot([p[1] for p in pts], [p[2] for p in pts], color=STYLE[family][0], lw=0.8)
    for family, (colour, marker) in STYLE.items():
        if any(VARIANTS[s].family == family for s in solvers):
            exact = any(VARIANTS[s].exact_cones for s in solvers if VARIANTS[s].family == family)
            label = family if exact else f"{family} (pyramid)"
            ax.plot([], [], ls="none", marker=marker, color=colour,
                    mfc=colour if exact else "none", label=label)
    ax.plot([], [], ls="none", marker="o", color="gray", mfc="none", label="hollow: pyramid")
    ax.plot([], [], "x", color="gray", ls="none", label="> 5 % of QPs not solved")
    ax.axhline(100 * TORQUE_LIMIT_SHARE, color="gray", ls=":", lw=1)
    ax.plot([], [], color="gray", ls=":", label=f"{100 * TORQUE_LIMIT_SHARE:g} % of limit")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("median solve time [us]")
    ax.set_ylabel(f"p95 torque error [% of joint limit]\n({REFERENCE_NOTE}; "
                  f"values < {_WP_FLOOR:g} % drawn at {_WP_FLOOR:g} %)", fontsize=8)
    ax.set_title(f"Work-precision: {ts.robot} / {ts.scenario} set, {len(ts)} QPs", fontsize=10)
    ax.legend(**_LEGEND)
    fig.tight_layout()
    name = f"work_precision_{ts.robot}.png"
    fig.savefig(out / name, dpi=_DPI)
    plt.close(fig)
    return name


def plot_distribution(sets: Sequence[tuple[TestSet, list[dict[str, object]]]], out: Path) -> str:
    """Box plots of per-QP solve times of the default variants, one panel per test set."""
    fig, axes = plt.subplots(len(sets), 1, figsize=(9, 3.2 * len(sets)), squeeze=False)
    for ax, (ts, rows) in zip(axes[:, 0], sets, strict=True):
        solvers = [
            s for s in dict.fromkeys(str(r["solver"]) for r in rows) if not VARIANTS[s].sweep
        ]
        data = [[1e6 * float(r["time"]) for r in rows if r["solver"] == s] for s in solvers]
        boxes = ax.boxplot(data, orientation="horizontal", whis=(5, 95), flierprops={"ms": 2},
                           patch_artist=True)
        for box, s in zip(boxes["boxes"], solvers, strict=True):
            style = _style(s)
            box.set_facecolor(style["color"] if VARIANTS[s].exact_cones else "white")
            box.set_edgecolor(style["color"])
        ax.set_yticks(range(1, len(solvers) + 1), [_label(s) for s in solvers], fontsize=7)
        ax.set_xscale("log")
        ax.set_title(f"{ts.robot} / {ts.scenario} set: solve time [us] (whiskers 5-95 %; "
                     "white boxes: pyramid)", fontsize=9)
    fig.tight_layout()
    name = "time_distribution.png"
    fig.savefig(out / name, dpi=_DPI)
    plt.close(fig)
    return name
