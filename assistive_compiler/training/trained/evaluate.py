"""``evaluate``: roll out a run's trained policy as the reference evaluates (the reference implementation, Assistive Gym v1.0): mean and
std of the episode return, of the per-episode mean total force on the person (N) and of the
final-step task success, over ``episodes`` episodes seeded ``seed``, ``seed + 1``, ...

Actions are the policy's deterministic ones (the mean of its Gaussian), so the same run, seed
and episode count give the same figures. SB3 and RLlib runs alike: a co-optimised run's robot
and human policies act together in the task's co-optimisation face (``step_agents``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...episode import rollout
from ...errors import UsageError
from ...paths import display
from ...policies.checkpoint import latest_checkpoint, load_policy
from ...policies.pair import both_agents
from ...run_dir import RunDir
from ..config import run_config


def checkpoint_at(run: RunDir, steps: int | None) -> tuple[int, Path]:
    """The run's complete checkpoint at ``steps`` env steps (None: the newest)."""
    if steps is None:
        return latest_checkpoint(run)
    done = run.complete_checkpoints()
    if steps not in done:
        have = ", ".join(f"{s:,}" for s in done) or "none yet"
        raise UsageError(f"{display(run.path)}: no complete checkpoint at {steps:,} env steps; it has {have}")
    return steps, done[steps]


def _stats(values: list[float]) -> tuple[float, float]:
    return float(np.mean(values)), float(np.std(values))


def trained_task_spec(info: dict) -> Path:
    """The spec an exported policy was trained on: its recorded path where it exists, else the
    shipped task of the same name."""
    from ...paths import specs_dir

    recorded = Path(info.get("spec", ""))
    if recorded.is_file():
        return recorded
    return specs_dir() / "tasks" / f"{info['task']}.yaml"


def compile_for_policy(info: dict):
    """The task an exported policy was trained on, compiled on the current code (a cache hit when unchanged)."""
    from ...compile.compiler import compile_task
    from ...registration import cached_artifact_dir

    spec = trained_task_spec(info)
    return compile_task(spec, info["robot"], cached_artifact_dir(spec, info["robot"]))


def play_episodes(artifact_dir: str | Path, policy, coop: bool, episodes: int, seed: int) -> list[dict]:
    """``episodes`` seeded episodes (``seed``, ``seed + 1``, ...) of ``policy`` on the artifact; a
    co-optimised pair (anything with ``agent("robot")`` and ``agent("human")``) plays both agents."""
    if coop:
        from ...coop.parallel import AssistiveParallelEnv
        from ...coop.rollout import rollout_coop

        env = AssistiveParallelEnv(artifact_dir)
        play = lambda k: rollout_coop(env, policy.agent("robot"), policy.agent("human"), seed + k)  # noqa: E731
    else:
        from ...runtime.env import AssistiveEnv

        env = AssistiveEnv(artifact_dir)
        play = lambda k: rollout(env, policy, seed + k)  # noqa: E731
    try:
        return [play(k) for k in range(episodes)]
    finally:
        env.close()


def write_rollout(artifact_dir: str | Path, policy, coop: bool, seed: int, out: Path, every: int = 2) -> str:
    """Write one rollout of ``policy`` as a GIF (or a PNG strip); returns a line saying so."""
    from ...pictures import episode_frames, write_picture
    from ...runtime.env import AssistiveEnv

    env = AssistiveEnv(artifact_dir, render_mode="rgb_array")
    target, act = (env, policy) if not coop else both_agents(env, policy)
    frames, summary = episode_frames(target, act, seed, every)
    env.close()
    write_picture(frames, out, fps=max(1, 10 // every))
    return f"wrote {display(out)} ({len(frames)} frames; return {summary['return']:.1f}, success {'yes' if summary['success'] else 'no'})"


def evaluate_exported(
    source: str, episodes: int = 100, seed: int = 0, render: str | None = None, stochastic: bool = False
) -> dict:
    """Evaluate a shipped or exported policy (``pretrained:<name>`` or a policy folder) on its
    task, compiled on the current code (NumPy only; no training library needed). A co-optimised
    pair plays both agents. ``stochastic`` samples its actions as training did (seeded with
    ``seed``): for policies exported with their log-std; older ones are refused with what to do."""
    from ...errors import UsageError
    from ...policies.pretrained import load_trained

    trained, info = load_trained(source)
    if stochastic and not trained.samples:
        raise UsageError(
            f"evaluate --stochastic: {source} was exported without its policy's log-std (by an earlier version), "
            "so it keeps only the deterministic action; evaluate its run directory, or export the run again"
        )
    policy = trained.sampling(seed) if stochastic else trained
    coop = bool(info.get("coop"))
    compiled = compile_for_policy(info)
    results = play_episodes(compiled.out_dir, policy, coop, episodes, seed)
    out = {
        "run": source,
        "gym_id": info["gym_id"],
        "task": info["task"],
        "robot": info["robot"],
        "coop": coop,
        "engine": info["engine"],
        "checkpoint": source,
        "trained_steps": info["trained_steps"],
        "episodes": episodes,
        "seed": seed,
        "actions": "stochastic" if stochastic else "deterministic",
        "content_hash": compiled.manifest.content_hash,
        "trained_on_content_hash": info["content_hash"],
        **_figures(results),
        "per_episode": results,
    }
    if render:  # the first episode again: a sampling policy starts over from its seed
        picture = trained.sampling(seed) if stochastic else trained
        out["render"] = write_rollout(compiled.out_dir, picture, coop, seed, Path(render))
    return out


def _figures(results: list[dict]) -> dict:
    mean_r, std_r = _stats([e["return"] for e in results])
    mean_f, std_f = _stats([e["mean_force_on_human_n"] for e in results])
    mean_s, std_s = _stats([float(e["success"]) for e in results])
    return {
        "mean_return": mean_r,
        "std_return": std_r,
        "success_rate": mean_s,
        "std_success": std_s,
        "mean_force_on_human_n": mean_f,
        "std_force_on_human_n": std_f,
    }


def evaluate(
    run_dir: str | Path,
    episodes: int | None = None,
    seed: int = 0,
    render: str | None = None,
    checkpoint_steps: int | None = None,
    stochastic: bool = False,
) -> dict:
    """Evaluate the run's checkpoint at ``checkpoint_steps`` env steps (None: the newest); optionally
    write a rollout (``render``: .gif or .png). Actions are deterministic, as the paper evaluates;
    ``stochastic`` samples them as training did (seeded with ``seed``), to see how much of a training
    curve's success the policy's noise makes."""
    run = RunDir(run_dir)
    info = run.info()
    steps, checkpoint = checkpoint_at(run, checkpoint_steps)
    episodes = episodes or run_config(info).eval_episodes
    policy = load_policy(info, checkpoint, stochastic=stochastic, seed=seed)
    results = play_episodes(run.artifact, policy, info.coop, episodes, seed)
    out = {
        "run": display(run.path),
        "gym_id": info.gym_id,
        "task": info.task,
        "robot": info.robot,
        "coop": info.coop,
        "engine": info.engine,
        "checkpoint": display(checkpoint),
        "trained_steps": steps,
        "episodes": episodes,
        "seed": seed,
        "actions": "stochastic" if stochastic else "deterministic",
        "demonstrations": run.demonstrations() is not None,  # started from demonstrations, not the reward alone
        **_figures(results),
        "per_episode": results,
    }
    if render:
        # the first episode again: a sampling policy starts over from its seed, a deterministic one as it is
        picture = load_policy(info, checkpoint, stochastic=True, seed=seed) if stochastic else policy
        out["render"] = write_rollout(run.artifact, picture, info.coop, seed, Path(render))
    return out


def save_evaluation(run: RunDir, result: dict) -> Path:
    """Write ``evaluation.json`` in the run directory (``table`` reads it)."""
    import json

    from ...run_dir import write_atomic

    out = run.path / "evaluation.json"
    write_atomic(out, json.dumps(result, indent=1))
    return out


def format_report(result: dict) -> str:
    """The human-readable evaluation summary."""
    return "\n".join(
        [
            f"{result['gym_id']}  {result['engine']}  checkpoint {result['checkpoint']} ({result['trained_steps']:,} steps)",
            f"episodes {result['episodes']} (seeds {result['seed']}..{result['seed'] + result['episodes'] - 1}), "
            f"{result.get('actions', 'deterministic')} actions",
            f"return          {result['mean_return']:9.2f} ± {result['std_return']:.2f}",
            f"success rate    {result['success_rate']:9.2f} ± {result['std_success']:.2f}",
            f"force on person {result['mean_force_on_human_n']:9.2f} ± {result['std_force_on_human_n']:.2f} N (per-episode mean)",
        ]
        + ([result["render"]] if "render" in result else [])
    )
