"""What the compile stages ask of a resolved task: which furniture is in the scene, which person
joints a joint-group reference names, which person links the task refers to, the seat links, the
per-variant sampling seed, the start pose of an acting side, a located error for a spec path —
and :func:`rounded`, which every solver-made number in the manifest goes through.

Takes a :class:`~assistive_compiler.resolve.ResolvedTask` (or its loaded spec); returns plain
names, seeds and spec parts. No physics, no files written."""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import Problem, SpecError
from ..paths import display
from ..references import JointGroup, LinkPoint
from ..resolve import ResolvedTask
from ..resolve.resolved import SurfaceTarget
from ..spec.load import LoadedSpec


def fail(rt: ResolvedTask, path: tuple, message: str) -> SpecError:
    """A :class:`SpecError` located at the spec value at ``path``."""
    return SpecError([Problem(rt.loaded.smap.value(path), message)])


def rounded(values: Any, digits: int = 6) -> Any:
    """Round floats so the manifest's bytes do not depend on the last bits of a solver."""
    if isinstance(values, (list, tuple)):
        return (
            type(values)(rounded(v, digits) for v in values)
            if isinstance(values, list)
            else tuple(rounded(v, digits) for v in values)
        )
    if isinstance(values, (float, np.floating)):
        r = round(float(values), digits)
        return 0.0 if r == 0 else r
    return values


def mounted_on(rt: ResolvedTask) -> str | None:
    """The furniture the robot is mounted on (``robot.mount_on``), if the robot is mountable."""
    return rt.spec.robot.mount_on if rt.robot.part.mountable else None


def present_furniture(rt: ResolvedTask, placed_only: bool = False) -> dict[str, Any]:
    """The scene's furniture for this robot: only_when_mounted pieces only under a mounted robot;
    with ``placed_only`` also without one carried under a searched base (its pose is not known yet)."""
    spec = rt.spec
    mount = mounted_on(rt)
    carried = mount if spec.robot.mount_base == "search" else None
    return {
        name: use
        for name, use in spec.scene.furniture.items()
        if (not use.only_when_mounted or name == mount) and not (placed_only and name == carried)
    }


def group_joints(rt: ResolvedTask, refs) -> list[str]:
    """The person joints of joint-group references (``person.policy`` included), in order, once each."""
    out: list[str] = []
    for ref in refs:
        group = policy_joints(rt) if ref == "person.policy" else rt.joint_groups[ref].joints
        out += [j for j in group if j not in out]
    return out


def policy_joints(rt: ResolvedTask) -> list[str]:
    """The person joints a person policy drives (``person.control.policy_joints``)."""
    return group_joints(rt, rt.spec.person.control.policy_joints)


def impairment_joints(rt: ResolvedTask, choice) -> list[str]:
    """The person joints an impairment choice names (joint-group references resolved)."""
    return group_joints(rt, getattr(choice, "joints", []))


def observed_person_joints(rt: ResolvedTask) -> set[str]:
    """Person joints named by a joint group in any term's parameters (e.g. ``joint_angles`` of
    ``person.head``): they are not baked into fixed joints, so the runtime can read them."""
    out: set[str] = set()
    for term in [t for ts in rt.observations.values() for t in ts] + list(rt.reward):
        for value in term.params.values():
            if isinstance(value, JointGroup) and value.body == "person":
                out |= set(value.joints)
    return out


def referenced_person_links(rt: ResolvedTask) -> set[str]:
    """Person links the task refers to (they must survive the merge as links of their own)."""
    found: set[str] = set()

    def visit(point: object) -> None:
        if isinstance(point, LinkPoint) and point.body == "person":
            found.add(point.link)

    for term in [*rt.reward, *(t for ts in rt.observations.values() for t in ts)]:
        for value in term.params.values():
            for v in value if isinstance(value, list) else [value]:
                visit(v)
    for target in rt.targets.values():
        if isinstance(target, SurfaceTarget):
            found.update(target.surface_links)
        else:
            visit(target)
    script = rt.scripted
    while script is not None:
        for point in [script.move, *(w.to for w in script.waypoints)]:
            visit(point)
        script = script.left
    for ms in rt.markers.values():
        found.update(ms.links)
    return found


def seat_links() -> list[str]:
    """Links that rest on a seat: the pelvis and thighs (waist and hip joint children)."""
    from ..person.skeleton import JOINT_GROUPS, JOINT_NAMES, LINK_NAMES

    child = dict(zip(JOINT_NAMES, LINK_NAMES))
    joints = list(JOINT_GROUPS["waist"]) + [j for j in JOINT_NAMES if "_hip_" in j]
    return [child[j] for j in joints]


def seed(rt: ResolvedTask, variant: str) -> int:
    """A deterministic seed per (task, robot, variant) for compile-time sampling."""
    digest = hashlib.sha256(f"{rt.spec.name}/{rt.robot_name}/{variant}".encode()).digest()
    return int.from_bytes(digest[:4], "little")


def start_for(rt: ResolvedTask, side: str):
    """The start pose of the acting side's tool: the left arm of a two-arm robot acting with both
    arms starts at robot.start_left; the right (or only) arm at per_robot.<robot>.start, else robot.start."""
    role = rt.spec.robot
    if side == "left" and len(rt.sides) > 1:
        if role.start_left is None:
            raise fail(
                rt,
                ("robot", "arm"),
                f"robot '{rt.robot_name}' acts with both arms here; give robot.start_left, the left arm's start pose",
            )
        return role.start_left
    own = role.per_robot.get(rt.robot_name)
    return own.start if own is not None and own.start is not None else role.start


def arm_limits_path(loaded: LoadedSpec) -> Path:
    """The .npz that ``person.control.arm_limits`` names, relative to the spec file that says it."""
    value = loaded.spec.person.control.arm_limits
    where = loaded.smap.value(("person", "control", "arm_limits")).path
    spec_file = next((f for f in loaded.files if display(f) == where), loaded.path)
    return (Path(spec_file).parent / value).resolve()
