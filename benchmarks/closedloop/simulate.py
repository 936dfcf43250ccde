"""The closed loop: MuJoCo physics, the controller at a fixed rate, one solver in between.

:func:`run` starts the robot at rest in its SRDF posture on the floor and, every control
period, reads MuJoCo's state, builds the QP (:class:`~benchmarks.closedloop.controller.
Controller`), prepares it for the solver (not timed) and calls the solver; only that call
is timed (the adapter's own :func:`time.perf_counter` pair, see
:mod:`benchmarks.adapters`; variants of :mod:`benchmarks.closedloop.variants`). The
answer's torques then drive the motors for the whole period (zero-order hold over the
physics steps). Every answer the solver reports solved
is applied, however long it took: the run is offline, and a tick longer than the period
is counted as an overrun (a real controller would have missed that deadline). An answer
not reported solved (or not finite) is not applied: the controller holds the previous
torques (zeros before the first answer) and counts the failure. As in the open-loop
harness, the solver's first-call costs (imports, workspaces) are paid before the run: it
solves the first QP once, untimed, and is reset; and the objects that exist when the run
starts are frozen out of the garbage collector (``gc.freeze``), so that collections stay
short.

While the physics steps, every foot contact with the floor is measured: the tangential
speed of the contact point (slip) and the simulated force's ``|f_t| / (mu f_n)``. The run
stops early when the robot falls: base below half its starting height above the floor,
or tilted by more than 60 degrees.
"""

from __future__ import annotations

import gc
import time
from dataclasses import dataclass, field

import mujoco
import numpy as np

from benchmarks.adapters import Adapter
from benchmarks.closedloop.controller import Controller
from benchmarks.closedloop.model import SimModel
from benchmarks.closedloop.scenarios import Scenario
from benchmarks.closedloop.variants import make
from benchmarks.wbc_qp import WbcQP

__all__ = ["Trace", "run"]

_FALL_TILT = np.cos(np.radians(60.0))


@dataclass
class Trace:
    """Everything one run records (per-tick arrays have one entry per control tick).

    Attributes
    ----------
    variant, scenario, period, mu_fraction
        The solver variant, the scenario, the control period (s) and the controller's
        friction coefficient as a fraction of the floor's.
    time
        Tick times (s).
    solve_time
        Wall time of the solver call (s).
    cpu_time
        CPU time of this thread over the same call (s, :func:`time.thread_time`): the
        solver's work without the time other processes took the core away.
    solved
        Whether the answer was reported solved and finite (else the torques were held).
    status, iterations
        The solver's status string and reported iterations (-1 when it reports none).
    torque
        Torques applied during the tick (ticks x nu).
    com_error, foot_error
        CoM and largest swing-foot tracking error at the tick (m).
    n_contacts
        Contact points in the QP (its friction cones).
    touching
        Whether a foot touched the floor during the tick's physics steps.
    slip
        Largest tangential contact-point speed over the tick's physics steps (m/s; 0
        without contact).
    slide
        Distance the contact points slid during the tick, summed over them (m).
    cone_ratio
        Largest simulated ``|f_t| / (mu f_n)`` over the tick's contacts pressed by at
        least 1 % of the robot's weight (0 without).
    qp_cone_ratio
        Largest ``|f_t| / (floor mu f_n)`` of the applied answer's contact forces (over
        contacts carrying at least 1 % of the mean normal force).
    fell_at
        Time of the fall (s), or ``None`` if the run completed.
    qps, answers, stances
        The QPs, the solver's answers and the feet in contact (sorted names), when the
        run was asked to keep them.
    """

    variant: str
    scenario: Scenario
    period: float
    mu_fraction: float
    time: list[float] = field(default_factory=list)
    solve_time: list[float] = field(default_factory=list)
    cpu_time: list[float] = field(default_factory=list)
    solved: list[bool] = field(default_factory=list)
    status: list[str] = field(default_factory=list)
    iterations: list[int] = field(default_factory=list)
    torque: list[np.ndarray] = field(default_factory=list)
    com_error: list[float] = field(default_factory=list)
    foot_error: list[float] = field(default_factory=list)
    n_contacts: list[int] = field(default_factory=list)
    touching: list[bool] = field(default_factory=list)
    slip: list[float] = field(default_factory=list)
    slide: list[float] = field(default_factory=list)
    cone_ratio: list[float] = field(default_factory=list)
    qp_cone_ratio: list[float] = field(default_factory=list)
    fell_at: float | None = None
    qps: list[WbcQP] = field(default_factory=list)
    answers: list[np.ndarray] = field(default_factory=list)
    stances: list[tuple[str, ...]] = field(default_factory=list)


def _contacts(sim: SimModel, data: mujoco.MjData, feet: set[int],
              min_force: float) -> tuple[bool, float, float, float]:
    """Whether a foot touches the floor now; the largest and the summed slip speed over
    the foot-floor contacts, and the largest ``|f_t| / (mu f_n)`` over those pressed by
    at least ``min_force`` (N; a corner barely touching slides at any force ratio)."""
    touching, slip, total, ratio = False, 0.0, 0.0, 0.0
    velocity = np.zeros(6)
    force = np.zeros(6)
    for i in range(data.ncon):
        contact = data.contact[i]
        geom = contact.geom1 if contact.geom1 in feet else contact.geom2
        if geom not in feet:
            continue
        touching = True
        mujoco.mj_objectVelocity(sim.model, data, mujoco.mjtObj.mjOBJ_GEOM, geom, velocity, 0)
        w, arm = velocity[:3], contact.pos - data.geom_xpos[geom]
        vx = velocity[3] + w[1] * arm[2] - w[2] * arm[1]  # (v + w x arm), horizontal part
        vy = velocity[4] + w[2] * arm[0] - w[0] * arm[2]
        speed = float(np.hypot(vx, vy))
        slip, total = max(slip, speed), total + speed
        mujoco.mj_contactForce(sim.model, data, i, force)
        if force[0] >= min_force:
            tangential = np.hypot(force[1], force[2])
            ratio = max(ratio, float(tangential / (contact.friction[0] * force[0])))
    return touching, slip, total, ratio


def _fallen(sim: SimModel, data: mujoco.MjData, height0: float) -> bool:
    base = sim.root_body
    height = data.xpos[base][2] - sim.floor_height
    upright = data.xmat[base][8]  # z component of the base's z axis
    return bool(height < 0.5 * height0 or upright < _FALL_TILT)


def _qp_cone_ratio(qp: WbcQP, x: np.ndarray, floor_mu: float) -> float:
    if qp.n_contacts == 0:
        return 0.0
    f = qp.forces(x)
    loaded = f[:, 2] >= 0.01 * max(float(np.mean(f[:, 2])), 1e-9)  # unloaded: no ratio
    return float(np.max(np.hypot(f[loaded, 0], f[loaded, 1]) / (floor_mu * f[loaded, 2]),
                        initial=0.0))


def run(sim: SimModel, scenario: Scenario, variant: str, period: float,
        mu_fraction: float = 1.0, keep_qps: bool = False, ticks: int | None = None) -> Trace:
    """Run ``scenario`` with solver ``variant`` at control period ``period`` (s).

    ``sim`` must have been built with the scenario's floor friction; its timestep must
    divide ``period``. ``mu_fraction`` scales the controller's friction coefficient
    (the margin of the friction sweep). ``keep_qps`` keeps every QP, answer and stance.
    ``ticks`` stops the run after that many ticks (default: the scenario's end).
    """
    robot = sim.robot
    steps = round(period / sim.model.opt.timestep)
    if steps < 1 or abs(steps * sim.model.opt.timestep - period) > 1e-9:
        raise ValueError(f"physics step {sim.model.opt.timestep} does not divide {period}")
    data = mujoco.MjData(sim.model)
    sim.set_state(data, robot.q0, np.zeros(robot.model.nv))
    height0 = data.xpos[sim.root_body][2] - sim.floor_height
    controller = Controller(robot, scenario, mu_fraction * scenario.floor_mu)
    adapter = make(variant)
    trace = Trace(variant, scenario, period, mu_fraction)
    first, _ = controller.qp(0.0, *sim.to_pinocchio(data))
    adapter.solve(adapter.prepare(first))  # warm-up, untimed
    adapter.reset()
    gc.collect()
    gc.freeze()
    try:
        _loop(sim, data, controller, adapter, trace, steps, keep_qps,
              round(scenario.duration / period) if ticks is None else ticks, height0)
    finally:
        gc.unfreeze()
    return trace


def _loop(sim: SimModel, data: mujoco.MjData, controller: Controller, adapter: Adapter,
          trace: Trace, steps: int, keep_qps: bool, ticks: int, height0: float) -> None:
    """The control ticks of :func:`run` (at most ``ticks``), recorded into ``trace``."""
    period, scenario = trace.period, trace.scenario
    u = np.zeros(sim.robot.model.nv - 6)
    model = sim.robot.model
    min_force = 0.01 * np.linalg.norm(model.gravity.linear) * sum(i.mass for i in model.inertias)
    feet = {g for ids in sim.foot_geoms.values() for g in ids}
    for tick in range(min(ticks, round(scenario.duration / period))):
        t = tick * period
        q, v = sim.to_pinocchio(data)
        qp, tracking = controller.qp(t, q, v)
        prepared = adapter.prepare(qp)
        cpu = time.thread_time()
        outcome = adapter.solve(prepared)
        cpu = time.thread_time() - cpu
        ok = bool(outcome.success and np.all(np.isfinite(outcome.x)))
        if ok:
            u = np.array(outcome.x[qp.layout["u"]])
        sim.set_torques(data, u)
        touching, slip, slide, ratio, fell = False, 0.0, 0.0, 0.0, False
        for _ in range(steps):
            data.xfrc_applied[sim.root_body, :3] = scenario.push_force(data.time)
            mujoco.mj_step(sim.model, data)
            c, s, total, r = _contacts(sim, data, feet, min_force)
            touching, slip, ratio = touching or c, max(slip, s), max(ratio, r)
            slide += total * sim.model.opt.timestep
            if _fallen(sim, data, height0):
                fell = True
                break
        trace.time.append(t)
        trace.solve_time.append(outcome.time)
        trace.cpu_time.append(cpu)
        trace.solved.append(ok)
        trace.status.append(outcome.status)
        trace.iterations.append(outcome.iterations)
        trace.torque.append(u.copy())
        trace.com_error.append(tracking.com)
        trace.foot_error.append(tracking.foot)
        trace.n_contacts.append(qp.n_contacts)
        trace.touching.append(touching)
        trace.slip.append(slip)
        trace.slide.append(slide)
        trace.cone_ratio.append(ratio)
        trace.qp_cone_ratio.append(_qp_cone_ratio(qp, outcome.x, scenario.floor_mu) if ok
                                   else float("nan"))
        if keep_qps:
            trace.qps.append(qp)
            trace.answers.append(np.array(outcome.x))
            trace.stances.append(tuple(sorted(controller.stance)))
        if fell:
            trace.fell_at = float(data.time)
            break

