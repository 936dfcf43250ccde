"""A MuJoCo model generated from the controller's Pinocchio model, and state conversion.

The simulator must integrate the very dynamics the controller's QP is built from, or the
closed loop would measure a model mismatch instead of the solvers. So the MuJoCo model is
written from the Pinocchio model of :func:`benchmarks.robots.load_robot` (with
:class:`mujoco.MjSpec`), not from the URDF: one body per Pinocchio joint at its
``jointPlacement``, carrying the joint's (fixed links already merged) mass, centre of mass
and rotational inertia, a hinge along the joint's axis and a motor of gear 1; the root is
a free joint. No joint damping, friction, armature or limit (Pinocchio's ``crba`` and
``nonLinearEffects`` have none either: talos' URDF damping and friction are left out of
both). The only collision geometry is one sphere per contact point, centred on it, of the
radius in :data:`FOOT_RADIUS`; the floor is a plane at the height of the lowest sphere's
bottom in the starting posture, so the robot starts touching it. Contacts use MuJoCo's
elliptic (exact) friction cone with the floor's coefficient, and its no-slip pass
(:data:`NOSLIP_ITERATIONS`): MuJoCo's friction is otherwise soft, and a loaded foot crept
at 10-30 mm/s with its force at 60 % of the cone, which would blur the slip the friction
margin is about.

Velocities differ by convention: Pinocchio's free-flyer velocity is the base twist in the
base frame, MuJoCo's free joint has the linear velocity in the world frame and the
angular one in the base frame, so ``v_mj = T v_pin`` with ``T = diag(R, I, I)``.
Quaternions are ``(x, y, z, w)`` in Pinocchio and ``(w, x, y, z)`` in MuJoCo.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import pinocchio as pin

from benchmarks.robots import LoadedRobot

__all__ = ["FOOT_RADIUS", "NOSLIP_ITERATIONS", "SimModel", "build_sim_model"]

NOSLIP_ITERATIONS = 10
"""Iterations of MuJoCo's no-slip solver (no tangential creep inside the friction cone)."""

FOOT_RADIUS: dict[str, float] = {
    "go2": 0.022,  # the foot sphere of Unitree's own MuJoCo model
    "solo12": 0.016,
    "anymal_c": 0.03,  # the URDF's foot sphere
    "talos_reduced": 0.005,  # small spheres at the four sole corners
}
"""Radius (m) of the collision sphere centred on each contact point."""

_AXES = {"RX": (1.0, 0.0, 0.0), "RY": (0.0, 1.0, 0.0), "RZ": (0.0, 0.0, 1.0)}


def _axis(joint: pin.JointModel) -> tuple[float, ...]:
    """Rotation axis of a revolute Pinocchio joint, in its own frame."""
    short = joint.shortname()
    for suffix, axis in _AXES.items():
        if short.endswith(suffix):
            return axis
    if short == "JointModelRevoluteUnaligned":
        return tuple(float(a) for a in joint.extract().axis)
    raise ValueError(f"joint type {short} has no MuJoCo counterpart here")


def _set_inertia(body: mujoco.MjsBody, inertia: pin.Inertia) -> None:
    body.explicitinertial = True
    body.mass = float(inertia.mass)
    body.ipos = np.array(inertia.lever, dtype=float)
    rot = np.array(inertia.inertia, dtype=float)
    body.fullinertia = [rot[0, 0], rot[1, 1], rot[2, 2], rot[0, 1], rot[0, 2], rot[1, 2]]


def _quat_wxyz(rotation: np.ndarray) -> np.ndarray:
    x, y, z, w = pin.Quaternion(rotation).coeffs()
    return np.array([w, x, y, z])


@dataclass(frozen=True, eq=False)
class SimModel:
    """The compiled MuJoCo model of a robot and the maps between the two models' states.

    Attributes
    ----------
    robot
        The Pinocchio robot it was generated from.
    model
        The compiled :class:`mujoco.MjModel` (its ``opt.timestep`` is the physics step).
    qpos_index, dof_index
        For each actuated Pinocchio configuration / velocity entry after the free flyer,
        the MuJoCo ``qpos`` / ``qvel`` index holding it.
    foot_geoms
        Collision-sphere geom ids of each foot's contact points, by foot name.
    root_body
        MuJoCo id of the base body (pushes are applied to it).
    floor_height
        Height of the floor plane (m).
    """

    robot: LoadedRobot
    model: mujoco.MjModel
    qpos_index: np.ndarray
    dof_index: np.ndarray
    foot_geoms: dict[str, tuple[int, ...]]
    root_body: int
    floor_height: float

    def to_pinocchio(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        """Pinocchio ``(q, v)`` of MuJoCo's state."""
        q = np.empty(self.robot.model.nq)
        v = np.empty(self.robot.model.nv)
        q[:3] = data.qpos[:3]
        w, x, y, z = data.qpos[3:7]
        q[3:7] = (x, y, z, w)
        q[7:] = data.qpos[self.qpos_index]
        R = pin.Quaternion(w, x, y, z).toRotationMatrix()
        v[:3] = R.T @ data.qvel[:3]
        v[3:6] = data.qvel[3:6]
        v[6:] = data.qvel[self.dof_index]
        return q, v

    def set_state(self, data: mujoco.MjData, q: np.ndarray, v: np.ndarray) -> None:
        """Write Pinocchio ``(q, v)`` into MuJoCo's state (and run ``mj_forward``)."""
        x, y, z, w = q[3:7]
        data.qpos[:3] = q[:3]
        data.qpos[3:7] = (w, x, y, z)
        data.qpos[self.qpos_index] = q[7:]
        R = pin.Quaternion(w, x, y, z).toRotationMatrix()
        data.qvel[:3] = R @ v[:3]
        data.qvel[3:6] = v[3:6]
        data.qvel[self.dof_index] = v[6:]
        mujoco.mj_forward(self.model, data)

    def velocity_map(self, data: mujoco.MjData) -> np.ndarray:
        """``T`` with ``v_mj = T v_pin`` (MuJoCo's dof order) at the current state."""
        nv = self.model.nv
        T = np.zeros((nv, nv))
        w, x, y, z = data.qpos[3:7]
        T[:3, :3] = pin.Quaternion(w, x, y, z).toRotationMatrix()
        T[3:6, 3:6] = np.eye(3)
        T[self.dof_index, np.arange(6, nv)] = 1.0
        return T

    def set_torques(self, data: mujoco.MjData, u: np.ndarray) -> None:
        """Apply the QP's torques ``u`` (Pinocchio order) to the motors."""
        data.ctrl[:] = u


def build_sim_model(robot: LoadedRobot, floor_mu: float, timestep: float) -> SimModel:
    """Compile the MuJoCo model of ``robot`` on a floor of friction ``floor_mu``.

    ``timestep`` is the physics step (s); the semi-implicit Euler integrator is MuJoCo's
    default. Contact softness is MuJoCo's default (``solref`` time constant 0.02 s),
    friction made hard by the no-slip pass.
    """
    pmodel = robot.model
    spec = mujoco.MjSpec()
    spec.modelname = robot.config.name
    spec.option.timestep = timestep
    spec.option.gravity = np.array(pmodel.gravity.linear, dtype=float)
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.noslip_iterations = NOSLIP_ITERATIONS
    spec.compiler.autolimits = True
    radius = FOOT_RADIUS[robot.config.name]

    pdata = pmodel.createData()
    pin.framesForwardKinematics(pmodel, pdata, robot.q0)
    lowest = min(
        pdata.oMf[fid].translation[2] for ids in robot.contact_frames.values() for fid in ids
    )
    floor_height = float(lowest - radius)
    floor = spec.worldbody.add_geom()
    floor.name = "floor"
    floor.type = mujoco.mjtGeom.mjGEOM_PLANE
    floor.size = [0.0, 0.0, 0.05]
    floor.pos = [0.0, 0.0, floor_height]
    floor.friction = [floor_mu, 0.005, 0.0001]
    floor.condim = 3

    bodies: dict[int, mujoco.MjsBody] = {}
    for jid in range(1, pmodel.njoints):
        joint = pmodel.joints[jid]
        name = pmodel.names[jid]
        parent = spec.worldbody if jid == 1 else bodies[pmodel.parents[jid]]
        body = parent.add_body()
        body.name = name
        placement = pmodel.jointPlacements[jid]
        body.pos = np.array(placement.translation, dtype=float)
        body.quat = _quat_wxyz(placement.rotation)
        _set_inertia(body, pmodel.inertias[jid])
        if jid == 1:
            body.add_freejoint().name = name
        else:
            hinge = body.add_joint()
            hinge.name = name
            hinge.type = mujoco.mjtJoint.mjJNT_HINGE
            hinge.axis = _axis(joint)
            motor = spec.add_actuator()
            motor.name = name
            motor.target = name
            motor.trntype = mujoco.mjtTrn.mjTRN_JOINT
            motor.gear[0] = 1.0
        bodies[jid] = body

    geom_names: dict[str, list[str]] = {}
    for foot, ids in robot.contact_frames.items():
        for fid in ids:
            frame = pmodel.frames[fid]
            sphere = bodies[frame.parentJoint].add_geom()
            sphere.name = pmodel.frames[fid].name
            sphere.type = mujoco.mjtGeom.mjGEOM_SPHERE
            sphere.size = [radius, 0.0, 0.0]
            sphere.pos = np.array(frame.placement.translation, dtype=float)
            sphere.friction = [floor_mu, 0.005, 0.0001]
            sphere.condim = 3
            sphere.mass = 0.0
            sphere.density = 0.0
            geom_names.setdefault(foot, []).append(sphere.name)

    model = spec.compile()
    qpos_index = np.empty(pmodel.nq - 7, dtype=int)
    dof_index = np.empty(pmodel.nv - 6, dtype=int)
    for jid in range(2, pmodel.njoints):
        joint = pmodel.joints[jid]
        mj = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, pmodel.names[jid])
        qpos_index[joint.idx_q - 7] = model.jnt_qposadr[mj]
        dof_index[joint.idx_v - 6] = model.jnt_dofadr[mj]
    for jid in range(2, pmodel.njoints):
        actuator = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, pmodel.names[jid])
        if actuator != pmodel.joints[jid].idx_v - 6:
            raise RuntimeError("MuJoCo's actuator order differs from Pinocchio's torque order")
    foot_geoms = {
        foot: tuple(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in names)
        for foot, names in geom_names.items()
    }
    root = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, pmodel.names[1])
    return SimModel(robot, model, qpos_index, dof_index, foot_geoms, root, floor_height)
