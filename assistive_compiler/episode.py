"""One episode: :func:`rollout` plays it, :class:`EpisodeTally` sums it (the co-optimisation
rollout shares the tally)."""

from __future__ import annotations

import numpy as np


class EpisodeTally:
    """Sums an episode's rewards and each term's unweighted values (the reward is Σ weight ×
    value), and averages the contact force on the person (N), from each step's reward and info."""

    def __init__(self) -> None:
        self.total = 0.0
        self.terms: dict[str, float] = {}
        self.forces: list[float] = []
        self.info: dict = {}

    def add(self, reward: float, info: dict) -> None:
        self.total += reward
        for name, value in info["terms"].items():
            self.terms[name] = self.terms.get(name, 0.0) + value
        self.forces.append(info["total_force_on_human"])
        self.info = info

    def summary(self, seed: int) -> dict:
        return {
            "seed": seed,
            "return": self.total,
            "success": bool(self.info["task_success"]),
            "success_metric": self.info["success_metric"],
            "mean_force_on_human_n": float(np.mean(self.forces)),
            "terms": self.terms,
        }


def rollout(env, policy, seed: int) -> dict:
    """One episode of ``policy`` (``obs -> action``) in ``env`` from ``reset(seed=seed)``: return,
    success, each term's unweighted values summed over the episode (the reward is Σ weight ×
    value), mean force on the person (N)."""
    obs, info = env.reset(seed=seed)
    tally = EpisodeTally()
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        tally.add(reward, info)
        done = terminated or truncated
    return tally.summary(seed)
