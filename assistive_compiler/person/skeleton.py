"""The person's skeleton: its joints and links by name, in the reference's order, the landmark
links, joint groups, joint axes and limits, and the self-collision groups (paper §III-A).

Names only, no measurements (those are :mod:`.body`'s). Frames follow the templates' convention:
Z-up, the person faces -Y and their right side is -X; the body is a fixed-base tree rooted at link
``chest``. Angles are in degrees only where a name says ``_deg``, else radians.
"""

from __future__ import annotations

from typing import Literal, NamedTuple

__all__ = [
    "ROOT_LINK",
    "JOINT_NAMES",
    "REVOLUTE_JOINTS",
    "LINK_NAMES",
    "LANDMARKS",
    "JOINT_GROUPS",
    "JOINT_AXES",
    "JOINT_LIMITS_DEG",
    "LIMIT_SCALED_JOINTS",
    "CollisionGroup",
    "SELF_COLLISION_GROUPS",
    "self_collision_pairs",
]

#: The root (base) link.
ROOT_LINK = "chest"

#: All 42 joints in the reference's depth-first order: pybullet joint index k == reference index
#: k (index 24, ``stomach``, is the only fixed one).
JOINT_NAMES: tuple[str, ...] = (
    "right_pecs_x",
    "right_pecs_y",
    "right_pecs_z",
    "right_shoulder_x",
    "right_shoulder_y",
    "right_shoulder_z",
    "right_elbow",
    "right_forearm",
    "right_wrist_x",
    "right_wrist_y",
    "left_pecs_x",
    "left_pecs_y",
    "left_pecs_z",
    "left_shoulder_x",
    "left_shoulder_y",
    "left_shoulder_z",
    "left_elbow",
    "left_forearm",
    "left_wrist_x",
    "left_wrist_y",
    "neck",
    "head_x",
    "head_y",
    "head_z",
    "stomach",
    "waist_x",
    "waist_y",
    "waist_z",
    "right_hip_x",
    "right_hip_y",
    "right_hip_z",
    "right_knee",
    "right_ankle_x",
    "right_ankle_y",
    "right_ankle_z",
    "left_hip_x",
    "left_hip_y",
    "left_hip_z",
    "left_knee",
    "left_ankle_x",
    "left_ankle_y",
    "left_ankle_z",
)

#: The 41 revolute joints (every joint but ``stomach``), in index order.
REVOLUTE_JOINTS: tuple[str, ...] = tuple(j for j in JOINT_NAMES if j != "stomach")

#: Landmark joint -> the link that carries the landmark name, for joints whose child link is not
#: ``<joint>_link``. (The landmark link is the last link of its joint group.)
_LANDMARK_CHILD: dict[str, str] = {
    "right_pecs_z": "right_pecs",
    "right_shoulder_z": "right_shoulder",
    "right_forearm": "right_elbow",
    "right_wrist_y": "right_wrist",
    "left_pecs_z": "left_pecs",
    "left_shoulder_z": "left_shoulder",
    "left_forearm": "left_elbow",
    "left_wrist_y": "left_wrist",
    "neck": "neck",
    "head_z": "head",
    "stomach": "stomach",
    "waist_z": "waist",
    "right_hip_z": "right_hip",
    "right_knee": "right_knee",
    "right_ankle_z": "right_ankle",
    "left_hip_z": "left_hip",
    "left_knee": "left_knee",
    "left_ankle_z": "left_ankle",
}

#: Child link of each joint, in joint order (so pybullet link index k is ``LINK_NAMES[k]``).
LINK_NAMES: tuple[str, ...] = tuple(_LANDMARK_CHILD.get(j, f"{j}_link") for j in JOINT_NAMES)

#: The landmark links specs may refer to. Each frame is at its joint centre.
LANDMARKS: tuple[str, ...] = (
    "chest",
    "right_pecs",
    "right_shoulder",
    "right_elbow",
    "right_wrist",
    "left_pecs",
    "left_shoulder",
    "left_elbow",
    "left_wrist",
    "neck",
    "head",
    "stomach",
    "waist",
    "right_hip",
    "right_knee",
    "right_ankle",
    "left_hip",
    "left_knee",
    "left_ankle",
)

#: The reference's joint groups (its ``*_joints`` lists), by joint name.
JOINT_GROUPS: dict[str, tuple[str, ...]] = {
    "right_arm": JOINT_NAMES[0:10],
    "left_arm": JOINT_NAMES[10:20],
    "head": JOINT_NAMES[20:24],
    "waist": JOINT_NAMES[25:28],
    "right_leg": JOINT_NAMES[28:35],
    "left_leg": JOINT_NAMES[35:42],
}

#: Rotation axis (in the joint frame) of each revolute joint. Note shoulder_x turns about y and
#: shoulder_y about x, as in the reference.
JOINT_AXES: dict[str, Literal["x", "y", "z"]] = {}
for _j in REVOLUTE_JOINTS:
    if _j.endswith(("_elbow", "_knee")) or _j == "neck":
        JOINT_AXES[_j] = "x"
    elif _j.endswith("_forearm"):
        JOINT_AXES[_j] = "z"
    elif _j.endswith("_shoulder_x"):
        JOINT_AXES[_j] = "y"
    elif _j.endswith("_shoulder_y"):
        JOINT_AXES[_j] = "x"
    else:
        JOINT_AXES[_j] = _j[-1]  # type: ignore[assignment]
del _j

#: Pose-independent joint limits in degrees (paper §III-A); the template emits the same in radians.
JOINT_LIMITS_DEG: dict[str, tuple[float, float]] = {
    "right_pecs_x": (-10, 10),
    "right_pecs_y": (-10, 30),
    "right_pecs_z": (-35, 35),
    "right_shoulder_x": (5, 198),
    "right_shoulder_y": (-188, 61),
    "right_shoulder_z": (-90, 90),
    "right_elbow": (-128, 0),
    "right_forearm": (-90, 90),
    "right_wrist_x": (-81, 90),
    "right_wrist_y": (-27, 47),
    "left_pecs_x": (-10, 10),
    "left_pecs_y": (-30, 10),
    "left_pecs_z": (-35, 35),
    "left_shoulder_x": (-198, -5),
    "left_shoulder_y": (-188, 61),
    "left_shoulder_z": (-90, 90),
    "left_elbow": (-128, 0),
    "left_forearm": (-90, 90),
    "left_wrist_x": (-81, 90),
    "left_wrist_y": (-47, 27),
    "neck": (-10, 20),
    "head_x": (-50, 50),
    "head_y": (-34, 34),
    "head_z": (-70, 70),
    "waist_x": (-75, 30),
    "waist_y": (-30, 30),
    "waist_z": (-30, 30),
    "right_hip_x": (-127, 30),
    "right_hip_y": (-40, 45),
    "right_hip_z": (-45, 40),
    "right_knee": (0, 130),
    "right_ankle_x": (-35, 38),
    "right_ankle_y": (-23, 24),
    "right_ankle_z": (-43, 35),
    "left_hip_x": (-127, 30),
    "left_hip_y": (-45, 40),
    "left_hip_z": (-40, 45),
    "left_knee": (0, 130),
    "left_ankle_x": (-35, 38),
    "left_ankle_y": (-24, 23),
    "left_ankle_z": (-35, 43),
}

#: Joints whose limits the reference's limited-range-of-motion impairment multiplies by gamma
#: (reference indices 0-23: both arms, neck and head; not the waist or legs).
LIMIT_SCALED_JOINTS: tuple[str, ...] = JOINT_NAMES[0:24]


class CollisionGroup(NamedTuple):
    """Self-collision is enabled between every link of ``links`` and every link of ``against``."""

    links: tuple[str, ...]
    against: tuple[str, ...]


def _links(first: int, last: int) -> tuple[str, ...]:
    """Links of reference indices first..last inclusive (-1 is the root, ``chest``)."""
    return tuple(ROOT_LINK if i < 0 else LINK_NAMES[i] for i in range(first, last + 1))


#: Self-collision groups (paper §III-A). The body is loaded with self-collision on, every link pair
#: is disabled, and only these pairs are re-enabled; torso, head and shoulder girdles never
#: collide with each other.
SELF_COLLISION_GROUPS: dict[str, CollisionGroup] = {
    "right_arm": CollisionGroup(_links(3, 9), _links(-1, -1) + _links(10, 41)),
    "left_arm": CollisionGroup(_links(13, 19), _links(-1, 9) + _links(20, 41)),
    "right_leg": CollisionGroup(_links(28, 34), _links(-1, 23) + _links(35, 41)),
    "left_leg": CollisionGroup(_links(35, 41), _links(-1, 23) + _links(28, 34)),
}


def self_collision_pairs() -> frozenset[tuple[str, str]]:
    """Every enabled self-collision link pair, each as a name-sorted tuple."""
    pairs: set[tuple[str, str]] = set()
    for group in SELF_COLLISION_GROUPS.values():
        for a in group.links:
            for b in group.against:
                if a != b:
                    pairs.add((a, b) if a < b else (b, a))
    return frozenset(pairs)
