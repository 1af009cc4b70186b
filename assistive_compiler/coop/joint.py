"""The two agents of a co-optimisation env seen as one Gymnasium env, for learners that train the
pair with one shared critic (Stable-Baselines3 SAC or PPO with one actor per agent:
:mod:`assistive_compiler.training.learners.factored_actor`, :mod:`~assistive_compiler.training.learners.factored_actor_critic`).

* **Observation**: the robot's observation, then the person's (the PettingZoo env's ``state()``).
* **Action**: the robot's action, then the person's, each in [−1, 1].
* **Reward**: the one both agents share (paper §V-B; :mod:`.parallel`), with the same ``info``.

Each agent still acts on its own observation only: the learner's actor reads its agent's slice of
the joint observation (``agent_split``), so the exported pair plays in the PettingZoo env, ``--coop``
and the viewer like any other pair.
"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np

from .parallel import AssistiveParallelEnv


def agent_slices(agent_split: tuple[int, int], obs_size: int, action_size: int) -> tuple[dict, dict]:
    """Each agent's slice of the joint observation and of the joint action, by agent name
    (``agent_split``: the robot's observation and action sizes; the person's parts follow them)."""
    obs_robot, act_robot = agent_split
    return (
        {"robot": slice(0, obs_robot), "human": slice(obs_robot, obs_size)},
        {"robot": slice(0, act_robot), "human": slice(act_robot, action_size)},
    )


class JointAgentsEnv(gym.Env):
    """Robot and person of a compiled co-optimisation task as one agent (see the module)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, artifact_dir: str | Path):
        #: The PettingZoo env underneath (its checks: the person must have policy joints).
        self.pair = AssistiveParallelEnv(artifact_dir)
        robot_obs, human_obs = (self.pair.observation_space(a) for a in ("robot", "human"))
        robot_act, human_act = (self.pair.action_space(a) for a in ("robot", "human"))
        self.observation_space = gym.spaces.Box(
            np.concatenate([robot_obs.low, human_obs.low]).astype(np.float32),
            np.concatenate([robot_obs.high, human_obs.high]).astype(np.float32),
            dtype=np.float32,
        )
        self.action_space = gym.spaces.Box(-1.0, 1.0, (robot_act.shape[0] + human_act.shape[0],), np.float32)
        #: (robot observation size, robot action size): where the person's part begins in each.
        self.agent_split = (int(robot_obs.shape[0]), int(robot_act.shape[0]))

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        _, infos = self.pair.reset(seed=seed, options=options)
        return self.pair.state(), infos["robot"]

    def step(self, action):
        n = self.agent_split[1]
        action = np.asarray(action, dtype=np.float32)
        _, rewards, terminated, truncated, infos = self.pair.step({"robot": action[:n], "human": action[n:]})
        return self.pair.state(), rewards["robot"], terminated["robot"], truncated["robot"], infos["robot"]

    def close(self):
        self.pair.close()
