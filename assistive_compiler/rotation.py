"""Rotations, in one place: quaternions (x, y, z, w) as pybullet orders them (and the (w, x, y, z)
order viewers use), 3×3 rotation matrices (columns: the rotated frame's axes), URDF's fixed-axis
roll-pitch-yaw, rotation about an axis, and the frame of a capsule axis. Angles in radians unless
a name says degrees. Plain numpy, no pybullet, so the term library and the compiler can use it
without importing the simulator; :func:`quat_matrix` gives bit for bit what pybullet's
``getMatrixFromQuaternion`` gives, so the runtime reads body orientations as matrices with it too."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np


def quat_rotate(q, v) -> np.ndarray:
    """Rotate vector ``v`` by unit quaternion ``q`` (x, y, z, w). Scalar arithmetic on Python
    floats: for one 3-vector this is ~20× faster than numpy's cross products (and ~4× faster than
    the same arithmetic on numpy scalars, hence ``_floats``)."""
    x, y, z, w = _floats(q)
    vx, vy, vz = _floats(v)
    tx, ty, tz = 2.0 * (y * vz - z * vy), 2.0 * (z * vx - x * vz), 2.0 * (x * vy - y * vx)
    return np.array(
        [
            vx + w * tx + (y * tz - z * ty),
            vy + w * ty + (z * tx - x * tz),
            vz + w * tz + (x * ty - y * tx),
        ]
    )


def quat_matrix(q) -> np.ndarray:
    """3×3 rotation matrix of a quaternion (x, y, z, w), which need not be of unit length: its
    columns are the rotated frame's axes. The same operations in the same order as Bullet's
    ``btMatrix3x3::setRotation`` (pybullet's ``getMatrixFromQuaternion``), so the same doubles."""
    x, y, z, w = _floats(q)
    s = 2.0 / (x * x + y * y + z * z + w * w)
    xs, ys, zs = x * s, y * s, z * s
    wx, wy, wz = w * xs, w * ys, w * zs
    xx, xy, xz = x * xs, x * ys, x * zs
    yy, yz, zz = y * ys, y * zs, z * zs
    return np.array(
        [
            [1.0 - (yy + zz), xy - wz, xz + wy],
            [xy + wz, 1.0 - (xx + zz), yz - wx],
            [xz - wy, yz + wx, 1.0 - (xx + yy)],
        ]
    )


def _floats(a):
    """A numpy array as a list of Python floats (other sequences as they are)."""
    return a.tolist() if isinstance(a, np.ndarray) else a


def quat_conj(q: np.ndarray) -> np.ndarray:
    return np.array([-q[0], -q[1], -q[2], q[3]])


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ax, ay, az, aw = _floats(a)
    bx, by, bz, bw = _floats(b)
    return np.array(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ]
    )


def quat_about(axis, angle: float) -> np.ndarray:
    """Unit quaternion (x, y, z, w) turning by ``angle`` (rad) about the unit vector ``axis``."""
    h = angle / 2
    return np.concatenate([np.asarray(axis, dtype=float) * math.sin(h), [math.cos(h)]])


def quat_angle(a, b) -> float:
    """Angle (rad, 0 … π) of the smallest rotation between unit quaternions ``a`` and ``b``
    (x, y, z, w); q and −q are the same orientation."""
    return 2 * math.acos(min(1.0, abs(float(np.dot(a, b)))))


def vec_angle(a, b) -> float:
    """Angle (rad, 0 … π) between two nonzero vectors (any lengths)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    cos = float(np.dot(a, b)) / (float(np.linalg.norm(a)) * float(np.linalg.norm(b)))
    return math.acos(max(-1.0, min(1.0, cos)))


def quat_towards(a, b, max_angle: float) -> np.ndarray:
    """Unit quaternion on the shortest rotation from ``a`` to ``b`` (x, y, z, w), at most
    ``max_angle`` (rad) from ``a``: ``b`` itself when it is that close already."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if quat_angle(a, b) <= max_angle:
        return b
    d = quat_mul(b, quat_conj(a))  # the turn a -> b, in the world frame
    if d[3] < 0:
        d = -d
    axis = d[:3] / max(float(np.linalg.norm(d[:3])), 1e-12)
    return quat_mul(quat_about(axis, max_angle), a)


def quat_from_rpy(rpy: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """Quaternion (x, y, z, w) of fixed-axis roll, pitch, yaw (rad; URDF convention R = Rz·Ry·Rx)."""
    r, p, y = (a / 2 for a in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def quat_from_rpy_deg(rpy_deg) -> tuple[float, float, float, float]:
    """:func:`quat_from_rpy` of angles in degrees (a spec's ``rpy_deg``)."""
    return quat_from_rpy(tuple(math.radians(a) for a in rpy_deg))


def quat_yaw(orn) -> float:
    """Yaw (rad, about world z) of a quaternion (x, y, z, w)."""
    x, y, z, w = orn
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def capsule_axes(start, end) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """``(length, axis, u, v)`` of the segment start → end: its length, the unit axis, and two unit
    vectors completing a right-handed frame (u = axis × (x or y), v = axis × u), in the segment's frame."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    length = float(np.linalg.norm(end - start))
    axis = (end - start) / length
    u = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    return length, axis, u, np.cross(axis, u)


def rpy_matrix(rpy: Sequence[float]) -> np.ndarray:
    """URDF's fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = (float(v) for v in rpy)
    cr, sr = math.cos(r), math.sin(r)
    cp, sp = math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def matrix_rpy(rot: np.ndarray) -> tuple[float, float, float]:
    """Inverse of :func:`rpy_matrix`, numerically stable at pitch = +-pi/2.

    Yaw comes from the first column (0 when that column is along z, i.e. at gimbal lock); roll
    and pitch are then solved from ``Rz(yaw)^T R = Ry(pitch) Rx(roll)`` so that the three angles
    reproduce ``rot`` to rounding error whatever the yaw.
    """
    if math.hypot(rot[0, 0], rot[1, 0]) < 1e-10:
        yaw = 0.0
    else:
        yaw = math.atan2(rot[1, 0], rot[0, 0])
    cy, sy = math.cos(yaw), math.sin(yaw)
    pitch = math.atan2(-rot[2, 0], cy * rot[0, 0] + sy * rot[1, 0])
    roll = math.atan2(sy * rot[0, 2] - cy * rot[1, 2], cy * rot[1, 1] - sy * rot[0, 1])
    return roll, pitch, yaw


def matrix_quat(rot: np.ndarray) -> tuple[float, float, float, float]:
    """Rotation matrix -> unit quaternion (x, y, z, w), w >= 0 (Shepperd's method)."""
    m = rot
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        w, x = 0.25 * s, (m[2, 1] - m[1, 2]) / s
        y, z = (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        w, x = (m[2, 1] - m[1, 2]) / s, 0.25 * s
        y, z = (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        w, x = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s
        y, z = 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        w, x = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s
        y, z = (m[1, 2] + m[2, 1]) / s, 0.25 * s
    q = np.array([x, y, z, w])
    q /= np.linalg.norm(q)
    if q[3] < 0.0:
        q = -q
    return tuple(float(v) + 0.0 for v in q)  # type: ignore[return-value]


def axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` (rad) about the unit vector ``axis`` (Rodrigues)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def wxyz(xyzw) -> np.ndarray:
    """A quaternion (x, y, z, w) reordered as (w, x, y, z)."""
    return np.array([xyzw[3], xyzw[0], xyzw[1], xyzw[2]])
