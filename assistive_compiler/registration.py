"""Gymnasium ids for the shipped tasks: ``assistive_compiler/<Task><Robot>-v1``, and
``assistive_compiler/Task-v1`` for any other task spec (``gym.make(TASK_ID, spec=PATH, robot=NAME)``).

Registration reads only each task's name, title and supported robots (and each robot's title)
with plain YAML, so ``import assistive_compiler`` stays light. An env made by id is compiled on
first use into the artifact cache (``$ASSISTIVE_COMPILER_CACHE``, default
``~/.cache/assistive-compiler``) and reused while its inputs are unchanged.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import yaml

from .paths import specs_dir

NAMESPACE = "assistive_compiler"
TASK_ID = f"{NAMESPACE}/Task-v1"
"""The id of a task spec that is not shipped: ``gym.make(TASK_ID, spec="my_task.yaml", robot="jaco")``."""


def cache_dir() -> Path:
    root = (
        os.environ.get("ASSISTIVE_COMPILER_CACHE")
        or Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "assistive-compiler"
    )
    return Path(root)


@dataclass(frozen=True)
class ShippedTask:
    """A task spec shipped with the package, its supported robots and their Gymnasium ids."""

    name: str
    title: str
    spec: Path
    robots: list[str]
    ids: list[str]


def shipped_tasks() -> list[ShippedTask]:
    """Every shipped task (``specs/tasks/*.yaml``), read with plain YAML (no validation, no compile)."""
    out: list[ShippedTask] = []
    robots_dir = specs_dir() / "robots"
    robot_titles: dict[str, str] = {}  # each robot file read once, not once per task supporting it

    def robot_title(robot: str) -> str:
        if robot not in robot_titles:
            robot_file = robots_dir / f"{robot}.yaml"
            robot_titles[robot] = (
                (yaml.safe_load(robot_file.read_text()) or {}).get("title", robot) if robot_file.is_file() else robot
            )
        return robot_titles[robot]

    for spec in sorted((specs_dir() / "tasks").glob("*.yaml")):
        data = yaml.safe_load(spec.read_text()) or {}
        title = str(data.get("title", spec.stem))
        robots = list((data.get("robot") or {}).get("supported", []))
        ids = [f"{NAMESPACE}/{title.replace(' ', '')}{robot_title(robot)}-v1" for robot in robots]
        out.append(ShippedTask(str(data.get("name", spec.stem)), title, spec, robots, ids))
    return out


def shipped_ids() -> dict[str, tuple[Path, str]]:
    """Gymnasium id → (task spec path, robot name) for every shipped task and supported robot."""
    return {env_id: (t.spec, robot) for t in shipped_tasks() for robot, env_id in zip(t.robots, t.ids)}


def shipped_gym_id(spec: str | Path, name: str, robot: str) -> str | None:
    """The registered id of ``spec`` compiled for ``robot`` when ``spec`` is a shipped task file
    (and still names that task), else None: only shipped tasks have ids of their own."""
    path = Path(spec).resolve()
    for task in shipped_tasks():
        if task.spec.resolve() == path and task.name == name and robot in task.robots:
            return task.ids[task.robots.index(robot)]
    return None


def cached_artifact_dir(spec: str | Path, robot: str | None) -> Path:
    """Where an env made by name compiles ``spec`` for ``robot``: ``$ASSISTIVE_COMPILER_CACHE/<task>-<robot>``
    (shared by the Gymnasium id and the co-optimisation name of the same task and robot). A spec that
    is not shipped gets a folder of its own path's (``<stem>-<path hash>-<robot>``), so two user specs
    of the same file name do not take turns recompiling one folder."""
    import hashlib

    path = Path(spec).resolve()
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
