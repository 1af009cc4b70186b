"""Episode recordings: write every episode as a compact ``.npz`` (:class:`RecordEpisodes`, or
``run --record DIR``) and read it back without simulating (:func:`load_recording`).

The file format (every array's shape, units and frames) is documented in :mod:`.format`.
"""

from __future__ import annotations

from .format import Recording, RecordingError, episode_files, load_recording
from .wrapper import RecordEpisodes

__all__ = ["RecordEpisodes", "Recording", "RecordingError", "episode_files", "load_recording", "record_episode"]


def record_episode(
    env, policy, seed: int | None, directory, policy_name: str | None = None, options: dict | None = None
) -> Recording:
    """Play one episode of ``env`` with ``policy`` (``obs -> action``) from ``reset(seed=seed)``
    and write it to ``directory`` (see :class:`RecordEpisodes`). Returns the recording."""
    recorder = RecordEpisodes(env, directory, policy=policy_name)
    obs, _ = recorder.reset(seed=seed, options=options)
    done = False
    while not done:
        obs, _, terminated, truncated, _ = recorder.step(policy(obs))
        done = terminated or truncated
    return recorder.last_recording
