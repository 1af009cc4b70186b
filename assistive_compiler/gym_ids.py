"""The Gymnasium ids of tasks: ``assistive_compiler/<Task><Robot>-v1`` for each shipped task and
supported robot, and ``assistive_compiler/Task-v1`` for any other task spec
(``gym.make(TASK_ID, spec=PATH, robot=NAME)``).

Ids are read from the shipped task files with plain YAML (each task's name, title and supported
robots, each robot's title): no validation, no compile, no Gymnasium. The artifact's manifest and
the compiler name tasks by these ids; :mod:`assistive_compiler.registration` registers them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import yaml

from .paths import specs_dir

NAMESPACE = "assistive_compiler"
TASK_ID = f"{NAMESPACE}/Task-v1"
"""The id of a task spec that is not shipped: ``gym.make(TASK_ID, spec="my_task.yaml", robot="jaco")``."""


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
