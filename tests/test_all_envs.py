"""Every shipped Gymnasium id compiles, builds and passes Gymnasium's env checker (real compiles,
real pybullet). Slow (each id compiles once, base searches included); run in CI."""

from __future__ import annotations

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env

import assistive_compiler  # noqa: F401  (registers the ids)
from assistive_compiler.registration import shipped_ids

IDS = sorted(shipped_ids())


def test_shipped_task_robot_pairs_are_registered():
    tasks = {i.split("/")[1].removesuffix("-v1") for i in IDS}
    robots = ("PR2", "Jaco", "Baxter", "Sawyer", "Panda", "Stretch")
    expected = {f"{task}{robot}" for task in ("Feeding", "ScratchItch", "BedBathing", "Drinking", "Dressing", "ArmManipulation")
                for robot in robots}
    assert tasks == expected and len(IDS) == 36


@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS)
def test_check_env(env_id, tmp_path_factory, monkeypatch):
    monkeypatch.setenv("ASSISTIVE_COMPILER_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))
    env = gym.make(env_id)
    try:
        check_env(env.unwrapped, skip_render_check=True)
        obs, info = env.reset(seed=0)
        assert env.observation_space.contains(obs)
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert {"terms", "task_success", "total_force_on_human"} <= set(info)
    finally:
        env.close()
