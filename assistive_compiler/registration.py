"""Gymnasium registration of the task ids (:mod:`assistive_compiler.gym_ids`) and the artifact
cache behind them.

Registration reads only the shipped task files' ids (plain YAML), so ``import assistive_compiler``
stays light. An env made by id is compiled on first use into the artifact cache
(``$ASSISTIVE_COMPILER_CACHE``, default ``~/.cache/assistive-compiler``) and reused while its
inputs are unchanged.
"""

from __future__ import annotations

import os
from pathlib import Path

from .gym_ids import TASK_ID, shipped_ids
from .paths import specs_dir


def cache_dir() -> Path:
    root = (
        os.environ.get("ASSISTIVE_COMPILER_CACHE")
        or Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "assistive-compiler"
    )
    return Path(root)


def cached_artifact_dir(spec: str | Path, robot: str | None) -> Path:
    """Where an env made by name compiles ``spec`` for ``robot``: ``$ASSISTIVE_COMPILER_CACHE/<task>-<robot>``
    (shared by the Gymnasium id and the co-optimisation name of the same task and robot). A spec that
    is not shipped gets a folder of its own path's (``<stem>-<path hash>-<robot>``), so two user specs
    of the same file name do not take turns recompiling one folder."""
    import hashlib

    from .spec.load import spec_path

    path = spec_path(spec).resolve()  # a shipped task's name or shipped:tasks/<file> too
    label = robot or "default"
    if path.parent == (specs_dir() / "tasks").resolve():
        return cache_dir() / f"{path.stem}-{label}"
    return cache_dir() / f"{path.stem}-{hashlib.sha256(str(path).encode()).hexdigest()[:8]}-{label}"


def make_env(spec: str, robot: str | None = None, **kwargs):
    """Entry point of registered ids: compile (cached) into the artifact cache and build the env
    (``robot`` None: the spec's default robot)."""
    from .runtime.env import AssistiveEnv

    return AssistiveEnv.from_spec(spec, robot=robot, out_dir=cached_artifact_dir(spec, robot), **kwargs)


def register_all() -> list[str]:
    import gymnasium

    ids = []
    for env_id, (spec, robot) in shipped_ids().items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point="assistive_compiler.registration:make_env",
                kwargs={"spec": str(spec), "robot": robot},
                disable_env_checker=True,
            )
        ids.append(env_id)
    if TASK_ID not in gymnasium.registry:  # any other spec: gym.make(TASK_ID, spec=..., robot=...)
        gymnasium.register(id=TASK_ID, entry_point="assistive_compiler.registration:make_env", disable_env_checker=True)
    return ids
