"""Figures of the closed-loop report, PNG files with fixed names (see docs/closedloop.md).

- ``cdf_<robot>_<rate>hz.png``: tick-time CDF per solver, every tick of every scenario
  of that robot and rate (the nominal-margin runs), the control period as a line;
- ``trace_<robot>_<rate>hz_<scenario>.png``: solve time along one run of fccqp, OSQP and
  DAQP (the paper's Figure 1, top), contact switches as vertical lines;
- ``torque_<robot>_<rate>hz_<scenario>.png``: one knee's torque along that run from
  fccqp and a pyramid solver (Figure 1, bottom), with the torque limit.

Each solver keeps the colour and marker of the open-loop figures
(:data:`benchmarks.plots.STYLE`); ``fccqp-default`` is dashed beside the realtime preset.
A tick whose answer was not applied is a cross at its time.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks.closedloop.simulate import Trace  # noqa: E402
from benchmarks.closedloop.variants import lookup  # noqa: E402
from benchmarks.plots import STYLE  # noqa: E402
from benchmarks.robots import actuated_joint_names, load_robot  # noqa: E402

__all__ = ["KNEES", "TORQUED", "TRACED", "plot_cdf", "plot_torques", "plot_trace"]

TRACED = ("fccqp-realtime", "osqp-pyr4", "daqp-pyr4")
"""Solvers of the solve-time trace (fccqp and OSQP are the paper's; DAQP the fastest peer)."""

TORQUED = ("fccqp-realtime", "osqp-pyr4")
"""Solvers of the torque trace (the paper's pair)."""

KNEES = {"go2": "FL_calf_joint", "solo12": "FL_KFE", "anymal_c": "LF_KFE",
         "talos_reduced": "leg_left_4_joint"}
"""The joint whose torque is plotted, per robot."""

_DPI = 110
_LEGEND = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "fontsize": 7, "frameon": False}


def _style(variant: str) -> dict[str, object]:
    colour, _ = STYLE[lookup(variant).family]
    dashed = lookup(variant).setting not in ("default", "realtime")
    return {"color": colour, "linestyle": "--" if dashed or variant == "fccqp-default" else "-"}


def _save(fig: plt.Figure, ax: plt.Axes, labels: tuple[str, str, str], out: Path,
          name: str) -> str:
    """Label the axes (x, y, title), add the legend, write ``out / name``; return ``name``."""
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_title(labels[2], fontsize=9)
    ax.legend(**_LEGEND)
    fig.tight_layout()
    fig.savefig(out / name, dpi=_DPI)
    plt.close(fig)
    return name


def plot_cdf(traces: Sequence[Trace], robot: str, rate: int, out: Path) -> str:
    """Tick-time CDF per solver over ``traces`` (one robot and rate); returns the file name."""
    fig, ax = plt.subplots(figsize=(7.5, 4.0))
    period = traces[0].period
    for variant in dict.fromkeys(t.variant for t in traces):
        times = np.sort(np.concatenate([t.solve_time for t in traces if t.variant == variant]))
        share = np.arange(1, times.size + 1) / times.size
        ax.step(times * 1e3, share, where="post", label=f"{variant} ({times.size} ticks)",
                **_style(variant))
    ax.axvline(period * 1e3, color="k", linewidth=0.8, linestyle=":")
    ax.text(period * 1e3, 0.02, " control period", fontsize=7)
    ax.set_xscale("log")
    labels = ("solver call per tick (ms, log)", "share of ticks",
              f"{robot}, {rate} Hz: tick-time CDF, every scenario")
    return _save(fig, ax, labels, out, f"cdf_{robot}_{rate}hz.png")


def _switches(ax: plt.Axes, trace: Trace) -> None:
    n = np.asarray(trace.n_contacts)
    for t in np.asarray(trace.time)[1:][np.diff(n) != 0]:
        ax.axvline(t, color="0.6", linewidth=0.6)


def plot_trace(traces: Sequence[Trace], out: Path) -> str:
    """Solve time along one scenario's run of the :data:`TRACED` solvers present."""
    first = traces[0]
    robot, scenario, rate = first.scenario.robot, first.scenario.name, round(1 / first.period)
    fig, ax = plt.subplots(figsize=(8.0, 3.6))
    for trace in traces:
        t, times = np.asarray(trace.time), np.asarray(trace.solve_time) * 1e3
        ax.plot(t, times, linewidth=0.7, label=trace.variant, **_style(trace.variant))
        failed = ~np.asarray(trace.solved)
        ax.plot(t[failed], times[failed], "x", color=_style(trace.variant)["color"])
    _switches(ax, first)
    ax.axhline(first.period * 1e3, color="k", linewidth=0.8, linestyle=":")
    ax.set_yscale("log")
    labels = ("time (s); grey lines: contact switches", "solver call (ms, log)",
              f"{robot}, {scenario}, {rate} Hz: solve time along the run")
    return _save(fig, ax, labels, out, f"trace_{robot}_{rate}hz_{scenario}.png")


def plot_torques(traces: Sequence[Trace], out: Path) -> str:
    """One knee's torque along one scenario's run of the :data:`TORQUED` solvers present."""
    first = traces[0]
    robot, scenario, rate = first.scenario.robot, first.scenario.name, round(1 / first.period)
    loaded = load_robot(robot)
    joint = actuated_joint_names(loaded).index(KNEES[robot])
    limit = loaded.model.effortLimit[6 + joint]
    fig, ax = plt.subplots(figsize=(8.0, 3.6))
    for trace in traces:
        ax.plot(trace.time, np.asarray(trace.torque)[:, joint], linewidth=0.8,
                label=trace.variant, **_style(trace.variant))
    _switches(ax, first)
    low, high = ax.get_ylim()
    if high > 0.8 * limit:
        ax.axhline(limit, color="k", linewidth=0.8, linestyle=":")
    if low < -0.8 * limit:
        ax.axhline(-limit, color="k", linewidth=0.8, linestyle=":")
    labels = ("time (s); grey lines: contact switches", f"{KNEES[robot]} torque (Nm)",
              f"{robot}, {scenario}, {rate} Hz: applied knee torque")
    return _save(fig, ax, labels, out, f"torque_{robot}_{rate}hz_{scenario}.png")
