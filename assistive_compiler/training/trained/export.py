"""``export``: a run's newest checkpoint as a shipped-policy folder (NumPy only), evaluated.

The folder (default ``pretrained/<task>-<robot>[-coop]``) holds the network as
:class:`~assistive_compiler.policies.mlp.MLPPolicy` files, the run's learning curve
(``curve.csv``) and, in ``policy.json``, everything ``results`` needs to write a table row:
what was trained (task, robot, algorithm, config, the compiled task's content hash), how long
(env steps, wall time, env steps/s including learning), and the exported policy's own
evaluation (the mean action, ``episodes`` episodes on seeds ``seed``.. that training never used),
the same with actions sampled from the policy's Gaussian (``evaluation_sampled``: the reference
code's protocol), plus the few fixed ``regression`` seeds the test suite re-checks on the current
code.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from ...policies.mlp import MLPPolicy
from ...run_dir import RunDir
from ..bookkeeping.curves import cut_curve
from ..config import run_config
from .evaluate import checkpoint_at

#: Unseen seeds of the evaluation: training seeds its envs with the config's seed (0–10 in the
#: shipped configs, plus the step count on resume) and never resets with a seed after that.
EVAL_SEED = 1_000_000
REGRESSION_EPISODES = 10


def _linears(module) -> list:
    import torch.nn as nn

    return [m for m in module.modules() if isinstance(m, nn.Linear)]


def _layers(linears) -> list[tuple[np.ndarray, np.ndarray]]:
    return [
        (m.weight.detach().cpu().numpy().astype(np.float64), m.bias.detach().cpu().numpy().astype(np.float64))
        for m in linears
    ]


def _sac_actor(actor, activation: str, low: np.ndarray, high: np.ndarray) -> MLPPolicy:
    """SAC's actor (SB3's, or one agent's head of a factored actor: ``latent_pi``, ``mu``,
    ``log_std``) as its mean through tanh, with the log-std layer for sampling."""
    from stable_baselines3.sac.policies import LOG_STD_MAX, LOG_STD_MIN

    layers = _layers(_linears(actor.latent_pi) + [actor.mu])
    log_std = _layers([actor.log_std])[0]  # a layer on the same features as the mean's
    return MLPPolicy(layers, activation, "tanh", low, high, log_std=log_std, log_std_bounds=(LOG_STD_MIN, LOG_STD_MAX))


def _ppo_actor(
    loaded, linears, activation: str, actions: slice = slice(None), observations: slice = slice(None)
) -> MLPPolicy:
    """PPO's Gaussian mean (the ``linears`` from observation to mean), clipped to the action
    bounds, with its observation normalisation if it used one and its free log-std vector; the
    ``actions`` and ``observations`` slices pick one agent's part of a co-optimised pair's."""
    model = loaded.model
    low, high = model.action_space.low[actions], model.action_space.high[actions]
    free = model.policy.log_std.detach().cpu().numpy().astype(np.float64)[actions]  # one vector, whatever the state
    rms = loaded.obs_rms
    normalisation = (
        {}
        if rms is None
        else {
            "obs_mean": rms.mean[observations],
            "obs_var": rms.var[observations],
            "obs_clip": loaded.clip,
            "obs_eps": loaded.eps,
        }
    )
    return MLPPolicy(_layers(linears), activation, "clip", low, high, log_std=free, **normalisation)


def pair_from_sb3(loaded, algorithm: str, activation: str) -> dict[str, MLPPolicy]:
    """Each agent's deterministic policy of a co-optimised SB3 checkpoint
    (:class:`~assistive_compiler.policies.checkpoint.SB3PairPolicy`: SAC's factored actor, or PPO's
    factored actor-critic), by agent name."""
    model = loaded.model
    if algorithm == "sac":
        actor, space = model.actor, model.action_space
        return {
            agent: _sac_actor(
                head, activation, space.low[actor.action_slices[agent]], space.high[actor.action_slices[agent]]
            )
            for agent, head in actor.heads.items()
        }
    policy = model.policy
    return {
        agent: _ppo_actor(
            loaded,
            _linears(head) + [policy.action_net.heads[agent]],
            activation,
            policy.action_slices[agent],
            policy.obs_slices[agent],
        )
        for agent, head in policy.mlp_extractor.policy_heads.items()
    }


def mlp_from_sb3(loaded, algorithm: str, activation: str) -> MLPPolicy:
    """The deterministic policy of a loaded SB3 checkpoint (:class:`~assistive_compiler.policies.checkpoint.SB3Policy`: SAC's actor
    mean through tanh; PPO's Gaussian mean, clipped), with PPO's observation normalisation if it used one."""
    model = loaded.model
    if loaded.numpy_policy is not None:  # SBX's SAC: its actor as the checkpoint already acts with it
        return loaded.numpy_policy
    if algorithm == "sac":
        return _sac_actor(model.actor, activation, model.action_space.low, model.action_space.high)
    return _ppo_actor(loaded, _linears(model.policy.mlp_extractor.policy_net) + [model.policy.action_net], activation)


def mlp_from_rllib(module, algorithm: str, activation: str) -> MLPPolicy:
    """The deterministic policy of an RLlib RLModule (the actor's encoder and its head, the
    Gaussian's means only): SAC's squashed through tanh, PPO's clipped to the action bounds."""
    encoder = module.pi_encoder if algorithm == "sac" else module.encoder.actor_encoder
    layers = _layers(_linears(encoder) + _linears(module.pi))
    w, b = layers[-1]
    half = w.shape[0] // 2  # the head gives means, then log-stds, from the same features
    layers[-1] = (w[:half], b[:half])
    space = module.action_space
    head = "tanh" if algorithm == "sac" else "clip"
    return MLPPolicy(
        layers, activation, head, space.low, space.high, log_std=(w[half:], b[half:]), log_std_bounds=(-20.0, 20.0)
    )


def _jax_mean_action(model):
    """An SBX model's deterministic action of one observation, computed by SBX itself."""
    return lambda obs: model.predict(np.asarray(obs, dtype=np.float32), deterministic=True)[0]


def check_same_actions(exported: MLPPolicy, original, observations: np.ndarray, atol: float = 1e-4) -> float:
    """The largest difference between the exported and the original policy's actions on
    ``observations``; raises when it exceeds ``atol`` (an export that changed the policy)."""
    worst = max(float(np.max(np.abs(exported(o) - np.asarray(original(o), dtype=np.float64)))) for o in observations)
    if worst > atol:
        raise RuntimeError(
            f"the exported policy's actions differ from the checkpoint's by up to {worst:.2e} (> {atol:g})"
        )
    return worst


def evaluate_policy(artifact: Path, policy, episodes: int, seed: int) -> dict:
    """Mean ± std return, success rate and force on the person over seeded episodes (deterministic);
    a co-optimised pair (:class:`~assistive_compiler.policies.pretrained.CoopPolicy`) plays both agents."""
    from ...policies.pretrained import CoopPolicy
    from .evaluate import play_episodes

    runs = play_episodes(artifact, policy, isinstance(policy, CoopPolicy), episodes, seed)
    returns = [r["return"] for r in runs]
    forces = [r["mean_force_on_human_n"] for r in runs]
    return {
        "episodes": episodes,
        "seed": seed,
        "mean_return": float(np.mean(returns)),
        "std_return": float(np.std(returns)),
        "success_rate": float(np.mean([r["success"] for r in runs])),
        "mean_force_on_human_n": float(np.mean(forces)),
        "std_force_on_human_n": float(np.std(forces)),
        "successes": [bool(r["success"]) for r in runs],
        "returns": [round(float(x), 3) for x in returns],
    }


def evaluations(artifact: Path, policy, episodes: int, seed: int, progress=None) -> tuple[dict, dict | None, dict]:
    """The exported policy's evaluation with its mean action; the same with actions sampled from its
    Gaussian (the reference code's protocol; seeded with the first episode's seed, as ``evaluate
    --stochastic`` samples), None without a log-std; and the regression record of its first seeds."""
    evaluation = evaluate_policy(artifact, policy, episodes, seed)
    sampled = evaluate_policy(artifact, policy.sampling(seed), episodes, seed) if policy.samples else None
    if progress:
        also = f", sampled actions {sampled['success_rate']:.2f}" if sampled else ""
        progress(f"evaluated {episodes} episodes: success {evaluation['success_rate']:.2f}{also}")
    first = min(REGRESSION_EPISODES, episodes)
    regression = {
        "seed": seed,
        "episodes": first,
        "success_rate": float(np.mean(evaluation["successes"][:first])),
        "mean_return": float(np.mean(evaluation["returns"][:first])),
    }
    return evaluation, sampled, regression


def _wall_at(run: RunDir, steps: int) -> float | None:
    """Wall seconds of training up to ``steps`` env steps (over every sitting of a resumed run),
    from the learning curve's last row at or before them."""
    from ..bookkeeping.curves import read_curve

    rows = [r for r in read_curve(run.curve_csv) if r["steps"] <= steps]
    return rows[-1]["wall_s"] if rows else None


def _trained_on_hash(run: RunDir) -> str:
    """The content hash, as today's code hashes it, of the compiled task the run trained on (its
    own artifact, checked undamaged)."""
    from ...artifact import Manifest

    return Manifest.read(run.artifact, verify=True).hash_of(run.artifact)


def _default_label(info) -> str:
    """``SAC (sac_laptop)``: the algorithm and the config the run was started with (``results``
    adds what a run that started from demonstrations started from)."""
    command = list(info.command)
    config = command[command.index("--config") + 1] if "--config" in command[:-1] else "config"
    return f"{info.algorithm.upper()} ({Path(config).stem})"


def export_run(
    run_dir: str | Path,
    out: str | Path | None = None,
    *,
    episodes: int = 100,
    seed: int = EVAL_SEED,
    label: str = "",
    progress=None,
    checkpoint_steps: int | None = None,
) -> dict:
    """Export the run's checkpoint at ``checkpoint_steps`` env steps (None: the newest) to ``out``
    and evaluate the exported policy there; returns its ``policy.json``. ``label`` names the table
    row (e.g. ``"PPO (paper) baseline"``). The learning curve goes with it up to that checkpoint."""
    from ...policies.pretrained import pretrained_dir

    run = RunDir(run_dir)
    info = run.info()
    steps, checkpoint = checkpoint_at(run, checkpoint_steps)
    config = run_config(info)
    rng = np.random.default_rng(0)
    from ...policies.pretrained import CoopPolicy

    if info.engine == "sb3" and not info.coop:
        from ...policies.checkpoint import SB3Policy

        original = SB3Policy(checkpoint, config.algorithm, library=config.library)
        policy = mlp_from_sb3(original, config.algorithm, config.network.activation)
        # an SBX checkpoint acts with the exported policy itself: compare with SBX's own (JAX) actions
        acting = original if original.numpy_policy is None else _jax_mean_action(original.model)
        worst = check_same_actions(policy, acting, rng.normal(0.0, 1.0, (32, policy.obs_dim)))
    else:
        from ...policies.checkpoint import SINGLE_MODULE, RLlibPolicy, SB3PairPolicy

        agents: SB3PairPolicy | RLlibPolicy  # each agent's checkpoint policy, by name: .agent(name)
        if info.engine == "sb3":
            agents = SB3PairPolicy(checkpoint, config.algorithm)
            parts = pair_from_sb3(agents, config.algorithm, config.network.activation)
        else:
            agents = RLlibPolicy(checkpoint, info.coop, config.algorithm)
            parts = {
                name: mlp_from_rllib(module, config.algorithm, config.network.activation)
                for name, module in agents.modules.items()
            }
        worst = max(
            check_same_actions(part, agents.agent(name), rng.normal(0.0, 1.0, (32, part.obs_dim)))
            for name, part in parts.items()
        )
        policy = CoopPolicy(parts["robot"], parts["human"], {}) if info.coop else parts[SINGLE_MODULE]

    name = f"{info.task}-{info.robot}{'-coop' if info.coop else ''}"
    out = Path(out) if out else pretrained_dir() / name
    evaluation, sampled, regression = evaluations(run.artifact, policy, episodes, seed, progress)
    wall = _wall_at(run, steps)
    record = {
        "name": out.name,
        "label": label or _default_label(info),
        "task": info.task,
        "robot": info.robot,
        "coop": info.coop,
        "gym_id": info.gym_id,
        "spec": info.spec,
        # the run's own artifact under today's hashing rule (a run started before the rule recorded
        # the hash of its manifest file's JSON: the same task, another number)
        "content_hash": _trained_on_hash(run),
        "engine": info.engine,
        "algorithm": config.algorithm,
        # False for pure RL; a run started from demonstrations: its dataset and how the start went
        "demonstrations": run.demonstrations() or False,
        "config": config.model_dump(exclude_none=True),
        "trained_steps": steps,
        "wall_s": wall,
        "steps_per_s_including_learning": (steps / wall) if wall else None,
        "versions": info.versions,
        "export_max_action_difference": worst,
        "evaluation": evaluation,
        "evaluation_sampled": sampled,
        "regression": regression,
    }
    if out.exists():
        shutil.rmtree(out)
    if info.coop:
        for agent in ("robot", "human"):
            policy.agent(agent).save(out / agent, {"agent": agent, "task": info.task, "robot": info.robot})
        (out / "policy.json").write_text(json.dumps(record, indent=1) + "\n")
    else:
        policy.save(out, record)
    if run.curve_csv.is_file():  # the curve up to the exported checkpoint
        cut_curve(run.curve_csv, out / "curve.csv", steps)
    return json.loads((out / "policy.json").read_text())
