"""Closed-loop scenarios: contact schedule, centre-of-mass references and pushes over time.

A :class:`Scenario` is a timeline in seconds, the same for every solver: phases with a
fixed set of feet in contact (a foot not in the stance follows a swing bump and lands at
the end of its phase, an impact), a horizontal centre-of-mass offset reached by a
minimum-jerk curve within each phase, an optional CoM sway, and pushes (a constant
world-frame force on the base for a while). :func:`make_scenario` builds the named
scenarios of :data:`SCENARIOS` for a robot; the floor's friction coefficient is a
parameter of each.

- ``stand``: all feet down, nothing else.
- ``sway``: all feet down, CoM sinusoid (5 cm sideways, 3 cm forward for a quadruped,
  4 cm / 2 cm for the humanoid; 0.8 Hz).
- ``push``: all feet down, five sideways pushes of 0.1 s, 0.8 s apart, each larger than
  the last (base speed changes of 0.2, 0.4, 0.6, 0.8 and 1 m/s if the robot were free;
  the last one's force is the robot's weight): the later ones may throw it over.
- ``lift``: CoM over the other feet, one foot (a quadruped's left front, the humanoid's
  right) lifted 6 cm (humanoid 5 cm) and put down, CoM back.
- ``trot`` (quadrupeds): a trot in place, diagonal pairs alternating every 0.2 s.
- ``shift`` (humanoid): the CoM moves over one foot, then the other, and back.
- ``step`` (humanoid): CoM over the left foot, the right foot steps 10 cm forward, CoM
  to the middle of the new support.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from benchmarks.robots import LoadedRobot
from benchmarks.scenarios import _min_jerk

__all__ = ["SCENARIOS", "Phase", "Push", "Reference", "Scenario", "make_scenario"]

_GRAVITY = 9.81


@dataclass(frozen=True)
class Phase:
    """A stretch of time with a fixed contact set.

    Attributes
    ----------
    duration
        Length (s).
    stance
        Names of the feet in contact; the others swing and land at the phase's end.
    com_shift
        Horizontal CoM offset from the start, reached at the phase's end (m).
    """

    duration: float
    stance: tuple[str, ...]
    com_shift: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class Push:
    """A constant world-frame force (N) on the base from ``start`` for ``duration`` s."""

    start: float
    duration: float
    force: tuple[float, float, float]


@dataclass(frozen=True)
class Reference:
    """What the scenario asks at one instant.

    Attributes
    ----------
    stance
        Feet in contact.
    com
        CoM offset from the starting CoM: position, velocity, acceleration (3,) each.
    swing
        For each swinging foot, its progress ``s`` in [0, 1) through the swing and the
        swing's duration (s).
    """

    stance: tuple[str, ...]
    com: tuple[np.ndarray, np.ndarray, np.ndarray]
    swing: dict[str, tuple[float, float]]


@dataclass(frozen=True)
class Scenario:
    """One closed-loop run's script (everything but the robot model and the solver).

    Attributes
    ----------
    name, robot
        Scenario and robot names.
    phases
        Contact phases in order; the run lasts their total duration.
    floor_mu
        Friction coefficient of the simulated floor.
    sway_amp, sway_freq
        CoM sinusoid amplitude per axis (m) and frequency (Hz).
    pushes
        Pushes on the base.
    swing_height
        Peak height of a swing foot above its lift-off point (m).
    stride
        Horizontal displacement of a swing foot from lift-off to touch-down (m).
    """

    name: str
    robot: str
    phases: tuple[Phase, ...]
    floor_mu: float
    sway_amp: tuple[float, float, float] = (0.0, 0.0, 0.0)
    sway_freq: float = 0.0
    pushes: tuple[Push, ...] = ()
    swing_height: float = 0.06
    stride: tuple[float, float] = (0.0, 0.0)

    @property
    def duration(self) -> float:
        """Length of the run (s)."""
        return float(sum(p.duration for p in self.phases))

    def push_force(self, t: float) -> np.ndarray:
        """Total push force on the base at time ``t`` (N, world frame)."""
        force = np.zeros(3)
        for p in self.pushes:
            if p.start <= t < p.start + p.duration:
                force += p.force
        return force

    def reference(self, t: float) -> Reference:
        """The stance, CoM offset and swing progress at time ``t``."""
        start, prev = 0.0, (0.0, 0.0)
        for phase in self.phases:  # stops at the phase holding t (or the last)
            if t < start + phase.duration or phase is self.phases[-1]:
                break
            start += phase.duration
            prev = phase.com_shift
        T = phase.duration
        s = min(max((t - start) / T, 0.0), 1.0)
        blend = _min_jerk(s)
        shift = np.subtract(phase.com_shift, prev)
        pos = np.r_[np.add(prev, blend[0] * shift), 0.0]
        vel = np.r_[blend[1] * shift / T, 0.0]
        acc = np.r_[blend[2] * shift / T**2, 0.0]
        w = 2.0 * np.pi * self.sway_freq
        amp = np.asarray(self.sway_amp)
        pos = pos + amp * np.sin(w * t)
        vel = vel + amp * w * np.cos(w * t)
        acc = acc - amp * w**2 * np.sin(w * t)
        feet = {name for ph in self.phases for name in ph.stance}
        swing = {f: (s, T) for f in sorted(feet) if f not in phase.stance}
        return Reference(phase.stance, (pos, vel, acc), swing)


SCENARIOS: dict[str, tuple[str, ...]] = {
    "quadruped": ("stand", "sway", "push", "lift", "trot"),
    "humanoid": ("stand", "sway", "push", "lift", "shift", "step"),
}
"""Scenario names by robot kind, in report order."""


def _support_shift(robot: LoadedRobot, stance: tuple[str, ...],
                   share: float) -> tuple[float, float]:
    """Horizontal offset taking the CoM ``share`` of the way to the stance feet's centroid."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.q0)
    com = pin.centerOfMass(robot.model, data, robot.q0)[:2]
    points = [data.oMf[fid].translation[:2] for f in stance for fid in robot.contact_frames[f]]
    target = share * (np.mean(points, axis=0) - com)
    return float(target[0]), float(target[1])


def _mass(robot: LoadedRobot) -> float:
    return float(sum(i.mass for i in robot.model.inertias[1:]))


def make_scenario(robot: LoadedRobot, name: str, floor_mu: float) -> Scenario:
    """Scenario ``name`` (one of :data:`SCENARIOS` for the robot's kind) on a floor ``floor_mu``.

    Raises
    ------
    ValueError
        If ``name`` is not a scenario of the robot's kind.
    """
    kind = robot.config.kind
    if name not in SCENARIOS[kind]:
        raise ValueError(f"unknown {kind} scenario {name!r}; known: {SCENARIOS[kind]}")
    feet = tuple(f.name for f in robot.config.feet)
    quad = kind == "quadruped"
    common = {"name": name, "robot": robot.config.name, "floor_mu": floor_mu}
    if name == "stand":
        return Scenario(phases=(Phase(2.0, feet),), **common)
    if name == "sway":
        amp = (0.03, 0.05, 0.0) if quad else (0.02, 0.04, 0.0)
        return Scenario(phases=(Phase(3.0, feet),), sway_amp=amp, sway_freq=0.8, **common)
    if name == "push":
        mass = _mass(robot)
        pushes = tuple(
            Push(start, 0.1, (0.0, mass * dv / 0.1, 0.0))
            for start, dv in zip((0.5, 1.3, 2.1, 2.9, 3.7), (0.2, 0.4, 0.6, 0.8, 1.0),
                                 strict=True)
        )
        return Scenario(phases=(Phase(4.5, feet),), pushes=pushes, **common)
    if name == "lift":
        lifted = feet[0] if quad else feet[1]
        stance = tuple(f for f in feet if f != lifted)
        shift = _support_shift(robot, stance, 0.7 if quad else 0.9)
        return Scenario(
            phases=(
                Phase(0.2, feet),
                Phase(0.8, feet, shift),
                Phase(0.5, stance, shift),
                Phase(0.3, feet, shift),
                Phase(0.8, feet),
            ),
            swing_height=0.06 if quad else 0.05,
            **common,
        )
    if name == "trot":
        pairs = ((feet[0], feet[3]), (feet[1], feet[2]))
        steps = tuple(Phase(0.2, pairs[i % 2]) for i in range(10))
        return Scenario(phases=(Phase(0.3, feet), *steps, Phase(0.5, feet)),
                        swing_height=0.05, **common)
    left = _support_shift(robot, (feet[0],), 0.8)
    if name == "step":
        stride = (0.1, 0.0)
        left_full = _support_shift(robot, (feet[0],), 0.95)
        middle = (0.5 * stride[0], 0.0)
        return Scenario(
            phases=(Phase(0.2, feet), Phase(1.2, feet, left_full), Phase(0.8, (feet[0],),
                    left_full), Phase(1.2, feet, middle), Phase(0.6, feet, middle)),
            swing_height=0.04, stride=stride, **common,
        )
    right = _support_shift(robot, (feet[1],), 0.8)
    return Scenario(
        phases=(Phase(0.2, feet), Phase(1.0, feet, left), Phase(1.5, feet, right),
                Phase(1.0, feet)),
        **common,
    )
