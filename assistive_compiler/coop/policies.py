"""Policies for one agent of a co-optimisation env, by name or given: ``obs -> action``.

Robot: ``random``, ``zero``, ``scripted`` (the task's IK baseline). Human: ``random``, ``zero``
(the person keeps its policy joints where they are: a zero delta each step) and ``hold`` (no
human action at all: the static person of the single-agent task, ``step_agents(·, None)``).
Either agent: a trained policy by source (``pretrained:<task>-<robot>[-coop]``, a run directory,
an exported policy folder); a co-optimised pair gives each agent its own half, a robot-only
policy plays the robot.
A callable ``obs -> action`` or an object with Stable-Baselines3's ``predict(obs, deterministic)``
(a trained model) is used as it is.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..policies import HUMAN_POLICIES, POLICIES

__all__ = ["ROBOT_POLICIES", "HUMAN_POLICIES", "agent_policy"]

ROBOT_POLICIES = POLICIES

Policy = Callable[[np.ndarray], "np.ndarray | None"]


def agent_policy(env, agent: str, policy: Any, seed: int = 0) -> Policy:
    """``obs -> action`` for ``agent`` ('robot' or 'human') of ``env`` (an
    :class:`~assistive_compiler.coop.parallel.AssistiveParallelEnv`). ``random`` draws from its own
    generator seeded with ``seed`` (the env's spaces are left alone)."""
    if agent not in ("robot", "human"):
        raise ValueError(f"agent must be 'robot' or 'human', got {agent!r}")
    if isinstance(policy, str):
        names = ROBOT_POLICIES if agent == "robot" else HUMAN_POLICIES
        if policy not in names and _is_trained(policy):
            return trained_agent_policy(env, agent, policy)
        if policy not in names:
            raise ValueError(f"unknown {agent} policy '{policy}'; expected one of {', '.join(names)}")
        shape = env.action_space(agent).shape
        if policy == "hold":
            return lambda obs: None
        if policy == "zero":
            return lambda obs: np.zeros(shape, dtype=np.float32)
        if policy == "scripted":
            from ..policies import make_policy

            return make_policy("scripted", env.env)
        rng = np.random.default_rng(seed)
        return lambda obs: rng.uniform(-1.0, 1.0, shape).astype(np.float32)
    if callable(getattr(policy, "predict", None)):  # a trained model (Stable-Baselines3's interface)
        return lambda obs: policy.predict(obs, deterministic=True)[0]
    if callable(policy):
        return policy
    raise TypeError(
        f"a {agent} policy must be a name, a callable obs -> action or a model with predict(), got {type(policy).__name__}"
    )


def pair_policy(env, robot_policy: Any, human_policy: Any, seed: int = 0):
    """``(robot_obs, human_obs) -> (robot_action, human_action)``: ``robot_policy`` and
    ``human_policy`` (as :func:`agent_policy` takes them) in the single-agent ``env`` (an
    :class:`~assistive_compiler.runtime.env.AssistiveEnv`), the form a co-optimised pair has, so
    that the single-agent tools (``render``, ``view``'s recording; :func:`~assistive_compiler.policies.pair.both_agents`)
    play both agents."""
    from types import SimpleNamespace

    from ..errors import UsageError

    if env.human_action_space is None:
        raise UsageError(
            "--coop: the person of this task has no policy joints (person.control.policy_joints), so it cannot act"
        )
    spaces = {"robot": env.action_space, "human": env.human_action_space}
    agents = SimpleNamespace(env=env, action_space=spaces.__getitem__)
    robot, human = agent_policy(agents, "robot", robot_policy, seed), agent_policy(agents, "human", human_policy, seed)
    return lambda robot_obs, human_obs: (robot(robot_obs), human(human_obs))


def _is_trained(source: str) -> bool:
    from pathlib import Path

    from ..policies.pretrained import PREFIX

    return source.startswith(PREFIX) or Path(source).is_dir()


def trained_agent_policy(env, agent: str, source: str) -> Policy:
    """``agent``'s part of the trained policy ``source``, checked against the env's task and robot."""
    from ..errors import UsageError
    from ..policies.pretrained import check_fits, load_trained

    policy, info = load_trained(source)
    check_fits(info, env.env.manifest, source, coop=True)
    if info.get("coop"):
        return policy.agent(agent)
    if agent == "human":
        raise UsageError(
            f"--human-policy {source}: trained for the robot alone; a person's policy comes from a "
            "co-optimised pair (pretrained:<task>-<robot>-coop or a --coop run)"
        )
    return policy
