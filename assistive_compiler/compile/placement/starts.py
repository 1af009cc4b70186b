"""The robot's base poses and start configurations, per person variant.

:func:`place_for_variant` takes the task, the client, the loaded scene, the arm chains and a
person variant; with only that variant in the scene it takes the fixed mount's pose or searches
base poses (:mod:`.base_search`), then samples ``start.samples`` start states over them (the
first exactly at the start pose, the rest within ``noise_m``), each by collision-free IK. It
returns the start states (base position m, orientation x, y, z, w, arm joints rad or m, tool
position m; world frame, rounded) and the manifest's placement record. :func:`pose_at_first_start`
leaves the robot (and any carried furniture) at the first variant's first start and returns the
robot's manifest entry."""

from __future__ import annotations

import math

import numpy as np

from ...artifact import BasePose, BaseSearch, Body, Mounted, StartState
from ...resolve import ResolvedTask
from ...rotation import quat_yaw
from ..task import fail, mounted_on, rounded, seed
from .base_search import reach_goals, search_base
from .client import PlacementClient
from .scene import PlacedScene


def place_for_variant(
    rt: ResolvedTask, pc: PlacementClient, scene: PlacedScene, arms: list, variant: str
) -> tuple[list[StartState], Mounted | BaseSearch]:
    """(start states, placement record) for ``variant``; raises when no start is reachable."""
    for other, pid in scene.people.items():  # only this variant in the scene
        pc.place(pid, scene.person_pos[other] if other == variant else (0, 0, -20), scene.person_orns[other])
    rng = np.random.default_rng(seed(rt, variant))
    goals = reach_goals(rt, pc, scene, arms, variant)
    if scene.mount_pose is not None:
        bases = [(scene.mount_pose, len(goals), 0.0)]
        placement: Mounted | BaseSearch = Mounted(mounted_on=mounted_on(rt))
    else:
        bases = search_base(rt, [a[0] for a in arms], goals, scene.offset, rng, scene.carry)
        placement = BaseSearch(
            base_poses=[
                BasePose(
                    position=rounded(b[0][0]),
                    yaw_rad=rounded(quat_yaw(b[0][1])),
                    goals_reached=b[1],
                    goals=len(goals),
                    jlwki=rounded(b[2]),
                )
                for b in bases
            ]
        )
    starts = _sample_starts(scene, arms, bases, rng)
    if not starts:
        start = arms[0][1]
        own = rt.spec.robot.per_robot.get(rt.robot_name)
        where = (
            ("robot", "per_robot", rt.robot_name, "start", "tool_position_m")
            if own is not None and own.start is not None
            else ("robot", "start", "tool_position_m")
        )
        raise fail(
            rt,
            where,
            f"robot '{rt.robot_name}' cannot reach the start pose {tuple(start.tool_position_m)} (tool rpy {tuple(start.tool_rpy_deg)}°) without collision for person '{variant}'",
        )
    return starts, placement


def _sample_starts(scene: PlacedScene, arms: list, bases: list, rng) -> list[StartState]:
    """``start.samples`` start states spread over ``bases``: per base, the exact start pose, then
    start poses perturbed by U(±noise_m); a sample counts only if every arm reaches its pose."""
    arm_kin, start, _ = arms[0]
    starts: list[StartState] = []
    per_base = max(1, math.ceil(start.samples / len(bases)))
    for (base_pos, base_orn), _, _ in bases:
        arm_kin.place(base_pos, base_orn)
        if scene.carry is not None:
            scene.carry.place(base_pos, base_orn)
        for kin, _, _ in arms:
            kin.set_arm(kin.rest)
        for s in range(per_base):
            qs, first_goal = [], None
            for kin, side_start, side_orn in arms:
                noise = np.zeros(3) if s == 0 else rng.uniform(-side_start.noise_m, side_start.noise_m, 3)
                goal = tuple(np.asarray(side_start.tool_position_m) + noise)
                q = kin.reach(goal, side_orn, rng, tries=24)
                if q is None:
                    break
                qs += list(q)
                first_goal = first_goal or goal
            else:
                starts.append(
                    StartState(
                        base_position=rounded(base_pos),
                        base_orientation=rounded(base_orn),
                        joints=rounded(qs),
                        tool_position=rounded(first_goal),
                    )
                )
    return starts


def pose_at_first_start(
    rt: ResolvedTask, pc: PlacementClient, scene: PlacedScene, arms: list, first: StartState
) -> Body:
    """Put the robot at ``first`` (and carried furniture under it, updating its manifest entry:
    ``reset()`` carries it under each start's base); returns the robot's manifest entry."""
    base_pos, base_orn = first.base_position, first.base_orientation
    arms[0][0].place(base_pos, base_orn)
    carry = scene.carry
    if carry is not None:  # the manifest's pose: under the first start's base; reset() carries it under each start's
        pos, orn = carry.place(base_pos, base_orn)
        k = next(i for i, b in enumerate(scene.bodies) if b.name == mounted_on(rt))
        scene.bodies[k] = scene.bodies[k].model_copy(
            update={
                "position": rounded(pos),
                "orientation": rounded(orn),
                "carried_by_robot": (rounded(carry.inv_pos), rounded(carry.inv_orn)),
            }
        )
    at = 0
    for kin, _, _ in arms:  # each arm (and the joints following it) at its part of the first start
        kin.set_arm(first.joints[at : at + len(kin.arm_idx)])
        at += len(kin.arm_idx)
    return Body(
        name="robot",
        kind="robot",
        urdf=str(scene.robot_urdf),
        position=rounded(base_pos),
        orientation=rounded(base_orn),
        fixed_base=True,
        gravity=rt.spec.robot.gravity_mps2,
    )
