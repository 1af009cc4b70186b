"""Starting and resuming a training run: its ``run.json`` and the checks that a run resumes the
same compiled task the same way (the directory's format: :mod:`assistive_compiler.run_dir`)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

from ...artifact import Manifest
from ...errors import SpecError
from ...paths import display
from ...run_dir import RUN_FILE, RunDir, RunInfo, package_versions
from ..config import TrainingConfig


def new_run_info(spec: str, manifest, robot: str, coop: bool, engine: str, config: TrainingConfig) -> RunInfo:
    return RunInfo(
        spec=display(Path(spec)),
        task=manifest.task,
        robot=robot,
        coop=coop,
        engine=engine,
        content_hash=manifest.content_hash,
        gym_id=manifest.gym_id + ("" if not coop else " (Human)"),
        config=config.model_dump(exclude_none=True),
        versions=package_versions(),
        command=sys.argv[:],
        created=time.strftime("%Y-%m-%dT%H:%M:%S"),
    )


def _same_content(run: RunDir, content_hash: str) -> bool:
    """Whether the run's own, undamaged artifact has ``content_hash`` as today's compiler hashes
    content (a run recorded before 2026-11-28 holds the older hash, which covered the compiler
    source: the same task compiled to the same files after any compiler change would not match)."""
    try:
        own = Manifest.read(run.artifact)
    except (OSError, ValueError, SpecError):  # no readable artifact: nothing to compare
        return False
    return own.intact_hash(run.artifact) == content_hash


def check_resumable(run: RunDir, content_hash: str, robot: str, coop: bool, engine: str) -> RunInfo:
    """The run's info, after checking it trains the same compiled task the same way."""
    info = run.info()
    where = display(run.path / RUN_FILE)
    if info.content_hash != content_hash and not _same_content(run, content_hash):
        raise SpecError.at(
            where,
            f"--resume: this run trained a different compiled task (content hash {info.content_hash[:12]}, spec {info.spec}); "
            f"the spec given compiles to {content_hash[:12]}. Resume with the run's own spec, or start a new run (another --out)",
        )
    for what, ours, theirs in (
        ("robot", robot, info.robot),
        ("--coop", coop, info.coop),
        ("engine", engine, info.engine),
    ):
        if ours != theirs:
            raise SpecError.at(where, f"--resume: this run was trained with {what} {theirs!r}, not {ours!r}")
    return info
