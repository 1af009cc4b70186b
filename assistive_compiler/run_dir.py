"""A run directory: everything one training run needs to be understood, resumed and evaluated.

The on-disk format only, as :mod:`assistive_compiler.artifact` is the compiled task's: training
writes it (:mod:`assistive_compiler.training`), and policies play its newest checkpoint
(:mod:`assistive_compiler.policies.checkpoint`) without the training code.

Layout (``runs/<task>-<robot>[-coop]-s<seed>/`` by default)::

    run.json          what was trained: spec, robot, co-op, engine, the compiled spec's content
                      hash, the resolved training config, package versions, the command line
    config.yaml       the resolved training config (command-line overrides applied)
    artifact/         the compiled task the run trained on (evaluation rebuilds envs from it)
    tb/               TensorBoard logs (Episode_Reward/<term>, Episode/success_rate, ...)
    checkpoints/      step_<N>/ — one directory per checkpoint, resumable
    curve.csv         the learning curve: env steps, wall seconds, mean return, success rate
    learning_curve.png
    summary.json      the run's final figures (steps, wall time, throughput, last returns)
    demonstrations.json   a run started from demonstrations: the dataset and how the start went
                      (episodes, steps cloned, the cloning error before and after, steps replayed)
"""

from __future__ import annotations

import json
import os
import platform
import shutil
import time
from dataclasses import asdict, dataclass
from importlib import metadata
from pathlib import Path

import yaml

from .errors import UsageError
from .paths import display

RUN_FILE = "run.json"
PARTIAL = ".partial-"


def write_atomic(path: Path, text: str) -> None:
    """Write ``path`` so that a reader (or a process killed mid-write) sees the old file or the new
    one, never a torn one: a temporary file beside it, flushed to disk, then renamed over it."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    with tmp.open("w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


PACKAGES = ("assistive-compiler", "pybullet", "gymnasium", "numpy", "torch", "stable-baselines3", "ray", "pettingzoo")


def package_versions() -> dict[str, str | None]:
    """Versions of the packages a run depends on (None: not installed), and Python's."""
    out: dict[str, str | None] = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def engine_modules(engine: str, library: str = "sb3") -> tuple[str, ...]:
    """The modules a training engine (``sb3``, ``rllib``) needs to train, or to play its checkpoints;
    ``library`` ``sbx``: the SB3 engine learning with SBX (JAX) as well."""
    if engine != "sb3":
        return ("torch", "ray")
    return ("torch", "stable_baselines3") + (("jax", "sbx") if library == "sbx" else ())


@dataclass(frozen=True)
class RunInfo:
    """What a run trains; written once to ``run.json`` when the run starts."""

    spec: str
    task: str
    robot: str
    coop: bool
    engine: str
    content_hash: str
    gym_id: str
    config: dict
    versions: dict
    command: list[str]
    created: str

    @property
    def algorithm(self) -> str:
        """The trained algorithm's name (``ppo``, ``sac``); the whole config is
        :func:`assistive_compiler.training.config.run_config`."""
        return str(self.config["algorithm"])

    @property
    def library(self) -> str:
        """The implementation that learned an SB3-engine run: ``sb3`` (PyTorch) or ``sbx`` (JAX)."""
        return str((self.config.get("sac") or {}).get("library", "sb3"))


class RunDir:
    """A run directory on disk (see the module docstring for its layout)."""

    def __init__(self, path: str | Path):
        self.path = Path(path)

    # -- layout --------------------------------------------------------------------------------
    artifact = property(lambda self: self.path / "artifact")
    tb = property(lambda self: self.path / "tb")
    checkpoints = property(lambda self: self.path / "checkpoints")
    curve_csv = property(lambda self: self.path / "curve.csv")
    curve_png = property(lambda self: self.path / "learning_curve.png")
    summary_json = property(lambda self: self.path / "summary.json")
    demonstrations_json = property(lambda self: self.path / "demonstrations.json")

    def exists(self) -> bool:
        return (self.path / RUN_FILE).is_file()

    def info(self) -> RunInfo:
        """The run's ``run.json``; a clear error when ``path`` is not a run directory."""
        file = self.path / RUN_FILE
        if not file.is_file():
            raise UsageError(
                f"{display(self.path)}: not a run directory (no {RUN_FILE}); `assistive-compiler train` writes one"
            )
        return RunInfo(**json.loads(file.read_text()))

    def create(self, info: RunInfo, artifact_src: Path) -> None:
        """Write a new run: its description, config and a copy of the compiled task."""
        self.path.mkdir(parents=True, exist_ok=True)
        if self.artifact.exists():
            shutil.rmtree(self.artifact)
        shutil.copytree(artifact_src, self.artifact)
        write_atomic(self.path / "config.yaml", yaml.safe_dump(info.config, sort_keys=False))
        write_atomic(self.path / RUN_FILE, json.dumps(asdict(info), indent=1))

    # -- checkpoints ---------------------------------------------------------------------------
    def checkpoint_dir(self, steps: int) -> Path:
        return self.checkpoints / f"step_{steps:010d}"

    def latest_checkpoint(self) -> tuple[int, Path] | None:
        """(env steps, directory) of the newest complete checkpoint, or None."""
        done = self.complete_checkpoints()
        if not done:
            return None
        steps = max(done)
        return steps, done[steps]

    def complete_checkpoints(self) -> dict[int, Path]:
        """Every complete checkpoint: env steps -> directory, oldest first."""
        if not self.checkpoints.is_dir():
            return {}
        done = sorted(p for p in self.checkpoints.glob("step_*") if (p / "COMPLETE").is_file())
        return {int(p.name.split("_")[1]): p for p in done}

    def begin_checkpoint(self, steps: int) -> Path:
        """A fresh, empty directory to write the checkpoint at ``steps`` into: a hidden partial one
        (``checkpoints/.partial-step_N``), renamed into place by :meth:`end_checkpoint`. A process
        killed while writing leaves only partial directories, which are never resumed from and are
        cleared by the next checkpoint."""
        self.checkpoints.mkdir(parents=True, exist_ok=True)
        for stale in self.checkpoints.glob(f"{PARTIAL}*"):
            shutil.rmtree(stale, ignore_errors=True)
        out = self.checkpoints / f"{PARTIAL}{self.checkpoint_dir(steps).name}"
        out.mkdir()
        return out

    def end_checkpoint(self, out: Path, steps: int, extra: dict | None = None) -> Path:
        """Mark the written checkpoint complete and move it into place (replacing one of the same
        steps); returns its directory. Only complete checkpoints are resumed from."""
        write_atomic(out / "COMPLETE", json.dumps({"steps": steps, "time": time.time(), **(extra or {})}))
        final = self.checkpoint_dir(steps)
        if final.exists():
            shutil.rmtree(final)
        os.replace(out, final)
        return final

    # -- results -------------------------------------------------------------------------------
    def write_summary(self, summary: dict) -> None:
        write_atomic(self.summary_json, json.dumps(summary, indent=1))

    def demonstrations(self) -> dict | None:
        """How a run started from demonstrations did so (``demonstrations.json``); None for pure RL."""
        return json.loads(self.demonstrations_json.read_text()) if self.demonstrations_json.is_file() else None
