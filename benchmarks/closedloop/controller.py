"""The closed-loop controller: task-space PD commands and the whole-body-control QP.

At every control tick :meth:`Controller.qp` turns the measured state ``(q, v)`` and the
scenario's :class:`~benchmarks.closedloop.scenarios.Reference` into task commands --
CoM (PD to the scripted offset from the starting CoM), base orientation (PD to the
starting orientation), posture (PD to the starting joint angles), a point task per
swinging foot (PD to a half-sine bump over the line from its lift-off point to its
lift-off point plus the scenario's stride, by a minimum-jerk curve) -- and contact
stabilization accelerations that hold each stance contact point at its anchor (where it
touched down), then builds the QP of :func:`benchmarks.wbc_qp.build_wbc_qp` with the
controller's friction coefficient. Gains are the open-loop generator's
(:class:`benchmarks.scenarios.Gains`). A humanoid's hand handle of the open-loop
benchmark does not exist in the simulation, so the hand is free here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from benchmarks.closedloop.scenarios import Scenario
from benchmarks.robots import LoadedRobot
from benchmarks.scenarios import Gains, _min_jerk
from benchmarks.wbc_qp import TaskCommands, WbcQP, build_wbc_qp

__all__ = ["Controller", "Tracking"]

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class Tracking:
    """Tracking errors at one tick (m): CoM, and the largest swing-foot error (0 if none)."""

    com: float
    foot: float


class Controller:
    """Whole-body controller of one robot following one scenario.

    Parameters
    ----------
    robot
        The Pinocchio robot (its model is only read).
    scenario
        The script to follow.
    mu
        Friction coefficient the QP's cones use (the floor's times a margin).
    gains
        Task and contact PD gains; :class:`~benchmarks.scenarios.Gains` defaults if ``None``.
    """

    def __init__(self, robot: LoadedRobot, scenario: Scenario, mu: float,
                 gains: Gains | None = None) -> None:
        self.robot = robot
        self.scenario = scenario
        self.mu = mu
        self.gains = gains or Gains()
        model = robot.model
        self._data = model.createData()
        pin.framesForwardKinematics(model, self._data, robot.q0)
        self._com0 = pin.centerOfMass(model, self._data, robot.q0).copy()
        self._R0 = self._data.oMi[1].rotation.copy()
        self._anchors = {fid: self._data.oMf[fid].translation.copy()
                         for ids in robot.contact_frames.values() for fid in ids}
        self._lift_off = {name: self._data.oMf[fid].translation.copy()
                          for name, fid in robot.foot_frames.items()}
        self._stance = tuple(f.name for f in robot.config.feet)

    @property
    def stance(self) -> tuple[str, ...]:
        """Feet in contact at the last :meth:`qp` call."""
        return self._stance

    def _switch(self, stance: tuple[str, ...]) -> None:
        """Re-anchor feet that touched down and remember where lifted feet left."""
        data = self._data
        for foot in stance:
            if foot not in self._stance:
                for fid in self.robot.contact_frames[foot]:
                    self._anchors[fid] = data.oMf[fid].translation.copy()
        for foot in self._stance:
            if foot not in stance:
                self._lift_off[foot] = data.oMf[self.robot.foot_frames[foot]].translation.copy()
        self._stance = stance

    def qp(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[WbcQP, Tracking]:
        """The QP at time ``t`` and state ``(q, v)``, and the tracking errors there."""
        model, data, g, robot = self.robot.model, self._data, self.gains, self.robot
        ref = self.scenario.reference(t)
        pin.forwardKinematics(model, data, q, v)
        pin.updateFramePlacements(model, data)
        if ref.stance != self._stance:
            self._switch(ref.stance)
        com = pin.centerOfMass(model, data, q, v)
        c_pos, c_vel, c_acc = ref.com
        com_err = self._com0 + c_pos - com
        com_cmd = c_acc + g.com[0] * com_err + g.com[1] * (c_vel - data.vcom[0])

        R = data.oMi[1].rotation
        base_cmd = g.base[0] * pin.log3(self._R0 @ R.T) - g.base[1] * (R @ v[3:6])
        posture_cmd = g.posture[0] * pin.difference(model, q, robot.q0)[6:] - g.posture[1] * v[6:]

        points, foot_err = {}, 0.0
        height, stride = self.scenario.swing_height, np.r_[self.scenario.stride, 0.0]
        for foot, (s, T) in ref.swing.items():
            fid = robot.foot_frames[foot]
            w = np.pi / T
            bump = height * np.array([np.sin(np.pi * s), w * np.cos(np.pi * s),
                                      -(w**2) * np.sin(np.pi * s)])
            blend = _min_jerk(s)
            up = np.array([0.0, 0.0, 1.0])
            p_ref = self._lift_off[foot] + blend[0] * stride + bump[0] * up
            v_ref = blend[1] / T * stride + bump[1] * up
            a_ref = blend[2] / T**2 * stride + bump[2] * up
            err = p_ref - data.oMf[fid].translation
            vel = v_ref - pin.getFrameVelocity(model, data, fid, _LWA).linear
            points[fid] = a_ref + g.swing[0] * err + g.swing[1] * vel
            foot_err = max(foot_err, float(np.linalg.norm(err)))

        contacts = [fid for f in ref.stance for fid in robot.contact_frames[f]]
        contact_acc = np.concatenate([
            -g.contact[0] * (data.oMf[fid].translation - self._anchors[fid])
            - g.contact[1] * pin.getFrameVelocity(model, data, fid, _LWA).linear
            for fid in contacts
        ] or [np.zeros(0)])
        commands = TaskCommands(com=com_cmd, base_angular=base_cmd, points=points,
                                posture=posture_cmd)
        qp = build_wbc_qp(model, data, q, v, commands, contacts, self.mu,
                          contact_acc=contact_acc)
        return qp, Tracking(float(np.linalg.norm(com_err)), foot_err)
