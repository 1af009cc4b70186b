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

from ..coop.rollout import both_agents
from ..episode import rollout
from ..errors import UsageError
from ..paths import display
from .run_dir import RunDir, RunInfo


def latest_checkpoint(run: RunDir) -> tuple[int, Path]:
    found = run.latest_checkpoint()
    if found is None:
        raise UsageError(f"{display(run.path)}: the run has no complete checkpoint yet (checkpoints/step_*/COMPLETE)")
    return found


def load_policy(info: RunInfo, checkpoint: Path):
    """The run's policy as ``obs -> action`` (co-optimised runs: ``(robot_obs, human_obs) -> (a_r, a_h)``)."""
    if info.engine == "sb3":
        from .sb3 import SB3Policy

        return SB3Policy(checkpoint, info.training_config.algorithm)
    from .rllib import RLlibPolicy

    return RLlibPolicy(checkpoint, coop=info.coop, algorithm=info.training_config.algorithm)


def _stats(values: list[float]) -> tuple[float, float]:
    return float(np.mean(values)), float(np.std(values))


def trained_task_spec(info: dict) -> Path:
    """The spec an exported policy was trained on: its recorded path where it exists, else the
    shipped task of the same name."""
    from ..paths import specs_dir

    recorded = Path(info.get("spec", ""))
    if recorded.is_file():
        return recorded
    return specs_dir() / "tasks" / f"{info['task']}.yaml"


def evaluate_exported(source: str, episodes: int = 100, seed: int = 0, render: str | None = None) -> dict:
    """Evaluate a shipped or exported policy (``pretrained:<name>`` or a policy folder) on its
    task, compiled on the current code (NumPy only; no training library needed). A co-optimised
    pair plays both agents."""
    from ..compile.compiler import compile_task
    from ..policies.pretrained import load_trained
    from ..registration import cached_artifact_dir

    policy, info = load_trained(source)
    spec = trained_task_spec(info)
    compiled = compile_task(spec, info["robot"], cached_artifact_dir(spec, info["robot"]))
    if info.get("coop"):
        from ..coop.parallel import AssistiveParallelEnv
        from ..coop.rollout import rollout_coop

        env = AssistiveParallelEnv(compiled.out_dir)
        results = [rollout_coop(env, policy.robot, policy.human, seed + k) for k in range(episodes)]
    else:
        from ..runtime.env import AssistiveEnv

        env = AssistiveEnv.from_compiled(compiled)
        results = [rollout(env, policy, seed + k) for k in range(episodes)]
    env.close()
    out = {"run": source, "gym_id": info["gym_id"], "task": info["task"], "robot": info["robot"], "coop": bool(info.get("coop")),
           "engine": info["engine"], "checkpoint": source, "trained_steps": info["trained_steps"], "episodes": episodes,
           "seed": seed, "content_hash": compiled.manifest.content_hash, "trained_on_content_hash": info["content_hash"],
           **_figures(results), "per_episode": results}
    if render:
        from ..cli.render import record, write_picture
        from ..runtime.env import AssistiveEnv

        env = AssistiveEnv(compiled.out_dir, render_mode="rgb_array")
        target, act = (env, policy) if not info.get("coop") else both_agents(env, policy)
        frames, summary = record(target, act, seed, 2)
        env.close()
        write_picture(frames, Path(render), fps=5)
        out["render"] = (f"wrote {display(Path(render))} ({len(frames)} frames; return {summary['return']:.1f}, "
                         f"success {'yes' if summary['success'] else 'no'})")
    return out


def _figures(results: list[dict]) -> dict:
    mean_r, std_r = _stats([e["return"] for e in results])
    mean_f, std_f = _stats([e["mean_force_on_human_n"] for e in results])
    mean_s, std_s = _stats([float(e["success"]) for e in results])
    return {"mean_return": mean_r, "std_return": std_r, "success_rate": mean_s, "std_success": std_s,
            "mean_force_on_human_n": mean_f, "std_force_on_human_n": std_f}


def evaluate(run_dir: str | Path, episodes: int | None = None, seed: int = 0, render: str | None = None) -> dict:
    """Evaluate the run's newest checkpoint; optionally write a rollout (``render``: .gif or .png)."""
    from ..runtime.env import AssistiveEnv

    run = RunDir(run_dir)
    info = run.info()
    steps, checkpoint = latest_checkpoint(run)
    episodes = episodes or info.training_config.eval_episodes
    policy = load_policy(info, checkpoint)
    if info.coop:
        from ..coop.parallel import AssistiveParallelEnv
        from ..coop.rollout import rollout_coop

        env = AssistiveParallelEnv(run.artifact)
        results = [rollout_coop(env, policy.agent("robot"), policy.agent("human"), seed + k) for k in range(episodes)]
    else:
        env = AssistiveEnv(run.artifact)
        results = [rollout(env, policy, seed + k) for k in range(episodes)]
    env.close()
    out = {
        "run": display(run.path), "gym_id": info.gym_id, "task": info.task, "robot": info.robot, "coop": info.coop,
        "engine": info.engine, "checkpoint": display(checkpoint), "trained_steps": steps, "episodes": episodes, "seed": seed,
        **_figures(results), "per_episode": results,
    }
    if render:
        out["render"] = render_rollout(run, info, checkpoint, seed, Path(render))
    return out


def render_rollout(run: RunDir, info: RunInfo, checkpoint: Path, seed: int, out: Path, every: int = 2) -> str:
    """Write one rollout of the trained policy as a GIF (or a PNG strip); returns a line saying so."""
    from ..cli.render import record, write_picture
    from ..runtime.env import AssistiveEnv

    env = AssistiveEnv(run.artifact, render_mode="rgb_array")
    policy = load_policy(info, checkpoint)
    target, act = (env, policy) if not info.coop else both_agents(env, policy)
    frames, summary = record(target, act, seed, every)
    env.close()
    write_picture(frames, out, fps=max(1, 10 // every))
    return f"wrote {display(out)} ({len(frames)} frames; return {summary['return']:.1f}, success {'yes' if summary['success'] else 'no'})"


def save_evaluation(run: RunDir, result: dict) -> Path:
    """Write ``evaluation.json`` in the run directory (``table`` reads it)."""
    import json

    from .run_dir import write_atomic

    out = run.path / "evaluation.json"
    write_atomic(out, json.dumps(result, indent=1))
    return out


def format_report(result: dict) -> str:
    """The human-readable evaluation summary."""
    return "\n".join([
        f"{result['gym_id']}  {result['engine']}  checkpoint {result['checkpoint']} ({result['trained_steps']:,} steps)",
        f"episodes {result['episodes']} (seeds {result['seed']}..{result['seed'] + result['episodes'] - 1}), deterministic actions",
        f"return          {result['mean_return']:9.2f} ± {result['std_return']:.2f}",
        f"success rate    {result['success_rate']:9.2f} ± {result['std_success']:.2f}",
        f"force on person {result['mean_force_on_human_n']:9.2f} ± {result['std_force_on_human_n']:.2f} N (per-episode mean)",
    ] + ([result["render"]] if "render" in result else []))
