"""The arms' joint convention shared by every limit model: sides, the four joints a model sees,
the reference's input encoding and mirroring, and the :class:`ArmLimitModel` protocol."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal, Protocol, runtime_checkable

import numpy as np

from ..skeleton import JOINT_LIMITS_DEG

Side = Literal["right", "left"]
SIDES: tuple[Side, Side] = ("right", "left")

#: The four joints a limit model sees, per arm, in input order.
ARM_LIMIT_JOINTS: dict[str, tuple[str, str, str, str]] = {
    side: (f"{side}_shoulder_x", f"{side}_shoulder_y", f"{side}_shoulder_z", f"{side}_elbow") for side in SIDES
}

_TWO_PI = 2.0 * math.pi
_MIRROR = np.array([-1.0, 1.0, -1.0, 1.0])


def _check_side(side: str) -> Side:
    if side not in SIDES:
        raise ValueError(f"side must be 'right' or 'left', got {side!r}")
    return side  # type: ignore[return-value]


def _as_poses(q: np.ndarray | Sequence[float]) -> tuple[np.ndarray, bool]:
    """``q`` as a float (N, 4) array, and whether it was a single (4,) pose."""
    arr = np.asarray(q, dtype=float)
    if arr.shape == (4,):
        return arr[None, :], True
    if arr.ndim == 2 and arr.shape[1] == 4:
        return arr, False
    raise ValueError(f"q must have shape (4,) or (N, 4), got {arr.shape}")


def arm_box(side: Side) -> tuple[np.ndarray, np.ndarray]:
    """The pose-independent limits (paper §III-A) of one arm's four joints, radians: (lower, upper)."""
    names = ARM_LIMIT_JOINTS[_check_side(side)]
    lo = np.radians([JOINT_LIMITS_DEG[n][0] for n in names])
    hi = np.radians([JOINT_LIMITS_DEG[n][1] for n in names])
    return lo, hi


def mirror_pose(q: np.ndarray | Sequence[float]) -> np.ndarray:
    """The other arm's pose mirrored in the sagittal plane: (qx, qy, qz, qe) -> (-qx, qy, -qz, qe).

    Its own inverse; maps left-arm poses to the equivalent right-arm poses and back."""
    return np.asarray(q, dtype=float) * _MIRROR


def reference_input(q: np.ndarray | Sequence[float], side: Side) -> np.ndarray:
    """Our (shoulder_x, shoulder_y, shoulder_z, elbow) -> the reference network's input.

    Facts 3.6: the four angles are read as (tz, tx, ty, qe) and, with s = -1 for the right arm and
    +1 for the left, converted to tz' = (s*tz + 2pi) mod 2pi, tx' = (tx + 2pi) mod 2pi,
    ty' = s*ty, qe' = (-qe + 2pi) mod 2pi; the network gets [tz', tx', ty', qe'].
    Returns shape (N, 4) (N = 1 for a single pose)."""
    poses, _ = _as_poses(q)
    s = -1.0 if _check_side(side) == "right" else 1.0
    out = np.empty_like(poses)
    out[:, 0] = np.mod(s * poses[:, 0] + _TWO_PI, _TWO_PI)
    out[:, 1] = np.mod(poses[:, 1] + _TWO_PI, _TWO_PI)
    out[:, 2] = s * poses[:, 2]
    out[:, 3] = np.mod(-poses[:, 3] + _TWO_PI, _TWO_PI)
    return out


@runtime_checkable
class ArmLimitModel(Protocol):
    """A pose-dependent arm limit model.

    ``valid(q, side)`` takes one pose, shape (4,), or a batch, shape (N, 4), of
    (shoulder_x, shoulder_y, shoulder_z, elbow) in radians in our joint convention and returns a
    boolean array of shape () or (N,): True where the pose is anatomically valid."""

    def valid(self, q: np.ndarray, side: Side) -> np.ndarray: ...
