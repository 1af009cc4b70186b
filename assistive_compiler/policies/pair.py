"""A co-optimised pair played in a single-agent env: the tools that step one agent (``render``,
``record``, evaluation) run the robot and the person together through the env's
``step_agents`` face."""

from __future__ import annotations


class BothAgents:
    """A co-optimisation env seen as a robot-only one, so single-agent tools (``record``) can run
    it: the robot's action comes from :meth:`robot_action`, which also picks the human's from a
    co-optimised pair ``policy(robot_obs, human_obs) -> (robot_action, human_action)``."""

    def __init__(self, env, policy):
        self.env, self.policy, self.human_action = env, policy, None

    def __getattr__(self, name):
        return getattr(self.env, name)

    def robot_action(self, obs):
        a_robot, self.human_action = self.policy(obs, self.env.unwrapped.observe_human())
        return a_robot

    def step(self, a_robot):
        obs, _, reward, terminated, truncated, info = self.env.step_agents(a_robot, self.human_action)
        return obs, reward, terminated, truncated, info


def both_agents(env, pair):
    """``(target, act)`` to play a co-optimised ``pair`` in a single-agent
    :class:`~assistive_compiler.runtime.env.AssistiveEnv` (its ``step_agents`` face): step
    ``target`` with ``act(obs)``, and the person acts too."""
    both = BothAgents(env, pair)
    return both, both.robot_action
