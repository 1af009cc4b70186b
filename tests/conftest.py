"""Fixtures shared by the test modules."""

from __future__ import annotations

import functools
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


# pytest-xdist grouping (pyproject: -n auto --dist loadgroup). xdist's scheduler keeps the tests
# of one group on one worker, reading the group from a "@group" suffix of the node id, which its
# worker plugin adds by writing Item._nodeid; pytest 9.2 keeps the id in Item._id, so that write
# is lost and no group (not even an explicit xdist_group mark) reached the scheduler
# (pytest-dev/pytest-xdist#1386). The hook below runs on each xdist worker after xdist's own.


def _module_fixture_groups(items: list[pytest.Item]) -> dict[pytest.Item, str]:
    """For each test that uses a module- or class-scoped fixture defined in its own module, a group
    name shared by every test of that module linked to it through such fixtures, so that the
    fixture is built on one worker only (and, being a group of several tests, early: xdist hands
    out its largest groups first). That holds for one built across workers by :func:`built_once`
    too: spread over both workers, the second would wait idle for the first one's build."""
    parent: dict[str, str] = {}  # union-find over "<module>::<fixture>"

    def root(key: str) -> str:
        while parent.setdefault(key, key) != key:
            key = parent[key]
        return key

    used: dict[pytest.Item, str] = {}
    for item in items:
        module = item.getparent(pytest.Module)
        info = getattr(item, "_fixtureinfo", None)
        if module is None or info is None:
            continue
        keys = [
            f"{module.nodeid}::{name}"
            for name, defs in info.name2fixturedefs.items()
            if defs and defs[-1].scope in ("module", "class") and defs[-1].baseid.split("::")[0] == module.nodeid
        ]
        for key in keys:
            parent[root(key)] = root(keys[0])
        if keys:
            used[item] = keys[0]
    members: dict[str, list[str]] = {}
    for key in list(parent):
        members.setdefault(root(key), []).append(key.rpartition("::")[2])
    return {
        item: f"{Path(key.partition('::')[0]).stem}.{'+'.join(sorted(members[root(key)]))}".replace("@", "_")
        for item, key in used.items()
    }


def _xdist_group(item: pytest.Item) -> str | None:
    """The group xdist's worker plugin names for ``item``: its xdist_group marks, joined."""
    names = {str(m.args[0] if m.args else m.kwargs.get("name", "default")) for m in item.iter_markers("xdist_group")}
    return "_".join(sorted(names)) or None


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """On an xdist worker under --dist loadgroup, after xdist's own hook: mark the tests that share
    an expensive module fixture as one group (:func:`_module_fixture_groups`; a test with a group
    of its own keeps it), then give every grouped test the "@group" suffix the scheduler reads,
    where xdist's write did not take (a pytest that keeps the id where xdist writes it, or a
    fixed xdist, leaves nothing to do)."""
    if not getattr(config.option, "loadgroup", False):  # set on xdist workers under --dist loadgroup
        return
    for item, group in _module_fixture_groups(items).items():
        if not item.get_closest_marker("xdist_group"):
            item.add_marker(pytest.mark.xdist_group(group))
    for item in items:
        group = _xdist_group(item)
        if group is None or item.nodeid.endswith(f"@{group}"):
            continue
        grouped = f"{item.nodeid}@{group}"
        if hasattr(item, "_id"):  # pytest >= 9.2: a structured NodeId
            item._id = type(item._id).parse(grouped)
        else:
            item._nodeid = grouped
        if item.nodeid != grouped:
            raise pytest.UsageError(f"cannot give {item.nodeid} its xdist group: this pytest keeps node ids elsewhere")


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


@pytest.fixture
def shared_cache(tmp_path_factory, monkeypatch) -> Callable[[str], FileLock]:
    """One artifact cache ($ASSISTIVE_COMPILER_CACHE) for the whole test session, every xdist worker
    and every test file that makes shipped envs by name, so each shipped task × robot compiles once
    (a Gymnasium id and its co-optimisation name share one folder); returns the lock, by either
    name, to hold while making such an env (the first maker compiles, the others wait)."""
    cache = tmp_path_factory.getbasetemp().parent / "shipped-ids-cache"
    cache.mkdir(exist_ok=True)
    monkeypatch.setenv("ASSISTIVE_COMPILER_CACHE", str(cache))
    return lambda name: artifact_lock(*_shipped_envs()[name])


@functools.cache
def _shipped_envs() -> dict[str, tuple[Path, str]]:
    """(task spec, robot) of every shipped env, by Gymnasium id and by co-optimisation name."""
    from assistive_compiler.coop import coop_name
    from assistive_compiler.gym_ids import shipped_ids

    ids = shipped_ids()
    return ids | {coop_name(env_id): where for env_id, where in ids.items()}


def artifact_lock(spec: Path, robot: str) -> FileLock:
    """The lock of the folder of the artifact cache ($ASSISTIVE_COMPILER_CACHE) that ``spec`` for
    ``robot`` compiles into, made by name or by ``compile_task(spec, robot, cached_artifact_dir(...))``."""
    from assistive_compiler.registration import cached_artifact_dir

    return FileLock(f"{cached_artifact_dir(spec, robot)}.lock")


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
