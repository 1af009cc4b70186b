"""SAC's twin Q critics with layer normalisation (``sac.critic_layer_norm``).

Each hidden layer of each critic is ``Linear → LayerNorm → activation`` instead of ``Linear →
activation``: the critic's features keep unit scale whatever the input, so its output is bounded
by the norm of its last layer's weights and cannot run away where the data are thin. Ball et al.
(2023, "Efficient Online Reinforcement Learning with Offline Data", RLPD) found this the one
change that lets SAC use offline data without its critics over-valuing the actions the data
never show; it is their default for every run from demonstrations. Measured here on Drinking's
demonstrations: docs/results.md (tenth sitting).

The classes are Stable-Baselines3's own with only the critic's layers changed; a model saved with
them records :class:`LayerNormSACPolicy` as its policy class, so it loads (``SAC.load``,
``--resume``, ``--policy RUN_DIR``) wherever this module is importable. The actor is SB3's.
"""

from __future__ import annotations

from stable_baselines3.common.policies import ContinuousCritic
from stable_baselines3.sac.policies import SACPolicy
from torch import nn


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
