"""The task spec language: pydantic models, strict, one ``description=`` per field.

A task spec (``specs/tasks/*.yaml``) says *what* the task is — the scene, the person, the robot's
role, tools, named targets, particles, observations, reward terms, preferences and success — and
never *how* to simulate it. Units are in field names (``_m``, ``_deg``, ``_kg``, ``_s``, ``_n``)
or descriptions. World frame: Z up, gravity along −Z; the seated person faces −Y and their right
side is −X (the reference's convention).

References between parts are plain strings checked by :mod:`assistive_compiler.resolve`:

* a **body**: ``robot``, ``person``, a furniture name, a tool name, a particle-set name;
* a **link** of a body: ``body.semantic_link`` (``person.head``, ``robot.end_effector``,
  ``spoon.tip``); a bare body name means the body's reference link;
* a **target**: a name declared under ``targets:`` (``mouth``);
* a **joint group**: ``robot.arm`` or ``person.<group>`` (``person.head``, ``person.right_arm``);
* a **segment** of waypoints: a name declared under ``scripted.segments:`` (``{segment: side_lanes}``).

One module per spec section, in the order a spec reads: :mod:`.sim`, :mod:`.scene`,
:mod:`.person`, :mod:`.robot` (robot role and tools), :mod:`.bodies` (targets, markers, particles,
garments), :mod:`.terms` (observations, reward, preferences, success), :mod:`.scripted` and
:mod:`.task` (camera and :class:`TaskSpec`), on the building blocks of :mod:`.common`.
"""

from __future__ import annotations

from .bodies import (
    ClearedBy,
    ConsumedAt,
    Garment,
    GarmentHold,
    GarmentSettle,
    LostBeyond,
    Markers,
    Particles,
    RestInContainer,
    SimulatedNear,
    SleeveShape,
    SoftBodyPhysics,
    Target,
)
from .common import Name, Ref, Rgba, Scalar, Strict, Uniform, Vec3, describe, scalar_bounds
from .person import (
    CompliantHold,
    Impairment,
    Impairments,
    LimitedRange,
    NoImpairment,
    Person,
    PersonControl,
    Placement,
    Settle,
    SettleStage,
    StageHold,
    Tremor,
    Weakness,
)
from .robot import BaseSearch, Goal, PerRobot, RobotControl, RobotRole, StartGoal, ToolUse
from .scene import FurnitureUse, Scene
from .scripted import Scripted, ScriptedArm, ScriptedRobot, SegmentUse, Waypoint, WaypointItem
from .sim import Ground, Sim, Solver
from .task import Camera, CameraView, TaskSpec
from .terms import (
    PAPER_PREFERENCE_WEIGHTS,
    PREFERENCE_NAMES,
    Observations,
    Preference,
    Preferences,
    RewardTerm,
    Success,
    TermUse,
)

__all__ = [
    "Name",
    "Ref",
    "Vec3",
    "Rgba",
    "Strict",
    "Uniform",
    "Scalar",
    "describe",
    "scalar_bounds",
    "Solver",
    "Ground",
    "Sim",
    "FurnitureUse",
    "Scene",
    "Tremor",
    "Weakness",
    "LimitedRange",
    "NoImpairment",
    "Impairment",
    "Impairments",
    "CompliantHold",
    "PersonControl",
    "Settle",
    "StageHold",
    "SettleStage",
    "Placement",
    "Person",
    "RobotControl",
    "StartGoal",
    "Goal",
    "BaseSearch",
    "PerRobot",
    "RobotRole",
    "ToolUse",
    "Target",
    "ClearedBy",
    "Markers",
    "ConsumedAt",
    "LostBeyond",
    "RestInContainer",
    "SimulatedNear",
    "Particles",
    "SleeveShape",
    "SoftBodyPhysics",
    "GarmentHold",
    "GarmentSettle",
    "Garment",
    "TermUse",
    "RewardTerm",
    "Observations",
    "PREFERENCE_NAMES",
    "PAPER_PREFERENCE_WEIGHTS",
    "Preference",
    "Preferences",
    "Success",
    "Waypoint",
    "SegmentUse",
    "WaypointItem",
    "ScriptedArm",
    "ScriptedRobot",
    "Scripted",
    "CameraView",
    "Camera",
    "TaskSpec",
]
