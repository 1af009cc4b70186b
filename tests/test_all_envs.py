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
    expected = {f"{task}{robot}" for task in ("Feeding", "ScratchItch") for robot in ("PR2", "Jaco", "Baxter", "Sawyer", "Panda")}
    expected |= {f"{task}{robot}" for task in ("BedBathing", "Drinking", "Dressing", "ArmManipulation") for robot in ("PR2", "Jaco", "Baxter", "Sawyer", "Panda")}
    # Stretch: not Feeding or Drinking, whose mouth (1.20 m above the floor, seated) is above its
    # grasp centre's highest point (1.125 m at full lift), with a spoon or cup held below it.
    expected |= {f"{task}Stretch" for task in ("ScratchItch", "BedBathing", "Dressing", "ArmManipulation")}
    assert tasks == expected


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
