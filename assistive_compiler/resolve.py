"""Resolution: a validated spec plus the part library → a :class:`ResolvedTask` for one robot.

Every name a spec uses is checked here, with a located message and a "did you mean" on failure:
library parts, body names, links (semantic names for robots and tools; URDF names for the
person), joints and joint limits, targets, particle sets, term kinds and term parameters,
preference names, and the success term. References come out normalised so the compiler and the
runtime never parse a spec string again:

* point → ``{"target": name}`` or ``{"body": body, "link": urdf_link}``
* body → body name; bodies → list of body names
* joints → ``{"body": "robot" | "person", "group": name, "joints": [urdf joint names]}``
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from pydantic import ValidationError

from .compile.render import UrdfInfo
from .errors import Problem, SpecError, did_you_mean, one_of
from .library import Library, LoadedPart
from .spec.load import LoadedSpec
from .spec.models import PAPER_PREFERENCE_WEIGHTS, PREFERENCE_NAMES, TaskSpec, Uniform
from .spec.validation import problems_from_validation
from .terms.registry import Category, TermDef, ref_fields, terms

RESERVED_BODIES = ("robot", "person")
GARMENT_HELD_LINK = "held"
"""The one link of a garment body: its held frame (the pose the robot's hand gives it)."""
ROBOT_SEMANTIC_LINKS = ("base", "end_effector", "tool_mount")


@dataclass(frozen=True)
class ResolvedTerm:
    """A term use with its parameters validated and references normalised (JSON-ready)."""

    name: str
    term: str
    category: Category
    weight: float
    params: dict[str, Any]


@dataclass
class ResolvedTask:
    """Everything the compiler needs for one (task, robot) pair."""

    loaded: LoadedSpec
    robot_name: str
    robot: LoadedPart
    robot_urdf: UrdfInfo
    tools: dict[str, LoadedPart]
    furniture: dict[str, LoadedPart]
    people: dict[str, LoadedPart]
    person_urdf: UrdfInfo
    robot_links: dict[str, str]
    joint_groups: dict[str, dict[str, Any]]
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


def _deg_range(lower: float | None, upper: float | None) -> str:
    return f"[{math.degrees(lower):.0f}°, {math.degrees(upper):.0f}°]" if lower is not None and upper is not None else "unlimited"


class _Resolver:
    def __init__(self, loaded: LoadedSpec, library: Library, robot_name: str):
        self.loaded = loaded
        self.spec = loaded.spec
        self.lib = library
        self.robot_name = robot_name
        self.problems: list[Problem] = []
        self.tool_aliases: dict[str, str] = {}

    # -- helpers -----------------------------------------------------------------------------
    def at(self, *path: Any):
        return self.loaded.smap.value(tuple(path))

    def key_at(self, *path: Any):
        return self.loaded.smap.key(tuple(path))

    def problem(self, path: tuple, message: str, key: bool = False) -> None:
        self.problems.append(Problem(self.key_at(*path) if key else self.at(*path), message))

    def part(self, kind: str, name: str, path: tuple, what: str) -> LoadedPart | None:
        try:
            return self.lib.get(kind, name)
        except KeyError:
            names = self.lib.names(kind)
            self.problem(path, f"unknown {what} '{name}'; expected one of {one_of(names)}{did_you_mean(name, names)}")
        except SpecError as exc:
            self.problems.extend(exc.problems)
        return None

    # -- the passes ----------------------------------------------------------------------------
    def run(self) -> ResolvedTask:
        spec = self.spec
        robot_path = ("robot", "default")
        for i, name in enumerate(spec.robot.supported):
            if not self.lib.path_of("robots", name):
                names = self.lib.names("robots")
                self.problem(("robot", "supported", i), f"unknown robot '{name}'; expected one of {one_of(names)}{did_you_mean(name, names)}")
        if self.robot_name not in spec.robot.supported:
            raise SpecError([Problem(self.at(*robot_path), f"robot '{self.robot_name}' is not supported by task '{spec.name}'; supported: {one_of(spec.robot.supported)}{did_you_mean(self.robot_name, spec.robot.supported)}")])
        robot = self.part("robots", self.robot_name, robot_path, "robot")
        furniture = {n: p for n, use in spec.scene.furniture.items() if (p := self.part("furniture", use.part, ("scene", "furniture", n, "part"), "furniture part"))}
        tools = {n: p for n, use in spec.tools.items() if (p := self.part("tools", use.part, ("tools", n, "part"), "tool"))}
        people = {n: p for i, n in enumerate(spec.person.variants) if (p := self.part("people", n, ("person", "variants", i), "person"))}
        known = self.lib.names("robots")
        for name in spec.robot.per_robot:  # may name robots a spec extending this one supports
            if name not in known:
                self.problem(("robot", "per_robot", name), f"per_robot names unknown robot '{name}'; expected one of {one_of(known)}{did_you_mean(name, known)}", key=True)
        if self.problems or robot is None or not people:
            raise SpecError(self.problems)

        self.robot = robot
        self.sides = self._sides(spec)
        self.tool_aliases = self._tool_aliases(spec, tools)
        tools = {n: p for n, p in tools.items() if n not in self.tool_aliases}
        self.robot_urdf = self.lib.default_urdf("robots", self.robot_name)
        self.person_urdf = self.lib.default_urdf("people", spec.person.variants[0])
        self.tools, self.furniture, self.people = tools, furniture, people
        self._bodies(spec)
        self.robot_links = self._robot_links()
        self.joint_groups = self._joint_groups()
        self._person(spec)
        self._robot_role(spec)
        points = self._targets(spec)
        markers = self._markers(spec)
        self._particles(spec)
        self._garments(spec)
        observations = {
            agent: [self._term(use, "observation", ("observations", agent, i), f"{agent}_{i}", 1.0) for i, use in enumerate(getattr(spec.observations, agent))]
            for agent in ("robot", "human")
        }
        arms = len(self.sides)
        reward = [self._term(t, "reward", ("reward", i), t.name, t.weight) for i, t in enumerate(spec.reward) if t.arms in (None, arms)]
        names_seen: dict[str, int] = {}
        for i, t in enumerate(spec.reward):
            if t.name in names_seen:
                self.problem(("reward", i, "name"), f"reward term name '{t.name}' is already used by reward[{names_seen[t.name]}]")
            names_seen[t.name] = i
        reward += self._preferences(spec)
        threshold = self._success(spec, {t.name for t in spec.reward if t.arms in (None, arms)})
        scripted = self._scripted(spec)
        base_goals = [
            {"point": self.point(g.point, ("robot", "base_search", "goals", i, "point")), "offset_m": list(g.offset_m),
             "oriented": g.oriented, "required": g.required, "arm": (g.arm or "right") if len(self.sides) > 1 else self.sides[0]}
            for i, g in enumerate(spec.robot.base_search.goals)
        ]
        for i, g in enumerate(spec.robot.base_search.goals):
            if g.arm is not None and spec.robot.arm != "both":
                self.problem(("robot", "base_search", "goals", i, "arm"), f"a goal names an arm only in a task acting with both arms (robot.arm: both); this task's arm is '{spec.robot.arm}'")
        if self.problems:
            raise SpecError(self.problems)
        return ResolvedTask(
            self.loaded, self.robot_name, robot, self.robot_urdf, tools, furniture, people, self.person_urdf,
            self.robot_links, self.joint_groups, {a: [t for t in ts if t] for a, ts in observations.items()},
            [t for t in reward if t], threshold, points, scripted, base_goals, markers,
            self.sides, {n: u for n, u in spec.tools.items() if n not in self.tool_aliases}, self.tool_aliases,
        )

    def _sides(self, spec: TaskSpec) -> tuple[str, ...]:
        """The acting sides in action order (see ResolvedTask.sides)."""
        part = self.robot.part
        if spec.robot.arm == "both" and len(part.arms) > 1:
            return ("right", "left")
        return (spec.robot.arm if spec.robot.arm != "both" else "right",)

    def _tool_aliases(self, spec: TaskSpec, tools: dict[str, LoadedPart]) -> dict[str, str]:
        """Which tools share another tool's body on this robot, checking that every tool's hand is
        one the robot acts with: on a robot acting with one arm, a tool in the other hand must be
        ``one_arm_same_as`` a tool of the same part in the acting hand (facts §2.6)."""
        aliases: dict[str, str] = {}
        one_arm = len(self.sides) == 1
        robot_arms = len(self.robot.part.arms)
        for name, use in spec.tools.items():
            path = ("tools", name)
            other = use.one_arm_same_as
            if other is not None:
                if other not in spec.tools or other == name:
                    pool = [t for t in spec.tools if t != name]
                    self.problem(path + ("one_arm_same_as",), f"unknown tool '{other}'; expected one of {one_of(pool) or 'none'}{did_you_mean(other, pool)}")
                    continue
                target = spec.tools[other]
                if target.one_arm_same_as is not None:
                    self.problem(path + ("one_arm_same_as",), f"tool '{other}' is itself one_arm_same_as '{target.one_arm_same_as}'; name a tool that is a body of its own")
                elif target.part != use.part:
                    self.problem(path + ("one_arm_same_as",), f"tool '{other}' is a '{target.part}' but '{name}' is a '{use.part}'; one body can only stand for tools of the same part")
                elif target.hand == use.hand:
                    self.problem(path + ("one_arm_same_as",), f"tool '{other}' is already in the {use.hand} hand; one_arm_same_as names the tool in the other hand")
                elif one_arm:
                    aliases[name] = other
                    continue
            if one_arm and spec.robot.arm != "both" and robot_arms > 1 and use.hand != spec.robot.arm:
                self.problem(path + ("hand",), f"tool '{name}' is held in the {use.hand} hand, but the task acts with the {spec.robot.arm} arm only; use hand: {spec.robot.arm} or robot.arm: both")
        if one_arm:
            held = [n for n in spec.tools if n not in aliases]
            hands = {spec.tools[n].hand for n in held}
            if len(hands) > 1 and (robot_arms == 1 or spec.robot.arm == "both"):
                first = held[0]
                for n in held[1:]:
                    if spec.tools[n].hand != spec.tools[first].hand:
                        self.problem(("tools", n, "hand"), f"robot '{self.robot_name}' acts with one arm, which would hold both '{first}' ({spec.tools[first].hand} hand) and '{n}' ({spec.tools[n].hand} hand); give '{n}' one_arm_same_as: {first} (one tool serving both hands) or a hand the arm already uses")
        return aliases

    def _bodies(self, spec: TaskSpec) -> None:
        self.body_names: dict[str, str] = {"robot": "robot", "person": "person"}
        for section, names in (("scene.furniture", spec.scene.furniture), ("tools", spec.tools), ("particles", spec.particles),
                               ("garments", spec.garments)):
            for name in names:
                path = tuple(section.split(".")) + (name,)
                if name in self.body_names:
                    other = self.body_names[name]
                    why = "is reserved" if name in RESERVED_BODIES else f"is already used in {other}"
                    self.problem(path, f"body name '{name}' {why}; every furniture, tool and particle set needs its own name", key=True)
                else:
                    self.body_names[name] = section

    def _robot_links(self) -> dict[str, str]:
        part = self.robot.part
        side = self.spec.robot.arm if self.spec.robot.arm != "both" else "right"
        out = {"base": part.base_link}
        _, arm = part.arm_for(side)
        out["end_effector"], out["tool_mount"] = arm.end_effector, arm.tool_mount
        for s in ("right", "left"):
            _, a = part.arm_for(s)
            out[f"{s}_end_effector"], out[f"{s}_tool_mount"] = a.end_effector, a.tool_mount
        return out

    def _joint_groups(self) -> dict[str, dict[str, Any]]:
        from .person.body import JOINT_GROUPS

        part = self.robot.part
        groups: dict[str, dict[str, Any]] = {}
        sides = ("right", "left") if self.spec.robot.arm == "both" and len(part.arms) > 1 else (self.spec.robot.arm if self.spec.robot.arm != "both" else "right",)
        arm_joints: list[str] = []
        for s in sides:
            arm_joints += part.arm_for(s)[1].joints
        groups["robot.arm"] = {"body": "robot", "group": "arm", "joints": arm_joints}
        for s in ("right", "left"):
            groups[f"robot.{s}_arm"] = {"body": "robot", "group": f"{s}_arm", "joints": list(part.arm_for(s)[1].joints)}
        for name, joints in JOINT_GROUPS.items():
            groups[f"person.{name}"] = {"body": "person", "group": name, "joints": list(joints)}
        return groups

    # -- references ----------------------------------------------------------------------------
    def links_of(self, body: str) -> dict[str, str]:
        if body == "robot":
            return self.robot_links
        if body == "person":
            return {l: l for l in self.person_urdf.links}
        if body in self.tools:
            return dict(self.tools[body].part.links) | {"base": self.tools[body].part.base_link}
        if body in self.furniture:
            return dict(self.furniture[body].part.links) | {"base": self.furniture[body].part.base_link}
        if body in self.spec.garments:
            return {GARMENT_HELD_LINK: GARMENT_HELD_LINK}
        return {}

    def reference_link(self, body: str) -> str | None:
        if body == "robot":
            return self.robot_links["end_effector"]
        if body == "person":
            return self.robot_person_root()
        if body in self.tools:
            tool = self.tools[body].part
            return tool.links[tool.reference_link]
        if body in self.furniture:
            return self.furniture[body].part.base_link
        if body in self.spec.garments:
            return GARMENT_HELD_LINK
        return None

    def robot_person_root(self) -> str:
        return self.person_urdf.root_link

    def body(self, value: str, path: tuple, *, allow_particles: bool = True) -> str | None:
        pool = [b for b, section in self.body_names.items() if allow_particles or section != "particles"]
        if value not in pool:
            self.problem(path, f"unknown body '{value}'; expected one of {one_of(pool)}{did_you_mean(value, pool)}")
            return None
        if self._conditional(value, path):
            return None
        return self.tool_aliases.get(value, value)

    def _conditional(self, body: str, path: tuple) -> bool:
        """True (and a problem) when ``body`` is furniture present only under a mounted robot."""
        use = self.spec.scene.furniture.get(body)
        if use is None or not use.only_when_mounted:
            return False
        self.problem(path, f"furniture '{body}' is in the scene only when the robot is mounted on it (only_when_mounted: true), "
                           "so nothing may refer to it; refer to furniture that is always there")
        return True

    def point(self, value: str, path: tuple, *, allow_target: bool = True) -> dict[str, Any] | None:
        if allow_target and value in self.spec.targets:
            return {"target": value}
        body, _, link = value.partition(".")
        if body in self.body_names:
            body = self.tool_aliases.get(body, body)  # a one-arm robot's second name for its tool
        if body not in self.body_names or self.body_names[body] == "particles":
            pool = [b for b, s in self.body_names.items() if s != "particles"] + (list(self.spec.targets) if allow_target else [])
            what = "target or body" if allow_target else "body"
            self.problem(path, f"unknown {what} '{value}'; expected one of {one_of(pool)}{did_you_mean(body, pool)}")
            return None
        if self._conditional(body, path):
            return None
        if not link:
            return {"body": body, "link": self.reference_link(body)}
        links = self.links_of(body)
        if link not in links:
            self.problem(path, f"unknown link '{link}' of {body}; expected one of {one_of(links)}{did_you_mean(link, links)}")
            return None
        return {"body": body, "link": links[link]}

    def joints(self, value: str, path: tuple) -> dict[str, Any] | None:
        if value == "person.policy":
            return {"body": "person", "group": "policy", "joints": self.policy_joints}
        if value not in self.joint_groups:
            pool = list(self.joint_groups) + ["person.policy"]
            self.problem(path, f"unknown joint group '{value}'; expected one of {one_of(pool, 20)}{did_you_mean(value, pool)}")
            return None
        return self.joint_groups[value]

    def node_set(self, value: str, path: tuple) -> dict[str, Any] | None:
        """``<garment>.<set>`` → {"garment", "set", "nodes"} (node indices of the generated mesh)."""
        from .garment import sleeve_node_sets

        name, _, set_name = value.partition(".")
        if name not in self.spec.garments:
            pool = list(self.spec.garments)
            self.problem(path, f"unknown garment '{name}'; expected one of {one_of(pool) or 'none (declare one under garments:)'}{did_you_mean(name, pool)}")
            return None
        shape = self.spec.garments[name].shape
        sets = sleeve_node_sets(shape.rings, shape.segments)
        if set_name not in sets:
            self.problem(path, f"unknown node set '{set_name}' of garment '{name}'; expected one of {one_of(sets)}{did_you_mean(set_name, sets)} (write {name}.<set>)")
            return None
        return {"garment": name, "set": set_name, "nodes": [int(i) for i in sets[set_name]]}

    def _garments(self, spec: TaskSpec) -> None:
        from .garment import sleeve_node_sets

        for name, g in spec.garments.items():
            base = ("garments", name, "held")
            if g.held.grip not in self.robot.part.grips:
                grips = list(self.robot.part.grips)
                self.problem(base + ("grip",), f"robot '{self.robot_name}' has no grip '{g.held.grip}' to hold garment '{name}' (add it under grips: in {self.robot.shown}); its grips are {one_of(grips)}{did_you_mean(g.held.grip, grips)}")
            for i, body in enumerate(g.collides_with or []):
                if self.body(body, ("garments", name, "collides_with", i), allow_particles=False) == name:
                    self.problem(("garments", name, "collides_with", i), f"garment '{name}' cannot collide with itself (self-collision is off)")
            sets = sleeve_node_sets(g.shape.rings, g.shape.segments)
            if g.held.nodes not in sets:
                self.problem(base + ("nodes",), f"unknown node set '{g.held.nodes}' of garment '{name}'; expected one of {one_of(sets)}{did_you_mean(g.held.nodes, sets)}")
        if spec.garments and spec.tools:
            self.problem(("garments",), "a task with a garment holds no tool (the garment is what the hand holds); remove tools: or garments:", key=True)

    def particles(self, value: str, path: tuple) -> str | None:
        if value not in self.spec.particles:
            pool = list(self.spec.particles)
            self.problem(path, f"unknown particle set '{value}'; expected one of {one_of(pool) or 'none (declare one under particles:)'}{did_you_mean(value, pool)}")
            return None
        return value

    # -- sections ------------------------------------------------------------------------------
    def _person(self, spec: TaskSpec) -> None:
        person = spec.person
        movable = self.person_urdf.movable_joints
        for section, values in (("joints_deg", person.joints_deg), ("randomize_deg", person.randomize_deg)):
            for name, value in values.items():
                path = ("person", section, name)
                if name not in movable:
                    self.problem(path, f"unknown person joint '{name}'; expected one of {one_of(movable)}{did_you_mean(name, movable)}", key=True)
                    continue
                j = movable[name]
                lows, highs = (value.uniform if isinstance(value, Uniform) else (value, value))
                for deg in (lows, highs):
                    rad = math.radians(deg)
                    if j.lower is not None and not (j.lower - 1e-9 <= rad <= j.upper + 1e-9):
                        self.problem(path, f"{name} = {deg:g}° is outside the joint's limits {_deg_range(j.lower, j.upper)}")
                        break
        self.policy_joints: list[str] = []
        for i, ref in enumerate(person.control.policy_joints):
            group = self.joints(ref, ("person", "control", "policy_joints", i))
            if group:
                if group["body"] != "person":
                    self.problem(("person", "control", "policy_joints", i), f"policy_joints must be person joint groups, got '{ref}'")
                else:
                    self.policy_joints += [j for j in group["joints"] if j not in self.policy_joints]
        if person.control.compliant:
            for i, ref in enumerate(person.control.compliant.joints):
                self.joints(ref, ("person", "control", "compliant", "joints", i))
        for i, choice in enumerate(person.impairments.choices):
            for k, ref in enumerate(getattr(choice, "joints", [])):
                self.joints(ref, ("person", "impairments", "choices", i, "joints", k))
        stage = person.placement.settle.then if person.placement.settle else None
        if stage is not None:
            base = ("person", "placement", "settle", "then")
            for i, ref in enumerate(stage.dynamic):
                group = self.joints(ref, base + ("dynamic", i))
                if group and group["body"] != "person":
                    self.problem(base + ("dynamic", i), f"dynamic joints must be person joint groups, got '{ref}'")
            for name, deg in stage.joints_deg.items():
                if name not in movable:
                    self.problem(base + ("joints_deg", name), f"unknown person joint '{name}'; expected one of {one_of(movable)}{did_you_mean(name, movable)}", key=True)
                elif movable[name].lower is not None and not (movable[name].lower - 1e-9 <= math.radians(deg) <= movable[name].upper + 1e-9):
                    self.problem(base + ("joints_deg", name), f"{name} = {deg:g}° is outside the joint's limits {_deg_range(movable[name].lower, movable[name].upper)}")
        seat = person.placement.seated_on
        if seat is not None:
            if seat not in spec.scene.furniture:
                pool = list(spec.scene.furniture)
                self.problem(("person", "placement", "seated_on"), f"unknown furniture '{seat}'; expected one of {one_of(pool)}{did_you_mean(seat, pool)}")
            elif self._conditional(seat, ("person", "placement", "seated_on")):
                pass
            elif seat in self.furniture and not self.furniture[seat].part.seat_link:
                self.problem(("person", "placement", "seated_on"), f"furniture '{seat}' (part '{self.furniture[seat].part.name}') has no seat_link to sit on")

    def _robot_role(self, spec: TaskSpec) -> None:
        mount = spec.robot.mount_on
        if mount is not None:
            if mount not in spec.scene.furniture:
                pool = list(spec.scene.furniture)
                self.problem(("robot", "mount_on"), f"unknown furniture '{mount}'; expected one of {one_of(pool)}{did_you_mean(mount, pool)}")
            elif mount in self.furniture and self.robot.part.mountable and not self.furniture[mount].part.mount_link:
                self.problem(("robot", "mount_on"), f"furniture '{mount}' has no mount_link for the robot")
        for name, use in spec.scene.furniture.items():
            if use.only_when_mounted and name != mount:
                self.problem(("scene", "furniture", name, "only_when_mounted"),
                             f"furniture '{name}' is only_when_mounted but the robot mounts on {repr(mount) if mount else 'nothing'} "
                             "(robot.mount_on); only the mount furniture can be left out for robots that stand on the floor")
        if spec.robot.mount_base == "search":
            use = spec.scene.furniture.get(mount) if mount else None
            if mount is None:
                self.problem(("robot", "mount_base"), "mount_base 'search' carries the mount furniture under the searched base, "
                                                      "but robot.mount_on names no furniture; set robot.mount_on or use mount_base: furniture")
            elif use is not None and not use.only_when_mounted:
                self.problem(("robot", "mount_base"), f"mount_base 'search' places furniture '{mount}' under a mounted robot's base, "
                                                      f"so without one it has no place: set scene.furniture.{mount}.only_when_mounted: true")
            elif use is not None:
                for field in ("position_m", "rpy_deg", "position_noise_m"):
                    if field in use.model_fields_set:
                        self.problem(("scene", "furniture", mount, field),
                                     f"furniture '{mount}' is carried under the robot's searched base (robot.mount_base: search), "
                                     f"so its {field} is not used; remove it (move the base search instead)")
        for name, use in spec.tools.items():
            if use.part not in self.robot.part.grips:
                self.problem(("tools", name, "part"), f"robot '{self.robot_name}' has no grip for tool '{use.part}' (add it under grips: in {self.robot.shown})")

    def limbs(self, refs: list[str], path: tuple) -> list[str]:
        """URDF names of person limbs with a capsule (a cylinder collision shape)."""
        out = []
        for i, ref in enumerate(refs):
            p = self.point(ref, path + (i,), allow_target=False)
            if p is None:
                continue
            if p["body"] != "person" or p["link"] not in self.person_urdf.capsules:
                pool = sorted(self.person_urdf.capsules)
                self.problem(path + (i,), f"'{ref}' is not a person limb with a capsule; expected one of {one_of(['person.' + l for l in pool])}")
                continue
            out.append(p["link"])
        return out

    def _targets(self, spec: TaskSpec) -> dict[str, dict[str, Any]]:
        out: dict[str, dict[str, Any]] = {}
        for name, target in spec.targets.items():
            if target.surface_of:
                links = self.limbs(target.surface_of, ("targets", name, "surface_of"))
                if links:
                    out[name] = {"body": "person", "link": links[0], "surface_links": links}
                continue
            p = self.point(target.link, ("targets", name, "link"), allow_target=False)
            for variant in target.offset_by_variant:
                if variant not in spec.person.variants:
                    self.problem(("targets", name, "offset_by_variant", variant), f"'{variant}' is not a person variant of this task; variants are {one_of(spec.person.variants)}{did_you_mean(variant, spec.person.variants)}", key=True)
            if p:
                out[name] = p
        return out

    def _markers(self, spec: TaskSpec) -> dict[str, dict[str, Any]]:
        out: dict[str, dict[str, Any]] = {}
        for name, ms in spec.markers.items():
            base = ("markers", name)
            if name in self.body_names or name in spec.targets:
                self.problem(base, f"marker set name '{name}' is already used by a body or target", key=True)
            links = self.limbs(ms.surface_of, base + ("surface_of",))
            tool = self.point(ms.cleared_by.tool, base + ("cleared_by", "tool"), allow_target=False)
            if tool is not None and tool["body"] not in spec.tools:
                self.problem(base + ("cleared_by", "tool"), f"markers are cleared by a tool link; '{ms.cleared_by.tool}' is not on a tool (tools: {one_of(spec.tools)})")
                tool = None
            if links and tool:
                out[name] = {"links": links, "tool": tool, "radius_m": ms.cleared_by.radius_m, "spacing_m": ms.spacing_m,
                             "show_rgba": ms.show_rgba}
        return out

    def _particles(self, spec: TaskSpec) -> None:
        for name, ps in spec.particles.items():
            base = ("particles", name)
            self.body(ps.attach, base + ("attach",), allow_particles=False)
            if ps.consumed_at:
                self.point(ps.consumed_at.target, base + ("consumed_at", "target"))
                if ps.consumed_at.outside_of is not None:
                    self._container(ps.consumed_at.outside_of, base + ("consumed_at", "outside_of"))
            if ps.rest is not None:
                self._container(ps.rest.container, base + ("rest", "container"))
            if ps.lost_beyond:
                self.body(ps.lost_beyond.body, base + ("lost_beyond", "body"), allow_particles=False)
            if ps.hit_body:
                self.body(ps.hit_body, base + ("hit_body",), allow_particles=False)

    def _container(self, holder: str, path: tuple) -> None:
        """``holder`` must be a tool whose part declares a container."""
        if self.body(holder, path, allow_particles=False):
            if holder not in self.tools or self.tools[holder].part.container is None:
                with_container = [t for t, part in self.tools.items() if part.part.container is not None]
                self.problem(path, f"'{holder}' is not a tool with a container; tools with one: {one_of(with_container) or 'none'}")

    def _term(self, use: Any, category: Category, path: tuple, name: str, weight: float) -> ResolvedTerm | None:
        registry = terms(category)
        if use.term not in registry:
            self.problem(path + ("term",), f"unknown {category} term '{use.term}'; expected one of {one_of(registry)}{did_you_mean(use.term, registry)}")
            return None
        params = self._params(registry[use.term], use.params, path + ("params",))
        return None if params is None else ResolvedTerm(name, use.term, category, weight, params)

    def _params(self, tdef: TermDef, raw: dict[str, Any], path: tuple) -> dict[str, Any] | None:
        try:
            model = tdef.params.model_validate(raw)
        except ValidationError as exc:
            self.problems.extend(problems_from_validation(exc, raw, self.loaded.smap, tdef.params, prefix=path))
            return None
        values = model.model_dump()
        before = len(self.problems)
        for fname, (kind, shape) in ref_fields(tdef.params).items():
            value = values[fname]
            fpath = path + (fname,)
            if shape == "optional" and value is None:
                continue
            if shape == "list":
                values[fname] = [self._ref(kind.kind, v, fpath + (i,)) for i, v in enumerate(value)]
            else:
                values[fname] = self._ref(kind.kind, value, fpath)
        return values if len(self.problems) == before else None

    def _ref(self, kind: str, value: Any, path: tuple) -> Any:
        if kind == "point":
            return self.point(value, path)
        if kind == "body":
            return self.body(value, path)
        if kind == "bodies":
            return [self.body(v, path + (i,)) for i, v in enumerate(value)]
        if kind == "joints":
            return self.joints(value, path)
        if kind == "particles":
            return self.particles(value, path)
        if kind == "nodes":
            return self.node_set(value, path)
        if kind == "markers":
            if value not in self.spec.markers:
                pool = list(self.spec.markers)
                self.problem(path, f"unknown marker set '{value}'; expected one of {one_of(pool) or 'none (declare one under markers:)'}{did_you_mean(value, pool)}")
                return None
            return value
        return value  # frame: a literal pydantic already checked

    def _preferences(self, spec: TaskSpec) -> list[ResolvedTerm | None]:
        registry = terms("preference")
        out: list[ResolvedTerm | None] = []
        for name, pref in spec.preferences.active.items():
            path = ("preferences", "active", name)
            if name not in PREFERENCE_NAMES:
                self.problem(path, f"unknown preference '{name}'; expected one of {one_of(PREFERENCE_NAMES)}{did_you_mean(name, PREFERENCE_NAMES)}", key=True)
                continue
            weight = PAPER_PREFERENCE_WEIGHTS[name] if pref.weight is None else pref.weight
            params = self._params(registry[name], pref.params, path + ("params",))
            out.append(None if params is None else ResolvedTerm(f"preference_{name}", name, "preference", weight, params))
        return out

    def _scripted(self, spec: TaskSpec) -> dict[str, Any] | None:
        if spec.scripted is None:
            return None
        known = self.lib.names("robots")
        for name in spec.scripted.per_robot:  # may name robots a spec extending this one supports
            if name not in known:
                self.problem(("scripted", "per_robot", name), f"per_robot names unknown robot '{name}'; expected one of {one_of(known)}{did_you_mean(name, known)}", key=True)
        own = spec.scripted.per_robot.get(self.robot_name)
        out = self._script(spec, own, ("scripted", "per_robot", self.robot_name)) if own is not None else self._script(spec, spec.scripted, ("scripted",))
        for side in ("left", "right"):  # a two-arm robot: the left arm's part, and the right arm's own (replacing the main one)
            arm = getattr(spec.scripted, side)
            if arm is None or len(self.sides) < 2:
                continue
            resolved = self._script(spec, arm, ("scripted", side))
            if side == "left":
                out["left"] = resolved
            else:
                out.update(resolved)
        return out

    def _script(self, spec: TaskSpec, script, base: tuple) -> dict[str, Any]:
        """One arm's script (``move``, ``waypoints``, ``repeat_from``) with its references resolved."""
        waypoints = []
        for i, w in enumerate(script.waypoints):
            to = self.point(w.to, base + ("waypoints", i, "to"))
            used = {"normal_offset_m": w.normal_offset_m != 0.0, "axis_offset_m": w.axis_offset_m != 0.0,
                    "face_normal_within_deg": w.face_normal_within_deg is not None}
            for key in used:
                if used[key] and not (w.to in spec.targets and spec.targets[w.to].surface_of):
                    self.problem(base + ("waypoints", i, key), f"{key} needs a target drawn on a surface (surface_of); '{w.to}' is not one")
            waypoints.append({"to": to, "offset_m": list(w.offset_m), "tolerance_m": w.tolerance_m,
                              "normal_offset_m": w.normal_offset_m, "axis_offset_m": w.axis_offset_m,
                              "rpy_rad": [math.radians(a) for a in w.rpy_deg] if w.rpy_deg is not None else None,
                              "face_normal_within_rad": math.radians(w.face_normal_within_deg) if w.face_normal_within_deg is not None else None}
                             | ({"step_m": w.step_m} if w.step_m is not None else {}))  # absent when unset: other artifacts unchanged
        move, where = (script.move, base + ("move",)) if script.move is not None else (spec.scripted.move, ("scripted", "move"))  # a robot's own script may keep the task's point
        return {"move": self.point(move, where), "waypoints": waypoints, "repeat_from": script.repeat_from}

    def _success(self, spec: TaskSpec, reward_names: set[str]) -> float:
        success = spec.success
        if success.term not in reward_names:
            self.problem(("success", "term"), f"unknown reward term '{success.term}'; expected one of {one_of(reward_names)}{did_you_mean(success.term, reward_names)}")
        if success.relative_to is not None:
            if success.relative_to in spec.markers:
                return success.threshold  # a fraction: the runtime multiplies by the variant's marker count
            if success.relative_to not in spec.particles:
                pool = list(spec.particles) + list(spec.markers)
                self.problem(("success", "relative_to"), f"unknown particle or marker set '{success.relative_to}'; expected one of {one_of(pool) or 'none'}{did_you_mean(success.relative_to, pool)}")
                return success.threshold
            return success.threshold * spec.particles[success.relative_to].count
        return success.threshold


def resolve(loaded: LoadedSpec, robot: str | None = None, library: Library | None = None) -> ResolvedTask:
    """Resolve ``loaded`` for ``robot`` (default: the spec's default robot)."""
    return _Resolver(loaded, library or Library(), robot or loaded.spec.robot.default).run()


def validate_all_robots(loaded: LoadedSpec, library: Library | None = None) -> list[ResolvedTask]:
    """Resolve the spec for every robot it supports; problems from all of them are reported together."""
    library = library or Library()
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
