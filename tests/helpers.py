"""Small helpers shared by test modules: where a needle sits in a spec's text (``LINE:COL``, as
the CLI reports locations) and an env of a spec compiled into a fresh directory."""

from __future__ import annotations

from pathlib import Path

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.runtime.env import AssistiveEnv


def at(text: str, needle: str, occurrence: int = 1) -> str:
    """``LINE:COL`` (1-based) of the ``occurrence``-th ``needle`` in ``text``."""
    index = -1
    for _ in range(occurrence):
        index = text.index(needle, index + 1)
    line = text.count("\n", 0, index) + 1
    column = index - (text.rfind("\n", 0, index) + 1) + 1
    return f"{line}:{column}"


def compiled_env(tmp_path_factory, spec: Path, robot: str):
    """For a module fixture (``yield from``): ``spec`` compiled for ``robot`` into a fresh
    directory, its env yielded and closed afterwards."""
    name = f"{Path(spec).stem}-{robot}"
    env = AssistiveEnv(compile_task(spec, robot, tmp_path_factory.mktemp(name) / name).out_dir)
    yield env
    env.close()


def cli(*args: str, cwd: Path | None = None, env: dict | None = None, timeout: float = 600):
    """The real ``assistive-compiler`` command in a subprocess: (exit status, stdout, stderr).
    ``env`` entries are added to the current environment."""
    import os
    import subprocess
    import sys

    proc = subprocess.run(
        [sys.executable, "-m", "assistive_compiler.cli", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=os.environ | (env or {}),
    )
    return proc.returncode, proc.stdout, proc.stderr
