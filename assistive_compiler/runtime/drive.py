"""Commands beyond the arm's own joints: joints that follow an arm joint, and a mobile base's drive.

:class:`FollowerControl` — joints moved with an arm joint (Stretch's telescoping tubes l2, l1, l0
with l3): each gets its leader's target change every step (the reference's action duplication),
measured from its own position, and starts at its leader's value.

:class:`BaseDriveControl` — a differential-drive base modelled as a planar chain (prismatic x,
prismatic y, revolute yaw between the placed root frame and the base; see the robot spec's
``base_drive``). The two wheel actions turn the wheels by ``Δθ = frame_skip · action_scale · a``
(rad) per env step; rolling without slip, that moves the base ``r (Δθ_r + Δθ_l) / 2`` forward
along its heading at mid-turn and turns it by ``r (Δθ_r − Δθ_l) / separation`` (m, rad). Those
poses are the three joints' position targets, clamped to their limits; the joints' gains and
force limits (what the wheel motors can push) bound how fast the base follows. The base never
moves sideways.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb

from ..artifact import Drive


class FollowerControl:
    """Targets of the joints that follow arm joints (``followers``: follower -> leader name)."""

    def __init__(self, world, followers: dict[str, str], arm_joints: list[str], delta_scale: np.ndarray):
        robot = world.robot
        self.world = world
        self.idx = [robot.joints[f] for f in followers]
        self.leader_cols = [arm_joints.index(lead) for lead in followers.values()]
        self.scale = np.asarray([delta_scale[k] for k in self.leader_cols])
        infos = [pb.getJointInfo(robot.id, j, physicsClientId=world.client) for j in self.idx]
        self.lower = np.asarray([i[8] for i in infos])
        self.upper = np.asarray([i[9] for i in infos])

    def start(self, arm_q) -> list[float]:
        """Each follower's start value: its leader's."""
        return [float(arm_q[k]) for k in self.leader_cols]

    def targets(self, arm_action: np.ndarray) -> list[float]:
        """Position targets: own position + the leader's change, within the follower's limits."""
        if not self.idx:
            return []
        w = self.world
        q = np.array([s[0] for s in pb.getJointStates(w.robot.id, self.idx, physicsClientId=w.client)])
        return np.minimum(np.maximum(q + self.scale * arm_action[self.leader_cols], self.lower), self.upper).tolist()


class BaseDriveControl:
    """Targets of a differential-drive base's planar joints from the two wheel actions (right, left)."""

    def __init__(self, world, drive: Drive, frame_skip: int):
        robot = world.robot
        self.world, self.d = world, drive
        self.idx = [robot.joints[j] for j in drive.joints]
        self.base_link = robot.links[drive.base_link]
        self.wheel_turn = frame_skip * drive.action_scale  # rad per unit action per env step
        self.gains = [drive.position_gain] * 3
        self.forces = list(drive.max_force)
        infos = [pb.getJointInfo(robot.id, j, physicsClientId=world.client) for j in self.idx]
        self.lower = [i[8] for i in infos]
        self.upper = [i[9] for i in infos]

    def motion(self, wheels: np.ndarray) -> tuple[float, float]:
        """(forward m, turn rad) of one env step for wheel actions (right, left) in [−1, 1]."""
        right, left = (float(v) * self.wheel_turn for v in wheels)
        r = self.d.wheel_radius
        return r * (right + left) / 2.0, r * (right - left) / self.d.wheel_separation

    def wheels_for(self, forward: float, turn: float) -> np.ndarray:
        """Wheel actions (right, left) for one env step moving the base ``forward`` m along its
        heading and turning it ``turn`` rad: the inverse of :meth:`motion`. Where a wheel would
        need more than ±1, both are scaled down by the same factor, so the base follows the same
        arc, only a shorter piece of it."""
        r, half = self.d.wheel_radius, self.d.wheel_separation / 2.0
        wheels = np.array([forward + turn * half, forward - turn * half]) / (r * self.wheel_turn)
        return wheels / max(1.0, float(np.max(np.abs(wheels))))

    def pose(self) -> tuple[float, float, float]:
        """The base's planar pose in the placed root frame: x, y (m), yaw (rad)."""
        w = self.world
        x, y, yaw = (s[0] for s in pb.getJointStates(w.robot.id, self.idx, physicsClientId=w.client))
        return x, y, yaw

    def wheels_towards(self, dx: float, dy: float, dyaw: float) -> np.ndarray:
        """Wheel actions (right, left) heading for a planar change of the base (dx, dy m in the
        root frame, dyaw rad). The base cannot move sideways: the change is projected onto its
        heading (the sideways part is dropped; a goal off to the side is reached by turning,
        which the change's dyaw asks for, or by the arm)."""
        yaw = self.pose()[2]
        forward = dx * math.cos(yaw) + dy * math.sin(yaw)
        return self.wheels_for(forward, dyaw)

    def targets(self, wheels: np.ndarray) -> list[float]:
        """x, y, yaw targets: the measured pose moved as the wheels roll."""
        x, y, yaw = self.pose()
        forward, turn = self.motion(wheels)
        heading = yaw + turn / 2.0
        goal = (x + forward * math.cos(heading), y + forward * math.sin(heading), yaw + turn)
        return [min(max(v, lo), hi) for v, lo, hi in zip(goal, self.lower, self.upper)]
