"""The ``scripted`` section: waypoints of the built-in IK baseline policy.

Checks that ``per_robot`` keys name known robots, that every ``{segment: NAME}`` names a segment
of ``scripted.segments`` (and none stands inside a segment), that no segment is empty and that each
segment the spec file itself defines is used, that every ``move`` and waypoint ``to`` is a known
point, that surface offsets (``normal_offset_m``, ``axis_offset_m``, ``face_normal_within_deg``) are
used only with targets drawn on a surface (or, but for ``axis_offset_m``, with ``along_surface_of``),
that a waypoint's ``frame`` is a known point, its ``offset_by_variant`` names person variants and
its ``along_surface_of`` a person link with a collision shape (whose shapes per variant it carries), that ``face_normal_level`` comes with
``face_normal_within_deg`` and that a robot's ``ik_damping`` names its acting arm joints. Produces
this robot's script (its own ``per_robot`` one if it has it, else the task's; a two-arm robot's
``left`` part under ``"left"``), segments spliced in, with points resolved and angles in radians; a
problem in a segment's waypoint is reported where the segment writes it.
"""

from __future__ import annotations

import math

from ..artifact import FollowedSurface, Script, ScriptWaypoint, SurfaceShape
from ..errors import SpecError, did_you_mean, one_of
from ..references import LinkPoint
from ..spec.models import SegmentUse, Waypoint
from ..spec.models.scripted import SURFACE_STEP_M
from ..urdf import urdf_info
from .located import expected
from .robot import check_per_robot_keys
from .scope import Scope


def scripted(s: Scope) -> Script | None:
    """This robot's script (None: the task has none, or a problem was found and recorded)."""
    spec = s.spec
    if spec.scripted is None:
        return None
    check_per_robot_keys(s, ("scripted", "per_robot"), spec.scripted.per_robot)
    check_segments(s)
    own = spec.scripted.per_robot.get(s.robot_name)
    main = (
        _script(s, own, ("scripted", "per_robot", s.robot_name))
        if own is not None
        else _script(s, spec.scripted, ("scripted",))
    )
    ik_damping = _ik_damping(s, own.ik_damping) if own is not None and own.ik_damping else None
    left = None
    for side in (
        "left",
        "right",
    ):  # a two-arm robot: the left arm's part, and the right arm's own (replacing the main one)
        arm = getattr(spec.scripted, side)
        if arm is None or len(s.sides) < 2:
            continue
        resolved = _script(s, arm, ("scripted", side))
        if side == "left":
            left = resolved
        else:
            main = resolved
    if main is None:
        return None
    return main.model_copy(update={"ik_damping": ik_damping, "left": left})


def check_segments(s: Scope) -> None:
    """Every segment use names a segment and stands in a script (not in a segment); every segment
    holds a waypoint and, when this spec file defines it, is used by a script (one a spec extends
    may be left unused by the extension's scripts)."""
    section = s.spec.scripted
    names = section.segments
    used: set[str] = set()
    for where, script in section.scripts():
        for i, item in enumerate(script.waypoints):
            if not isinstance(item, SegmentUse):
                continue
            used.add(item.segment)
            if item.segment not in names:
                s.problem(
                    ("scripted",) + where + ("waypoints", i, "segment"),
                    f"unknown segment '{item.segment}'; "
                    f"{expected(names, item.segment, empty='none (declare one under scripted.segments:)')}",
                )
    this_file = s.at().path
    for name, items in names.items():
        path = ("scripted", "segments", name)
        for j, item in enumerate(items):
            if isinstance(item, SegmentUse):
                s.problem(
                    path + (j, "segment"),
                    f"segment '{name}' uses segment '{item.segment}'; a segment holds waypoints "
                    "only: write them here, or splice both segments into the script one after the other",
                )
        if not items:
            s.problem(path, f"segment '{name}' has no waypoints; give it at least one, or delete it")
        elif name not in used and s.at(*path).path == this_file:
            s.problem(
                path,
                f"segment '{name}' is never used; splice it into a script with {{segment: {name}}}, or delete it",
                key=True,
            )


def _ik_damping(s: Scope, damping: dict[str, float]) -> dict[str, float]:
    """A robot's own script's IK damping by arm joint name; a problem for a name that is not one of
    the acting arm joints."""
    arm = s.joint_groups["robot.arm"].joints
    for name in damping:
        if name not in arm:
            s.problem(
                ("scripted", "per_robot", s.robot_name, "ik_damping", name),
                f"'{name}' is not an acting arm joint of robot '{s.robot_name}' ({', '.join(arm)})",
            )
    return dict(damping)


def _script(s: Scope, script, base: tuple) -> Script | None:
    """One arm's script (``move``, ``waypoints``, ``repeat_from``) with segments spliced in and
    its references resolved (each problem located where its waypoint is written); None when a
    point is unknown (the problem is recorded)."""
    spec = s.spec
    waypoints: list[ScriptWaypoint] = []
    complete = True
    step_m = getattr(script, "step_m", None)  # a robot's own script may set every straight-line waypoint's look-ahead
    for w, at in spec.scripted.spliced(script.waypoints, base + ("waypoints",)):
        resolved = _waypoint(s, w, at, step_m)
        if resolved is None:
            complete = False
        else:
            waypoints.append(resolved)
    move, where = (
        (script.move, base + ("move",)) if script.move is not None else (spec.scripted.move, ("scripted", "move"))
    )  # a robot's own script may keep the task's point
    point = s.point(move, where)
    if point is None or not complete:
        return None
    return Script(move=point, waypoints=waypoints, repeat_from=script.repeat_from)


def _waypoint(s: Scope, w: Waypoint, at: tuple, step_m: float | None) -> ScriptWaypoint | None:
    """One waypoint resolved (None when a point it names is unknown; the problem is recorded)."""
    spec = s.spec
    to = s.point(w.to, at + ("to",))
    frame = None if w.frame == "world" else s.point(w.frame, at + ("frame",))
    own_step = (step_m or w.step_m) if w.step_m is not None else None
    surface = _surface(s, w.along_surface_of, at + ("along_surface_of",), own_step)
    for variant in w.offset_by_variant:
        if variant not in spec.person.variants:
            s.problem(
                at + ("offset_by_variant", variant),
                f"'{variant}' is not a person variant of this task; variants are "
                f"{one_of(spec.person.variants)}{did_you_mean(variant, spec.person.variants)}",
                key=True,
            )
    used = {
        "normal_offset_m": w.normal_offset_m != 0.0,
        "axis_offset_m": w.axis_offset_m != 0.0,
        "face_normal_within_deg": w.face_normal_within_deg is not None,
    }
    if w.face_normal_level and w.face_normal_within_deg is None:
        s.problem(
            at + ("face_normal_level",),
            "face_normal_level turns the tool to face the surface only "
            "with face_normal_within_deg (how far to turn); add it or drop face_normal_level",
        )
    drawn = w.to in spec.targets and bool(spec.targets[w.to].surface_of)
    for key in used:
        followed = w.along_surface_of is not None and key != "axis_offset_m"
        if used[key] and not drawn and not followed:
            s.problem(
                at + (key,),
                f"{key} needs a target drawn on a surface (surface_of)"
                + (" or a surface to follow (along_surface_of)" if key != "axis_offset_m" else "")
                + f"; '{w.to}' is not one",
            )
    if to is None or (w.frame != "world" and frame is None) or (w.along_surface_of is not None and surface is None):
        return None
    return ScriptWaypoint(
        to=to,
        offset_m=w.offset_m,
        frame=frame,
        offset_by_variant=dict(w.offset_by_variant),
        surface=surface,
        tolerance_m=w.tolerance_m,
        normal_offset_m=w.normal_offset_m,
        axis_offset_m=w.axis_offset_m,
        rpy_rad=tuple(math.radians(a) for a in w.rpy_deg) if w.rpy_deg is not None else None,
        face_normal_within_rad=math.radians(w.face_normal_within_deg) if w.face_normal_within_deg is not None else None,
        step_m=own_step,
        face_normal_level=w.face_normal_level,
        turn_step_rad=math.radians(w.turn_step_deg) if w.turn_step_deg is not None else None,
        stall_steps=w.stall_steps,
        stall_progress_m=w.stall_progress_m,
    )


def _surface(s: Scope, ref: str | None, at: tuple, step_m: float | None) -> FollowedSurface | None:
    """The person link a lane follows (``along_surface_of``) with each variant's collision shapes;
    None (and a problem for a bad name) when there is none."""
    if ref is None:
        return None
    p = s.link_point(ref, at)
    if p is None:
        return None
    if p.body != "person" or p.link not in s.person_urdf.surface_links:
        pool = ["person." + name for name in s.person_urdf.surface_links]
        s.problem(at, f"'{ref}' is not a person link with a collision shape to follow; {expected(pool, ref, limit=21)}")
        return None
    link = p.link
    shapes: dict[str, list[SurfaceShape]] = {}
    for variant in s.spec.person.variants:
        try:
            info = urdf_info(s.lib.person_urdf(variant))
        except (KeyError, SpecError):  # an unknown or broken variant: the person section reports it
            return None
        own = [SurfaceShape(start=sp.centre, end=sp.centre, radius=sp.radius) for sp in info.spheres.get(link, ())]
        cap = info.capsules.get(link)
        if cap is not None:
            own.append(SurfaceShape(start=cap.start, end=cap.end, radius=cap.radius))
        shapes[variant] = own
    return FollowedSurface(
        link=LinkPoint(body="person", link=link), shapes=shapes, step_m=step_m if step_m is not None else SURFACE_STEP_M
    )
