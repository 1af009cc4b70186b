"""An SB3 optimiser with work added around its ``step``: how the SAC settings that change an update
(``sac.conservative_weight``, ``sac.actor_learning_rate``, ``sac.actor_average_tau``,
``demonstrations.clone_weight`` and ``hold_actor_steps``) reach into Stable-Baselines3's own loop.

SB3's SAC back-propagates each loss and calls ``<actor or critic>.optimizer.step()``; a subclass
replaces that optimiser and overrides :meth:`WrappedOptimizer.step`. Everything else
(``zero_grad``, ``state_dict``, ``param_groups``: SB3 saves, loads and schedules through them) is
the wrapped optimiser's, so checkpoints stay SB3's. Wrappers nest; none is saved, so a resumed run
wraps its optimisers again from its config.
"""

from __future__ import annotations


class WrappedOptimizer:
    """``optimizer`` as it is; subclasses add to :meth:`step`."""

    def __init__(self, optimizer):
        self.optimizer = optimizer

    def step(self, closure=None):
        return self.optimizer.step(closure)

    def __getattr__(self, name: str):
        return getattr(self.__dict__["optimizer"], name)
