"""A robot's commands beyond its arm joints (:mod:`assistive_compiler.runtime.drive`), on Stretch:
the differential-drive base (wheel actions → planar pose targets, and back) and the telescoping
tubes that follow one arm joint."""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb
import pytest
from helpers import drive_state

from assistive_compiler.runtime.env import AssistiveEnv


@pytest.fixture(scope="module")
def scratch_env(stretch_scratch_artifact):
    env = AssistiveEnv(stretch_scratch_artifact)
    yield env
    env.close()


def tubes(env) -> list[str]:
    """The telescoping tubes: the arm joint the others follow, then its followers."""
    followers = env.manifest.robot.followers
    return [*dict.fromkeys(followers.values()), *followers]


def test_equal_wheel_actions_drive_straight_and_opposite_ones_turn_in_place(scratch_env):
    env = scratch_env
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.array([1.0, 1.0, 0.0, 0.0, 0.0]))
    x, y, yaw = drive_state(env)
    assert x > 0.02 and abs(y) < 1e-3 and abs(yaw) < 1e-3  # forward along the heading, never sideways
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.array([1.0, -1.0, 0.0, 0.0, 0.0]))
    x, y, yaw = drive_state(env)
    assert yaw > 0.05 and math.hypot(x, y) < 1e-3  # right wheel forward, left back: counter-clockwise in place


def test_one_action_extends_all_four_tubes(scratch_env):
    # One telescoping action gives every tube the same target change (the reference's action
    # duplication); the inner tubes carry less and get there first, as in the reference.
    env = scratch_env
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.array([0.0, 0.0, 0.0, 1.0, 0.0]))
    extended = [
        pb.getJointState(env.body_id("robot"), env.joint_index("robot", t), physicsClientId=env.client)[0]
        for t in tubes(env)
    ]
    assert min(extended) > 0.01


def test_wheel_actions_for_a_planar_change_invert_the_drive(scratch_env):
    # BaseDriveControl.wheels_for is the inverse of motion: forward and turn come back, and a
    # change too large for one step is shortened along the same arc (both wheels scaled alike).
    drive = scratch_env.drive
    wheels = drive.wheels_for(0.01, 0.05)
    assert np.allclose(drive.motion(wheels), (0.01, 0.05))
    big = drive.wheels_for(0.5, 0.2)
    assert np.max(np.abs(big)) == pytest.approx(1.0)
    forward, turn = drive.motion(big)
    assert turn / forward == pytest.approx(0.2 / 0.5)


def test_pose_targets_start_from_the_measured_pose_and_stay_within_the_joints(scratch_env):
    env = scratch_env
    env.reset(seed=0)
    drive = env.drive
    x, y, yaw = drive.pose()
    assert np.allclose((x, y, yaw), drive_state(env))
    forward, turn = drive.motion(np.array([0.4, 0.2]))
    heading = yaw + turn / 2  # the base moves along its heading at mid-turn
    assert drive.targets(np.array([0.4, 0.2])) == pytest.approx(
        [x + forward * math.cos(heading), y + forward * math.sin(heading), yaw + turn]
    )
    robot, c = env.body_id("robot"), env.client
    pb.resetJointState(robot, drive.idx[0], drive.upper[0] - 0.001, physicsClientId=c)  # at the x limit
    assert drive.targets(np.array([1.0, 1.0]))[0] == drive.upper[0]


def test_a_sideways_goal_is_dropped_the_base_only_drives_along_its_heading(scratch_env):
    env = scratch_env
    env.reset(seed=0)
    drive = env.drive
    yaw = drive.pose()[2]
    ahead = np.array([math.cos(yaw), math.sin(yaw)])
    side = np.array([-math.sin(yaw), math.cos(yaw)])
    assert np.allclose(drive.wheels_towards(*(0.02 * ahead + 0.3 * side), 0.0), drive.wheels_for(0.02, 0.0))
    assert np.allclose(drive.wheels_towards(*(0.3 * side), 0.0), (0.0, 0.0))


def test_followers_start_at_their_leader_and_take_its_change(scratch_env):
    env = scratch_env
    env.reset(seed=0)
    lead, *followers = tubes(env)
    column = list(env.manifest.robot.arm_joints).index(lead)
    arm_q = np.zeros(len(env.manifest.robot.arm_joints))
    arm_q[column] = 0.05
    assert env.follow.start(arm_q) == [0.05] * len(followers)
    robot, c = env.body_id("robot"), env.client
    q = [pb.getJointState(robot, env.joint_index("robot", f), physicsClientId=c)[0] for f in followers]
    action = np.zeros(len(arm_q))
    action[column] = 0.5
    change = env.delta_scale[column] * 0.5
    assert env.follow.targets(action) == pytest.approx([min(v + change, 0.13) for v in q])
