"""``camera`` and the whole task: :class:`TaskSpec`."""

from __future__ import annotations

from pydantic import Field

from .bodies import Garment, Markers, Particles, Target
from .common import Name, Strict, Vec3
from .person import Person
from .robot import RobotRole, ToolUse
from .scene import Scene
from .scripted import Scripted
from .sim import Sim
from .terms import Observations, Preferences, RewardTerm, Success


class CameraView(Strict):
    """Where renders look from (world frame: the person faces −Y; the robot usually stands at −X)."""

    eye_m: Vec3 | None = Field(
        None, description="Camera position, world frame, m (default: the shipped default view's)."
    )
    target_m: Vec3 | None = Field(None, description="Point the camera looks at, world frame, m.")
    fov_deg: float | None = Field(None, gt=5, lt=150, description="Vertical field of view, degrees.")


class Camera(CameraView):
    """The task's camera for renders, with per-robot overrides (each field merged over the task's)."""

    per_robot: dict[Name, CameraView] = Field(
        default_factory=dict,
        description="Per-robot camera fields (e.g. a robot standing farther away needs a wider view).",
    )


class TaskSpec(Strict):
    """A complete assistive task."""

    name: Name = Field(description="Task name; Gymnasium ids are <TaskName><Robot>-v1.")
    title: str = Field(description="Human-readable title, e.g. 'Feeding'.")
    description: str = Field("", description="What the task is and where its numbers come from.")
    extends: str | None = Field(
        None,
        description="Path of a spec this one builds on (relative to this file, or shipped:tasks/<name>.yaml for a "
        "shipped one). Mappings merge key by key and anything else is replaced; inside a mapping, '$delete: [key, ...]' "
        "removes inherited keys and '$replace: VALUE' (alone) takes VALUE instead of merging.",
    )
    sim: Sim = Field(default_factory=Sim, description="Timing and world physics.")
    scene: Scene = Field(default_factory=Scene, description="Furniture and objects.")
    person: Person = Field(description="The person being helped.")
    robot: RobotRole = Field(description="The robot's role.")
    tools: dict[Name, ToolUse] = Field(default_factory=dict, description="Tools by name.")
    targets: dict[Name, Target] = Field(default_factory=dict, description="Named points on bodies.")
    particles: dict[Name, Particles] = Field(default_factory=dict, description="Particle sets by name.")
    markers: dict[Name, Markers] = Field(
        default_factory=dict, description="Marker sets on the person by name (e.g. spots to wipe)."
    )
    garments: dict[Name, Garment] = Field(
        default_factory=dict,
        max_length=1,
        description="Garments by name (soft bodies held by the robot, e.g. a gown sleeve); at most one.",
    )
    observations: Observations = Field(description="Observation features per agent.")
    reward: list[RewardTerm] = Field(min_length=1, description="Weighted reward terms.")
    preferences: Preferences = Field(default_factory=Preferences, description="Human-preference costs.")
    success: Success = Field(description="What counts as success.")
    scripted: Scripted | None = Field(None, description="A scripted baseline controller (optional).")
    camera: Camera = Field(
        default_factory=Camera,
        description="The camera of renders (render, demo): eye, target, field of view; per robot.",
    )
