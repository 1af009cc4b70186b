"""Fixtures shared by the test modules."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pybullet as pb
import pytest
import xacro
import yourdfpy
from filelock import FileLock

from assistive_compiler.bullet import connect
from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.runtime.env import AssistiveEnv
from assistive_compiler.runtime.snapshot import Snapshot

REPO = Path(__file__).resolve().parents[1]
FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"


@pytest.fixture(scope="session")
def artifact(tmp_path_factory) -> Path:
    """Feeding compiled for Jaco, once per test session."""
    return compile_task(FEEDING, "jaco", tmp_path_factory.mktemp("feeding-artifact") / "feeding-jaco").out_dir


def built_once(tmp_path_factory, worker_id: str, name: str, build: Callable[[Path], None]) -> Path:
    """A directory ``build(path)`` makes, built once per test session, not once per xdist worker:
    the first worker to ask builds it into the session's shared temporary folder under a file
    lock (xdist's documented recipe); every worker gets its own copy, so tests that write into
    it do not race."""
    mine = tmp_path_factory.mktemp(name) / name
    if worker_id == "master":  # not under xdist
        build(mine)
        return mine
    shared = tmp_path_factory.getbasetemp().parent / f"built-once-{name}"
    with FileLock(f"{shared}.lock"):
        if not (shared / ".built").is_file():
            if shared.exists():
                shutil.rmtree(shared)  # a build that failed part way
            build(shared)
            (shared / ".built").touch()
    shutil.copytree(shared, mine, ignore=shutil.ignore_patterns(".built"))
    return mine


def shipped_once(tmp_path_factory, worker_id: str, task: str, robot: str) -> Path:
    """The shipped task ``task`` compiled for ``robot``, once per test session (:func:`built_once`)."""
    spec = REPO / "specs" / "tasks" / f"{task}.yaml"
    return built_once(tmp_path_factory, worker_id, f"{task}-{robot}", lambda out: compile_task(spec, robot, out))


@pytest.fixture(scope="session")
def stretch_scratch_artifact(tmp_path_factory, worker_id) -> Path:
    """Scratch Itch compiled for Stretch (a mobile base and telescoping tubes), once per session."""
    return shipped_once(tmp_path_factory, worker_id, "scratch_itch", "stretch")


@pytest.fixture(scope="session")
def itch_artifact(tmp_path_factory, worker_id) -> Path:
    """Scratch Itch compiled for Jaco (its scratcher welded to the hand), once per session."""
    return shipped_once(tmp_path_factory, worker_id, "scratch_itch", "jaco")


@pytest.fixture
def cid():
    """A private pybullet DIRECT client for one test, with the package's engine settings."""
    client = connect()
    yield client
    pb.disconnect(client)


@pytest.fixture(scope="module")
def env(artifact):
    """One env shared by a module's tests that only reset and step it."""
    e = AssistiveEnv(artifact)
    yield e
    e.close()


@pytest.fixture
def snap(env) -> Snapshot:
    """A fresh snapshot of the module's env's world, just reset (seed 0), nothing bound yet."""
    env.reset(seed=0)
    return Snapshot(env.world)


# Template modules (test_<robot>_kinematics.py) define TEMPLATE; these render and load it once per module.


@pytest.fixture(scope="module")
def urdf_text(request) -> str:
    """The module's TEMPLATE rendered with its defaults (a fresh mappings dict: xacro mutates it)."""
    return xacro.process_file(str(request.module.TEMPLATE), mappings={}).toprettyxml(indent="  ")


@pytest.fixture(scope="module")
def urdf_path(urdf_text, request, tmp_path_factory) -> Path:
    name = Path(request.module.TEMPLATE).name.removesuffix(".urdf.xacro")
    path = tmp_path_factory.mktemp(name) / f"{name}.urdf"
    path.write_text(urdf_text)
    return path


@pytest.fixture(scope="module")
def model(urdf_path):
    """The rendered template loaded by yourdfpy (an independent URDF reader)."""
    return yourdfpy.URDF.load(str(urdf_path), build_scene_graph=True, load_meshes=False)
