"""Playing a training run directory's newest checkpoint: Stable-Baselines3 and RLlib checkpoints
as plain functions of raw observations, deterministic. Needs the ``train`` extra (torch, and SB3
or Ray); the run directory's format is :mod:`assistive_compiler.run_dir`."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..artifact import AGENTS
from ..errors import UsageError
from ..paths import display
from ..run_dir import RunDir, RunInfo, engine_modules
from .mlp import MLPPolicy

#: RLlib's module id of a single-agent run (``ray.rllib.core.DEFAULT_MODULE_ID``).
SINGLE_MODULE = "default_policy"
#: The averaged actor's weights in an SB3 SAC checkpoint (``sac.actor_average_tau``): what acts
#: from that checkpoint in the actor's place.
ACTOR_AVERAGE = "actor_average.pt"


def algorithm_class(config_or_name, library: str | None = None):
    """The learning library's class for the config's algorithm (or an algorithm name): SB3's, or
    with ``library`` ``sbx`` (the config's own, given a config) SBX's JAX one."""
    name = getattr(config_or_name, "algorithm", config_or_name)
    library = library or getattr(config_or_name, "library", "sb3")
    if name == "sac" and library == "sbx":
        from sbx import SAC as SBXSAC

        return SBXSAC
    if name == "sac":
        from stable_baselines3 import SAC

        return SAC
    from stable_baselines3 import PPO

    return PPO


def sbx_sac_actor(model, activation: str) -> MLPPolicy:
    """SBX's SAC actor (flax ``Dense_0`` .. ``Dense_{n-1}`` hidden, then the mean's layer and the
    log-std's, both on the last hidden features) as a NumPy policy: its mean through tanh, with the
    log-std layer for sampling. Flax keeps a kernel as (inputs, outputs), the policy (outputs, inputs)."""
    from sbx.sac.policies import SquashedGaussianActor

    dense = model.policy.actor_state.params["params"]
    actor = model.policy.actor
    if not isinstance(actor, SquashedGaussianActor) or len(dense) != len(actor.net_arch) + 2:
        raise UsageError(f"{type(actor).__name__}: not SBX's SAC actor (hidden layers, a mean and a log-std layer)")

    def layer(k: int) -> tuple[np.ndarray, np.ndarray]:
        weights = dense[f"Dense_{k}"]
        return np.asarray(weights["kernel"], dtype=np.float64).T, np.asarray(weights["bias"], dtype=np.float64)

    space = model.action_space
    return MLPPolicy(
        [layer(k) for k in range(len(dense) - 1)],
        activation,
        "tanh",
        space.low,
        space.high,
        log_std=layer(len(dense) - 1),
        log_std_bounds=(float(actor.log_std_min), float(actor.log_std_max)),
    )


class SB3Policy:
    """A trained SB3 policy as a function of raw observations (normalised as during training):
    the distribution's mode, or with ``stochastic`` a sample of it as in training (seeded)."""

    def __init__(
        self, checkpoint: Path, algorithm: str = "ppo", stochastic: bool = False, seed: int = 0, library: str = "sb3"
    ):
        self.algorithm, self.stochastic = algorithm, stochastic
        if stochastic:  # SB3 samples with torch's generator: seeded, the same seed gives the same episodes
            import torch

            torch.manual_seed(seed)
        self.model = algorithm_class(algorithm, library).load(
            str(checkpoint / "model.zip"), device="cpu", custom_objects={"replay_buffer_class": None}
        )
        # SBX's actor acts in NumPy (its own JAX call hands each action to XLA's thread: slow on a
        # busy core), sampling from a generator seeded with ``seed``; ``numpy_policy`` is also its export
        self.numpy_policy: MLPPolicy | None = None
        self.numpy_actor = None
        if library == "sbx":
            self.numpy_policy = sbx_sac_actor(self.model, self.model.policy.actor.activation_fn.__name__)
            self.numpy_actor = self.numpy_policy.sampling(seed) if stochastic else self.numpy_policy
        average = checkpoint / ACTOR_AVERAGE
        if average.is_file():  # trained with an averaged actor: the average acts
            import torch

            self.model.actor.load_state_dict(torch.load(average, weights_only=True))
        self.obs_rms = None
        stats = checkpoint / "vecnormalize.pkl"
        if stats.is_file():
            import pickle

            with stats.open("rb") as f:
                vn = pickle.load(f)
            self.obs_rms = vn.obs_rms if vn.norm_obs else None
            self.clip, self.eps = vn.clip_obs, vn.epsilon

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        if self.numpy_actor is not None:
            return self.numpy_actor(np.asarray(obs, dtype=np.float64))
        if self.obs_rms is not None:
            obs = np.clip((obs - self.obs_rms.mean) / np.sqrt(self.obs_rms.var + self.eps), -self.clip, self.clip)
        action, _ = self.model.predict(obs.astype(np.float32), deterministic=not self.stochastic)
        return action


class SB3PairPolicy(SB3Policy):
    """A co-optimised pair trained with SB3 SAC or PPO, one actor per agent
    (:mod:`assistive_compiler.training.learners.factored_actor`, :mod:`~assistive_compiler.training.learners.factored_actor_critic`):
    ``(robot_obs, human_obs) -> (a_robot, a_human)``, and each agent alone with :meth:`agent` (its
    actor reads its own observation only; PPO's observation normalisation is per entry)."""

    def __init__(self, checkpoint: Path, algorithm: str = "sac", stochastic: bool = False, seed: int = 0):
        super().__init__(checkpoint, algorithm, stochastic, seed)
        self.robot_obs_size, self.robot_action_size = self.model.policy.agent_split
        self.human_obs_size = self.model.observation_space.shape[0] - self.robot_obs_size

    def __call__(self, obs: np.ndarray, human_obs: np.ndarray | None = None):
        joint = super().__call__(np.concatenate([obs, human_obs]))
        return joint[: self.robot_action_size], joint[self.robot_action_size :]

    def agent(self, name: str):
        """One agent's policy, ``obs -> action`` (the other agent's observation is not read: zeros)."""
        if name == AGENTS[0]:
            return lambda obs: self(obs, np.zeros(self.human_obs_size, np.float32))[0]
        return lambda obs: self(np.zeros(self.robot_obs_size, np.float32), obs)[1]


class RLlibPolicy:
    """A trained RLlib run's policies as plain functions (by default deterministic: the Gaussian's mean).

    Single agent: ``obs -> action``; co-optimised: ``(robot_obs, human_obs) -> (a_robot, a_human)``.
    With ``stochastic``, a sample of the Gaussian (seeded), squashed or clipped as the mean is.
    Loads the RLModules from the checkpoint alone: no Ray instance is needed."""

    def __init__(self, checkpoint: Path, coop: bool, algorithm: str = "ppo", stochastic: bool = False, seed: int = 0):
        from ray.rllib.core.rl_module.rl_module import RLModule

        root = checkpoint / "algo" / "learner_group" / "learner" / "rl_module"
        names = AGENTS if coop else (SINGLE_MODULE,)
        self.modules = {name: RLModule.from_checkpoint(str((root / name).resolve())) for name in names}
        self.coop, self.algorithm = coop, algorithm
        self.rng = np.random.default_rng(seed) if stochastic else None

    def _act(self, name: str, obs: np.ndarray) -> np.ndarray:
        import torch

        with torch.no_grad():
            out = self.modules[name].forward_inference({"obs": torch.as_tensor(obs, dtype=torch.float32)[None]})
        dist = out["action_dist_inputs"][0].numpy()
        half = dist.shape[0] // 2
        mean = dist[:half]  # a diagonal Gaussian's inputs: means, then log-stds
        if self.rng is not None:  # a sample, as in training
            mean = mean + np.exp(dist[half:]) * self.rng.standard_normal(half)
        space = self.modules[name].action_space
        if self.algorithm != "sac":  # PPO's mean, clipped to the action bounds as SB3's PPO and the export clip it
            return np.clip(mean, space.low, space.high).astype(np.float32)
        # SAC's Gaussian is squashed by tanh into the action bounds.
        return (space.low + 0.5 * (np.tanh(mean) + 1.0) * (space.high - space.low)).astype(np.float32)

    def agent(self, name: str):
        """One co-optimised agent's policy, ``obs -> action``."""
        return lambda obs: self._act(name, obs)

    def __call__(self, obs: np.ndarray, human_obs: np.ndarray | None = None):
        if self.coop:
            return self._act(AGENTS[0], obs), self._act(AGENTS[1], human_obs)
        return self._act(SINGLE_MODULE, obs)


def latest_checkpoint(run: RunDir) -> tuple[int, Path]:
    """(env steps, directory) of the run's newest complete checkpoint; a clear error when it has none."""
    found = run.latest_checkpoint()
    if found is None:
        raise UsageError(f"{display(run.path)}: the run has no complete checkpoint yet (checkpoints/step_*/COMPLETE)")
    return found


def load_policy(info: RunInfo, checkpoint: Path, stochastic: bool = False, seed: int = 0):
    """The run's policy as ``obs -> action`` (co-optimised runs: ``(robot_obs, human_obs) -> (a_r, a_h)``):
    deterministic, or with ``stochastic`` sampling its actions as training did (from a generator
    seeded with ``seed``)."""
    if info.engine == "sb3":
        if info.coop:
            return SB3PairPolicy(checkpoint, info.algorithm, stochastic=stochastic, seed=seed)
        return SB3Policy(checkpoint, info.algorithm, stochastic=stochastic, seed=seed, library=info.library)
    return RLlibPolicy(checkpoint, coop=info.coop, algorithm=info.algorithm, stochastic=stochastic, seed=seed)


def load_run(path: Path, source: str):
    """``(policy, info)`` of the run directory ``path``'s newest checkpoint (``source``: how the
    user named it, for messages); ``info`` has ``task``, ``robot``, ``coop``, ``run`` and
    ``trained_steps``."""
    import importlib.util

    run = RunDir(path)
    run_info = run.info()
    missing = [m for m in engine_modules(run_info.engine, run_info.library) if importlib.util.find_spec(m) is None]
    if missing:
        raise UsageError(
            f"--policy {source}: playing a run directory needs its training library ({', '.join(missing)} not "
            "installed): install the 'train' extra (README: Training), or play its export (assistive-compiler export)"
        )
    steps, checkpoint = latest_checkpoint(run)
    return load_policy(run_info, checkpoint), {
        "task": run_info.task,
        "robot": run_info.robot,
        "coop": run_info.coop,
        "run": display(path),
        "trained_steps": steps,
    }
