"""Loading the emitted bodies into the placement client at their nominal poses.

:func:`load_scene` takes the resolved task, the client, the emitted scene and the artifact's
temporary directory; it loads the furniture (at its spec pose), each person variant (seated on
the furniture's seat, at its settled pose, or at an explicit position; joints at the posture),
the robot (at the origin; its base is placed later), the carried or fixed mount, and the tools
(out of the way) and returns a :class:`PlacedScene`: body ids, the manifest entries of furniture
and tools, the tool attachments and the garments' grips. Positions in m, orientations as
quaternions (x, y, z, w), world frame."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...artifact import Body, ToolAttachment
from ...resolve import ResolvedTask
from ...rotation import quat_from_rpy, quat_from_rpy_deg
from ...spec.parts import tool_grip
from ..emit import EmittedScene
from ..task import mounted_on, present_furniture, rounded, seat_links
from .base_search import Carried
from .client import PlacementClient


@dataclass
class PlacedScene:
    """The compile-time world's bodies and what the manifest records of them so far."""

    furniture: dict[str, int]
    people: dict[str, int]  # variant -> body id
    person_pos: dict[str, tuple]  # variant -> base position (rounded)
    person_orns: dict[str, tuple]  # variant -> base orientation
    robot: int
    robot_urdf: str  # its URDF, relative to the artifact
    robot_joints: dict[str, int]
    arm_joints: list[str]  # robot.arm's joints, in action order
    lower: list[float]  # their limits (rad or m)
    upper: list[float]
    offset: tuple  # per-robot base offset (m)
    mount_pose: tuple | None  # a fixed mount's base pose
    carry: Carried | None  # furniture carried under a searched base
    tools: dict[str, int]
    attachments: list[ToolAttachment]
    bodies: list[Body]  # furniture, tools, people (manifest entries); the robot's comes once it is placed
    garment_grips: dict[str, tuple]  # garment -> (parent link, grip position, grip orientation)


def load_scene(rt: ResolvedTask, pc: PlacementClient, emitted: EmittedScene, out_tmp: Path) -> PlacedScene:
    """Load every emitted body (see the module docstring); the artifact paths are relative to ``out_tmp``."""
    spec = rt.spec
    p, c = pc.p, pc.client
    p.setGravity(0, 0, spec.sim.gravity_mps2, physicsClientId=c)
    p.setTimeStep(spec.sim.time_step_s, physicsClientId=c)
    furniture, bodies = _load_furniture(rt, pc, emitted, out_tmp)
    people, person_pos, person_orns = _load_people(rt, pc, emitted, furniture)
    robot = pc.load(emitted.written["robot"], (0, 0, 0), (0, 0, 0, 1), True)
    robot_joints = pc.joint_index(robot)
    arm_joints = rt.joint_groups["robot.arm"].joints
    infos = {j: p.getJointInfo(robot, robot_joints[j], physicsClientId=c) for j in arm_joints}
    per_robot = spec.robot.per_robot.get(rt.robot_name)
    offset = per_robot.base_offset_m if per_robot and per_robot.base_offset_m else (0.0, 0.0, 0.0)
    mount_pose, carry = _mount(rt, pc, furniture, offset)
    tools, attachments, tool_bodies = _load_tools(rt, pc, emitted, out_tmp)
    person_bodies = [
        Body(
            name=f"person_{v}",
            kind="person",
            urdf=str(emitted.written[f"person_{v}"].relative_to(out_tmp)),
            position=person_pos[v],
            orientation=rounded(person_orns[v]),
            fixed_base=True,
            gravity=spec.person.gravity_mps2,
        )
        for v in spec.person.variants
    ]
    return PlacedScene(
        furniture,
        people,
        person_pos,
        person_orns,
        robot,
        str(emitted.written["robot"].relative_to(out_tmp)),
        robot_joints,
        arm_joints,
        [infos[j][8] for j in arm_joints],
        [infos[j][9] for j in arm_joints],
        offset,
        mount_pose,
        carry,
        tools,
        attachments,
        bodies + tool_bodies + person_bodies,
        _garment_grips(rt),
    )


def _load_furniture(
    rt: ResolvedTask, pc: PlacementClient, emitted: EmittedScene, out_tmp: Path
) -> tuple[dict[str, int], list[Body]]:
    """Furniture at its nominal pose, and its manifest entries."""
    ids: dict[str, int] = {}
    bodies: list[Body] = []
    for name, use in present_furniture(rt).items():
        part = rt.furniture[name].part
        orn = quat_from_rpy_deg(use.rpy_deg)
        static = part.static if use.static is None else use.static
        path = emitted.written[name]
        ids[name] = pc.load(path, use.position_m, orn, True)
        bodies.append(
            Body(
                name=name,
                kind="furniture",
                urdf=str(path.relative_to(out_tmp)),
                position=rounded(use.position_m),
                orientation=rounded(orn),
                fixed_base=static,
                gravity=None,
                friction=use.friction if use.friction is not None else part.friction,
            )
        )
    return ids, bodies


def _load_people(rt: ResolvedTask, pc: PlacementClient, emitted: EmittedScene, furniture: dict[str, int]):
    """Each person variant: seated on the furniture's seat surface, at its settled pose, or at an
    explicit position; its movable joints at the posture. Returns (ids, positions, orientations)."""
    p, c = pc.p, pc.client
    person_spec = rt.spec.person
    placement = person_spec.placement
    settled = emitted.settled
    orns = {v: settled[v][1] if v in settled else quat_from_rpy_deg(placement.rpy_deg) for v in person_spec.variants}
    ids: dict[str, int] = {}
    positions: dict[str, tuple] = {}
    for variant in person_spec.variants:
        probe = pc.load(emitted.written[f"person_{variant}"], (0, 0, 0), orns[variant], True)
        if variant in settled:
            pos = settled[variant][0]
        elif placement.seated_on:
            seat = placement.seated_on
            seat_pos, _ = pc.named_link_pose(furniture[seat], rt.furniture[seat].part.seat_link)
            lowest = min(p.getAABB(probe, pc.link_index(probe, link), physicsClientId=c)[0][2] for link in seat_links())
            pos = (seat_pos[0], seat_pos[1], seat_pos[2] - lowest + 0.002)
            pos = tuple(a + b for a, b in zip(pos, placement.offset_m))
        else:
            pos = tuple(placement.position_m)
        pc.place(probe, pos, orns[variant])
        jidx = pc.joint_index(probe)
        for j in emitted.movable:
            p.resetJointState(probe, jidx[j], emitted.postures[variant][j], physicsClientId=c)
        ids[variant], positions[variant] = probe, rounded(pos)
    return ids, positions, orns


def _mount(
    rt: ResolvedTask, pc: PlacementClient, furniture: dict[str, int], offset
) -> tuple[tuple | None, Carried | None]:
    """A mounted robot's base: the mount link's pose (plus the offset), or — with a searched base —
    the furniture to carry under it. (None, None) for a robot on the floor."""
    mount = mounted_on(rt)
    if not mount:
        return None, None
    mpos, morn = pc.named_link_pose(furniture[mount], rt.furniture[mount].part.mount_link)
    if (
        rt.spec.robot.mount_base == "search"
    ):  # loaded at the origin: the mount link's pose is its pose in the furniture frame
        return None, Carried(pc, furniture[mount], tuple(mpos), tuple(morn))
    return (tuple(a + b for a, b in zip(mpos, offset)), tuple(morn)), None


def _load_tools(rt: ResolvedTask, pc: PlacementClient, emitted: EmittedScene, out_tmp: Path):
    """Each tool, out of the way, with its grip attachment and manifest entry."""
    robot_part = rt.robot.part
    ids: dict[str, int] = {}
    attachments: list[ToolAttachment] = []
    bodies: list[Body] = []
    for name, use in rt.tool_uses.items():
        tpart = rt.tools[name].part
        grip = tool_grip(robot_part, tpart, use.grip)  # checked in resolve: there is one
        assert grip is not None
        friction = use.friction if use.friction is not None else tpart.friction
        _, hand = robot_part.arm_for(use.hand)
        ids[name] = pc.load(emitted.written[name], (0, 0, -10), (0, 0, 0, 1), True)
        if friction is not None:  # as the runtime has it (Body.friction), for the particles settled in it
            pc.set_friction(ids[name], friction)
        attachments.append(
            ToolAttachment(
                body=name,
                parent_link=hand.tool_mount,
                position=rounded(grip.position_m),
                orientation=rounded(quat_from_rpy(grip.rpy_rad)),
                links=dict(tpart.links) | {"base": tpart.base_link},
            )
        )
        bodies.append(
            Body(
                name=name,
                kind="tool",
                urdf=str(emitted.written[name].relative_to(out_tmp)),
                position=(0.0, 0.0, 0.0),
                orientation=(0.0, 0.0, 0.0, 1.0),
                fixed_base=False,
                gravity=use.gravity_mps2,
                friction=friction,
            )
        )
    return ids, attachments, bodies


def _garment_grips(rt: ResolvedTask) -> dict[str, tuple[str, Any, Any]]:
    """Garment -> (the holding hand's tool-mount link, grip position m, grip orientation), rounded."""
    robot_part = rt.robot.part
    grips = {}
    for gname, g in rt.spec.garments.items():
        grip = robot_part.grips[g.held.grip]
        grips[gname] = (
            robot_part.arm_for(g.held.hand)[1].tool_mount,
            rounded(tuple(grip.position_m)),
            rounded(quat_from_rpy(grip.rpy_rad)),
        )
    return grips
