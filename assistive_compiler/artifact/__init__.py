"""The compiled artifact: the contract between the compiler (writes it) and the runtime (reads it).

An artifact is a directory::

    manifest.json          the manifest (:class:`Manifest`), serialised with sorted keys
    urdf/<body>.urdf       one standard URDF per body (person variants: person_<variant>.urdf)

Everything the runtime needs is here, already decided: body files and poses, the person's
posture and which joints move, the robot's arm joints and precomputed start configurations,
tool attachments, targets, particles with their settled positions, the observation, reward
and success programs with references normalised to URDF link and joint names, and what a reset
does, as ordered events. The runtime never
reads YAML and never searches (no IK at reset).

The models, by part: the manifest and its hash (:mod:`.manifest`), the bodies and things of the
world (:mod:`.scene`), the person (:mod:`.person`), the robot (:mod:`.robot`), the terms, success
and scripted baseline (:mod:`.programs`) and the reset's events (:mod:`.events`). This package
imports nothing of the compiler or the runtime: it stands below both.

Frames and units: positions in metres in the world frame unless a field says otherwise;
orientations are quaternions (x, y, z, w) as pybullet uses; joint values in radians.
"""

from __future__ import annotations

from .events import (
    ComponentResetEvent,
    Event,
    FloorFrictionEvent,
    FurnitureNoiseEvent,
    PersonVariantEvent,
    RobotStartEvent,
    SurfaceTargetsEvent,
    reset_events,
)
from .manifest import AGENTS, FORMAT_VERSION, Manifest
from .model import ArtifactModel, Quat, Vec3
from .person import (
    Capsule,
    Impairment,
    LimitedRange,
    MarkerPoint,
    NoImpairment,
    Person,
    PersonVariant,
    SurfacePoint,
    Tremor,
    Weakness,
)
from .programs import FollowedSurface, Script, ScriptWaypoint, Success, SurfaceShape, TermUse
from .robot import BasePose, BaseSearch, Drive, Mounted, Robot, StartState, ToolAttachment
from .scene import Body, Camera, Container, Garment, MarkerSet, ParticleRest, ParticleSet, Sim, Target

__all__ = [
    "AGENTS",
    "ArtifactModel",
    "BasePose",
    "BaseSearch",
    "Body",
    "Camera",
    "Capsule",
    "ComponentResetEvent",
    "Container",
    "Drive",
    "Event",
    "FORMAT_VERSION",
    "FloorFrictionEvent",
    "FollowedSurface",
    "FurnitureNoiseEvent",
    "Garment",
    "Impairment",
    "LimitedRange",
    "Manifest",
    "MarkerPoint",
    "MarkerSet",
    "Mounted",
    "NoImpairment",
    "ParticleRest",
    "ParticleSet",
    "Person",
    "PersonVariant",
    "PersonVariantEvent",
    "Quat",
    "Robot",
    "RobotStartEvent",
    "Script",
    "ScriptWaypoint",
    "Sim",
    "StartState",
    "Success",
    "SurfacePoint",
    "SurfaceShape",
    "SurfaceTargetsEvent",
    "Target",
    "TermUse",
    "ToolAttachment",
    "Tremor",
    "Vec3",
    "Weakness",
    "reset_events",
]
