"""Digests of one seeded episode start per shipped id, to show a refactor changes no episode.

For each of the 36 Gymnasium ids, two rollouts from a seeded reset: the scripted baseline
(``SCRIPTED_SEED``) and seeded random actions (``RANDOM_SEED``), ``STEPS`` env steps each. Every
step's observation, reward and unweighted term values (and the success flag and force on the
person) are rounded to ``DECIMALS`` places and hashed, one short digest per step and field, so a
mismatch names the first step and the field that changed.

Regenerate the stored digests (only after a change that is meant to change episodes, and say so in
the commit)::

    python -m tests.episode_digests --write
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import numpy as np

STORE = Path(__file__).parent / "data" / "episode_digests.json"
STEPS = 25
SCRIPTED_SEED = 0
RANDOM_SEED = 1
DECIMALS = 7
"""Rounding before hashing: far below any physical effect, far above the last bit a numpy build or
CPU may differ in."""


def _digest(*arrays, names: str = "") -> str:
    h = hashlib.sha256(names.encode())
    for a in arrays:
        h.update(np.round(np.asarray(a, dtype=np.float64), DECIMALS).tobytes())
    return h.hexdigest()[:10]


def episode(env, policy_name: str, seed: int) -> dict[str, list[str]]:
    """Per-step digests of ``policy_name`` (scripted or random) from ``env.reset(seed=seed)``."""
    from assistive_compiler.policies import make_policy

    obs, _ = env.reset(seed=seed)
    policy = make_policy(policy_name, env, seed=seed)
    out: dict[str, list[str]] = {"obs": [_digest(obs)], "reward": [], "terms": [], "outcome": []}
    for _ in range(STEPS):
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        terms = info["terms"]
        out["obs"].append(_digest(obs))
        out["reward"].append(_digest(reward))
        out["terms"].append(_digest([terms[k] for k in terms], names=",".join(terms)))
        out["outcome"].append(_digest(float(info["task_success"]), info["total_force_on_human"]))
        if terminated or truncated:
            break
    return out


def rollouts(env) -> dict[str, dict[str, list[str]]]:
    """Both rollouts in ``env``: {"scripted": ..., "random": ...}."""
    return {"scripted": episode(env, "scripted", SCRIPTED_SEED), "random": episode(env, "random", RANDOM_SEED)}


def digests(env_id: str) -> dict[str, dict[str, list[str]]]:
    """Both rollouts of the shipped id ``env_id``."""
    import gymnasium as gym

    import assistive_compiler  # noqa: F401  (registers the ids)

    env = gym.make(env_id).unwrapped
    try:
        return rollouts(env)
    finally:
        env.close()


def first_difference(expected: dict, got: dict) -> str | None:
    """Where two ``digests`` results first differ ('random rollout, step 3: obs, reward'), or None."""
    for rollout in ("scripted", "random"):
        e, g = expected[rollout], got[rollout]
        for step in range(max(len(e["obs"]), len(g["obs"]))):
            fields = [f for f in ("obs", "reward", "terms", "outcome") if _at(e[f], f, step) != _at(g[f], f, step)]
            if fields:
                return f"{rollout} rollout, step {step}: {', '.join(fields)} changed"
    return None


def _at(values: list[str], field: str, step: int) -> str | None:
    index = step if field == "obs" else step - 1  # obs[0] is the reset's observation
    return values[index] if 0 <= index < len(values) else None


def main(argv: list[str] | None = None) -> int:
    from assistive_compiler.gym_ids import shipped_ids

    from .stored_record import compare_or_write

    return compare_or_write(
        STORE,
        __doc__.split("\n\n")[0],
        "only these ids (default all shipped)",
        lambda: sorted(shipped_ids()),
        digests,
        first_difference,
        argv,
    )


if __name__ == "__main__":
    sys.exit(main())
