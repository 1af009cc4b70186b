"""pybullet IK options shared by the compile-time placement and the scripted policy: which joints
IK may move (the placement's reach checks freeze a mobile base's drive: reaching there is the arm's
job), how readily it moves a drive the scripted policy may drive, and how limits apply."""

from __future__ import annotations

PYBULLET_DAMPING = 0.1  # pybullet's default IK damping of a joint
FROZEN_DAMPING = 1e6  # IK damping of joints IK must not move
DRIVE_DAMPING = PYBULLET_DAMPING  # IK damping of a drive's planar joints that the scripted policy drives


def ik_damping(
    movable: list[int], frozen: list[int], driven: list[int] = (), own: dict[int, float] | None = None
) -> list[float] | None:
    """Per movable joint, pybullet's IK damping: huge for ``frozen`` joints (a mobile base's drive,
    which reaching must not move), ``own``'s value for the joints a script damps itself (joint
    index → damping, e.g. a slow shoulder), DRIVE_DAMPING for ``driven`` ones (a drive IK may
    move), the default elsewhere; None when nothing is frozen, damped or driven."""
    own = own or {}
    if not frozen and not driven and not own:
        return None
    return [
        FROZEN_DAMPING if j in frozen else own[j] if j in own else DRIVE_DAMPING if j in driven else PYBULLET_DAMPING
        for j in movable
    ]


def ik_limits(chain, rest) -> dict:
    """pybullet IK keywords: null-space IK towards ``rest`` within the joint limits; with frozen
    joints plain damped least squares instead (null-space IK moves heavily damped joints anyway),
    whose result the caller clamps to the limits. ``chain`` has ``lo_all``, ``hi_all``,
    ``ranges`` and ``damping``."""
    if chain.damping is not None:
        return dict(jointDamping=chain.damping)
    return dict(lowerLimits=chain.lo_all, upperLimits=chain.hi_all, jointRanges=chain.ranges, restPoses=rest)
