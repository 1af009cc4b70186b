"""Training on one machine: Stable-Baselines3 PPO or SAC over ``envs`` env processes.

The envs are SB3's process-based vector env (:class:`SubprocVecEnv`; one env runs in-process),
each a :class:`~assistive_compiler.runtime.env.AssistiveEnv` built from the run's compiled
artifact, optionally (PPO) behind :class:`VecNormalize` (running observation and return
statistics, saved with every checkpoint). A co-optimisation run (``coop``, SAC only) trains the
robot and the person together: each env is :class:`~assistive_compiler.coop.joint.JointAgentsEnv`
and the actor one network per agent with one shared critic (:mod:`.learners.factored_actor`).

A checkpoint is a directory holding ``model.zip``, PPO's ``vecnormalize.pkl`` and SAC's
``replay_buffer.pkl`` (kept in the newest checkpoint only: it is the bulk of a checkpoint);
resuming loads them and continues the step count.
"""

from __future__ import annotations

import functools
from pathlib import Path

from ...episode import EpisodeTally
from ...policies.checkpoint import algorithm_class
from ...run_dir import RunDir
from ..bookkeeping.progress import Progress
from ..config import TrainingConfig

ACTIVATIONS = {"tanh": "Tanh", "relu": "ReLU"}
#: Env steps between two learning-curve rows for SAC, whose "rollouts" are single env steps.
SAC_LOG_EVERY_STEPS = 2_000
REPLAY_BUFFER = "replay_buffer.pkl"


def make_monitored_env(artifact_dir: str, in_worker: bool = False, coop: bool = False):
    """One env of the vector env: the compiled task (``coop``: both agents as one,
    :class:`~assistive_compiler.coop.joint.JointAgentsEnv`) behind SB3's episode Monitor. In a
    worker process Ctrl-C is ignored: the trainer stops the workers after writing its checkpoint."""
    from stable_baselines3.common.monitor import Monitor

    if in_worker:
        import signal

        signal.signal(signal.SIGINT, signal.SIG_IGN)
    if coop:
        from ...coop.joint import JointAgentsEnv

        return Monitor(JointAgentsEnv(artifact_dir))
    from ...runtime.env import AssistiveEnv

    return Monitor(AssistiveEnv(artifact_dir))


def make_vec_env(artifact_dir: Path, n_envs: int, seed: int, coop: bool = False, in_process: bool = False):
    """``n_envs`` envs seeded ``seed``, ``seed + 1``, ...: each in a process of its own when more
    than one, or all in this process (``in_process``: stepped in turn, one core)."""
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    processes = n_envs > 1 and not in_process
    fns = [functools.partial(make_monitored_env, str(artifact_dir), processes, coop) for _ in range(n_envs)]
    venv = SubprocVecEnv(fns, start_method="forkserver") if processes else DummyVecEnv(fns)
    venv.seed(seed)
    return venv


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


def _normalized(venv, config: TrainingConfig, checkpoint: Path | None):
    from stable_baselines3.common.vec_env import VecNormalize

    if config.ppo is None or not (config.ppo.normalize_observations or config.ppo.normalize_rewards):
        return venv
    if checkpoint is not None:
        return VecNormalize.load(str(checkpoint / "vecnormalize.pkl"), venv)
    return VecNormalize(
        venv,
        norm_obs=config.ppo.normalize_observations,
        norm_reward=config.ppo.normalize_rewards,
        gamma=config.ppo.gamma,
    )


def sac_policy(config: TrainingConfig, agent_split: tuple[int, int] | None) -> tuple[object, dict]:
    """SAC's policy class and ``policy_kwargs``: SB3's own, with layer-normalised critics
    (``sac.critic_layer_norm``) and, for a co-optimised pair (``agent_split``: the robot's
    observation and action sizes), one actor per agent."""
    from ..learners.critics import LayerNormSACPolicy

    assert config.sac is not None
    kwargs = policy_kwargs(config)
    if agent_split is None:
        return (LayerNormSACPolicy if config.sac.critic_layer_norm else "MlpPolicy"), kwargs
    from ..learners.factored_actor import FactoredLayerNormSACPolicy, FactoredSACPolicy

    policy = FactoredLayerNormSACPolicy if config.sac.critic_layer_norm else FactoredSACPolicy
    return policy, kwargs | {"agent_split": agent_split}


def _new_model(venv, config: TrainingConfig, run: RunDir, agent_split: tuple[int, int] | None = None):
    from stable_baselines3 import PPO

    if config.sac is not None:
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
    p = config.ppo
    return PPO(
        "MlpPolicy",
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
        policy_kwargs=policy_kwargs(config),
        tensorboard_log=str(run.tb),
        seed=config.seed,
        device="cpu",
        verbose=0,
    )


def save_checkpoint(run: RunDir, model, steps: int) -> Path:
    """Write a complete checkpoint at ``steps``; an off-policy model's replay buffer goes with it
    and leaves the older checkpoints (they stay loadable as policies, not resumable with data)."""
    from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
    from stable_baselines3.common.vec_env import VecNormalize

    older = run.latest_checkpoint()
    out = run.begin_checkpoint(steps)
    model.save(str(out / "model.zip"))
    venv = model.get_env()
    if isinstance(venv, VecNormalize):
        venv.save(str(out / "vecnormalize.pkl"))
    off_policy = isinstance(model, OffPolicyAlgorithm)
    if off_policy:
        model.save_replay_buffer(str(out / REPLAY_BUFFER))
        from ..learners.averaging import averaged

        average = averaged(model)
        if average is not None:
            average.save(out)
    final = run.end_checkpoint(out, steps, {"engine": "sb3", "algorithm": type(model).__name__.lower()})
    if off_policy and older is not None and older[1] != final:
        (older[1] / REPLAY_BUFFER).unlink(missing_ok=True)
    return final


def _callback(run: RunDir, progress: Progress, config: TrainingConfig, n_envs: int, stop=None):
    from stable_baselines3.common.callbacks import BaseCallback

    # PPO: a row per rollout (its update); SAC updates every step, so a row per SAC_LOG_EVERY_STEPS
    log_every = config.batch_size if config.ppo is not None else max(config.batch_size, SAC_LOG_EVERY_STEPS)

    class RunCallback(BaseCallback):
        """Per-term episode sums, the learning curve and checkpoints, at the end of each rollout."""

        def __init__(self) -> None:
            super().__init__()
            self.tallies = [EpisodeTally() for _ in range(n_envs)]
            self.next_checkpoint = 0

        def _on_training_start(self) -> None:
            every = config.checkpoint_every_steps
            self.next_checkpoint = (self.num_timesteps // every + 1) * every
            self.next_log = self.num_timesteps + log_every

        def _on_step(self) -> bool:
            for i, (info, done) in enumerate(zip(self.locals["infos"], self.locals["dones"])):
                # The rewards SB3 sees may be normalised: the episode's return is the Monitor's.
                self.tallies[i].add(0.0, info)
                if done:
                    tally, self.tallies[i] = self.tallies[i], EpisodeTally()
                    progress.episode(info["episode"]["r"], info["task_success"], tally.terms)
            return not stop  # False ends model.learn() after this step

        def _on_rollout_end(self) -> None:
            if self.num_timesteps < self.next_log and self.num_timesteps < self.next_checkpoint:
                return
            self.next_log = self.num_timesteps + log_every
            for key, value in progress.update(self.num_timesteps).items():
                self.logger.record(key, value)
            if self.num_timesteps >= self.next_checkpoint:
                save_checkpoint(run, self.model, self.num_timesteps)
                every = config.checkpoint_every_steps
                self.next_checkpoint = (self.num_timesteps // every + 1) * every

    return RunCallback()


def train(
    run: RunDir,
    config: TrainingConfig,
    weights: dict[str, float],
    *,
    resume: bool,
    quiet: bool = False,
    stop=None,
    demonstrations=None,
    coop: bool = False,
    timer=None,
) -> dict:
    """Train (or continue) the run to ``config.total_steps``; returns the session's figures.
    ``timer`` (:class:`.throughput.StageTimer`, for ``bench --training``) times the env steps and
    the learner's updates of this session.
    ``coop`` (SAC): the robot and the person together, one actor each and one critic.

    A new run given ``demonstrations`` (:class:`.learners.demonstrations.DemonstrationData`) starts from
    them: its actor cloned, its replay buffer filled, its critics warmed up and a checkpoint
    written at step 0 (the cloned policy, before any env step), before it learns; with the
    config's ``clone_weight`` > 0 (new or resumed run) the cloning stays in the actor's loss, and
    with ``hold_actor_steps`` the actor waits for the critics first.

    A stop request (``stop``, set by Ctrl-C or SIGTERM: :func:`.train.stop_on_signals`) ends
    training after the current env step; a checkpoint is written and the figures come back with
    ``interrupted: True``; a later ``resume`` continues from it."""
    import torch

    torch.set_num_threads(1)  # small MLPs: more threads only contend with the env processes
    latest = run.latest_checkpoint() if resume else None
    start_steps = latest[0] if latest else 0
    if latest and config.sac is not None and not (latest[1] / REPLAY_BUFFER).is_file():
        from ...errors import UsageError

        raise UsageError(
            f"{latest[1] / REPLAY_BUFFER}: --resume of a SAC run needs the newest checkpoint's replay buffer, which is missing"
        )
    venv = make_vec_env(
        run.artifact, config.envs, config.seed + start_steps, coop, in_process=config.vec_env == "in_process"
    )
    if timer is not None:
        venv = timer.wrap_env(venv)
    venv = _normalized(venv, config, latest[1] if latest else None)
    if latest:
        model = algorithm_class(config).load(str(latest[1] / "model.zip"), env=venv, device="cpu")
        model.set_random_seed(config.seed + start_steps)
        if config.sac is not None:
            model.load_replay_buffer(str(latest[1] / REPLAY_BUFFER))
    else:
        model = _new_model(venv, config, run, venv.get_attr("agent_split")[0] if coop else None)
    if config.sac is not None and config.sac.actor_learning_rate is not None:  # new or resumed
        from ..learners.actor_rate import set_actor_learning_rate

        set_actor_learning_rate(model, config.sac.actor_learning_rate)
    if config.sac is not None and config.sac.conservative_weight > 0:  # new or resumed: not in the checkpoint
        from ..learners.critics import make_conservative

        make_conservative(model, config.sac.conservative_weight, config.seed + start_steps)
    if demonstrations is not None:  # train.train reads them only for a config that has a demonstrations block
        from ..learners.demonstrations import start_from, update_actor_as_configured

        assert config.demonstrations is not None
        if not latest:
            assert config.sac is not None
            started_from = start_from(
                model, demonstrations, config.demonstrations, config.seed, config.sac.target_entropy
            )
        update_actor_as_configured(model, demonstrations, config.demonstrations, config.seed + start_steps)
    if config.sac is not None and config.sac.actor_average_tau > 0:  # new (after any cloning) or resumed
        from ..learners.averaging import make_averaged

        make_averaged(model, config.sac.actor_average_tau, latest[1] if latest else None)
    if demonstrations is not None and not latest:
        import json

        from ...run_dir import write_atomic

        save_checkpoint(run, model, 0)  # the cloned policy, before any env step
        write_atomic(run.demonstrations_json, json.dumps(started_from, indent=1))
    progress = Progress(run, weights, config.total_steps, start_steps, quiet=quiet)
    interrupted = False
    try:
        remaining = max(0, config.total_steps - model.num_timesteps)
        if timer is not None:
            timer.watch_updates(model)
        if remaining:
            model.learn(
                remaining,
                callback=_callback(run, progress, config, config.envs, stop),
                reset_num_timesteps=not latest,
                tb_log_name="sb3",
            )
        interrupted = bool(stop)
    except KeyboardInterrupt:  # a second Ctrl-C: stop at once
        interrupted = True
    finally:
        if timer is not None:
            timer.unwatch(model)
        steps = model.num_timesteps
        save_checkpoint(run, model, steps)
        wall = progress.wall_s()
        session_rate = (steps - start_steps) / max(1e-9, wall - progress.wall_before)
        progress.close()
        venv.close()
    return {
        "steps": int(steps),
        "wall_s": wall,
        "steps_per_s_including_learning": session_rate,
        "interrupted": interrupted,
    }
