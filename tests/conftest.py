"""Fixtures shared by the test modules."""

from __future__ import annotations

from pathlib import Path

import pytest

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.runtime.env import AssistiveEnv

REPO = Path(__file__).resolve().parents[1]
FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"


@pytest.fixture(scope="session")
def artifact(tmp_path_factory) -> Path:
    """Feeding compiled for Jaco, once per test session."""
    return compile_task(FEEDING, "jaco", tmp_path_factory.mktemp("feeding-artifact") / "feeding-jaco").out_dir


@pytest.fixture(scope="module")
def env(artifact):
    """One env shared by a module's tests that only reset and step it."""
    e = AssistiveEnv(artifact)
    yield e
    e.close()
