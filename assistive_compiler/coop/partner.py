"""One agent learns, the other is fixed: a co-optimisation env as a plain Gymnasium env.

``FixedPartner(parallel_env, fixed="human", policy=...)`` exposes the *robot* as a Gymnasium env
whose person acts by the given policy ("train the robot against a fixed human policy");
``fixed="robot"`` exposes the *human* against a fixed robot. The partner policy is a name
(:mod:`.policies`: ``zero``, ``random``, ``hold`` for the human, ``scripted`` for the robot), a
callable ``obs -> action`` given the partner's own observation, or a trained model with
``predict(obs, deterministic)`` (e.g. a Stable-Baselines3 checkpoint loaded by the caller).

The learner's spaces, the shared reward, its ``info`` and the episode end are the parallel
env's. ``reset(seed=s)`` replays the episode bit for bit (a named ``random`` partner is reseeded
from ``s`` too).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from .parallel import AGENTS, AssistiveParallelEnv
from .policies import agent_policy

__all__ = ["FixedPartner"]


class FixedPartner(gym.Env):
    """The non-fixed agent of ``env`` as a Gymnasium env; the ``fixed`` agent acts by ``policy``."""

    def __init__(self, env: AssistiveParallelEnv, fixed: str, policy: Any):
        if fixed not in AGENTS:
            raise ValueError(f"fixed must be 'robot' or 'human', got {fixed!r}")
        self.parallel = env
        self.fixed = fixed
        self.learner = "robot" if fixed == "human" else "human"
        self._policy_arg = policy
        self.partner = agent_policy(env, fixed, policy)
        self.observation_space = env.observation_space(self.learner)
        self.action_space = env.action_space(self.learner)
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": env.metadata["render_fps"]}
        self.render_mode = env.render_mode
        self._partner_obs: np.ndarray | None = None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if seed is not None and isinstance(self._policy_arg, str):
            self.partner = agent_policy(self.parallel, self.fixed, self._policy_arg, seed=seed)
        obs, infos = self.parallel.reset(seed=seed, options=options)
        self._partner_obs = obs[self.fixed]
        return obs[self.learner], infos[self.learner]

    def step(self, action):
        if self._partner_obs is None:
            raise RuntimeError("step() before reset()")
        actions = {self.learner: action, self.fixed: self.partner(self._partner_obs)}
        obs, rewards, terminations, truncations, infos = self.parallel.step(actions)
        self._partner_obs = obs[self.fixed]
        me = self.learner
        return obs[me], rewards[me], terminations[me], truncations[me], infos[me]

    def render(self):
        return self.parallel.render()

    def close(self):
        self.parallel.close()
