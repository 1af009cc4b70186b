"""Which robot joints the artifact welds, and where: the acting hands' fingers at the task's grip,
every other joint the task does not drive at 0.

:func:`robot_welds` takes a resolved task and the robot's URDF text and returns joint name ->
value (rad or m) for :func:`~assistive_compiler.compile.merge.weld_joints`; :func:`gripper`
returns the acting hands' finger joints and their grip values (also recorded in the manifest)."""

from __future__ import annotations

from ..resolve import ResolvedTask
from .render import urdf_info
from .task import fail


def robot_welds(rt: ResolvedTask, urdf_xml: str) -> dict[str, float]:
    """Every moving robot joint the task does not drive, and the value it keeps all episode:
    fingers at the task's grip (:func:`gripper`), anything else (an idle arm, a head, finger
    tips) at 0; both clamped into the joint's limits, where the limit would hold it. They are
    welded (made fixed joints) in the artifact's URDF: Bullet builds a motor row for every moving
    joint every physics step, and each row costs in proportion to the robot's joint count, so a
    Jaco's six finger joints cost about a seventh of a Scratch Itch step while holding still."""
    driven = set(rt.joint_groups["robot.arm"]["joints"])
    finger_joints, grip = gripper(rt)
    held = dict(zip(finger_joints, grip))
    welds: dict[str, float] = {}
    for name, joint in urdf_info(urdf_xml).joints.items():
        if joint.type in ("revolute", "continuous", "prismatic") and name not in driven:
            value = held.get(name, 0.0)
            if joint.lower is not None and joint.upper is not None and joint.lower <= joint.upper:
                value = min(max(value, joint.lower), joint.upper)
            welds[name] = value
    return welds


def gripper(rt: ResolvedTask) -> tuple[list[str], list[float]]:
    """The acting hands' finger joints and their positions for the tool each holds (or 'none')."""
    robot_part = rt.robot.part
    joints: list[str] = []
    positions: list[float] = []
    for side in rt.sides:
        real_side = robot_part.arm_for(side)[0]
        hand = robot_part.gripper.get(real_side)
        held = [use.part for use in rt.tool_uses.values() if robot_part.arm_for(use.hand)[0] == real_side]
        if not held and len(rt.sides) == 1 and rt.tool_uses:
            held = [next(iter(rt.tool_uses.values())).part]
        tool_part = held[0] if held else "none"
        garments = [g.held.grip for g in rt.spec.garments.values() if robot_part.arm_for(g.held.hand)[0] == real_side]
        if garments:  # the hand holds a garment: its grip's finger positions, else the empty hand's
            tool_part = garments[0]
        grip_pos = hand.positions.get(tool_part, hand.positions.get("none", 0.0)) if hand else 0.0
        n_fingers = len(hand.joints) if hand else 0
        grip_pos = [float(v) for v in grip_pos] if isinstance(grip_pos, list) else [float(grip_pos)] * n_fingers
        if len(grip_pos) != n_fingers:
            raise fail(rt, ("tools",), f"robot '{rt.robot_name}' gives {len(grip_pos)} finger positions for '{tool_part}' but has {n_fingers} finger joints")
        joints += list(hand.joints) if hand else []
        positions += grip_pos
    return joints, positions
