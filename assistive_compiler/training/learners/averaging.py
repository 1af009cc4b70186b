"""Policy weight averaging for SAC (``sac.actor_average_tau``).

An off-policy actor keeps moving while its critics do: Drinking's SAC-from-demonstrations run drank
on 31% of the unseen seeds at 40,091 env steps and on 5% at 50,000 (docs/results.md), so a
checkpoint is one draw from a policy that swings. Nikishin et al. (2018, "Improving Stability in
Deep Reinforcement Learning with Weight Averaging") act with an average of the weights instead.
Here it is an exponential moving average, updated after every actor step as the target critics
are (Polyak):

    average ← (1 − τ)·average + τ·actor,

so it follows the actor over about 1/τ updates. Training explores and learns with the actor
itself; the checkpoint carries the average beside it (``actor_average.pt``, the actor's
``state_dict``), and whatever acts from the checkpoint — evaluation, export, ``--policy RUN_DIR``
— loads it in the actor's place (:class:`~assistive_compiler.policies.checkpoint.SB3Policy`).
"""

from __future__ import annotations

from pathlib import Path

import torch
from stable_baselines3.common.utils import polyak_update

from ...errors import UsageError
from ...policies.checkpoint import ACTOR_AVERAGE
from .wrapped_optimizer import WrappedOptimizer


class AveragedActorUpdate(WrappedOptimizer):
    """SAC's actor optimiser, followed after each step by the average's Polyak update. The
    average's distance from the actor, relative to the actor's weights' norm, is logged as
    ``train/actor_average_distance``."""

    def __init__(self, model, tau: float):
        super().__init__(model.actor.optimizer)
        self._model, self._tau = model, tau
        self.average = model.policy.make_actor()  # the same architecture, its own weights
        self.average.load_state_dict(model.actor.state_dict())
        self.average.requires_grad_(False)

    def step(self, closure=None):
        result = self.optimizer.step(closure)
        actor = self._model.actor
        polyak_update(actor.parameters(), self.average.parameters(), self._tau)
        if getattr(self._model, "_logger", None) is not None:  # SB3 sets its logger up when learn() starts
            with torch.no_grad():
                live = torch.cat([p.view(-1) for p in actor.parameters()])
                mean = torch.cat([p.view(-1) for p in self.average.parameters()])
                self._model.logger.record_mean(
                    "train/actor_average_distance", float((mean - live).norm() / live.norm().clamp_min(1e-12))
                )
        return result

    def save(self, checkpoint: Path) -> None:
        torch.save(self.average.state_dict(), checkpoint / ACTOR_AVERAGE)


def averaged(model) -> AveragedActorUpdate | None:
    """``model``'s actor average, where it keeps one."""
    actor = getattr(model, "actor", None)  # SAC's; PPO has none
    optimizer = getattr(actor, "optimizer", None)
    return optimizer if isinstance(optimizer, AveragedActorUpdate) else None


def make_averaged(model, tau: float, checkpoint: Path | None) -> None:
    """From now on ``model`` keeps an average of its actor's weights: a new one from the actor as it
    is, or (resuming) the one saved in ``checkpoint``."""
    if tau <= 0 or averaged(model) is not None:
        return
    update = AveragedActorUpdate(model, tau)
    if checkpoint is not None:
        saved = checkpoint / ACTOR_AVERAGE
        if not saved.is_file():
            raise UsageError(
                f"{saved}: --resume of a run with sac.actor_average_tau needs the checkpoint's averaged actor, "
                "which is missing"
            )
        update.average.load_state_dict(torch.load(saved, weights_only=True))
    model.actor.optimizer = update
