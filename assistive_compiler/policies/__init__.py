"""Policies to roll out: the baselines ``random``, ``zero`` and ``scripted``, and trained ones —
``pretrained:<task>-<robot>`` (shipped), a training run directory, or an exported policy folder
(see :func:`make_policy` and :mod:`.pretrained`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

POLICIES = ("random", "zero", "scripted")
#: The person's policies in co-optimisation (see :mod:`assistive_compiler.coop.policies`).
HUMAN_POLICIES = ("random", "zero", "hold")
#: How ``--policy`` is described in every rollout command's help.
POLICY_HELP = (
    "random, zero, scripted, pretrained:<task>-<robot> (a shipped trained policy, e.g. pretrained:feeding-jaco), "
    "or a training run directory (its newest checkpoint)"
)


def make_policy(name: str, env, seed: int = 0, trace: bool = False) -> Callable[[np.ndarray], np.ndarray]:
    """A callable ``obs -> action`` for ``env``. ``scripted`` needs a task with a ``scripted:``
    section (``trace``: it keeps a trace of its waypoint events, see
    :class:`~assistive_compiler.policies.scripted.ScriptedPolicy`); a trained policy (``pretrained:...``, a run or policy folder) must have been trained
    for the env's task and robot."""
    if name == "random":
        space = env.action_space
        space.seed(seed)
        return lambda obs: space.sample()
    if name == "zero":
        return lambda obs: np.zeros(env.action_space.shape, dtype=np.float32)
    if name == "scripted":
        from .scripted import ScriptedPolicy

        return ScriptedPolicy(env, trace=trace)
    from .pretrained import check_fits, load_trained

    policy, info = load_trained(name)
    check_fits(info, env.manifest, name)
    return policy


def make_player(name: str, env, seed: int = 0):
    """``(target, act)`` to play ``name`` in ``env`` with single-agent tools (render, record):
    ``act(obs)`` gives the action to step ``target`` with. A co-optimised pair plays both agents
    (``target`` steps the robot and the person); any other policy is :func:`make_policy`'s."""
    if name not in POLICIES:
        from .pretrained import check_fits, load_trained

        policy, info = load_trained(name)
        if info.get("coop"):
            from .pair import both_agents

            check_fits(info, env.manifest, name, coop=True)
            return both_agents(env, policy)
    return env, make_policy(name, env, seed=seed)
