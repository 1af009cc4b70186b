"""Training on one machine: Stable-Baselines3 PPO or SAC over ``envs`` env processes.

The envs are SB3's process-based vector env (:class:`SubprocVecEnv`; one env runs in-process),
each a :class:`~assistive_compiler.runtime.env.AssistiveEnv` built from the run's compiled
artifact, optionally (PPO) behind :class:`VecNormalize` (running observation and return
statistics, saved with every checkpoint). A co-optimisation run (``coop``) trains the robot and
the person together: each env is :class:`~assistive_compiler.coop.joint.JointAgentsEnv` and the
actor one network per agent with one shared critic (SAC: :mod:`.learners.factored_actor`; PPO:
:mod:`.learners.factored_actor_critic`).
The model itself, and the SAC settings that change its updates, come from :mod:`.learners`
(:func:`.learners.choice.new_model`, :func:`.learners.sac.set_up_sac`): this module runs it.

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
from ..learners.choice import new_model
from ..learners.sac import set_up_sac

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
    ``coop``: the robot and the person together, one actor each and one critic.

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
        model = new_model(venv, config, run, venv.get_attr("agent_split")[0] if coop else None)
    started_from = set_up_sac(model, config, demonstrations, latest, start_steps)
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
