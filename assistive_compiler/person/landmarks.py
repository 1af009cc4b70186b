"""Named landmarks on the person: points such as the mouth, the top of the head or a palm, each on one link,
placed from that link's collision shapes so that it scales with every person variant.

A spec uses one wherever it uses a point, as ``person.<landmark>`` (a waypoint's ``to``, a term's
point parameter, a camera), or as the ``link`` of a target, whose ``offset_m`` then starts from the
landmark. The joints are points already: a limb link's frame sits at the joint at its top, so
``person.right_elbow`` is the elbow joint, ``person.right_knee`` the knee, ``person.right_shoulder``
the shoulder (see docs/person.md).

Offsets are in the landmark's link frame, metres, at the person's zero pose: +x the person's left,
-y the front, +z up (toward the head); limbs hang along -z.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from ..urdf import urdf_info

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Landmark:
    """A named point: the link it is on and how its offset follows from that link's shapes."""

    link: str
    description: str
    offset: Callable[[LinkShapes], Vec3]


@dataclass(frozen=True)
class LinkShapes:
    """A link's collision spheres and capsules (link frame, m): (centre, radius) and (centre, radius,
    length, axis index 0/1/2)."""

    spheres: tuple[tuple[Vec3, float], ...]
    capsules: tuple[tuple[Vec3, float, float, int], ...]


def _front_at(shapes: LinkShapes, z: float) -> float:
    """The most forward (-y) surface point of a link's spheres at height ``z`` (x = 0)."""
    ys = [c[1] - math.sqrt(r * r - (z - c[2]) ** 2) for c, r in shapes.spheres if abs(z - c[2]) < r]
    return min(ys)


def _jaw(shapes: LinkShapes) -> tuple[Vec3, float]:
    """The head's smaller sphere (the face and jaw; the larger is the cranium)."""
    return min(shapes.spheres, key=lambda s: s[1])


def _mouth(s: LinkShapes) -> Vec3:
    (cx, cy, cz), r = _jaw(s)
    return (0.0, _front_at(s, cz), cz)


def _chin(s: LinkShapes) -> Vec3:
    (cx, cy, cz), r = _jaw(s)
    a = math.radians(45)
    return (0.0, cy - r * math.cos(a), cz - r * math.sin(a))


def _nose(s: LinkShapes) -> Vec3:
    (cx, cy, cz), r = _jaw(s)
    z = cz + 0.6 * r
    return (0.0, _front_at(s, z), z)


def _cheek(sign: float) -> Callable[[LinkShapes], Vec3]:
    def offset(s: LinkShapes) -> Vec3:
        (cx, cy, cz), r = _jaw(s)
        a = math.radians(50)  # around the face from the front, toward the side
        return (sign * r * math.sin(a), cy - r * math.cos(a), cz + 0.2 * r)

    return offset


def _cranium(shapes: LinkShapes) -> tuple[Vec3, float]:
    """The head's larger sphere (the cranium; the smaller is the face and jaw)."""
    return max(shapes.spheres, key=lambda s: s[1])


def _top_of_head(s: LinkShapes) -> Vec3:
    (cx, cy, cz), r = _cranium(s)
    return (cx, cy, cz + r)


def _forehead(s: LinkShapes) -> Vec3:
    (cx, cy, cz), r = _cranium(s)
    a = math.radians(25)  # up from the cranium's front, above the brows
    return (cx, cy - r * math.cos(a), cz + r * math.sin(a))


def _ear(sign: float) -> Callable[[LinkShapes], Vec3]:
    def offset(s: LinkShapes) -> Vec3:
        (cx, cy, cz), r = _cranium(s)
        a = math.radians(20)  # down from the cranium's side, about the nose's height
        return (cx + sign * r * math.cos(a), cy, cz - r * math.sin(a))

    return offset


def _hand(s: LinkShapes) -> tuple[Vec3, float]:
    return max(s.spheres, key=lambda sphere: sphere[1])


def _palm(toward_body: float) -> Callable[[LinkShapes], Vec3]:
    """The palm's centre: on the hand's surface on the side that faces the body at the zero pose."""

    def offset(s: LinkShapes) -> Vec3:
        (cx, cy, cz), r = _hand(s)
        return (cx + toward_body * r, cy, cz)

    return offset


def _fingertips(s: LinkShapes) -> Vec3:
    (cx, cy, cz), r = _hand(s)
    return (cx, cy, cz - r)


def _foot(s: LinkShapes) -> tuple[Vec3, float, float]:
    centre, radius, length, axis = s.capsules[0]
    return centre, radius, length


def _heel(s: LinkShapes) -> Vec3:
    (cx, cy, cz), r, length = _foot(s)
    return (cx, cy + length / 2.0, cz - r)


def _toes(s: LinkShapes) -> Vec3:
    (cx, cy, cz), r, length = _foot(s)
    return (cx, cy - length / 2.0, cz)


LANDMARKS: dict[str, Landmark] = {
    "mouth": Landmark("head", "the front of the face at the jaw's centre height (the lips)", _mouth),
    "chin": Landmark("head", "the jaw's front-bottom, 45° below its front", _chin),
    "nose": Landmark("head", "the front of the face 0.6 jaw radii above the mouth", _nose),
    "right_cheek": Landmark("head", "the face's right side, 50° round from the front", _cheek(-1.0)),
    "left_cheek": Landmark("head", "the face's left side, 50° round from the front", _cheek(1.0)),
    "top_of_head": Landmark("head", "the top of the cranium (the crown of the head)", _top_of_head),
    "forehead": Landmark("head", "the front of the cranium 25° above its centre (above the brows)", _forehead),
    "right_ear": Landmark(
        "head", "the cranium's right side 20° below its centre (about the nose's height)", _ear(-1.0)
    ),
    "left_ear": Landmark("head", "the cranium's left side 20° below its centre (about the nose's height)", _ear(1.0)),
    "right_palm": Landmark(
        "right_wrist", "the right hand's surface toward the body (the palm's centre at the zero pose)", _palm(1.0)
    ),
    "left_palm": Landmark(
        "left_wrist", "the left hand's surface toward the body (the palm's centre at the zero pose)", _palm(-1.0)
    ),
    "right_fingertips": Landmark("right_wrist", "the right hand's far end", _fingertips),
    "left_fingertips": Landmark("left_wrist", "the left hand's far end", _fingertips),
    "right_heel": Landmark("right_ankle", "the bottom of the right foot's back end", _heel),
    "left_heel": Landmark("left_ankle", "the bottom of the left foot's back end", _heel),
    "right_toes": Landmark("right_ankle", "the centre of the right foot's front end", _toes),
    "left_toes": Landmark("left_ankle", "the centre of the left foot's front end", _toes),
}
"""Every landmark by name (``person.<name>`` in a spec)."""


def vec3(text: str | None) -> Vec3:
    """A URDF ``xyz`` / ``rpy`` attribute as three floats (absent: zeros)."""
    return tuple(float(v) for v in (text or "0 0 0").split())  # type: ignore[return-value]


def link_shapes(urdf_xml: str) -> dict[str, LinkShapes]:
    """Each link's collision spheres and capsule (its cylinder; the end spheres are part of it), as
    :func:`assistive_compiler.urdf.urdf_info` reads them: centres in the link frame, m."""
    info = urdf_info(urdf_xml)
    out: dict[str, LinkShapes] = {}
    for link in info.links:
        spheres = tuple((s.centre, s.radius) for s in info.spheres.get(link, ()))
        cap = info.capsules.get(link)
        capsules: tuple[tuple[Vec3, float, float, int], ...] = ()
        if cap is not None:
            centre = tuple((a + b) / 2 for a, b in zip(cap.start, cap.end))
            axis = max(range(3), key=lambda k: abs(cap.end[k] - cap.start[k]))
            capsules = ((centre, cap.radius, cap.length, axis),)  # type: ignore[assignment]
        out[link] = LinkShapes(spheres, capsules)
    return out


def landmark_offsets(urdf_xml: str) -> dict[str, tuple[str, Vec3]]:
    """Every landmark of the person ``urdf_xml`` (one variant): name -> (link, offset in the link
    frame, m, rounded to 0.1 mm)."""
    shapes = link_shapes(urdf_xml)
    return {
        name: (lm.link, tuple(round(v, 4) + 0.0 for v in lm.offset(shapes[lm.link])))  # type: ignore[misc]
        for name, lm in LANDMARKS.items()
    }
