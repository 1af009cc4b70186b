"""Which learner a training config asks for, built new: its ``algorithm`` (and ``sac.library``)
picks the module that builds it. A new learner is a module beside :mod:`.ppo` and :mod:`.sac`
and one branch here. Loading a saved one goes through its library's class
(:func:`assistive_compiler.policies.checkpoint.algorithm_class`)."""

from __future__ import annotations

from ...run_dir import RunDir
from ..config import TrainingConfig


def new_model(venv, config: TrainingConfig, run: RunDir, agent_split: tuple[int, int] | None = None):
    """A new model of the config's algorithm on ``venv`` (``agent_split``: a co-optimised pair's
    robot observation and action sizes: one actor per agent)."""
    if config.sac is not None:
        from .sac import new_sac

        return new_sac(venv, config, run, agent_split)
    from .ppo import new_ppo

    return new_ppo(venv, config, run, agent_split)
