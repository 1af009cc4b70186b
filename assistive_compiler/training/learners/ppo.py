"""PPO (the paper's on-policy learner): Stable-Baselines3's, built from the config's ``ppo``
settings. Its observation and return normalisation (``VecNormalize``) wraps the envs, so the
engine sets it up (:mod:`..engines.sb3`). Co-optimised pairs get one actor per agent and one value
function (:mod:`.factored_actor_critic`)."""

from __future__ import annotations

from ...run_dir import RunDir
from ..config import TrainingConfig
from .network import policy_kwargs


def new_ppo(venv, config: TrainingConfig, run: RunDir, agent_split: tuple[int, int] | None = None):
    """A new PPO model on ``venv`` as ``config`` says, logging to the run's TensorBoard folder
    (``agent_split``: a co-optimised pair's robot observation and action sizes)."""
    from stable_baselines3 import PPO

    policy, kwargs = "MlpPolicy", policy_kwargs(config)
    if agent_split is not None:
        from .factored_actor_critic import FactoredActorCriticPolicy

        policy, kwargs = FactoredActorCriticPolicy, kwargs | {"agent_split": agent_split}
    p = config.ppo
    return PPO(
        policy,
        venv,
        n_steps=p.rollout_steps,
        batch_size=p.minibatch_size,
        n_epochs=p.epochs,
        gamma=p.gamma,
        gae_lambda=p.gae_lambda,
        learning_rate=p.learning_rate,
        clip_range=p.clip_range,
        ent_coef=p.entropy_coef,
        vf_coef=p.value_coef,
        max_grad_norm=p.max_grad_norm,
        policy_kwargs=kwargs,
        tensorboard_log=str(run.tb),
        seed=config.seed,
        device="cpu",
        verbose=0,
    )
