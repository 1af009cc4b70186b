"""The base of the artifact's models, and its vector types.

Frames and units: positions in metres in the world frame unless a field says otherwise;
orientations are quaternions (x, y, z, w) as pybullet uses; joint values in radians.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict

Vec3 = tuple[float, float, float]
"""A position or direction (x, y, z), m unless a field says otherwise."""
Quat = tuple[float, float, float, float]
"""An orientation as a quaternion (x, y, z, w), pybullet's order."""


class ArtifactModel(BaseModel):
    """Base of every model of the manifest: strict (no unknown fields) and frozen."""

    model_config = ConfigDict(extra="forbid", frozen=True)
