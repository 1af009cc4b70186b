"""The robot's base-pose search (paper §III: sampling + IK + joint-limit-weighted kinematic
isotropy), and furniture carried under a searched base.

:func:`reach_goals` takes the task, the client, the loaded scene, the arm chains and a person
variant and returns the goals a base pose is scored on: the arms' start poses, then the task's
``base_goals`` (world positions m, orientations x, y, z, w or None). :func:`search_base` returns
the ``keep`` best sampled base poses ((position, orientation), goals reached, Σ JLWKI)."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from ...references import Point, TargetPoint
from ...resolve import ResolvedTask
from ...resolve.resolved import SurfaceTarget
from ...rotation import quat_from_rpy
from ..task import fail


class Carried:
    """Furniture carried under a robot whose base is searched (robot.mount_base: search): its
    mount link (pose ``mount_pos``/``mount_orn`` in the furniture frame, m) lies on the base frame."""

    def __init__(self, pc, body: int, mount_pos, mount_orn):
        self.pc, self.body, self.height = pc, body, float(mount_pos[2])
        self.inv_pos, self.inv_orn = pc.p.invertTransform(mount_pos, mount_orn)  # furniture frame in the base frame

    def place(self, base_pos, base_orn) -> tuple[tuple, tuple]:
        """Put the furniture under a base pose (world); returns its frame's world pose."""
        pos, orn = self.pc.p.multiplyTransforms(base_pos, base_orn, self.inv_pos, self.inv_orn)
        self.pc.place(self.body, pos, orn)
        return tuple(pos), tuple(orn)


def reach_goals(rt: ResolvedTask, pc, scene, arms: list, variant: str) -> list[tuple]:
    """(position, orientation or None, required, description, the arm's kinematics, is a start pose)
    for each arm's start pose and each of the task's base goals, with ``variant`` in the scene."""
    goals = []
    for side, (kin, side_start, side_orn) in zip(rt.sides, arms):
        kin.person = scene.people[variant]
        what = "the start pose" if len(arms) == 1 else f"the {side} arm's start pose"
        goals.append((tuple(side_start.tool_position_m), side_orn, True, what, kin, True))
    for g in rt.base_goals:
        where = np.asarray(_point_world(pc, rt, g.point, scene, variant)) + g.offset_m
        k = rt.sides.index(g.arm) if g.arm in rt.sides else 0
        kin, _, side_orn = arms[k]
        goals.append((tuple(where), side_orn if g.oriented else None, g.required, _describe_point(g.point), kin, False))
    return goals


def _describe_point(ref: Point) -> str:
    return f"target '{ref.target}'" if isinstance(ref, TargetPoint) else f"{ref.body}.{ref.link}"


def _point_world(pc, rt: ResolvedTask, ref: Point, scene, variant: str) -> tuple[float, float, float]:
    """World position of a point reference in the compile-time scene."""
    if isinstance(ref, TargetPoint):
        target = rt.spec.targets[ref.target]
        resolved = rt.targets[ref.target]
        base = resolved.point if isinstance(resolved, SurfaceTarget) else resolved
        offset = target.offset_by_variant.get(variant, target.offset_m)
    else:
        base, offset = ref, (0.0, 0.0, 0.0)
    body = {"person": scene.people[variant]} | scene.furniture | scene.tools
    pos, orn = pc.named_link_pose(body[base.body], base.link)
    return tuple(pc.p.multiplyTransforms(pos, orn, tuple(offset), (0, 0, 0, 1))[0])


def search_base(rt: ResolvedTask, arms: list, goals, offset, rng, carry: Carried | None = None):
    """The paper's base-pose search, bounded: exactly ``attempts`` samples; the ``keep`` best by
    (goals reached, Σ JLWKI), each reaching every required goal. ``goals`` are (position,
    orientation or None, required, description, the arm's kinematics, is a start pose); each arm
    starts from its rest pose. Raises with the goal that no sampled pose reached. With ``carry``
    the base sits at the carried furniture's mount height and the furniture moves under every
    sampled base; a pose where it touches the person or other furniture is rejected."""
    search = rt.spec.robot.search_for(rt.robot_name)
    anchor = np.asarray(search.origin_m[:2]) + np.asarray(offset[:2])
    z = (carry.height if carry is not None else rt.robot.part.base_height_m) + (offset[2] if len(offset) > 2 else 0.0)
    found = []
    required_misses = np.zeros(len(goals), dtype=int)
    blocked: Counter = Counter()  # samples whose base (arm at rest) touched a body, by body
    misses: list[list] = [[] for _ in goals]  # per goal: why IK missed it, per sample
    for _ in range(search.attempts):
        xy = anchor + [rng.uniform(*search.x_range_m), rng.uniform(*search.y_range_m)]
        yaw = math.radians(
            search.yaw_deg + rt.robot.part.facing_yaw_deg + rng.uniform(-search.yaw_noise_deg, search.yaw_noise_deg)
        )
        pos, orn = (float(xy[0]), float(xy[1]), float(z)), quat_from_rpy((0.0, 0.0, yaw))
        touched = _base_blocked_by(arms, pos, orn, carry)
        if touched is not None:
            blocked[touched] += 1
            continue
        first = goals[0][4]
        if first.frozen:  # a mobile base drives from the sample to where its arm reaches the start pose
            pos, orn = first.drive_to(pos, orn, goals[0][0], goals[0][1])
        reached, score, ok = 0, 0.0, True
        for k, (gpos, gorn, required, _name, kin, is_start) in enumerate(goals):
            q = kin.reach(gpos, gorn, rng, tries=2, tool_may_touch=not is_start)
            if q is None:
                if required:
                    required_misses[k] += 1
                    misses[k].append(kin.miss)
                    ok = False
                    break
                continue
            reached += 1
            score += kin.jlwki(q)
        if ok:
            found.append(((pos, orn), reached, score))
    if not found:
        worst = int(np.argmax(required_misses))
        own = rt.spec.robot.per_robot.get(rt.robot_name)
        in_force = (
            ("robot", "per_robot", rt.robot_name, "base_search")
            if own is not None and own.base_search is not None
            else ("robot", "base_search")
        )
        # The task's own goals follow the start poses, in the order of base_search.goals.
        starts = sum(1 for g in goals if g[5])

        def path(k: int) -> str:  # where the spec writes one of its own goals
            return f"{'.'.join(in_force)}.goals[{k - starts}]"

        def marked(k: int) -> str:  # a goal the spec marks required
            return f"{goals[k][3]} (required: true at {path(k)})"

        others = [  # the samples that reached the worst goal but missed another (each is required)
            (int(required_misses[k]), goals[k][3] if goals[k][5] else marked(k))
            for k in range(len(goals))
            if k != worst and required_misses[k]
        ]
        culprits = [path(k) for k in range(len(goals)) if not goals[k][5] and required_misses[k]]
        drop = (
            f", or drop required: true from {' and '.join(culprits)} (a base pose that misses a required goal is "
            "discarded; a goal not required only ranks the poses)"
            if culprits
            else ""
        )
        what = marked(worst) if not goals[worst][5] else goals[worst][3]
        raise fail(
            rt,
            in_force,
            f"robot '{rt.robot_name}' reaches {what} from none of {search.attempts} sampled base poses: "
            f"{_why(blocked, misses[worst], search.attempts, others)}; set robot.per_robot.{rt.robot_name}.base_offset_m "
            f"or widen {'.'.join(in_force)} (x_range_m, y_range_m, yaw_noise_deg){drop}",
        )
    found.sort(key=lambda f: (-f[1], -f[2]))
    return found[: search.keep]


def _why(blocked: Counter, misses: list, attempts: int, others: list[tuple[int, str]] = ()) -> str:
    """What stopped the samples: bases against a body, then the goal's IK misses by reason (out of
    reach with the closest approach, a wrong orientation, or reached in collision), then ``others``
    (how many samples reached it but missed another required goal, and that goal in words)."""
    parts = []
    if blocked:
        parts.append(f"{sum(blocked.values())} put the robot (arm at rest) against {_names(blocked)}")
    kinds = Counter(m.kind for m in misses if m is not None)
    if kinds["out of reach"]:
        closest = min(m.distance_m for m in misses if m is not None and m.kind == "out of reach")
        parts.append(
            f"{kinds['out of reach']} left it out of reach (the closest the end effector came was {closest:.2f} m away)"
        )
    if kinds["orientation"]:
        best = min(m.angle_deg for m in misses if m is not None and m.kind == "orientation")
        parts.append(
            f"{kinds['orientation']} reached it only at the wrong orientation (at best {best:.0f}° off, 3° allowed)"
        )
    if kinds["collision"]:
        parts.append(
            f"{kinds['collision']} reached it only in collision with {_names(Counter(m.body for m in misses if m is not None and m.kind == 'collision'))}"
        )
    parts.extend(f"{n} missed {goal}" for n, goal in others)
    rest = attempts - sum(blocked.values()) - len(misses) - sum(n for n, _ in others)
    if rest > 0:
        parts.append(f"{rest} missed another goal")
    return "; ".join(parts) or "no sample was tried"


def _names(counts: Counter) -> str:
    return ", ".join(f"{name} ({n})" for name, n in counts.most_common())


def _base_blocked_by(arms: list, pos, orn, carry: Carried | None) -> str | None:
    """Place the base (and any carried furniture) at (pos, orn), the arms at rest; the body that
    the robot or the carried furniture touches there (its URDF name), or None when they clear the
    person and the other furniture."""
    arm = arms[0]
    pc = arm.pc
    arm.place(pos, orn)
    for a in arms:
        a.set_arm(a.rest)
    if carry is not None:
        carry.place(pos, orn)
        for o in arm.obstacles:
            if o != carry.body and pc.touching(carry.body, o):
                return pc.body_name(o)
        if pc.touching(carry.body, arm.person):
            return "person"
    # The base must clear the scene at the arm's rest pose; its own carried mount is checked per IK solution
    # only (a folded arm may rest against the mount's top, which says nothing about the base pose).
    for o in arm.obstacles:
        if (carry is None or o != carry.body) and pc.touching(arm.robot, o):
            return pc.body_name(o)
    return "person" if pc.touching(arm.robot, arm.person) else None
