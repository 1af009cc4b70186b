"""Co-optimisation episodes and speed: :func:`rollout_coop` (one episode of both agents, summed)
and :func:`bench_coop` (single- vs multi-agent env steps/s of one artifact, in one run)."""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..episode import EpisodeTally
from .parallel import AssistiveParallelEnv
from .policies import agent_policy

__all__ = ["rollout_coop", "bench_coop"]


def rollout_coop(env: AssistiveParallelEnv, robot_policy: Any, human_policy: Any, seed: int) -> dict:
    """One episode with both agents acting (policies as :func:`~.policies.agent_policy` takes them).
    Returns the shared return, success, each term's unweighted values summed over the episode,
    the mean force on the person (N) and the arm-limit reverts of the episode."""
    obs, _ = env.reset(seed=seed)
    act = {
        "robot": agent_policy(env, "robot", robot_policy, seed),
        "human": agent_policy(env, "human", human_policy, seed),
    }
    tally = EpisodeTally()
    while env.agents:
        obs, rewards, _, _, infos = env.step({agent: act[agent](obs[agent]) for agent in env.possible_agents})
        tally.add(rewards["robot"], infos["human"])
    return {**tally.summary(seed), "arm_limit_reverts": tally.info["arm_limit_reverts"]}


def bench_coop(artifact_dir: str | Path, steps: int = 200, repeats: int = 5, seed: int = 0, chunk: int = 10) -> dict:
    """Env steps/s of one artifact as the single-agent env (the robot acts, the person is static)
    and as the multi-agent env (the PettingZoo step, both agents acting), random actions: two envs
    of the artifact side by side, ``repeats`` episodes of ``steps`` each, stepped in alternating
    chunks of ``chunk`` steps (the order flips every chunk), so that the load of a shared machine
    weighs on both alike; where ``steps`` is longer than an episode, both envs start a new one
    (unseeded, untimed) when it ends. Medians over repeats, and their ratio."""
    from ..runtime.env import AssistiveEnv

    single, multi = AssistiveEnv(artifact_dir), AssistiveParallelEnv(artifact_dir)
    rng = np.random.default_rng(seed)
    shapes = {agent: multi.action_space(agent).shape for agent in multi.possible_agents}

    def draw(agent: str) -> np.ndarray:
        return rng.uniform(-1.0, 1.0, shapes[agent]).astype(np.float32)

    def run_single(n: int) -> float:
        t0 = time.perf_counter()
        for _ in range(n):
            single.step(draw("robot"))
        return time.perf_counter() - t0

    def run_multi(n: int) -> float:
        t0 = time.perf_counter()
        for _ in range(n):
            multi.step({"robot": draw("robot"), "human": draw("human")})
        return time.perf_counter() - t0

    episode_steps = single.manifest.sim.episode_steps
    rates: dict[str, list[float]] = {"single": [], "multi": []}
    try:
        for r in range(repeats):
            single.reset(seed=seed + r)
            multi.reset(seed=seed + r)
            spent = {"single": 0.0, "multi": 0.0}
            start, k = 0, 0
            while start < steps:
                if not multi.agents:  # an episode ended (sim.episode_steps): both go on in a new one, untimed
                    single.reset()
                    multi.reset()
                n = min(chunk, steps - start, episode_steps - multi.env.steps)
                order = (("single", run_single), ("multi", run_multi))
                for name, run in order if k % 2 == 0 else order[::-1]:
                    spent[name] += run(n)
                start, k = start + n, k + 1
            for name in rates:
                rates[name].append(steps / spent[name])
        reverts = multi.env.arm_limit_reverts
    finally:
        single.close()
        multi.close()
    s, mu = statistics.median(rates["single"]), statistics.median(rates["multi"])
    m = single.manifest
    return {
        "task": m.task,
        "robot": m.robot_name,
        "name": multi.metadata["name"],
        "human_action_size": int(shapes["human"][0]),
        "human_obs_size": int(multi.observation_space("human").shape[0]),
        "single_agent_env_steps_per_s": round(s, 1),
        "multi_agent_env_steps_per_s": round(mu, 1),
        "multi_over_single": round(mu / s, 3),
        "arm_limit_reverts_last_episode": reverts,
        "steps_per_repeat": steps,
        "repeats": repeats,
        "chunk": chunk,
        "notes": "one artifact, two envs side by side; single: env.step (robot acts, person static); multi: the "
        "PettingZoo step, both agents random; stepped in alternating chunks; medians over episodes",
    }
