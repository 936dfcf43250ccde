"""Robot configurations for the whole-body-control benchmarks.

A robot is a small frozen :class:`RobotConfig` entry in :data:`ROBOTS`: the
example-robot-data URDF and SRDF, the SRDF posture to start from, its feet (each a set
of contact points), an optional hand holding a fixed handle (holonomic constraint),
torque-limit overrides and a default friction coefficient. :func:`load_robot` turns an
entry into a Pinocchio model (free-flyer root, no geometry, a few milliseconds) with one
operational frame per contact point.
"""

from __future__ import annotations

import importlib.metadata
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import numpy as np
import pinocchio as pin

__all__ = [
    "ROBOTS",
    "Foot",
    "LoadedRobot",
    "RobotConfig",
    "actuated_joint_names",
    "contact_point_names",
    "data_dir",
    "load_robot",
]


@dataclass(frozen=True)
class Foot:
    """A foot: a frame of the URDF and the contact points it touches the ground with.

    Parameters
    ----------
    name
        Short name used by scenarios (e.g. ``"LF"``, ``"left"``).
    frame
        URDF frame the points are attached to.
    points
        Contact points in ``frame`` coordinates; one point (the origin) for a
        point foot, the four sole corners for a humanoid's flat foot.
    """

    name: str
    frame: str
    points: tuple[tuple[float, float, float], ...] = ((0.0, 0.0, 0.0),)


@dataclass(frozen=True)
class RobotConfig:
    """Everything the generator needs to know about one robot.

    Parameters
    ----------
    name
        Key in :data:`ROBOTS`.
    urdf, srdf
        Paths relative to :func:`data_dir`.
    posture
        Name of the SRDF reference configuration to start from.
    feet
        Feet in a fixed order; quadrupeds list them so that ``feet[0], feet[3]`` and
        ``feet[1], feet[2]`` are the trot's diagonal pairs.
    kind
        ``"quadruped"`` or ``"humanoid"``; selects the contact schedules of scenarios.
    hand_frame
        Frame of a hand holding a fixed handle, or ``None``.
    hand_dim
        3 for a point constraint on the hand, 6 for a rigid grasp.
    effort_overrides
        Torque limits (Nm) replacing the URDF's, by joint name.
    mu
        Default friction coefficient.
    """

    name: str
    urdf: str
    srdf: str
    posture: str
    feet: tuple[Foot, ...]
    kind: str = "quadruped"
    hand_frame: str | None = None
    hand_dim: int = 6
    effort_overrides: dict[str, float] = field(default_factory=dict)
    mu: float = 0.7


def _quadruped(
    name: str, urdf: str, srdf: str, feet: tuple[str, str, str, str], **kwargs: object
) -> RobotConfig:
    """Config of a point-footed quadruped; ``feet`` are frames in order LF, RF, LH, RH."""
    names = ("LF", "RF", "LH", "RH")
    return RobotConfig(
        name=name,
        urdf=urdf,
        srdf=srdf,
        posture="standing",
        feet=tuple(Foot(n, f) for n, f in zip(names, feet, strict=True)),
        **kwargs,  # type: ignore[arg-type]
    )


# solo12's URDF gives a 1000 Nm placeholder effort limit. The real actuator (T-motor
# Antigravity 4004 with a 9:1 belt reduction) saturates at about 2.7 Nm at the joint
# (Grimminger et al., "An Open Torque-Controlled Modular Robot Architecture for Legged
# Locomotion Research", RA-L 2020), so that is the limit used here.
_SOLO12_TORQUE = 2.7
_SOLO12_JOINTS = tuple(
    f"{leg}_{j}" for leg in ("FL", "FR", "HL", "HR") for j in ("HAA", "HFE", "KFE")
)

# TALOS sole: 0.21 m x 0.138 m rectangle around the sole frame (the values TSID uses).
_TALOS_SOLE = tuple((x, y, 0.0) for x in (0.1, -0.11) for y in (0.069, -0.069))

ROBOTS: dict[str, RobotConfig] = {
    "solo12": _quadruped(
        "solo12",
        "solo_description/robots/solo12.urdf",
        "solo_description/srdf/solo.srdf",
        ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"),
        effort_overrides=dict.fromkeys(_SOLO12_JOINTS, _SOLO12_TORQUE),
    ),
    "anymal_c": _quadruped(
        "anymal_c",
        "anymal_c_simple_description/urdf/anymal.urdf",
        "anymal_c_simple_description/srdf/anymal.srdf",
        ("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"),
    ),
    "go2": _quadruped(
        "go2",
        "go2_description/urdf/go2.urdf",
        "go2_description/srdf/go2.srdf",
        ("FL_foot", "FR_foot", "RL_foot", "RR_foot"),
    ),
    "talos_reduced": RobotConfig(
        name="talos_reduced",
        urdf="talos_data/robots/talos_reduced.urdf",
        srdf="talos_data/srdf/talos.srdf",
        posture="half_sitting",
        feet=(
            Foot("left", "left_sole_link", _TALOS_SOLE),
            Foot("right", "right_sole_link", _TALOS_SOLE),
        ),
        kind="humanoid",
        hand_frame="gripper_left_base_link",
        hand_dim=6,
    ),
}


def _point_name(foot: Foot, i: int) -> str:
    """Name of the frame of ``foot``'s ``i``-th contact point."""
    return f"{foot.name}_{i}"


def contact_point_names(robot: str, stance: tuple[str, ...]) -> tuple[str, ...]:
    """Names of the contact points of ``robot`` (a key of :data:`ROBOTS`) with the feet
    ``stance`` down, in the order the scenarios stack their cones: the robot's feet
    order, each foot's points in order (the frames of :func:`load_robot`)."""
    return tuple(_point_name(foot, i) for foot in ROBOTS[robot].feet if foot.name in stance
                 for i in range(len(foot.points)))


def data_dir() -> Path:
    """Directory holding example-robot-data's ``robots`` folder."""
    dist = importlib.metadata.distribution("example-robot-data")
    return Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))


@dataclass(frozen=True)
class LoadedRobot:
    """A Pinocchio model ready for QP building.

    Attributes
    ----------
    config
        The entry it was built from.
    model
        Free-flyer model with one ``OP_FRAME`` per contact point, named
        ``"<foot>_<i>"``, and the effort limits overridden.
    q0
        Starting configuration (the SRDF posture).
    contact_frames
        Frame ids of the contact points of each foot, by foot name.
    foot_frames
        Frame id of each foot's own frame, by foot name (swing-foot tasks).
    hand_frame
        Frame id of the grasping hand, or ``None``.
    """

    config: RobotConfig
    model: pin.Model
    q0: np.ndarray
    contact_frames: dict[str, tuple[int, ...]]
    foot_frames: dict[str, int]
    hand_frame: int | None


@cache
def load_robot(name: str) -> LoadedRobot:
    """Load robot ``name`` of :data:`ROBOTS` (cached; treat the model as read-only).

    Raises
    ------
    KeyError
        If ``name`` is not a known robot; the message lists the known ones.
    """
    if name not in ROBOTS:
        raise KeyError(f"unknown robot {name!r}; known robots: {sorted(ROBOTS)}")
    cfg = ROBOTS[name]
    root = data_dir()
    model = pin.buildModelFromUrdf(str(root / cfg.urdf), pin.JointModelFreeFlyer())
    pin.loadReferenceConfigurations(model, str(root / cfg.srdf), False)
    q0 = np.array(model.referenceConfigurations[cfg.posture], dtype=float)
    for joint, limit in cfg.effort_overrides.items():
        jid = model.getJointId(joint)
        if jid >= model.njoints:
            raise KeyError(f"{name}: no joint {joint!r} to override the effort limit of")
        model.effortLimit[model.joints[jid].idx_v] = limit
    contact_frames: dict[str, tuple[int, ...]] = {}
    foot_frames: dict[str, int] = {}
    for foot in cfg.feet:
        fid = model.getFrameId(foot.frame)
        if fid >= model.nframes:
            raise KeyError(f"{name}: no frame {foot.frame!r}")
        foot_frames[foot.name] = fid
        parent = model.frames[fid]
        ids = []
        for i, point in enumerate(foot.points):
            placement = parent.placement * pin.SE3(np.eye(3), np.asarray(point))
            frame = pin.Frame(
                _point_name(foot, i), parent.parentJoint, fid, placement, pin.FrameType.OP_FRAME
            )
            ids.append(model.addFrame(frame, False))
        contact_frames[foot.name] = tuple(ids)
    hand = None
    if cfg.hand_frame is not None:
        hand = model.getFrameId(cfg.hand_frame)
        if hand >= model.nframes:
            raise KeyError(f"{name}: no frame {cfg.hand_frame!r}")
    return LoadedRobot(cfg, model, q0, contact_frames, foot_frames, hand)


def actuated_joint_names(robot: LoadedRobot) -> list[str]:
    """Names of the actuated joints in the order of the torque block ``u`` (URDF names).

    Torque ``u_j`` drives velocity ``6 + j`` (after the free flyer), so a joint's name
    is the one whose velocity index that is.
    """
    model = robot.model
    names = [""] * (model.nv - 6)
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        for k in range(joint.nv):
            if joint.idx_v + k >= 6:
                names[joint.idx_v + k - 6] = model.names[jid]
    return names
