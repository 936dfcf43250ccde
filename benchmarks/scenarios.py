"""Scenarios: controller-loop sequences of whole-body-control QPs.

A sequence is a :class:`SequenceSpec` (drawn deterministically from a seed by
:func:`make_sequence`) rolled forward by :func:`rollout`: at each tick the task PD
commands are formed from the state, the QP of :mod:`benchmarks.wbc_qp` is built and
solved with Clarabel, and the state is integrated with the solved accelerations
(semi-implicit Euler), so consecutive QPs are correlated as in a real controller.

Scenarios (:data:`SCENARIOS`):

``stand_push``
    All feet down, gentle CoM sway, base velocity impulses (pushes) every third of the
    sequence.
``aggressive``
    All feet down, large fast CoM and base-orientation sinusoids.
``low_friction``
    Friction coefficient drawn in [0.2, 1.0], CoM motion peaking at 0.7-1.4 ``mu g`` and
    one push.
``contact_switch``
    Quadrupeds: a trot in place (diagonal pairs alternate) or one foot lifted then put
    down again. Humanoid: single support on the left foot then double support. Before a
    foot lifts the CoM is shifted over the remaining support during an unrecorded
    pre-roll. The CoM sways as hard as in ``low_friction``.

Sinusoid frequencies follow Froude scaling (see :func:`_froude_scaled`), so a scenario
is the same motion, in units of the robot's size, on every robot.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from benchmarks.robots import LoadedRobot
from benchmarks.wbc_qp import (
    TaskCommands,
    WbcQP,
    build_wbc_qp,
    solve_reference,
    solve_tight_reference,
)

__all__ = ["SCENARIOS", "Gains", "Phase", "SequenceSpec", "make_sequence", "rollout"]

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_GRAVITY = 9.81
_COM_CAP = np.array([0.15, 0.15, 0.05])  # CoM sinusoid amplitude caps, in base heights
_REF_HEIGHT = 0.5  # base height (m) the sinusoid frequency ranges are given for


@dataclass(frozen=True)
class Phase:
    """A stretch of ticks with a fixed contact set.

    Attributes
    ----------
    ticks
        Duration in controller ticks.
    stance
        Names of the feet in contact; the others follow a swing arc.
    com_shift
        Horizontal CoM offset from the start reached at the end of the phase (by a
        minimum-jerk curve from the previous phase's offset).
    record
        Whether the phase's QPs go into the test set (``False`` for a pre-roll).
    """

    ticks: int
    stance: tuple[str, ...]
    com_shift: tuple[float, float] = (0.0, 0.0)
    record: bool = True


@dataclass(frozen=True)
class SequenceSpec:
    """Everything that defines one sequence besides the robot and ``dt``.

    Sinusoids are ``amp * sin(2 pi freq t + phase)`` per axis, added to the CoM position
    (m) and to the base orientation as a world-frame rotation vector (rad). A swing
    foot follows a half-sine bump over its phase of duration ``T`` whose height
    ``swing_accel (T / pi)^2`` gives a peak vertical acceleration of ``swing_accel``.
    """

    scenario: str
    phases: tuple[Phase, ...]
    mu: float
    com_amp: np.ndarray
    com_freq: np.ndarray
    com_phase: np.ndarray
    base_amp: np.ndarray
    base_freq: np.ndarray
    base_phase: np.ndarray
    swing_accel: float
    pushes: dict[int, np.ndarray] = field(default_factory=dict)


@dataclass(frozen=True)
class Gains:
    """PD gains (stiffness, damping) of the tasks and the contact stabilization."""

    com: tuple[float, float] = (100.0, 20.0)
    base: tuple[float, float] = (100.0, 20.0)
    swing: tuple[float, float] = (400.0, 40.0)
    posture: tuple[float, float] = (25.0, 10.0)
    contact: tuple[float, float] = (100.0, 20.0)


def _sinusoid(
    amp: np.ndarray, freq: np.ndarray, phase: np.ndarray, t: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity and acceleration of ``amp sin(2 pi freq t + phase)``."""
    w = 2.0 * np.pi * freq
    arg = w * t + phase
    return amp * np.sin(arg), amp * w * np.cos(arg), -amp * w**2 * np.sin(arg)


def _min_jerk(s: float) -> tuple[float, float, float]:
    """Minimum-jerk blend ``10s^3 - 15s^4 + 6s^5`` and its first two s-derivatives."""
    return (
        10 * s**3 - 15 * s**4 + 6 * s**5,
        30 * s**2 - 60 * s**3 + 30 * s**4,
        60 * s - 180 * s**2 + 120 * s**3,
    )


def _random_sinusoids(
    rng: np.random.Generator,
    amp_lo: np.ndarray,
    amp_hi: np.ndarray,
    freq: tuple[float, float],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (
        rng.uniform(amp_lo, amp_hi) * rng.choice([-1.0, 1.0], 3),
        rng.uniform(*freq, 3),
        rng.uniform(0.0, 2.0 * np.pi, 3),
    )


def _froude_scaled(freq: tuple[float, float], height: float) -> tuple[float, float]:
    """Frequency range ``freq`` (Hz for a 0.5 m base height) for a base ``height`` m high.

    Dynamically similar motions of robots of different sizes have their times in
    proportion to ``sqrt(height / g)`` (Froude scaling), so frequencies go as
    ``sqrt(0.5 / height)``. The CoM amplitudes are capped in units of the height, so at
    one frequency for all robots the caps would cut the drawn accelerations of small
    robots only (solo12's aggressive sway lost up to half its drawn acceleration).
    """
    k = np.sqrt(_REF_HEIGHT / height)
    return freq[0] * k, freq[1] * k


def _foot_xy(robot: LoadedRobot) -> dict[str, np.ndarray]:
    """Horizontal position of each foot at the starting posture."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.q0)
    return {name: data.oMf[fid].translation[:2].copy() for name, fid in robot.foot_frames.items()}


def _com_xy(robot: LoadedRobot) -> np.ndarray:
    data = robot.model.createData()
    return pin.centerOfMass(robot.model, data, robot.q0)[:2].copy()


def _contact_phases(
    robot: LoadedRobot, rng: np.random.Generator, n_ticks: int, dt: float
) -> tuple[Phase, ...]:
    """Contact schedule of ``contact_switch``: trot, or one foot lifted then put down."""
    feet = tuple(f.name for f in robot.config.feet)
    pre = round(0.3 / dt)
    if robot.config.kind == "quadruped" and rng.random() < 0.6:
        pairs = ((feet[0], feet[3]), (feet[1], feet[2]))
        half = round(rng.uniform(0.08, 0.15) / dt)
        phases = [Phase(min(10, n_ticks), feet)]
        left, i = n_ticks - phases[0].ticks, int(rng.integers(2))
        while left > 0:
            phases.append(Phase(min(half, left), pairs[i]))
            left -= phases[-1].ticks
            i = 1 - i
        return tuple(phases)
    lifted = feet[-1] if robot.config.kind == "humanoid" else feet[int(rng.integers(4))]
    stance = tuple(f for f in feet if f != lifted)
    xy = _foot_xy(robot)
    target = 0.8 * (np.mean([xy[f] for f in stance], axis=0) - _com_xy(robot))
    shift = (float(target[0]), float(target[1]))
    lift_ticks = round(0.6 * n_ticks)
    return (
        Phase(pre, feet, shift, record=False),
        Phase(pre // 5, feet, shift, record=False),
        Phase(lift_ticks, stance, shift),
        Phase(n_ticks - lift_ticks, feet, shift),
    )


def make_sequence(
    robot: LoadedRobot, scenario: str, rng: np.random.Generator, n_ticks: int, dt: float
) -> SequenceSpec:
    """Draw one sequence of ``scenario`` for ``robot`` with ``n_ticks`` recorded ticks.

    CoM sinusoids are drawn by their peak acceleration -- horizontal in units of
    ``mu g``, the most friction can give, vertical in units of ``g`` -- so that one
    definition stresses the cones of a 2.5 kg quadruped and of a 90 kg humanoid alike;
    amplitudes are capped at ``0.15 L`` horizontally and ``0.05 L`` vertically, ``L``
    being the standing base height, and frequencies are Froude-scaled from ``L`` so that
    the caps bind alike on every robot. Push speeds are also in units of ``mu g`` (s).
    """
    if scenario not in SCENARIOS:
        raise ValueError(f"unknown scenario {scenario!r}; known: {sorted(SCENARIOS)}")
    L = float(robot.q0[2])
    feet = tuple(f.name for f in robot.config.feet)
    phases: tuple[Phase, ...] = (Phase(n_ticks, feet),)
    mu = robot.config.mu
    pushes: dict[int, np.ndarray] = {}
    # Peak CoM accelerations: (x, y) in mu g, z in g; base amplitudes in rad.
    com_lo, com_hi = np.array([0.1, 0.1, 0.02]), np.array([0.2, 0.2, 0.05])
    base_lo, base_hi = np.zeros(3), np.full(3, 0.03)
    com_f, base_f = (0.5, 1.5), (0.5, 1.5)
    if scenario == "aggressive":
        com_lo, com_hi = np.array([0.8, 0.8, 0.1]), np.array([1.6, 1.6, 0.3])
        base_lo, base_hi = np.array([0.1, 0.1, 0.1]), np.array([0.25, 0.25, 0.3])
        com_f, base_f = (2.0, 3.5), (1.0, 2.5)
    elif scenario == "low_friction":
        mu = 0.2 + 0.8 * float(rng.random()) ** 2  # low values more often
        com_lo, com_hi = np.array([0.7, 0.7, 0.05]), np.array([1.4, 1.4, 0.1])
        com_f = (1.5, 2.5)
    elif scenario == "contact_switch":
        phases = _contact_phases(robot, rng, n_ticks, dt)
        mu = float(rng.uniform(0.3, 0.7))
        com_lo, com_hi = np.array([0.7, 0.7, 0.02]), np.array([1.4, 1.4, 0.05])
        com_f = (1.5, 2.5)
    com_f, base_f = _froude_scaled(com_f, L), _froude_scaled(base_f, L)
    scale = np.array([mu * _GRAVITY, mu * _GRAVITY, _GRAVITY])
    acc, com_freq, com_phase = _random_sinusoids(rng, com_lo * scale, com_hi * scale, com_f)
    com_amp = np.clip(acc / (2 * np.pi * com_freq) ** 2, -L * _COM_CAP, L * _COM_CAP)

    def push() -> np.ndarray:
        heading = rng.uniform(0.0, 2.0 * np.pi)
        speed = rng.uniform(0.05, 0.1) * mu * _GRAVITY
        lin = speed * np.array([np.cos(heading), np.sin(heading), 0.0])
        return np.concatenate([lin, rng.uniform(-0.8, 0.8, 3)])

    if scenario == "stand_push":
        pushes = {t: push() for t in range(5, n_ticks, max(n_ticks // 3, 1))}
    elif scenario == "low_friction":
        pushes = {n_ticks // 2: push()}
    return SequenceSpec(
        scenario,
        phases,
        mu,
        com_amp,
        com_freq,
        com_phase,
        *_random_sinusoids(rng, base_lo, base_hi, base_f),
        swing_accel=15.0 if robot.config.kind == "quadruped" else 4.0,
        pushes=pushes,
    )


SCENARIOS: tuple[str, ...] = (
    "stand_push",
    "aggressive",
    "low_friction",
    "contact_switch",
)


def _push(
    robot: LoadedRobot, data: pin.Data, q: np.ndarray, frames: list[int], dv: np.ndarray
) -> np.ndarray:
    """Velocity jump of a base impulse that would change the free base velocity by ``dv``.

    The impulse ``p = M_bb dv`` (base block of the mass matrix) hits a robot whose feet
    and grasping hand stay put, so the jump is the constrained impulse response
    ``M^-1 (S'p + J'L)`` with contact impulses ``L`` keeping ``J jump = 0``.
    """
    model = robot.model
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    rows = [pin.getFrameJacobian(model, data, fid, _LWA)[:3] for fid in frames]
    if robot.hand_frame is not None:
        rows.append(pin.getFrameJacobian(model, data, robot.hand_frame, _LWA))
    impulse = np.zeros(model.nv)
    impulse[:6] = M[:6, :6] @ dv
    jump = np.linalg.solve(M, impulse)
    if rows:
        J = np.vstack(rows)
        MinvJt = np.linalg.solve(M, J.T)
        jump -= MinvJt @ np.linalg.lstsq(J @ MinvJt, J @ jump, rcond=None)[0]
    return jump


def _hand_feedback(robot: LoadedRobot, data: pin.Data, handle: pin.SE3, g: Gains) -> np.ndarray:
    """Baumgarte term ``-Kp e - Kd J v`` keeping the hand on the handle.

    The error and velocity are expressed like the constraint rows: LOCAL twist and
    ``log6`` for a rigid grasp, world-aligned point position for a point constraint.
    """
    hand = robot.hand_frame
    if robot.config.hand_dim == 6:
        err = pin.log6(handle.actInv(data.oMf[hand])).vector
        vel = pin.getFrameVelocity(robot.model, data, hand, pin.ReferenceFrame.LOCAL).vector
    else:
        err = data.oMf[hand].translation - handle.translation
        vel = pin.getFrameVelocity(robot.model, data, hand, _LWA).linear
    return -g.contact[0] * err - g.contact[1] * vel


def _phase_at(
    phases: tuple[Phase, ...], tick: int
) -> tuple[int, Phase, float, tuple[float, float]]:
    """Index of the phase holding ``tick``, the phase, progress in [0, 1) and previous shift."""
    start, prev = 0, (0.0, 0.0)
    for i, ph in enumerate(phases):
        if tick < start + ph.ticks:
            return i, ph, (tick - start) / ph.ticks, prev
        start += ph.ticks
        prev = ph.com_shift
    raise IndexError(tick)


def rollout(
    robot: LoadedRobot,
    spec: SequenceSpec,
    dt: float,
    gains: Gains | None = None,
    tol: float = 1e-9,
    progress: Callable[[], None] | None = None,
) -> tuple[list[WbcQP], list[np.ndarray], list[tuple[str, ...]]]:
    """Run the controller loop of ``spec``; return the recorded QPs, their reference
    solutions (:func:`~benchmarks.wbc_qp.solve_tight_reference`) and the feet in contact
    at each (the phase's ``stance``, sorted).

    Parameters
    ----------
    robot
        Loaded robot; the sequence starts at rest in its SRDF posture.
    spec
        The sequence to run.
    dt
        Controller period (s).
    gains
        Task and contact PD gains; :class:`Gains` defaults if ``None``.
    tol
        Clarabel tolerance of the controller's own solve, whose accelerations drive the
        robot (the recorded references are solved tighter).
    progress
        Called once per recorded QP (e.g. a progress bar's update).

    Raises
    ------
    RuntimeError
        If the base falls below half its starting height (a scenario to retune).
    """
    g = gains or Gains()
    model, data = robot.model, robot.model.createData()
    q, v = robot.q0.copy(), np.zeros(model.nv)
    pin.framesForwardKinematics(model, data, q)
    anchors = {fid: data.oMf[fid].translation.copy() for fid in robot.foot_frames.values()}
    anchors |= {
        fid: data.oMf[fid].translation.copy()
        for ids in robot.contact_frames.values()
        for fid in ids
    }
    handle = data.oMf[robot.hand_frame].copy() if robot.hand_frame is not None else None
    com0 = pin.centerOfMass(model, data, q).copy()
    R0 = data.oMi[1].rotation.copy()
    qs, xs, stances = [], [], []
    total = sum(ph.ticks for ph in spec.phases)
    rec = -1
    for tick in range(total):
        i, phase, s, prev = _phase_at(spec.phases, tick)
        rec += phase.record
        contacts = [fid for f in phase.stance for fid in robot.contact_frames[f]]
        if phase.record and rec in spec.pushes:
            v = v + _push(robot, data, q, contacts, spec.pushes[rec])

        t = tick * dt
        pin.forwardKinematics(model, data, q, v)
        pin.updateFramePlacements(model, data)
        com = pin.centerOfMass(model, data, q, v)
        vcom = data.vcom[0]
        c_ref, c_vel, c_acc = _sinusoid(spec.com_amp, spec.com_freq, spec.com_phase, t)
        blend = _min_jerk(s)
        dshift = np.subtract(phase.com_shift, prev)
        T = phase.ticks * dt
        c_ref = c_ref + com0 + np.r_[np.add(prev, blend[0] * dshift), 0.0]
        c_vel = c_vel + np.r_[blend[1] * dshift / T, 0.0]
        c_acc = c_acc + np.r_[blend[2] * dshift / T**2, 0.0]
        com_cmd = c_acc + g.com[0] * (c_ref - com) + g.com[1] * (c_vel - vcom)

        r_ref, w_ref, a_ref = _sinusoid(spec.base_amp, spec.base_freq, spec.base_phase, t)
        R = data.oMi[1].rotation
        err = pin.log3(pin.exp3(r_ref) @ R0 @ R.T)
        omega = R @ v[3:6]
        base_cmd = a_ref + g.base[0] * err + g.base[1] * (w_ref - omega)

        posture_cmd = g.posture[0] * pin.difference(model, q, robot.q0)[6:] - g.posture[1] * v[6:]

        points = {}
        for foot, fid in robot.foot_frames.items():
            if foot in phase.stance:
                continue
            bump = (
                spec.swing_accel
                * (T / np.pi) ** 2
                * np.array(
                    [
                        np.sin(np.pi * s),
                        np.pi / T * np.cos(np.pi * s),
                        -((np.pi / T) ** 2) * np.sin(np.pi * s),
                    ]
                )
            )
            p = data.oMf[fid].translation
            pv = pin.getFrameVelocity(model, data, fid, _LWA).linear
            p_ref = anchors[fid] + np.r_[0.0, 0.0, bump[0]]
            v_ref = np.r_[0.0, 0.0, bump[1]]
            points[fid] = (
                np.r_[0.0, 0.0, bump[2]] + g.swing[0] * (p_ref - p) + g.swing[1] * (v_ref - pv)
            )

        contact_acc = np.concatenate(
            [
                -g.contact[0] * (data.oMf[fid].translation - anchors[fid])
                - g.contact[1] * pin.getFrameVelocity(model, data, fid, _LWA).linear
                for fid in contacts
            ]
            or [np.zeros(0)]
        )
        hand_acc = None
        if handle is not None:
            hand_acc = _hand_feedback(robot, data, handle, g)

        commands = TaskCommands(
            com=com_cmd, base_angular=base_cmd, points=points, posture=posture_cmd
        )
        qp = build_wbc_qp(
            model,
            data,
            q,
            v,
            commands,
            contacts,
            spec.mu,
            hand=robot.hand_frame,
            hand_dim=robot.config.hand_dim,
            contact_acc=contact_acc,
            hand_acc=hand_acc,
        )
        x = solve_reference(qp, tol)
        if phase.record:
            qs.append(qp)
            xs.append(solve_tight_reference(qp))
            stances.append(tuple(sorted(phase.stance)))
            if progress is not None:
                progress()
        v = v + dt * x[qp.layout["vdot"]]
        q = pin.integrate(model, q, dt * v)
        if q[2] < 0.5 * robot.q0[2]:
            raise RuntimeError(
                f"{robot.config.name} fell in {spec.scenario} at tick {tick} (phase {i})"
            )
    return qs, xs, stances
