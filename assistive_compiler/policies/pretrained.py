"""Trained policies by name: the shipped ones (``pretrained:<task>-<robot>``, and
``pretrained:<task>-<robot>-coop`` for a co-optimised pair), an exported policy folder, or a
training run directory.

A shipped policy is a folder of ``pretrained/`` (in the repository; inside the installed package
as data) holding ``policy.json`` and ``weights.npz`` (:mod:`.mlp`): it runs on NumPy alone. Its
``policy.json`` says what it was trained on (task, robot, the compiled task's content hash,
algorithm, env steps, wall time) and how it evaluated (``evaluation``: unseen seeds, 100
episodes; ``regression``: the few fixed seeds the test suite re-checks on the current code).
A co-optimised policy folder holds ``robot/`` and ``human/``, one such pair each.

A run directory (``train``'s ``--out``) is played from its newest checkpoint with the training
library it was trained with, so it needs the ``train`` extra.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import UsageError, did_you_mean, one_of
from ..paths import data_root
from ..run_dir import RUN_FILE
from .mlp import POLICY_FILE, MLPPolicy, SampledPolicy

PREFIX = "pretrained:"
BASELINES = ("random", "zero", "scripted")


def pretrained_dir() -> Path:
    """The folder of shipped policies (``pretrained/`` beside ``specs/``)."""
    return data_root() / "pretrained"


def shipped_names() -> list[str]:
    """The shipped policies' names, e.g. ``feeding-jaco``."""
    root = pretrained_dir()
    return sorted(p.name for p in root.iterdir() if (p / POLICY_FILE).is_file()) if root.is_dir() else []


def shipped_info(name: str) -> dict:
    """A shipped policy's ``policy.json``."""
    return json.loads((pretrained_folder(name) / POLICY_FILE).read_text())


def pretrained_folder(name: str) -> Path:
    """The folder of the shipped policy ``name`` (``feeding-jaco``); a clear error if none ships."""
    names = shipped_names()
    if name not in names:
        shipped = one_of(names) if names else "none"
        raise UsageError(
            f"--policy {PREFIX}{name}: no shipped policy of that name; shipped: {shipped}{did_you_mean(name, names)}"
        )
    return pretrained_dir() / name


class CoopPolicy:
    """A co-optimised pair: the robot's and the person's policies, each ``obs -> action``."""

    def __init__(self, robot, human, info: dict):
        self.robot, self.human, self.info = robot, human, info

    def agent(self, name: str):
        return {"robot": self.robot, "human": self.human}[name]

    def __call__(self, robot_obs: np.ndarray, human_obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.robot(robot_obs), self.human(human_obs)

    @property
    def samples(self) -> bool:
        return self.robot.samples and self.human.samples

    def sampling(self, seed: int) -> CoopPolicy:
        """Both agents acting as in training (:class:`.mlp.SampledPolicy`), drawing their noise in turn
        (robot, then person) from one generator seeded with ``seed``, as the run's checkpoint does."""
        if not self.samples:
            raise ValueError("this pair was exported without its log-stds (by an earlier version): it has means only")
        rng = np.random.default_rng(seed)
        return CoopPolicy(SampledPolicy(self.robot, rng), SampledPolicy(self.human, rng), self.info)


def load_folder(folder: Path):
    """An exported policy folder: one :class:`MLPPolicy`, or a :class:`CoopPolicy` (``robot/``, ``human/``)."""
    info = json.loads((folder / POLICY_FILE).read_text())
    if info.get("coop"):
        return CoopPolicy(MLPPolicy.load(folder / "robot"), MLPPolicy.load(folder / "human"), info)
    return MLPPolicy.load(folder)


def load_trained(source: str):
    """The trained policy ``source`` names: ``pretrained:<name>``, an exported policy folder or a
    run directory (newest checkpoint). Returns ``(policy, info)``; ``info`` has at least ``task``,
    ``robot`` and ``coop``."""
    if source.startswith(PREFIX):
        policy = load_folder(pretrained_folder(source[len(PREFIX) :]))
        return policy, policy.info
    path = Path(source)
    if (path / POLICY_FILE).is_file():
        policy = load_folder(path)
        return policy, policy.info
    if (path / RUN_FILE).is_file():
        from .checkpoint import load_run

        return load_run(path, source)
    expected = f"{one_of(BASELINES)}, {PREFIX}<task>-<robot> (shipped: {', '.join(shipped_names()) or 'none'}), a run directory or an exported policy folder"
    if path.exists():
        raise UsageError(
            f"--policy {source}: neither a run directory (no run.json) nor an exported policy (no {POLICY_FILE}); expected {expected}"
        )
    raise UsageError(f"--policy: unknown policy '{source}'; expected {expected}{did_you_mean(source, BASELINES)}")


def check_fits(info: dict, manifest, source: str, coop: bool = False) -> None:
    """Refuse a trained policy of another task or robot than the env's, or a co-optimised pair
    outside ``--coop``."""
    task, robot = info.get("task"), info.get("robot")
    if (task, robot) != (manifest.task, manifest.robot_name):
        raise UsageError(
            f"--policy {source}: trained for {task} with {robot}, but the env is {manifest.task} with "
            f"{manifest.robot_name}"
        )
    if info.get("coop") and not coop:
        raise UsageError(f"--policy {source}: a co-optimised pair (robot and person) plays under --coop only")
