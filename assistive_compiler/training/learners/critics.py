"""SAC's twin Q critics: layer-normalised (``sac.critic_layer_norm``) and conservative
(``sac.conservative_weight``).

Each hidden layer of each critic is ``Linear → LayerNorm → activation`` instead of ``Linear →
activation``: the critic's features keep unit scale whatever the input, so its output is bounded
by the norm of its last layer's weights and cannot run away where the data are thin. Ball et al.
(2023, "Efficient Online Reinforcement Learning with Offline Data", RLPD) make it their default
for SAC on offline data, against critics that over-value actions the data never show. Measured
here on Drinking's demonstrations (docs/results.md, tenth sitting): it stops the plain critics'
divergence, but alone their values still drift above the returns; with the conservative update
below they stay ordered, and SAC improved on the cloned policy.

The classes are Stable-Baselines3's own with only the critic's layers changed; a model saved with
them records :class:`LayerNormSACPolicy` as its policy class, so it loads (``SAC.load``,
``--resume``, ``--policy RUN_DIR``) wherever this module is importable. The actor is SB3's.

A conservative critic (:class:`ConservativeCriticUpdate`, CQL: Kumar et al. 2020) adds to each
critic update the gap between a soft maximum of Q over actions the buffer did not take and Q of
the action it did, so the critics value unseen actions lower and the actor's gradient points back
toward the data instead of off into actions nobody tried.
"""

from __future__ import annotations

import math

import torch
from stable_baselines3.common.policies import ContinuousCritic
from stable_baselines3.sac.policies import SACPolicy
from torch import nn

from .wrapped_optimizer import WrappedOptimizer


def layer_normed(q_network: nn.Sequential) -> nn.Sequential:
    """``q_network`` (SB3's ``Linear, act, ..., Linear``) rebuilt with a LayerNorm after every
    hidden Linear, fresh weights, the same widths and activation."""
    linears = [m for m in q_network if isinstance(m, nn.Linear)]
    activations = [m for m in q_network if not isinstance(m, nn.Linear)]
    layers: list[nn.Module] = []
    for linear, activation in zip(linears[:-1], activations, strict=True):
        layers += [nn.Linear(linear.in_features, linear.out_features), nn.LayerNorm(linear.out_features), activation]
    layers.append(nn.Linear(linears[-1].in_features, linears[-1].out_features))
    return nn.Sequential(*layers)


class LayerNormCritic(ContinuousCritic):
    """SB3's twin critics (``qf0``, ``qf1``), each hidden layer layer-normalised."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.q_networks = [layer_normed(q) for q in self.q_networks]
        for index, q_network in enumerate(self.q_networks):
            self.add_module(f"qf{index}", q_network)  # replaces SB3's registered module of that name


class LayerNormSACPolicy(SACPolicy):
    """SB3's SAC policy whose critic and target critic are :class:`LayerNormCritic`."""

    def make_critic(self, features_extractor=None) -> ContinuousCritic:
        critic_kwargs = self._update_features_extractor(self.critic_kwargs, features_extractor)
        return LayerNormCritic(**critic_kwargs).to(self.device)


class ConservativeCriticUpdate(WrappedOptimizer):
    """SAC's critic optimiser with CQL's regulariser (the CQL(H) form for SAC).

    SB3's SAC back-propagates its critic loss and calls ``critic.optimizer.step()``. Before that step
    this object adds the gradient of

        weight × Σ_critics mean_s [ log Σ_a' exp(Q(s, a') − log p(a')) − log 2k − Q(s, a_buffer) ]

    on ``states`` transitions (s, a_buffer) of the replay buffer, with k actions a' drawn uniformly
    from the [-1, 1] action box (p = 2^-|A|) and k from the current policy at s (p = π(a'|s)): the
    importance-weighted soft maximum of Q over actions, minus Q of the action taken. It is zero
    when unseen actions are valued no higher than the taken one and pushes them down otherwise.
    The gap is logged as ``train/conservative_gap``."""

    def __init__(self, model, weight: float, actions_per_state: int = 4, states: int = 64, seed: int = 0):
        super().__init__(model.critic.optimizer)
        self._model, self._weight, self._k, self._states = model, weight, actions_per_state, states
        self._generator = torch.Generator().manual_seed(seed)

    def gap(self, obs: torch.Tensor, taken: torch.Tensor) -> torch.Tensor:
        """The conservative gap summed over the critics, per state (with the critics' gradient)."""
        model, k = self._model, self._k
        n, dims = taken.shape
        repeated = obs.repeat_interleave(k, dim=0)
        uniform = torch.rand(n * k, dims, generator=self._generator) * 2.0 - 1.0
        with torch.no_grad():
            sampled, log_prob = model.actor.action_log_prob(repeated)
        log_uniform = -dims * math.log(2.0)
        # one forward pass of each critic over the n·k uniform, n·k sampled and n taken pairs
        values = model.critic(torch.cat([repeated, repeated, obs]), torch.cat([uniform, sampled, taken]))
        total = torch.zeros(n)
        for q in values:
            q_uniform, q_sampled, q_taken = q.view(-1).split([n * k, n * k, n])
            soft = torch.cat([q_uniform.view(n, k) - log_uniform, q_sampled.view(n, k) - log_prob.view(n, k)], dim=1)
            total = total + torch.logsumexp(soft, dim=1) - math.log(2 * k) - q_taken
        return total

    def step(self, closure=None):
        batch = self._model.replay_buffer.sample(self._states)
        gap = self.gap(batch.observations, batch.actions).mean()
        (self._weight * gap).backward()
        if getattr(self._model, "_logger", None) is not None:  # SB3 sets its logger up when learn() starts
            self._model.logger.record_mean("train/conservative_gap", gap.item())
        return self.optimizer.step(closure)


def make_conservative(model, weight: float, seed: int) -> None:
    """From now on ``model``'s critics update conservatively (:class:`ConservativeCriticUpdate`)."""
    if weight > 0 and not isinstance(model.critic.optimizer, ConservativeCriticUpdate):
        model.critic.optimizer = ConservativeCriticUpdate(model, weight, seed=seed)
