"""Welding: robot joints the task never drives become ``fixed`` joints in the artifact.

:func:`robot_welds` takes a resolved task and the robot's URDF text and returns joint name ->
value (rad or m): the acting hands' fingers at the task's grip (:func:`gripper`, also recorded in
the manifest), every other undriven moving joint at 0. :func:`weld_joints` rewrites a URDF with
those joints fixed: the joint's origin becomes ``T_J * motion(axis, value)`` and its motion
elements (``<axis>``, ``<limit>``, ``<dynamics>``, ...) are dropped; numbers are written as
:mod:`.merge` writes them (same rules, deterministic bytes)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping

import numpy as np

from ..resolve import ResolvedTask
from ..rotation import axis_rotation
from ..urdf import urdf_info
from .merge import Pose, origin_pose, parse_vector, reindent, write_origin
from .task import fail

_MOTION_TAGS = ("axis", "limit", "dynamics", "calibration", "safety_controller", "mimic")


def weld_joints(urdf_xml: str, values: Mapping[str, float]) -> str:
    """Make each joint named in ``values`` ``fixed`` at that value: rad for ``revolute`` and
    ``continuous`` joints (a rotation about the joint's axis), m for ``prismatic`` ones (a shift
    along it). The child link then sits exactly where it sat with the joint at that value.

    Raises ValueError when the document is not well-formed, a name is not a joint of the
    document, a joint is of another type (fixed, floating, planar) or a number is not finite.
    """
    try:
        root = ET.fromstring(urdf_xml)
    except ET.ParseError as exc:
        raise ValueError(f"not well-formed XML: {exc}") from None
    joints = {joint.get("name"): joint for joint in root.findall("joint")}
    unknown = sorted(set(values) - set(joints))
    if unknown:
        raise ValueError(f"no joint named {', '.join(repr(n) for n in unknown)} in the document")
    for name, value in values.items():
        joint = joints[name]
        kind = joint.get("type")
        if kind not in ("revolute", "continuous", "prismatic"):
            raise ValueError(
                f"joint {name!r} is {kind!r}; only revolute, continuous and prismatic joints can be welded"
            )
        if not math.isfinite(value):
            raise ValueError(f"joint {name!r}: value {value!r} is not a finite number")
        axis_elem = joint.find("axis")
        axis = (
            parse_vector(axis_elem.get("xyz"), f"joint {name!r} <axis xyz>")
            if axis_elem is not None
            else np.array([1.0, 0.0, 0.0])
        )
        norm = float(np.linalg.norm(axis))
        if norm == 0.0:
            raise ValueError(f"joint {name!r} has a zero axis")
        axis = axis / norm
        if kind == "prismatic":
            motion = Pose(np.eye(3), axis * float(value))
        else:
            motion = Pose(axis_rotation(axis, float(value)), np.zeros(3))
        origin = origin_pose(joint, f"joint {name!r}")
        write_origin(joint, origin * motion, index=0)
        joint.set("type", "fixed")
        for tag in _MOTION_TAGS:
            for elem in joint.findall(tag):
                joint.remove(elem)
    reindent(root)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def robot_welds(rt: ResolvedTask, urdf_xml: str) -> dict[str, float]:
    """Every moving robot joint the task does not drive, and the value it keeps all episode:
    fingers at the task's grip (:func:`gripper`), anything else (an idle arm, a head, finger
    tips) at 0; both clamped into the joint's limits, where the limit would hold it. They are
    welded (made fixed joints) in the artifact's URDF: Bullet builds a motor row for every moving
    joint every physics step, and each row costs in proportion to the robot's joint count, so a
    Jaco's six finger joints cost about a seventh of a Scratch Itch step while holding still."""
    driven = set(rt.joint_groups["robot.arm"].joints)
    part = rt.robot.part
    for side in rt.sides:  # joints moved with an arm joint (Stretch's telescoping tubes)
        driven |= set(part.arm_for(side)[1].follow)
    if part.base_drive is not None:  # the mobile base's planar chain
        driven |= set(part.base_drive.joints)
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
            raise fail(
                rt,
                ("tools",),
                f"robot '{rt.robot_name}' gives {len(grip_pos)} finger positions for '{tool_part}' but has {n_fingers} finger joints",
            )
        joints += list(hand.joints) if hand else []
        positions += grip_pos
    return joints, positions
