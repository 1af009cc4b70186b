"""What a term may read of the scene at one env step: the :class:`SceneReads` protocol.

Terms depend on this protocol, not on the runtime: the runtime's
:class:`~assistive_compiler.runtime.snapshot.Snapshot` implements it (batched pybullet reads, once
per step), and a test may hand a term anything else that does. Positions are in metres and
forces in newtons, in the world frame unless a method takes a ``frame`` (a name of the task's
frames: ``world``, ``robot_base``, ...)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from ..references import JointsHandle, NodesHandle, PointHandle

ContactPoint = tuple[Any, ...]
"""One of pybullet's contact points (getContactPoints: [5] position on A, [9] normal force, ...)."""


@dataclass
class ParticleEvents:
    """What happened to a particle set during the last env step."""

    consumed: int = 0
    lost: int = 0
    hit: int = 0
    consumed_speed_sum: float = 0.0


class SceneReads(Protocol):
    """The scene at one env step, as the terms read it."""

    def position(self, h: PointHandle) -> np.ndarray:
        """A point's position (m, world frame)."""
        ...

    def orientation(self, h: PointHandle) -> np.ndarray:
        """The orientation of a point's link, quaternion (x, y, z, w), world frame."""
        ...

    def velocity(self, h: PointHandle) -> np.ndarray:
        """The linear velocity of a point's link (m/s, world frame)."""
        ...

    def joint_angles(self, h: JointsHandle) -> np.ndarray:
        """A joint group's positions (rad for revolute joints, m for prismatic), in the group's order."""
        ...

    def node_positions(self, h: NodesHandle) -> np.ndarray:
        """A garment node set's positions (m, world frame), one row per node."""
        ...

    def point_in_frame(self, frame: str, p: np.ndarray) -> np.ndarray:
        """A world-frame position expressed in ``frame`` (m)."""
        ...

    def vector_in_frame(self, frame: str, v: np.ndarray) -> np.ndarray:
        """A world-frame direction expressed in ``frame`` (rotation only)."""
        ...

    def quat_in_frame(self, frame: str, q: np.ndarray) -> np.ndarray:
        """A world-frame orientation (x, y, z, w) expressed in ``frame``."""
        ...

    def action(self, agent: str) -> np.ndarray:
        """The step's action of ``robot``, ``human`` or ``all`` (both, robot first), in [-1, 1]."""
        ...

    def particle_events(self, name: str) -> ParticleEvents:
        """What happened to particle set ``name`` during the step."""
        ...

    def markers_cleared(self, name: str) -> int:
        """Markers of set ``name`` cleared during the step."""
        ...

    def contacts(self, a: Sequence[str], b: Sequence[str]) -> list[ContactPoint]:
        """pybullet contact points between any body of ``a`` (as bodyA) and any of ``b`` this step."""
        ...

    def closest_distance(self, a: str, b: Sequence[str], max_distance: float) -> float:
        """Smallest surface distance (m) between body ``a`` and any body of ``b``, at most ``max_distance``."""
        ...

    def contact_force(
        self, a: Sequence[str], b: Sequence[str], near: PointHandle | None = None, radius: float = 0.0
    ) -> float:
        """Σ normal force (N) of contacts between bodies of ``a`` and of ``b`` (with ``near``: within
        ``radius`` m of that point)."""
        ...

    def contact_force_and_count(self, a: str, b: Sequence[str], distance: float) -> tuple[float, int]:
        """Contact force (N) of body ``a`` on ``b`` and the number of closest points within ``distance`` m."""
        ...
