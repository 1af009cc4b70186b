"""What resolution produces: a :class:`ResolvedTask` per (task, robot), its terms :class:`ResolvedTerm`.

Everything in it is checked and normalised, so the compiler and the runtime never parse a spec
string again (see :mod:`assistive_compiler.resolve` for the shapes references take).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..library import LoadedPart
from ..references import JointGroup, ParamValue
from ..spec.load import LoadedSpec
from ..spec.models import TaskSpec
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


@dataclass(kw_only=True)
class ResolvedTask:
    """Everything the compiler needs for one (task, robot) pair (built by keyword only)."""

    loaded: LoadedSpec
    robot_name: str
    robot: LoadedPart
    robot_urdf: UrdfInfo
    tools: dict[str, LoadedPart]
    furniture: dict[str, LoadedPart]
    people: dict[str, LoadedPart]
    person_urdf: UrdfInfo
    robot_links: dict[str, str]
    joint_groups: dict[str, JointGroup]
    observations: dict[str, list[ResolvedTerm]]
    reward: list[ResolvedTerm]
    success_threshold: float
    points: dict[str, dict[str, Any]] = field(default_factory=dict)
    scripted: dict[str, Any] | None = None
    base_goals: list[dict[str, Any]] = field(default_factory=list)
    markers: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: The sides acting, in action order: ("right", "left") for a two-arm robot in a task with arm
    #: 'both', else the one side (a one-arm robot's arm serves as either).
    sides: tuple[str, ...] = ("right",)
    #: Tools that are bodies of their own (one-arm robots: a tool ``one_arm_same_as`` another is not).
    tool_uses: dict[str, Any] = field(default_factory=dict)
    #: Tool names that refer to another tool's body on this robot (alias -> tool).
    tool_aliases: dict[str, str] = field(default_factory=dict)

    @property
    def spec(self) -> TaskSpec:
        return self.loaded.spec
