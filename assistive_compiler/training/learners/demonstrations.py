"""Start a SAC run from demonstrations: a Minari dataset that ``collect`` wrote on the same task.

Before the first env step of a new run (never on ``--resume``):

1. **Behaviour cloning.** The actor's deterministic action (its squashed mean, in the policy's
   [-1, 1] action scale) is fitted to the actions of the dataset's *successful* episodes by mean
   squared error, and its log-std by the likelihood of its misses, ``clone_epochs`` passes
   of Adam (``clone_learning_rate``) in shuffled batches of ``clone_batch_size`` steps.
2. **Replay.** Every demonstrated transition, failed episodes too, goes into the replay buffer with
   the reward it was recorded with; an episode's last step is terminal only where the episode
   terminated (a truncation at the time limit is not: SB3 bootstraps it).
3. **Critic warm-up.** ``critic_warmup_steps`` gradient steps of SAC's critic update alone (soft
   Bellman targets of the cloned actor, target critics following by Polyak averaging), on batches
   of the buffer. Untrained critics would otherwise steer the first actor updates away from the
   cloned behaviour before they know what it is worth.

While SAC learns (``clone_weight`` > 0, on ``--resume`` too), the cloning stays in the actor's
loss as a term, and the actor may be held still for SAC's first ``hold_actor_steps`` updates
(:class:`ActorUpdate`), as offline-to-online methods (TD3+BC, AWAC) anchor the actor: without
it, SAC's first actor updates follow critics that know the demonstrated actions only, and a
Drinking actor cloned to 15 % success lost it within 13,000 env steps. (With both, Drinking still
loses it to critics that over-value: docs/results.md, ninth sitting.)

The dataset must have been collected on the run's compiled task (the same content hash): a
dataset of another task, robot or task version is refused with what it was collected on.
Everything here is seeded from the run's seed, so the same dataset and config start the same.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import UsageError
from ..config import Demonstrations
from .wrapped_optimizer import WrappedOptimizer


@dataclass(frozen=True)
class DemonstrationData:
    """The transitions of a dataset's episodes, concatenated in episode order."""

    dataset: str
    observations: np.ndarray  # (N, O) float32, the observation each action was taken in
    next_observations: np.ndarray  # (N, O) float32, the observation after it
    actions: np.ndarray  # (N, A) in the env's action space
    rewards: np.ndarray  # (N,)
    terminations: np.ndarray  # (N,) bool
    truncations: np.ndarray  # (N,) bool
    successful: np.ndarray  # (N,) bool: the step belongs to an episode that succeeded
    episodes: int
    successes: int
    policy: str


def load_demonstrations(settings: Demonstrations, content_hash: str) -> DemonstrationData:
    """Read the dataset ``settings.dataset`` and check it was collected on ``content_hash``."""
    if settings.dataset is None:
        raise UsageError("starting from demonstrations needs a dataset: --demonstrations DATASET")
    try:
        import minari
    except ImportError:
        raise UsageError(
            'train --demonstrations: Minari datasets need the "datasets" extra: pip install "assistive-compiler[datasets]"'
        ) from None
    if settings.root is not None:
        os.environ["MINARI_DATASETS_PATH"] = str(Path(settings.root).resolve())
    where = settings.root or os.environ.get("MINARI_DATASETS_PATH", "~/.minari/datasets")
    try:
        dataset = minari.load_dataset(settings.dataset)
    except (FileNotFoundError, ValueError) as exc:
        local = []
        try:
            local = sorted(minari.list_local_datasets())
        except Exception:  # noqa: BLE001 — only for the message
            pass
        there = f"; datasets there: {', '.join(local)}" if local else "; there are none there"
        raise UsageError(
            f"--demonstrations {settings.dataset}: no such Minari dataset under {where} ({exc}){there}"
        ) from None
    meta = dataset.storage.metadata.get("assistive_compiler")
    if not isinstance(meta, dict) or "content_hash" not in meta:
        raise UsageError(
            f"--demonstrations {settings.dataset}: not a dataset written by `assistive-compiler collect` "
            "(its metadata has no assistive_compiler.content_hash), so it cannot be checked against the task"
        )
    if meta["content_hash"] != content_hash:
        raise UsageError(
            f"--demonstrations {settings.dataset}: collected on {meta.get('task')} × {meta.get('robot')}, "
            f"compiled task {str(meta['content_hash'])[:12]}; this run trains compiled task {content_hash[:12]}. "
            "Collect demonstrations on this task and robot (assistive-compiler collect SPEC --robot ROBOT)"
        )
    parts: dict[str, list[np.ndarray]] = {k: [] for k in ("obs", "next", "act", "rew", "term", "trunc", "ok")}
    successes = 0
    for episode in dataset.iterate_episodes():
        obs = np.asarray(episode.observations, dtype=np.float32)
        steps = len(episode.actions)
        success = bool(np.asarray(episode.infos["task_success"])[-1])
        successes += success
        parts["obs"].append(obs[:-1])
        parts["next"].append(obs[1:])
        parts["act"].append(np.asarray(episode.actions, dtype=np.float32))
        parts["rew"].append(np.asarray(episode.rewards, dtype=np.float32))
        parts["term"].append(np.asarray(episode.terminations, dtype=bool))
        parts["trunc"].append(np.asarray(episode.truncations, dtype=bool))
        parts["ok"].append(np.full(steps, success))
    if (settings.clone_epochs or settings.clone_weight) and not successes:
        raise UsageError(
            f"--demonstrations {settings.dataset}: none of its {len(parts['obs'])} episodes succeeded, so there is "
            "nothing to clone; collect more episodes, or set demonstrations.clone_epochs: 0 and clone_weight: 0 "
            "to use it for replay only"
        )
    return DemonstrationData(
        dataset=settings.dataset,
        observations=np.concatenate(parts["obs"]),
        next_observations=np.concatenate(parts["next"]),
        actions=np.concatenate(parts["act"]),
        rewards=np.concatenate(parts["rew"]),
        terminations=np.concatenate(parts["term"]),
        truncations=np.concatenate(parts["trunc"]),
        successful=np.concatenate(parts["ok"]),
        episodes=len(parts["obs"]),
        successes=successes,
        policy=str(meta.get("policy", "?")),
    )


def cloning_loss(actor, obs, target):
    """``(miss, spread)``: the behaviour-cloning loss of an SB3 SAC ``actor`` on demonstrated steps
    (``target``: actions in the [-1, 1] scale). ``miss``: the mean squared error of the
    deterministic action (the squashed mean). ``spread``: a Gaussian's negative log-likelihood of
    those misses (the mean held) under the actor's σ, so σ is as wide as the clone misses, per
    action dimension — in the action scale: before the squashing σ is then at most as wide where
    tanh' < 1 (a likelihood through the squashing would blow σ up on the demonstrations' saturated
    ±1 actions). The log-std head reads the shared layers without training them: they serve the
    mean's fit."""
    import torch
    from stable_baselines3.sac.policies import LOG_STD_MAX, LOG_STD_MIN

    latent = actor.latent_pi(actor.extract_features(obs, actor.features_extractor))
    log_std = torch.clamp(actor.log_std(latent.detach()), LOG_STD_MIN, LOG_STD_MAX)
    miss = torch.tanh(actor.mu(latent)) - target
    spread = torch.mean(0.5 * (miss.detach() / log_std.exp()) ** 2 + log_std)
    return torch.mean(miss**2), spread


def clone(model, data: DemonstrationData, settings: Demonstrations, seed: int) -> dict:
    """Fit ``model``'s (SB3 SAC) actor to the successful episodes' actions; returns the figures
    (steps cloned, epochs, the deterministic action's mean squared error before and after in the
    [-1, 1] action scale, and the policy's mean standard deviation before the squashing after).

    The deterministic action (the squashed mean) is fitted by mean squared error; the log-std, by
    a Gaussian likelihood of the mean's misses (the mean held), so the cloned policy
    explores as far as it misses the demonstrations, not with the initial noise (σ ≈ 1 before the
    squashing, which would throw the cloned behaviour away at the first sampled step)."""
    import torch

    figures = {"cloned_steps": int(data.successful.sum()), "clone_epochs": settings.clone_epochs}
    if settings.clone_epochs == 0:
        return figures
    obs, target = _cloning_targets(model, data)
    actor = model.actor
    optimiser = torch.optim.Adam(actor.parameters(), lr=settings.clone_learning_rate)
    rng = np.random.default_rng(seed)
    n, batch = len(obs), min(settings.clone_batch_size, len(obs))

    def measured() -> tuple[float, float]:
        with torch.no_grad():
            _, log_std, _ = actor.get_action_dist_params(obs)
            return float(torch.mean((actor(obs, deterministic=True) - target) ** 2)), float(log_std.exp().mean())

    figures["clone_mse_before"], figures["clone_std_before"] = measured()
    actor.train()
    for _ in range(settings.clone_epochs):
        order = rng.permutation(n)
        for start in range(0, n - batch + 1, batch):
            idx = torch.as_tensor(order[start : start + batch])
            loss = sum(cloning_loss(actor, obs[idx], target[idx]))
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
    actor.train(False)
    figures["clone_mse_after"], figures["clone_std_after"] = measured()
    return figures


def fill_replay(model, data: DemonstrationData) -> int:
    """Add every demonstrated transition to ``model``'s replay buffer (one env: SB3 adds per env
    process); returns how many."""
    buffer = model.replay_buffer
    actions = model.policy.scale_action(data.actions).clip(-1.0, 1.0)
    for k in range(len(actions)):
        terminated, truncated = bool(data.terminations[k]), bool(data.truncations[k])
        buffer.add(
            data.observations[k : k + 1],
            data.next_observations[k : k + 1],
            actions[k : k + 1],
            data.rewards[k : k + 1],
            np.array([terminated or truncated]),
            [{"TimeLimit.truncated": truncated and not terminated}],
        )
    return len(actions)


def warm_critic(model, steps: int) -> dict:
    """``steps`` of SAC's critic update alone on ``model``'s replay buffer (the actor and the
    temperature held); returns the mean critic loss of the first and the last 100 steps."""
    import torch
    import torch.nn.functional as F
    from stable_baselines3.common.utils import polyak_update

    if steps == 0:
        return {"critic_warmup_steps": 0}
    critic, target, actor = model.critic, model.critic_target, model.actor
    temperature = torch.exp(model.log_ent_coef.detach()) if model.log_ent_coef is not None else model.ent_coef_tensor
    losses = []
    critic.set_training_mode(True)
    for step in range(steps):
        batch = model.replay_buffer.sample(model.batch_size)
        with torch.no_grad():
            next_actions, next_log_prob = actor.action_log_prob(batch.next_observations)
            next_q = torch.min(torch.cat(target(batch.next_observations, next_actions), dim=1), dim=1, keepdim=True)[0]
            next_q = next_q - temperature * next_log_prob.reshape(-1, 1)
            goal = batch.rewards + (1 - batch.dones) * model.gamma * next_q
        loss = 0.5 * sum(F.mse_loss(q, goal) for q in critic(batch.observations, batch.actions))
        critic.optimizer.zero_grad()
        loss.backward()
        critic.optimizer.step()
        if step % model.target_update_interval == 0:
            polyak_update(critic.parameters(), target.parameters(), model.tau)
            polyak_update(model.batch_norm_stats, model.batch_norm_stats_target, 1.0)
        losses.append(loss.item())
    critic.set_training_mode(False)
    return {
        "critic_warmup_steps": steps,
        "critic_loss_first_100": float(np.mean(losses[:100])),
        "critic_loss_last_100": float(np.mean(losses[-100:])),
    }


def _cloning_targets(model, data: DemonstrationData):
    """The successful episodes' observations and actions (in the policy's [-1, 1] scale), as tensors."""
    import torch

    keep = data.successful
    obs = torch.as_tensor(data.observations[keep])
    target = torch.as_tensor(model.policy.scale_action(data.actions[keep]).clip(-1.0, 1.0), dtype=torch.float32)
    return obs, target


class ActorUpdate(WrappedOptimizer):
    """SAC's actor optimiser as a run started from demonstrations updates its actor.

    SB3's SAC computes its actor loss (temperature × log π − min Q), back-propagates it and calls
    ``actor.optimizer.step()``. In its place this object

    * **holds the actor** for the first ``hold_steps`` gradient steps of SAC (the step is skipped;
      the critics and the temperature learn as usual), so the critics first learn the cloned
      policy's own returns online before the actor follows them;
    * then, with ``weight`` > 0, first adds the gradient of

          weight × mean |min Q(s, a)| × (miss + spread)

      on a batch of the successful demonstrations' steps (s, a) — the cloning loss itself
      (:func:`cloning_loss`: the deterministic action's squared miss, and σ's likelihood of it),
      |Q| of the demonstrated pairs taken without gradient, as TD3+BC scales its cloning term —
      and then steps. σ is held too: SAC's entropy estimate rewards a squashed Gaussian whose σ
      runs to its bound on a few action dimensions while the others narrow (Drinking: σ up to e²
      on some joints after 5,000 steps at the clone's total entropy, their actions ±1 noise).

    The sum is the actor loss of SAC plus that term; nothing else of SAC changes."""

    def __init__(self, model, data: DemonstrationData, weight: float, hold_steps: int, seed: int):
        import torch

        super().__init__(model.actor.optimizer)
        self._model, self._weight, self._hold_steps = model, weight, hold_steps
        self._obs, self._target = _cloning_targets(model, data)
        self._generator = torch.Generator().manual_seed(seed)

    def step(self, closure=None):
        import torch

        model = self._model
        if model._n_updates < self._hold_steps:  # SB3 counts its gradient steps over every sitting
            return None
        if self._weight > 0:
            idx = torch.randint(len(self._obs), (model.batch_size,), generator=self._generator)
            obs, target = self._obs[idx], self._target[idx]
            with torch.no_grad():
                q_scale = torch.min(torch.cat(model.critic(obs, target), dim=1), dim=1)[0].abs().mean()
            miss, spread = cloning_loss(model.actor, obs, target)
            (self._weight * q_scale * (miss + spread)).backward()
            model.logger.record_mean("train/clone_miss", miss.item())
            model.logger.record_mean("train/clone_spread", spread.item())
            model.logger.record_mean("train/clone_q_scale", q_scale.item())
        return self.optimizer.step(closure)


def update_actor_as_configured(model, data: DemonstrationData, settings: Demonstrations, seed: int) -> None:
    """From now on, ``model``'s actor updates as :class:`ActorUpdate` says (where the settings
    hold the actor or keep cloning; otherwise SAC's own update stays)."""
    if settings.steers_actor_updates and not isinstance(model.actor.optimizer, ActorUpdate):
        model.actor.optimizer = ActorUpdate(model, data, settings.clone_weight, settings.hold_actor_steps, seed)


def cloned_entropy(model, data: DemonstrationData, seed: int) -> float:
    """The entropy (nats, −E[log π(a|s)] with a sampled) of ``model``'s policy over the successful
    demonstrations' states: what ``sac.target_entropy: cloned`` holds SAC's exploration to."""
    import torch

    obs, _ = _cloning_targets(model, data)
    with torch.random.fork_rng(), torch.no_grad():
        torch.manual_seed(seed)
        _, log_prob = model.actor.action_log_prob(obs)
    return float(-log_prob.mean())


def start_from(
    model, data: DemonstrationData, settings: Demonstrations, seed: int, target_entropy: float | str = "auto"
) -> dict:
    """Behaviour cloning, the replay buffer and the critic warm-up (:func:`clone`,
    :func:`fill_replay`, :func:`warm_critic`) of a new run's model, its target entropy set to the
    clone's (:func:`cloned_entropy`) where the config's ``target_entropy`` is ``cloned``; returns what
    ``demonstrations.json`` (and ``summary.json``) record as the run's ``demonstrations``."""
    figures = {
        "dataset": data.dataset,
        "policy": data.policy,
        "episodes": data.episodes,
        "successful_episodes": data.successes,
        "steps": int(len(data.actions)),
    }
    figures.update(clone(model, data, settings, seed))
    if target_entropy == "cloned":
        figures["target_entropy"] = model.target_entropy = cloned_entropy(model, data, seed)
    figures["replayed_steps"] = fill_replay(model, data) if settings.replay else 0
    figures.update(warm_critic(model, settings.critic_warmup_steps))
    figures["clone_weight"] = settings.clone_weight
    figures["hold_actor_steps"] = settings.hold_actor_steps
    return figures
