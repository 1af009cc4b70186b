"""Resolution: a validated spec plus the part library → a :class:`ResolvedTask` for one robot.

Every name a spec uses is checked here, with a located message and a "did you mean" on failure:
library parts, body names, links (semantic names for robots and tools; URDF names for the
person), joints and joint limits, targets, particle sets, term kinds and term parameters,
preference names, and the success term. References come out normalised so the compiler and the
runtime never parse a spec string again (:mod:`.scope` lists how each kind of reference resolves;
:mod:`.resolved` the types handed to the compiler).

One module per spec section, all reporting into one :class:`~.located.Collector` (the
:class:`~.scope.Scope` of the task on one robot): :mod:`.robot`, :mod:`.person`, :mod:`.bodies`
(targets, markers, particles, garments), :mod:`.terms` (observations, reward, preferences,
success) and :mod:`.scripted`. Problems from every section are raised together.
"""

from __future__ import annotations

from ..errors import Problem, SpecError
from ..library import Library
from ..spec.load import LoadedSpec
from . import bodies, person, scripted, terms
from . import robot as robot_section
from .landmarks import with_landmarks
from .resolved import ResolvedTask, ResolvedTerm
from .scope import GARMENT_HELD_LINK, RESERVED_BODIES, ROBOT_SEMANTIC_LINKS, Scope

__all__ = [
    "GARMENT_HELD_LINK",
    "RESERVED_BODIES",
    "ROBOT_SEMANTIC_LINKS",
    "ResolvedTask",
    "ResolvedTerm",
    "resolve",
    "validate_all_robots",
]


def _load_parts(s: Scope) -> None:
    """The library parts the task uses on this robot (raises when the robot or every person is missing)."""
    spec = s.spec
    robot = s.part("robots", s.robot_name, ("robot", "default"), "robot")
    s.furniture = {
        n: p
        for n, use in spec.scene.furniture.items()
        if (p := s.part("furniture", use.part, ("scene", "furniture", n, "part"), "furniture part"))
    }
    s.tools = {n: p for n, use in spec.tools.items() if (p := s.part("tools", use.part, ("tools", n, "part"), "tool"))}
    s.people = {
        n: p
        for i, n in enumerate(spec.person.variants)
        if (p := s.part("people", n, ("person", "variants", i), "person"))
    }
    robot_section.check_per_robot_keys(s, ("robot", "per_robot"), spec.robot.per_robot)
    robot_section.check_per_robot_keys(s, ("camera", "per_robot"), spec.camera.per_robot)
    if s.problems or robot is None or not s.people:
        raise SpecError(s.problems)
    s.robot = robot


def resolve(loaded: LoadedSpec, robot: str | None = None, library: Library | None = None) -> ResolvedTask:
    """Resolve ``loaded`` for ``robot`` (default: the spec's default robot)."""
    library = library or Library.for_spec(loaded.path)
    loaded = with_landmarks(loaded, library)  # person.<landmark> references become targets
    s = Scope(loaded, library, robot or loaded.spec.robot.default)
    spec = s.spec
    robot_section.check_supported(s)
    _load_parts(s)
    s.sides = robot_section.acting_sides(spec, s.robot)
    s.tool_aliases = robot_section.tool_aliases(s)
    s.tools = {n: p for n, p in s.tools.items() if n not in s.tool_aliases}
    s.robot_urdf = s.lib.default_urdf("robots", s.robot_name)
    s.person_urdf = s.lib.default_urdf("people", spec.person.variants[0])
    bodies.name_bodies(s)
    s.robot_links = robot_section.robot_links(s)
    s.joint_groups = robot_section.joint_groups(s)
    person.check_person(s)
    robot_section.check_mount(s)
    robot_section.check_arm_rest(s)
    targets = bodies.targets(s)
    markers = bodies.markers(s)
    bodies.check_particles(s)
    bodies.check_garments(s)
    observations = terms.observations(s)
    reward = terms.reward(s)
    threshold = terms.success_threshold(s)
    script = scripted.scripted(s)
    base_goals = robot_section.base_goals(s)
    s.fail_if_any()
    return ResolvedTask(
        loaded=loaded,
        robot_name=s.robot_name,
        robot=s.robot,
        robot_urdf=s.robot_urdf,
        tools=s.tools,
        furniture=s.furniture,
        people=s.people,
        person_urdf=s.person_urdf,
        robot_links=s.robot_links,
        joint_groups=s.joint_groups,
        observations=observations,
        reward=reward,
        success_threshold=threshold,
        targets=targets,
        scripted=script,
        base_goals=base_goals,
        markers=markers,
        sides=s.sides,
        tool_uses={n: u for n, u in spec.tools.items() if n not in s.tool_aliases},
        tool_aliases=s.tool_aliases,
    )


def validate_all_robots(loaded: LoadedSpec, library: Library | None = None) -> list[ResolvedTask]:
    """Resolve the spec for every robot it supports; problems from all of them are reported together."""
    library = library or Library.for_spec(loaded.path)
    resolved: list[ResolvedTask] = []
    problems: list[Problem] = []
    for robot in loaded.spec.robot.supported:
        try:
            resolved.append(resolve(loaded, robot, library))
        except SpecError as exc:
            problems.extend(p for p in exc.problems if p not in problems)
    if problems:
        raise SpecError(problems)
    return resolved
