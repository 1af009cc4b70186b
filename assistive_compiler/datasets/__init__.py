"""Demonstration datasets in Minari, the Farama standard for offline RL (the ``datasets`` extra).

:func:`collect` plays a policy for N episodes from consecutive seeds and writes them with
``minari.create_dataset_from_buffers``, loadable with ``minari.load_dataset(dataset_id)``:

* per episode: observations (T+1, O) float32, actions (T, A), rewards (T,), terminations and
  truncations (T,), the reset seed, and infos ``task_success`` (T+1,) int (0 after reset),
  ``success_metric`` (T+1,) and ``force_on_human`` (T+1,) N (0 after reset);
* dataset metadata: ``assistive_compiler`` = {``content_hash`` (the artifact's), ``task``, ``robot``,
  ``gym_id``, ``policy``, ``seeds``, ``successes`` (per episode), ``term_weights``};
* the env spec is the registered entry point with the spec path and robot, so
  ``dataset.recover_environment()`` builds the env again.

Datasets go under ``$MINARI_DATASETS_PATH`` (Minari's default ``~/.minari/datasets``), or under
``root`` when given.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

__all__ = ["collect"]


def _play(env, act, seed: int):
    """One episode as a Minari ``EpisodeBuffer`` (complete lists), and whether it succeeded."""
    from minari.data_collector.episode_buffer import EpisodeBuffer

    obs, _ = env.reset(seed=seed)
    observations, actions, rewards, terminations, truncations = [obs], [], [], [], []
    infos = {"task_success": [0], "success_metric": [0.0], "force_on_human": [0.0]}
    done = False
    while not done:
        action = act(obs)
        obs, reward, terminated, truncated, info = env.step(action)  # the policy's action as it is, as `run` plays it
        observations.append(obs)
        actions.append(np.asarray(action, dtype=np.float32))  # stored in the action space's dtype
        rewards.append(float(reward))
        terminations.append(bool(terminated))
        truncations.append(bool(truncated))
        infos["task_success"].append(int(info["task_success"]))
        infos["success_metric"].append(float(info["success_metric"]))
        infos["force_on_human"].append(float(info["total_force_on_human"]))
        done = terminated or truncated
    buffer = EpisodeBuffer(
        seed=seed,
        observations=np.asarray(observations),
        actions=np.asarray(actions),
        rewards=rewards,
        terminations=terminations,
        truncations=truncations,
        infos={k: np.asarray(v) for k, v in infos.items()},
    )
    return buffer, bool(infos["task_success"][-1])


def collect(
    spec: str,
    robot: str | None,
    dataset_id: str,
    policy: str = "scripted",
    episodes: int = 5,
    seed: int = 0,
    root: str | Path | None = None,
    out: str | None = None,
    progress=None,
):
    """Play ``policy`` for ``episodes`` episodes (seeds ``seed``, ``seed + 1``, ...) and write the
    Minari dataset ``dataset_id`` (e.g. ``assistive_compiler/feeding-jaco/scripted-v0``). Returns
    the ``MinariDataset``. ``progress(k, success)`` is called after each episode.

    Episodes are played here and handed to ``minari.create_dataset_from_buffers``: Minari's
    ``DataCollector`` wrapper needs jax (``minari[create]``) only to append steps, which complete
    episode buffers do not need."""
    import gymnasium as gym
    import minari

    from ..compile.compiler import compile_task
    from ..policies import make_policy
    from ..runtime.env import AssistiveEnv

    if root is not None:
        os.environ["MINARI_DATASETS_PATH"] = str(Path(root).resolve())
    result = compile_task(spec, robot, out)
    m = result.manifest
    env = AssistiveEnv.from_compiled(result)
    env_spec = gym.envs.registration.EnvSpec(
        m.gym_id,
        entry_point="assistive_compiler.registration:make_env",
        kwargs={"spec": str(Path(spec).resolve()), "robot": m.robot_name},
        max_episode_steps=m.sim.episode_steps,
        disable_env_checker=True,
    )
    act = make_policy(policy, env, seed=seed)
    buffers, successes = [], []
    try:
        for k in range(episodes):
            buffer, success = _play(env, act, seed + k)
            buffers.append(buffer)
            successes.append(success)
            if progress is not None:
                progress(k, success)
        dataset = minari.create_dataset_from_buffers(
            dataset_id,
            buffers,
            env=env_spec,
            observation_space=env.observation_space,
            action_space=env.action_space,
            algorithm_name=f"assistive-compiler {policy} policy",
            data_format="hdf5",
            description=f"{m.title} with {m.robot.title}: {episodes} episodes of the {policy} policy from seed {seed} "
            f"(assistive-compiler, artifact {m.content_hash[:12]})",
        )
    finally:
        env.close()
    dataset.storage.update_metadata(
        {
            "assistive_compiler": {
                "content_hash": m.content_hash,
                "task": m.task,
                "robot": m.robot_name,
                "gym_id": m.gym_id,
                "policy": policy,
                "seeds": [seed + k for k in range(episodes)],
                "successes": successes,
                "term_weights": {t.name: t.weight for t in m.reward},
            }
        }
    )
    return minari.load_dataset(dataset_id)
