"""QPs logged from the closed loop, as a test set of the open-loop harness (``closedloop``).

Open-loop sequences (:mod:`benchmarks.scenarios`) integrate the controller's own model,
so they are smooth where a real loop is not. This module records the QPs a controller
builds in MuJoCo (:func:`benchmarks.closedloop.simulate.run`) instead, so that every
open-loop table can be read on closed-loop data: ``python -m benchmarks --scenario
closedloop`` (cached like the other sets, :mod:`benchmarks.cache`).

Sequence ``j`` draws from ``numpy.random.default_rng([seed, j])``: a floor friction in
[0.4, 0.8], then a window of ``seq_len`` control ticks that starts a few ticks before one
event of the scenario (a push, a lift-off, a touch-down, a CoM shift); scenarios cycle
through :data:`CYCLE`. The loop is driven by Clarabel (exact cones, its default
tolerance) from the robot's rest state; each recorded QP gets the reference solution
of the open-loop sets (:func:`benchmarks.wbc_qp.solve_tight_reference`).
"""

from __future__ import annotations

import numpy as np

from benchmarks.closedloop.model import build_sim_model
from benchmarks.closedloop.scenarios import Scenario, make_scenario
from benchmarks.closedloop.simulate import run
from benchmarks.robots import load_robot
from benchmarks.wbc_qp import WbcQP, solve_tight_reference

__all__ = ["CYCLE", "DRIVER", "logged_sequences"]

CYCLE: dict[str, tuple[str, ...]] = {
    "quadruped": ("push", "lift", "trot", "sway"),
    "humanoid": ("push", "lift", "shift", "sway"),
}
"""Scenario of sequence ``j``: ``CYCLE[kind][j % 4]``."""

DRIVER = "clarabel"
"""Solver variant that drives the logged loop."""


def _events(scenario: Scenario) -> list[float]:
    """Times (s) where something happens: pushes and phase boundaries (else 1 s in)."""
    times = [p.start for p in scenario.pushes]
    start = 0.0
    for phase in scenario.phases[:-1]:
        start += phase.duration
        times.append(start)
    return times or [1.0]


def logged_sequences(
    robot: str, n_qps: int, seed: int, dt: float, seq_len: int,
    progress=None,
) -> tuple[list[WbcQP], list[np.ndarray], list[tuple[str, ...]], list[int]]:
    """``n_qps`` closed-loop QPs of ``robot`` at control period ``dt`` in windows of
    ``seq_len`` ticks: the QPs, their references, stances and sequence indices.

    ``progress`` (if given) is called once per recorded QP.
    """
    loaded = load_robot(robot)
    qps: list[WbcQP] = []
    xs: list[np.ndarray] = []
    stances: list[tuple[str, ...]] = []
    seq: list[int] = []
    j = 0
    while len(qps) < n_qps:
        rng = np.random.default_rng([seed, j])
        mu = float(rng.uniform(0.4, 0.8))
        names = CYCLE[loaded.config.kind]
        scenario = make_scenario(loaded, names[j % len(names)], mu)
        total = round(scenario.duration / dt)
        length = min(seq_len, n_qps - len(qps), total)
        event = round(float(rng.choice(_events(scenario))) / dt)
        first = int(np.clip(event - rng.integers(1, max(2, seq_len // 3 + 1)), 0, total - length))
        trace = run(build_sim_model(loaded, mu, 0.001), scenario, DRIVER, dt, keep_qps=True,
                    ticks=first + length)
        for qp, stance in zip(trace.qps[first:], trace.stances[first:], strict=True):
            qps.append(qp)
            xs.append(solve_tight_reference(qp))
            stances.append(stance)
            seq.append(j)
            if progress is not None:
                progress()
        j += 1
    return qps, xs, stances, seq
