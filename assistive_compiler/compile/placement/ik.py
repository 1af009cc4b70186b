"""Arm inverse kinematics in the placement client: one :class:`ArmKinematics` per acting arm.

:func:`arm_chains` takes the resolved task, the client and the loaded scene and returns, per
acting side (action order), the arm's kinematics, its start pose (spec part) and the tool's
start orientation (quaternion x, y, z, w). :meth:`ArmKinematics.reach` solves IK for a tool
pose (world frame, m) with collision checks against person and furniture;
:meth:`ArmKinematics.jlwki` scores a configuration (paper §III-D)."""

from __future__ import annotations

import math

import numpy as np

from ...ik_options import ik_damping, ik_limits
from ...resolve import ResolvedTask
from ...rotation import quat_angle, quat_from_rpy_deg
from ..task import start_for
from .client import PlacementClient


class Miss:
    """Why IK found no configuration for a goal: ``kind`` 'out of reach' (the end effector ended
    ``distance_m`` from it), 'orientation' (there, but ``angle_deg`` off) or 'collision' (there,
    but touching ``body``)."""

    def __init__(self, kind: str, distance_m: float = 0.0, angle_deg: float = 0.0, body: str = ""):
        self.kind, self.distance_m, self.angle_deg, self.body = kind, distance_m, angle_deg, body


class ArmKinematics:
    """IK, collision checks and JLWKI for one arm in the compile-time world."""

    def __init__(
        self,
        pc,
        robot,
        ee_link,
        arm_idx,
        lower,
        upper,
        tool_from_ee,
        tool_ids,
        obstacles,
        rest,
        followers: dict[int, int] | None = None,
        frozen: list[int] | None = None,
    ):
        """``followers``: follower joint index -> its leader's position in ``arm_idx`` (set to the
        leader's value); ``frozen``: joint indices IK must not move (a mobile base's drive)."""
        p, c = pc.p, pc.client
        self.pc, self.robot, self.ee_link, self.arm_idx = pc, robot, ee_link, arm_idx
        self.lower, self.upper = lower, upper
        self.tool_inv = tool_from_ee  # inverse grip: tool frame -> end-effector frame
        self.tool_ids, self.obstacles = tool_ids, obstacles
        self.person: int | None = None
        self.rest = rest or [0.0] * len(arm_idx)
        self.movable = [
            j
            for j in range(p.getNumJoints(robot, physicsClientId=c))
            if p.getJointInfo(robot, j, physicsClientId=c)[2] != p.JOINT_FIXED
        ]
        self.lo_all = [p.getJointInfo(robot, j, physicsClientId=c)[8] for j in self.movable]
        self.hi_all = [p.getJointInfo(robot, j, physicsClientId=c)[9] for j in self.movable]
        self.ranges = [max(h - link, 1e-3) for link, h in zip(self.lo_all, self.hi_all)]
        self.cols = [self.movable.index(i) for i in arm_idx]
        self.followers = followers or {}
        self.groups = [
            [self.cols[k]] + [self.movable.index(f) for f, lead in self.followers.items() if lead == k]
            for k in range(len(arm_idx))
        ]
        self.frozen = frozen or []
        self.damping = ik_damping(self.movable, self.frozen)
        self.miss: Miss | None = None

    def place(self, pos, orn) -> None:
        self.pc.place(self.robot, pos, orn)

    def set_arm(self, q) -> None:
        for i, v in zip(self.arm_idx, q):
            self.pc.p.resetJointState(self.robot, i, v, physicsClientId=self.pc.client)
        for f, lead in self.followers.items():
            self.pc.p.resetJointState(self.robot, f, q[lead], physicsClientId=self.pc.client)

    def reach(self, tool_pos, tool_orn, rng, tries: int = 2, tool_may_touch: bool = False):
        """Arm configuration putting the tool at ``tool_pos`` (with ``tool_orn`` unless None) within
        1 cm (and 3°), the arm free of collisions with person and furniture, and the tool too unless
        ``tool_may_touch`` (a goal at the mouth puts the spoon against the face); None if none found."""
        p, c = self.pc.p, self.pc.client
        orn = tool_orn if tool_orn is not None else (0, 0, 0, 1)
        ee_pos, ee_orn = p.multiplyTransforms(tool_pos, orn, *self.tool_inv)
        self.miss = None  # why the last call returned None (see :class:`Miss`)
        for attempt in range(tries):
            arm_rest = list(self.rest) if attempt == 0 else list(rng.uniform(self.lower, self.upper))
            rest = [p.getJointState(self.robot, j, physicsClientId=c)[0] for j in self.movable]
            for col, q in zip(self.cols, arm_rest):
                rest[col] = q
            self.set_arm(arm_rest)
            q = arm_rest
            for _ in range(4):  # refine from the last solution
                kwargs = ik_limits(self, rest) | dict(maxNumIterations=100, residualThreshold=1e-6, physicsClientId=c)
                sol = (
                    p.calculateInverseKinematics(self.robot, self.ee_link, ee_pos, ee_orn, **kwargs)
                    if tool_orn is not None
                    else p.calculateInverseKinematics(self.robot, self.ee_link, ee_pos, **kwargs)
                )
                q = [
                    min(max(float(np.mean([sol[k] for k in group])), link), u)
                    for group, link, u in zip(self.groups, self.lower, self.upper)
                ]
                self.set_arm(q)
            got_pos, got_orn = self.pc.link_pose(self.robot, self.ee_link)
            distance = float(np.linalg.norm(np.subtract(got_pos, ee_pos)))
            if distance >= 0.01:
                self._note(Miss("out of reach", distance_m=distance))
                continue
            angle = quat_angle(got_orn, ee_orn) if tool_orn is not None else 0.0
            if angle >= math.radians(3):
                self._note(Miss("orientation", angle_deg=math.degrees(angle)))
                continue
            touched = self.collision_with(tool_pos, orn, check_tool=not tool_may_touch)
            if touched is not None:
                self._note(Miss("collision", body=touched))
                continue
            return q
        return None

    def _note(self, miss: Miss) -> None:
        """Keep the most telling reason of one ``reach`` call: a collision or a wrong orientation
        (the tool got there) over out of reach, and the closest of the misses by distance."""
        rank = {"collision": 0, "orientation": 1, "out of reach": 2}
        old = self.miss
        if (
            old is None
            or rank[miss.kind] < rank[old.kind]
            or (miss.kind == old.kind == "out of reach" and miss.distance_m < old.distance_m)
        ):
            self.miss = miss

    def drive_to(self, base_pos, base_orn, tool_pos, tool_orn) -> tuple[tuple, tuple]:
        """A mobile base's pose near (``base_pos``, ``base_orn``) from which the arm reaches the tool
        pose: IK with the drive's planar joints free (the robot drives there), their values folded
        into the base pose and reset to 0. The caller then checks the reach with the drive frozen."""
        p, c = self.pc.p, self.pc.client
        self.place(base_pos, base_orn)
        self.set_arm(self.rest)
        ee_pos, ee_orn = p.multiplyTransforms(tool_pos, tool_orn, *self.tool_inv)
        damping = [0.1] * len(self.movable)
        for _ in range(4):
            sol = p.calculateInverseKinematics(
                self.robot,
                self.ee_link,
                ee_pos,
                ee_orn,
                jointDamping=damping,
                maxNumIterations=100,
                residualThreshold=1e-6,
                physicsClientId=c,
            )
            for j, v in zip(self.movable, sol):
                p.resetJointState(self.robot, j, v, physicsClientId=c)
        x, y, yaw = (sol[self.movable.index(j)] for j in self.frozen)
        for j in self.frozen:
            p.resetJointState(self.robot, j, 0.0, physicsClientId=c)
        pos, orn = p.multiplyTransforms(base_pos, base_orn, (x, y, 0.0), p.getQuaternionFromEuler((0.0, 0.0, yaw)))
        self.place(pos, orn)
        return tuple(pos), tuple(orn)

    def collision_with(self, tool_pos, tool_orn, check_tool: bool = True) -> str | None:
        """The body the arm (or, with ``check_tool``, the tool at its pose) touches first, by the
        name its URDF gives it ('robot' → 'person' for the tool), or None when clear."""
        touching = self.pc.touching
        for o in self.obstacles:
            if touching(self.robot, o):
                return self.pc.body_name(o)
        if self.person is not None and touching(self.robot, self.person):
            return "person"
        for tid in self.tool_ids.values() if check_tool else ():
            self.pc.place(tid, tool_pos, tool_orn)
            if self.person is not None and touching(tid, self.person):
                return "person (the tool)"
        return None

    def jlwki(self, q) -> float:
        """Joint-limit-weighted kinematic isotropy at ``q`` (paper §III-D: φ = 0.5, λ = 0.05)."""
        p, c = self.pc.p, self.pc.client
        all_q = [p.getJointState(self.robot, j, physicsClientId=c)[0] for j in self.movable]
        zeros = [0.0] * len(self.movable)
        lin, ang = p.calculateJacobian(self.robot, self.ee_link, [0, 0, 0], all_q, zeros, zeros, physicsClientId=c)
        J = np.vstack([np.asarray(lin)[:, self.cols], np.asarray(ang)[:, self.cols]])
        w = []
        for qi, link, u in zip(q, self.lower, self.upper):
            qr = (u - link) / 2
            w.append(max(0.001, 1 - 0.5 ** ((qr - abs(qr - qi + link)) / (0.05 * qr) + 1)))
        M = J @ np.diag(w) @ J.T
        # Isotropy over the directions the arm can move in: with n = min(6, joints) it is the
        # geometric over the arithmetic mean of M's n largest eigenvalues (det^(1/6) / (trace/6) for
        # six or more joints; a 3-joint arm such as Stretch's has rank 3 and would always score 0).
        n = min(6, J.shape[1])
        eig = np.clip(np.sort(np.linalg.eigvalsh(M))[::-1][:n], 0.0, None)
        return float(np.prod(eig) ** (1 / n) / (eig.sum() / n)) if eig.sum() > 0 else 0.0


def arm_chains(rt: ResolvedTask, pc: PlacementClient, scene) -> list[tuple[ArmKinematics, object, tuple]]:
    """One kinematic chain per acting side (a two-arm robot in a task with arm 'both' has two), each
    with its start pose and the tool (or garment) in its hand: (kinematics, start, tool orientation)."""
    robot_part = rt.robot.part
    arms: list[tuple[ArmKinematics, object, tuple]] = []
    offset_in_action = 0
    own_rest = rt.spec.robot.arm_rest_for(rt.robot_name)  # this task's rest for the acting arm, if it sets one
    for side in rt.sides:
        real_side, arm = robot_part.arm_for(side)
        rest = own_rest if own_rest is not None else arm.rest_rad
        n = len(arm.joints)
        side_start = start_for(rt, side)
        side_orn = quat_from_rpy_deg(side_start.tool_rpy_deg)
        held = [k for k, (name, use) in enumerate(rt.tool_uses.items()) if robot_part.arm_for(use.hand)[0] == real_side]
        held_garments = [
            scene.garment_grips[gname][1:]
            for gname, g in rt.spec.garments.items()
            if robot_part.arm_for(g.held.hand)[0] == real_side
        ]
        if held:
            att = scene.attachments[held[0]]
            inv = pc.p.invertTransform(att.position, att.orientation)
            side_tools = {att.body: scene.tools[att.body]}
        elif held_garments:  # the start pose is the garment's held frame
            inv, side_tools = pc.p.invertTransform(*held_garments[0]), {}
        else:
            inv, side_tools = ((0, 0, 0), (0, 0, 0, 1)), {}
        drive = robot_part.base_drive
        kin = ArmKinematics(
            pc,
            scene.robot,
            pc.link_index(scene.robot, arm.tool_mount),
            [scene.robot_joints[j] for j in arm.joints],
            scene.lower[offset_in_action : offset_in_action + n],
            scene.upper[offset_in_action : offset_in_action + n],
            inv,
            side_tools,
            list(scene.furniture.values()),
            rest,
            followers={scene.robot_joints[f]: arm.joints.index(lead) for f, lead in arm.follow.items()},
            frozen=[scene.robot_joints[j] for j in drive.joints] if drive else None,
        )
        arms.append((kin, side_start, side_orn))
        offset_in_action += n
    return arms
