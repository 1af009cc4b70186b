"""A trained policy as plain NumPy: a multilayer perceptron from observation to action.

Shipped and exported policies (:mod:`.pretrained`) are stored in this form so that rolling one
out needs no torch, Stable-Baselines3 or Ray: ``pip install assistive-compiler`` is enough to
``run``, ``render``, ``view``, ``collect`` or ``evaluate`` them. The file pair is

* ``policy.json`` — what the policy is (task, robot, algorithm, training and evaluation figures)
  and how to evaluate the network (``network``: activation, output head, layer names);
* ``weights.npz`` — the layers' weights and biases (float32) and, for policies trained on
  normalised observations, the running mean and variance used to normalise them.

The network is evaluated in float64 whatever the training library did; actions are the policy's
deterministic ones (the mean of its Gaussian), mapped to the action space's bounds as the
training library maps them: ``tanh`` (SAC's squashed Gaussian, then scaled to [low, high]) or
``clip`` (PPO's unbounded Gaussian mean, clipped to [low, high]).

Policies exported with their Gaussian's log-std (``network.log_std``
in ``policy.json``) can also act as they did in training: :meth:`MLPPolicy.sampling` draws each
action from the Gaussian (seeded) before the same squashing or clipping. The log-std is either a
layer on the last hidden features (``state``: SAC's, clamped to its library's bounds) or one free
vector (``free``: PPO's).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

POLICY_FILE = "policy.json"
WEIGHTS_FILE = "weights.npz"
ACTIVATIONS = {
    "tanh": np.tanh,
    "relu": lambda x: np.maximum(x, 0.0),
}
HEADS = ("tanh", "clip")


class MLPPolicy:
    """``obs -> action``: normalise the observation (if trained so), hidden layers, output head.

    ``layers``: ``[(W, b), ...]`` with ``W`` of shape (out, in), the last one the action layer.
    Observations are in the env's observation units; actions are in the env's action units.
    """

    def __init__(
        self,
        layers: list[tuple[np.ndarray, np.ndarray]],
        activation: str,
        head: str,
        action_low: np.ndarray,
        action_high: np.ndarray,
        obs_mean: np.ndarray | None = None,
        obs_var: np.ndarray | None = None,
        obs_clip: float = 10.0,
        obs_eps: float = 1e-8,
        info: dict | None = None,
        log_std: tuple[np.ndarray, np.ndarray] | np.ndarray | None = None,
        log_std_bounds: tuple[float, float] = (-20.0, 2.0),
    ):
        if activation not in ACTIVATIONS:
            raise ValueError(f"unknown activation '{activation}'; expected one of {', '.join(ACTIVATIONS)}")
        if head not in HEADS:
            raise ValueError(f"unknown output head '{head}'; expected one of {', '.join(HEADS)}")
        self.layers = [(np.asarray(w, dtype=np.float64), np.asarray(b, dtype=np.float64)) for w, b in layers]
        self.activation, self.head = activation, head
        self.low, self.high = np.asarray(action_low, dtype=np.float64), np.asarray(action_high, dtype=np.float64)
        self.obs_mean = None if obs_mean is None else np.asarray(obs_mean, dtype=np.float64)
        self.obs_var = None if obs_var is None else np.asarray(obs_var, dtype=np.float64)
        self.obs_std = None if obs_var is None else np.sqrt(self.obs_var + obs_eps)
        self.obs_clip, self.obs_eps = float(obs_clip), float(obs_eps)
        self.info = dict(info or {})
        if isinstance(log_std, tuple):  # a layer on the last hidden features: (W, b)
            self.log_std: tuple[np.ndarray, np.ndarray] | np.ndarray | None = tuple(
                np.asarray(a, dtype=np.float64) for a in log_std
            )
        else:
            self.log_std = None if log_std is None else np.asarray(log_std, dtype=np.float64)
        self.log_std_bounds = (float(log_std_bounds[0]), float(log_std_bounds[1]))

    @property
    def obs_dim(self) -> int:
        return self.layers[0][0].shape[1]

    @property
    def action_dim(self) -> int:
        return self.layers[-1][0].shape[0]

    @property
    def samples(self) -> bool:
        """Whether the policy carries its Gaussian's log-std, so :meth:`sampling` can act as in training."""
        return self.log_std is not None

    def _features(self, obs: np.ndarray) -> np.ndarray:
        """The last hidden layer's output for ``obs`` (normalised first where trained so)."""
        x = np.asarray(obs, dtype=np.float64)
        if self.obs_mean is not None:
            x = np.clip((x - self.obs_mean) / self.obs_std, -self.obs_clip, self.obs_clip)
        act = ACTIVATIONS[self.activation]
        for w, b in self.layers[:-1]:
            x = act(w @ x + b)
        return x

    def _to_bounds(self, x: np.ndarray) -> np.ndarray:
        if self.head == "tanh":
            x = self.low + 0.5 * (np.tanh(x) + 1.0) * (self.high - self.low)
        else:
            x = np.clip(x, self.low, self.high)
        return x.astype(np.float32)

    def _require_log_std(self) -> None:
        if self.log_std is None:
            raise ValueError("this policy was exported without its log-std (by an earlier version): it has a mean only")

    def mean_and_std(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The Gaussian's mean and standard deviation for ``obs``, before the squashing or clipping
        (the policy's [-1, 1]-scale pre-tanh units for SAC, the env's action units for PPO)."""
        self._require_log_std()
        h = self._features(obs)
        w, b = self.layers[-1]
        if isinstance(self.log_std, tuple):
            log_std = np.clip(self.log_std[0] @ h + self.log_std[1], *self.log_std_bounds)
        else:
            log_std = self.log_std
        return w @ h + b, np.exp(log_std)

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        w, b = self.layers[-1]
        return self._to_bounds(w @ self._features(obs) + b)

    def sampling(self, seed: int) -> SampledPolicy:
        """This policy acting as in training: each action a sample of its Gaussian, squashed or
        clipped as the mean is, from a generator seeded with ``seed``."""
        self._require_log_std()
        return SampledPolicy(self, np.random.default_rng(seed))

    # -- files ---------------------------------------------------------------------------------
    def save(self, directory: str | Path, info: dict) -> Path:
        """Write ``policy.json`` (``info`` plus the network's description) and ``weights.npz``."""
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        arrays: dict[str, np.ndarray] = {
            "action_low": self.low.astype(np.float32),
            "action_high": self.high.astype(np.float32),
        }
        for k, (w, b) in enumerate(self.layers):
            arrays[f"layer{k}_weight"] = w.astype(np.float32)
            arrays[f"layer{k}_bias"] = b.astype(np.float32)
        if self.obs_mean is not None:
            arrays["obs_mean"] = self.obs_mean
            arrays["obs_var"] = self.obs_var
        if isinstance(self.log_std, tuple):
            arrays["log_std_weight"] = self.log_std[0].astype(np.float32)
            arrays["log_std_bias"] = self.log_std[1].astype(np.float32)
        elif self.log_std is not None:
            arrays["log_std"] = self.log_std.astype(np.float32)
        network = {
            "activation": self.activation,
            "head": self.head,
            "layers": len(self.layers),
            "sizes": [self.obs_dim] + [w.shape[0] for w, _ in self.layers],
            "obs_normalised": self.obs_mean is not None,
            "obs_clip": self.obs_clip,
            "obs_eps": self.obs_eps,
            "log_std": None if self.log_std is None else ("state" if isinstance(self.log_std, tuple) else "free"),
            "log_std_bounds": list(self.log_std_bounds),
        }
        np.savez_compressed(directory / WEIGHTS_FILE, **arrays)
        (directory / POLICY_FILE).write_text(json.dumps({**info, "network": network}, indent=1) + "\n")
        self.info = {**info, "network": network}
        return directory

    @classmethod
    def load(cls, directory: str | Path) -> MLPPolicy:
        """The policy stored in ``directory`` (``policy.json`` + ``weights.npz``)."""
        directory = Path(directory)
        info = json.loads((directory / POLICY_FILE).read_text())
        net = info["network"]
        with np.load(directory / WEIGHTS_FILE) as z:
            layers = [(z[f"layer{k}_weight"], z[f"layer{k}_bias"]) for k in range(net["layers"])]
            mean = z["obs_mean"] if net["obs_normalised"] else None
            var = z["obs_var"] if net["obs_normalised"] else None
            low, high = z["action_low"], z["action_high"]
            kind = net.get("log_std")  # absent from exports of earlier versions
            log_std = (z["log_std_weight"], z["log_std_bias"]) if kind == "state" else z["log_std"] if kind else None
        return cls(
            layers,
            net["activation"],
            net["head"],
            low,
            high,
            mean,
            var,
            net["obs_clip"],
            net["obs_eps"],
            info=info,
            log_std=log_std,
            log_std_bounds=tuple(net.get("log_std_bounds", (-20.0, 2.0))),
        )


class SampledPolicy:
    """An :class:`MLPPolicy` acting as in training: ``obs -> action`` drawn from its Gaussian
    (mean and σ of :meth:`MLPPolicy.mean_and_std`), then squashed or clipped to the bounds. The
    noise comes from ``rng``, which a co-optimised pair's two agents share as their run's
    checkpoint does (:class:`~assistive_compiler.policies.checkpoint.RLlibPolicy`)."""

    def __init__(self, policy: MLPPolicy, rng: np.random.Generator):
        self.policy, self.info, self.rng = policy, policy.info, rng

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        mean, std = self.policy.mean_and_std(obs)
        return self.policy._to_bounds(mean + std * self.rng.standard_normal(mean.shape[0]))
