"""Co-optimisation with Stable-Baselines3 SAC: one actor per agent, one critic for the pair.

The env is :class:`~assistive_compiler.coop.joint.JointAgentsEnv` (observation and action: the
robot's, then the person's; the reward they share). SAC's twin critics see the whole state and
both actions, as a centralised critic does (Lowe et al. 2017, MADDPG); the actor is two networks,
the robot's reading only the robot's observation and the person's only the person's, each with
its own Gaussian head. So training is centralised and acting is not: each exported policy plays
its agent alone, in the PettingZoo env, under ``--coop`` and in the viewer. One temperature and
one entropy target serve the joint action (SAC's default target: minus its size).

The classes are Stable-Baselines3's own with only the actor replaced; a model saved with them
records its policy class and ``agent_split`` (in ``policy_kwargs``), so it loads (``SAC.load``,
``--resume``, ``--policy RUN_DIR``) wherever this module is importable.
"""

from __future__ import annotations

import torch
from stable_baselines3.common.preprocessing import get_action_dim
from stable_baselines3.common.torch_layers import create_mlp
from stable_baselines3.sac.policies import LOG_STD_MAX, LOG_STD_MIN, Actor, SACPolicy
from torch import nn

from ...artifact import AGENTS
from ...coop.joint import agent_slices
from .critics import LayerNormSACPolicy


class AgentHead(nn.Module):
    """One agent's actor: its observation → hidden layers → Gaussian mean and log-std (SB3's
    ``latent_pi``, ``mu``, ``log_std`` names, so the export reads it as SB3's own actor)."""

    def __init__(self, obs_size: int, action_size: int, net_arch: list[int], activation_fn: type[nn.Module]):
        super().__init__()
        self.latent_pi = nn.Sequential(*create_mlp(obs_size, -1, net_arch, activation_fn))
        width = net_arch[-1] if net_arch else obs_size
        self.mu = nn.Linear(width, action_size)
        self.log_std = nn.Linear(width, action_size)


class FactoredActor(Actor):
    """SB3's SAC actor as one :class:`AgentHead` per agent (``heads['robot']``, ``heads['human']``),
    each on its own slice of the observation, their means and log-stds concatenated in the
    action's order. ``agent_split``: (robot observation size, robot action size)."""

    def __init__(self, *args, agent_split: tuple[int, int], **kwargs):
        super().__init__(*args, **kwargs)
        if self.use_sde:
            raise ValueError("a factored actor has Gaussian heads; gSDE (use_sde) is not supported")
        self.agent_split = (int(agent_split[0]), int(agent_split[1]))
        #: Each agent's slice of the (flattened) joint observation and of the joint action.
        self.obs_slices, self.action_slices = agent_slices(
            self.agent_split, self.features_dim, get_action_dim(self.action_space)
        )
        self.heads = nn.ModuleDict(
            {
                agent: AgentHead(
                    self.obs_slices[agent].stop - self.obs_slices[agent].start,
                    self.action_slices[agent].stop - self.action_slices[agent].start,
                    self.net_arch,
                    self.activation_fn,
                )
                for agent in AGENTS
            }
        )
        # SB3 built one joint network; the heads replace it (None: no parameters, nothing optimised).
        self.latent_pi = self.mu = self.log_std = None  # type: ignore[assignment]

    def _get_constructor_parameters(self) -> dict:
        return super()._get_constructor_parameters() | {"agent_split": self.agent_split}

    def get_action_dist_params(self, obs) -> tuple[torch.Tensor, torch.Tensor, dict]:
        features = self.extract_features(obs, self.features_extractor)
        means, log_stds = [], []
        for agent in AGENTS:
            head = self.heads[agent]
            latent = head.latent_pi(features[:, self.obs_slices[agent]])
            means.append(head.mu(latent))
            log_stds.append(head.log_std(latent))
        return torch.cat(means, dim=-1), torch.clamp(torch.cat(log_stds, dim=-1), LOG_STD_MIN, LOG_STD_MAX), {}


class FactoredSACPolicy(SACPolicy):
    """SB3's SAC policy with a :class:`FactoredActor` (``agent_split`` in ``policy_kwargs``)."""

    def __init__(self, *args, agent_split: tuple[int, int], **kwargs):
        #: (robot observation size, robot action size), as :class:`FactoredActor` has it.
        self.agent_split = (int(agent_split[0]), int(agent_split[1]))  # make_actor runs inside SACPolicy.__init__
        super().__init__(*args, **kwargs)

    def make_actor(self, features_extractor=None) -> Actor:
        actor_kwargs = self._update_features_extractor(self.actor_kwargs, features_extractor)
        return FactoredActor(**actor_kwargs, agent_split=self.agent_split).to(self.device)

    def _get_constructor_parameters(self) -> dict:
        return super()._get_constructor_parameters() | {"agent_split": self.agent_split}


class FactoredLayerNormSACPolicy(FactoredSACPolicy, LayerNormSACPolicy):
    """:class:`FactoredSACPolicy` whose critics are layer-normalised (``sac.critic_layer_norm``)."""
