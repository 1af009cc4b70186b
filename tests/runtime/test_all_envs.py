"""Every shipped Gymnasium id compiles, builds, passes Gymnasium's env checker and starts its seeded
episodes exactly as recorded (real compiles, real pybullet). Slow (each id compiles once per test
session, base searches included); run in CI."""

from __future__ import annotations

import json

import gymnasium as gym
import pytest
from episode_digests import STORE, first_difference, rollouts
from gymnasium.utils.env_checker import check_env

import assistive_compiler  # noqa: F401  (registers the ids)
from assistive_compiler.gym_ids import shipped_ids

IDS = sorted(shipped_ids())


def test_shipped_task_robot_pairs_are_registered():
    tasks = {i.split("/")[1].removesuffix("-v1") for i in IDS}
    robots = ("PR2", "Jaco", "Baxter", "Sawyer", "Panda", "Stretch")
    expected = {
        f"{task}{robot}"
        for task in ("Feeding", "ScratchItch", "BedBathing", "Drinking", "Dressing", "ArmManipulation")
        for robot in robots
    }
    assert tasks == expected and len(IDS) == 36


@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS)
def test_check_env(env_id, shared_cache):
    with shared_cache(env_id):
        env = gym.make(env_id)
    try:
        check_env(env.unwrapped, skip_render_check=True)
        obs, info = env.reset(seed=0)
        assert env.observation_space.contains(obs)
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert {"terms", "task_success", "total_force_on_human"} <= set(info)
        env.reset(seed=0)
        assert_the_camera_shows_person_arm_and_tools(env.unwrapped)
    finally:
        env.close()


MIN_PIXELS = {"person": 200, "arm": 20, "tool": 4}
"""Pixels of a 160 x 120 picture each must cover (a tool is small: 4 px is a scratcher tip in view)."""


def assert_the_camera_shows_person_arm_and_tools(env, width: int = 160, height: int = 120) -> None:
    """The task's camera for this robot, first frame after a seeded reset: the person, the robot's
    acting arm (the links its arm joints move) and every tool each cover pixels of pybullet's
    segmentation mask (not hidden behind the robot, not outside the picture)."""
    import numpy as np
    import pybullet as pb

    from assistive_compiler.runtime.camera import camera_matrices

    w, m = env.world, env.manifest
    view, proj = camera_matrices(m.camera, width, height, w.client)
    seg = np.asarray(
        pb.getCameraImage(
            width,
            height,
            view,
            proj,
            renderer=pb.ER_TINY_RENDERER,
            flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
            physicsClientId=w.client,
        )[4]
    ).reshape(-1)
    body, link = seg & ((1 << 24) - 1), (seg >> 24) - 1
    shown = {
        "person": int((body == w.variant_bodies[w.active_variant.name].id).sum()),
        "arm": int(((body == w.robot.id) & np.isin(link, env.arm_idx)).sum()),
    }
    shown |= {att.body: int((body == w.bodies[att.body].id).sum()) for att in m.tools}
    hidden = [name for name, pixels in shown.items() if pixels < MIN_PIXELS.get(name, MIN_PIXELS["tool"])]
    assert not hidden, f"{m.gym_id}: {hidden} hardly visible from the task camera ({shown} pixels of {width}x{height})"


@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS)
def test_seeded_episodes_are_unchanged(env_id, shared_cache):
    """The scripted and the random-action episode from a seeded reset give the recorded
    observations, rewards, term values, success and force, step by step (tests/episode_digests.py):
    a refactor of the compiler or runtime changes no episode unless it means to."""
    expected = json.loads(STORE.read_text())[env_id]
    with shared_cache(env_id):
        env = gym.make(env_id).unwrapped  # compiles under the lock
    try:
        changed = first_difference(expected, rollouts(env))
    finally:
        env.close()
    assert changed is None, (
        f"{env_id}: {changed}; if the change is meant to change episodes, "
        "regenerate with `python -m tests.episode_digests --write` and say so in the commit"
    )
