"""Reference math for the kinematics tests, independent of the URDFs under test: rotations and
homogeneous transforms in numpy (URDF conventions: rpy is fixed-axis roll, pitch, yaw, so
R = Rz(yaw)·Ry(pitch)·Rx(roll)), and pybullet's name → index tables of a loaded body."""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def homogeneous(rot=None, xyz=(0, 0, 0)) -> np.ndarray:
    """A 4×4 transform from a rotation matrix (None: none) and a translation."""
    t = np.eye(4)
    t[:3, :3] = np.eye(3) if rot is None else rot
    t[:3, 3] = xyz
    return t


def origin_matrix(xyz, rpy) -> np.ndarray:
    """The transform of a URDF ``<origin xyz rpy>``."""
    return homogeneous(rot_z(rpy[2]) @ rot_y(rpy[1]) @ rot_x(rpy[0]), xyz)


def body_indices(cid: int, body: int) -> tuple[dict[str, int], dict[str, int]]:
    """Joint index by joint name and link index by link name (a joint's child link shares its index)."""
    joints, links = {}, {}
    for j in range(pb.getNumJoints(body, physicsClientId=cid)):
        info = pb.getJointInfo(body, j, physicsClientId=cid)
        joints[info[1].decode()] = j
        links[info[12].decode()] = j
    return joints, links
