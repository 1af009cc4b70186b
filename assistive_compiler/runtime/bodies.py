"""The world's loaded bodies as handles (pybullet ids and name → index tables), and where
inactive bodies wait (:data:`PARK`, world frame, m)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

PARK = (
    0.0,
    500.0,
    50.0,
)  # where inactive bodies (other person variants, removed particles) wait: far away, beyond the floor's edge, m


@dataclass
class BodyHandle:
    """A loaded body: its pybullet id and name → index tables (base link is index -1)."""

    name: str
    id: int
    links: dict[str, int]
    joints: dict[str, int]
    inertial_inv: tuple  # inverse of the base's local inertial frame (COM → URDF frame)
    pose_id: int | None = None  # body whose base pose is this body's frame (a garment: its anchor; None: id itself)
    #: A welded tool: the link of ``id`` (the robot) that is its base; −1: its own body's base.
    base_link: int = -1
    #: The links of ``id`` that are this body's when it shares its pybullet body with another (a
    #: welded tool and the robot it is welded to: contacts and distances are filtered to them);
    #: None: every link of ``id``.
    link_set: frozenset[int] | None = None


def own_points(points: Sequence, a: BodyHandle, b: BodyHandle | None = None) -> Sequence:
    """Those of pybullet's contact or closest points between ``a.id`` (bodyA) and ``b.id`` (bodyB)
    that lie on the links of ``a`` and ``b`` themselves (see :attr:`BodyHandle.link_set`); ``points``
    itself when neither shares its pybullet body (the common case, on every step: no copy)."""
    keep_a, keep_b = a.link_set, b.link_set if b is not None else None
    if keep_a is None and keep_b is None:
        return points
    return [cp for cp in points if (keep_a is None or cp[3] in keep_a) and (keep_b is None or cp[4] in keep_b)]


@dataclass
class GarmentHandle:
    """A loaded garment: the soft body, the anchor body its held nodes are pinned to, and where
    the held frame rides (robot link index, pose in that link's URDF frame)."""

    name: str
    soft_id: int
    anchor_id: int
    link: int
    grip: tuple  # (position, orientation) of the held frame in the link's URDF frame
    nodes_in_held: np.ndarray  # (n, 3) settled node positions, held frame, m
    faces: np.ndarray  # (m, 3) node indices of the mesh's triangles (renders draw the cloth from these)
    rgba: tuple  # colour
