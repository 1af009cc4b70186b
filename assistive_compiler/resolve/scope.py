"""The names a task may refer to on one robot, and how a reference to each resolves.

A :class:`Scope` holds the library parts a task uses (robot, tools, furniture, people), the body
names its sections declare, the robot's semantic links and the joint groups, and collects located
problems (it is a :class:`~.located.Collector`). The section passes fill it in (see
:func:`assistive_compiler.resolve.resolve` for the order) and ask it to resolve references:

* point → :class:`~assistive_compiler.references.TargetPoint` (a target's name) or ``LinkPoint``
  (a body and its URDF link name)
* body → body name; bodies → list of body names
* joints → :class:`~assistive_compiler.references.JointGroup`
* node set → :class:`~assistive_compiler.references.NodeSet`
* particle set, marker set → their name
"""

from __future__ import annotations

from typing import Any

from ..errors import SpecError, did_you_mean, one_of
from ..library import Library, LoadedPart
from ..references import JointGroup, LinkPoint, NodeSet, Point, TargetPoint
from ..spec.load import LoadedSpec
from ..urdf import UrdfInfo
from .located import Collector, expected

RESERVED_BODIES = ("robot", "person")


GARMENT_HELD_LINK = "held"
"""The one link of a garment body: its held frame (the pose the robot's hand gives it)."""
ROBOT_SEMANTIC_LINKS = ("base", "end_effector", "tool_mount")


class Scope(Collector):
    """One task on one robot: its parts, names and references, and the problems found so far."""

    robot: LoadedPart
    tools: dict[str, LoadedPart]
    furniture: dict[str, LoadedPart]
    people: dict[str, LoadedPart]
    robot_urdf: UrdfInfo
    person_urdf: UrdfInfo
    sides: tuple[str, ...]
    body_names: dict[str, str]
    """Every body name -> the section declaring it ("robot", "person", "tools", "particles", ...)."""
    robot_links: dict[str, str]
    joint_groups: dict[str, JointGroup]

    def __init__(self, loaded: LoadedSpec, library: Library, robot_name: str):
        super().__init__(loaded)
        self.spec = loaded.spec
        self.lib = library
        self.robot_name = robot_name
        self.tool_aliases: dict[str, str] = {}
        self.policy_joints: list[str] = []

    def part(self, kind: str, name: str, path: tuple, what: str) -> LoadedPart | None:
        """The library part ``name`` of ``kind`` (None and a problem when there is none)."""
        try:
            return self.lib.get(kind, name)
        except KeyError:
            self.problem(
                path, f"unknown {what} '{name}'; {expected(self.lib.names(kind), name)}{self.lib.searched(kind)}"
            )
        except SpecError as exc:
            self.problems.extend(exc.problems)
        return None

    # -- links of bodies -----------------------------------------------------------------------
    def links_of(self, body: str) -> dict[str, str]:
        """The link names a reference may use on ``body`` -> URDF link names."""
        if body == "robot":
            return self.robot_links
        if body == "person":
            return {link: link for link in self.person_urdf.links}
        if body in self.tools:
            return dict(self.tools[body].part.links) | {"base": self.tools[body].part.base_link}
        if body in self.furniture:
            return dict(self.furniture[body].part.links) | {"base": self.furniture[body].part.base_link}
        if body in self.spec.garments:
            return {GARMENT_HELD_LINK: GARMENT_HELD_LINK}
        return {}

    def reference_link(self, body: str) -> str | None:
        """The URDF link a bare body name (no ``.link``) refers to."""
        if body == "robot":
            return self.robot_links["end_effector"]
        if body == "person":
            return self.person_urdf.root_link
        if body in self.tools:
            tool = self.tools[body].part
            return tool.links[tool.reference_link]
        if body in self.furniture:
            return self.furniture[body].part.base_link
        if body in self.spec.garments:
            return GARMENT_HELD_LINK
        return None

    # -- references ----------------------------------------------------------------------------
    def body(self, value: str, path: tuple, *, allow_particles: bool = True) -> str | None:
        pool = [b for b, section in self.body_names.items() if allow_particles or section != "particles"]
        if value not in pool:
            self.problem(path, f"unknown body '{value}'; {expected(pool, value)}")
            return None
        if self.conditional(value, path):
            return None
        return self.tool_aliases.get(value, value)

    def conditional(self, body: str, path: tuple) -> bool:
        """True (and a problem) when ``body`` is furniture present only under a mounted robot."""
        use = self.spec.scene.furniture.get(body)
        if use is None or not use.only_when_mounted:
            return False
        self.problem(
            path,
            f"furniture '{body}' is in the scene only when the robot is mounted on it (only_when_mounted: true), "
            "so nothing may refer to it; refer to furniture that is always there",
        )
        return True

    def point(self, value: str, path: tuple) -> Point | None:
        """A point reference: a target's name, or a body's link (:meth:`link_point`)."""
        if value in self.spec.targets:
            return TargetPoint(target=value)
        return self.link_point(value, path, targets_too=True)

    def link_point(self, value: str, path: tuple, *, targets_too: bool = False) -> LinkPoint | None:
        """``body`` (its reference link) or ``body.link`` → the body and its URDF link name.
        ``targets_too``: the problem's list of names also offers the targets (a :meth:`point`)."""
        body, _, link = value.partition(".")
        if body in self.body_names:
            body = self.tool_aliases.get(body, body)  # a one-arm robot's second name for its tool
        if body not in self.body_names or self.body_names[body] == "particles":
            pool = [b for b, s in self.body_names.items() if s != "particles"] + (
                list(self.spec.targets) if targets_too else []
            )
            what = "target or body" if targets_too else "body"
            self.problem(path, f"unknown {what} '{value}'; {expected(pool, body)}")
            return None
        if self.conditional(body, path):
            return None
        if not link:
            return LinkPoint(body=body, link=self.reference_link(body))
        links = self.links_of(body)
        if link not in links:
            if body == "person":
                self.problem(path, unknown_person_link(link, links))
            else:
                self.problem(path, f"unknown link '{link}' of {body}; {expected(links, link)}")
            return None
        return LinkPoint(body=body, link=links[link])

    def surface_links(self, refs: list[str], path: tuple) -> list[str]:
        """URDF names of person links with a collision shape (capsule or sphere) to cover."""
        out = []
        for i, ref in enumerate(refs):
            p = self.link_point(ref, path + (i,))
            if p is None:
                continue
            if p.body != "person" or p.link not in self.person_urdf.surface_links:
                pool = ["person." + link for link in self.person_urdf.surface_links]
                self.problem(
                    path + (i,), f"'{ref}' is not a person link with a collision shape; {expected(pool, ref, limit=21)}"
                )
                continue
            out.append(p.link)
        return out

    def joints(self, value: str, path: tuple) -> JointGroup | None:
        if value == "person.policy":
            return JointGroup(body="person", group="policy", joints=tuple(self.policy_joints))
        if value not in self.joint_groups:
            pool = list(self.joint_groups) + ["person.policy"]
            self.problem(path, f"unknown joint group '{value}'; {expected(pool, value, limit=20)}")
            return None
        return self.joint_groups[value]

    def node_set(self, value: str, path: tuple) -> NodeSet | None:
        """``<garment>.<set>`` → its :class:`NodeSet` (node indices of the generated mesh)."""
        from ..garment import sleeve_node_sets

        name, _, set_name = value.partition(".")
        if self.declared(name, path, "garments", "garment") is None:
            return None
        shape = self.spec.garments[name].shape
        sets = sleeve_node_sets(shape.rings, shape.segments)
        if set_name not in sets:
            self.problem(
                path,
                f"unknown node set '{set_name}' of garment '{name}'; {expected(sets, set_name)} (write {name}.<set>)",
            )
            return None
        return NodeSet(garment=name, set=set_name, nodes=tuple(int(i) for i in sets[set_name]))

    def declared(self, value: str, path: tuple, section: str, what: str) -> str | None:
        """``value`` if the spec's ``section`` (particles, markers, garments) declares it."""
        declared = getattr(self.spec, section)
        if value not in declared:
            self.problem(
                path,
                f"unknown {what} '{value}'; {expected(declared, value, empty=f'none (declare one under {section}:)')}",
            )
            return None
        return value

    def ref(self, kind: str, value: Any, path: tuple) -> Any:
        """A term parameter's reference of ``kind`` (see terms.registry.ref_fields), resolved."""
        if kind == "point":
            return self.point(value, path)
        if kind == "body":
            return self.body(value, path)
        if kind == "bodies":
            return [self.body(v, path + (i,)) for i, v in enumerate(value)]
        if kind == "joints":
            return self.joints(value, path)
        if kind == "particles":
            return self.declared(value, path, "particles", "particle set")
        if kind == "nodes":
            return self.node_set(value, path)
        if kind == "markers":
            return self.declared(value, path, "markers", "marker set")
        return value  # frame: a literal pydantic already checked


PERSON_PART_LINKS = {
    "hand": "wrist",
    "palm": "wrist",
    "fingers": "wrist",
    "forearm": "elbow",
    "upper_arm": "shoulder",
    "arm": "shoulder",
    "thigh": "hip",
    "leg": "hip",
    "shin": "knee",
    "calf": "knee",
    "lower_leg": "knee",
    "foot": "ankle",
    "heel": "ankle",
    "toes": "ankle",
}
"""Body parts by their everyday names → the person link that is that part (a limb link is named
after the joint at its top, the reference's naming: the hand is ``right_wrist``)."""


PERSON_PART_LANDMARKS = {
    "hand": ("palm", "fingertips"),
    "palm": ("palm",),
    "fingers": ("fingertips",),
    "foot": ("heel", "toes"),
    "heel": ("heel",),
    "toes": ("toes",),
}
"""Body parts → the landmarks on them (``person.right_palm`` ...)."""


def unknown_person_link(link: str, links) -> str:
    """The message for ``person.<link>`` that is not a link: the link that is that body part when
    ``link`` names one (``right_hand`` → ``right_wrist``), else the closest names; and where all 43
    links and their frames are listed."""
    from ..person.landmarks import LANDMARKS

    where = f"; all {len(links)} links of the person and their frames: docs/person.md; landmarks: " + ", ".join(
        LANDMARKS
    )
    side, _, part = link.partition("_") if link.startswith(("right_", "left_")) else ("", "", link)
    if part in PERSON_PART_LINKS:
        names = (
            [f"{side}_{PERSON_PART_LINKS[part]}"]
            if side
            else [f"right_{PERSON_PART_LINKS[part]}", f"left_{PERSON_PART_LINKS[part]}"]
        )
        if all(n in links for n in names):
            points = [f"person.{side}_{lm}" for lm in PERSON_PART_LANDMARKS.get(part, ())] if side else []
            on_it = f", and person points on it: {', '.join(points)}" if points else ""
            return (
                f"unknown link '{link}' of person; the {part.replace('_', ' ')} is link {' or '.join(repr(n) for n in names)} "
                f"(limb links are named after the joint at their top){on_it}{where}"
            )
    # The closest name among the links and the landmarks: both are written person.<name>.
    guess = did_you_mean(link, [*links, *LANDMARKS])
    return f"unknown link '{link}' of person; expected one of {one_of(links)}{guess}{where}"
