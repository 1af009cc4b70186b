"""SAC's actor at a learning rate of its own (``sac.actor_learning_rate``).

Stable-Baselines3 sets every optimiser of SAC (actor, critics, temperature) to the one learning-rate
schedule before each round of gradient steps. The wrapper below sets the actor's back to its own
rate right before each of its steps; nothing else of SAC changes.
"""

from __future__ import annotations

from .wrapped_optimizer import WrappedOptimizer


class ActorLearningRate(WrappedOptimizer):
    """The actor's optimiser, stepping at ``learning_rate``."""

    def __init__(self, optimizer, learning_rate: float):
        super().__init__(optimizer)
        self._learning_rate = learning_rate

    def step(self, closure=None):
        for group in self.optimizer.param_groups:
            group["lr"] = self._learning_rate
        return self.optimizer.step(closure)


def set_actor_learning_rate(model, learning_rate: float) -> None:
    """From now on ``model``'s actor steps at ``learning_rate`` (not in the checkpoint: a resumed
    run sets it again from its config)."""
    if not isinstance(model.actor.optimizer, ActorLearningRate):
        model.actor.optimizer = ActorLearningRate(model.actor.optimizer, learning_rate)
