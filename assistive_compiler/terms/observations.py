"""Observation features. Positions in metres, orientations as quaternions (x, y, z, w), forces in
newtons. ``frame`` expresses a feature in the world, the robot's base frame or the person's base
(chest) frame, as the reference does (robot obs in the robot base frame)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .registry import BodiesRef, FrameRef, JointsRef, Params, PointRef, SizeContext, term

if TYPE_CHECKING:
    from .reads import SceneReads


class PointInFrame(Params):
    of: PointRef
    frame: FrameRef = "robot_base"


class Displacement(Params):
    of: PointRef
    to: PointRef
    frame: FrameRef = "robot_base"


class JointAngles(Params):
    joints: JointsRef
    wrap: bool = True


class ContactForce(Params):
    a: BodiesRef
    b: BodiesRef


@term("position", "observation", PointInFrame, size=3)
def position(snap: SceneReads, p: PointInFrame) -> np.ndarray:
    """Position of a point in ``frame`` (m)."""
    return snap.point_in_frame(p.frame, snap.position(p.of))


@term("orientation", "observation", PointInFrame, size=4)
def orientation(snap: SceneReads, p: PointInFrame) -> np.ndarray:
    """Orientation of a point's link in ``frame`` as a quaternion (x, y, z, w)."""
    return snap.quat_in_frame(p.frame, snap.orientation(p.of))


@term("displacement", "observation", Displacement, size=3)
def displacement(snap: SceneReads, p: Displacement) -> np.ndarray:
    """Vector from ``to`` to ``of`` (``of − to``), rotated into ``frame`` (m)."""
    return snap.vector_in_frame(p.frame, snap.position(p.of) - snap.position(p.to))


def _joint_size(p: Any, ctx: SizeContext) -> int:
    """The group's size; ``p`` is the parameters as the spec writes them (``joints``: the group's name)."""
    return ctx.joint_group_sizes[p.joints]


@term("joint_angles", "observation", JointAngles, size=_joint_size)
def joint_angles(snap: SceneReads, p: JointAngles) -> np.ndarray:
    """Joint angles of a group (rad); wrapped to [−π, π] when ``wrap`` (the robot's, as in the paper)."""
    q = snap.joint_angles(p.joints)
    if p.wrap:
        q = (q + np.pi) % (2 * np.pi) - np.pi
    return q


@term("contact_force", "observation", ContactForce, size=1)
def contact_force_obs(snap: SceneReads, p: ContactForce) -> np.ndarray:
    """Sum of contact normal forces between bodies ``a`` and ``b`` this step (N)."""
    return np.array([snap.contact_force(p.a, p.b)])
