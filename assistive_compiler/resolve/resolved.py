"""What resolution produces: a :class:`ResolvedTask` per (task, robot), its terms :class:`ResolvedTerm`.

Everything in it is checked and normalised, so the compiler and the runtime never parse a spec
string again (see :mod:`assistive_compiler.resolve` for the shapes references take).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from ..artifact import Script
from ..library import LoadedPart
from ..references import JointGroup, LinkPoint, ParamValue, Point
from ..spec.load import LoadedSpec
from ..spec.models import TaskSpec, ToolUse
from ..spec.parts import FurniturePart, PersonPart, RobotPart, ToolPart
from ..terms.registry import Category
from ..urdf import UrdfInfo


@dataclass(frozen=True)
class ResolvedTerm:
    """A term use with its parameters validated and its references resolved to reference models."""

    name: str
    term: str
    category: Category
    weight: float
    params: dict[str, ParamValue]


@dataclass(frozen=True)
class RegionCentre:
    """Where a surface region is centred: on ``link`` (a person URDF link), at the offset of
    ``target`` on each person variant (None: the link's origin)."""

    link: str
    target: str | None


@dataclass(frozen=True)
class ResolvedRegion:
    """A region of person links' surfaces (:func:`~.bodies.region_of`): within ``radius_m`` of its
    centre, within ``max_angle_rad`` of the unit ``facing`` direction (link frame), between the
    ``along`` fractions of the limb's capsule; each None where the spec leaves it open."""

    radius_m: float
    along: tuple[float, float] | None
    max_angle_rad: float | None
    facing: tuple[float, float, float] | None
    near: RegionCentre | None


@dataclass(frozen=True)
class SurfaceTarget:
    """A target drawn anew each reset on the surface of person links (``surface_of``), in a region."""

    surface_links: tuple[str, ...]
    """Person URDF links it is drawn on (each with a collision capsule or sphere)."""
    region: ResolvedRegion | None

    @property
    def point(self) -> LinkPoint:
        """The link it starts on before the first draw (the first surface link)."""
        return LinkPoint(body="person", link=self.surface_links[0])


#: A target: a fixed point on a link (offset by the spec), or drawn on the person's surface.
ResolvedTarget = LinkPoint | SurfaceTarget


@dataclass(frozen=True)
class ResolvedMarkerSet:
    """A marker set: points ``spacing_m`` apart on ``links`` (person URDF links) in ``region``,
    each cleared when ``tool``'s link touches the person within ``radius_m`` of it."""

    links: tuple[str, ...]
    tool: LinkPoint
    radius_m: float
    spacing_m: float
    show_rgba: tuple[float, float, float, float] | None
    region: ResolvedRegion | None


@dataclass(frozen=True)
class BaseGoal:
    """A point the base search places the robot to reach with ``arm``: ``point`` plus ``offset_m``
    (world frame, m), with the start's tool orientation when ``oriented``; must be reached when
    ``required``."""

    point: Point
    offset_m: tuple[float, float, float]
    oriented: bool
    required: bool
    arm: Literal["right", "left"]


@dataclass(kw_only=True)
class ResolvedTask:
    """Everything the compiler needs for one (task, robot) pair (built by keyword only)."""

    loaded: LoadedSpec
    robot_name: str
    robot: LoadedPart[RobotPart]
    robot_urdf: UrdfInfo
    tools: dict[str, LoadedPart[ToolPart]]
    furniture: dict[str, LoadedPart[FurniturePart]]
    people: dict[str, LoadedPart[PersonPart]]
    person_urdf: UrdfInfo
    robot_links: dict[str, str]
    joint_groups: dict[str, JointGroup]
    observations: dict[str, list[ResolvedTerm]]
    reward: list[ResolvedTerm]
    success_threshold: float
    #: Each target: the link it sits on, or the person links it is drawn on.
    targets: dict[str, ResolvedTarget] = field(default_factory=dict)
    #: The scripted baseline for this robot, as the manifest carries it (None: the task has none).
    scripted: Script | None = None
    #: What the base search (``robot.mount_base: search``) must reach.
    base_goals: list[BaseGoal] = field(default_factory=list)
    #: Each marker set: its links, clearing tool and spacing.
    markers: dict[str, ResolvedMarkerSet] = field(default_factory=dict)
    #: The sides acting, in action order: ("right", "left") for a two-arm robot in a task with arm
    #: 'both', else the one side (a one-arm robot's arm serves as either).
    sides: tuple[str, ...] = ("right",)
    #: Tools that are bodies of their own (one-arm robots: a tool ``one_arm_same_as`` another is not).
    tool_uses: dict[str, ToolUse] = field(default_factory=dict)
    #: Tool names that refer to another tool's body on this robot (alias -> tool).
    tool_aliases: dict[str, str] = field(default_factory=dict)

    @property
    def spec(self) -> TaskSpec:
        return self.loaded.spec
