"""The person model's reference page (``docs/person.md``): every link with its collision shape and
frame, every joint with its axis and limits, per variant where sizes differ.

Written by ``assistive-compiler person-reference``; ``tests/person/test_person_reference.py`` keeps the
page equal to what the code renders, so link names, frames and limits in the docs are always the
model's. Everything is read from the person template rendered with each variant's measurements
(the same URDF the compiler emits), nothing from a table of its own.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from .landmarks import LANDMARKS, LinkShapes, landmark_offsets, link_shapes, vec3

PAGE_VARIANTS = ("male_50th", "female_50th")
"""The variants whose sizes the page lists (the shipped tasks' two); the others scale the same way."""


def _cm(v: float) -> str:
    return f"{v * 100:.1f}"


def _xyz_cm(xyz) -> str:
    return "(" + ", ".join(_cm(v) for v in xyz) + ")"


def _shape_text(shapes: LinkShapes) -> str:
    """A link's collision shapes in words (a capsule as one shape, its end spheres part of it)."""
    out = [f"capsule r {_cm(r)}, length {_cm(length)}, centre {_xyz_cm(c)}" for c, r, length, _axis in shapes.capsules]
    out += [f"sphere r {_cm(r)}, centre {_xyz_cm(c)}" for c, r in shapes.spheres]
    return " / ".join(out)


def _axis_name(axis) -> str:
    names = {
        (1.0, 0.0, 0.0): "x",
        (0.0, 1.0, 0.0): "y",
        (0.0, 0.0, 1.0): "z",
        (-1.0, 0.0, 0.0): "−x",
        (0.0, -1.0, 0.0): "−y",
        (0.0, 0.0, -1.0): "−z",
    }
    return names.get(tuple(float(a) for a in axis), str(axis))


def _direction(xyz) -> str:
    """Which way a point lies from a frame's origin, in words (the person's zero pose)."""
    words = {0: ("left", "right"), 1: ("back", "front"), 2: ("up", "down")}
    parts = [f"{_cm(abs(v))} cm {words[k][0 if v > 0 else 1]}" for k, v in enumerate(xyz) if abs(v) >= 0.0005]
    return ", ".join(parts) or "at the origin"


def _landmark_lines(urdfs: dict[str, str], shown: str) -> list[str]:
    """The page's Landmarks section: each landmark's link, what it is and its offset (cm) per variant."""
    marks = {v: landmark_offsets(urdfs[v]) for v in PAGE_VARIANTS}
    lines = [
        "",
        "## Landmarks",
        "",
        "Named points placed from each variant's own shapes (`assistive_compiler/person/landmarks.py`),",
        "used as `person.<landmark>` wherever a point is (a waypoint's `to`, a term's point), or as a",
        "target's `link` (its `offset_m` then starts at the landmark). The joints are points already:",
        "`person.right_elbow` is the elbow joint (the forearm's frame origin), `person.right_knee` the knee,",
        "`person.right_shoulder` the shoulder, `person.right_wrist` the wrist.",
        "",
        f"| landmark | link | where | offset in the link frame (cm), {shown} |",
        "|---|---|---|---|",
    ]
    for name, lm in LANDMARKS.items():
        where = " / ".join(_xyz_cm(marks[v][name][1]) for v in PAGE_VARIANTS)
        lines.append(f"| `person.{name}` | `{lm.link}` | {lm.description} | {where} |")
    return lines


def _joint_lines(joints: list[ET.Element]) -> list[str]:
    """The page's Joints section: each joint's type, axis, parent and child links and limits (°)."""
    lines = [
        "",
        "## Joints",
        "",
        "Limits are the model's (degrees; a fixed joint is held at its angle). The policy, impairments",
        "and `joints_deg` move only the revolute ones.",
        "",
        "| joint | type | axis | parent → child | limits (°) |",
        "|---|---|---|---|---|",
    ]
    for j in joints:
        limit = j.find("limit")
        axis_el = j.find("axis")
        axis = _axis_name(vec3(axis_el.get("xyz"))) if axis_el is not None else "—"
        if limit is not None and j.get("type") == "revolute":
            limits = f"[{math.degrees(float(limit.get('lower'))):.0f}, {math.degrees(float(limit.get('upper'))):.0f}]"
        elif j.get("type") == "fixed":
            rpy = vec3(j.find("origin").get("rpy"))
            limits = f"fixed at {math.degrees(max(rpy, key=abs)):.0f}" if any(rpy) else "fixed"
        else:
            limits = "—"
        lines.append(
            f"| `{j.get('name')}` | {j.get('type')} | {axis} | `{j.find('parent').get('link')}` → "
            f"`{j.find('child').get('link')}` | {limits} |"
        )
    return lines


def person_reference_markdown() -> str:
    """The page, as Markdown."""
    from ..library import Library

    library = Library()
    urdfs = {name: library.person_urdf(name) for name in PAGE_VARIANTS}
    roots = {name: ET.fromstring(text) for name, text in urdfs.items()}
    shapes_by_variant = {name: link_shapes(text) for name, text in urdfs.items()}
    first = roots[PAGE_VARIANTS[0]]
    links = [el.get("name") for el in first.findall("link")]
    joints = first.findall("joint")
    parent_joint = {j.find("child").get("link"): j for j in joints}
    children: dict[str, list[ET.Element]] = {}
    for j in joints:
        children.setdefault(j.find("parent").get("link"), []).append(j)
    joints_by_variant = {name: {el.get("name"): el for el in root.findall("joint")} for name, root in roots.items()}
    shown = " / ".join(PAGE_VARIANTS)

    lines = [
        "# The person model",
        "",
        "<!-- written by `assistive-compiler person-reference`; tests/person/test_person_reference.py keeps it equal to the code -->",
        "",
        "Every link and joint of the person (`templates/person/person.urdf.xacro`, rendered with each",
        "variant's measurements in `specs/people/`), as a spec refers to them: a point is",
        "`person.<link>` (its frame's origin), a target is `{link: person.<link>, offset_m: [x, y, z]}`",
        "(the offset in that link's frame, metres), a marker or surface target covers",
        "`surface_of: [person.<link>]` (any link with a shape below, optionally a `region` of it).",
        "",
        "**Frames.** At the person's zero pose every link frame is parallel to the person's base frame:",
        "**+x is the person's left, −y is the way the person faces (front), +z is up** (toward the head).",
        "A joint sits at its child link's frame origin; a limb's capsule hangs from its joint along −z",
        "(the upper arm from the shoulder toward the elbow, the shin from the knee toward the ankle), so",
        "a point along a limb has a negative z in its frame. Seated and supine postures rotate the frames",
        "with the joints; a task's `person.posture` and `joints_deg` set them.",
        "",
        "**Names follow the reference's model: a limb link is named after the joint at its top.**",
        "`right_shoulder` is the upper arm, `right_elbow` the forearm, `right_wrist` the hand,",
        "`right_hip` the thigh, `right_knee` the shin, `right_ankle` the foot (the same on the left);",
        "`head`, `neck`, `chest`, `waist`, `stomach` and `*_pecs` (the shoulder girdle) are what they say.",
        "Offsets along a limb are negative z in its frame: the middle of male_50th's right forearm is",
        "`{link: person.right_elbow, offset_m: [0, 0, -0.128]}` (the capsule's centre in the table below),",
        "and its wrist joint is 29.0 cm down that frame (`right_wrist_x`).",
        "",
        f"Sizes are centimetres for the variants {shown} (each variant scales its own segments:",
        "`render-person SPEC` draws them). Links without a shape are the joint links of a",
        "multi-axis joint (shoulder, hip, ankle ...): they carry mass but no collision shape.",
        "",
        "## Links",
        "",
        "| link | joint that moves it | collision shape | next joints, from this frame's origin |",
        "|---|---|---|---|",
    ]
    for name in links:
        joint = parent_joint.get(name)
        moved_by = f"`{joint.get('name')}` ({joint.get('type')})" if joint is not None else "— (root)"
        shapes = [_shape_text(shapes_by_variant[v][name]) for v in PAGE_VARIANTS]
        shape_text = (
            shapes[0] if len(set(shapes)) == 1 else "<br>".join(f"{v}: {s}" for v, s in zip(PAGE_VARIANTS, shapes))
        )
        nexts = []
        for child in children.get(name, []):
            xyz = [vec3(joints_by_variant[v][child.get("name")].find("origin").get("xyz")) for v in PAGE_VARIANTS]
            where = _direction(xyz[0]) + (
                f" ({_direction(xyz[1])})" if _direction(xyz[1]) != _direction(xyz[0]) else ""
            )
            nexts.append(f"`{child.get('name')}`: {where}")
        lines.append(f"| `{name}` | {moved_by} | {shape_text or 'none'} | {'<br>'.join(nexts) or '—'} |")
    lines += _landmark_lines(urdfs, shown) + _joint_lines(joints)
    return "\n".join(lines) + "\n"
