"""What a term parameter refers to, in its two forms: the **reference** the resolver makes and the
manifest carries, and the **handle** the runtime binds it to once, when the env is built.

A spec names things (``mouth``, ``robot.end_effector``, ``person.head``, ``sleeve.opening``); the
resolver checks each name and turns it into a reference with the URDF names it stands for; the
runtime's :func:`assistive_compiler.runtime.binding.bind` turns each reference into a handle
(a slot in the per-step snapshot, joint indices, node indices), so a step only indexes arrays.

===========  ==================================  ==================  =====================
kind         spec                                reference           handle
===========  ==================================  ==================  =====================
point        ``mouth``, ``robot.end_effector``   :class:`TargetPoint`  :class:`PointHandle`
                                                 / :class:`LinkPoint`
joints       ``robot.arm``, ``person.head``      :class:`JointGroup`   :class:`JointsHandle`
nodes        ``sleeve.opening``                  :class:`NodeSet`      :class:`NodesHandle`
body(ies),   ``spoon``, ``[robot, spoon]``,      the name            the name
particles,   ``food``, ``spots``, ``robot_base``
markers,
frame
===========  ==================================  ==================  =====================

Light: pydantic only.
"""

from __future__ import annotations

from dataclasses import dataclass

from pydantic import BaseModel, ConfigDict, Field


class _Reference(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class TargetPoint(_Reference):
    """A task target (a point on a link at an offset, or drawn on the person's surface per episode)."""

    target: str = Field(description="The target's name (the spec's targets section).")


class LinkPoint(_Reference):
    """A link's origin (its URDF frame)."""

    body: str = Field(description="The body: robot, person, a tool, a furniture piece or a garment.")
    link: str = Field(description="The URDF link name on that body.")


Point = TargetPoint | LinkPoint
"""A point reference: a target, or a body's link."""


class JointGroup(_Reference):
    """A named group of joints of the robot or the person (``robot.arm``, ``person.head``)."""

    body: str = Field(description="'robot' or 'person'.")
    group: str = Field(description="The group's name after the body ('arm', 'head', 'policy').")
    joints: tuple[str, ...] = Field(description="URDF joint names, in the group's order.")

    @property
    def name(self) -> str:
        """How a spec names the group: ``<body>.<group>``."""
        return f"{self.body}.{self.group}"


class NodeSet(_Reference):
    """A named set of a garment's mesh nodes (``sleeve.opening``)."""

    garment: str = Field(description="The garment's body name.")
    set: str = Field(description="The set's name on that garment.")
    nodes: tuple[int, ...] = Field(description="Node indices of the generated mesh, in the set's order.")


ParamValue = (
    TargetPoint
    | LinkPoint
    | JointGroup
    | NodeSet
    | list[TargetPoint | LinkPoint]
    | bool
    | int
    | float
    | str
    | list[str]
    | list[float]
    | tuple[float, ...]
    | None
)
"""A term parameter's value in the manifest: a reference, a list of points, or a plain value (names
of bodies, particle and marker sets and frames stay names)."""


@dataclass(frozen=True)
class PointHandle:
    """A bound point: its link's slot in the snapshot, plus the target it is (its offset and,
    for a surface target, its link change per episode), or None for a link's origin."""

    slot: int
    target: str | None = None


@dataclass(frozen=True)
class JointsHandle:
    """A bound joint group: the body ('robot' or 'person') and its joints' pybullet indices."""

    body: str
    indices: tuple[int, ...]


@dataclass(frozen=True)
class NodesHandle:
    """A bound node set: the garment's index in ``world.garments`` and the node indices."""

    garment: int
    indices: tuple[int, ...]
