"""The task's programs: bound terms (observations, reward, preference costs), the success
criterion, and the scripted baseline's waypoints (world frame, m; rad)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from ..references import LinkPoint, ParamValue, TargetPoint
from .model import ArtifactModel, Vec3


class TermUse(ArtifactModel):
    """A bound term: registered kind, normalised parameters, weight."""

    name: str = Field(description="Name in info.")
    term: str = Field(description="Registered term kind.")
    category: Literal["reward", "observation", "preference"] = Field(description="Registry category.")
    weight: float = Field(description="Weight (1 for observations).")
    params: dict[str, ParamValue] = Field(
        description="Parameters: references resolved to reference models (assistive_compiler.references), other values as written."
    )
    size: int = Field(1, description="Number of floats it produces (observations).")


class Success(ArtifactModel):
    """Success: aggregate of a reward term's value ≥ threshold (absolute)."""

    term: str = Field(description="Reward term name.")
    aggregate: Literal["sum", "max", "min", "last"] = Field(description="Aggregation over the episode.")
    threshold: float = Field(description="Absolute threshold (a fraction when fraction_of is set).")
    fraction_of: str | None = Field(
        None, description="A marker set: the threshold is this fraction of the active variant's markers."
    )


class SurfaceShape(ArtifactModel):
    """One collision shape of a followed link, in its link frame: a capsule from ``start`` to
    ``end`` with ``radius`` (a sphere when they are equal)."""

    start: Vec3 = Field(description="One end of the axis (a sphere's centre), link frame, m.")
    end: Vec3 = Field(description="The other end (a sphere's centre again), link frame, m.")
    radius: float = Field(description="Radius, m.")


class FollowedSurface(ArtifactModel):
    """The surface a waypoint's lane follows (``along_surface_of``): a person link's shapes per variant."""

    link: LinkPoint = Field(description="The person link followed.")
    shapes: dict[str, list[SurfaceShape]] = Field(description="Its collision shapes by person variant name.")
    step_m: float = Field(description="Look-ahead along the surface per step, m.")


class ScriptWaypoint(ArtifactModel):
    """One waypoint of the scripted baseline: where the moved point goes next (world frame, m)."""

    to: TargetPoint | LinkPoint = Field(description="The point it heads for.")
    offset_m: Vec3 = Field(description="Offset from that point, m, along the axes of frame (world when none).")
    frame: TargetPoint | LinkPoint | None = Field(
        None,
        description="The point whose link frame offset_m, offset_by_variant and rpy_rad are in (none: world).",
    )
    offset_by_variant: dict[str, Vec3] = Field(
        default_factory=dict, description="Per person-variant offsets replacing offset_m, m (same frame)."
    )
    surface: FollowedSurface | None = Field(None, description="The surface the lane to this waypoint follows.")
    tolerance_m: float = Field(description="Reached within this distance, m (0: never; a last waypoint to hold).")
    normal_offset_m: float = Field(0.0, description="Offset along a surface target's outward normal, m.")
    axis_offset_m: float = Field(0.0, description="Offset along a surface target's limb axis, m.")
    rpy_rad: Vec3 | None = Field(
        description="Orientation of the moved point's link to hold (roll, pitch, yaw, rad; R = Rz·Ry·Rx, in frame), or none."
    )
    face_normal_within_rad: float | None = Field(
        description="Turn the tool towards the surface normal by at most this much, rad, or none."
    )
    step_m: float | None = Field(None, description="Straight-line look-ahead per step, m (none: straight to the goal).")
    face_normal_level: bool = Field(False, description="Turn about the vertical only (keep the tool level).")
    turn_step_rad: float | None = Field(None, description="Most the tool turns per step, rad (none: no limit).")
    # The defaults are the spec's (spec.models.scripted.STALL_STEPS, STALL_PROGRESS_M).
    stall_steps: int = Field(
        10, description="Moved on (stalled) after this many steps without stall_progress_m of progress."
    )
    stall_progress_m: float = Field(0.002, description="Progress that restarts the stall count, m.")


class Script(ArtifactModel):
    """The scripted baseline's script for one arm: the point it moves through its waypoints."""

    move: TargetPoint | LinkPoint = Field(description="The point moved (a tool's tip, the end effector).")
    waypoints: list[ScriptWaypoint] = Field(description="Waypoints in order.")
    repeat_from: int | None = Field(description="After the last waypoint, go on from this one (none: hold the last).")
    ik_damping: dict[str, float] | None = Field(None, description="IK damping of some arm joints, by URDF name.")
    left: Script | None = Field(
        None, description="A two-arm robot's left arm's own script (this one is the right arm's)."
    )
