"""The rotation helpers the compiler, the terms, the scripted policy and the viewer share: quaternions
(x, y, z, w order), matrices, URDF roll-pitch-yaw, rotation about an axis; checked against pybullet."""

import math

import numpy as np
import pybullet as pb
import pytest

from assistive_compiler.rotation import (
    axis_rotation,
    matrix_quat,
    matrix_rpy,
    quat_about,
    quat_angle,
    quat_from_rpy,
    quat_matrix,
    quat_rotate,
    quat_towards,
    rpy_matrix,
    vec_angle,
    wxyz,
)


def test_quat_angle_is_the_rotation_between_orientations_and_ignores_the_sign():
    a = quat_from_rpy((0.3, -0.2, 1.0))
    turned = pb.multiplyTransforms([0, 0, 0], quat_about((0.0, 0.6, 0.8), 0.7).tolist(), [0, 0, 0], a)[1]
    assert quat_angle(a, turned) == pytest.approx(0.7, abs=1e-6)
    assert quat_angle(a, -np.asarray(turned)) == pytest.approx(0.7, abs=1e-6)  # −q: the same orientation
    assert quat_angle(a, a) == pytest.approx(0.0, abs=1e-6)


def test_vec_angle_takes_any_lengths():
    assert vec_angle((2.0, 0.0, 0.0), (0.0, 0.0, 0.5)) == pytest.approx(math.pi / 2)
    assert vec_angle((1.0, 1.0, 0.0), (-3.0, -3.0, 0.0)) == pytest.approx(math.pi)
    assert vec_angle((0.0, 0.0, 1.0), (0.0, 0.0, 7.0)) == pytest.approx(0.0, abs=1e-7)


def test_quat_towards_turns_at_most_the_step_along_the_shortest_way():
    a = np.array(quat_from_rpy((0.0, 0.0, 0.0)))
    b = np.array(quat_from_rpy((0.0, 0.0, math.radians(90))))
    step = quat_towards(a, b, math.radians(30))
    assert quat_angle(a, step) == pytest.approx(math.radians(30), abs=1e-9)
    assert quat_angle(step, b) == pytest.approx(math.radians(60), abs=1e-9)
    assert quat_rotate(step, (1.0, 0.0, 0.0)) == pytest.approx(
        [math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0]
    )
    assert quat_towards(a, b, math.radians(120)) is b  # already within reach: the goal itself


@pytest.mark.parametrize(
    "rpy", [(0.3, -0.2, 1.0), (-2.9, 1.2, -0.4), (0.0, 0.0, 0.0), (1.0, math.pi / 2, 0.5), (0.2, -math.pi / 2, -1.1)]
)
def test_rpy_matrix_is_pybullets_and_converts_back_to_the_same_rotation(rpy):
    """URDF's fixed-axis roll-pitch-yaw (R = Rz Ry Rx) matches pybullet's Euler convention; the
    inverse reproduces the matrix even at gimbal lock (pitch ±π/2), and the quaternion of the
    matrix is pybullet's (up to sign; w ≥ 0)."""
    rot = rpy_matrix(rpy)
    expected = np.asarray(pb.getMatrixFromQuaternion(pb.getQuaternionFromEuler(rpy))).reshape(3, 3)
    assert np.allclose(rot, expected, atol=1e-12)
    assert np.allclose(rpy_matrix(matrix_rpy(rot)), rot, atol=1e-12)
    q = np.asarray(matrix_quat(rot))
    assert q[3] >= 0 and quat_angle(q, quat_from_rpy(rpy)) == pytest.approx(0.0, abs=1e-6)


def test_axis_rotation_is_the_quaternion_about_the_axis():
    axis, angle = np.array([0.0, 0.6, 0.8]), 0.7
    v = np.array([0.3, -1.0, 0.25])
    assert np.allclose(axis_rotation(axis, angle) @ v, quat_rotate(quat_about(axis, angle), v), atol=1e-12)
    assert np.allclose(axis_rotation(axis, 0.0), np.eye(3))


def test_wxyz_reorders_for_viewers():
    assert wxyz((0.1, 0.2, 0.3, 0.9)).tolist() == [0.9, 0.1, 0.2, 0.3]


def test_quat_matrix_is_pybullets_bit_for_bit():
    """The runtime reads orientations as matrices with quat_matrix instead of pybullet's
    getMatrixFromQuaternion: the same doubles, so no episode changes (unit and non-unit
    quaternions; the columns are the rotated axes)."""
    rng = np.random.default_rng(7)
    for k in range(2000):
        q = rng.normal(size=4)
        q = q / np.linalg.norm(q) * (1.0 if k % 2 else 1.0 + 1e-6 * rng.normal())
        expected = np.asarray(pb.getMatrixFromQuaternion(q), dtype=float).reshape(3, 3)
        assert np.array_equal(quat_matrix(q), expected)
    quarter_turn_about_z = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    assert np.allclose(quat_matrix(quarter_turn_about_z)[:, 0], [0.0, 1.0, 0.0], atol=1e-15)
