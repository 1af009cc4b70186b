"""What a URDF declares, read without a simulator: its links, its joints with their limits, and the
collision capsules and spheres of each link (link frame, metres, radians). The compiler checks
references against it, the resolver names a robot's and a person's links with it, and the person's
surface (markers, surface targets) is laid out over its shapes."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from .rotation import rpy_matrix


@dataclass(frozen=True)
class JointInfo:
    """A URDF joint: type, parent/child links, limits (radians or metres; None when absent)."""

    name: str
    type: str
    parent: str
    child: str
    lower: float | None
    upper: float | None
    axis: tuple[float, float, float]


@dataclass(frozen=True)
class Capsule:
    """The cylinder of a link's capsule (cylinder + two spheres), in the link frame: its axis from
    ``start`` (the end nearer the link origin, i.e. the joint) to ``end``, and its radius (m)."""

    start: tuple[float, float, float]
    end: tuple[float, float, float]
    radius: float

    @property
    def length(self) -> float:
        return math.dist(self.start, self.end)


@dataclass(frozen=True)
class Sphere:
    """A collision sphere of a link in the link frame: its centre and radius (m)."""

    centre: tuple[float, float, float]
    radius: float


@dataclass(frozen=True)
class UrdfInfo:
    """Names declared by a URDF, for cross-reference checks."""

    root_link: str
    links: tuple[str, ...]
    joints: dict[str, JointInfo]
    capsules: dict[str, Capsule]
    root_tag: str = "robot"
    spheres: dict[str, tuple[Sphere, ...]] = field(default_factory=dict)
    """Each link's collision spheres that are not the end caps of its capsule."""

    @property
    def surface_links(self) -> tuple[str, ...]:
        """Links with a collision capsule or sphere (what markers and surface targets may cover)."""
        return tuple(link for link in self.links if link in self.capsules or link in self.spheres)

    @property
    def movable_joints(self) -> dict[str, JointInfo]:
        return {n: j for n, j in self.joints.items() if j.type in ("revolute", "prismatic", "continuous")}


def urdf_info(urdf_xml: str) -> UrdfInfo:
    """Link and joint names (and joint limits) declared by ``urdf_xml``."""
    root = ET.fromstring(urdf_xml)
    links = tuple(el.get("name", "") for el in root.findall("link"))
    joints: dict[str, JointInfo] = {}
    children: set[str] = set()
    for el in root.findall("joint"):
        limit = el.find("limit")
        axis_el = el.find("axis")
        axis = tuple(float(v) for v in axis_el.get("xyz", "1 0 0").split()) if axis_el is not None else (1.0, 0.0, 0.0)
        jtype = el.get("type", "")
        lower = upper = None
        if limit is not None and jtype in ("revolute", "prismatic"):
            lower, upper = float(limit.get("lower", "0")), float(limit.get("upper", "0"))
        if jtype == "continuous":
            lower, upper = -math.inf, math.inf
        child = el.find("child").get("link", "")  # type: ignore[union-attr]
        children.add(child)
        joints[el.get("name", "")] = JointInfo(
            el.get("name", ""),
            jtype,
            el.find("parent").get("link", ""),
            child,
            lower,
            upper,
            axis,  # type: ignore[union-attr]
        )
    roots = [link for link in links if link not in children]
    capsules = _capsules(root)
    return UrdfInfo(roots[0] if roots else "", links, joints, capsules, root.tag, _spheres(root, capsules))


def _spheres(root: ET.Element, capsules: dict[str, Capsule]) -> dict[str, tuple[Sphere, ...]]:
    """Each link's collision spheres, leaving out the two that cap its capsule's cylinder."""
    out: dict[str, tuple[Sphere, ...]] = {}
    for link in root.findall("link"):
        name, cap = link.get("name", ""), capsules.get(link.get("name", ""))
        found = []
        for col in link.findall("collision"):
            sphere = col.find("geometry/sphere")
            if sphere is None:
                continue
            origin = col.find("origin")
            centre = tuple(float(v) for v in (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split())
            radius = float(sphere.get("radius", "0"))
            if (
                cap is not None
                and abs(radius - cap.radius) < 1e-9
                and min(math.dist(centre, cap.start), math.dist(centre, cap.end)) < 1e-6
            ):
                continue
            found.append(Sphere(centre, radius))  # type: ignore[arg-type]
        if found:
            out[name] = tuple(found)
    return out


def _capsules(root: ET.Element) -> dict[str, Capsule]:
    """Each link's first collision cylinder, as a capsule axis in the link frame."""
    out: dict[str, Capsule] = {}
    for link in root.findall("link"):
        for col in link.findall("collision"):
            cyl = col.find("geometry/cylinder")
            if cyl is None:
                continue
            origin = col.find("origin")
            xyz = [float(v) for v in (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split()]
            rpy = [float(v) for v in (origin.get("rpy", "0 0 0") if origin is not None else "0 0 0").split()]
            half = float(cyl.get("length", "0")) / 2
            axis = [float(v) for v in rpy_matrix(rpy)[:, 2]]
            a = tuple(c - half * d for c, d in zip(xyz, axis))
            b = tuple(c + half * d for c, d in zip(xyz, axis))
            start, end = (a, b) if math.hypot(*a) <= math.hypot(*b) else (b, a)
            out[link.get("name", "")] = Capsule(start, end, float(cyl.get("radius", "0")))
            break
    return out
