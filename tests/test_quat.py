"""The quaternion helpers the compiler, the terms and the scripted policy share (x, y, z, w order)."""

import math

import numpy as np
import pybullet as pb
import pytest

from assistive_compiler.quat import quat_about, quat_angle, quat_from_rpy, quat_rotate, quat_towards, vec_angle


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
    assert quat_rotate(step, (1.0, 0.0, 0.0)) == pytest.approx([math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0])
    assert quat_towards(a, b, math.radians(120)) is b  # already within reach: the goal itself
