"""Co-optimisation envs by name, the reference's naming: ``<Task><Robot>Human-v1`` (e.g.
``FeedingJacoHuman-v1``), one per shipped task and supported robot (30).

``make(name)`` compiles on first use into the artifact cache (``$ASSISTIVE_COMPILER_CACHE``,
the same artifact as the Gymnasium id ``assistive_compiler/<Task><Robot>-v1``) and returns an
:class:`~assistive_compiler.coop.parallel.AssistiveParallelEnv`. These are PettingZoo envs, not
Gymnasium ids: for one agent against a fixed partner see :class:`~assistive_compiler.coop.partner.FixedPartner`.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import did_you_mean
from ..gym_ids import NAMESPACE, shipped_ids
from ..registration import cached_artifact_dir
from .parallel import AssistiveParallelEnv, coop_name, parallel_env

__all__ = ["ids", "make", "spec_of"]


def _names() -> dict[str, tuple[Path, str]]:
    return {coop_name(gym_id): where for gym_id, where in shipped_ids().items()}


def ids() -> list[str]:
    """Every co-optimisation name, sorted (``ArmManipulationBaxterHuman-v1`` … ``ScratchItchSawyerHuman-v1``)."""
    return sorted(_names())


def spec_of(name: str) -> tuple[Path, str]:
    """(task spec path, robot) of a co-optimisation name; a ``ValueError`` with a suggestion if unknown."""
    names = _names()
    key = name.removeprefix(f"{NAMESPACE}/")
    if key not in names:
        raise ValueError(
            f"unknown co-optimisation env '{name}'{did_you_mean(key, names)}; "
            f"expected <Task><Robot>Human-v1, one of assistive_compiler.coop.ids() ({len(names)} in all)"
        )
    return names[key]


def make(name: str, render_mode: str | None = None, **kwargs) -> AssistiveParallelEnv:
    """The co-optimisation env called ``name`` (e.g. ``"FeedingJacoHuman-v1"``), compiled into the cache."""
    spec, robot = spec_of(name)
    return parallel_env(spec, robot=robot, render_mode=render_mode, out_dir=cached_artifact_dir(spec, robot), **kwargs)
