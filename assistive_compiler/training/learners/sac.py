"""SAC (soft actor-critic, off-policy): Stable-Baselines3's, or SBX's JAX one (``sac.library``),
built from the config's ``sac`` settings, and the settings that change its updates wired into a
new or resumed model: the actor's own learning rate (:mod:`.actor_rate`), conservative critics
(:mod:`.critics`), the start from demonstrations (:mod:`.demonstrations`) and the actor's weight
average (:mod:`.averaging`). None of those is saved in a checkpoint: a resumed run wires them
again from its config. Co-optimised pairs get one actor per agent (:mod:`.factored_actor`)."""

from __future__ import annotations

from pathlib import Path

from ...policies.checkpoint import algorithm_class
from ...run_dir import RunDir
from ..config import TrainingConfig
from .network import policy_kwargs


def sac_policy(config: TrainingConfig, agent_split: tuple[int, int] | None) -> tuple[object, dict]:
    """SAC's policy class and ``policy_kwargs``: SB3's own, with layer-normalised critics
    (``sac.critic_layer_norm``) and, for a co-optimised pair (``agent_split``: the robot's
    observation and action sizes), one actor per agent."""
    from .critics import LayerNormSACPolicy

    assert config.sac is not None
    kwargs = policy_kwargs(config)
    if agent_split is None:
        return (LayerNormSACPolicy if config.sac.critic_layer_norm else "MlpPolicy"), kwargs
    from .factored_actor import FactoredLayerNormSACPolicy, FactoredSACPolicy

    policy = FactoredLayerNormSACPolicy if config.sac.critic_layer_norm else FactoredSACPolicy
    return policy, kwargs | {"agent_split": agent_split}


def new_sac(venv, config: TrainingConfig, run: RunDir, agent_split: tuple[int, int] | None = None):
    """A new SAC model on ``venv`` as ``config`` says (``agent_split``: a co-optimised pair's robot
    observation and action sizes), logging to the run's TensorBoard folder."""
    s = config.sac
    policy, kwargs = sac_policy(config, agent_split) if s.library == "sb3" else ("MlpPolicy", policy_kwargs(config))
    return algorithm_class(config)(
        policy,
        venv,
        learning_rate=s.learning_rate,
        buffer_size=s.buffer_size,
        learning_starts=s.learning_starts,
        batch_size=s.batch_size,
        tau=s.tau,
        gamma=s.gamma,
        train_freq=s.train_freq,
        gradient_steps=s.gradient_steps,
        ent_coef=f"auto_{s.initial_ent_coef:g}" if s.ent_coef == "auto" else s.ent_coef,
        target_entropy="auto" if s.target_entropy == "cloned" else s.target_entropy,  # cloned: set on cloning
        policy_kwargs=kwargs,
        tensorboard_log=str(run.tb),
        seed=config.seed,
        device="cpu",
        verbose=0,
    )


def set_up_sac(model, config: TrainingConfig, demonstrations, latest: tuple[int, Path] | None, start_steps: int):
    """Wire the config's SAC settings into ``model``, new or resumed from ``latest`` (its step count
    and checkpoint) at ``start_steps``, in this order: the actor's learning rate, conservative
    critics, the start from ``demonstrations`` (a new run: the actor cloned, the buffer filled, the
    critics warmed up; any run: the cloning kept in the actor's loss as configured), then the
    actor's average (after any cloning). Returns what a new run started from demonstrations
    records (``demonstrations.json``), else None. Nothing to do for a config without these (PPO)."""
    started_from = None
    if config.sac is not None and config.sac.actor_learning_rate is not None:  # new or resumed
        from .actor_rate import set_actor_learning_rate

        set_actor_learning_rate(model, config.sac.actor_learning_rate)
    if config.sac is not None and config.sac.conservative_weight > 0:  # new or resumed: not in the checkpoint
        from .critics import make_conservative

        make_conservative(model, config.sac.conservative_weight, config.seed + start_steps)
    if demonstrations is not None:  # train.train reads them only for a config that has a demonstrations block
        from .demonstrations import start_from, update_actor_as_configured

        assert config.demonstrations is not None
        if not latest:
            assert config.sac is not None
            started_from = start_from(
                model, demonstrations, config.demonstrations, config.seed, config.sac.target_entropy
            )
        update_actor_as_configured(model, demonstrations, config.demonstrations, config.seed + start_steps)
    if config.sac is not None and config.sac.actor_average_tau > 0:  # new (after any cloning) or resumed
        from .averaging import make_averaged

        make_averaged(model, config.sac.actor_average_tau, latest[1] if latest else None)
    return started_from
