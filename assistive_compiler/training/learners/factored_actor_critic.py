"""Co-optimisation with Stable-Baselines3 PPO: one actor per agent, one value function for the pair.

The PPO counterpart of :mod:`.factored_actor` (SAC), on the same env
(:class:`~assistive_compiler.coop.joint.JointAgentsEnv`: observation and action, the robot's
then the person's; the reward they share). The value function reads the whole joint
observation, a centralised critic as in MAPPO (Yu et al. 2022); the policy's Gaussian mean is
two networks, the robot's reading only the robot's observation and the person's only the
person's, and PPO's state-independent log-std is one entry per action dimension, so each agent's
entries are its own. Training is centralised, acting is not: each agent exports to a NumPy
policy that plays alone, under ``--coop`` and in the viewer. (The paper co-optimises with two
independent PPO learners, one critic each, §IV; one critic for the pair sees what both agents
do, and their shared reward makes one value function enough.)

The classes are Stable-Baselines3's own with only the networks replaced; a saved model records its
policy class and ``agent_split`` (in ``policy_kwargs``), so it loads (``PPO.load``, ``--resume``,
``--policy RUN_DIR``) wherever this module is importable.
"""

from __future__ import annotations

import torch
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.common.preprocessing import get_action_dim
from stable_baselines3.common.torch_layers import create_mlp
from torch import nn

from ...artifact import AGENTS
from ...coop.joint import agent_slices


def _width(s: slice) -> int:
    return s.stop - s.start


class FactoredExtractor(nn.Module):
    """SB3's ``MlpExtractor`` for a pair: the policy's latent is each agent's hidden layers on
    its own observation, side by side (robot's, then person's); the value's is one network on
    the joint observation. ``latent_dim_pi``, ``latent_dim_vf``: as SB3's extractor has them."""

    def __init__(self, feature_dim: int, net_arch: dict, activation_fn: type[nn.Module], obs_slices: dict):
        super().__init__()
        pi, vf = list(net_arch["pi"]), list(net_arch["vf"])
        if not pi:
            raise ValueError("a factored actor needs at least one hidden layer per agent (network.hidden)")
        self.obs_slices = obs_slices
        self.policy_heads = nn.ModuleDict(
            {agent: nn.Sequential(*create_mlp(_width(obs_slices[agent]), -1, pi, activation_fn)) for agent in AGENTS}
        )
        self.value_net = nn.Sequential(*create_mlp(feature_dim, -1, vf, activation_fn))
        self.head_width = pi[-1]
        self.latent_dim_pi = len(AGENTS) * pi[-1]
        self.latent_dim_vf = vf[-1] if vf else feature_dim

    def forward(self, features: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return self.forward_actor(features), self.forward_critic(features)

    def forward_actor(self, features: torch.Tensor) -> torch.Tensor:
        return torch.cat([self.policy_heads[a](features[:, self.obs_slices[a]]) for a in AGENTS], dim=-1)

    def forward_critic(self, features: torch.Tensor) -> torch.Tensor:
        return self.value_net(features)


class FactoredActionNet(nn.Module):
    """The Gaussian's means: each agent's linear layer on its own part of the policy latent,
    concatenated in the joint action's order (robot's, then person's)."""

    def __init__(self, head_width: int, action_slices: dict):
        super().__init__()
        self.head_width = head_width
        self.heads = nn.ModuleDict({agent: nn.Linear(head_width, _width(action_slices[agent])) for agent in AGENTS})

    def forward(self, latent: torch.Tensor) -> torch.Tensor:
        w = self.head_width
        return torch.cat([self.heads[a](latent[:, k * w : (k + 1) * w]) for k, a in enumerate(AGENTS)], dim=-1)


class FactoredActorCriticPolicy(ActorCriticPolicy):
    """SB3's PPO policy with one actor per agent (:class:`FactoredExtractor`,
    :class:`FactoredActionNet`) and one value function; ``agent_split`` (robot observation size,
    robot action size) in ``policy_kwargs``. Orthogonal initialisation as SB3's own (gain √2 for
    hidden layers, 0.01 for the means)."""

    def __init__(self, *args, agent_split: tuple[int, int], **kwargs):
        self.agent_split = (int(agent_split[0]), int(agent_split[1]))  # _build runs inside __init__
        super().__init__(*args, **kwargs)
        if self.use_sde:
            raise ValueError("a factored actor has one Gaussian per agent; gSDE (use_sde) is not supported")

    def _build_mlp_extractor(self) -> None:
        self.obs_slices, self.action_slices = agent_slices(
            self.agent_split, self.features_dim, get_action_dim(self.action_space)
        )
        self.mlp_extractor = FactoredExtractor(self.features_dim, self.net_arch, self.activation_fn, self.obs_slices)

    def _build(self, lr_schedule) -> None:
        super()._build(lr_schedule)
        # SB3 built one linear layer from the whole latent to all means: one per agent instead
        self.action_net = FactoredActionNet(self.mlp_extractor.head_width, self.action_slices)
        if self.ortho_init:
            self.action_net.apply(lambda m: self.init_weights(m, gain=0.01))
        self.optimizer = self.optimizer_class(self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs)

    def _get_constructor_parameters(self) -> dict:
        return super()._get_constructor_parameters() | {"agent_split": self.agent_split}
