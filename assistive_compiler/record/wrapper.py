"""``RecordEpisodes``: a Gymnasium wrapper that writes every episode it sees as a recording."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np

from .capture import SceneReader
from .format import FORMAT, FORMAT_VERSION, Recording


class RecordEpisodes(gym.Wrapper):
    """Writes ``directory/episode-NNNN.npz`` (see :mod:`assistive_compiler.record.format`) for each
    episode of an :class:`~assistive_compiler.runtime.env.AssistiveEnv` (possibly wrapped).

    An episode is written when it ends (terminated or truncated); one cut short by ``reset()`` or
    ``close()`` is written too, with ``complete: false``. ``policy`` is a label stored in the
    header. Recording only reads the world, so the episode is the one an unwrapped env plays.
    :attr:`last_path` is the file of the last episode written, :attr:`last_recording` its contents.
    """

    def __init__(self, env: gym.Env, directory: str | Path, policy: str | None = None):
        super().__init__(env)
        from ..runtime.env import AssistiveEnv

        if not isinstance(env.unwrapped, AssistiveEnv):
            raise TypeError(f"RecordEpisodes needs an assistive_compiler env, got {type(env.unwrapped).__name__}")
        self.directory = Path(directory)
        self.policy = policy
        self.reader = SceneReader(env.unwrapped)
        self.episode = len(list(self.directory.glob("episode-*.npz"))) if self.directory.is_dir() else 0
        self.last_path: Path | None = None
        self.last_recording: Recording | None = None
        self._rows: dict[str, list] | None = None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        self._flush(complete=False)
        obs, info = self.env.reset(seed=seed, options=options)
        base = self.env.unwrapped
        self._meta = {
            "seed": seed,
            "person_variant": info["person_variant"],
            "start": info["start"],
            "person_body": base.person_body,
        }
        self._rows = {"observations": [np.asarray(obs, dtype=np.float32)]}
        self._add_state()
        return obs, info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._record(obs, action, reward, terminated, truncated, info)
        return obs, reward, terminated, truncated, info

    def step_agents(self, robot_action, human_action):
        """One step of both agents (the env's ``step_agents``: co-optimisation), recorded as
        :meth:`step` records the robot's; returns what ``step_agents`` does."""
        obs, human_obs, reward, terminated, truncated, info = self.env.unwrapped.step_agents(robot_action, human_action)
        self._record(obs, robot_action, reward, terminated, truncated, info)
        return obs, human_obs, reward, terminated, truncated, info

    def _record(self, obs, action, reward, terminated, truncated, info) -> None:
        if self._rows is not None:
            rows = self._rows
            rows["observations"].append(np.asarray(obs, dtype=np.float32))
            rows.setdefault("actions", []).append(np.asarray(action, dtype=np.float64).reshape(-1))
            rows.setdefault("rewards", []).append(float(reward))
            rows.setdefault("terms", []).append([info["terms"][name] for name in self._term_names()])
            rows.setdefault("task_success", []).append(int(info["task_success"]))
            rows.setdefault("success_metric", []).append(float(info["success_metric"]))
            rows.setdefault("force_on_human", []).append(float(info["total_force_on_human"]))
            self._add_state()
            if terminated or truncated:
                self._flush(complete=True)

    def close(self):
        self._flush(complete=False)
        super().close()

    # -- helpers -------------------------------------------------------------------------------
    def _term_names(self) -> list[str]:
        return [t.name for t in self.env.unwrapped.manifest.reward]

    def _add_state(self) -> None:
        for name, value in self.reader.state().items():
            self._rows.setdefault(name, []).append(value)

    def _flush(self, complete: bool) -> None:
        rows, self._rows = self._rows, None
        if rows is None or "rewards" not in rows:
            return
        m = self.env.unwrapped.manifest
        arrays = {name: np.asarray(values) for name, values in rows.items()}
        arrays["observations"] = arrays["observations"].astype(np.float32)
        arrays["task_success"] = arrays["task_success"].astype(np.int8)
        header = {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "task": m.task,
            "robot": m.robot_name,
            "gym_id": m.gym_id,
            "content_hash": m.content_hash,
            "policy": self.policy,
            "episode": self.episode,
            **self._meta,
            "dt": m.sim.time_step * m.sim.frame_skip,
            "steps": len(rows["rewards"]),
            "complete": complete,
            "return": float(arrays["rewards"].sum()),
            "success": bool(arrays["task_success"][-1]),
            "success_metric": float(arrays["success_metric"][-1]),
            "terms": self._term_names(),
            "term_weights": {t.name: t.weight for t in m.reward},
            "term_categories": {t.name: t.category for t in m.reward},
            **self.reader.header(),
        }
        recording = Recording(header, arrays)
        self.last_path = recording.save(self.directory / f"episode-{self.episode:04d}.npz")
        self.last_recording = recording
        self.episode += 1
