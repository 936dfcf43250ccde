"""Per-run figures of a closed-loop :class:`~benchmarks.closedloop.simulate.Trace`.

Tick-time percentiles are nearest ranks (:func:`benchmarks.metrics.percentile`), so with
fewer than 100 ticks a p99 is the maximum. The first :data:`SETTLE` seconds are left out
of the tracking and slip figures: the robot starts at rest touching the floor, and MuJoCo's
soft contacts let it sink a few millimetres and the feet slide a little while it settles,
the same for every solver. Tick times, failures and overruns count every tick.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from benchmarks.closedloop.simulate import Trace
from benchmarks.metrics import percentile

__all__ = ["SETTLE", "SLIDING", "RunSummary", "summarize"]

SETTLE = 0.1
"""Seconds at the start left out of the tracking and slip figures (settling on the floor)."""

SLIDING = 0.99
"""A contact counts as sliding when its simulated ``|f_t| / (mu f_n)`` reaches this."""


@dataclass(frozen=True)
class RunSummary:
    """The figures of one run (times in s, lengths in m, speeds in m/s).

    Attributes
    ----------
    robot, scenario, variant
        What ran.
    rate
        Control rate (Hz).
    floor_mu, mu_fraction
        The floor's friction coefficient and the controller's as a fraction of it.
    completed, fell_at
        Whether the run reached its end upright, and the time of the fall otherwise.
    ticks, failed
        Control ticks run, and those whose answer was not applied (not solved).
    median, p99, max
        Solver-call time along the run.
    overruns
        Ticks whose solver call took longer than the control period.
    cpu_p99, cpu_max
        The solver call's CPU time (this thread's), p99 and largest: its tail without
        preemptions by other processes.
    com_rms, com_max
        CoM tracking error, RMS and largest.
    foot_max
        Largest swing-foot tracking error (0 without a swing).
    slip_max, slip_mean
        Largest tangential contact-point speed, and its mean over ticks with a contact
        (a foot landing with a sideways speed counts: it slides as it lands).
    slide
        Distance the contact points slid, summed over them and over the run.
    sliding
        Share of ticks with a contact at the simulated friction cone's boundary.
    qp_cone_max
        Largest ``|f_t| / (floor mu f_n)`` the applied answers asked for (above 1: more
        friction than the floor has).
    torque_rate
        RMS over ticks and joints of the torque change per second (Nm/s): smoothness.
    """

    robot: str
    scenario: str
    variant: str
    rate: float
    floor_mu: float
    mu_fraction: float
    completed: bool
    fell_at: float | None
    ticks: int
    failed: int
    median: float
    p99: float
    max: float
    overruns: int
    cpu_p99: float
    cpu_max: float
    com_rms: float
    com_max: float
    foot_max: float
    slip_max: float
    slip_mean: float
    slide: float
    sliding: float
    qp_cone_max: float
    torque_rate: float

    def row(self) -> dict[str, object]:
        """The summary as a flat dict (one CSV row)."""
        return asdict(self)


def summarize(trace: Trace) -> RunSummary:
    """The figures of ``trace``."""
    times = np.asarray(trace.solve_time)
    t = np.asarray(trace.time)
    late = t >= SETTLE
    com = np.asarray(trace.com_error)[late]
    slip = np.asarray(trace.slip)[late]
    touching = np.asarray(trace.touching)[late]
    ratio = np.asarray(trace.cone_ratio)[late]
    torque = np.asarray(trace.torque)
    rate = np.diff(torque, axis=0) / trace.period if len(torque) > 1 else np.zeros((1, 1))
    qp_ratio = np.asarray(trace.qp_cone_ratio)
    scenario = trace.scenario
    return RunSummary(
        robot=scenario.robot,
        scenario=scenario.name,
        variant=trace.variant,
        rate=1.0 / trace.period,
        floor_mu=scenario.floor_mu,
        mu_fraction=trace.mu_fraction,
        completed=trace.fell_at is None,
        fell_at=trace.fell_at,
        ticks=len(times),
        failed=int(len(times) - np.sum(trace.solved)),
        median=percentile(times, 50),
        p99=percentile(times, 99),
        max=float(times.max()),
        overruns=int(np.sum(times > trace.period)),
        cpu_p99=percentile(trace.cpu_time, 99),
        cpu_max=float(np.max(trace.cpu_time)),
        com_rms=float(np.sqrt(np.mean(com**2))) if com.size else float("nan"),
        com_max=float(com.max(initial=0.0)),
        foot_max=float(np.max(trace.foot_error, initial=0.0)),
        slip_max=float(slip.max(initial=0.0)),
        slip_mean=float(slip[touching].mean()) if touching.any() else 0.0,
        slide=float(np.sum(np.asarray(trace.slide)[late])),
        sliding=float(np.mean(ratio[touching] >= SLIDING)) if touching.any() else 0.0,
        qp_cone_max=float(np.nanmax(qp_ratio)) if np.isfinite(qp_ratio).any() else float("nan"),
        torque_rate=float(np.sqrt(np.mean(rate**2))),
    )
