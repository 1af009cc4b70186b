"""Baseline policies: ``random``, ``zero`` and ``scripted`` (see :func:`make_policy`)."""

from __future__ import annotations

from typing import Callable

import numpy as np

POLICIES = ("random", "zero", "scripted")
#: The person's policies in co-optimisation (see :mod:`assistive_compiler.coop.policies`).
HUMAN_POLICIES = ("random", "zero", "hold")


def make_policy(name: str, env, seed: int = 0) -> Callable[[np.ndarray], np.ndarray]:
    """A callable ``obs -> action`` for ``env``. ``scripted`` needs a task with a ``scripted:`` section."""
    if name == "random":
        space = env.action_space
        space.seed(seed)
        return lambda obs: space.sample()
    if name == "zero":
        return lambda obs: np.zeros(env.action_space.shape, dtype=np.float32)
    if name == "scripted":
        from .scripted import ScriptedPolicy

        return ScriptedPolicy(env)
    raise ValueError(f"unknown policy '{name}'; expected one of {', '.join(POLICIES)}")
