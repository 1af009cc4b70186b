"""The policy's and critics' network, as the learning library takes it: hidden layer widths and
the activation, a PyTorch module class for SB3 and a JAX function for SBX."""

from __future__ import annotations

from ..config import TrainingConfig

ACTIVATIONS = {"tanh": "Tanh", "relu": "ReLU"}


def policy_kwargs(config: TrainingConfig) -> dict:
    """The network's shape and activation as the learning library takes them (a PyTorch module
    class for SB3, a JAX function for SBX)."""
    hidden = list(config.network.hidden)
    arch = {"pi": hidden, "vf": hidden} if config.algorithm == "ppo" else {"pi": hidden, "qf": hidden}
    if config.library == "sbx":
        import flax.linen

        return {"net_arch": arch, "activation_fn": getattr(flax.linen, config.network.activation)}
    import torch.nn as nn

    return {"net_arch": arch, "activation_fn": getattr(nn, ACTIVATIONS[config.network.activation])}
