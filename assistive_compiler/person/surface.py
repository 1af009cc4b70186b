"""Points on the surface of a person link, where markers are laid out and surface targets drawn.

A link's surface is the outside of its collision shapes (link frame, metres): a limb's capsule, the
head's two spheres (cranium and face), a hand's sphere. Each point carries its outward normal and
an axis along the surface (for a capsule the limb's axis away from the joint; for a sphere the
direction toward the link's +z, or +x at its poles), both unit vectors in the link frame.

A capsule is covered as the reference lays out its wiping markers (``capsule_points``): rings along
its cylinder, the caps left out. A sphere is covered by a Fibonacci lattice of about
4πr² / spacing² points. Points inside another shape of the same link (where the face sphere sinks
into the cranium) are not on the surface and are dropped. A :class:`Region` then keeps part of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..rotation import capsule_axes
from ..urdf import Capsule, Sphere, UrdfInfo

Vec3 = tuple[float, float, float]

SURFACE_TARGET_SPACING_M = 0.01
"""Spacing of the points a surface target is drawn from where it is not drawn on a capsule."""

INSIDE_TOLERANCE_M = 1e-4
"""A point this far inside another shape of its link already counts as covered by it."""


@dataclass(frozen=True)
class SurfacePoint:
    """A point on a link's surface: link frame position, outward normal and an along-surface axis."""

    link: str
    offset: Vec3
    normal: Vec3
    axis: Vec3


@dataclass(frozen=True)
class Region:
    """The part of a link's surface to keep (every criterion given must hold), link frame.

    ``centre``/``radius``: within ``radius`` metres of ``centre`` (straight-line distance).
    ``facing``/``max_angle``: outward normal within ``max_angle`` radians of the unit ``facing``.
    ``along``: on a capsule, between these fractions of its cylinder's length from the joint end.
    """

    centre: Vec3 | None = None
    radius: float | None = None
    facing: Vec3 | None = None
    max_angle: float | None = None
    along: tuple[float, float] | None = None

    def keeps(self, p: SurfacePoint, capsule: Capsule | None) -> bool:
        if self.centre is not None and math.dist(p.offset, self.centre) > self.radius + 1e-9:  # type: ignore[operator]
            return False
        if self.facing is not None:
            cos = float(np.dot(p.normal, self.facing))
            if cos < math.cos(self.max_angle) - 1e-9:  # type: ignore[arg-type]
                return False
        if self.along is not None and capsule is not None:
            length, axis, _, _ = capsule_axes(capsule.start, capsule.end)
            t = float(np.dot(np.subtract(p.offset, capsule.start), axis)) / length
            if not self.along[0] - 1e-9 <= t <= self.along[1] + 1e-9:
                return False
        return True


def capsule_rings(link: str, cap: Capsule, spacing: float) -> list[SurfacePoint]:
    """The reference's capsule_points: int(L/spacing) rings at L·(i+1)/(n+1) from the joint end,
    each with int(2πr/spacing) points spacing/r radians apart (male right arm: 81 + 48)."""
    start, r = np.asarray(cap.start), cap.radius
    length, axis, u, v = capsule_axes(cap.start, cap.end)
    rings, per_ring = int(length / spacing), int(2 * math.pi * r / spacing)
    out = []
    for i in range(rings):
        centre = start + axis * length * (i + 1) / (rings + 1)
        for k in range(per_ring):
            a = k * spacing / r
            normal = math.cos(a) * u + math.sin(a) * v
            out.append(SurfacePoint(link, _vec(centre + r * normal), _vec(normal), _vec(axis)))
    return out


def sphere_lattice(link: str, sphere: Sphere, spacing: float) -> list[SurfacePoint]:
    """About 4πr²/spacing² points spread evenly over a sphere (a Fibonacci lattice), the first at
    its top (+z of the link frame)."""
    r = sphere.radius
    n = max(1, round(4 * math.pi * r * r / (spacing * spacing)))
    golden = math.pi * (3 - math.sqrt(5))
    out = []
    for i in range(n):
        z = 1 - (2 * i + 1) / n
        ring = math.sqrt(max(0.0, 1 - z * z))
        normal = np.array([ring * math.cos(golden * i), ring * math.sin(golden * i), z])
        out.append(
            SurfacePoint(link, _vec(np.asarray(sphere.centre) + r * normal), _vec(normal), _vec(_sphere_axis(normal)))
        )
    return out


def _sphere_axis(normal: np.ndarray) -> np.ndarray:
    """The tangent toward +z (the link's "up"), or toward +x where the normal is ±z."""
    toward = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.99 else np.array([1.0, 0.0, 0.0])
    t = toward - normal * float(np.dot(toward, normal))
    return t / np.linalg.norm(t)


def _inside(point: np.ndarray, shapes: list[Capsule | Sphere]) -> bool:
    for s in shapes:
        if isinstance(s, Sphere):
            if math.dist(point, s.centre) < s.radius - INSIDE_TOLERANCE_M:
                return True
        elif float(np.linalg.norm(point - axis_point(s.start, s.end, point))) < s.radius - INSIDE_TOLERANCE_M:
            return True
    return False


def axis_point(start, end, point: np.ndarray) -> np.ndarray:
    """The point of a capsule's axis (the segment ``start``-``end``, a sphere's centre when they
    are equal) nearest to ``point``; all in one frame, m."""
    a, b = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    ab = b - a
    length2 = float(ab @ ab)
    t = 0.0 if length2 < 1e-12 else min(1.0, max(0.0, float((point - a) @ ab) / length2))
    return a + t * ab


def link_surface(info: UrdfInfo, link: str, spacing: float, region: Region | None = None) -> list[SurfacePoint]:
    """Points every ``spacing`` metres over ``link``'s surface (see the module docstring), kept by
    ``region`` when one is given; in a fixed order (capsule rings first, then each sphere)."""
    capsule = info.capsules.get(link)
    shapes: list[Capsule | Sphere] = ([capsule] if capsule else []) + list(info.spheres.get(link, ()))
    out = []
    for i, shape in enumerate(shapes):
        points = (
            capsule_rings(link, shape, spacing) if isinstance(shape, Capsule) else sphere_lattice(link, shape, spacing)
        )
        others = shapes[:i] + shapes[i + 1 :]
        out += [p for p in points if not _inside(np.asarray(p.offset), others)]
    if region is not None:
        out = [p for p in out if region.keeps(p, capsule)]
    return out


def _vec(a) -> Vec3:
    return tuple(float(v) for v in a)  # type: ignore[return-value]
