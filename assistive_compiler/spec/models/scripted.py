"""``scripted``: waypoints of the built-in IK baseline, per arm and per robot.

A waypoint list holds waypoints and ``{segment: NAME}`` items; the latter stand for the waypoints
of ``scripted.segments.NAME``, spliced in at resolve time (:mod:`assistive_compiler.resolve.scripted`),
so scripts that share lanes write them once. ``repeat_from`` counts the spliced waypoints.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Annotated, Any

from pydantic import Discriminator, Field, Tag, model_validator

from .common import Name, Ref, Strict, Vec3

#: The scripted controller's stall rule by default: a waypoint it has not got ``STALL_PROGRESS_M``
#: closer to in ``STALL_STEPS`` steps is given up (the next one starts).
STALL_STEPS = 10
STALL_PROGRESS_M = 0.002
#: The look-ahead along a followed surface (``along_surface_of``) when a waypoint gives no ``step_m``, metres.
SURFACE_STEP_M = 0.03


class Waypoint(Strict):
    """A goal for the scripted controller: a point near a target, reached within a tolerance."""

    to: Ref = Field(description="Target or link the goal is relative to, e.g. mouth.")
    frame: Ref = Field(
        "world",
        description="The frame offset_m, offset_by_variant and rpy_deg are given in: world (the default: x, y, z "
        "of the world), or a point, i.e. a target (e.g. mouth), a person landmark (e.g. person.top_of_head) or a link "
        "(e.g. person.head): that point's link frame, turning with the link, so a lane written in the head's frame "
        "follows the head as it turns (a target's or landmark's frame is the frame of the link it is on; "
        "docs/person.md: +x the person's left, -y their front, +z up at the zero pose). The offset still starts at "
        "'to'; only its axes are the frame's.",
    )
    offset_m: Vec3 = Field(
        (0.0, 0.0, 0.0),
        description="Goal offset from 'to', metres, along the axes of 'frame' (world unless frame names a point).",
    )
    offset_by_variant: dict[Name, Vec3] = Field(
        default_factory=dict,
        description="Per person-variant offsets replacing offset_m for that variant (same frame as offset_m), "
        "e.g. {female_50th: [0, 0, 0.088]} for a smaller head; a variant not listed uses offset_m.",
    )
    along_surface_of: Ref | None = Field(
        None,
        description="A person link with a collision shape (e.g. person.head) to follow: the goal is the point of "
        "that link's surface nearest to 'to' plus the offset, moved normal_offset_m along the surface's outward "
        "normal there (each person variant's own shapes), and on the way to it every look-ahead of step_m "
        f"(default {SURFACE_STEP_M:g} m here) is put on the surface the same way, so the moved point slides along the surface "
        "between the previous waypoint and this one (over a sphere, along a great circle) instead of cutting "
        "through it. face_normal_within_deg then turns the tool towards the surface's inward normal at each "
        "look-ahead. None: a straight line (or one IK jump).",
    )
    tolerance_m: float = Field(
        0.02,
        ge=0,
        le=1,
        description="Distance at which the waypoint counts as reached and the next one starts, metres (0: never "
        "reached). The controller also moves on when it stalls: when the moved point has not got more than "
        f"stall_progress_m (default {STALL_PROGRESS_M * 1000:g} mm) closer to the goal in stall_steps (default "
        f"{STALL_STEPS}) steps, e.g. a goal out of the arm's reach or behind a contact. The last waypoint is held "
        "(unless repeat_from is given) however it stalls. run --trace prints each reached or stalled waypoint.",
    )
    stall_steps: int = Field(
        STALL_STEPS,
        ge=1,
        le=100000,
        description="Steps without progress (see stall_progress_m) after which the controller gives this waypoint "
        "up and moves on to the next, e.g. more for a slow approach that must not be cut short.",
    )
    stall_progress_m: float = Field(
        STALL_PROGRESS_M,
        ge=0,
        le=1,
        description="Progress, metres: getting closer to the goal than the closest distance so far by more than this "
        "restarts the stall_steps count.",
    )
    normal_offset_m: float = Field(
        0.0,
        ge=-0.5,
        le=0.5,
        description="Offset along the outward surface normal, metres: of the target (targets drawn on a surface), "
        "or of the surface followed (along_surface_of); negative presses into it.",
    )
    axis_offset_m: float = Field(
        0.0,
        ge=-0.5,
        le=0.5,
        description="Offset along the limb's axis, away from its joint (targets drawn on a surface), metres.",
    )
    rpy_deg: Vec3 | None = Field(
        None,
        description="Orientation of the moved point's link at this waypoint, degrees: roll, pitch, yaw about fixed "
        "axes x, then y, then z, i.e. R = Rz(yaw)·Ry(pitch)·Rx(roll) (pybullet's Euler convention), relative to "
        "'frame' (world by default; in a link's frame the orientation turns with the link: R_world = R_frame·R), "
        "e.g. to tilt a cup; None keeps the tool's start orientation.",
    )
    face_normal_within_deg: float | None = Field(
        None,
        ge=0,
        le=180,
        description="Turn the tool, by the smallest rotation from its start orientation, until its "
        "pointing axis (from the end effector to the moved point) lies within this angle of the inward surface "
        "normal (of a target drawn on a surface, or of the surface followed: along_surface_of), so the tool meets the surface tip first instead of lying across the limb; "
        "degrees. None keeps the start orientation (or rpy_deg's).",
    )
    face_normal_level: bool = Field(
        False,
        description="With face_normal_within_deg: turn the tool about the vertical only, towards the inward normal's "
        "horizontal part, so it stays level (a wrist that only yaws, e.g. Stretch's); a spot facing more up or down than "
        "sideways (its normal over 45 degrees from the horizontal) is left unturned, since no yaw meets it tip first.",
    )
    step_m: float | None = Field(
        None,
        gt=0,
        le=0.5,
        description="Largest distance, metres, between the moved point and the goal handed to IK while heading "
        "for this waypoint: the point then follows the straight line from where it is (e.g. wiping along a limb) instead of the "
        "joint-space path one IK jump takes. None: IK aims at the waypoint itself.",
    )
    turn_step_deg: float | None = Field(
        None,
        gt=0,
        le=180,
        description="Pour speed: the orientation handed to IK while heading for this waypoint turns "
        "at most this many degrees per step, from the moved point's orientation when the waypoint begins towards rpy_deg's "
        "(or the kept one), so the tool turns at about that rate (e.g. a cup tipped slowly enough to reach the lips before "
        "its water runs out) instead of as fast as the joints follow one IK jump. None: IK aims at the waypoint's orientation itself.",
    )


class SegmentUse(Strict):
    """``{segment: NAME}`` in a waypoint list: the waypoints of ``scripted.segments.NAME``, in order, in its place."""

    segment: Name = Field(
        description="The name of a segment under scripted.segments, e.g. side_lanes; its waypoints "
        "go here, in order, as if written here."
    )


def _item_kind(value: Any) -> str:
    """Which model a waypoint-list item is: ``{segment: ...}`` is a segment use, anything else a waypoint."""
    if isinstance(value, dict):
        return "SegmentUse" if "segment" in value else "Waypoint"
    return "SegmentUse" if isinstance(value, SegmentUse) else "Waypoint"


WaypointItem = Annotated[
    Annotated[Waypoint, Tag("Waypoint")] | Annotated[SegmentUse, Tag("SegmentUse")], Discriminator(_item_kind)
]
"""An item of a waypoint list: a waypoint, or ``{segment: NAME}`` splicing a named segment in."""


class ScriptedArm(Strict):
    """The left arm's part of a scripted baseline when the robot acts with both arms."""

    move: Ref = Field(description="The point the left arm moves, e.g. scooper_left.blade.")
    waypoints: list[WaypointItem] = Field(
        min_length=1,
        description="Goals in order, each a waypoint or {segment: NAME} (that "
        "segment's waypoints); the last is held unless repeat_from is given.",
    )
    repeat_from: int | None = Field(
        None, ge=0, description="After the last waypoint, go on from this index; None holds the last."
    )


class ScriptedRobot(Strict):
    """One robot's own script: its waypoints replace the task's for that robot (robots differ in
    reach and in the wrist orientations they can hold, so one set of waypoints rarely suits all)."""

    move: Ref | None = Field(None, description="The point moved; None: the task's scripted.move.")
    waypoints: list[WaypointItem] = Field(
        min_length=1,
        description="Goals in order, each a waypoint or {segment: NAME} (that "
        "segment's waypoints), replacing scripted.waypoints for this robot; the last is held "
        "unless repeat_from is given.",
    )
    repeat_from: int | None = Field(
        None,
        ge=0,
        description="After the last waypoint, go on from this index (replacing scripted.repeat_from); None holds the last.",
    )
    step_m: float | None = Field(
        None,
        gt=0,
        le=0.5,
        description="Replaces the step_m of each of these waypoints that has one (those spliced in from "
        "segments too): how far ahead of the moved point IK aims along a straight line, metres (robots differ in how far their "
        "tool lags behind that goal, so two robots can share waypoints and differ in this). None: each waypoint's own.",
    )
    ik_damping: dict[Name, Annotated[float, Field(gt=0)]] = Field(
        default_factory=dict,
        description="pybullet IK damping of some of this robot's arm joints by joint name (the others "
        "keep pybullet's 0.1; the IK is then damped least squares): a joint damped more moves less in each IK step, so the "
        "script leans on the other joints, e.g. an arm whose shoulder turns much more slowly than its elbow and wrist. Empty: "
        "pybullet's null-space IK towards the current pose.",
    )


class Scripted(Strict):
    """A privileged baseline controller (IK each step) that moves a point of the tool through
    waypoints, keeping the tool's start orientation. It shows the task is solvable and checks the
    reward wiring; it is not a learned policy."""

    move: Ref = Field(description="The point moved, e.g. spoon (its reference link) or spoon.tip.")
    segments: dict[Name, list[WaypointItem]] = Field(
        default_factory=dict,
        description="Named runs of waypoints (e.g. one lane along a limb), written once and spliced into "
        "any waypoint list of this section (waypoints, left, right, per_robot.<robot>) by the item {segment: NAME}, so scripts "
        "that share lanes do not copy them. A segment holds at least one waypoint and no {segment: ...} of its own, and each "
        "segment a spec file defines is used.",
    )
    waypoints: list[WaypointItem] = Field(
        min_length=1,
        description="Goals in order, each a waypoint or {segment: NAME} (that "
        "segment's waypoints); the last is held unless repeat_from is given.",
    )
    repeat_from: int | None = Field(
        None,
        ge=0,
        description="After the last waypoint, go on from this index (e.g. to rub back and forth); None holds the last.",
    )
    step_m: float | None = Field(
        None,
        gt=0,
        le=0.5,
        description="Replaces the step_m of each of these waypoints that has one (those spliced in from "
        "segments too): how far ahead of the moved point IK aims along a straight line, metres. A robot's own script "
        "(per_robot.<robot>) uses its own step_m instead. None: each waypoint's own.",
    )
    left: ScriptedArm | None = Field(
        None,
        description="The left arm's waypoints when the robot acts with both arms (robot.arm: both, a two-arm robot); "
        "move/waypoints then drive the right arm. Ignored on one-arm robots.",
    )
    right: ScriptedArm | None = Field(
        None,
        description="The right arm's part when the robot acts with both arms (robot.arm: both, a two-arm robot): it "
        "replaces move/waypoints/repeat_from there, so that a two-arm script (e.g. lift with both hands) can differ from the "
        "one-arm script that move/waypoints give. Ignored on one-arm robots.",
    )
    per_robot: dict[Name, ScriptedRobot] = Field(
        default_factory=dict,
        description="Scripts by robot name: the named robot follows its own move/waypoints/repeat_from "
        "instead of the ones above (left/right still apply to two-arm robots acting with both arms).",
    )

    def scripts(self) -> Iterator[tuple[tuple[str, ...], Scripted | ScriptedArm | ScriptedRobot]]:
        """Every waypoint script of this section with its path below ``scripted`` (``()`` for this one)."""
        yield (), self
        for side in ("left", "right"):
            if getattr(self, side) is not None:
                yield (side,), getattr(self, side)
        for name, own in self.per_robot.items():
            yield ("per_robot", name), own

    def spliced(self, items: list[Waypoint | SegmentUse], path: tuple) -> list[tuple[Waypoint, tuple]]:
        """``items`` (a waypoint list at data path ``path`` of the spec) with each ``{segment: NAME}``
        replaced by that segment's waypoints, each waypoint paired with the data path it is written
        at (for located problems). An unknown name, and a segment use inside a segment, splice
        nothing (resolve reports them)."""
        out: list[tuple[Waypoint, tuple]] = []
        for i, item in enumerate(items):
            if isinstance(item, Waypoint):
                out.append((item, path + (i,)))
            elif item.segment in self.segments:
                where = ("scripted", "segments", item.segment)
                out.extend(
                    (w, where + (j,)) for j, w in enumerate(self.segments[item.segment]) if isinstance(w, Waypoint)
                )
        return out

    @model_validator(mode="after")
    def _repeat_in_range(self) -> Scripted:
        """Each script's repeat_from is an index of its waypoints, segments spliced in."""

        def plain(
            name: str,
        ) -> bool:  # a segment to count: known, not empty, no segment use in it (resolve reports the others)
            return bool(self.segments.get(name)) and all(isinstance(w, Waypoint) for w in self.segments[name])

        for where, script in self.scripts():
            if not all(plain(i.segment) for i in script.waypoints if isinstance(i, SegmentUse)):
                continue
            count = len(self.spliced(script.waypoints, ()))
            if script.repeat_from is not None and script.repeat_from >= count:
                field = ".".join(where + ("repeat_from",))
                raise ValueError(f"@{field}: repeat_from {script.repeat_from} is not a waypoint index (0..{count - 1})")
        return self
