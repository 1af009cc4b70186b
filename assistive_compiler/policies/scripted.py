"""The scripted baseline: move a tool point through the task's waypoints by inverse kinematics.

Each step it reads the world (privileged: true target positions), asks pybullet's IK for the arm
configuration that puts the moved point at the current waypoint with the tool's start
orientation (or the waypoint's own), and returns the joint-delta action that heads there (clipped to [−1, 1]). It
advances to the next waypoint within the waypoint's tolerance — or when it has stopped getting
closer (no gain of 2 mm over 10 steps: an approach point the arm cannot quite reach should not
end the episode) — and holds the last one, or goes on from ``repeat_from`` (to rub back and
forth). A waypoint may sit off a surface-drawn target along its outward normal and along its limb,
and may turn the tool towards that target's surface (``face_normal_within_rad``: the smallest
rotation of the start orientation that brings the tool's pointing axis — end effector to moved
point — within that angle of the inward normal, so a spot on the far side of a limb is met tip
first rather than with the tool lying across the limb), and may be approached along a straight line
(``step_m``: IK aims at most that far ahead of the moved point). Works for any task and robot whose
manifest has a ``scripted`` section.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb

from ..quat import quat_conj, quat_mul, quat_rotate


STALL_STEPS = 10  # steps without getting STALL_GAIN_M closer before moving on to the next waypoint
STALL_GAIN_M = 0.002


class ScriptedPolicy:
    """Callable ``obs -> action`` bound to one :class:`~assistive_compiler.runtime.env.AssistiveEnv`."""

    def __init__(self, env):
        m = env.manifest
        if m.scripted is None:
            raise ValueError(f"task '{m.task}' has no scripted: section, so there is no scripted policy for it")
        self.env = env
        snap = env.snap
        self.move = snap.point(m.scripted["move"])
        self.waypoints = [(snap.point(w["to"]), np.asarray(w["offset_m"]), w["tolerance_m"], w.get("normal_offset_m", 0.0),
                           w.get("axis_offset_m", 0.0)) for w in m.scripted["waypoints"]]
        self.orientations = [pb.getQuaternionFromEuler(w["rpy_rad"]) if w.get("rpy_rad") else None for w in m.scripted["waypoints"]]
        self.face_normal = [w.get("face_normal_within_rad") for w in m.scripted["waypoints"]]
        self.repeat_from = m.scripted.get("repeat_from")
        self.steps_m = [w.get("step_m") for w in m.scripted["waypoints"]]
        robot = env.world.robot
        self.ee_link = robot.links[m.robot.links["tool_mount"]]
        self.ee_point = snap.point({"body": "robot", "link": m.robot.links["tool_mount"]})
        c = env.world.client
        movable = [j for j in range(pb.getNumJoints(robot.id, physicsClientId=c)) if pb.getJointInfo(robot.id, j, physicsClientId=c)[2] != pb.JOINT_FIXED]
        self.movable = movable
        self.cols = [movable.index(i) for i in env.arm_idx]
        self.lo = [pb.getJointInfo(robot.id, j, physicsClientId=c)[8] for j in movable]
        self.hi = [pb.getJointInfo(robot.id, j, physicsClientId=c)[9] for j in movable]
        self.ranges = [max(h - l, 1e-3) for l, h in zip(self.lo, self.hi)]

    def _start_episode(self) -> None:
        snap = self.env.snap
        # The moved point rides rigidly on the end effector: remember its pose in the EE frame,
        # and the orientation to keep.
        ee_pos, ee_orn = snap.position(self.ee_point), snap.orientation(self.ee_point)
        pt_pos, pt_orn = snap.position(self.move), snap.orientation(self.move)
        inv = pb.invertTransform(ee_pos.tolist(), ee_orn.tolist())
        self.point_in_ee = pb.multiplyTransforms(inv[0], inv[1], pt_pos.tolist(), pt_orn.tolist())
        self.keep_orn = pt_orn.tolist()
        # The tool's pointing axis (end effector → moved point), in the moved point's link frame.
        d = pt_pos - ee_pos
        d = d / max(float(np.linalg.norm(d)), 1e-9)
        self.axis_in_point = np.asarray(quat_rotate(quat_conj(pt_orn), d))
        self.index = 0
        self._best, self._since_best = float("inf"), 0

    def _facing(self, orn, inward: np.ndarray, within: float) -> list[float]:
        """``orn`` turned by the smallest rotation that brings the pointing axis within ``within``
        (rad) of the unit vector ``inward`` (world); unchanged when it already is."""
        d = quat_rotate(np.asarray(orn), self.axis_in_point)
        angle = math.acos(max(-1.0, min(1.0, float(np.dot(d, inward)))))
        if angle <= within:
            return list(orn)
        k = np.cross(d, inward)
        if np.linalg.norm(k) < 1e-6:  # pointing straight away from the surface: turn through the horizontal z × d
            k = np.cross(d, np.cross(np.array([0.0, 0.0, 1.0]), d))
            if np.linalg.norm(k) < 1e-6:
                k = np.cross(d, np.array([1.0, 0.0, 0.0]))
        k = k / np.linalg.norm(k)
        turn = angle - within
        q = np.concatenate([k * math.sin(turn / 2), [math.cos(turn / 2)]])
        return quat_mul(q, np.asarray(orn)).tolist()

    def _goal(self) -> tuple[np.ndarray, float]:
        """The current waypoint's position (world, m) and tolerance."""
        to, offset, tol, along_normal, along_axis = self.waypoints[self.index]
        snap = self.env.snap
        return snap.position(to) + offset + along_normal * snap.normal(to) + along_axis * snap.axis(to), tol

    def __call__(self, obs) -> np.ndarray:
        env = self.env
        if env.steps == 0:  # first action of an episode
            self._start_episode()
        snap = env.snap
        goal, tol = self._goal()
        error = float(np.linalg.norm(snap.position(self.move) - goal))
        if error < self._best - STALL_GAIN_M:
            self._best, self._since_best = error, 0
        else:
            self._since_best += 1
        last = self.index == len(self.waypoints) - 1
        if (not last or self.repeat_from is not None) and (error <= tol or self._since_best >= STALL_STEPS):
            self.index = self.index + 1 if not last else self.repeat_from
            self._best, self._since_best = float("inf"), 0
            goal, tol = self._goal()
        step = self.steps_m[self.index]
        if step is not None:  # a straight line from where the point is: IK aims at most step_m ahead
            here = snap.position(self.move)
            ahead = goal - here
            distance = float(np.linalg.norm(ahead))
            if distance > step:
                goal = here + ahead * (step / distance)
        # End-effector pose that puts the moved point at the goal with the kept orientation.
        inv_pos, inv_orn = pb.invertTransform(*self.point_in_ee)
        orn = self.orientations[self.index] or self.keep_orn
        if self.face_normal[self.index] is not None:
            orn = self._facing(orn, -snap.normal(self.waypoints[self.index][0]), self.face_normal[self.index])
        ee_pos, ee_orn = pb.multiplyTransforms(goal.tolist(), orn, inv_pos, inv_orn)
        c = env.world.client
        robot = env.world.robot.id
        rest = [pb.getJointState(robot, j, physicsClientId=c)[0] for j in self.movable]
        sol = pb.calculateInverseKinematics(robot, self.ee_link, ee_pos, ee_orn, lowerLimits=self.lo, upperLimits=self.hi,
                                            jointRanges=self.ranges, restPoses=rest, maxNumIterations=50, physicsClientId=c)
        q_goal = np.array([sol[k] for k in self.cols])
        q = np.array([rest[k] for k in self.cols])
        return np.clip((q_goal - q) / env.delta_scale, -1.0, 1.0).astype(np.float32)
