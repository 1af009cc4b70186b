"""Training throughput: env steps per second *including learning*, and where that time goes.

``bench --training CONFIG ...`` trains a few thousand env steps of each config on a task through
the same code path as ``train`` (a throw-away run directory; SB3 engine) and reports, per config:

- ``env_steps_per_s``: env steps over the wall time of the session's learning loop (the first
  env step to the last update; set-up, compiling and the final checkpoint are not in it);
- ``env_share``: the share of that time spent stepping the envs (SB3's ``VecEnv.step`` and
  ``reset``, all env processes together; with env processes on other cores, the time the trainer
  waited for them);
- ``update_share``: the share spent in the learner's updates (``model.train()``: PPO's epochs
  over a rollout, SAC's gradient steps);
- ``rest_share``: everything else — the policy acting on each observation, the replay buffer or
  rollout buffer, observation and return normalisation, the run's curves and checkpoints.

Taken on an otherwise idle core, ``env_steps_per_s`` says how many env steps an hour a config buys:
the measure the recipe is chosen by (docs/results.md, "The recipe by the clock").
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from ..run_dir import RunDir
from .config import TrainingConfig


class StageTimer:
    """Wall time of the env steps and of the learner's updates within one training session."""

    def __init__(self) -> None:
        self.env_s = 0.0
        self.update_s = 0.0
        self.updates = 0
        self.start: float | None = None
        self.end = 0.0

    def _add_env(self, seconds: float, now: float) -> None:
        self.env_s += seconds
        self.end = now

    def wrap_env(self, venv):
        """``venv`` behind a wrapper that adds its ``step`` and ``reset`` time to :attr:`env_s`."""
        from stable_baselines3.common.vec_env import VecEnvWrapper

        timer = self

        class TimedVecEnv(VecEnvWrapper):
            def reset(self):
                t = time.perf_counter()
                obs = self.venv.reset()
                now = time.perf_counter()
                timer._add_env(now - t, now)
                return obs

            def step_async(self, actions) -> None:
                self._t = time.perf_counter()
                self.venv.step_async(actions)

            def step_wait(self):
                out = self.venv.step_wait()
                now = time.perf_counter()
                timer._add_env(now - self._t, now)
                return out

        return TimedVecEnv(venv)

    def watch_updates(self, model) -> None:
        """Time each of ``model``'s updates from now on; the session's clock starts here."""
        original = model.train
        timer = self

        def timed_train(*args, **kwargs):
            t = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                now = time.perf_counter()
                timer.update_s += now - t
                timer.updates += 1
                timer.end = now

        model.train = timed_train
        self.start = time.perf_counter()

    @staticmethod
    def unwatch(model) -> None:
        """Stop timing ``model``'s updates (before it is saved: the timing wrapper does not pickle)."""
        model.__dict__.pop("train", None)

    def report(self, steps: int) -> dict:
        """The session's figures for ``steps`` env steps."""
        assert self.start is not None, "watch_updates was never called"
        wall = max(1e-9, self.end - self.start)
        return {
            "env_steps": steps,
            "wall_s": round(wall, 2),
            "env_steps_per_s": round(steps / wall, 1),
            "env_share": round(self.env_s / wall, 3),
            "update_share": round(self.update_s / wall, 3),
            "rest_share": round(max(0.0, 1 - (self.env_s + self.update_s) / wall), 3),
            "updates": self.updates,
            "env_steps_per_hour_millions": round(3600 * steps / wall / 1e6, 2),
        }


def measure_training(spec: str, robot: str, config_path: str, steps: int) -> dict:
    """Train ``steps`` env steps of the config at ``config_path`` on ``spec`` × ``robot`` (SB3
    engine, a temporary run directory) and return :meth:`StageTimer.report`'s figures with the
    config's name and settings. An off-policy config's random warm-up (``learning_starts``) is
    cut to 1,000 steps so that the few thousand steps measured are mostly learning ones."""
    from .bookkeeping.resume import new_run_info
    from .config import load_training_config
    from .engines import sb3
    from .train import compile_for_run, reward_weights

    config: TrainingConfig = load_training_config(config_path)
    data = config.model_dump()
    data["total_steps"] = steps
    data["checkpoint_every_steps"] = 10 * steps  # the session's final checkpoint only, after the clock stops
    if config.sac is not None:
        data["sac"]["learning_starts"] = min(config.sac.learning_starts, 1_000)
        data["sac"]["buffer_size"] = min(config.sac.buffer_size, 10 * steps)
    config = TrainingConfig.model_validate(data)
    result, robot = compile_for_run(spec, robot, coop=False)
    manifest = result.manifest
    timer = StageTimer()
    with tempfile.TemporaryDirectory(prefix="bench-training-") as tmp:
        run = RunDir(Path(tmp) / "run")
        run.create(new_run_info(spec, manifest, robot, False, "sb3", config), result.out_dir)
        sb3.train(run, config, reward_weights(manifest), resume=False, quiet=True, timer=timer)
    figures = timer.report(steps)
    return {
        "config": Path(config_path).stem,
        "algorithm": config.algorithm,
        "library": config.library,
        "network": "×".join(str(w) for w in config.network.hidden),
        "envs": config.envs,
        "vec_env": config.vec_env,
        "updates_per_env_step": _updates_per_env_step(config),
        "task": manifest.task,
        "robot": robot,
        **figures,
    }


def _updates_per_env_step(config: TrainingConfig) -> float:
    """Gradient steps per env step (PPO: epochs × minibatches per batch, over the batch)."""
    if config.sac is not None:
        return round(config.sac.gradient_steps / (config.sac.train_freq * config.envs), 3)
    p = config.ppo
    batch = p.rollout_steps * config.envs
    return round(p.epochs * -(-batch // p.minibatch_size) / batch, 3)
