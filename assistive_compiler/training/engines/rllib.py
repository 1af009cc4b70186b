"""Co-optimisation and clusters: Ray RLlib PPO (the new API stack: RLModules, EnvRunners).

* **Co-optimisation** (``coop``): the task's PettingZoo face (robot and human, shared reward)
  behind RLlib's :class:`ParallelPettingZooEnv`, two policies ``robot`` and ``human`` mapped by
  agent id, as the reference. RLlib sums the agents' identical rewards into its own episode
  return; the returns this module reports are the task's (Σ weight × term, counted once), which
  is the reference's "logged co-op rewards divided by 2".
* **Clusters**: ``address`` attaches to a running Ray cluster (``ray start --head`` on one
  machine, ``ray start --address=...`` on the others); env runners then spread over it.
* A checkpoint is RLlib's own (``Algorithm.save_to_path``) under ``checkpoints/step_<N>/algo``.

RLlib runs apply no observation or return normalisation (the reference's RLlib configs used no
filter); ``ppo.normalize_*`` are SB3's.
"""

from __future__ import annotations

import math
import os
import socket
import sys
from pathlib import Path

from ...artifact import AGENTS
from ...errors import UsageError
from ...run_dir import RunDir
from ..bookkeeping.progress import Progress
from ..config import TrainingConfig

ENV_NAME = "assistive_compiler"
CONNECT_TIMEOUT_S = 3.0
GCS_WAIT_VAR = "RAY_gcs_server_port_wait_time_s"


def make_rllib_env(env_config: dict):
    """RLlib's env creator: the run's compiled task, as two agents (co-op) or one. The task
    travels in the env config (:mod:`assistive_compiler.bundle`): each worker unpacks it into its
    own cache, so no machine needs the driver's files."""
    from ...bundle import unpack

    artifact_dir = unpack(env_config["artifact_bundle"])
    if env_config["coop"]:
        from ray.rllib.env.wrappers.pettingzoo_env import ParallelPettingZooEnv

        from ...coop.parallel import AssistiveParallelEnv

        return ParallelPettingZooEnv(AssistiveParallelEnv(artifact_dir))
    from ...runtime.env import AssistiveEnv

    return AssistiveEnv(artifact_dir)


def env_config(run: RunDir, coop: bool, weights: dict[str, float]) -> dict:
    """What every env runner gets: the compiled task itself (not a path), co-op or not, the reward weights."""
    from ...bundle import pack

    return {"artifact_bundle": pack(run.artifact), "coop": coop, "weights": weights}


def check_address(address: str) -> None:
    """Fail fast, with a message, when nothing listens at a Ray cluster ``address``
    (``host:port`` or ``ray://host:port``); ``auto`` is left to Ray."""
    if address == "auto":
        return
    target = address.split("://", 1)[-1]
    host, _, port = target.rpartition(":")
    if not host or not port.isdigit():
        raise UsageError(f"--address: expected HOST:PORT or ray://HOST:PORT (e.g. 10.0.0.5:6379), got '{address}'")
    try:
        socket.create_connection((host, int(port)), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as exc:
        raise UsageError(
            f"--address: no Ray cluster reachable at {address} ({exc.strerror or exc}); "
            "start one with `ray start --head` there, or leave out --address to train locally"
        ) from None


def authentication_refused(address: str) -> str | None:
    """Why the cluster at ``address`` refused us, when it answers but rejects this machine's Ray
    authentication token (Ray ≥ 2.5x enables token authentication; a stale ``~/.ray/auth_token``
    from an earlier local ``ray.init()`` is the usual cause); None when it does not say so."""
    from ray.exceptions import AuthenticationError

    try:
        from ray._raylet import GcsClient

        GcsClient(address=address.split("://", 1)[-1]).internal_kv_get(
            b"assistive-compiler-probe", None, timeout=CONNECT_TIMEOUT_S
        )
    except AuthenticationError:
        return (
            f"--address: the Ray cluster at {address} refused this machine's authentication token "
            "(~/.ray/auth_token, $RAY_AUTH_TOKEN or $RAY_AUTH_TOKEN_PATH). Ray's remedy: every machine uses the "
            "cluster's token — print it on the head with `ray get-auth-token` and put it in ~/.ray/auth_token here "
            "(or export RAY_AUTH_TOKEN); see https://docs.ray.io/en/latest/ray-security/token-auth.html"
        )
    except Exception:  # noqa: BLE001 — any other failure: not an authentication refusal
        return None
    return None


def init_ray(address: str | None, envs: int) -> None:
    """Attach to the cluster at ``address``; without one, start a private local Ray instance
    (unless this process already runs one). Never a cluster that merely runs on this machine:
    Ray's own default (``ray.init()``) joins the latest ``ray start`` cluster it finds here."""
    import ray

    if address:
        check_address(address)
    if ray.is_initialized():
        return
    if address:
        # Something answers at the address; give Ray a few seconds (not its default 20) to find a
        # cluster there. The variable is read when connecting, by this process only.
        previous = os.environ.get(GCS_WAIT_VAR)
        os.environ[GCS_WAIT_VAR] = str(int(CONNECT_TIMEOUT_S))
        try:
            ray.init(address=address, log_to_driver=False)
        except (ConnectionError, RuntimeError) as exc:
            refused = authentication_refused(address)
            if refused:
                raise UsageError(refused) from None
            raise UsageError(
                f"--address: no Ray cluster at {address} ({str(exc).splitlines()[0]}); "
                "start one with `ray start --head` there, or leave out --address to train locally"
            ) from None
        finally:
            if previous is None:
                os.environ.pop(GCS_WAIT_VAR, None)
            else:
                os.environ[GCS_WAIT_VAR] = previous
    else:
        ray.init(address="local", num_cpus=max(2, envs + 1), include_dashboard=False, log_to_driver=False)


def _callbacks_class():
    from ray.rllib.callbacks.callbacks import RLlibCallback

    class EpisodeTerms(RLlibCallback):
        """Sums each reward term over an episode (the robot's view: both agents share the reward)
        and logs, per training iteration, the episodes' return, success and weighted term sums."""

        def on_episode_step(self, *, episode, **kwargs) -> None:
            info = _task_info(episode.get_infos(-1))
            if info is None:
                return
            sums = episode.custom_data.setdefault("terms", {})
            for name, value in info["terms"].items():
                sums[name] = sums.get(name, 0.0) + value
            episode.custom_data["success"] = info["task_success"]

        def on_episode_end(self, *, episode, env_runner=None, metrics_logger=None, **kwargs) -> None:
            weights = env_runner.config.env_config["weights"]
            sums = episode.custom_data.get("terms", {})
            metrics_logger.log_value(("task", "episodes"), 1, reduce="sum")
            metrics_logger.log_value(
                ("task", "return"), sum(w * sums.get(n, 0.0) for n, w in weights.items()), reduce="sum"
            )
            metrics_logger.log_value(("task", "success"), float(episode.custom_data.get("success", 0)), reduce="sum")
            for name, weight in weights.items():
                metrics_logger.log_value(("task", "terms", name), weight * sums.get(name, 0.0), reduce="sum")

    return EpisodeTerms


def _task_info(infos):
    """The task's step info from RLlib's per-step infos (one agent's dict, or agent -> dict)."""
    if not infos:
        return None
    if "terms" in infos:
        return infos
    robot = infos.get("robot")
    return robot if robot and "terms" in robot else None


#: Env steps each SAC env runner samples between two rounds of updates (the updates per env step
#: are the config's gradient_steps / train_freq, through RLlib's training_intensity).
SAC_FRAGMENT_STEPS = 8
#: Env steps of one RLlib SAC iteration at most (a learning-curve row and a chance to stop or
#: checkpoint); fewer where the run or its checkpoint interval is shorter.
SAC_ITERATION_STEPS = 1000


def check_supported(config: TrainingConfig) -> None:
    """Refuse, with what to do, the settings that only the SB3 engine builds. ``train`` calls this
    before it writes the run directory, so a refused config leaves nothing behind."""
    if config.vec_env == "in_process":
        raise UsageError(
            "vec_env: in_process steps every env in the trainer's process, which is built for the sb3 engine only; "
            "use --engine sb3, or set vec_env: processes (RLlib runs one env per env runner)"
        )
    s = config.sac
    if s is None:
        return
    if s.library == "sbx":
        raise UsageError(
            "sac.library: sbx is the SB3 engine's JAX SAC; use --engine sb3, or set library: sb3 (RLlib learns with "
            "its own PyTorch SAC)"
        )
    if s.ent_coef != "auto":
        raise UsageError(
            f"sac.ent_coef {s.ent_coef}: the rllib engine learns the entropy temperature; use ent_coef: auto"
        )
    if s.critic_layer_norm:
        raise UsageError(
            "sac.critic_layer_norm: layer-normalised critics are built for the sb3 engine only; "
            "use --engine sb3, or set critic_layer_norm: false"
        )
    if s.conservative_weight:
        raise UsageError(
            "sac.conservative_weight: conservative critics are built for the sb3 engine only; "
            "use --engine sb3, or set conservative_weight: 0"
        )
    if s.actor_average_tau:
        raise UsageError(
            "sac.actor_average_tau: the averaged actor is built for the sb3 engine only; "
            "use --engine sb3, or set actor_average_tau: 0"
        )


def _shared_settings(
    algo_config, run: RunDir, config: TrainingConfig, weights, coop: bool, fragment_steps: int, **model
):
    """What the PPO and SAC configs share: the env, one env runner per ``--envs`` with one CPU each
    (none beside the driver for one env), the learner in the driver, the network (``model``: the
    algorithm's own settings of RLlib's default model), the callbacks, the seed, and for
    co-optimisation one module per agent."""
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig

    cfg = (
        algo_config.environment(ENV_NAME, env_config=env_config(run, coop, weights))
        .framework("torch")
        .env_runners(
            num_env_runners=config.envs if config.envs > 1 else 0,
            num_envs_per_env_runner=1,
            rollout_fragment_length=fragment_steps,
            num_cpus_per_env_runner=1,
        )
        .learners(num_learners=0)
        .rl_module(
            model_config=DefaultModelConfig(
                fcnet_hiddens=list(config.network.hidden), fcnet_activation=config.network.activation, **model
            )
        )
        .callbacks(_callbacks_class())
        .debugging(seed=config.seed, log_level="ERROR")
    )
    if coop:
        cfg = cfg.multi_agent(policies=set(AGENTS), policy_mapping_fn=lambda agent_id, *args, **kwargs: agent_id)
    return cfg


def build_sac_config(run: RunDir, config: TrainingConfig, weights: dict[str, float], coop: bool):
    """RLlib's SACConfig for this run: the same SAC as the SB3 engine's (twin Q critics, target
    entropy, Polyak τ), with a multi-agent episode replay buffer for co-optimisation."""
    from ray.rllib.algorithms.sac import SACConfig

    check_supported(config)
    s = config.sac
    updates_per_step = s.gradient_steps / s.train_freq
    buffer = "MultiAgentEpisodeReplayBuffer" if coop else "EpisodeReplayBuffer"
    sac = (
        SACConfig()
        .training(
            actor_lr=s.actor_learning_rate or s.learning_rate,
            critic_lr=s.learning_rate,
            alpha_lr=s.learning_rate,
            gamma=s.gamma,
            tau=s.tau,
            train_batch_size_per_learner=s.batch_size,
            num_steps_sampled_before_learning_starts=s.learning_starts,
            target_entropy=s.target_entropy,
            initial_alpha=s.initial_ent_coef,
            n_step=1,
            twin_q=True,
            training_intensity=s.batch_size * updates_per_step,
            replay_buffer_config={"type": buffer, "capacity": s.buffer_size},
        )
        .reporting(
            min_sample_timesteps_per_iteration=min(
                SAC_ITERATION_STEPS, config.total_steps, config.checkpoint_every_steps
            )
        )
    )
    return _shared_settings(sac, run, config, weights, coop, SAC_FRAGMENT_STEPS)


def build_config(run: RunDir, config: TrainingConfig, weights: dict[str, float], coop: bool):
    """RLlib's PPOConfig (or SACConfig: :func:`build_sac_config`) for this run."""
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.tune.registry import register_env

    register_env(ENV_NAME, make_rllib_env)
    if config.sac is not None:
        return build_sac_config(run, config, weights, coop)
    p = config.ppo
    ppo = PPOConfig().training(
        train_batch_size_per_learner=config.batch_size,
        minibatch_size=p.minibatch_size,
        num_epochs=p.epochs,
        gamma=p.gamma,
        lambda_=p.gae_lambda,
        lr=p.learning_rate,
        clip_param=p.clip_range,
        vf_loss_coeff=p.value_coef,
        entropy_coeff=p.entropy_coef,
        grad_clip=p.max_grad_norm,
    )
    return _shared_settings(ppo, run, config, weights, coop, p.rollout_steps, vf_share_layers=False)


def _record(progress: Progress, result: dict, weights: dict[str, float]) -> None:
    task = result.get("env_runners", {}).get("task", {})
    episodes = float(task.get("episodes", 0) or 0)
    n = int(episodes) if math.isfinite(episodes) else 0  # NaN: an iteration without episodes after a restore
    if n:
        terms = {name: task.get("terms", {}).get(name, 0.0) / n for name in weights}
        progress.episodes_summary(n, task["return"] / n, task["success"] / n, terms)


def save_checkpoint(run: RunDir, algo, steps: int) -> Path:
    out = run.begin_checkpoint(steps)
    algo.save_to_path(str((out / "algo").resolve()))
    return run.end_checkpoint(out, steps, {"engine": "rllib"})


def train(
    run: RunDir,
    config: TrainingConfig,
    weights: dict[str, float],
    *,
    coop: bool,
    resume: bool,
    address: str | None = None,
    quiet: bool = False,
    stop=None,
) -> dict:
    """Train (or continue) the run to ``config.total_steps`` env steps; a stop request (``stop``:
    Ctrl-C or SIGTERM, see :func:`.train.stop_on_signals`) ends it after the current iteration,
    with a checkpoint."""
    init_ray(address, config.envs)  # train.train has already started or attached; a no-op then
    latest = run.latest_checkpoint() if resume else None
    start_steps = latest[0] if latest else 0
    algo = build_config(run, config, weights, coop).build_algo()
    if latest:
        algo.restore_from_path(str((latest[1] / "algo").resolve()))
    progress = Progress(run, weights, config.total_steps, start_steps, quiet=quiet)
    steps, interrupted, lost = start_steps, False, None
    every = config.checkpoint_every_steps
    next_checkpoint = (steps // every + 1) * every
    try:
        while steps < config.total_steps and not stop:
            try:
                result = algo.train()
            except Exception:  # an iteration whose env runners all died under it (their node went away)
                lost = env_runners_lost(algo, config)
                if lost is None:
                    raise
                break
            sampled = result["env_runners"].get("num_env_steps_sampled", 0)
            # NaN when no env runner reported this iteration (all lost under it): nothing sampled.
            steps += int(sampled) if sampled == sampled else 0
            lost = env_runners_lost(algo, config)
            if lost is not None:  # none left to sample with: stop here, resumable, rather than wait for a node
                break
            _record(progress, result, weights)
            progress.update(steps)
            if steps >= next_checkpoint and steps < config.total_steps:
                save_checkpoint(run, algo, steps)
                next_checkpoint = (steps // every + 1) * every
        interrupted = bool(stop) or lost is not None
    except KeyboardInterrupt:  # a second Ctrl-C: stop at once
        interrupted = True
    finally:
        save_checkpoint(run, algo, steps)
        wall = progress.wall_s()
        rate = (steps - start_steps) / max(1e-9, wall - progress.wall_before)
        progress.close()
        algo.stop()
    if not quiet and interrupted and lost is None:
        print("interrupted: checkpoint written", file=sys.stderr)
    return {
        "steps": int(steps),
        "wall_s": wall,
        "steps_per_s_including_learning": rate,
        "interrupted": interrupted,
        **({"stopped_because": lost} if lost is not None else {}),
    }


def env_runners_lost(algo, config: TrainingConfig) -> str | None:
    """Why training cannot go on, when every remote env runner is gone (their node died or was
    stopped): RLlib would wait for a node to restart them on (up to its restore timeout, 30 min).
    None while one is healthy: RLlib then samples with those and restarts the others where it can."""
    group = getattr(algo, "env_runner_group", None)
    if config.envs <= 1 or group is None:
        return None
    if group.num_healthy_remote_env_runners() > 0:
        return None
    return (
        f"all {group.num_remote_env_runners()} env runners were lost (the node they ran on died or left the cluster); "
        "checkpoint written: start a worker node again and run the same command with --resume"
    )
