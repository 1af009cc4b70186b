"""Where a lane that follows a surface goes (a waypoint's ``along_surface_of``): the nearest point
of a link's collision shapes (spheres and capsules, link frame) and the outward normal there.

Pure NumPy; the scripted policy (:mod:`assistive_compiler.policies.scripted`) puts each look-ahead
of such a lane through :func:`onto_surface`, so the moved point slides over the surface (over a
sphere, along a great circle: the central projection of the chord) instead of cutting through it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..person.surface import axis_point

Shape = tuple[np.ndarray, np.ndarray, float]
"""A capsule in a link frame: its axis's two ends (equal for a sphere) and its radius, m."""


def shapes_of(shapes: Sequence) -> list[Shape]:
    """The artifact's :class:`~assistive_compiler.artifact.SurfaceShape` list as NumPy shapes."""
    return [(np.asarray(s.start, dtype=float), np.asarray(s.end, dtype=float), float(s.radius)) for s in shapes]


def signed_distance(shape: Shape, p: np.ndarray) -> float:
    """Distance from ``p`` to the shape's surface, m (negative inside)."""
    return float(np.linalg.norm(p - axis_point(shape[0], shape[1], p))) - shape[2]


def onto_surface(shapes: Sequence[Shape], p: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The point of the union of ``shapes``' surface nearest to ``p`` along each shape's radial
    direction, and the outward unit normal there (both in the shapes' frame). Of the shapes'
    radial points those inside no other shape count; the nearest of them wins (so a point inside
    the head's cranium goes out radially through the cranium, not into the jaw)."""
    p = np.asarray(p, dtype=float)
    candidates: list[tuple[float, np.ndarray, np.ndarray]] = []
    for shape in shapes:
        c = axis_point(shape[0], shape[1], p)
        d = p - c
        n = float(np.linalg.norm(d))
        normal = d / n if n > 1e-9 else np.array([0.0, 0.0, 1.0])
        q = c + shape[2] * normal
        outside = all(signed_distance(other, q) >= -1e-6 for other in shapes if other is not shape)
        candidates.append((abs(n - shape[2]) + (0.0 if outside else 1e3), q, normal))
    _, q, normal = min(candidates, key=lambda item: item[0])
    return q, normal
