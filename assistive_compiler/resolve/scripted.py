"""The ``scripted`` section: waypoints of the built-in IK baseline policy.

Checks that ``per_robot`` keys name known robots, that every ``move`` and waypoint ``to`` is a
known point, that surface offsets (``normal_offset_m``, ``axis_offset_m``,
``face_normal_within_deg``) are used only with targets drawn on a surface, that
``face_normal_level`` comes with ``face_normal_within_deg`` and that a robot's ``ik_damping``
names its acting arm joints. Produces this robot's script (its own ``per_robot`` one if it has it, else the task's; a two-arm robot's ``left`` part
under ``"left"``), with points resolved and angles in radians.
"""

from __future__ import annotations

import math
from typing import Any

from .robot import check_per_robot_keys
from .scope import Scope


def scripted(s: Scope) -> dict[str, Any] | None:
    spec = s.spec
    if spec.scripted is None:
        return None
    check_per_robot_keys(s, ("scripted", "per_robot"), spec.scripted.per_robot)
    own = spec.scripted.per_robot.get(s.robot_name)
    out = _script(s, own, ("scripted", "per_robot", s.robot_name)) if own is not None else _script(s, spec.scripted, ("scripted",))
    if own is not None and own.ik_damping:
        out["ik_damping"] = _ik_damping(s, own.ik_damping)
    for side in ("left", "right"):  # a two-arm robot: the left arm's part, and the right arm's own (replacing the main one)
        arm = getattr(spec.scripted, side)
        if arm is None or len(s.sides) < 2:
            continue
        resolved = _script(s, arm, ("scripted", side))
        if side == "left":
            out["left"] = resolved
        else:
            out.update(resolved)
    return out


def _ik_damping(s: Scope, damping: dict[str, float]) -> dict[str, float]:
    """A robot's own script's IK damping by arm joint name; a problem for a name that is not one of
    the acting arm joints."""
    arm = s.joint_groups["robot.arm"]["joints"]
    for name in damping:
        if name not in arm:
            s.problem(("scripted", "per_robot", s.robot_name, "ik_damping", name),
                      f"'{name}' is not an acting arm joint of robot '{s.robot_name}' ({', '.join(arm)})")
    return dict(damping)


def _script(s: Scope, script, base: tuple) -> dict[str, Any]:
    """One arm's script (``move``, ``waypoints``, ``repeat_from``) with its references resolved."""
    spec = s.spec
    waypoints = []
    step_m = getattr(script, "step_m", None)  # a robot's own script may set every straight-line waypoint's look-ahead
    for i, w in enumerate(script.waypoints):
        to = s.point(w.to, base + ("waypoints", i, "to"))
        used = {"normal_offset_m": w.normal_offset_m != 0.0, "axis_offset_m": w.axis_offset_m != 0.0,
                "face_normal_within_deg": w.face_normal_within_deg is not None}
        if w.face_normal_level and w.face_normal_within_deg is None:
            s.problem(base + ("waypoints", i, "face_normal_level"), "face_normal_level turns the tool to face the surface only "
                      "with face_normal_within_deg (how far to turn); add it or drop face_normal_level")
        for key in used:
            if used[key] and not (w.to in spec.targets and spec.targets[w.to].surface_of):
                s.problem(base + ("waypoints", i, key), f"{key} needs a target drawn on a surface (surface_of); '{w.to}' is not one")
        waypoints.append({"to": to, "offset_m": list(w.offset_m), "tolerance_m": w.tolerance_m,
                          "normal_offset_m": w.normal_offset_m, "axis_offset_m": w.axis_offset_m,
                          "rpy_rad": [math.radians(a) for a in w.rpy_deg] if w.rpy_deg is not None else None,
                          "face_normal_within_rad": math.radians(w.face_normal_within_deg) if w.face_normal_within_deg is not None else None}
                         | ({"step_m": step_m or w.step_m} if w.step_m is not None else {})  # absent when unset: other artifacts unchanged
                         | ({"face_normal_level": True} if w.face_normal_level else {})
                         | ({"turn_step_rad": math.radians(w.turn_step_deg)} if w.turn_step_deg is not None else {}))
    move, where = (script.move, base + ("move",)) if script.move is not None else (spec.scripted.move, ("scripted", "move"))  # a robot's own script may keep the task's point
    return {"move": s.point(move, where), "waypoints": waypoints, "repeat_from": script.repeat_from}
